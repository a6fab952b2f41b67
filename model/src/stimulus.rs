//! Deterministic stimulus: seeded random streams and a single-gyro source (simulation only).
//!
//! Every random number comes from one of two generators whose output is specified as integer
//! arithmetic and so the same on every platform, with one stream per noise source and gyro:
//! ChaCha8 (`rand_chacha`, streams by its stream number) for the rate-level noise and the
//! decompositions, and xoshiro256++ (`rand_xoshiro`, [`FastStream`]) for the resonator's
//! sources, which draw six Gaussians per ADC sample (ChaCha8's block refills cost 10 % of the
//! closed loop's time there). Gaussian samples come from a 256-layer ziggurat (Marsaglia &
//! Tsang, 2000) whose tables are built once with the pure-Rust `libm` — so one seed gives
//! byte-identical vectors everywhere. Nothing here calls the platform's libm.

use rand_chacha::ChaCha8Rng;
use rand_core::{RngCore, SeedableRng};
use rand_xoshiro::{SplitMix64, Xoshiro256PlusPlus};

use crate::fx::Format;

/// Independent random streams, one per noise source and gyro.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Stream {
    /// White rate noise (ARW) of gyro `0` or `1`.
    AngleRandomWalk(u8),
    /// Bias random walk (RRW) of a gyro.
    RateRandomWalk(u8),
    /// Gauss–Markov process `index` of a gyro's bias instability.
    BiasInstability(u8, u8),
    /// Noise realization `index` of an ensemble decomposition (ICEEMDAN).
    DecompositionNoise(u32),
    /// A random source of a simulated resonator ([`crate::resonator`]); the two gyros of a
    /// pair take different seeds.
    Resonator(ResonatorSource),
}

/// The random sources of one simulated resonator, each on its own stream.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ResonatorSource {
    /// Thermomechanical (Brownian) force on both axes.
    Thermomechanical,
    /// Electronic noise of the pick-off of axis `0` (x) or `1` (y).
    Pickoff(u8),
    /// Gauss–Markov drift of the damping split `d1 − d2`.
    DampingSplitDrift,
    /// Gauss–Markov drift of the damping angle θ.
    DampingAngleDrift,
    /// Gauss–Markov drift of the sense channel's phase error.
    PhaseDrift,
}

impl Stream {
    /// The stream number: distinct for every source, gyro and process.
    pub fn id(self) -> u64 {
        let (source, gyro) = match self {
            Stream::AngleRandomWalk(g) => (1, g),
            Stream::RateRandomWalk(g) => (2, g),
            Stream::BiasInstability(g, j) => (16 + u64::from(j), g),
            // Above every plant stream (those stay below 1024 · 256).
            Stream::DecompositionNoise(i) => return (1 << 32) + u64::from(i),
            // Above the decomposition streams.
            Stream::Resonator(source) => {
                let index = match source {
                    ResonatorSource::Thermomechanical => 0,
                    ResonatorSource::Pickoff(axis) => 1 + u64::from(axis),
                    ResonatorSource::DampingSplitDrift => 1 + 256,
                    ResonatorSource::DampingAngleDrift => 2 + 256,
                    ResonatorSource::PhaseDrift => 3 + 256,
                };
                return (2 << 32) + index;
            }
        };
        source + 1024 * u64::from(gyro)
    }
}

/// R of the 256-layer normal ziggurat: where the tail starts.
const ZIGGURAT_R: f64 = 3.654_152_885_361_009;
/// V: the area of each layer.
const ZIGGURAT_V: f64 = 0.004_928_673_233_99;

/// Ziggurat tables: layer `i` spans `|x| < x[i]` between heights `f[i]` and `f[i+1]`
/// (`f(x) = e^{−x²/2}`); `x[0] = V/f(R)` covers the base strip with its tail, `x[1] = R`,
/// `x[256] = 0`.
struct Ziggurat {
    x: [f64; 257],
    f: [f64; 257],
}

