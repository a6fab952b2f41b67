//! Deterministic stimulus: seeded random streams and a single-gyro source (simulation only).
//!
//! Every random number comes from ChaCha12 (`rand_chacha`, whose output is specified and the
//! same on every platform) with one stream per noise source, and Gaussian samples come from
//! Marsaglia's polar method with the pure-Rust `libm` — so one seed gives byte-identical
//! vectors everywhere.
//! Nothing here calls the platform's libm.

use rand_chacha::ChaCha12Rng;
use rand_core::{RngCore, SeedableRng};

use crate::fx::{from_f64, Format, Overflow, Rounding};

/// Independent random streams, one per noise source and gyro.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Stream {
    /// White rate noise (ARW) of gyro `0` or `1`.
    AngleRandomWalk(u8),
    /// Bias random walk (RRW) of a gyro.
    RateRandomWalk(u8),
    /// Gauss–Markov process `index` of a gyro's bias instability.
    BiasInstability(u8, u8),
}

impl Stream {
    /// The ChaCha stream number: distinct for every source, gyro and process.
    pub fn id(self) -> u64 {
        let (source, gyro) = match self {
            Stream::AngleRandomWalk(g) => (1, g),
            Stream::RateRandomWalk(g) => (2, g),
            Stream::BiasInstability(g, j) => (16 + u64::from(j), g),
        };
        source + 1024 * u64::from(gyro)
    }
}

/// A seeded Gaussian source on its own ChaCha12 stream.
#[derive(Clone, Debug)]
pub struct Gaussian {
    rng: ChaCha12Rng,
    spare: Option<f64>,
}

impl Gaussian {
    /// The stream `stream` of seed `seed`.
    pub fn new(seed: u64, stream: Stream) -> Self {
        let mut rng = ChaCha12Rng::seed_from_u64(seed);
        rng.set_stream(stream.id());
        Gaussian { rng, spare: None }
    }

    /// Uniform in [0, 1) with 53 random bits.
    pub fn uniform(&mut self) -> f64 {
        (self.rng.next_u64() >> 11) as f64 * crate::fx::pow2(-53)
    }

    /// Standard normal sample (Marsaglia's polar method: one `libm::log` per pair, no
    /// trigonometry; `sqrt` is exactly rounded everywhere).
    pub fn sample(&mut self) -> f64 {
        if let Some(z) = self.spare.take() {
            return z;
        }
        loop {
            let u = 2.0 * self.uniform() - 1.0;
            let v = 2.0 * self.uniform() - 1.0;
            let s = u * u + v * v;
            if s > 0.0 && s < 1.0 {
                let factor = (-2.0 * libm::log(s) / s).sqrt();
                self.spare = Some(v * factor);
                return u * factor;
            }
        }
    }

    /// `count` standard normal samples scaled by `sigma`.
    pub fn samples(&mut self, count: usize, sigma: f64) -> Vec<f64> {
        (0..count).map(|_| sigma * self.sample()).collect()
    }
}

/// The true input rate Ω(t), °/s.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Scenario {
    /// Ω alternates between 0 and `rate_dps` every `period_s` (a turntable step test).
    Steps {
        /// Rate of the high steps, °/s.
        rate_dps: f64,
        /// Duration of each step, s.
        period_s: f64,
    },
    /// Ω = `slope_dps_per_s · t`.
    Ramp {
        /// Slope, °/s per s.
        slope_dps_per_s: f64,
    },
    /// Ω = 0 (gyro at rest).
    Static,
    /// Ω = `rate_dps`.
    Constant {
        /// Rate, °/s.
        rate_dps: f64,
    },
    /// Ω = `amplitude_dps · sin(2π f t)` (paper 000's swing test: 20 °/s at 0.1–0.5 Hz).
    Sine {
        /// Amplitude, °/s.
        amplitude_dps: f64,
        /// Frequency, Hz.
        frequency_hz: f64,
    },
}

impl Scenario {
    /// Ω at time `t_s` seconds (pure-Rust `libm::sin`).
    pub fn rate_at(&self, t_s: f64) -> f64 {
        match *self {
            Scenario::Steps { rate_dps, period_s } => {
                if (t_s / period_s) as u64 % 2 == 1 {
                    rate_dps
                } else {
                    0.0
                }
            }
            Scenario::Ramp { slope_dps_per_s } => slope_dps_per_s * t_s,
            Scenario::Static => 0.0,
            Scenario::Constant { rate_dps } => rate_dps,
            Scenario::Sine {
                amplitude_dps,
                frequency_hz,
            } => amplitude_dps * libm::sin(2.0 * std::f64::consts::PI * frequency_hz * t_s),
        }
    }
}

/// One gyro: `y(k) = Ω(k) + b(k) + n(k)` with `b` = initial bias + rate random walk and `n`
/// white (ARW), then an ADC that rounds to nearest and saturates.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SingleGyro {
    /// Sample rate, Hz.
    pub fs_hz: f64,
    /// True rate.
    pub scenario: Scenario,
    /// Bias at t = 0, °/s.
    pub initial_bias_dps: f64,
    /// Angle random walk, °/√h.
    pub arw_deg_per_sqrt_h: f64,
    /// Rate random walk, °/h/√h.
    pub rrw_deg_per_h_per_sqrt_h: f64,
}

