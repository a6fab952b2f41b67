
# The DPI-C testbenches (@folder@/): make sim-dpi or make dpi-<block> (@list@), in Verilator,
# against gyrofx's C library: GYROFX_CAPI_LIB=<path to libgyrofx_capi.a> (cargo build --release
# -p gyrofx-capi in the gyrofx repository). DPI_PLUSARGS: +samples=<n> +seed=<n> +flip=<k>.
GYROFX_CAPI_LIB ?=
DPI_PLUSARGS ?=
.PHONY: sim-dpi@targets@
sim-dpi:@targets@
