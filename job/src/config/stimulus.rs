//! `[stimulus]`: where the true rate Ω comes from, a synthetic scenario or a CSV column.

use std::path::PathBuf;

use serde::{Deserialize, Serialize};

use gyrofx_model::stimulus::Scenario;

use super::check::{finite, non_negative, positive};
use crate::error::{Error, Result};

/// `[stimulus]`: the true rate Ω.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct StimulusConfig {
    /// `synthetic` or `csv`.
    pub source: String,
    /// Sample rate, Hz.
    pub fs_hz: f64,
    /// `static`, `constant`, `sine`, `steps` or `ramp`.
    pub scenario: String,
    /// Constant rate, sine amplitude or step height, °/s.
    pub rate_dps: f64,
    /// Sine frequency, Hz.
    pub frequency_hz: f64,
    /// Step duration, s.
    pub period_s: f64,
    /// Ramp slope, °/s per s.
    pub slope_dps_per_s: f64,
    /// CSV file of the true rate (°/s), relative to the config file.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub csv_path: Option<PathBuf>,
    /// Column of the CSV file.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub csv_column: Option<String>,
}

/// Where the true rate comes from, validated.
#[derive(Clone, Debug, PartialEq)]
pub enum Source {
    /// A scenario.
    Synthetic(Scenario),
    /// A CSV file and column.
    Csv {
        /// Resolved path.
        path: PathBuf,
        /// Column name.
        column: String,
    },
}

impl StimulusConfig {
    /// Checks the section (the numbers first, then the scenario, then the source) and returns
    /// the source of the true rate.
    ///
    /// # Errors
    /// [`Error::Config`] naming the first bad field.
    pub fn validate(&self) -> Result<Source> {
        positive("stimulus.fs_hz", self.fs_hz)?;
        finite("stimulus.rate_dps", self.rate_dps)?;
        non_negative("stimulus.frequency_hz", self.frequency_hz)?;
        positive("stimulus.period_s", self.period_s)?;
        finite("stimulus.slope_dps_per_s", self.slope_dps_per_s)?;
        let scenario = match self.scenario.as_str() {
            "static" => Scenario::Static,
            "constant" => Scenario::Constant {
                rate_dps: self.rate_dps,
            },
            "sine" => Scenario::Sine {
                amplitude_dps: self.rate_dps,
                frequency_hz: self.frequency_hz,
            },
            "steps" => Scenario::Steps {
                rate_dps: self.rate_dps,
                period_s: self.period_s,
            },
            "ramp" => Scenario::Ramp {
                slope_dps_per_s: self.slope_dps_per_s,
            },
            other => {
                return Err(Error::config(
                    "stimulus.scenario",
                    format!("{other:?}"),
                    "one of \"static\", \"constant\", \"sine\", \"steps\", \"ramp\"",
                ))
            }
        };
        match self.source.as_str() {
            "synthetic" => Ok(Source::Synthetic(scenario)),
            "csv" => Ok(Source::Csv {
                path: self.csv_path.clone().ok_or_else(|| {
                    Error::config(
                        "stimulus.csv_path",
                        "(missing)",
                        "a CSV file path when source = \"csv\"",
                    )
                })?,
                column: self
                    .csv_column
                    .clone()
                    .unwrap_or_else(|| "rate_dps".to_string()),
            }),
            other => Err(Error::config(
                "stimulus.source",
                format!("{other:?}"),
                "\"synthetic\" or \"csv\"",
            )),
        }
    }
}

#[cfg(test)]
mod tests {
    use crate::config::assert_refused;

    #[test]
    fn bad_stimulus_values_name_field_value_and_what_is_allowed() {
        assert_refused(&[
            ("[stimulus]\nfs_hz = 0.0", "stimulus.fs_hz = 0", "> 0"),
            ("[stimulus]\nfs_hz = -200.0", "stimulus.fs_hz = -200", "> 0"),
            (
                "[stimulus]\nscenario = \"chirp\"",
                "stimulus.scenario = \"chirp\"",
                "ramp",
            ),
            (
                "[stimulus]\nsource = \"csv\"",
                "stimulus.csv_path = (missing)",
                "CSV",
            ),
        ]);
    }
}
