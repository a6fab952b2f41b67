//! The TOML config: the annotated embedded default, overlays, and validation into typed values.
//!
//! A user config is a partial overlay of the embedded default ([`DEFAULT_TOML`]): keys it
//! leaves out keep their default. Unknown keys, wrong types and out-of-range values are errors
//! naming the key, the value and what is allowed.

use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

use gyrofx_model::estimator::Spec as EstimatorSpec;
use gyrofx_model::fx::{CoefficientFormat, Format, Overflow, Rounding};
use gyrofx_model::kf::design::{Convergence, Method};
use gyrofx_model::mean_filter::Spec as MeanFilterSpec;
use gyrofx_model::plant::{GyroErrors, Plant};
use gyrofx_model::sequencer::{Pattern, Schedule, ScheduleError};
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
    /// Samples of the chain run.
    pub samples: usize,
    /// Rounding mode name of every quantization point.
    pub rounding: String,
    /// Overflow mode name of every quantization point.
    pub overflow: String,
    /// The true rate.
    pub stimulus: StimulusConfig,
    /// Gyro A's errors.
    pub gyro_a: GyroErrors,
    /// Gyro B's errors.
    pub gyro_b: GyroErrors,
    /// Plant-wide settings.
    pub plant: PlantConfig,
    /// The sequencer.
    pub sequencer: SequencerConfig,
    /// The bias estimator.
    pub estimator: EstimatorConfig,
    /// The Kalman filter.
    pub kf: KfConfig,
    /// The mean filter with gross-error rejection (paper 003; a block of its own, beside the
    /// chain).
    pub mean_filter: MeanFilterConfig,
}

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

/// `[plant]`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PlantConfig {
    /// Shortest bias-instability correlation time, s.
    pub bi_tau_min_s: f64,
    /// Longest, s.
    pub bi_tau_max_s: f64,
}

/// `[sequencer]`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SequencerConfig {
    /// L.
    pub interval_length: usize,
    /// W.
    pub intervals: usize,
    /// `alternating` or `abba`.
    pub pattern: String,
    /// M.
    pub blank: usize,
    /// S.
    pub stagger: usize,
}

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

/// Everything the config says, validated and typed.
#[derive(Clone, Debug, PartialEq)]
pub struct Settings {
    /// The true rate.
    pub source: Source,
    /// The plant.
    pub plant: Plant,
    /// The estimator (with the sequencer's schedule).
    pub estimator: EstimatorSpec,
    /// The KF.
    pub kf: KfSettings,
    /// The mean filter (its input format is the KF's).
    pub mean_filter: MeanFilterSpec,
}

/// The names of the presets, in the order `gyrofx init --preset` lists them.
pub const PRESETS: [(&str, &str); 3] = [
    ("gu2019", include_str!("presets/gu2019.toml")),
    ("xue2015", include_str!("presets/xue2015.toml")),
    ("mpu6050", include_str!("presets/mpu6050.toml")),
];

