//! The package's DPI-C testbenches (`dpi/`): per block with a golden model, a SystemVerilog
//! testbench that imports the model's step from gyrofx's C ABI (`capi/`, `libgyrofx_capi`)
//! and scoreboards the DUT against it in Verilator, with random stimulus over the whole input
//! range and a small-signal half.
//!
//! Outputs qualified by a valid flag are compared as a stream (a queue of expected values),
//! whatever the latency; combinational outputs before the clock edge that takes the sample,
//! registered outputs without a valid flag after the block's pipeline. Each testbench prints
//! `PASS n=<N>` or `FAIL mismatches=<M> n=<N>` and exits non-zero on a mismatch or a refused
//! model call. Plusargs: `+samples=<n>`, `+seed=<n>`, `+flip=<k>` (flip bit 0 of the k-th
//! expected value: the testbench must then fail).

use crate::block::{Block, Signal};
use crate::testbench::verilog::instance;
use crate::text::{fill, Provenance};

/// Folder of the DPI-C testbenches in a package.
pub const FOLDER: &str = "dpi";

/// The blocks of `blocks` that have a DPI-C testbench (those whose IR carries its
/// [`crate::block::DpiParts`]: the blocks with a golden model), in the package's order.
pub fn tested(blocks: &[Block]) -> Vec<&Block> {
    blocks.iter().filter(|b| b.dpi.is_some()).collect()
}

/// Every file of the package's `dpi/` folder: `(path, text)`: the imports' package, then a
/// testbench per tested block (none at all when no block is tested).
pub fn files(blocks: &[Block], provenance: &Provenance) -> Vec<(String, String)> {
    let tested = tested(blocks);
    if tested.is_empty() {
        return Vec::new();
    }
    let mut files = vec![(
        format!("{FOLDER}/{PACKAGE}.sv"),
        package(&tested, provenance),
    )];
    files.extend(tested.into_iter().map(|block| {
        (
            format!("{FOLDER}/tb_dpi_{}.sv", block.module),
            testbench(block, provenance),
        )
    }));
    files
}

/// The SystemVerilog package every DPI-C testbench imports.
pub const PACKAGE: &str = "gyrofx_dpi_pkg";

/// `gyrofx_dpi_pkg`: the C ABI's common imports and each tested block's own, once.
fn package(tested: &[&Block], provenance: &Provenance) -> String {
    // Two blocks may import one function: each import statement (to its `;`, lines and all)
    // once.
    let mut imports: Vec<&str> = Vec::new();
    for statement in tested
        .iter()
        .filter_map(|b| b.dpi.map(|parts| parts.imports))
        .flat_map(|text| text.split_inclusive(';'))
        .map(str::trim)
        .filter(|s| !s.is_empty())
    {
        if !imports.contains(&statement) {
            imports.push(statement);
        }
    }
    fill(
        PACKAGE_TEMPLATE,
        &[
            ("provenance", &provenance.line("//")),
            ("imports", &imports.join("\n")),
        ],
    )
}

fn declaration(signal: &Signal, kind: &str) -> String {
    let signed = if signal.format.signed { " signed" } else { "" };
    let range = if signal.format.width > 1 {
        format!(" [{}:0]", signal.format.width - 1)
    } else {
        String::new()
    };
    format!("{kind}{signed}{range} {};", signal.name)
}

/// The DPI-C testbench of `block`: the shared frame around the block's own parts.
///
/// # Panics
/// When the block has no DPI-C parts (see [`tested`]).
pub fn testbench(block: &Block, provenance: &Provenance) -> String {
    let tb = format!("tb_dpi_{}", block.module);
    let parts = block
        .dpi
        .expect("dpi::tested keeps the blocks with DPI-C parts");
    let mut declarations: Vec<String> = block
        .inputs
        .iter()
        .map(|s| declaration(s, "logic"))
        .collect();
    declarations.extend(block.outputs.iter().map(|o| declaration(&o.signal, "wire")));
    let interval_width = block
        .inputs
        .iter()
        .chain(block.outputs.iter().map(|o| &o.signal))
        .find(|s| s.name == "interval_a")
        .map_or(1, |s| s.format.width);
    let monitor = match parts.stream {
        Some(stream) => fill(
            STREAM_MONITOR,
            &[
                ("valid", stream.valid),
                ("value", stream.value),
                (
                    "second",
                    &match stream.second {
                        Some(name) => format!(
                            "compare(longint'({name}), expected_second.pop_front(), \"{name}\");"
                        ),
                        None => "void'(expected_second.pop_front());".to_string(),
                    },
                ),
            ],
        ),
        None => String::new(),
    };
    fill(
        TESTBENCH,
        &[
            ("provenance", &provenance.line("//")),
            ("tb", &tb),
            ("module", block.module),
            ("title", block.title),
            ("params_file", &block.file("params.vh")),
            ("interval_width", &interval_width.to_string()),
            ("declarations", &declarations.join("\n")),
            ("instance", &instance(block)),
            ("samples", &parts.samples.to_string()),
            ("monitor", &monitor),
            ("handles", parts.handles),
            ("step", &(parts.step)(block)),
        ],
    )
}

/// The DPI-C testbench's frame and, for a block whose outputs come as a valid-qualified
/// stream, its monitor (`codegen/templates/dpi/`), filled by [`fill`].
const TESTBENCH: &str = include_str!("../templates/dpi/testbench.sv");
const STREAM_MONITOR: &str = include_str!("../templates/dpi/stream_monitor.sv");
const PACKAGE_TEMPLATE: &str = include_str!("../templates/dpi/package.sv");
