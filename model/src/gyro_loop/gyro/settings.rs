//! The loop's settings as the config writes them (the `[loop]` section): rates, bandwidths,
//! lock criteria, and every format as a string (`s18.16`, parsed by [`Format`]'s parser).

use serde::{Deserialize, Serialize};

use crate::fx::{Format, Overflow, Rounding};
use crate::gyro_loop::{field_error, PlanError};

/// One gyro loop's settings (also the `[loop]` config section; the field names are the keys).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LoopSettings {
    /// ADC (and DAC) sample rate `fs`, Hz; must equal the resonator's.
    pub adc_rate_hz: f64,
    /// `R`: the CIC's decimation; the chain's rate is `fs / R` (200 kHz / 1000 = 200 Hz).
    pub decimation: u32,
    /// `L`: samples from an ADC code to the DAC code computed from it (0..=8).
    pub adc_to_dac_latency_samples: u32,
    /// PLL open-loop crossover, Hz.
    pub pll_bandwidth_hz: f64,
    /// AGC open-loop crossover, Hz.
    pub agc_bandwidth_hz: f64,
    /// The PLL integrator's limits reach this far below the lower and above the higher of the
    /// two modes' nominal frequencies, Hz.
    pub pll_pull_range_hz: f64,
    /// Lock: largest low-passed drive phase error, degrees.
    pub lock_phase_deg: f64,
    /// Lock: largest low-passed amplitude error, as a fraction of the setpoint.
    pub lock_amplitude_tolerance: f64,
    /// Lock: both errors must stay within their limits this long, ms.
    pub lock_hold_ms: f64,
    /// Lock filters' shift `s` (−3 dB at `fs 2^−s / 2π`).
    pub lock_filter_shift: u32,
    /// NCO accumulator bits `P` (the frequency word and the PLL output are `u P.P` / `s P.P`).
    pub nco_phase_bits: u32,
    /// NCO quarter-wave ROM address bits `A`.
    pub nco_address_bits: u32,
    /// Carry each NCO's truncation error into its next phase (see `gyro_loop::nco`): no static
    /// phase error from the truncation at any locked frequency. On by default; a resolved
    /// config without the key (a package manifest written before it existed) was made with
    /// plain truncation, so it reads as off.
    #[serde(default)]
    pub nco_error_feedback: bool,
    /// NCO sine width `S` (`s S.(S−1)`).
    pub nco_sine_width: u32,
    /// ADC codes, `s W.(W−1)` full-scale units; `W` must be the resonator's ADC width.
    pub adc_format: String,
    /// Demodulator product `2·x·ref`.
    pub demod_product_format: String,
    /// Demodulator low-pass state.
    pub demod_state_format: String,
    /// Demodulator outputs `I`, `Q` (also the PLL's and AGC's error inputs and the CICs').
    pub demod_output_format: String,
    /// Demodulator low-pass shift `k` (−3 dB at `fs 2^−k / 2π`).
    pub demod_lowpass_shift: u32,
    /// PLL integrator (cycles per sample).
    pub pll_integrator_format: String,
    /// Width of the PLL's `kp` and `ki` (their fraction bits are chosen to fit).
    pub pll_gain_width: u32,
    /// AGC integrator (DAC LSB).
    pub agc_integrator_format: String,
    /// AGC output, the drive amplitude `u` (DAC LSB).
    pub agc_output_format: String,
    /// Width of the AGC's `kp` and `ki`.
    pub agc_gain_width: u32,
    /// DAC codes (`s W.0`: one LSB is the resonator's `dac_newton_per_lsb`).
    pub dac_format: String,
    /// CIC stages `N`.
    pub cic_stages: u32,
    /// The CIC's scaled output `c`, before the compensator.
    pub cic_internal_format: String,
    /// Compensator taps (odd, 1..=15).
    pub cic_taps: u32,
    /// Compensator passband edge, cycles per output sample.
    pub cic_passband: f64,
    /// Compensator tap width.
    pub cic_tap_width: u32,
    /// The CIC's output.
    pub cic_output_format: String,
    /// Width of the per-mode `1/SF` coefficients (one shared format, its fraction bits chosen
    /// to fit) unless `scale_coefficient_format` is given.
    pub scale_coefficient_width: u32,
    /// An explicit format of the `1/SF` coefficients (e.g. `s24.6`); a coefficient that does
    /// not fit is refused.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub scale_coefficient_format: Option<String>,
    /// Trim each mode's sense offset `δ_S` so that the loop realizes the configured phase
    /// error: designed at the coupled resonance the PLL locks on and net of the PLL's `2f`
    /// phase modulation, where `false` designs it at `sqrt(k_aa/m)` (see
    /// `gyro_loop::realized_phase`). Only the per-mode offset words change. On by default
    /// (it costs no logic and takes 3.4 mdps of residual off at the defaults); a resolved
    /// config without the key (a manifest written before it existed, or with it off) reads as
    /// off.
    #[serde(default, skip_serializing_if = "is_false")]
    pub phase_trim: bool,
    /// Rate and quadrature outputs, °/s (the chain's input format).
    pub output_format: String,
    /// Rounding mode name at every configurable point.
    pub rounding: String,
    /// Overflow mode name at every configurable point.
    pub overflow: String,
}

