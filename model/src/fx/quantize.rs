//! Quantization: rounding and overflow handling at a declared point.

use std::fmt;
use std::str::FromStr;

use super::{pow2, Format, FxError};

/// How dropped fraction bits are rounded, exactly as the RTL implements each mode.
///
/// | value | floor | ceil | zero | nearest | round | convergent |
/// |------:|------:|-----:|-----:|--------:|------:|-----------:|
/// |   2.2 |     2 |    3 |    2 |       2 |     2 |          2 |
/// |   2.7 |     2 |    3 |    2 |       3 |     3 |          3 |
/// |  −1.5 |    −2 |   −1 |   −1 |      −1 |    −2 |         −2 |
/// |  −0.5 |    −1 |    0 |    0 |       0 |    −1 |          0 |
/// |   0.5 |     0 |    1 |    0 |       1 |     1 |          0 |
/// |   1.5 |     1 |    2 |    1 |       2 |     2 |          2 |
///
/// (Rounding to an integer, i.e. into a format with `frac = 0`; the table is a unit test.)
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Rounding {
    /// Drop the bits: toward −∞ (two's-complement truncation). No adder in hardware.
    Floor,
    /// Toward +∞.
    Ceil,
    /// Toward zero (sign-magnitude truncation).
    Zero,
    /// Nearest, ties toward +∞: add half an LSB, then floor. The cheap hardware rounding.
    Nearest,
    /// Nearest, ties away from zero (MATLAB `round`).
    Round,
    /// Nearest, ties to even (unbiased; MATLAB `convergent`).
    Convergent,
}

impl Rounding {
    /// All modes, in the order of the table above.
    pub const ALL: [Rounding; 6] = [
        Rounding::Floor,
        Rounding::Ceil,
        Rounding::Zero,
        Rounding::Nearest,
        Rounding::Round,
        Rounding::Convergent,
    ];

    /// Config and RTL name.
    pub fn name(self) -> &'static str {
        match self {
            Rounding::Floor => "floor",
            Rounding::Ceil => "ceil",
            Rounding::Zero => "zero",
            Rounding::Nearest => "nearest",
            Rounding::Round => "round",
            Rounding::Convergent => "convergent",
        }
    }

    /// Integer code of the mode as the RTL's `ROUNDING` parameter takes it.
    pub fn rtl_code(self) -> u32 {
        match self {
            Rounding::Floor => 0,
            Rounding::Ceil => 1,
            Rounding::Zero => 2,
            Rounding::Nearest => 3,
            Rounding::Round => 4,
            Rounding::Convergent => 5,
        }
    }

    /// Largest rounding error, in LSB of the target: 1 (exclusive) for the directed modes,
    /// 1/2 for the round-to-nearest family.
    pub fn max_error_lsb(self) -> f64 {
        match self {
            Rounding::Floor | Rounding::Ceil | Rounding::Zero => 1.0,
            Rounding::Nearest | Rounding::Round | Rounding::Convergent => 0.5,
        }
    }

    /// Whether to add one LSB to `floor(value / 2^shift)`, given the dropped `remainder`
    /// (`0 <= remainder < 2^shift`), `half = 2^(shift-1)` (0 when shift is 0, where nothing is
    /// dropped), the sign of the value and the parity of the floored quotient.
    #[inline(always)]
    fn increment(self, remainder: i128, half: i128, negative: bool, quotient_odd: bool) -> bool {
        if remainder == 0 {
            return false;
        }
        match self {
            Rounding::Floor => false,
            Rounding::Ceil => true,
            Rounding::Zero => negative,
            Rounding::Nearest => remainder >= half,
            Rounding::Round => remainder > half || (remainder == half && !negative),
            Rounding::Convergent => remainder > half || (remainder == half && quotient_odd),
        }
    }
}

impl fmt::Display for Rounding {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl FromStr for Rounding {
    type Err = FxError;
    fn from_str(text: &str) -> Result<Self, FxError> {
        Rounding::ALL
            .into_iter()
            .find(|r| r.name() == text)
            .ok_or_else(|| FxError::RoundingName {
                text: text.to_string(),
            })
    }
}

/// What happens to a value outside the target format's range.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Overflow {
    /// Keep the low `width` bits (two's-complement wrap-around).
    Wrap,
    /// Clamp to the nearest representable code.
    Saturate,
}

