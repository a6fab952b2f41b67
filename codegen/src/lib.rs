//! gyrofx-codegen: config, the vector / ROM / testbench writers, the output package and the
//! simulator runner.
//!
//! Data flows one way: [`config::Config`] → [`job::Job`] (designs and every block's plan) →
//! [`vectors`] (one run of the chain, cut into every registered block's [`block::Block`] by
//! its module in [`blocks`]) → [`writers`] and
//! [`testbench`] → [`package::Package`], written atomically by [`generate::generate`].
//! [`simulate`] runs a written package.
#![warn(missing_docs)]

pub mod block;
pub mod blocks;
pub mod cocotb;
pub mod config;
pub mod dpi;
pub mod error;
pub mod explore;
pub mod filter_package;
pub mod formats;
pub mod generate;
pub mod golden;
pub mod hdl;
pub mod input;
pub mod job;
pub mod junit;
pub mod output_folder;
pub mod package;
pub mod place_route;
pub mod plot;
pub mod processes;
pub mod progress;
pub mod recording;
pub mod report;
pub mod reproduce;
pub mod rom;
pub mod simulate;
pub mod stats;
pub mod synth;
pub mod testbench;
pub mod vector_rows;
pub mod vectors;
pub mod writers;

pub use error::{Error, Result};
