//! `gyrofx population`: a population of gyro pairs whose resonators and front ends spread as
//! `[population]` says, each pair through its closed loops and the chain; figures per member,
//! quantiles and yields.

use std::process::ExitCode;

use anyhow::Result;

use gyrofx_job::population::summary::Report;
use gyrofx_job::population::targets::Target;
use gyrofx_job::population::{Population, RunSettings, MAX_SECONDS};
use gyrofx_lab::population::{self, Request};

use super::options::{ConfigSource, OutputFolder};
use super::usage;

/// Spread the gyros over many pairs: lock, settling, bias, residual, yield.
///
/// Draws --gyros members (gyro pairs) from the config's [population] spreads of the resonators'
/// and the front end's parameters (normal, uniform or a list of values; absolute or relative to
/// the configured value), each member from its own random stream of (seed, member index), and
/// runs each through the configured fixed-point loops (designed for the nominal gyros), the
/// sequencer, the bias estimator and the KF: per member, whether each loop locked (and why
/// not) and when, settling after each switch, bias per mode and the residual after reversal
/// beside SPEC 1.6's closed forms, saturation and overflow counts, the calibrated output's
/// mean at rest, and with --noise its ARW and bias instability. Writes to --out, all or
/// nothing: population.csv (drawn parameters and figures, one row per member in member
/// order), summary.json (quantiles of each figure, yields against each --target and against
/// the blanking), a histogram per figure and yield_vs_blanking.svg, manifest.json. The same
/// seed gives the same files byte for byte, whatever --jobs.
#[derive(clap::Args)]
pub struct Args {
    #[command(flatten)]
    out: OutputFolder,
    #[command(flatten)]
    source: ConfigSource,
    /// Members: gyro pairs, 1..=10000000.
    #[arg(long, value_parser = super::options::count)]
    gyros: usize,
    /// Seconds of chain run per member after its 0.5 s start-up (the first bias estimate
    /// comes after one window of the sequencer).
    #[arg(long, default_value_t = 10.0)]
    seconds: f64,
    /// Thermomechanical and electronic noise and drift in the chain run, and the calibrated
    /// output's Allan terms.
    #[arg(long)]
    noise: bool,
    /// Seed of the draws and the noise [default: the config's seed].
    #[arg(long, value_parser = super::options::seed)]
    seed: Option<u64>,
    /// A target the yield counts: FIGURE<=NUMBER (or >=, <, >), FIGURE one of residual_dps,
    /// bias_dps, scale_factor_error, settling_ms, lock_ms, output_mean_dps, output_std_dps,
    /// saturations, arw_deg_per_sqrt_h, bias_instability_deg_per_h. Repeatable.
    #[arg(long, value_name = "FIGURE<=NUMBER")]
    target: Vec<String>,
    /// Members studied at once, 1..=256 (default: the available cores).
    #[arg(long, value_parser = super::options::jobs)]
    jobs: Option<usize>,
    /// No progress bar (it shows only on a terminal).
    #[arg(long)]
    quiet: bool,
}

/// Most members.
const MAX_MEMBERS: usize = 10_000_000;

/// The command line the output records, with the folder left out.
fn command_line(args: &Args, seed: u64) -> String {
    let mut words = vec![format!(
        "gyrofx population --out <folder> --gyros {}",
        args.gyros
    )];
    if let Some(p) = &args.source.preset {
        words.push(format!("--preset {p}"));
    }
    if let Some(c) = &args.source.config {
        words.push(format!("--config {}", c.display()));
    }
    words.push(format!("--seconds {} --seed {seed}", args.seconds));
    if args.noise {
        words.push("--noise".into());
    }
    for t in &args.target {
        words.push(format!("--target '{t}'"));
    }
    words.join(" ")
}

/// Runs the study, writes the folder and prints the summary.
pub fn run(args: Args) -> Result<ExitCode> {
    if args.gyros == 0 || args.gyros > MAX_MEMBERS {
        usage!("--gyros {} is not allowed: 1..={MAX_MEMBERS}", args.gyros);
    }
    if !(args.seconds.is_finite() && args.seconds > 0.0 && args.seconds <= MAX_SECONDS) {
        usage!(
            "--seconds {} is not allowed: a number of seconds in (0, {MAX_SECONDS}]",
            args.seconds
        );
    }
    let targets: Vec<Target> = args
        .target
        .iter()
        .map(|t| t.parse())
        .collect::<std::result::Result<_, String>>()
        .map_err(super::Usage)?;
    let mut config = args.source.load()?;
    if let Some(seed) = args.seed {
        config.seed = seed;
    }
    let population = Population::new(&config)?;
    let out = args.out.out.as_path();
    let _lock =
        super::options::claim_output_folder(out, &[("--config", args.source.config.as_deref())])?;
    let jobs = args.jobs.unwrap_or_else(|| {
        std::thread::available_parallelism().map_or(1, std::num::NonZeroUsize::get)
    });
    let request = Request {
        out,
        replace: args.out.replace(),
        members: args.gyros as u64,
        jobs,
        settings: RunSettings {
            seconds: args.seconds,
            noise: args.noise,
        },
        targets,
        command: command_line(&args, config.seed),
    };
    let bar = super::progress::bar(args.gyros as u64, "population", args.quiet);
    let started = std::time::Instant::now();
    let outcome = population::run(&population, &request, &|n| bar.inc(n))?;
    bar.finish_and_clear();
    let wall = started.elapsed().as_secs_f64();
    print_report(&outcome.report);
    println!(
        "{} gyro-samples in {wall:.1} s on {jobs} threads: {:.2} M gyro-samples/s ({:.2} M per thread)",
        outcome.gyro_samples,
        outcome.gyro_samples as f64 / wall / 1e6,
        outcome.gyro_samples as f64 / wall / 1e6 / jobs as f64
    );
    println!("wrote {} ({} files)", out.display(), outcome.files.len());
    Ok(ExitCode::SUCCESS)
}

fn print_report(report: &Report) {
    let c = report.counts;
    println!(
        "members {}: {} locked, {} unlocked, {} invalid",
        c.members, c.ok, c.unlocked, c.invalid
    );
    println!(
        "{:<28} {:>7} {:>12} {:>12} {:>12} {:>12}",
        "figure", "members", "p5", "median", "p95", "max"
    );
    for f in &report.figures {
        let at = |q: f64| {
            f.quantiles
                .iter()
                .find(|(p, _)| *p == q)
                .map_or("-".to_string(), |(_, v)| format!("{v:.4e}"))
        };
        println!(
            "{:<28} {:>7} {:>12} {:>12} {:>12} {:>12}",
            f.figure,
            f.count,
            at(0.05),
            at(0.5),
            at(0.95),
            at(1.0)
        );
    }
    for t in &report.targets {
        println!(
            "target {}: {} members, yield {:.2} %",
            t.target,
            t.met,
            100.0 * t.yield_fraction
        );
    }
    println!(
        "yield (every target): {:.2} %",
        100.0 * report.yield_fraction
    );
}