impl Overflow {
    /// Both modes.
    pub const ALL: [Overflow; 2] = [Overflow::Wrap, Overflow::Saturate];

    /// Config name.
    pub fn name(self) -> &'static str {
        match self {
            Overflow::Wrap => "wrap",
            Overflow::Saturate => "saturate",
        }
    }

    /// Integer code of the mode as the RTL's `SATURATE` parameter takes it.
    pub fn rtl_code(self) -> u32 {
        match self {
            Overflow::Wrap => 0,
            Overflow::Saturate => 1,
        }
    }
}

impl fmt::Display for Overflow {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl FromStr for Overflow {
    type Err = FxError;
    fn from_str(text: &str) -> Result<Self, FxError> {
        Overflow::ALL
            .into_iter()
            .find(|o| o.name() == text)
            .ok_or_else(|| FxError::OverflowName {
                text: text.to_string(),
            })
    }
}

/// Result of one quantization: the code, and whether the rounded value lay outside the
/// target range (and so was wrapped or saturated).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Quantized {
    /// The code in the target format.
    pub code: i128,
    /// The rounded value did not fit the target format.
    pub overflowed: bool,
}

/// Re-quantizes `code` (with `from_frac` fractional bits) into `to`: rounds the dropped bits
/// with `rounding`, then wraps or saturates with `overflow`. Exact when no bits are dropped
/// and the value fits.
///
/// # Example
/// ```
/// use gyrofx_model::fx::{requantize, Format, Overflow, Rounding};
/// let to: Format = "s8.1".parse().unwrap();
/// // 1.25 (code 5 at 2 fraction bits) -> 1.5 under `nearest` (a tie, rounded toward +inf)
/// let q = requantize(5, 2, to, Rounding::Nearest, Overflow::Saturate);
/// assert_eq!(q.code, 3);
/// ```
#[inline(always)]
pub fn requantize(
    code: i128,
    from_frac: i32,
    to: Format,
    rounding: Rounding,
    overflow: Overflow,
) -> Quantized {
    let shift = from_frac - to.frac;
    let (rounded, shift_overflow) = if shift > 0 {
        round_shift_right(code, shift as u32, rounding)
    } else {
        let left = (-shift) as u32;
        if left >= 128 {
            (0, code != 0)
        } else {
            let shifted = code << left;
            (shifted, (shifted >> left) != code)
        }
    };
    finish_overflow(rounded, shift_overflow, code < 0, to, overflow)
}

/// `value / 2^shift` rounded with `rounding` (shift >= 1). Never overflows: the increment is
/// applied to the already shifted quotient.
#[inline(always)]
fn round_shift_right(value: i128, shift: u32, rounding: Rounding) -> (i128, bool) {
    if shift >= 128 {
        // |value / 2^shift| <= 1/2, with equality only for i128::MIN at shift 128.
        let exact_negative_half = shift == 128 && value == i128::MIN;
        let code = match rounding {
            Rounding::Floor => -i128::from(value < 0),
            Rounding::Ceil => i128::from(value > 0),
            Rounding::Zero | Rounding::Nearest | Rounding::Convergent => 0,
            Rounding::Round => -i128::from(exact_negative_half),
        };
        return (code, false);
    }
    let quotient = value >> shift;
    let remainder = value & (i128::MAX >> (127 - shift));
    let half = 1i128 << (shift - 1);
    let up = rounding.increment(remainder, half, value < 0, quotient & 1 == 1);
    (quotient + i128::from(up), false)
}

/// The rounding modes as const-generic parameters (their [`Rounding::rtl_code`] values), for
/// hot loops monomorphized per mode.
pub mod mode {
    /// [`super::Rounding::Floor`].
    pub const FLOOR: u8 = 0;
    /// [`super::Rounding::Ceil`].
    pub const CEIL: u8 = 1;
    /// [`super::Rounding::Zero`].
    pub const ZERO: u8 = 2;
    /// [`super::Rounding::Nearest`].
    pub const NEAREST: u8 = 3;
    /// [`super::Rounding::Round`].
    pub const ROUND: u8 = 4;
    /// [`super::Rounding::Convergent`].
    pub const CONVERGENT: u8 = 5;
}

