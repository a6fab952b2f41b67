//! One gyro's closed drive/sense loop at the ADC rate `fs` (SPEC §1.6): the blocks of
//! [`super`] wired into a PLL, an AGC and a sense channel that turns the resonator's pick-off
//! codes into a rate in °/s at the chain's rate `fs / R`.
//!
//! # Architecture (per ADC sample `k`, mode `σ`)
//!
//! ```text
//!  adc_drive ──► demod_D (ref: NCO_D, offset 0) ──► Q_D ─► PLL (PI) ──► freq (next sample's NCO word)
//!                                                 └─► I_D ─► e_A = Q(a_set − I_D) ─► AGC (PI) ─► u
//!  NCO_T (offset δ_T) ─► cos ─► dac = Q(u · cos) ─► L-sample delay line ─► drive DAC
//!  adc_sense ──► demod_S (ref: NCO_S, offset δ_S[σ]) ──► I_S, Q_S ─► CIC_I, CIC_Q (÷R)
//!             ──► rate = Q(c_rate[σ] · CIC_I),  quadrature = Q(c_quad[σ] · CIC_Q)      (°/s)
//! ```
//!
//! Normal mode drives x (DAC 0) and senses y (ADC 1); reverse mode drives y and senses x.
//! The three NCOs take the same frequency word (their accumulators stay equal); the sense DAC
//! is held at 0 (the sense axis is open loop).
//!
//! # Design equations (from the nominal physics, [`Plan::new`])
//!
//! Units: `I`, `Q` and the setpoint in ADC full-scale units (the demodulators' output), the
//! frequency word in cycles per sample, the AGC output `u` in DAC LSB.
//!
//! - **Phases.** The drive DAC uses `cos` of NCO_T: at resonance the displacement lags the
//!   force by 90°, so it is then in phase with NCO_D's `sin` and `Q_D` is the phase error. The
//!   DAC value computed at sample `k` is output at `k + L` (`L` =
//!   `adc_to_dac_latency_samples`) and held for a sample, whose fundamental is centred half a
//!   sample later: NCO_T leads by `δ_T = (L + ½) f_nom / fs` cycles, corrected for the phase
//!   the AGC's proportional path adds with the drive demodulator's 2f ripple (derived in
//!   [`Plan::new`]'s helper `dac_offset`; 51 mHz of detuning at the defaults uncorrected).
//!   The sense reference is
//!   the drive displacement's phase shifted to the Coriolis component:
//!   `δ_S = −¼ − ψ/2π` cycles (`ψ = arg Z` of the mode, [`crate::resonator::ModeFigures`]);
//!   both pick-offs are sampled at the same instant and both demodulators run on the same
//!   sample, so no pipeline delay enters `δ_S`. Then `I_S = a_s (σΩ + B)` and
//!   `−Q_S = a_s Q/SF` with `a_s = (g_s/FS) A_nco SF` (closed forms of §1.6).
//! - **Setpoint.** `a_set = (g_a/FS) q0 A_nco` (`g_a` the driven axis's pick-off gain, `FS`
//!   the ADC full scale, `A_nco` the NCO amplitude).
//! - **PLL.** Near lock the resonator turns a frequency offset `Δω` into a phase error
//!   `e = −Δω/(s + 1/τ)` (`τ = 2m/d_mode`, the drive mode's ring-down, 7.15 ms), and
//!   `Q_D ≈ a_set e`. With `u = kp Q_D + ki Σ Q_D` (cycles/sample) and `ki fs / kp = 1/τ` the
//!   PI's zero cancels the resonator's pole: the open loop is `2π fs kp a_set / s` (times the
//!   demodulator's low-pass), a crossover at `f_pll = fs kp a_set`. So
//!   `kp = f_pll / (fs a_set)`, `ki = kp / (τ fs)`. The low-pass pole (`fs 2^−k`, 781 rad/s
//!   at the defaults) leaves `90° − atan(2π f_pll / (fs 2^−k))` of phase margin (81° at
//!   20 Hz).
//! - **AGC.** The amplitude follows the force with the same pole: `I_D = G u / (1 + sτ)`,
//!   `G = (g_a/FS) A_nco² N_lsb sinc(π f/fs) τ / (2 m w)` (FS per DAC LSB; `N_lsb` N per DAC
//!   LSB, the sinc is the DAC hold's gain at `f`). The same cancellation gives a crossover
//!   `ω = kp G / τ`: `kp = 2π f_agc τ / G`, `ki = kp / (τ fs)`; the nominal amplitude is
//!   `u_nom = a_set / G`. The closed loop has the poles `−2π f_agc` and `−1/τ`: the amplitude
//!   settles to 1e-3 in about `ln(1000) / min(2π f_agc, 1/τ)` (73 ms at 15 Hz).
//! - **Limits.** The PLL integrator stays within `pll_pull_range_hz` of the two modes'
//!   nominal frequencies, the AGC integrator within `[0, DAC full scale]` (anti-windup).
//! - Both are designed from normal mode (`a_set`, `τ`); in reverse mode `τ′` (7.62 ms) leaves
//!   a slow pole–zero doublet and the bandwidths scale with `a_set′/a_set` (1 with equal
//!   pick-off gains).
//! - **Scale.** `c_rate[σ] = σ / (a_s′ · g_CIC)` (°/s per FS unit; `a_s′` the sense gain per
//!   °/s, `g_CIC` the quantized CIC cascade's DC gain) and `c_quad = −1 / (a_s′ g_CIC)`, so the
//!   chain sees `Ω + B` (normal) and `Ω − B′` (reverse), and the quadrature channel reads the
//!   closed form's `Q/SF` in °/s.
//!
//! # At a mode switch
//!
//! When `mode` changes (applied before that sample): the PLL integrator is preset to the new
//! mode's nominal frequency word and the NCOs' frequency register loaded with it; the AGC
//! integrator, both demodulators' states, the lock filters, the lock counter and the DAC
//! delay line (it held values for the other axis) are cleared. The AGC starts from 0 on
//! purpose: with the pole–zero cancellation above, a zero initial state is exactly what makes
//! the amplitude rise as the first-order `q0 (1 − e^{−2π f_agc t})` without overshoot
//! (presetting `u_nom` excites the `−1/τ` mode as well and overshoots by tens of per cent).
//! The NCO accumulators and the CICs keep running (the output keeps its cadence; the
//! sequencer blanks the transient). The loop starts as if switched into normal mode.
//!
//! # Lock detector
//!
//! Each of `Q_D` and `e_A` passes a leaky integrator `z ← z − ⌊z·2^−s⌋ + e` (`s` =
//! `lock_filter_shift`; `z·2^−s` is the low-passed error in its own LSB, −3 dB at
//! `fs 2^−s / 2π`, which removes the demodulators' 2f ripple). `locked` is high once
//! `|z_Q| < a_set sin(lock_phase_deg) 2^s` and `|z_A| < lock_amplitude_tolerance · a_set 2^s`
//! have held for `lock_hold_ms`.
//!
//! # Quantization points
//!
//! Besides those inside the blocks ([`super`]'s table):
//!
//! | point | from (exact) | to | rounding | overflow |
//! |-------|--------------|----|----------|----------|
//! | ADC | volts | `adc_format` `s W.(W−1)` (FS units) | nearest (the resonator's ADC) | saturate |
//! | setpoint, presets, offsets (offline) | f64 | demod output / PI integrator / `u P.P` | convergent | refused if they do not fit |
//! | `e_A = a_set − I_D` | `s (W+1).F` | demodulator output format | exact | config |
//! | PLL output → NCO word | `s P.P` | `u P.P` | exact | wrap (mod one cycle) |
//! | DAC `u · cos` | `s (Wu+S).(Fu+S−1)` | `dac_format` | config | config |
//! | lock filters `⌊z·2^−s⌋` | `z` | integer | floor | never (`z` has `W + s + 1` bits) |
//! | `c_rate`, `c_quad` (offline) | f64 | `Auto` of `scale_coefficient_width` bits, one format | convergent | refused |
//! | rate, quadrature | `c · y_CIC` exact | `output_format` (°/s) | config | config |
//!
//! # Latency
//!
//! ADC to DAC: `L` samples (the DAC code output at sample `k` was computed from the ADC codes
//! of sample `k − L`; the frequency word reaches the NCO one sample after the PLL computed
//! it, as a PI's registered output does). The fixed model, the float twin and the RTL share
//! `L`. The rate and quadrature appear with the CIC's output, every `R`-th sample.

mod design;
mod fixed;
mod float;
mod overflows;
mod plan;
mod settings;

pub use design::{
    phase_shifts, trimmed_sense_offset, Design, LockPlan, ModePlan, PhaseInputs, PhaseShifts,
};
pub use fixed::{ChainSample, FixedGyroLoop, FixedStep};
pub use float::{FloatChainSample, FloatGyroLoop, FloatStep};
pub use overflows::{LoopNode, LoopOverflows};
pub use plan::{Plan, Spec};
pub use settings::LoopSettings;

use crate::resonator::Mode;

/// Index of `mode` in per-mode arrays: 0 normal, 1 reverse.
pub fn mode_index(mode: Mode) -> usize {
    match mode {
        Mode::Normal => 0,
        Mode::Reverse => 1,
    }
}

#[cfg(test)]
mod tests;
