//! The closed loop: a simulated resonator ([`Resonator`]) and one gyro's loop, the fixed
//! model ([`FixedGyroLoop`]) or its float twin ([`FloatGyroLoop`]), sample by sample.
//!
//! Per ADC sample `k` the loop takes the pick-off codes sampled at `kT` and returns the DAC
//! codes that the resonator holds over `[kT, (k+1)T]`; the resonator returns the pick-off at
//! `(k+1)T`, the next sample's input. The fixed loop sees the resonator's ADC codes and drives
//! it through its DAC (`code · dac_newton_per_lsb`); the twin sees the unquantized pick-off
//! voltages over the full scale and drives an unquantized force.
//!
//! The input rate `Ω` (°/s) and the mode are set per call ([`ClosedLoop::step_chain`]: one
//! chain-rate sample; [`ClosedLoop::advance`]: any number of ADC samples), so a run streams:
//! only what the caller keeps is stored. A mode change calls [`Resonator::set_mode`] and is
//! given to the loop's `mode` input at the same sample.

use super::gyro::{FixedGyroLoop, FixedStep, FloatGyroLoop, LoopOverflows, Plan};
use crate::resonator::{
    Mode, ModeFigures, ParamError, PhysicsSettings, Resonator, ResonatorParams,
};

/// What one loop sample gives the harness.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ChainOutput {
    /// Rate, °/s.
    pub rate_dps: f64,
    /// Quadrature, °/s.
    pub quadrature_dps: f64,
    /// The lock flag.
    pub locked: bool,
}

/// A loop the harness can close around a resonator.
pub trait LoopUnderTest {
    /// The loop of `plan`, in normal mode.
    fn from_plan(plan: &Plan) -> Self;
    /// One ADC sample: reads the pick-off, drives the resonator for one period; returns the
    /// chain-rate output when there is one.
    fn sample(&mut self, resonator: &mut Resonator, mode: Mode) -> Option<ChainOutput>;
    /// The NCO frequency of the next sample, Hz.
    fn frequency_hz(&self) -> f64;
    /// The lock flag.
    fn locked(&self) -> bool;
    /// The saturations and wraps of the loop's quantizers since construction (none for the
    /// float twin, which has no quantizers).
    fn overflows(&self) -> LoopOverflows;
}

/// [`FixedGyroLoop`] with the ADC codes of the last sample.
#[derive(Clone, Debug)]
pub struct FixedHarness {
    /// The loop.
    pub gyro: FixedGyroLoop,
    adc: [i64; 2],
    output_lsb: f64,
    hz_per_word: f64,
}

impl LoopUnderTest for FixedHarness {
    fn from_plan(plan: &Plan) -> Self {
        FixedHarness {
            gyro: FixedGyroLoop::new(plan),
            adc: [0; 2],
            output_lsb: plan.output.to.lsb(),
            hz_per_word: plan.adc_rate_hz * crate::fx::pow2(-(plan.nco.phase.width as i32)),
        }
    }

    #[inline]
    fn sample(&mut self, resonator: &mut Resonator, mode: Mode) -> Option<ChainOutput> {
        let out = self.gyro.step(self.adc, mode);
        self.adc = resonator.step_codes(out.dac);
        out.chain.map(|c| ChainOutput {
            rate_dps: c.rate as f64 * self.output_lsb,
            quadrature_dps: c.quadrature as f64 * self.output_lsb,
            locked: c.locked,
        })
    }

    fn frequency_hz(&self) -> f64 {
        self.gyro.frequency_word() as f64 * self.hz_per_word
    }

    fn locked(&self) -> bool {
        self.gyro.locked()
    }

    fn overflows(&self) -> LoopOverflows {
        self.gyro.overflows()
    }
}

/// [`FloatGyroLoop`] with the pick-off of the last sample (full-scale units).
#[derive(Clone, Debug)]
pub struct FloatHarness {
    /// The loop.
    pub gyro: FloatGyroLoop,
    adc: [f64; 2],
    volts_to_fs: f64,
    newton_per_lsb: f64,
    fs: f64,
}

