//! The TOML config: the annotated embedded default, overlays, and validation into typed values.
//!
//! A user config is a partial overlay of the embedded default ([`DEFAULT_TOML`]): keys it
//! leaves out keep their default. Unknown keys, wrong types and out-of-range values are errors
//! naming the key, the value and what is allowed.

use std::path::Path;

use serde::{Deserialize, Serialize};

use gyrofx_model::estimator::Spec as EstimatorSpec;
use gyrofx_model::fx::{Overflow, Rounding};
use gyrofx_model::mean_filter::Spec as MeanFilterSpec;
use gyrofx_model::plant::{GyroErrors, Plant};
use gyrofx_model::resonator::ResonatorParams;

use crate::error::{Error, Result};

pub(crate) mod check;
mod estimator;
mod gyro;
mod kf;
mod mean_filter;
mod population;
mod resonator;
mod sequencer;
mod stimulus;

pub use estimator::EstimatorConfig;
pub use gyro::PlantConfig;
pub use kf::{KfConfig, KfSettings};
pub use mean_filter::MeanFilterConfig;
pub use population::{PopulationConfig, SpreadConfig};
pub use resonator::GyroLoop;
pub use sequencer::SequencerConfig;
pub use stimulus::{Source, StimulusConfig};

/// Largest `seed`: the config is written as TOML, whose integers are 64-bit signed.
pub const MAX_SEED: u64 = i64::MAX as u64;

/// Largest `samples`: the vector set and its files are built in memory.
pub const MAX_SAMPLES: usize = 20_000_000;

/// The embedded, annotated default config (`gyrofx init` prints it).
pub const DEFAULT_TOML: &str = include_str!("../default.toml");

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
    /// The chain's RTL: `"parallel"` (`gyrofx_top`) or `"serial"` (`gyrofx_top_serial`).
    pub architecture: String,
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
    /// Gyro A's structure at resonator level (SPEC §1.6).
    pub resonator_a: ResonatorParams,
    /// Gyro B's structure.
    pub resonator_b: ResonatorParams,
    /// The resonators' front end (`PhysicsSettings` without its sample rate, which is
    /// `[loop]`'s).
    pub front_end: toml::Table,
    /// Gyro A's own front-end keys over `[front_end]` (optional; left out of the resolved
    /// config when empty).
    #[serde(default, skip_serializing_if = "toml::Table::is_empty")]
    pub front_end_a: toml::Table,
    /// Gyro B's own front-end keys over `[front_end]`.
    #[serde(default, skip_serializing_if = "toml::Table::is_empty")]
    pub front_end_b: toml::Table,
    /// One gyro's digital loop (`LoopSettings` without rounding and overflow, which are the
    /// config's).
    #[serde(rename = "loop")]
    pub gyro_loop: toml::Table,
    /// How the resonators and front ends spread over a population (`gyrofx population`);
    /// optional, left out of the resolved config when empty.
    #[serde(default, skip_serializing_if = "PopulationConfig::is_empty")]
    pub population: PopulationConfig,
}

/// Everything the config says, validated and typed.
#[derive(Clone, Debug, PartialEq)]
pub struct Settings {
    /// The true rate.
    pub source: Source,
    /// The plant.
    pub plant: Plant,
    /// Whether the resonator-level gyros feed the chain instead of the rate-level plant.
    pub resonator: Option<[GyroLoop; 2]>,
    /// The estimator (with the sequencer's schedule).
    pub estimator: EstimatorSpec,
    /// The KF.
    pub kf: KfSettings,
    /// The mean filter (its input format is the KF's).
    pub mean_filter: MeanFilterSpec,
    /// The chain's architecture.
    pub architecture: Architecture,
}

/// How the chain's RTL computes a sample.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Architecture {
    /// `gyrofx_top`: every block in parallel, a sample every few clocks.
    Parallel,
    /// `gyrofx_top_serial`: one shared multiplier run by a program, a sample every few
    /// thousand clocks.
    Serial,
}

