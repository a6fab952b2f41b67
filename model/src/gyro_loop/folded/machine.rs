//! The folded loop run clock by clock, register by register, as `hdl/gyrofx_gyro_loop_serial.v`
//! runs it: the proof of a [`Schedule`] against the parallel model. One machine runs one gyro
//! ([`FoldedGyroLoop`]) or the pair on one datapath ([`FoldedPair`]): the datapath's registers
//! are shared, each gyro has its own mode, NCO, inter-template registers, DAC, lock and outputs,
//! and each unit of a control word works on the gyro its field names.

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

/// One gyro's constants (its plan's values; the formats are the machine's).
#[derive(Clone, Debug)]
struct GyroConstants {
    modes: [ModeConstants; 2],
    gains: [i128; 4],
    pll_limits: [i128; 2],
    agc_limits: [i128; 2],
}

/// One gyro's registers.
#[derive(Clone, Debug)]
struct GyroRegisters {
    mode: Mode,
    switching: bool,
    adc: [i128; 2],
    nco_acc: u64,
    residue: [i64; 3],
    freq: u64,
    drive_q: i128,
    amplitude_error: i128,
    amplitude: i128,
    delay: Vec<i128>,
    dac: [i128; 2],
    rate: i128,
    quadrature: i128,
    inside_q: bool,
    lock_count: u32,
    locked: bool,
    /// The mode and lock flag of the last decimating sample (the `1/SF` coefficients and the
    /// decimated output's flag, which a pair produces samples later).
    decimation_mode: Mode,
    decimation_locked: bool,
}

impl GyroRegisters {
    fn new(latency: usize) -> GyroRegisters {
        GyroRegisters {
            mode: Mode::Normal,
            switching: false,
            adc: [0; 2],
            nco_acc: 0,
            residue: [0; 3],
            freq: 0,
            drive_q: 0,
            amplitude_error: 0,
            amplitude: 0,
            delay: vec![0; latency.max(1)],
            dac: [0; 2],
            rate: 0,
            quadrature: 0,
            inside_q: false,
            lock_count: 0,
            locked: false,
            decimation_mode: Mode::Normal,
            decimation_locked: false,
        }
    }
}

/// The folded datapath running a schedule for one or two gyros.
#[derive(Clone, Debug)]
struct Machine {
    schedule: Schedule,
    datapath: Datapath,
    points: Points,
    exact: ExactWidths,
    shifts: Shifts,
    nco: NcoConstants,
    taps: Vec<i128>,
    decimation: u32,
    latency: usize,
    lock_hold: u32,
    most_seen: u32,
    constants: Vec<GyroConstants>,
    gyros: Vec<GyroRegisters>,
    // Shared registers.
    start: bool,
    first: bool,
    decimate: bool,
    count: u32,
    seen: u32,
    /// The deferred segment the next sample runs (a pair after a decimating sample).
    pending: Option<usize>,
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
    /// The integrator register: a PI's integrator, held as `Shifts::v_held` says.
    v: i128,
    c: i128,
    cic_output: i128,
    ram: Vec<i128>,
}

/// The folded loop of one gyro: the same ports and results as
/// [`crate::gyro_loop::gyro::FixedGyroLoop`].
#[derive(Clone, Debug)]
pub struct FoldedGyroLoop {
    machine: Machine,
}

/// What one ADC sample of the folded pair gives.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct PairStep {
    /// Each gyro's DAC codes `[x, y]` (DAC format); the sense axis's is 0.
    pub dac: [[i64; 2]; 2],
    /// Each gyro's lock flag after the sample.
    pub locked: [bool; 2],
    /// Whether this sample decimates (the parallel loops' chain sample comes now).
    pub decimating: bool,
    /// Both gyros' decimated outputs, in the sample whose deferred segment completes them
    /// ([`FoldedPair::output_delay`] samples after their decimating sample).
    pub chain: Option<[ChainSample; 2]>,
}

