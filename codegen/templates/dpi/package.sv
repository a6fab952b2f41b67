@provenance@
// Language: SystemVerilog. The DPI-C imports of libgyrofx_capi (capi/include/gyrofx.h) for
// this package's blocks, in one package: the testbenches here start with
// `import gyrofx_dpi_pkg::*;`, and so can a testbench of your own (compile this file first).
`timescale 1ns / 1ps

package gyrofx_dpi_pkg;

import "DPI-C" function string gyrofx_version();
import "DPI-C" function chandle gyrofx_plan_from_package(input string folder);
import "DPI-C" function void gyrofx_plan_free(input chandle plan);
import "DPI-C" function string gyrofx_last_error();
@imports@

endpackage
