//! What each part of a gyro's loop costs in residual bias after reversal (issue 32): the
//! budget behind `gyrofx formats --residual-budget`.
//!
//! Mode reversal leaves `R = (B − B′)/2`, and at the configured phase errors `φ`, `φ′` that is
//! the closed form `R_c` of SPEC §1.6. The loop as built realizes other phases (see
//! [`super::realized_phase`]), and each degree a mode's phase moves costs `dB/dφ =
//! k_xy/(2 m w cos² φ)` °/s of bias (2.9 °/s per degree at the defaults), so half that in `R`.
//! The budget lists what moves `R` away from `R_c`, in the chain's sign convention, each part
//! either **derived** (a signed value the plan knows for this structure) or **bounded** (a
//! magnitude that holds for any locked frequency):
//!
//! | part | setting | kind | what |
//! |---|---|---|---|
//! | locked frequency | (the structure) | derived | `−[ψ(f_L) − ψ(f_nom)]` and `w_L/w` |
//! | PLL 2f modulation | `pll_bandwidth_hz`, `demod_lowpass_shift` | derived | the proportional path's phase |
//! | phase trim | `phase_trim` | derived | minus the two above |
//! | sense gain | (the structure, the PLL) | derived | `|Z_ss(f_nom)|/|Z_ss(f_L)|` and the modulation's gain |
//! | 1/SF coefficients | `scale_coefficient_width` | derived | each mode's rate coefficient's rounding |
//! | offset word | `nco_phase_bits` | bound | `δ_S` rounded to `P` bits: `180°·2^−P` |
//! | PLL frequency step | `nco_phase_bits`, `pll_bandwidth_hz` | bound | [`FREQUENCY_STEP_SHARE`] of `(fs/2^P)/(2π f_PLL)` rad: the word's dither |
//! | NCO truncation | `nco_address_bits`, `nco_error_feedback` | bound | [`FEEDBACK_TRUNCATION_BINS`] or [`PLAIN_TRUNCATION_BINS`] of `360°/2^(A+2)` of phase, [`FEEDBACK_TRUNCATION_GAIN`] or [`PLAIN_TRUNCATION_GAIN`] of a bin (rad) of gain |
//! | latency | `adc_to_dac_latency_samples` | bound | `δ_T` is exact at `f_nom`, not at `f_L` |
//! | output LSB | `output_format` | bound | half an LSB of the constant rate output |
//!
//! A bounded phase part `e` (deg, per mode) costs at most `(|s| e + |s′| e′)/2` of `R`, `s` the
//! mode's `dB/dφ`, and a bounded gain error `g` at most `g (|B| + |B′|)/2`. The budget's worst
//! case is `|Σ derived| + Σ bounds`.
//!
//! The budget leaves out a locked frequency on a small fraction of `fs` ([`small_fraction_near`]
//! names it, and `formats` warns): there the ROM's and the DAC's roundings repeat with the
//! NCO's few phases and leave a static phase of their own (1.4e-3° seen at 8000 Hz = 1/25 of
//! 200 kHz, gone 0.02 Hz away), which no NCO width takes away.
//!
//! The truncation's bounds are measured, not proven: over random structures (the realized-phase
//! property's ranges), the fixed loop's phase departed from its float twin's (which has no
//! truncation) by at most 0.0038 bin with error feedback (0.0044 at `A` = 12 and 13; rms
//! 0.0009; 3,400 modes at `A` = 6, 8, 9, 10 and 11 with `P` from 20 to 32), and its gain
//! (`|B + iQ|`) by at most 3.4e-3 per radian of a bin (1,000 of those modes); plainly
//! truncated, by up to 0.29 bin where `2^(A+2) f_L/fs` sits near a fraction of small
//! denominator. The offline sweep that checks it is
//! `GYROFX_TRUNCATION_CASES=200 GYROFX_TRUNCATION_A=8 GYROFX_TRUNCATION_P=20 cargo test
//! --release -p gyrofx-model --lib truncation_stays_within_its_budget`. With fewer
//! than [`MIN_RESIDUE_BITS`] bits under the truncation, or fewer than
//! [`MIN_FEEDBACK_PHASE_BITS`] phase bits, the carried error is too coarse for those figures
//! (0.26 bin at `A` = 6, `P` = 14), and the plain ones apply.

use serde::Serialize;

use super::closed::FloatHarness;
use super::figures::{characterize, Procedure};
use super::gyro::{Plan, Spec};
use super::realized_phase::{self, RealizedPhase};
use crate::resonator::{coupled_resonance_hz, sense_impedance, Mode, ModeFigures, ResonatorParams};

