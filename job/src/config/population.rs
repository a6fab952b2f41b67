//! `[population]`: how each resonator and front-end parameter spreads over a population of
//! gyro pairs (`gyrofx population`). Optional; the default config has none.
//!
//! ```toml
//! [population.resonator]
//! q_drive = { distribution = "normal", std = 0.05, relative = true }   # 5 % of the nominal
//! stiffness_angle_deg = { distribution = "uniform", low = -1.0, high = 1.0 }
//! phase_error_deg = { distribution = "values", values = [0.5, 1.0, 1.5] }
//! [population.front_end]
//! pickoff_gain_x_v_per_m = { distribution = "normal", std = 0.01, relative = true }
//! ```
//!
//! Each gyro of a member draws each parameter on its own, around its own nominal value (the
//! config's `[resonator_a]`/`[resonator_b]` and `[front_end]`); see
//! `gyrofx_model::population::draw` for the order of the draws.

use std::collections::BTreeMap;

use serde::{Deserialize, Serialize};

use gyrofx_model::population::distribution::{Distribution, Spread};
use gyrofx_model::population::draw::{Parameter, Section};

use super::check::{finite, non_negative};
use crate::error::{Error, Result};

/// Most values a `values` list may hold.
pub const MAX_VALUES: usize = 10_000;

/// `[population]`.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PopulationConfig {
    /// Spreads of `[resonator_a]`/`[resonator_b]`'s keys, by key.
    #[serde(default, skip_serializing_if = "BTreeMap::is_empty")]
    pub resonator: BTreeMap<String, SpreadConfig>,
    /// Spreads of `[front_end]`'s scalars (`pickoff_gain_x_v_per_m` and `…_y_…` for the two
    /// entries of `pickoff_gain_v_per_m`), by key.
    #[serde(default, skip_serializing_if = "BTreeMap::is_empty")]
    pub front_end: BTreeMap<String, SpreadConfig>,
}

/// One parameter's spread as written.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SpreadConfig {
    /// `normal`, `uniform` or `values`.
    pub distribution: String,
    /// Normal: the mean (default: the nominal value, or 0 when relative).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub mean: Option<f64>,
    /// Normal: the standard deviation.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub std: Option<f64>,
    /// Uniform: the lower end.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub low: Option<f64>,
    /// Uniform: the upper end.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub high: Option<f64>,
    /// Values: the list.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub values: Option<Vec<f64>>,
    /// Whether the drawn number is a fraction of the nominal value (parameter `v0 (1 + d)`).
    #[serde(default)]
    pub relative: bool,
}

impl PopulationConfig {
    /// Whether the section is empty (then it is left out of the resolved config).
    pub fn is_empty(&self) -> bool {
        self.resonator.is_empty() && self.front_end.is_empty()
    }

    /// The spreads, `[population.resonator]`'s then `[population.front_end]`'s, each in key
    /// order: the order of the draws and of `population.csv`'s columns.
    ///
    /// # Errors
    /// [`Error::Config`] naming the first bad key, its value and what is allowed.
    pub fn spreads(&self) -> Result<Vec<(Parameter, Spread)>> {
        let mut out = Vec::new();
        for (section, name, table) in [
            (Section::Resonator, "resonator", &self.resonator),
            (Section::FrontEnd, "front_end", &self.front_end),
        ] {
            for (key, spread) in table {
                let field = format!("population.{name}.{key}");
                let parameter = Parameter::named(section, key).ok_or_else(|| {
                    Error::config(
                        &field,
                        "a spread",
                        format!(
                            "{key:?} is not a parameter of [population.{name}]; one of {}",
                            Parameter::names(section).join(", ")
                        ),
                    )
                })?;
                out.push((parameter, spread.validate(&field)?));
            }
        }
        Ok(out)
    }
}

