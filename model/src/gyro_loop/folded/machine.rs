//! The folded loop run clock by clock, register by register, as `hdl/gyrofx_gyro_loop_serial.v`
//! runs it: the proof of a [`Schedule`] against the parallel model.

use super::control::{
    ASource, AccX, AccY, BSource, Control, Issue, Quantize, ReadGate, RomRead, WriteData, LIMB_BITS,
};
use super::schedule::Schedule;
use super::{sign_extend, Datapath};
use crate::fx::Quantizer;
use crate::gyro_loop::gyro::{mode_index, ChainSample, FixedStep, Plan};
use crate::resonator::Mode;

/// Per-mode constants.
#[derive(Clone, Copy, Debug)]
struct ModeConstants {
    setpoint: i128,
    pll_preset: i128,
    frequency_word: u64,
    offsets: [u64; 3],
    coefficients: [i128; 2],
    lock_limits: [i128; 2],
}

/// The quantization points, as the parallel loop has them.
#[derive(Clone, Debug)]
struct Points {
    product: Quantizer,
    state: Quantizer,
    output: Quantizer,
    agc_error: Quantizer,
    pll_integrator: Quantizer,
    pll_output: Quantizer,
    agc_integrator: Quantizer,
    agc_output: Quantizer,
    dac: Quantizer,
    cic: Quantizer,
    cic_output: Quantizer,
    rate: Quantizer,
}

/// Widths of the exact values the points read from the accumulator.
#[derive(Clone, Copy, Debug)]
struct ExactWidths {
    product: u32,
    state: u32,
    agc_error: u32,
    pll_update: u32,
    pll_sum: u32,
    agc_update: u32,
    agc_sum: u32,
    dac: u32,
    register: u32,
    fir: u32,
    rate: u32,
}

/// Constant left shifts of the datapath.
#[derive(Clone, Copy, Debug)]
struct Shifts {
    lowpass: u32,
    product_to_state: u32,
    pll_v_to_update: u32,
    agc_v_to_update: u32,
    /// How the integrator register `v` and the RAM hold each PI's integrator (PLL, AGC): shifted
    /// left by these, so that both output sums take `v` at one alignment, `v_to_sum` (one
    /// operand of the accumulator, not two).
    v_held: [u32; 2],
    v_to_sum: u32,
    /// The PI products' alignments, by [`BSource::alignment`].
    align: [u32; 5],
    lock: u32,
}

/// The NCO's constants.
#[derive(Clone, Debug)]
struct NcoConstants {
    rom: Vec<i128>,
    mask: u64,
    truncation_shift: u32,
    address_bits: u32,
    error_feedback: bool,
    below_truncation: u64,
    half_bin: i64,
}

/// The folded loop of one gyro: the same ports and results as
/// [`crate::gyro_loop::gyro::FixedGyroLoop`].
#[derive(Clone, Debug)]
pub struct FoldedGyroLoop {
    schedule: Schedule,
    datapath: Datapath,
    modes: [ModeConstants; 2],
    points: Points,
    exact: ExactWidths,
    shifts: Shifts,
    nco: NcoConstants,
    gains: [i128; 4],
    taps: Vec<i128>,
    pll_limits: [i128; 2],
    agc_limits: [i128; 2],
    decimation: u32,
    latency: usize,
    lock_hold: u32,
    most_seen: u32,
    // Registers.
    mode: Mode,
    start: bool,
    switching: bool,
    first: bool,
    decimate: bool,
    count: u32,
    seen: u32,
    adc: [i128; 2],
    nco_acc: u64,
    residue: [i64; 3],
    freq: u64,
    reference: i128,
    rd: i128,
    /// The read register's preset gate: [`AccX::PllIntegrator`] reads the PLL's preset.
    rd_preset: bool,
    previous_rd: i128,
    /// The multiplier's operand registers: the limb of `a`, `b`, and the product's weight
    /// (a left shift).
    operands: (i128, i128, u32),
    /// The multiplier's output register and the weight that travels with it.
    product: (i128, u32),
    /// The weighted product the accumulator adds.
    pp: i128,
    acc: i128,
    p: i128,
    y: i128,
    /// `Q_O(y)` of the clock before.
    output: i128,
    drive_q: i128,
    amplitude_error: i128,
    /// The integrator register: a PI's integrator, held as `Shifts::v_held` says.
    v: i128,
    amplitude: i128,
    c: i128,
    cic_output: i128,
    delay: Vec<i128>,
    dac: [i128; 2],
    rate: i128,
    quadrature: i128,
    inside_q: bool,
    lock_count: u32,
    locked: bool,
    ram: Vec<i128>,
}