/// The names of the presets, in the order `gyrofx init --preset` lists them.
pub const PRESETS: [(&str, &str); 3] = [
    ("gu2019", include_str!("../presets/gu2019.toml")),
    ("xue2015", include_str!("../presets/xue2015.toml")),
    ("mpu6050", include_str!("../presets/mpu6050.toml")),
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
const OPTIONAL_KEYS: [&str; 5] = [
    "stimulus.csv_path",
    "stimulus.csv_column",
    "kf.g1_format",
    "kf.g2_format",
    "loop.scale_coefficient_format",
];

/// Optional sections the default leaves out, whose keys their own types check
/// (`deny_unknown_fields`).
const OPTIONAL_SECTIONS: [&str; 1] = ["population"];

/// Optional sections the default leaves out that overlay a section of it for one gyro: their
/// keys are that section's.
const GYRO_OVERLAYS: [(&str, &str); 2] =
    [("front_end_a", "front_end"), ("front_end_b", "front_end")];

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
        let overlaid = GYRO_OVERLAYS
            .iter()
            .find(|(overlay, _)| prefix.is_empty() && overlay == key)
            .and_then(|(_, section)| default.get(*section));
        match (default.get(key).or(overlaid), value) {
            (Some(toml::Value::Table(d)), toml::Value::Table(u)) => {
                check_known_keys(u, d, &format!("{path}."), text, origin)?
            }
            (Some(_), _) => {}
            (None, _) if OPTIONAL_KEYS.contains(&path.as_str()) => {}
            (None, _) if OPTIONAL_SECTIONS.contains(&path.as_str()) => {}
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

/// The 1-based line of `text` that sets the dotted key `path` (`kf.tolerance`; a key inside an
/// inline table or array is found at the line of its outer key), tracking `[section]` headers
/// and dotted keys.
fn line_of(text: &str, path: &str) -> Option<usize> {
    let mut section = String::new();
    for (index, line) in text.lines().enumerate() {
        let line = line.trim();
        if let Some(header) = line.strip_prefix('[') {
            section = header
                .trim_start_matches('[')
                .split(']')
                .next()
                .unwrap_or("")
                .split('.')
                .map(|part| part.trim().trim_matches('"'))
                .collect::<Vec<_>>()
                .join(".");
            continue;
        }
        let Some((key, _)) = line.split_once('=') else {
            continue;
        };
        let key = key
            .split('.')
            .map(|part| part.trim().trim_matches('"'))
            .collect::<Vec<_>>()
            .join(".");
        if key.is_empty() || key.starts_with('#') {
            continue;
        }
        let full = if section.is_empty() {
            key
        } else {
            format!("{section}.{key}")
        };
        if path == full
            || path.starts_with(&format!("{full}."))
            || path.starts_with(&format!("{full}["))
        {
            return Some(index + 1);
        }
    }
    None
}

/// Merges `overlay` into `base`, table by table.
pub(crate) fn merge(base: &mut toml::Table, overlay: toml::Table) {
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
        // The merged text's line means nothing to the user: a type error names the key and the
        // line of the last overlay that sets it.
        let located = |key: String, message: &str| {
            let (origin, line) = overlays
                .iter()
                .rev()
                .find_map(|(text, origin)| line_of(text, &key).map(|line| (*origin, line)))
                .map(|(origin, line)| (origin.to_string(), format!("line {line}: ")))
                .unwrap_or_else(|| ("embedded default".to_string(), String::new()));
            Error::ConfigSyntax {
                origin,
                message: format!("{line}{key}: {}", message.trim_end()),
            }
        };
        let config: Config =
            serde_path_to_error::deserialize(toml::Deserializer::new(&merged_text))
                .map_err(|e| located(e.path().to_string(), e.inner().message()))?;
        if let Some((key, message)) = config.section_type_error() {
            return Err(located(key, &message));
        }
        Ok(config)
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
            let text = crate::input::read_text(path)?;
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

    /// The config a `gyrofx generate` package was made from: the `config` of its
    /// `manifest.json` (every key resolved), so a model built from it reproduces the
    /// package's vectors.
    ///
    /// # Errors
    /// [`Error::Input`] when the folder has no readable gyrofx manifest or its config does not
    /// parse.
    pub fn from_package(folder: &Path) -> Result<Config> {
        let path = folder.join("manifest.json");
        let bad = |message: String| Error::Input {
            path: path.clone(),
            message,
        };
        let text = std::fs::read_to_string(&path).map_err(|e| Error::io(&path, e))?;
        let manifest: serde_json::Value =
            serde_json::from_str(&text).map_err(|e| bad(format!("not JSON: {e}")))?;
        if manifest.get("tool").and_then(|t| t.as_str()) != Some("gyrofx") {
            return Err(bad(
                "not a gyrofx package manifest (no \"tool\": \"gyrofx\")".into(),
            ));
        }
        let config = manifest
            .get("config")
            .cloned()
            .ok_or_else(|| bad("has no \"config\"".into()))?;
        serde_json::from_value(config).map_err(|e| bad(format!("its config: {e}")))
    }

    /// The config as TOML (resolved: every key present).
    pub fn to_toml(&self) -> String {
        toml::to_string(self).expect("config serializes")
    }

    /// Checks every value and returns the typed settings of every block.
    ///
    /// The top-level keys come first, then each section checks itself, in the order
    /// `[stimulus]`, `[gyro_a]`, `[gyro_b]`, `[plant]`, `[sequencer]`, `[kf]`, `[estimator]`,
    /// `[mean_filter]`; the estimator and the mean filter read the KF's input format.
    ///
    /// # Errors
    /// [`Error::Config`] naming the first bad field.
    pub fn validate(&self) -> Result<Settings> {
        if self.seed > MAX_SEED {
            return Err(Error::config(
                "seed",
                self.seed,
                format!("0..={MAX_SEED} (TOML integers are 64-bit signed)"),
            ));
        }
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
        let architecture = match self.architecture.as_str() {
            "parallel" => Architecture::Parallel,
            "serial" => Architecture::Serial,
            other => {
                return Err(Error::config(
                    "architecture",
                    format!("{other:?}"),
                    "\"parallel\" or \"serial\"",
                ))
            }
        };
        let source = self.stimulus.validate()?;
        let fs_hz = self.stimulus.fs_hz;
        let plant = self.plant.validate(fs_hz, &self.gyro_a, &self.gyro_b)?;
        let resonator = match self.plant.model.as_str() {
            "rate" => None,
            "resonator" => Some(self.gyro_loops()?),
            other => {
                return Err(Error::config(
                    "plant.model",
                    format!("{other:?}"),
                    "\"rate\" or \"resonator\"",
                ))
            }
        };
        let schedule = self.sequencer.validate()?;
        let kf = self.kf.validate(fs_hz, rounding, overflow)?;
        let estimator = self
            .estimator
            .validate(schedule, kf.input, rounding, overflow)?;
        let mean_filter = self.mean_filter.validate(kf.input, rounding, overflow)?;
        self.population.spreads()?;
        if let Some(loops) = &resonator {
            resonator::check_chain(loops, fs_hz, kf.input, &estimator.schedule)?;
        }
        Ok(Settings {
            source,
            plant,
            resonator,
            estimator,
            kf,
            mean_filter,
            architecture,
        })
    }
}

/// Asserts that each `(overlay, field, allowed)` parses but fails validation with an error that
/// contains `field` (as `key = value`) and `allowed`. Each section's tests call it.
#[cfg(test)]
pub(crate) fn assert_refused(cases: &[(&str, &str, &str)]) {
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

    /// A seed beyond TOML's signed integers is refused by validation, not a panic when the
    /// config is written; the largest one round-trips through TOML.
    #[test]
    fn a_seed_must_fit_a_toml_integer() {
        let mut config = Config::embedded();
        config.seed = MAX_SEED + 1;
        let err = config.validate().unwrap_err().to_string();
        assert!(
            err.contains("seed = 9223372036854775808") && err.contains("0..=9223372036854775807"),
            "{err}"
        );
        config.seed = MAX_SEED;
        config.validate().unwrap();
        let again = Config::from_toml(&config.to_toml(), "written").unwrap();
        assert_eq!(again.seed, MAX_SEED);
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
    fn bad_top_level_values_name_field_value_and_what_is_allowed() {
        assert_refused(&[
            (
                "rounding = \"half_up\"",
                "rounding = \"half_up\"",
                "convergent",
            ),
            ("overflow = \"clip\"", "overflow = \"clip\"", "saturate"),
            ("samples = 0", "samples = 0", "1..="),
        ]);
    }
}
