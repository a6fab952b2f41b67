//! `gyrofx loop`: both resonator-level gyros closed by their fixed-point loops, in both modes at
//! a constant input rate, each figure beside SPEC §1.6's closed-form prediction.

use std::path::PathBuf;
use std::process::ExitCode;

use anyhow::Result;
use serde::Serialize;

use gyrofx_model::gyro_loop::closed::FixedHarness;
use gyrofx_model::gyro_loop::figures::{
    characterize_reporting, Characterization, Figure, ModeCharacterization, Procedure, AVERAGES,
};

use gyrofx_lab::plot;
use gyrofx_model::gyro_loop::trace::{switch_trace, TraceSpec};

use super::options::ConfigSource;
use super::usage;

/// Run both gyros' closed loops in both modes and print their figures beside SPEC 1.6's.
///
/// Runs both gyros' closed loops (resonator physics, NCO, PLL, AGC, sense demodulation, CIC,
/// 1/SF) in normal and reverse mode at a constant rate and print, per gyro and mode, the
/// locked drive frequency, drive amplitude, scale factor, bias (the chain's sign convention),
/// quadrature, the sense reference's phase the loop realizes (read from its outputs, beside the
/// phase derived from the plan and its parts) and settling after a switch beside SPEC 1.6's
/// closed forms, the residual bias after reversal (predicted at the realized phases, and at
/// the configured ones), and the fixed loop's nodes that saturated or wrapped (counts; a
/// warning when that clipped the figures). Noise and drift are off unless --noise is given.
#[derive(clap::Args)]
pub struct Args {
    #[command(flatten)]
    source: ConfigSource,
    /// Seconds of output averaged for each figure (the chain rate times this many samples per
    /// mean).
    #[arg(long, default_value_t = 0.2)]
    seconds: f64,
    /// The input rate for the scale factor, °/s (the bias is measured at 0).
    #[arg(long, default_value_t = 100.0)]
    rate_dps: f64,
    /// Thermomechanical and electronic noise and drift as [front_end] says.
    #[arg(long)]
    noise: bool,
    /// Print JSON instead of the table.
    #[arg(long)]
    json: bool,
    /// Refuse (exit 1, nothing printed or plotted) when a quantizer of a fixed loop saturated
    /// or wrapped while the figures were measured; without it that is a warning.
    #[arg(long)]
    strict: bool,
    /// Also plot both gyros across a switch (normal to reverse at t = 0): drive amplitude, NCO
    /// frequency and rate output against time, the re-lock marked (.png or .svg).
    #[arg(long)]
    plot: Option<PathBuf>,
    /// No progress bar (it shows only on a terminal).
    #[arg(long)]
    quiet: bool,
}

/// One gyro's figures.
#[derive(Serialize)]
struct GyroFigures {
    gyro: &'static str,
    #[serde(flatten)]
    figures: Characterization,
}

/// Characterizes both gyros and prints the figures.
/// Chain samples per average for `seconds` at `chain_rate_hz`.
fn average_samples(seconds: f64, chain_rate_hz: f64) -> usize {
    ((seconds * chain_rate_hz).round() as usize).max(1)
}

