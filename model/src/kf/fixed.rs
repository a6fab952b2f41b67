//! [`FixedKf`]: the bit-accurate fixed-point steady-state KF.

use super::plan::Plan;
use crate::fx::{mode, requantize, round_right, Quantizer, Rounding};

/// The fixed-point KF: `e = z − x1 − x2` exact, `x_i ← Q(x_i + g_i·e)` into the state format,
/// `rate_hat = Q(x1)` into the output format, rounding and overflow as the plan declares.
///
/// Codes are `i64` at the ports and in the state (every declared format is at most 64 bits)
/// and `i128` for the exact intermediates.
///
/// Two paths compute the same bits: [`FixedKf::step_reference`] follows the definition
/// literally in `i128`; [`FixedKf::step`] / [`FixedKf::process`] are monomorphized per rounding
/// mode and, for plans whose intermediates allow it, keep the state recursion in 64 bits
/// (see `update`). A property test checks them against each other.
#[derive(Clone, Debug)]
pub struct FixedKf {
    rom: Vec<[i64; 2]>,
    /// `e` fits 64 bits and `x_i + Q(g_i·e)` fits 63 bits: the fast path applies.
    narrow: bool,
    /// `state.frac − input.frac`: aligns `z` to the state's fraction.
    z_shift: u32,
    /// `product_i.frac − state.frac`: the bits each state update drops.
    x_shift: [u32; 2],
    state_quantizer: [Quantizer; 2],
    output_quantizer: Quantizer,
    /// Range of the state format.
    state_min: i64,
    state_max: i64,
    x: [i64; 2],
}

/// Overflow counts of the three quantization points of the KF.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct OverflowCounts {
    /// Values of `x1 + g1·e` that did not fit the state format.
    pub x1: u64,
    /// Values of `x2 + g2·e` that did not fit the state format.
    pub x2: u64,
    /// Values of `x1` that did not fit the output format.
    pub rate_hat: u64,
}

impl FixedKf {
    /// Builds the model from a plan (which has validated every format), in the reset state.
    pub fn new(plan: &Plan) -> Self {
        let q = |from_frac, to| Quantizer::new(from_frac, to, plan.rounding, plan.overflow);
        let x_shift = [
            (plan.product[0].frac - plan.state.frac) as u32,
            (plan.product[1].frac - plan.state.frac) as u32,
        ];
        // After dropping x_shift bits the sum has sum.width - x_shift bits.
        let narrow = plan.error.width <= 64
            && (0..2).all(|i| plan.sum[i].width - x_shift[i] <= 63 && x_shift[i] >= 1);
        FixedKf {
            rom: plan
                .rom
                .iter()
                .map(|c| [c[0] as i64, c[1] as i64])
                .collect(),
            narrow,
            z_shift: (plan.state.frac - plan.input.frac) as u32,
            x_shift,
            state_quantizer: [
                q(plan.product[0].frac, plan.state),
                q(plan.product[1].frac, plan.state),
            ],
            output_quantizer: q(plan.state.frac, plan.output),
            state_min: plan.state.min_code() as i64,
            state_max: plan.state.max_code() as i64,
            x: [0, 0],
        }
    }

    /// Synchronous reset: clears the state (not the overflow counts).
    pub fn reset(&mut self) {
        self.x = [0, 0];
    }

    /// One sample: input code `z` (input format), ROM address `bw_sel`; returns the
    /// `rate_hat` code (output format).
    ///
    /// # Panics
    /// When `bw_sel` addresses no ROM entry.
    #[inline]
    pub fn step(&mut self, z: i64, bw_sel: usize) -> i64 {
        match self.output_quantizer.rounding {
            Rounding::Floor => self.step_mode::<{ mode::FLOOR }>(z, bw_sel),
            Rounding::Ceil => self.step_mode::<{ mode::CEIL }>(z, bw_sel),
            Rounding::Zero => self.step_mode::<{ mode::ZERO }>(z, bw_sel),
            Rounding::Nearest => self.step_mode::<{ mode::NEAREST }>(z, bw_sel),
            Rounding::Round => self.step_mode::<{ mode::ROUND }>(z, bw_sel),
            Rounding::Convergent => self.step_mode::<{ mode::CONVERGENT }>(z, bw_sel),
        }
    }

    /// Runs a block of samples at one `bw_sel`, writing `rate_hat` codes to `out`.
    ///
    /// # Panics
    /// When the slices differ in length or `bw_sel` addresses no ROM entry.
    pub fn process(&mut self, z: &[i64], bw_sel: usize, out: &mut [i64]) {
        match self.output_quantizer.rounding {
            Rounding::Floor => self.process_mode::<{ mode::FLOOR }>(z, bw_sel, out),
            Rounding::Ceil => self.process_mode::<{ mode::CEIL }>(z, bw_sel, out),
            Rounding::Zero => self.process_mode::<{ mode::ZERO }>(z, bw_sel, out),
            Rounding::Nearest => self.process_mode::<{ mode::NEAREST }>(z, bw_sel, out),
            Rounding::Round => self.process_mode::<{ mode::ROUND }>(z, bw_sel, out),
            Rounding::Convergent => self.process_mode::<{ mode::CONVERGENT }>(z, bw_sel, out),
        }
    }

