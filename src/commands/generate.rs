//! `gyrofx generate`: the verification package (vectors, ROMs, testbenches, RTL, manifest),
//! written atomically.

use std::path::PathBuf;
use std::process::ExitCode;

use anyhow::Result;

use gyrofx_codegen::generate::{generate, overflow_list, Contents, Options, Output};
use gyrofx_codegen::progress::Progress;
use gyrofx_job::job::Job;
use gyrofx_job::recording::{Recording, Units};

use super::options::{ConfigSource, OutputFolder};
use super::usage;

/// Write the verification package (vectors, ROM, testbench, RTL, manifest) atomically.
#[derive(clap::Args)]
pub struct Args {
    #[command(flatten)]
    out: OutputFolder,
    #[command(flatten)]
    source: ConfigSource,
    /// Samples of the chain run, 1..=20000000 (overrides the config).
    #[arg(long, value_parser = super::options::samples)]
    samples: Option<usize>,
    /// Seed, 0..=2^63 - 1 (overrides the config).
    #[arg(long, value_parser = super::options::seed)]
    seed: Option<u64>,
    /// Refuse to write the package when a quantizer overflows or saturates on the run's data
    /// (exit 1); without it, a warning names the signals.
    #[arg(long)]
    strict: bool,
    /// Write only these blocks' folders and Makefile targets, comma-separated (e.g. kf,top;
    /// calibration has none of its own: top checks it).
    #[arg(long, value_delimiter = ',')]
    blocks: Option<Vec<String>>,
    /// Leave out the <block>_vectors.csv twins of the hex vector files.
    #[arg(long)]
    no_csv: bool,
    /// No progress bar (it shows only on a terminal).
    #[arg(long)]
    quiet: bool,
    /// Recorded outputs of the two gyros (CSV) that drive the chain's blocks (sequencer,
    /// estimator, KF, top, mean filter) instead of the simulated plant; the manifest records
    /// its SHA-256. Samples: its rows (or --samples of them).
    #[arg(long)]
    recording: Option<PathBuf>,
    /// The recording's columns of gyro A and B, by name or 0-based index.
    #[arg(
        long,
        value_delimiter = ',',
        num_args = 1,
        default_value = "y_a_dps,y_b_dps",
        requires = "recording"
    )]
    recording_columns: Vec<String>,
    /// The recording's unit: dps (°/s) or rad/s.
    #[arg(long, default_value = "dps", requires = "recording")]
    recording_units: String,
    /// The recording's sample rate, Hz (must be the config's stimulus.fs_hz).
    #[arg(long, allow_negative_numbers = true, requires = "recording")]
    recording_rate: Option<f64>,
    /// A column with gyro A's mode per row (1 normal, 0 or -1 reverse), checked against the
    /// configured sequencer; without it the rows are taken to follow the sequencer.
    #[arg(long, requires = "recording")]
    recording_mode: Option<String>,
}

