//! PI controller with a clamped integrator (anti-windup) and a preset: the loop's PLL (phase
//! error in, NCO frequency word out) and AGC (amplitude error in, drive amplitude out).
//!
//! # What it does
//!
//! Per sample, with `e` the error input:
//!
//! ```text
//! v = clamp(Q_v(v + ki·e), v_min, v_max)     integrator format; the clamp is the anti-windup
//! u = Q_u(kp·e + v)                          output format
//! ```
//!
//! The output uses the integrator *after* this sample's update, so `u = kp·e + ki·Σe` with no
//! extra delay. `preset(v0)` loads `clamp(v0)` into the integrator: on a mode switch the PLL's
//! integrator is preset to the other mode's nominal frequency word. In the RTL a `preset`
//! strobe in the clock of a `ce` loads the integrator before that sample's update (the
//! model's `preset` then `step`); without `ce` it only loads it.
//!
//! For the PLL the output format `s P.P` (cycles per sample) is the NCO's frequency word: its
//! bits, read as unsigned, are the same frequency mod `fs`.
//!
//! # Quantization points
//!
//! | point | from (exact) | to | rounding | overflow |
//! |-------|--------------|----|----------|----------|
//! | `kp`, `ki` (offline) | f64 | coefficient formats | convergent | refused if they do not fit |
//! | `v` | `v + ki·e` | integrator format | config | clamped to `[v_min, v_max]` (the limits lie inside the format, so it never wraps) |
//! | `u` | `kp·e + v` | output format | config | config |
//!
//! When the integrator has at least the fraction bits of `ki·e` (`Fv ≥ Fki + Fe`) its update
//! is exact: [`Plan::integrator_is_exact`].
//!
//! # Error bound
//!
//! The float twin ([`FloatPi`]) runs the same recursion in f64 with the quantized gains and
//! limits. The integrator's rounding error `u_v·q_v` per sample is not forgotten (an
//! integrator has no leak) and the clamp does not enlarge a difference, so after `n` samples
//! since the last reset or preset `|u_fixed − u_float| ≤ n·u_v·q_v + u_u·q_u` (plus the
//! twin's f64 rounding): [`Plan::error_bound_lsb`]. An exact integrator leaves the output
//! rounding alone. Valid while the output does not saturate or wrap.
//!
//! # Interface (RTL `hdl/gyrofx_pi.v`)
//!
//! | port | dir | format | meaning |
//! |------|-----|--------|---------|
//! | `clk`, `rst`, `ce` | in | 1 bit | clock, synchronous reset (integrator to 0), sample strobe |
//! | `err` | in | `input` | error `e` |
//! | `preset` | in | 1 bit | load `clamp(preset_value)` into the integrator |
//! | `preset_value` | in | `integrator` | the value to load |
//! | `u_out` | out | `output` | `u` of the sample taken at the last `ce` |
//! | `out_valid` | out | 1 bit | high for one clock, 1 clock after `ce` |
//!
//! Latency: 1 clock. `kp`, `ki` and the limits are parameters (codes).

use super::{
    field_error, intermediate, mode_parameters, quantize_coefficients, require_signed, Coefficient,
    PlanError, Point, RtlParameter,
};
use crate::fx::{from_f64, mode, CoefficientFormat, Format, Overflow, Quantizer, Rounding};

/// What a PI controller is asked to be.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Spec {
    /// Error input `e`.
    pub input: Format,
    /// Proportional gain (output units per input unit).
    pub kp: f64,
    /// Integral gain (output units per input unit per sample).
    pub ki: f64,
    /// Format rule of `kp`.
    pub kp_format: CoefficientFormat,
    /// Format rule of `ki`.
    pub ki_format: CoefficientFormat,
    /// Integrator `v`, output units.
    pub integrator: Format,
    /// `[v_min, v_max]`, output units: the integrator's anti-windup limits.
    pub integrator_limits: [f64; 2],
    /// Output `u`.
    pub output: Format,
    /// Rounding at the integrator and the output.
    pub rounding: Rounding,
    /// Overflow handling at the output.
    pub overflow: Overflow,
}

