//! The front end that makes each resonator-level gyro of the `gu2019` preset show paper 004's
//! raw N and B (Table 2), derived, not fitted: what its `[front_end_a]` and `[front_end_b]`
//! hold, and what a test holds them to.
//!
//! **N (white rate noise, °/√s).** A white source at the sense pick-off of density `e_n`
//! (V/√Hz, one-sided) reads as a white rate of `N = e_n / (g · SF)` rad/√s, with `g` the
//! sense pick-off gain (V/m) and `SF = 2 m w q0 cos φ / |Z|` (m per rad/s, SPEC §1.6): the
//! in-phase demodulation halves the one-sided density and doubles the amplitude, and a white
//! rate of one-sided PSD `S` has `N = √(S/2)`. The thermomechanical force `√(4 k_B T d_s)`
//! (N/√Hz) reads the same way with `F / (2 m w q0 cos φ)`. The fixed-point loop adds a floor of
//! its own (its word lengths' rounding; [`loop_floor`] measures it, no random source on). The
//! three add in power, so the pick-off noise is what is left of `N²` after the floor and the
//! thermomechanical part.
//!
//! **B (bias instability, °/s).** The three Gauss–Markov drifts of the front end, at
//! [`DRIFT_CORRELATION_S`] (1, 10 and 100 s: their Allan humps at 1.9, 19 and 190 s tile the
//! 1–256 s a 1000 s record's Allan curve reads as a floor), each move the bias through SPEC
//! §1.6's closed forms ([`bias_sensitivities`]). Each is given an equal share `s` of bias
//! (°/s), so that the expected Allan deviation of their sum, from the Gauss–Markov closed form
//! ([`gauss_markov_avar`]), has its minimum over octaves 1–256 s at `0.6643 B` (IEEE Std
//! 952's flicker floor).
//!
//! One 1000 s record is one draw: its Allan deviation at τ of a hundred seconds scatters by
//! tens of percent around the expected one, as the paper's own single record did.

use gyrofx_job::config::GyroLoop;
use gyrofx_job::error::{Error, Result};
use gyrofx_model::analysis::allan::{self, Kind};
use gyrofx_model::analysis::noise::FLICKER_FLOOR;
use gyrofx_model::gyro_loop::closed::FixedClosedLoop;
use gyrofx_model::resonator::{
    GaussMarkov, Mode, ModeFigures, PhysicsSettings, ResonatorParams, BOLTZMANN_J_PER_K,
};

/// Correlation times of the phase, damping-angle and damping-split drifts, s.
pub const DRIFT_CORRELATION_S: [f64; 3] = [1.0, 10.0, 100.0];

/// The averaging times whose expected Allan deviation sets the floor, s (octaves 1–256).
pub const FLOOR_TAUS_S: [f64; 9] = [1.0, 2.0, 4.0, 8.0, 16.0, 32.0, 64.0, 128.0, 256.0];

/// The averaging factors (of the 50 Hz output) over which white noise is read, and the rate.
const WHITE_FACTORS: [usize; 4] = [5, 10, 25, 50];

/// Seconds of drift-free output [`white_noise`] reads.
pub const WHITE_SECONDS: f64 = 100.0;

/// What one gyro's front end is set to, and why.
#[derive(Clone, Debug, PartialEq)]
pub struct Calibration {
    /// The paper's raw N (°/√s) and B (°/s) it aims at.
    pub target: [f64; 2],
    /// The loop's own white floor, °/√s (measured, [`loop_floor`]).
    pub loop_floor: f64,
    /// The thermomechanical part at the front end's temperature, °/√s.
    pub thermomechanical: f64,
    /// The pick-off noise that makes the rest, V/√Hz.
    pub pickoff_noise_v_per_sqrt_hz: f64,
    /// °/s of bias per unit of each drift: phase (°), damping angle (°), damping split
    /// (fraction of the mean damping).
    pub sensitivities: [f64; 3],
    /// Each drift's share of bias, °/s (its stationary standard deviation as bias).
    pub share_dps: f64,
    /// The drifts: phase, damping angle, damping split.
    pub drifts: [GaussMarkov; 3],
}

