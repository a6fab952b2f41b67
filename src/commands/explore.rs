//! `gyrofx explore`: sweep the formats of chosen nodes and report, per candidate, the
//! fixed-versus-float noise and the synthesized cost; choose the cheapest that meets a target.

use std::path::PathBuf;
use std::process::ExitCode;

use anyhow::{Context, Result};

use gyrofx_codegen::progress::Progress;
use gyrofx_lab::explore::{
    self, default_folder, Costs, GuardBits, Plan, PlanError, Sweep, Target, Vary, MAX_CANDIDATES,
};

use super::options::{count, ConfigSource, OutputFolder};
use super::usage;

/// Sweep word lengths: error, noise share, overflows and FPGA cost per candidate.
///
/// Sweeps word lengths: for each candidate, the chain's fixed-versus-float error (rms and max,
/// in output LSB and °/s), the quantization noise's share of the output's Allan deviation at
/// τ = 1 s (σ of fixed − float over σ of the float output) and of the sensor's ARW (the error's
/// σ(1 s)·√1 s, in °/√h, over kf.arw_deg_per_sqrt_h), the chain's overflows on the run's data,
/// whether `gyrofx formats` proves the swept formats, and the yosys cost (generic cells,
/// flip-flops, multipliers; Xilinx 7-series LUTs, flip-flops, DSP48E1) of gyrofx_top — and of
/// gyrofx_gyro_loop when a loop.* key is swept (the error is then against the float loops too,
/// and the cost counts two loops). Costs are cached by RTL, parameters, ROM words and yosys
/// version; candidates run --jobs at a time.
///
/// Writes to --out, all or nothing: explore.csv (one row per candidate, in sweep order; a
/// candidate the config refuses or yosys fails on has the reason in `status`), pareto.png and
/// pareto.svg (the target's metric against LUTs and against DSP48E1, Pareto fronts and the
/// chosen point marked), best.toml (the cheapest candidate meeting --target with no overflow
/// on the run's data, and with --require-proven with proven formats: fewest DSP48E1, then LUTs,
/// then flip-flops; a complete config `generate --strict` accepts)
/// and manifest.json. When no candidate meets the target, everything but best.toml is written,
/// the reason printed, and the exit code is 1. Bad arguments exit 2 and write nothing.
#[derive(clap::Args)]
pub struct Args {
    #[command(flatten)]
    out: OutputFolder,
    #[command(flatten)]
    source: ConfigSource,
    /// Sweep a format node: KEY=FORMAT..FORMAT, the endpoints sharing their integer bits (the
    /// fraction bits step by 1, the width with them: kf.state_format=s30.20..s40.30) or their
    /// fraction bits (the width steps by 1: kf.state_format=s30.20..s36.20). Repeat for more
    /// nodes: their Cartesian product, the last flag fastest. Keys: the nodes `gyrofx formats`
    /// analyses whose format a key sets alone (estimator.mean_format, estimator.bias_format,
    /// kf.state_format, kf.output_format, loop.*_format); at most 200 candidates.
    #[arg(long, value_name = "KEY=FORMAT..FORMAT", conflicts_with = "guard_bits")]
    vary: Vec<String>,
    /// Instead of --vary: estimator.mean_format, estimator.bias_format, kf.state_format and
    /// kf.output_format together at their configured fraction bits + g (integer bits kept),
    /// one candidate for each g from A to B (e.g. 0..4, or -2..2).
    #[arg(long, value_name = "A..B", allow_hyphen_values = true)]
    guard_bits: Option<String>,
    /// What the chosen candidate must meet: METRIC<=LIMIT, METRIC one of arw-share,
    /// adev-share, max-error-lsb, rms-error-lsb, max-error-dps, rms-error-dps.
    #[arg(long, default_value = "arw-share<=0.01", value_name = "METRIC<=LIMIT")]
    target: String,
    /// Choose only among candidates whose swept formats `gyrofx formats` proves (no overflow
    /// possible for any input in the ADC's range over the record).
    #[arg(long)]
    require_proven: bool,
    /// Record length, samples (default: the config's `samples`); it must hold the first bias
    /// estimate and 2·fs + 1 samples after it (the ADEV at 1 s).
    #[arg(long, value_parser = count)]
    samples: Option<usize>,
    /// Candidates simulated and synthesized at once, 1..=256 (default: the available cores).
    #[arg(long, value_parser = super::options::jobs)]
    jobs: Option<usize>,
    /// Cost cache folder, one JSON file per synthesized design (default:
    /// $XDG_CACHE_HOME/gyrofx/synth, else ~/.cache/gyrofx/synth).
    #[arg(long, value_name = "DIR")]
    cache: Option<PathBuf>,
    /// No progress bar (it shows only on a terminal).
    #[arg(long)]
    quiet: bool,
}

