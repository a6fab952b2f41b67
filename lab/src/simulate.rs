//! Running a package's testbenches in a simulator (through the package's own Makefile, one
//! `make <simulator>-<block>` per block, so the commands `gyrofx verify` runs are exactly those a
//! user runs without gyrofx).

use std::path::Path;
use std::time::Instant;

use gyrofx_job::error::{Error, Result};

use crate::toolchain::{self, Tool};

/// A supported simulator.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Simulator {
    /// Icarus Verilog (`iverilog` + `vvp`), the Verilog RTL.
    Icarus,
    /// Verilator (`--binary --timing`), the Verilog RTL.
    Verilator,
    /// GHDL (`--std=08`), the VHDL RTL and testbenches.
    Ghdl,
    /// The cocotb tests (`cocotb/`) in Icarus Verilog, checked live against the `gyrofx`
    /// Python model.
    Cocotb,
    /// The DPI-C testbenches (`dpi/`) in Verilator against gyrofx's C library (the
    /// `GYROFX_CAPI_LIB` environment variable names `libgyrofx_capi.a`).
    Dpi,
}

impl Simulator {
    /// The three HDL simulators (`--sim all`); the cocotb tests are asked for by name.
    pub const ALL: [Simulator; 3] = [Simulator::Icarus, Simulator::Verilator, Simulator::Ghdl];

    /// CLI name (also the Makefile's target prefix).
    pub fn name(self) -> &'static str {
        match self {
            Simulator::Icarus => "iverilog",
            Simulator::Verilator => "verilator",
            Simulator::Ghdl => "ghdl",
            Simulator::Cocotb => "cocotb",
            Simulator::Dpi => "dpi",
        }
    }

    /// Programs it needs on PATH.
    fn tools(self) -> &'static [Tool] {
        match self {
            Simulator::Icarus => &[Tool::Iverilog, Tool::Vvp, Tool::Make],
            Simulator::Verilator | Simulator::Dpi => &[Tool::Verilator, Tool::Make],
            Simulator::Ghdl => &[Tool::Ghdl, Tool::Make],
            Simulator::Cocotb => &[
                Tool::Iverilog,
                Tool::Vvp,
                Tool::Make,
                Tool::CocotbConfig,
                Tool::Python3,
            ],
        }
    }
}

impl std::str::FromStr for Simulator {
    type Err = Error;
    fn from_str(text: &str) -> Result<Self> {
        match text {
            "iverilog" | "icarus" => Ok(Simulator::Icarus),
            "verilator" => Ok(Simulator::Verilator),
            "ghdl" => Ok(Simulator::Ghdl),
            "cocotb" => Ok(Simulator::Cocotb),
            "dpi" => Ok(Simulator::Dpi),
            other => Err(Error::Simulation(format!(
                "simulator {other:?} is not supported: use iverilog, verilator, ghdl, cocotb or dpi"
            ))),
        }
    }
}

/// Testbench options (the Makefile's `MASK`, `MAX_REPORTED`, `MAX_MISMATCHES`, `WAVES`).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Options {
    /// Samples not compared at the start and from every reset sample on.
    pub mask: u64,
    /// Mismatches printed per testbench.
    pub max_reported: u64,
    /// Stop a testbench at this many mismatches (0: never).
    pub max_mismatches: u64,
    /// Write a VCD per testbench.
    pub waves: bool,
    /// Only these blocks (all when `None`).
    pub blocks: Option<Vec<String>>,
    /// A `gyrofx synth` folder whose gate-level netlists replace the RTL of the blocks it
    /// synthesized (only those blocks run; Icarus and Verilator only).
    pub netlist: Option<std::path::PathBuf>,
}

impl Default for Options {
    fn default() -> Self {
        Options {
            mask: 0,
            max_reported: u64::from(gyrofx_codegen::testbench::MAX_REPORTED),
            max_mismatches: 0,
            waves: false,
            blocks: None,
            netlist: None,
        }
    }
}

