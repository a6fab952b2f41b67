//! `gyrofx reproduce`: a paper's pipeline on simulated data, its tables beside gyrofx's, with
//! the differences explained (markdown).

use std::path::PathBuf;
use std::process::ExitCode;

use anyhow::Result;

use super::usage;

use gyrofx_codegen::output_folder;
use gyrofx_lab::reproduce;

/// Reproduce a paper's tables (000, 002, 003, 004) beside gyrofx's.
///
/// Runs the paper's pipeline on simulated data and prints its tables beside gyrofx's, with the
/// differences measured and explained (markdown).
#[derive(clap::Args)]
pub struct Args {
    /// The paper: 000, 002, 003 or 004.
    #[arg(long)]
    paper: String,
    /// Samples to simulate, at most 20000000 (default: the paper's record length).
    #[arg(long, value_parser = super::options::samples)]
    samples: Option<usize>,
    /// Seed of the simulation, 0..=2^63 - 1.
    #[arg(long, default_value = "1", value_parser = super::options::seed)]
    seed: u64,
    /// Also write report.md, allan.png (and davar.png for 002) into this folder (replaced
    /// only if empty or a previous reproduction holding only its own files, unchanged).
    #[arg(long)]
    out: Option<PathBuf>,
    /// Replace --out even if it holds other files or another kind of package.
    #[arg(long, requires = "out")]
    force: bool,
    /// No progress spinner (it shows only on a terminal).
    #[arg(long)]
    quiet: bool,
}

/// Prints the report; with `--out`, also writes it and its plots.
pub fn run(args: Args) -> Result<ExitCode> {
    let Args {
        paper,
        samples,
        seed,
        out,
        force,
        quiet,
    } = args;
    let paper = paper.as_str();
    let replace = super::options::replace(force);
    let mut _lock = None;
    if let Some(folder) = &out {
        _lock = Some(super::options::claim_output_folder(folder, &[])?);
        // Before the simulation: a folder that cannot be written fails now, not minutes later.
        output_folder::check(folder, output_folder::Kind::Reproduce, replace)?;
    }
    let spinner = super::progress::spinner(&format!("reproduce: paper {paper}"), quiet);
    let (report, curves, davar) = match paper {
        "000" => {
            let p = reproduce::paper_000(samples.unwrap_or(reproduce::SAMPLES_000), seed)?;
            (p.markdown(), p.curves, None)
        }
        "002" => {
            let p = reproduce::paper_002(samples.unwrap_or(reproduce::SAMPLES_002), seed)?;
            (p.markdown(), Vec::new(), Some(p.adaptive))
        }
        "003" => {
            let p = reproduce::paper_003(samples.unwrap_or(reproduce::SAMPLES), seed)?;
            (p.markdown(), p.curves, None)
        }
        "004" => {
            let p = reproduce::paper_004(samples.unwrap_or(reproduce::SAMPLES_004), seed)?;
            let curves = p.resonator.curves.iter().chain(&p.rate.curves).cloned();
            (p.markdown(), curves.collect(), None)
        }
        other => usage!("--paper {other:?} is not one of the papers: use 000, 002, 003 or 004"),
    };
    spinner.finish_and_clear();
    print!("{report}");
    if let Some(folder) = &out {
        let davar = davar.as_ref().map(|(d, c)| (d, c));
        let files = reproduce::write(folder, replace, paper, seed, &report, &curves, davar)?;
        eprintln!("wrote {} in {}", files.join(", "), folder.display());
    }
    Ok(ExitCode::SUCCESS)
}