impl SpreadConfig {
    /// The spread, checked; `field` names it in errors.
    fn validate(&self, field: &str) -> Result<Spread> {
        let present = [
            ("mean", self.mean.is_some()),
            ("std", self.std.is_some()),
            ("low", self.low.is_some()),
            ("high", self.high.is_some()),
            ("values", self.values.is_some()),
        ];
        let allowed: &[&str] = match self.distribution.as_str() {
            "normal" => &["mean", "std"],
            "uniform" => &["low", "high"],
            "values" => &["values"],
            other => {
                return Err(Error::config(
                    format!("{field}.distribution"),
                    format!("{other:?}"),
                    "one of normal, uniform, values",
                ))
            }
        };
        if let Some((key, _)) = present
            .iter()
            .find(|(key, set)| *set && !allowed.contains(key))
        {
            return Err(Error::config(
                format!("{field}.{key}"),
                "given",
                format!(
                    "a {} distribution takes {}",
                    self.distribution,
                    allowed.join(" and ")
                ),
            ));
        }
        let required = |key: &str, value: Option<f64>| {
            value.ok_or_else(|| {
                Error::config(
                    format!("{field}.{key}"),
                    "missing",
                    format!("a {} distribution needs {key}", self.distribution),
                )
            })
        };
        let distribution = match self.distribution.as_str() {
            "normal" => {
                let std = required("std", self.std)?;
                non_negative(&format!("{field}.std"), std)?;
                if let Some(mean) = self.mean {
                    finite(&format!("{field}.mean"), mean)?;
                }
                Distribution::Normal {
                    mean: self.mean,
                    std,
                }
            }
            "uniform" => {
                let (low, high) = (required("low", self.low)?, required("high", self.high)?);
                finite(&format!("{field}.low"), low)?;
                if !(high.is_finite() && high >= low) {
                    return Err(Error::config(
                        format!("{field}.high"),
                        high,
                        format!("a finite number >= low = {low}"),
                    ));
                }
                Distribution::Uniform { low, high }
            }
            _ => {
                let values = self.values.clone().unwrap_or_default();
                if values.is_empty() || values.len() > MAX_VALUES {
                    return Err(Error::config(
                        format!("{field}.values"),
                        format!("{} values", values.len()),
                        format!("a list of 1 to {MAX_VALUES} numbers"),
                    ));
                }
                for (i, v) in values.iter().enumerate() {
                    finite(&format!("{field}.values[{i}]"), *v)?;
                }
                Distribution::Values(values)
            }
        };
        Ok(Spread {
            distribution,
            relative: self.relative,
        })
    }
}

#[cfg(test)]
mod tests {
    use crate::config::{assert_refused, Config};

    #[test]
    fn spreads_are_read_in_section_and_key_order() {
        let config = Config::from_toml(
            "[population.resonator]\nq_sense = { distribution = \"uniform\", low = 150.0, high = 250.0 }\nq_drive = { distribution = \"normal\", std = 0.05, relative = true }\n[population.front_end]\ntemperature_k = { distribution = \"values\", values = [280.0, 320.0] }\n",
            "t",
        )
        .unwrap();
        config.validate().unwrap();
        let names: Vec<&str> = config
            .population
            .spreads()
            .unwrap()
            .iter()
            .map(|(p, _)| p.name())
            .collect();
        assert_eq!(names, ["q_drive", "q_sense", "temperature_k"]);
        // An empty section stays out of the resolved config (and so out of every manifest).
        assert!(!Config::embedded().to_toml().contains("population"));
        assert!(config.to_toml().contains("[population.resonator.q_drive]"));
        assert_eq!(
            Config::from_toml(&config.to_toml(), "round trip").unwrap(),
            config
        );
    }

    #[test]
    fn bad_spreads_name_field_value_and_what_is_allowed() {
        assert_refused(&[
            (
                "[population.resonator]\nq_drive = { distribution = \"gauss\", std = 1.0 }",
                "population.resonator.q_drive.distribution = \"gauss\"",
                "one of normal, uniform, values",
            ),
            (
                "[population.resonator]\nq_drv = { distribution = \"normal\", std = 1.0 }",
                "population.resonator.q_drv",
                "one of mass_kg, drive_frequency_hz",
            ),
            (
                "[population.front_end]\nq_drive = { distribution = \"normal\", std = 1.0 }",
                "population.front_end.q_drive",
                "pickoff_gain_x_v_per_m",
            ),
            (
                "[population.resonator]\nq_drive = { distribution = \"normal\" }",
                "population.resonator.q_drive.std = missing",
                "needs std",
            ),
            (
                "[population.resonator]\nq_drive = { distribution = \"normal\", std = -1.0 }",
                "population.resonator.q_drive.std = -1",
                ">= 0",
            ),
            (
                "[population.resonator]\nq_drive = { distribution = \"normal\", std = 1.0, low = 0.0 }",
                "population.resonator.q_drive.low",
                "takes mean and std",
            ),
            (
                "[population.resonator]\nq_drive = { distribution = \"uniform\", low = 2.0, high = 1.0 }",
                "population.resonator.q_drive.high = 1",
                ">= low = 2",
            ),
            (
                "[population.resonator]\nq_drive = { distribution = \"values\", values = [] }",
                "population.resonator.q_drive.values = 0 values",
                "a list of 1 to",
            ),
        ]);
        // Unknown keys of a spread are refused when the config is read.
        let err = Config::from_toml(
            "[population.resonator]\nq_drive = { distribution = \"normal\", std = 1.0, sigma = 2.0 }",
            "t",
        )
        .unwrap_err()
        .to_string();
        assert!(err.contains("sigma") && err.contains("population"), "{err}");
        let err = Config::from_toml("[population]\nmembers = 3\n", "t")
            .unwrap_err()
            .to_string();
        assert!(err.contains("members"), "{err}");
    }
}