/// The outcome of one block's testbench.
#[derive(Clone, Debug, PartialEq)]
pub struct BlockOutcome {
    /// The block (folder) name.
    pub block: String,
    /// Exit 0 and a `PASS` line.
    pub passed: bool,
    /// Its `PASS`, `FAIL` and `MISMATCH` lines.
    pub report: Vec<String>,
    /// Everything make printed for it (stdout then stderr).
    pub log: String,
    /// Wall-clock seconds, build included.
    pub seconds: f64,
}

/// The outcome of one simulator over every block.
#[derive(Clone, Debug, PartialEq)]
pub struct Outcome {
    /// The simulator.
    pub simulator: Simulator,
    /// Per block, in the Makefile's order.
    pub blocks: Vec<BlockOutcome>,
}

impl Outcome {
    /// Whether every block passed.
    pub fn passed(&self) -> bool {
        !self.blocks.is_empty() && self.blocks.iter().all(|b| b.passed)
    }

    /// `== <block>` headers and each block's report lines.
    pub fn report(&self) -> Vec<String> {
        self.blocks
            .iter()
            .flat_map(|b| std::iter::once(format!("== {}", b.block)).chain(b.report.clone()))
            .collect()
    }
}

/// The blocks the package's Makefile runs under `simulator` (its `sim-<simulator>:` line).
fn blocks(out: &Path, simulator: Simulator) -> Result<Vec<String>> {
    let makefile = std::fs::read_to_string(out.join("Makefile")).map_err(|e| {
        Error::Simulation(format!(
            "{} is not a gyrofx package (no readable Makefile: {e}): run gyrofx generate --out {} first",
            out.display(),
            out.display()
        ))
    })?;
    let rule = format!("sim-{}:", simulator.name());
    let prefix = format!("{}-", simulator.name());
    let line = makefile
        .lines()
        .find(|l| l.starts_with(&rule))
        .ok_or_else(|| {
            Error::Simulation(format!(
                "{}/Makefile has no {rule} target: regenerate the package with this gyrofx",
                out.display()
            ))
        })?;
    Ok(line[rule.len()..]
        .split_whitespace()
        .filter_map(|t| t.strip_prefix(&prefix).map(str::to_string))
        .collect())
}

/// Runs every block of the package in `out` under `simulator`.
///
/// # Errors
/// [`Error::Simulation`] when the folder is not a package or a program is missing (a missing
/// simulator is an error, never a skipped check).
pub fn run(out: &Path, simulator: Simulator, options: &Options) -> Result<Outcome> {
    run_reporting(out, simulator, options, &mut |_| {})
}

/// The blocks [`run`] runs for `simulator`: the package's, or those of `options.blocks`.
///
/// # Errors
/// [`Error::Simulation`] when the folder is not a package or names a block it lacks.
pub fn block_names(out: &Path, simulator: Simulator, options: &Options) -> Result<Vec<String>> {
    let mut names = blocks(out, simulator)?;
    if let Some(wanted) = &options.blocks {
        if let Some(unknown) = wanted.iter().find(|w| !names.contains(w)) {
            return Err(Error::Simulation(format!(
                "--blocks {unknown}: the package has no such block; it has {}",
                names.join(", ")
            )));
        }
        names.retain(|n| wanted.contains(n));
    }
    if let Some(folder) = &options.netlist {
        let netlists = Netlists::read(folder, out, simulator)?;
        let covered: Vec<&str> = netlists.files.iter().map(|(b, _)| b.as_str()).collect();
        if let Some(uncovered) = options
            .blocks
            .iter()
            .flatten()
            .find(|w| !covered.contains(&w.as_str()))
        {
            return Err(Error::Simulation(format!(
                "--blocks {uncovered}: {} has no netlist of it; its netlists are of {}",
                folder.display(),
                covered.join(", ")
            )));
        }
        names.retain(|n| covered.contains(&n.as_str()));
    }
    Ok(names)
}