impl LoopUnderTest for FloatHarness {
    fn from_plan(plan: &Plan) -> Self {
        FloatHarness {
            gyro: FloatGyroLoop::new(plan),
            adc: [0.0; 2],
            volts_to_fs: 1.0 / plan.adc_full_scale_v,
            newton_per_lsb: plan.dac_newton_per_lsb,
            fs: plan.adc_rate_hz,
        }
    }

    fn sample(&mut self, resonator: &mut Resonator, mode: Mode) -> Option<ChainOutput> {
        let out = self.gyro.step(self.adc, mode);
        let volts = resonator.step(out.dac.map(|d| d * self.newton_per_lsb));
        self.adc = volts.map(|v| v * self.volts_to_fs);
        out.chain.map(|c| ChainOutput {
            rate_dps: c.rate_dps,
            quadrature_dps: c.quadrature_dps,
            locked: c.locked,
        })
    }

    fn frequency_hz(&self) -> f64 {
        self.gyro.frequency() * self.fs
    }

    fn locked(&self) -> bool {
        self.gyro.locked()
    }

    fn overflows(&self) -> LoopOverflows {
        LoopOverflows::default()
    }
}

/// A summary of some ADC samples.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Window {
    /// Mean NCO frequency over the window, Hz.
    pub mean_frequency_hz: f64,
    /// Drive amplitude at the window's end, m: `sqrt(q_a² + (q_a′/w)²)` of the driven axis
    /// from the resonator's state, `w` the mode's nominal drive resonance.
    pub drive_amplitude_m: f64,
    /// The lock flag at the window's end.
    pub locked: bool,
    /// The last chain-rate output within the window.
    pub chain: Option<ChainOutput>,
}

/// One chain-rate sample of a run.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ChainRecord {
    /// Its mode.
    pub mode: Mode,
    /// The input rate, °/s.
    pub input_dps: f64,
    /// The loop's output.
    pub output: ChainOutput,
    /// Mean NCO frequency over the chain period, Hz.
    pub drive_frequency_hz: f64,
    /// Drive amplitude at its end, m.
    pub drive_amplitude_m: f64,
}

/// A resonator and a loop, closed.
#[derive(Clone, Debug)]
pub struct ClosedLoop<L: LoopUnderTest> {
    /// The physics.
    pub resonator: Resonator,
    /// The loop.
    pub gyro: L,
    nominal_drive: [f64; 2],
    mode: Mode,
}

impl<L: LoopUnderTest> ClosedLoop<L> {
    /// The loop of `plan` closed around a resonator of `params` and `physics` whose random
    /// streams come from `seed`, at rest, normal mode, `Ω = 0`.
    ///
    /// # Errors
    /// [`ParamError`] for invalid physics.
    pub fn new(
        plan: &Plan,
        params: &ResonatorParams,
        physics: &PhysicsSettings,
        seed: u64,
    ) -> Result<Self, ParamError> {
        Ok(ClosedLoop {
            resonator: Resonator::new(params, physics, seed)?,
            gyro: L::from_plan(plan),
            nominal_drive: [Mode::Normal, Mode::Reverse]
                .map(|m| ModeFigures::new(params, m).drive_angular_frequency),
            mode: Mode::Normal,
        })
    }

    /// Sets the input rate (°/s) and the mode for the next samples.
    pub fn set(&mut self, rate_dps: f64, mode: Mode) {
        self.resonator.set_rate(rate_dps.to_radians());
        if mode != self.mode {
            self.mode = mode;
            self.resonator.set_mode(mode);
        }
    }

    /// The mode.
    pub fn mode(&self) -> Mode {
        self.mode
    }

    /// The driven axis's amplitude now, m.
    pub fn drive_amplitude_m(&self) -> f64 {
        let axis = self.mode.axes()[0];
        let w = self.nominal_drive[super::gyro::mode_index(self.mode)];
        let q = self.resonator.position()[axis];
        let v = self.resonator.velocity()[axis] / w;
        libm::hypot(q, v)
    }

