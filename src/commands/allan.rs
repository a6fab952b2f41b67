//! `gyrofx allan`: the Allan deviation of rate records with confidence intervals, and the five
//! noise terms fitted to it.

use std::path::{Path, PathBuf};
use std::process::ExitCode;

use anyhow::{bail, Result};

use gyrofx_job::input::read_column_with_gaps;
use gyrofx_model::analysis::{allan, noise};

use super::options::SampleRate;
use super::usage;

/// Allan deviation of rate records and the five noise terms fitted to it.
///
/// Rates in °/s; each deviation with its 1σ confidence interval, the noise type per τ, and the
/// terms (Q, N, B, K, R) in IEEE-952 and Kalibr units.
#[derive(clap::Args)]
pub struct Args {
    /// CSV file(s) with a header line; `#` lines are skipped (gyrofx's CSVs work as is).
    #[arg(long, required = true)]
    input: Vec<PathBuf>,
    /// Column(s) of rates in °/s; each input × column is one series [default: each file's only
    /// column, else rate_dps].
    #[arg(long)]
    column: Vec<String>,
    #[command(flatten)]
    rate: SampleRate,
    /// Averaging times: octave, decade, many (ten per decade) or all (every factor: O(N²) time).
    #[arg(long, default_value = "octave")]
    taus: String,
    /// Deviation: overlapping, nonoverlapping, modified or hadamard.
    #[arg(long, default_value = "overlapping")]
    kind: String,
    /// Print JSON (one object per input; an array for several).
    #[arg(long)]
    json: bool,
    /// Write a log-log plot with confidence bars and fitted terms (.png or .svg).
    #[arg(long)]
    plot: Option<PathBuf>,
    /// No progress bar (it shows only on a terminal).
    #[arg(long)]
    quiet: bool,
}

/// The longest record `--taus all` takes: its time grows as N² (10⁵ samples: 1.2 s, 10⁶:
/// about 2 minutes on two cores); memory stays O(N) at any length.
const ALL_TAUS_MAX_SAMPLES: usize = 1_000_000;

/// Prints the deviation and the noise terms of every input × column (a table, or JSON), and
/// writes the plot if asked.
pub fn run(args: Args) -> Result<ExitCode> {
    let Args {
        input: inputs,
        column: columns,
        rate,
        taus,
        kind,
        json,
        plot,
        quiet,
    } = args;
    let rate = rate.hz()?;
    if let Some(path) = &plot {
        let inputs: Vec<(&str, Option<&Path>)> = inputs
            .iter()
            .map(|p| ("--input", Some(p.as_path())))
            .collect();
        super::options::check_plot(path, &inputs)?;
    }
    let grid: allan::Grid = taus
        .parse()
        .map_err(|e: String| super::Usage(format!("--taus: {e}")))?;
    let kind = parse_kind(&kind)?;
    let mut results = Vec::new();
    let mut curves = Vec::new();
    for path in &inputs {
        let path_columns = if columns.is_empty() {
            vec![super::options::default_column(path)?]
        } else {
            columns.clone()
        };
        for column in &path_columns {
            let (values, skipped) = read_series(path, column, grid, json)?;
            let analysis = analyse(&values, rate, kind, grid, path, quiet);
            let series = Series {
                path,
                column,
                samples: values.len(),
                skipped,
                rate_hz: rate,
                kind,
                analysis,
            };
            if json {
                results.push(series.json());
            } else {
                print!("{series}");
            }
            let label = if columns.len() > 1 {
                format!("{} [{column}]", path.display())
            } else {
                path.display().to_string()
            };
            curves.push((label, series.analysis.points, series.analysis.terms));
        }
    }
    if let Some(path) = &plot {
        write_plot(path, &curves, kind)?;
        if !json {
            println!("plot: {}", path.display());
        }
    }
    if json {
        let value = if results.len() == 1 {
            results.remove(0)
        } else {
            serde_json::Value::Array(results)
        };
        println!("{}", serde_json::to_string_pretty(&value)?);
    }
    Ok(ExitCode::SUCCESS)
}

