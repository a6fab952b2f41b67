//! `gyrofx verify`: a generated package's testbenches in one or more simulators, with a
//! non-zero exit on any failure.

use std::path::PathBuf;
use std::process::ExitCode;

use anyhow::{Context, Result};

use gyrofx_lab::junit;
use gyrofx_lab::simulate::{self, Simulator};

/// Run a generated package's testbench in a simulator; non-zero exit on failure.
#[derive(clap::Args)]
pub struct Args {
    /// The package folder.
    #[arg(long)]
    out: PathBuf,
    /// Simulators, comma-separated: iverilog, verilator, ghdl (the VHDL RTL), cocotb (the
    /// cocotb tests in Icarus against the gyrofx Python model), dpi (the DPI-C testbenches in
    /// Verilator against libgyrofx_capi: set GYROFX_CAPI_LIB), or all (the first three).
    #[arg(long, default_value = "iverilog")]
    sim: String,
    /// Latency mask: samples not compared at the start and from every reset sample on.
    #[arg(long, default_value_t = 0)]
    mask: u64,
    /// Mismatches printed per testbench.
    #[arg(long, default_value_t = 10)]
    max_reported: u64,
    /// Stop a testbench at this many mismatches (0: never).
    #[arg(long, default_value_t = 0)]
    max_mismatches: u64,
    /// Write a VCD per testbench (tb_<module>.vcd in each block folder).
    #[arg(long)]
    waves: bool,
    /// Only these blocks, comma-separated (default: every block of the package).
    #[arg(long, value_delimiter = ',')]
    blocks: Option<Vec<String>>,
    /// No progress bar (it shows only on a terminal).
    #[arg(long)]
    quiet: bool,
    /// Write a JUnit XML summary here (one testsuite per simulator, one testcase per block).
    #[arg(long)]
    junit: Option<PathBuf>,
    /// A `gyrofx synth` folder (same config): run the testbenches of the blocks it synthesized
    /// (top, gyro_loop) on its gate-level netlists instead of the RTL, in iverilog and/or
    /// verilator.
    #[arg(long, value_name = "SYNTH_DIR")]
    netlist: Option<PathBuf>,
}

/// Checks the package against its manifest, then runs every block's testbench in each
/// simulator, prints the mismatches and a verdict per simulator, and writes the JUnit summary
/// if asked.
pub fn run(args: Args) -> Result<ExitCode> {
    let Args {
        out,
        sim,
        mask,
        max_reported,
        max_mismatches,
        waves,
        blocks,
        quiet,
        junit: junit_path,
        netlist,
    } = args;
    let options = simulate::Options {
        mask,
        max_reported,
        max_mismatches,
        waves,
        blocks,
        netlist,
    };
    let simulators: Vec<Simulator> = if sim == "all" {
        Simulator::ALL.to_vec()
    } else {
        sim.split(',')
            .map(|name| name.trim().parse())
            .collect::<std::result::Result<_, _>>()
            .map_err(|e| super::Usage(format!("--sim {sim}: {e}")))?
    };
    if let Some(path) = &junit_path {
        // Before the simulations, which can take minutes.
        super::options::check_writable_file("--junit", path)?;
    }
    let mut total = 0;
    for simulator in &simulators {
        total += simulate::block_names(&out, *simulator, &options)?.len() as u64;
    }
    // What the testbenches check is what the manifest lists: an edited testbench, vector
    // count or manifest is refused before anything runs.
    gyrofx_codegen::output_folder::verify_contents(&out)?;
    let bar = super::progress::bar(total, "verify", quiet);
    let mut outcomes = Vec::with_capacity(simulators.len());
    for simulator in simulators {
        bar.set_message(format!("verify: {}", simulator.name()));
        let outcome = simulate::run_reporting(&out, simulator, &options, &mut |_| bar.inc(1))?;
        bar.suspend(|| {
            for line in outcome.report() {
                println!("{line}");
            }
            for block in outcome
                .blocks
                .iter()
                .filter(|b| !b.passed && b.report.is_empty())
            {
                eprintln!("{}", block.log);
            }
            if outcome.passed() {
                println!("{}: passed", simulator.name());
            } else {
                eprintln!("{}: FAILED", simulator.name());
            }
        });
        outcomes.push(outcome);
    }
    bar.finish_and_clear();
    if let Some(path) = &junit_path {
        std::fs::write(path, junit::report(&outcomes))
            .with_context(|| format!("cannot write the JUnit summary {}", path.display()))?;
    }
    if outcomes.iter().all(simulate::Outcome::passed) {
        Ok(ExitCode::SUCCESS)
    } else {
        Ok(ExitCode::FAILURE)
    }
}
