//! `gyrofx formats`: the proven range of every analysed quantization point, the formats that
//! cannot overflow for any input inside the ADC's range, and the config with them.

use std::io::Write as _;
use std::path::PathBuf;
use std::process::ExitCode;

use anyhow::{Context, Result};

use super::options::{count, ConfigSource};
use super::usage;

use gyrofx_codegen::output_folder;
use gyrofx_job::formats::{analyse, fractions_for};
use gyrofx_job::residual_budget::{parse_target, residual_budget, BudgetError};

/// Prove the formats: which quantization points can overflow, and the bits that prevent it.
///
/// For any input inside the ADC's range, the range of every analysed
/// quantization point (worst-case peak gain of the linear blocks, interval arithmetic, the
/// rounding errors' worst case), the integer bits that make overflow impossible, and whether
/// the configured format has them. `--strict` exits 1 when a configured format can overflow.
#[derive(clap::Args)]
pub struct Args {
    #[command(flatten)]
    config: ConfigSource,
    /// Record length the bounds must hold for, samples, 1..=20000000 (default: the config's
    /// `samples`).
    #[arg(long, value_parser = super::options::samples)]
    samples: Option<usize>,
    /// Changes of `bw_sel` the bounds must allow for (each can move the KF's states).
    #[arg(long, value_parser = count, default_value = "100")]
    switches: usize,
    /// Error budget on the chain's output against its float model, in KF output LSB (`1.5`)
    /// or °/s (`0.0001dps`): also choose the fewest fraction bits of the interval means, bias
    /// estimates and KF state that meet it over the record (for --write and the table).
    #[arg(long, allow_hyphen_values = true)]
    output_error: Option<String>,
    /// Residual bias after reversal to budget for, in mdps (`1mdps`) or °/s (`0.001dps`): also
    /// show what each part of the gyro loops (NCO phase and address bits, latency, trim, ...)
    /// moves `(B − B′)/2` by, measured beside it, and choose the cheapest NCO and phase trim
    /// whose worst case meets the target (for --write and the table).
    #[arg(long, allow_hyphen_values = true)]
    residual_budget: Option<String>,
    /// Print JSON.
    #[arg(long)]
    json: bool,
    /// Write the config with every configured node's proven format (same fraction bits) to
    /// this TOML file, which `generate`, `filter` and `--strict` accept.
    #[arg(long)]
    write: Option<PathBuf>,
    /// Replace an existing --write file.
    #[arg(long, requires = "write")]
    force: bool,
    /// Exit 1 when a configured format can overflow.
    #[arg(long)]
    strict: bool,
}

/// Prints the table (or JSON); writes the derived config.
pub fn run(args: Args) -> Result<ExitCode> {
    if let Some(path) = &args.write {
        if path.is_dir() {
            usage!(
                "--write {} is a folder: name the TOML file to write",
                path.display()
            );
        }
        if path.exists() && !args.force {
            usage!(
                "--write {} exists: choose another file, or give --force to replace it",
                path.display()
            );
        }
    }
    let config = args.config.load()?;
    let samples = args.samples.unwrap_or(config.samples) as u64;
    let job = gyrofx_codegen::blocks::checked_job(config.clone())?;
    let analysis = analyse(&job, samples, args.switches as u64);
    let budget = match &args.output_error {
        None => None,
        Some(text) => {
            let lsb = job.kf().output.lsb();
            let value = match text.strip_suffix("dps") {
                Some(dps) => dps.trim().parse::<f64>().map(|v| v / lsb),
                None => text.trim().parse::<f64>(),
            };
            let Ok(budget) = value else {
                usage!("--output-error {text} is not a budget: a number of output LSB (1.5) or of °/s ending in dps (0.0001dps)");
            };
            match fractions_for(&job, samples, args.switches as u64, budget) {
                Ok(budget) => Some(budget),
                Err(message) => usage!("{message}"),
            }
        }
    };
    let residual = match &args.residual_budget {
        None => None,
        Some(text) => match parse_target(text).map(|target| residual_budget(&config, target)) {
            Ok(Ok(report)) => Some(report),
            // A target under what the loop can reach is the flag's fault, not the config's.
            Ok(Err(e @ BudgetError::Target { .. })) => usage!("{e}"),
            Ok(Err(e)) => return Err(e.into()),
            Err(message) => usage!("{message}"),
        },
    };
    if let Some(path) = &args.write {
        let mut derived = analysis.derived_config(&config, budget.as_ref())?;
        if let Some(report) = &residual {
            report.apply(&mut derived);
            gyrofx_codegen::blocks::checked_job(derived.clone())?;
        }
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
        let mut json = analysis.json();
        if let Some(b) = &budget {
            json["output_error"] = serde_json::json!({
                "budget_lsb": b.budget_lsb,
                "floor_lsb": b.floor_lsb,
                "bound_lsb": b.bound_lsb,
                "estimator.mean_format": b.mean.to_string(),
                "estimator.bias_format": b.bias.to_string(),
                "kf.state_format": b.state.to_string(),
                "mean_filter.reciprocal_width": b.mean_filter_reciprocal_width,
                "mean_filter_bound_lsb": b.mean_filter_bound_lsb,
            });
        }
        if let Some(report) = &residual {
            json["residual_budget"] = serde_json::to_value(report)?;
        }
        println!("{}", serde_json::to_string_pretty(&json)?);
    } else {
        print!("{}", analysis.text());
        if let Some(b) = &budget {
            println!(
                "for an output error of at most {:.3} LSB (at least {:.3}: the output's and calibrated samples' roundings): mean_format = {}, bias_format = {}, state_format = {}; bound {:.3} LSB; mean_filter.reciprocal_width = {} (bound {:.3} LSB of its output)",
                b.budget_lsb, b.floor_lsb, b.mean, b.bias, b.state, b.bound_lsb,
                b.mean_filter_reciprocal_width, b.mean_filter_bound_lsb
            );
        }
        if let Some(report) = &residual {
            print!("{report}");
        }
    }
    Ok(if args.strict && analysis.overflows().next().is_some() {
        ExitCode::FAILURE
    } else {
        ExitCode::SUCCESS
    })
}
