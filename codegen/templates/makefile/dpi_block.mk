
dpi-@name@:
	@echo "== @name@"
	@test -n "$(GYROFX_CAPI_LIB)" || (echo "GYROFX_CAPI_LIB is not set: point it at libgyrofx_capi.a (cargo build --release -p gyrofx-capi)" >&2; exit 2)
	cd @name@ && $(VERILATOR) --binary --timing -Wno-fatal -Wno-WIDTH -Wno-DECLFILENAME -Wno-UNUSEDSIGNAL -j 2 --top-module @tb@ -Mdir obj_dpi $(RTL) ../@folder@/gyrofx_dpi_pkg.sv ../@folder@/@tb@.sv -LDFLAGS "$(abspath $(GYROFX_CAPI_LIB)) -lpthread -ldl -lm" >dpi_build.log 2>&1 || (cat dpi_build.log; exit 1)
	cd @name@ && ./obj_dpi/V@tb@ $(DPI_PLUSARGS)
