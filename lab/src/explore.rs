//! `gyrofx explore`: what word lengths cost in noise and in hardware, candidate by candidate.
//!
//! A sweep ([`Sweep`]: `--vary KEY=FORMAT..FORMAT`, several flags giving their Cartesian
//! product, or `--guard-bits A..B` over [`GUARD_BIT_KEYS`]) gives the candidates; each is the
//! config with those formats, resolved by [`gyrofx_codegen::blocks::checked_job`] (a candidate the config's validation
//! refuses gets a CSV row with the reason, not a crash). Per candidate:
//!
//! - the noise ([`measure`]): the chain's fixed output against its float twin over the
//!   configured stimulus (`--samples` overrides the record length): rms and max error in
//!   output LSB and °/s, the quantization noise's share of the output's Allan deviation at
//!   τ = 1 s and of the sensor's ARW, and the chain's overflows on the run's data;
//! - whether `gyrofx formats`' analysis ([`gyrofx_job::formats::analyse`], for this record and its
//!   `bw_sel` switches) proves the swept nodes' formats: the `proven` column, `yes` or `no:`
//!   and the nodes that can overflow;
//! - the cost: [`crate::synth::cost`] of `gyrofx_top` (and of `gyrofx_gyro_loop` when a
//!   `loop.*` key is swept: the hardware then counts the chain and two loops), cached by
//!   [`crate::synth::cache_key`] across runs ([`Costs`]).
//!
//! Candidates run `jobs` at a time on their own threads; rows come out in candidate order
//! whatever the scheduling, so the same inputs give a byte-identical `explore.csv`.
//!
//! The chosen candidate ([`Exploration::best`]) is the cheapest that meets the [`Target`] with
//! no overflow on the run's data (what `generate --strict` refuses), and with `proven_only`
//! only among those whose swept formats are proven: fewest DSP48E1s first (the
//! scarce resource of a small 7-series part), then fewest LUTs, then fewest flip-flops, then
//! the earliest in the sweep. Its config is `best.toml`: the user's config with the candidate's
//! formats (every key resolved, the config's own `samples`), checked by resolving it as
//! `generate` does.

use std::path::Path;

use crate::synth::{Design, Resources};
use gyrofx_codegen::output_folder::{Kind, Replace};
use gyrofx_codegen::package::Package;
use gyrofx_codegen::progress::Progress;
use gyrofx_job::config::Config;
use gyrofx_job::error::{Error, Result};
use gyrofx_job::job::Job;

mod cache;
pub mod measure;
mod pareto;
mod sweep;
mod target;

pub use cache::{default_folder, CostCounts, Costs};
pub use measure::{Metrics, Reference};
pub use sweep::{
    candidates, explorable_keys, Candidate, GuardBits, Sweep, Vary, GUARD_BIT_KEYS, MAX_CANDIDATES,
};
pub use target::{Metric, Target};

/// A candidate's hardware: the chain's resources plus two loops' when loops are costed.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Cost {
    /// Xilinx 7-series LUTs.
    pub luts: u64,
    /// DSP48E1s.
    pub dsp48: u64,
    /// Xilinx flip-flops.
    pub flip_flops: u64,
}

/// What was measured of a candidate.
#[derive(Clone, Debug, PartialEq)]
pub struct Measured {
    /// The noise.
    pub metrics: Metrics,
    /// Swept nodes whose format the formats analysis does not prove (empty: proven).
    pub unproven: Vec<&'static str>,
    /// `gyrofx_top`'s resources.
    pub chain: Resources,
    /// `gyrofx_gyro_loop`'s (one gyro's), when loops are costed.
    pub gyro_loop: Option<Resources>,
}

