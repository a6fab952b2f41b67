//! The fixed-point core: runtime formats, exact arithmetic, and declared quantization points.
//!
//! Arithmetic is exact until a declared quantization point (SPEC §2): [`Fx::exact_add`] grows one
//! bit, [`Fx::exact_mul`] adds widths, and only [`Fx::quantize`] / [`Quantizer::apply`] round (six
//! [`Rounding`] modes) and wrap or saturate ([`Overflow`]). Codes are carried in `i128`, so
//! every intermediate up to 128 bits is exact; plans refuse anything wider.
//!
//! Rounding every mode applies, to an integer (`frac = 0`), as the RTL does:
//!
//! | value | floor | ceil | zero | nearest | round | convergent |
//! |------:|------:|-----:|-----:|--------:|------:|-----------:|
//! |   2.2 |     2 |    3 |    2 |       2 |     2 |          2 |
//! |   2.7 |     2 |    3 |    2 |       3 |     3 |          3 |
//! |  −1.5 |    −2 |   −1 |   −1 |      −1 |    −2 |         −2 |
//! |  −0.5 |    −1 |    0 |    0 |       0 |    −1 |          0 |
//! |   0.5 |     0 |    1 |    0 |       1 |     1 |          0 |
//! |   1.5 |     1 |    2 |    1 |       2 |     2 |          2 |

mod format;
mod quantize;

pub use format::{Format, MAX_DECLARED_WIDTH, MAX_INTERMEDIATE_WIDTH};
pub use quantize::{
    from_f64, mode, requantize, round_right, round_right_split_i64, Overflow, Quantized, Quantizer,
    Rounding,
};

/// Errors of the fixed-point core. Each names the offending value and what is allowed.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum FxError {
    /// A declared width outside 1..=64.
    #[error("width {width} is not allowed: a format's width must be 1..={max} bits")]
    Width {
        /// The width given.
        width: u32,
        /// The largest allowed.
        max: u32,
    },
    /// An exact intermediate that would not fit the model's 128-bit carrier.
    #[error("an exact intermediate would need {width} bits; at most {max} are supported: narrow the operand formats")]
    IntermediateWidth {
        /// The width needed.
        width: u32,
        /// The largest supported.
        max: u32,
    },
    /// A format string that does not parse.
    #[error("'{text}' is not a fixed-point format: expected s<width>.<frac> or u<width>.<frac>, e.g. s18.16 or u12.12")]
    Parse {
        /// The text given.
        text: String,
    },
    /// An unknown rounding-mode name.
    #[error("'{text}' is not a rounding mode: expected one of floor, ceil, zero, nearest, round, convergent")]
    RoundingName {
        /// The text given.
        text: String,
    },
    /// An unknown overflow-mode name.
    #[error("'{text}' is not an overflow mode: expected wrap or saturate")]
    OverflowName {
        /// The text given.
        text: String,
    },
    /// NaN or infinity where a real value is quantized.
    #[error("{value} cannot be quantized: only finite values have a fixed-point code")]
    NotFinite {
        /// The value given.
        value: f64,
    },
}

/// How a coefficient's format is chosen.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum CoefficientFormat {
    /// Signed, this width, and the most fraction bits for which every value fits (see
    /// [`fitting_format`]): each coefficient gets its own scaling.
    Auto {
        /// Word length in bits (e.g. 18 for a DSP48 multiplier port).
        width: u32,
    },
    /// Exactly this format; values that do not fit are an error.
    Fixed(Format),
}

/// Signed `width` bits and the most fraction bits for which every value fits after rounding to
/// nearest (ties to even). Exact: uses the binary exponent of the largest magnitude
/// (`libm::frexp`).
///
/// # Errors
/// [`FxError::Width`] for a width outside 1..=64.
pub fn fitting_format(values: &[f64], width: u32) -> Result<Format, FxError> {
    Format::signed(width, 0)?;
    let largest = values.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    if largest == 0.0 || !largest.is_finite() {
        return Format::signed(width, width as i32 - 1);
    }
    // largest = mantissa · 2^exponent with mantissa in [0.5, 1): |v| < 2^exponent.
    let (_, exponent) = libm::frexp(largest);
    let mut frac = width as i32 - 1 - exponent;
    loop {
        let format = Format::signed(width, frac)?;
        let fits = values.iter().all(|v| {
            from_f64(*v, format, Rounding::Convergent, Overflow::Saturate)
                .map(|q| !q.overflowed)
                .unwrap_or(false)
        });
        if fits {
            return Ok(format);
        }
        frac -= 1;
    }
}

