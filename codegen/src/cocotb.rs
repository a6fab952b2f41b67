//! The package's cocotb tests (`cocotb/`): per block with a Python model, a Verilog wrapper
//! that sets the block's parameters from its `<block>_params.vh`, a cocotb makefile and a test
//! module that drives the RTL with random and directed stimulus and checks it live against the
//! `gyrofx` Python package (the same Rust model as the vectors). The driver, the timing and the
//! scoreboard are the Python package's `gyrofx.cocotb`; the tests' timing constants are written
//! here from each block's pipeline.
//!
//! Run from the package: `make cocotb-<block>` (`SIM=icarus`, the default), `pytest cocotb`
//! (cocotb's Python runner, one pytest test per cocotb test, RTL of your own with `--rtl`), or
//! `gyrofx verify --sim cocotb`. cocotb 2.x runs Verilator only from 5.036 on; Debian 12's
//! 5.006 is refused by cocotb's own makefile, so Icarus is the simulator CI runs.

use std::fmt::Write as _;

use serde::Serialize;

use crate::block::Block;
use crate::hdl::RTL_SOURCES;
use crate::testbench::verilog::instance;
use crate::text::Provenance;

/// The pytest options (simulator, seed, your own RTL and its timing).
const CONFTEST: &str = include_str!("../templates/cocotb/conftest.py");
/// One pytest test per cocotb test, on cocotb's Python runner.
const TEST_PACKAGE: &str = include_str!("../templates/cocotb/test_package.py");

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
    let mut files = vec![
        (format!("{FOLDER}/conftest.py"), python(CONFTEST)),
        (format!("{FOLDER}/test_package.py"), python(TEST_PACKAGE)),
        (
            format!("{FOLDER}/tests.json"),
            tests_json(&tested, provenance),
        ),
    ];
    for block in &tested {
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

/// The line of a cocotb test that holds the DUT's timing (`gyrofx.cocotb.Timing`).
const TIMING_LINE: &str = "TIMING = tb.Timing(";

/// `test` with its `TIMING` line set from `block`'s pipeline, the one source of its timing.
/// Every block's test has one such line (`blocks::tests` holds them to it).
fn with_pipeline(test: &str, block: &Block) -> String {
    let mut text: String = test
        .lines()
        .map(|line| {
            if line.starts_with(TIMING_LINE) {
                timing_line(block)
            } else {
                line.to_string()
            }
        })
        .collect::<Vec<_>>()
        .join("\n");
    text.push('\n');
    text
}

/// `TIMING = tb.Timing(latency_clocks=.., min_clocks_per_sample=..)` for `block`.
fn timing_line(block: &Block) -> String {
    format!(
        "{TIMING_LINE}latency_clocks={}, min_clocks_per_sample={})",
        block.pipeline.latency_clocks, block.pipeline.min_clocks_per_sample
    )
}

/// The names of the cocotb tests in a test module: each `async def` right after a
/// `@cocotb.test()` line.
pub fn test_names(test: &str) -> Vec<&str> {
    let lines: Vec<&str> = test.lines().collect();
    lines
        .windows(2)
        .filter(|pair| pair[0].trim_start().starts_with("@cocotb.test("))
        .filter_map(|pair| {
            let rest = pair[1].trim_start().strip_prefix("async def ")?;
            rest.split('(').next()
        })
        .collect()
}

/// `tests.json`: what `test_package.py` runs, one entry per tested block.
#[derive(Serialize)]
struct Tests<'a> {
    generated_by: String,
    /// The RTL sources, relative to the package.
    sources: Vec<String>,
    blocks: Vec<TestedBlock<'a>>,
}

#[derive(Serialize)]
struct TestedBlock<'a> {
    name: &'a str,
    toplevel: String,
    wrapper: String,
    module: String,
    tests: Vec<&'a str>,
    latency_clocks: u32,
    min_clocks_per_sample: u32,
}

fn tests_json(tested: &[&Block], provenance: &Provenance) -> String {
    let tests = Tests {
        generated_by: provenance.line("").trim_start().to_string(),
        sources: RTL_SOURCES
            .iter()
            .map(|(name, _)| format!("hdl/{name}"))
            .collect(),
        blocks: tested
            .iter()
            .map(|block| TestedBlock {
                name: block.name,
                toplevel: format!("cocotb_{}", block.module),
                wrapper: format!("{FOLDER}/cocotb_{}.v", block.module),
                module: format!("test_{}", block.name),
                tests: test_names(block.cocotb_test.expect("tested blocks have a test")),
                latency_clocks: block.pipeline.latency_clocks,
                min_clocks_per_sample: block.pipeline.min_clocks_per_sample,
            })
            .collect(),
    };
    let mut text = serde_json::to_string_pretty(&tests).expect("plain data serializes");
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
        out.push(format!("{FOLDER}/sim_build/"));
        out.push(format!("{FOLDER}/.pytest_cache/"));
    }
    out
}