impl Default for Spec {
    /// A PLL at 200 kHz: phase error `s24.23` (full scale) in, frequency word `s32.32`
    /// (cycles per sample) out, `kp` = 2^−10, `ki` = 2^−18 (18-bit gains), an `s59.57`
    /// integrator limited to 7–10 kHz (0.035–0.05 cycles per sample); nearest, saturate. The
    /// integrator keeps every bit of `ki·e` (57 fraction bits), so the fixed PLL stays within
    /// half an output LSB of the float one however long it runs.
    fn default() -> Self {
        let f = |w, frac| Format::signed(w, frac).expect("valid");
        Spec {
            input: f(24, 23),
            kp: 1.0 / 1024.0,
            ki: 1.0 / 262_144.0,
            kp_format: CoefficientFormat::Auto { width: 18 },
            ki_format: CoefficientFormat::Auto { width: 18 },
            integrator: f(59, 57),
            integrator_limits: [0.035, 0.05],
            output: f(32, 32),
            rounding: Rounding::Nearest,
            overflow: Overflow::Saturate,
        }
    }
}

/// The resolved PI controller.
#[derive(Clone, Debug, PartialEq)]
pub struct Plan {
    /// Error input.
    pub input: Format,
    /// Quantized `kp`.
    pub kp: Coefficient,
    /// Quantized `ki`.
    pub ki: Coefficient,
    /// Integrator format.
    pub integrator: Format,
    /// `v + ki·e` exact → the integrator's fraction, in a format wide enough that only the
    /// clamp limits the range (its overflow mode never acts).
    pub integrator_point: Point,
    /// `[v_min, v_max]` codes (integrator format).
    pub limits: [i128; 2],
    /// `kp·e + v` exact → output format.
    pub output: Point,
}

impl Plan {
    /// Validates `spec`, quantizes the gains and limits, derives the exact formats.
    ///
    /// # Errors
    /// [`PlanError::CoefficientOverflow`] / [`PlanError::CoefficientZero`] for a gain that
    /// does not fit its format; [`PlanError::Field`] for unsigned formats, limits that are not
    /// ordered or leave the integrator format, an output with more fraction bits than
    /// `kp·e + v`; [`PlanError::Intermediate`] beyond 128 bits.
    pub fn new(spec: &Spec) -> Result<Plan, PlanError> {
        const B: &str = "pi";
        require_signed(
            B,
            &[
                ("input_format", spec.input),
                ("integrator_format", spec.integrator),
                ("output_format", spec.output),
            ],
        )?;
        let kp = quantize_coefficients(B, "kp", &[spec.kp], spec.kp_format)?[0];
        let ki = quantize_coefficients(B, "ki", &[spec.ki], spec.ki_format)?[0];
        let [low, high] = spec.integrator_limits;
        let limit = |value: f64| {
            from_f64(
                value,
                spec.integrator,
                Rounding::Convergent,
                Overflow::Saturate,
            )
            .ok()
            .filter(|q| !q.overflowed)
            .map(|q| q.code)
        };
        let limits = match (limit(low), limit(high)) {
            (Some(lo), Some(hi)) if lo <= hi => [lo, hi],
            _ => {
                return Err(field_error(
                    B,
                    "integrator_limits",
                    format!("[{low}, {high}]"),
                    format!(
                        "min <= max, both within the integrator format {} ({} to {})",
                        spec.integrator,
                        spec.integrator.min_value(),
                        spec.integrator.max_value()
                    ),
                ))
            }
        };
        let ki_e = Format::product(ki.format, spec.input).map_err(intermediate(B, "ki * e"))?;
        let update =
            Format::sum(spec.integrator, ki_e, false).map_err(intermediate(B, "v + ki * e"))?;
        // The rounded update, before the clamp: one bit more than the exact sum's integer part
        // holds any rounding-up.
        let rounded = Format::intermediate(
            true,
            (update.int_bits() + 1 + spec.integrator.frac).max(1) as u32,
            spec.integrator.frac,
        )
        .map_err(intermediate(B, "v rounded"))?;
        let integrator_point = Point::new(
            B,
            "integrator_format",
            update,
            rounded,
            spec.rounding,
            Overflow::Wrap,
        )?;
        let kp_e = Format::product(kp.format, spec.input).map_err(intermediate(B, "kp * e"))?;
        let sum =
            Format::sum(kp_e, spec.integrator, false).map_err(intermediate(B, "kp * e + v"))?;
        let output = Point::new(
            B,
            "output_format",
            sum,
            spec.output,
            spec.rounding,
            spec.overflow,
        )?;
        Ok(Plan {
            input: spec.input,
            kp,
            ki,
            integrator: spec.integrator,
            integrator_point,
            limits,
            output,
        })
    }

