
# The cocotb tests (@folder@/): make sim-cocotb or make cocotb-<block> (@list@). They need
# cocotb 2.x and the gyrofx Python package (pip install <gyrofx>/python) for the python3 on
# PATH. SIM picks cocotb's simulator: icarus (its Verilator support needs 5.036 or later).
SIM ?= icarus
.PHONY: sim-cocotb@targets@
sim-cocotb:@targets@