/// With `nco_error_feedback`, the most the truncation moves a mode's realized phase, in bins
/// of the `A + 2`-bit phase (0.0035 seen; see the module doc).
pub const FEEDBACK_TRUNCATION_BINS: f64 = 0.005;

/// Plainly truncated, the most the truncation moves a mode's realized phase, in bins (0.29
/// seen where `2^(A+2) f_L/fs` is near a small fraction).
pub const PLAIN_TRUNCATION_BINS: f64 = 0.3;

/// With `nco_error_feedback`, the most the truncation moves a mode's sense gain (relative),
/// per radian of a bin: the DAC NCO's truncation moves the drive's phase, the PLL the locked
/// frequency, and that the sense axis's gain (3.4e-3 seen; see the module doc).
pub const FEEDBACK_TRUNCATION_GAIN: f64 = 0.005;

/// Plainly truncated, the most the truncation moves a mode's sense gain, per radian of a bin
/// (3e-4 at `A` = 10, 0.2 per radian, seen near a small fraction).
pub const PLAIN_TRUNCATION_GAIN: f64 = 0.3;

/// The least phase bound of the truncation part, deg: where the bins are fine (14 address bits
/// and more) the fixed loop's other roundings (the ROM's words, the demodulators') are what
/// moves its phase from the twin's (3.9e-5° seen at 14 address bits, 3.5e-5° at 16).
pub const ROUNDINGS_FLOOR_DEG: f64 = 5e-5;

/// The least gain bound of the truncation part, relative (4e-7 seen at 16 address bits).
pub const ROUNDINGS_GAIN_FLOOR: f64 = 1e-6;

/// The share of `Δf/(2π f_PLL)` (rad) bounding the frequency step's phase wander (0.042
/// seen; see [`frequency_step_bound_deg`]).
pub const FREQUENCY_STEP_SHARE: f64 = 0.1;

/// Fewest bits below the truncation (`P − A − 2`) for which [`FEEDBACK_TRUNCATION_BINS`] was
/// measured.
pub const MIN_RESIDUE_BITS: u32 = 10;

/// Fewest phase bits for which [`FEEDBACK_TRUNCATION_BINS`] was measured (at `A` = 6,
/// `P` = 18 the PLL's 0.8 Hz frequency step let 0.007 bin through).
pub const MIN_FEEDBACK_PHASE_BITS: u32 = 20;

/// Largest denominator `q` of a fraction `p/q` of `fs` that [`small_fraction_near`] names.
pub const SMALL_FRACTION_DENOMINATOR: u32 = 100;

/// How close to `p/q · fs` a locked frequency must be for [`small_fraction_near`] to name it,
/// Hz (0.02 Hz away from 1/25 · 200 kHz the departure is down to 2e-5°).
pub const SMALL_FRACTION_WIDTH_HZ: f64 = 0.05;

/// The fraction `p/q` of `fs_hz` (in lowest terms, `q ≤` [`SMALL_FRACTION_DENOMINATOR`])
/// within [`SMALL_FRACTION_WIDTH_HZ`] of `f_hz`, if any. There the NCO visits only `q` phases
/// (its error feedback aside), so the ROM's and the DAC's roundings repeat instead of
/// averaging out and leave a static phase error of their own: 1.4e-3° at 8000 Hz = 1/25 of
/// 200 kHz with 18-bit words, 3e-4° at 6000 Hz = 3/100, 2e-5° at 8000.02 Hz.
pub fn small_fraction_near(f_hz: f64, fs_hz: f64) -> Option<(u32, u32)> {
    (1..=SMALL_FRACTION_DENOMINATOR).find_map(|q| {
        let p = libm::round(f_hz / fs_hz * f64::from(q));
        ((f_hz - p * fs_hz / f64::from(q)).abs() < SMALL_FRACTION_WIDTH_HZ).then_some((p as u32, q))
    })
}

/// How a part moves the residual.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Cost {
    /// By this much, °/s (signed, the chain's convention).
    Derived(f64),
    /// By at most this much, °/s.
    Bound(f64),
    /// By this much, °/s, measured on the float twin (see [`ResidualBudget::with_twin`]).
    Measured(f64),
}

