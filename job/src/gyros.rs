//! The two gyros a run feeds its chain from, simulated (rate-level streams or resonator-level
//! closed loops) or read from a recording, a batch of chain samples at a time. The one gyro
//! simulation of gyrofx: `generate`'s chain run and `explore`'s candidates both take their
//! input from here.

use gyrofx_model::fx::Format;
use gyrofx_model::gyro_loop::closed::{ClosedLoop, FixedClosedLoop, FixedHarness, LoopUnderTest};
use gyrofx_model::gyro_loop::gyro::LoopOverflows;
use gyrofx_model::plant::GyroStream;
use gyrofx_model::resonator::Mode;
use gyrofx_model::stimulus::adc;
use gyrofx_model::system::loop_mode;
use serde::Serialize;

use crate::config::GyroLoop;
use crate::error::{Error, Result};
use crate::job::Job;

/// Chain samples a caller hands [`Gyros::simulate`] at a time (the gyros run that far ahead
/// of the chain).
pub const BATCH: usize = 2048;

/// One batch of chain samples: the true rates (°/s), the sequencer's modes `[p_A, p_B]` and
/// blanking in; the gyros' codes (the chain's input format) and, with [`Twins::Unreversed`],
/// the unreversed gyros' outputs (°/s) out.
#[derive(Clone, Debug, Default)]
pub struct Batch {
    /// The true rate of each sample, °/s.
    pub rates: Vec<f64>,
    /// The sequencer's modes of A and B (+1 normal, −1 reversed).
    pub modes: Vec<[i8; 2]>,
    /// Whether the sequencer blanks A's and B's sample (for the loops' saturation counts;
    /// empty: none is).
    pub blanked: Vec<[bool; 2]>,
    /// The chain's input codes of A and B.
    pub codes: Vec<[i64; 2]>,
    /// The unreversed twins' outputs of A and B (°/s); empty without them.
    pub raw: Vec<[f64; 2]>,
}

impl Batch {
    /// Empties the inputs for the next batch.
    pub fn clear(&mut self) {
        self.rates.clear();
        self.modes.clear();
        self.blanked.clear();
    }
}

/// Whether each gyro has an unreversed twin beside it: the same gyro with the same noise,
/// always in normal mode, whose output the report compares with the calibrated chain.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Twins {
    /// A and B only.
    None,
    /// A and B, and A and B always in normal mode.
    Unreversed,
}

/// One resonator-level gyro's loop saturations and wraps on the record (the start-up before
/// it not included), node by node, split by the sequencer's blanking of the chain sample they
/// fell in.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct GyroLoopCounts {
    /// In chain samples the estimator takes: they reach the chain's output.
    pub used: LoopOverflows,
    /// In blanked chain samples (the transient after a mode switch, which the sequencer
    /// blanks because it may exceed the output range): not counted among the run's overflows.
    pub blanked: LoopOverflows,
}

/// The gyros of a run ([`Gyros::new`]).
pub struct Gyros {
    kind: Kind,
    twins: Twins,
}

enum Kind {
    Rate {
        reversed: Box<[GyroStream; 2]>,
        normal: Box<[GyroStream; 2]>,
        input: Format,
        saturations: [u64; 2],
    },
    Resonator {
        reversed: Box<[FixedClosedLoop; 2]>,
        normal: Box<[FixedClosedLoop; 2]>,
        scale: f64,
        /// The saturations of `reversed` (whose outputs feed the chain) on the record.
        counts: Box<[GyroLoopCounts; 2]>,
        /// `reversed`'s running counts at the last chain sample.
        last: Box<[LoopOverflows; 2]>,
    },
    /// Recorded outputs (`generate --recording`): already in the sequencer's modes; their
    /// twins are the same record.
    Recorded {
        rows: Box<crate::recording::Rows>,
        /// This batch's rates of gyro A and B, °/s.
        rates: [Vec<f64>; 2],
        input: Format,
        saturations: [u64; 2],
    },
}

/// Start-up before the record: the loops lock from rest (about 80 ms for paper 004's gyro).
pub const RESONATOR_STARTUP_S: f64 = 0.5;

/// Resonator-level gyro `g` of a run seeded `seed` (the seed `2·seed + g`), its loop closed
/// (fixed or float: `L`) and run [`RESONATOR_STARTUP_S`] at the first sample's rate `rate0`
/// (°/s) in normal mode before the record, as every run of gyrofx starts it.
///
/// # Errors
/// Resonator parameters the physics refuses, named by their config section.
pub fn started_loop<L: LoopUnderTest>(
    gyro: &GyroLoop,
    g: usize,
    seed: u64,
    rate0: f64,
) -> Result<ClosedLoop<L>> {
    let mut closed = ClosedLoop::<L>::new(
        &gyro.plan,
        &gyro.params,
        &gyro.front_end,
        seed.wrapping_mul(2).wrapping_add(g as u64),
    )
    .map_err(|e| Error::config(format!("resonator_{}", gyro.name), e, "see gyrofx init"))?;
    let startup = (RESONATOR_STARTUP_S * gyro.plan.chain_rate_hz()).ceil() as usize;
    for _ in 0..startup {
        closed.step_chain(rate0, Mode::Normal);
    }
    Ok(closed)
}