/// The folded pair: gyros A and B on one datapath ([`Schedule::pair`]), each the same loop as
/// its [`crate::gyro_loop::gyro::FixedGyroLoop`] bit for bit but that each decimated output
/// comes [`FoldedPair::output_delay`] samples after the sample that decimates.
#[derive(Clone, Debug)]
pub struct FoldedPair {
    machine: Machine,
}

impl FoldedPair {
    /// Gyro A's and B's loops of `plans` (one set of formats: the config checks it), reset.
    ///
    /// # Panics
    /// When the plans have no pair schedule ([`Schedule::pair`] refuses them).
    pub fn new(plans: [&Plan; 2]) -> Self {
        let schedule = Schedule::pair(plans[0]).expect("the plans have a folded pair schedule");
        FoldedPair {
            machine: Machine::new(&plans, schedule),
        }
    }

    /// The schedule the pair runs.
    pub fn schedule(&self) -> &Schedule {
        &self.machine.schedule
    }

    /// Samples from a decimating sample to the one that gives its outputs.
    pub fn output_delay(&self) -> usize {
        self.machine.schedule.deferred.len()
    }

    /// One ADC sample: each gyro's codes `[x, y]` (ADC format) and mode.
    pub fn step(&mut self, adc: [[i64; 2]; 2], modes: [Mode; 2]) -> PairStep {
        let m = &mut self.machine;
        let done = m.sample(&adc, &modes);
        let step = |g: usize| m.dac(g);
        PairStep {
            dac: [step(0), step(1)],
            locked: [m.gyros[0].locked, m.gyros[1].locked],
            decimating: m.decimate,
            chain: done.then(|| [m.chain_sample(0), m.chain_sample(1)]),
        }
    }
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
        FoldedGyroLoop {
            machine: Machine::new(&[plan], schedule),
        }
    }

    /// The schedule this loop runs.
    pub fn schedule(&self) -> &Schedule {
        &self.machine.schedule
    }

    /// The lock flag.
    pub fn locked(&self) -> bool {
        self.machine.gyros[0].locked
    }

    /// One ADC sample: the clock with `ce` high, then the schedule's clocks.
    pub fn step(&mut self, adc: [i64; 2], mode: Mode) -> FixedStep {
        let m = &mut self.machine;
        let done = m.sample(&[adc], &[mode]);
        FixedStep {
            dac: m.dac(0),
            chain: done.then(|| m.chain_sample(0)),
        }
    }
}

impl GyroConstants {
    fn new(plan: &Plan) -> GyroConstants {
        let mode = |m: &crate::gyro_loop::gyro::ModePlan| ModeConstants {
            setpoint: i128::from(m.setpoint_code),
            pll_preset: i128::from(m.pll_preset).clamp(plan.pll.limits[0], plan.pll.limits[1]),
            frequency_word: m.frequency_word,
            offsets: [0, m.dac_offset_word, m.sense_offset_word],
            coefficients: [m.rate_coefficient.code, m.quadrature_coefficient.code],
            lock_limits: m.lock_limits.map(i128::from),
        };
        let (pll, agc) = (&plan.pll, &plan.agc);
        GyroConstants {
            modes: [mode(&plan.modes[0]), mode(&plan.modes[1])],
            gains: [pll.ki.code, pll.kp.code, agc.ki.code, agc.kp.code],
            pll_limits: pll.limits,
            agc_limits: agc.limits,
        }
    }
}

