//! gyrofx-lab: the only code that runs external programs. It takes what codegen writes (a
//! verification package, a design's files) and runs it: the simulators on a package
//! ([`simulate`], with [`junit`] summaries), yosys on the chain and the loop ([`synth`]),
//! yosys and nextpnr per block ([`place_route`]), word-length sweeps costed in yosys
//! ([`explore`]), the papers' figures ([`reproduce`]) and the plots ([`plot`]). Every external
//! program is found, versioned and run through [`toolchain`] (its children tracked by
//! [`processes`], which ends them all when a signal ends gyrofx), and work runs side by side in
//! one [`pool`].
//!
//! It stands on codegen, the job and the model, and nothing below it knows it exists: the CLI
//! is its only user.
//!
//! Work runs side by side in the one pool, results in item order:
//!
//! ```
//! let squares = gyrofx_lab::pool::map(&[1, 2, 3, 4], 2, |x| x * x);
//! assert_eq!(squares, [1, 4, 9, 16]);
//! ```
#![warn(missing_docs)]

pub mod explore;
pub mod junit;
pub mod place_route;
pub mod plot;
pub mod pool;
pub mod population;
pub mod processes;
pub mod reproduce;
pub mod simulate;
pub mod synth;
pub mod toolchain;