/// Writes the package and prints what it holds: the files, the KF plan, the fixed-point
/// errors, the overflow counts and the noise report.
pub fn run(args: Args) -> Result<ExitCode> {
    let Args {
        out: folder,
        source,
        samples,
        seed,
        strict,
        blocks,
        no_csv,
        quiet,
        recording,
        recording_columns,
        recording_units,
        recording_rate,
        recording_mode,
    } = args;
    let contents = Contents {
        blocks,
        csv: !no_csv,
    };
    contents.check().map_err(super::Usage)?;
    let out = folder.out.as_path();
    let _lock = super::options::claim_output_folder(
        out,
        &[
            ("--config", source.config.as_deref()),
            ("--recording", recording.as_deref()),
        ],
    )?;
    let mut config = source.load()?;
    let recording = match recording {
        Some(path) => {
            let [a, b] = <[String; 2]>::try_from(recording_columns).map_err(|c| {
                super::Usage(format!(
                    "--recording-columns {}: name gyro A's and gyro B's columns, e.g. y_a_dps,y_b_dps or 1,2",
                    c.join(",")
                ))
            })?;
            let units: Units = recording_units
                .parse()
                .map_err(|e: String| super::Usage(format!("--recording-units: {e}")))?;
            let Some(rate) = recording_rate else {
                usage!("--recording needs --recording-rate HZ (the recording's sample rate; the chain runs at stimulus.fs_hz = {} Hz)", config.stimulus.fs_hz);
            };
            let recording =
                Recording::read(&path, [&a, &b], units, rate, recording_mode.as_deref())?;
            // Every row, unless --samples asks for fewer.
            config.samples = samples.unwrap_or(recording.len());
            Some(recording)
        }
        None => {
            if let Some(n) = samples {
                config.samples = n;
            }
            None
        }
    };
    if let Some(s) = seed {
        config.seed = s;
    }
    let mut job = gyrofx_codegen::blocks::checked_job(config)?;
    if let Some(recording) = recording {
        job = job.with_recording(recording)?;
    }
    contents.check_for(&job).map_err(super::Usage)?;
    let mut provenance = source.provenance(&job, Output::Package);
    if let Some(recording) = &job.recording {
        provenance.command.push_str(&recording.arguments());
    }
    let options = Options {
        replace: folder.replace(),
        strict,
        contents,
    };
    let progress = Progress::default();
    let summary = super::progress::follow("generate", quiet, &progress, || {
        generate(&job, out, options, &provenance, &progress)
    })?;
    let run = &summary.run;
    let overflowed = run.overflows.in_chain_run();
    if !overflowed.is_empty() {
        eprintln!(
            "warning: quantizers overflowed or saturated on the chain run's data: {} (counts; the directed test segments' saturations are not counted; --strict makes this an error)",
            overflow_list(&overflowed)
        );
    }
    println!(
        "wrote {} files to {}: {} chain samples; vectors: {}",
        summary.files.len(),
        out.display(),
        run.samples,
        run.blocks
            .iter()
            .map(|b| format!("{} {}", b.name, b.len()))
            .collect::<Vec<_>>()
            .join(", ")
    );
    println!("kf plan: {}", job.kf());
    for what in ["kf", "chain", "bias"] {
        let Some(s) = run.stats(what) else { continue };
        println!(
            "{what} fixed vs float: max {:.3} LSB, rms {:.3} LSB, bound {:.3} LSB; vs ideal: max {:.3} LSB, SQNR {:.1} dB",
            s.max_lsb, s.rms_lsb, s.bound_lsb, s.ideal_max_lsb, s.sqnr_db
        );
    }
    let o = &run.overflows;
    let loops = loop_overflows(&job, o);
    // The KF's directed segment, as the KF's builder reported it (every package has a KF).
    let directed = match o.directed.get("kf_directed") {
        Some(d) => format!(
            " (directed segment: x1 {} x2 {} rate_hat {})",
            d["x1"], d["x2"], d["rate_hat"]
        ),
        None => String::new(),
    };
    println!(
        "overflows: ADC {:?}, means {:?}, biases {:?}, calibrated {:?}, combined {}, KF x1 {} x2 {} rate_hat {}{directed}{loops}",
        o.adc, o.estimator.mean, o.estimator.bias, o.estimator.calibrated, o.estimator.combined,
        o.kf_chain.x1, o.kf_chain.x2, o.kf_chain.rate_hat
    );
    println!(
        "report ({} s):",
        run.report
            .tau_s
            .iter()
            .map(|t| t.to_string())
            .collect::<Vec<_>>()
            .join(", ")
    );
    for line in &run.report.lines {
        let adev: Vec<String> = line
            .adev_dps
            .iter()
            .map(|a| a.map(|v| format!("{v:.3e}")).unwrap_or_else(|| "-".into()))
            .collect();
        println!(
            "  {:<26} bias error {:>+10.3e} °/s, ADEV {}",
            line.signal,
            line.bias_error_dps,
            adev.join(" ")
        );
    }
    Ok(ExitCode::SUCCESS)
}

/// `, loop A [...] B [...] (blanked switch transients: A [...] B [...])`: the nodes of the
/// resonator-level gyros' loops that saturated or wrapped in the samples the chain takes, and
/// apart those in the transients the sequencer blanks; empty for the other plants.
fn loop_overflows(job: &Job, overflows: &gyrofx_codegen::vectors::Overflows) -> String {
    if job.settings.resonator.is_none() || job.recording.is_some() {
        return String::new();
    }
    let [a, b] = &overflows.gyro_loop;
    format!(
        ", loop A [{}] B [{}] (blanked switch transients: A [{}] B [{}])",
        a.used.summary(),
        b.used.summary(),
        a.blanked.summary(),
        b.blanked.summary()
    )
}
