//! `gyrofx formats`: the proven range of every analysed quantization point, the formats that
//! cannot overflow for any input inside the ADC's range, and the config with them.

use std::io::Write as _;
use std::path::PathBuf;
use std::process::ExitCode;

use anyhow::{Context, Result};

use super::options::{count, ConfigSource};
use super::usage;

use gyrofx_codegen::formats::analyse;
use gyrofx_codegen::job::Job;
use gyrofx_codegen::output_folder;

/// Prove the formats: for any input inside the ADC's range, the range of every analysed
/// quantization point (worst-case peak gain of the linear blocks, interval arithmetic, the
/// rounding errors' worst case), the integer bits that make overflow impossible, and whether
/// the configured format has them. `--strict` exits 1 when a configured format can overflow.
#[derive(clap::Args)]
pub struct Args {
    #[command(flatten)]
    config: ConfigSource,
    /// Record length the bounds must hold for, samples (default: the config's `samples`).
    #[arg(long, value_parser = count)]
    samples: Option<usize>,
    /// Changes of `bw_sel` the bounds must allow for (each can move the KF's states).
    #[arg(long, value_parser = count, default_value = "100")]
    switches: usize,
    /// Print JSON.
    #[arg(long)]
    json: bool,
    /// Write the config with every configured node's proven format (same fraction bits) to
    /// this TOML file, which `generate`, `filter` and `--strict` accept.
    #[arg(long)]
    write: Option<PathBuf>,
    /// Replace an existing --write file.
    #[arg(long)]
    force: bool,
    /// Exit 1 when a configured format can overflow.
    #[arg(long)]
    strict: bool,
}

/// Prints the table (or JSON); writes the derived config.
pub fn run(args: Args) -> Result<ExitCode> {
    if let Some(path) = &args.write {
        if path.exists() && !args.force {
            usage!(
                "--write {} exists: choose another file, or give --force to replace it",
                path.display()
            );
        }
    }
    let config = args.config.load()?;
    let samples = args.samples.unwrap_or(config.samples) as u64;
    let job = Job::new(config.clone())?;
    let analysis = analyse(&job, samples, args.switches as u64);
    if let Some(path) = &args.write {
        let derived = analysis.derived_config(&config)?;
        let folder = match path.parent() {
            Some(p) if !p.as_os_str().is_empty() => p,
            _ => std::path::Path::new("."),
        };
        let mut staged = output_folder::staged_file(folder, ".gyrofx-formats-", ".toml")
            .with_context(|| {
                format!(
                    "--write {}: cannot create a file in {}",
                    path.display(),
                    folder.display()
                )
            })?;
        write!(
            staged,
            "# written by gyrofx formats: the config with proven formats for a record of {samples} samples and {} bw_sel switches\n{}",
            args.switches,
            derived.to_toml()
        )
        .with_context(|| format!("--write {}", path.display()))?;
        staged
            .persist(path)
            .with_context(|| format!("--write {}: cannot move into place", path.display()))?;
    }
    if args.json {
        println!("{}", serde_json::to_string_pretty(&analysis.json())?);
    } else {
        print!("{}", analysis.text());
    }
    Ok(if args.strict && analysis.overflows().next().is_some() {
        ExitCode::FAILURE
    } else {
        ExitCode::SUCCESS
    })
}
