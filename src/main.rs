//! gyrofx: the command line. Parsing here, work in gyrofx-model and gyrofx-codegen.

use std::path::{Path, PathBuf};
use std::process::ExitCode;

use anyhow::{bail, Context, Result};
use clap::{Parser, Subcommand};

use gyrofx_codegen::config::{Config, DEFAULT_TOML};
use gyrofx_codegen::generate::{generate, provenance, Output};
use gyrofx_codegen::input::{read_column, read_column_with_gaps};
use gyrofx_codegen::job::{design_bandwidths, plan_for, Job};
use gyrofx_codegen::junit;
use gyrofx_codegen::report;
use gyrofx_codegen::reproduce;
use gyrofx_codegen::simulate::{self, Simulator};
use gyrofx_model::fx::{from_f64, Overflow, Rounding};
use gyrofx_model::kf::design::{design, design_for_bandwidth, Convergence, Method, Noise};
use gyrofx_model::kf::{CoefficientFormat, FixedKf, FloatKf, Plan, Spec};

#[derive(Parser)]
#[command(
    name = "gyrofx",
    version,
    about = "Bit-accurate fixed-point model, vector and testbench generator for a MEMS-gyro FPGA signal chain"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Allan deviation of rate records (°/s) with 1σ confidence intervals, and the five noise
    /// terms fitted to it.
    Allan {
        /// CSV file(s) with a header line; `#` lines are skipped (gyrofx's CSVs work as is).
        #[arg(long, required = true)]
        input: Vec<PathBuf>,
        /// Column(s) of rates in °/s; each input × column is one series.
        #[arg(long, default_value = "rate_dps")]
        column: Vec<String>,
        /// Sample rate, Hz.
        #[arg(long, allow_negative_numbers = true)]
        rate: f64,
        /// Averaging times: octave, decade or all.
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
    },
    /// AR(1..p) models of a record by Yule–Walker (Levinson–Durbin), each with its AIC, and the
    /// order AIC picks (paper 003).
    Ar {
        /// CSV file with a header line; `#` lines and empty cells are skipped.
        #[arg(long)]
        input: PathBuf,
        /// Column to model.
        #[arg(long, default_value = "rate_dps")]
        column: String,
        /// Largest order.
        #[arg(long, default_value_t = 3)]
        max_order: usize,
        /// Print JSON.
        #[arg(long)]
        json: bool,
    },
    /// Dynamic Allan deviation: the ADEV of a window sliding along the record, fixed or
    /// PID-adapted (paper 002), with the noise coefficients over time and the disturbances.
    Davar {
        /// CSV file with a header line.
        #[arg(long)]
        input: PathBuf,
        /// Column of rates in °/s.
        #[arg(long, default_value = "rate_dps")]
        column: String,
        /// Sample rate, Hz.
        #[arg(long, allow_negative_numbers = true)]
        rate: f64,
        /// Window length, samples (the longest window with --adaptive).
        #[arg(long, default_value_t = 3001)]
        window: usize,
        /// Adapt the window with the PID controller.
        #[arg(long)]
        adaptive: bool,
        /// Shortest adaptive window, samples (default: window / 10).
        #[arg(long)]
        min_window: Option<usize>,
        /// PID gains, samples per unit of the deviation index (defaults: window/25, window/50, 0).
        #[arg(long, allow_negative_numbers = true)]
        kp: Option<f64>,
        #[arg(long, allow_negative_numbers = true)]
        ki: Option<f64>,
        #[arg(long, allow_negative_numbers = true)]
        kd: Option<f64>,
        /// Samples between window centres (default: window / 20).
        #[arg(long)]
        step: Option<usize>,
        /// Print JSON.
        #[arg(long)]
        json: bool,
        /// Write the heatmap and the coefficients over time (.png or .svg).
        #[arg(long)]
        plot: Option<PathBuf>,
    },
    /// Print the annotated default config, or a preset (an overlay of it).
    Init {
        /// gu2019 (paper 004), xue2015 (paper 000) or mpu6050.
        #[arg(long)]
        preset: Option<String>,
    },
    /// Design the steady-state KF gain and quantize it.
    Design {
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
    },
    /// Write the verification package (vectors, ROM, testbench, RTL, manifest) atomically.
    Generate {
        /// Output folder (replaced only if empty or a previous gyrofx output).
        #[arg(long)]
        out: PathBuf,
        /// Config file (TOML, overlays the embedded default and the preset).
        #[arg(long)]
        config: Option<PathBuf>,
        /// Start from a preset: gu2019, xue2015, mpu6050.
        #[arg(long)]
        preset: Option<String>,
        /// Samples of the chain run (overrides the config).
        #[arg(long)]
        samples: Option<usize>,
        /// Seed (overrides the config).
        #[arg(long)]
        seed: Option<u64>,
    },
    /// Synthesize the chain with the config's widths in yosys (generic and Xilinx 7-series):
    /// fails on a latch, an undriven or multiply-driven net or a missing module; writes the
    /// resource report, scripts and logs atomically.
    Synth {
        /// Output folder (replaced only if empty or a previous gyrofx output).
        #[arg(long)]
        out: PathBuf,
        /// Config file (TOML, overlays the embedded default and the preset).
        #[arg(long)]
        config: Option<PathBuf>,
        /// Start from a preset: gu2019, xue2015, mpu6050.
        #[arg(long)]
        preset: Option<String>,
    },
    /// Run a generated package's testbench in a simulator; non-zero exit on failure.
    Verify {
        /// The package folder.
        #[arg(long)]
        out: PathBuf,
        /// Simulators, comma-separated: iverilog, verilator, ghdl (the VHDL RTL), or all.
        #[arg(long, default_value = "iverilog")]
        sim: String,
        /// Latency mask: samples not compared at the start and from every reset sample on.
        #[arg(long, default_value_t = 0)]
        mask: u64,
        /// Mismatches printed per testbench.
        #[arg(long, default_value_t = 10)]
        max_reported: u64,
        /// Stop a testbench at this many mismatches (0: never).
        #[arg(long, default_value_t = 0)]
        max_mismatches: u64,
        /// Write a VCD per testbench (tb_<module>.vcd in each block folder).
        #[arg(long)]
        waves: bool,
        /// Write a JUnit XML summary here (one testsuite per simulator, one testcase per block).
        #[arg(long)]
        junit: Option<PathBuf>,
    },
    /// Run recorded rate data (°/s) through the bit-accurate KF and its float model.
    Filter {
        /// CSV file with a header line.
        #[arg(long)]
        input: PathBuf,
        /// Column of rates in °/s.
        #[arg(long, default_value = "rate_dps")]
        column: String,
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
    },
    /// Run a paper's pipeline on simulated data and print its tables beside gyrofx's, with
    /// the differences explained (markdown): 000, 002, 003, 004.
    Reproduce {
        /// The paper: 000, 002, 003 or 004.
        #[arg(long)]
        paper: String,
        /// Samples to simulate (default: the paper's record length).
        #[arg(long)]
        samples: Option<usize>,
        /// Seed of the simulation.
        #[arg(long, default_value_t = 1)]
        seed: u64,
        /// Also write report.md, allan.png (and davar.png for 002) into this folder.
        #[arg(long)]
        out: Option<PathBuf>,
    },
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    match run(cli) {
        Ok(code) => code,
        Err(e) => {
            eprintln!("error: {e:#}");
            ExitCode::FAILURE
        }
    }
}