impl Machine {
    /// The machine of `plans` (gyro A's, then B's; their formats are `plans[0]`'s) running
    /// `schedule`, in the state of reset.
    fn new(plans: &[&Plan], schedule: Schedule) -> Machine {
        let plan = plans[0];
        let demod = &plan.demodulator;
        let shift_of = |to: i32, from: i32| (to - from) as u32;
        let pll = &plan.pll;
        let agc = &plan.agc;
        let nco = &plan.nco;
        let width = nco.phase.width;
        let below = width - nco.address_bits - 2;
        let words = schedule.ram_words();
        let pll_v_to_sum = shift_of(pll.output.from.frac, pll.integrator.frac);
        let agc_v_to_sum = shift_of(agc.output.from.frac, agc.integrator.frac);
        Machine {
            datapath: Datapath::new(plan),
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
            taps: plan.cic.taps.iter().map(|h| h.code).collect(),
            decimation: plan.cic.decimation,
            latency: plan.latency as usize,
            lock_hold: plan.lock.hold_samples,
            most_seen: plan
                .cic
                .differential_delay
                .max(plan.cic.taps.len() as u32 - 1),
            constants: plans.iter().map(|p| GyroConstants::new(p)).collect(),
            gyros: plans
                .iter()
                .map(|_| GyroRegisters::new(plan.latency as usize))
                .collect(),
            start: true,
            first: false,
            decimate: false,
            count: 0,
            seen: 0,
            pending: None,
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
            v: 0,
            c: 0,
            cic_output: 0,
            ram: vec![0; words],
            schedule,
        }
    }

    /// One ADC sample: the `ce` clock, then the schedule's clocks; whether the sample completed
    /// a decimation's outputs.
    fn sample(&mut self, adc: &[[i64; 2]], modes: &[Mode]) -> bool {
        self.capture(adc, modes);
        let regular = self.schedule.regular;
        let pair = self.schedule.words_b.is_some();
        let segment: Option<usize> = if pair {
            self.pending
        } else {
            self.decimate.then_some(0)
        };
        for t in 0..regular {
            let control = self.schedule.controls[t];
            self.clock(&control);
        }
        if self.decimate {
            for g in &mut self.gyros {
                g.decimation_locked = g.locked;
            }
        }
        let mut done = false;
        if let Some(k) = segment {
            let words = if pair {
                self.schedule.deferred[k].len()
            } else {
                self.schedule.controls.len() - regular
            };
            for t in 0..words {
                // Copied word by word: the segment is not cloned every sample.
                let control = if pair {
                    self.schedule.deferred[k][t]
                } else {
                    self.schedule.controls[regular + t]
                };
                self.clock(&control);
            }
            done = !pair || k + 1 == self.schedule.deferred.len();
            self.pending = (!done).then_some(k + 1);
        }
        if pair && self.decimate {
            self.pending = Some(0);
        }
        if done {
            self.seen = (self.seen + 1).min(self.most_seen);
        }
        done
    }

    /// Gyro `g`'s DAC codes after a sample (the sense axis's 0).
    fn dac(&self, g: usize) -> [i64; 2] {
        let regs = &self.gyros[g];
        let [driven, _] = regs.mode.axes();
        let mut dac = [0i64; 2];
        dac[driven] = regs.dac[driven] as i64;
        dac
    }

    /// Gyro `g`'s decimated output of the last decimation.
    fn chain_sample(&self, g: usize) -> ChainSample {
        let regs = &self.gyros[g];
        ChainSample {
            rate: regs.rate as i64,
            quadrature: regs.quadrature as i64,
            locked: regs.decimation_locked,
        }
    }

    /// The `ce` clock: the sample's inputs, the mode switches' register clears and nominal
    /// frequency words, the decimation count.
    fn capture(&mut self, adc: &[[i64; 2]], modes: &[Mode]) {
        let start = self.start;
        self.first = start;
        self.start = false;
        self.decimate = self.count == self.decimation - 1;
        self.count = if self.decimate { 0 } else { self.count + 1 };
        let decimate = self.decimate;
        for (g, regs) in self.gyros.iter_mut().enumerate() {
            let mode = modes[g];
            regs.switching = mode != regs.mode || start;
            regs.mode = mode;
            regs.adc = adc[g].map(i128::from);
            if regs.switching {
                regs.delay.iter_mut().for_each(|d| *d = 0);
                regs.lock_count = 0;
                // The first sample of a mode runs at its nominal word; the PLL's output point
                // loads the next sample's after the NCO's advance.
                regs.freq = self.constants[g].modes[mode_index(mode)].frequency_word;
            }
            if decimate {
                regs.decimation_mode = mode;
            }
        }
    }