    /// Whether `v + ki·e` needs no rounding (the integrator has the fraction bits of `ki·e`).
    pub fn integrator_is_exact(&self) -> bool {
        self.integrator_point.from.frac == self.integrator_point.to.frac
    }

    /// The integrator code of `value` (output units), rounded to nearest (ties to even) and
    /// clamped to the limits: what [`FixedPi::preset`] and the RTL's `preset_value` take.
    ///
    /// # Errors
    /// [`PlanError::Field`] when `value` is not finite.
    pub fn integrator_code(&self, value: f64) -> Result<i64, PlanError> {
        let q = from_f64(
            value,
            self.integrator,
            Rounding::Convergent,
            Overflow::Saturate,
        )
        .map_err(|_| field_error("pi", "preset", value, "a finite number"))?;
        Ok(q.code.clamp(self.limits[0], self.limits[1]) as i64)
    }

    /// `[v_min, v_max]` as quantized, output units.
    pub fn limit_values(&self) -> [f64; 2] {
        self.limits.map(|c| self.integrator.to_f64(c))
    }

    /// Worst-case `|u_fixed − u_float|`, in output LSB, `samples` samples after a reset or a
    /// preset (see the module doc).
    pub fn error_bound_lsb(&self, samples: u64) -> f64 {
        let e_max = self.input.min_value().abs();
        let ki_e = self.ki.quantized().abs() * e_max;
        let kp_e = self.kp.quantized().abs() * e_max;
        let [lo, hi] = self.limit_values();
        let v_max = lo.abs().max(hi.abs());
        let rounding = if self.integrator_is_exact() {
            0.0
        } else {
            self.integrator_point.max_error()
        };
        // The twin rounds ki·e (if over 53 bits) and v + ki·e; then kp·e and kp·e + v.
        let integrator_step = rounding + super::f64_rounding(2.0 * (v_max + ki_e));
        let output_step = super::f64_rounding(2.0 * (kp_e + v_max + ki_e));
        (samples as f64 * integrator_step + output_step + self.output.max_error())
            / self.output.to.lsb()
    }

    /// Parameters of `hdl/gyrofx_pi.v`.
    pub fn rtl_parameters(&self) -> Vec<RtlParameter> {
        let mut p = vec![
            ("ERR_W", i128::from(self.input.width)),
            ("ERR_F", i128::from(self.input.frac)),
            ("KP_W", i128::from(self.kp.format.width)),
            ("KP_F", i128::from(self.kp.format.frac)),
            ("KI_W", i128::from(self.ki.format.width)),
            ("KI_F", i128::from(self.ki.format.frac)),
            ("INT_W", i128::from(self.integrator.width)),
            ("INT_F", i128::from(self.integrator.frac)),
            ("OUT_W", i128::from(self.output.to.width)),
            ("OUT_F", i128::from(self.output.to.frac)),
            ("KP", self.kp.code),
            ("KI", self.ki.code),
            ("INT_MIN", self.limits[0]),
            ("INT_MAX", self.limits[1]),
        ];
        p.extend(mode_parameters(self.output.rounding, self.output.overflow));
        p
    }
}

/// Counts of the PI's quantization points.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct OverflowCounts {
    /// Samples whose integrator update hit a limit (anti-windup acted).
    pub integrator_clamped: u64,
    /// Outputs that did not fit the output format.
    pub output: u64,
}

/// Which 64-bit path [`FixedPi::step`] takes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Path {
    /// Every exact intermediate fits `i64`.
    Narrow,
    /// The integrator update is wider; it is rounded as integrator plus aligned product.
    SplitUpdate,
}

