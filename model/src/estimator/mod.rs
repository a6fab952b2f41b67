//! Bias estimator and calibration of mode reversal (SPEC §1.3, paper 004 §3).
//!
//! # What it does
//!
//! For each interval it sums the valid (not blanked) samples of each gyro and forms the
//! interval means `m = Q(Σ y · recip)` with `recip = 1/(L − M)` from the ROM (an exact shift
//! when `L − M` is a power of two). At the end of each window it solves the least-squares
//! problem of [`design`] — `b_new = Q(Σ_j G_j m_j)` for each gyro, `2W` multiplies, `G` from
//! the coefficient ROM (entries ±2^-n, as in the paper's cases, are constants that synthesis
//! turns into shifts) — and optionally smooths `b ← Q(b + 2^-s (b_new − b))` (shift-only; the
//! first estimate after reset is taken as is). Estimates from window `j` apply from the sample
//! after its end (causal).
//!
//! Every sample is calibrated with the current estimates: `out_g = Q(y_g − p_g·b_g)`, and
//! combined: `Q((out_A + out_B)/2)` when both are valid, the valid one otherwise. The combined
//! output feeds the KF, which steps only on samples with a valid combined value.
//!
//! # Parameters
//!
//! | parameter | meaning | default (gu2019) |
//! |-----------|---------|------------------|
//! | `interval_length` L, `intervals` W, `pattern`, `blank` M, `stagger` S | [`crate::sequencer`] | 150, 4, alternating, 10, 0 |
//! | `rate_order` r | rate polynomial over a window | 0 |
//! | `mean_format`, `bias_format` | °/s | input + 4 guard bits |
//! | `calibrated_format` | °/s, the KF's input | the KF input format |
//! | `gain_width`, `reciprocal_width` | coefficient widths (fraction bits automatic) | 18 |
//! | `smoothing_shift` s | 0 = no smoothing | 0 |
//!
//! # Interface (RTL `hdl/gyrofx_bias_estimator.v`, `hdl/gyrofx_calibration.v`)
//!
//! The estimator takes `y_a`, `y_b` (input format) and the sequencer's slot, and holds
//! `bias_a`, `bias_b` (bias format) and `estimated` in registers updated on the `ce` of a
//! window's last sample (visible from the next clock). The calibration is combinational:
//! `out_a`, `out_b`, `combined` (calibrated format), `valid_a`, `valid_b`, `combined_valid`.
//!
//! # Quantization points and the fixed-vs-float bound
//!
//! Means, new estimates, smoothing, calibrated outputs, combined output: all with the
//! configured rounding and overflow ([`Plan`]). Against the float model with the same
//! quantized gains and reciprocal, the estimates differ by at most
//! [`Plan::bias_error_bound`] (derived there), and each calibrated or combined output by that
//! plus its own rounding.

pub mod design;
mod fixed;
mod float;
mod plan;

pub use fixed::{FixedEstimator, OverflowCounts, Sample};
pub use float::{FloatEstimator, FloatSample};
pub use plan::{Plan, PlanError, Spec};

#[cfg(test)]
mod tests;