/// One part of the budget.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Part {
    /// What it is (`locked frequency`, `NCO truncation`, ...).
    pub name: &'static str,
    /// The `[loop]` settings that set it, or `structure` where only the resonator does.
    pub settings: &'static str,
    /// What it does to each mode's phase, deg: normal, reverse (signed where derived, a
    /// magnitude where bounded; 0 for a part that moves the gain or the output only).
    pub phase_deg: [f64; 2],
    /// What it does to the residual.
    pub cost: Cost,
}

/// One gyro's residual budget.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct ResidualBudget {
    /// `|dB/dφ|` of each mode (normal, reverse), °/s per degree.
    pub slope_dps_per_deg: [f64; 2],
    /// `R_c`: the residual at the configured phases, °/s.
    pub configured_dps: f64,
    /// The parts, in the order of the module doc.
    pub parts: Vec<Part>,
    /// Each mode whose locked frequency sits on a small fraction `p/q` of `fs` (see
    /// [`small_fraction_near`]): the budget does not cover it.
    pub small_fractions: Vec<(&'static str, u32, u32)>,
}

impl ResidualBudget {
    /// The budget of the loop `plan` closes around `params` (`plan` made for `params`).
    pub fn new(plan: &Plan, params: &ResonatorParams) -> Self {
        let modes = [Mode::Normal, Mode::Reverse];
        let figures = modes.map(|mode| ModeFigures::new(params, mode));
        let realized = modes.map(|mode| realized_phase::derive(plan, params, mode));
        let slope = figures.map(|f| f.bias_sensitivity_to_phase().abs());
        let configured_dps = (figures[0].bias_dps() - figures[1].bias_dps()) / 2.0;
        let bounded =
            |phase: [f64; 2]| Cost::Bound((slope[0] * phase[0] + slope[1] * phase[1]) / 2.0);
        let mut parts = derived_parts(params, &figures, &realized, configured_dps);
        parts.push(coefficient_part(plan, params, &realized));
        let word = 180.0 * crate::fx::pow2(-(plan.nco.phase.width as i32));
        parts.push(Part {
            name: "offset word",
            settings: "nco_phase_bits",
            phase_deg: [word; 2],
            cost: bounded([word; 2]),
        });
        let step = frequency_step_bound_deg(plan);
        parts.push(Part {
            name: "PLL frequency step",
            settings: "nco_phase_bits, pll_bandwidth_hz",
            phase_deg: [step; 2],
            cost: bounded([step; 2]),
        });
        let (truncation, gain) = truncation_bounds(plan);
        let biases = figures.map(|f| f.bias_dps().abs());
        parts.push(Part {
            name: "NCO truncation",
            settings: "nco_address_bits, nco_error_feedback",
            phase_deg: [truncation; 2],
            cost: Cost::Bound(
                (slope[0] * truncation + slope[1] * truncation + gain * (biases[0] + biases[1]))
                    / 2.0,
            ),
        });
        let latency = modes.map(|mode| latency_bound_deg(plan, params, mode));
        parts.push(Part {
            name: "latency",
            settings: "adc_to_dac_latency_samples",
            phase_deg: latency,
            cost: bounded(latency),
        });
        parts.push(Part {
            name: "output LSB",
            settings: "output_format",
            phase_deg: [0.0; 2],
            cost: Cost::Bound(plan.output.to.lsb() / 2.0),
        });
        let small_fractions = modes
            .iter()
            .filter_map(|&mode| {
                small_fraction_near(coupled_resonance_hz(params, mode), plan.adc_rate_hz)
                    .map(|(p, q)| (mode.name(), p, q))
            })
            .collect();
        ResidualBudget {
            slope_dps_per_deg: slope,
            configured_dps,
            parts,
            small_fractions,
        }
    }

    /// Adds what the derivation leaves out, `leftover_dps`: the float twin's residual less
    /// the one predicted for it ([`twin_leftover_dps`]). The twin has the plan but no
    /// truncation, so this is the loop's continuous dynamics the closed forms miss (3e-5° of
    /// phase at the defaults, up to 3e-4° at a 2.5° stiffness angle).
    pub fn with_twin(mut self, leftover_dps: f64) -> Self {
        self.parts.push(Part {
            name: "float twin leftover",
            settings: "(what the derivation leaves out)",
            phase_deg: [0.0; 2],
            cost: Cost::Measured(leftover_dps),
        });
        self
    }

    /// `Σ derived` and measured, °/s: the residual the plan and the twin predict, less `R_c`.
    pub fn derived_dps(&self) -> f64 {
        self.parts
            .iter()
            .filter_map(|p| match p.cost {
                Cost::Derived(v) | Cost::Measured(v) => Some(v),
                Cost::Bound(_) => None,
            })
            .sum()
    }

