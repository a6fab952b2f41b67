//! `gyrofx denoise`: paper 004's ICEEMDAN + sample-entropy threshold denoising on a user's
//! record, block by block with overlap, and the Allan deviation before and after.

use std::fmt;
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};
use std::process::ExitCode;

use anyhow::{Context, Result};

use gyrofx_model::analysis::allan::{self, Grid, Kind, Point};
use gyrofx_model::analysis::denoise::{self, BlockReport, Rule};
use gyrofx_model::analysis::emd::Ensemble;
use gyrofx_model::analysis::noise::{self, Terms};

use super::options::{check_output, CsvColumn, SampleRate};
use super::usage;

/// Denoise a record as paper 004 does (ICEEMDAN, sample entropy, thresholds).
///
/// Each block of --block samples is decomposed by ICEEMDAN with --overlap samples of context on
/// either side (kept out of the output). The IMF of largest sample entropy among the first three
/// is the noise-dominant one. The other IMFs' noise levels follow white noise's EMD energy law.
/// Noise-dominated IMFs are thresholded (soft or hard) and signal-dominated ones kept. Writes
/// --output (sample, rate_dps, denoised_dps) all or nothing, and prints the overlapping Allan
/// deviation before and after. The defaults are the paper's: blocks of 4096, 50 realizations,
/// noise amplitude 0.2, soft thresholds.
#[derive(clap::Args)]
pub struct Args {
    #[command(flatten)]
    csv: CsvColumn,
    #[command(flatten)]
    rate: SampleRate,
    /// The denoised record (CSV): sample, rate_dps (the input), denoised_dps.
    #[arg(long)]
    output: PathBuf,
    /// Samples per block (16 or more; the last block takes a short rest).
    #[arg(long, default_value_t = 4096)]
    block: usize,
    /// Samples of context decomposed on either side of a block (below --block).
    #[arg(long, default_value_t = 256)]
    overlap: usize,
    /// ICEEMDAN noise realizations (1..=1000).
    #[arg(long, default_value_t = 50)]
    realizations: usize,
    /// ICEEMDAN noise amplitude, relative to the block's standard deviation (0 < a <= 10).
    #[arg(long, default_value_t = 0.2, allow_negative_numbers = true)]
    noise_amplitude: f64,
    /// Thresholding: soft (shrink) or hard (keep or zero).
    #[arg(long, default_value = "soft")]
    rule: String,
    /// Seed of the ICEEMDAN noise (one seed, one output, on every platform).
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// Print JSON instead of the table.
    #[arg(long)]
    json: bool,
    /// Also draw the deviations before and after with their fitted terms (.png or .svg).
    #[arg(long)]
    plot: Option<PathBuf>,
    /// No progress bar.
    #[arg(long)]
    quiet: bool,
    /// Replace an existing --output file even when gyrofx did not write it.
    #[arg(long)]
    force: bool,
}

/// The output CSV's first line: how an earlier output of `denoise` is known.
const HEADER: &str = "sample,rate_dps,denoised_dps";

/// The checked settings of a run.
struct Settings {
    block: usize,
    overlap: usize,
    ensemble: Ensemble,
    rule: Rule,
}

fn settings(args: &Args) -> Result<Settings> {
    if args.block < 16 {
        usage!(
            "--block {} is not allowed: a block is 16 samples or more",
            args.block
        );
    }
    if args.overlap >= args.block {
        usage!(
            "--overlap {} is not allowed: it must be below --block ({})",
            args.overlap,
            args.block
        );
    }
    if !(1..=1000).contains(&args.realizations) {
        usage!(
            "--realizations {} is not allowed: 1..=1000",
            args.realizations
        );
    }
    let amplitude = args.noise_amplitude;
    if !(amplitude.is_finite() && amplitude > 0.0 && amplitude <= 10.0) {
        usage!("--noise-amplitude {amplitude} is not allowed: a number in (0, 10]");
    }
    let rule = match args.rule.as_str() {
        "soft" => Rule::Soft,
        "hard" => Rule::Hard,
        other => usage!("--rule {other} is not allowed: soft or hard"),
    };
    Ok(Settings {
        block: args.block,
        overlap: args.overlap,
        ensemble: Ensemble {
            realizations: args.realizations,
            noise_amplitude: amplitude,
            max_modes: 0,
            seed: args.seed,
        },
        rule,
    })
}

