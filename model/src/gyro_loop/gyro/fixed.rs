//! The bit-accurate loop: ADC codes of both axes in, DAC codes of both axes out, the rate and
//! quadrature every `R`-th sample.

use super::design::ModePlan;
use super::mode_index;
use super::overflows::{LoopNode, LoopOverflows};
use super::plan::Plan;
use crate::fx::Quantizer;
use crate::gyro_loop::cic::FixedCic;
use crate::gyro_loop::demodulator::{FixedDemodulator, Iq};
use crate::gyro_loop::nco::FixedNco;
use crate::gyro_loop::pi::FixedPi;
use crate::resonator::Mode;

use super::plan::MAX_LATENCY;

/// One chain-rate output.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ChainSample {
    /// Rate, output format code (°/s): `Ω + B` normal, `Ω − B′` reverse.
    pub rate: i64,
    /// Quadrature, output format code (°/s).
    pub quadrature: i64,
    /// The lock flag at this sample.
    pub locked: bool,
}

/// One ADC sample's result.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct FixedStep {
    /// DAC codes `[x, y]` (DAC format); the sense axis's is 0.
    pub dac: [i64; 2],
    /// The chain-rate output, every `R`-th sample.
    pub chain: Option<ChainSample>,
}

/// Per-mode constants in the form the step uses.
#[derive(Clone, Copy, Debug)]
struct ModeConstants {
    setpoint: i64,
    pll_preset: i64,
    frequency_word: u64,
    dac_offset: u64,
    sense_offset: u64,
    rate_coefficient: i128,
    quadrature_coefficient: i128,
    lock_limits: [i64; 2],
}

impl ModeConstants {
    fn new(m: &ModePlan) -> Self {
        ModeConstants {
            setpoint: m.setpoint_code,
            pll_preset: m.pll_preset,
            frequency_word: m.frequency_word,
            dac_offset: m.dac_offset_word,
            sense_offset: m.sense_offset_word,
            rate_coefficient: m.rate_coefficient.code,
            quadrature_coefficient: m.quadrature_coefficient.code,
            lock_limits: m.lock_limits,
        }
    }
}

/// The bit-accurate loop of one gyro (allocation-free `step`, state in `i64`).
#[derive(Clone, Debug)]
pub struct FixedGyroLoop {
    modes: [ModeConstants; 2],
    mode: Mode,
    nco_drive: FixedNco,
    nco_dac: FixedNco,
    nco_sense: FixedNco,
    demod_drive: FixedDemodulator,
    demod_sense: FixedDemodulator,
    pll: FixedPi,
    agc: FixedPi,
    agc_error: Quantizer,
    dac: Quantizer,
    /// Whether `setpoint − I` and `amplitude · cos` fit 64 bits (they do unless formats near
    /// 64 bits are declared): then their points round in `i64`.
    narrow_drive: bool,
    cic_i: FixedCic,
    cic_q: FixedCic,
    output: [Quantizer; 2],
    /// `u P.P` mask of the frequency word.
    phase_mask: u64,
    /// Frequency word the NCOs take this sample (the PLL's output of the last one).
    freq: u64,
    /// DAC codes of the last `L` samples (ring), for the driven axis.
    delay: [i64; MAX_LATENCY as usize + 1],
    delay_head: usize,
    latency: usize,
    lock_shift: u32,
    lock_hold: u32,
    lock_z: [i64; 2],
    lock_count: u32,
}

impl FixedGyroLoop {
    /// The loop of `plan` in normal mode, PLL and AGC preset to normal mode's nominal values,
    /// everything else at 0.
    pub fn new(plan: &Plan) -> Self {
        let modes = plan.modes.each_ref().map(ModeConstants::new);
        let mut gyro = FixedGyroLoop {
            modes,
            mode: Mode::Normal,
            nco_drive: FixedNco::new(&plan.nco),
            nco_dac: FixedNco::new(&plan.nco),
            nco_sense: FixedNco::new(&plan.nco),
            demod_drive: FixedDemodulator::new(&plan.demodulator),
            demod_sense: FixedDemodulator::new(&plan.demodulator),
            pll: FixedPi::new(&plan.pll),
            agc: FixedPi::new(&plan.agc),
            agc_error: plan.agc_error.quantizer(),
            dac: plan.dac.quantizer(),
            narrow_drive: plan.agc_error.from.width <= 64 && plan.dac.from.width <= 64,
            cic_i: FixedCic::new(&plan.cic),
            cic_q: FixedCic::new(&plan.cic),
            output: [plan.output.quantizer(), plan.output.quantizer()],
            phase_mask: u64::MAX >> (64 - plan.nco.phase.width),
            freq: 0,
            delay: [0; MAX_LATENCY as usize + 1],
            delay_head: 0,
            latency: plan.latency as usize,
            lock_shift: plan.lock.shift,
            lock_hold: plan.lock.hold_samples,
            lock_z: [0; 2],
            lock_count: 0,
        };
        gyro.enter(Mode::Normal);
        gyro
    }

    /// Back to the state of [`FixedGyroLoop::new`] (overflow counts kept).
    pub fn reset(&mut self) {
        self.nco_drive.reset();
        self.nco_dac.reset();
        self.nco_sense.reset();
        self.cic_i.reset();
        self.cic_q.reset();
        self.enter(Mode::Normal);
    }

