//! `gyrofx design`: the steady-state KF gain for a noise model, quantized to the coefficient
//! width.

use std::process::ExitCode;

use anyhow::Result;

use super::usage;

use gyrofx_codegen::report;
use gyrofx_model::fx::{Overflow, Rounding};
use gyrofx_model::kf::design::{design, design_for_bandwidth, Convergence, Method, Noise};
use gyrofx_model::kf::{CoefficientFormat, Plan, Spec};

/// Design the steady-state KF gain and quantize it.
#[derive(clap::Args)]
pub struct Args {
    /// Random-walk intensity of the true rate, (°/s)²/s (sets the bandwidth).
    #[arg(long, allow_negative_numbers = true)]
    qw: Option<f64>,
    /// Rate-random-walk intensity of the bias, (°/s)²/s (RRW²).
    #[arg(long, allow_negative_numbers = true)]
    qb: f64,
    /// White-noise intensity, (°/s)²·s (ARW² with ARW in °/√s).
    #[arg(long, allow_negative_numbers = true)]
    qn: f64,
    /// Sample rate, Hz.
    #[arg(long, allow_negative_numbers = true)]
    fs: f64,
    /// Design for this −3 dB bandwidth (Hz) instead of --qw.
    #[arg(long, allow_negative_numbers = true)]
    bandwidth: Option<f64>,
    /// Discretisation: direct or paper.
    #[arg(long, default_value = "direct")]
    method: String,
    /// Coefficient width, bits (fraction bits chosen per coefficient).
    #[arg(long, default_value_t = 18)]
    coefficient_width: u32,
    /// Print JSON.
    #[arg(long)]
    json: bool,
}

/// Prints the gain, the bandwidth and every quantized coefficient with its error (text, or
/// JSON).
pub fn run(args: Args) -> Result<ExitCode> {
    let Args {
        qw,
        qb,
        qn,
        fs,
        bandwidth,
        method,
        coefficient_width,
        json,
    } = args;
    let method: Method = method.parse()?;
    let convergence = Convergence::default();
    let designed = match (bandwidth, qw) {
        (Some(bw), _) => design_for_bandwidth(
            bw,
            Noise {
                q_w: 0.0,
                q_b: qb,
                q_n: qn,
            },
            fs,
            method,
            convergence,
        )?,
        (None, Some(q_w)) => design(
            Noise {
                q_w,
                q_b: qb,
                q_n: qn,
            },
            fs,
            method,
            convergence,
        )?,
        (None, None) => usage!("give --qw (°/s)²/s or --bandwidth HZ"),
    };
    let label = match bandwidth {
        Some(bw) => format!("{bw} Hz"),
        None => "design".to_string(),
    };
    let plan = Plan::new(&Spec {
        input: "s24.14".parse()?,
        state: "s36.26".parse()?,
        output: "s24.14".parse()?,
        coefficients: [CoefficientFormat::Auto {
            width: coefficient_width,
        }; 2],
        rounding: Rounding::Nearest,
        overflow: Overflow::Saturate,
        gains: vec![designed.g],
        labels: vec![label],
    })?;
    let summary = &report::designs(std::slice::from_ref(&designed), &plan)[0];
    let coefficients = report::coefficients(&plan);
    if json {
        let mut value = serde_json::to_value(summary)?;
        value["coefficients"] = serde_json::to_value(&coefficients)?;
        println!("{}", serde_json::to_string_pretty(&value)?);
    } else {
        println!(
            "method {}, fs {} Hz, q_w {:e}, q_b {:e}, q_n {:e}",
            summary.method, fs, summary.q_w, summary.q_b, summary.q_n
        );
        println!(
            "K = [{:e}, {:e}] after {} iterations",
            summary.k[0], summary.k[1], summary.iterations
        );
        println!("g = [{:e}, {:e}]", summary.g[0], summary.g[1]);
        match summary.bandwidth_hz {
            Some(bw) => println!("bandwidth {bw} Hz (-3 dB), DC gain {}", summary.dc_gain),
            None => println!("no -3 dB point below Nyquist, DC gain {}", summary.dc_gain),
        }
        for c in &coefficients {
            println!(
                "{} = {:e} -> {} code {} (0x{}) = {:e}, error {:e}",
                c.name, c.value, c.format, c.code, c.hex, c.quantized, c.error
            );
        }
        println!(
            "eigenvalues of quantized A: {} and {}",
            summary.eigenvalues[0], summary.eigenvalues[1]
        );
    }
    Ok(ExitCode::SUCCESS)
}