impl Default for LoopSettings {
    /// For paper 004 at 200 kHz and a 200 Hz chain: 20 Hz PLL, 15 Hz AGC (the amplitude
    /// within 1e-4 in about 100 ms, as SPEC §1.6 expects), 1 sample of latency, a 32-bit NCO
    /// with a 1024-word ROM of 18-bit words, the 24-bit ADC, demodulator outputs with 30
    /// fraction bits (the sense signal is 1e-5 FS per °/s, so the rate keeps its resolution
    /// through the CIC) and `k` = 8 (124 Hz: little lag in the 15–20 Hz loops), lock within
    /// 0.1° and 0.1 % for 10 ms behind a 2.6 ms filter (`s` = 9, which takes the 2f ripple
    /// down to 3e-5 of the setpoint), an 18-bit DAC, a 3-stage CIC with a 5-tap compensator
    /// and the chain's `s24.14` °/s, the phase trimmed; nearest, saturate.
    fn default() -> Self {
        let s = |text: &str| text.to_string();
        LoopSettings {
            adc_rate_hz: 200e3,
            decimation: 1000,
            adc_to_dac_latency_samples: 1,
            pll_bandwidth_hz: 20.0,
            agc_bandwidth_hz: 15.0,
            pll_pull_range_hz: 100.0,
            lock_phase_deg: 0.1,
            lock_amplitude_tolerance: 1e-3,
            lock_hold_ms: 10.0,
            lock_filter_shift: 9,
            nco_phase_bits: 32,
            nco_address_bits: 10,
            nco_error_feedback: true,
            nco_sine_width: 18,
            adc_format: s("s24.23"),
            demod_product_format: s("s36.34"),
            demod_state_format: s("s44.42"),
            demod_output_format: s("s32.30"),
            demod_lowpass_shift: 8,
            pll_integrator_format: s("s40.38"),
            pll_gain_width: 18,
            agc_integrator_format: s("s40.20"),
            agc_output_format: s("s24.6"),
            agc_gain_width: 18,
            dac_format: s("s18.0"),
            cic_stages: 3,
            cic_internal_format: s("s40.38"),
            cic_taps: 5,
            cic_passband: 0.25,
            cic_tap_width: 18,
            cic_output_format: s("s32.30"),
            scale_coefficient_width: 24,
            scale_coefficient_format: None,
            phase_trim: true,
            output_format: s("s24.14"),
            rounding: s("nearest"),
            overflow: s("saturate"),
        }
    }
}

/// Parses the format of key `field`, naming it on failure.
pub(super) fn format(field: &'static str, text: &str) -> Result<Format, PlanError> {
    text.parse::<Format>()
        .map_err(|e| field_error("loop", field, format!("{text:?}"), e.to_string()))
}

impl LoopSettings {
    /// The rounding mode.
    ///
    /// # Errors
    /// [`PlanError::Field`] naming `rounding` for an unknown name.
    pub fn rounding_mode(&self) -> Result<Rounding, PlanError> {
        self.rounding.parse().map_err(|_| {
            field_error(
                "loop",
                "rounding",
                format!("{:?}", self.rounding),
                "floor, ceil, zero, nearest, round or convergent",
            )
        })
    }

    /// The overflow mode.
    ///
    /// # Errors
    /// [`PlanError::Field`] naming `overflow` for an unknown name.
    pub fn overflow_mode(&self) -> Result<Overflow, PlanError> {
        self.overflow.parse().map_err(|_| {
            field_error(
                "loop",
                "overflow",
                format!("{:?}", self.overflow),
                "wrap or saturate",
            )
        })
    }
}

/// `serde`'s skip test for `phase_trim`: off is left out of the resolved config, so packages
/// made before the key existed keep their manifests, and a manifest without it reads as off.
fn is_false(value: &bool) -> bool {
    !*value
}
