//! The chain compiled to the engine's program: every block's arithmetic as column scans of
//! limb products, every quantization point as the same rounding and overflow, in the model's
//! order.
//!
//! A sum of products `V = Σ source · coefficient` is built column by column: column `c`
//! accumulates every limb product `s_i · k_l` with `i + l = c` (plus the carry, which is the
//! accumulator shifted right by 15), then emits its low 15 bits as limb `c`. A shift by `s`
//! bits is a product with `2^s` (a coefficient limb `2^(s mod 15)` at limb offset `s / 15`).
//!
//! `Q(V)` from `f` to a format `(w, f')` drops `d = f − f'` bits in up to three passes:
//! 1. scan `V · 2^t` with `t = 15 m − d` (`m = ceil(d / 15)`): the lowest `m` limbs are the
//!    dropped bits (`Drop`, `DropHalf` gather the half bit and the sticky bits), the rounding
//!    increment is added at column `m` (`Round`, which also sees the quotient's LSB), the
//!    quotient's limbs are emitted. If the quotient cannot exceed `w` bits, they go straight
//!    to the destination;
//! 2. (saturate) scan the quotient `· 2^u` so that bit `w − 1` starts a limb: every limb from
//!    there up must be the sign (`High`, then `Fits`);
//! 3. copy the quotient's low limbs to the destination: clamped when it does not fit
//!    (`StoreLow`, `StoreTop`), or (wrap) its top limb sign-extended from bit `w − 1` by two
//!    products with powers of two.

use std::collections::BTreeMap;

use crate::chain::Plan;
use crate::fx::{Format, Overflow, Rounding};

use super::isa::{Cond, Instruction, Layout, Op, RamIndex, CLOCKS_PER_INSTRUCTION, LIMB_BITS};

/// Why a plan has no serial program.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum CompileError {
    /// A format the engine cannot hold.
    #[error("{node} has format {format}: the serial architecture takes signed formats only")]
    Unsigned {
        /// The node.
        node: &'static str,
        /// Its format.
        format: String,
    },
    /// An alignment shift to the right, where the model only shifts left.
    #[error(
        "{node}: aligning needs a shift of {shift} bits; the serial architecture needs it >= 0"
    )]
    Alignment {
        /// The node.
        node: &'static str,
        /// The shift.
        shift: i32,
    },
    /// A memory larger than the instruction word addresses.
    #[error("the serial program needs {words} {memory} words; at most {limit} are addressable")]
    TooLarge {
        /// Which memory.
        memory: &'static str,
        /// Words it needs.
        words: usize,
        /// The limit.
        limit: usize,
    },
}

/// Output registers of [`Op::Out`].
pub const OUTPUT_RATE: u16 = 0;
/// `bias_a`'s output register.
pub const OUTPUT_BIAS_A: u16 = 1;
/// `bias_b`'s output register.
pub const OUTPUT_BIAS_B: u16 = 2;

/// The compiled chain: both programs, the coefficient ROM, the memory sizes and the widths
/// the RTL takes as parameters.
#[derive(Clone, Debug, PartialEq)]
pub struct Program {
    /// The per-sample program (from address 0 to its [`Op::End`]); on the first sample since
    /// reset it clears the state first.
    pub sample: Vec<Instruction>,
    /// Coefficient ROM words (16-bit signed limbs).
    pub coefficients: Vec<i16>,
    /// Data RAM words used (state first, then temporaries).
    pub ram_words: usize,
    /// Data RAM words holding state (cleared by the first sample since reset).
    pub state_words: usize,
    /// Left shift of an interval index added to a RAM address.
    pub ram_index_shift: u32,
    /// Left shift of `bw_sel` added to a coefficient address.
    pub coefficient_index_shift: u32,
    /// Bits of the column accumulator: the largest sum any column can reach, signed (at
    /// least 17, so that a limb and its sign fit).
    pub accumulator_bits: u32,
    /// Limbs of an input sample, of the rate output and of a bias output.
    pub input_limbs: u32,
    /// Limbs of the rate output.
    pub rate_limbs: u32,
    /// Limbs of a bias output.
    pub bias_limbs: u32,
    /// Widths of the outputs: rate, bias.
    pub output_widths: [u32; 2],
    /// Rounding of every quantization point.
    pub rounding: Rounding,
    /// Overflow of every quantization point.
    pub overflow: Overflow,
    /// Program-ROM word layout.
    pub layout: Layout,
}

