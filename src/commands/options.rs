//! Option groups that several commands share, each defined once and `#[command(flatten)]`ed,
//! with the small helpers that turn them into working values.
//!
//! The groups carry `//` comments, not `///`: clap takes a struct's doc comment as the `about`
//! text of whichever command flattens it.

use std::path::{Path, PathBuf};

use anyhow::Result;

use super::usage;

use gyrofx_codegen::generate::{provenance, Output};
use gyrofx_codegen::output_folder::Replace;
use gyrofx_codegen::text::Provenance;
use gyrofx_job::config::{Config, MAX_SAMPLES, MAX_SEED, PRESETS};
use gyrofx_job::input::{read_column, read_column_with_gaps, read_header};
use gyrofx_job::job::Job;
use gyrofx_model::analysis::{MAX_RATE_HZ, MIN_RATE_HZ};

// One column of a CSV record (ar, davar, filter). A command whose help words these flags
// differently sets its own text with `#[command(mut_arg(..))]`.
#[derive(clap::Args)]
pub struct CsvColumn {
    /// CSV file with a header line.
    #[arg(long)]
    pub input: PathBuf,
    /// Column of rates in °/s [default: the file's only column, else rate_dps].
    #[arg(long)]
    pub column: Option<String>,
}

impl CsvColumn {
    /// The column read: `--column`, else [`default_column`].
    pub fn column(&self) -> Result<String> {
        match &self.column {
            Some(column) => Ok(column.clone()),
            None => default_column(&self.input),
        }
    }

    /// The column's values; an empty cell is an error.
    pub fn read(&self) -> Result<Vec<f64>> {
        Ok(read_column(&self.input, &self.column()?)?)
    }

    /// The column's values without its gaps (empty cells, blank rows), and how many rows were
    /// skipped for one.
    pub fn read_with_gaps(&self) -> Result<(Vec<f64>, usize)> {
        Ok(read_column_with_gaps(&self.input, &self.column()?)?)
    }
}

/// The column a command reads from `path` when `--column` is not given: the file's only
/// column, else `rate_dps` (gyrofx's own records), else a usage error naming the columns.
pub fn default_column(path: &std::path::Path) -> Result<String> {
    let header = read_header(path)?;
    if let [only] = header.as_slice() {
        return Ok(only.clone());
    }
    if header.iter().any(|name| name == "rate_dps") {
        return Ok("rate_dps".to_string());
    }
    usage!(
        "{}: --column is needed: the file has {} columns ({}), none named rate_dps",
        path.display(),
        header.len(),
        header.join(", ")
    )
}

/// The note that `skipped` rows of `column` in `path` were gaps (an empty cell or a blank row)
/// and left out, so that the samples after them moved up; `None` when none were.
pub fn gaps_note(path: &std::path::Path, column: &str, skipped: usize) -> Option<String> {
    let rows = if skipped == 1 { "row" } else { "rows" };
    (skipped > 0).then(|| {
        format!(
            "{}: skipped {skipped} {rows} without a {column} value (an empty cell or a blank \
             row): the samples after each gap are taken as following it directly",
            path.display()
        )
    })
}

// The sample rate of a recorded series (allan, davar).
#[derive(clap::Args)]
pub struct SampleRate {
    /// Sample rate, Hz (1e-9..=1e9: the range in which τ and the noise fit stay finite).
    #[arg(long, allow_negative_numbers = true)]
    pub rate: f64,
}

