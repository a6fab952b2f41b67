//! gyrofx-codegen: config, the vector / ROM / testbench writers, the output package and the
//! simulator runner.
//!
//! Data flows one way: [`config::Config`] → [`job::Job`] (designs and the fixed-point plan)
//! → [`vectors`] (the models run over the schedule) → [`writers`] → [`package::Package`],
//! written atomically by [`generate::generate`]. [`simulate`] runs a written package.
#![warn(missing_docs)]

pub mod config;
pub mod error;
pub mod generate;
pub mod input;
pub mod job;
pub mod package;
pub mod report;
pub mod simulate;
pub mod vectors;
pub mod writers;

pub use error::{Error, Result};