impl Measured {
    /// The chain plus both gyros' loops (when costed).
    pub fn cost(&self) -> Cost {
        let lp = self.gyro_loop.as_ref();
        let twice = |f: fn(&Resources) -> u64| lp.map_or(0, |r| 2 * f(r));
        Cost {
            luts: self.chain.xilinx.luts + twice(|r| r.xilinx.luts),
            dsp48: self.chain.xilinx.dsp48 + twice(|r| r.xilinx.dsp48),
            flip_flops: self.chain.xilinx.flip_flops + twice(|r| r.xilinx.flip_flops),
        }
    }
}

/// One candidate's row.
#[derive(Clone, Debug, PartialEq)]
pub struct Row {
    /// The candidate.
    pub candidate: Candidate,
    /// What was measured, or why it was not (refused by the config, synthesis failed).
    pub outcome: std::result::Result<Measured, String>,
}

/// Why a run cannot start.
#[derive(Debug)]
pub enum PlanError {
    /// The command line asks for something not allowed (the text names the flag).
    Usage(String),
    /// The config itself is refused.
    Config(Error),
}

impl std::fmt::Display for PlanError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            PlanError::Usage(text) => f.write_str(text),
            PlanError::Config(e) => e.fmt(f),
        }
    }
}

impl std::error::Error for PlanError {}

/// A checked sweep of a config: its candidates and record, ready to run.
#[derive(Clone, Debug)]
pub struct Plan {
    base: Config,
    job: Job,
    keys: Vec<&'static str>,
    candidates: Vec<Candidate>,
    samples: usize,
    reference: Reference,
}

impl Plan {
    /// Checks `sweep` against `config` for a record of `samples` samples (default the
    /// config's): every key explorable, at most [`MAX_CANDIDATES`], a resonator plant when a
    /// loop key is swept, a record long enough for the ADEV at 1 s.
    ///
    /// # Errors
    /// [`PlanError::Config`] when the config (with `samples`) does not resolve;
    /// [`PlanError::Usage`] for the rest.
    pub fn new(
        config: Config,
        sweep: &Sweep,
        samples: Option<usize>,
    ) -> std::result::Result<Plan, PlanError> {
        let record = samples.unwrap_or(config.samples);
        let mut run = config.clone();
        run.samples = record;
        let job = gyrofx_codegen::blocks::checked_job(run).map_err(|e| match (samples, &e) {
            (Some(n), Error::Config { field, .. }) if field == "samples" => {
                PlanError::Usage(format!(
                    "--samples {n} is not allowed: 1 to {}",
                    gyrofx_job::config::MAX_SAMPLES
                ))
            }
            _ => PlanError::Config(e),
        })?;
        let analysis = gyrofx_job::formats::analyse(&job, record as u64, measure::switches(&job));
        let (keys, candidates) = candidates(&analysis, sweep).map_err(PlanError::Usage)?;
        let loops = keys.iter().any(|k| k.starts_with("loop."));
        if loops && job.settings.resonator.is_none() {
            return Err(PlanError::Usage(format!(
                "--vary {}=…: plant.model is \"rate\", whose gyros are not the loops: sweep loop formats with plant.model = \"resonator\"",
                keys.iter().find(|k| k.starts_with("loop.")).expect("a loop key")
            )));
        }
        let needed = measure::min_samples(&job);
        if record < needed {
            let what = match samples {
                Some(n) => format!("--samples {n}"),
                None => format!("samples = {record} (the config's; --samples overrides it)"),
            };
            return Err(PlanError::Usage(format!(
                "{what} is too short: the Allan deviation at τ = {} s needs at least {needed} samples (the first bias estimate comes at sample {}, then 2·fs·τ + 1 more)",
                measure::TAU_S,
                measure::first_estimate(&job)
            )));
        }
        Ok(Plan {
            base: config,
            job,
            keys,
            candidates,
            samples: record,
            reference: if loops {
                Reference::System
            } else {
                Reference::Chain
            },
        })
    }

    /// The swept keys, in the CSV's order.
    pub fn keys(&self) -> &[&'static str] {
        &self.keys
    }

    /// Every candidate.
    pub fn candidates(&self) -> &[Candidate] {
        &self.candidates
    }