/// A simulated record.
#[derive(Clone, Debug, PartialEq)]
pub struct Record {
    /// True rate Ω(k), °/s.
    pub true_rate: Vec<f64>,
    /// Gyro output before the ADC, °/s.
    pub analog: Vec<f64>,
}

impl SingleGyro {
    /// Simulates `samples` samples from `seed`.
    ///
    /// Per sample `T = 1/fs`: white noise of standard deviation `N/√T` (N in °/√s), and a bias
    /// that steps by `K·√T` times a standard normal (K in °/s/√s).
    pub fn simulate(&self, samples: usize, seed: u64) -> Record {
        let t = 1.0 / self.fs_hz;
        let white_sigma = self.arw_deg_per_sqrt_h / 60.0 / t.sqrt();
        let walk_sigma = self.rrw_deg_per_h_per_sqrt_h / 216_000.0 * t.sqrt();
        // The streams are independent, so they are drawn on two threads.
        let (white, steps) = std::thread::scope(|scope| {
            let steps = scope.spawn(|| {
                Gaussian::new(seed, Stream::RateRandomWalk(0)).samples(samples, walk_sigma)
            });
            let white =
                Gaussian::new(seed, Stream::AngleRandomWalk(0)).samples(samples, white_sigma);
            (
                white,
                steps.join().expect("the noise generator does not panic"),
            )
        });
        let mut bias = self.initial_bias_dps;
        let mut true_rate = Vec::with_capacity(samples);
        let mut analog = Vec::with_capacity(samples);
        for k in 0..samples {
            let omega = self.scenario.rate_at(k as f64 * t);
            true_rate.push(omega);
            analog.push(omega + bias + white[k]);
            bias += steps[k];
        }
        Record { true_rate, analog }
    }
}

/// The ADC: rounds each value to nearest into `format` and saturates at full scale. Returns
/// the codes and the number of saturated samples.
///
/// # Panics
/// On a non-finite value (the simulation produces none).
pub fn adc(values: &[f64], format: Format) -> (Vec<i64>, u64) {
    let mut saturated = 0;
    let codes = values
        .iter()
        .map(|v| {
            let q = from_f64(*v, format, Rounding::Nearest, Overflow::Saturate)
                .expect("simulated values are finite");
            saturated += u64::from(q.overflowed);
            q.code as i64
        })
        .collect();
    (codes, saturated)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn same_seed_same_record_other_seed_other_record() {
        let gyro = crate::examples::gyro();
        let a = gyro.simulate(1000, 7);
        assert_eq!(a, gyro.simulate(1000, 7));
        assert_ne!(a.analog, gyro.simulate(1000, 8).analog);
        assert_eq!(
            a.true_rate[50],
            20.0 * libm::sin(2.0 * std::f64::consts::PI * 0.125)
        );
    }

    #[test]
    fn noise_has_the_configured_level() {
        // ARW 60 °/√h = 1 °/√s; at 100 Hz the white noise is 10 °/s rms.
        let gyro = SingleGyro {
            fs_hz: 100.0,
            scenario: Scenario::Static,
            initial_bias_dps: 0.0,
            arw_deg_per_sqrt_h: 60.0,
            rrw_deg_per_h_per_sqrt_h: 0.0,
        };
        let r = gyro.simulate(200_000, 1);
        let n = r.analog.len() as f64;
        let mean = r.analog.iter().sum::<f64>() / n;
        let rms = (r
            .analog
            .iter()
            .map(|v| (v - mean) * (v - mean))
            .sum::<f64>()
            / n)
            .sqrt();
        assert!((rms - 10.0).abs() < 0.05, "{rms}");
        assert!(mean.abs() < 0.1, "{mean}");
    }

    #[test]
    fn bias_random_walk_grows_with_the_square_root_of_time() {
        // RRW 216000 °/h^1.5 = 1 °/s/√s: after 100 s the bias has spread by 10 °/s rms.
        let gyro = SingleGyro {
            fs_hz: 10.0,
            scenario: Scenario::Static,
            initial_bias_dps: 0.0,
            arw_deg_per_sqrt_h: 0.0,
            rrw_deg_per_h_per_sqrt_h: 216_000.0,
        };
        let ends: Vec<f64> = (0..400)
            .map(|seed| *gyro.simulate(1001, seed).analog.last().unwrap())
            .collect();
        let rms = (ends.iter().map(|v| v * v).sum::<f64>() / ends.len() as f64).sqrt();
        assert!((rms - 10.0).abs() < 1.0, "{rms}");
    }

    #[test]
    fn adc_rounds_and_saturates() {
        let f: Format = "s8.2".parse().unwrap();
        let (codes, saturated) = adc(&[0.125, -0.125, 100.0, -100.0, 1.3], f);
        assert_eq!(codes, vec![1, 0, 127, -128, 5]);
        assert_eq!(saturated, 2);
    }
}