    /// The switch actions of the [module doc](super): presets and clears.
    fn enter(&mut self, mode: Mode) {
        self.mode = mode;
        let m = self.modes[mode_index(mode)];
        self.pll.preset(m.pll_preset);
        self.agc.reset();
        self.freq = m.frequency_word;
        self.demod_drive.reset();
        self.demod_sense.reset();
        self.delay = [0; MAX_LATENCY as usize + 1];
        self.delay_head = 0;
        self.lock_z = [0; 2];
        self.lock_count = 0;
    }

    /// The current mode.
    pub fn mode(&self) -> Mode {
        self.mode
    }

    /// The frequency word the NCOs take at the next sample (`u P.P` cycles per sample).
    pub fn frequency_word(&self) -> u64 {
        self.freq
    }

    /// The lock flag.
    pub fn locked(&self) -> bool {
        self.lock_count >= self.lock_hold
    }

    /// The AGC integrator's code (its format): the drive amplitude without the P part.
    pub fn agc_integrator(&self) -> i64 {
        self.agc.integrator()
    }

    /// One ADC sample: the codes `[x, y]` (ADC format) and the mode input. A change of mode
    /// takes effect before this sample.
    #[inline]
    pub fn step(&mut self, adc: [i64; 2], mode: Mode) -> FixedStep {
        if mode != self.mode {
            self.enter(mode);
        }
        let m = self.modes[mode_index(mode)];
        let [driven, sensed] = mode.axes();
        let freq = self.freq;
        let reference = self.nco_drive.step(freq, 0);
        let transmit = self.nco_dac.step(freq, m.dac_offset);
        let sense_reference = self.nco_sense.step(freq, m.sense_offset);
        let Iq { i, q } = self.demod_drive.step(adc[driven], reference);
        let sense = self.demod_sense.step(adc[sensed], sense_reference);

        self.freq = (self.pll.step(q) as u64) & self.phase_mask;
        let error = if self.narrow_drive {
            self.agc_error.apply_i64(m.setpoint - i)
        } else {
            self.agc_error.apply(i128::from(m.setpoint) - i128::from(i)) as i64
        };
        let amplitude = self.agc.step(error);
        let drive = if self.narrow_drive {
            self.dac.apply_i64(amplitude * transmit.cos)
        } else {
            self.dac
                .apply(i128::from(amplitude) * i128::from(transmit.cos)) as i64
        };

        // Delay line: write this sample's code, read the one L samples old.
        self.delay[self.delay_head] = drive;
        let oldest = if self.delay_head == self.latency {
            0
        } else {
            self.delay_head + 1
        };
        let out = self.delay[oldest];
        self.delay_head = oldest;
        let mut dac = [0i64; 2];
        dac[driven] = out;

        // Lock filters.
        let s = self.lock_shift;
        for (z, e) in self.lock_z.iter_mut().zip([q, error]) {
            *z = *z - (*z >> s) + e;
        }
        let inside =
            self.lock_z[0].abs() < m.lock_limits[0] && self.lock_z[1].abs() < m.lock_limits[1];
        self.lock_count = if inside {
            self.lock_count.saturating_add(1).min(self.lock_hold)
        } else {
            0
        };

        let yi = self.cic_i.step(sense.i);
        let yq = self.cic_q.step(sense.q);
        let chain = match (yi, yq) {
            (Some(yi), Some(yq)) => Some(ChainSample {
                rate: self.output[0].apply(m.rate_coefficient * i128::from(yi)) as i64,
                quadrature: self.output[1].apply(m.quadrature_coefficient * i128::from(yq)) as i64,
                locked: self.locked(),
            }),
            _ => None,
        };
        FixedStep { dac, chain }
    }

    /// The saturations and wraps of every node since construction (a reset keeps them): a few
    /// loads, cheap enough to take once per chain sample.
    pub fn overflows(&self) -> LoopOverflows {
        let drive = self.demod_drive.overflow_counts();
        let sense = self.demod_sense.overflow_counts();
        let pll = self.pll.overflow_counts();
        let agc = self.agc.overflow_counts();
        let cic = [self.cic_i.overflow_counts(), self.cic_q.overflow_counts()];
        let both = |pair: [u64; 2]| pair[0] + pair[1];
        LoopOverflows::from_counts(&[
            (LoopNode::DriveDemodProduct, both(drive.product)),
            (LoopNode::DriveDemodState, both(drive.state)),
            (LoopNode::DriveDemodOutput, both(drive.output)),
            (LoopNode::SenseDemodProduct, both(sense.product)),
            (LoopNode::SenseDemodState, both(sense.state)),
            (LoopNode::SenseDemodOutput, both(sense.output)),
            (LoopNode::PllIntegrator, pll.integrator_clamped),
            (LoopNode::PllOutput, pll.output),
            (LoopNode::AgcError, self.agc_error.overflow_count),
            (LoopNode::AgcIntegrator, agc.integrator_clamped),
            (LoopNode::AgcOutput, agc.output),
            (LoopNode::Dac, self.dac.overflow_count),
            (LoopNode::Cic, cic[0].cic + cic[1].cic),
            (LoopNode::CicCompensator, cic[0].output + cic[1].output),
            (LoopNode::RateOutput, self.output[0].overflow_count),
            (LoopNode::QuadratureOutput, self.output[1].overflow_count),
        ])
    }
}