    /// The record length, samples.
    pub fn samples(&self) -> usize {
        self.samples
    }

    /// Which float model the error is against.
    pub fn reference(&self) -> Reference {
        self.reference
    }

    /// Whether the loop is synthesized too.
    pub fn loops_costed(&self) -> bool {
        self.reference == Reference::System
    }

    /// The config of `candidate`: the user's with its formats, and the run's `samples`.
    pub fn config_of(&self, candidate: &Candidate) -> Config {
        let mut config = self.base.clone();
        config.samples = self.samples;
        for (key, format) in &candidate.formats {
            gyrofx_job::formats::set_format(&mut config, key, *format);
        }
        config
    }
}

/// A run's results.
#[derive(Clone, Debug)]
pub struct Exploration {
    /// The user's config (what `best.toml` starts from).
    pub base: Config,
    /// The swept keys.
    pub keys: Vec<&'static str>,
    /// One row per candidate, in candidate order.
    pub rows: Vec<Row>,
    /// What the error is against.
    pub reference: Reference,
    /// Whether the loop was synthesized.
    pub loops_costed: bool,
    /// The target.
    pub target: Target,
    /// Whether only candidates with proven formats may be chosen.
    pub proven_only: bool,
    /// Record length, samples.
    pub samples: usize,
    /// The chosen candidate's index.
    pub best: Option<usize>,
    /// How the costs were found.
    pub costs: CostCounts,
}

/// A message on one line, at most 400 characters (a yosys log tail has many).
fn one_line(text: &str) -> String {
    let flat: String = text
        .lines()
        .map(str::trim)
        .filter(|l| !l.is_empty())
        .collect::<Vec<_>>()
        .join(" | ");
    if flat.chars().count() > 400 {
        format!("{}…", flat.chars().take(400).collect::<String>())
    } else {
        flat
    }
}

/// Measures one candidate.
fn run_candidate(
    plan: &Plan,
    candidate: &Candidate,
    shared: Option<&measure::Stimulus>,
    costs: &Costs,
) -> Result<Row> {
    let row = |outcome| Row {
        candidate: candidate.clone(),
        outcome,
    };
    let job = match gyrofx_codegen::blocks::checked_job(plan.config_of(candidate)) {
        Ok(job) => job,
        Err(e) => return Ok(row(Err(one_line(&format!("refused: {e}"))))),
    };
    let own;
    let stimulus = match shared {
        Some(s) => s,
        None => match measure::stimulus(&job, true) {
            Ok(s) => {
                own = s;
                &own
            }
            Err(e) => return Ok(row(Err(one_line(&format!("simulation failed: {e}"))))),
        },
    };
    let metrics = match measure::measure(&job, stimulus) {
        Ok(m) => m,
        Err(message) => return Ok(row(Err(one_line(&message)))),
    };
    let analysis = gyrofx_job::formats::analyse(&job, plan.samples as u64, measure::switches(&job));
    let unproven: Vec<&'static str> = candidate
        .formats
        .iter()
        .map(|(key, _)| *key)
        .filter(|key| {
            analysis
                .rows
                .iter()
                .any(|r| r.key == Some(*key) && !r.node.fits())
        })
        .collect();
    let chain = match costs.cost(&job, Design::Chain)? {
        Ok(r) => r,
        Err(m) => return Ok(row(Err(one_line(&format!("synthesis failed: {m}"))))),
    };
    let gyro_loop = if plan.loops_costed() {
        match costs.cost(&job, Design::GyroLoop)? {
            Ok(r) => Some(r),
            Err(m) => return Ok(row(Err(one_line(&format!("synthesis failed: {m}"))))),
        }
    } else {
        None
    };
    Ok(row(Ok(Measured {
        metrics,
        unproven,
        chain,
        gyro_loop,
    })))
}

