//! [`Plan`]: every format and every ROM word of the fixed-point KF, resolved once.
//!
//! The fixed model, the float model, the error bound and every writer read the plan; none of
//! them derives a format on its own.

use std::fmt;

pub use crate::fx::CoefficientFormat;
use crate::fx::{from_f64, Format, FxError, Overflow, Rounding};

/// What the user (or config) specifies; [`Plan::new`] validates and resolves it.
#[derive(Clone, Debug, PartialEq)]
pub struct Spec {
    /// Format of the input `z` (°/s).
    pub input: Format,
    /// Format of both state registers `x1`, `x2` (°/s); its extra fraction bits over the
    /// output are the guard bits.
    pub state: Format,
    /// Format of the output `rate_hat` (°/s).
    pub output: Format,
    /// Format rule for `g1` and for `g2`.
    pub coefficients: [CoefficientFormat; 2],
    /// Rounding at the state and output quantization points.
    pub rounding: Rounding,
    /// Overflow handling at the state and output quantization points.
    pub overflow: Overflow,
    /// Innovation gains `[g1, g2]`, one set per `bw_sel` value (ROM address order).
    pub gains: Vec<[f64; 2]>,
    /// A label for each set, used in messages and files (e.g. "10 Hz").
    pub labels: Vec<String>,
}

/// Errors of planning: each names the node or coefficient, its value and what is allowed.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum PlanError {
    /// A coefficient that overflows its (explicit) format.
    #[error("coefficient {name} for {label} = {value:e} does not fit {format}: it needs {bits_needed} bits at {frac} fraction bits (largest is {max:e})")]
    CoefficientOverflow {
        /// `g1` or `g2`.
        name: &'static str,
        /// Label of the ROM entry.
        label: String,
        /// Its value.
        value: f64,
        /// The format it must fit.
        format: Format,
        /// Signed width its code needs.
        bits_needed: u32,
        /// Fraction bits of the format.
        frac: i32,
        /// Largest representable value.
        max: f64,
    },
    /// A coefficient that rounds to zero in its format.
    #[error("coefficient {name} for {label} = {value:e} quantizes to zero in {format}: use more fraction bits (a wider coefficient) or a larger gain")]
    CoefficientZero {
        /// `g1` or `g2`.
        name: &'static str,
        /// Label of the ROM entry.
        label: String,
        /// Its value.
        value: f64,
        /// The format.
        format: Format,
    },
    /// The quantized `A = I − gH` has an eigenvalue outside the unit circle.
    #[error("quantized filter for {label} is unstable: A = I - gH has eigenvalues 1 and {eigenvalue} (|λ| must be <= 1) with g1 in {g1_format}, g2 in {g2_format}")]
    Unstable {
        /// Label of the ROM entry.
        label: String,
        /// The second eigenvalue `1 − (g1 + g2)` of the quantized matrix.
        eigenvalue: f64,
        /// Format of g1.
        g1_format: Format,
        /// Format of g2.
        g2_format: Format,
    },
    /// A format the architecture does not allow.
    #[error("{field} = {format} is not allowed: {reason}")]
    Format {
        /// Which format.
        field: &'static str,
        /// Its value.
        format: Format,
        /// What is allowed.
        reason: &'static str,
    },
    /// No ROM entries, or labels that do not match the entries.
    #[error("the coefficient ROM needs at least one gain set and one label per set (got {gains} sets, {labels} labels)")]
    RomShape {
        /// Gain sets given.
        gains: usize,
        /// Labels given.
        labels: usize,
    },
    /// A gain that is NaN or infinite.
    #[error("coefficient {name} for {label} = {value} is not finite")]
    NotFinite {
        /// `g1` or `g2`.
        name: &'static str,
        /// Label of the ROM entry.
        label: String,
        /// Its value.
        value: f64,
    },
    /// An intermediate too wide for the exact model.
    #[error("intermediate {node}: {source}")]
    Intermediate {
        /// The node.
        node: &'static str,
        /// Why.
        source: FxError,
    },
}