impl Program {
    /// Clocks after the `ce` clock until the outputs show the sample: every instruction of
    /// the sample program, executed or not, takes [`CLOCKS_PER_INSTRUCTION`]. The next `ce`
    /// may come one clock later.
    pub fn settle_clocks(&self) -> u32 {
        CLOCKS_PER_INSTRUCTION * self.sample.len() as u32
    }

    /// The program ROM's words.
    pub fn rom_words(&self) -> Vec<u64> {
        self.sample.iter().map(|i| i.encode(&self.layout)).collect()
    }
}

/// Limbs of a `width`-bit signed value.
pub fn limbs_of(width: u32) -> u32 {
    width.div_ceil(LIMB_BITS).max(1)
}

/// Bits of `n` (at least 1): the address width of `n` words.
fn address_bits(n: usize) -> u32 {
    (usize::BITS - n.saturating_sub(1).leading_zeros()).max(1)
}

/// Signed bits holding every value in `[-bound, bound]`.
fn signed_bits(bound: u128) -> u32 {
    128 - bound.leading_zeros() + 1
}

/// A value in the data RAM.
#[derive(Clone, Copy, Debug)]
struct Value {
    address: u16,
    limbs: u32,
    width: u32,
    frac: i32,
}

fn limb_bound(width: u32, limbs: u32, i: u32) -> u128 {
    if i + 1 < limbs {
        (1 << LIMB_BITS) - 1
    } else {
        let top_bits = width.saturating_sub(LIMB_BITS * (limbs - 1)).max(1);
        1 << (top_bits - 1)
    }
}

/// Where a product's first operand comes from.
#[derive(Clone, Copy, Debug)]
enum Source {
    Ram(Value),
    /// Gyro `g`'s input sample.
    Input(usize),
}

/// A coefficient: its nonzero limbs (limb offset, ROM address, largest magnitude), the
/// largest magnitude of its value, and whether `bw_sel` selects it.
#[derive(Clone, Debug)]
struct Coefficient {
    limbs: Vec<(u32, u16, u128)>,
    bound: u128,
    by_bw_sel: bool,
}

/// `source · coefficient`, acting under `cond` (else the statement's).
#[derive(Clone, Debug)]
struct Term {
    source: Source,
    coefficient: Coefficient,
    cond: Option<Cond>,
}

/// Limbs of `value` (low limbs 0..2^15, the top signed), as few as hold it.
fn split(value: i128) -> Vec<i16> {
    let k = limbs_of(signed_bits(value.unsigned_abs()));
    (0..k).map(|i| limb_at(value, i, k)).collect()
}

struct Compiler {
    input: Format,
    overflow: Overflow,
    code: Vec<Instruction>,
    cond: Cond,
    coefficients: Vec<i16>,
    constants: BTreeMap<i16, u16>,
    ram_top: usize,
    ram_high: usize,
    bound: u128,
    bound_high: u128,
}

impl Compiler {
    fn push(&mut self, op: Op, address: u16, coefficient: u16) {
        self.push_full(op, self.cond, RamIndex::None, false, address, coefficient);
    }

    fn push_full(
        &mut self,
        op: Op,
        cond: Cond,
        ram_index: RamIndex,
        coefficient_by_bw_sel: bool,
        address: u16,
        coefficient: u16,
    ) {
        match op {
            Op::Zero => self.bound = 0,
            Op::Emit
            | Op::EmitTop
            | Op::Drop
            | Op::DropHalf
            | Op::High
            | Op::StoreLow
            | Op::StoreTop => self.bound = (self.bound >> LIMB_BITS) + 1,
            Op::Round => self.bound += 1,
            _ => {}
        }
        self.bound_high = self.bound_high.max(self.bound);
        self.code.push(Instruction {
            op,
            cond,
            ram_index,
            coefficient_by_bw_sel,
            address,
            coefficient,
        });
    }

    fn allocate(&mut self, limbs: u32) -> u16 {
        let address = self.ram_top;
        self.ram_top += limbs as usize;
        self.ram_high = self.ram_high.max(self.ram_top);
        address as u16
    }

    fn value(&mut self, width: u32, frac: i32) -> Value {
        let limbs = limbs_of(width);
        Value {
            address: self.allocate(limbs),
            limbs,
            width,
            frac,
        }
    }

    /// The ROM address of a constant limb (each distinct limb stored once).
    fn constant_limb(&mut self, limb: i16) -> u16 {
        if let Some(&a) = self.constants.get(&limb) {
            return a;
        }
        let a = self.coefficients.len() as u16;
        self.coefficients.push(limb);
        self.constants.insert(limb, a);
        a
    }

