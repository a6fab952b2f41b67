//! [`Format`]: a runtime fixed-point number format.

use std::fmt;
use std::str::FromStr;

use super::FxError;

/// Widest format a user may declare, in bits.
pub const MAX_DECLARED_WIDTH: u32 = 64;
/// Widest exact intermediate (sums, products) the model carries in its `i128` codes, in bits:
/// 128 signed (a full s64 x s64 product), 127 unsigned.
pub const MAX_INTERMEDIATE_WIDTH: u32 = 128;

/// A two's-complement (signed) or plain binary (unsigned) fixed-point format.
///
/// A code `c` of this format stands for the real value `c · 2^-frac`. `frac` may be negative
/// (the LSB weighs more than 1) or exceed `width` (every bit is fractional). Written as
/// `s18.16` (signed, 18-bit word, 16 fractional bits; MATLAB `fixdt(1,18,16)`) or `u12.12`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct Format {
    /// Two's complement when true, unsigned binary otherwise.
    pub signed: bool,
    /// Word length in bits.
    pub width: u32,
    /// Fractional bits: the LSB weighs `2^-frac`.
    pub frac: i32,
}

impl Format {
    /// A declared format (width 1..=64).
    ///
    /// # Errors
    /// [`FxError::Width`] when `width` is 0 or above 64.
    pub fn new(signed: bool, width: u32, frac: i32) -> Result<Self, FxError> {
        if width == 0 || width > MAX_DECLARED_WIDTH {
            return Err(FxError::Width {
                width,
                max: MAX_DECLARED_WIDTH,
            });
        }
        Ok(Format {
            signed,
            width,
            frac,
        })
    }

    /// A signed declared format.
    ///
    /// # Errors
    /// As [`Format::new`].
    pub fn signed(width: u32, frac: i32) -> Result<Self, FxError> {
        Self::new(true, width, frac)
    }

    /// An intermediate format (width 1..=128 signed, 1..=127 unsigned), as produced by exact
    /// arithmetic.
    ///
    /// # Errors
    /// [`FxError::IntermediateWidth`] when the width exceeds what an `i128` code holds.
    pub fn intermediate(signed: bool, width: u32, frac: i32) -> Result<Self, FxError> {
        let max = MAX_INTERMEDIATE_WIDTH - u32::from(!signed);
        if width == 0 || width > max {
            return Err(FxError::IntermediateWidth { width, max });
        }
        Ok(Format {
            signed,
            width,
            frac,
        })
    }

    /// Integer bits (including the sign bit when signed): `width - frac`. May be negative.
    pub fn int_bits(&self) -> i32 {
        self.width as i32 - self.frac
    }

    /// Smallest code.
    pub fn min_code(&self) -> i128 {
        if self.signed && self.width == 128 {
            i128::MIN
        } else if self.signed {
            -(1i128 << (self.width - 1))
        } else {
            0
        }
    }

    /// Largest code.
    pub fn max_code(&self) -> i128 {
        if self.width == 128 {
            i128::MAX
        } else if self.signed {
            (1i128 << (self.width - 1)) - 1
        } else {
            (1i128 << self.width) - 1
        }
    }

    /// Whether `code` is representable.
    pub fn contains(&self, code: i128) -> bool {
        code >= self.min_code() && code <= self.max_code()
    }

    /// Weight of one LSB, `2^-frac` (exact).
    pub fn lsb(&self) -> f64 {
        super::pow2(-self.frac)
    }

    /// Smallest representable real value.
    pub fn min_value(&self) -> f64 {
        self.min_code() as f64 * self.lsb()
    }

    /// Largest representable real value (rounded to f64 for words wider than 53 bits).
    pub fn max_value(&self) -> f64 {
        self.max_code() as f64 * self.lsb()
    }

    /// Real value of `code`: `code · 2^-frac`. Exact for codes of up to 53 significant bits;
    /// wider codes round to nearest f64.
    pub fn to_f64(&self, code: i128) -> f64 {
        code as f64 * self.lsb()
    }

    /// Format of the exact sum or difference of `a` and `b`: the finer `frac`, the wider
    /// integer part, one bit of growth. Differences are always signed.
    ///
    /// # Errors
    /// [`FxError::IntermediateWidth`] when the result exceeds 128 bits.
    pub fn sum(a: Format, b: Format, subtract: bool) -> Result<Format, FxError> {
        let signed = a.signed || b.signed || subtract;
        let frac = a.frac.max(b.frac);
        let int_of = |f: Format| f.int_bits() + i32::from(signed && !f.signed);
        let int = int_of(a).max(int_of(b)) + 1;
        let width = (int + frac).max(1);
        Format::intermediate(signed, width as u32, frac)
    }

    /// Format of the exact product `a · b`: widths add, fractions add.
    ///
    /// # Errors
    /// [`FxError::IntermediateWidth`] when the result exceeds 128 bits.
    pub fn product(a: Format, b: Format) -> Result<Format, FxError> {
        Format::intermediate(a.signed || b.signed, a.width + b.width, a.frac + b.frac)
    }

    /// Sign-extend (or zero-extend) the low `width` bits of `raw` to a code of this format.
    pub fn wrap(&self, raw: i128) -> i128 {
        if self.width >= 128 {
            return raw;
        }
        let shift = 128 - self.width;
        if self.signed {
            (raw << shift) >> shift
        } else {
            ((raw as u128) << shift >> shift) as i128
        }
    }

    /// Two's-complement bit pattern of `code` in `width` bits, as an unsigned integer.
    pub fn to_bits(&self, code: i128) -> u128 {
        let mask = if self.width >= 128 {
            u128::MAX
        } else {
            (1u128 << self.width) - 1
        };
        (code as u128) & mask
    }

    /// Inverse of [`Format::to_bits`]: the code whose bit pattern is the low `width` bits of
    /// `bits`.
    pub fn from_bits(&self, bits: u128) -> i128 {
        self.wrap(bits as i128)
    }

    /// Hex digits needed for one word: `ceil(width / 4)`.
    pub fn hex_digits(&self) -> usize {
        self.width.div_ceil(4) as usize
    }
}

impl fmt::Display for Format {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let s = if self.signed { 's' } else { 'u' };
        write!(f, "{s}{}.{}", self.width, self.frac)
    }
}

impl FromStr for Format {
    type Err = FxError;

    /// Parses `s18.16`, `u12.12`, `s8.-2`; a missing `.frac` means 0 (`s24` = `s24.0`).
    fn from_str(text: &str) -> Result<Self, FxError> {
        let bad = || FxError::Parse {
            text: text.to_string(),
        };
        let trimmed = text.trim();
        let mut chars = trimmed.chars();
        let signed = match chars.next() {
            Some('s') | Some('S') => true,
            Some('u') | Some('U') => false,
            _ => return Err(bad()),
        };
        let rest = chars.as_str();
        let (width_text, frac_text) = match rest.split_once('.') {
            Some((w, f)) => (w, f),
            None => (rest, "0"),
        };
        let all_digits = |t: &str| !t.is_empty() && t.bytes().all(|b| b.is_ascii_digit());
        let frac_digits = frac_text.strip_prefix('-').unwrap_or(frac_text);
        if !all_digits(width_text) || !all_digits(frac_digits) {
            return Err(bad());
        }
        let width: u32 = width_text.parse().map_err(|_| bad())?;
        let frac: i32 = frac_text.parse().map_err(|_| bad())?;
        Format::new(signed, width, frac)
    }
}