/// `--kind`'s deviation.
fn parse_kind(kind: &str) -> Result<allan::Kind> {
    Ok(match kind {
        "overlapping" => allan::Kind::Overlapping,
        "nonoverlapping" => allan::Kind::NonOverlapping,
        "modified" => allan::Kind::Modified,
        "hadamard" => allan::Kind::Hadamard,
        other => usage!("--kind {other} is not a deviation: expected overlapping, nonoverlapping, modified or hadamard"),
    })
}

/// One column of one input (°/s) and the count of its empty cells, refused where the analysis
/// cannot take it: too short, magnitudes whose sums would overflow, or too long for `--taus all`.
fn read_series(
    path: &Path,
    column: &str,
    grid: allan::Grid,
    json: bool,
) -> Result<(Vec<f64>, usize)> {
    let (values, skipped) = read_column_with_gaps(path, column)?;
    if let Some(note) = super::options::gaps_note(path, column, skipped).filter(|_| !json) {
        eprintln!("{note}");
    }
    if values.len() < 4 {
        bail!(
            "{}: {} samples are too few: an Allan deviation needs at least 4 (τ = 1/rate needs 2 differences)",
            path.display(),
            values.len()
        );
    }
    // The phase sums N·max|y| and their squares must stay finite, and not underflow.
    if let Err(e) = gyrofx_model::analysis::check_magnitudes(&values) {
        bail!("{}: column {column}, {e}", path.display());
    }
    if grid == allan::Grid::All && values.len() > ALL_TAUS_MAX_SAMPLES {
        usage!(
            "--taus all on {} ({} samples): every factor up to N/2 is a pass over the record, about N²/4 = {:.1e} terms (hours at this size); all takes at most {ALL_TAUS_MAX_SAMPLES} samples: use --taus many (ten per decade) or octave",
            path.display(),
            values.len(),
            (values.len() as f64).powi(2) / 4.0
        );
    }
    Ok((values, skipped))
}

/// The terms in the order of [`noise::Identification`] and [`noise::REPORT_SCALE`]: the name
/// printed, the JSON key and the unit.
const TERMS: [(&str, &str, &str); 5] = [
    ("quantization Q", "quantization_urad", "µrad"),
    ("angle random walk N", "arw_deg_per_sqrt_h", "°/√h"),
    ("bias instability B", "bias_instability_deg_per_h", "°/h"),
    ("rate random walk K", "rrw_deg_per_h_per_sqrt_h", "°/h/√h"),
    ("rate ramp R", "rate_ramp_deg_per_h2", "°/h²"),
];

/// What the analysis gives of one series.
struct Analysis {
    points: Vec<allan::Point>,
    terms: noise::Terms,
    report: noise::Report,
    /// How well the fitted model follows the points it was fitted to.
    fit: noise::FitQuality,
    /// The τ (s) below which the curve does not follow the five terms (the sensor's filtering,
    /// a tone), kept out of the fit.
    filtered_below_tau_s: Option<f64>,
    /// Which terms the curve shows; upper bounds of the others.
    identification: noise::Identification,
    /// The white-noise density, °/s/√Hz: Welch's median over fs/50..fs/5; none on a record
    /// too short for a segment of 8.
    density: Option<f64>,
}