    /// `Σ bounds`, °/s.
    pub fn bound_dps(&self) -> f64 {
        self.parts
            .iter()
            .filter_map(|p| match p.cost {
                Cost::Bound(v) => Some(v),
                Cost::Derived(_) | Cost::Measured(_) => None,
            })
            .sum()
    }

    /// `|Σ derived| + Σ bounds`, °/s: the most the loop as built moves the residual from `R_c`.
    pub fn worst_dps(&self) -> f64 {
        self.derived_dps().abs() + self.bound_dps()
    }
}

/// A derived part: its name, its settings, and what it copies from the realized phase into the
/// one being built (returning its phase, deg).
type Step = (
    &'static str,
    &'static str,
    fn(&mut RealizedPhase, &RealizedPhase) -> f64,
);

/// The derived phase parts, added one after the other onto the configured phases so that
/// they sum to the plan's prediction less `R_c` (the offset word's rounding aside).
fn derived_parts(
    params: &ResonatorParams,
    figures: &[ModeFigures; 2],
    realized: &[RealizedPhase; 2],
    configured_dps: f64,
) -> Vec<Part> {
    let nominal = figures.map(|f| RealizedPhase {
        configured_deg: f.phase_error.to_degrees(),
        locked_frequency_hz: f.drive_frequency_hz(),
        locked_frequency_deg: 0.0,
        pll_modulation_deg: 0.0,
        offset_word_deg: 0.0,
        trim_deg: 0.0,
        design_deg: 0.0,
        gain: 1.0,
        design_scale: 2.0 * f.mass_kg() * f.drive_angular_frequency * libm::cos(f.phase_error),
    });
    let steps: [Step; 4] = [
        ("locked frequency", "structure", |to, from| {
            to.locked_frequency_hz = from.locked_frequency_hz;
            to.locked_frequency_deg = from.locked_frequency_deg;
            from.locked_frequency_deg
        }),
        (
            "PLL 2f modulation",
            "pll_bandwidth_hz, demod_lowpass_shift",
            |to, from| {
                to.pll_modulation_deg = from.pll_modulation_deg;
                from.pll_modulation_deg
            },
        ),
        ("phase trim", "phase_trim", |to, from| {
            to.trim_deg = from.trim_deg;
            from.trim_deg
        }),
        ("sense gain", "structure, pll_bandwidth_hz", |to, from| {
            to.gain = from.gain;
            0.0
        }),
    ];
    let mut current = nominal;
    let mut before = configured_dps;
    steps
        .iter()
        .map(|(name, settings, step)| {
            let phase_deg = [0, 1].map(|i| step(&mut current[i], &realized[i]));
            let after = realized_phase::residual_dps(params, &current);
            let part = Part {
                name,
                settings,
                phase_deg,
                cost: Cost::Derived(after - before),
            };
            before = after;
            part
        })
        .collect()
}

/// Each mode's rate coefficient rounded to its format scales that mode's output bias by
/// `c_q/c`.
fn coefficient_part(plan: &Plan, params: &ResonatorParams, realized: &[RealizedPhase; 2]) -> Part {
    let moved = [Mode::Normal, Mode::Reverse].map(|mode| {
        let c = plan.mode(mode).rate_coefficient;
        let bias = realized[super::gyro::mode_index(mode)].chain_bias_dps(params, mode);
        bias * (c.quantized() / c.value - 1.0)
    });
    Part {
        name: "1/SF coefficients",
        settings: "scale_coefficient_width",
        phase_deg: [0.0; 2],
        cost: Cost::Derived((moved[0] + moved[1]) / 2.0),
    }
}

/// The most the NCOs' truncation moves a mode's phase, deg, and its sense gain (relative): a
/// share of a bin of the `A + 2`-bit phase (at least [`ROUNDINGS_FLOOR_DEG`]), and of that bin
/// in radians (at least [`ROUNDINGS_GAIN_FLOOR`]; see the module doc).
pub fn truncation_bounds(plan: &Plan) -> (f64, f64) {
    let nco = &plan.nco;
    let residue_bits = nco.phase.width - nco.address_bits - 2;
    let carried = nco.error_feedback
        && residue_bits >= MIN_RESIDUE_BITS
        && nco.phase.width >= MIN_FEEDBACK_PHASE_BITS;
    let (bins, gain_per_radian) = if carried {
        (FEEDBACK_TRUNCATION_BINS, FEEDBACK_TRUNCATION_GAIN)
    } else {
        (PLAIN_TRUNCATION_BINS, PLAIN_TRUNCATION_GAIN)
    };
    let bin_deg = 360.0 / crate::fx::pow2(nco.address_bits as i32 + 2);
    (
        (bins * bin_deg).max(ROUNDINGS_FLOOR_DEG),
        (gain_per_radian * bin_deg.to_radians()).max(ROUNDINGS_GAIN_FLOOR),
    )
}

