//! `[kf]`: the Kalman filter's design (method, bandwidths, noise model, Riccati stopping rule)
//! and formats, validated into [`KfSettings`], from which the job designs the gains and builds
//! the model's plan.

use serde::{Deserialize, Serialize};

use gyrofx_model::fx::{CoefficientFormat, Format, Overflow, Rounding};
use gyrofx_model::kf::design::{Convergence, Method};

use crate::config::check::{parse_format, positive, width};
use crate::error::{Error, Result};

/// `[kf]`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct KfConfig {
    /// `direct` or `paper`.
    pub method: String,
    /// One ROM entry per bandwidth, Hz.
    pub bandwidths_hz: Vec<f64>,
    /// ARW of the design's noise model, °/√h.
    pub arw_deg_per_sqrt_h: f64,
    /// RRW of the design's noise model, °/h/√h.
    pub rrw_deg_per_h_per_sqrt_h: f64,
    /// Riccati tolerance (relative gain change).
    pub tolerance: f64,
    /// Riccati iteration limit.
    pub max_iterations: u64,
    /// Input format (ADC, gyro samples, calibrated outputs).
    pub input_format: String,
    /// State format.
    pub state_format: String,
    /// Output format.
    pub output_format: String,
    /// Coefficient width for automatic formats.
    pub coefficient_width: u32,
    /// Explicit g1 format.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub g1_format: Option<String>,
    /// Explicit g2 format.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub g2_format: Option<String>,
}

/// The KF settings, validated and typed.
#[derive(Clone, Debug, PartialEq)]
pub struct KfSettings {
    /// Discretisation.
    pub method: Method,
    /// Bandwidths, Hz.
    pub bandwidths_hz: Vec<f64>,
    /// Riccati stopping rule.
    pub convergence: Convergence,
    /// Input format.
    pub input: Format,
    /// State format.
    pub state: Format,
    /// Output format.
    pub output: Format,
    /// Coefficient format rules.
    pub coefficients: [CoefficientFormat; 2],
    /// Rounding.
    pub rounding: Rounding,
    /// Overflow.
    pub overflow: Overflow,
}

impl KfConfig {
    /// Checks the section and returns the KF's settings: each bandwidth must lie below the
    /// Nyquist frequency of `fs_hz` (Hz, already checked by `[stimulus]`); every quantization
    /// point uses `rounding` and `overflow`.
    ///
    /// # Errors
    /// [`Error::Config`] naming the first bad field.
    pub fn validate(
        &self,
        fs_hz: f64,
        rounding: Rounding,
        overflow: Overflow,
    ) -> Result<KfSettings> {
        let method = self.method.parse().map_err(|_| {
            Error::config(
                "kf.method",
                format!("{:?}", self.method),
                "\"direct\" or \"paper\"",
            )
        })?;
        if self.bandwidths_hz.is_empty() || self.bandwidths_hz.len() > 256 {
            return Err(Error::config(
                "kf.bandwidths_hz",
                format!("{:?}", self.bandwidths_hz),
                "a list of 1 to 256 bandwidths in Hz",
            ));
        }
        for (i, bw) in self.bandwidths_hz.iter().enumerate() {
            if !(bw.is_finite() && *bw > 0.0 && *bw < fs_hz / 2.0) {
                return Err(Error::config(
                    format!("kf.bandwidths_hz[{i}]"),
                    bw,
                    format!("0 < bandwidth < fs/2 = {} Hz", fs_hz / 2.0),
                ));
            }
        }
        positive("kf.arw_deg_per_sqrt_h", self.arw_deg_per_sqrt_h)?;
        positive("kf.rrw_deg_per_h_per_sqrt_h", self.rrw_deg_per_h_per_sqrt_h)?;
        positive("kf.tolerance", self.tolerance)?;
        if self.max_iterations == 0 {
            return Err(Error::config("kf.max_iterations", 0, "at least 1"));
        }
        let coefficient = |field: &str, explicit: &Option<String>| -> Result<CoefficientFormat> {
            match explicit {
                Some(text) => Ok(CoefficientFormat::Fixed(parse_format(field, text)?)),
                None => width("kf.coefficient_width", self.coefficient_width),
            }
        };
        Ok(KfSettings {
            method,
            bandwidths_hz: self.bandwidths_hz.clone(),
            convergence: Convergence {
                tolerance: self.tolerance,
                max_iterations: self.max_iterations,
            },
            input: parse_format("kf.input_format", &self.input_format)?,
            state: parse_format("kf.state_format", &self.state_format)?,
            output: parse_format("kf.output_format", &self.output_format)?,
            coefficients: [
                coefficient("kf.g1_format", &self.g1_format)?,
                coefficient("kf.g2_format", &self.g2_format)?,
            ],
            rounding,
            overflow,
        })
    }
}

#[cfg(test)]
mod tests {
    use crate::config::assert_refused;

    #[test]
    fn bad_kf_values_name_field_value_and_what_is_allowed() {
        assert_refused(&[
            (
                "[kf]\nstate_format = \"s0.3\"",
                "kf.state_format = \"s0.3\"",
                "1..=64",
            ),
            (
                "[kf]\noutput_format = \"s65.3\"",
                "kf.output_format = \"s65.3\"",
                "1..=64",
            ),
            (
                "[kf]\ninput_format = \"q24.14\"",
                "kf.input_format = \"q24.14\"",
                "s18.16",
            ),
            (
                "[kf]\narw_deg_per_sqrt_h = -1.0",
                "kf.arw_deg_per_sqrt_h = -1",
                "> 0",
            ),
            (
                "[kf]\nrrw_deg_per_h_per_sqrt_h = 0.0",
                "kf.rrw_deg_per_h_per_sqrt_h = 0",
                "> 0",
            ),
            (
                "[kf]\nbandwidths_hz = [10.0, 150.0]",
                "kf.bandwidths_hz[1] = 150",
                "fs/2 = 100",
            ),
            (
                "[kf]\ncoefficient_width = 0",
                "kf.coefficient_width = 0",
                "1..=64",
            ),
        ]);
    }
}