/// `2^exp` as f64, exact for -1074 <= exp <= 1023: built from the exponent bits for normal
/// results, through the pure-Rust `libm::ldexp` for subnormal and out-of-range ones.
#[inline]
pub fn pow2(exp: i32) -> f64 {
    if (-1022..=1023).contains(&exp) {
        f64::from_bits(((exp + 1023) as u64) << 52)
    } else {
        libm::ldexp(1.0, exp)
    }
}

/// `⌊x + ½⌋` of a finite `x` as `i64` (round to nearest, ties toward +∞, the ADC's rule),
/// saturating beyond the `i64` range: the same integer as `x.floor()` plus one when
/// `x − x.floor() ≥ ½`, without the call to the platform's `floor` that baseline x86-64 makes.
/// Exact: below 2^52 in magnitude the truncation and the remainder are exact in f64; from 2^52
/// on every f64 is an integer.
///
/// The result for NaN is 0 (callers check finiteness first).
#[inline(always)]
pub fn round_half_up(x: f64) -> i64 {
    let truncated = x as i64; // toward zero, saturating
    let floor = truncated.saturating_sub(i64::from(truncated as f64 > x));
    floor.saturating_add(i64::from(x - floor as f64 >= 0.5))
}

/// A code together with its format: the exact-arithmetic view of a fixed-point value.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Fx {
    /// The integer code; the value is `code · 2^-format.frac`.
    pub code: i128,
    /// Its format.
    pub format: Format,
}

impl Fx {
    /// A value from its code. Debug builds check that the code fits.
    pub fn new(code: i128, format: Format) -> Self {
        debug_assert!(format.contains(code), "code {code} does not fit {format}");
        Fx { code, format }
    }

    /// The real value (see [`Format::to_f64`]).
    pub fn to_f64(self) -> f64 {
        self.format.to_f64(self.code)
    }

    fn aligned(self, frac: i32) -> i128 {
        self.code << (frac - self.format.frac)
    }

    /// Exact sum: format from [`Format::sum`].
    ///
    /// # Errors
    /// [`FxError::IntermediateWidth`] when the sum would exceed 128 bits.
    pub fn exact_add(self, other: Fx) -> Result<Fx, FxError> {
        let format = Format::sum(self.format, other.format, false)?;
        Ok(Fx::new(
            self.aligned(format.frac) + other.aligned(format.frac),
            format,
        ))
    }

    /// Exact difference: format from [`Format::sum`] (always signed).
    ///
    /// # Errors
    /// [`FxError::IntermediateWidth`] when the difference would exceed 128 bits.
    pub fn exact_sub(self, other: Fx) -> Result<Fx, FxError> {
        let format = Format::sum(self.format, other.format, true)?;
        Ok(Fx::new(
            self.aligned(format.frac) - other.aligned(format.frac),
            format,
        ))
    }

    /// Exact product: format from [`Format::product`].
    ///
    /// # Errors
    /// [`FxError::IntermediateWidth`] when the product would exceed 128 bits.
    pub fn exact_mul(self, other: Fx) -> Result<Fx, FxError> {
        let format = Format::product(self.format, other.format)?;
        Ok(Fx::new(self.code * other.code, format))
    }

    /// Rounds with `rounding` and wraps or saturates with `overflow` into `to`.
    pub fn quantize(self, to: Format, rounding: Rounding, overflow: Overflow) -> Quantized {
        requantize(self.code, self.format.frac, to, rounding, overflow)
    }
}

#[cfg(test)]
mod tests;
