//! One member's physics from the nominal physics, the spreads and `(seed, member)`.
//!
//! Member `i` of a population seeded `s` draws from its own ChaCha8 stream: the key from `s`,
//! the stream number `i`. From that stream it takes, in this order: the noise seeds of gyro A
//! and B (one word each), then gyro A's parameters and gyro B's, each in the order of the
//! spreads given. So a member's draws depend on nothing but `(s, i)` and the spreads (not on
//! the number of members, the threads or their timing), and the noise seeds do not change when
//! a spread is added.

use rand_chacha::ChaCha8Rng;
use rand_core::{RngCore, SeedableRng};

use super::distribution::Spread;
use crate::resonator::{PhysicsSettings, ResonatorParams};

/// A parameter a population spreads: one of `[resonator_a]`/`[resonator_b]`'s or one of
/// `[front_end]`'s scalars (per gyro: each gyro draws its own).
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub enum Parameter {
    /// `mass_kg`, kg.
    MassKg,
    /// `drive_frequency_hz`, Hz.
    DriveFrequencyHz,
    /// `sense_frequency_hz`, Hz.
    SenseFrequencyHz,
    /// `q_drive`.
    QDrive,
    /// `q_sense`.
    QSense,
    /// `stiffness_angle_deg`, deg.
    StiffnessAngleDeg,
    /// `damping_angle_deg`, deg.
    DampingAngleDeg,
    /// `drive_amplitude_m`, m.
    DriveAmplitudeM,
    /// `phase_error_deg`, deg.
    PhaseErrorDeg,
    /// `phase_error_reverse_deg`, deg.
    PhaseErrorReverseDeg,
    /// The x pick-off gain, V/m.
    PickoffGainXVPerM,
    /// The y pick-off gain, V/m.
    PickoffGainYVPerM,
    /// `pickoff_noise_v_per_sqrt_hz`, V/√Hz.
    PickoffNoiseVPerSqrtHz,
    /// `adc_full_scale_v`, V.
    AdcFullScaleV,
    /// `dac_newton_per_lsb`, N.
    DacNewtonPerLsb,
    /// `temperature_k`, K.
    TemperatureK,
}

/// Which section a [`Parameter`] belongs to.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Section {
    /// The resonator's structure.
    Resonator,
    /// The front end.
    FrontEnd,
}

impl Parameter {
    /// Every parameter, resonator first.
    pub const ALL: [Parameter; 16] = [
        Parameter::MassKg,
        Parameter::DriveFrequencyHz,
        Parameter::SenseFrequencyHz,
        Parameter::QDrive,
        Parameter::QSense,
        Parameter::StiffnessAngleDeg,
        Parameter::DampingAngleDeg,
        Parameter::DriveAmplitudeM,
        Parameter::PhaseErrorDeg,
        Parameter::PhaseErrorReverseDeg,
        Parameter::PickoffGainXVPerM,
        Parameter::PickoffGainYVPerM,
        Parameter::PickoffNoiseVPerSqrtHz,
        Parameter::AdcFullScaleV,
        Parameter::DacNewtonPerLsb,
        Parameter::TemperatureK,
    ];

