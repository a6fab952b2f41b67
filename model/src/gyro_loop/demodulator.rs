//! I/Q demodulator: the ADC signal times the NCO's sine and cosine, each low-passed.
//!
//! # What it does
//!
//! Per sample, with `x` the ADC code and `(s, c)` the NCO references of the same sample:
//!
//! ```text
//! p_I = Q_p(2·x·s),  p_Q = Q_p(2·x·c)        product format (exact product, then rounded)
//! y  ← Q_y(y + (p − y)·2^−k)                  state format, per channel
//! I  = Q_o(y_I),     Q = Q_o(y_Q)             output format
//! ```
//!
//! For `x = a·sin(θ + φ)` and references `A_nco·sin θ`, `A_nco·cos θ`, the products are
//! `a·A_nco·(cos φ − cos(2θ + φ))` and `a·A_nco·(sin φ + sin(2θ + φ))`: after the low-pass,
//! `I = a·A_nco·cos φ` and `Q = a·A_nco·sin φ` (the factor 2 is a free reinterpretation of
//! the product's fraction bits). Units: those of `x` (fractions of the ADC full scale).
//!
//! The low-pass is a first-order leaky integrator, `H(z) = 2^−k / (1 − (1 − 2^−k) z^−1)`: one
//! shift and two adders per channel, DC gain exactly 1, −3 dB at about `fs · 2^−k / 2π`
//! (124 Hz for `k` = 8 at 200 kHz). It passes the `2θ` ripple at `2f` attenuated by about
//! `2f / (fs · 2^−k / 2π)`: 42 dB for 16.4 kHz at the defaults. That is enough for the PLL and
//! AGC, whose integrators average it further, and the sense channel's CIC removes it before
//! the rate output; a second section or a notch at `2f` would buy more where needed.
//!
//! # Quantization points
//!
//! | point | from (exact) | to | rounding | overflow |
//! |-------|--------------|----|----------|----------|
//! | `p` | `2·x·s`: `s (Wx+Wr).(Fx+Fr−1)` | `product` | config | config |
//! | `y` | `y + (p − y)·2^−k`: `s (Wy+k+1).(Fy+k)` | `state` | config | config (never: see below) |
//! | `I`, `Q` | `y`: `state` | `output` | config | config |
//!
//! The plan requires the state to hold every product (no fewer integer bits, no fewer
//! fraction bits): then `y + (p − y)·2^−k` lies between two state codes and no monotone
//! rounding leaves that interval, so the state never overflows.
//!
//! # Error bound
//!
//! The float twin ([`FloatDemodulator`]) runs `y ← y + (2xs − y)·2^−k` in f64 on the same input
//! codes. The product error `ε_p ≤ u_p·q_p` passes the low-pass at DC gain 1; the state's
//! rounding `u_y·q_y` per sample accumulates through `1/(1 − (1 − 2^−k)) = 2^k`; the output
//! rounds once more. So `|I_fixed − I_float| ≤ u_p q_p + 2^k u_y q_y + u_o q_o` (plus the f64
//! rounding of the twin), independent of the number of samples: [`Plan::error_bound_lsb`].
//! Valid while no product or output saturates or wraps.
//!
//! # Interface (RTL `hdl/gyrofx_demodulator.v`)
//!
//! | port | dir | format | meaning |
//! |------|-----|--------|---------|
//! | `clk`, `rst`, `ce` | in | 1 bit | clock, synchronous reset (clears both states), sample strobe |
//! | `adc` | in | `input` | ADC code, full-scale units |
//! | `ref_sin`, `ref_cos` | in | `reference` | NCO outputs of the same sample |
//! | `i_out`, `q_out` | out | `output` | `I`, `Q` after this sample |
//! | `out_valid` | out | 1 bit | high for one clock, 1 clock after `ce` |
//!
//! Latency: 1 clock.

use super::nco::Reference;
use super::{
    field_error, intermediate, mode_parameters, require_signed, PlanError, Point, RtlParameter,
};
use crate::fx::{mode, Format, Overflow, Quantizer, Rounding};

/// Largest low-pass shift `k`: −3 dB at `fs · 2^−24 / 2π`, 2 mHz at 200 kHz.
pub const MAX_LOWPASS_SHIFT: u32 = 24;

