//! The simulated resonator's settings: sample rate, pick-off, ADC and DAC, temperature,
//! electronic noise and the Gauss–Markov drifts (units in every field's doc).

use super::params::ParamError;
use super::params::ResonatorParams;

/// A first-order Gauss–Markov drift: stationary standard deviation and correlation time.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct GaussMarkov {
    /// Stationary standard deviation, in the unit of the quantity that drifts (see each use).
    pub std: f64,
    /// Correlation time, s.
    pub correlation_time_s: f64,
}

impl GaussMarkov {
    /// No drift.
    pub const OFF: GaussMarkov = GaussMarkov {
        std: 0.0,
        correlation_time_s: 1.0,
    };
}

/// How the resonator is sampled, driven, read and disturbed (the same for both gyros).
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PhysicsSettings {
    /// ADC (and DAC) sample rate `fs`, Hz; above twice the higher mode frequency.
    pub sample_rate_hz: f64,
    /// Pick-off gain of the x and y axes, V/m.
    pub pickoff_gain_v_per_m: [f64; 2],
    /// White electronic noise at each pick-off output, V/√Hz (one-sided; per sample
    /// `σ = e_n · sqrt(fs/2)`).
    pub pickoff_noise_v_per_sqrt_hz: f64,
    /// ADC word width, bits (2..=64): codes `−2^(w−1) ..= 2^(w−1) − 1`.
    pub adc_width: u32,
    /// ADC full scale, V: the code `2^(w−1)` would stand for `+full_scale`.
    pub adc_full_scale_v: f64,
    /// DAC force per LSB, N.
    pub dac_newton_per_lsb: f64,
    /// Temperature of the thermomechanical noise, K.
    pub temperature_k: f64,
    /// Master switch of every random source (thermomechanical, electronic, drift): off, the
    /// resonator is deterministic and follows the closed forms exactly.
    pub noise: bool,
    /// Drift of the damping split `d1 − d2`; `std` as a fraction of `(d1 + d2)/2`.
    pub damping_split_drift: GaussMarkov,
    /// Drift of the damping angle `θ`; `std` in degrees.
    pub damping_angle_drift: GaussMarkov,
    /// Drift of the sense channel's phase error (added to `φ` and `φ′` alike); `std` in
    /// degrees.
    pub phase_drift: GaussMarkov,
    /// The drifts advance, and the discretisation is recomputed, every this many samples.
    pub drift_update_samples: u32,
}

impl PhysicsSettings {
    /// An example for [`ResonatorParams::paper_004`]: fs = 200 kHz (24.4 samples per drive
    /// cycle), 1e5 V/m pick-off (q0 = 2 µm gives 0.2 V) with 50 nV/√Hz, a 24-bit ADC of ±1 V
    /// (paper 004's ADC width), 1 nN per DAC LSB (the 15.6 µN drive force is ~15 600 LSB),
    /// 300 K, and drifts of 1 % of the mean damping in the split, 0.05° in θ and 0.02° in the
    /// phase, each with a 100 s correlation time, updated every 1000 samples (5 ms).
    pub fn example() -> Self {
        let drift = |std| GaussMarkov {
            std,
            correlation_time_s: 100.0,
        };
        PhysicsSettings {
            sample_rate_hz: 200e3,
            pickoff_gain_v_per_m: [1e5, 1e5],
            pickoff_noise_v_per_sqrt_hz: 50e-9,
            adc_width: 24,
            adc_full_scale_v: 1.0,
            dac_newton_per_lsb: 1e-9,
            temperature_k: 300.0,
            noise: true,
            damping_split_drift: drift(0.01),
            damping_angle_drift: drift(0.05),
            phase_drift: drift(0.02),
            drift_update_samples: 1000,
        }
    }

    /// The same without any random source.
    pub fn noiseless(mut self) -> Self {
        self.noise = false;
        self
    }

    /// Checks every field against `params` (the sample rate must exceed twice the higher
    /// mode frequency).
    ///
    /// # Errors
    /// [`ParamError::Range`] naming the first field out of range.
    pub fn validate(&self, params: &ResonatorParams) -> Result<(), ParamError> {
        let check = |field: &'static str, value: f64, ok: bool, allowed: &'static str| {
            if value.is_finite() && ok {
                Ok(())
            } else {
                Err(ParamError::Range {
                    field,
                    value,
                    allowed,
                })
            }
        };
        let highest = params.drive_frequency_hz.max(params.sense_frequency_hz);
        check(
            "sample_rate_hz",
            self.sample_rate_hz,
            self.sample_rate_hz > 2.0 * highest,
            "a sample rate above twice the higher mode frequency",
        )?;
        for gain in self.pickoff_gain_v_per_m {
            check(
                "pickoff_gain_v_per_m",
                gain,
                gain > 0.0,
                "finite gains above 0",
            )?;
        }
        let non_negative = "a finite value of at least 0";
        check(
            "pickoff_noise_v_per_sqrt_hz",
            self.pickoff_noise_v_per_sqrt_hz,
            self.pickoff_noise_v_per_sqrt_hz >= 0.0,
            non_negative,
        )?;
        check(
            "adc_width",
            f64::from(self.adc_width),
            (2..=64).contains(&self.adc_width),
            "2..=64 bits",
        )?;
        let positive = "a finite value above 0";
        check(
            "adc_full_scale_v",
            self.adc_full_scale_v,
            self.adc_full_scale_v > 0.0,
            positive,
        )?;
        check(
            "dac_newton_per_lsb",
            self.dac_newton_per_lsb,
            self.dac_newton_per_lsb > 0.0,
            positive,
        )?;
        check(
            "temperature_k",
            self.temperature_k,
            self.temperature_k >= 0.0,
            non_negative,
        )?;
        let drifts = [
            ("damping_split_drift", self.damping_split_drift, 0.25),
            ("damping_angle_drift", self.damping_angle_drift, 45.0),
            ("phase_drift", self.phase_drift, 45.0),
        ];
        for (field, drift, largest) in drifts {
            check(
                field,
                drift.std,
                (0.0..=largest).contains(&drift.std),
                "a std of at least 0: at most 0.25 for the damping split, 45 degrees for the angles",
            )?;
            check(
                field,
                drift.correlation_time_s,
                drift.correlation_time_s > 0.0,
                "a correlation time above 0 s",
            )?;
        }
        check(
            "drift_update_samples",
            f64::from(self.drift_update_samples),
            self.drift_update_samples >= 1,
            "at least 1 sample",
        )
    }
}