/// Chain samples between two calls of the progress callback.
pub const PROGRESS_STEP: usize = 1024;

impl Gyros {
    /// The gyros of `job`, with or without `twins`. Resonator-level gyro `g` takes the seed
    /// `2·seed + g` and runs [`RESONATOR_STARTUP_S`] at the first sample's rate `rate0` (°/s)
    /// in normal mode before the record; its outputs are already codes of the chain's input
    /// format (checked by the config).
    ///
    /// # Errors
    /// A recording that cannot be opened; resonator parameters the physics refuses.
    pub fn new(job: &Job, rate0: f64, twins: Twins) -> Result<Self> {
        let seed = job.config.seed;
        let input = job.chain.estimator.input;
        if let Some(recording) = &job.recording {
            let kind = Kind::Recorded {
                rows: Box::new(recording.rows()?),
                rates: [Vec::with_capacity(BATCH), Vec::with_capacity(BATCH)],
                input,
                saturations: [0; 2],
            };
            return Ok(Gyros { kind, twins });
        }
        let kind = match &job.settings.resonator {
            None => {
                let plant = &job.settings.plant;
                let streams = || Box::new([0, 1].map(|g| plant.gyro_stream(g, seed)));
                Kind::Rate {
                    reversed: streams(),
                    normal: streams(),
                    input,
                    saturations: [0; 2],
                }
            }
            Some(loops) => {
                let closed = |g: usize| started_loop::<FixedHarness>(&loops[g], g, seed, rate0);
                let reversed = Box::new([closed(0)?, closed(1)?]);
                let normal = reversed.clone();
                // The start-up is not the record: its saturations are left out.
                let last = Box::new(reversed.each_ref().map(|gyro| gyro.gyro.overflows()));
                Kind::Resonator {
                    reversed,
                    normal,
                    scale: libm::ldexp(1.0, input.frac),
                    counts: Box::default(),
                    last,
                }
            }
        };
        Ok(Gyros { kind, twins })
    }

    /// Fills `batch.codes` (and `batch.raw` with twins) for its rates and modes; the
    /// resonator-level loops call `progress` with the chain samples they simulated, every
    /// [`PROGRESS_STEP`] of them (twice that with twins: their twins are as much work).
    ///
    /// # Errors
    /// A recording that cannot be read to the batch's end.
    pub fn simulate(&mut self, batch: &mut Batch, progress: &(dyn Fn(u64) + Sync)) -> Result<()> {
        let len = batch.rates.len();
        let twins = self.twins == Twins::Unreversed;
        batch.codes.clear();
        batch.raw.clear();
        match &mut self.kind {
            Kind::Rate {
                reversed,
                normal,
                input,
                saturations,
            } => {
                let mut values: [Vec<f64>; 2] = [Vec::with_capacity(len), Vec::with_capacity(len)];
                for (omega, modes) in batch.rates.iter().zip(&batch.modes) {
                    for g in 0..2 {
                        values[g].push(reversed[g].step(*omega, modes[g]).0);
                    }
                    if twins {
                        batch.raw.push([0, 1].map(|g| normal[g].step(*omega, 1).0));
                    }
                }
                let [(a, sat_a), (b, sat_b)] = values.map(|v| adc(&v, *input));
                saturations[0] += sat_a;
                saturations[1] += sat_b;
                batch
                    .codes
                    .extend(a.into_iter().zip(b).map(|(a, b)| [a, b]));
            }
            Kind::Resonator {
                reversed,
                normal,
                scale,
                counts,
                last,
            } => {
                let scale = *scale;
                let (rates, modes, blanked) = (&batch.rates, &batch.modes, &batch.blanked);
                let weight = if twins { 2 } else { 1 };
                let run = |g: usize,
                           reversed: &mut FixedClosedLoop,
                           normal: &mut FixedClosedLoop,
                           counts: &mut GyroLoopCounts,
                           last: &mut LoopOverflows| {
                    let mut out = Vec::with_capacity(len);
                    for (k, (omega, mode)) in rates.iter().zip(modes).enumerate() {
                        if k % PROGRESS_STEP == PROGRESS_STEP - 1 {
                            progress(weight * PROGRESS_STEP as u64);
                        }
                        let output = reversed
                            .step_chain(*omega, loop_mode(mode[g]))
                            .output
                            .rate_dps;
                        // Booked to the chain sample they fell in, so that a switch
                        // transient's are told apart from those the chain takes in.
                        let now = reversed.gyro.overflows();
                        let stretch = if blanked.get(k).is_some_and(|b| b[g]) {
                            &mut counts.blanked
                        } else {
                            &mut counts.used
                        };
                        stretch.add(&now.since(last));
                        *last = now;
                        let raw = if twins {
                            normal.step_chain(*omega, Mode::Normal).output.rate_dps
                        } else {
                            0.0
                        };
                        out.push(((output * scale).round() as i64, raw));
                    }
                    out
                };
                let [reversed_a, reversed_b] = &mut **reversed;
                let [normal_a, normal_b] = &mut **normal;
                let [counts_a, counts_b] = &mut **counts;
                let [last_a, last_b] = &mut **last;
                let (a, b) = std::thread::scope(|scope| {
                    let b = scope.spawn(|| run(1, reversed_b, normal_b, counts_b, last_b));
                    let a = run(0, reversed_a, normal_a, counts_a, last_a);
                    (a, b.join().expect("the loop simulation does not panic"))
                });
                for ((code_a, raw_a), (code_b, raw_b)) in a.into_iter().zip(b) {
                    batch.codes.push([code_a, code_b]);
                    if twins {
                        batch.raw.push([raw_a, raw_b]);
                    }
                }
            }
            Kind::Recorded {
                rows,
                rates,
                input,
                saturations,
            } => {
                rates.iter_mut().for_each(Vec::clear);
                rows.read_into(len, rates)?;
                let [(a, sat_a), (b, sat_b)] = [0, 1].map(|g| adc(&rates[g], *input));
                saturations[0] += sat_a;
                saturations[1] += sat_b;
                batch
                    .codes
                    .extend(a.into_iter().zip(b).map(|(a, b)| [a, b]));
                if twins {
                    batch
                        .raw
                        .extend(rates[0].iter().zip(&rates[1]).map(|(a, b)| [*a, *b]));
                }
            }
        }
        Ok(())
    }