    /// Runs `samples` ADC samples at the current rate and mode.
    pub fn advance(&mut self, samples: u32) -> Window {
        let mut sum = 0.0;
        let mut chain = None;
        for _ in 0..samples {
            sum += self.gyro.frequency_hz();
            if let Some(c) = self.gyro.sample(&mut self.resonator, self.mode) {
                chain = Some(c);
            }
        }
        Window {
            mean_frequency_hz: sum / f64::from(samples.max(1)),
            drive_amplitude_m: self.drive_amplitude_m(),
            locked: self.gyro.locked(),
            chain,
        }
    }

    /// Sets the rate and mode, then runs until the loop's next chain-rate output.
    pub fn step_chain(&mut self, rate_dps: f64, mode: Mode) -> ChainRecord {
        self.set(rate_dps, mode);
        let mut sum = 0.0;
        let mut n = 0u32;
        loop {
            sum += self.gyro.frequency_hz();
            n += 1;
            if let Some(output) = self.gyro.sample(&mut self.resonator, self.mode) {
                return ChainRecord {
                    mode,
                    input_dps: rate_dps,
                    output,
                    drive_frequency_hz: sum / f64::from(n),
                    drive_amplitude_m: self.drive_amplitude_m(),
                };
            }
        }
    }
}

/// The fixed loop closed around the physics.
pub type FixedClosedLoop = ClosedLoop<FixedHarness>;
/// The float twin closed around the physics.
pub type FloatClosedLoop = ClosedLoop<FloatHarness>;

/// Runs `chain_samples` chain-rate samples from rest with the input rate `rate(n)` (°/s) and
/// the mode `mode(n)` of chain sample `n`; returns every record.
///
/// # Errors
/// [`ParamError`] for invalid physics.
pub fn run<L: LoopUnderTest>(
    plan: &Plan,
    params: &ResonatorParams,
    physics: &PhysicsSettings,
    seed: u64,
    chain_samples: usize,
    rate: impl Fn(usize) -> f64,
    mode: impl Fn(usize) -> Mode,
) -> Result<Vec<ChainRecord>, ParamError> {
    let mut closed = ClosedLoop::<L>::new(plan, params, physics, seed)?;
    Ok((0..chain_samples)
        .map(|n| closed.step_chain(rate(n), mode(n)))
        .collect())
}

/// One ADC sample of a recorded closed-loop run: what the fixed loop was given and what it
/// did, as the loop's RTL sees it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct RecordedSample {
    /// The ADC codes `[x, y]` the loop took (ADC format).
    pub adc: [i64; 2],
    /// The mode input.
    pub mode: Mode,
    /// The DAC codes and the chain-rate output.
    pub step: FixedStep,
    /// The lock flag after the sample.
    pub locked: bool,
}

/// The fixed loop of `plan` closed around the physics (`params`, `physics`, random streams
/// from `seed`) from reset, at the input rate `rate_dps` (°/s): `samples` ADC samples in normal
/// mode up to sample `switch_at` and in reverse mode from it, each recorded. The loop's RTL
/// given the recorded ADC codes and modes must reproduce every recorded output.
///
/// # Errors
/// [`ParamError`] for invalid physics.
pub fn record(
    plan: &Plan,
    params: &ResonatorParams,
    physics: &PhysicsSettings,
    seed: u64,
    rate_dps: f64,
    samples: usize,
    switch_at: usize,
) -> Result<Vec<RecordedSample>, ParamError> {
    let mut resonator = Resonator::new(params, physics, seed)?;
    resonator.set_rate(rate_dps.to_radians());
    let mut gyro = FixedGyroLoop::new(plan);
    let mut adc = [0i64; 2];
    let mut out = Vec::with_capacity(samples);
    for k in 0..samples {
        let mode = if k < switch_at {
            Mode::Normal
        } else {
            Mode::Reverse
        };
        if k == switch_at {
            resonator.set_mode(mode);
        }
        let step = gyro.step(adc, mode);
        out.push(RecordedSample {
            adc,
            mode,
            step,
            locked: gyro.locked(),
        });
        adc = resonator.step_codes(step.dac);
    }
    Ok(out)
}

#[cfg(test)]
pub(crate) mod tests;
