//! The open-loop blocks of the per-gyro digital drive/sense loop (SPEC §1.6), run at the ADC
//! rate `fs` (100–200 kHz) around a ~8 kHz resonator: [`nco`], [`demodulator`], [`pi`] and
//! [`cic`]; [`gyro`] wires them into one gyro's closed loop, [`closed`] closes it around the
//! simulated resonator and [`figures`] measures what it achieves against SPEC §1.6's closed
//! forms.
//!
//! Each block follows the KF's shape: a `Spec` (formats, widths, settings, the rounding and
//! overflow modes of the config) resolved once into a pure-data `Plan` (the format of every
//! node, every ROM word, the RTL parameters), a bit-accurate fixed model (`reset`, `step`,
//! `process`; `step` allocates nothing and keeps its state in `i64`, exact intermediates in
//! `i128`), a float golden twin (f64), and a derived bound on the difference between the two,
//! in output LSB, checked by property tests over random formats, settings and inputs.
//!
//! # Quantization points of the loop
//!
//! Every point is a [`Point`]: an exact value of a known format rounded into a declared one
//! with [`crate::fx::Quantizer`], so the RTL (`hdl/gyrofx_quantize.v` at each point) rounds
//! the same bits. `config` means the block's configured rounding / overflow mode.
//!
//! | block | point | from (exact) | to | rounding | overflow |
//! |-------|-------|--------------|----|----------|----------|
//! | NCO | phase truncation | `u P.P` cycles | `u (A+2).(A+2)` cycles | floor (by design, see [`nco`]) | wrap (mod 1 cycle) |
//! | NCO | sine ROM (offline) | `A_nco·sin`, f64 | `s S.(S−1)` | convergent | never (refused) |
//! | demodulator | product `2·x·ref` | `s (Wx+Wr).(Fx+Fr−1)` | product format | config | config |
//! | demodulator | low-pass state | state, `k` more fraction bits | state format | config | config (cannot overflow) |
//! | demodulator | I, Q outputs | state format | output format | config | config |
//! | PI | integrator | `integrator + ki·e` | integrator format, then clamped to the limits | config | clamp (anti-windup) |
//! | PI | output | `kp·e + integrator` | output format | config | config |
//! | PI | `kp`, `ki` (offline) | f64 | coefficient formats | convergent | never (refused) |
//! | CIC | comb output `·2^−shift` | `s B.(F+shift)`, exact | CIC output format | config | config |
//! | CIC | compensator taps (offline) | f64 | coefficient format | convergent | never (refused) |
//! | CIC | compensator output | exact FIR sum | output format | config | config |
//!
//! The CIC's integrators and combs wrap (two's complement, `B` bits), which Hogenauer's
//! register width makes exact: no information is lost there.

use std::fmt;

use crate::fx::{from_f64, CoefficientFormat, Format, FxError, Overflow, Quantizer, Rounding};

pub mod cic;
pub mod closed;
pub mod demodulator;
pub mod figures;
pub mod folded;
pub mod gyro;
pub mod nco;
pub mod pi;
pub mod realized_phase;
pub mod residual_budget;
pub mod trace;

/// A refused spec: each variant names the block, the field or coefficient, its value and what
/// is allowed.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum PlanError {
    /// A setting or format outside what the block allows.
    #[error("{block}.{field} = {value} is not allowed: {allowed}")]
    Field {
        /// `nco`, `demodulator`, `pi` or `cic`.
        block: &'static str,
        /// The config field.
        field: &'static str,
        /// Its value, as written.
        value: String,
        /// What is allowed.
        allowed: String,
    },
    /// A coefficient that does not fit its format.
    #[error("{block}.{name} = {value:e} does not fit {format}: it needs {bits_needed} bits at {frac} fraction bits (the largest value is {max:e})")]
    CoefficientOverflow {
        /// The block.
        block: &'static str,
        /// The coefficient.
        name: &'static str,
        /// Its value.
        value: f64,
        /// The format it must fit.
        format: Format,
        /// Signed width its code needs at that fraction.
        bits_needed: u32,
        /// Fraction bits of the format.
        frac: i32,
        /// Largest representable value.
        max: f64,
    },
    /// A non-zero coefficient that rounds to zero.
    #[error(
        "{block}.{name} = {value:e} quantizes to zero in {format}: give it more fraction bits"
    )]
    CoefficientZero {
        /// The block.
        block: &'static str,
        /// The coefficient.
        name: &'static str,
        /// Its value.
        value: f64,
        /// The format.
        format: Format,
    },
    /// An exact intermediate too wide for the model's 128-bit carrier.
    #[error("{block} {node}: {source}")]
    Intermediate {
        /// The block.
        block: &'static str,
        /// The node.
        node: &'static str,
        /// Why.
        source: FxError,
    },
}