impl Calibration {
    /// `front_end` with this calibration's pick-off noise and drifts.
    pub fn apply(&self, front_end: &PhysicsSettings) -> PhysicsSettings {
        PhysicsSettings {
            pickoff_noise_v_per_sqrt_hz: self.pickoff_noise_v_per_sqrt_hz,
            phase_drift: self.drifts[0],
            damping_angle_drift: self.drifts[1],
            damping_split_drift: self.drifts[2],
            ..*front_end
        }
    }
}

/// The Allan variance at `tau_s` of a first-order Gauss–Markov process of stationary
/// standard deviation `std` and correlation time `correlation_s`:
/// `2 σ² (T/τ)² (τ/T − 3/2 + 2 e^{−τ/T} − ½ e^{−2τ/T})` (→ `2σ²τ/(3T)` for τ ≪ T, the random
/// walk it looks like; → `2σ²T/τ` for τ ≫ T, white).
pub fn gauss_markov_avar(std: f64, correlation_s: f64, tau_s: f64) -> f64 {
    let x = tau_s / correlation_s;
    2.0 * std * std / (x * x) * (x - 1.5 + 2.0 * libm::exp(-x) - 0.5 * libm::exp(-2.0 * x))
}

/// °/s of normal-mode bias per unit of each drift of the front end (SPEC §1.6's closed
/// forms): per degree of phase error `k_xy / (2 m w cos² φ)`; per degree of damping angle and
/// per fraction of damping split, the change of `d_xy / (2m)` (central differences of the
/// closed form, the split applied as the resonator applies it: `±δ (d1 + d2)/4` on the
/// principal dampings).
pub fn bias_sensitivities(params: &ResonatorParams) -> [f64; 3] {
    let bias = |p: &ResonatorParams| ModeFigures::new(p, Mode::Normal).bias_dps();
    let phase = ModeFigures::new(params, Mode::Normal).bias_sensitivity_to_phase();
    let h = 1e-3;
    let angled = |d: f64| ResonatorParams {
        damping_angle_deg: params.damping_angle_deg + d,
        ..*params
    };
    let angle = (bias(&angled(h)) - bias(&angled(-h))) / (2.0 * h);
    let [d1, d2] = params.principal_damping();
    let split = |delta: f64| {
        let shift = delta * (d1 + d2) / 4.0;
        let w = [params.drive_frequency_hz, params.sense_frequency_hz]
            .map(|f| params.mass_kg * 2.0 * std::f64::consts::PI * f);
        ResonatorParams {
            q_drive: w[0] / (d1 + shift),
            q_sense: w[1] / (d2 - shift),
            ..*params
        }
    };
    let split = (bias(&split(h)) - bias(&split(-h))) / (2.0 * h);
    [phase, angle, split]
}

/// `front_end` with its three drifts off (its white sources kept).
pub fn drift_free(front_end: &PhysicsSettings) -> PhysicsSettings {
    PhysicsSettings {
        phase_drift: GaussMarkov::OFF,
        damping_angle_drift: GaussMarkov::OFF,
        damping_split_drift: GaussMarkov::OFF,
        ..*front_end
    }
}

/// The white-noise level of a rate record at 50 Hz, °/√s: the Allan deviation times `√τ`,
/// averaged over τ = 0.1–1 s.
pub(super) fn white_level(rate_dps: &[f64], rate_hz: f64) -> f64 {
    let phase = allan::phase(rate_dps);
    WHITE_FACTORS
        .iter()
        .map(|&m| {
            allan::deviation(Kind::Overlapping, &phase, m, rate_hz)
                .map_or(f64::NAN, |(dev, _)| dev * (m as f64 / rate_hz).sqrt())
        })
        .sum::<f64>()
        / WHITE_FACTORS.len() as f64
}

