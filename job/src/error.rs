//! The one error type of gyrofx-codegen: every variant names the field, file or node, the
//! value and what is allowed.

use std::path::PathBuf;

use gyrofx_model::kf::design::DesignError;
use gyrofx_model::kf::PlanError;

/// Errors of configuration, design, input files, output and simulation.
#[derive(Debug, thiserror::Error)]
pub enum Error {
    /// A config value outside what is allowed.
    #[error("config: {field} = {value} is not allowed: {allowed}")]
    Config {
        /// Dotted key, e.g. `stimulus.fs_hz`.
        field: String,
        /// The value given.
        value: String,
        /// What is allowed.
        allowed: String,
    },
    /// The config text does not parse (syntax, unknown key, wrong type).
    #[error("config {origin}: {message}")]
    ConfigSyntax {
        /// Where the config came from.
        origin: String,
        /// The parser's message (with line and key).
        message: String,
    },
    /// The filter cannot be designed.
    #[error("design of {what}: {source}")]
    Design {
        /// Which design (e.g. `kf.bandwidths_hz[2] = 30 Hz`).
        what: String,
        /// Why.
        source: DesignError,
    },
    /// The fixed-point plan is refused.
    #[error("kf plan: {0}")]
    Plan(#[from] PlanError),
    /// The estimator's plan is refused.
    #[error("estimator: {0}")]
    Estimator(gyrofx_model::estimator::PlanError),
    /// The mean filter's plan is refused (the message names the `mean_filter.` field).
    #[error("{0}")]
    MeanFilter(gyrofx_model::mean_filter::PlanError),
    /// A bad input file (CSV).
    #[error("{path}: {message}")]
    Input {
        /// The file.
        path: PathBuf,
        /// What is wrong, with line and column where known.
        message: String,
    },
    /// `--strict`: a quantizer overflowed or saturated on the run's data.
    #[error(
        "--strict: quantizers overflowed or saturated in the chain run ({0}); nothing was written"
    )]
    Overflow(String),
    /// Reading or writing a file failed.
    #[error("{path}: {source}")]
    Io {
        /// The file or folder.
        path: PathBuf,
        /// The OS error.
        source: std::io::Error,
    },
    /// The output folder cannot be used.
    #[error("output folder {path}: {message}")]
    Output {
        /// The folder.
        path: PathBuf,
        /// Why.
        message: String,
    },
    /// A plot cannot be drawn (no font).
    #[error("{0}")]
    Plot(String),
    /// A simulation could not run or did not pass.
    #[error("{0}")]
    Simulation(String),
    /// yosys could not run, or the synthesis check failed.
    #[error("{0}")]
    Synthesis(String),
}

impl Error {
    /// A config error for `field` with its `value` and what is `allowed`.
    pub fn config(
        field: impl Into<String>,
        value: impl ToString,
        allowed: impl Into<String>,
    ) -> Self {
        Error::Config {
            field: field.into(),
            value: value.to_string(),
            allowed: allowed.into(),
        }
    }

    /// An I/O error on `path`.
    pub fn io(path: impl Into<PathBuf>, source: std::io::Error) -> Self {
        Error::Io {
            path: path.into(),
            source,
        }
    }
}

/// Result with [`Error`].
pub type Result<T> = std::result::Result<T, Error>;