/// The increment of a floor quotient under rounding mode `MODE`, from the dropped bits (any
/// set; the half bit; any set below it), the sign of the value and the quotient (for its
/// parity), all 0/1 words.
macro_rules! mode_increment {
    ($mode:ident, $any_dropped:expr, $half_bit:expr, $below_half:expr, $negative:expr, $quotient:expr) => {
        match $mode {
            mode::FLOOR => 0,
            mode::CEIL => $any_dropped,
            mode::ZERO => $any_dropped & $negative,
            mode::NEAREST => $half_bit,
            mode::ROUND => $half_bit & ($below_half | (1 - $negative)),
            _ => $half_bit & ($below_half | ($quotient & 1)),
        }
    };
}

/// One branch-free rounding kernel per word type: `value / 2^shift` rounded with `MODE`.
macro_rules! round_right_kernel {
    ($(#[$doc:meta])* $name:ident, $word:ty) => {
        $(#[$doc])*
        #[inline(always)]
        pub fn $name<const MODE: u8>(value: $word, shift: u32) -> $word {
            let quotient = value >> shift;
            let dropped_mask = <$word>::MAX >> (<$word>::BITS - 1 - shift);
            let any_dropped = <$word>::from(value & dropped_mask != 0);
            let half_bit = (value >> (shift - 1)) & 1;
            let below_half = <$word>::from(value & (dropped_mask >> 1) != 0);
            let negative = <$word>::from(value < 0);
            quotient + mode_increment!(MODE, any_dropped, half_bit, below_half, negative, quotient)
        }
    };
}

round_right_kernel!(
    /// `value / 2^shift` rounded with the mode `MODE` (see [`mode`]), for `1 <= shift <= 127`:
    /// branch-free, the same result as [`requantize`]'s rounding (an exhaustive test checks it).
    round_right,
    i128
);

round_right_kernel!(
    /// [`round_right`] on 64-bit values (`1 <= shift <= 63`), for the per-sample paths whose
    /// plans prove their values fit 64 bits (an exhaustive test checks it).
    round_right_i64,
    i64
);

/// `(aligned · 2^shift + term) / 2^shift` rounded with the mode `MODE`, in 64 bits, for
/// `1 <= shift <= 63`, without forming the sum: `aligned` is already at the target fraction
/// (its shifted bits are zeros), so the dropped bits are `term`'s and the sum's sign is the
/// quotient's. The caller proves `aligned + (term >> shift)` fits `i64`. A property test checks
/// it against [`round_right`] on the sum in `i128`.
#[inline(always)]
pub fn round_right_split_i64<const MODE: u8>(aligned: i64, term: i64, shift: u32) -> i64 {
    let quotient = aligned + (term >> shift);
    let dropped_mask = i64::MAX >> (63 - shift);
    let any_dropped = i64::from(term & dropped_mask != 0);
    let half_bit = (term >> (shift - 1)) & 1;
    let below_half = i64::from(term & (dropped_mask >> 1) != 0);
    let negative = i64::from(quotient < 0);
    quotient + mode_increment!(MODE, any_dropped, half_bit, below_half, negative, quotient)
}

#[inline(always)]
fn finish_overflow(
    rounded: i128,
    shift_overflow: bool,
    negative: bool,
    to: Format,
    overflow: Overflow,
) -> Quantized {
    if !shift_overflow && to.contains(rounded) {
        return Quantized {
            code: rounded,
            overflowed: false,
        };
    }
    let code = match overflow {
        Overflow::Wrap => to.wrap(rounded),
        Overflow::Saturate => {
            let too_low = if shift_overflow {
                negative
            } else {
                rounded < to.min_code()
            };
            if too_low {
                to.min_code()
            } else {
                to.max_code()
            }
        }
    };
    Quantized {
        code,
        overflowed: true,
    }
}

/// Quantizes a real value into `to`, rounding with `rounding` and wrapping or saturating with
/// `overflow`. Scaling by `2^frac` is exact in f64, so the only rounding is the declared one.
///
/// # Errors
/// [`FxError::NotFinite`] for NaN or ±∞.
///
/// # Example
/// ```
/// use gyrofx_model::fx::{from_f64, Format, Overflow, Rounding};
/// let f: Format = "s8.1".parse().unwrap();
/// assert_eq!(from_f64(-1.25, f, Rounding::Nearest, Overflow::Saturate).unwrap().code, -2);
/// assert_eq!(from_f64(1.25, f, Rounding::Nearest, Overflow::Saturate).unwrap().code, 3);
/// ```
pub fn from_f64(
    value: f64,
    to: Format,
    rounding: Rounding,
    overflow: Overflow,
) -> Result<Quantized, FxError> {
    if !value.is_finite() {
        return Err(FxError::NotFinite { value });
    }
    let scaled = scale_by_pow2(value, to.frac);
    let floor = scaled.floor();
    let remainder = scaled - floor; // exact: floor has no fewer integer bits than scaled
    let negative = scaled < 0.0;
    // 2^127 is exactly representable; anything at or beyond it cannot fit any format.
    let limit = pow2(127);
    if floor >= limit || floor < -limit {
        let sat = finish_overflow(0, true, negative, to, Overflow::Saturate);
        let code = match overflow {
            Overflow::Saturate => sat.code,
            // Beyond i128 the low bits of an f64 integer are zeros.
            Overflow::Wrap => 0,
        };
        return Ok(Quantized {
            code,
            overflowed: true,
        });
    }
    let quotient = floor as i128; // exact: an integer-valued f64 below 2^127
    let up = if remainder == 0.0 {
        false
    } else {
        match rounding {
            Rounding::Floor => false,
            Rounding::Ceil => true,
            Rounding::Zero => negative,
            Rounding::Nearest => remainder >= 0.5,
            Rounding::Round => remainder > 0.5 || (remainder == 0.5 && !negative),
            Rounding::Convergent => remainder > 0.5 || (remainder == 0.5 && quotient & 1 == 1),
        }
    };
    // quotient + 1 only overflows i128 at 2^127 - 1, which f64 cannot hold below the limit.
    Ok(finish_overflow(
        quotient + i128::from(up),
        false,
        negative,
        to,
        overflow,
    ))
}

/// `value · 2^exp`, exact unless the result leaves the normal f64 range.
fn scale_by_pow2(value: f64, exp: i32) -> f64 {
    // Split large exponents so that each factor is a normal power of two.
    let mut result = value;
    let mut remaining = exp;
    while remaining != 0 {
        let step = remaining.clamp(-1000, 1000);
        result *= pow2(step);
        remaining -= step;
    }
    result
}

/// A declared quantization point: a fixed source fraction, a target format and modes, and a
/// count of the values that overflowed there (wrapped or saturated), like a logging fimath.
///
/// Rounds and overflows exactly as [`requantize`]; the range and shift are precomputed so the
/// per-sample path is a shift, a compare and an add.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Quantizer {
    /// Fraction bits of the values that arrive here.
    pub from_frac: i32,
    /// Target format.
    pub to: Format,
    /// Rounding of the dropped bits.
    pub rounding: Rounding,
    /// Handling of out-of-range values.
    pub overflow: Overflow,
    /// Values that did not fit `to` since construction or the last [`Quantizer::clear_count`].
    pub overflow_count: u64,
    shift: i32,
    min: i128,
    max: i128,
}

impl Quantizer {
    /// A quantization point from `from_frac` fraction bits into `to`.
    pub fn new(from_frac: i32, to: Format, rounding: Rounding, overflow: Overflow) -> Self {
        Quantizer {
            from_frac,
            to,
            rounding,
            overflow,
            overflow_count: 0,
            shift: from_frac - to.frac,
            min: to.min_code(),
            max: to.max_code(),
        }
    }

    /// Quantizes one value (see [`requantize`]) and counts an overflow.
    #[inline(always)]
    pub fn apply(&mut self, code: i128) -> i128 {
        match self.rounding {
            Rounding::Floor => self.apply_mode::<{ mode::FLOOR }>(code),
            Rounding::Ceil => self.apply_mode::<{ mode::CEIL }>(code),
            Rounding::Zero => self.apply_mode::<{ mode::ZERO }>(code),
            Rounding::Nearest => self.apply_mode::<{ mode::NEAREST }>(code),
            Rounding::Round => self.apply_mode::<{ mode::ROUND }>(code),
            Rounding::Convergent => self.apply_mode::<{ mode::CONVERGENT }>(code),
        }
    }

    /// [`Quantizer::apply`] with the rounding mode fixed at compile time. `MODE` must be this
    /// quantizer's mode (debug builds check it).
    #[inline(always)]
    pub fn apply_mode<const MODE: u8>(&mut self, code: i128) -> i128 {
        debug_assert_eq!(u32::from(MODE), self.rounding.rtl_code());
        if self.shift <= 0 || self.shift >= 128 {
            let q = requantize(code, self.from_frac, self.to, self.rounding, self.overflow);
            self.overflow_count += u64::from(q.overflowed);
            return q.code;
        }
        let rounded = round_right::<MODE>(code, self.shift as u32);
        if rounded >= self.min && rounded <= self.max {
            return rounded;
        }
        self.overflow_count += 1;
        match self.overflow {
            Overflow::Saturate => rounded.clamp(self.min, self.max),
            Overflow::Wrap => self.to.wrap(rounded),
        }
    }

    /// [`Quantizer::apply`] on a 64-bit value: the mode dispatched at run time to
    /// [`Quantizer::apply_mode_i64`], for points that run once per sample in a loop whose other
    /// points are not monomorphized.
    #[inline]
    pub fn apply_i64(&mut self, code: i64) -> i64 {
        match self.rounding {
            Rounding::Floor => self.apply_mode_i64::<{ mode::FLOOR }>(code),
            Rounding::Ceil => self.apply_mode_i64::<{ mode::CEIL }>(code),
            Rounding::Zero => self.apply_mode_i64::<{ mode::ZERO }>(code),
            Rounding::Nearest => self.apply_mode_i64::<{ mode::NEAREST }>(code),
            Rounding::Round => self.apply_mode_i64::<{ mode::ROUND }>(code),
            Rounding::Convergent => self.apply_mode_i64::<{ mode::CONVERGENT }>(code),
        }
    }

    /// [`Quantizer::apply_mode`] on a 64-bit value (shifts of 1..=63 take the 64-bit kernel;
    /// anything else, and every overflow, the general path).
    #[inline(always)]
    pub fn apply_mode_i64<const MODE: u8>(&mut self, code: i64) -> i64 {
        if self.shift >= 1 && self.shift <= 63 {
            let rounded = round_right_i64::<MODE>(code, self.shift as u32);
            if i128::from(rounded) >= self.min && i128::from(rounded) <= self.max {
                return rounded;
            }
        }
        self.apply_mode::<MODE>(i128::from(code)) as i64
    }

    /// [`Quantizer::apply_mode`] of `aligned · 2^shift + term`, `shift` being this point's
    /// dropped bits (1..=63), for a sum wider than 64 bits whose wide part is already aligned
    /// (an integrator plus a product): [`round_right_split_i64`], and the general path for an
    /// overflow. The caller proves `aligned + (term >> shift)` fits `i64`.
    #[inline(always)]
    pub fn apply_mode_split_i64<const MODE: u8>(&mut self, aligned: i64, term: i64) -> i64 {
        debug_assert!((1..=63).contains(&self.shift));
        let rounded = round_right_split_i64::<MODE>(aligned, term, self.shift as u32);
        if i128::from(rounded) >= self.min && i128::from(rounded) <= self.max {
            return rounded;
        }
        let sum = (i128::from(aligned) << self.shift) + i128::from(term);
        self.apply_mode::<MODE>(sum) as i64
    }

    /// Whether the dropped bits of `code` are exactly half an LSB of the target: the case
    /// where the round-to-nearest modes differ.
    pub fn is_tie(&self, code: i128) -> bool {
        if self.shift <= 0 || self.shift >= 128 {
            return false;
        }
        code & (i128::MAX >> (127 - self.shift)) == 1i128 << (self.shift - 1)
    }

    /// Resets the overflow count.
    pub fn clear_count(&mut self) {
        self.overflow_count = 0;
    }
}
