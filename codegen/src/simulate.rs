//! Running a package's testbench in a simulator (through the package's own Makefile, so the
//! commands `gyrofx verify` runs are exactly those a user runs without gyrofx).

use std::path::Path;
use std::process::Command;

use crate::error::{Error, Result};

/// A supported simulator.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Simulator {
    /// Icarus Verilog (`iverilog` + `vvp`).
    Icarus,
    /// Verilator (`--binary --timing`).
    Verilator,
}

impl Simulator {
    /// CLI name.
    pub fn name(self) -> &'static str {
        match self {
            Simulator::Icarus => "iverilog",
            Simulator::Verilator => "verilator",
        }
    }

    /// Programs it needs on PATH.
    fn programs(self) -> &'static [&'static str] {
        match self {
            Simulator::Icarus => &["iverilog", "vvp", "make"],
            Simulator::Verilator => &["verilator", "make"],
        }
    }

    /// Makefile target.
    fn target(self) -> &'static str {
        match self {
            Simulator::Icarus => "sim-iverilog",
            Simulator::Verilator => "sim-verilator",
        }
    }
}

impl std::str::FromStr for Simulator {
    type Err = Error;
    fn from_str(text: &str) -> Result<Self> {
        match text {
            "iverilog" | "icarus" => Ok(Simulator::Icarus),
            "verilator" => Ok(Simulator::Verilator),
            other => Err(Error::Simulation(format!(
                "simulator {other:?} is not supported: use iverilog or verilator"
            ))),
        }
    }
}

/// The outcome of one simulation.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Outcome {
    /// Whether every block's testbench passed (exit 0 and a `PASS` line for each).
    pub passed: bool,
    /// The testbenches' report: `== <block>` headers and their `PASS`, `FAIL` and `MISMATCH`
    /// lines.
    pub report: Vec<String>,
    /// Everything it printed (stdout then stderr).
    pub log: String,
}

fn on_path(program: &str) -> bool {
    std::env::var_os("PATH")
        .map(|paths| std::env::split_paths(&paths).any(|dir| dir.join(program).is_file()))
        .unwrap_or(false)
}

/// Runs the package in `out` under `simulator`.
///
/// # Errors
/// [`Error::Simulation`] when the folder is not a package or a program is missing (a missing
/// simulator is an error, never a skipped check).
pub fn run(out: &Path, simulator: Simulator) -> Result<Outcome> {
    if !out.join("Makefile").is_file() || !out.join("kf").is_dir() {
        return Err(Error::Simulation(format!(
            "{} is not a gyrofx package (no Makefile or kf/): run gyrofx generate --out {} first",
            out.display(),
            out.display()
        )));
    }
    for program in simulator.programs() {
        if !on_path(program) {
            return Err(Error::Simulation(format!(
                "{program} is not on PATH: {} needs it (scripts/test.sh installs it with apt-get)",
                simulator.name()
            )));
        }
    }
    // -k: a failing block does not hide the others.
    let output = Command::new("make")
        .arg("--no-print-directory")
        .arg("-k")
        .arg("-C")
        .arg(out)
        .arg(simulator.target())
        .output()
        .map_err(|e| Error::Simulation(format!("cannot run make: {e}")))?;
    let mut log = String::from_utf8_lossy(&output.stdout).into_owned();
    log.push_str(&String::from_utf8_lossy(&output.stderr));
    let report: Vec<String> = log
        .lines()
        .filter(|l| {
            l.starts_with("== ")
                || l.starts_with("PASS")
                || l.starts_with("FAIL")
                || l.starts_with("MISMATCH")
        })
        .map(str::to_string)
        .collect();
    let blocks = report.iter().filter(|l| l.starts_with("== ")).count();
    let passes = report.iter().filter(|l| l.starts_with("PASS ")).count();
    let passed = output.status.success() && blocks > 0 && passes == blocks;
    Ok(Outcome {
        passed,
        report,
        log,
    })
}
