//! gyrofx-job: what one run of gyrofx is, before anything is written or simulated.
//!
//! [`config::Config`] (the TOML, its validation and the presets) → [`job::Job`] (the KF
//! designs and every block's plan, from `gyrofx-model`), with its inputs read by [`input`]
//! (bounded CSV) and [`recording`]; [`formats`] proves the formats the job's plans use, and
//! [`golden`] gives the port-level models a testbench steps sample by sample. It knows no
//! output file, template, simulator or synthesis tool: the codegen crate turns a job into a
//! verification package, and the Python and C bindings stand on this crate and the model
//! alone.
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
pub mod recording;
pub mod system;