/// The deviation curve (with a progress bar on a terminal), the noise fit, and the spectrum's
/// density, computed on a thread of its own beside the curve.
fn analyse(
    values: &[f64],
    rate: f64,
    kind: allan::Kind,
    grid: allan::Grid,
    path: &Path,
    quiet: bool,
) -> Analysis {
    // Welch with the largest power-of-two segment up to N/8, at most 2048 (half of the
    // clamp's 4096: the power of two at or above the clamped length, halved).
    let segment = (values.len() / 8).clamp(8, 4096).next_power_of_two() / 2;
    let bar = super::progress::bar(1, &format!("allan: {}", path.display()), quiet);
    let (points, density) = std::thread::scope(|scope| {
        let density = scope.spawn(|| {
            (segment >= 8)
                .then(|| gyrofx_model::analysis::spectrum::welch(values, rate, segment.max(8)))
                .and_then(|psd| psd.median_density(rate / 50.0, rate / 5.0))
        });
        let points = allan::curve_reporting(kind, values, rate, grid, &mut |done, total| {
            bar.set_length(total as u64);
            bar.set_position(done as u64);
        });
        (points, density.join().expect("the spectrum does not panic"))
    });
    bar.finish_and_clear();
    // The terms come from the points past the sensor's own filtering at the shortest τ.
    let identified = noise::identify(&points, kind);
    let filtered = identified.filtered;
    let filtered_below_tau_s = (filtered > 0).then(|| points[filtered].tau_s);
    let report = noise::report(&points, &identified.terms, kind);
    Analysis {
        points,
        terms: identified.terms,
        report,
        fit: identified.fit,
        filtered_below_tau_s,
        identification: identified.identification,
        density,
    }
}

/// One analysed series and what it was read from: printed as a table (`Display`) or JSON.
struct Series<'a> {
    path: &'a Path,
    column: &'a str,
    samples: usize,
    skipped: usize,
    rate_hz: f64,
    kind: allan::Kind,
    analysis: Analysis,
}

impl Series<'_> {
    /// The JSON object of `--json` (the fields the guide's noise-analysis page lists).
    fn json(&self) -> serde_json::Value {
        let points = &self.analysis.points;
        serde_json::json!({
            "input": self.path.display().to_string(),
            "column": self.column,
            "samples": self.samples,
            "skipped_empty_cells": self.skipped,
            "rate_hz": self.rate_hz,
            "kind": format!("{:?}", self.kind).to_lowercase(),
            "tau_s": points.iter().map(|p| p.tau_s).collect::<Vec<_>>(),
            "adev": points.iter().map(|p| p.dev).collect::<Vec<_>>(),
            "adev_lo": points.iter().map(|p| p.lo).collect::<Vec<_>>(),
            "adev_hi": points.iter().map(|p| p.hi).collect::<Vec<_>>(),
            "edf": points.iter().map(|p| p.edf).collect::<Vec<_>>(),
            "noise_alpha": points.iter().map(|p| p.alpha).collect::<Vec<_>>(),
            "noise": self.analysis.report,
            "fit": self.analysis.fit,
            "filtered_below_tau_s": self.analysis.filtered_below_tau_s,
            "identified": TERMS
                .iter()
                .zip(self.analysis.identification.identified)
                .map(|((_, key, _), shown)| (key.to_string(), serde_json::json!(shown)))
                .collect::<serde_json::Map<_, _>>(),
            "upper_bound": TERMS
                .iter()
                .zip(self.analysis.identification.upper_bound)
                .zip(noise::REPORT_SCALE)
                .map(|(((_, name, _), bound), scale)| {
                    (name.to_string(), serde_json::json!((bound * scale).is_finite().then_some(bound * scale)))
                })
                .collect::<serde_json::Map<_, _>>(),
            "noise_density_dps_per_sqrt_hz": self.analysis.density,
        })
    }
}