/// Refuses the first unsigned format of `formats` (field name, format) of `block`: every
/// signal of the loop is signed.
pub(crate) fn require_signed(
    block: &'static str,
    formats: &[(&'static str, Format)],
) -> Result<(), PlanError> {
    match formats.iter().find(|(_, format)| !format.signed) {
        Some((field, format)) => Err(field_error(block, field, format, "a signed format")),
        None => Ok(()),
    }
}

/// A [`PlanError::Field`].
pub(crate) fn field_error(
    block: &'static str,
    field: &'static str,
    value: impl fmt::Display,
    allowed: impl Into<String>,
) -> PlanError {
    PlanError::Field {
        block,
        field,
        value: value.to_string(),
        allowed: allowed.into(),
    }
}

pub(crate) fn intermediate(
    block: &'static str,
    node: &'static str,
) -> impl Fn(FxError) -> PlanError {
    move |source| PlanError::Intermediate {
        block,
        node,
        source,
    }
}

/// A declared quantization point: an exact value of format `from` rounded with `rounding`
/// into `to`, wrapped or saturated with `overflow`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Point {
    /// Format of the exact value that arrives.
    pub from: Format,
    /// Declared format it is quantized into.
    pub to: Format,
    /// Rounding of the dropped fraction bits.
    pub rounding: Rounding,
    /// Handling of values outside `to`.
    pub overflow: Overflow,
}

impl Point {
    /// A point from `from` into `to`, refused (naming `block.field`) unless it drops between 0
    /// and `from.width − 1` fraction bits, as `gyrofx_quantize` requires.
    pub(crate) fn new(
        block: &'static str,
        field: &'static str,
        from: Format,
        to: Format,
        rounding: Rounding,
        overflow: Overflow,
    ) -> Result<Point, PlanError> {
        let shift = from.frac - to.frac;
        if shift < 0 || shift >= from.width as i32 {
            return Err(field_error(
                block,
                field,
                to,
                format!(
                    "fraction bits from {} to {} (the exact value here is {from})",
                    from.frac - from.width as i32 + 1,
                    from.frac
                ),
            ));
        }
        Ok(Point {
            from,
            to,
            rounding,
            overflow,
        })
    }

    /// The counting quantizer of this point.
    pub fn quantizer(&self) -> Quantizer {
        Quantizer::new(self.from.frac, self.to, self.rounding, self.overflow)
    }

    /// Largest rounding error of this point, in real units (`u · 2^−to.frac`, `u` = 1/2 for
    /// the round-to-nearest modes, 1 for the directed ones).
    pub fn max_error(&self) -> f64 {
        self.rounding.max_error_lsb() * self.to.lsb()
    }
}

impl fmt::Display for Point {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "{} -> {} ({}/{})",
            self.from, self.to, self.rounding, self.overflow
        )
    }
}

/// A coefficient quantized once, offline: round to nearest (ties to even), never wrapping.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Coefficient {
    /// The designed value.
    pub value: f64,
    /// Its format.
    pub format: Format,
    /// Its code.
    pub code: i128,
}

impl Coefficient {
    /// The quantized value.
    pub fn quantized(&self) -> f64 {
        self.format.to_f64(self.code)
    }
}

/// Resolves `rule` for the values `values` of coefficient `name` and quantizes them (nearest,
/// ties to even). A value that does not fit is an error naming it, its value and the bits it
/// needs; a non-zero value that rounds to zero is an error.
pub(crate) fn quantize_coefficients(
    block: &'static str,
    name: &'static str,
    values: &[f64],
    rule: CoefficientFormat,
) -> Result<Vec<Coefficient>, PlanError> {
    if let Some(bad) = values.iter().find(|v| !v.is_finite()) {
        return Err(field_error(block, name, bad, "a finite number"));
    }
    let format = match rule {
        CoefficientFormat::Fixed(format) => format,
        CoefficientFormat::Auto { width } => crate::fx::fitting_format(values, width)
            .map_err(|_| field_error(block, name, width, "a coefficient width of 1..=64 bits"))?,
    };
    if !format.signed {
        return Err(field_error(
            block,
            name,
            format,
            "a signed coefficient format",
        ));
    }
    values
        .iter()
        .map(|&value| {
            let q = from_f64(value, format, Rounding::Convergent, Overflow::Saturate)
                .map_err(|_| field_error(block, name, value, "a finite number"))?;
            if q.overflowed {
                let wide = Format::intermediate(true, 128, format.frac).unwrap_or(format);
                let unbounded = from_f64(value, wide, Rounding::Convergent, Overflow::Saturate)
                    .map(|u| u.code)
                    .unwrap_or(i128::MAX);
                return Err(PlanError::CoefficientOverflow {
                    block,
                    name,
                    value,
                    format,
                    bits_needed: crate::kf::signed_bits_needed(unbounded),
                    frac: format.frac,
                    max: format.max_value(),
                });
            }
            if q.code == 0 && value != 0.0 {
                return Err(PlanError::CoefficientZero {
                    block,
                    name,
                    value,
                    format,
                });
            }
            Ok(Coefficient {
                value,
                format,
                code: q.code,
            })
        })
        .collect()
}

/// One Verilog parameter (VHDL generic) of a block's RTL: its name and integer value.
pub type RtlParameter = (&'static str, i128);

/// The RTL parameters the modes of a point imply: `ROUNDING` and `SATURATE`.
pub(crate) fn mode_parameters(rounding: Rounding, overflow: Overflow) -> [RtlParameter; 2] {
    [
        ("ROUNDING", i128::from(rounding.rtl_code())),
        ("SATURATE", i128::from(overflow.rtl_code())),
    ]
}

/// `2^-52 · magnitude`: one f64 rounding of a value of this magnitude, with a factor 2 of
/// margin (an f64 rounding is at most half an ulp, `2^-53` relative).
pub(crate) fn f64_rounding(magnitude: f64) -> f64 {
    crate::fx::pow2(-52) * magnitude
}

#[cfg(test)]
mod tests;
