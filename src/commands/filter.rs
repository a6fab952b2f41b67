//! `gyrofx filter`: recorded rate data through the bit-accurate KF and its float model, into
//! a CSV.

use std::path::{Path, PathBuf};
use std::process::ExitCode;

use std::io::Write;

use anyhow::{Context, Result};

use gyrofx_codegen::filter_package::FilterPackage;
use gyrofx_codegen::text::Provenance;
use gyrofx_job::config::Config;
use gyrofx_job::hash::sha256_hex;
use gyrofx_job::job::{design_bandwidths, plan_for, Job};
use gyrofx_model::fx::{from_f64, Overflow, Rounding};
use gyrofx_model::kf::{FixedKf, FloatKf};

use super::options::{check_output, number, CsvColumn};
use super::usage;

/// Run recorded rate data (°/s) through the bit-accurate KF and its float model.
#[derive(clap::Args)]
pub struct Args {
    #[command(flatten)]
    csv: CsvColumn,
    /// Sample rate of the data, Hz.
    #[arg(long, allow_negative_numbers = true)]
    fs: f64,
    /// KF bandwidth, Hz (default: the config's first).
    #[arg(long, allow_negative_numbers = true)]
    bandwidth: Option<f64>,
    /// Config for formats and noise model (default: the embedded one).
    #[arg(long)]
    config: Option<PathBuf>,
    /// Output CSV.
    #[arg(long)]
    output: PathBuf,
    /// Refuse (exit 1, no output file) when the input saturated the KF's input format or a
    /// KF quantizer overflowed; without it that is a warning.
    #[arg(long)]
    strict: bool,
    /// Also write the KF block's vectors of this record into this folder: its RTL, ROM,
    /// Verilog, VHDL, cocotb and DPI-C testbenches, a Makefile and a manifest with the
    /// recording's SHA-256.
    #[arg(long)]
    vectors: Option<PathBuf>,
    /// Replace an existing --output file or --vectors folder even when gyrofx did not write it.
    #[arg(long)]
    force: bool,
}

/// Samples the KF runs between two formatting rounds.
const FILTER_BATCH: usize = 1 << 18;

/// One output row's codes and float reference.
struct Row {
    z: i64,
    rate: i64,
    reference: f64,
}

/// The CSV text of `rows`, the first being sample `first`.
fn format_rows(rows: &[Row], first: usize, plan: &gyrofx_model::kf::Plan) -> Vec<u8> {
    let (mut integer, mut real) = (itoa::Buffer::new(), ryu::Buffer::new());
    let mut text = Vec::with_capacity(rows.len() * 80);
    for (k, row) in rows.iter().enumerate() {
        text.extend_from_slice(integer.format(first + k).as_bytes());
        text.push(b',');
        text.extend_from_slice(real.format(plan.input.to_f64(i128::from(row.z))).as_bytes());
        text.push(b',');
        text.extend_from_slice(integer.format(row.z).as_bytes());
        text.push(b',');
        text.extend_from_slice(integer.format(row.rate).as_bytes());
        text.push(b',');
        text.extend_from_slice(
            real.format(plan.output.to_f64(i128::from(row.rate)))
                .as_bytes(),
        );
        text.push(b',');
        text.extend_from_slice(real.format(row.reference).as_bytes());
        text.push(b'\n');
    }
    text
}

/// The command that rewrites the vectors (as the files' generated-by line gives it).
fn filter_provenance(
    job: &Job,
    csv: &CsvColumn,
    column: &str,
    fs: f64,
    bandwidth: Option<f64>,
) -> Provenance {
    let mut command = format!(
        "gyrofx filter --input {} --column {column} --fs {fs}",
        csv.input.display(),
    );
    if let Some(bw) = bandwidth {
        command.push_str(&format!(" --bandwidth {bw}"));
    }
    command.push_str(" --output <file> --vectors <folder>");
    Provenance {
        version: env!("CARGO_PKG_VERSION").to_string(),
        command,
        config_sha256: sha256_hex(job.config.to_toml().as_bytes()),
    }
}

/// Refuses, before any work, an `--fs` that is not a finite number of Hz > 0 and a
/// `--bandwidth` outside (0, fs/2).
fn check_rates(fs: f64, bandwidth: Option<f64>) -> Result<()> {
    if !(fs.is_finite() && fs > 0.0) {
        usage!(
            "--fs {} is not allowed: the sample rate must be a finite number of Hz > 0",
            number(fs)
        );
    }
    super::options::check_bandwidth(bandwidth, fs)?;
    Ok(())
}

/// A config error on a key that `--fs` or `--bandwidth` set, reported as that flag's usage
/// error (exit 2); any other stays the config file's error.
fn flag_error(error: gyrofx_codegen::Error, fs: f64, bandwidth: Option<f64>) -> anyhow::Error {
    let field = match &error {
        gyrofx_codegen::Error::Config { field, .. } => field.as_str(),
        _ => "",
    };
    match (field, bandwidth) {
        ("stimulus.fs_hz", _) => {
            super::Usage(format!("--fs {} is not allowed: {error}", number(fs))).into()
        }
        (f, Some(bw)) if f.starts_with("kf.bandwidths_hz") => super::Usage(format!(
            "--bandwidth {} is not allowed: {error}",
            number(bw)
        ))
        .into(),
        _ => error.into(),
    }
}

