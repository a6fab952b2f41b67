//! gyrofx-codegen: a job (`gyrofx-job`) → a verification package: the vector / ROM / testbench
//! writers and the output package. It runs no external program: simulating, synthesizing and
//! placing what it writes is `gyrofx-lab`'s.
//!
//! Data flows one way: [`gyrofx_job::config::Config`] → [`gyrofx_job::job::Job`] (designs and
//! every block's plan; [`blocks::checked_job`] adds each block's own check) →
//! [`vectors`] (one run of the chain, cut into every registered block's [`block::Block`] by
//! its module in [`blocks`]) → [`writers`] and
//! [`testbench`] → [`package::Package`], written atomically by [`generate::generate`].
//!
//! The blocks a default package holds, as the registry lists them:
//!
//! ```
//! use gyrofx_job::{config::Config, job::Job};
//!
//! let job = Job::new(Config::embedded()).unwrap();
//! let names: Vec<&str> = gyrofx_codegen::blocks::of(&job).map(|block| block.name()).collect();
//! assert!(names.contains(&"kf") && names.contains(&"gyro_loop"));
//! ```
#![warn(missing_docs)]

pub mod block;
pub mod blocks;
pub mod cocotb;
pub mod design;
pub mod dpi;
pub mod filter_package;
pub mod fusesoc;
pub mod generate;
pub mod hdl;
pub mod output_folder;
pub mod package;
pub mod progress;
pub mod report;
pub mod rom;
pub mod stats;
pub mod testbench;
pub mod text;
pub mod vector_rows;
pub mod vectors;
pub mod writers;

pub use gyrofx_job::error::{Error, Result};
