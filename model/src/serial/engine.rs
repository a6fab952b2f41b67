//! [`Engine`]: the serial architecture executed instruction by instruction, as the RTL's
//! `gyrofx_serial_engine` does, one sample per program run.

use crate::fx::Rounding;
use crate::sequencer::Slot;

use super::compile::Program;
use super::isa::{Flags, Instruction, Op, RamIndex, LIMB_BITS, LIMB_MASK};

/// What a sample produces at the program's end.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Outputs {
    /// The KF's rate (output format), when a gyro was valid.
    pub rate: Option<i64>,
    /// The bias estimates after the sample (bias format).
    pub bias: [i64; 2],
    /// A window has produced estimates.
    pub estimated: bool,
}

/// The engine's registers and memories.
#[derive(Clone, Debug)]
pub struct Engine<'a> {
    program: &'a Program,
    ram: Vec<i16>,
    acc: i128,
    half: bool,
    sticky: bool,
    negative: bool,
    high_zero: bool,
    high_ones: bool,
    fits: bool,
    estimated: bool,
    fresh: bool,
    shadow: [u128; 3],
    ports: [i64; 3],
}

impl<'a> Engine<'a> {
    /// The engine at power-up: RAM and registers zero.
    pub fn new(program: &'a Program) -> Self {
        Engine {
            program,
            ram: vec![0; program.ram_words],
            acc: 0,
            half: false,
            sticky: false,
            negative: false,
            high_zero: true,
            high_ones: true,
            fits: false,
            estimated: false,
            fresh: true,
            shadow: [0; 3],
            ports: [0; 3],
        }
    }

    /// `rst`: the outputs clear at once; the next sample clears the state first.
    pub fn reset(&mut self) {
        self.ports = [0; 3];
        self.shadow = [0; 3];
        self.estimated = false;
        self.fresh = true;
    }

    /// One sample: the gyro codes `y`, the KF's ROM address `bw_sel`, the sequencer's `slot`.
    pub fn step(&mut self, y: [i64; 2], bw_sel: usize, slot: &Slot) -> Outputs {
        let program = self.program;
        let any = self.run(&program.sample, y, bw_sel, slot);
        Outputs {
            rate: any.then_some(self.ports[0]),
            bias: [self.ports[1], self.ports[2]],
            estimated: self.estimated,
        }
    }

    /// Runs `code` to its `End`; returns whether a gyro was valid (the rate was updated).
    fn run(&mut self, code: &[Instruction], y: [i64; 2], bw_sel: usize, slot: &Slot) -> bool {
        let p = self.program;
        let mut flags = Flags {
            valid: [!slot.blank_a, !slot.blank_b],
            done: [slot.done_a, slot.done_b],
            window: slot.window_done,
            mode_positive: [slot.mode_a > 0, slot.mode_b > 0],
            estimated: self.estimated,
            fresh: self.fresh,
        };
        let limit = 1i128 << (p.accumulator_bits - 1);
        for ins in code {
            flags.estimated = self.estimated;
            if !ins.cond.holds(&flags) {
                continue;
            }
            let index = match ins.ram_index {
                RamIndex::None => 0,
                RamIndex::IntervalA => slot.interval_a,
                RamIndex::IntervalB => slot.interval_b,
            };
            let address = ins.address as usize + (index << p.ram_index_shift);
            let coefficient = ins.coefficient as usize
                + if ins.coefficient_by_bw_sel {
                    bw_sel << p.coefficient_index_shift
                } else {
                    0
                };
            let b = || i128::from(p.coefficients[coefficient]);
            let low = self.acc & LIMB_MASK;
            let sext = |v: i128| if v & (1 << 14) != 0 { v - (1 << 15) } else { v };
            match ins.op {
                Op::Zero => {
                    self.acc = 0;
                    self.half = false;
                    self.sticky = false;
                    self.high_zero = true;
                    self.high_ones = true;
                }
                Op::Mac => self.acc += i128::from(self.ram[address]) * b(),
                Op::MacInput => self.acc += self.input_limb(y, address) * b(),
                Op::Emit => self.write(address, low),
                Op::EmitTop => self.write(address, sext(low)),
                Op::Drop => self.sticky |= low != 0,
                Op::DropHalf => {
                    self.half = low & (1 << 14) != 0;
                    self.sticky |= low & ((1 << 14) - 1) != 0;
                }
                Op::Sign => self.negative = self.ram[address] < 0,
                Op::Round => self.acc += i128::from(self.increment()),
                Op::High => {
                    self.high_zero &= low == 0;
                    self.high_ones &= low == LIMB_MASK;
                }
                Op::Fits => {
                    self.fits =
                        (self.acc == 0 && self.high_zero) || (self.acc == -1 && self.high_ones);
                }
                Op::StoreLow => {
                    let v = match (self.fits, self.negative) {
                        (true, _) => low,
                        (false, true) => 0,
                        (false, false) => LIMB_MASK,
                    };
                    self.write(address, v);
                }
                Op::StoreTop => {
                    let v = match (self.fits, self.negative) {
                        (true, _) => sext(low),
                        (false, true) => !b(),
                        (false, false) => b(),
                    };
                    self.write(address, v);
                }
                Op::Out => {
                    let port = ins.coefficient as usize;
                    let limbs = [p.rate_limbs, p.bias_limbs, p.bias_limbs][port];
                    let limb = (i128::from(self.ram[address]) & LIMB_MASK) as u128;
                    self.shadow[port] =
                        (self.shadow[port] >> LIMB_BITS) | (limb << (LIMB_BITS * (limbs - 1)));
                }
                Op::SetEstimated => self.estimated = true,
                Op::End => {
                    let any = flags.valid[0] || flags.valid[1];
                    for port in 0..3 {
                        let width = p.output_widths[usize::from(port > 0)];
                        let bits = self.shadow[port] & ((1u128 << width) - 1);
                        let value = ((bits << (128 - width)) as i128) >> (128 - width);
                        if port > 0 || any {
                            self.ports[port] = value as i64;
                        }
                    }
                    self.fresh = false;
                    return any;
                }
            }
            if matches!(
                ins.op,
                Op::Emit
                    | Op::EmitTop
                    | Op::Drop
                    | Op::DropHalf
                    | Op::High
                    | Op::StoreLow
                    | Op::StoreTop
            ) {
                self.acc >>= LIMB_BITS;
            }
            assert!(
                -limit <= self.acc && self.acc < limit,
                "the column accumulator left its {} bits",
                p.accumulator_bits
            );
        }
        panic!("a program without End");
    }

    fn write(&mut self, address: usize, value: i128) {
        self.ram[address] = value as i16;
    }

    /// Limb `address` of the inputs: `y_a`'s limbs, then `y_b`'s, the top ones signed.
    fn input_limb(&self, y: [i64; 2], address: usize) -> i128 {
        let k = self.program.input_limbs as usize;
        let (g, i) = (address / k, address % k);
        let v = i128::from(y[g]) >> (LIMB_BITS as usize * i);
        if i + 1 < k {
            v & LIMB_MASK
        } else {
            v
        }
    }

    fn increment(&self) -> bool {
        let any = self.half || self.sticky;
        let odd = self.acc & 1 != 0;
        match self.program.rounding {
            Rounding::Floor => false,
            Rounding::Ceil => any,
            Rounding::Zero => any && self.negative,
            Rounding::Nearest => self.half,
            Rounding::Round => self.half && (self.sticky || !self.negative),
            Rounding::Convergent => self.half && (self.sticky || odd),
        }
    }
}
