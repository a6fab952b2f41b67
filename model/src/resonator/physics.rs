//! The simulated 2-DOF resonator at the ADC rate (float, deterministic): exact zero-order-hold
//! discretisation, pick-off with the sense channel's phase error, ADC and DAC, thermomechanical
//! and electronic noise, and slow drift. The equations and units are in the [module
//! doc](super).

use super::closed_form::ModeFigures;
use super::expm::{expm, Matrix};
use super::noise::{cholesky, Drift, Sources};
use super::params::{rotated, ParamError, ResonatorParams};
use super::settings::{GaussMarkov, PhysicsSettings};
use super::Mode;
use crate::stimulus::{Gaussian, ResonatorSource, Stream};

/// Boltzmann's constant, J/K (exact since the 2019 SI).
pub const BOLTZMANN_J_PER_K: f64 = 1.380_649e-23;

/// 2^63 as f64 (exact): the ADC's scaled input must stay below it for the cast to i64.
const I64_LIMIT: f64 = 9_223_372_036_854_775_808.0;

/// Neither principal damping drifts below this fraction of its nominal value.
const DAMPING_FLOOR: f64 = 0.1;

/// One simulated resonator.
///
/// State: `q = [x, y]` (m) and `q′` (m/s), carried internally as `[x, y, x′/w0, y′/w0]` with
/// `w0 = sqrt((k1 + k2)/(2m))` so that the state matrix is balanced for the matrix exponential.
#[derive(Clone, Debug)]
pub struct Resonator {
    params: ResonatorParams,
    settings: PhysicsSettings,
    seed: u64,
    /// `w0`, rad/s.
    velocity_scale: f64,
    /// `T = 1/fs`, s.
    sample_period: f64,
    /// Nominal drive resonance of each mode (normal, reverse), rad/s: the frequency at which
    /// the sense pick-off's phase shift equals the phase error.
    nominal_drive: [f64; 2],
    /// Input rate Ω, rad/s.
    omega: f64,
    mode: Mode,
    /// Transition matrix `Φ = e^{A T}` (scaled state).
    transition: Matrix<4>,
    /// Input matrix `Γ = ∫₀ᵀ e^{Aτ} dτ B` (scaled state per N).
    input: [[f64; 2]; 4],
    /// Lower Cholesky factor of the discrete thermomechanical noise covariance (scaled state).
    noise_factor: Matrix<4>,
    /// Pick-off rows: volts from the scaled state.
    pickoff: [[f64; 4]; 2],
    state: [f64; 4],
    samples: u64,
    sources: Sources,
    /// ADC scale `2^(w−1) / full_scale`, codes per V, and the code range.
    adc_codes_per_volt: f64,
    adc_range: (i64, i64),
    adc_saturations: u64,
}

impl Resonator {
    /// A resonator at rest, in normal mode, at Ω = 0, its random streams drawn from `seed`
    /// (one ChaCha8 stream per source: [`ResonatorSource`]). Two gyros of a pair take
    /// different seeds.
    ///
    /// # Errors
    /// [`ParamError::Range`] for a parameter or setting out of range.
    pub fn new(
        params: &ResonatorParams,
        settings: &PhysicsSettings,
        seed: u64,
    ) -> Result<Self, ParamError> {
        params.validate()?;
        settings.validate(params)?;
        let sample_period = 1.0 / settings.sample_rate_hz;
        let [k1, k2] = params.principal_stiffness();
        let velocity_scale = ((k1 + k2) / (2.0 * params.mass_kg)).sqrt();
        let drift_period = f64::from(settings.drift_update_samples) * sample_period;
        let sources = if settings.noise {
            let [d1, d2] = params.principal_damping();
            Sources {
                thermomechanical: (settings.temperature_k > 0.0 && d1 + d2 > 0.0).then(|| {
                    Gaussian::on(seed, Stream::Resonator(ResonatorSource::Thermomechanical))
                }),
                pickoff: (settings.pickoff_noise_v_per_sqrt_hz > 0.0).then(|| {
                    (
                        [0, 1].map(|axis| {
                            Gaussian::on(seed, Stream::Resonator(ResonatorSource::Pickoff(axis)))
                        }),
                        settings.pickoff_noise_v_per_sqrt_hz
                            * (settings.sample_rate_hz / 2.0).sqrt(),
                    )
                }),
                damping_split: Drift::new(
                    settings.damping_split_drift,
                    drift_period,
                    seed,
                    ResonatorSource::DampingSplitDrift,
                ),
                damping_angle: Drift::new(
                    GaussMarkov {
                        std: settings.damping_angle_drift.std.to_radians(),
                        ..settings.damping_angle_drift
                    },
                    drift_period,
                    seed,
                    ResonatorSource::DampingAngleDrift,
                ),
                phase: Drift::new(
                    GaussMarkov {
                        std: settings.phase_drift.std.to_radians(),
                        ..settings.phase_drift
                    },
                    drift_period,
                    seed,
                    ResonatorSource::PhaseDrift,
                ),
            }
        } else {
            Sources {
                thermomechanical: None,
                pickoff: None,
                damping_split: None,
                damping_angle: None,
                phase: None,
            }
        };
        let half_range = 1i128 << (settings.adc_width - 1);
        let mut resonator = Resonator {
            params: *params,
            settings: *settings,
            seed,
            velocity_scale,
            sample_period,
            nominal_drive: [Mode::Normal, Mode::Reverse]
                .map(|mode| ModeFigures::new(params, mode).drive_angular_frequency),
            omega: 0.0,
            mode: Mode::Normal,
            transition: [[0.0; 4]; 4],
            input: [[0.0; 2]; 4],
            noise_factor: [[0.0; 4]; 4],
            pickoff: [[0.0; 4]; 2],
            state: [0.0; 4],
            samples: 0,
            sources,
            adc_codes_per_volt: half_range as f64 / settings.adc_full_scale_v,
            adc_range: ((-half_range) as i64, (half_range - 1) as i64),
            adc_saturations: 0,
        };
        resonator.discretise();
        resonator.update_pickoff();
        Ok(resonator)
    }