/// What a demodulator is asked to be.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Spec {
    /// ADC codes, fractions of full scale.
    pub input: Format,
    /// NCO sine and cosine.
    pub reference: Format,
    /// `2·x·ref` after quantization.
    pub product: Format,
    /// Low-pass state `y`: its fraction bits beyond the output's are guard bits (`k` + 2 keep
    /// the accumulated state rounding under a quarter output LSB).
    pub state: Format,
    /// `I` and `Q`.
    pub output: Format,
    /// `k`: the low-pass coefficient `2^−k`.
    pub lowpass_shift: u32,
    /// Rounding at every quantization point.
    pub rounding: Rounding,
    /// Overflow handling at every quantization point.
    pub overflow: Overflow,
}

impl Default for Spec {
    /// `s24.23` ADC, `s18.17` references, `s32.30` products (`|2xs| < 2`, 7 guard bits),
    /// `s40.38` state (15 guard bits), `s24.23` out, `k` = 8; nearest, saturate: within
    /// 0.51 output LSB of the float twin.
    fn default() -> Self {
        let f = |w, frac| Format::signed(w, frac).expect("valid");
        Spec {
            input: f(24, 23),
            reference: f(18, 17),
            product: f(32, 30),
            state: f(40, 38),
            output: f(24, 23),
            lowpass_shift: 8,
            rounding: Rounding::Nearest,
            overflow: Overflow::Saturate,
        }
    }
}

/// The resolved demodulator: formats and the three quantization points.
#[derive(Clone, Debug, PartialEq)]
pub struct Plan {
    /// ADC codes.
    pub input: Format,
    /// NCO references.
    pub reference: Format,
    /// `2·x·ref` exact → product format.
    pub product: Point,
    /// `y + (p − y)·2^−k` exact → state format.
    pub state: Point,
    /// `y` → output format.
    pub output: Point,
    /// `k`.
    pub lowpass_shift: u32,
}

impl Plan {
    /// Validates `spec` and derives the exact formats.
    ///
    /// # Errors
    /// [`PlanError::Field`] for an unsigned format, a state that cannot hold every product,
    /// a quantization point that would add fraction bits, `k` outside `1..=24`;
    /// [`PlanError::Intermediate`] beyond 128 bits.
    pub fn new(spec: &Spec) -> Result<Plan, PlanError> {
        const B: &str = "demodulator";
        require_signed(
            B,
            &[
                ("input_format", spec.input),
                ("reference_format", spec.reference),
                ("product_format", spec.product),
                ("state_format", spec.state),
                ("output_format", spec.output),
            ],
        )?;
        if !(1..=MAX_LOWPASS_SHIFT).contains(&spec.lowpass_shift) {
            return Err(field_error(
                B,
                "lowpass_shift",
                spec.lowpass_shift,
                format!("1..={MAX_LOWPASS_SHIFT}"),
            ));
        }
        if spec.state.frac < spec.product.frac || spec.state.int_bits() < spec.product.int_bits() {
            return Err(field_error(
                B,
                "state_format",
                spec.state,
                format!(
                    "at least the product's {} integer and {} fraction bits (product_format {})",
                    spec.product.int_bits(),
                    spec.product.frac,
                    spec.product
                ),
            ));
        }
        let exact_product = Format::intermediate(
            true,
            spec.input.width + spec.reference.width,
            spec.input.frac + spec.reference.frac - 1,
        )
        .map_err(intermediate(B, "2 * x * ref"))?;
        let k = spec.lowpass_shift;
        let y_aligned =
            Format::intermediate(true, spec.state.width + k, spec.state.frac + k as i32)
                .map_err(intermediate(B, "y aligned"))?;
        let difference =
            Format::intermediate(true, spec.state.width + 1, spec.state.frac + k as i32)
                .map_err(intermediate(B, "(p - y) * 2^-k"))?;
        let update = Format::sum(y_aligned, difference, false)
            .map_err(intermediate(B, "y + (p - y) * 2^-k"))?;
        let point = |field, from, to| Point::new(B, field, from, to, spec.rounding, spec.overflow);
        Ok(Plan {
            input: spec.input,
            reference: spec.reference,
            product: point("product_format", exact_product, spec.product)?,
            state: point("state_format", update, spec.state)?,
            output: point("output_format", spec.state, spec.output)?,
            lowpass_shift: k,
        })
    }

