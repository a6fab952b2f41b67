//! The sense-reference phase a gyro's closed loop realizes, derived from its plan (issue 32).
//!
//! The plan designs each mode's sense offset `δ_S = −¼ − ψ(f_nom)/2π` (cycles) so that the
//! sense reference lags the Coriolis component by exactly the configured phase error `φ`
//! (SPEC §1.6). The fixed loop realizes a slightly different phase `φ_r`, and since every
//! degree of phase leaks `dB/dφ = k_xy/(2 m w cos² φ)` of quadrature into the bias (2.9 °/s
//! per degree at the defaults), thousandths of a degree between the modes are what the
//! reversal residual `(B − B′)/2` is made of. Three terms move it, each derived here:
//!
//! 1. **The locked frequency.** The drive PLL locks at the coupled resonance `f_L` (where the
//!    driven axis's effective impedance is imaginary, [`coupled_resonance_hz`]), not at
//!    `f_nom = sqrt(k_aa/m)/2π`; the sense axis's phase `ψ(f) = arg(k_ss − m w² + i w d_ss)`
//!    there differs from the design's by `ψ(f_L) − ψ(f_nom)` (−0.0011° normal, +0.0014°
//!    reverse at the defaults, ±0.02° at a 2° stiffness angle). It is why the modes differ.
//! 2. **The PLL's proportional path.** The drive demodulator's `Q` carries a ripple at `2f`
//!    (`Im(a_set H(Ω) e^{2iθ})`, `H = α / (1 − (1 − α) e^{−iΩ})`, `α = 2^−k`, `Ω = 4π f/fs`);
//!    `kp` passes it to the frequency word, registered, and the accumulator integrates it: the
//!    NCO's phase is modulated by `Im(P e^{2iθ})` with
//!    `P = 2π kp a_set H e^{−2iΩ} / (1 − e^{−iΩ}) = |P| e^{iγ}`. A signal at phase `β`
//!    demodulated by that reference reads `β − (|P|/2) sin(2β − γ)` at a gain
//!    `1 + (|P|/2) cos(2β − γ)`. The PLL nulls the drive's reading (`β = 0`), so the sense
//!    signal, at `β_s = 2π δ_S + arg(k_xy + i w d_xy) + φ − π/2` against the NCO, reads
//!    `−(|P|/2)[sin(2β_s − γ) + sin γ]` beside its design phase (±0.00015° at the defaults),
//!    and the AGC, holding the drive's reading, leaves the sense gain
//!    `1 + (|P|/2)[cos(2β_s − γ) − cos γ]`.
//! 3. **The offset word.** `δ_S` is rounded to the NCO's `P` phase bits: the reference leads by
//!    `word·2^−P − frac(δ_S)` cycles more than designed (2e-8° at 32 bits, 6e-4° at 18).
//!
//! So `φ_r = φ − [ψ(f_L) − ψ(f_nom)] − (|P|/2)[sin(2β_s − γ) + sin γ] − 360°·(word·2^−P − frac δ_S)`,
//! and the sense gain is `g = |Z_ss(f_nom)| / |Z_ss(f_L)| · [1 + (|P|/2)(cos(2β_s − γ) − cos γ)]`.
//! The bias the loop outputs is then `g·B(φ_r)` (to first order; [`RealizedPhase::bias_dps`]
//! keeps the ratios that matter where the bias is large) and the residual is
//! `(g B(φ_r) − g′ B′(φ_r′))/2`.
//! The loop's latency and the DAC offset act only through `f_L` (below 5e-5°).
//!
//! **A resonator the plan was not made for** (a population's member under the nominal FPGA,
//! `gyrofx population`): the offset word was designed from the nominal sense axis's phase
//! `ψ_d(f_nom)`, so the member's reference also lags by its own axis's difference there,
//! `−[ψ(f_nom) − ψ_d(f_nom)]` ([`RealizedPhase::design_deg`]); the sense gain is
//! `|Z_d(f_nom)| / |Z(f_L)|`, and the loop's `1/SF` is the design's, `2 m_d w_d cos φ_d`. Both
//! terms vanish for the plan's own resonator. The design's drive amplitude is assumed (the
//! AGC holds the pick-off reading, so a member whose pick-off gain or ADC full scale differs
//! drives another amplitude, which scales its bias by the same ratio).
//!
//! With `[loop] phase_trim = true` the plan advances `δ_S` by the first two terms
//! ([`super::gyro::trimmed_sense_offset`]), so that the loop realizes the configured phase up to
//! the offset word's rounding; [`RealizedPhase::trim_deg`] is that advance. Only the per-mode
//! offset words (`SENSE_OFFSET_N`/`_R` of `gyrofx_gyro_loop`) change: the RTL is the same.
//!
//! The derivation leaves out the NCOs' phase truncation to `A + 2` bits. Plainly truncated, it
//! averages out except where `2^(A+2) f_L / fs` sits near a fraction of small denominator;
//! there it leaves a static phase error of up to about 0.3 bin (0.026° at `A = 10`) and, through
//! the DAC NCO, a sense gain error of up to 3e-4. With `[loop] nco_error_feedback` (the
//! default, see [`super::nco`]) no frequency leaves a static error, and the fixed loop realizes
//! the derived phase within about 2e-4° at the defaults; [`super::figures`] measures the gap
//! between the measured and the derived phase.

use std::f64::consts::PI;

use serde::Serialize;

use super::gyro::{phase_shifts, PhaseInputs, Plan};
use crate::resonator::{sense_impedance, Mode, ModeFigures, ResonatorParams};