/// The bit-accurate PI controller.
///
/// The paths compute the same bits: [`FixedPi::step_reference`] follows the definition in
/// `i128` with each point's own mode; [`FixedPi::step`] is monomorphized per rounding mode
/// when both points share one mode, and runs in `i64` when every exact intermediate fits 64
/// bits (the AGC's defaults do), or when only the integrator update is wider and its wide
/// part is the integrator itself, aligned (the PLL's defaults: `v · 2^30` beside a 50-bit
/// `ki · e`), rounding the update split into the two ([`round_right_split_i64`]). Property
/// tests check them against each other.
///
/// [`round_right_split_i64`]: crate::fx::round_right_split_i64
#[derive(Clone, Debug)]
pub struct FixedPi {
    kp: i64,
    ki: i64,
    /// Left shifts aligning `v` and `ki·e` to the update's fraction.
    v_to_update: u32,
    ki_e_to_update: u32,
    /// Left shifts aligning `kp·e` and `v` to the output sum's fraction.
    kp_e_to_sum: u32,
    v_to_sum: u32,
    integrator: Quantizer,
    output: Quantizer,
    limits: [i64; 2],
    /// The shared rounding mode, when a 64-bit path applies, and which.
    fast: Option<(Rounding, Path)>,
    clamped: u64,
    v: i64,
}

impl FixedPi {
    /// The controller of `plan`, integrator at 0.
    pub fn new(plan: &Plan) -> Self {
        let update = plan.integrator_point.from;
        let sum = plan.output.from;
        let ki_e_frac = plan.ki.format.frac + plan.input.frac;
        let kp_e_frac = plan.kp.format.frac + plan.input.frac;
        let shared = plan.integrator_point.rounding == plan.output.rounding;
        let v_to_update = (update.frac - plan.integrator.frac) as u32;
        let ki_e_to_update = (update.frac - ki_e_frac) as u32;
        // The products are no wider than the sums they enter.
        let narrow = update.width <= 64 && sum.width <= 64;
        // The split update: `ki·e` aligned fits 63 bits and the integrator 62, so
        // `v + (ki·e >> v_to_update)` cannot overflow i64.
        let product_bits = plan.ki.format.width + plan.input.width + ki_e_to_update;
        let split = sum.width <= 64
            && (1..=62).contains(&v_to_update)
            && plan.integrator.width <= 62
            && product_bits <= 63;
        let path = if narrow {
            Some(Path::Narrow)
        } else if split {
            Some(Path::SplitUpdate)
        } else {
            None
        };
        FixedPi {
            kp: plan.kp.code as i64,
            ki: plan.ki.code as i64,
            v_to_update,
            ki_e_to_update,
            kp_e_to_sum: (sum.frac - kp_e_frac) as u32,
            v_to_sum: (sum.frac - plan.integrator.frac) as u32,
            integrator: plan.integrator_point.quantizer(),
            output: plan.output.quantizer(),
            limits: plan.limits.map(|c| c as i64),
            fast: path
                .filter(|_| shared)
                .map(|path| (plan.output.rounding, path)),
            clamped: 0,
            v: 0,
        }
    }

    /// Synchronous reset: integrator to 0 (not the counts).
    pub fn reset(&mut self) {
        self.v = 0;
    }

    /// Loads `clamp(code)` (integrator format) into the integrator.
    pub fn preset(&mut self, code: i64) {
        self.v = code.clamp(self.limits[0], self.limits[1]);
    }

    /// The integrator code.
    pub fn integrator(&self) -> i64 {
        self.v
    }