/// [`run`], calling `done` after each block.
///
/// # Errors
/// Those of [`run`].
pub fn run_reporting(
    out: &Path,
    simulator: Simulator,
    options: &Options,
    done: &mut dyn FnMut(&BlockOutcome),
) -> Result<Outcome> {
    let names = block_names(out, simulator, options)?;
    for tool in simulator.tools() {
        if !tool.on_path() {
            return Err(Error::Simulation(format!(
                "{} is not on PATH: {} needs it ({})",
                tool.program(),
                simulator.name(),
                tool.install_hint()
            )));
        }
    }
    if simulator == Simulator::Dpi {
        let library = std::env::var_os("GYROFX_CAPI_LIB").map(std::path::PathBuf::from);
        if !library.as_ref().is_some_and(|l| l.is_file()) {
            return Err(Error::Simulation(format!(
                "dpi needs GYROFX_CAPI_LIB, the path of libgyrofx_capi.a (cargo build --release -p gyrofx-capi in the gyrofx repository); it is {}",
                library.map_or("not set".to_string(), |l| format!("{} (no such file)", l.display()))
            )));
        }
    }
    let netlists = match &options.netlist {
        Some(folder) => Some(Netlists::read(folder, out, simulator)?),
        None => None,
    };
    // The simulators' temporary files (iverilog's) go into a work folder of gyrofx's own: a
    // signal that ends them mid-run leaves none in the system's temporary folder.
    let temp = gyrofx_codegen::output_folder::WorkFolder::new()
        .map_err(|e| Error::Simulation(format!("cannot create a temporary folder: {e}")))?;
    let mut blocks = Vec::with_capacity(names.len());
    for block in names {
        let start = Instant::now();
        let mut make = Tool::Make.command();
        make.env("TMPDIR", temp.path());
        if let Some(netlists) = &netlists {
            make.args(netlists.make_variables(&block, simulator));
        }
        make.arg("--no-print-directory")
            .arg("-C")
            .arg(out)
            .arg(format!("{}-{block}", simulator.name()))
            .arg(format!("MASK={}", options.mask))
            .arg(format!("MAX_REPORTED={}", options.max_reported))
            .arg(format!("MAX_MISMATCHES={}", options.max_mismatches))
            .arg(format!("WAVES={}", u8::from(options.waves)));
        let finished = toolchain::run_to_end(&mut make)
            .map_err(|e| Error::Simulation(format!("cannot run make: {e}")))?;
        let seconds = start.elapsed().as_secs_f64();
        let log = finished.printed();
        let report: Vec<String> = log
            .lines()
            .filter(|l| l.starts_with("PASS") || l.starts_with("FAIL") || l.starts_with("MISMATCH"))
            .map(str::to_string)
            .collect();
        let passed = finished.success && report.iter().any(|l| l.starts_with("PASS "));
        let outcome = BlockOutcome {
            block,
            passed,
            report,
            log,
            seconds,
        };
        done(&outcome);
        blocks.push(outcome);
    }
    Ok(Outcome { simulator, blocks })
}

/// The gate-level netlists of a `gyrofx synth` folder, by the package block they replace.
#[derive(Clone, Debug)]
struct Netlists {
    /// (block, absolute paths of its netlist files: the shell, then the netlist).
    files: Vec<(String, Vec<std::path::PathBuf>)>,
}

/// Verilator's options for a netlist. `-fno-const-bit-op-tree` keeps 5.006 from miscompiling
/// yosys netlists: its bit-op-tree optimization gives wrong results on gate-level XOR/AND trees
/// (verilator issue #4059; the netlist passes with it off, as it does with `-O0` and in Icarus).
/// The C++ is compiled at `-O0`: for a gate-level netlist the compile dominates (the loop's
/// 80 000 cells: 6 min at Verilator's default, under 2 min at `-O0`; its 40 000 samples then run
/// in seconds).
pub const VERILATOR_NETLIST_OPTIONS: &str = "-fno-const-bit-op-tree -MAKEFLAGS OPT_FAST=-O0 -MAKEFLAGS OPT_SLOW=-O0 -MAKEFLAGS OPT_GLOBAL=-O0";

/// A ROM image's words: its lines other than comments (whose provenance names the command).
fn rom_words(path: &Path) -> Result<Vec<String>> {
    let text = std::fs::read_to_string(path).map_err(|e| Error::io(path, e))?;
    Ok(text
        .lines()
        .map(str::trim)
        .filter(|l| !l.is_empty() && !l.starts_with("//"))
        .map(str::to_string)
        .collect())
}

