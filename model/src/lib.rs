//! gyrofx-model: the bit-accurate fixed-point core, the float golden models beside it, and
//! the offline design algebra of the gyro signal chain.
//!
//! Data flows one way: a config is resolved into a *plan* (every node's format, every ROM's
//! contents), and both the models here and the writers in `gyrofx-codegen` read that plan.
//!
//! Every quantization point goes through [`fx`]: a real value or a wider code into a format,
//! with the RTL's rounding and overflow.
//!
//! ```
//! use gyrofx_model::fx::{from_f64, Format, Overflow, Rounding};
//!
//! let format: Format = "s8.4".parse().unwrap(); // signed, 8-bit word, 4 fraction bits
//! let q = from_f64(1.53, format, Rounding::Nearest, Overflow::Saturate).unwrap();
//! assert_eq!(q.code, 24); // 1.53 · 16 = 24.48 → 24, i.e. 1.5
//! assert!(!q.overflowed);
//! let big = from_f64(100.0, format, Rounding::Nearest, Overflow::Saturate).unwrap();
//! assert_eq!((big.code, big.overflowed), (127, true)); // saturated, and counted
//! ```
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
pub mod population;
pub mod range;
pub mod resonator;
pub mod sequencer;
pub mod serial;
pub mod stimulus;
pub mod system;