fn run(cli: Cli) -> Result<ExitCode> {
    match cli.command {
        Command::Allan {
            input,
            column,
            rate,
            taus,
            kind,
            json,
            plot,
        } => run_allan(&input, &column, rate, &taus, &kind, json, plot.as_deref()),
        Command::Ar {
            input,
            column,
            max_order,
            json,
        } => run_ar(&input, &column, max_order, json),
        Command::Reproduce {
            paper,
            samples,
            seed,
            out,
        } => run_reproduce(&paper, samples, seed, out.as_deref()),
        Command::Davar {
            input,
            column,
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
        } => run_davar(
            &input,
            &column,
            rate,
            window,
            adaptive,
            min_window,
            [kp, ki, kd],
            step,
            json,
            plot.as_deref(),
        ),
        Command::Init { preset } => {
            match preset {
                Some(name) => print!("{}", gyrofx_codegen::config::preset(&name)?),
                None => print!("{DEFAULT_TOML}"),
            }
            Ok(ExitCode::SUCCESS)
        }
        Command::Design {
            qw,
            qb,
            qn,
            fs,
            bandwidth,
            method,
            coefficient_width,
            json,
        } => run_design(qw, qb, qn, fs, bandwidth, &method, coefficient_width, json),
        Command::Generate {
            out,
            config,
            preset,
            samples,
            seed,
        } => run_generate(&out, preset.as_deref(), config.as_deref(), samples, seed),
        Command::Verify {
            out,
            sim,
            mask,
            max_reported,
            max_mismatches,
            waves,
            junit,
        } => run_verify(
            &out,
            &sim,
            &simulate::Options {
                mask,
                max_reported,
                max_mismatches,
                waves,
            },
            junit.as_deref(),
        ),
        Command::Synth {
            out,
            config,
            preset,
        } => run_synth(&out, preset.as_deref(), config.as_deref()),
        Command::Filter {
            input,
            column,
            fs,
            bandwidth,
            config,
            output,
        } => run_filter(&input, &column, fs, bandwidth, config.as_deref(), &output),
    }
}

