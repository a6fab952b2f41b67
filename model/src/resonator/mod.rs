//! The resonator-level gyro (SPEC §1.6; simulation only, float, deterministic): the 2-DOF
//! vibratory structure that the fixed-point drive and sense loops close around.
//!
//! - [`params`]: the structure ([`ResonatorParams`], the `[resonator_a]` / `[resonator_b]`
//!   config sections) and its stiffness and damping matrices.
//! - [`closed_form`]: scale factor, bias, quadrature and the mode-reversal residual per mode,
//!   the oracle the simulation reproduces.
//! - [`physics`]: [`Resonator`], the simulation at the ADC rate.
//! - [`expm`]: the deterministic matrix exponential behind the discretisation.
//!
//! # Equation of motion
//!
//! Displacements `q = [x, y]` (m), input rate `Ω` (rad/s), forces `τ` (N):
//!
//! ```text
//! m q″ + D q′ + K q = τ + G q′ + f_th,     G = [[0, 2mΩ], [−2mΩ, 0]]
//! ```
//!
//! `m` in kg, `K` in N/m, `D` in N·s/m (see [`params`]). `f_th` is the thermomechanical force:
//! white, one-sided PSD `4 k_B T D` (N²/Hz), i.e. `sqrt(4 k_B T d_i)` N/√Hz along each
//! principal damping axis, independent between them. Normal mode drives x and senses y,
//! reverse mode drives y and senses x; the mechanics are the same in both, so the Coriolis
//! force on the sense axis flips sign with the roles by itself.
//!
//! # Discretisation (exact zero-order hold)
//!
//! With the state `s = [x, y, x′/w0, y′/w0]` (all in m; `w0 = sqrt((k1+k2)/2m)` balances the
//! matrix) and `s′ = A s + B τ`, the force is held over each sample period `T = 1/fs`, so
//!
//! ```text
//! s(k+1) = Φ s(k) + Γ τ(k) + n(k),    Φ = e^{AT},  Γ = ∫₀ᵀ e^{Aσ} dσ B
//! ```
//!
//! exactly, both from one 6×6 exponential `e^{[[A, B], [0, 0]] T}`. The thermomechanical part
//! `n(k)` is the exact integral of the continuous white force over the period: Gaussian with
//! covariance `Q_d = ∫₀ᵀ e^{Aσ} B Q_c Bᵀ e^{Aᵀσ} dσ`, `Q_c = 2 k_B T D` (Van Loan's 8×8
//! exponential), drawn as `L·[n1..n4]` with `L` its Cholesky factor. So the sampled state has
//! exactly the continuous system's statistics, e.g. `⟨q qᵀ⟩ = k_B T K⁻¹` and
//! `⟨q′ q′ᵀ⟩ = k_B T/m · I` at equilibrium. `Φ`, `Γ` and `L` depend on `Ω` and on the drifting
//! damping: they are recomputed when [`Resonator::set_rate`] changes `Ω` and when the drifts
//! advance (every `drift_update_samples`), never per sample; the per-sample step is a 4×4
//! matrix–vector product plus `Γ τ` (plus `L n` with noise).
//!
//! # Pick-off, phase error, ADC and DAC
//!
//! The DAC turns codes into forces, `τ = code · dac_newton_per_lsb` (N), held over a sample.
//! The pick-off voltages are sampled at the end of each period (V):
//!
//! ```text
//! driven axis a:  v_a = g_a q_a                          + e_a
//! sensed axis s:  v_s = g_s (cos φ q_s + sin φ q_s′ / w) + e_s
//! ```
//!
//! with `g` the pick-off gain (V/m), `e` white electronic noise (`σ = e_n sqrt(fs/2)` V per
//! sample for a density `e_n` V/√Hz), `w` the mode's nominal drive resonance
//! (`sqrt(kxx/m)` normal, `sqrt(kyy/m)` reverse) and `φ` the mode's phase error (`φ` normal,
//! `φ′` reverse, in radians, plus the phase drift). At the drive frequency `w` this is the
//! sense signal advanced by exactly `φ` with unit gain (phasor `cos φ + i sin φ = e^{iφ}`):
//! it stands for the sense channel's front end (charge amplifier, anti-alias filter) whose
//! phase the design did not compensate. A demodulation reference designed from the nominal
//! physics (phase of the drive displacement, minus `ψ = arg Z`, shifted to the Coriolis
//! component) therefore lags the Coriolis component of the sensed signal by `φ`, and the
//! in-phase output follows [`closed_form`]: `I = SF (σΩ + B)` with `SF = 2 m w q0 cos φ / |Z|`
//! and `B = d_xy/(2m) + k_xy tan φ/(2 m w)`. The driven axis's pick-off has no phase error,
//! so the drive loop is unaffected. [`Resonator::set_mode`] selects which axis is sensed;
//! the fixed-point loop's `mode` input must follow it.
//!
//! The ADC maps volts to codes `round(v · 2^(w−1) / full_scale)` (nearest, ties toward +∞),
//! saturating to `w` bits.
//!
//! # Drift
//!
//! First-order Gauss–Markov processes (stationary from the start, each on its own stream)
//! move the damping split `d1 − d2` (by `δ·(d1+d2)/2`, keeping the mean; neither principal
//! damping falls below 10 % of its nominal value), the damping angle `θ`, and the phase error
//! (the same offset on `φ` and `φ′`: one front end). They change `B` through `d_xy` and the
//! quadrature leak, so the bias drifts for physical reasons.
//!
//! # Random streams and determinism
//!
//! Every source has its own ChaCha8 stream ([`crate::stimulus::ResonatorSource`]): the
//! thermomechanical force, each pick-off's noise, each drift. Turning one source on or off
//! does not change another's realisation. [`PhysicsSettings::noise`] off disables all of them.
//! Everything on the path to the ADC uses `+ − × ÷`, `sqrt` (both correctly rounded by
//! IEEE 754) and the pure-Rust `libm`, so one seed gives bit-identical codes everywhere.
//!
//! # Units
//!
//! | quantity | unit |
//! |----------|------|
//! | displacement, drive amplitude `q0` | m |
//! | velocity | m/s |
//! | force, DAC LSB | N |
//! | rate `Ω`, bias `B`, quadrature (rate-equivalent) | rad/s (`*_dps` accessors: °/s) |
//! | scale factor `SF` | m per rad/s (`scale_factor_m_per_dps`: m per °/s) |
//! | pick-off output, ADC full scale | V |
//! | frequencies | Hz in the config, rad/s as `w` |
//! | angles `ε`, `θ`, `φ` | degrees in the config, rad inside |

pub mod closed_form;
pub mod expm;
mod noise;
pub mod params;
pub mod physics;
pub mod settings;

pub use closed_form::{coupled_resonance_hz, sense_impedance, ModeFigures, Reversal};
pub use params::{Matrices, ParamError, ResonatorParams};
pub use physics::{Resonator, BOLTZMANN_J_PER_K};
pub use settings::{GaussMarkov, PhysicsSettings};

/// Which axis is driven: the mode of mode reversal.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Mode {
    /// x driven at `sqrt(kxx/m)`, y sensed; `σ = +1`.
    Normal,
    /// y driven at `sqrt(kyy/m)`, x sensed; `σ = −1`.
    Reverse,
}

impl Mode {
    /// `[driven, sensed]` axis (0 = x, 1 = y).
    pub fn axes(self) -> [usize; 2] {
        match self {
            Mode::Normal => [0, 1],
            Mode::Reverse => [1, 0],
        }
    }

    /// `normal` or `reverse`, as reports and the config name it.
    pub fn name(self) -> &'static str {
        match self {
            Mode::Normal => "normal",
            Mode::Reverse => "reverse",
        }
    }
}

#[cfg(test)]
mod tests;
