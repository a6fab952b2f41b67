//! `[estimator]`: the bias estimator's formats and widths, validated into the model's
//! [`EstimatorSpec`].

use serde::{Deserialize, Serialize};

use gyrofx_model::estimator::Spec as EstimatorSpec;
use gyrofx_model::fx::{Format, Overflow, Rounding};
use gyrofx_model::sequencer::Schedule;

use crate::config::check::{parse_format, width};
use crate::error::{Error, Result};

/// `[estimator]`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct EstimatorConfig {
    /// r.
    pub rate_order: usize,
    /// Mean format.
    pub mean_format: String,
    /// Bias format.
    pub bias_format: String,
    /// Gain width.
    pub gain_width: u32,
    /// Reciprocal width.
    pub reciprocal_width: u32,
    /// Smoothing shift.
    pub smoothing_shift: u32,
}

impl EstimatorConfig {
    /// Checks the section and returns the estimator's spec: it runs on `schedule` (from
    /// `[sequencer]`), reads and writes samples in `input` (the KF's input format: the estimator
    /// calibrates what the KF filters) and quantizes with `rounding` and `overflow`.
    ///
    /// # Errors
    /// [`Error::Config`] naming the first bad field.
    pub fn validate(
        &self,
        schedule: Schedule,
        input: Format,
        rounding: Rounding,
        overflow: Overflow,
    ) -> Result<EstimatorSpec> {
        let spec = EstimatorSpec {
            schedule,
            rate_order: self.rate_order,
            input,
            mean: parse_format("estimator.mean_format", &self.mean_format)?,
            bias: parse_format("estimator.bias_format", &self.bias_format)?,
            calibrated: input,
            gain: width("estimator.gain_width", self.gain_width)?,
            reciprocal: width("estimator.reciprocal_width", self.reciprocal_width)?,
            smoothing_shift: self.smoothing_shift,
            rounding,
            overflow,
        };
        if self.rate_order > 8 {
            return Err(Error::config(
                "estimator.rate_order",
                self.rate_order,
                "0..=8",
            ));
        }
        if self.smoothing_shift > 32 {
            return Err(Error::config(
                "estimator.smoothing_shift",
                self.smoothing_shift,
                "0..=32",
            ));
        }
        Ok(spec)
    }
}

#[cfg(test)]
mod tests {
    use crate::config::assert_refused;

    #[test]
    fn bad_estimator_values_name_field_value_and_what_is_allowed() {
        assert_refused(&[
            (
                "[estimator]\nmean_format = \"x\"",
                "estimator.mean_format = \"x\"",
                "s18.16",
            ),
            (
                "[estimator]\nrate_order = 9",
                "estimator.rate_order = 9",
                "0..=8",
            ),
        ]);
    }
}