/// The command line the output records, with the folder left out.
fn command_line(args: &Args) -> String {
    let mut words = vec!["gyrofx explore --out <folder>".to_string()];
    if let Some(p) = &args.source.preset {
        words.push(format!("--preset {p}"));
    }
    if let Some(c) = &args.source.config {
        words.push(format!("--config {}", c.display()));
    }
    for v in &args.vary {
        words.push(format!("--vary {v}"));
    }
    if let Some(g) = &args.guard_bits {
        words.push(format!("--guard-bits {g}"));
    }
    words.push(format!("--target '{}'", args.target));
    if args.require_proven {
        words.push("--require-proven".into());
    }
    if let Some(n) = args.samples {
        words.push(format!("--samples {n}"));
    }
    words.join(" ")
}

/// Runs the sweep, writes the folder and prints one line per candidate.
pub fn run(args: Args) -> Result<ExitCode> {
    // Everything the command line says is checked before any work or output.
    let sweep = match (&args.guard_bits, args.vary.is_empty()) {
        (Some(text), _) => Sweep::GuardBits(GuardBits::parse(text).map_err(super::Usage)?),
        (None, false) => Sweep::Vary(
            args.vary
                .iter()
                .map(|v| Vary::parse(v))
                .collect::<std::result::Result<_, _>>()
                .map_err(super::Usage)?,
        ),
        (None, true) => usage!(
            "give what to sweep: --vary KEY=FORMAT..FORMAT (repeatable) or --guard-bits A..B"
        ),
    };
    let target: Target = args.target.parse().map_err(super::Usage)?;
    let cache = match args.cache.clone().or_else(default_folder) {
        Some(folder) => folder,
        None => usage!("no cache folder: neither XDG_CACHE_HOME nor HOME is set; give --cache DIR"),
    };
    let config = args.source.load()?;
    let plan = match Plan::new(config, &sweep, args.samples) {
        Ok(plan) => plan,
        Err(PlanError::Usage(text)) => usage!("{text}"),
        Err(PlanError::Config(e)) => return Err(e.into()),
    };
    let out = args.out.out.as_path();
    let _lock = super::options::claim_output_folder(
        out,
        &[
            ("--config", args.source.config.as_deref()),
            ("--cache", Some(cache.as_path())),
        ],
    )?;
    gyrofx_codegen::output_folder::check(
        out,
        gyrofx_codegen::output_folder::Kind::Explore,
        args.out.replace(),
    )?;
    if gyrofx_lab::toolchain::Tool::Yosys.version().is_none() {
        anyhow::bail!("gyrofx explore synthesizes every candidate with yosys, which is not installed (or not on PATH)");
    }
    let costs = Costs::open(&cache).with_context(|| format!("--cache {}", cache.display()))?;
    let jobs = args.jobs.unwrap_or_else(|| {
        std::thread::available_parallelism().map_or(1, std::num::NonZeroUsize::get)
    });
    let n = plan.candidates().len();
    debug_assert!(n <= MAX_CANDIDATES);
    let progress = Progress::default();
    let exploration = super::progress::follow("explore", args.quiet, &progress, || {
        explore::explore(&plan, target, args.require_proven, jobs, &costs, &progress)
    })?;
    let command = command_line(&args);
    let files = explore::write(out, args.out.replace(), &exploration, &command)?;

    let metric = target.metric;
    for row in &exploration.rows {
        let formats = row.candidate.assignments("=");
        let mark = if exploration.best == Some(row.candidate.index) {
            "*"
        } else {
            " "
        };
        match &row.outcome {
            Ok(m) => {
                let c = m.cost();
                println!(
                    "{mark}{:>3} {}  {} {:.3e}  error rms {:.3} LSB  {} LUTs  {} DSP48E1  {} FFs{}",
                    row.candidate.index,
                    formats.join(" "),
                    metric.name(),
                    metric.of(&m.metrics),
                    m.metrics.rms_lsb,
                    c.luts,
                    c.dsp48,
                    c.flip_flops,
                    if m.metrics.overflows > 0 {
                        format!("  {} overflows", m.metrics.overflows)
                    } else {
                        String::new()
                    }
                );
            }
            Err(why) => println!(" {:>3} {}  {why}", row.candidate.index, formats.join(" ")),
        }
    }
    let counts = exploration.costs;
    println!(
        "costs: {} synthesized by yosys, {} from the cache ({}), {} shared between candidates",
        counts.synthesized,
        counts.cached,
        costs.folder().display(),
        counts.shared
    );
    // The marker is gyrofx's bookkeeping, not a result.
    let shown: Vec<&str> = files
        .iter()
        .map(String::as_str)
        .filter(|f| !f.starts_with('.'))
        .collect();
    println!("wrote {} to {}", shown.join(", "), out.display());
    match exploration.best_row() {
        Some(row) => {
            println!(
                "best: candidate {} (the cheapest meeting {}{}): {}",
                row.candidate.index,
                target,
                if args.require_proven {
                    " with proven formats"
                } else {
                    ""
                },
                out.join("best.toml").display()
            );
            Ok(ExitCode::SUCCESS)
        }
        None => {
            eprintln!("no best.toml: {}", exploration.why_none());
            Ok(ExitCode::FAILURE)
        }
    }
}