/// Runs every candidate of `plan`, `jobs` at a time, with costs from `costs`, and chooses the
/// cheapest that meets `target` (and with `proven_only`, whose swept formats are proven).
/// `progress` counts candidates.
///
/// # Errors
/// The shared gyro simulation fails (a bad CSV stimulus), or a cache file cannot be written.
pub fn explore(
    plan: &Plan,
    target: Target,
    proven_only: bool,
    jobs: usize,
    costs: &Costs,
    progress: &Progress,
) -> Result<Exploration> {
    progress.plan(plan.candidates.len() as u64);
    progress.set_phase("simulating the gyros");
    let shared = match plan.reference {
        Reference::Chain => Some(measure::stimulus(&plan.job, false)?),
        Reference::System => None,
    };
    progress.set_phase("simulating and synthesizing candidates");
    let rows = crate::pool::try_map(&plan.candidates, jobs, |candidate| {
        let row = run_candidate(plan, candidate, shared.as_ref(), costs);
        progress.advance(1);
        row
    })?;
    let best = rows
        .iter()
        .filter_map(|r| {
            let m = r.outcome.as_ref().ok()?;
            eligible(m, &target, proven_only).then(|| {
                let c = m.cost();
                ((c.dsp48, c.luts, c.flip_flops, r.candidate.index), r)
            })
        })
        .min_by_key(|(key, _)| *key)
        .map(|(_, r)| r.candidate.index);
    Ok(Exploration {
        base: plan.base.clone(),
        keys: plan.keys.clone(),
        rows,
        reference: plan.reference,
        loops_costed: plan.loops_costed(),
        target,
        proven_only,
        samples: plan.samples,
        best,
        costs: costs.counts(),
    })
}

/// Whether a measured candidate may be chosen: it meets the target, no quantizer of the chain
/// overflowed on the run's data, and (with `proven_only`) its swept formats are proven.
fn eligible(m: &Measured, target: &Target, proven_only: bool) -> bool {
    m.metrics.overflows == 0 && target.met(&m.metrics) && (!proven_only || m.unproven.is_empty())
}

/// A number for the CSV: the shortest text that reads back to the same f64 (ryu).
fn number(v: f64) -> String {
    ryu::Buffer::new().format(v).to_string()
}

const RESOURCE_COLUMNS: [&str; 8] = [
    "cells",
    "generic_flip_flops",
    "multipliers",
    "luts",
    "flip_flops",
    "dsp48",
    "block_rams",
    "carry4",
];

fn resource_values(r: &Resources) -> [u64; 8] {
    [
        r.generic.cells,
        r.generic.flip_flops,
        r.generic.multipliers,
        r.xilinx.luts,
        r.xilinx.flip_flops,
        r.xilinx.dsp48,
        r.xilinx.block_rams,
        r.xilinx.carry4,
    ]
}

impl Exploration {
    /// The CSV's header.
    pub fn header(&self) -> Vec<String> {
        let mut header: Vec<String> = vec!["candidate".into()];
        header.extend(self.keys.iter().map(|k| k.to_string()));
        header.extend(
            [
                "status",
                "proven",
                "overflows",
                "error_rms_lsb",
                "error_max_lsb",
                "error_rms_dps",
                "error_max_dps",
                "adev_error_1s_dps",
                "adev_output_1s_dps",
                "adev_share",
                "arw_quantization_deg_per_sqrt_h",
                "arw_share",
            ]
            .map(String::from),
        );
        header.extend(RESOURCE_COLUMNS.iter().map(|c| format!("chain_{c}")));
        if self.loops_costed {
            header.extend(RESOURCE_COLUMNS.iter().map(|c| format!("loop_{c}")));
        }
        header.extend(["luts", "dsp48", "flip_flops", "meets_target", "best"].map(String::from));
        header
    }