    /// The key as the config names it.
    pub fn name(self) -> &'static str {
        match self {
            Parameter::MassKg => "mass_kg",
            Parameter::DriveFrequencyHz => "drive_frequency_hz",
            Parameter::SenseFrequencyHz => "sense_frequency_hz",
            Parameter::QDrive => "q_drive",
            Parameter::QSense => "q_sense",
            Parameter::StiffnessAngleDeg => "stiffness_angle_deg",
            Parameter::DampingAngleDeg => "damping_angle_deg",
            Parameter::DriveAmplitudeM => "drive_amplitude_m",
            Parameter::PhaseErrorDeg => "phase_error_deg",
            Parameter::PhaseErrorReverseDeg => "phase_error_reverse_deg",
            Parameter::PickoffGainXVPerM => "pickoff_gain_x_v_per_m",
            Parameter::PickoffGainYVPerM => "pickoff_gain_y_v_per_m",
            Parameter::PickoffNoiseVPerSqrtHz => "pickoff_noise_v_per_sqrt_hz",
            Parameter::AdcFullScaleV => "adc_full_scale_v",
            Parameter::DacNewtonPerLsb => "dac_newton_per_lsb",
            Parameter::TemperatureK => "temperature_k",
        }
    }

    /// Its section.
    pub fn section(self) -> Section {
        if self <= Parameter::PhaseErrorReverseDeg {
            Section::Resonator
        } else {
            Section::FrontEnd
        }
    }

    /// The parameter of `section` named `name`.
    pub fn named(section: Section, name: &str) -> Option<Parameter> {
        Parameter::ALL
            .into_iter()
            .find(|p| p.section() == section && p.name() == name)
    }

    /// The names of `section`'s parameters.
    pub fn names(section: Section) -> Vec<&'static str> {
        Parameter::ALL
            .into_iter()
            .filter(|p| p.section() == section)
            .map(Parameter::name)
            .collect()
    }

    fn slot(self, gyro: &mut GyroPhysics) -> &mut f64 {
        let (r, f) = (&mut gyro.params, &mut gyro.front_end);
        match self {
            Parameter::MassKg => &mut r.mass_kg,
            Parameter::DriveFrequencyHz => &mut r.drive_frequency_hz,
            Parameter::SenseFrequencyHz => &mut r.sense_frequency_hz,
            Parameter::QDrive => &mut r.q_drive,
            Parameter::QSense => &mut r.q_sense,
            Parameter::StiffnessAngleDeg => &mut r.stiffness_angle_deg,
            Parameter::DampingAngleDeg => &mut r.damping_angle_deg,
            Parameter::DriveAmplitudeM => &mut r.drive_amplitude_m,
            Parameter::PhaseErrorDeg => &mut r.phase_error_deg,
            Parameter::PhaseErrorReverseDeg => &mut r.phase_error_reverse_deg,
            Parameter::PickoffGainXVPerM => &mut f.pickoff_gain_v_per_m[0],
            Parameter::PickoffGainYVPerM => &mut f.pickoff_gain_v_per_m[1],
            Parameter::PickoffNoiseVPerSqrtHz => &mut f.pickoff_noise_v_per_sqrt_hz,
            Parameter::AdcFullScaleV => &mut f.adc_full_scale_v,
            Parameter::DacNewtonPerLsb => &mut f.dac_newton_per_lsb,
            Parameter::TemperatureK => &mut f.temperature_k,
        }
    }
}

/// One gyro's physics: its structure, its front end and the seed of its random streams.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GyroPhysics {
    /// The structure.
    pub params: ResonatorParams,
    /// The front end.
    pub front_end: PhysicsSettings,
    /// Seed of the resonator's random streams.
    pub seed: u64,
}

/// One member: both gyros' physics and the values drawn, gyro A's spreads then gyro B's.
#[derive(Clone, Debug, PartialEq)]
pub struct Member {
    /// Its index in the population.
    pub index: u64,
    /// Gyro A and B.
    pub gyros: [GyroPhysics; 2],
    /// The drawn values in the order of the spreads, gyro A's then gyro B's (units of each
    /// parameter).
    pub drawn: Vec<f64>,
}

/// The random stream of member `index` of the population seeded `seed`.
pub fn member_rng(seed: u64, index: u64) -> ChaCha8Rng {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    rng.set_stream(index);
    rng
}

/// Member `index` of the population seeded `seed`: the nominal physics `nominal` (A, B; their
/// seeds ignored) with each of `spreads` drawn per gyro, as the [module doc](self) says.
pub fn member(
    nominal: &[GyroPhysics; 2],
    spreads: &[(Parameter, Spread)],
    seed: u64,
    index: u64,
) -> Member {
    let mut rng = member_rng(seed, index);
    let mut gyros = *nominal;
    for gyro in &mut gyros {
        gyro.seed = rng.next_u64();
    }
    let mut drawn = Vec::with_capacity(2 * spreads.len());
    for (g, gyro) in gyros.iter_mut().enumerate() {
        for (parameter, spread) in spreads {
            let mut copy = nominal[g];
            let nominal_value = *parameter.slot(&mut copy);
            let value = spread.draw(nominal_value, &mut rng);
            *parameter.slot(gyro) = value;
            drawn.push(value);
        }
    }
    Member {
        index,
        gyros,
        drawn,
    }
}
