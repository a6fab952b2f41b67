//! The vector set: one run of the whole chain (plant, sequencer, estimator, KF) with the float
//! golden chains beside it, sample by sample ([`ChainSample`]), handed to every
//! [`VectorBuilder`] the caller gives it (the registered blocks' builders), each of which cuts
//! its own vectors from it, adds its directed segments and reports what it found
//! ([`BlockResults`]). The run also yields the report's Allan table. The run knows no block:
//! it owns this interface, and the blocks implement it.
//!
//! Schedule of the run: `samples` samples of the configured stimulus, `bw_sel` cycling through
//! every ROM entry (each for `samples / (2·entries)` samples), and one reset of the whole chain
//! late in the run. The gyros are simulated in the modes the sequencer asks for, resets
//! included.

use gyrofx_model::analysis::allan::OverlappingStream;
use std::collections::BTreeMap;

use gyrofx_model::chain::{FixedChain, FloatChain, FloatSample, Sample};
use gyrofx_model::estimator::OverflowCounts as EstimatorOverflows;
use gyrofx_model::kf::OverflowCounts;
use gyrofx_model::sequencer::Sequencer;
use serde::Serialize;

use crate::block::Block;
use crate::progress::Progress;
pub use crate::stats::ErrorStats;
use gyrofx_job::error::Result;
use gyrofx_job::gyros::{Batch, GyroLoopCounts, Gyros, Twins, BATCH, PROGRESS_STEP};
use gyrofx_job::job::Job;

/// Overflow counts of every quantization point.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Overflows {
    /// ADC saturations of gyro A and B.
    pub adc: [u64; 2],
    /// Estimator and calibration.
    pub estimator: EstimatorCounts,
    /// The KF in the chain run.
    pub kf_chain: KfCounts,
    /// The resonator-level gyros' fixed loops (A, B) on the record; zeros for the other plants.
    pub gyro_loop: [GyroLoopCounts; 2],
    /// The blocks' own counts on their directed segments, by key ([`BlockResults::overflows`]:
    /// the KF's `kf_directed`, full scale included; the mean filter's output, `mean_filter`,
    /// whose full-scale blocks may round past the range). They saturate on purpose.
    #[serde(flatten)]
    pub directed: BTreeMap<&'static str, serde_json::Value>,
}

impl Overflows {
    /// The quantization points that overflowed or saturated on the chain run's data, with
    /// their counts, by signal name, the resonator-level loops' nodes first (`loop A
    /// rate_output`, ...). The directed test segments (the KF's full-scale segment, the mean
    /// filter's blocks) saturate on purpose and are not among them, nor are the loops'
    /// saturations in the switch transients the sequencer blanks ([`GyroLoopCounts::blanked`]).
    pub fn in_chain_run(&self) -> Vec<(String, u64)> {
        let e = &self.estimator;
        let k = &self.kf_chain;
        let loops = ["A", "B"]
            .into_iter()
            .zip(&self.gyro_loop)
            .flat_map(|(gyro, counts)| {
                counts
                    .used
                    .saturated()
                    .map(move |(node, n)| (format!("loop {gyro} {}", node.name()), n))
            });
        let chain = [
            ("ADC A", self.adc[0]),
            ("ADC B", self.adc[1]),
            ("interval mean A", e.mean[0]),
            ("interval mean B", e.mean[1]),
            ("bias A", e.bias[0]),
            ("bias B", e.bias[1]),
            ("calibrated A", e.calibrated[0]),
            ("calibrated B", e.calibrated[1]),
            ("combined", e.combined),
            ("KF x1", k.x1),
            ("KF x2", k.x2),
            ("KF rate_hat", k.rate_hat),
        ]
        .into_iter()
        .filter(|(_, n)| *n > 0)
        .map(|(name, n)| (name.to_string(), n));
        loops.chain(chain).collect()
    }
}