pub fn run(args: Args) -> Result<ExitCode> {
    if !(args.seconds.is_finite() && args.seconds > 0.0 && args.seconds <= 100.0) {
        usage!(
            "--seconds {} is not allowed: a number of seconds in (0, 100]",
            args.seconds
        );
    }
    if !(args.rate_dps.is_finite() && args.rate_dps != 0.0 && args.rate_dps.abs() <= 1e4) {
        usage!(
            "--rate-dps {} is not allowed: a non-zero rate within ±10000 °/s",
            args.rate_dps
        );
    }
    if let Some(path) = &args.plot {
        super::options::check_plot(path, &[("--config", args.source.config.as_deref())])?;
    }
    let config = args.source.load()?;
    let loops = config.gyro_loops()?;
    let total: usize = loops
        .iter()
        .map(|gyro| average_samples(args.seconds, gyro.plan.chain_rate_hz()) * AVERAGES)
        .sum();
    let bar = super::progress::bar(total as u64, "loop", args.quiet);
    let figures: Vec<GyroFigures> = std::thread::scope(|scope| {
        let handles: Vec<_> = loops
            .iter()
            .enumerate()
            .map(|(index, gyro)| {
                let procedure = Procedure {
                    rate_dps: args.rate_dps,
                    average_samples: average_samples(args.seconds, gyro.plan.chain_rate_hz()),
                    noise: args.noise,
                    seed: config.seed.wrapping_mul(2).wrapping_add(index as u64),
                    ..Procedure::default()
                };
                let bar = &bar;
                scope.spawn(move || {
                    characterize_reporting::<FixedHarness>(
                        &gyro.plan,
                        &gyro.params,
                        &gyro.front_end,
                        &procedure,
                        &|n| bar.inc(n as u64),
                    )
                    .map(|figures| GyroFigures {
                        gyro: gyro.name,
                        figures,
                    })
                })
            })
            .collect();
        handles
            .into_iter()
            .map(|h| h.join().expect("the loop simulation does not panic"))
            .collect::<std::result::Result<_, _>>()
    })?;
    bar.finish_and_clear();
    if let Some(clipped) = clipped_figures(&figures) {
        if args.strict {
            anyhow::bail!("--strict: {clipped}; nothing printed (choose wider [loop] formats or settings for the nodes named, loop.output_format together with kf.input_format, or a resonator within range; or drop --strict to see the clipped figures)");
        }
        eprintln!("warning: {clipped}: those figures are clipped and not trustworthy (--strict makes this an error)");
    }
    if args.json {
        println!("{}", serde_json::to_string_pretty(&figures)?);
    } else {
        print_table(&figures);
    }
    if let Some(path) = &args.plot {
        let traces = std::thread::scope(|scope| {
            let handles: Vec<_> = loops
                .iter()
                .enumerate()
                .map(|(index, gyro)| {
                    let spec = TraceSpec {
                        rate_dps: args.rate_dps,
                        noise: args.noise,
                        seed: config.seed.wrapping_mul(2).wrapping_add(index as u64),
                        ..TraceSpec::default()
                    };
                    scope.spawn(move || {
                        switch_trace(&gyro.plan, &gyro.params, &gyro.front_end, &spec)
                    })
                })
                .collect();
            handles
                .into_iter()
                .map(|h| h.join().expect("the loop simulation does not panic"))
                .collect::<std::result::Result<Vec<_>, _>>()
        })?;
        let series: Vec<plot::LoopTrace> = loops
            .iter()
            .zip(&traces)
            .map(|(gyro, points)| plot::LoopTrace {
                label: format!("gyro {}", gyro.name),
                points,
            })
            .collect();
        plot::gyro_loop(path, &series)?;
        eprintln!("wrote {}", path.display());
    }
    Ok(ExitCode::SUCCESS)
}

/// The fixed loops' saturations while figures were measured, gyro by gyro and mode by mode,
/// as one sentence; `None` when there were none.
fn clipped_figures(figures: &[GyroFigures]) -> Option<String> {
    let clipped: Vec<String> = figures
        .iter()
        .flat_map(|gyro| {
            [&gyro.figures.normal, &gyro.figures.reverse]
                .into_iter()
                .filter(|mode| mode.saturations.total() > 0)
                .map(|mode| {
                    format!(
                        "gyro {} {}: {}",
                        gyro.gyro,
                        mode.mode,
                        mode.saturations.summary()
                    )
                })
        })
        .collect();
    if clipped.is_empty() {
        None
    } else {
        Some(format!(
            "the fixed loop saturated or wrapped while the figures were measured (counts per node): {}",
            clipped.join("; ")
        ))
    }
}

