//! The commands, one module each: its clap arguments beside its `run`.

pub mod allan;
pub mod ar;
pub mod davar;
pub mod denoise;
pub mod design;
pub mod explore;
pub mod filter;
pub mod formats;
pub mod generate;
pub mod gyro_loop;
pub mod init;
mod options;
pub mod population;
mod progress;
pub mod reproduce;
pub mod synth;
pub mod verify;

/// A command line that asks for something not allowed (an argument's value, a missing or
/// conflicting option): the program exits with 2, as for clap's own parse errors, where a
/// failure of the work itself exits with 1.
#[derive(Debug)]
pub struct Usage(pub String);

impl std::fmt::Display for Usage {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.0)
    }
}

impl std::error::Error for Usage {}

/// Returns a [`Usage`] error built like `format!`.
macro_rules! usage {
    ($($arg:tt)*) => {
        return Err($crate::commands::Usage(format!($($arg)*)).into())
    };
}
pub(crate) use usage;