/// One record's deviation and identified terms.
struct Deviation {
    points: Vec<Point>,
    terms: Terms,
    report: noise::Report,
}

/// The same identification as `gyrofx allan` gives on the file (filtered shortest τ left out,
/// the model's error counted), so that the before and after figures read as `allan`'s do.
fn deviation(values: &[f64], rate: f64) -> Deviation {
    let points = allan::curve(Kind::Overlapping, values, rate, Grid::Octave);
    let terms = noise::identify(&points, Kind::Overlapping).terms;
    let report = noise::report(&points, &terms, Kind::Overlapping);
    Deviation {
        points,
        terms,
        report,
    }
}

/// Denoises the record, writes the CSV atomically and prints the comparison.
pub fn run(args: Args) -> Result<ExitCode> {
    let rate = args.rate.hz()?;
    let settings = settings(&args)?;
    let column = args.csv.column()?;
    let inputs = [("--input", Some(args.csv.input.as_path()))];
    check_output("--output", &args.output, false, &inputs)?;
    super::options::check_replaceable(&args.output, HEADER, args.force)?;
    if let Some(path) = &args.plot {
        super::options::check_plot(
            path,
            &[
                ("--input", Some(&args.csv.input)),
                ("--output", Some(&args.output)),
            ],
        )?;
    }
    let values = args.csv.read()?;
    gyrofx_model::analysis::check_magnitudes(&values)
        .map_err(|e| anyhow::anyhow!("{}, column {column}: {e}", args.csv.input.display()))?;
    if values.len() < 16 {
        anyhow::bail!(
            "{}, column {column}: {} samples; denoising needs 16 or more",
            args.csv.input.display(),
            values.len()
        );
    }
    let mut staged = super::options::stage_output(&args.output, ".gyrofx-denoise-")?;
    let bar = super::progress::bar(
        1,
        &format!("denoise: {}", args.csv.input.display()),
        args.quiet,
    );
    let (denoised, blocks) = denoise::denoise_overlapped(
        &values,
        settings.block,
        settings.overlap,
        &settings.ensemble,
        settings.rule,
        &mut |done, total| {
            bar.set_length(total as u64);
            bar.set_position(done as u64);
        },
    );
    bar.finish_and_clear();
    write_csv(staged.as_file_mut(), &values, &denoised)
        .with_context(|| format!("output {}", args.output.display()))?;
    let comparison = Comparison {
        input: &args.csv.input,
        column: &column,
        output: &args.output,
        rate,
        samples: values.len(),
        blocks: &blocks,
        before: deviation(&values, rate),
        after: deviation(&denoised, rate),
    };
    if let Some(path) = &args.plot {
        plot(path, &comparison)?;
    }
    staged
        .persist(&args.output)
        .with_context(|| format!("output {}: cannot move into place", args.output.display()))?;
    if args.json {
        println!(
            "{}",
            serde_json::to_string_pretty(&comparison.json(&settings))?
        );
    } else {
        print!("{comparison}");
    }
    Ok(ExitCode::SUCCESS)
}

/// `sample,rate_dps,denoised_dps`, one row per sample (shortest round-trip decimals).
fn write_csv(file: &mut std::fs::File, input: &[f64], denoised: &[f64]) -> std::io::Result<()> {
    let mut out = BufWriter::new(file);
    writeln!(out, "{HEADER}")?;
    let mut a = ryu::Buffer::new();
    let mut b = ryu::Buffer::new();
    for (k, (x, y)) in input.iter().zip(denoised).enumerate() {
        writeln!(out, "{k},{},{}", a.format(*x), b.format(*y))?;
    }
    out.flush()
}

