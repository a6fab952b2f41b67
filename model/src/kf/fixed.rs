//! [`FixedKf`]: the bit-accurate fixed-point steady-state KF.

use super::plan::Plan;
use crate::fx::{requantize, Quantizer};

/// The fixed-point KF: `e = z − x1 − x2` exact, `x_i ← Q(x_i + g_i·e)` into the state format,
/// `rate_hat = Q(x1)` into the output format, rounding and overflow as the plan declares.
///
/// Codes are `i64` at the ports (every declared format is at most 64 bits) and `i128` inside.
#[derive(Clone, Debug)]
pub struct FixedKf {
    rom: Vec<[i128; 2]>,
    /// `state.frac − input.frac`: aligns `z` to the state's fraction.
    z_shift: u32,
    /// `product_i.frac − state.frac`: aligns `x_i` to the product's fraction.
    x_shift: [u32; 2],
    state_quantizer: [Quantizer; 2],
    output_quantizer: Quantizer,
    x: [i128; 2],
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
        FixedKf {
            rom: plan.rom.clone(),
            z_shift: (plan.state.frac - plan.input.frac) as u32,
            x_shift: [
                (plan.product[0].frac - plan.state.frac) as u32,
                (plan.product[1].frac - plan.state.frac) as u32,
            ],
            state_quantizer: [
                q(plan.product[0].frac, plan.state),
                q(plan.product[1].frac, plan.state),
            ],
            output_quantizer: q(plan.state.frac, plan.output),
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
        let [g1, g2] = self.rom[bw_sel];
        let e = (i128::from(z) << self.z_shift) - self.x[0] - self.x[1];
        let s1 = (self.x[0] << self.x_shift[0]) + g1 * e;
        let s2 = (self.x[1] << self.x_shift[1]) + g2 * e;
        self.x[0] = self.state_quantizer[0].apply(s1);
        self.x[1] = self.state_quantizer[1].apply(s2);
        self.output_quantizer.apply(self.x[0]) as i64
    }

    /// Runs a block of samples at one `bw_sel`, writing `rate_hat` codes to `out`.
    ///
    /// # Panics
    /// When the slices differ in length or `bw_sel` addresses no ROM entry.
    pub fn process(&mut self, z: &[i64], bw_sel: usize, out: &mut [i64]) {
        assert_eq!(
            z.len(),
            out.len(),
            "input and output blocks differ in length"
        );
        for (zi, oi) in z.iter().zip(out.iter_mut()) {
            *oi = self.step(*zi, bw_sel);
        }
    }

    /// The state codes `[x1, x2]` (state format).
    pub fn state(&self) -> [i128; 2] {
        self.x
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
        let e = (i128::from(z) << self.z_shift) - self.x[0] - self.x[1];
        let s1 = (self.x[0] << self.x_shift[0]) + g1 * e;
        let s2 = (self.x[1] << self.x_shift[1]) + g2 * e;
        let q = &self.state_quantizer[0];
        let x1_next = requantize(s1, q.from_frac, q.to, q.rounding, q.overflow).code;
        [
            self.state_quantizer[0].is_tie(s1),
            self.state_quantizer[1].is_tie(s2),
            self.output_quantizer.is_tie(x1_next),
        ]
    }
}

impl FixedKf {
    /// Loads the state registers (state-format codes), e.g. to start a test from a known
    /// point.
    pub fn set_state(&mut self, x: [i128; 2]) {
        self.x = x;
    }
}