/// Refuses a netlist whose ROM images (baked into its gates) differ from the package block's.
fn same_roms(design: &Path, block_folder: &Path, block: &str) -> Result<()> {
    let entries = std::fs::read_dir(design).map_err(|e| Error::io(design, e))?;
    let mut names: Vec<std::ffi::OsString> = entries
        .filter_map(|e| e.ok().map(|e| e.file_name()))
        .filter(|n| n.to_string_lossy().ends_with(".mem"))
        .collect();
    names.sort();
    for name in names {
        let packaged = block_folder.join(&name);
        if !packaged.is_file() {
            continue;
        }
        if rom_words(&design.join(&name))? != rom_words(&packaged)? {
            return Err(Error::Simulation(format!(
                "the ROM image {} differs between the netlist ({}) and the package's {block} block ({}): synthesize and generate from the same formats and coefficients",
                name.to_string_lossy(),
                design.display(),
                block_folder.display()
            )));
        }
    }
    Ok(())
}

fn read_manifest(folder: &Path, what: &str) -> Result<serde_json::Value> {
    let path = folder.join(gyrofx_codegen::output_folder::MANIFEST);
    let text = std::fs::read_to_string(&path).map_err(|e| {
        Error::Simulation(format!(
            "{} is not {what} (no readable {}: {e})",
            folder.display(),
            path.display()
        ))
    })?;
    serde_json::from_str(&text)
        .map_err(|e| Error::Simulation(format!("{} is not JSON: {e}", path.display())))
}

impl Netlists {
    /// The netlists of the synthesis folder `folder`, checked against the package `out`: the
    /// same ROM contents (the config may differ elsewhere, e.g. in the stimulus; the netlist's
    /// shell refuses other parameter values when the simulation starts) and a simulator that
    /// runs the Verilog testbenches.
    fn read(folder: &Path, out: &Path, simulator: Simulator) -> Result<Netlists> {
        if !matches!(simulator, Simulator::Icarus | Simulator::Verilator) {
            return Err(Error::Simulation(format!(
                "--netlist runs the Verilog testbenches on the netlists: --sim {} is not allowed; use iverilog and/or verilator",
                simulator.name()
            )));
        }
        let synth = read_manifest(folder, "a `gyrofx synth` folder")?;
        let netlists = synth["netlists"].as_array().ok_or_else(|| {
            Error::Simulation(format!(
                "{} holds no netlists (it is not the folder of this gyrofx's `synth`): run gyrofx synth --out SYNTH_DIR with the package's config and pass --netlist SYNTH_DIR",
                folder.display()
            ))
        })?;
        let folder = std::path::absolute(folder).map_err(|e| Error::io(folder, e))?;
        let mut files = Vec::new();
        for netlist in netlists {
            let block = netlist["block"].as_str().unwrap_or_default().to_string();
            let paths: Vec<std::path::PathBuf> = netlist["files"]
                .as_array()
                .into_iter()
                .flatten()
                .filter_map(|f| f.as_str())
                .map(|f| folder.join(f))
                .collect();
            if let Some(missing) = paths.iter().find(|p| !p.is_file()) {
                return Err(Error::Simulation(format!(
                    "{} lists the netlist {}, which is missing",
                    folder
                        .join(gyrofx_codegen::output_folder::MANIFEST)
                        .display(),
                    missing.display()
                )));
            }
            let design = paths
                .first()
                .and_then(|shell| shell.parent())
                .and_then(Path::parent)
                .unwrap_or(&folder);
            same_roms(design, &out.join(&block), &block)?;
            files.push((block, paths));
        }
        Ok(Netlists { files })
    }

    /// The Makefile variables that build `block`'s testbench on its netlist.
    fn make_variables(&self, block: &str, simulator: Simulator) -> Vec<String> {
        let Some((_, paths)) = self.files.iter().find(|(b, _)| b == block) else {
            return Vec::new();
        };
        let rtl: Vec<String> = paths.iter().map(|p| p.display().to_string()).collect();
        let mut variables = vec![format!("RTL={}", rtl.join(" "))];
        if simulator == Simulator::Verilator {
            let verilator = std::env::var("VERILATOR").unwrap_or_else(|_| "verilator".into());
            variables.push(format!("VERILATOR={verilator} {VERILATOR_NETLIST_OPTIONS}"));
        }
        variables
    }
}