    fn process_mode<const MODE: u8>(&mut self, z: &[i64], bw_sel: usize, out: &mut [i64]) {
        assert_eq!(
            z.len(),
            out.len(),
            "input and output blocks differ in length"
        );
        for (zi, oi) in z.iter().zip(out.iter_mut()) {
            *oi = self.step_mode::<MODE>(*zi, bw_sel);
        }
    }

    /// One sample with the rounding mode fixed at compile time (the plan's mode).
    #[inline(always)]
    pub(crate) fn step_mode<const MODE: u8>(&mut self, z: i64, bw_sel: usize) -> i64 {
        if !self.narrow {
            return self.step_reference(z, bw_sel);
        }
        let [g1, g2] = self.rom[bw_sel];
        let [x1, x2] = self.x;
        // Exact: the plan's error format is at most 64 bits wide.
        let e = i128::from((z << self.z_shift) - x1 - x2);
        let x1 = self.update::<MODE>(0, x1, i128::from(g1) * e);
        let x2 = self.update::<MODE>(1, x2, i128::from(g2) * e);
        self.x = [x1, x2];
        self.output_quantizer.apply_mode_i64::<MODE>(x1)
    }

    /// `Q(x·2^s + p)` into the state format. For floor, ceil and nearest, adding a multiple of
    /// `2^s` commutes with the rounding, so this is `x + Q(p)`: the state recursion stays in 64
    /// bits. Toward-zero, half-away and half-even look at the sum's sign or parity and take
    /// the general path.
    #[inline(always)]
    fn update<const MODE: u8>(&mut self, i: usize, x: i64, product: i128) -> i64 {
        let shift = self.x_shift[i];
        match MODE {
            mode::FLOOR | mode::CEIL | mode::NEAREST => {
                // Fits 63 bits by the plan (`narrow`), so the sum cannot overflow i64.
                let sum = x + round_right::<MODE>(product, shift) as i64;
                if sum >= self.state_min && sum <= self.state_max {
                    sum
                } else {
                    self.state_quantizer[i].apply_mode::<MODE>((i128::from(x) << shift) + product)
                        as i64
                }
            }
            _ => self.state_quantizer[i].apply_mode::<MODE>((i128::from(x) << shift) + product)
                as i64,
        }
    }

    /// One sample computed literally from the definition in `i128`: the reference the fast
    /// path is tested against, and the path for plans too wide for it.
    pub fn step_reference(&mut self, z: i64, bw_sel: usize) -> i64 {
        let [g1, g2] = self.rom[bw_sel];
        let [x1, x2] = [i128::from(self.x[0]), i128::from(self.x[1])];
        let e = (i128::from(z) << self.z_shift) - x1 - x2;
        let s1 = (x1 << self.x_shift[0]) + i128::from(g1) * e;
        let s2 = (x2 << self.x_shift[1]) + i128::from(g2) * e;
        let x1 = self.state_quantizer[0].apply(s1);
        let x2 = self.state_quantizer[1].apply(s2);
        self.x = [x1 as i64, x2 as i64];
        self.output_quantizer.apply(x1) as i64
    }

    /// The state codes `[x1, x2]` (state format).
    pub fn state(&self) -> [i128; 2] {
        [i128::from(self.x[0]), i128::from(self.x[1])]
    }

    /// Loads the state registers (state-format codes), e.g. to start a test from a known
    /// point.
    ///
    /// # Panics
    /// When a code does not fit 64 bits.
    pub fn set_state(&mut self, x: [i128; 2]) {
        self.x = [
            i64::try_from(x[0]).expect("state codes fit 64 bits"),
            i64::try_from(x[1]).expect("state codes fit 64 bits"),
        ];
    }

    /// Overflow counts since construction.
    pub fn overflow_counts(&self) -> OverflowCounts {
        OverflowCounts {
            x1: self.state_quantizer[0].overflow_count,
            x2: self.state_quantizer[1].overflow_count,
            rate_hat: self.output_quantizer.overflow_count,
        }
    }

    /// Which of the three quantization points (`x1`, `x2`, `rate_hat`) the sample `z` at
    /// `bw_sel` would put exactly on a rounding tie (half an LSB), from the current state,
    /// without changing it: used to build tie-case vectors.
    pub fn ties(&self, z: i64, bw_sel: usize) -> [bool; 3] {
        let [g1, g2] = self.rom[bw_sel];
        let [x1, x2] = self.state();
        let e = (i128::from(z) << self.z_shift) - x1 - x2;
        let s1 = (x1 << self.x_shift[0]) + i128::from(g1) * e;
        let s2 = (x2 << self.x_shift[1]) + i128::from(g2) * e;
        let q = &self.state_quantizer[0];
        let x1_next = requantize(s1, q.from_frac, q.to, q.rounding, q.overflow).code;
        [
            self.state_quantizer[0].is_tie(s1),
            self.state_quantizer[1].is_tie(s2),
            self.output_quantizer.is_tie(x1_next),
        ]
    }
}