/// The table: the curve with its confidence bounds, then the noise terms and the readings.
impl std::fmt::Display for Series<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let Analysis {
            points,
            report,
            density,
            ..
        } = &self.analysis;
        let kind = self.kind;
        writeln!(
            f,
            "{} ({} samples at {} Hz, column {}), {kind:?} deviation",
            self.path.display(),
            self.samples,
            self.rate_hz,
            self.column
        )?;
        writeln!(
            f,
            "{:>12} {:>13} {:>13} {:>13} {:>6} {:>9}",
            "tau (s)", "dev (°/s)", "lo", "hi", "alpha", "edf"
        )?;
        for p in points {
            writeln!(
                f,
                "{:>12.6} {:>13.6e} {:>13.6e} {:>13.6e} {:>6} {:>9.1}",
                p.tau_s, p.dev, p.lo, p.hi, p.alpha, p.edf
            )?;
        }
        writeln!(
            f,
            "noise terms (weighted non-negative fit of the {} variance's model; ±1σ intervals that count the correlation between τ):",
            format!("{kind:?}").to_lowercase()
        )?;
        let id = &self.analysis.identification;
        let estimates = [
            report.quantization_urad,
            report.arw_deg_per_sqrt_h,
            report.bias_instability_deg_per_h,
            report.rrw_deg_per_h_per_sqrt_h,
            report.rate_ramp_deg_per_h2,
        ];
        for (index, ((name, _, unit), e)) in TERMS.iter().zip(estimates).enumerate() {
            if e.value.is_nan() {
                // Only the Hadamard variance's rate ramp.
                writeln!(
                    f,
                    "  {name:<28} {:>12} (the Hadamard variance cancels a rate ramp)",
                    "-"
                )?;
                continue;
            }
            let bound = id.upper_bound[index] * noise::REPORT_SCALE[index];
            let note = if id.identified[index] {
                String::new()
            } else if bound.is_finite() {
                format!("  not shown by the curve: at most {bound:.5e} {unit}")
            } else {
                "  not shown by the curve".to_string()
            };
            writeln!(
                f,
                "  {name:<28} {:>12.5e} [{:.5e}, {:.5e}] {unit}{note}",
                e.value, e.lo, e.hi
            )?;
        }
        writeln!(
            f,
            "  Kalibr: noise density {:.5e} rad/s/√Hz, random walk {:.5e} rad/s²/√Hz",
            report.kalibr_noise_density_rad_per_s_per_sqrt_hz,
            report.kalibr_random_walk_rad_per_s2_per_sqrt_hz
        )?;
        let opt = |v: Option<f64>| v.map(|v| format!("{v:.5e}")).unwrap_or_else(|| "-".into());
        writeln!(
            f,
            "  noise density (Welch, median over fs/50..fs/5): {} °/s/√Hz",
            opt(*density)
        )?;
        writeln!(
            f,
            "  slope readings: N {} °/√h (τ = 1 s), K {} °/h/√h (τ = 3 s), B {:.5e} °/h (min/0.6643), the kind's response divided out",
            opt(report.slope_arw_deg_per_sqrt_h),
            opt(report.slope_rrw_deg_per_h_per_sqrt_h),
            report.slope_bias_instability_deg_per_h
        )?;
        let fit = &self.analysis.fit;
        if let Some(tau) = self.analysis.filtered_below_tau_s {
            writeln!(
                f,
                "  below τ = {tau} s the curve does not follow the five terms (the sensor's filtering bends it, or a tone): those points are kept out of the fit"
            )?;
        }
        writeln!(
            f,
            "  fit: the model lies outside the 1σ band at {} of {} fitted τ; furthest at τ = {} s, model/measured = {:.3}",
            fit.outside_band, fit.points, fit.worst_tau_s, fit.worst_model_over_measured
        )?;
        if fit.model_error > 0.0 {
            writeln!(
                f,
                "  the points scatter about the model by {:.1} % of their variance beyond their own χ² spread: the weights and the intervals include it",
                100.0 * fit.model_error
            )?;
        }
        Ok(())
    }
}

/// The log-log plot of every series with its fitted terms.
fn write_plot(
    path: &Path,
    curves: &[(String, Vec<allan::Point>, noise::Terms)],
    kind: allan::Kind,
) -> Result<()> {
    let series: Vec<gyrofx_lab::plot::AllanSeries> = curves
        .iter()
        .map(|(label, points, terms)| gyrofx_lab::plot::AllanSeries {
            label: label.clone(),
            points,
            terms: Some((terms, kind)),
        })
        .collect();
    let title = match kind {
        allan::Kind::Overlapping => "Overlapping Allan deviation",
        allan::Kind::NonOverlapping => "Allan deviation (non-overlapping)",
        allan::Kind::Modified => "Modified Allan deviation",
        allan::Kind::Hadamard => "Overlapping Hadamard deviation",
    };
    gyrofx_lab::plot::deviation(path, &series, title)?;
    Ok(())
}