impl std::fmt::Debug for Ziggurat {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("Ziggurat(256 layers)")
    }
}

fn ziggurat() -> &'static Ziggurat {
    static TABLES: std::sync::OnceLock<Ziggurat> = std::sync::OnceLock::new();
    TABLES.get_or_init(|| {
        let density = |x: f64| libm::exp(-0.5 * x * x);
        let mut x = [0.0; 257];
        x[0] = ZIGGURAT_V / density(ZIGGURAT_R);
        x[1] = ZIGGURAT_R;
        for i in 1..255 {
            x[i + 1] = (-2.0 * libm::log(ZIGGURAT_V / x[i] + density(x[i]))).sqrt();
        }
        x[256] = 0.0;
        let mut f = [0.0; 257];
        for i in 0..257 {
            f[i] = if i == 0 { 0.0 } else { density(x[i]) };
        }
        Ziggurat { x, f }
    })
}

/// A generator that gives every [`Stream`] of a seed its own sequence.
pub trait StreamRng: RngCore + Clone + std::fmt::Debug {
    /// The stream `stream` of seed `seed`.
    fn for_stream(seed: u64, stream: Stream) -> Self;
}

impl StreamRng for ChaCha8Rng {
    /// ChaCha8 keyed by `seed` (expanded by `seed_from_u64`), on stream number `stream.id()`.
    fn for_stream(seed: u64, stream: Stream) -> Self {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        rng.set_stream(stream.id());
        rng
    }
}

/// xoshiro256++ for the per-sample sources of the resonator: its 256-bit state is four
/// SplitMix64 outputs seeded by `SplitMix64(seed)`'s first output XOR `stream.id()` times the
/// 64-bit golden ratio, so every (seed, stream) starts at its own pseudo-random point of the
/// 2^256 − 1 cycle (Vigna's recommended seeding; two streams overlapping within 10^12 samples
/// has a probability below 2^−200).
pub type FastStream = Xoshiro256PlusPlus;

impl StreamRng for Xoshiro256PlusPlus {
    fn for_stream(seed: u64, stream: Stream) -> Self {
        let key = SplitMix64::seed_from_u64(seed).next_u64();
        let mut mixer =
            SplitMix64::seed_from_u64(key ^ stream.id().wrapping_mul(0x9e37_79b9_7f4a_7c15));
        let mut state = [0u8; 32];
        for word in state.chunks_exact_mut(8) {
            word.copy_from_slice(&mixer.next_u64().to_le_bytes());
        }
        Xoshiro256PlusPlus::from_seed(state)
    }
}

/// A seeded Gaussian source on its own stream of the generator `R`.
#[derive(Clone, Debug)]
pub struct Gaussian<R = ChaCha8Rng> {
    rng: R,
    /// Held rather than looked up per sample (the lookup is an atomic load and a branch).
    tables: &'static Ziggurat,
}

impl Gaussian {
    /// The ChaCha8 stream `stream` of seed `seed`.
    pub fn new(seed: u64, stream: Stream) -> Self {
        Self::on(seed, stream)
    }
}

impl<R: StreamRng> Gaussian<R> {
    /// The stream `stream` of seed `seed`, on the generator `R`.
    pub fn on(seed: u64, stream: Stream) -> Self {
        let rng = R::for_stream(seed, stream);
        Gaussian {
            rng,
            tables: ziggurat(),
        }
    }

    /// Uniform in [0, 1) with 53 random bits.
    pub fn uniform(&mut self) -> f64 {
        (self.rng.next_u64() >> 11) as f64 * crate::fx::pow2(-53)
    }

