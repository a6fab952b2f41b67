//! The study of one member ([`study`]): a pure function of the nominal plans, the member's
//! physics and the run's length, giving the figures a population is judged by.
//!
//! 1. **Each gyro's loop characterized** ([`characterize`] with the fixed loop, noise and
//!    drift off, the nominal plan around the member's structure and front end): drive
//!    frequency, scale factor, bias per mode beside SPEC §1.6's closed forms, settling (lock
//!    and amplitude; rate within 0.01 °/s) after the switch into each mode, the residual bias
//!    after reversal beside its closed form, and the loop's saturations.
//! 2. **The pair through the chain** ([`FixedSystem`]): both resonators at rest, the loops
//!    locking for [`Study::startup_s`] in normal mode (the chain held), then
//!    [`Study::seconds`] of the sequencer switching the modes, the bias estimator and the KF
//!    at `bw_sel` (noise and drift as [`Study::noise`] says) at the input rate
//!    [`Study::rate_dps`]. Lock: each loop's lock flag at the end of the start-up, and the
//!    time it last rose. The calibrated output: the KF's output minus the input rate from one
//!    interval after the first bias estimate on, its mean (the residual bias the chain leaves)
//!    and standard deviation; with noise its Allan terms (below).
//!
//! Allan terms of the calibrated output are read from its overlapping Allan deviation,
//! accumulated as the samples come ([`OverlappingStream`]: memory does not grow with the
//! run) at octave factors and at τ = 1 s: ARW `N = σ(1 s)·√(1 s)` (the −½ line's reading at
//! τ = 1 s, °/√h), bias instability `B = min σ / 0.6643` (°/h). A blanked chain sample (both
//! gyros blanked) holds the KF's last output, as the output register does.

use std::cell::Cell;

use serde::Serialize;

use super::draw::{GyroPhysics, Member};
use crate::analysis::allan::OverlappingStream;
use crate::analysis::noise::FLICKER_FLOOR;
use crate::chain::Plan as ChainPlan;
use crate::gyro_loop::closed::{ChainOutput, FixedHarness, LoopUnderTest};
use crate::gyro_loop::figures::{characterize, coupled_resonance_hz, Characterization, Procedure};
use crate::gyro_loop::gyro::{LoopOverflows, Plan as LoopPlan};
use crate::resonator::{Mode, Resonator};
use crate::system::FixedSystem;

/// How each member is studied.
#[derive(Clone, Debug)]
pub struct Study<'a> {
    /// Gyro A's and B's loop plans (the nominal ones: every member has the same FPGA).
    pub loops: [&'a LoopPlan; 2],
    /// The chain's plan (sequencer schedule, estimator, KF).
    pub chain: &'a ChainPlan,
    /// Chain run after the start-up, s.
    pub seconds: f64,
    /// Start-up in normal mode with the chain held, s.
    pub startup_s: f64,
    /// Thermomechanical and electronic noise and drift in the chain run (the
    /// characterization is always noiseless, as its closed forms are).
    pub noise: bool,
    /// The input rate of the chain run, °/s.
    pub rate_dps: f64,
    /// The KF's bandwidth selection.
    pub bw_sel: usize,
}

/// Whether a loop locked during the start-up, and when.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Lock {
    /// The lock flag at the end of the start-up.
    pub locked: bool,
    /// When it last rose during the start-up, ms from rest (`None`: not locked at its end).
    pub lock_ms: Option<f64>,
    /// Why not, when not locked: the likeliest cause the loop's plan and the member's
    /// physics show.
    pub why_not: Option<String>,
}

/// One gyro's figures.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct GyroFigures {
    /// Lock at start-up in the chain run.
    pub lock: Lock,
    /// The loop's characterization (noiseless, fixed loop) beside the closed forms.
    pub characterization: Characterization,
    /// The loop's saturations and wraps in the chain run, in chain samples the estimator takes.
    pub saturations_used: u64,
    /// Those in chain samples the sequencer blanks (switch transients).
    pub saturations_blanked: u64,
}