impl FoldedGyroLoop {
    /// The folded loop of `plan` with its derived schedule, in the state of reset.
    ///
    /// # Panics
    /// When `plan` has no schedule ([`Schedule::new`] refuses it).
    pub fn new(plan: &Plan) -> Self {
        let schedule = Schedule::new(plan).expect("the plan has a folded schedule");
        Self::with_schedule(plan, schedule)
    }

    /// The folded loop of `plan` running `schedule`.
    pub fn with_schedule(plan: &Plan, schedule: Schedule) -> Self {
        let mode = |m: &crate::gyro_loop::gyro::ModePlan| ModeConstants {
            setpoint: i128::from(m.setpoint_code),
            pll_preset: i128::from(m.pll_preset).clamp(plan.pll.limits[0], plan.pll.limits[1]),
            frequency_word: m.frequency_word,
            offsets: [0, m.dac_offset_word, m.sense_offset_word],
            coefficients: [m.rate_coefficient.code, m.quadrature_coefficient.code],
            lock_limits: m.lock_limits.map(i128::from),
        };
        let demod = &plan.demodulator;
        let shift_of = |to: i32, from: i32| (to - from) as u32;
        let pll = &plan.pll;
        let agc = &plan.agc;
        let nco = &plan.nco;
        let width = nco.phase.width;
        let below = width - nco.address_bits - 2;
        let words = schedule.words.count();
        let pll_v_to_sum = shift_of(pll.output.from.frac, pll.integrator.frac);
        let agc_v_to_sum = shift_of(agc.output.from.frac, agc.integrator.frac);
        FoldedGyroLoop {
            datapath: Datapath::new(plan),
            modes: [mode(&plan.modes[0]), mode(&plan.modes[1])],
            points: Points {
                product: demod.product.quantizer(),
                state: demod.state.quantizer(),
                output: demod.output.quantizer(),
                agc_error: plan.agc_error.quantizer(),
                pll_integrator: pll.integrator_point.quantizer(),
                pll_output: pll.output.quantizer(),
                agc_integrator: agc.integrator_point.quantizer(),
                agc_output: agc.output.quantizer(),
                dac: plan.dac.quantizer(),
                cic: plan.cic.cic.quantizer(),
                cic_output: plan.cic.output.quantizer(),
                rate: plan.output.quantizer(),
            },
            exact: ExactWidths {
                product: demod.product.from.width,
                state: demod.state.from.width,
                agc_error: plan.agc_error.from.width,
                pll_update: pll.integrator_point.from.width,
                pll_sum: pll.output.from.width,
                agc_update: agc.integrator_point.from.width,
                agc_sum: agc.output.from.width,
                dac: plan.dac.from.width,
                register: plan.cic.register.width,
                fir: plan.cic.output.from.width,
                rate: plan.output.from.width,
            },
            shifts: Shifts {
                lowpass: demod.lowpass_shift,
                product_to_state: shift_of(demod.state.to.frac, demod.product.to.frac),
                pll_v_to_update: shift_of(pll.integrator_point.from.frac, pll.integrator.frac),
                agc_v_to_update: shift_of(agc.integrator_point.from.frac, agc.integrator.frac),
                v_held: [
                    pll_v_to_sum.saturating_sub(agc_v_to_sum),
                    agc_v_to_sum.saturating_sub(pll_v_to_sum),
                ],
                v_to_sum: pll_v_to_sum.min(agc_v_to_sum),
                align: [
                    0,
                    shift_of(
                        pll.integrator_point.from.frac,
                        pll.ki.format.frac + pll.input.frac,
                    ),
                    shift_of(pll.output.from.frac, pll.kp.format.frac + pll.input.frac),
                    shift_of(
                        agc.integrator_point.from.frac,
                        agc.ki.format.frac + agc.input.frac,
                    ),
                    shift_of(agc.output.from.frac, agc.kp.format.frac + agc.input.frac),
                ],
                lock: plan.lock.shift,
            },
            nco: NcoConstants {
                rom: nco.rom_codes().to_vec(),
                mask: u64::MAX >> (64 - width),
                truncation_shift: below,
                address_bits: nco.address_bits,
                error_feedback: nco.error_feedback,
                below_truncation: (1u64 << below) - 1,
                half_bin: if nco.error_feedback {
                    1 << (below - 1)
                } else {
                    0
                },
            },
            gains: [pll.ki.code, pll.kp.code, agc.ki.code, agc.kp.code],
            taps: plan.cic.taps.iter().map(|h| h.code).collect(),
            pll_limits: pll.limits,
            agc_limits: agc.limits,
            decimation: plan.cic.decimation,
            latency: plan.latency as usize,
            lock_hold: plan.lock.hold_samples,
            most_seen: plan
                .cic
                .differential_delay
                .max(plan.cic.taps.len() as u32 - 1),
            mode: Mode::Normal,
            start: true,
            switching: false,
            first: false,
            decimate: false,
            count: 0,
            seen: 0,
            adc: [0; 2],
            nco_acc: 0,
            residue: [0; 3],
            freq: 0,
            reference: 0,
            rd: 0,
            rd_preset: false,
            previous_rd: 0,
            operands: (0, 0, 0),
            product: (0, 0),
            pp: 0,
            acc: 0,
            p: 0,
            y: 0,
            output: 0,
            drive_q: 0,
            amplitude_error: 0,
            v: 0,
            amplitude: 0,
            c: 0,
            cic_output: 0,
            delay: vec![0; plan.latency.max(1) as usize],
            dac: [0; 2],
            rate: 0,
            quadrature: 0,
            inside_q: false,
            lock_count: 0,
            locked: false,
            ram: vec![0; words],
            schedule,
        }
    }

