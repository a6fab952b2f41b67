//! The package's FuseSoC core (`gyrofx_package.core`): the reference RTL in both languages
//! and, per block, a simulation target that runs its generated testbench on its vectors:
//! `sim_<block>` (Verilog; Icarus by default, `--tool verilator` too) and `sim_<block>_vhdl`
//! (GHDL). The testbenches read their vector files and ROM images from the simulator's work
//! folder, where FuseSoC copies them.

use std::fmt::Write as _;

use crate::block::Block;
use crate::hdl::{RTL_SOURCES, VHDL_SOURCES};
use crate::text::{fill, Provenance};

/// The core's file name in a package.
pub const CORE_FILE: &str = "gyrofx_package.core";

/// The core's VLNV name, without the version.
pub const CORE_NAME: &str = "gyrofx:package:vectors";

/// What FuseSoC writes when it runs in the package folder.
pub const BUILD_OUTPUT: &str = "build/";

/// The core of a package of `blocks`.
pub fn core(blocks: &[Block], provenance: &Provenance) -> String {
    let listed = |names: Vec<&str>| -> String {
        names
            .iter()
            .map(|n| format!("      - hdl/{n}\n"))
            .collect::<String>()
            .trim_end()
            .to_string()
    };
    let mut filesets = String::new();
    let mut targets = String::new();
    for block in blocks {
        let _ = write!(filesets, "{}", fileset(block));
        let _ = write!(targets, "{}", targets_of(block));
    }
    fill(
        TEMPLATE,
        &[
            ("provenance", &provenance.line("#")),
            ("name", CORE_NAME),
            ("version", &provenance.version),
            (
                "blocks",
                &blocks.iter().map(|b| b.name).collect::<Vec<_>>().join(", "),
            ),
            (
                "verilog",
                &listed(RTL_SOURCES.iter().map(|(n, _)| *n).collect()),
            ),
            (
                "vhdl",
                &listed(VHDL_SOURCES.iter().map(|(n, _)| *n).collect()),
            ),
            ("block_filesets", filesets.trim_end()),
            ("block_targets", targets.trim_end()),
        ],
    )
}

/// A block's filesets: its Verilog testbench with its parameter include, its VHDL testbench,
/// and the files both read, copied into the work folder.
fn fileset(block: &Block) -> String {
    let n = block.name;
    let mut data = vec![block.file("stimulus.hex"), block.file("expected.hex")];
    data.extend(block.roms.iter().map(|(file, _)| file.clone()));
    let mut text = format!(
        "  tb_{n}:\n    files:\n      - {n}/{params}:\n          file_type: verilogSource\n          is_include_file: true\n      - {n}/{tb}:\n          file_type: verilogSource\n",
        params = block.file("params.vh"),
        tb = block.file("tb"),
    );
    for file in &data {
        let _ = writeln!(
            text,
            "      - {n}/{file}:\n          file_type: user\n          copyto: {file}"
        );
    }
    let _ = writeln!(
        text,
        "  tb_{n}_vhdl:\n    files:\n      - {n}/{tb}:\n          file_type: vhdlSource-2008",
        tb = block.file("tb.vhd")
    );
    text
}

/// A block's two simulation targets.
fn targets_of(block: &Block) -> String {
    let n = block.name;
    let top = format!("tb_{}", block.module);
    format!(
        "  sim_{n}:
    description: {n}'s Verilog testbench (Icarus by default; --tool verilator)
    default_tool: icarus
    filesets: [rtl, tb_{n}]
    toplevel: {top}
    tools:
      icarus:
        iverilog_options: [-g2005]
      verilator:
        mode: binary
        verilator_options: [--timing, -Wno-fatal]
  sim_{n}_vhdl:
    description: {n}'s VHDL testbench in GHDL
    default_tool: ghdl
    filesets: [rtl_vhdl, tb_{n}, tb_{n}_vhdl]
    toplevel: {top}
    tools:
      ghdl:
        analyze_options: [--std=08]
        run_options: [--ieee-asserts=disable-at-0]
"
    )
}

/// The core's frame (`codegen/templates/fusesoc/`).
const TEMPLATE: &str = include_str!("../templates/fusesoc/package.core");