    /// Back to the state right after [`Resonator::new`]: at rest, normal mode, Ω = 0, every
    /// random stream restarted.
    pub fn reset(&mut self) {
        *self = Resonator::new(&self.params, &self.settings, self.seed)
            .expect("the parameters were validated at construction");
    }

    /// The input rate Ω, rad/s, from the next sample on. Recomputes the discretisation
    /// (a 6×6 matrix exponential, and an 8×8 one with thermomechanical noise) when Ω changes.
    pub fn set_rate(&mut self, omega_rad_s: f64) {
        if omega_rad_s.to_bits() != self.omega.to_bits() {
            self.omega = omega_rad_s;
            self.discretise();
        }
    }

    /// The input rate Ω, rad/s.
    pub fn rate(&self) -> f64 {
        self.omega
    }

    /// Selects which axis the sense channel reads (normal: y, reverse: x), and with it
    /// which pick-off carries the phase error. The mechanics do not change.
    pub fn set_mode(&mut self, mode: Mode) {
        self.mode = mode;
        self.update_pickoff();
    }

    /// The mode.
    pub fn mode(&self) -> Mode {
        self.mode
    }

    /// Sample rate, Hz.
    pub fn sample_rate_hz(&self) -> f64 {
        self.settings.sample_rate_hz
    }

    /// Pick-off gains `[g_x, g_y]`, V/m.
    pub fn pickoff_gain(&self) -> [f64; 2] {
        self.settings.pickoff_gain_v_per_m
    }

    /// Displacements `[x, y]`, m.
    pub fn position(&self) -> [f64; 2] {
        [self.state[0], self.state[1]]
    }

    /// Velocities `[x′, y′]`, m/s.
    pub fn velocity(&self) -> [f64; 2] {
        [
            self.state[2] * self.velocity_scale,
            self.state[3] * self.velocity_scale,
        ]
    }

    /// Sets displacements (m) and velocities (m/s), e.g. to start in a steady state.
    pub fn set_state(&mut self, position: [f64; 2], velocity: [f64; 2]) {
        self.state = [
            position[0],
            position[1],
            velocity[0] / self.velocity_scale,
            velocity[1] / self.velocity_scale,
        ];
    }

    /// Samples simulated since construction or reset.
    pub fn samples(&self) -> u64 {
        self.samples
    }

    /// The current drift offsets: damping split (fraction of the mean damping), damping
    /// angle (rad), phase (rad); zero when off.
    pub fn drift(&self) -> [f64; 3] {
        let value = |d: &Option<Drift>| d.as_ref().map_or(0.0, |d| d.value);
        [
            value(&self.sources.damping_split),
            value(&self.sources.damping_angle),
            value(&self.sources.phase),
        ]
    }

