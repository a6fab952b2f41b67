//! `gyrofx design`: the steady-state KF gain for a noise model, quantized to the coefficient
//! width.

use std::process::ExitCode;

use anyhow::Result;

use super::options::number;
use super::usage;

use gyrofx_codegen::report;
use gyrofx_model::fx::{Overflow, Rounding};
use gyrofx_model::kf::design::{design, design_for_bandwidth, Convergence, Method, Noise};
use gyrofx_model::kf::{CoefficientFormat, Plan, Spec};

/// Design the steady-state KF gain and quantize it.
#[derive(clap::Args)]
pub struct Args {
    /// Random-walk intensity of the true rate, (°/s)²/s (sets the bandwidth).
    #[arg(long, allow_negative_numbers = true, conflicts_with = "bandwidth")]
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
    /// Coefficient width, 2..=64 bits (fraction bits chosen per coefficient).
    #[arg(long, default_value_t = 18)]
    coefficient_width: u32,
    /// Print JSON.
    #[arg(long)]
    json: bool,
}

/// Largest `--coefficient-width`: a fixed-point format is at most 64 bits wide.
const MAX_COEFFICIENT_WIDTH: u32 = 64;

/// Refuses, before the design, every value it cannot take: the intensities and the rate must
/// be finite and > 0, the bandwidth in (0, fs/2), the width 2..=64 bits.
fn check_values(
    qw: Option<f64>,
    qb: f64,
    qn: f64,
    fs: f64,
    bandwidth: Option<f64>,
    coefficient_width: u32,
) -> Result<()> {
    let positive = [
        ("--qw", qw),
        ("--qb", Some(qb)),
        ("--qn", Some(qn)),
        ("--fs", Some(fs)),
    ];
    for (flag, value) in positive {
        if let Some(v) = value.filter(|v| !(v.is_finite() && *v > 0.0)) {
            usage!("{flag} {} is not allowed: a finite number > 0", number(v));
        }
    }
    super::options::check_bandwidth(bandwidth, fs)?;
    if !(2..=MAX_COEFFICIENT_WIDTH).contains(&coefficient_width) {
        usage!(
            "--coefficient-width {coefficient_width} is not allowed: 2..={MAX_COEFFICIENT_WIDTH} bits (a sign bit and at least one more)"
        );
    }
    Ok(())
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
    check_values(qw, qb, qn, fs, bandwidth, coefficient_width)?;
    let method: Method = method
        .parse()
        .map_err(|e| super::Usage(format!("--method {method}: {e}")))?;
    let convergence = Convergence::default();
    // Every value of the design comes from the command line: a design that fails is a usage
    // error, named by the flags that made it.
    let flags = match bandwidth {
        Some(bw) => format!("--bandwidth {}", number(bw)),
        None => format!("--qw {}", number(qw.unwrap_or(0.0))),
    };
    let flags = format!(
        "{flags} --qb {} --qn {} --fs {}",
        number(qb),
        number(qn),
        number(fs)
    );
    let refused = |e: gyrofx_model::kf::design::DesignError| {
        super::Usage(format!("{flags} cannot be designed: {e}"))
    };
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
        )
        .map_err(refused)?,
        (None, Some(q_w)) => design(
            Noise {
                q_w,
                q_b: qb,
                q_n: qn,
            },
            fs,
            method,
            convergence,
        )
        .map_err(refused)?,
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
    })
    .map_err(|e| super::Usage(format!("--coefficient-width {coefficient_width}: {e}")))?;
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
