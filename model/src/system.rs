//! The whole gyro system at the ADC rate (SPEC §1.6 and §1): two resonator-level loops
//! ([`FixedGyroLoop`]) whose decimated rates feed the mode-reversal chain ([`FixedChain`]),
//! and whose modes the chain's sequencer commands. The bit-accurate model of the RTL system
//! top `gyrofx_system`.
//!
//! Per ADC sample `k`, with the input `enable`:
//!
//! ```text
//! mode_g  = enable ? the chain's upcoming mode of gyro g : normal     (before the sample)
//! step both loops on their ADC codes in mode_g
//! if enable and the loops produced a decimated output:                 (A's and B's coincide)
//!     the chain steps on [rate_A, rate_B] at bw_sel
//! ```
//!
//! So every ADC sample of chain period `n` is taken in the mode the sequencer describes for
//! chain sample `n`, and the chain sees each period's rate once. `enable` low holds the chain
//! (no step) and runs both loops in normal mode: the start-up while the loops lock. Both loops
//! share the decimation, so their outputs come at the same sample; gyro A's marks the period.

use crate::chain::{
    FixedChain, FloatChain, FloatSample as FloatChainSample, Plan as ChainPlan,
    Sample as ChainSample,
};
use crate::gyro_loop::gyro::{FixedGyroLoop, FloatGyroLoop, Plan as LoopPlan};
use crate::resonator::{Mode, ParamError, PhysicsSettings, Resonator, ResonatorParams};

/// A chain mode (`+1` normal, `−1` reverse) as the loop's mode.
pub fn loop_mode(p: i8) -> Mode {
    if p > 0 {
        Mode::Normal
    } else {
        Mode::Reverse
    }
}

/// The modes the loops take: the chain's upcoming ones while `enable` is high, else normal.
fn modes_taken(enable: bool, upcoming: [Mode; 2]) -> [Mode; 2] {
    if enable {
        upcoming
    } else {
        [Mode::Normal; 2]
    }
}

/// Both loops' decimated outputs, which come at the same sample.
fn both<T>(a: Option<T>, b: Option<T>) -> Option<[T; 2]> {
    match (a, b) {
        (Some(a), Some(b)) => Some([a, b]),
        (None, None) => None,
        _ => unreachable!("both loops decimate by the same factor from the same reset"),
    }
}

/// What one ADC sample of the system gives.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct SystemStep {
    /// The modes the loops took this sample in (`[A, B]`).
    pub modes: [Mode; 2],
    /// DAC codes `[[A x, A y], [B x, B y]]` (DAC format).
    pub dac: [[i64; 2]; 2],
    /// The loops' lock flags after the sample.
    pub locked: [bool; 2],
    /// The loops' decimated rates (output format), when they produced one this sample.
    pub rates: Option<[i64; 2]>,
    /// The chain's sample, when it stepped.
    pub chain: Option<ChainSample>,
}

/// The bit-accurate system: two loops and the chain.
#[derive(Clone, Debug)]
pub struct FixedSystem {
    loops: [FixedGyroLoop; 2],
    chain: FixedChain,
}

impl FixedSystem {
    /// Gyro A's and B's loops of `loops` and the chain of `chain`, reset.
    ///
    /// The loops' output format must be the chain's input format (the config checks it).
    pub fn new(loops: [&LoopPlan; 2], chain: &ChainPlan) -> Self {
        debug_assert!(loops.iter().all(|l| l.output.to == chain.estimator.input));
        FixedSystem {
            loops: loops.map(FixedGyroLoop::new),
            chain: FixedChain::new(chain),
        }
    }

    /// The modes the loops take at the next sample if `enable` is high there.
    pub fn upcoming_modes(&self) -> [Mode; 2] {
        self.chain.upcoming_modes().map(loop_mode)
    }

    /// One ADC sample: each gyro's codes `[x, y]` (ADC format), `enable` and the KF's
    /// `bw_sel`.
    #[inline]
    pub fn step(&mut self, adc: [[i64; 2]; 2], enable: bool, bw_sel: usize) -> SystemStep {
        let modes = modes_taken(enable, self.upcoming_modes());
        let a = self.loops[0].step(adc[0], modes[0]);
        let b = self.loops[1].step(adc[1], modes[1]);
        let rates = both(a.chain.map(|c| c.rate), b.chain.map(|c| c.rate));
        let chain = match rates {
            Some(y) if enable => Some(self.chain.step(y, bw_sel)),
            _ => None,
        };
        SystemStep {
            modes,
            dac: [a.dac, b.dac],
            locked: [self.loops[0].locked(), self.loops[1].locked()],
            rates,
            chain,
        }
    }

    /// The chain (its estimator's registers and overflow counts).
    pub fn chain(&self) -> &FixedChain {
        &self.chain
    }

    /// Gyro A's and B's loops (their overflow counts).
    pub fn loops(&self) -> &[FixedGyroLoop; 2] {
        &self.loops
    }
}

