//! What the design produces besides the blocks' plans: the per-mode constants, the lock
//! detector, the unquantized gains, and the drive phase correction.

use std::f64::consts::PI;

use crate::gyro_loop::Coefficient;
use crate::resonator::{Mode, ModeFigures};

/// The float values the design produced (before quantization), for the float twin and the
/// report.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Design {
    /// PLL `kp` (cycles/sample per FS unit) and `ki` (per sample).
    pub pll_gains: [f64; 2],
    /// AGC `kp` (DAC LSB per FS unit) and `ki` (per sample).
    pub agc_gains: [f64; 2],
    /// The PLL integrator's limits, cycles per sample.
    pub pll_limits: [f64; 2],
    /// The AGC integrator's limits, DAC LSB.
    pub agc_limits: [f64; 2],
}

/// Everything that differs between the modes.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ModePlan {
    /// The mode.
    pub mode: Mode,
    /// The closed forms of the mode.
    pub figures: ModeFigures,
    /// `a_set`, FS units, and its code (demodulator output format).
    pub setpoint: f64,
    /// Code of `a_set`.
    pub setpoint_code: i64,
    /// Nominal drive frequency `sqrt(k_aa/m)/2π`, Hz.
    pub nominal_frequency_hz: f64,
    /// `f_nom / fs`, cycles per sample, and the PLL integrator's preset code.
    pub frequency: f64,
    /// The PLL integrator's preset code.
    pub pll_preset: i64,
    /// `f_nom / fs` as the NCO's `u P.P` word: loaded into the NCOs' frequency register at
    /// a switch (the PLL's registered output is the old mode's until its next sample).
    pub frequency_word: u64,
    /// `G`: FS units of `I_D` per DAC LSB of AGC output, at resonance.
    pub plant_gain: f64,
    /// `u_nom = a_set / G`, DAC LSB: the AGC output the mode needs.
    pub nominal_amplitude: f64,
    /// `δ_T`, cycles, and its `u P.P` word.
    pub dac_offset: f64,
    /// Word of `δ_T`.
    pub dac_offset_word: u64,
    /// `δ_S`, cycles, and its word.
    pub sense_offset: f64,
    /// Word of `δ_S`.
    pub sense_offset_word: u64,
    /// `a_s′ g_CIC`: FS units at the CIC output per °/s.
    pub sense_gain_per_dps: f64,
    /// `c_rate = σ / (a_s′ g_CIC)`, °/s per FS unit.
    pub rate_coefficient: Coefficient,
    /// `c_quad = −1 / (a_s′ g_CIC)`, °/s per FS unit.
    pub quadrature_coefficient: Coefficient,
    /// Lock limits on `z_Q` and `z_A` (codes of the demodulator output times `2^s`).
    pub lock_limits: [i64; 2],
}

/// The lock detector.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct LockPlan {
    /// `s`.
    pub shift: u32,
    /// Samples both errors must stay within their limits.
    pub hold_samples: u32,
}

/// `δ_T` in cycles: the delay compensation `delay` (cycles) corrected for the phase that the
/// AGC's proportional path adds to the drive. The drive demodulator's `I` carries a ripple
/// `−a_set |H| cos(2θ + η)` at twice the drive frequency (`H = 2^−k / (1 − (1 − 2^−k) e^{−iΩ})`
/// at `Ω = 4π f/fs`, `η = arg H`); `kp` passes it to `u`, and `u cos(θ + δ)` then holds a
/// fundamental `½ kp a_set |H| cos(θ + η − δ)` beside `u_nom cos(θ + δ)`: the drive's phase
/// moves by `r sin(η − 2δ)` with `r = kp a_set |H| / (2 u_nom)` (`ripple_ratio` is
/// `kp a_set / (2 u_nom)`). Uncorrected this detunes the drive by `f/(2Q) · r sin(η − 2δ)`
/// (12 mHz at the defaults, 51 mHz with `k` = 8). Solved by fixed-point iteration.
pub(super) fn dac_offset(delay: f64, frequency: f64, shift: u32, ripple_ratio: f64) -> f64 {
    let alpha = crate::fx::pow2(-(shift as i32));
    let omega = 4.0 * PI * frequency;
    let re = 1.0 - (1.0 - alpha) * libm::cos(omega);
    let im = (1.0 - alpha) * libm::sin(omega);
    let magnitude = alpha / libm::hypot(re, im);
    let eta = -libm::atan2(im, re);
    let r = ripple_ratio * magnitude;
    let target = 2.0 * PI * delay;
    let mut delta = target;
    for _ in 0..4 {
        delta = target - r * libm::sin(eta - 2.0 * delta);
    }
    delta / (2.0 * PI)
}
