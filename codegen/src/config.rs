//! The TOML config: the annotated embedded default, overlays, and validation into typed values.
//!
//! A user config is a partial overlay of the embedded default ([`DEFAULT_TOML`]): keys it
//! leaves out keep their default. Unknown keys, wrong types and out-of-range values are errors
//! naming the key, the value and what is allowed.

use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

use gyrofx_model::fx::{Format, Overflow, Rounding};
use gyrofx_model::kf::design::{Convergence, Method};
use gyrofx_model::kf::CoefficientFormat;
use gyrofx_model::stimulus::Scenario;

use crate::error::{Error, Result};

/// Largest `samples`: the vector set and its files are built in memory.
pub const MAX_SAMPLES: usize = 20_000_000;

/// The embedded, annotated default config (`gyrofx init` prints it).
pub const DEFAULT_TOML: &str = include_str!("default.toml");

/// The whole config, as read (after overlaying the default).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Config {
    /// Seed of every random stream.
    pub seed: u64,
    /// Stimulus samples in the vector set.
    pub samples: usize,
    /// The stimulus source.
    pub stimulus: StimulusConfig,
    /// The Kalman filter.
    pub kf: KfConfig,
}

/// `[stimulus]`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct StimulusConfig {
    /// `synthetic` or `csv`.
    pub source: String,
    /// Sample rate, Hz.
    pub fs_hz: f64,
    /// `static`, `constant` or `sine`.
    pub scenario: String,
    /// Constant rate or sine amplitude, °/s.
    pub rate_dps: f64,
    /// Sine frequency, Hz.
    pub frequency_hz: f64,
    /// Bias at t = 0, °/s.
    pub initial_bias_dps: f64,
    /// Angle random walk, °/√h.
    pub arw_deg_per_sqrt_h: f64,
    /// Rate random walk, °/h/√h.
    pub rrw_deg_per_h_per_sqrt_h: f64,
    /// CSV file of rates (°/s), relative to the config file.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub csv_path: Option<PathBuf>,
    /// Column of the CSV file.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub csv_column: Option<String>,
}

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
    /// Input format.
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
    /// Rounding mode name.
    pub rounding: String,
    /// Overflow mode name.
    pub overflow: String,
}

/// Where the stimulus comes from, validated.
#[derive(Clone, Debug, PartialEq)]
pub enum Source {
    /// The single-gyro simulation.
    Synthetic(Scenario),
    /// A CSV file and column.
    Csv {
        /// Resolved path.
        path: PathBuf,
        /// Column name.
        column: String,
    },
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
    /// Input, state, output formats.
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

/// Optional keys that the default leaves commented out.
const OPTIONAL_KEYS: [&str; 4] = [
    "stimulus.csv_path",
    "stimulus.csv_column",
    "kf.g1_format",
    "kf.g2_format",
];

/// Refuses a key of `user` that neither the default nor [`OPTIONAL_KEYS`] has, naming it and
/// the line it stands on.
fn check_known_keys(
    user: &toml::Table,
    default: &toml::Table,
    prefix: &str,
    text: &str,
    origin: &str,
) -> Result<()> {
    for (key, value) in user {
        let path = format!("{prefix}{key}");
        match (default.get(key), value) {
            (Some(toml::Value::Table(d)), toml::Value::Table(u)) => {
                check_known_keys(u, d, &format!("{path}."), text, origin)?
            }
            (Some(_), _) => {}
            (None, _) if OPTIONAL_KEYS.contains(&path.as_str()) => {}
            (None, _) => {
                let line = text
                    .lines()
                    .position(|l| {
                        let l = l.trim_start();
                        l.starts_with(key.as_str())
                            && l[key.len()..].trim_start().starts_with(['=', '.'])
                            || l.trim_start_matches('[').starts_with(path.as_str())
                    })
                    .map(|i| format!(" (line {})", i + 1))
                    .unwrap_or_default();
                let mut known: Vec<String> = default
                    .keys()
                    .map(|k| format!("{prefix}{k}"))
                    .chain(
                        OPTIONAL_KEYS
                            .iter()
                            .filter(|k| k.starts_with(prefix) && !prefix.is_empty())
                            .map(|k| k.to_string()),
                    )
                    .collect();
                known.sort();
                return Err(Error::ConfigSyntax {
                    origin: origin.to_string(),
                    message: format!(
                        "unknown key {path}{line}; known keys here: {}",
                        known.join(", ")
                    ),
                });
            }
        }
    }
    Ok(())
}

/// Merges `overlay` into `base`, table by table.
fn merge(base: &mut toml::Table, overlay: toml::Table) {
    for (key, value) in overlay {
        match (base.get_mut(&key), value) {
            (Some(toml::Value::Table(b)), toml::Value::Table(o)) => merge(b, o),
            (_, v) => {
                base.insert(key, v);
            }
        }
    }
}

impl Config {
    /// The embedded default.
    pub fn embedded() -> Config {
        Config::from_toml(DEFAULT_TOML, "embedded default").expect("the embedded default is valid")
    }

