
cocotb-@name@:
	@echo "== @name@"
	cd @name@ && $(MAKE) --no-print-directory -f ../@folder@/@name@.mk SIM=$(SIM)