/// Estimator overflow counts (serializable mirror).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct EstimatorCounts {
    /// Means of A and B.
    pub mean: [u64; 2],
    /// Bias estimates of A and B.
    pub bias: [u64; 2],
    /// Calibrated outputs of A and B (valid samples).
    pub calibrated: [u64; 2],
    /// Combined output.
    pub combined: u64,
}

/// KF overflow counts (serializable mirror).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct KfCounts {
    /// State x1.
    pub x1: u64,
    /// State x2.
    pub x2: u64,
    /// Output.
    pub rate_hat: u64,
}

impl EstimatorCounts {
    /// Every overflow and saturation counted.
    pub fn total(&self) -> u64 {
        self.mean
            .iter()
            .chain(&self.bias)
            .chain(&self.calibrated)
            .sum::<u64>()
            + self.combined
    }
}

impl KfCounts {
    /// Every overflow and saturation counted.
    pub fn total(&self) -> u64 {
        self.x1 + self.x2 + self.rate_hat
    }
}

impl From<OverflowCounts> for KfCounts {
    fn from(c: OverflowCounts) -> Self {
        KfCounts {
            x1: c.x1,
            x2: c.x2,
            rate_hat: c.rate_hat,
        }
    }
}

impl From<EstimatorOverflows> for EstimatorCounts {
    fn from(c: EstimatorOverflows) -> Self {
        EstimatorCounts {
            mean: c.mean,
            bias: c.bias,
            calibrated: c.calibrated,
            combined: c.combined,
        }
    }
}

/// One line of the report: a signal's bias error and Allan deviation.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct ReportLine {
    /// What the signal is.
    pub signal: String,
    /// Mean of (signal − true rate), °/s.
    pub bias_error_dps: f64,
    /// Allan deviation at each of [`Report::tau_s`], °/s (null where the record is too short).
    pub adev_dps: Vec<Option<f64>>,
}

/// What mode reversal and the KF did: raw gyros (run without reversal, same noise), the
/// calibrated combined output, and the filtered output.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Report {
    /// Samples analysed.
    pub samples: usize,
    /// Averaging times, s.
    pub tau_s: Vec<f64>,
    /// One line per signal.
    pub lines: Vec<ReportLine>,
}

/// One sample of the chain run, as every block's vectors see it.
pub struct ChainSample<'a> {
    /// Sample index in the run (resets not counted).
    pub index: usize,
    /// KF ROM address in use.
    pub bw_sel: usize,
    /// Gyro A's and B's ADC codes (input format).
    pub y: [i64; 2],
    /// What the fixed chain did.
    pub fixed: &'a Sample,
    /// The float chain with the same quantized coefficients.
    pub float: &'a FloatSample,
    /// The float chain with the designed coefficients.
    pub ideal: &'a FloatSample,
    /// The estimator's bias registers after the sample (bias format).
    pub bias_after: [i128; 2],
    /// Whether a window has produced an estimate since reset, after the sample.
    pub estimated: bool,
    /// The true rate, °/s.
    pub true_rate_dps: f64,
}

/// Cuts one block's vectors from the chain run, sample by sample.
pub trait VectorBuilder {
    /// A synchronous reset of the whole chain before the next sample.
    fn reset(&mut self);

    /// One sample.
    fn sample(&mut self, sample: &ChainSample);

    /// After the last sample: appends the block's directed segments, records what it found in
    /// `results` and returns its vectors.
    fn finish(self: Box<Self>, results: &mut BlockResults) -> Block;
}