    /// Parses a (partial) config text over the embedded default. `origin` names it in errors.
    ///
    /// # Errors
    /// [`Error::ConfigSyntax`] for bad TOML, unknown keys or wrong types.
    pub fn from_toml(text: &str, origin: &str) -> Result<Config> {
        let syntax = |e: toml::de::Error| Error::ConfigSyntax {
            origin: origin.to_string(),
            message: e.to_string().trim_end().to_string(),
        };
        let user: toml::Table = toml::from_str(text).map_err(syntax)?;
        let mut merged: toml::Table = toml::from_str(DEFAULT_TOML).expect("default parses");
        check_known_keys(&user, &merged, "", text, origin)?;
        merge(&mut merged, user);
        let merged_text = toml::to_string(&merged).expect("a table serializes");
        toml::from_str(&merged_text).map_err(syntax)
    }

    /// Reads a config file over the embedded default; a relative `csv_path` is resolved against
    /// the file's folder.
    ///
    /// # Errors
    /// [`Error::Io`] when the file cannot be read, and those of [`Config::from_toml`].
    pub fn from_file(path: &Path) -> Result<Config> {
        let text = std::fs::read_to_string(path).map_err(|e| Error::io(path, e))?;
        let mut config = Config::from_toml(&text, &path.display().to_string())?;
        if let Some(csv) = &config.stimulus.csv_path {
            if csv.is_relative() {
                let folder = path.parent().unwrap_or(Path::new("."));
                config.stimulus.csv_path = Some(folder.join(csv));
            }
        }
        Ok(config)
    }

    /// The config as TOML (resolved: every key present).
    pub fn to_toml(&self) -> String {
        toml::to_string(self).expect("config serializes")
    }

