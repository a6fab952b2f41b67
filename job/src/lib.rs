//! gyrofx-job: what one run of gyrofx is, before anything is written or simulated.
//!
//! [`config::Config`] (the TOML, its validation and the presets) → [`job::Job`] (the KF
//! designs and every block's plan, from `gyrofx-model`), with its inputs read by [`input`]
//! (bounded CSV) and [`recording`]; [`formats`] proves the formats the job's plans use, and
//! [`golden`] gives the port-level models a testbench steps sample by sample. It knows no
//! output file, template, simulator or synthesis tool: the codegen crate turns a job into a
//! verification package, and the Python and C bindings stand on this crate and the model
//! alone.
//!
//! The KF of the default config as a testbench steps it, one sample at a time:
//!
//! ```
//! use gyrofx_job::{config::Config, golden, job::Job};
//!
//! let job = Job::new(Config::embedded()).unwrap();
//! let mut kf = golden::Kf::new(&job.chain.kf);
//! let rate_out = kf.step(1000, 0).unwrap(); // z and bw_sel as the RTL ports carry them
//! assert!(job.chain.kf.output.contains(i128::from(rate_out)));
//! // A code outside the input port's format is refused, naming the port.
//! assert!(kf.step(1 << 40, 0).unwrap_err().starts_with("z = 1099511627776 is not a code of"));
//! ```
#![warn(missing_docs)]

pub mod config;
pub mod error;
pub mod formats;
pub mod golden;
pub mod gyros;
pub mod hash;
pub mod input;
pub mod job;
pub mod pipeline;
pub mod population;
pub mod recording;
pub mod residual_budget;
pub mod system;