    /// Standard normal sample: ziggurat with 256 layers. The layer comes from the low 8 bits
    /// of one ChaCha output, a uniform in [−1, 1) from its top 53 bits; 98.8 % of samples are
    /// accepted at the first compare, the rest go through the wedge test or the tail (beyond
    /// R = 3.654) with `libm::exp` / `libm::log`.
    #[inline(always)]
    pub fn sample(&mut self) -> f64 {
        let bits = self.rng.next_u64();
        let layer = (bits & 0xff) as usize;
        let u = (bits >> 11) as f64 * crate::fx::pow2(-52) - 1.0; // [-1, 1)
        let x = u * self.tables.x[layer];
        if x.abs() < self.tables.x[layer + 1] {
            return x;
        }
        self.sample_beyond_the_rectangle(layer, u, x)
    }

    /// The 1.2 % of [`Self::sample`] that a layer's rectangle rejects, out of line so that the
    /// common path inlines into the callers' loops.
    #[cold]
    #[inline(never)]
    fn sample_beyond_the_rectangle(&mut self, mut layer: usize, mut u: f64, mut x: f64) -> f64 {
        let t = self.tables;
        loop {
            if layer == 0 {
                // The tail beyond R (Marsaglia 1964).
                loop {
                    let a = -libm::log(1.0 - self.uniform()) / ZIGGURAT_R;
                    let b = -libm::log(1.0 - self.uniform());
                    if 2.0 * b > a * a {
                        return if u < 0.0 {
                            -(ZIGGURAT_R + a)
                        } else {
                            ZIGGURAT_R + a
                        };
                    }
                }
            }
            // Wedge between the layer's rectangle and the curve.
            let y = t.f[layer] + self.uniform() * (t.f[layer + 1] - t.f[layer]);
            if y < libm::exp(-0.5 * x * x) {
                return x;
            }
            let bits = self.rng.next_u64();
            layer = (bits & 0xff) as usize;
            u = (bits >> 11) as f64 * crate::fx::pow2(-52) - 1.0;
            x = u * t.x[layer];
            if x.abs() < t.x[layer + 1] {
                return x;
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

/// The ADC: rounds each value to nearest (ties toward +∞) into `format` and saturates at full
/// scale — exactly [`from_f64`] with `Nearest` / `Saturate` (a test checks it), on a direct
/// path. Returns the codes and the number of saturated samples.
///
/// # Panics
/// On a non-finite value (the simulation produces none).
pub fn adc(values: &[f64], format: Format) -> (Vec<i64>, u64) {
    let scale = crate::fx::pow2(format.frac);
    let (min, max) = (format.min_code() as i64, format.max_code() as i64);
    let mut saturated = 0;
    let codes = values
        .iter()
        .map(|v| {
            assert!(v.is_finite(), "the ADC input must be finite, got {v}");
            // Scaling by a power of two is exact in range; beyond ±2^63 the cast saturates,
            // and so does the clamp below, as from_f64 would.
            let scaled = v * scale;
            let code = crate::fx::round_half_up(scaled);
            let clamped = code.clamp(min, max);
            saturated += u64::from(clamped != code || !(-9.2e18..9.2e18).contains(&scaled));
            clamped
        })
        .collect();
    (codes, saturated)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fx::{from_f64, Overflow, Rounding};

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
    fn ziggurat_samples_are_standard_normal() {
        let mut chacha = Gaussian::new(3, Stream::AngleRandomWalk(0));
        let mut fast =
            Gaussian::<FastStream>::on(3, Stream::Resonator(ResonatorSource::Pickoff(1)));
        let n = 2_000_000;
        check_standard_normal(&(0..n).map(|_| chacha.sample()).collect::<Vec<_>>());
        check_standard_normal(&(0..n).map(|_| fast.sample()).collect::<Vec<_>>());
        // The tables close: the last layer, from f[255] up to the top of the curve (1), has
        // the area V of every other layer.
        let z = ziggurat();
        let last = z.x[255] * (1.0 - z.f[255]);
        assert!((last / ZIGGURAT_V - 1.0).abs() < 1e-3, "{last}");
    }

    /// The fast streams of one seed, and one stream of neighbouring seeds, are uncorrelated
    /// (|ρ| within 5σ of 0 over 10^6 samples) and differ from the first sample on.
    #[test]
    fn fast_streams_are_distinct_and_uncorrelated() {
        let n = 1_000_000;
        let draw = |seed: u64, source: ResonatorSource| {
            let mut g = Gaussian::<FastStream>::on(seed, Stream::Resonator(source));
            (0..n).map(|_| g.sample()).collect::<Vec<f64>>()
        };
        let records = [
            draw(1, ResonatorSource::Thermomechanical),
            draw(1, ResonatorSource::Pickoff(0)),
            draw(1, ResonatorSource::Pickoff(1)),
            draw(2, ResonatorSource::Thermomechanical),
            draw(0, ResonatorSource::Thermomechanical),
        ];
        for (i, a) in records.iter().enumerate() {
            for b in &records[i + 1..] {
                assert_ne!(a[0], b[0]);
                let rho = a.iter().zip(b).map(|(x, y)| x * y).sum::<f64>() / n as f64;
                assert!(rho.abs() < 5.0 / (n as f64).sqrt(), "{i}: ρ = {rho}");
            }
        }
        assert_eq!(
            draw(1, ResonatorSource::Pickoff(0))[..100],
            records[1][..100]
        );
    }

    fn check_standard_normal(v: &[f64]) {
        let n = v.len();
        let mean = v.iter().sum::<f64>() / n as f64;
        let var = v.iter().map(|x| (x - mean) * (x - mean)).sum::<f64>() / n as f64;
        let kurt = v.iter().map(|x| (x - mean).powi(4)).sum::<f64>() / n as f64 / (var * var);
        assert!(
            mean.abs() < 3e-3 && (var - 1.0).abs() < 3e-3 && (kurt - 3.0).abs() < 0.02,
            "{mean} {var} {kurt}"
        );
        // Tail probabilities: P(|x| > 1) = 0.3173, P(|x| > 3) = 0.0026998, P(|x| > 4) = 6.334e-5.
        for (t, p) in [(1.0, 0.317_310_5), (3.0, 0.002_699_8), (4.0, 6.334e-5)] {
            let got = v.iter().filter(|x| x.abs() > t).count() as f64 / n as f64;
            let sigma = (p * (1.0 - p) / n as f64).sqrt();
            assert!((got - p).abs() < 5.0 * sigma, "P(|x| > {t}) = {got} vs {p}");
        }
    }

    #[test]
    fn adc_equals_from_f64_nearest_saturate() {
        let mut g = Gaussian::new(8, Stream::RateRandomWalk(3));
        for format in ["s24.14", "s16.7", "s8.2", "s64.10", "s12.-3", "u10.4"] {
            let f: Format = format.parse().unwrap();
            let values: Vec<f64> = (0..20_000)
                .map(|k| match k % 4 {
                    0 => g.sample() * 1000.0,
                    1 => (g.sample() * 64.0).round() / 16.0 + 1.0 / 32.0, // ties
                    2 => g.sample() * 1e19,                               // beyond i64
                    _ => g.sample(),
                })
                .collect();
            let (codes, saturated) = adc(&values, f);
            let mut want_saturated = 0;
            for (v, c) in values.iter().zip(&codes) {
                let q = from_f64(*v, f, Rounding::Nearest, Overflow::Saturate).unwrap();
                want_saturated += u64::from(q.overflowed);
                assert_eq!(i128::from(*c), q.code, "{v} into {f}");
            }
            assert_eq!(saturated, want_saturated, "{f}");
        }
    }

    #[test]
    fn adc_rounds_and_saturates() {
        let f: Format = "s8.2".parse().unwrap();
        let (codes, saturated) = adc(&[0.125, -0.125, 100.0, -100.0, 1.3], f);
        assert_eq!(codes, vec![1, 0, 127, -128, 5]);
        assert_eq!(saturated, 2);
    }
}
