//! The time-multiplexed ("serial") architecture of the chain: one 16×16 signed multiplier,
//! one column accumulator and a data RAM of 15-bit limbs, run by a program that
//! [`compile`] derives from the chain's plan.
//!
//! The program performs the model's arithmetic exactly ([`crate::chain::FixedChain`]): the
//! same exact sums, the same quantization points with the same rounding and overflow, in
//! the same order, so the same vectors hold for both architectures; only the latency
//! differs ([`Program::clocks_per_sample`]). [`Engine`] executes the program as the RTL
//! (`gyrofx_serial_engine`) does; the tests hold it to `FixedChain` sample by sample.
//!
//! The instruction set is in [`isa`]; how a sum of products and a requantization become
//! instructions is in [`compile`].

pub mod compile;
pub mod engine;
pub mod isa;

pub use compile::{compile, CompileError, Program};
pub use engine::{Engine, Outputs};

#[cfg(test)]
mod tests;