fn load_config(path: Option<&Path>) -> Result<Config> {
    Ok(match path {
        Some(p) => Config::from_file(p)?,
        None => Config::embedded(),
    })
}

#[allow(clippy::too_many_arguments)]
fn run_design(
    qw: Option<f64>,
    qb: f64,
    qn: f64,
    fs: f64,
    bandwidth: Option<f64>,
    method: &str,
    coefficient_width: u32,
    json: bool,
) -> Result<ExitCode> {
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
        (None, None) => bail!("give --qw (°/s)²/s or --bandwidth HZ"),
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

fn run_synth(out: &Path, preset: Option<&str>, config_path: Option<&Path>) -> Result<ExitCode> {
    let config = Config::from_preset_and_file(preset, config_path)?;
    let job = Job::new(config)?;
    let provenance = provenance(&job, Output::Synthesis, preset, config_path);
    let resources = gyrofx_codegen::synth::synthesize(&job, out, &provenance)?;
    let (g, x) = (&resources.generic, &resources.xilinx);
    println!(
        "synthesis check passed: {}; report in {}",
        gyrofx_codegen::synth::TOP,
        out.join("report.md").display()
    );
    println!(
        "generic: {} cells, {} flip-flops, {} multipliers",
        g.cells, g.flip_flops, g.multipliers
    );
    println!(
        "xilinx 7-series: {} LUTs, {} flip-flops, {} DSP48E1, {} block RAM",
        x.luts, x.flip_flops, x.dsp48, x.block_rams
    );
    Ok(ExitCode::SUCCESS)
}

fn run_generate(
    out: &Path,
    preset: Option<&str>,
    config_path: Option<&Path>,
    samples: Option<usize>,
    seed: Option<u64>,
) -> Result<ExitCode> {
    let mut config = Config::from_preset_and_file(preset, config_path)?;
    if let Some(n) = samples {
        config.samples = n;
    }
    if let Some(s) = seed {
        config.seed = s;
    }
    let job = Job::new(config)?;
    let bar = indicatif::ProgressBar::new_spinner();
    let long = job.config.samples >= 1_000_000;
    let provenance = provenance(&job, Output::Package, preset, config_path);
    let summary = generate(&job, out, &provenance, &mut |phase| {
        if long {
            bar.set_message(format!("generate: {phase}"));
            bar.tick();
        }
    })?;
    bar.finish_and_clear();
    let run = &summary.run;
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
    for (what, s) in [
        ("kf", &run.kf_stats),
        ("chain", &run.chain_stats),
        ("bias", &run.bias_stats),
    ] {
        println!(
            "{what} fixed vs float: max {:.3} LSB, rms {:.3} LSB, bound {:.3} LSB; vs ideal: max {:.3} LSB, SQNR {:.1} dB",
            s.max_lsb, s.rms_lsb, s.bound_lsb, s.ideal_max_lsb, s.sqnr_db
        );
    }
    let o = &run.overflows;
    println!(
        "overflows: ADC {:?}, means {:?}, biases {:?}, calibrated {:?}, combined {}, KF x1 {} x2 {} rate_hat {} (directed segment: x1 {} x2 {} rate_hat {})",
        o.adc, o.estimator.mean, o.estimator.bias, o.estimator.calibrated, o.estimator.combined,
        o.kf_chain.x1, o.kf_chain.x2, o.kf_chain.rate_hat, o.kf_directed.x1, o.kf_directed.x2, o.kf_directed.rate_hat
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

fn run_ar(input: &Path, column: &str, max_order: usize, json: bool) -> Result<ExitCode> {
    use gyrofx_model::analysis::ar;
    let (values, _) = read_column_with_gaps(input, column)?;
    let models = ar::fit_orders(&values, max_order)
        .map_err(|e| anyhow::anyhow!("{}, column {column}: {e}", input.display()))?;
    let chosen = ar::select_by_aic(&models).order;
    if json {
        let value = serde_json::json!({
            "samples": values.len(),
            "aic_order": chosen,
            "models": models.iter().map(|m| serde_json::json!({
                "order": m.order,
                "coefficients": m.coefficients,
                "noise_variance": m.noise_variance,
                "aic": m.aic,
            })).collect::<Vec<_>>(),
        });
        println!("{}", serde_json::to_string_pretty(&value)?);
    } else {
        println!(
            "{} samples of {column}; AIC = N ln(sigma_a^2) + 2n",
            values.len()
        );
        println!("order  sigma_a^2      AIC            coefficients (phi1..phip)");
        for m in &models {
            let phi: Vec<String> = m.coefficients.iter().map(|c| format!("{c:+.5}")).collect();
            let mark = if m.order == chosen { "  <- AIC" } else { "" };
            println!(
                "{:>5}  {:<13.6e}  {:<13.4}  {}{mark}",
                m.order,
                m.noise_variance,
                m.aic,
                phi.join(" ")
            );
        }
    }
    Ok(ExitCode::SUCCESS)
}

fn run_reproduce(
    paper: &str,
    samples: Option<usize>,
    seed: u64,
    out: Option<&Path>,
) -> Result<ExitCode> {
    let (report, curves, davar) = match paper {
        "000" => {
            let p = reproduce::paper_000(samples.unwrap_or(reproduce::SAMPLES_000), seed)?;
            (p.markdown(), p.curves, None)
        }
        "002" => {
            let p = reproduce::paper_002(samples.unwrap_or(reproduce::SAMPLES_002), seed)?;
            (p.markdown(), Vec::new(), Some(p.adaptive))
        }
        "003" => {
            let p = reproduce::paper_003(samples.unwrap_or(reproduce::SAMPLES), seed)?;
            (p.markdown(), p.curves, None)
        }
        "004" => {
            let p = reproduce::paper_004(samples.unwrap_or(reproduce::SAMPLES_004), seed)?;
            (p.markdown(), p.curves, None)
        }
        other => bail!("--paper {other:?} is not one of the papers: use 000, 002, 003 or 004"),
    };
    print!("{report}");
    if let Some(folder) = out {
        let davar = davar.as_ref().map(|(d, c)| (d, c));
        let files = reproduce::write(folder, paper, seed, &report, &curves, davar)?;
        eprintln!("wrote {} in {}", files.join(", "), folder.display());
    }
    Ok(ExitCode::SUCCESS)
}

fn run_verify(
    out: &Path,
    sim: &str,
    options: &simulate::Options,
    junit_path: Option<&Path>,
) -> Result<ExitCode> {
    let simulators: Vec<Simulator> = if sim == "all" {
        Simulator::ALL.to_vec()
    } else {
        sim.split(',')
            .map(|name| name.trim().parse())
            .collect::<std::result::Result<_, _>>()?
    };
    let mut outcomes = Vec::with_capacity(simulators.len());
    for simulator in simulators {
        let outcome = simulate::run(out, simulator, options)?;
        for line in outcome.report() {
            println!("{line}");
        }
        for block in outcome
            .blocks
            .iter()
            .filter(|b| !b.passed && b.report.is_empty())
        {
            eprintln!("{}", block.log);
        }
        if outcome.passed() {
            println!("{}: passed", simulator.name());
        } else {
            eprintln!("{}: FAILED", simulator.name());
        }
        outcomes.push(outcome);
    }
    if let Some(path) = junit_path {
        std::fs::write(path, junit::report(&outcomes))
            .with_context(|| format!("cannot write the JUnit summary {}", path.display()))?;
    }
    if outcomes.iter().all(simulate::Outcome::passed) {
        Ok(ExitCode::SUCCESS)
    } else {
        Ok(ExitCode::FAILURE)
    }
}

fn run_filter(
    input: &Path,
    column: &str,
    fs: f64,
    bandwidth: Option<f64>,
    config_path: Option<&Path>,
    output: &Path,
) -> Result<ExitCode> {
    let mut config = load_config(config_path)?;
    config.stimulus.fs_hz = fs;
    if let Some(bw) = bandwidth {
        config.kf.bandwidths_hz = vec![bw];
    }
    let settings = config.validate()?.kf;
    let designs = design_bandwidths(
        &settings,
        fs,
        config.kf.arw_deg_per_sqrt_h,
        config.kf.rrw_deg_per_h_per_sqrt_h,
    )?;
    let plan = plan_for(&settings, &designs)?;
    let values = read_column(input, column)?;
    let mut fixed = FixedKf::new(&plan);
    let mut float = FloatKf::new(plan.gains.clone());
    let mut text = String::with_capacity(values.len() * 80);
    text.push_str("sample,z_dps,z_code,rate_code,rate_dps,float_rate_dps\n");
    let mut saturated = 0u64;
    for (k, value) in values.iter().enumerate() {
        let q = from_f64(*value, plan.input, Rounding::Nearest, Overflow::Saturate)?;
        saturated += u64::from(q.overflowed);
        let z = q.code as i64;
        let rate = fixed.step(z, 0);
        let reference = float.step(*value, 0);
        text.push_str(&format!(
            "{k},{},{z},{rate},{},{reference}\n",
            plan.input.to_f64(q.code),
            plan.output.to_f64(i128::from(rate))
        ));
    }
    let folder = match output.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => Path::new("."),
    };
    let mut staged = tempfile::NamedTempFile::new_in(folder).with_context(|| {
        format!(
            "output {}: cannot create a file in {}",
            output.display(),
            folder.display()
        )
    })?;
    std::io::Write::write_all(&mut staged, text.as_bytes())
        .with_context(|| format!("output {}", output.display()))?;
    staged
        .persist(output)
        .with_context(|| format!("output {}: cannot move into place", output.display()))?;
    let o = fixed.overflow_counts();
    println!(
        "filtered {} samples at {} Hz, bandwidth {} Hz -> {}; ADC saturations {}, overflows x1 {} x2 {} rate_hat {}",
        values.len(),
        fs,
        settings.bandwidths_hz[0],
        output.display(),
        saturated,
        o.x1,
        o.x2,
        o.rate_hat
    );
    Ok(ExitCode::SUCCESS)
}

#[allow(clippy::too_many_arguments)]
fn run_allan(
    inputs: &[PathBuf],
    columns: &[String],
    rate: f64,
    taus: &str,
    kind: &str,
    json: bool,
    plot: Option<&Path>,
) -> Result<ExitCode> {
    use gyrofx_model::analysis::{allan, noise};
    if !(rate.is_finite() && rate > 0.0) {
        bail!("--rate {rate} is not allowed: the sample rate must be a finite number of Hz > 0");
    }
    let grid: allan::Grid = taus.parse().map_err(anyhow::Error::msg)?;
    let kind = match kind {
        "overlapping" => allan::Kind::Overlapping,
        "nonoverlapping" => allan::Kind::NonOverlapping,
        "modified" => allan::Kind::Modified,
        "hadamard" => allan::Kind::Hadamard,
        other => bail!("--kind {other} is not a deviation: expected overlapping, nonoverlapping, modified or hadamard"),
    };
    let mut results = Vec::new();
    let mut curves = Vec::new();
    let series: Vec<(&PathBuf, &str)> = inputs
        .iter()
        .flat_map(|p| columns.iter().map(move |c| (p, c.as_str())))
        .collect();
    for (path, column) in series {
        let (values, skipped) = read_column_with_gaps(path, column)?;
        if skipped > 0 && !json {
            eprintln!(
                "{}: skipped {skipped} rows with an empty {column} cell",
                path.display()
            );
        }
        if values.len() < 4 {
            bail!(
                "{}: {} samples are too few: an Allan deviation needs at least 4 (τ = 1/rate needs 2 differences)",
                path.display(),
                values.len()
            );
        }
        let points = allan::curve(kind, &values, rate, grid);
        let terms = noise::fit(&points);
        let report = noise::report(&points, &terms);
        let label = if columns.len() > 1 {
            format!("{} [{column}]", path.display())
        } else {
            path.display().to_string()
        };
        curves.push((label, points.clone(), terms));
        // Welch with the largest power-of-two segment up to N/8 (at most 4096).
        let segment = (values.len() / 8).clamp(8, 4096).next_power_of_two() / 2;
        let density = (segment >= 8)
            .then(|| gyrofx_model::analysis::spectrum::welch(&values, rate, segment.max(8)))
            .and_then(|psd| psd.median_density(rate / 50.0, rate / 5.0));
        if json {
            results.push(serde_json::json!({
                "input": path.display().to_string(),
                "column": column,
                "samples": values.len(),
                "skipped_empty_cells": skipped,
                "rate_hz": rate,
                "kind": format!("{kind:?}").to_lowercase(),
                "tau_s": points.iter().map(|p| p.tau_s).collect::<Vec<_>>(),
                "adev": points.iter().map(|p| p.dev).collect::<Vec<_>>(),
                "adev_lo": points.iter().map(|p| p.lo).collect::<Vec<_>>(),
                "adev_hi": points.iter().map(|p| p.hi).collect::<Vec<_>>(),
                "edf": points.iter().map(|p| p.edf).collect::<Vec<_>>(),
                "noise_alpha": points.iter().map(|p| p.alpha).collect::<Vec<_>>(),
                "noise": report,
                "noise_density_dps_per_sqrt_hz": density,
            }));
        } else {
            println!(
                "{} ({} samples at {rate} Hz, column {column}), {kind:?} deviation",
                path.display(),
                values.len()
            );
            println!(
                "{:>12} {:>13} {:>13} {:>13} {:>6} {:>9}",
                "tau (s)", "dev (°/s)", "lo", "hi", "alpha", "edf"
            );
            for p in &points {
                println!(
                    "{:>12.6} {:>13.6e} {:>13.6e} {:>13.6e} {:>6} {:>9.1}",
                    p.tau_s, p.dev, p.lo, p.hi, p.alpha, p.edf
                );
            }
            let line = |name: &str, e: noise::Estimate, unit: &str| {
                println!(
                    "  {name:<28} {:>12.5e} [{:.5e}, {:.5e}] {unit}",
                    e.value, e.lo, e.hi
                );
            };
            println!("noise terms (weighted non-negative fit, ±1 standard error):");
            line("quantization Q", report.quantization_urad, "µrad");
            line("angle random walk N", report.arw_deg_per_sqrt_h, "°/√h");
            line(
                "bias instability B",
                report.bias_instability_deg_per_h,
                "°/h",
            );
            line(
                "rate random walk K",
                report.rrw_deg_per_h_per_sqrt_h,
                "°/h/√h",
            );
            line("rate ramp R", report.rate_ramp_deg_per_h2, "°/h²");
            println!(
                "  Kalibr: noise density {:.5e} rad/s/√Hz, random walk {:.5e} rad/s²/√Hz",
                report.kalibr_noise_density_rad_per_s_per_sqrt_hz,
                report.kalibr_random_walk_rad_per_s2_per_sqrt_hz
            );
            let opt = |v: Option<f64>| v.map(|v| format!("{v:.5e}")).unwrap_or_else(|| "-".into());
            println!(
                "  noise density (Welch, median over fs/50..fs/5): {} °/s/√Hz",
                opt(density)
            );
            println!(
                "  slope readings: N {} °/√h (τ = 1 s), K {} °/h/√h (τ = 3 s), B {:.5e} °/h (min/0.6643)",
                opt(report.slope_arw_deg_per_sqrt_h),
                opt(report.slope_rrw_deg_per_h_per_sqrt_h),
                report.slope_bias_instability_deg_per_h
            );
        }
    }
    if let Some(path) = plot {
        let series: Vec<gyrofx_codegen::plot::AllanSeries> = curves
            .iter()
            .map(|(label, points, terms)| gyrofx_codegen::plot::AllanSeries {
                label: label.clone(),
                points,
                terms: Some(terms),
            })
            .collect();
        gyrofx_codegen::plot::allan(path, &series)?;
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

#[allow(clippy::too_many_arguments)]
fn run_davar(
    input: &Path,
    column: &str,
    rate: f64,
    window: usize,
    adaptive: bool,
    min_window: Option<usize>,
    gains: [Option<f64>; 3],
    step: Option<usize>,
    json: bool,
    plot: Option<&Path>,
) -> Result<ExitCode> {
    use gyrofx_model::analysis::davar::{coefficients, davar, disturbances, Pid, Window};
    if !(rate.is_finite() && rate > 0.0) {
        bail!("--rate {rate} is not allowed: the sample rate must be a finite number of Hz > 0");
    }
    let (values, skipped) = read_column_with_gaps(input, column)?;
    if window < 4 || window > values.len() {
        bail!(
            "--window {window} is not allowed: it must be 4..={} samples (the record's length)",
            values.len()
        );
    }
    let min = min_window.unwrap_or((window / 10).max(4));
    if adaptive && !(4..=window).contains(&min) {
        bail!("--min-window {min} is not allowed: it must be 4..={window}");
    }
    let step = step.unwrap_or((window / 20).max(1));
    if step == 0 {
        bail!("--step 0 is not allowed: windows move by at least 1 sample");
    }
    let mode = if adaptive {
        Window::Adaptive(Pid {
            min,
            max: window,
            kp: gains[0].unwrap_or(window as f64 / 25.0),
            ki: gains[1].unwrap_or(window as f64 / 50.0),
            kd: gains[2].unwrap_or(0.0),
        })
    } else {
        Window::Fixed(window)
    };
    let d = davar(&values, rate, mode, step);
    let c = coefficients(&d);
    let runs = disturbances(&d, 2.0);
    if let Some(path) = plot {
        gyrofx_codegen::plot::davar(path, &d, &c)?;
        if !json {
            println!("plot: {}", path.display());
        }
    }
    if json {
        let value = serde_json::json!({
            "input": input.display().to_string(),
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
            input.display(),
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