    /// `explore.csv`: the header, then one row per candidate in candidate order. A candidate
    /// that was not measured has its reason in `status` and empty figures.
    pub fn csv(&self) -> String {
        let mut writer = csv::WriterBuilder::new()
            .terminator(csv::Terminator::Any(b'\n'))
            .from_writer(Vec::new());
        writer.write_record(self.header()).expect("in memory");
        let width = self.header().len();
        for row in &self.rows {
            let mut record: Vec<String> = vec![row.candidate.index.to_string()];
            record.extend(row.candidate.formats.iter().map(|(_, f)| f.to_string()));
            match &row.outcome {
                Err(why) => {
                    record.push(why.clone());
                    record.resize(width - 1, String::new());
                    record.push("false".into());
                }
                Ok(m) => {
                    let x = &m.metrics;
                    record.push("ok".into());
                    record.push(if m.unproven.is_empty() {
                        "yes".into()
                    } else {
                        format!("no: {}", m.unproven.join(" "))
                    });
                    record.push(x.overflows.to_string());
                    record.extend(
                        [
                            x.rms_lsb,
                            x.max_lsb,
                            x.rms_dps,
                            x.max_dps,
                            x.adev_error_dps,
                            x.adev_output_dps,
                            x.adev_share,
                            x.arw_deg_per_sqrt_h,
                            x.arw_share,
                        ]
                        .map(number),
                    );
                    record.extend(resource_values(&m.chain).map(|v| v.to_string()));
                    if let Some(l) = &m.gyro_loop {
                        record.extend(resource_values(l).map(|v| v.to_string()));
                    }
                    let c = m.cost();
                    record.extend([c.luts, c.dsp48, c.flip_flops].map(|v| v.to_string()));
                    record.push(eligible(m, &self.target, self.proven_only).to_string());
                    record.push((self.best == Some(row.candidate.index)).to_string());
                }
            }
            writer.write_record(&record).expect("in memory");
        }
        String::from_utf8(writer.into_inner().expect("in memory")).expect("UTF-8")
    }

    /// The chosen row.
    pub fn best_row(&self) -> Option<&Row> {
        let best = self.best?;
        self.rows.iter().find(|r| r.candidate.index == best)
    }

    /// `best.toml`: the user's config with the chosen candidate's formats, headed by what was
    /// chosen and why; `None` when none meets the target.
    ///
    /// # Errors
    /// The config does not resolve (it did in the run, so this is a bug guard).
    pub fn best_toml(&self, command: &str) -> Result<Option<String>> {
        let Some(row) = self.best_row() else {
            return Ok(None);
        };
        let Ok(m) = &row.outcome else {
            return Ok(None);
        };
        let mut config = self.base.clone();
        for (key, format) in &row.candidate.formats {
            gyrofx_job::formats::set_format(&mut config, key, *format);
        }
        gyrofx_codegen::blocks::checked_job(config.clone())?;
        let c = m.cost();
        let formats = row.candidate.assignments(" = ");
        Ok(Some(format!(
            "# written by gyrofx explore: candidate {} of {}, the cheapest (fewest DSP48E1, then LUTs, then\n\
             # flip-flops) whose {} is at most {} with no quantizer overflow{}, over {} samples:\n\
             #   {}\n\
             # {} = {}; {} LUTs, {} DSP48E1, {} flip-flops{}; formats proven: {}.\n\
             # Command: {command}\n{}",
            row.candidate.index,
            self.rows.len(),
            self.target.metric.name(),
            self.target.limit,
            if self.proven_only { " and proven formats" } else { "" },
            self.samples,
            formats.join(", "),
            self.target.metric.column(),
            number(self.target.metric.of(&m.metrics)),
            c.luts,
            c.dsp48,
            c.flip_flops,
            if self.loops_costed {
                " (the chain and two loops)"
            } else {
                " (gyrofx_top)"
            },
            if m.unproven.is_empty() {
                "yes".to_string()
            } else {
                format!("no, {} can overflow (gyrofx formats)", m.unproven.join(", "))
            },
            config.to_toml()
        )))
    }

