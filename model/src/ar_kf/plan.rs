//! [`Plan`]: the gain schedule of the AR(1) KF, quantized, and every format.

use crate::fx::{fitting_format, from_f64, Format, Overflow, Rounding};

/// What the AR(1) KF is asked to be.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Spec {
    /// `φ` (= `A`), `|φ| < 1`.
    pub phi: f64,
    /// `Q = σ_a²`, > 0 (units of the signal, squared).
    pub process_variance: f64,
    /// `R`, > 0.
    pub measurement_variance: f64,
    /// Relative gain change at which the schedule stops.
    pub tolerance: f64,
    /// Most schedule entries (the ROM depth).
    pub max_entries: usize,
    /// Format of `z`.
    pub input: Format,
    /// Format of `x̂` (`frac ≥ input.frac`, so `x̂0 = z0` is exact).
    pub state: Format,
    /// Format of the output.
    pub output: Format,
    /// Width of the `a` and `K` codes (fraction bits chosen to fit the largest of each).
    pub coefficient_width: u32,
    /// Rounding at both quantizers.
    pub rounding: Rounding,
    /// Overflow at both quantizers.
    pub overflow: Overflow,
}

/// A refused spec.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum PlanError {
    /// A parameter out of range.
    #[error("ar_kf.{field} = {value} is not allowed: {allowed}")]
    Field {
        /// Which.
        field: &'static str,
        /// Its value.
        value: String,
        /// What is allowed.
        allowed: &'static str,
    },
}

fn field(field: &'static str, value: impl ToString, allowed: &'static str) -> PlanError {
    PlanError::Field {
        field,
        value: value.to_string(),
        allowed,
    }
}

/// The gains `K_1, K_2, …` of the filter from `P0 = 0`, until the relative change is at most
/// `tolerance` or there are `max_entries` of them (pure arithmetic: the same on every platform).
pub fn schedule(
    phi: f64,
    process_variance: f64,
    measurement_variance: f64,
    tolerance: f64,
    max_entries: usize,
) -> Vec<f64> {
    let mut p = 0.0;
    let mut gains: Vec<f64> = Vec::new();
    while gains.len() < max_entries {
        let predicted = phi * phi * p + process_variance;
        let gain = predicted / (predicted + measurement_variance);
        p = (1.0 - gain) * predicted;
        let settled = gains
            .last()
            .is_some_and(|last| (gain - last).abs() <= tolerance * gain);
        gains.push(gain);
        if settled {
            break;
        }
    }
    gains
}

/// The AR(1) KF's schedule and formats.
#[derive(Clone, Debug, PartialEq)]
pub struct Plan {
    /// `φ`.
    pub phi: f64,
    /// Designed gains `K_k` (f64).
    pub gains: Vec<f64>,
    /// Format of the `a` codes.
    pub a_format: Format,
    /// Format of the `K` codes.
    pub k_format: Format,
    /// `(a_k, K_k)` codes, one per schedule entry; the last holds for every later sample.
    pub rom: Vec<[i128; 2]>,
    /// Format of `z`.
    pub input: Format,
    /// Format of `x̂`.
    pub state: Format,
    /// Format of the output.
    pub output: Format,
    /// Fraction bits of the exact `a·x̂ + K·z`.
    pub sum_frac: i32,
    /// Rounding.
    pub rounding: Rounding,
    /// Overflow.
    pub overflow: Overflow,
}