    /// One sample: holds `force_n` (N on x and y) over `T = 1/fs`, adds the thermomechanical
    /// noise of that interval, and returns the pick-off voltages `[v_x, v_y]` (V, with their
    /// electronic noise) sampled at its end. Every `drift_update_samples` samples the drifts
    /// then advance.
    #[inline]
    pub fn step(&mut self, force_n: [f64; 2]) -> [f64; 2] {
        let z = self.state;
        let mut next = [0.0; 4];
        for (i, value) in next.iter_mut().enumerate() {
            let row = &self.transition[i];
            *value = row[0] * z[0]
                + row[1] * z[1]
                + row[2] * z[2]
                + row[3] * z[3]
                + self.input[i][0] * force_n[0]
                + self.input[i][1] * force_n[1];
        }
        if let Some(source) = self.sources.thermomechanical.as_mut() {
            let n = [
                source.sample(),
                source.sample(),
                source.sample(),
                source.sample(),
            ];
            for (i, value) in next.iter_mut().enumerate() {
                let row = &self.noise_factor[i];
                *value += row[0] * n[0] + row[1] * n[1] + row[2] * n[2] + row[3] * n[3];
            }
        }
        self.state = next;
        self.samples += 1;
        let mut volts = [0.0; 2];
        for (axis, v) in volts.iter_mut().enumerate() {
            let row = &self.pickoff[axis];
            *v = row[0] * next[0] + row[1] * next[1] + row[2] * next[2] + row[3] * next[3];
        }
        if let Some((sources, sigma)) = self.sources.pickoff.as_mut() {
            for (v, source) in volts.iter_mut().zip(sources.iter_mut()) {
                *v += *sigma * source.sample();
            }
        }
        if self
            .samples
            .is_multiple_of(u64::from(self.settings.drift_update_samples))
        {
            self.advance_drift();
        }
        volts
    }

    /// Forces from DAC codes: `code · dac_newton_per_lsb`, N (the DAC holds them over a
    /// sample).
    #[inline]
    pub fn force_from_dac(&self, codes: [i64; 2]) -> [f64; 2] {
        codes.map(|c| c as f64 * self.settings.dac_newton_per_lsb)
    }

    /// The ADC: each voltage scaled by `2^(w−1) / full_scale`, rounded to nearest with ties
    /// toward +∞ (add half an LSB, floor) and saturated to `−2^(w−1) ..= 2^(w−1) − 1`, as
    /// [`crate::stimulus::adc`] does. Saturations are counted ([`Self::adc_saturations`]).
    ///
    /// # Panics
    /// On a non-finite voltage.
    #[inline]
    pub fn adc(&mut self, volts: [f64; 2]) -> [i64; 2] {
        let mut codes = [0; 2];
        for (code, v) in codes.iter_mut().zip(volts) {
            assert!(v.is_finite(), "the ADC input must be finite, got {v}");
            let scaled = v * self.adc_codes_per_volt;
            let rounded = crate::fx::round_half_up(scaled);
            *code = rounded.clamp(self.adc_range.0, self.adc_range.1);
            // Beyond ±2^63 the rounding has saturated already.
            let beyond_i64 = !(-I64_LIMIT..I64_LIMIT).contains(&scaled);
            self.adc_saturations += u64::from(*code != rounded || beyond_i64);
        }
        codes
    }

    /// ADC samples that saturated since construction or reset.
    pub fn adc_saturations(&self) -> u64 {
        self.adc_saturations
    }

    /// One sample from DAC codes to ADC codes: [`Self::force_from_dac`], [`Self::step`],
    /// [`Self::adc`].
    #[inline]
    pub fn step_codes(&mut self, dac_codes: [i64; 2]) -> [i64; 2] {
        let force = self.force_from_dac(dac_codes);
        let volts = self.step(force);
        self.adc(volts)
    }

    fn advance_drift(&mut self) {
        let mut mechanics = false;
        for drift in [
            &mut self.sources.damping_split,
            &mut self.sources.damping_angle,
        ]
        .into_iter()
        .flatten()
        {
            drift.advance();
            mechanics = true;
        }
        if mechanics {
            self.discretise();
        }
        if let Some(phase) = self.sources.phase.as_mut() {
            phase.advance();
            self.update_pickoff();
        }
    }

    /// `D` with the drifts applied, N·s/m.
    fn damping(&self) -> [[f64; 2]; 2] {
        let [d1, d2] = self.params.principal_damping();
        let [split, angle, _] = self.drift();
        let shift = split * (d1 + d2) / 4.0;
        let principal = [
            (d1 + shift).max(DAMPING_FLOOR * d1),
            (d2 - shift).max(DAMPING_FLOOR * d2),
        ];
        rotated(
            principal,
            self.params.damping_angle_deg.to_radians() + angle,
        )
    }

    /// The continuous state matrix of the scaled state `[x, y, x′/w0, y′/w0]`.
    fn state_matrix(&self) -> Matrix<4> {
        let m = self.params.mass_kg;
        let w0 = self.velocity_scale;
        let k = self.params.matrices().k;
        let d = self.damping();
        let coriolis = 2.0 * m * self.omega;
        // m q″ = −K q − (D − G) q′ + τ with G = [[0, 2mΩ], [−2mΩ, 0]].
        let d_minus_g = [[d[0][0], d[0][1] - coriolis], [d[1][0] + coriolis, d[1][1]]];
        let mut a = [[0.0; 4]; 4];
        a[0][2] = w0;
        a[1][3] = w0;
        for i in 0..2 {
            for j in 0..2 {
                a[2 + i][j] = -k[i][j] / (m * w0);
                a[2 + i][2 + j] = -d_minus_g[i][j] / m;
            }
        }
        a
    }