    /// The schedule this loop runs.
    pub fn schedule(&self) -> &Schedule {
        &self.schedule
    }

    /// The lock flag.
    pub fn locked(&self) -> bool {
        self.locked
    }

    /// One ADC sample: the clock with `ce` high, then the schedule's clocks.
    pub fn step(&mut self, adc: [i64; 2], mode: Mode) -> FixedStep {
        self.capture(adc, mode);
        let clocks = if self.decimate {
            self.schedule.controls.len()
        } else {
            self.schedule.regular
        };
        for t in 0..clocks {
            let control = self.schedule.controls[t];
            self.clock(&control);
        }
        if self.decimate {
            self.seen = (self.seen + 1).min(self.most_seen);
        }
        let [driven, _] = mode.axes();
        let mut dac = [0i64; 2];
        dac[driven] = self.dac[driven] as i64;
        FixedStep {
            dac,
            chain: self.decimate.then_some(ChainSample {
                rate: self.rate as i64,
                quadrature: self.quadrature as i64,
                locked: self.locked,
            }),
        }
    }

    /// The `ce` clock: the sample's inputs, the mode switch's register clears and nominal
    /// frequency word, the decimation count.
    fn capture(&mut self, adc: [i64; 2], mode: Mode) {
        self.switching = mode != self.mode || self.start;
        self.first = self.start;
        self.start = false;
        self.mode = mode;
        self.adc = adc.map(i128::from);
        if self.switching {
            self.delay.iter_mut().for_each(|d| *d = 0);
            self.lock_count = 0;
            // The first sample of a mode runs at its nominal word; the PLL's output point
            // loads the next sample's after the NCO's advance.
            self.freq = self.constants().frequency_word;
        }
        self.decimate = self.count == self.decimation - 1;
        self.count = if self.decimate { 0 } else { self.count + 1 };
    }

    /// The sample's mode constants.
    fn constants(&self) -> ModeConstants {
        self.modes[mode_index(self.mode)]
    }

