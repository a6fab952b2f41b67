//! `[mean_filter]`: the mean filter's window, threshold and formats, validated into the model's
//! [`MeanFilterSpec`].

use serde::{Deserialize, Serialize};

use gyrofx_model::fx::{Format, Overflow, Rounding};
use gyrofx_model::mean_filter::Spec as MeanFilterSpec;

use crate::config::check::parse_format;
use crate::error::Result;

/// `[mean_filter]`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MeanFilterConfig {
    /// L, samples per block.
    pub window: u32,
    /// r, °/s.
    pub threshold_dps: f64,
    /// Output format.
    pub output_format: String,
    /// Width of the 1/n codes.
    pub reciprocal_width: u32,
}

impl MeanFilterConfig {
    /// Checks the output format and returns the mean filter's spec: its input is in `input`
    /// (the KF's input format) and it quantizes with `rounding` and `overflow`. The window,
    /// threshold and reciprocal width are checked by the model's plan.
    ///
    /// # Errors
    /// [`Error::Config`](crate::Error::Config) for a bad output format.
    pub fn validate(
        &self,
        input: Format,
        rounding: Rounding,
        overflow: Overflow,
    ) -> Result<MeanFilterSpec> {
        Ok(MeanFilterSpec {
            input,
            output: parse_format("mean_filter.output_format", &self.output_format)?,
            window: self.window,
            threshold_dps: self.threshold_dps,
            reciprocal_width: self.reciprocal_width,
            rounding,
            overflow,
        })
    }
}

#[cfg(test)]
mod tests {
    use crate::config::assert_refused;

    #[test]
    fn a_bad_output_format_names_field_value_and_what_is_allowed() {
        assert_refused(&[(
            "[mean_filter]\noutput_format = \"q\"",
            "mean_filter.output_format = \"q\"",
            "s18.16",
        )]);
    }
}