    fn constant(&mut self, value: i128) -> Coefficient {
        let limbs = split(value)
            .into_iter()
            .enumerate()
            .filter(|(_, l)| *l != 0)
            .map(|(i, l)| {
                (
                    i as u32,
                    self.constant_limb(l),
                    u128::from(l.unsigned_abs()),
                )
            })
            .collect();
        Coefficient {
            limbs,
            bound: value.unsigned_abs(),
            by_bw_sel: false,
        }
    }

    /// `2^shift`; `node` names the alignment in the error.
    fn power(&mut self, node: &'static str, shift: i32) -> Result<Coefficient, CompileError> {
        if !(0..=120).contains(&shift) {
            return Err(CompileError::Alignment { node, shift });
        }
        Ok(self.constant(1i128 << shift))
    }

    fn source_limbs(&self, source: Source) -> (u32, u32) {
        match source {
            Source::Ram(v) => (v.limbs, v.width),
            Source::Input(_) => (limbs_of(self.input.width), self.input.width),
        }
    }

    fn max_column(&self, terms: &[Term]) -> u32 {
        terms
            .iter()
            .flat_map(|t| {
                let (limbs, _) = self.source_limbs(t.source);
                t.coefficient
                    .limbs
                    .iter()
                    .map(move |(off, _, _)| limbs - 1 + off)
            })
            .max()
            .unwrap_or(0)
    }

    /// Signed width holding every value of the sum.
    fn width(&self, terms: &[Term]) -> u32 {
        let bound: u128 = terms
            .iter()
            .map(|t| {
                let (_, width) = self.source_limbs(t.source);
                (1u128 << (width - 1)) * t.coefficient.bound
            })
            .sum();
        signed_bits(bound)
    }

    /// The products of column `column`.
    fn macs(&mut self, terms: &[Term], column: u32) {
        for term in terms {
            let (limbs, width) = self.source_limbs(term.source);
            for i in 0..limbs {
                for &(off, address, bound) in &term.coefficient.limbs {
                    if i + off != column {
                        continue;
                    }
                    let (op, base) = match term.source {
                        Source::Ram(v) => (Op::Mac, v.address),
                        Source::Input(g) => (Op::MacInput, (g as u32 * limbs) as u16),
                    };
                    self.bound += limb_bound(width, limbs, i) * bound;
                    self.push_full(
                        op,
                        term.cond.unwrap_or(self.cond),
                        RamIndex::None,
                        term.coefficient.by_bw_sel,
                        base + i as u16,
                        address,
                    );
                }
            }
        }
    }

    /// The exact sum into `dest` (which must hold it).
    fn materialize_into(&mut self, terms: &[Term], dest: Value) {
        debug_assert!(self.max_column(terms) < dest.limbs);
        self.push(Op::Zero, 0, 0);
        for c in 0..dest.limbs {
            self.macs(terms, c);
            let op = if c + 1 < dest.limbs {
                Op::Emit
            } else {
                Op::EmitTop
            };
            self.push(op, dest.address + c as u16, 0);
        }
    }

    /// The exact sum into a new value at `frac` fraction bits.
    fn materialize(&mut self, terms: &[Term], frac: i32) -> Value {
        let width = self.width(terms);
        let limbs = limbs_of(width).max(self.max_column(terms) + 1);
        let dest = Value {
            address: self.allocate(limbs),
            limbs,
            width,
            frac,
        };
        self.materialize_into(terms, dest);
        dest
    }

    fn store(&mut self, op: Op, dest: u16, index: RamIndex, coefficient: u16) {
        self.push_full(op, self.cond, index, false, dest, coefficient);
    }

    /// `Q(v)` into `to` at `dest` (RAM address, plus the run-time `index`): the rounded
    /// quotient, then, when it may not fit, the clamp or the wrap.
    fn quantize(
        &mut self,
        node: &'static str,
        v: Value,
        to: Format,
        dest: u16,
        index: RamIndex,
    ) -> Result<(), CompileError> {
        let mark = self.ram_top;
        if let Some(quotient) = self.rounded_quotient(node, v, to, dest, index)? {
            let copy = [Term {
                source: Source::Ram(quotient),
                coefficient: self.constant(1),
                cond: None,
            }];
            match self.overflow {
                Overflow::Saturate => self.saturate(node, quotient, &copy, to, dest, index)?,
                Overflow::Wrap => self.wrap(node, quotient, &copy, to, dest, index)?,
            }
        }
        self.ram_top = mark;
        Ok(())
    }