/// The text of preset `name`.
///
/// # Errors
/// [`Error::Config`] for an unknown name, listing the known ones.
pub fn preset(name: &str) -> Result<&'static str> {
    PRESETS
        .iter()
        .find(|(n, _)| *n == name)
        .map(|(_, text)| *text)
        .ok_or_else(|| {
            let names: Vec<&str> = PRESETS.iter().map(|(n, _)| *n).collect();
            Error::config(
                "preset",
                format!("{name:?}"),
                format!("one of {}", names.join(", ")),
            )
        })
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
        Config::from_overlays(&[(text, origin)])
    }

    /// Parses partial config texts over the embedded default, later ones over earlier ones
    /// (a preset, then a file). Each `(text, origin)`; `origin` names it in errors.
    ///
    /// # Errors
    /// [`Error::ConfigSyntax`] for bad TOML, unknown keys or wrong types.
    pub fn from_overlays(overlays: &[(&str, &str)]) -> Result<Config> {
        let mut merged: toml::Table = toml::from_str(DEFAULT_TOML).expect("default parses");
        let default = merged.clone();
        for (text, origin) in overlays {
            let syntax = |e: toml::de::Error| Error::ConfigSyntax {
                origin: origin.to_string(),
                message: e.to_string().trim_end().to_string(),
            };
            let user: toml::Table = toml::from_str(text).map_err(syntax)?;
            check_known_keys(&user, &default, "", text, origin)?;
            merge(&mut merged, user);
        }
        let merged_text = toml::to_string(&merged).expect("a table serializes");
        let origin = overlays.last().map(|o| o.1).unwrap_or("embedded default");
        toml::from_str(&merged_text).map_err(|e| Error::ConfigSyntax {
            origin: origin.to_string(),
            message: e.to_string().trim_end().to_string(),
        })
    }

    /// Reads a config file over the embedded default; a relative `csv_path` is resolved against
    /// the file's folder.
    ///
    /// # Errors
    /// [`Error::Io`] when the file cannot be read, and those of [`Config::from_toml`].
    pub fn from_file(path: &Path) -> Result<Config> {
        Config::from_preset_and_file(None, Some(path))
    }

    /// The embedded default, overlaid by a preset and then by a config file (either optional).
    ///
    /// # Errors
    /// An unknown preset, and those of [`Config::from_overlays`] and reading the file.
    pub fn from_preset_and_file(preset_name: Option<&str>, path: Option<&Path>) -> Result<Config> {
        let mut overlays: Vec<(String, String)> = Vec::new();
        if let Some(name) = preset_name {
            overlays.push((preset(name)?.to_string(), format!("preset {name}")));
        }
        if let Some(path) = path {
            let text = std::fs::read_to_string(path).map_err(|e| Error::io(path, e))?;
            overlays.push((text, path.display().to_string()));
        }
        let refs: Vec<(&str, &str)> = overlays
            .iter()
            .map(|(t, o)| (t.as_str(), o.as_str()))
            .collect();
        let mut config = Config::from_overlays(&refs)?;
        let Some(path) = path else {
            return Ok(config);
        };
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

    /// Checks every value and returns the typed settings of every block.
    ///
    /// # Errors
    /// [`Error::Config`] naming the first bad field.
    pub fn validate(&self) -> Result<Settings> {
        if self.samples == 0 || self.samples > MAX_SAMPLES {
            return Err(Error::config(
                "samples",
                self.samples,
                format!("1..={MAX_SAMPLES}"),
            ));
        }
        let rounding: Rounding = self.rounding.parse().map_err(|_| {
            Error::config(
                "rounding",
                format!("{:?}", self.rounding),
                "one of floor, ceil, zero, nearest, round, convergent",
            )
        })?;
        let overflow: Overflow = self.overflow.parse().map_err(|_| {
            Error::config(
                "overflow",
                format!("{:?}", self.overflow),
                "wrap or saturate",
            )
        })?;
        let s = &self.stimulus;
        positive("stimulus.fs_hz", s.fs_hz)?;
        finite("stimulus.rate_dps", s.rate_dps)?;
        non_negative("stimulus.frequency_hz", s.frequency_hz)?;
        positive("stimulus.period_s", s.period_s)?;
        finite("stimulus.slope_dps_per_s", s.slope_dps_per_s)?;
        let scenario = match s.scenario.as_str() {
            "static" => Scenario::Static,
            "constant" => Scenario::Constant {
                rate_dps: s.rate_dps,
            },
            "sine" => Scenario::Sine {
                amplitude_dps: s.rate_dps,
                frequency_hz: s.frequency_hz,
            },
            "steps" => Scenario::Steps {
                rate_dps: s.rate_dps,
                period_s: s.period_s,
            },
            "ramp" => Scenario::Ramp {
                slope_dps_per_s: s.slope_dps_per_s,
            },
            other => {
                return Err(Error::config(
                    "stimulus.scenario",
                    format!("{other:?}"),
                    "one of \"static\", \"constant\", \"sine\", \"steps\", \"ramp\"",
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
        let plant = Plant {
            fs_hz: s.fs_hz,
            gyros: [gyro("gyro_a", &self.gyro_a)?, gyro("gyro_b", &self.gyro_b)?],
            bi_tau_min_s: self.plant.bi_tau_min_s,
            bi_tau_max_s: self.plant.bi_tau_max_s,
        };
        positive("plant.bi_tau_min_s", plant.bi_tau_min_s)?;
        if !(plant.bi_tau_max_s.is_finite() && plant.bi_tau_max_s > plant.bi_tau_min_s) {
            return Err(Error::config(
                "plant.bi_tau_max_s",
                plant.bi_tau_max_s,
                format!("a finite number > bi_tau_min_s = {}", plant.bi_tau_min_s),
            ));
        }

        let q = &self.sequencer;
        let pattern = match q.pattern.as_str() {
            "alternating" => Pattern::Alternating,
            "abba" => Pattern::Abba,
            other => {
                return Err(Error::config(
                    "sequencer.pattern",
                    format!("{other:?}"),
                    "\"alternating\" or \"abba\"",
                ))
            }
        };
        let schedule = Schedule {
            interval_length: q.interval_length,
            intervals: q.intervals,
            pattern,
            blank: q.blank,
            stagger: q.stagger,
        };
        schedule.validate().map_err(|e| match e {
            ScheduleError::Range {
                name,
                value,
                allowed,
            } => Error::config(format!("sequencer.{name}"), value, allowed),
        })?;

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
                None => width("kf.coefficient_width", k.coefficient_width),
            }
        };
        let input = parse_format("kf.input_format", &k.input_format)?;
        let kf = KfSettings {
            method,
            bandwidths_hz: k.bandwidths_hz.clone(),
            convergence: Convergence {
                tolerance: k.tolerance,
                max_iterations: k.max_iterations,
            },
            input,
            state: parse_format("kf.state_format", &k.state_format)?,
            output: parse_format("kf.output_format", &k.output_format)?,
            coefficients: [
                coefficient("kf.g1_format", &k.g1_format)?,
                coefficient("kf.g2_format", &k.g2_format)?,
            ],
            rounding,
            overflow,
        };
        let e = &self.estimator;
        let estimator = EstimatorSpec {
            schedule,
            rate_order: e.rate_order,
            input,
            mean: parse_format("estimator.mean_format", &e.mean_format)?,
            bias: parse_format("estimator.bias_format", &e.bias_format)?,
            calibrated: input,
            gain: width("estimator.gain_width", e.gain_width)?,
            reciprocal: width("estimator.reciprocal_width", e.reciprocal_width)?,
            smoothing_shift: e.smoothing_shift,
            rounding,
            overflow,
        };
        if e.rate_order > 8 {
            return Err(Error::config("estimator.rate_order", e.rate_order, "0..=8"));
        }
        if e.smoothing_shift > 32 {
            return Err(Error::config(
                "estimator.smoothing_shift",
                e.smoothing_shift,
                "0..=32",
            ));
        }
        let m = &self.mean_filter;
        let mean_filter = MeanFilterSpec {
            input,
            output: parse_format("mean_filter.output_format", &m.output_format)?,
            window: m.window,
            threshold_dps: m.threshold_dps,
            reciprocal_width: m.reciprocal_width,
            rounding,
            overflow,
        };
        Ok(Settings {
            source,
            plant,
            estimator,
            kf,
            mean_filter,
        })
    }
}

fn width(field: &str, width: u32) -> Result<CoefficientFormat> {
    if (1..=64).contains(&width) {
        Ok(CoefficientFormat::Auto { width })
    } else {
        Err(Error::config(field, width, "1..=64 bits"))
    }
}

/// Checks one gyro's section.
fn gyro(section: &str, g: &GyroErrors) -> Result<GyroErrors> {
    let field = |name: &str| format!("{section}.{name}");
    for (name, value) in [
        ("sf_ppm", g.sf_ppm),
        ("sf_mode_mismatch_ppm", g.sf_mode_mismatch_ppm),
        ("bias_dps", g.bias_dps),
        ("bias_mode_mismatch_dps", g.bias_mode_mismatch_dps),
        ("rate_ramp_deg_per_h2", g.rate_ramp_deg_per_h2),
    ] {
        finite(&field(name), value)?;
    }
    for (name, value) in [
        ("arw_deg_per_sqrt_h", g.arw_deg_per_sqrt_h),
        ("bias_instability_deg_per_h", g.bias_instability_deg_per_h),
        ("rrw_deg_per_h_per_sqrt_h", g.rrw_deg_per_h_per_sqrt_h),
        ("settle_tau_s", g.settle_tau_s),
    ] {
        non_negative(&field(name), value)?;
    }
    Ok(*g)
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
        let config = Config::from_toml("seed = 9\nrounding = \"convergent\"\n", "t").unwrap();
        assert_eq!(config.seed, 9);
        assert_eq!(config.rounding, "convergent");
        assert_eq!(config.kf.state_format, "s36.26");
    }

    #[test]
    fn presets_overlay_the_default_and_are_valid() {
        for (name, _) in PRESETS {
            let config = Config::from_preset_and_file(Some(name), None).unwrap();
            config
                .validate()
                .unwrap_or_else(|e| panic!("preset {name}: {e}"));
        }
        let gu = Config::from_preset_and_file(Some("gu2019"), None).unwrap();
        assert_eq!(
            (gu.stimulus.fs_hz, gu.sequencer.interval_length),
            (50.0, 150)
        );
        let err = Config::from_preset_and_file(Some("nope"), None)
            .unwrap_err()
            .to_string();
        assert!(
            err.contains("preset = \"nope\"") && err.contains("gu2019"),
            "{err}"
        );
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
                "rounding = \"half_up\"",
                "rounding = \"half_up\"",
                "convergent",
            ),
            (
                "[sequencer]\nblank = 150",
                "sequencer.blank = 150",
                "less than interval_length = 150",
            ),
            (
                "[sequencer]\nstagger = 200",
                "sequencer.stagger = 200",
                "less than interval_length",
            ),
            (
                "[sequencer]\ninterval_length = 0",
                "sequencer.interval_length = 0",
                "at least 1",
            ),
            (
                "[sequencer]\nintervals = 1",
                "sequencer.intervals = 1",
                "2..=256",
            ),
            (
                "[sequencer]\npattern = \"abab\"",
                "sequencer.pattern = \"abab\"",
                "abba",
            ),
            (
                "[gyro_b]\narw_deg_per_sqrt_h = -1.0",
                "gyro_b.arw_deg_per_sqrt_h = -1",
                ">= 0",
            ),
            (
                "[estimator]\nmean_format = \"x\"",
                "estimator.mean_format = \"x\"",
                "s18.16",
            ),
            (
                "[kf]\ncoefficient_width = 0",
                "kf.coefficient_width = 0",
                "1..=64",
            ),
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