    /// Worst-case `|I_fixed − I_float|` (and for `Q`), in output LSB (see the module doc).
    pub fn error_bound_lsb(&self) -> f64 {
        let gain = crate::fx::pow2(self.lowpass_shift as i32);
        // |2·x·ref| <= 2 · |min x| · |min ref|: the largest product, and so state, magnitude.
        let largest = 2.0 * self.input.min_value().abs() * self.reference.min_value().abs();
        let product_error = self.product.max_error() + super::f64_rounding(largest);
        // The twin's update: a rounded difference (times an exact 2^-k) and a rounded sum.
        let twin_step = super::f64_rounding(2.0 * largest);
        let state_error = product_error + gain * (self.state.max_error() + twin_step);
        (state_error + self.output.max_error()) / self.output.to.lsb()
    }

    /// Parameters of `hdl/gyrofx_demodulator.v`.
    pub fn rtl_parameters(&self) -> Vec<RtlParameter> {
        let mut p = vec![
            ("ADC_W", i128::from(self.input.width)),
            ("ADC_F", i128::from(self.input.frac)),
            ("REF_W", i128::from(self.reference.width)),
            ("REF_F", i128::from(self.reference.frac)),
            ("PROD_W", i128::from(self.product.to.width)),
            ("PROD_F", i128::from(self.product.to.frac)),
            ("STATE_W", i128::from(self.state.to.width)),
            ("STATE_F", i128::from(self.state.to.frac)),
            ("OUT_W", i128::from(self.output.to.width)),
            ("OUT_F", i128::from(self.output.to.frac)),
            ("SHIFT", i128::from(self.lowpass_shift)),
        ];
        p.extend(mode_parameters(self.output.rounding, self.output.overflow));
        p
    }
}

/// One demodulator output: `I` and `Q` codes (output format).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Iq {
    /// In-phase (with the sine reference).
    pub i: i64,
    /// Quadrature (with the cosine reference).
    pub q: i64,
}

/// Overflow counts of the demodulator's quantization points, `[I, Q]` each.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct OverflowCounts {
    /// Products that did not fit the product format.
    pub product: [u64; 2],
    /// State updates that did not fit (never, by the plan).
    pub state: [u64; 2],
    /// States that did not fit the output format.
    pub output: [u64; 2],
}

/// The bit-accurate demodulator.
///
/// Two paths compute the same bits: [`FixedDemodulator::step_reference`] follows the
/// definition in `i128` with each point's own mode; [`FixedDemodulator::step`] is
/// monomorphized per rounding mode and runs in `i64` when every point shares one mode and
/// every exact intermediate fits 64 bits (the defaults do). A property test checks them
/// against each other.
#[derive(Clone, Debug)]
pub struct FixedDemodulator {
    product: [Quantizer; 2],
    state: [Quantizer; 2],
    output: [Quantizer; 2],
    /// `state.frac − product.frac`: aligns a product to the state.
    align: u32,
    k: u32,
    /// The shared rounding mode, when the 64-bit path applies.
    fast: Option<Rounding>,
    y: [i64; 2],
}

impl FixedDemodulator {
    /// The demodulator of `plan`, states at 0.
    pub fn new(plan: &Plan) -> Self {
        let pair = |p: &Point| [p.quantizer(), p.quantizer()];
        let shared = plan.product.rounding == plan.state.rounding
            && plan.state.rounding == plan.output.rounding;
        // x·ref and y·2^k + (p − y) fit 64 bits.
        let narrow = plan.product.from.width <= 64 && plan.state.from.width <= 64;
        FixedDemodulator {
            product: pair(&plan.product),
            state: pair(&plan.state),
            output: pair(&plan.output),
            align: (plan.state.to.frac - plan.product.to.frac) as u32,
            k: plan.lowpass_shift,
            fast: (shared && narrow).then_some(plan.output.rounding),
            y: [0, 0],
        }
    }

    /// Synchronous reset: both states to 0 (not the overflow counts).
    pub fn reset(&mut self) {
        self.y = [0, 0];
    }

