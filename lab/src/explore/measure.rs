//! What a candidate's word lengths cost in noise: the chain's fixed output against its float
//! twin over the configured stimulus.
//!
//! The gyros are simulated as `generate` simulates them (same seeds, the sequencer's modes,
//! the resonator loops started 0.5 s ahead at the first sample's rate), into the chain's input
//! codes; `bw_sel` cycles through the KF's ROM twice, as in `generate`'s run, without its late
//! reset. Two references:
//!
//! - [`Reference::Chain`] (no `loop.*` key swept): the fixed chain against its float twin
//!   ([`FloatChain::quantized`]: same quantized coefficients) on the same gyro codes — the
//!   chain's own quantization, as `generate`'s report states it. The gyros are simulated once
//!   for every candidate.
//! - [`Reference::System`] (a `loop.*` key swept): the fixed loops and chain against the float
//!   loops ([`FloatHarness`] closed around the same resonators, seeds and noise) and the float
//!   chain — the quantization of the loop and the chain together. Simulated per candidate.
//!
//! The error `e = fixed − float` of the KF output (°/s; blanked samples hold the last output,
//! as the hardware does) gives:
//!
//! - rms and max of `|e|` over every sample the KF stepped ([`gyrofx_codegen::stats::Accumulator`]), in
//!   output LSB and °/s;
//! - `σ_e(τ)`, `σ_out(τ)`: the overlapping ADEV ([`OverlappingStream`]) at τ = m/fs, m =
//!   round(fs · 1 s), of `e` and of the float output, from the first bias estimate on (before
//!   it the output carries the uncorrected mode-reversal bias); `adev_share = σ_e / σ_out`;
//! - the quantization noise's ARW `N_q = σ_e(τ) · √τ` (°/√s, × 60 for °/√h): the IEEE 952
//!   reading of the −½ line at τ = 1 s. At 1 s the error is white (the KF's time constant is
//!   1/(2π·bandwidth), ≤ 16 ms in the default), so this is its white-noise level; at the
//!   shortest τ the KF's low-pass would hide the state's rounding noise. Anything slower in `e`
//!   (the bias estimates' rounding, which changes once a window) adds to `σ_e(1 s)`: the
//!   reading errs on the safe side. `arw_share = N_q / kf.arw_deg_per_sqrt_h` (the sensor's
//!   ARW the KF is designed for, paper 000's 4.87 °/√h in the default);
//! - the chain's quantizer overflows and saturations on the run's data (estimator,
//!   calibration, KF): what `generate --strict` refuses.

use gyrofx_model::analysis::allan::OverlappingStream;
use gyrofx_model::chain::{FixedChain, FloatChain};
use gyrofx_model::gyro_loop::closed::FloatHarness;
use gyrofx_model::sequencer::Sequencer;
use gyrofx_model::system::loop_mode;
use serde::Serialize;

use gyrofx_codegen::stats::Accumulator;
use gyrofx_codegen::vectors::{bw_sel_at, bw_sel_switches, EstimatorCounts, KfCounts};
use gyrofx_job::config::GyroLoop;
use gyrofx_job::error::Result;
use gyrofx_job::gyros::{started_loop, Batch, Gyros, Twins, BATCH};
use gyrofx_job::job::Job;

/// The averaging time of the ADEV and ARW readings, s.
pub const TAU_S: f64 = 1.0;

/// Which float model the fixed output is compared with.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Reference {
    /// The float chain on the fixed gyros' codes.
    Chain,
    /// The float loops and the float chain.
    System,
}

impl Reference {
    /// One line for the manifest and the CSV's readers.
    pub fn describe(self) -> &'static str {
        match self {
            Reference::Chain => {
                "fixed chain vs its float twin (same quantized coefficients) on the same gyro codes"
            }
            Reference::System => {
                "fixed loops and chain vs the float loops (same resonators, seeds and noise) and float chain"
            }
        }
    }
}