/// The resolved fixed-point KF: formats of every node and the coefficient ROM.
///
/// Nodes, in data-flow order (all exact until `x` and `rate_hat`):
///
/// | node | format | rule |
/// |------|--------|------|
/// | `z` | [`Plan::input`] | declared |
/// | `e = z − x1 − x2` | [`Plan::error`] | exact, at `state.frac` |
/// | `p_i = g_i · e` | [`Plan::product`]`[i]` | exact: widths and fractions add |
/// | `s_i = x_i + p_i` | [`Plan::sum`]`[i]` | exact, at `p_i`'s fraction |
/// | `x_i ← Q(s_i)` | [`Plan::state`] | **quantized**: rounding, overflow |
/// | `rate_hat = Q(x1)` | [`Plan::output`] | **quantized**: rounding, overflow |
#[derive(Clone, Debug, PartialEq)]
pub struct Plan {
    /// Input format.
    pub input: Format,
    /// State format.
    pub state: Format,
    /// Output format.
    pub output: Format,
    /// Resolved formats of `g1` and `g2`.
    pub coefficient: [Format; 2],
    /// Rounding at the quantization points.
    pub rounding: Rounding,
    /// Overflow handling at the quantization points.
    pub overflow: Overflow,
    /// Coefficient ROM: `[g1, g2]` codes per `bw_sel` address.
    pub rom: Vec<[i128; 2]>,
    /// The unquantized gains the ROM came from.
    pub gains: Vec<[f64; 2]>,
    /// Labels of the ROM entries.
    pub labels: Vec<String>,
    /// Format of the innovation `e`.
    pub error: Format,
    /// Formats of the products `g_i · e`.
    pub product: [Format; 2],
    /// Formats of the sums `x_i + g_i · e`.
    pub sum: [Format; 2],
}

/// Names of the two coefficients, in ROM order.
pub const COEFFICIENT_NAMES: [&str; 2] = ["g1", "g2"];

/// Signed bits needed to hold `code`.
pub fn signed_bits_needed(code: i128) -> u32 {
    let magnitude = if code < 0 { !code } else { code };
    128 - magnitude.leading_zeros() + 1
}

impl Plan {
    /// Validates `spec`, resolves the coefficient formats, quantizes the ROM (round to nearest,
    /// ties to even, never wrapping) and derives every intermediate format.
    ///
    /// # Errors
    /// [`PlanError`] naming the offending format or coefficient.
    pub fn new(spec: &Spec) -> Result<Plan, PlanError> {
        if spec.gains.is_empty() || spec.gains.len() != spec.labels.len() {
            return Err(PlanError::RomShape {
                gains: spec.gains.len(),
                labels: spec.labels.len(),
            });
        }
        for (field, format) in [
            ("input_format", spec.input),
            ("state_format", spec.state),
            ("output_format", spec.output),
        ] {
            if !format.signed {
                return Err(PlanError::Format {
                    field,
                    format,
                    reason: "the KF's signals are signed: use an s-format",
                });
            }
        }
        if spec.state.frac < spec.input.frac {
            return Err(PlanError::Format {
                field: "state_format",
                format: spec.state,
                reason: "the state needs at least the input's fraction bits (guard bits >= 0)",
            });
        }
        if spec.output.frac > spec.state.frac {
            return Err(PlanError::Format {
                field: "output_format",
                format: spec.output,
                reason: "the output cannot have more fraction bits than the state",
            });
        }
        for (label, gains) in spec.labels.iter().zip(&spec.gains) {
            for (name, value) in COEFFICIENT_NAMES.iter().zip(gains) {
                if !value.is_finite() {
                    return Err(PlanError::NotFinite {
                        name,
                        label: label.clone(),
                        value: *value,
                    });
                }
            }
        }
        let mut coefficient = [spec.input; 2];
        for i in 0..2 {
            let values: Vec<f64> = spec.gains.iter().map(|g| g[i]).collect();
            coefficient[i] = match spec.coefficients[i] {
                CoefficientFormat::Fixed(format) => format,
                CoefficientFormat::Auto { width } => crate::fx::fitting_format(&values, width)
                    .map_err(|source| PlanError::Intermediate {
                        node: COEFFICIENT_NAMES[i],
                        source,
                    })?,
            };
            if coefficient[i].frac < 0 {
                return Err(PlanError::Format {
                    field: COEFFICIENT_NAMES[i],
                    format: coefficient[i],
                    reason: "coefficients need fraction bits >= 0",
                });
            }
        }
        let mut rom = Vec::with_capacity(spec.gains.len());
        for (label, gains) in spec.labels.iter().zip(&spec.gains) {
            let mut codes = [0i128; 2];
            for i in 0..2 {
                codes[i] =
                    quantize_coefficient(COEFFICIENT_NAMES[i], label, gains[i], coefficient[i])?;
            }
            let s = coefficient[0].to_f64(codes[0]) + coefficient[1].to_f64(codes[1]);
            let eigenvalue = 1.0 - s;
            if eigenvalue.abs() > 1.0 {
                return Err(PlanError::Unstable {
                    label: label.clone(),
                    eigenvalue,
                    g1_format: coefficient[0],
                    g2_format: coefficient[1],
                });
            }
            rom.push(codes);
        }
        let node = |node: &'static str| move |source| PlanError::Intermediate { node, source };
        let z_aligned = Format::intermediate(
            true,
            spec.input.width + (spec.state.frac - spec.input.frac) as u32,
            spec.state.frac,
        )
        .map_err(node("z aligned to the state"))?;
        let z_minus_x1 = Format::sum(z_aligned, spec.state, true).map_err(node("z - x1"))?;
        let error = Format::sum(z_minus_x1, spec.state, true).map_err(node("e = z - x1 - x2"))?;
        let product = [
            Format::product(coefficient[0], error).map_err(node("g1 * e"))?,
            Format::product(coefficient[1], error).map_err(node("g2 * e"))?,
        ];
        let sum = [
            Format::sum(spec.state, product[0], false).map_err(node("x1 + g1 * e"))?,
            Format::sum(spec.state, product[1], false).map_err(node("x2 + g2 * e"))?,
        ];
        Ok(Plan {
            input: spec.input,
            state: spec.state,
            output: spec.output,
            coefficient,
            rounding: spec.rounding,
            overflow: spec.overflow,
            rom,
            gains: spec.gains.clone(),
            labels: spec.labels.clone(),
            error,
            product,
            sum,
        })
    }