fn plot(path: &Path, comparison: &Comparison) -> Result<()> {
    let series = [
        gyrofx_lab::plot::AllanSeries {
            label: "input".into(),
            points: &comparison.before.points,
            terms: Some((&comparison.before.terms, Kind::Overlapping)),
        },
        gyrofx_lab::plot::AllanSeries {
            label: "denoised".into(),
            points: &comparison.after.points,
            terms: Some((&comparison.after.terms, Kind::Overlapping)),
        },
    ];
    gyrofx_lab::plot::deviation(
        path,
        &series,
        "Overlapping Allan deviation, before and after denoising",
    )?;
    Ok(())
}

/// What `denoise` prints.
struct Comparison<'a> {
    input: &'a Path,
    column: &'a str,
    output: &'a Path,
    rate: f64,
    samples: usize,
    blocks: &'a [BlockReport],
    before: Deviation,
    after: Deviation,
}

impl Comparison<'_> {
    /// Thresholded IMFs over all IMFs, across the blocks.
    fn thresholded(&self) -> (usize, usize) {
        let all: usize = self.blocks.iter().map(|b| b.threshold.len()).sum();
        let cut: usize = self
            .blocks
            .iter()
            .map(|b| b.threshold.iter().filter(|t| t.is_some()).count())
            .sum();
        (cut, all)
    }

    fn json(&self, settings: &Settings) -> serde_json::Value {
        let curve = |d: &Deviation| {
            serde_json::json!({
                "tau_s": d.points.iter().map(|p| p.tau_s).collect::<Vec<_>>(),
                "adev": d.points.iter().map(|p| p.dev).collect::<Vec<_>>(),
                "terms": d.report,
            })
        };
        let (cut, all) = self.thresholded();
        serde_json::json!({
            "input": self.input.display().to_string(),
            "column": self.column,
            "output": self.output.display().to_string(),
            "samples": self.samples,
            "rate_hz": self.rate,
            "block": settings.block,
            "overlap": settings.overlap,
            "realizations": settings.ensemble.realizations,
            "noise_amplitude": settings.ensemble.noise_amplitude,
            "seed": settings.ensemble.seed,
            "rule": match settings.rule { Rule::Soft => "soft", Rule::Hard => "hard" },
            "blocks": self.blocks.len(),
            "thresholded_imfs": cut,
            "imfs": all,
            "noise_mode": self.blocks.iter().map(|b| b.noise_mode).collect::<Vec<_>>(),
            "before": curve(&self.before),
            "after": curve(&self.after),
        })
    }
}

impl fmt::Display for Comparison<'_> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let (cut, all) = self.thresholded();
        writeln!(
            f,
            "{} (column {}, {} samples at {} Hz): {} blocks, {cut} of {all} IMFs thresholded -> {}",
            self.input.display(),
            self.column,
            self.samples,
            self.rate,
            self.blocks.len(),
            self.output.display()
        )?;
        writeln!(
            f,
            "{:>12} {:>14} {:>14} {:>8}",
            "tau (s)", "ADEV before", "ADEV after", "after/before"
        )?;
        for (b, a) in self.before.points.iter().zip(&self.after.points) {
            writeln!(
                f,
                "{:>12.6} {:>14.6e} {:>14.6e} {:>8.3}",
                b.tau_s,
                b.dev,
                a.dev,
                a.dev / b.dev
            )?;
        }
        let (nb, na) = (
            self.before.report.arw_deg_per_sqrt_h.value,
            self.after.report.arw_deg_per_sqrt_h.value,
        );
        let (bb, ba) = (
            self.before.report.bias_instability_deg_per_h.value,
            self.after.report.bias_instability_deg_per_h.value,
        );
        writeln!(f, "ARW (fitted): {nb:.4} -> {na:.4} °/√h; bias instability (fitted): {bb:.4} -> {ba:.4} °/h")
    }
}