/// The most the PLL's output rounded to the NCO's `P`-bit frequency word moves a mode's phase,
/// deg: [`FREQUENCY_STEP_SHARE`] of `Δf/(2π f_PLL)` rad, `Δf = fs/2^P` the word's step and
/// `f_PLL` the loop's crossover. The word dithers between two steps around the locked frequency
/// and the phase wanders with it over seconds (0.042 of `Δf/(2π f_PLL)` seen on a 1.2°
/// stiffness angle at 22 and 23 phase bits: 8e-4° at 22).
pub fn frequency_step_bound_deg(plan: &Plan) -> f64 {
    let step_hz = plan.adc_rate_hz * crate::fx::pow2(-(plan.nco.phase.width as i32));
    let crossover = 2.0 * std::f64::consts::PI * plan.settings.pll_bandwidth_hz;
    (FREQUENCY_STEP_SHARE * step_hz / crossover).to_degrees()
}

/// The latency's first-order effect on a mode's phase, deg. `δ_T` compensates the loop's
/// `L + ½` samples at `f_nom`, so at `f_L` the drive is `2π (f_L − f_nom)(L + ½)/fs` rad off;
/// the PLL takes that up by moving the drive frequency along the driven axis's phase slope
/// `2m/d` (rad per rad/s), and the sense phase moves along its own slope `dψ/dw`.
fn latency_bound_deg(plan: &Plan, params: &ResonatorParams, mode: Mode) -> f64 {
    let m = plan.mode(mode);
    let f_locked = coupled_resonance_hz(params, mode);
    let drive_rad = 2.0
        * std::f64::consts::PI
        * (f_locked - m.nominal_frequency_hz).abs()
        * (f64::from(plan.latency) + 0.5)
        / plan.adc_rate_hz;
    let [driven, _] = mode.axes();
    let mats = params.matrices();
    let moved_w = drive_rad * mats.d[driven][driven] / (2.0 * params.mass_kg);
    let w = 2.0 * std::f64::consts::PI * f_locked;
    let step = 1e-7 * w;
    let slope = (sense_impedance(params, mode, w + step).1
        - sense_impedance(params, mode, w - step).1)
        / (2.0 * step);
    (slope * moved_w).abs().to_degrees()
}

/// The `[loop]` settings the budget chooses: the NCO's widths, its error feedback and the
/// phase trim.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
pub struct NcoSettings {
    /// `nco_address_bits`, `A`.
    pub nco_address_bits: u32,
    /// `nco_phase_bits`, `P`.
    pub nco_phase_bits: u32,
    /// `nco_error_feedback`.
    pub nco_error_feedback: bool,
    /// `phase_trim`.
    pub phase_trim: bool,
}

impl NcoSettings {
    /// The settings `spec` has.
    pub fn of(spec: &Spec) -> Self {
        let s = &spec.settings;
        NcoSettings {
            nco_address_bits: s.nco_address_bits,
            nco_phase_bits: s.nco_phase_bits,
            nco_error_feedback: s.nco_error_feedback,
            phase_trim: s.phase_trim,
        }
    }

    /// `spec` with these settings.
    pub fn apply(&self, spec: &Spec) -> Spec {
        let mut spec = spec.clone();
        let s = &mut spec.settings;
        s.nco_address_bits = self.nco_address_bits;
        s.nco_phase_bits = self.nco_phase_bits;
        s.nco_error_feedback = self.nco_error_feedback;
        s.phase_trim = self.phase_trim;
        spec
    }
}

impl std::fmt::Display for NcoSettings {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "nco_address_bits = {}, nco_phase_bits = {}, nco_error_feedback = {}, phase_trim = {}",
            self.nco_address_bits, self.nco_phase_bits, self.nco_error_feedback, self.phase_trim
        )
    }
}

/// A budget's choice: the cheapest NCO (fewest ROM address bits, then fewest phase bits)
/// whose worst case meets the target for every gyro. Error feedback is always chosen (it
/// costs a `P − A − 2`-bit adder per NCO); the trim is the configured one unless the target
/// needs it on.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Choice {
    /// The settings chosen.
    pub settings: NcoSettings,
    /// Each gyro's budget with them.
    pub budgets: Vec<ResidualBudget>,
}

