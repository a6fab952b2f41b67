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
//!
//! Nothing holds the record: [`Recording::read`] streams the file once (every cell checked,
//! the rows counted, the SHA-256 taken from the same bytes), [`Recording::check`] streams the
//! mode column, and the run streams the rates ([`Recording::rows`]).

use std::path::{Path, PathBuf};

use serde_json::json;

use gyrofx_model::sequencer::{Schedule, Sequencer};

use sha2::{Digest, Sha256};

use crate::error::{Error, Result};
use crate::hash::digest_hex;
use crate::input::{read_header, Columns};

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
    /// °/s per recorded unit.
    scale: f64,
    /// Data rows.
    rows: usize,
}

/// A reader that hashes the bytes it passes on.
struct Hashing<R> {
    inner: R,
    hasher: Sha256,
}

impl<R: std::io::Read> std::io::Read for Hashing<R> {
    fn read(&mut self, buffer: &mut [u8]) -> std::io::Result<usize> {
        let read = self.inner.read(buffer)?;
        self.hasher.update(&buffer[..read]);
        Ok(read)
    }
}

/// A mode cell: +1 normal, −1 reverse.
fn mode_of(path: &Path, name: &str, line: u64, value: f64) -> Result<i8> {
    match value {
        1.0 => Ok(1),
        0.0 | -1.0 => Ok(-1),
        v => Err(Error::Input {
            path: path.to_path_buf(),
            message: format!(
                "line {line}, column {name:?}: {v} is not a mode: 1 (normal) or 0 / -1 (reverse)"
            ),
        }),
    }
}

/// Gyro A's and B's recorded rates, °/s, row by row ([`Recording::rows`]).
pub struct Rows {
    path: PathBuf,
    columns: Columns<std::io::BufReader<std::fs::File>>,
    scale: f64,
    read: usize,
}

impl Rows {
    /// Appends the next `count` rows' rates (°/s) to `out`: gyro A's to `out[0]`, B's to
    /// `out[1]`.
    ///
    /// # Errors
    /// A bad cell, or the file ending early (it changed since it was read).
    pub fn read_into(&mut self, count: usize, out: &mut [Vec<f64>; 2]) -> Result<()> {
        let mut values = [0.0; 2];
        for _ in 0..count {
            if self.columns.next_row(&mut values)?.is_none() {
                return Err(Error::Input {
                    path: self.path.clone(),
                    message: format!(
                        "the file ended after {} rows, fewer than when it was first read: it changed while gyrofx read it",
                        self.read
                    ),
                });
            }
            self.read += 1;
            for (column, value) in out.iter_mut().zip(values) {
                column.push(value * self.scale);
            }
        }
        Ok(())
    }
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
        let mode_column = mode_column
            .map(|spec| column_name(path, &header, spec))
            .transpose()?;
        let scale = match units {
            Units::DegreesPerSecond => 1.0,
            Units::RadiansPerSecond => 180.0 / std::f64::consts::PI,
        };
        let mut wanted: Vec<&str> = names.iter().map(String::as_str).collect();
        wanted.extend(mode_column.as_deref());
        let file = crate::input::open(path)?;
        let hashing = std::io::BufReader::new(Hashing {
            inner: file,
            hasher: Sha256::new(),
        });
        let mut reader = Columns::from_reader(path, hashing, &wanted)?;
        let mut values = [0.0; 3];
        let mut rows = 0;
        while let Some(line) = reader.next_row(&mut values[..wanted.len()])? {
            if let Some(name) = &mode_column {
                mode_of(path, name, line, values[2])?;
            }
            rows += 1;
        }
        let sha256 = digest_hex(&reader.into_inner().into_inner().hasher.finalize());
        Ok(Recording {
            path: path.to_path_buf(),
            columns: names,
            units,
            rate_hz,
            mode_column,
            sha256,
            scale,
            rows,
        })
    }

    /// The rates from the first row on.
    ///
    /// # Errors
    /// The file cannot be opened again.
    pub fn rows(&self) -> Result<Rows> {
        let names = [self.columns[0].as_str(), self.columns[1].as_str()];
        Ok(Rows {
            path: self.path.clone(),
            columns: Columns::open(&self.path, &names)?,
            scale: self.scale,
            read: 0,
        })
    }

    /// Rows (chain samples).
    pub fn len(&self) -> usize {
        self.rows
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
        if let Some(name) = &self.mode_column {
            let mut sequencer = Sequencer::new(schedule);
            let mut modes = Columns::open(&self.path, &[name.as_str()])?;
            let mut value = [0.0];
            for row in 0..samples {
                let Some(line) = modes.next_row(&mut value)? else {
                    break;
                };
                let mode = mode_of(&self.path, name, line, value[0])?;
                let expected = sequencer.advance().mode_a;
                if mode != expected {
                    let word = |m: i8| if m > 0 { "normal" } else { "reverse" };
                    return Err(bad(format!(
                        "line {line} (row {row}), column {name:?}: the recording has gyro A in {} mode but the configured sequencer runs it {} there; align the recording with [sequencer] (interval_length, intervals, pattern, blank, stagger)",
                        word(mode),
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