/// The output CSV's first line: how an earlier output of `filter` is known.
const HEADER: &str = "sample,z_dps,z_code,rate_code,rate_dps,float_rate_dps";

/// Writes the CSV atomically (one row per sample: the input, its code, the fixed-point and the
/// float rate) and prints a summary with the saturation and overflow counts.
pub fn run(args: Args) -> Result<ExitCode> {
    let Args {
        csv,
        fs,
        bandwidth,
        config,
        output,
        strict,
        vectors,
        force,
    } = args;
    check_rates(fs, bandwidth)?;
    let column = csv.column()?;
    let output = output.as_path();
    check_outputs(&csv, config.as_deref(), output, vectors.as_deref())?;
    super::options::check_replaceable(output, HEADER, force)?;
    let mut staged = super::options::stage_output(output, ".gyrofx-filter-")?;
    let (config, bandwidth_hz, plan) = configured(config.as_deref(), fs, bandwidth)?;
    // The vectors' folder is checked, and their files opened, before the work.
    let mut kf_vectors = match &vectors {
        Some(folder) => {
            let job = gyrofx_codegen::blocks::checked_job(config)?;
            let provenance = filter_provenance(&job, &csv, &column, fs, bandwidth);
            let package =
                FilterPackage::create(folder, &job, &provenance, super::options::replace(force))?;
            Some((job, provenance, package))
        }
        None => None,
    };
    let values = csv.read()?;
    let package = kf_vectors.as_mut().map(|(_, _, package)| package);
    let counts = filter(&values, &plan, staged.as_file_mut(), package)
        .map_err(|e| anyhow::anyhow!("output {}: {e}", output.display()))??;
    if let Some(message) = counts.warning(&plan) {
        if strict {
            // The staged file is removed when it drops: nothing is written.
            anyhow::bail!("--strict: {message}; no output written (choose wider formats in --config, or drop --strict to keep the saturated result)");
        }
        eprintln!("warning: {message} (--strict makes this an error)");
    }
    // The vectors first: when they fail, the staged CSV is removed as it drops, and neither
    // output is left.
    if let (Some((job, provenance, package)), Some(folder)) = (kf_vectors, &vectors) {
        let recording = serde_json::json!({
            "input": csv.input.display().to_string(),
            "column": column,
            "sha256": gyrofx_job::hash::file_sha256(&csv.input)?,
            "samples": values.len(),
            "fs_hz": fs,
            "bandwidth_hz": bandwidth_hz,
            "quantization": format!("nearest, saturate into {}", plan.input),
        });
        let files = package.finish(&job, &provenance, recording)?;
        println!(
            "wrote the KF's vectors of the record ({} files) -> {}; run them with make -C {} iverilog-kf",
            files.len(),
            folder.display(),
            folder.display()
        );
    }
    staged
        .persist(output)
        .with_context(|| format!("output {}: cannot move into place", output.display()))?;
    let summary = Summary {
        samples: values.len(),
        fs,
        bandwidth_hz,
        output,
        counts,
    };
    println!("{summary}");
    Ok(ExitCode::SUCCESS)
}

/// Refuses, before any work, an `--output` or `--vectors` that would overwrite an input or
/// each other.
fn check_outputs(
    csv: &CsvColumn,
    config: Option<&Path>,
    output: &Path,
    vectors: Option<&Path>,
) -> Result<()> {
    let inputs = [("--input", Some(csv.input.as_path())), ("--config", config)];
    check_output("--output", output, false, &inputs)?;
    if let Some(folder) = vectors {
        let mut inputs = inputs.to_vec();
        inputs.push(("--output", Some(output)));
        check_output("--vectors", folder, true, &inputs)?;
    }
    Ok(())
}

/// The config (the embedded default, or the file over it: filter takes no --preset) with
/// `--fs` and `--bandwidth` set, the bandwidth the KF runs at (Hz) and its plan.
fn configured(
    path: Option<&Path>,
    fs: f64,
    bandwidth: Option<f64>,
) -> Result<(Config, f64, gyrofx_model::kf::Plan)> {
    let mut config = match path {
        Some(path) => Config::from_file(path)?,
        None => Config::embedded(),
    };
    config.stimulus.fs_hz = fs;
    // The recorded data replace the gyros: the resonator plant's rate (fixed by its loop)
    // need not match the record's.
    config.plant.model = "rate".into();
    if let Some(bw) = bandwidth {
        config.kf.bandwidths_hz = vec![bw];
    }
    let settings = config
        .validate()
        .map_err(|e| flag_error(e, fs, bandwidth))?
        .kf;
    let designs = design_bandwidths(
        &settings,
        fs,
        config.kf.arw_deg_per_sqrt_h,
        config.kf.rrw_deg_per_h_per_sqrt_h,
    )
    .map_err(|e| {
        let bw = settings.bandwidths_hz[0];
        super::Usage(format!(
            "--fs {} with the bandwidth {} Hz (--bandwidth, else the config's kf.bandwidths_hz) cannot be designed: {e}",
            number(fs),
            number(bw)
        ))
    })?;
    let plan = plan_for(&settings, &designs)?;
    Ok((config, settings.bandwidths_hz[0], plan))
}