    /// One clock of `control`: every unit reads the registers as they were, then loads.
    fn clock(&mut self, control: &Control) {
        let m = self.constants();
        let acc = self.acc;
        let rd = self.rd;
        let previous_rd = self.previous_rd;
        let y_register = self.y;

        let reference = self.rom_read(control.rom, &m);
        if control.advance {
            self.nco_acc = self.nco_acc.wrapping_add(self.freq) & self.nco.mask;
        }
        let operands = control
            .issue
            .map_or((0, 0, 0), |issue| self.operands(&issue, &m));
        let (a_limb, b, shift) = self.operands;
        let product = (a_limb * b, shift);
        let pp = self.product.0 << self.product.1;
        let acc_next = control.accumulate.map(|op| {
            let x = match op.x {
                AccX::Keep => acc,
                AccX::Zero => 0,
                AccX::Read => rd,
                AccX::ReadLowpass => rd << self.shifts.lowpass,
                AccX::Setpoint => m.setpoint,
                AccX::PllIntegrator if self.rd_preset => {
                    m.pll_preset << self.shifts.pll_v_to_update
                }
                AccX::PllIntegrator => {
                    held_to(rd, self.shifts.v_held[0], self.shifts.pll_v_to_update)
                }
                AccX::AgcIntegrator => {
                    held_to(rd, self.shifts.v_held[1], self.shifts.agc_v_to_update)
                }
                AccX::PllSum | AccX::AgcSum => self.v << self.shifts.v_to_sum,
            };
            let y = match op.y {
                AccY::Zero => 0,
                AccY::Product => self.pp,
                AccY::NegRead => -rd,
                AccY::DemodProduct => self.p << self.shifts.product_to_state,
                AccY::NegDemodOutput => -self.output,
                AccY::DemodOutput => self.output,
                AccY::PreviousRead => previous_rd,
                AccY::NegReadShifted => -(rd >> self.shifts.lock),
                AccY::DriveQ => self.drive_q,
                AccY::AmplitudeError => self.amplitude_error,
            };
            sign_extend(x.wrapping_add(y), self.datapath.accumulator_width)
        });
        let read = control.read.map(|read| {
            let word = self.ram[usize::from(read.address)];
            assert!(
                control.write.is_none_or(|w| w.address != read.address),
                "word {} read and written in one clock: {control}",
                read.address
            );
            let preset = read.gate == ReadGate::Preset && self.switching;
            let value = match read.gate {
                ReadGate::None | ReadGate::Preset => word,
                ReadGate::Switch => {
                    if self.switching {
                        0
                    } else {
                        word
                    }
                }
                ReadGate::First => {
                    if self.first {
                        0
                    } else {
                        word
                    }
                }
                ReadGate::Seen => {
                    if self.seen < u32::from(read.seen) {
                        0
                    } else {
                        word
                    }
                }
            };
            (value, preset)
        });
        if let Some(write) = control.write {
            let value = match write.data {
                WriteData::AccCic => sign_extend(acc, self.exact.register),
                WriteData::AccLock => sign_extend(acc, self.datapath.lock_width),
                WriteData::DemodState => y_register,
                WriteData::Integrator => self.v,
                WriteData::Read => rd,
                WriteData::Cic => self.c,
            };
            self.ram[usize::from(write.address)] = value;
        }
        self.quantize(control.quantize, acc, &m);

        // The loads.
        self.previous_rd = rd;
        if let Some((value, preset)) = read {
            self.rd = value;
            self.rd_preset = preset;
        }
        self.output = self.points.output.apply(y_register);
        self.pp = pp;
        self.product = product;
        self.operands = operands;
        if let Some(value) = acc_next {
            self.acc = value;
        }
        if let Some(value) = reference {
            self.reference = value;
        }
    }

    /// A sine ROM read: the reference (loaded at the clock's end) and, on a cosine read, the
    /// reference's new truncation error.
    fn rom_read(&mut self, rom: RomRead, m: &ModeConstants) -> Option<i128> {
        let (nco, cos) = match rom {
            RomRead::None => return None,
            RomRead::DriveSin => (0, false),
            RomRead::DriveCos => (0, true),
            RomRead::TransmitCos => (1, true),
            RomRead::SenseSin => (2, false),
            RomRead::SenseCos => (2, true),
        };
        let n = &self.nco;
        let mut phase = self.nco_acc.wrapping_add(m.offsets[nco]) & n.mask;
        if n.error_feedback {
            phase = phase.wrapping_add(self.residue[nco] as u64) & n.mask;
            if cos {
                self.residue[nco] = (phase & n.below_truncation) as i64 - n.half_bin;
            }
        }
        let t = (phase >> n.truncation_shift) as u32 + if cos { 1 << n.address_bits } else { 0 };
        let a = n.address_bits;
        let index = t & ((1 << a) - 1);
        let address = if (t >> a) & 1 == 1 {
            (1 << a) - 1 - index
        } else {
            index
        };
        let magnitude = n.rom[address as usize];
        Some(if (t >> (a + 1)) & 1 == 1 {
            -magnitude
        } else {
            magnitude
        })
    }

    /// The operand registers' values for `issue`: the limb of `a`, `b`, and the product's
    /// weight (the limb's and the PI's alignment).
    fn operands(&self, issue: &Issue, m: &ModeConstants) -> (i128, i128, u32) {
        let a = self.a_operand(issue.a);
        let shift = LIMB_BITS * u32::from(issue.limb);
        let limb = if issue.top {
            a >> shift
        } else {
            (a >> shift) & ((1 << LIMB_BITS) - 1)
        };
        debug_assert!(
            (-(1 << 15)..(1 << 15)).contains(&limb),
            "limb {limb} of {a}"
        );
        let b = self.b_operand(issue.b, issue.tap, m);
        (limb, b, shift + self.shifts.align[issue.b.alignment()])
    }