/// A candidate's noise figures.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Metrics {
    /// Rms of `fixed − float` over the KF's steps, output LSB.
    pub rms_lsb: f64,
    /// Largest `|fixed − float|`, output LSB.
    pub max_lsb: f64,
    /// Rms, °/s.
    pub rms_dps: f64,
    /// Largest, °/s.
    pub max_dps: f64,
    /// Overlapping ADEV of `fixed − float` at [`TAU_S`], °/s.
    pub adev_error_dps: f64,
    /// Overlapping ADEV of the float output at [`TAU_S`], °/s.
    pub adev_output_dps: f64,
    /// `adev_error_dps / adev_output_dps`.
    pub adev_share: f64,
    /// The quantization noise's ARW, `σ_e(τ)·√τ` in °/√h.
    pub arw_deg_per_sqrt_h: f64,
    /// `arw_deg_per_sqrt_h` over the sensor's ARW (`kf.arw_deg_per_sqrt_h`).
    pub arw_share: f64,
    /// Overflows and saturations of the chain's quantizers on the run's data.
    pub overflows: u64,
}

/// The chain's input over the record: the fixed gyros' codes, and the float gyros' rates
/// (°/s) for [`Reference::System`].
#[derive(Clone, Debug)]
pub struct Stimulus {
    codes: Vec<[i64; 2]>,
    float: Option<Vec<[f64; 2]>>,
}

/// The sequencer's modes `[p_A, p_B]` over `samples` samples.
fn modes(job: &Job, samples: usize) -> Vec<[i8; 2]> {
    let mut sequencer = Sequencer::new(&job.chain.estimator.schedule);
    (0..samples)
        .map(|_| {
            let slot = sequencer.advance();
            [slot.mode_a, slot.mode_b]
        })
        .collect()
}

/// Gyro `g`'s float loop closed around its resonator and started up as every run starts it
/// ([`started_loop`]); its chain-rate outputs (°/s) over the record.
fn float_loop_rates(
    gyro: &GyroLoop,
    g: usize,
    seed: u64,
    rates: &[f64],
    modes: &[[i8; 2]],
) -> Result<Vec<f64>> {
    let rate0 = rates.first().copied().unwrap_or(0.0);
    let mut closed = started_loop::<FloatHarness>(gyro, g, seed, rate0)?;
    Ok(rates
        .iter()
        .zip(modes)
        .map(|(omega, m)| closed.step_chain(*omega, loop_mode(m[g])).output.rate_dps)
        .collect())
}

/// Simulates the gyros of `job` over its `samples` ([`Gyros`], as `generate` does) into the
/// chain's input codes, and with `float_twin` also the float loops' rates (the two gyros side
/// by side in the lab's pool).
///
/// # Errors
/// A bad CSV stimulus, or resonator parameters the physics refuses.
pub fn stimulus(job: &Job, float_twin: bool) -> Result<Stimulus> {
    let samples = job.config.samples;
    let rates = job.true_rate(samples)?;
    let modes = modes(job, samples);
    let seed = job.config.seed;
    let mut gyros = Gyros::new(job, rates.first().copied().unwrap_or(0.0), Twins::None)?;
    let mut codes = Vec::with_capacity(samples);
    let mut batch = Batch::default();
    for (rates, modes) in rates.chunks(BATCH).zip(modes.chunks(BATCH)) {
        batch.clear();
        batch.rates.extend_from_slice(rates);
        batch.modes.extend_from_slice(modes);
        gyros.simulate(&mut batch, &|_| {})?;
        codes.extend_from_slice(&batch.codes);
    }
    let float = match (&job.settings.resonator, float_twin) {
        (Some(loops), true) => {
            let [a, b]: [Vec<f64>; 2] = crate::pool::try_map(&[0, 1], 2, |&g| {
                float_loop_rates(&loops[g], g, seed, &rates, &modes)
            })?
            .try_into()
            .expect("two gyros");
            Some(a.into_iter().zip(b).map(|(a, b)| [a, b]).collect())
        }
        _ => None,
    };
    Ok(Stimulus { codes, float })
}

/// The first sample at which the chain of `job` has a bias estimate (from reset, whatever the
/// data): the analysed part of the record starts there.
pub fn first_estimate(job: &Job) -> usize {
    let schedule = &job.chain.estimator.schedule;
    // A window of both gyros' schedules, B's behind A's: well within two windows.
    let limit = 2 * (schedule.intervals * schedule.interval_length + schedule.stagger) + 1;
    let mut chain = FixedChain::new(&job.chain);
    (0..limit)
        .find(|_| chain.step([0, 0], 0).estimator.estimated)
        .unwrap_or(limit)
}

