//! CIC decimator with a droop-compensation FIR: the sense channel's `I` from the ADC rate `fs`
//! down to the chain's rate `fs / R` (e.g. 200 kHz / 1000 = 200 Hz, or / 4000 = 50 Hz).
//!
//! # What it does
//!
//! ```text
//! at fs:     v_1 ← v_1 + x,  v_j ← v_j + v_{j−1} (j = 2..N)     N integrators, B bits, wrap
//! at fs/R:   w_0 = v_N,  w_j = w_{j−1} − w_{j−1}[m − M]          N combs, B bits, wrap
//!            c = Q_c(w_N · 2^−shift)                              CIC output format
//!            y = Q_y(Σ_t h_t · c[m − t])                          T-tap symmetric FIR
//! ```
//!
//! The integrators are a registered cascade (each adds the previous stage's value of the last
//! sample, as the RTL's registers do), which delays the response by `N − 1` input samples and
//! changes nothing else. An output is produced at every `R`-th input (the `R`-th, `2R`-th, …
//! after a reset).
//!
//! **Register width.** The CIC's gain is `(R·M)^N`, so `B = W_in + ⌈N·log2(R·M)⌉` bits hold
//! every comb output (Hogenauer): computed exactly in integers ([`Plan::growth_bits`]). All
//! integrator and comb arithmetic is two's complement mod `2^B`; the integrators overflow and
//! wrap all the time, and the combs undo it exactly.
//!
//! **Scaling.** `2^−shift` (default `shift = ⌈N·log2(R·M)⌉`, a gain `(R·M)^N / 2^shift` in
//! `(½, 1]`) is a reinterpretation of the comb output's fraction bits, then the one rounding
//! `Q_c`. The compensator's taps carry the rest of the gain: the cascade's DC gain is 1 up to
//! the taps' quantization ([`Flatness::dc_gain`]).
//!
//! **Droop compensation.** The CIC's response at output-rate frequency `f` (cycles per output
//! sample) is `H_c(f) = [sin(π M f) / (R M sin(π f / R))]^N`. The compensator is zero-phase
//! symmetric, `H_h(f) = h_c + 2 Σ_k h_{c+k} cos(2π k f)`; its taps minimise
//! `max |H_c(f)·H_h(f) − 1|` over 256 points of `[0, passband]` (Lawson's iteratively
//! reweighted least squares, 40 rounds), are scaled to the DC gain `g = 2^shift / (R M)^N`
//! exactly, then quantized to nearest (ties to even). Deterministic: `libm` and nalgebra's SVD.
//! [`Plan::flatness`] reports what the quantized cascade achieves. With the defaults (`N` = 3,
//! `R` = 1000, passband a quarter of the output rate, 18-bit taps) the CIC alone droops
//! 2.74 dB at the passband edge; with 5 taps the passband is flat within 0.032 dB peak to
//! peak, with 7 taps within 0.004 dB (3 taps: 0.27 dB). The same holds at `R` = 4000.
//!
//! # Quantization points
//!
//! | point | from (exact) | to | rounding | overflow |
//! |-------|--------------|----|----------|----------|
//! | integrators, combs | — | `s B.F_in` | exact | wrap (by design, exact) |
//! | `c` | `w_N · 2^−shift`: `s B.(F_in + shift)` | `cic_output` | config | config |
//! | taps (offline) | f64 | coefficient format | convergent | refused if they do not fit |
//! | `y` | `Σ h·c`: `s (W_c + W_h + ⌈log2 T⌉).(F_c + F_h)` | `output` | config | config |
//!
//! # Error bound
//!
//! The float twin ([`FloatCic`]) is a different structure with the same response: the CIC as
//! one direct-form FIR with the integer impulse response of `((1 − z^−RM)/(1 − z^−1))^N`
//! (delayed `N − 1` samples) in f64, times `2^−shift`, then the compensator with the
//! quantized taps. The CIC part of the fixed model is exact, so the difference is `c`'s
//! rounding through the compensator plus the output rounding:
//! `|y_fixed − y_float| ≤ Σ|h|·u_c·q_c + u_y·q_y` (plus the twin's f64 rounding):
//! [`Plan::error_bound_lsb`]. Valid while neither `c` nor `y` saturates or wraps.
//!
//! # Interface (RTL `hdl/gyrofx_cic.v`)
//!
//! | port | dir | format | meaning |
//! |------|-----|--------|---------|
//! | `clk`, `rst`, `ce` | in | 1 bit | clock, synchronous reset (registers and phase to 0), sample strobe |
//! | `x` | in | `input` | sample at `fs` |
//! | `y` | out | `output` | decimated, compensated sample |
//! | `y_valid` | out | 1 bit | high for one clock, 1 clock after every `R`-th `ce` |
//!
//! Latency: 1 clock after the `ce` of the `R`-th sample. ROM: `ROM_FILE` (`$readmemh`), `T`
//! words of the tap format, [`Plan::tap_codes`]. The register width is derived inside the RTL
//! from `STAGES`, `DECIMATION`, `DELAY` by the same integer rule.