/// What the chain gives for the pair.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct ChainFigures {
    /// Chain samples of the calibrated output the statistics cover.
    pub output_samples: u64,
    /// Mean of KF output − input rate, °/s (`None`: no calibrated sample).
    pub output_mean_dps: Option<f64>,
    /// Its standard deviation, °/s.
    pub output_std_dps: Option<f64>,
    /// The estimator's last bias estimates of A and B, °/s (`None`: no window completed).
    pub bias_estimate_dps: Option<[f64; 2]>,
    /// Overflows and saturations of the estimator's and the KF's quantizers.
    pub chain_overflows: u64,
    /// ARW of the calibrated output, °/√h (with noise and at least 1 s of output; see the
    /// [module doc](self)).
    pub arw_deg_per_sqrt_h: Option<f64>,
    /// Bias instability of the calibrated output, °/h (with noise).
    pub bias_instability_deg_per_h: Option<f64>,
}

/// A member's figures.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct MemberFigures {
    /// Gyro A and B.
    pub gyros: [GyroFigures; 2],
    /// The pair through the chain.
    pub chain: ChainFigures,
    /// Gyro-samples simulated (ADC samples of each resonator and loop, both studies).
    pub gyro_samples: u64,
}

thread_local! {
    static SAMPLES: Cell<u64> = const { Cell::new(0) };
}

/// [`FixedHarness`] counting its samples (per thread) for the gyro-samples a study reports.
struct Counted(FixedHarness);

impl LoopUnderTest for Counted {
    fn from_plan(plan: &LoopPlan) -> Self {
        Counted(FixedHarness::from_plan(plan))
    }
    #[inline]
    fn sample(&mut self, resonator: &mut Resonator, mode: Mode) -> Option<ChainOutput> {
        SAMPLES.with(|n| n.set(n.get() + 1));
        self.0.sample(resonator, mode)
    }
    fn frequency_hz(&self) -> f64 {
        self.0.frequency_hz()
    }
    fn locked(&self) -> bool {
        self.0.locked()
    }
    fn overflows(&self) -> LoopOverflows {
        self.0.overflows()
    }
}

/// Studies `member` as `study` says (see the [module doc](self)).
///
/// # Errors
/// The first drawn parameter the physics refuses, as `gyro a: q_drive = -3 is not allowed: …`.
pub fn study(study: &Study, member: &Member) -> Result<MemberFigures, String> {
    for (g, gyro) in member.gyros.iter().enumerate() {
        let name = ["a", "b"][g];
        gyro.params
            .validate()
            .and_then(|()| gyro.front_end.validate(&gyro.params))
            .map_err(|e| format!("gyro {name}: {e}"))?;
    }
    SAMPLES.with(|n| n.set(0));
    let procedure = Procedure::default();
    let mut characterizations = Vec::with_capacity(2);
    for (plan, gyro) in study.loops.iter().zip(&member.gyros) {
        let c = characterize::<Counted>(plan, &gyro.params, &gyro.front_end, &procedure)
            .map_err(|e| e.to_string())?;
        characterizations.push(c);
    }
    let characterized = SAMPLES.with(Cell::get);
    let run = chain_run(study, &member.gyros)?;
    let gyros = [0, 1].map(|g| GyroFigures {
        lock: lock(study.loops[g], &member.gyros[g], &run, g),
        characterization: characterizations[g],
        saturations_used: run.saturations[g][0],
        saturations_blanked: run.saturations[g][1],
    });
    Ok(MemberFigures {
        gyros,
        chain: run.figures,
        gyro_samples: characterized + run.gyro_samples,
    })
}

/// What the chain run leaves for the figures.
struct ChainRun {
    figures: ChainFigures,
    locked: [bool; 2],
    /// ADC samples from rest to the last rise of each lock flag in the start-up.
    lock_sample: [u64; 2],
    startup_saturations: [LoopOverflows; 2],
    /// `[used, blanked]` per gyro.
    saturations: [[u64; 2]; 2],
    gyro_samples: u64,
}

