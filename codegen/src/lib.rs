//! gyrofx-codegen: config, the vector / ROM / testbench writers, the output package and the
//! simulator runner.
//!
//! Data flows one way: [`config::Config`] → [`job::Job`] (designs and every block's plan) →
//! [`vectors`] (one run of the chain fills every [`block::Block`]) → [`writers`] and
//! [`testbench`] → [`package::Package`], written atomically by [`generate::generate`].
//! [`simulate`] runs a written package.
#![warn(missing_docs)]

pub mod block;
/// One folder per RTL block; for now each holds its config section.
pub mod blocks;
pub mod config;
pub mod error;
pub mod generate;
pub mod input;
pub mod job;
pub mod junit;
pub mod package;
pub mod plot;
pub mod report;
pub mod reproduce;
pub mod rom;
pub mod simulate;
pub mod synth;
pub mod testbench;
pub mod vectors;
pub mod writers;

pub use error::{Error, Result};