/// The averaging factor of [`TAU_S`] at `fs_hz`: round(fs · τ), at least 1.
pub fn tau_factor(fs_hz: f64) -> usize {
    ((fs_hz * TAU_S).round() as usize).max(1)
}

/// The shortest record whose analysed part holds an ADEV at [`TAU_S`]: the first estimate,
/// then `2m + 1` samples (an overlapping ADEV at factor m needs 2m + 1 phase points).
pub fn min_samples(job: &Job) -> usize {
    first_estimate(job) + 2 * tau_factor(job.config.stimulus.fs_hz) + 1
}

/// Runs the fixed chain of `job` and its float reference over `stimulus` and measures the
/// error.
///
/// # Errors
/// The text of why: a record too short for the ADEV at [`TAU_S`].
pub fn measure(job: &Job, stimulus: &Stimulus) -> std::result::Result<Metrics, String> {
    let plan = &job.chain;
    let samples = stimulus.codes.len();
    let entries = plan.kf.rom.len();
    let fs = job.config.stimulus.fs_hz;
    let m = tau_factor(fs);
    let output = plan.kf.output;
    let input = plan.estimator.input;
    let mut fixed = FixedChain::new(plan);
    let mut float = FloatChain::quantized(plan);
    let mut errors = Accumulator::default();
    let mut error_adev = OverlappingStream::new(&[m], fs);
    let mut output_adev = OverlappingStream::new(&[m], fs);
    let (mut last_fixed, mut last_float) = (0.0, 0.0);
    let mut analysed = false;
    for k in 0..samples {
        let sel = bw_sel_at(k, samples, entries);
        let codes = stimulus.codes[k];
        let a = fixed.step(codes, sel);
        let y = match &stimulus.float {
            Some(rates) => rates[k],
            None => codes.map(|c| input.to_f64(i128::from(c))),
        };
        let b = float.step(y, sel);
        if let Some(code) = a.rate {
            last_fixed = output.to_f64(i128::from(code));
        }
        if let Some(rate) = b.rate {
            last_float = rate;
        }
        if a.rate.is_some() {
            // Only the rms and max are read: the float output stands in for the ideal one.
            errors.add(last_fixed, last_float, last_float, output.lsb());
        }
        analysed |= a.estimator.estimated;
        if analysed {
            error_adev.push(last_fixed - last_float);
            output_adev.push(last_float);
        }
    }
    let deviation = |stream: &OverlappingStream| stream.deviations()[0].map(|(d, _)| d);
    let (Some(adev_error_dps), Some(adev_output_dps)) =
        (deviation(&error_adev), deviation(&output_adev))
    else {
        return Err(format!(
            "{samples} samples are too few for an Allan deviation at τ = {TAU_S} s: {} after the first bias estimate (sample {}) are needed",
            2 * m + 1,
            first_estimate(job)
        ));
    };
    let stats = errors.finish(f64::NAN);
    let tau = m as f64 / fs;
    let arw_deg_per_sqrt_h = adev_error_dps * tau.sqrt() * 60.0;
    let e: EstimatorCounts = fixed.estimator().overflow_counts().into();
    let f: KfCounts = fixed.kf().overflow_counts().into();
    let overflows = e.total() + f.total();
    Ok(Metrics {
        rms_lsb: stats.rms_lsb,
        max_lsb: stats.max_lsb,
        rms_dps: stats.rms_lsb * output.lsb(),
        max_dps: stats.max_lsb * output.lsb(),
        adev_error_dps,
        adev_output_dps,
        adev_share: adev_error_dps / adev_output_dps,
        arw_deg_per_sqrt_h,
        arw_share: arw_deg_per_sqrt_h / job.config.kf.arw_deg_per_sqrt_h,
        overflows,
    })
}

/// Changes of `bw_sel` in the run (for the formats' proof over the record).
pub fn switches(job: &Job) -> u64 {
    bw_sel_switches(job.config.samples, job.kf().rom.len())
}