    /// Pass 1: the quotient of `v` rounded to `to`'s fraction bits, straight into `dest` when
    /// it always fits `to` (then `None`), else into scratch RAM (returned).
    fn rounded_quotient(
        &mut self,
        node: &'static str,
        v: Value,
        to: Format,
        dest: u16,
        index: RamIndex,
    ) -> Result<Option<Value>, CompileError> {
        let drop = v.frac - to.frac;
        let m = if drop > 0 {
            (drop as u32).div_ceil(LIMB_BITS)
        } else {
            0
        };
        let t = (LIMB_BITS * m) as i32 - drop;
        let rounds = drop > 0;
        let scale = self.power(node, t)?;
        let scaled = [Term {
            source: Source::Ram(v),
            coefficient: scale,
            cond: None,
        }];
        let quotient_width =
            (v.width as i32 + t - (LIMB_BITS * m) as i32 + i32::from(rounds)).max(1) as u32;
        // The sign picks the rounding (toward zero, half away) and the clamp.
        self.push(Op::Sign, v.address + v.limbs as u16 - 1, 0);
        let direct = quotient_width <= to.width;
        let (kq, q_address, q_index) = if direct {
            (limbs_of(to.width), dest, index)
        } else {
            let kq = limbs_of(quotient_width);
            (kq, self.allocate(kq), RamIndex::None)
        };
        assert!(
            self.max_column(&scaled) < m + kq,
            "{node}: the scaled value has limbs beyond the quotient"
        );
        self.push(Op::Zero, 0, 0);
        for c in 0..m + kq {
            self.macs(&scaled, c);
            if c + 1 < m {
                self.push(Op::Drop, 0, 0);
            } else if c + 1 == m {
                self.push(Op::DropHalf, 0, 0);
            } else {
                if c == m && rounds {
                    self.push(Op::Round, 0, 0);
                }
                let op = if c + 1 < m + kq {
                    Op::Emit
                } else {
                    Op::EmitTop
                };
                self.store(op, q_address + (c - m) as u16, q_index, 0);
            }
        }
        Ok((!direct).then_some(Value {
            address: q_address,
            limbs: kq,
            width: quotient_width,
            frac: to.frac,
        }))
    }

    /// Passes 2 and 3 of a saturating `Q`: whether `quotient` fits `to`, then its low limbs
    /// or the clamp into `dest` (`copy` is the quotient times one).
    fn saturate(
        &mut self,
        node: &'static str,
        quotient: Value,
        copy: &[Term],
        to: Format,
        dest: u16,
        index: RamIndex,
    ) -> Result<(), CompileError> {
        let kd = limbs_of(to.width);
        let top_bits = to.width - LIMB_BITS * (kd - 1);
        let u = (LIMB_BITS - (to.width - 1) % LIMB_BITS) % LIMB_BITS;
        let m2 = (to.width - 1 + u) / LIMB_BITS;
        let columns = (quotient.width + u).div_ceil(LIMB_BITS);
        let aligned = [Term {
            source: Source::Ram(quotient),
            coefficient: self.power(node, u as i32)?,
            cond: None,
        }];
        assert!(
            self.max_column(&aligned) < columns,
            "{node}: pass 2 misses limbs"
        );
        self.push(Op::Zero, 0, 0);
        for c in 0..columns {
            self.macs(&aligned, c);
            let op = if c < m2 {
                Op::Drop
            } else if c + 1 < columns {
                Op::High
            } else {
                Op::Fits
            };
            self.push(op, 0, 0);
        }
        let largest_top = self.constant_limb(((1i32 << (top_bits - 1)) - 1) as i16);
        self.push(Op::Zero, 0, 0);
        for c in 0..kd {
            self.macs(copy, c);
            if c + 1 < kd {
                self.store(Op::StoreLow, dest + c as u16, index, 0);
            } else {
                self.store(Op::StoreTop, dest + c as u16, index, largest_top);
            }
        }
        Ok(())
    }