/// One mode's realized reference phase, derived from the plan, with its parts. Phases in
/// degrees, positive when the reference lags the Coriolis component more (as `φ`).
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct RealizedPhase {
    /// The configured phase error `φ` (or `φ′`), deg.
    pub configured_deg: f64,
    /// `f_L`, the coupled resonance the drive locks on, Hz.
    pub locked_frequency_hz: f64,
    /// `−[ψ(f_L) − ψ(f_nom)]`: the sense axis's phase at the locked frequency against the
    /// design's, deg.
    pub locked_frequency_deg: f64,
    /// `−(|P|/2)[sin(2β_s − γ) + sin γ]`: the PLL's `2f` phase modulation, deg.
    pub pll_modulation_deg: f64,
    /// `−360°·(word·2^−P − frac δ_S)`: the offset word's rounding, deg.
    pub offset_word_deg: f64,
    /// `−360°·trim`: what `[loop] phase_trim` took off (0 without it), deg.
    pub trim_deg: f64,
    /// `−[ψ(f_nom) − ψ_d(f_nom)]`: the resonator's sense axis against the one the plan was
    /// designed for, at the design's frequency (0 for the plan's own resonator), deg.
    pub design_deg: f64,
    /// The sense gain against the design's: `|Z_ss(f_nom)|/|Z_ss(f_L)|` times the modulation's
    /// gain (1 − 5e-5 at the defaults).
    pub gain: f64,
    /// The loop's `1/SF` without `q0/|Z|`: `2 m w cos φ` of the design, N·s/m.
    #[serde(skip)]
    pub design_scale: f64,
}

impl RealizedPhase {
    /// `φ_r`, deg: the configured phase plus the derived parts and the trim.
    pub fn derived_deg(&self) -> f64 {
        self.configured_deg
            + self.locked_frequency_deg
            + self.pll_modulation_deg
            + self.offset_word_deg
            + self.trim_deg
            + self.design_deg
    }

    /// The bias the loop outputs in this mode, °/s (`B`'s sign, not the chain's), for
    /// `params`. The sense signal is `(q0/|Z_ss(f_L)|)(k_xy + i w_L d_xy) e^{iφ_r}` against the
    /// reference, and the loop divides its in-phase part by the design's scale factor
    /// `2 m w q0 cos φ / |Z_ss(f_nom)|`, so the output is
    /// `g [k_xy sin φ_r + w_L d_xy cos φ_r] / (2 m w cos φ)`: `g B(φ_r)` but for the ratios
    /// `w_L / w` and `cos φ_r / cos φ`, which matter where the bias is large (2e-5 of a 505 °/s
    /// bias is 10 mdps).
    pub fn bias_dps(&self, params: &ResonatorParams, _mode: Mode) -> f64 {
        let mats = params.matrices();
        let w_locked = 2.0 * PI * self.locked_frequency_hz;
        let phase = self.derived_deg().to_radians();
        let coupling = mats.k[0][1] * libm::sin(phase) + w_locked * mats.d[0][1] * libm::cos(phase);
        self.gain * (coupling / self.design_scale).to_degrees()
    }

    /// [`RealizedPhase::bias_dps`] in the chain's sign convention (`+B` normal, `−B′`
    /// reverse), as the loop's rate output reads it.
    pub fn chain_bias_dps(&self, params: &ResonatorParams, mode: Mode) -> f64 {
        ModeFigures::new(params, mode).sigma() * self.bias_dps(params, mode)
    }
}

/// The residual after reversal, `(g B(φ_r) − g′ B′(φ_r′))/2` in the chain's convention, °/s,
/// for the modes' realized phases `[normal, reverse]`.
pub fn residual_dps(params: &ResonatorParams, realized: &[RealizedPhase; 2]) -> f64 {
    (realized[0].chain_bias_dps(params, Mode::Normal)
        + realized[1].chain_bias_dps(params, Mode::Reverse))
        / 2.0
}

/// The realized reference phase of `mode` in the loop `plan` closes around `params`, derived
/// (see the [module doc](self)): the plan made for `params`, or another (a population's
/// nominal plan around a member).
pub fn derive(plan: &Plan, params: &ResonatorParams, mode: Mode) -> RealizedPhase {
    let m = plan.mode(mode);
    let shifts = phase_shifts(params, mode, &phase_inputs(plan, mode));
    let word = m.sense_offset_word as f64 * crate::fx::pow2(-(plan.nco.phase.width as i32));
    let exact = m.sense_offset - libm::floor(m.sense_offset);
    let design = &m.figures;
    // The same computation as the design's figures, so exactly the design's for its resonator.
    let (z_own, psi_own) = sense_impedance(params, mode, design.drive_angular_frequency);
    RealizedPhase {
        configured_deg: ModeFigures::new(params, mode).phase_error.to_degrees(),
        locked_frequency_hz: shifts.locked_frequency_hz,
        locked_frequency_deg: shifts.locked_frequency_deg,
        pll_modulation_deg: shifts.pll_modulation_deg,
        offset_word_deg: -360.0 * (word - exact),
        trim_deg: -360.0 * m.sense_offset_trim,
        design_deg: -(psi_own - design.sense_phase).to_degrees(),
        gain: shifts.gain * (design.sense_impedance / z_own),
        design_scale: 2.0
            * design.mass_kg()
            * design.drive_angular_frequency
            * libm::cos(design.phase_error),
    }
}

/// What [`phase_shifts`] needs of `plan`'s `mode`.
fn phase_inputs(plan: &Plan, mode: Mode) -> PhaseInputs {
    let m = plan.mode(mode);
    PhaseInputs {
        nominal_frequency_hz: m.nominal_frequency_hz,
        sense_offset: m.sense_offset,
        pll_kp: plan.pll.kp.quantized(),
        setpoint: m.setpoint,
        demod_lowpass_shift: plan.settings.demod_lowpass_shift,
        adc_rate_hz: plan.adc_rate_hz,
    }
}