use std::f64::consts::PI;

use super::{
    field_error, intermediate, mode_parameters, quantize_coefficients, require_signed, Coefficient,
    PlanError, Point, RtlParameter,
};
use crate::fx::{CoefficientFormat, Format, Overflow, Quantizer, Rounding};

/// Largest `N`.
pub const MAX_STAGES: u32 = 8;
/// Largest `R`.
pub const MAX_DECIMATION: u32 = 1 << 16;
/// Largest compensator length.
pub const MAX_TAPS: u32 = 15;
/// Points of `[0, passband]` the compensator is fitted on.
const DESIGN_POINTS: usize = 256;
/// Points of `[0, passband]` the flatness is measured on.
const FLATNESS_POINTS: usize = 1024;

/// What a CIC decimator is asked to be.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Spec {
    /// Input at `fs`.
    pub input: Format,
    /// `N`, integrator and comb stages.
    pub stages: u32,
    /// `R`, the decimation.
    pub decimation: u32,
    /// `M`, the comb's differential delay (1 or 2).
    pub differential_delay: u32,
    /// `2^−shift` after the combs; `None`: `⌈N·log2(R·M)⌉`, a CIC gain in `(½, 1]`.
    pub shift: Option<u32>,
    /// Format of `c`, the scaled CIC output.
    pub cic_output: Format,
    /// `T`, compensator taps, odd, `1..=15` (1: a gain, no compensation).
    pub taps: u32,
    /// Passband edge the compensator flattens up to, in cycles per output sample, in
    /// `(0, 0.5/M)`.
    pub passband: f64,
    /// Format rule of the taps.
    pub coefficients: CoefficientFormat,
    /// Output `y`.
    pub output: Format,
    /// Rounding at `c` and `y`.
    pub rounding: Rounding,
    /// Overflow handling at `c` and `y`.
    pub overflow: Overflow,
}

impl Default for Spec {
    /// `s24.23` in, `N` = 3, `R` = 1000, `M` = 1 (200 kHz to 200 Hz), `c` in `s28.27`, 5 taps
    /// of 18 bits flat to a quarter of the output rate, `s24.23` out; nearest, saturate.
    fn default() -> Self {
        let f = |w, frac| Format::signed(w, frac).expect("valid");
        Spec {
            input: f(24, 23),
            stages: 3,
            decimation: 1000,
            differential_delay: 1,
            shift: None,
            cic_output: f(28, 27),
            taps: 5,
            passband: 0.25,
            coefficients: CoefficientFormat::Auto { width: 18 },
            output: f(24, 23),
            rounding: Rounding::Nearest,
            overflow: Overflow::Saturate,
        }
    }
}

/// How flat the quantized cascade (CIC times compensator) is over `[0, passband]`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Flatness {
    /// DC gain of the whole cascade, `(R M)^N 2^−shift Σ h` (1 up to the taps' quantization).
    pub dc_gain: f64,
    /// Lowest response relative to DC, dB.
    pub min_db: f64,
    /// Highest response relative to DC, dB.
    pub max_db: f64,
    /// The CIC alone at the passband edge relative to DC, dB: what is compensated.
    pub uncompensated_edge_db: f64,
}

impl Flatness {
    /// Peak-to-peak passband ripple, dB.
    pub fn ripple_db(&self) -> f64 {
        self.max_db - self.min_db
    }
}

/// The resolved CIC decimator and compensator.
#[derive(Clone, Debug, PartialEq)]
pub struct Plan {
    /// Input.
    pub input: Format,
    /// `N`.
    pub stages: u32,
    /// `R`.
    pub decimation: u32,
    /// `M`.
    pub differential_delay: u32,
    /// `⌈N·log2(R·M)⌉`, exact.
    pub growth_bits: u32,
    /// Integrator and comb registers, `s B.F_in` with `B = W_in + growth_bits`.
    pub register: Format,
    /// The `2^−shift` after the combs.
    pub shift: u32,
    /// `w_N · 2^−shift` → the CIC output format.
    pub cic: Point,
    /// The compensator's taps, symmetric.
    pub taps: Vec<Coefficient>,
    /// Passband edge, cycles per output sample.
    pub passband: f64,
    /// `Σ h·c`, exact.
    pub fir_sum: Format,
    /// `Σ h·c` → output format.
    pub output: Point,
}

