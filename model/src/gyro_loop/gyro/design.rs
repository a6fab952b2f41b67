//! What the design produces besides the blocks' plans: the per-mode constants, the lock
//! detector, the unquantized gains, and the drive phase correction.

use std::f64::consts::PI;

use crate::gyro_loop::Coefficient;
use crate::resonator::{coupled_resonance_hz, sense_impedance, Mode, ModeFigures, ResonatorParams};

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
    /// What `[loop] phase_trim` added to `δ_S`, cycles (0 without it).
    pub sense_offset_trim: f64,
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

/// What the realized sense-reference phase of a mode depends on besides the structure (see
/// `gyro_loop::realized_phase` for the derivation).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PhaseInputs {
    /// `f_nom`, the frequency `δ_S` is designed at, Hz.
    pub nominal_frequency_hz: f64,
    /// `δ_S`, cycles (as designed, before rounding).
    pub sense_offset: f64,
    /// The PLL's quantized `kp`, cycles/sample per FS unit.
    pub pll_kp: f64,
    /// `a_set`, FS units.
    pub setpoint: f64,
    /// The demodulators' low-pass shift `k`.
    pub demod_lowpass_shift: u32,
    /// `fs`, Hz.
    pub adc_rate_hz: f64,
}

/// The shifts of a mode's realized phase that the design can know: at the coupled resonance
/// `f_L` the drive locks on, the sense axis's phase moves by `ψ(f_L) − ψ(f_nom)` and the PLL's
/// proportional path modulates the NCO. Phases in degrees, positive when the reference lags
/// the Coriolis component more.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PhaseShifts {
    /// `f_L`, Hz.
    pub locked_frequency_hz: f64,
    /// `−[ψ(f_L) − ψ(f_nom)]`, deg.
    pub locked_frequency_deg: f64,
    /// `−(|P|/2)[sin(2β_s − γ) + sin γ]`, deg.
    pub pll_modulation_deg: f64,
    /// `|Z_ss(f_nom)|/|Z_ss(f_L)| · [1 + (|P|/2)(cos(2β_s − γ) − cos γ)]`.
    pub gain: f64,
}

/// `|P|` and `γ = arg P` of the PLL's `2f` phase modulation at `f_hz`:
/// `P = 2π kp a_set H e^{−2iΩ} / (1 − e^{−iΩ})`, `H = α / (1 − (1 − α) e^{−iΩ})`, `Ω = 4π f/fs`.
fn pll_modulation(inputs: &PhaseInputs, f_hz: f64) -> (f64, f64) {
    let omega = 4.0 * PI * f_hz / inputs.adc_rate_hz;
    let alpha = crate::fx::pow2(-(inputs.demod_lowpass_shift as i32));
    let (h_re, h_im) = (
        1.0 - (1.0 - alpha) * libm::cos(omega),
        (1.0 - alpha) * libm::sin(omega),
    );
    let (h_abs, h_arg) = (alpha / libm::hypot(h_re, h_im), -libm::atan2(h_im, h_re));
    // 1 − e^{−iΩ}: the accumulator's integration of the registered word.
    let (d_re, d_im) = (1.0 - libm::cos(omega), libm::sin(omega));
    let magnitude = 2.0 * PI * inputs.pll_kp * inputs.setpoint * h_abs / libm::hypot(d_re, d_im);
    (magnitude, h_arg - 2.0 * omega - libm::atan2(d_im, d_re))
}

/// The [`PhaseShifts`] of `mode` of `params` under `inputs`.
pub fn phase_shifts(params: &ResonatorParams, mode: Mode, inputs: &PhaseInputs) -> PhaseShifts {
    let f = ModeFigures::new(params, mode);
    let f_locked = coupled_resonance_hz(params, mode);
    let (z_nominal, psi_nominal) =
        sense_impedance(params, mode, 2.0 * PI * inputs.nominal_frequency_hz);
    let (z_locked, psi_locked) = sense_impedance(params, mode, 2.0 * PI * f_locked);
    let (p_abs, gamma) = pll_modulation(inputs, f_locked);
    // The sense signal's phase against the NCO's sine.
    let beta = 2.0 * PI * inputs.sense_offset
        + f.mechanical_angle(f.drive_angular_frequency)
        + f.phase_error
        - PI / 2.0;
    let modulation_phase = -(p_abs / 2.0) * (libm::sin(2.0 * beta - gamma) + libm::sin(gamma));
    let modulation_gain = 1.0 + (p_abs / 2.0) * (libm::cos(2.0 * beta - gamma) - libm::cos(gamma));
    PhaseShifts {
        locked_frequency_hz: f_locked,
        locked_frequency_deg: -(psi_locked - psi_nominal).to_degrees(),
        pll_modulation_deg: modulation_phase.to_degrees(),
        gain: z_nominal / z_locked * modulation_gain,
    }
}

/// `δ_S` (cycles) trimmed so that the loop realizes the configured phase: the design's
/// `δ_S` advanced by the shifts it can know, `(Δψ_L + Δ_PLL)/360°`. The modulation depends on
/// `δ_S` through `β_s`, so the trim is iterated (it moves by 1e-9 cycles after two steps).
pub fn trimmed_sense_offset(params: &ResonatorParams, mode: Mode, inputs: &PhaseInputs) -> f64 {
    let mut trimmed = *inputs;
    for _ in 0..3 {
        let shifts = phase_shifts(params, mode, &trimmed);
        trimmed.sense_offset =
            inputs.sense_offset + (shifts.locked_frequency_deg + shifts.pll_modulation_deg) / 360.0;
    }
    trimmed.sense_offset
}