    fn a_operand(&self, a: ASource) -> i128 {
        let [driven, sensed] = self.mode.axes();
        match a {
            ASource::None => 0,
            ASource::AdcDrive => self.adc[driven],
            ASource::AdcSense => self.adc[sensed],
            ASource::DriveQ => self.drive_q,
            ASource::AmplitudeError => self.amplitude_error,
            ASource::Amplitude => self.amplitude,
            ASource::Cic => self.c,
            ASource::Read => self.rd,
            ASource::CicOutput => self.cic_output,
        }
    }

    fn b_operand(&self, b: BSource, tap: u8, m: &ModeConstants) -> i128 {
        match b {
            BSource::Reference => self.reference,
            BSource::PllKi => self.gains[0],
            BSource::PllKp => self.gains[1],
            BSource::AgcKi => self.gains[2],
            BSource::AgcKp => self.gains[3],
            BSource::Tap => self.taps[usize::from(tap)],
            BSource::RateCoefficient => m.coefficients[0],
            BSource::QuadratureCoefficient => m.coefficients[1],
        }
    }

    fn pll_integrator(&mut self, acc: i128) -> i128 {
        let update = sign_extend(acc, self.exact.pll_update);
        let [low, high] = self.pll_limits;
        self.points.pll_integrator.apply(update).clamp(low, high)
    }

    fn agc_integrator(&mut self, acc: i128) -> i128 {
        let update = sign_extend(acc, self.exact.agc_update);
        let [low, high] = self.agc_limits;
        self.points.agc_integrator.apply(update).clamp(low, high)
    }

    /// The quantization point of this clock, from the accumulator (or the state register).
    fn quantize(&mut self, point: Quantize, acc: i128, m: &ModeConstants) {
        let e = &self.exact;
        match point {
            Quantize::None => {}
            Quantize::DemodProduct => {
                self.p = self.points.product.apply(sign_extend(acc, e.product));
            }
            Quantize::DemodState => self.y = self.points.state.apply(sign_extend(acc, e.state)),
            Quantize::DriveQ => self.drive_q = self.output,
            Quantize::AmplitudeError => {
                self.amplitude_error = self.points.agc_error.apply(sign_extend(acc, e.agc_error));
            }
            Quantize::PllIntegrator => self.v = self.pll_integrator(acc) << self.shifts.v_held[0],
            Quantize::PllOutput => {
                let u = self.points.pll_output.apply(sign_extend(acc, e.pll_sum));
                self.freq = (u as u64) & self.nco.mask;
            }
            Quantize::AgcIntegrator => self.v = self.agc_integrator(acc) << self.shifts.v_held[1],
            Quantize::AgcOutput => {
                self.amplitude = self.points.agc_output.apply(sign_extend(acc, e.agc_sum));
            }
            Quantize::Dac => {
                let drive = self.points.dac.apply(sign_extend(acc, e.dac));
                let out = if self.latency == 0 {
                    drive
                } else {
                    self.delay[self.latency - 1]
                };
                let [driven, sensed] = self.mode.axes();
                self.dac[driven] = out;
                self.dac[sensed] = 0;
                self.delay.rotate_right(1);
                self.delay[0] = drive;
            }
            Quantize::Cic => self.c = self.points.cic.apply(sign_extend(acc, e.register)),
            Quantize::CicOutput => {
                self.cic_output = self.points.cic_output.apply(sign_extend(acc, e.fir));
            }
            Quantize::Rate => self.rate = self.points.rate.apply(sign_extend(acc, e.rate)),
            Quantize::Quadrature => {
                self.quadrature = self.points.rate.apply(sign_extend(acc, e.rate));
            }
            Quantize::LockQ => {
                let z = sign_extend(acc, self.datapath.lock_width);
                self.inside_q = z.abs() < m.lock_limits[0];
            }
            Quantize::LockA => {
                let z = sign_extend(acc, self.datapath.lock_width);
                let inside = self.inside_q && z.abs() < m.lock_limits[1];
                self.lock_count = if inside {
                    (self.lock_count + 1).min(self.lock_hold)
                } else {
                    0
                };
                self.locked = self.lock_count >= self.lock_hold;
            }
        }
    }
}

/// An integrator's word, held shifted left by `held`, at the update's alignment `to` (a right
/// shift when `held` is the larger: the word's low bits are the hold's zeros).
fn held_to(word: i128, held: u32, to: u32) -> i128 {
    if to >= held {
        word << (to - held)
    } else {
        word >> (held - to)
    }
}
