//! Option groups that several commands share, each defined once and `#[command(flatten)]`ed,
//! with the small helpers that turn them into working values.
//!
//! The groups carry `//` comments, not `///`: clap takes a struct's doc comment as the `about`
//! text of whichever command flattens it.

use std::path::PathBuf;

use anyhow::Result;

use super::usage;

use gyrofx_codegen::config::Config;
use gyrofx_codegen::generate::{provenance, Output};
use gyrofx_codegen::input::{read_column, read_column_with_gaps};
use gyrofx_codegen::job::Job;
use gyrofx_codegen::output_folder::Replace;
use gyrofx_codegen::writers::Provenance;

// One column of a CSV record (ar, davar, filter). A command whose help words these flags
// differently sets its own text with `#[command(mut_arg(..))]`.
#[derive(clap::Args)]
pub struct CsvColumn {
    /// CSV file with a header line.
    #[arg(long)]
    pub input: PathBuf,
    /// Column of rates in °/s.
    #[arg(long, default_value = "rate_dps")]
    pub column: String,
}

impl CsvColumn {
    /// The column's values; an empty cell is an error.
    pub fn read(&self) -> Result<Vec<f64>> {
        Ok(read_column(&self.input, &self.column)?)
    }

    /// The column's values without its empty cells, and how many rows were skipped for one.
    pub fn read_with_gaps(&self) -> Result<(Vec<f64>, usize)> {
        Ok(read_column_with_gaps(&self.input, &self.column)?)
    }
}

// The sample rate of a recorded series (allan, davar).
#[derive(clap::Args)]
pub struct SampleRate {
    /// Sample rate, Hz.
    #[arg(long, allow_negative_numbers = true)]
    pub rate: f64,
}

impl SampleRate {
    /// The rate in Hz, refused unless it is finite and > 0.
    pub fn hz(&self) -> Result<f64> {
        let rate = self.rate;
        if !(rate.is_finite() && rate > 0.0) {
            usage!(
                "--rate {rate} is not allowed: the sample rate must be a finite number of Hz > 0"
            );
        }
        Ok(rate)
    }
}

// The folder a command writes its output into atomically (generate, synth).
#[derive(clap::Args)]
pub struct OutputFolder {
    /// Output folder (replaced only if empty, or a package of this command that holds only the
    /// files gyrofx wrote, unchanged).
    #[arg(long)]
    pub out: PathBuf,
    /// Replace --out even if it holds other files or another kind of package.
    #[arg(long)]
    pub force: bool,
}

impl OutputFolder {
    /// How `--out` may be replaced.
    pub fn replace(&self) -> Replace {
        replace(self.force)
    }
}

/// Refuses (a usage error) an output that would destroy one of the command's inputs (it is
/// one, or as a folder holds one) and, for a `folder`, one that may never be an output folder
/// (a filesystem root, the home folder, the current folder or an ancestor): before any work.
pub fn check_output(
    flag: &str,
    out: &std::path::Path,
    folder: bool,
    inputs: &[(&str, Option<&std::path::Path>)],
) -> Result<()> {
    if folder {
        if let Some(reason) = gyrofx_codegen::output_folder::unsafe_folder(out) {
            usage!("{flag} {} {reason}", out.display());
        }
    }
    let inputs: Vec<(&str, &std::path::Path)> = inputs
        .iter()
        .filter_map(|(f, p)| p.map(|p| (*f, p)))
        .collect();
    gyrofx_codegen::output_folder::refuse_overlap((flag, out), &inputs)
        .map_err(|message| super::Usage(message).into())
}

/// [`Replace::Force`] when `--force` was given.
pub fn replace(force: bool) -> Replace {
    if force {
        Replace::Force
    } else {
        Replace::IfOwned
    }
}

// Where the chain's config comes from (generate, synth): the embedded default, overlaid by a
// preset, overlaid by a file.
#[derive(clap::Args)]
pub struct ConfigSource {
    /// Config file (TOML, overlays the embedded default and the preset).
    #[arg(long)]
    pub config: Option<PathBuf>,
    /// Start from a preset: gu2019, xue2015, mpu6050.
    #[arg(long)]
    pub preset: Option<String>,
}

impl ConfigSource {
    /// The config: the embedded default, overlaid by the preset, overlaid by the file.
    pub fn load(&self) -> Result<Config> {
        Ok(Config::from_preset_and_file(
            self.preset.as_deref(),
            self.config.as_deref(),
        )?)
    }

    /// What `output` made from `job` records about its origin: this preset and file, and the
    /// command that regenerates it.
    pub fn provenance(&self, job: &Job, output: Output) -> Provenance {
        provenance(job, output, self.preset.as_deref(), self.config.as_deref())
    }
}

/// A count of samples from the command line: a whole number, also written as `1e6` or
/// `2.5e5` when that is exactly a whole number (clap's value parser).
pub fn count(text: &str) -> std::result::Result<usize, String> {
    let refuse =
        || format!("'{text}' is not a count: a whole number >= 0 such as 1000000, 1e6 or 2.5e5");
    if let Ok(n) = text.parse::<usize>() {
        return Ok(n);
    }
    let value: f64 = text.parse().map_err(|_| refuse())?;
    if value.is_finite() && value >= 0.0 && value.fract() == 0.0 && value < 2f64.powi(53) {
        Ok(value as usize)
    } else {
        Err(refuse())
    }
}
