//! Text writers of the verification package: coefficient ROMs, each block's parameter include,
//! vector files and testbench, the Makefile, the README and the report.
//!
//! Every file starts with a line saying it is generated and how to regenerate it.

use std::fmt::Write as _;

use crate::block::Block;
use crate::hdl::{RTL_SOURCES, VHDL_SOURCES};
use crate::vector_rows::RowLayout;
use crate::vectors::Run;

use crate::text::{fill, Provenance};

/// The block's parameter include: the DUT's parameters as `P_<NAME>` localparams, the vector
/// count and the vector file names.
pub fn params_vh(block: &Block, provenance: &Provenance) -> String {
    let mut out = provenance.line("//");
    let _ = writeln!(
        out,
        "\n// {} parameters of {} (include inside a module).",
        block.name, block.module
    );
    for p in &block.params {
        let kind = if p.kind.is_empty() {
            String::new()
        } else {
            format!("{} ", p.kind)
        };
        let _ = writeln!(
            out,
            "localparam {kind}P_{} = {}; // {}",
            p.name, p.value, p.comment
        );
    }
    let _ = writeln!(out, "localparam integer VECTOR_COUNT = {};", block.len());
    let _ = writeln!(
        out,
        "localparam STIMULUS_FILE = \"{}\";",
        block.file("stimulus.hex")
    );
    let _ = writeln!(
        out,
        "localparam EXPECTED_FILE = \"{}\";",
        block.file("expected.hex")
    );
    out
}

/// The block's stimulus and expected vector files (hex, one line per clock-enable), from its
/// kept rows.
///
/// # Panics
/// When the block's rows were streamed.
pub fn vector_hex(block: &Block, provenance: &Provenance) -> (String, String) {
    let layout = RowLayout::of(block);
    let n = block.len();
    let mut stimulus = layout.stimulus_header(provenance);
    let mut expected = layout.expected_header(provenance);
    stimulus.reserve(n * (2 + 8 * block.inputs.len()));
    expected.reserve(n * (2 + 8 * block.outputs.len()));
    for k in 0..n {
        let row = block.row(k);
        layout.stimulus_line(row, &mut stimulus);
        layout.expected_line(row, &mut expected);
    }
    (stimulus, expected)
}

/// The block's vectors as CSV ([`RowLayout::csv_header`]), from its kept rows.
///
/// # Panics
/// When the block's rows were streamed.
pub fn vector_csv(block: &Block, provenance: &Provenance) -> String {
    let layout = RowLayout::of(block);
    let n = block.len();
    let mut csv = layout.csv_header(provenance);
    csv.reserve(n * 16 * block.stride());
    let mut buffers = (itoa::Buffer::new(), ryu::Buffer::new());
    for k in 0..n {
        layout.csv_line(k, block.row(k), block.extra_row(k), &mut csv, &mut buffers);
    }
    csv
}

/// The Makefile: `sim-iverilog` / `sim-verilator` / `sim-ghdl` run every block's testbench, and
/// `<simulator>-<block>` one; `MASK`, `MAX_REPORTED`, `MAX_MISMATCHES` and `WAVES` set the
/// testbench options in every simulator (plusargs in Verilog, generics in VHDL). Each recipe runs
/// in the block's folder.
pub fn makefile(blocks: &[Block], provenance: &Provenance) -> String {
    let sources = |list: &[&(&str, &str)]| -> String {
        list.iter()
            .map(|(n, _)| format!("../hdl/{n}"))
            .collect::<Vec<_>>()
            .join(" ")
    };
    let names: Vec<&str> = blocks.iter().map(|b| b.name).collect();
    // " <prefix>-<block>" for each block of `names`, as a target list.
    let targets = |prefixes: &[&str], names: &[&str]| -> String {
        names
            .iter()
            .flat_map(|n| prefixes.iter().map(move |p| format!(" {p}-{n}")))
            .collect()
    };
    let mut out = fill(
        MAKEFILE_HEAD,
        &[
            ("header", &provenance.line("#")),
            ("list", &names.join(", ")),
            ("rtl", &sources(&RTL_SOURCES.iter().collect::<Vec<_>>())),
            ("vhdl", &sources(&VHDL_SOURCES.iter().collect::<Vec<_>>())),
            (
                "phony",
                &targets(&["iverilog", "verilator", "ghdl"], &names),
            ),
            ("iverilog", &targets(&["iverilog"], &names)),
            ("verilator", &targets(&["verilator"], &names)),
            ("ghdl", &targets(&["ghdl"], &names)),
        ],
    );
    for b in blocks {
        out.push_str(&fill(
            MAKEFILE_BLOCK,
            &[
                ("name", b.name),
                ("tb", &format!("tb_{}", b.module)),
                ("vhdl", &sources(&crate::hdl::vhdl_sources_of(b.module))),
            ],
        ));
    }
    let cocotb = crate::cocotb::tested(blocks);
    if !cocotb.is_empty() {
        let names: Vec<&str> = cocotb.iter().map(|b| b.name).collect();
        out.push_str(&fill(
            MAKEFILE_COCOTB_HEAD,
            &[
                ("folder", crate::cocotb::FOLDER),
                ("list", &names.join(", ")),
                ("targets", &targets(&["cocotb"], &names)),
            ],
        ));
        for name in names {
            out.push_str(&fill(
                MAKEFILE_COCOTB_BLOCK,
                &[("name", name), ("folder", crate::cocotb::FOLDER)],
            ));
        }
    }
    let dpi = crate::dpi::tested(blocks);
    if !dpi.is_empty() {
        let names: Vec<&str> = dpi.iter().map(|b| b.name).collect();
        out.push_str(&fill(
            MAKEFILE_DPI_HEAD,
            &[
                ("folder", crate::dpi::FOLDER),
                ("list", &names.join(", ")),
                ("targets", &targets(&["dpi"], &names)),
            ],
        ));
        for block in dpi {
            out.push_str(&fill(
                MAKEFILE_DPI_BLOCK,
                &[
                    ("name", block.name),
                    ("tb", &format!("tb_dpi_{}", block.module)),
                    ("folder", crate::dpi::FOLDER),
                ],
            ));
        }
    }
    let _ = write!(
        out,
        "\nclean:\n\trm -rf {}\n",
        build_outputs(blocks).join(" ")
    );
    out
}