    /// A wrapping `Q`: `quotient`'s low `to.width` bits into `dest`, the top limb
    /// sign-extended from its kept bits (`copy` is the quotient times one).
    fn wrap(
        &mut self,
        node: &'static str,
        quotient: Value,
        copy: &[Term],
        to: Format,
        dest: u16,
        index: RamIndex,
    ) -> Result<(), CompileError> {
        let kd = limbs_of(to.width);
        let top_bits = to.width - LIMB_BITS * (kd - 1);
        self.push(Op::Zero, 0, 0);
        for c in 0..kd - 1 {
            self.macs(copy, c);
            self.store(Op::Emit, dest + c as u16, index, 0);
        }
        let top = dest + kd as u16 - 1;
        if top_bits == LIMB_BITS {
            self.macs(copy, kd - 1);
            self.store(Op::EmitTop, top, index, 0);
            return Ok(());
        }
        // sext(limb mod 2^b) = ((limb · 2^(15−b)) as 15-bit signed) · 2^b / 2^15.
        let limb = Value {
            address: quotient.address + kd as u16 - 1,
            limbs: 1,
            width: LIMB_BITS + 1,
            frac: 0,
        };
        let up = self.power(node, (LIMB_BITS - top_bits) as i32)?;
        let back = self.power(node, top_bits as i32)?;
        let temp = self.allocate(1);
        self.push(Op::Zero, 0, 0);
        self.macs(
            &[Term {
                source: Source::Ram(limb),
                coefficient: up,
                cond: None,
            }],
            0,
        );
        self.push(Op::EmitTop, temp, 0);
        self.push(Op::Zero, 0, 0);
        let temp_value = Value {
            address: temp,
            limbs: 1,
            width: LIMB_BITS,
            frac: 0,
        };
        self.macs(
            &[Term {
                source: Source::Ram(temp_value),
                coefficient: back,
                cond: None,
            }],
            0,
        );
        self.push(Op::Drop, 0, 0);
        self.store(Op::EmitTop, top, index, 0);
        Ok(())
    }

    fn zero_into(&mut self, dest: Value) {
        self.materialize_into(&[], dest);
    }
}

fn term(source: Source, coefficient: Coefficient) -> Term {
    Term {
        source,
        coefficient,
        cond: None,
    }
}

fn when(cond: Cond, source: Source, coefficient: Coefficient) -> Term {
    Term {
        source,
        coefficient,
        cond: Some(cond),
    }
}

fn check_signed(node: &'static str, format: Format) -> Result<(), CompileError> {
    if format.signed {
        Ok(())
    } else {
        Err(CompileError::Unsigned {
            node,
            format: format.to_string(),
        })
    }
}

/// Largest data RAM and coefficient ROM the instruction word addresses.
pub const MAX_WORDS: usize = 1 << 12;

/// Where the chain's state lives in the data RAM: what every stage of the program reads.
struct State {
    /// The interval sums of gyro A and B.
    accumulator: [Value; 2],
    /// First address of each gyro's interval means.
    means: [u16; 2],
    /// log2 of the RAM stride between two intervals' means.
    ram_index_shift: u32,
    /// Limbs of one mean.
    mean_limbs: u32,
    /// The bias estimates of A and B.
    bias: [Value; 2],
    /// The KF's states x1 and x2.
    x: [Value; 2],
    /// RAM words of the state; scratch values go above them.
    state_words: usize,
}

impl State {
    /// Interval `k`'s mean of gyro `g`.
    fn mean(&self, g: usize, k: u32, format: Format) -> Value {
        Value {
            address: self.means[g] + (k << self.ram_index_shift) as u16,
            limbs: self.mean_limbs,
            width: format.width,
            frac: format.frac,
        }
    }
}