fn print_table(figures: &[GyroFigures]) {
    println!(
        "{:<5} {:<8} {:<19} {:>16} {:>16} {:>12} {:>10}",
        "gyro", "mode", "figure", "measured", "predicted", "difference", "relative"
    );
    for gyro in figures {
        let modes: [&ModeCharacterization; 2] = [&gyro.figures.normal, &gyro.figures.reverse];
        for mode in modes {
            let rows: [(&str, &Figure, f64); 8] = [
                ("drive_frequency_hz", &mode.drive_frequency_hz, 1.0),
                ("drive_amplitude_um", &mode.drive_amplitude_m, 1e6),
                ("scale_factor", &mode.scale_factor, 1.0),
                ("bias_dps", &mode.bias_dps, 1.0),
                ("quadrature_dps", &mode.quadrature_dps, 1.0),
                ("reference_phase_deg", &mode.reference_phase_deg, 1.0),
                ("settling_ms", &mode.settling_ms, 1.0),
                ("rate_settling_ms", &mode.rate_settling_ms, 1.0),
            ];
            for (name, figure, unit) in rows {
                print_row(gyro.gyro, mode.mode, name, figure, unit);
                if name == "reference_phase_deg" {
                    print_phase_parts(gyro.gyro, mode);
                }
            }
            print_saturations(gyro.gyro, mode);
        }
        print_row(
            gyro.gyro,
            "both",
            "residual_bias_dps",
            &gyro.figures.residual_bias_dps,
            1.0,
        );
        let configured = Figure {
            measured: gyro.figures.residual_bias_dps.measured,
            predicted: gyro.figures.residual_configured_phase_dps,
        };
        print_row(gyro.gyro, "both", "residual_configured", &configured, 1.0);
    }
}

/// How the derived reference phase of `mode` is made up: the configured phase and the parts
/// the loop adds (`gyrofx_model::gyro_loop::realized_phase`), deg.
fn print_phase_parts(gyro: &str, mode: &ModeCharacterization) {
    let parts = &mode.realized_phase;
    println!(
        "{gyro:<5} {:<8} {:<19} configured {:+.6}, locked frequency {:+.6}, PLL modulation {:+.6}, offset word {:+.1e}{}; sense gain {:.6}",
        mode.mode,
        "phase_parts_deg",
        parts.configured_deg,
        parts.locked_frequency_deg,
        parts.pll_modulation_deg,
        parts.offset_word_deg,
        if parts.trim_deg == 0.0 {
            String::new()
        } else {
            format!(", trim {:+.6}", parts.trim_deg)
        },
        parts.gain
    );
}

/// The nodes of `mode`'s fixed loop that saturated or wrapped, with their counts: while its
/// figures were measured (always shown, `none` when clean), and during the start-up or the
/// switch into it (shown only when there were any; the chain blanks that stretch).
fn print_saturations(gyro: &str, mode: &ModeCharacterization) {
    println!(
        "{gyro:<5} {:<8} {:<19} {}",
        mode.mode,
        "saturations",
        mode.saturations.summary()
    );
    if mode.transient_saturations.total() > 0 {
        println!(
            "{gyro:<5} {:<8} {:<19} {} (start-up or switch transient: blanked in the chain, only rate_settling_ms is measured there)",
            mode.mode,
            "transient_saturations",
            mode.transient_saturations.summary()
        );
    }
}

fn print_row(gyro: &str, mode: &str, name: &str, figure: &Figure, unit: f64) {
    let (measured, predicted) = (figure.measured * unit, figure.predicted * unit);
    let difference = measured - predicted;
    let relative = if predicted != 0.0 {
        format!("{:+.3} %", 100.0 * difference / predicted.abs())
    } else {
        "-".to_string()
    };
    println!(
        "{gyro:<5} {mode:<8} {name:<19} {measured:>16.6} {predicted:>16.6} {difference:>+12.3e} {relative:>10}"
    );
}
