//! A population of gyro pairs: each member's resonators and front ends drawn from
//! distributions around the configured (nominal) ones ([`draw`]), and the study of one member
//! ([`study`]): both gyros' closed fixed-point loops characterized beside SPEC §1.6's closed
//! forms, then the pair run through the sequencer, the bias estimator and the KF.
//!
//! Everything here is a pure function of the nominal plans, the distributions, the seed and
//! the member's index: members can run in any order, on any thread or machine, and give the
//! same figures bit for bit. The loops' plans stay the nominal ones (the FPGA is the same for
//! every member); only the physics varies.

pub mod distribution;
pub mod draw;
pub mod study;

#[cfg(test)]
mod tests;