/// What the KF met on the record: input saturations and its quantizers' overflows.
struct Counts {
    saturated: u64,
    overflows: gyrofx_model::kf::OverflowCounts,
}

impl Counts {
    /// The warning (or, with --strict, the error) when anything saturated or overflowed.
    fn warning(&self, plan: &gyrofx_model::kf::Plan) -> Option<String> {
        let o = &self.overflows;
        (self.saturated + o.x1 + o.x2 + o.rate_hat > 0).then(|| {
            format!(
                "the input saturated the KF's input format {} {} times, the KF's quantizers overflowed x1 {} x2 {} rate_hat {}",
                plan.input, self.saturated, o.x1, o.x2, o.rate_hat
            )
        })
    }
}

/// `values` (°/s) through the fixed-point KF and its float model into `file` as CSV rows, and
/// into `package` when the KF's vectors are written too. The KF runs in batches; each batch's
/// rows are formatted (itoa/ryu, shortest round-trip reals: formatting is most of filter's
/// time) on every core, and a writer thread writes the formatted parts in order while the
/// next batch runs. The outer error is the file's, the inner one the input's.
fn filter(
    values: &[f64],
    plan: &gyrofx_model::kf::Plan,
    file: &mut std::fs::File,
    mut package: Option<&mut FilterPackage>,
) -> std::io::Result<Result<Counts>> {
    let mut fixed = FixedKf::new(plan);
    let mut float = FloatKf::new(plan.gains.clone());
    let cores = std::thread::available_parallelism().map_or(1, |n| n.get().min(8));
    let mut saturated = 0u64;
    let mut input_error = None;
    std::thread::scope(|scope| -> std::io::Result<()> {
        let (send, receive) = std::sync::mpsc::sync_channel::<Vec<u8>>(2 * cores);
        // The parts are large: written as they are, not copied through a buffer.
        let writer = scope.spawn(move || -> std::io::Result<()> {
            file.write_all(HEADER.as_bytes())?;
            file.write_all(b"\n")?;
            for part in receive {
                file.write_all(&part)?;
            }
            file.flush()
        });
        let mut rows = Vec::with_capacity(FILTER_BATCH.min(values.len()));
        'batches: for (batch, chunk) in values.chunks(FILTER_BATCH).enumerate() {
            rows.clear();
            for value in chunk {
                let q = match from_f64(*value, plan.input, Rounding::Nearest, Overflow::Saturate) {
                    Ok(q) => q,
                    Err(e) => {
                        input_error = Some(e);
                        break 'batches;
                    }
                };
                saturated += u64::from(q.overflowed);
                let z = q.code as i64;
                let rate = fixed.step(z, 0);
                if let Some(package) = package.as_mut() {
                    package.push(z, rate);
                }
                rows.push(Row {
                    z,
                    rate,
                    reference: float.step(*value, 0),
                });
            }
            for part in format_in_parts(&rows, batch * FILTER_BATCH, cores, plan) {
                if send.send(part).is_err() {
                    break 'batches; // the writer failed: its error is reported below
                }
            }
        }
        drop(send);
        writer.join().expect("the writer does not panic")
    })?;
    Ok(match input_error {
        Some(e) => Err(e.into()),
        None => Ok(Counts {
            saturated,
            overflows: fixed.overflow_counts(),
        }),
    })
}

/// The CSV text of `rows` (the first being sample `first`) in `cores` parts formatted at once,
/// in order.
fn format_in_parts(
    rows: &[Row],
    first: usize,
    cores: usize,
    plan: &gyrofx_model::kf::Plan,
) -> Vec<Vec<u8>> {
    let part_rows = rows.len().div_ceil(cores).max(1);
    std::thread::scope(|formatters| {
        let handles: Vec<_> = rows
            .chunks(part_rows)
            .enumerate()
            .map(|(p, part)| {
                formatters.spawn(move || format_rows(part, first + p * part_rows, plan))
            })
            .collect();
        handles
            .into_iter()
            .map(|h| h.join().expect("formatting does not panic"))
            .collect()
    })
}

/// The line `filter` prints at the end.
struct Summary<'a> {
    samples: usize,
    fs: f64,
    bandwidth_hz: f64,
    output: &'a Path,
    counts: Counts,
}

impl std::fmt::Display for Summary<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
        let o = &self.counts.overflows;
        write!(
            f,
            "filtered {} samples at {} Hz, bandwidth {} Hz -> {}; ADC saturations {}, overflows x1 {} x2 {} rate_hat {}",
            self.samples,
            self.fs,
            self.bandwidth_hz,
            self.output.display(),
            self.counts.saturated,
            o.x1,
            o.x2,
            o.rate_hat
        )
    }
}
