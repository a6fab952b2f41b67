//! Paper 004's Table 2 through the real loops: the `gu2019` preset's resonator-level gyros,
//! whose front ends carry the paper's raw N and B ([`calibration`](super::calibration)), each
//! closed by its fixed-point loop at 200 kHz. Per column, as the paper: gyro A and gyro B alone
//! (normal mode, no reversal), the two-gyro system under mode reversal ([`record`]: both loops,
//! the sequencer, the estimator, the KF), and that output denoised. The raw gyros run on the
//! same random streams as the system's (one seed per gyro), so the columns differ only by
//! what reversal does.
//!
//! The four runs (the system also drift-free, for at most 200 s), and each gyro's drift-free
//! white noise and loop floor, go side by side on the lab's pool, longest first: 1000 s
//! (9.6·10⁸ gyro-samples in all) takes 65 s of `reproduce --paper 004` on two cores. The
//! system is one run, half the work: more cores than two shorten it little.

use gyrofx_job::config::GyroLoop;
use gyrofx_job::error::{Error, Result};
use gyrofx_job::gyros::RESONATOR_STARTUP_S;
use gyrofx_model::chain::Plan as ChainPlan;
use gyrofx_model::gyro_loop::closed::FixedClosedLoop;
use gyrofx_model::resonator::Mode;
use gyrofx_model::system::{record, GyroPhysics};

use super::calibration::{self, Calibration};

/// One piece of the comparison.
#[derive(Clone, Copy, Debug)]
enum Run {
    /// Both gyros under mode reversal through the chain.
    System,
    /// The same with the drifts off, for [`DRIFT_FREE_SAMPLES`] at most.
    SystemDriftFree,
    /// Gyro `g` alone in normal mode.
    Raw(usize),
    /// Gyro `g`'s white noise with its drifts off.
    White(usize),
    /// Gyro `g`'s loop floor (no random source).
    Floor(usize),
}

/// What a run gives.
enum Output {
    /// The calibrated output (°/s at the chain rate) and the chain sample of the first bias
    /// estimate.
    Calibrated(Vec<f64>, usize),
    /// A gyro's rate, °/s at the chain rate.
    Rate(Vec<f64>),
    /// A white-noise level, °/√s.
    Level(f64),
}

/// The records and figures of the resonator-level comparison.
#[derive(Clone, Debug)]
pub struct Records {
    /// Gyro A's and B's rates alone (°/s, chain rate), from the first bias estimate on.
    pub raw: [Vec<f64>; 2],
    /// The calibrated output under reversal (°/s, chain rate), from the first bias estimate
    /// on (a chain sample without a new value holds the last, as the output register does).
    pub calibrated: Vec<f64>,
    /// Each gyro's white noise with its drifts off, °/√s.
    pub white_n: [f64; 2],
    /// The calibrated output under reversal with the drifts off (°/s, chain rate, at most
    /// [`DRIFT_FREE_SAMPLES`]), from the first bias estimate on.
    pub calibrated_drift_free: Vec<f64>,
    /// Each gyro's calibration (with its loop floor measured here).
    pub calibrations: [Calibration; 2],
    /// Gyro-samples simulated.
    pub gyro_samples: u64,
}

/// Chain samples of the drift-free reversal run (200 s at 50 Hz: white noise needs no more).
pub const DRIFT_FREE_SAMPLES: usize = 10_000;

/// Seed of gyro `g`'s random streams in every run of the comparison.
fn gyro_seed(seed: u64, g: usize) -> u64 {
    seed.wrapping_mul(2).wrapping_add(g as u64)
}

