//! The blocks as their RTL ports see them, for golden models inside users' testbenches (the
//! Python package, the C ABI and its DPI-C testbenches): codes in, codes out, one call per
//! clock that takes a sample, every input checked against its port.
//!
//! Codes are `i64` exactly as the ports carry them: two's-complement values of the port's
//! format, flags 0/1, a mode 1 normal / 0 reverse, indices from 0. A refused input is an
//! `Err` naming the port, the value and what is allowed; the model's state is then unchanged.
//!
//! One file per block (its model over its ports), with the checks every port shares here.

mod estimator;
mod gyro_loop;
mod kf;
mod mean_filter;
mod overflows;
pub mod ports;
mod sequencer;
mod system;
mod top;

pub use estimator::{slot_from_ports, Estimator, ESTIMATOR_OUTPUTS, ESTIMATOR_SLOT_PORTS};
pub use gyro_loop::{GyroLoop, GYRO_LOOP_OUTPUTS};
pub use kf::Kf;
pub use mean_filter::MeanFilter;
pub use overflows::Overflows;
pub use sequencer::{slot_codes, Sequencer, SLOT_PORTS};
pub use system::{System, NO_SYSTEM, SYSTEM_ADC_PORTS, SYSTEM_OUTPUTS};
pub use top::{Chain, CHAIN_OUTPUTS};

use gyrofx_model::fx::Format;
use gyrofx_model::resonator::Mode;

/// The blocks with a golden model here, by folder name: the ones that get cocotb and DPI-C
/// testbenches.
pub const BLOCKS: [&str; 7] = [
    "sequencer",
    "estimator",
    "kf",
    "top",
    "mean_filter",
    "gyro_loop",
    "system",
];

/// A refused input: the message names the port, the value and what is allowed.
pub type PortResult<T> = std::result::Result<T, String>;

/// Checks that `code` is a code of `format`.
pub fn check_code(code: i64, format: Format, port: &str) -> PortResult<()> {
    if format.contains(i128::from(code)) {
        Ok(())
    } else {
        Err(format!(
            "{port} = {code} is not a code of {format}: allowed {}..={}",
            format.min_code(),
            format.max_code()
        ))
    }
}

/// The first code of `codes` outside `format`, as [`check_code`]'s error naming `port[i]`.
pub fn check_codes(codes: &[i64], format: Format, port: &str) -> PortResult<()> {
    // Declared formats are at most 64 bits wide, so their code range fits i64 (u64 aside,
    // whose upper half no i64 reaches).
    let min = i64::try_from(format.min_code()).unwrap_or(i64::MIN);
    let max = i64::try_from(format.max_code()).unwrap_or(i64::MAX);
    if codes
        .iter()
        .fold(false, |bad, c| bad | (*c < min) | (*c > max))
    {
        let index = codes.iter().position(|c| *c < min || *c > max).unwrap_or(0);
        check_code(codes[index], format, &format!("{port}[{index}]"))?;
    }
    Ok(())
}

/// A flag port's value (0 or 1).
pub fn check_flag(value: i64, port: &str) -> PortResult<bool> {
    match value {
        0 => Ok(false),
        1 => Ok(true),
        other => Err(format!("{port} = {other}: a flag is 0 or 1")),
    }
}

/// A mode port (1 normal, 0 reverse) as the loop's mode.
pub fn check_mode(value: i64, port: &str) -> PortResult<Mode> {
    match value {
        1 => Ok(Mode::Normal),
        0 => Ok(Mode::Reverse),
        other => Err(format!(
            "{port} = {other}: a mode is 1 (normal) or 0 (reverse)"
        )),
    }
}

/// A `bw_sel` that addresses a ROM of `depth` entries.
pub fn check_bw_sel(bw_sel: i64, depth: usize, port: &str) -> PortResult<usize> {
    usize::try_from(bw_sel)
        .ok()
        .filter(|b| *b < depth)
        .ok_or_else(|| {
            format!(
                "{port} = {bw_sel} does not address the KF's coefficient ROM: allowed 0..={}",
                depth - 1
            )
        })
}
