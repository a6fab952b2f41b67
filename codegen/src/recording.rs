//! [`Recording`]: recorded outputs of the two gyros (`generate --recording`), which drive the
//! chain's blocks instead of the simulated plant.
//!
//! Each gyro's column holds its rate output in °/s or rad/s at the config's sample rate, one
//! row per chain sample, already in the mode the sequencer put that gyro in (the chain runs the
//! configured sequencer from the first row, without the simulated run's late reset). An
//! optional mode column (gyro A's mode: 1 normal, 0 or -1 reverse) is checked against that
//! sequencer row by row, so a recording out of step with the config is refused, not
//! mis-calibrated. The values become the chain's input codes as the rate plant's ADC makes
//! them (nearest, saturating, counted).

use std::path::{Path, PathBuf};

use serde_json::json;

use gyrofx_model::sequencer::{Schedule, Sequencer};

use crate::error::{Error, Result};
use crate::input::{read_column, read_header};
use crate::package::file_sha256;

/// The unit of the recorded rates.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Units {
    /// Degrees per second.
    DegreesPerSecond,
    /// Radians per second.
    RadiansPerSecond,
}

impl std::str::FromStr for Units {
    type Err = String;
    fn from_str(text: &str) -> std::result::Result<Self, String> {
        match text {
            "dps" | "deg/s" => Ok(Units::DegreesPerSecond),
            "rad/s" | "rad_s" => Ok(Units::RadiansPerSecond),
            other => Err(format!("{other:?} is not a unit: dps (°/s) or rad/s")),
        }
    }
}

impl Units {
    fn name(self) -> &'static str {
        match self {
            Units::DegreesPerSecond => "dps",
            Units::RadiansPerSecond => "rad/s",
        }
    }
}

/// The recorded outputs of gyro A and B, °/s, with where they came from.
#[derive(Clone, Debug)]
pub struct Recording {
    path: PathBuf,
    columns: [String; 2],
    units: Units,
    rate_hz: f64,
    mode_column: Option<String>,
    sha256: String,
    /// Gyro A's and B's rates, °/s, one per chain sample.
    pub rates_dps: [Vec<f64>; 2],
    /// Gyro A's mode per row (+1 normal, −1 reverse), when a column gives it.
    modes: Option<Vec<i8>>,
}

/// A column named, or numbered from 0 when no header cell has that name.
fn column_name(path: &Path, header: &[String], spec: &str) -> Result<String> {
    if header.iter().any(|h| h == spec) {
        return Ok(spec.to_string());
    }
    match spec.parse::<usize>() {
        Ok(index) if index < header.len() => Ok(header[index].clone()),
        _ => Err(Error::Input {
            path: path.to_path_buf(),
            message: format!(
                "no column {spec:?} (by name, or by index 0..{}); the header has: {}",
                header.len(),
                header.join(", ")
            ),
        }),
    }
}

impl Recording {
    /// Reads gyro A's and B's columns (`columns`: names or 0-based indices) of the CSV file
    /// at `path`, in `units`, sampled at `rate_hz`; and gyro A's modes from `mode_column`.
    ///
    /// # Errors
    /// The file's or a column's errors (naming the line), columns of different lengths, a
    /// mode that is not 1, 0 or -1.
    pub fn read(
        path: &Path,
        columns: [&str; 2],
        units: Units,
        rate_hz: f64,
        mode_column: Option<&str>,
    ) -> Result<Recording> {
        let header = read_header(path)?;
        let names = [
            column_name(path, &header, columns[0])?,
            column_name(path, &header, columns[1])?,
        ];
        let scale = match units {
            Units::DegreesPerSecond => 1.0,
            Units::RadiansPerSecond => 180.0 / std::f64::consts::PI,
        };
        let mut rates_dps = [read_column(path, &names[0])?, read_column(path, &names[1])?];
        if rates_dps[0].len() != rates_dps[1].len() {
            return Err(Error::Input {
                path: path.to_path_buf(),
                message: format!(
                    "columns {} and {} hold {} and {} values: each row needs both gyros",
                    names[0],
                    names[1],
                    rates_dps[0].len(),
                    rates_dps[1].len()
                ),
            });
        }
        for rates in &mut rates_dps {
            for value in rates.iter_mut() {
                *value *= scale;
            }
        }
        let (mode_column, modes) = match mode_column {
            None => (None, None),
            Some(spec) => {
                let name = column_name(path, &header, spec)?;
                let values = read_column(path, &name)?;
                let modes = values
                    .iter()
                    .enumerate()
                    .map(|(row, value)| match *value {
                        1.0 => Ok(1),
                        0.0 | -1.0 => Ok(-1),
                        v => Err(Error::Input {
                            path: path.to_path_buf(),
                            message: format!(
                                "column {name}, value {row} = {v}: a mode is 1 (normal) or 0 / -1 (reverse)"
                            ),
                        }),
                    })
                    .collect::<Result<Vec<i8>>>()?;
                (Some(name), Some(modes))
            }
        };
        Ok(Recording {
            path: path.to_path_buf(),
            columns: names,
            units,
            rate_hz,
            mode_column,
            sha256: file_sha256(path)?,
            rates_dps,
            modes,
        })
    }

    /// Rows (chain samples).
    pub fn len(&self) -> usize {
        self.rates_dps[0].len()
    }

    /// Whether it has no rows.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Refuses a recording at another sample rate than the chain's `fs_hz`, or whose modes
    /// (when a column gives them) are not the sequencer's over its first `samples` rows.
    ///
    /// # Errors
    /// A message naming the first disagreement.
    pub fn check(&self, fs_hz: f64, schedule: &Schedule, samples: usize) -> Result<()> {
        let bad = |message: String| Error::Input {
            path: self.path.clone(),
            message,
        };
        if self.rate_hz != fs_hz {
            return Err(bad(format!(
                "the recording's rate {} Hz is not the config's stimulus.fs_hz = {fs_hz} Hz: the chain runs one sample per recorded row (set stimulus.fs_hz, or resample the recording)",
                self.rate_hz
            )));
        }
        if let (Some(name), Some(modes)) = (&self.mode_column, &self.modes) {
            let mut sequencer = Sequencer::new(schedule);
            for (row, mode) in modes.iter().take(samples).enumerate() {
                let expected = sequencer.advance().mode_a;
                if *mode != expected {
                    let word = |m: i8| if m > 0 { "normal" } else { "reverse" };
                    return Err(bad(format!(
                        "column {name}, value {row}: the recording has gyro A in {} mode but the configured sequencer runs it {} there; align the recording with [sequencer] (interval_length, intervals, pattern, blank, stagger)",
                        word(*mode),
                        word(expected)
                    )));
                }
            }
        }
        Ok(())
    }

    /// The `generate` arguments that read it again (for the files' regenerate line).
    pub fn arguments(&self) -> String {
        let mut text = format!(
            " --recording {} --recording-columns {},{} --recording-units {} --recording-rate {}",
            self.path.display(),
            self.columns[0],
            self.columns[1],
            self.units.name(),
            self.rate_hz
        );
        if let Some(mode) = &self.mode_column {
            text.push_str(&format!(" --recording-mode {mode}"));
        }
        text
    }

    /// What the manifest records of it.
    pub fn manifest(&self, samples: usize) -> serde_json::Value {
        json!({
            "file": self.path.display().to_string(),
            "sha256": self.sha256,
            "columns": {"gyro_a": self.columns[0], "gyro_b": self.columns[1]},
            "units": self.units.name(),
            "rate_hz": self.rate_hz,
            "mode_column": self.mode_column,
            "rows": self.len(),
            "samples_used": samples,
        })
    }
}
