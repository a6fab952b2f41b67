//! How one parameter spreads over a population: a normal or uniform distribution or a list of
//! values, absolute or relative to the nominal value, drawn from a ChaCha stream with
//! platform-independent arithmetic (`libm`), so that a seed gives the same draws everywhere.

use rand_chacha::ChaCha8Rng;
use rand_core::RngCore;

/// The shape of a spread. With [`Spread::relative`] the drawn number `d` is a fraction of the
/// nominal value `v0` and the parameter is `v0 (1 + d)`; otherwise it is the parameter itself.
#[derive(Clone, Debug, PartialEq)]
pub enum Distribution {
    /// `mean + std·z`, `z` standard normal (Box–Muller over two 53-bit uniforms). An absolute
    /// spread's `mean` defaults to the nominal value, a relative one's to 0.
    Normal {
        /// The mean (`None`: the default above).
        mean: Option<f64>,
        /// The standard deviation (≥ 0).
        std: f64,
    },
    /// Uniform in `[low, high)` (one 53-bit uniform).
    Uniform {
        /// Lower end.
        low: f64,
        /// Upper end (≥ `low`).
        high: f64,
    },
    /// One of the values, each equally likely (one 64-bit word, reduced without bias).
    Values(Vec<f64>),
}

/// A parameter's spread: its distribution, absolute or relative.
#[derive(Clone, Debug, PartialEq)]
pub struct Spread {
    /// The distribution of the drawn number.
    pub distribution: Distribution,
    /// Whether the drawn number is a fraction of the nominal value.
    pub relative: bool,
}

/// A uniform number in `[0, 1)` from the top 53 bits of one word.
pub fn uniform(rng: &mut ChaCha8Rng) -> f64 {
    (rng.next_u64() >> 11) as f64 * libm::ldexp(1.0, -53)
}

/// A standard normal number (Box–Muller, the cosine branch; two words).
pub fn standard_normal(rng: &mut ChaCha8Rng) -> f64 {
    let u1 = 1.0 - uniform(rng); // (0, 1]: the logarithm stays finite
    let u2 = uniform(rng);
    libm::sqrt(-2.0 * libm::log(u1)) * libm::cos(2.0 * std::f64::consts::PI * u2)
}

/// An index in `0..n` (`n ≥ 1`) without modulo bias (rejection of the incomplete last range).
fn index(rng: &mut ChaCha8Rng, n: usize) -> usize {
    let n = n as u64;
    let zone = u64::MAX - (u64::MAX % n) - 1;
    loop {
        let word = rng.next_u64();
        if word <= zone {
            return (word % n) as usize;
        }
    }
}

impl Spread {
    /// The parameter drawn for nominal value `nominal` (in the parameter's own unit).
    pub fn draw(&self, nominal: f64, rng: &mut ChaCha8Rng) -> f64 {
        let d = match &self.distribution {
            Distribution::Normal { mean, std } => {
                let mean = mean.unwrap_or(if self.relative { 0.0 } else { nominal });
                mean + std * standard_normal(rng)
            }
            Distribution::Uniform { low, high } => low + (high - low) * uniform(rng),
            Distribution::Values(values) => values[index(rng, values.len())],
        };
        if self.relative {
            nominal * (1.0 + d)
        } else {
            d
        }
    }
}