/// Runs the comparison on `loops` (the preset's gyros) and `chain` for `samples` chain samples
/// after [`RESONATOR_STARTUP_S`] of locking, and the paper's raw `targets` (`[gyro][N, B]`)
/// that the front ends were calibrated for.
///
/// # Errors
/// Invalid physics, or a target the calibration cannot reach.
pub fn run(
    loops: &[GyroLoop; 2],
    chain: &ChainPlan,
    samples: usize,
    seed: u64,
    targets: [[f64; 2]; 2],
) -> Result<Records> {
    let rate_hz = loops[0].plan.chain_rate_hz();
    let decimation = (loops[0].plan.adc_rate_hz / rate_hz).round() as usize;
    let startup = (RESONATOR_STARTUP_S * rate_hz).ceil() as usize;
    let simulation = |e: String| Error::Simulation(format!("paper 004 at resonator level: {e}"));
    // Longest first: the system is two gyros' work, each raw run one.
    let runs = [
        Run::System,
        Run::SystemDriftFree,
        Run::Raw(0),
        Run::Raw(1),
        Run::White(0),
        Run::White(1),
        Run::Floor(0),
        Run::Floor(1),
    ];
    let jobs = std::thread::available_parallelism().map_or(1, |n| n.get());
    let outputs = crate::pool::try_map(&runs, jobs, |run| -> Result<Output> {
        Ok(match *run {
            Run::System => {
                let (calibrated, first) = reversal(loops, chain, samples, startup, seed, false)?;
                Output::Calibrated(calibrated, first)
            }
            Run::SystemDriftFree => {
                let samples = samples.min(DRIFT_FREE_SAMPLES);
                let (calibrated, first) = reversal(loops, chain, samples, startup, seed, true)?;
                Output::Calibrated(calibrated, first)
            }
            Run::Raw(g) => {
                let gyro = &loops[g];
                let mut closed = FixedClosedLoop::new(
                    &gyro.plan,
                    &gyro.params,
                    &gyro.front_end,
                    gyro_seed(seed, g),
                )
                .map_err(|e| simulation(e.to_string()))?;
                Output::Rate(
                    (0..startup + samples)
                        .map(|_| closed.step_chain(0.0, Mode::Normal).output.rate_dps)
                        .skip(startup)
                        .collect(),
                )
            }
            Run::White(g) => Output::Level(calibration::white_noise(
                &loops[g],
                &loops[g].front_end,
                gyro_seed(seed, g),
            )?),
            Run::Floor(g) => Output::Level(calibration::loop_floor(&loops[g])?),
        })
    })?;
    let mut outputs = outputs.into_iter();
    let (
        Some(Output::Calibrated(calibrated, first)),
        Some(Output::Calibrated(drift_free, first_drift_free)),
        Some(Output::Rate(a)),
        Some(Output::Rate(b)),
    ) = (
        outputs.next(),
        outputs.next(),
        outputs.next(),
        outputs.next(),
    )
    else {
        unreachable!("the runs give their outputs in order")
    };
    let levels: Vec<f64> = outputs
        .map(|o| match o {
            Output::Level(level) => level,
            _ => unreachable!("the white-noise runs give levels"),
        })
        .collect();
    let calibrations = [0, 1]
        .map(|g| calibration::calibrate(&loops[g], targets[g][0], targets[g][1], levels[2 + g]));
    let [ca, cb] = calibrations;
    // The chain steps only once enabled, after the start-up the raw runs skip too: chain
    // sample k of each is the same time.
    let white = calibration::WHITE_SECONDS + 1.0;
    let gyro_samples = ((2 * (startup + samples) * 2
        + 2 * (startup + samples.min(DRIFT_FREE_SAMPLES))) as f64
        * decimation as f64
        + 4.0 * white * loops[0].plan.adc_rate_hz) as u64;
    Ok(Records {
        raw: [a[first..].to_vec(), b[first..].to_vec()],
        calibrated: calibrated[first..].to_vec(),
        white_n: [levels[0], levels[1]],
        calibrated_drift_free: drift_free[first_drift_free..].to_vec(),
        calibrations: [ca?, cb?],
        gyro_samples,
    })
}

/// Both gyros under mode reversal through `chain` (drifts off if `drift_free`): the calibrated
/// output (°/s) of each of `samples` chain samples after `startup` of locking, and the index of
/// the first bias estimate.
fn reversal(
    loops: &[GyroLoop; 2],
    chain: &ChainPlan,
    samples: usize,
    startup: usize,
    seed: u64,
    drift_free: bool,
) -> Result<(Vec<f64>, usize)> {
    let rate_hz = loops[0].plan.chain_rate_hz();
    let decimation = (loops[0].plan.adc_rate_hz / rate_hz).round() as usize;
    let front_ends = [0, 1].map(|g| {
        if drift_free {
            calibration::drift_free(&loops[g].front_end)
        } else {
            loops[g].front_end
        }
    });
    let physics = [0, 1].map(|g| GyroPhysics {
        params: &loops[g].params,
        front_end: &front_ends[g],
        seed: gyro_seed(seed, g),
    });
    let est = &chain.estimator;
    let mut calibrated = Vec::with_capacity(samples);
    let mut first_estimate = None;
    record(
        [&loops[0].plan, &loops[1].plan],
        chain,
        physics,
        0.0,
        (startup + samples) * decimation,
        startup * decimation,
        |_| 0,
        |s| {
            let Some(out) = s.step.chain else { return };
            let value = if out.estimator.combined_valid {
                est.calibrated.to_f64(i128::from(out.estimator.combined))
            } else {
                *calibrated.last().unwrap_or(&0.0)
            };
            if first_estimate.is_none() && out.estimator.estimated {
                first_estimate = Some(calibrated.len());
            }
            calibrated.push(value);
        },
    )
    .map_err(|e| Error::Simulation(format!("paper 004 at resonator level: {e}")))?;
    Ok((calibrated, first_estimate.unwrap_or(0)))
}
