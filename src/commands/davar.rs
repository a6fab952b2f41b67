//! `gyrofx davar`: the dynamic Allan deviation of a record, over a fixed or PID-adapted
//! sliding window, with the noise coefficients over time and the disturbances.

use std::path::PathBuf;
use std::process::ExitCode;

use anyhow::Result;

use super::usage;

use gyrofx_model::analysis::davar::{coefficients, davar_reporting, disturbances, Pid, Window};

use super::options::{CsvColumn, SampleRate};

/// Dynamic Allan deviation of a record: noise over time (paper 002).
///
/// The ADEV of a window sliding along the record, fixed or PID-adapted, with the noise
/// coefficients over time and the disturbances found.
#[derive(clap::Args)]
pub struct Args {
    #[command(flatten)]
    csv: CsvColumn,
    #[command(flatten)]
    rate: SampleRate,
    /// Window length, samples (the longest window with --adaptive).
    #[arg(long, default_value_t = 3001)]
    window: usize,
    /// Adapt the window with the PID controller.
    #[arg(long)]
    adaptive: bool,
    /// Shortest adaptive window, samples (default: window / 10; needs --adaptive).
    #[arg(long, requires = "adaptive")]
    min_window: Option<usize>,
    /// PID proportional gain, samples per unit of the deviation index (default: window / 25;
    /// needs --adaptive).
    #[arg(long, allow_negative_numbers = true, requires = "adaptive")]
    kp: Option<f64>,
    /// PID integral gain, samples per unit of the summed deviation index (default: window / 50;
    /// needs --adaptive).
    #[arg(long, allow_negative_numbers = true, requires = "adaptive")]
    ki: Option<f64>,
    /// PID derivative gain, samples per unit of the index's change (default: 0; needs
    /// --adaptive).
    #[arg(long, allow_negative_numbers = true, requires = "adaptive")]
    kd: Option<f64>,
    /// Samples between window centres, 1 up to the record's length (default: window / 20).
    #[arg(long)]
    step: Option<usize>,
    /// Print JSON.
    #[arg(long)]
    json: bool,
    /// Write the heatmap and the coefficients over time (.png or .svg).
    #[arg(long)]
    plot: Option<PathBuf>,
    /// No progress bar (it shows only on a terminal).
    #[arg(long)]
    quiet: bool,
}

/// Prints the windows' noise coefficients and the disturbances (a table, or JSON), and writes
/// the plot if asked.
pub fn run(args: Args) -> Result<ExitCode> {
    let Args {
        csv,
        rate,
        window,
        adaptive,
        min_window,
        kp,
        ki,
        kd,
        step,
        json,
        plot,
        quiet,
    } = args;
    let rate = rate.hz()?;
    if let Some(path) = &plot {
        super::options::check_plot(path, &[("--input", Some(&csv.input))])?;
    }
    for (name, gain) in [("--kp", kp), ("--ki", ki), ("--kd", kd)] {
        if let Some(g) = gain.filter(|g| !g.is_finite()) {
            usage!("{name} {g} is not allowed: a PID gain is a finite number");
        }
    }
    let column = csv.column()?;
    let (values, skipped) = csv.read_with_gaps()?;
    if let Some(note) = super::options::gaps_note(&csv.input, &column, skipped) {
        eprintln!("{note}");
    }
    // Beyond these the fixed-point sums overflow, or the squares underflow to zero deviations.
    gyrofx_model::analysis::check_magnitudes(&values)
        .map_err(|e| anyhow::anyhow!("{}, column {column}: {e}", csv.input.display()))?;
    if window < 4 || window > values.len() {
        usage!(
            "--window {window} is not allowed: it must be 4..={} samples (the record's length)",
            values.len()
        );
    }
    let min = min_window.unwrap_or((window / 10).max(4));
    if adaptive && !(4..=window).contains(&min) {
        usage!("--min-window {min} is not allowed: it must be 4..={window}");
    }
    let step = step.unwrap_or((window / 20).max(1));
    if step == 0 || step > values.len() {
        usage!(
            "--step {step} is not allowed: windows move by 1..={} samples (the record's length)",
            values.len()
        );
    }
    let mode = if adaptive {
        Window::Adaptive(Pid {
            min,
            max: window,
            kp: kp.unwrap_or(window as f64 / 25.0),
            ki: ki.unwrap_or(window as f64 / 50.0),
            kd: kd.unwrap_or(0.0),
        })
    } else {
        Window::Fixed(window)
    };
    let bar = super::progress::bar(values.len() as u64, "davar", quiet);
    let d = davar_reporting(&values, rate, mode, step, &mut |done, _| {
        bar.set_position(done as u64);
    });
    bar.finish_and_clear();
    let c = coefficients(&d);
    let runs = disturbances(&d, 2.0);
    if let Some(path) = &plot {
        gyrofx_lab::plot::davar(path, &d, &c)?;
        if !json {
            println!("plot: {}", path.display());
        }
    }
    if json {
        let value = serde_json::json!({
            "input": csv.input.display().to_string(),
            "column": column,
            "samples": values.len(),
            "skipped_empty_cells": skipped,
            "rate_hz": rate,
            "adaptive": adaptive,
            "davar": d,
            "coefficients": c,
            "disturbances": runs.iter().map(|(a, b)| serde_json::json!({"start_s": a, "end_s": b})).collect::<Vec<_>>(),
        });
        println!("{}", serde_json::to_string_pretty(&value)?);
    } else {
        println!(
            "{}: {} windows of {} samples{} every {step} samples; tau {} .. {} s",
            csv.input.display(),
            d.time_s.len(),
            window,
            if adaptive {
                format!(" (adaptive, >= {min})")
            } else {
                String::new()
            },
            d.tau_s.first().copied().unwrap_or(0.0),
            d.tau_s.last().copied().unwrap_or(0.0)
        );
        let show = d.time_s.len().div_ceil(20).max(1);
        println!(
            "{:>10} {:>7} {:>12} {:>12} {:>12}",
            "time (s)", "window", "N (°/√h)", "B (°/h)", "K (°/h/√h)"
        );
        for i in (0..d.time_s.len()).step_by(show) {
            println!(
                "{:>10.2} {:>7} {:>12.4e} {:>12.4e} {:>12.4e}",
                d.time_s[i],
                d.window[i],
                c.arw_deg_per_sqrt_h[i],
                c.bias_instability_deg_per_h[i],
                c.rrw_deg_per_h_per_sqrt_h[i]
            );
        }
        if runs.is_empty() {
            println!("no disturbance (shortest-tau deviation never above 2x its median)");
        }
        for (a, b) in runs {
            println!("disturbance from {a:.2} s to {b:.2} s");
        }
    }
    Ok(ExitCode::SUCCESS)
}
