//! The commands, one module each: its clap arguments beside its `run`.

pub mod allan;
pub mod ar;
pub mod davar;
pub mod design;
pub mod filter;
pub mod generate;
pub mod gyro_loop;
pub mod init;
mod options;
pub mod reproduce;
pub mod synth;
pub mod verify;