    /// One sample: error code `e`; returns the output code.
    #[inline]
    pub fn step(&mut self, e: i64) -> i64 {
        let Some((rounding, path)) = self.fast else {
            return self.step_reference(e);
        };
        match (rounding, path) {
            (Rounding::Floor, Path::Narrow) => self.step_mode::<{ mode::FLOOR }, false>(e),
            (Rounding::Ceil, Path::Narrow) => self.step_mode::<{ mode::CEIL }, false>(e),
            (Rounding::Zero, Path::Narrow) => self.step_mode::<{ mode::ZERO }, false>(e),
            (Rounding::Nearest, Path::Narrow) => self.step_mode::<{ mode::NEAREST }, false>(e),
            (Rounding::Round, Path::Narrow) => self.step_mode::<{ mode::ROUND }, false>(e),
            (Rounding::Convergent, Path::Narrow) => {
                self.step_mode::<{ mode::CONVERGENT }, false>(e)
            }
            (Rounding::Floor, Path::SplitUpdate) => self.step_mode::<{ mode::FLOOR }, true>(e),
            (Rounding::Ceil, Path::SplitUpdate) => self.step_mode::<{ mode::CEIL }, true>(e),
            (Rounding::Zero, Path::SplitUpdate) => self.step_mode::<{ mode::ZERO }, true>(e),
            (Rounding::Nearest, Path::SplitUpdate) => self.step_mode::<{ mode::NEAREST }, true>(e),
            (Rounding::Round, Path::SplitUpdate) => self.step_mode::<{ mode::ROUND }, true>(e),
            (Rounding::Convergent, Path::SplitUpdate) => {
                self.step_mode::<{ mode::CONVERGENT }, true>(e)
            }
        }
    }

    #[inline(always)]
    fn step_mode<const MODE: u8, const SPLIT: bool>(&mut self, e: i64) -> i64 {
        let product = (self.ki * e) << self.ki_e_to_update;
        let rounded = if SPLIT {
            self.integrator
                .apply_mode_split_i64::<MODE>(self.v, product)
        } else {
            self.integrator
                .apply_mode_i64::<MODE>((self.v << self.v_to_update) + product)
        };
        let v = rounded.clamp(self.limits[0], self.limits[1]);
        self.clamped += u64::from(v != rounded);
        self.v = v;
        let sum = ((self.kp * e) << self.kp_e_to_sum) + (v << self.v_to_sum);
        self.output.apply_mode_i64::<MODE>(sum)
    }

    /// One sample computed literally from the definition in `i128`, each point with its own
    /// mode: the reference the fast path is tested against, and the path for wide plans.
    pub fn step_reference(&mut self, e: i64) -> i64 {
        let e = i128::from(e);
        let update = (i128::from(self.v) << self.v_to_update)
            + ((i128::from(self.ki) * e) << self.ki_e_to_update);
        let rounded = self.integrator.apply(update);
        let [lo, hi] = self.limits.map(i128::from);
        let v = rounded.clamp(lo, hi);
        self.clamped += u64::from(v != rounded);
        self.v = v as i64;
        let sum = ((i128::from(self.kp) * e) << self.kp_e_to_sum) + (v << self.v_to_sum);
        self.output.apply(sum) as i64
    }

    /// Runs a block.
    ///
    /// # Panics
    /// When the slices differ in length.
    pub fn process(&mut self, e: &[i64], out: &mut [i64]) {
        assert_eq!(
            e.len(),
            out.len(),
            "input and output blocks differ in length"
        );
        for (ei, o) in e.iter().zip(out.iter_mut()) {
            *o = self.step(*ei);
        }
    }

    /// Counts since construction.
    pub fn overflow_counts(&self) -> OverflowCounts {
        OverflowCounts {
            integrator_clamped: self.clamped,
            output: self.output.overflow_count,
        }
    }
}

/// The float twin: the same recursion in f64 with the quantized gains and limits.
#[derive(Clone, Debug)]
pub struct FloatPi {
    kp: f64,
    ki: f64,
    limits: [f64; 2],
    v: f64,
}

impl FloatPi {
    /// The twin of `plan`'s controller.
    pub fn new(plan: &Plan) -> Self {
        FloatPi {
            kp: plan.kp.quantized(),
            ki: plan.ki.quantized(),
            limits: plan.limit_values(),
            v: 0.0,
        }
    }

    /// Integrator to 0.
    pub fn reset(&mut self) {
        self.v = 0.0;
    }

    /// Loads `clamp(value)`.
    pub fn preset(&mut self, value: f64) {
        self.v = value.clamp(self.limits[0], self.limits[1]);
    }

    /// One sample (`e` real); returns `u`.
    pub fn step(&mut self, e: f64) -> f64 {
        self.v = (self.v + self.ki * e).clamp(self.limits[0], self.limits[1]);
        self.kp * e + self.v
    }
}

#[cfg(test)]
mod tests;