    /// The resonator-level gyros' loop saturations on the record so far (zeros for the other
    /// gyros).
    pub fn loop_counts(&self) -> [GyroLoopCounts; 2] {
        match &self.kind {
            Kind::Resonator { counts, .. } => **counts,
            Kind::Rate { .. } | Kind::Recorded { .. } => Default::default(),
        }
    }

    /// ADC saturations of gyro A and B so far (the pick-offs' for resonator-level gyros).
    pub fn saturations(&self) -> [u64; 2] {
        match &self.kind {
            Kind::Rate { saturations, .. } | Kind::Recorded { saturations, .. } => *saturations,
            Kind::Resonator { reversed, .. } => reversed
                .each_ref()
                .map(|gyro| gyro.resonator.adc_saturations()),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::config::Config;

    /// The codes of `samples` samples of `job`'s gyros, `batch` samples at a time, every 7th
    /// sample of A reversed and every 5th of B.
    fn codes(job: &Job, samples: usize, batch: usize, twins: Twins) -> Vec<[i64; 2]> {
        let mut gyros = Gyros::new(job, 10.0, twins).unwrap();
        let mut out = Vec::new();
        let mut slice = Batch::default();
        for first in (0..samples).step_by(batch) {
            slice.clear();
            for k in first..(first + batch).min(samples) {
                slice.rates.push(10.0 + 0.01 * k as f64);
                slice.modes.push([
                    if k % 7 == 0 { -1 } else { 1 },
                    if k % 5 == 0 { -1 } else { 1 },
                ]);
            }
            gyros.simulate(&mut slice, &|_| {}).unwrap();
            assert_eq!(slice.codes.len(), slice.rates.len());
            let with_twins = if twins == Twins::Unreversed {
                slice.rates.len()
            } else {
                0
            };
            assert_eq!(slice.raw.len(), with_twins);
            out.extend_from_slice(&slice.codes);
        }
        out
    }

    fn job(toml: &str) -> Job {
        Job::new(Config::from_toml(toml, "test.toml").unwrap()).unwrap()
    }

    #[test]
    fn batches_and_twins_do_not_change_the_rate_level_gyros_codes() {
        let job = job("[plant]\nmodel = \"rate\"\n");
        assert!(job.settings.resonator.is_none());
        let one = codes(&job, 3000, 3000, Twins::None);
        assert_eq!(one, codes(&job, 3000, 333, Twins::Unreversed));
        assert_eq!(one, codes(&job, 3000, BATCH, Twins::None));
        // Reversal shows: the codes are not those of a run without it.
        assert!(one.iter().any(|c| c[0] != c[1]));
    }

    #[test]
    fn batches_and_twins_do_not_change_the_resonator_level_gyros_codes() {
        let job = job("");
        assert!(job.settings.resonator.is_some());
        let one = codes(&job, 300, 300, Twins::None);
        assert_eq!(one, codes(&job, 300, 64, Twins::Unreversed));
    }
}