impl Plan {
    /// Designs the schedule and resolves the formats.
    ///
    /// # Errors
    /// [`PlanError::Field`] for `|φ| ≥ 1`, variances ≤ 0 or not finite, a tolerance ≤ 0, no
    /// schedule entries, a state with fewer fraction bits than the input, a coefficient width
    /// outside 2..=64, or a quantized `|a| ≥ 1`.
    pub fn new(spec: &Spec) -> Result<Plan, PlanError> {
        if !(spec.phi.is_finite() && spec.phi.abs() < 1.0) {
            return Err(field(
                "phi",
                spec.phi,
                "-1 < phi < 1 (a stationary AR(1) model)",
            ));
        }
        for (name, value) in [
            ("process_variance", spec.process_variance),
            ("measurement_variance", spec.measurement_variance),
            ("tolerance", spec.tolerance),
        ] {
            if !(value.is_finite() && value > 0.0) {
                return Err(field(name, value, "a finite number > 0"));
            }
        }
        if spec.max_entries == 0 {
            return Err(field("max_entries", 0, "at least 1"));
        }
        if spec.state.frac < spec.input.frac {
            return Err(field(
                "state_format",
                spec.state,
                "at least the input's fraction bits (x̂0 = z0 must be exact)",
            ));
        }
        if !(2..=64).contains(&spec.coefficient_width) {
            return Err(field(
                "coefficient_width",
                spec.coefficient_width,
                "2..=64 bits",
            ));
        }
        let gains = schedule(
            spec.phi,
            spec.process_variance,
            spec.measurement_variance,
            spec.tolerance,
            spec.max_entries,
        );
        let a: Vec<f64> = gains.iter().map(|k| (1.0 - k) * spec.phi).collect();
        let a_format = fitting_format(&a, spec.coefficient_width)
            .map_err(|_| field("coefficient_width", spec.coefficient_width, "2..=64 bits"))?;
        let k_format = fitting_format(&gains, spec.coefficient_width)
            .map_err(|_| field("coefficient_width", spec.coefficient_width, "2..=64 bits"))?;
        let quantize = |value: f64, format: Format| {
            from_f64(value, format, Rounding::Convergent, Overflow::Saturate)
                .expect("finite")
                .code
        };
        let rom: Vec<[i128; 2]> = a
            .iter()
            .zip(&gains)
            .map(|(a, k)| [quantize(*a, a_format), quantize(*k, k_format)])
            .collect();
        if rom.iter().any(|[a, _]| a_format.to_f64(*a).abs() >= 1.0) {
            return Err(field(
                "coefficient_width",
                spec.coefficient_width,
                "enough bits that every quantized a = (1 - K) phi stays inside (-1, 1)",
            ));
        }
        let sum_frac = (a_format.frac + spec.state.frac).max(k_format.frac + spec.input.frac);
        // The exact a·x̂ + K·z, aligned, must fit an i128.
        let term_width = |width: u32, frac: i32| width as i32 + (sum_frac - frac);
        let sum_width = term_width(
            a_format.width + spec.state.width,
            a_format.frac + spec.state.frac,
        )
        .max(term_width(
            k_format.width + spec.input.width,
            k_format.frac + spec.input.frac,
        )) + 1;
        if sum_width > 127 {
            return Err(field(
                "state_format",
                spec.state,
                "formats whose exact a·x + K·z fits 127 bits",
            ));
        }
        Ok(Plan {
            phi: spec.phi,
            gains,
            a_format,
            k_format,
            rom,
            input: spec.input,
            state: spec.state,
            output: spec.output,
            sum_frac,
            rounding: spec.rounding,
            overflow: spec.overflow,
        })
    }

    /// The quantized `(a_k, K_k)` of schedule entry `entry`, as reals.
    pub fn quantized(&self, entry: usize) -> (f64, f64) {
        let [a, k] = self.rom[entry];
        (self.a_format.to_f64(a), self.k_format.to_f64(k))
    }

    /// Largest `|fixed − float|` in output LSB (same quantized coefficients, no overflow):
    /// `r_state·LSB_state / (1 − max|a|)` plus the output rounding.
    pub fn error_bound_lsb(&self) -> f64 {
        let largest_a = (0..self.rom.len())
            .map(|i| self.quantized(i).0.abs())
            .fold(0.0, f64::max);
        let state = self.rounding.max_error_lsb() * self.state.lsb() / (1.0 - largest_a);
        state / self.output.lsb() + self.rounding.max_error_lsb()
    }
}