    /// Why no candidate was chosen (empty when one was).
    pub fn why_none(&self) -> String {
        if self.best.is_some() {
            return String::new();
        }
        let measured: Vec<&Measured> = self
            .rows
            .iter()
            .filter_map(|r| r.outcome.as_ref().ok())
            .collect();
        if measured.is_empty() {
            return format!(
                "none of the {} candidates was measured (see the status column of explore.csv)",
                self.rows.len()
            );
        }
        let metric = self.target.metric;
        let least = measured
            .iter()
            .map(|m| metric.of(&m.metrics))
            .fold(f64::INFINITY, f64::min);
        let clean = measured.iter().filter(|m| m.metrics.overflows == 0).count();
        let proven = measured.iter().filter(|m| m.unproven.is_empty()).count();
        format!(
            "no candidate meets {}{}: the least {} of the {} measured is {}; {} of them ran without a quantizer overflow, {} have proven formats",
            self.target,
            if self.proven_only { " with proven formats" } else { "" },
            metric.name(),
            measured.len(),
            number(least),
            clean,
            proven
        )
    }

    /// The plot's points: every measured candidate.
    fn points(&self) -> Vec<pareto::Point> {
        self.rows
            .iter()
            .filter_map(|r| {
                let m = r.outcome.as_ref().ok()?;
                let c = m.cost();
                Some(pareto::Point {
                    index: r.candidate.index,
                    luts: c.luts as f64,
                    dsp48: c.dsp48 as f64,
                    value: self.target.metric.of(&m.metrics),
                    eligible: eligible(m, &self.target, self.proven_only),
                })
            })
            .collect()
    }
}

/// Writes `explore.csv`, `pareto.png`, `pareto.svg`, `best.toml` (when a candidate was chosen)
/// and a manifest to `out`, all or nothing, if `out` may be replaced ([`Kind::Explore`]).
/// `command` is the command line the files record. Returns the files written.
///
/// # Errors
/// A plot error (no font), or the package's output errors.
pub fn write(
    out: &Path,
    replace: Replace,
    exploration: &Exploration,
    command: &str,
) -> Result<Vec<String>> {
    gyrofx_codegen::output_folder::check(out, Kind::Explore, replace)?;
    let mut package = Package::new(Kind::Explore, Vec::new());
    package.add("explore.csv", exploration.csv());
    let points = exploration.points();
    if !points.is_empty() {
        let title = format!(
            "gyrofx explore: {} against cost ({} candidates, {} samples)",
            exploration.target.metric.name(),
            exploration.rows.len(),
            exploration.samples
        );
        let (png, svg) = pareto::render(&points, exploration.best, &exploration.target, &title)?;
        package.add("pareto.png", png);
        package.add("pareto.svg", svg);
    }
    if let Some(toml) = exploration.best_toml(command)? {
        package.add("best.toml", toml);
    }
    let mut files = package.paths();
    files.push(gyrofx_codegen::output_folder::MANIFEST.into());
    let manifest = serde_json::json!({
        "tool": "gyrofx",
        "version": env!("CARGO_PKG_VERSION"),
        "command": command,
        "config": exploration.base,
        "swept": exploration.keys,
        "candidates": exploration.rows.len(),
        "samples": exploration.samples,
        "reference": exploration.reference.describe(),
        "target": exploration.target.to_string(),
        "best": exploration.best,
        "cost_order": "fewest DSP48E1, then LUTs, then flip-flops",
        "proven_only": exploration.proven_only,
        "synthesized": if exploration.loops_costed { "gyrofx_top and gyrofx_gyro_loop (cost: the chain and two loops)" } else { "gyrofx_top" },
        "files": package.entries(),
    });
    package.add(
        gyrofx_codegen::output_folder::MANIFEST,
        serde_json::to_string_pretty(&manifest).expect("manifest serializes") + "\n",
    );
    package.write_atomically(out, replace)?;
    Ok(files)
}
