@header@
# Runs the testbenches without gyrofx: make sim-iverilog, make sim-verilator, make sim-ghdl (every
# block), or make <simulator>-<block>. Blocks: @list@.
# Options, the same in every simulator: MASK=<n> (latency mask: the first n samples of the run
# and from every reset on are not compared), MAX_REPORTED=<n> (mismatches printed),
# MAX_MISMATCHES=<n> (stop at the n-th; 0: never), WAVES=1 (VCD dump: tb_<module>.vcd).
# PLUSARGS / GHDL_RUN_FLAGS pass anything else to the Verilog / GHDL simulation. GHDL's LLVM back
# end runs the closed-loop testbenches about 3x faster than mcode (Debian: apt-get install
# ghdl-llvm, then GHDL_BACKEND=llvm).
IVERILOG ?= iverilog
VVP ?= vvp
VERILATOR ?= verilator
GHDL ?= ghdl
MASK ?= 0
MAX_REPORTED ?= 10
MAX_MISMATCHES ?= 0
WAVES ?= 0
RTL := @rtl@
VHDL := @vhdl@
TB_PLUSARGS = +mask=$(MASK) +max_reported=$(MAX_REPORTED) +max_mismatches=$(MAX_MISMATCHES) $(if $(filter 1,$(WAVES)),+dump) $(PLUSARGS)
TB_GENERICS = -gMASK_SAMPLES=$(MASK) -gMAX_REPORTED=$(MAX_REPORTED) -gMAX_MISMATCHES=$(MAX_MISMATCHES)

.PHONY: all sim-iverilog sim-verilator sim-ghdl clean@phony@
all: sim-iverilog sim-verilator sim-ghdl
sim-iverilog:@iverilog@
sim-verilator:@verilator@
sim-ghdl:@ghdl@
