//! The package's cocotb tests (`cocotb/`): per block with a Python model, a Verilog wrapper
//! that sets the block's parameters from its `<block>_params.vh`, a cocotb makefile and a test
//! module that drives the RTL with random and directed stimulus and checks it live against the
//! `gyrofx` Python package (the same Rust model as the vectors). The shared driver and
//! scoreboard are `cocotb/gyrofx_cocotb.py`.
//!
//! Run from the package: `make cocotb-<block>` (`SIM=icarus`, the default), or
//! `gyrofx verify --sim cocotb`. cocotb 2.x runs Verilator only from 5.036 on; Debian 12's
//! 5.006 is refused by cocotb's own makefile, so Icarus is the simulator CI runs.

use std::fmt::Write as _;

use crate::block::Block;
use crate::hdl::RTL_SOURCES;
use crate::testbench::verilog::instance;
use crate::text::Provenance;

/// The shared driver, protocol and scoreboard.
const SHARED: &str = include_str!("cocotb/gyrofx_cocotb.py");

/// Folder of the cocotb files in a package.
pub const FOLDER: &str = "cocotb";

/// The blocks of `blocks` that have a cocotb test ([`Block::cocotb_test`]), in the package's
/// order.
pub fn tested(blocks: &[Block]) -> Vec<&Block> {
    blocks.iter().filter(|b| b.cocotb_test.is_some()).collect()
}

/// Every file of the package's `cocotb/` folder: `(path, text)`.
pub fn files(blocks: &[Block], provenance: &Provenance) -> Vec<(String, String)> {
    let tested = tested(blocks);
    if tested.is_empty() {
        return Vec::new();
    }
    let python = |text: &str| format!("{}\n{text}", provenance.line("#"));
    let mut files = vec![(format!("{FOLDER}/gyrofx_cocotb.py"), python(SHARED))];
    for block in tested {
        let test = block.cocotb_test.expect("tested blocks have a test");
        files.push((
            format!("{FOLDER}/test_{}.py", block.name),
            python(&with_pipeline(test, block)),
        ));
        files.push((
            format!("{FOLDER}/cocotb_{}.v", block.module),
            wrapper(block, provenance),
        ));
        files.push((
            format!("{FOLDER}/{}.mk", block.name),
            makefile(block, provenance),
        ));
    }
    files
}

/// `test` with its pipeline constants set from `block`, the one source of its timing:
/// `OUTPUT_CLOCKS` (clocks after the edge that takes a sample until the registered outputs show
/// it) and `PIPELINE_CLOCKS` (idle clocks between samples at the fastest spacing).
fn with_pipeline(test: &str, block: &Block) -> String {
    let mut text: String = test
        .lines()
        .map(|line| {
            if line.starts_with("OUTPUT_CLOCKS = ") {
                format!("OUTPUT_CLOCKS = {}", block.settle_clocks())
            } else if line.starts_with("PIPELINE_CLOCKS = ") {
                format!("PIPELINE_CLOCKS = {}", block.clocks_per_sample() - 1)
            } else {
                line.to_string()
            }
        })
        .collect::<Vec<_>>()
        .join("\n");
    text.push('\n');
    text
}

/// `cocotb_<module>`: the block's module with this package's parameters, the test's top level.
pub fn wrapper(block: &Block, provenance: &Provenance) -> String {
    let top = format!("cocotb_{}", block.module);
    let ports = block.port_declarations();
    let mut out = String::new();
    let _ = write!(
        out,
        "{provenance}
`resetall
`timescale 1ns / 1ps
`default_nettype none

// {top}: {module} ({title}) with this package's parameters ({params_file}), the top level of
// the cocotb test {folder}/test_{name}.py. Compiled in the block's folder (ROM paths and the
// include are relative to it).
module {top} (
{ports}
);

`include \"{params_file}\"

{instance}
endmodule

`resetall
",
        provenance = provenance.line("//"),
        module = block.module,
        title = block.title,
        params_file = block.file("params.vh"),
        folder = FOLDER,
        name = block.name,
        ports = ports.join(",\n"),
        instance = instance(block),
    );
    out
}

/// `<block>.mk`: cocotb's makefile set up for the block, run from the block's folder.
pub fn makefile(block: &Block, provenance: &Provenance) -> String {
    let sources: Vec<String> = RTL_SOURCES
        .iter()
        .map(|(name, _)| format!("../hdl/{name}"))
        .collect();
    format!(
        "{provenance}
# The cocotb test of {name} ({module}); run it from the package folder with make cocotb-{name}
# (or from {name}/ with make -f ../{folder}/{name}.mk). Needs cocotb 2.x and the gyrofx Python
# package importable by the python3 on PATH. SIM=icarus (cocotb's Verilator support needs
# Verilator 5.036 or later).
SIM ?= icarus
# One seed, one stimulus: COCOTB_RANDOM_SEED=<n> picks another.
export COCOTB_RANDOM_SEED ?= 1
TOPLEVEL_LANG = verilog
VERILOG_SOURCES = {sources} ../{folder}/cocotb_{module}.v
COMPILE_ARGS += -I.
COCOTB_TOPLEVEL = cocotb_{module}
COCOTB_TEST_MODULES = test_{name}
export PYTHONPATH := $(abspath ../{folder})$(if $(PYTHONPATH),:$(PYTHONPATH))
export GYROFX_PACKAGE ?= $(abspath ..)
include $(shell cocotb-config --makefiles)/Makefile.sim
",
        provenance = provenance.line("#"),
        name = block.name,
        module = block.module,
        folder = FOLDER,
        sources = sources.join(" "),
    )
}

/// What running the cocotb tests writes into the package (for `make clean` and the marker).
pub fn build_outputs(blocks: &[Block]) -> Vec<String> {
    let tested = tested(blocks);
    let mut out: Vec<String> = tested
        .iter()
        .flat_map(|b| {
            [
                format!("{}/sim_build/", b.name),
                format!("{}/results.xml", b.name),
            ]
        })
        .collect();
    if !tested.is_empty() {
        out.push(format!("{FOLDER}/__pycache__/"));
    }
    out
}