/// The chain of `plan` as the engine's program: the state cleared on the first sample since
/// reset, calibration and the combined rate, the KF, the interval sums and means, the
/// window's bias estimates, then the outputs. Each stage is a function below, in that order.
///
/// # Errors
/// [`CompileError`] for an unsigned format, a right alignment or a memory too large.
pub fn compile(plan: &Plan) -> Result<Program, CompileError> {
    let est = &plan.estimator;
    let kf = &plan.kf;
    check_formats(plan)?;
    let mut c = Compiler {
        input: est.input,
        overflow: est.overflow,
        code: Vec::new(),
        cond: Cond::Always,
        coefficients: Vec::new(),
        constants: BTreeMap::new(),
        ram_top: 0,
        ram_high: 0,
        bound: 0,
        bound_high: 0,
    };
    let state = c.allocate_state(plan);
    let (kf_gain, coefficient_index_shift) = c.kf_gains(kf);
    let z = c.calibrate_and_combine(est, &state)?;
    c.kf_step(kf, &state, z, &kf_gain)?;
    c.interval_means(est, &state)?;
    c.window(est, &state)?;
    c.outputs(&state);
    let sample = std::mem::take(&mut c.code);
    for (memory, words) in [
        ("data RAM", c.ram_high),
        ("coefficient ROM", c.coefficients.len()),
    ] {
        if words > MAX_WORDS {
            return Err(CompileError::TooLarge {
                memory,
                words,
                limit: MAX_WORDS,
            });
        }
    }
    let input_limbs = limbs_of(est.input.width);
    // The input limbs share the RAM address field.
    // One bit over the run-time indexes, which the RTL zero-extends to an address.
    let layout = Layout {
        address_bits: address_bits(c.ram_high.max(2 * input_limbs as usize))
            .max(address_bits(est.schedule.intervals) + 1),
        coefficient_bits: address_bits(c.coefficients.len().max(3))
            .max(address_bits(kf.rom.len()) + 1),
    };
    Ok(Program {
        sample,
        coefficients: c.coefficients,
        ram_words: c.ram_high,
        state_words: state.state_words,
        ram_index_shift: state.ram_index_shift,
        coefficient_index_shift,
        accumulator_bits: signed_bits(c.bound_high).max(17),
        input_limbs,
        rate_limbs: limbs_of(kf.output.width),
        bias_limbs: limbs_of(est.bias.width),
        output_widths: [kf.output.width, est.bias.width],
        rounding: est.rounding,
        overflow: est.overflow,
        layout,
    })
}

/// Every format the engine computes in is signed.
fn check_formats(plan: &Plan) -> Result<(), CompileError> {
    let est = &plan.estimator;
    let kf = &plan.kf;
    for (node, f) in [
        ("estimator.input_format", est.input),
        ("estimator.accumulator", est.accumulator),
        ("estimator.reciprocal", est.reciprocal),
        ("estimator.mean_format", est.mean),
        ("estimator.gain_format", est.gain),
        ("estimator.bias_format", est.bias),
        ("estimator.calibrated_format", est.calibrated),
        ("kf.state_format", kf.state),
        ("kf.output_format", kf.output),
        ("kf.g1", kf.coefficient[0]),
        ("kf.g2", kf.coefficient[1]),
    ] {
        check_signed(node, f)?;
    }
    Ok(())
}

impl Compiler {
    /// The state in the RAM (accumulators, means at a power-of-two stride per interval,
    /// biases, KF states), and the code that clears it on the first sample since reset (reset
    /// itself is instant).
    fn allocate_state(&mut self, plan: &Plan) -> State {
        let est = &plan.estimator;
        let kf = &plan.kf;
        let accumulator = [0, 1].map(|_| self.value(est.accumulator.width, est.input.frac));
        let mean_limbs = limbs_of(est.mean.width);
        let ram_index_shift = mean_limbs.next_power_of_two().trailing_zeros();
        let intervals = est.schedule.intervals as u32;
        let means = [0, 1].map(|_| self.allocate(intervals << ram_index_shift));
        let bias = [0, 1].map(|_| self.value(est.bias.width, est.bias.frac));
        let x = [0, 1].map(|_| self.value(kf.state.width, kf.state.frac));
        let state_words = self.ram_top;
        self.cond = Cond::Fresh;
        self.push(Op::Zero, 0, 0);
        for a in 0..state_words {
            self.push(Op::Emit, a as u16, 0);
        }
        self.cond = Cond::Always;
        State {
            accumulator,
            means,
            ram_index_shift,
            mean_limbs,
            bias,
            x,
            state_words,
        }
    }

    /// The KF's gains at the ROM's start, one region per ROM word (`bw_sel`'s stride a power
    /// of two; the constants follow), and log2 of that stride.
    fn kf_gains(&mut self, kf: &crate::kf::Plan) -> ([Coefficient; 2], u32) {
        let gain_limbs = [0, 1].map(|i| limbs_of(kf.coefficient[i].width));
        let region = (gain_limbs[0] + gain_limbs[1]).next_power_of_two();
        let mut kf_gain = [0, 1].map(|i| Coefficient {
            limbs: (0..gain_limbs[i])
                .map(|l| (l, (l + if i == 1 { gain_limbs[0] } else { 0 }) as u16, 0))
                .collect(),
            bound: 0,
            by_bw_sel: true,
        });
        self.coefficients = vec![0; kf.rom.len() * region as usize];
        for (w, word) in kf.rom.iter().enumerate() {
            for i in 0..2 {
                kf_gain[i].bound = kf_gain[i].bound.max(word[i].unsigned_abs());
                for l in 0..gain_limbs[i] {
                    // Split at the format's limb count: a small word's sign fills its top limbs.
                    let limb = limb_at(word[i], l, gain_limbs[i]);
                    let address =
                        w * region as usize + (l + if i == 1 { gain_limbs[0] } else { 0 }) as usize;
                    self.coefficients[address] = limb;
                    let slot = &mut kf_gain[i].limbs[l as usize];
                    slot.2 = slot.2.max(u128::from(limb.unsigned_abs()));
                }
            }
        }
        (kf_gain, region.trailing_zeros())
    }