/// Mean and variance by Welford's recurrence.
#[derive(Default)]
struct Moments {
    n: u64,
    mean: f64,
    m2: f64,
}

impl Moments {
    fn push(&mut self, x: f64) {
        self.n += 1;
        let d = x - self.mean;
        self.mean += d / self.n as f64;
        self.m2 += d * (x - self.mean);
    }
    fn mean(&self) -> Option<f64> {
        (self.n > 0).then_some(self.mean)
    }
    fn std(&self) -> Option<f64> {
        (self.n > 1).then(|| libm::sqrt(self.m2 / (self.n - 1) as f64))
    }
}

/// Octave averaging factors up to a quarter of `samples`, and `one_second` (the factor of
/// τ = 1 s) among them.
fn allan_factors(samples: usize, one_second: usize) -> Vec<usize> {
    let mut factors: Vec<usize> = std::iter::successors(Some(1usize), |m| Some(m * 2))
        .take_while(|m| 4 * m <= samples)
        .collect();
    if !factors.contains(&one_second) {
        factors.push(one_second);
    }
    factors
}

fn chain_run(study: &Study, gyros: &[GyroPhysics; 2]) -> Result<ChainRun, String> {
    let plan = study.loops[0];
    let fs = plan.adc_rate_hz;
    let chain_rate = plan.chain_rate_hz();
    let decimation = u64::from(plan.cic.decimation);
    let startup = libm::ceil(study.startup_s * fs) as u64;
    let chain_samples = libm::ceil(study.seconds * chain_rate) as u64;
    let total = startup + chain_samples * decimation;
    let physics = |g: usize| {
        let front_end = if study.noise {
            gyros[g].front_end
        } else {
            gyros[g].front_end.noiseless()
        };
        Resonator::new(&gyros[g].params, &front_end, gyros[g].seed)
            .map_err(|e| format!("gyro {}: {e}", ["a", "b"][g]))
    };
    let mut resonators = [physics(0)?, physics(1)?];
    for r in &mut resonators {
        r.set_rate(study.rate_dps.to_radians());
    }
    let mut system = FixedSystem::new(study.loops, study.chain);
    let mut adc = [[0i64; 2]; 2];
    let mut modes_now = [Mode::Normal; 2];
    let mut lock_sample = [0u64; 2];
    let mut startup_saturations = [LoopOverflows::default(); 2];
    let mut last = [LoopOverflows::default(); 2];
    let mut saturations = [[0u64; 2]; 2];
    let output_lsb = study.chain.kf.output.lsb();
    let interval = study.chain.estimator.schedule.interval_length as u64;
    let one_second = libm::round(chain_rate).max(1.0) as usize;
    let factors = allan_factors(chain_samples as usize, one_second);
    let mut allan = OverlappingStream::new(&factors, chain_rate);
    let mut moments = Moments::default();
    let mut held = 0i64;
    let mut first_estimate: Option<u64> = None;
    let mut n = 0u64;
    for k in 0..total {
        let enable = k >= startup;
        let modes = if enable {
            system.upcoming_modes()
        } else {
            [Mode::Normal; 2]
        };
        for g in 0..2 {
            if modes[g] != modes_now[g] {
                resonators[g].set_mode(modes[g]);
                modes_now[g] = modes[g];
            }
        }
        let step = system.step(adc, enable, study.bw_sel);
        if !enable {
            for (sample, locked) in lock_sample.iter_mut().zip(step.locked) {
                if !locked {
                    *sample = k + 1;
                }
            }
            if k + 1 == startup {
                startup_saturations = [0, 1].map(|g| system.loops()[g].overflows());
                last = startup_saturations;
            }
        }
        if let Some(sample) = step.chain {
            for g in 0..2 {
                let now = system.loops()[g].overflows();
                let blanked = [sample.slot.blank_a, sample.slot.blank_b][g];
                saturations[g][usize::from(blanked)] += now.since(&last[g]).total();
                last[g] = now;
            }
            if let Some(rate) = sample.rate {
                held = rate;
            }
            if first_estimate.is_none() && system.chain().estimator().estimated() {
                first_estimate = Some(n);
            }
            if first_estimate.is_some_and(|first| n >= first + interval) {
                let out = held as f64 * output_lsb - study.rate_dps;
                allan.push(out);
                if sample.rate.is_some() {
                    moments.push(out);
                }
            }
            n += 1;
        }
        for g in 0..2 {
            adc[g] = resonators[g].step_codes(step.dac[g]);
        }
    }
    let locked = [0, 1].map(|g| system.loops()[g].locked() || startup == 0);
    let estimator = system.chain().estimator();
    let e = estimator.overflow_counts();
    let kf = system.chain().kf().overflow_counts();
    let chain_overflows = e
        .mean
        .iter()
        .chain(&e.bias)
        .chain(&e.calibrated)
        .sum::<u64>()
        + e.combined
        + kf.x1
        + kf.x2
        + kf.rate_hat;
    let bias_lsb = study.chain.estimator.bias.lsb();
    let (arw, bi) = if study.noise {
        allan_terms(&allan, &factors, one_second)
    } else {
        (None, None)
    };
    Ok(ChainRun {
        figures: ChainFigures {
            output_samples: moments.n,
            output_mean_dps: moments.mean(),
            output_std_dps: moments.std(),
            bias_estimate_dps: estimator
                .estimated()
                .then(|| estimator.bias().map(|b| b as f64 * bias_lsb)),
            chain_overflows,
            arw_deg_per_sqrt_h: arw,
            bias_instability_deg_per_h: bi,
        },
        locked,
        lock_sample,
        startup_saturations,
        saturations,
        gyro_samples: 2 * total,
    })
}