    /// Gyro `g`'s constants of its sample's mode.
    fn mode_constants(&self, g: u8) -> ModeConstants {
        let g = usize::from(g);
        self.constants[g].modes[mode_index(self.gyros[g].mode)]
    }

    /// One clock of `control`: every unit reads the registers as they were, then loads.
    fn clock(&mut self, control: &Control) {
        let acc = self.acc;
        let rd = self.rd;
        let previous_rd = self.previous_rd;
        let y_register = self.y;

        let reference = self.rom_read(control.rom, control.rom_gyro);
        if control.advance {
            let regs = &mut self.gyros[usize::from(control.advance_gyro)];
            regs.nco_acc = regs.nco_acc.wrapping_add(regs.freq) & self.nco.mask;
        }
        let operands = control
            .issue
            .map_or((0, 0, 0), |issue| self.operands(&issue));
        let (a_limb, b, shift) = self.operands;
        let product = (a_limb * b, shift);
        let pp = self.product.0 << self.product.1;
        let acc_next = control.accumulate.map(|op| {
            let m = self.mode_constants(op.gyro);
            let regs = &self.gyros[usize::from(op.gyro)];
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
                AccY::DriveQ => regs.drive_q,
                AccY::AmplitudeError => regs.amplitude_error,
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
            let switching = self.gyros[usize::from(read.gyro)].switching;
            let preset = read.gate == ReadGate::Preset && switching;
            let zero = match read.gate {
                ReadGate::None | ReadGate::Preset => false,
                ReadGate::Switch => switching,
                ReadGate::First => self.first,
                ReadGate::Seen => self.seen < u32::from(read.seen),
            };
            (if zero { 0 } else { word }, preset)
        });
        if let Some(write) = control.write.filter(|w| !w.decimating || self.decimate) {
            let value = match write.data {
                WriteData::AccCic => sign_extend(acc, self.exact.register),
                WriteData::AccLock => sign_extend(acc, self.datapath.lock_width),
                WriteData::AccFir => sign_extend(acc, self.exact.fir),
                WriteData::DemodState => y_register,
                WriteData::Integrator => self.v,
                WriteData::Read => rd,
                WriteData::Cic => self.c,
            };
            self.ram[usize::from(write.address)] = value;
        }
        self.quantize(control.quantize, control.quantize_gyro, acc);

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

    /// A sine ROM read of gyro `g`'s NCO: the reference (loaded at the clock's end) and, on a
    /// cosine read, the reference's new truncation error.
    fn rom_read(&mut self, rom: RomRead, g: u8) -> Option<i128> {
        let (nco, cos) = match rom {
            RomRead::None => return None,
            RomRead::DriveSin => (0, false),
            RomRead::DriveCos => (0, true),
            RomRead::TransmitCos => (1, true),
            RomRead::SenseSin => (2, false),
            RomRead::SenseCos => (2, true),
        };
        let m = self.mode_constants(g);
        let n = &self.nco;
        let regs = &mut self.gyros[usize::from(g)];
        let mut phase = regs.nco_acc.wrapping_add(m.offsets[nco]) & n.mask;
        if n.error_feedback {
            phase = phase.wrapping_add(regs.residue[nco] as u64) & n.mask;
            if cos {
                regs.residue[nco] = (phase & n.below_truncation) as i64 - n.half_bin;
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
    fn operands(&self, issue: &Issue) -> (i128, i128, u32) {
        let a = self.a_operand(issue.a, issue.gyro);
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
        let b = self.b_operand(issue.b, issue.tap, issue.gyro);
        (limb, b, shift + self.shifts.align[issue.b.alignment()])
    }

    fn a_operand(&self, a: ASource, g: u8) -> i128 {
        let regs = &self.gyros[usize::from(g)];
        let [driven, sensed] = regs.mode.axes();
        match a {
            ASource::None => 0,
            ASource::AdcDrive => regs.adc[driven],
            ASource::AdcSense => regs.adc[sensed],
            ASource::DriveQ => regs.drive_q,
            ASource::AmplitudeError => regs.amplitude_error,
            ASource::Amplitude => regs.amplitude,
            ASource::Cic => self.c,
            ASource::Read => self.rd,
            ASource::CicOutput => self.cic_output,
        }
    }

    fn b_operand(&self, b: BSource, tap: u8, g: u8) -> i128 {
        let g = usize::from(g);
        let constants = &self.constants[g];
        // The 1/SF of the mode the decimation was taken in (a pair scales samples later).
        let decimated = constants.modes[mode_index(self.gyros[g].decimation_mode)];
        match b {
            BSource::Reference => self.reference,
            BSource::PllKi => constants.gains[0],
            BSource::PllKp => constants.gains[1],
            BSource::AgcKi => constants.gains[2],
            BSource::AgcKp => constants.gains[3],
            BSource::Tap => self.taps[usize::from(tap)],
            BSource::RateCoefficient => decimated.coefficients[0],
            BSource::QuadratureCoefficient => decimated.coefficients[1],
        }
    }

    /// The quantization point of this clock, from the accumulator (or the state register),
    /// into gyro `g`'s register where it is the gyro's.
    fn quantize(&mut self, point: Quantize, g: u8, acc: i128) {
        let e = self.exact;
        let m = self.mode_constants(g);
        let latency = self.latency;
        let lock_hold = self.lock_hold;
        let lock_width = self.datapath.lock_width;
        let constants = &self.constants[usize::from(g)];
        let regs = &mut self.gyros[usize::from(g)];
        let points = &mut self.points;
        match point {
            Quantize::None => {}
            Quantize::DemodProduct => {
                self.p = points.product.apply(sign_extend(acc, e.product));
            }
            Quantize::DemodState => self.y = points.state.apply(sign_extend(acc, e.state)),
            Quantize::DriveQ => regs.drive_q = self.output,
            Quantize::AmplitudeError => {
                regs.amplitude_error = points.agc_error.apply(sign_extend(acc, e.agc_error));
            }
            Quantize::PllIntegrator => {
                let update = sign_extend(acc, e.pll_update);
                let [low, high] = constants.pll_limits;
                self.v =
                    points.pll_integrator.apply(update).clamp(low, high) << self.shifts.v_held[0];
            }
            Quantize::PllOutput => {
                let u = points.pll_output.apply(sign_extend(acc, e.pll_sum));
                regs.freq = (u as u64) & self.nco.mask;
            }
            Quantize::AgcIntegrator => {
                let update = sign_extend(acc, e.agc_update);
                let [low, high] = constants.agc_limits;
                self.v =
                    points.agc_integrator.apply(update).clamp(low, high) << self.shifts.v_held[1];
            }
            Quantize::AgcOutput => {
                regs.amplitude = points.agc_output.apply(sign_extend(acc, e.agc_sum));
            }
            Quantize::Dac => {
                let drive = points.dac.apply(sign_extend(acc, e.dac));
                let out = if latency == 0 {
                    drive
                } else {
                    regs.delay[latency - 1]
                };
                let [driven, sensed] = regs.mode.axes();
                regs.dac[driven] = out;
                regs.dac[sensed] = 0;
                regs.delay.rotate_right(1);
                regs.delay[0] = drive;
            }
            Quantize::Cic => self.c = points.cic.apply(sign_extend(acc, e.register)),
            Quantize::CicOutput => {
                self.cic_output = points.cic_output.apply(sign_extend(acc, e.fir));
            }
            Quantize::Rate => regs.rate = points.rate.apply(sign_extend(acc, e.rate)),
            Quantize::Quadrature => {
                regs.quadrature = points.rate.apply(sign_extend(acc, e.rate));
            }
            Quantize::LockQ => {
                let z = sign_extend(acc, lock_width);
                regs.inside_q = z.abs() < m.lock_limits[0];
            }
            Quantize::LockA => {
                let z = sign_extend(acc, lock_width);
                let inside = regs.inside_q && z.abs() < m.lock_limits[1];
                regs.lock_count = if inside {
                    (regs.lock_count + 1).min(lock_hold)
                } else {
                    0
                };
                regs.locked = regs.lock_count >= lock_hold;
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
