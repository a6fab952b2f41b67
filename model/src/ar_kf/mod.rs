//! Scalar Kalman filter on an AR(1) drift model (paper 003): gain schedule, plan, fixed-point
//! model, float golden model.
//!
//! # What it does
//!
//! Paper 003 fits the gyro drift as AR(1), `x_k = φ·x_{k−1} + a_k` (`a_k` white, variance
//! `Q = σ_a²`), observes it as `z_k = x_k + v_k` (`v_k` white, variance `R`) and filters with
//! `A = φ`, `B = 1`, `H = 1`, `P0 = 0`, `x̂0 = z0`:
//!
//! ```text
//! P⁻ = φ²·P + Q      K = P⁻ / (P⁻ + R)      P = (1 − K)·P⁻        (offline: the schedule)
//! x̂_k = φ·x̂_{k−1} + K_k·(z_k − φ·x̂_{k−1}) = a_k·x̂_{k−1} + K_k·z_k,   a_k = (1 − K_k)·φ
//! ```
//!
//! The gains depend on the data only through `k`, so they are computed once ([`schedule`]):
//! `K_1, K_2, …` until they settle (relative change ≤ `tolerance`) or the schedule reaches its
//! length limit; the last entry is then used for every later sample. The fixed-point filter
//! reads `(a_k, K_k)` from that schedule (a ROM in hardware), forms `a_k·x̂ + K_k·z` exactly and
//! quantizes once into the state format; the output is the state quantized to the output format.
//!
//! # Error vs the float model
//!
//! With the same quantized coefficients, the only difference is the state rounding `ρ_k`
//! (`|ρ| ≤ r·LSB`, `r` the rounding mode's largest error): `e_k = a_k·e_{k−1} + ρ_k`, `e_0 = 0`
//! (`x̂0 = z0` is exact), so `|e_k| ≤ r·LSB_state / (1 − max|a_k|)`; plus the output rounding.
//! [`Plan::error_bound_lsb`] states it in output LSB, and a property test checks it.

mod fixed;
mod float;
mod plan;

pub use fixed::FixedArKf;
pub use float::FloatArKf;
pub use plan::{schedule, Plan, PlanError, Spec};

#[cfg(test)]
mod tests;