/// ARW (°/√h) at τ = 1 s (factor `one_second`) and bias instability (°/h) from `allan`,
/// accumulated at `factors`.
fn allan_terms(
    allan: &OverlappingStream,
    factors: &[usize],
    one_second: usize,
) -> (Option<f64>, Option<f64>) {
    let deviations = allan.deviations();
    let arw = factors
        .iter()
        .zip(&deviations)
        .find(|(m, _)| **m == one_second)
        .and_then(|(_, d)| d.map(|(sigma, _)| sigma * 60.0));
    let floor = deviations
        .iter()
        .flatten()
        .map(|(sigma, _)| *sigma)
        .fold(None, |min: Option<f64>, s| {
            Some(min.map_or(s, |m| m.min(s)))
        });
    (arw, floor.map(|s| s / FLICKER_FLOOR * 3600.0))
}

/// Gyro `g`'s lock in `run`, and why not.
fn lock(plan: &LoopPlan, gyro: &GyroPhysics, run: &ChainRun, g: usize) -> Lock {
    if run.locked[g] {
        return Lock {
            locked: true,
            lock_ms: Some(run.lock_sample[g] as f64 / plan.adc_rate_hz * 1e3),
            why_not: None,
        };
    }
    let resonance = coupled_resonance_hz(&gyro.params, Mode::Normal);
    let nominal = plan.modes[0].nominal_frequency_hz;
    let pull = plan.settings.pll_pull_range_hz;
    let saturated = run.startup_saturations[g];
    let why = if (resonance - nominal).abs() > pull {
        format!(
            "drive resonance {resonance:.3} Hz is {:.3} Hz from the loop's nominal {nominal:.3} Hz, beyond the PLL's pull range of {pull} Hz",
            resonance - nominal
        )
    } else if saturated.total() > 0 {
        format!(
            "the loop saturated during the start-up: {}",
            saturated.summary()
        )
    } else {
        "the lock criteria (phase within loop.lock_phase_deg, amplitude within loop.lock_amplitude_tolerance, for loop.lock_hold_ms) were not met by the end of the start-up".to_string()
    };
    Lock {
        locked: false,
        lock_ms: None,
        why_not: Some(why),
    }
}