impl SampleRate {
    /// The rate in Hz, refused unless it is within what the analyses compute ([`check_rate`]).
    pub fn hz(&self) -> Result<f64> {
        check_rate("--rate", self.rate)
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

/// Claims `--out` before any work: refuses it as [`check_output`] does for a folder, then takes
/// its lock, held until the returned value drops, so that a second run into the same folder
/// fails at once rather than after its run.
pub fn claim_output_folder(
    out: &Path,
    inputs: &[(&str, Option<&Path>)],
) -> Result<gyrofx_codegen::output_folder::Lock> {
    check_output("--out", out, true, inputs)?;
    Ok(gyrofx_codegen::output_folder::lock(out)?)
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
        if let Some(name) = &self.preset {
            check_preset(name)?;
        }
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

/// Refuses a `--preset` that is not one of [`PRESETS`] (a usage error, exit 2).
pub fn check_preset(name: &str) -> Result<()> {
    if !PRESETS.iter().any(|(known, _)| *known == name) {
        let known: Vec<&str> = PRESETS.iter().map(|(n, _)| *n).collect();
        usage!(
            "--preset {name:?} is not allowed: one of {}",
            known.join(", ")
        );
    }
    Ok(())
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

/// A seed from the command line: a whole number in `0..=MAX_SEED` (clap's value parser). The
/// cap is the config's: a seed is written into TOML, whose integers are 64-bit signed.
pub fn seed(text: &str) -> std::result::Result<u64, String> {
    match text.trim().parse::<u64>() {
        Ok(seed) if seed <= MAX_SEED => Ok(seed),
        _ => Err(format!(
            "'{text}' is not a seed: a whole number 0..={MAX_SEED} (2^63 - 1: TOML integers are 64-bit signed)"
        )),
    }
}

/// A count of chain samples from the command line ([`count`]), in `1..=MAX_SAMPLES`: every
/// command that simulates builds its record in memory.
pub fn samples(text: &str) -> std::result::Result<usize, String> {
    let n = count(text)?;
    if (1..=MAX_SAMPLES).contains(&n) {
        Ok(n)
    } else {
        Err(format!(
            "{n} samples are not allowed: 1..={MAX_SAMPLES} (the record is built in memory)"
        ))
    }
}

/// Largest `--jobs`: more tools or candidates at once than this only queue on any machine
/// gyrofx runs on, and each costs a thread and its memory.
pub const MAX_JOBS: usize = 256;

/// A number of tools or candidates run at once, `1..=MAX_JOBS` (clap's value parser).
pub fn jobs(text: &str) -> std::result::Result<usize, String> {
    let n = count(text)?;
    if (1..=MAX_JOBS).contains(&n) {
        Ok(n)
    } else {
        Err(format!("{n} is not allowed: 1..={MAX_JOBS} at a time"))
    }
}

/// Checks, before any work, that a file can be created at `path` given as `flag`: its folder
/// exists and is writable (a file is created there and removed), and `path` is not a folder.
pub fn check_writable_file(flag: &str, path: &Path) -> Result<()> {
    if path.is_dir() {
        usage!(
            "{flag} {} is a folder: name the file to write",
            path.display()
        );
    }
    let folder = match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => Path::new("."),
    };
    if !folder.is_dir() {
        usage!(
            "{flag} {}: the folder {} does not exist",
            path.display(),
            folder.display()
        );
    }
    if let Err(e) = tempfile::Builder::new()
        .prefix(".gyrofx-check-")
        .tempfile_in(folder)
    {
        // The OS's reason, without the temporary file's name that tempfile adds.
        let reason = e.to_string();
        let reason = reason.split(" at path ").next().unwrap_or_default();
        usage!(
            "{flag} {}: cannot create a file in {}: {reason}",
            path.display(),
            folder.display()
        );
    }
    Ok(())
}

/// Checks a `--plot` path before any work: `.png` or `.svg`, in a writable folder, and none
/// of the command's `inputs` ([`check_output`]).
pub fn check_plot(path: &Path, inputs: &[(&str, Option<&Path>)]) -> Result<()> {
    gyrofx_lab::plot::check_path(path).map_err(|e| super::Usage(format!("--plot: {e}")))?;
    check_writable_file("--plot", path)?;
    check_output("--plot", path, false, inputs)
}

/// Checks a sample rate given as `flag`, in Hz: finite and within `MIN_RATE_HZ..=MAX_RATE_HZ`
/// of the analyses.
pub fn check_rate(flag: &str, rate: f64) -> Result<f64> {
    if !(rate.is_finite() && (MIN_RATE_HZ..=MAX_RATE_HZ).contains(&rate)) {
        usage!(
            "{flag} {} is not allowed: the sample rate must be {MIN_RATE_HZ:e}..={MAX_RATE_HZ:e} Hz",
            number(rate)
        );
    }
    Ok(rate)
}

/// Refuses (a usage error) a `--bandwidth` that is not a number of Hz in (0, fs/2).
pub fn check_bandwidth(bandwidth: Option<f64>, fs: f64) -> Result<()> {
    if let Some(bw) = bandwidth.filter(|bw| !(bw.is_finite() && *bw > 0.0 && *bw < fs / 2.0)) {
        usage!(
            "--bandwidth {} is not allowed: a number of Hz in (0, fs/2 = {})",
            number(bw),
            number(fs / 2.0)
        );
    }
    Ok(())
}

/// `value` as a message shows it: as written for ordinary magnitudes, in exponent form (`1e308`,
/// not 309 digits) for very large or small ones.
pub fn number(value: f64) -> String {
    let magnitude = value.abs();
    if value == 0.0 || !value.is_finite() || (1e-6..1e15).contains(&magnitude) {
        format!("{value}")
    } else {
        format!("{value:e}")
    }
}

/// A staged file beside `output` (named `<prefix>…`), moved into place when the command ends
/// well and removed when it drops: `output` is written all or nothing, and its folder is
/// checked before the work.
pub fn stage_output(output: &Path, prefix: &str) -> Result<tempfile::NamedTempFile> {
    let folder = match output.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => Path::new("."),
    };
    gyrofx_codegen::output_folder::staged_file(folder, prefix, ".csv").map_err(|e| {
        // The OS's reason, without the temporary file's name that tempfile adds.
        let reason = e.to_string();
        let reason = reason.split(" at path ").next().unwrap_or_default();
        anyhow::anyhow!(
            "--output {}: cannot create a file in {}: {reason}",
            output.display(),
            folder.display()
        )
    })
}

/// Refuses, before any work, an existing `--output` file gyrofx did not write: one whose first
/// line is not `header` (the line the command writes first), unless `force`. A missing file,
/// or the command's own earlier output, may be replaced.
pub fn check_replaceable(output: &Path, header: &str, force: bool) -> Result<()> {
    use std::io::Read as _;
    if force {
        return Ok(());
    }
    let meta = match std::fs::symlink_metadata(output) {
        Ok(meta) => meta,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(()),
        Err(e) => anyhow::bail!("--output {}: {e}", output.display()),
    };
    if !meta.is_file() {
        usage!(
            "--output {} exists and is not a regular file: choose another --output",
            output.display()
        );
    }
    // read_to_end over a `take`: one `read` may return fewer bytes than the header has.
    let mut start = Vec::with_capacity(header.len() + 1);
    std::fs::File::open(output)
        .and_then(|file| file.take(header.len() as u64 + 1).read_to_end(&mut start))
        .map_err(|e| anyhow::anyhow!("--output {}: {e}", output.display()))?;
    if start == format!("{header}\n").as_bytes() {
        return Ok(());
    }
    usage!(
        "--output {} exists and gyrofx did not write it (its first line is not {header}): choose \
         another --output, or give --force to replace it",
        output.display()
    )
}