    /// Calibration of each gyro with the estimates of earlier windows, then the combined rate
    /// (the mean of the valid ones): the KF's input `z`.
    fn calibrate_and_combine(
        &mut self,
        est: &crate::estimator::Plan,
        state: &State,
    ) -> Result<Value, CompileError> {
        let calibration_frac = est.input.frac.max(est.bias.frac);
        let mut out = Vec::new();
        for (g, bias_g) in state.bias.iter().enumerate() {
            let (positive, negative) = if g == 0 {
                (Cond::ModeA, Cond::NotModeA)
            } else {
                (Cond::ModeB, Cond::NotModeB)
            };
            let y_scale = self.power("calibration", calibration_frac - est.input.frac)?;
            let b_shift = calibration_frac - est.bias.frac;
            let b_minus = self.constant(-(1i128 << b_shift));
            let b_plus = self.power("calibration", b_shift)?;
            let corrected = self.materialize(
                &[
                    term(Source::Input(g), y_scale),
                    when(positive, Source::Ram(*bias_g), b_minus),
                    when(negative, Source::Ram(*bias_g), b_plus),
                ],
                calibration_frac,
            );
            let o = self.value(est.calibrated.width, est.calibrated.frac);
            self.quantize(
                "calibration",
                corrected,
                est.calibrated,
                o.address,
                RamIndex::None,
            )?;
            self.ram_top = o.address as usize + o.limbs as usize;
            out.push(o);
        }
        let z = self.value(est.calibrated.width, est.calibrated.frac);
        self.cond = Cond::AnyValid;
        let one = self.constant(1);
        let two = self.constant(2);
        let pair = self.materialize(
            &[
                when(Cond::BothValid, Source::Ram(out[0]), one.clone()),
                when(Cond::BothValid, Source::Ram(out[1]), one.clone()),
                when(Cond::OnlyA, Source::Ram(out[0]), two.clone()),
                when(Cond::OnlyB, Source::Ram(out[1]), two),
            ],
            est.calibrated.frac + 1,
        );
        self.quantize("combined", pair, est.calibrated, z.address, RamIndex::None)?;
        Ok(z)
    }

    /// The KF on `z`: e = z − x1 − x2; x_i = Q(x_i · 2^s_i + g_i · e); rate = Q(x1), sent
    /// out.
    fn kf_step(
        &mut self,
        kf: &crate::kf::Plan,
        state: &State,
        z: Value,
        kf_gain: &[Coefficient; 2],
    ) -> Result<(), CompileError> {
        let x = state.x;
        let z_scale = self.power("kf.e", kf.state.frac - kf.input.frac)?;
        let minus_one = self.constant(-1);
        let e = self.materialize(
            &[
                term(Source::Ram(z), z_scale),
                term(Source::Ram(x[0]), minus_one.clone()),
                term(Source::Ram(x[1]), minus_one),
            ],
            kf.state.frac,
        );
        for i in 0..2 {
            let mark = self.ram_top;
            let frac = kf.product[i].frac;
            let x_scale =
                self.power(if i == 0 { "kf.x1" } else { "kf.x2" }, frac - kf.state.frac)?;
            let sum = self.materialize(
                &[
                    term(Source::Ram(x[i]), x_scale),
                    term(Source::Ram(e), kf_gain[i].clone()),
                ],
                frac,
            );
            self.quantize("kf.state", sum, kf.state, x[i].address, RamIndex::None)?;
            self.ram_top = mark;
        }
        let rate = self.value(kf.output.width, kf.output.frac);
        self.quantize("kf.output", x[0], kf.output, rate.address, RamIndex::None)?;
        for l in 0..rate.limbs {
            self.push(Op::Out, rate.address + l as u16, OUTPUT_RATE);
        }
        self.ram_top = state.state_words;
        Ok(())
    }