/// The Makefile's parts (`codegen/templates/makefile/`), filled by [`fill`]: the variables and
/// the `sim-<simulator>` targets, then per block its three simulator recipes, then the cocotb
/// and DPI-C targets where a block has them.
const MAKEFILE_HEAD: &str = include_str!("../templates/makefile/head.mk");
const MAKEFILE_BLOCK: &str = include_str!("../templates/makefile/block.mk");
const MAKEFILE_COCOTB_HEAD: &str = include_str!("../templates/makefile/cocotb_head.mk");
const MAKEFILE_COCOTB_BLOCK: &str = include_str!("../templates/makefile/cocotb_block.mk");
const MAKEFILE_DPI_HEAD: &str = include_str!("../templates/makefile/dpi_head.mk");
const MAKEFILE_DPI_BLOCK: &str = include_str!("../templates/makefile/dpi_block.mk");

/// What the package's Makefile writes into it (the simulators' work files, `make clean`
/// removes them), as the marker lists them ([`crate::output_folder::Marker`]): a
/// regenerated package may replace a folder holding these.
pub fn build_outputs(blocks: &[Block]) -> Vec<String> {
    let mut outputs: Vec<String> = blocks
        .iter()
        .flat_map(|b| {
            let n = b.name;
            let tb = format!("tb_{}", b.module);
            // GHDL's LLVM and GCC back ends link the testbench into an executable beside it
            // (the mcode back end keeps everything in memory).
            [
                format!("{n}/*.vvp"),
                format!("{n}/obj_verilator/"),
                format!("{n}/verilator_build.log"),
                format!("{n}/ghdl_work/"),
                format!("{n}/*.vcd"),
                format!("{n}/{tb}"),
                format!("{n}/e~{tb}.o"),
                format!("{n}/e~{tb}.lst"),
            ]
        })
        .collect();
    outputs.extend(crate::cocotb::build_outputs(blocks));
    outputs.push(crate::fusesoc::BUILD_OUTPUT.to_string());
    outputs.extend(crate::dpi::tested(blocks).iter().flat_map(|b| {
        [
            format!("{}/obj_dpi/", b.name),
            format!("{}/dpi_build.log", b.name),
        ]
    }));
    outputs
}