/// No NCO meets the target: the least worst case the finest NCO of any width leaves, °/s,
/// over the trims tried.
#[derive(Clone, Copy, Debug, PartialEq, thiserror::Error)]
#[error("no NCO of up to {max_address_bits} address bits and {MAX_CHOSEN_PHASE_BITS} phase bits{trim} meets it: the finest leaves {floor_mdps:.6} mdps (the sense gain's, the coefficients', the other roundings', the output's and the twin's own parts)", max_address_bits = super::nco::MAX_ADDRESS_BITS, trim = if *only_trimmed { ", trimmed," } else { ", with or without the phase trim," }, floor_mdps = 1e3 * floor_dps)]
pub struct Unreachable {
    /// The floor, °/s.
    pub floor_dps: f64,
    /// Only the trimmed loop was tried (the config trims).
    pub only_trimmed: bool,
}

/// Smallest `A` the chooser tries (a 16-word quarter-wave ROM).
const MIN_CHOSEN_ADDRESS_BITS: u32 = 4;
/// Largest `P` the chooser tries.
const MAX_CHOSEN_PHASE_BITS: u32 = 40;

/// The cheapest NCO and trim whose worst case (see [`ResidualBudget::worst_dps`]) is at most
/// `target_dps` for each of `gyros` (each gyro's spec, which share the `[loop]` settings, and
/// its [`twin_leftover_dps`], measured as configured and taken for every candidate).
///
/// # Errors
/// [`Unreachable`], naming the floor, when no NCO meets the target.
pub fn choose(gyros: &[(Spec, f64)], target_dps: f64) -> Result<Choice, Unreachable> {
    let only_trimmed = gyros[0].0.settings.phase_trim;
    let trims: &[bool] = if only_trimmed {
        &[true]
    } else {
        &[false, true]
    };
    let budgets = |settings: NcoSettings| -> Option<Vec<ResidualBudget>> {
        gyros
            .iter()
            .map(|(spec, leftover)| {
                let spec = settings.apply(spec);
                Plan::new(&spec)
                    .ok()
                    .map(|plan| ResidualBudget::new(&plan, &spec.resonator).with_twin(*leftover))
            })
            .collect()
    };
    let worst = |b: &[ResidualBudget]| b.iter().map(ResidualBudget::worst_dps).fold(0.0, f64::max);
    let mut floor_dps = f64::INFINITY;
    for a in MIN_CHOSEN_ADDRESS_BITS..=super::nco::MAX_ADDRESS_BITS {
        let lowest = (a + 2 + MIN_RESIDUE_BITS).max(MIN_FEEDBACK_PHASE_BITS);
        for &phase_trim in trims {
            let settings = |p: u32| NcoSettings {
                nco_address_bits: a,
                nco_phase_bits: p,
                nco_error_feedback: true,
                phase_trim,
            };
            // The finest NCO of this A the loop accepts first (the PLL's integrator must
            // resolve its frequency step): if it misses, no coarser P meets the target.
            let Some((finest, budget)) = (lowest..=MAX_CHOSEN_PHASE_BITS)
                .rev()
                .find_map(|p| budgets(settings(p)).map(|b| (p, b)))
            else {
                continue;
            };
            floor_dps = floor_dps.min(worst(&budget));
            if worst(&budget) > target_dps {
                continue;
            }
            for p in lowest..=finest {
                if let Some(budgets) = budgets(settings(p)).filter(|b| worst(b) <= target_dps) {
                    return Ok(Choice {
                        settings: settings(p),
                        budgets,
                    });
                }
            }
        }
    }
    Err(Unreachable {
        floor_dps,
        only_trimmed,
    })
}

/// The float twin's residual less the one the plan predicts for `spec`, °/s, noise off.
///
/// # Errors
/// A spec the loop refuses, or a twin that does not lock.
pub fn twin_leftover_dps(spec: &Spec) -> Result<f64, String> {
    let plan = Plan::new(spec).map_err(|e| e.to_string())?;
    let c = characterize::<FloatHarness>(
        &plan,
        &spec.resonator,
        &spec.front_end,
        &Procedure::default(),
    )
    .map_err(|e| e.to_string())?;
    Ok(c.residual_bias_dps.measured - c.residual_bias_dps.predicted)
}

#[cfg(test)]
mod tests;