    /// Each valid sample into its gyro's interval sum; at an interval's end its mean, stored
    /// at the interval's index, and the sum cleared.
    fn interval_means(
        &mut self,
        est: &crate::estimator::Plan,
        state: &State,
    ) -> Result<(), CompileError> {
        let reciprocal = self.constant(est.reciprocal_code);
        for g in 0..2 {
            let accumulator = state.accumulator[g];
            self.cond = if g == 0 { Cond::ValidA } else { Cond::ValidB };
            let one = self.constant(1);
            self.materialize_into(
                &[
                    term(Source::Ram(accumulator), one.clone()),
                    term(Source::Input(g), one),
                ],
                accumulator,
            );
            self.cond = if g == 0 { Cond::DoneA } else { Cond::DoneB };
            let scaled = self.materialize(
                &[term(Source::Ram(accumulator), reciprocal.clone())],
                est.input.frac + est.reciprocal.frac,
            );
            let index = if g == 0 {
                RamIndex::IntervalA
            } else {
                RamIndex::IntervalB
            };
            self.quantize("estimator.mean", scaled, est.mean, state.means[g], index)?;
            self.zero_into(accumulator);
            self.ram_top = state.state_words;
        }
        Ok(())
    }

    /// At a window's end: each bias b_new = Q(G m), smoothed after the first window, then the
    /// estimated flag.
    fn window(&mut self, est: &crate::estimator::Plan, state: &State) -> Result<(), CompileError> {
        self.cond = Cond::Window;
        for (g, &bias_g) in state.bias.iter().enumerate() {
            let mut terms = Vec::new();
            for (j, &gain) in est.rom[g].iter().enumerate() {
                if gain != 0 {
                    let coefficient = self.constant(gain);
                    terms.push(term(
                        Source::Ram(state.mean(j % 2, (j / 2) as u32, est.mean)),
                        coefficient,
                    ));
                }
            }
            let dot = self.materialize(&terms, est.dot.frac);
            if est.smoothing_shift == 0 {
                self.quantize(
                    "estimator.bias",
                    dot,
                    est.bias,
                    bias_g.address,
                    RamIndex::None,
                )?;
            } else {
                self.smoothed_bias(est, dot, bias_g)?;
            }
            self.ram_top = state.state_words;
        }
        self.push(Op::SetEstimated, 0, 0);
        Ok(())
    }

    /// The smoothed bias: the first window takes the new estimate Q(dot), later ones
    /// Q((2^s − 1)·b + new) at s more fraction bits.
    fn smoothed_bias(
        &mut self,
        est: &crate::estimator::Plan,
        dot: Value,
        bias_g: Value,
    ) -> Result<(), CompileError> {
        let s = est.smoothing_shift;
        let new = self.value(est.bias.width, est.bias.frac);
        self.quantize("estimator.bias", dot, est.bias, new.address, RamIndex::None)?;
        let keep = self.constant((1i128 << s) - 1);
        let one = self.constant(1);
        let smoothed = self.materialize(
            &[
                term(Source::Ram(bias_g), keep),
                term(Source::Ram(new), one.clone()),
            ],
            est.bias.frac + s as i32,
        );
        let t = self.value(est.bias.width, est.bias.frac);
        self.quantize(
            "estimator.smoothing",
            smoothed,
            est.bias,
            t.address,
            RamIndex::None,
        )?;
        self.materialize_into(&[term(Source::Ram(new), one.clone())], bias_g);
        self.cond = Cond::WindowEstimated;
        self.materialize_into(&[term(Source::Ram(t), one)], bias_g);
        self.cond = Cond::Window;
        Ok(())
    }

    /// The bias registers out at every sample, then the end of the program.
    fn outputs(&mut self, state: &State) {
        self.cond = Cond::Always;
        for (g, output) in [OUTPUT_BIAS_A, OUTPUT_BIAS_B].into_iter().enumerate() {
            for l in 0..state.bias[g].limbs {
                self.push(Op::Out, state.bias[g].address + l as u16, output);
            }
        }
        self.push(Op::End, 0, 0);
    }
}

/// Limb `l` of `value` split into exactly `limbs` limbs.
fn limb_at(value: i128, l: u32, limbs: u32) -> i16 {
    let shifted = value >> (LIMB_BITS * l);
    if l + 1 < limbs {
        (shifted & ((1 << LIMB_BITS) - 1)) as i16
    } else {
        shifted as i16
    }
}