    /// One sample: ADC code `x`, the NCO's references of the same sample; returns `I`, `Q`.
    #[inline]
    pub fn step(&mut self, x: i64, reference: Reference) -> Iq {
        match self.fast {
            Some(Rounding::Floor) => self.step_mode::<{ mode::FLOOR }>(x, reference),
            Some(Rounding::Ceil) => self.step_mode::<{ mode::CEIL }>(x, reference),
            Some(Rounding::Zero) => self.step_mode::<{ mode::ZERO }>(x, reference),
            Some(Rounding::Nearest) => self.step_mode::<{ mode::NEAREST }>(x, reference),
            Some(Rounding::Round) => self.step_mode::<{ mode::ROUND }>(x, reference),
            Some(Rounding::Convergent) => self.step_mode::<{ mode::CONVERGENT }>(x, reference),
            None => self.step_reference(x, reference),
        }
    }

    #[inline(always)]
    fn step_mode<const MODE: u8>(&mut self, x: i64, reference: Reference) -> Iq {
        Iq {
            i: self.channel::<MODE, 0>(x, reference.sin),
            q: self.channel::<MODE, 1>(x, reference.cos),
        }
    }

    /// Channel `C` (0: I, 1: Q) of [`Self::step_mode`], one call per channel so that both
    /// unroll into straight-line code.
    #[inline(always)]
    fn channel<const MODE: u8, const C: usize>(&mut self, x: i64, reference: i64) -> i64 {
        let p = self.product[C].apply_mode_i64::<MODE>(x * reference);
        let y = self.y[C];
        let y = self.state[C].apply_mode_i64::<MODE>((y << self.k) + ((p << self.align) - y));
        self.y[C] = y;
        self.output[C].apply_mode_i64::<MODE>(y)
    }

    /// One sample computed literally from the definition in `i128`, each point with its own
    /// mode: the reference the fast path is tested against, and the path for wide plans.
    pub fn step_reference(&mut self, x: i64, reference: Reference) -> Iq {
        let x = i128::from(x);
        let references = [reference.sin, reference.cos];
        let mut out = [0i64; 2];
        for c in 0..2 {
            let p = self.product[c].apply(x * i128::from(references[c]));
            let y = i128::from(self.y[c]);
            let update = (y << self.k) + ((p << self.align) - y);
            let y = self.state[c].apply(update);
            self.y[c] = y as i64;
            out[c] = self.output[c].apply(y) as i64;
        }
        Iq {
            i: out[0],
            q: out[1],
        }
    }

    /// Runs a block.
    ///
    /// # Panics
    /// When the slices differ in length.
    pub fn process(&mut self, x: &[i64], reference: &[Reference], out: &mut [Iq]) {
        assert!(
            x.len() == reference.len() && x.len() == out.len(),
            "input and output blocks differ in length"
        );
        for ((xi, r), o) in x.iter().zip(reference).zip(out.iter_mut()) {
            *o = self.step(*xi, *r);
        }
    }

    /// The state codes `[y_I, y_Q]` (state format).
    pub fn state(&self) -> [i64; 2] {
        self.y
    }

    /// Overflow counts since construction.
    pub fn overflow_counts(&self) -> OverflowCounts {
        let counts = |q: &[Quantizer; 2]| [q[0].overflow_count, q[1].overflow_count];
        OverflowCounts {
            product: counts(&self.product),
            state: counts(&self.state),
            output: counts(&self.output),
        }
    }
}

/// The float twin: `y ← y + (2·x·ref − y)·2^−k` in f64, per channel.
#[derive(Clone, Debug)]
pub struct FloatDemodulator {
    a: f64,
    y: [f64; 2],
}

impl FloatDemodulator {
    /// The twin of `plan`'s demodulator.
    pub fn new(plan: &Plan) -> Self {
        FloatDemodulator {
            a: crate::fx::pow2(-(plan.lowpass_shift as i32)),
            y: [0.0, 0.0],
        }
    }

    /// States to 0.
    pub fn reset(&mut self) {
        self.y = [0.0, 0.0];
    }

    /// One sample (reals: `x` in full-scale units, the references); returns `[I, Q]`.
    pub fn step(&mut self, x: f64, sin: f64, cos: f64) -> [f64; 2] {
        for (y, r) in self.y.iter_mut().zip([sin, cos]) {
            *y += (2.0 * x * r - *y) * self.a;
        }
        self.y
    }
}

#[cfg(test)]
mod tests;
