//! [`Plan`]: every format and ROM word of the bias estimator and calibration, resolved once.

use crate::fx::{from_f64, CoefficientFormat, Format, FxError, Overflow, Rounding};
use crate::sequencer::{Schedule, ScheduleError};

use super::design::{bias_rows, DesignError};

/// What the config specifies; [`Plan::new`] validates and resolves it.
#[derive(Clone, Debug, PartialEq)]
pub struct Spec {
    /// The sequencer's schedule.
    pub schedule: Schedule,
    /// `r`: order of the rate polynomial over a window (0 = constant rate).
    pub rate_order: usize,
    /// Format of the gyro samples `y_A`, `y_B` (°/s).
    pub input: Format,
    /// Format of the interval means (°/s).
    pub mean: Format,
    /// Format of the bias estimates (°/s).
    pub bias: Format,
    /// Format of the calibrated and combined outputs (°/s): the KF's input.
    pub calibrated: Format,
    /// Format rule of the least-squares gains (one format for all).
    pub gain: CoefficientFormat,
    /// Format rule of the reciprocal `1/(L − M)` of the valid count.
    pub reciprocal: CoefficientFormat,
    /// Smoothing `b ← b + 2^-s (b_new − b)`; 0 = none.
    pub smoothing_shift: u32,
    /// Rounding at every quantization point.
    pub rounding: Rounding,
    /// Overflow handling at every quantization point.
    pub overflow: Overflow,
}