/// `⌈log2 value⌉` for `value ≥ 1`, exact.
fn ceil_log2(value: u128) -> u32 {
    128 - (value - 1).leading_zeros()
}

impl Plan {
    /// Validates `spec`, derives the register width and formats, designs and quantizes the
    /// compensator.
    ///
    /// # Errors
    /// [`PlanError::Field`] for a setting out of range or a format that adds fraction bits at
    /// a quantization point; [`PlanError::Intermediate`] when `B` or the FIR sum exceeds 128
    /// bits; [`PlanError::CoefficientOverflow`] for taps that do not fit a fixed tap format.
    pub fn new(spec: &Spec) -> Result<Plan, PlanError> {
        const B: &str = "cic";
        require_signed(
            B,
            &[
                ("input_format", spec.input),
                ("cic_output_format", spec.cic_output),
                ("output_format", spec.output),
            ],
        )?;
        if !(1..=MAX_STAGES).contains(&spec.stages) {
            return Err(field_error(
                B,
                "stages",
                spec.stages,
                format!("1..={MAX_STAGES}"),
            ));
        }
        if !(2..=MAX_DECIMATION).contains(&spec.decimation) {
            return Err(field_error(
                B,
                "decimation",
                spec.decimation,
                format!("2..={MAX_DECIMATION}"),
            ));
        }
        if !(1..=2).contains(&spec.differential_delay) {
            return Err(field_error(
                B,
                "differential_delay",
                spec.differential_delay,
                "1 or 2",
            ));
        }
        if spec.taps.is_multiple_of(2) || !(1..=MAX_TAPS).contains(&spec.taps) {
            return Err(field_error(
                B,
                "taps",
                spec.taps,
                format!("an odd number 1..={MAX_TAPS}"),
            ));
        }
        let edge = 0.5 / f64::from(spec.differential_delay);
        if !(spec.passband > 0.0 && spec.passband < edge) {
            return Err(field_error(
                B,
                "passband",
                spec.passband,
                format!("(0, {edge}) cycles per output sample (the CIC's first null is at 1/M)"),
            ));
        }
        let rm = u128::from(spec.decimation) * u128::from(spec.differential_delay);
        let gain = rm
            .checked_pow(spec.stages)
            .filter(|g| *g <= 1u128 << 127)
            .ok_or_else(|| {
                field_error(
                    B,
                    "stages",
                    spec.stages,
                    format!("a CIC gain (R·M)^N of at most 2^127 (R·M = {rm})"),
                )
            })?;
        let growth_bits = ceil_log2(gain);
        let register = Format::intermediate(true, spec.input.width + growth_bits, spec.input.frac)
            .map_err(intermediate(B, "integrator registers"))?;
        let shift = spec.shift.unwrap_or(growth_bits);
        let scaled = Format::intermediate(true, register.width, spec.input.frac + shift as i32)
            .map_err(intermediate(B, "comb output"))?;
        let cic = Point::new(
            B,
            "cic_output_format",
            scaled,
            spec.cic_output,
            spec.rounding,
            spec.overflow,
        )?;
        let correction = crate::fx::pow2(shift as i32) / gain as f64;
        let designed = design_compensator(spec, correction);
        let taps = quantize_coefficients(B, "taps", &designed, spec.coefficients)?;
        let tap_format = taps[0].format;
        let fir_sum = Format::intermediate(
            true,
            spec.cic_output.width + tap_format.width + ceil_log2(u128::from(spec.taps)),
            spec.cic_output.frac + tap_format.frac,
        )
        .map_err(intermediate(B, "compensator sum"))?;
        let output = Point::new(
            B,
            "output_format",
            fir_sum,
            spec.output,
            spec.rounding,
            spec.overflow,
        )?;
        Ok(Plan {
            input: spec.input,
            stages: spec.stages,
            decimation: spec.decimation,
            differential_delay: spec.differential_delay,
            growth_bits,
            register,
            shift,
            cic,
            taps,
            passband: spec.passband,
            fir_sum,
            output,
        })
    }