    /// Zero-order-hold discretisation of the current mechanics: `Φ` and `Γ` from the 6×6
    /// exponential `e^{[[A, B], [0, 0]] T}`, and, with thermomechanical noise, the exact
    /// discrete noise covariance `Q_d = ∫₀ᵀ e^{Aτ} B Q_c Bᵀ e^{Aᵀτ} dτ` by Van Loan's 8×8
    /// exponential, factored by Cholesky.
    fn discretise(&mut self) {
        let t = self.sample_period;
        let w0 = self.velocity_scale;
        let a = self.state_matrix();
        // The input columns are scaled by w0 (instead of 1/(m w0)) to keep the matrix
        // balanced; Γ is scaled back below.
        let mut augmented: Matrix<6> = [[0.0; 6]; 6];
        for i in 0..4 {
            for j in 0..4 {
                augmented[i][j] = a[i][j] * t;
            }
        }
        augmented[2][4] = w0 * t;
        augmented[3][5] = w0 * t;
        let e = expm(&augmented);
        let per_newton = 1.0 / (self.params.mass_kg * w0 * w0);
        for ((transition, input), row) in self.transition.iter_mut().zip(&mut self.input).zip(&e) {
            transition.copy_from_slice(&row[..4]);
            *input = [row[4] * per_newton, row[5] * per_newton];
        }
        if self.sources.thermomechanical.is_some() {
            self.noise_factor = self.thermomechanical_factor(&a);
        }
    }

    /// Cholesky factor of `Q_d` for the force noise of one-sided PSD `4 k_B T D` (N²/Hz),
    /// i.e. the white-noise intensity `Q_c = 2 k_B T D` (N²·s).
    fn thermomechanical_factor(&self, a: &Matrix<4>) -> Matrix<4> {
        let t = self.sample_period;
        let m = self.params.mass_kg;
        let w0 = self.velocity_scale;
        let d = self.damping();
        let d_mean = (d[0][0] + d[1][1]) / 2.0;
        // In the scaled state, B Q_c Bᵀ = [[0, 0], [0, 2 k_B T D / (m w0)²]]. Van Loan's
        // matrix uses it divided by 2 k_B T d̄ / (m² w0³) (so its entries are about w0), and
        // Q_d is scaled back.
        let intensity_scale =
            2.0 * BOLTZMANN_J_PER_K * self.settings.temperature_k * d_mean / (m * m * w0 * w0 * w0);
        let mut van_loan: Matrix<8> = [[0.0; 8]; 8];
        for i in 0..4 {
            for j in 0..4 {
                van_loan[i][j] = -a[i][j] * t;
                van_loan[4 + i][4 + j] = a[j][i] * t;
            }
        }
        for i in 0..2 {
            for j in 0..2 {
                van_loan[2 + i][4 + 2 + j] = d[i][j] / d_mean * w0 * t;
            }
        }
        let e = expm(&van_loan);
        // e = [[·, Φ⁻¹ Q_d], [0, Φᵀ]]: Q_d = Φ · (upper-right block).
        let mut q = [[0.0; 4]; 4];
        for i in 0..4 {
            for j in 0..4 {
                let mut sum = 0.0;
                for k in 0..4 {
                    sum += e[4 + k][4 + i] * e[k][4 + j];
                }
                q[i][j] = sum * intensity_scale;
            }
        }
        cholesky(&q)
    }

    /// Pick-off rows for the current mode and phase drift: the driven axis reads
    /// `g q_a`, the sensed axis `g (cos φ q_s + sin φ q_s′ / w)` with `w` the mode's nominal
    /// drive resonance.
    fn update_pickoff(&mut self) {
        let phase_drift = self.drift()[2];
        let (sensed, phase_deg, w) = match self.mode {
            Mode::Normal => (1, self.params.phase_error_deg, self.nominal_drive[0]),
            Mode::Reverse => (
                0,
                self.params.phase_error_reverse_deg,
                self.nominal_drive[1],
            ),
        };
        let phi = phase_deg.to_radians() + phase_drift;
        let gain = self.settings.pickoff_gain_v_per_m;
        self.pickoff = [[0.0; 4]; 2];
        let driven = 1 - sensed;
        self.pickoff[driven][driven] = gain[driven];
        self.pickoff[sensed][sensed] = gain[sensed] * libm::cos(phi);
        self.pickoff[sensed][2 + sensed] = gain[sensed] * libm::sin(phi) * self.velocity_scale / w;
    }
}

#[cfg(test)]
mod tests;