    /// Checks every value and returns the typed source and KF settings.
    ///
    /// # Errors
    /// [`Error::Config`] naming the first bad field.
    pub fn validate(&self) -> Result<(Source, KfSettings)> {
        // The vector set is built in memory (~300 bytes a sample with its text files).
        if self.samples == 0 || self.samples > MAX_SAMPLES {
            return Err(Error::config(
                "samples",
                self.samples,
                format!("1..={MAX_SAMPLES}"),
            ));
        }
        let s = &self.stimulus;
        positive("stimulus.fs_hz", s.fs_hz)?;
        finite("stimulus.rate_dps", s.rate_dps)?;
        finite("stimulus.initial_bias_dps", s.initial_bias_dps)?;
        non_negative("stimulus.frequency_hz", s.frequency_hz)?;
        non_negative("stimulus.arw_deg_per_sqrt_h", s.arw_deg_per_sqrt_h)?;
        non_negative(
            "stimulus.rrw_deg_per_h_per_sqrt_h",
            s.rrw_deg_per_h_per_sqrt_h,
        )?;
        let scenario = match s.scenario.as_str() {
            "static" => Scenario::Static,
            "constant" => Scenario::Constant {
                rate_dps: s.rate_dps,
            },
            "sine" => Scenario::Sine {
                amplitude_dps: s.rate_dps,
                frequency_hz: s.frequency_hz,
            },
            other => {
                return Err(Error::config(
                    "stimulus.scenario",
                    format!("{other:?}"),
                    "one of \"static\", \"constant\", \"sine\"",
                ))
            }
        };
        let source = match s.source.as_str() {
            "synthetic" => Source::Synthetic(scenario),
            "csv" => Source::Csv {
                path: s.csv_path.clone().ok_or_else(|| {
                    Error::config(
                        "stimulus.csv_path",
                        "(missing)",
                        "a CSV file path when source = \"csv\"",
                    )
                })?,
                column: s
                    .csv_column
                    .clone()
                    .unwrap_or_else(|| "rate_dps".to_string()),
            },
            other => {
                return Err(Error::config(
                    "stimulus.source",
                    format!("{other:?}"),
                    "\"synthetic\" or \"csv\"",
                ))
            }
        };

        let k = &self.kf;
        let method = k.method.parse().map_err(|_| {
            Error::config(
                "kf.method",
                format!("{:?}", k.method),
                "\"direct\" or \"paper\"",
            )
        })?;
        if k.bandwidths_hz.is_empty() || k.bandwidths_hz.len() > 256 {
            return Err(Error::config(
                "kf.bandwidths_hz",
                format!("{:?}", k.bandwidths_hz),
                "a list of 1 to 256 bandwidths in Hz",
            ));
        }
        for (i, bw) in k.bandwidths_hz.iter().enumerate() {
            if !(bw.is_finite() && *bw > 0.0 && *bw < s.fs_hz / 2.0) {
                return Err(Error::config(
                    format!("kf.bandwidths_hz[{i}]"),
                    bw,
                    format!("0 < bandwidth < fs/2 = {} Hz", s.fs_hz / 2.0),
                ));
            }
        }
        positive("kf.arw_deg_per_sqrt_h", k.arw_deg_per_sqrt_h)?;
        positive("kf.rrw_deg_per_h_per_sqrt_h", k.rrw_deg_per_h_per_sqrt_h)?;
        positive("kf.tolerance", k.tolerance)?;
        if k.max_iterations == 0 {
            return Err(Error::config("kf.max_iterations", 0, "at least 1"));
        }
        let coefficient = |field: &str, explicit: &Option<String>| -> Result<CoefficientFormat> {
            match explicit {
                Some(text) => Ok(CoefficientFormat::Fixed(parse_format(field, text)?)),
                None => {
                    if !(1..=64).contains(&k.coefficient_width) {
                        return Err(Error::config(
                            "kf.coefficient_width",
                            k.coefficient_width,
                            "1..=64 bits",
                        ));
                    }
                    Ok(CoefficientFormat::Auto {
                        width: k.coefficient_width,
                    })
                }
            }
        };
        let settings = KfSettings {
            method,
            bandwidths_hz: k.bandwidths_hz.clone(),
            convergence: Convergence {
                tolerance: k.tolerance,
                max_iterations: k.max_iterations,
            },
            input: parse_format("kf.input_format", &k.input_format)?,
            state: parse_format("kf.state_format", &k.state_format)?,
            output: parse_format("kf.output_format", &k.output_format)?,
            coefficients: [
                coefficient("kf.g1_format", &k.g1_format)?,
                coefficient("kf.g2_format", &k.g2_format)?,
            ],
            rounding: k.rounding.parse().map_err(|_| {
                Error::config(
                    "kf.rounding",
                    format!("{:?}", k.rounding),
                    "one of floor, ceil, zero, nearest, round, convergent",
                )
            })?,
            overflow: k.overflow.parse().map_err(|_| {
                Error::config(
                    "kf.overflow",
                    format!("{:?}", k.overflow),
                    "wrap or saturate",
                )
            })?,
        };
        Ok((source, settings))
    }
}

fn parse_format(field: &str, text: &str) -> Result<Format> {
    text.parse::<Format>()
        .map_err(|e| Error::config(field, format!("{text:?}"), e.to_string()))
}

fn finite(field: &str, value: f64) -> Result<()> {
    if value.is_finite() {
        Ok(())
    } else {
        Err(Error::config(field, value, "a finite number"))
    }
}

fn positive(field: &str, value: f64) -> Result<()> {
    if value.is_finite() && value > 0.0 {
        Ok(())
    } else {
        Err(Error::config(field, value, "a finite number > 0"))
    }
}

fn non_negative(field: &str, value: f64) -> Result<()> {
    if value.is_finite() && value >= 0.0 {
        Ok(())
    } else {
        Err(Error::config(field, value, "a finite number >= 0"))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_embedded_default_is_valid_and_round_trips() {
        let config = Config::embedded();
        config.validate().unwrap();
        assert_eq!(
            Config::from_toml(&config.to_toml(), "round trip").unwrap(),
            config
        );
        assert_eq!(config.kf.bandwidths_hz, vec![10.0, 20.0, 30.0]);
    }

    #[test]
    fn a_partial_config_overlays_the_default() {
        let config = Config::from_toml("seed = 9\n[kf]\nrounding = \"convergent\"\n", "t").unwrap();
        assert_eq!(config.seed, 9);
        assert_eq!(config.kf.rounding, "convergent");
        assert_eq!(config.kf.state_format, "s36.26");
    }

    #[test]
    fn unknown_keys_are_refused_with_name_and_line() {
        let err =
            Config::from_toml("seed = 1\n[kf]\nbandwith_hz = [1.0]\n", "my.toml").unwrap_err();
        let text = err.to_string();
        assert!(
            text.contains("my.toml") && text.contains("bandwith_hz") && text.contains("line 3"),
            "{text}"
        );
        let err = Config::from_toml("colour = 1\n", "t")
            .unwrap_err()
            .to_string();
        assert!(err.contains("colour"), "{err}");
    }

    #[test]
    fn bad_values_name_field_value_and_what_is_allowed() {
        let cases = [
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
            ("[stimulus]\nfs_hz = 0.0", "stimulus.fs_hz = 0", "> 0"),
            ("[stimulus]\nfs_hz = -200.0", "stimulus.fs_hz = -200", "> 0"),
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
                "[kf]\nrounding = \"half_up\"",
                "kf.rounding = \"half_up\"",
                "convergent",
            ),
            (
                "[kf]\ncoefficient_width = 0",
                "kf.coefficient_width = 0",
                "1..=64",
            ),
            (
                "[stimulus]\nscenario = \"ramp\"",
                "stimulus.scenario = \"ramp\"",
                "sine",
            ),
            (
                "[stimulus]\nsource = \"csv\"",
                "stimulus.csv_path = (missing)",
                "CSV",
            ),
            ("samples = 0", "samples = 0", "1..="),
        ];
        for (text, field, allowed) in cases {
            let err = Config::from_toml(text, "t")
                .unwrap()
                .validate()
                .unwrap_err()
                .to_string();
            assert!(
                err.contains(field) && err.contains(allowed),
                "{text}: {err}"
            );
        }
    }
}