/// What one block's vector builder reports beside its vectors; the run gathers them by key
/// ([`Run::stats`], [`Overflows::directed`], [`Run::fact`]).
#[derive(Debug, Default)]
pub struct BlockResults {
    /// Fixed-vs-float statistics of its signals, by name (`kf`, `chain`, `bias`,
    /// `mean_filter`): names are unique across the package's blocks.
    pub stats: Vec<(&'static str, ErrorStats)>,
    /// Overflow counts of its directed segments, by key of the manifest's `overflow_counts`.
    pub overflows: Vec<(&'static str, serde_json::Value)>,
    /// Facts for its own manifest section (what its recorded run covered, its tie cases), by
    /// key.
    pub facts: Vec<(&'static str, serde_json::Value)>,
}

/// Samples the run keeps each `bw_sel` for: it cycles through the ROM twice.
fn bw_sel_chunk(samples: usize, entries: usize) -> usize {
    (samples / (2 * entries)).max(1)
}

/// `bw_sel` at sample `k` of a run of `samples` samples over `entries` ROM entries.
pub fn bw_sel_at(k: usize, samples: usize, entries: usize) -> usize {
    (k / bw_sel_chunk(samples, entries)) % entries
}

/// Changes of `bw_sel` in a run of `samples` samples over `entries` ROM entries.
pub fn bw_sel_switches(samples: usize, entries: usize) -> u64 {
    if entries < 2 || samples == 0 {
        0
    } else {
        ((samples - 1) / bw_sel_chunk(samples, entries)) as u64
    }
}

/// Everything the run produced.
#[derive(Debug)]
pub struct Run {
    /// The blocks' vectors, in the order of their builders.
    pub blocks: Vec<Block>,
    /// Fixed-vs-float statistics by name, as the blocks reported them
    /// ([`BlockResults::stats`]), e.g. `kf`: the KF on its own inputs, in output LSB.
    stats: BTreeMap<&'static str, ErrorStats>,
    /// The blocks' manifest facts by block and key ([`BlockResults::facts`]).
    facts: BTreeMap<(&'static str, &'static str), serde_json::Value>,
    /// Overflow counts.
    pub overflows: Overflows,
    /// The Allan report.
    pub report: Report,
    /// Chain samples (excluding resets).
    pub samples: usize,
}

impl Run {
    /// The fixed-vs-float statistics a block reported as `name`, if one did.
    pub fn stats(&self, name: &str) -> Option<&ErrorStats> {
        self.stats.get(name)
    }

    /// The fact `key` block `block` reported for its manifest section, if it did.
    pub fn fact(&self, block: &str, key: &str) -> Option<&serde_json::Value> {
        self.facts
            .iter()
            .find(|((b, k), _)| *b == block && *k == key)
            .map(|(_, v)| v)
    }
}

/// Runs the chain for `job`, handing every sample to `builders` (each cuts one block's
/// vectors, kept in memory or streamed to its files, as the caller set it up), and gathers
/// what they report. `progress` counts the simulated samples.
///
/// # Errors
/// Stimulus errors (a bad CSV file); a builder's write errors.
///
/// # Panics
/// When two builders report statistics or overflow counts under the same key (a programming
/// error; facts are kept per block).
pub fn run<'a>(
    job: &Job,
    mut builders: Vec<Box<dyn VectorBuilder + 'a>>,
    progress: &Progress,
) -> Result<Run> {
    let plan = &job.chain;
    let kf = job.kf();
    let est = &plan.estimator;
    let rate = job.rate_source(job.config.samples)?;
    let n = job.config.samples;
    // Work units: chain samples of each closed-loop gyro simulation (two with reversal, two
    // without, for the report), then of the chain itself.
    let simulations = if job.settings.resonator.is_some() {
        4
    } else {
        0
    };
    progress.plan((simulations + 1) * n as u64);
    let entries = kf.rom.len();
    // One reset of the whole chain, late in the run, so that the report has a long stretch of
    // calibrated output before it.
    // A recording runs without it: its rows follow the sequencer from the first on.
    let reset_at = if n >= 20 && job.recording.is_none() {
        Some(n - n / 10)
    } else {
        None
    };

    // The gyros as the sequencer drives them, and the same gyros without reversal (same
    // noise streams) for the report, simulated a batch ahead of the chain.
    let mut gyros = Gyros::new(job, if n > 0 { rate.at(0) } else { 0.0 }, Twins::Unreversed)?;
    let mut sequencer = Sequencer::new(&est.schedule);
    let mut fixed = FixedChain::new(plan);
    let mut float = FloatChain::quantized(plan);
    let mut ideal = FloatChain::ideal(plan);
    let mut first_estimate: Option<usize> = None;
    let fs = job.config.stimulus.fs_hz;
    let mut report = ReportStream::new(fs);
    let (mut last_combined, mut last_filtered) = (0.0, 0.0);
    let mut batch = Batch::default();

    for first in (0..n).step_by(BATCH) {
        let last = (first + BATCH).min(n);
        batch.clear();
        for k in first..last {
            if reset_at == Some(k) {
                sequencer.reset();
            }
            let slot = sequencer.advance();
            batch.modes.push([slot.mode_a, slot.mode_b]);
            batch.blanked.push([slot.blank_a, slot.blank_b]);
            batch.rates.push(rate.at(k));
        }
        gyros.simulate(&mut batch, &|done| progress.advance(done))?;
        for (i, k) in (first..last).enumerate() {
            if k % PROGRESS_STEP == PROGRESS_STEP - 1 {
                progress.advance(PROGRESS_STEP as u64);
            }
            if reset_at == Some(k) {
                fixed.reset();
                float.reset();
                ideal.reset();
                for builder in &mut builders {
                    builder.reset();
                }
            }
            let bw_sel = bw_sel_at(k, n, entries);
            let y = batch.codes[i];
            let y_real = [
                est.input.to_f64(i128::from(y[0])),
                est.input.to_f64(i128::from(y[1])),
            ];
            let a = fixed.step(y, bw_sel);
            let b = float.step(y_real, bw_sel);
            let c = ideal.step(y_real, bw_sel);
            let sample = ChainSample {
                index: k,
                bw_sel,
                y,
                fixed: &a,
                float: &b,
                ideal: &c,
                bias_after: fixed.estimator().bias(),
                estimated: fixed.estimator().estimated(),
                true_rate_dps: batch.rates[i],
            };
            for builder in &mut builders {
                builder.sample(&sample);
            }
            if let Some(code) = a.rate {
                last_filtered = kf.output.to_f64(i128::from(code));
            }
            if a.estimator.combined_valid {
                last_combined = est.calibrated.to_f64(i128::from(a.estimator.combined));
            }
            if first_estimate.is_none() && a.estimator.estimated {
                first_estimate = Some(k);
            }
            // Only calibrated samples: from the first estimate to the reset.
            if first_estimate.is_some() && reset_at.is_none_or(|r| k < r) {
                let [raw_a, raw_b] = batch.raw[i];
                report.push(batch.rates[i], [raw_a, raw_b, last_combined, last_filtered]);
            }
        }
    }
    let Gathered {
        blocks,
        stats,
        facts,
        directed,
    } = gather(builders)?;
    Ok(Run {
        blocks,
        stats,
        facts,
        overflows: Overflows {
            adc: gyros.saturations(),
            estimator: fixed.estimator().overflow_counts().into(),
            kf_chain: fixed.kf().overflow_counts().into(),
            gyro_loop: gyros.loop_counts(),
            directed,
        },
        report: report.finish(),
        samples: n,
    })
}

/// What the builders returned and reported, gathered by key ([`gather`]).
struct Gathered {
    blocks: Vec<Block>,
    stats: BTreeMap<&'static str, ErrorStats>,
    facts: BTreeMap<(&'static str, &'static str), serde_json::Value>,
    directed: BTreeMap<&'static str, serde_json::Value>,
}

/// Finishes every builder (its directed segments, its files) and gathers what each reported.
///
/// # Panics
/// When two builders report statistics or overflow counts under the same key.
fn gather<'a>(builders: Vec<Box<dyn VectorBuilder + 'a>>) -> Result<Gathered> {
    let mut gathered = Gathered {
        blocks: Vec::with_capacity(builders.len()),
        stats: BTreeMap::new(),
        facts: BTreeMap::new(),
        directed: BTreeMap::new(),
    };
    for builder in builders {
        let mut results = BlockResults::default();
        let mut block = builder.finish(&mut results);
        block.finish_rows()?;
        let twice = |what: &str, key: &str| panic!("two blocks report the {what} `{key}`");
        for (name, value) in results.stats {
            if gathered.stats.insert(name, value).is_some() {
                twice("statistics", name);
            }
        }
        for (key, value) in results.overflows {
            if gathered.directed.insert(key, value).is_some() {
                twice("overflow counts", key);
            }
        }
        for (key, value) in results.facts {
            gathered.facts.insert((block.name, key), value);
        }
        gathered.blocks.push(block);
    }
    Ok(gathered)
}

/// The signals of the report, in its order.
const REPORT_SIGNALS: [&str; 4] = [
    "raw gyro A (no reversal)",
    "raw gyro B (no reversal)",
    "calibrated, combined",
    "filtered (KF output)",
];

/// Averaging times the report considers, s (those with at least three averages are shown).
const REPORT_TAUS_S: [f64; 5] = [0.1, 1.0, 10.0, 100.0, 1000.0];

/// The report accumulated sample by sample: per signal the sum of its error against the true
/// rate and its overlapping ADEV at the report's averaging times.
struct ReportStream {
    factors: Vec<(f64, usize)>,
    errors: [f64; 4],
    deviations: [OverlappingStream; 4],
    samples: usize,
}

impl ReportStream {
    fn new(fs: f64) -> Self {
        let factors: Vec<(f64, usize)> = REPORT_TAUS_S
            .iter()
            .map(|tau| (*tau, (tau * fs).round() as usize))
            .filter(|(tau, m)| *m >= 1 && tau * fs >= 1.0)
            .collect();
        let ms: Vec<usize> = factors.iter().map(|(_, m)| *m).collect();
        ReportStream {
            deviations: std::array::from_fn(|_| OverlappingStream::new(&ms, fs)),
            factors,
            errors: [0.0; 4],
            samples: 0,
        }
    }