    /// `(R·M)^N`, the CIC's DC gain (exact while below 2^53).
    pub fn cic_gain(&self) -> f64 {
        let rm = u128::from(self.decimation) * u128::from(self.differential_delay);
        rm.pow(self.stages) as f64
    }

    /// The taps' codes in order `h_0 … h_{T−1}` (symmetric): what `hdl/gyrofx_cic.v` reads.
    pub fn tap_codes(&self) -> Vec<i128> {
        self.taps.iter().map(|t| t.code).collect()
    }

    /// The taps as quantized, reals.
    pub fn tap_values(&self) -> Vec<f64> {
        self.taps.iter().map(Coefficient::quantized).collect()
    }

    /// The CIC's response at `f` cycles per output sample, relative to DC.
    pub fn cic_response(&self, f: f64) -> f64 {
        cic_response(self.stages, self.decimation, self.differential_delay, f)
    }

    /// The quantized compensator's zero-phase response at `f` cycles per output sample.
    pub fn compensator_response(&self, f: f64) -> f64 {
        zero_phase_response(&self.tap_values(), f)
    }

    /// Flatness of the quantized cascade over `[0, passband]`.
    pub fn flatness(&self) -> Flatness {
        let taps = self.tap_values();
        let dc = zero_phase_response(&taps, 0.0);
        let (mut min_db, mut max_db) = (f64::INFINITY, f64::NEG_INFINITY);
        for i in 0..FLATNESS_POINTS {
            let f = self.passband * i as f64 / (FLATNESS_POINTS - 1) as f64;
            let relative = (self.cic_response(f) * zero_phase_response(&taps, f) / dc).abs();
            let db = 20.0 * libm::log10(relative);
            min_db = min_db.min(db);
            max_db = max_db.max(db);
        }
        Flatness {
            dc_gain: self.cic_gain() * crate::fx::pow2(-(self.shift as i32)) * dc,
            min_db,
            max_db,
            uncompensated_edge_db: 20.0 * libm::log10(self.cic_response(self.passband).abs()),
        }
    }

    /// Worst-case `|y_fixed − y_float|`, in output LSB (see the module doc).
    pub fn error_bound_lsb(&self) -> f64 {
        let taps = self.tap_values();
        let tap_sum: f64 = taps.iter().map(|h| h.abs()).sum();
        let scaled_gain = self.cic_gain() * crate::fx::pow2(-(self.shift as i32));
        let x_max = self.input.min_value().abs();
        let c_max = scaled_gain * x_max;
        // The twin's direct-form CIC: L products and sums (gamma_L), its integer impulse
        // response rounded to f64 (one more relative rounding).
        let length =
            f64::from(self.stages) * f64::from(self.decimation * self.differential_delay) + 1.0;
        let twin_cic = gamma(length + 2.0) * c_max;
        let twin_fir = gamma(taps.len() as f64 + 1.0) * tap_sum * (c_max + twin_cic);
        let error =
            tap_sum * (self.cic.max_error() + twin_cic) + twin_fir + self.output.max_error();
        error / self.output.to.lsb()
    }

    /// Parameters of `hdl/gyrofx_cic.v` (the register width is derived there).
    pub fn rtl_parameters(&self) -> Vec<RtlParameter> {
        let mut p = vec![
            ("IN_W", i128::from(self.input.width)),
            ("IN_F", i128::from(self.input.frac)),
            ("STAGES", i128::from(self.stages)),
            ("DECIMATION", i128::from(self.decimation)),
            ("DELAY", i128::from(self.differential_delay)),
            ("SHIFT", i128::from(self.shift)),
            ("MID_W", i128::from(self.cic.to.width)),
            ("MID_F", i128::from(self.cic.to.frac)),
            ("TAPS", self.taps.len() as i128),
            ("COEF_W", i128::from(self.taps[0].format.width)),
            ("COEF_F", i128::from(self.taps[0].format.frac)),
            ("OUT_W", i128::from(self.output.to.width)),
            ("OUT_F", i128::from(self.output.to.frac)),
        ];
        p.extend(mode_parameters(self.output.rounding, self.output.overflow));
        p
    }
}

mod design;
mod fixed;
mod float;

use design::{cic_response, design_compensator, gamma, zero_phase_response};
#[cfg(test)]
use fixed::{Engine, Registers};
pub use fixed::{FixedCic, OverflowCounts};
pub use float::FloatCic;

#[cfg(test)]
mod tests;
