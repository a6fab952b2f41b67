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

    /// `Q(v)` into `to` at `dest` (RAM address, plus the run-time `index`).
    fn quantize(
        &mut self,
        node: &'static str,
        v: Value,
        to: Format,
        dest: u16,
        index: RamIndex,
    ) -> Result<(), CompileError> {
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
        let kd = limbs_of(to.width);
        let mark = self.ram_top;
        // The sign picks the rounding (toward zero, half away) and the clamp.
        self.push(Op::Sign, v.address + v.limbs as u16 - 1, 0);
        // Pass 1: the rounded quotient.
        let direct = quotient_width <= to.width;
        let (kq, q_address, q_index) = if direct {
            (kd, dest, index)
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
        if direct {
            self.ram_top = mark;
            return Ok(());
        }
        let quotient = Value {
            address: q_address,
            limbs: kq,
            width: quotient_width,
            frac: to.frac,
        };
        let copy = [Term {
            source: Source::Ram(quotient),
            coefficient: self.constant(1),
            cond: None,
        }];
        let top_bits = to.width - LIMB_BITS * (kd - 1);
        match self.overflow {
            Overflow::Saturate => {
                // Pass 2: does the quotient fit `to.width` bits?
                let u = (LIMB_BITS - (to.width - 1) % LIMB_BITS) % LIMB_BITS;
                let m2 = (to.width - 1 + u) / LIMB_BITS;
                let columns = (quotient_width + u).div_ceil(LIMB_BITS);
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
                // Pass 3: the low limbs, or the clamp.
                let largest_top = self.constant_limb(((1i32 << (top_bits - 1)) - 1) as i16);
                self.push(Op::Zero, 0, 0);
                for c in 0..kd {
                    self.macs(&copy, c);
                    if c + 1 < kd {
                        self.store(Op::StoreLow, dest + c as u16, index, 0);
                    } else {
                        self.store(Op::StoreTop, dest + c as u16, index, largest_top);
                    }
                }
            }
            Overflow::Wrap => {
                self.push(Op::Zero, 0, 0);
                for c in 0..kd - 1 {
                    self.macs(&copy, c);
                    self.store(Op::Emit, dest + c as u16, index, 0);
                }
                let top = dest + kd as u16 - 1;
                if top_bits == LIMB_BITS {
                    self.macs(&copy, kd - 1);
                    self.store(Op::EmitTop, top, index, 0);
                } else {
                    // sext(limb mod 2^b) = ((limb · 2^(15−b)) as 15-bit signed) · 2^b / 2^15.
                    let limb = Value {
                        address: q_address + kd as u16 - 1,
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
                }
            }
        }
        self.ram_top = mark;
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

/// The chain of `plan` as the engine's program.
///
/// # Errors
/// [`CompileError`] for an unsigned format, a right alignment or a memory too large.
pub fn compile(plan: &Plan) -> Result<Program, CompileError> {
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

    // State: accumulators, means (a power-of-two stride per interval), biases, KF states.
    let accumulator = [0, 1].map(|_| c.value(est.accumulator.width, est.input.frac));
    let mean_limbs = limbs_of(est.mean.width);
    let ram_index_shift = mean_limbs.next_power_of_two().trailing_zeros();
    let intervals = est.schedule.intervals as u32;
    let means = [0, 1].map(|_| c.allocate(intervals << ram_index_shift));
    let mean_value = |g: usize, k: u32| Value {
        address: means[g] + (k << ram_index_shift) as u16,
        limbs: mean_limbs,
        width: est.mean.width,
        frac: est.mean.frac,
    };
    let bias = [0, 1].map(|_| c.value(est.bias.width, est.bias.frac));
    let x = [0, 1].map(|_| c.value(kf.state.width, kf.state.frac));
    let state_words = c.ram_top;
    // The first sample since reset clears the state first: reset itself is instant.
    c.cond = Cond::Fresh;
    c.push(Op::Zero, 0, 0);
    for a in 0..state_words {
        c.push(Op::Emit, a as u16, 0);
    }
    c.cond = Cond::Always;

    // The KF's gains: one region per ROM word, bw_sel's stride a power of two.
    let gain_limbs = [0, 1].map(|i| limbs_of(kf.coefficient[i].width));
    let region = (gain_limbs[0] + gain_limbs[1]).next_power_of_two();
    let coefficient_index_shift = region.trailing_zeros();
    // The gains first, at the ROM's start; the constants follow.
    let mut kf_gain = [0, 1].map(|i| Coefficient {
        limbs: (0..gain_limbs[i])
            .map(|l| (l, (l + if i == 1 { gain_limbs[0] } else { 0 }) as u16, 0))
            .collect(),
        bound: 0,
        by_bw_sel: true,
    });
    c.coefficients = vec![0; kf.rom.len() * region as usize];
    for (w, word) in kf.rom.iter().enumerate() {
        for i in 0..2 {
            kf_gain[i].bound = kf_gain[i].bound.max(word[i].unsigned_abs());
            for l in 0..gain_limbs[i] {
                // Split at the format's limb count: a small word's sign fills its top limbs.
                let limb = limb_at(word[i], l, gain_limbs[i]);
                let address =
                    w * region as usize + (l + if i == 1 { gain_limbs[0] } else { 0 }) as usize;
                c.coefficients[address] = limb;
                let slot = &mut kf_gain[i].limbs[l as usize];
                slot.2 = slot.2.max(u128::from(limb.unsigned_abs()));
            }
        }
    }

    // Calibration with the estimates of earlier windows.
    let calibration_frac = est.input.frac.max(est.bias.frac);
    let mut out = Vec::new();
    for (g, bias_g) in bias.iter().enumerate() {
        let (positive, negative) = if g == 0 {
            (Cond::ModeA, Cond::NotModeA)
        } else {
            (Cond::ModeB, Cond::NotModeB)
        };
        let y_scale = c.power("calibration", calibration_frac - est.input.frac)?;
        let b_shift = calibration_frac - est.bias.frac;
        let b_minus = c.constant(-(1i128 << b_shift));
        let b_plus = c.power("calibration", b_shift)?;
        let corrected = c.materialize(
            &[
                term(Source::Input(g), y_scale),
                when(positive, Source::Ram(*bias_g), b_minus),
                when(negative, Source::Ram(*bias_g), b_plus),
            ],
            calibration_frac,
        );
        let o = c.value(est.calibrated.width, est.calibrated.frac);
        c.quantize(
            "calibration",
            corrected,
            est.calibrated,
            o.address,
            RamIndex::None,
        )?;
        c.ram_top = o.address as usize + o.limbs as usize;
        out.push(o);
    }
    let z = c.value(est.calibrated.width, est.calibrated.frac);
    c.cond = Cond::AnyValid;
    let one = c.constant(1);
    let two = c.constant(2);
    let pair = c.materialize(
        &[
            when(Cond::BothValid, Source::Ram(out[0]), one.clone()),
            when(Cond::BothValid, Source::Ram(out[1]), one.clone()),
            when(Cond::OnlyA, Source::Ram(out[0]), two.clone()),
            when(Cond::OnlyB, Source::Ram(out[1]), two),
        ],
        est.calibrated.frac + 1,
    );
    c.quantize("combined", pair, est.calibrated, z.address, RamIndex::None)?;

    // KF: e = z − x1 − x2; x_i = Q(x_i · 2^s_i + g_i · e); rate = Q(x1).
    let z_scale = c.power("kf.e", kf.state.frac - kf.input.frac)?;
    let minus_one = c.constant(-1);
    let e = c.materialize(
        &[
            term(Source::Ram(z), z_scale),
            term(Source::Ram(x[0]), minus_one.clone()),
            term(Source::Ram(x[1]), minus_one),
        ],
        kf.state.frac,
    );
    for i in 0..2 {
        let mark = c.ram_top;
        let frac = kf.product[i].frac;
        let x_scale = c.power(if i == 0 { "kf.x1" } else { "kf.x2" }, frac - kf.state.frac)?;
        let sum = c.materialize(
            &[
                term(Source::Ram(x[i]), x_scale),
                term(Source::Ram(e), kf_gain[i].clone()),
            ],
            frac,
        );
        c.quantize("kf.state", sum, kf.state, x[i].address, RamIndex::None)?;
        c.ram_top = mark;
    }
    let rate = c.value(kf.output.width, kf.output.frac);
    c.quantize("kf.output", x[0], kf.output, rate.address, RamIndex::None)?;
    for l in 0..rate.limbs {
        c.push(Op::Out, rate.address + l as u16, OUTPUT_RATE);
    }
    c.ram_top = state_words;

    // Interval sums and means.
    let reciprocal = c.constant(est.reciprocal_code);
    for g in 0..2 {
        c.cond = if g == 0 { Cond::ValidA } else { Cond::ValidB };
        let one = c.constant(1);
        c.materialize_into(
            &[
                term(Source::Ram(accumulator[g]), one.clone()),
                term(Source::Input(g), one),
            ],
            accumulator[g],
        );
        c.cond = if g == 0 { Cond::DoneA } else { Cond::DoneB };
        let scaled = c.materialize(
            &[term(Source::Ram(accumulator[g]), reciprocal.clone())],
            est.input.frac + est.reciprocal.frac,
        );
        let index = if g == 0 {
            RamIndex::IntervalA
        } else {
            RamIndex::IntervalB
        };
        c.quantize("estimator.mean", scaled, est.mean, means[g], index)?;
        c.zero_into(accumulator[g]);
        c.ram_top = state_words;
    }

    // Window: b_new = Q(G m), smoothed after the first window.
    c.cond = Cond::Window;
    for (g, &bias_g) in bias.iter().enumerate() {
        let mut terms = Vec::new();
        for (j, &gain) in est.rom[g].iter().enumerate() {
            if gain != 0 {
                let coefficient = c.constant(gain);
                terms.push(term(
                    Source::Ram(mean_value(j % 2, (j / 2) as u32)),
                    coefficient,
                ));
            }
        }
        let dot = c.materialize(&terms, est.dot.frac);
        if est.smoothing_shift == 0 {
            c.quantize(
                "estimator.bias",
                dot,
                est.bias,
                bias_g.address,
                RamIndex::None,
            )?;
        } else {
            let s = est.smoothing_shift;
            let new = c.value(est.bias.width, est.bias.frac);
            c.quantize("estimator.bias", dot, est.bias, new.address, RamIndex::None)?;
            let keep = c.constant((1i128 << s) - 1);
            let one = c.constant(1);
            let smoothed = c.materialize(
                &[
                    term(Source::Ram(bias_g), keep),
                    term(Source::Ram(new), one.clone()),
                ],
                est.bias.frac + s as i32,
            );
            let t = c.value(est.bias.width, est.bias.frac);
            c.quantize(
                "estimator.smoothing",
                smoothed,
                est.bias,
                t.address,
                RamIndex::None,
            )?;
            // The first window takes the new estimate, later ones the smoothed one.
            c.materialize_into(&[term(Source::Ram(new), one.clone())], bias_g);
            c.cond = Cond::WindowEstimated;
            c.materialize_into(&[term(Source::Ram(t), one)], bias_g);
            c.cond = Cond::Window;
        }
        c.ram_top = state_words;
    }
    c.push(Op::SetEstimated, 0, 0);
    c.cond = Cond::Always;
    for (g, output) in [OUTPUT_BIAS_A, OUTPUT_BIAS_B].into_iter().enumerate() {
        for l in 0..bias[g].limbs {
            c.push(Op::Out, bias[g].address + l as u16, output);
        }
    }
    c.push(Op::End, 0, 0);
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
        state_words,
        ram_index_shift,
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

/// Limb `l` of `value` split into exactly `limbs` limbs.
fn limb_at(value: i128, l: u32, limbs: u32) -> i16 {
    let shifted = value >> (LIMB_BITS * l);
    if l + 1 < limbs {
        (shifted & ((1 << LIMB_BITS) - 1)) as i16
    } else {
        shifted as i16
    }
}