/// The package's README.
pub fn package_readme(run: &Run, provenance: &Provenance) -> String {
    // Every package has the chain's blocks, which report these.
    let stats = |name: &str| {
        run.stats(name)
            .unwrap_or_else(|| panic!("no block reported the statistics `{name}`"))
    };
    let mut out = format!(
        "<!-- {line} -->
# gyrofx verification package

Self-contained: the reference RTL, the vectors, the coefficient ROMs and a self-checking
testbench per block. Run it without gyrofx:

    make sim-iverilog      # Icarus Verilog, every block
    make sim-verilator     # Verilator (--binary --timing), every block
    make sim-ghdl          # GHDL (--std=08), the VHDL RTL and testbenches, every block
    make iverilog-top      # one block

Each testbench prints `PASS n=<N>` or the first mismatches and `FAIL ...`, and exits non-zero on
any mismatch, timeout or unreadable vector file. Options, the same in every simulator:
`MASK=<n>` (latency mask: the first n samples of the run and from every reset sample on are
driven but not compared), `MAX_REPORTED=<n>` (mismatches printed, default 10),
`MAX_MISMATCHES=<n>` (stop at the n-th), `WAVES=1` (a VCD per testbench), e.g.
`make WAVES=1 MASK=4 ghdl-kf`. `gyrofx verify --junit <file>` writes a JUnit XML summary.

| folder | DUT | vectors |
|--------|-----|---------|
",
        line = provenance.line("").trim_start(),
    );
    for b in &run.blocks {
        let _ = writeln!(
            out,
            "| `{}/` | `{}` ({}) | {} |",
            b.name,
            b.module,
            b.title,
            b.len()
        );
    }
    let _ = write!(
        out,
        "
In each folder: `<block>_params.vh` (the DUT's parameters, the vector count and file names),
`<block>_stimulus.hex` (`rst` and the inputs per line), `<block>_expected.hex` (the outputs per
line), `<block>_vectors.csv` (the same with integer codes and real values in °/s) and the
testbenches `tb_<module>.v` (Verilog) and `tb_<module>.vhd` (VHDL-2008); the ROM images the DUT
reads. `hdl/` holds the RTL in both languages. Line 2 of each hex file names every
field and its format. `report.md` has the Allan table; `manifest.json` the config, formats,
SHA-256 of every file, overflow counts and fixed-vs-float error statistics.

`cocotb/` holds a cocotb test per block that has a Python model (`make sim-cocotb`, or
`make cocotb-kf`; cocotb 2.x and the gyrofx Python package, `pip install <gyrofx>/python`, for
the python3 on PATH; Icarus by default (`SIM=icarus`), `SIM` picks another of cocotb's simulators,
Verilator from 5.036 on). Each drives the RTL with random and directed stimulus (seed
`COCOTB_RANDOM_SEED`, default 1) and checks it live against the model of this package's
manifest: outputs with a valid flag as a stream whatever the latency, so your own RTL with
another pipeline depth passes as long as its valid-qualified stream matches; the reference
timing for combinational ports and registered ports without a valid flag. The same tests run on
cocotb's Python runner with `pytest cocotb` (one test per cocotb test: `-k kf`,
`--junitxml=FILE`), and on RTL of your own: `pytest cocotb -k kf --rtl <your .v files>` (same
module names and ports), `--toplevel NAME` for your own top, `--parameter NAME=VALUE`,
`--latency-clocks N` when your pipeline differs (`pytest cocotb --help`). The driver and
scoreboard are the Python package's `gyrofx.cocotb`.

`dpi/` holds a SystemVerilog testbench per block of those that imports the model's `step`
from gyrofx's C library through DPI-C and scoreboards the DUT in Verilator the same way:
`make sim-dpi GYROFX_CAPI_LIB=<gyrofx>/target/release/libgyrofx_capi.a` (built by
`cargo build --release -p gyrofx-capi`), or `make dpi-kf ...`; `DPI_PLUSARGS` takes
`+samples=<n> +seed=<n> +flip=<k>` (flip bit 0 of the k-th expected value: it must then fail).

Fixed vs float (same quantized coefficients): KF max {kf:.3} LSB (bound {kfb:.3}), chain max
{ch:.3} LSB (bound {chb:.3}), bias estimates max {bi:.3} LSB (bound {bib:.3}), mean filter max
{mf:.3} LSB (bound {mfb:.3}).
",
        kf = stats("kf").max_lsb,
        kfb = stats("kf").bound_lsb,
        ch = stats("chain").max_lsb,
        chb = stats("chain").bound_lsb,
        bi = stats("bias").max_lsb,
        bib = stats("bias").bound_lsb,
        mf = stats("mean_filter").max_lsb,
        mfb = stats("mean_filter").bound_lsb,
    );
    out
}

/// The report: bias error and Allan deviation of the raw, calibrated and filtered outputs.
pub fn report_md(run: &Run, provenance: &Provenance) -> String {
    let r = &run.report;
    let mut out = format!(
        "<!-- {} -->
# gyrofx report

{} samples, of which the {} from the first bias estimate to the reset near the end are
analysed (before the first window ends the output is not yet calibrated). Error = signal −
true rate. \"Raw\" gyros are the same gyros, with the same noise, run without mode reversal;
the calibrated output is the mean of the valid calibrated outputs (held over blanked samples);
the filtered output is the KF's (bw_sel as scheduled).

| signal | bias error (°/s) |",
        provenance.line("").trim_start(),
        run.samples,
        run.report.samples
    );
    for tau in &r.tau_s {
        let _ = write!(out, " ADEV τ={tau} s (°/s) |");
    }
    out.push_str("\n|---|---:|");
    for _ in &r.tau_s {
        out.push_str("---:|");
    }
    out.push('\n');
    for line in &r.lines {
        let _ = write!(out, "| {} | {:.3e} |", line.signal, line.bias_error_dps);
        for a in &line.adev_dps {
            match a {
                Some(v) => {
                    let _ = write!(out, " {v:.3e} |");
                }
                None => out.push_str(" – |"),
            }
        }
        out.push('\n');
    }
    out
}
