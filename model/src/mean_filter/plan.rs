//! [`Plan`]: every format, the quantized threshold and the reciprocal ROM of a mean filter.

use crate::fx::{from_f64, Format, FxError, Overflow, Rounding};

/// Largest window `L`: the RTL compares every sample of a block in parallel.
pub const MAX_WINDOW: u32 = 1024;

/// What a mean filter is asked to be.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Spec {
    /// Format of the samples, °/s.
    pub input: Format,
    /// Format of the block means, °/s.
    pub output: Format,
    /// `L`, samples per block.
    pub window: u32,
    /// `r`, °/s: samples farther than this from the block mean are rejected.
    pub threshold_dps: f64,
    /// Width of the `1/n` codes.
    pub reciprocal_width: u32,
    /// Rounding at the output.
    pub rounding: Rounding,
    /// Overflow at the output.
    pub overflow: Overflow,
}

/// A refused spec.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum PlanError {
    /// A parameter outside what the architecture allows.
    #[error("mean_filter.{field} = {value} is not allowed: {allowed}")]
    Field {
        /// Which one.
        field: &'static str,
        /// Its value.
        value: String,
        /// What is allowed.
        allowed: String,
    },
    /// An intermediate format beyond 128 bits.
    #[error("mean filter {node}: {source}")]
    Format {
        /// The node.
        node: &'static str,
        /// Why.
        source: FxError,
    },
}

/// Every format and constant of a mean filter (see the module docs for the algorithm).
#[derive(Clone, Debug, PartialEq)]
pub struct Plan {
    /// Samples.
    pub input: Format,
    /// Block means.
    pub output: Format,
    /// `L`.
    pub window: u32,
    /// `r` in input LSB (nearest).
    pub threshold_code: i128,
    /// `L·r` in input LSB: a sample is kept when `|L·x − sum| ≤ scaled_threshold`.
    pub scaled_threshold: i128,
    /// `Σ x` over a block, exact.
    pub sum: Format,
    /// `L·x − sum`, exact.
    pub deviation: Format,
    /// Bits of the kept count `0..=L`.
    pub count_bits: u32,
    /// `1/n` codes.
    pub reciprocal: Format,
    /// `rom[n] = Q(1/n)` for `n = 1..=L`; `rom[0] = rom[L]` (the all-rejected fallback).
    pub rom: Vec<i128>,
    /// `kept · recip`, exact.
    pub product: Format,
    /// Output rounding.
    pub rounding: Rounding,
    /// Output overflow.
    pub overflow: Overflow,
}

fn field(field: &'static str, value: impl ToString, allowed: impl Into<String>) -> PlanError {
    PlanError::Field {
        field,
        value: value.to_string(),
        allowed: allowed.into(),
    }
}

/// Bits of an unsigned number holding `0..=value`.
fn bits_for(value: u32) -> u32 {
    32 - value.leading_zeros()
}

impl Plan {
    /// Resolves `spec`.
    ///
    /// # Errors
    /// [`PlanError::Field`] for a window outside `2..=MAX_WINDOW`, a threshold that is negative,
    /// not finite or beyond the input range, a reciprocal width outside `4..=64`;
    /// [`PlanError::Format`] when an exact intermediate needs more than 128 bits.
    pub fn new(spec: &Spec) -> Result<Plan, PlanError> {
        if !(2..=MAX_WINDOW).contains(&spec.window) {
            return Err(field("window", spec.window, format!("2..={MAX_WINDOW}")));
        }
        if !spec.input.signed || !spec.output.signed {
            return Err(field(
                "output_format",
                spec.output,
                "signed input and output formats",
            ));
        }
        let threshold = if spec.threshold_dps.is_finite() && spec.threshold_dps >= 0.0 {
            from_f64(
                spec.threshold_dps,
                spec.input,
                Rounding::Convergent,
                Overflow::Saturate,
            )
            .ok()
            .filter(|q| !q.overflowed)
        } else {
            None
        };
        let Some(threshold) = threshold else {
            return Err(field(
                "threshold_dps",
                spec.threshold_dps,
                format!(
                    "a finite number from 0 to the input range's {} °/s",
                    spec.input.max_value()
                ),
            ));
        };
        if !(4..=64).contains(&spec.reciprocal_width) {
            return Err(field(
                "reciprocal_width",
                spec.reciprocal_width,
                "4..=64 bits",
            ));
        }
        let node = |node: &'static str| move |source| PlanError::Format { node, source };
        let window = spec.window;
        let count_bits = bits_for(window);
        let growth = 32 - (window - 1).leading_zeros(); // ceil(log2 L)
        let sum = Format::intermediate(true, spec.input.width + growth, spec.input.frac)
            .map_err(node("sum"))?;
        let deviation =
            Format::intermediate(true, spec.input.width + count_bits + 1, spec.input.frac)
                .map_err(node("deviation"))?;
        // 1/1 = 1 needs one integer bit besides the sign.
        let reciprocal = Format::signed(spec.reciprocal_width, spec.reciprocal_width as i32 - 2)
            .map_err(node("reciprocal"))?;
        let quantize = |n: u32| -> i128 {
            from_f64(
                1.0 / f64::from(n),
                reciprocal,
                Rounding::Convergent,
                Overflow::Saturate,
            )
            .expect("1/n is finite")
            .code
        };
        let mut rom = vec![quantize(window)];
        rom.extend((1..=window).map(quantize));
        if rom[0] == 0 {
            return Err(field(
                "reciprocal_width",
                spec.reciprocal_width,
                format!("enough bits that 1/{window} is not 0"),
            ));
        }
        let product = Format::product(sum, reciprocal).map_err(node("kept * recip"))?;
        Ok(Plan {
            input: spec.input,
            output: spec.output,
            window,
            threshold_code: threshold.code,
            scaled_threshold: threshold.code * i128::from(window),
            sum,
            deviation,
            count_bits,
            reciprocal,
            rom,
            product,
            rounding: spec.rounding,
            overflow: spec.overflow,
        })
    }

    /// `r` as quantized, °/s.
    pub fn threshold_dps(&self) -> f64 {
        self.input.to_f64(self.threshold_code)
    }

    /// Largest difference between [`super::FixedMeanFilter`] and [`super::FloatMeanFilter`]
    /// on the same input codes, in output LSB, for outputs that do not overflow: both keep
    /// the same samples (exact comparisons against the same quantized `r`), so the difference
    /// is the reciprocal's error times the kept sum, `n·|Q(1/n) − 1/n|·max|x|`, plus the output
    /// rounding.
    pub fn error_bound_lsb(&self) -> f64 {
        let largest_input = self.input.min_value().abs();
        let worst = (1..=self.window)
            .map(|n| {
                let quantized = self.reciprocal.to_f64(self.rom[n as usize]);
                f64::from(n) * (quantized - 1.0 / f64::from(n)).abs()
            })
            .fold(0.0, f64::max);
        worst * largest_input / self.output.lsb() + self.rounding.max_error_lsb()
    }

    /// The reciprocal ROM's value at `address`, as a real.
    pub fn reciprocal_at(&self, address: usize) -> f64 {
        self.reciprocal.to_f64(self.rom[address])
    }
}