/// The white rate noise (°/√s) of `gyro`'s closed fixed loop at rest in normal mode with
/// `front_end`'s noise and its drifts off, over [`WHITE_SECONDS`] after a second of start-up.
///
/// # Errors
/// Invalid physics.
pub fn white_noise(gyro: &GyroLoop, front_end: &PhysicsSettings, seed: u64) -> Result<f64> {
    let drift_free = drift_free(front_end);
    let mut closed = FixedClosedLoop::new(&gyro.plan, &gyro.params, &drift_free, seed)
        .map_err(|e| Error::Simulation(format!("gyro {}: {e}", gyro.name)))?;
    let rate_hz = gyro.plan.chain_rate_hz();
    let startup = rate_hz.round() as usize;
    let samples = (WHITE_SECONDS * rate_hz).round() as usize;
    let rate: Vec<f64> = (0..startup + samples)
        .map(|_| closed.step_chain(0.0, Mode::Normal).output.rate_dps)
        .skip(startup)
        .collect();
    Ok(white_level(&rate, rate_hz))
}

/// The loop's own white floor, °/√s: [`white_noise`] with no random source at all (the rounding
/// of its word lengths on a deterministic resonator).
///
/// # Errors
/// Invalid physics.
pub fn loop_floor(gyro: &GyroLoop) -> Result<f64> {
    let quiet = PhysicsSettings {
        noise: true,
        temperature_k: 0.0,
        pickoff_noise_v_per_sqrt_hz: 0.0,
        ..gyro.front_end
    };
    white_noise(gyro, &quiet, 0)
}

/// The front end that gives `gyro` (at rest, normal mode) the white noise `n` (°/√s) and the
/// expected bias instability `b` (°/s), over its loop's `floor` (°/√s) and its front end's
/// thermomechanical noise.
///
/// # Errors
/// [`Error::Simulation`] when `n` is below what the floor and the thermomechanical noise
/// already give.
pub fn calibrate(gyro: &GyroLoop, n: f64, b: f64, floor: f64) -> Result<Calibration> {
    let deg = 180.0 / std::f64::consts::PI;
    let figures = ModeFigures::new(&gyro.params, Mode::Normal);
    let coriolis = 2.0
        * gyro.params.mass_kg
        * figures.drive_angular_frequency
        * gyro.params.drive_amplitude_m
        * libm::cos(figures.phase_error);
    let [_, d_sense] = gyro.params.principal_damping();
    let force_density = (4.0 * BOLTZMANN_J_PER_K * gyro.front_end.temperature_k * d_sense).sqrt();
    let thermomechanical = force_density / coriolis * deg;
    let left = n * n - floor * floor - thermomechanical * thermomechanical;
    if left <= 0.0 {
        return Err(Error::Simulation(format!(
            "gyro {}: N = {n:e} °/√s is below the loop's floor {floor:.3e} °/√s and the \
             thermomechanical noise {thermomechanical:.3e} °/√s together",
            gyro.name
        )));
    }
    let volts_per_rad_s = gyro.front_end.pickoff_gain_v_per_m[1] * figures.scale_factor;
    let pickoff = left.sqrt() / deg * volts_per_rad_s;
    let unit_floor = FLOOR_TAUS_S
        .iter()
        .map(|&tau| {
            DRIFT_CORRELATION_S
                .iter()
                .map(|&t| gauss_markov_avar(1.0, t, tau))
                .sum::<f64>()
                .sqrt()
        })
        .fold(f64::INFINITY, f64::min);
    let share = FLICKER_FLOOR * b / unit_floor;
    let sensitivities = bias_sensitivities(&gyro.params);
    let drifts = [0, 1, 2].map(|i| GaussMarkov {
        std: share / sensitivities[i].abs(),
        correlation_time_s: DRIFT_CORRELATION_S[i],
    });
    Ok(Calibration {
        target: [n, b],
        loop_floor: floor,
        thermomechanical,
        pickoff_noise_v_per_sqrt_hz: pickoff,
        sensitivities,
        share_dps: share,
        drifts,
    })
}

/// The expected Allan deviation (°/s) at `tau_s` of a calibration's three drifts.
pub fn expected_drift_adev(calibration: &Calibration, tau_s: f64) -> f64 {
    calibration
        .drifts
        .iter()
        .map(|d| gauss_markov_avar(calibration.share_dps, d.correlation_time_s, tau_s))
        .sum::<f64>()
        .sqrt()
}

#[cfg(test)]
mod tests;