/// What one ADC sample of the float system gives.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FloatSystemStep {
    /// The modes the loops took this sample in (`[A, B]`).
    pub modes: [Mode; 2],
    /// DAC values `[[A x, A y], [B x, B y]]`, DAC LSB (unquantized).
    pub dac: [[f64; 2]; 2],
    /// The loops' lock flags after the sample.
    pub locked: [bool; 2],
    /// The loops' decimated rates, °/s, when they produced one this sample.
    pub rates: Option<[f64; 2]>,
    /// The chain's sample, °/s, when it stepped.
    pub chain: Option<FloatChainSample>,
}

/// The float golden twin of [`FixedSystem`]: both loops' twins ([`FloatGyroLoop`]) feeding the
/// chain's twin with the quantized coefficients ([`FloatChain::quantized`]), the same sequence
/// of modes and chain steps.
#[derive(Clone, Debug)]
pub struct FloatSystem {
    loops: [FloatGyroLoop; 2],
    chain: FloatChain,
}

impl FloatSystem {
    /// The twins of `loops` and `chain`, reset.
    pub fn new(loops: [&LoopPlan; 2], chain: &ChainPlan) -> Self {
        FloatSystem {
            loops: loops.map(FloatGyroLoop::new),
            chain: FloatChain::quantized(chain),
        }
    }

    /// The modes the loops take at the next sample if `enable` is high there.
    pub fn upcoming_modes(&self) -> [Mode; 2] {
        self.chain.upcoming_modes().map(loop_mode)
    }

    /// One ADC sample: each gyro's `[x, y]` in full-scale units, `enable` and `bw_sel`.
    pub fn step(&mut self, adc: [[f64; 2]; 2], enable: bool, bw_sel: usize) -> FloatSystemStep {
        let modes = modes_taken(enable, self.upcoming_modes());
        let a = self.loops[0].step(adc[0], modes[0]);
        let b = self.loops[1].step(adc[1], modes[1]);
        let rates = both(a.chain.map(|c| c.rate_dps), b.chain.map(|c| c.rate_dps));
        let chain = match rates {
            Some(y) if enable => Some(self.chain.step(y, bw_sel)),
            _ => None,
        };
        FloatSystemStep {
            modes,
            dac: [a.dac, b.dac],
            locked: [self.loops[0].locked(), self.loops[1].locked()],
            rates,
            chain,
        }
    }
}

/// One gyro's physics: its structure, front end and random streams.
#[derive(Clone, Copy, Debug)]
pub struct GyroPhysics<'a> {
    /// The structure.
    pub params: &'a ResonatorParams,
    /// Noise, drift and converters.
    pub front_end: &'a PhysicsSettings,
    /// Seed of its random streams.
    pub seed: u64,
}

/// One ADC sample of a recorded system run: what the RTL's inputs were and what it did.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct RecordedSample {
    /// Each gyro's ADC codes `[x, y]` the loops took (ADC format).
    pub adc: [[i64; 2]; 2],
    /// The `enable` input.
    pub enable: bool,
    /// What the system did.
    pub step: SystemStep,
    /// The chain's modes for its next sample after this one (`[A, B]`).
    pub upcoming: [Mode; 2],
    /// The estimator's bias registers after the sample (bias format).
    pub bias: [i128; 2],
    /// Whether a window has produced an estimate since reset, after the sample.
    pub estimated: bool,
}

/// The system closed around two resonators from reset, at the constant input rate
/// `rate_dps` (°/s) and `bw_sel(k)` at ADC sample `k`: `enable` low for the first `startup` ADC samples, high for
/// the `samples − startup` after them. `visit` sees every sample in order (so a caller keeps
/// only what it needs).
///
/// # Errors
/// [`ParamError`] for invalid physics.
#[allow(clippy::too_many_arguments)]
pub fn record(
    loops: [&LoopPlan; 2],
    chain: &ChainPlan,
    physics: [GyroPhysics; 2],
    rate_dps: f64,
    samples: usize,
    startup: usize,
    bw_sel: impl Fn(usize) -> usize,
    mut visit: impl FnMut(&RecordedSample),
) -> Result<(), ParamError> {
    let mut resonators = [
        Resonator::new(physics[0].params, physics[0].front_end, physics[0].seed)?,
        Resonator::new(physics[1].params, physics[1].front_end, physics[1].seed)?,
    ];
    for r in &mut resonators {
        r.set_rate(rate_dps.to_radians());
    }
    let mut system = FixedSystem::new(loops, chain);
    let mut adc = [[0i64; 2]; 2];
    let mut resonator_modes = [Mode::Normal; 2];
    for k in 0..samples {
        let enable = k >= startup;
        // The resonator's sense front end follows the loop's mode from the same sample on.
        let modes = if enable {
            system.upcoming_modes()
        } else {
            [Mode::Normal; 2]
        };
        for g in 0..2 {
            if modes[g] != resonator_modes[g] {
                resonators[g].set_mode(modes[g]);
                resonator_modes[g] = modes[g];
            }
        }
        let step = system.step(adc, enable, bw_sel(k));
        debug_assert_eq!(step.modes, modes);
        visit(&RecordedSample {
            adc,
            enable,
            step,
            upcoming: system.upcoming_modes(),
            bias: system.chain.estimator().bias(),
            estimated: system.chain.estimator().estimated(),
        });
        for g in 0..2 {
            adc[g] = resonators[g].step_codes(step.dac[g]);
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests;
