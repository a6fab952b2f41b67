
iverilog-@name@:
	@echo "== @name@"
	cd @name@ && $(IVERILOG) -g2005 -Wall -s @tb@ -o @tb@.vvp $(RTL) @tb@.v && $(VVP) -n @tb@.vvp $(TB_PLUSARGS)

verilator-@name@:
	@echo "== @name@"
	cd @name@ && $(VERILATOR) --binary --timing $(if $(filter 1,$(WAVES)),--trace) -Wall -Wno-DECLFILENAME -Wno-UNUSEDSIGNAL -Wno-fatal -j 2 --top-module @tb@ -Mdir obj_verilator $(RTL) @tb@.v >verilator_build.log 2>&1 || (cat verilator_build.log; exit 1)
	cd @name@ && ./obj_verilator/V@tb@ $(TB_PLUSARGS)

ghdl-@name@:
	@echo "== @name@"
	cd @name@ && rm -rf ghdl_work && mkdir ghdl_work && $(GHDL) -a --std=08 -Werror --workdir=ghdl_work @vhdl@ @tb@.vhd
	cd @name@ && $(GHDL) --elab-run --std=08 --workdir=ghdl_work @tb@ $(TB_GENERICS) --ieee-asserts=disable-at-0 $(if $(filter 1,$(WAVES)),--vcd=@tb@.vcd) $(GHDL_RUN_FLAGS)