    /// One sample: the true rate and the four signals, °/s.
    fn push(&mut self, rate: f64, signals: [f64; 4]) {
        for ((sum, deviation), signal) in self
            .errors
            .iter_mut()
            .zip(&mut self.deviations)
            .zip(signals)
        {
            let error = signal - rate;
            *sum += error;
            deviation.push(error);
        }
        self.samples += 1;
    }

    fn finish(self) -> Report {
        let shown: Vec<bool> = self
            .factors
            .iter()
            .map(|(_, m)| m * 3 <= self.samples)
            .collect();
        let tau_s = self
            .factors
            .iter()
            .zip(&shown)
            .filter(|(_, s)| **s)
            .map(|((tau, _), _)| *tau)
            .collect();
        let lines = REPORT_SIGNALS
            .iter()
            .zip(self.errors)
            .zip(&self.deviations)
            .map(|((name, sum), deviation)| ReportLine {
                signal: name.to_string(),
                bias_error_dps: sum / self.samples.max(1) as f64,
                adev_dps: deviation
                    .deviations()
                    .into_iter()
                    .zip(&shown)
                    .filter(|(_, s)| **s)
                    .map(|(d, _)| d.map(|(dev, _)| dev))
                    .collect(),
            })
            .collect();
        Report {
            samples: self.samples,
            tau_s,
            lines,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_switch_count_is_the_runs_bw_sel_changes() {
        for (samples, entries) in [
            (0, 3),
            (1, 3),
            (5, 3),
            (10_000, 3),
            (10_001, 2),
            (7, 1),
            (999, 4),
        ] {
            let changes = (1..samples)
                .filter(|&k| bw_sel_at(k, samples, entries) != bw_sel_at(k - 1, samples, entries))
                .count() as u64;
            assert_eq!(
                bw_sel_switches(samples, entries),
                changes,
                "{samples} {entries}"
            );
        }
    }
}