    /// The quantized gains `[g1, g2]` of each ROM entry, as reals.
    pub fn quantized_gains(&self) -> Vec<[f64; 2]> {
        self.rom
            .iter()
            .map(|c| {
                [
                    self.coefficient[0].to_f64(c[0]),
                    self.coefficient[1].to_f64(c[1]),
                ]
            })
            .collect()
    }

    /// Eigenvalues of the quantized `A = I − gH` of ROM entry `sel`: exactly 1 (the direction
    /// `[1, −1]` that `H` cannot see), and `1 − (g1 + g2)`.
    pub fn eigenvalues(&self, sel: usize) -> [f64; 2] {
        let g = self.quantized_gains()[sel];
        [1.0, 1.0 - (g[0] + g[1])]
    }

    /// Bits of the `bw_sel` port: enough to address every ROM entry, at least 1.
    pub fn select_width(&self) -> u32 {
        let n = self.rom.len() as u32;
        (32 - (n - 1).leading_zeros()).max(1)
    }

    /// Guard bits of the state over the output: `state.frac − output.frac`.
    pub fn guard_bits(&self) -> i32 {
        self.state.frac - self.output.frac
    }
}

impl fmt::Display for Plan {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "z {} -> e {} -> g1*e {}, g2*e {} -> x {} ({}/{}) -> rate_hat {}; g1 {}, g2 {}",
            self.input,
            self.error,
            self.product[0],
            self.product[1],
            self.state,
            self.rounding,
            self.overflow,
            self.output,
            self.coefficient[0],
            self.coefficient[1]
        )
    }
}

fn quantize_coefficient(
    name: &'static str,
    label: &str,
    value: f64,
    format: Format,
) -> Result<i128, PlanError> {
    let q = from_f64(value, format, Rounding::Convergent, Overflow::Saturate).map_err(|_| {
        PlanError::NotFinite {
            name,
            label: label.to_string(),
            value,
        }
    })?;
    if q.overflowed {
        let unbounded = from_f64(
            value,
            Format::intermediate(true, 128, format.frac).unwrap_or(format),
            Rounding::Convergent,
            Overflow::Saturate,
        )
        .map(|u| u.code)
        .unwrap_or(i128::MAX);
        return Err(PlanError::CoefficientOverflow {
            name,
            label: label.to_string(),
            value,
            format,
            bits_needed: signed_bits_needed(unbounded),
            frac: format.frac,
            max: format.max_value(),
        });
    }
    if q.code == 0 && value != 0.0 {
        return Err(PlanError::CoefficientZero {
            name,
            label: label.to_string(),
            value,
            format,
        });
    }
    Ok(q.code)
}