/// Errors of planning the estimator.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum PlanError {
    /// The schedule is invalid.
    #[error("sequencer: {0}")]
    Schedule(#[from] ScheduleError),
    /// The least-squares design is impossible.
    #[error("{0}")]
    Design(#[from] DesignError),
    /// A coefficient that does not fit its explicit format.
    #[error("coefficient {name} = {value:e} does not fit {format} (largest {max:e})")]
    CoefficientOverflow {
        /// Which coefficient.
        name: String,
        /// Its value.
        value: f64,
        /// The format.
        format: Format,
        /// Largest representable value.
        max: f64,
    },
    /// A non-zero coefficient that rounds to zero.
    #[error(
        "coefficient {name} = {value:e} quantizes to zero in {format}: use more fraction bits"
    )]
    CoefficientZero {
        /// Which coefficient.
        name: String,
        /// Its value.
        value: f64,
        /// The format.
        format: Format,
    },
    /// A format or parameter the architecture does not allow.
    #[error("{field} = {value} is not allowed: {reason}")]
    Field {
        /// Which one.
        field: &'static str,
        /// Its value.
        value: String,
        /// What is allowed.
        reason: &'static str,
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

/// The resolved estimator.
///
/// | node | format | rule |
/// |------|--------|------|
/// | `acc_g = Σ y_g` over valid samples | [`Plan::accumulator`] | exact: input + ⌈log2 L⌉ bits |
/// | `m_g(i) = Q(acc_g · recip)` | [`Plan::mean`] | **quantized** |
/// | `b_new = Q(Σ G_j m_j)` | [`Plan::bias`] | **quantized** (exact sum of 2W products) |
/// | `b ← Q(b + 2^-s (b_new − b))` | [`Plan::bias`] | **quantized** (when s > 0) |
/// | `out_g = Q(y_g − p_g b_g)` | [`Plan::calibrated`] | **quantized** |
/// | `combined = Q((out_A + out_B)/2)` | [`Plan::calibrated`] | **quantized** (one valid: that one) |
#[derive(Clone, Debug, PartialEq)]
pub struct Plan {
    /// The schedule.
    pub schedule: Schedule,
    /// Rate-model order.
    pub rate_order: usize,
    /// Input format.
    pub input: Format,
    /// Accumulator format.
    pub accumulator: Format,
    /// Reciprocal format.
    pub reciprocal: Format,
    /// Reciprocal code (`1/(L − M)`, rounded to nearest even).
    pub reciprocal_code: i128,
    /// Mean format.
    pub mean: Format,
    /// Gain format.
    pub gain: Format,
    /// Least-squares gains of `bA` and `bB` over `[mA0, mB0, mA1, …]`, as designed.
    pub gains: [Vec<f64>; 2],
    /// Their codes: the estimator's coefficient ROM.
    pub rom: [Vec<i128>; 2],
    /// Format of the exact dot product `Σ G_j m_j`.
    pub dot: Format,
    /// Bias format.
    pub bias: Format,
    /// Calibrated / combined format.
    pub calibrated: Format,
    /// Smoothing shift.
    pub smoothing_shift: u32,
    /// Rounding.
    pub rounding: Rounding,
    /// Overflow.
    pub overflow: Overflow,
}

fn resolve(rule: CoefficientFormat, values: &[f64], name: &str) -> Result<Format, PlanError> {
    match rule {
        CoefficientFormat::Fixed(f) => Ok(f),
        CoefficientFormat::Auto { width } => {
            crate::fx::fitting_format(values, width).map_err(|source| PlanError::Intermediate {
                node: if name == "recip" {
                    "reciprocal"
                } else {
                    "gain"
                },
                source,
            })
        }
    }
}

fn quantize(name: String, value: f64, format: Format) -> Result<i128, PlanError> {
    let q = from_f64(value, format, Rounding::Convergent, Overflow::Saturate).map_err(|_| {
        PlanError::Field {
            field: "coefficient",
            value: value.to_string(),
            reason: "coefficients must be finite",
        }
    })?;
    if q.overflowed {
        return Err(PlanError::CoefficientOverflow {
            name,
            value,
            format,
            max: format.max_value(),
        });
    }
    if q.code == 0 && value.abs() > 1e-12 {
        return Err(PlanError::CoefficientZero {
            name,
            value,
            format,
        });
    }
    Ok(q.code)
}

impl Plan {
    /// Validates `spec`, designs `G`, quantizes the ROMs and derives every format.
    ///
    /// # Errors
    /// [`PlanError`] naming the parameter, coefficient or node.
    pub fn new(spec: &Spec) -> Result<Plan, PlanError> {
        spec.schedule.validate()?;
        if spec.smoothing_shift > 32 {
            return Err(PlanError::Field {
                field: "smoothing_shift",
                value: spec.smoothing_shift.to_string(),
                reason: "0..=32",
            });
        }
        for (field, f) in [
            ("input_format", spec.input),
            ("mean_format", spec.mean),
            ("bias_format", spec.bias),
            ("calibrated_format", spec.calibrated),
        ] {
            if !f.signed {
                return Err(PlanError::Field {
                    field,
                    value: f.to_string(),
                    reason: "the estimator's signals are signed: use an s-format",
                });
            }
        }
        let gains = bias_rows(&spec.schedule, spec.rate_order)?;
        // Exact zeros of G stay zero; tiny numerical residues are zeros too.
        let gains = gains.map(|row| {
            row.into_iter()
                .map(|g| if g.abs() < 1e-12 { 0.0 } else { g })
                .collect::<Vec<f64>>()
        });
        let all: Vec<f64> = gains.iter().flatten().copied().collect();
        let gain = resolve(spec.gain, &all, "gain")?;
        let names = ["gA", "gB"];
        let mut rom = [Vec::new(), Vec::new()];
        for r in 0..2 {
            for (j, g) in gains[r].iter().enumerate() {
                let which = if j % 2 == 0 { "mA" } else { "mB" };
                rom[r].push(quantize(
                    format!("{}[{which}{}]", names[r], j / 2),
                    *g,
                    gain,
                )?);
            }
        }
        let count = spec.schedule.valid_count();
        let inverse = 1.0 / count as f64;
        let reciprocal = resolve(spec.reciprocal, &[inverse], "recip")?;
        let reciprocal_code = quantize("1/(L-M)".into(), inverse, reciprocal)?;

        // Every quantization point only drops fraction bits (as the RTL's requantizer does).
        let checks = [
            (
                "mean_format",
                spec.mean,
                spec.input.frac + reciprocal.frac,
                "at most input + reciprocal fraction bits",
            ),
            (
                "bias_format",
                spec.bias,
                gain.frac + spec.mean.frac,
                "at most gain + mean fraction bits",
            ),
            (
                "calibrated_format",
                spec.calibrated,
                spec.input.frac.max(spec.bias.frac),
                "at most max(input, bias) fraction bits",
            ),
        ];
        for (field, format, limit, reason) in checks {
            if format.frac > limit {
                return Err(PlanError::Field {
                    field,
                    value: format.to_string(),
                    reason,
                });
            }
        }
        let node = |node: &'static str| move |source| PlanError::Intermediate { node, source };
        let count_bits = usize::BITS - (spec.schedule.interval_length).leading_zeros();
        let accumulator =
            Format::intermediate(true, spec.input.width + count_bits, spec.input.frac)
                .map_err(node("accumulator"))?;
        Format::product(accumulator, reciprocal).map_err(node("acc * recip"))?;
        let product = Format::product(gain, spec.mean).map_err(node("G * m"))?;
        let terms = 2 * spec.schedule.intervals;
        let term_bits = usize::BITS - (terms - 1).leading_zeros();
        let dot = Format::intermediate(true, product.width + term_bits, product.frac)
            .map_err(node("sum of G * m"))?;
        Ok(Plan {
            schedule: spec.schedule.clone(),
            rate_order: spec.rate_order,
            input: spec.input,
            accumulator,
            reciprocal,
            reciprocal_code,
            mean: spec.mean,
            gain,
            gains,
            rom,
            dot,
            bias: spec.bias,
            calibrated: spec.calibrated,
            smoothing_shift: spec.smoothing_shift,
            rounding: spec.rounding,
            overflow: spec.overflow,
        })
    }

    /// The quantized gains, as reals.
    pub fn quantized_gains(&self) -> [Vec<f64>; 2] {
        self.rom
            .clone()
            .map(|row| row.iter().map(|c| self.gain.to_f64(*c)).collect())
    }

    /// The quantized reciprocal, as a real.
    pub fn quantized_reciprocal(&self) -> f64 {
        self.reciprocal.to_f64(self.reciprocal_code)
    }

    /// Whether every gain is 0 or ±2^-n (a shift in hardware).
    pub fn gains_are_shifts(&self) -> bool {
        self.quantized_gains()
            .iter()
            .flatten()
            .all(|g| *g == 0.0 || libm::frexp(g.abs()).0 == 0.5)
    }

    /// Bound on `|b_fixed − b_float|` of either bias estimate, °/s, with both models fed the
    /// same samples and the same quantized gains and reciprocal: each mean is off by at most
    /// `u·q_mean`, so `Σ G_j m_j` by `Σ|G_j|·u·q_mean`, plus `u·q_bias` for its own rounding;
    /// smoothing `e ← (1 − 2^-s) e + 2^-s e_new + u q_bias` keeps it below
    /// `e_new + 2^s u q_bias`.
    pub fn bias_error_bound(&self) -> f64 {
        let u = self.rounding.max_error_lsb();
        let gains = self.quantized_gains();
        let l1 = gains
            .iter()
            .map(|row| row.iter().map(|g| g.abs()).sum::<f64>())
            .fold(0.0, f64::max);
        let new = l1 * u * self.mean.lsb() + u * self.bias.lsb();
        let smoothing = if self.smoothing_shift == 0 {
            0.0
        } else {
            crate::fx::pow2(self.smoothing_shift as i32) * u * self.bias.lsb()
        };
        new + smoothing
    }
}
