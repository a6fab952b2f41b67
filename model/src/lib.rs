//! gyrofx-model: the bit-accurate fixed-point core, the float golden models beside it, and
//! the offline design algebra of the gyro signal chain.
//!
//! Data flows one way: a config is resolved into a *plan* (every node's format, every ROM's
//! contents), and both the models here and the writers in `gyrofx-codegen` read that plan.
#![warn(missing_docs)]

pub mod analysis;
pub mod ar_kf;
pub mod chain;
pub mod estimator;
pub mod examples;
pub mod fx;
pub mod gyro_loop;
pub mod kf;
pub mod mean_filter;
pub mod plant;
pub mod range;
pub mod resonator;
pub mod sequencer;
pub mod serial;
pub mod stimulus;
pub mod system;
