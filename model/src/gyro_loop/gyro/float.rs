//! The float golden twin: the same structure in f64 with the designed (unquantized) offsets,
//! setpoints and `1/SF`, the quantized PI gains (as [`FloatPi`] takes them), the CIC's twin,
//! an exact NCO phase and an unquantized DAC.

use std::f64::consts::PI;

use super::mode_index;
use super::plan::{Plan, MAX_LATENCY};
use crate::gyro_loop::cic::FloatCic;
use crate::gyro_loop::demodulator::FloatDemodulator;
use crate::gyro_loop::pi::FloatPi;
use crate::resonator::Mode;

/// One chain-rate output of the twin.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FloatChainSample {
    /// Rate, °/s.
    pub rate_dps: f64,
    /// Quadrature, °/s.
    pub quadrature_dps: f64,
    /// The lock flag.
    pub locked: bool,
}

/// One ADC sample's result.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FloatStep {
    /// DAC values `[x, y]`, DAC LSB (unquantized).
    pub dac: [f64; 2],
    /// The chain-rate output, every `R`-th sample.
    pub chain: Option<FloatChainSample>,
}

#[derive(Clone, Copy, Debug)]
struct ModeValues {
    setpoint: f64,
    frequency: f64,
    dac_offset: f64,
    sense_offset: f64,
    rate_coefficient: f64,
    quadrature_coefficient: f64,
    lock_limits: [f64; 2],
}

/// The float loop of one gyro.
#[derive(Clone, Debug)]
pub struct FloatGyroLoop {
    modes: [ModeValues; 2],
    mode: Mode,
    amplitude: f64,
    /// NCO phase, cycles in `[0, 1)`.
    phase: f64,
    freq: f64,
    demod_drive: FloatDemodulator,
    demod_sense: FloatDemodulator,
    pll: FloatPi,
    agc: FloatPi,
    cic_i: FloatCic,
    cic_q: FloatCic,
    delay: [f64; MAX_LATENCY as usize + 1],
    delay_head: usize,
    latency: usize,
    lock_decay: f64,
    lock_hold: u32,
    lock_y: [f64; 2],
    lock_count: u32,
}

impl FloatGyroLoop {
    /// The twin of `plan`'s loop, in normal mode.
    pub fn new(plan: &Plan) -> Self {
        let scale = crate::fx::pow2(plan.lock.shift as i32);
        let lsb = plan.demodulator.output.to.lsb();
        let modes = plan.modes.map(|m| ModeValues {
            setpoint: m.setpoint,
            frequency: m.frequency,
            dac_offset: m.dac_offset,
            sense_offset: m.sense_offset,
            rate_coefficient: m.rate_coefficient.value,
            quadrature_coefficient: m.quadrature_coefficient.value,
            // The fixed limits are on z = 2^s y in LSB; here on y in FS units.
            lock_limits: m.lock_limits.map(|l| l as f64 * lsb / scale),
        });
        let mut gyro = FloatGyroLoop {
            modes,
            mode: Mode::Normal,
            amplitude: plan.nco.amplitude(),
            phase: 0.0,
            freq: 0.0,
            demod_drive: FloatDemodulator::new(&plan.demodulator),
            demod_sense: FloatDemodulator::new(&plan.demodulator),
            pll: FloatPi::new(&plan.pll),
            agc: FloatPi::new(&plan.agc),
            cic_i: FloatCic::new(&plan.cic),
            cic_q: FloatCic::new(&plan.cic),
            delay: [0.0; MAX_LATENCY as usize + 1],
            delay_head: 0,
            latency: plan.latency as usize,
            lock_decay: 1.0 / scale,
            lock_hold: plan.lock.hold_samples,
            lock_y: [0.0; 2],
            lock_count: 0,
        };
        gyro.enter(Mode::Normal);
        gyro
    }

    fn enter(&mut self, mode: Mode) {
        self.mode = mode;
        let m = self.modes[mode_index(mode)];
        self.pll.preset(m.frequency);
        self.agc.reset();
        self.freq = m.frequency;
        self.demod_drive.reset();
        self.demod_sense.reset();
        self.delay = [0.0; MAX_LATENCY as usize + 1];
        self.delay_head = 0;
        self.lock_y = [0.0; 2];
        self.lock_count = 0;
    }

    /// The mode.
    pub fn mode(&self) -> Mode {
        self.mode
    }

    /// The frequency the NCO takes at the next sample, cycles per sample.
    pub fn frequency(&self) -> f64 {
        self.freq
    }

    /// The lock flag.
    pub fn locked(&self) -> bool {
        self.lock_count >= self.lock_hold
    }

    fn reference(&self, offset: f64) -> [f64; 2] {
        let angle = 2.0 * PI * (self.phase + offset);
        [
            self.amplitude * libm::sin(angle),
            self.amplitude * libm::cos(angle),
        ]
    }

    /// One ADC sample: `[x, y]` in full-scale units, and the mode.
    pub fn step(&mut self, adc: [f64; 2], mode: Mode) -> FloatStep {
        if mode != self.mode {
            self.enter(mode);
        }
        let m = self.modes[mode_index(mode)];
        let [driven, sensed] = mode.axes();
        let [sin_d, cos_d] = self.reference(0.0);
        let [_, cos_t] = self.reference(m.dac_offset);
        let [sin_s, cos_s] = self.reference(m.sense_offset);
        self.phase += self.freq;
        self.phase -= libm::floor(self.phase);
        let [i, q] = self.demod_drive.step(adc[driven], sin_d, cos_d);
        let [si, sq] = self.demod_sense.step(adc[sensed], sin_s, cos_s);
        self.freq = self.pll.step(q);
        let error = m.setpoint - i;
        let drive = self.agc.step(error) * cos_t;

        let len = self.latency + 1;
        self.delay[self.delay_head] = drive;
        let oldest = (self.delay_head + 1) % len;
        let out = self.delay[oldest];
        self.delay_head = oldest;
        let mut dac = [0.0; 2];
        dac[driven] = out;

        for (y, e) in self.lock_y.iter_mut().zip([q, error]) {
            *y += (e - *y) * self.lock_decay;
        }
        let inside =
            self.lock_y[0].abs() < m.lock_limits[0] && self.lock_y[1].abs() < m.lock_limits[1];
        self.lock_count = if inside {
            self.lock_count.saturating_add(1).min(self.lock_hold)
        } else {
            0
        };

        let chain = match (self.cic_i.step(si), self.cic_q.step(sq)) {
            (Some(yi), Some(yq)) => Some(FloatChainSample {
                rate_dps: m.rate_coefficient * yi,
                quadrature_dps: m.quadrature_coefficient * yq,
                locked: self.locked(),
            }),
            _ => None,
        };
        FloatStep { dac, chain }
    }
}
