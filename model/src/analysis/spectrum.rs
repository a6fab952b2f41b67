//! Spectrum and correlation of rate records: Welch PSD and noise density, autocorrelation, and
//! the 1σ error against a known true rate (paper 000's figures of merit).
//!
//! Welch: segments of `segment` samples (Hann window), 50 % overlap, each periodogram
//! normalized by the window's power so that the one-sided PSD integrates to the variance:
//! `S(f)` in (°/s)²/Hz. Noise density is quoted as MEMS datasheets do, `√(S(f)/2)` in
//! °/s/√Hz (the two-sided density), which for white rate noise equals the ARW N in °/√s.

use rustfft::{num_complex::Complex, FftPlanner};
use serde::Serialize;

/// A one-sided power spectral density.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Psd {
    /// Frequencies, Hz (0 to fs/2).
    pub frequency_hz: Vec<f64>,
    /// One-sided PSD, (°/s)²/Hz.
    pub psd: Vec<f64>,
}

impl Psd {
    /// Noise density `√(S/2)` (°/s/√Hz) at each frequency.
    pub fn density(&self) -> Vec<f64> {
        self.psd.iter().map(|s| (s / 2.0).sqrt()).collect()
    }

    /// Median noise density over `[lo, hi]` Hz, °/s/√Hz.
    pub fn median_density(&self, lo: f64, hi: f64) -> Option<f64> {
        let mut band: Vec<f64> = self
            .frequency_hz
            .iter()
            .zip(self.density())
            .filter(|(f, _)| **f >= lo && **f <= hi)
            .map(|(_, d)| d)
            .collect();
        if band.is_empty() {
            return None;
        }
        band.sort_by(f64::total_cmp);
        Some(band[band.len() / 2])
    }
}

/// Welch PSD of `rate` (°/s) at `rate_hz` with segments of `segment` samples.
///
/// # Panics
/// When `segment` is below 8 or longer than the record.
pub fn welch(rate: &[f64], rate_hz: f64, segment: usize) -> Psd {
    assert!(
        segment >= 8 && segment <= rate.len(),
        "segments of 8..=N samples"
    );
    let window: Vec<f64> = (0..segment)
        .map(|i| {
            let s = libm::sin(std::f64::consts::PI * i as f64 / segment as f64);
            s * s
        })
        .collect();
    let window_power: f64 = window.iter().map(|w| w * w).sum();
    let fft = FftPlanner::<f64>::new().plan_fft_forward(segment);
    let bins = segment / 2 + 1;
    let mut sum = vec![0.0; bins];
    let mut count = 0usize;
    let mut buffer = vec![Complex::new(0.0, 0.0); segment];
    let mut start = 0;
    while start + segment <= rate.len() {
        let chunk = &rate[start..start + segment];
        let mean = chunk.iter().sum::<f64>() / segment as f64;
        for ((b, v), w) in buffer.iter_mut().zip(chunk).zip(&window) {
            *b = Complex::new((v - mean) * w, 0.0);
        }
        fft.process(&mut buffer);
        for (k, s) in sum.iter_mut().enumerate() {
            // One-sided: double every bin but DC and Nyquist.
            let factor = if k == 0 || (segment.is_multiple_of(2) && k == segment / 2) {
                1.0
            } else {
                2.0
            };
            *s += factor * buffer[k].norm_sqr();
        }
        count += 1;
        start += segment / 2;
    }
    let scale = 1.0 / (rate_hz * window_power * count as f64);
    Psd {
        frequency_hz: (0..bins)
            .map(|k| k as f64 * rate_hz / segment as f64)
            .collect(),
        psd: sum.iter().map(|s| s * scale).collect(),
    }
}

/// Biased autocovariance `c(k) = (1/N) Σ (x_i − x̄)(x_{i+k} − x̄)` for lags `0..=max_lag`
/// (capped at `N − 1`): the estimator whose Toeplitz matrix stays positive semi-definite.
pub fn autocovariance(rate: &[f64], max_lag: usize) -> Vec<f64> {
    let n = rate.len();
    let mean = rate.iter().sum::<f64>() / n as f64;
    let centred: Vec<f64> = rate.iter().map(|v| v - mean).collect();
    (0..=max_lag.min(n - 1))
        .map(|k| {
            centred[..n - k]
                .iter()
                .zip(&centred[k..])
                .map(|(a, b)| a * b)
                .sum::<f64>()
                / n as f64
        })
        .collect()
}

/// Normalized autocorrelation `r(k) = c(k)/c(0)` for lags `0..=max_lag` (mean removed;
/// r(0) = 1; a constant record gives 1, 0, 0, …).
pub fn autocorrelation(rate: &[f64], max_lag: usize) -> Vec<f64> {
    let c = autocovariance(rate, max_lag);
    let c0 = c[0];
    c.iter()
        .enumerate()
        .map(|(k, ck)| match (c0 == 0.0, k) {
            (true, 0) => 1.0,
            (true, _) => 0.0,
            (false, _) => ck / c0,
        })
        .collect()
}

/// 1σ error against a known true rate (paper 000 eq. 19): `√(Σ(ω̂ − ω)² / (n − 1))`, and the
/// mean error, °/s.
pub fn one_sigma_error(estimate: &[f64], truth: &[f64]) -> (f64, f64) {
    let n = estimate.len().min(truth.len());
    let errors: Vec<f64> = estimate.iter().zip(truth).map(|(e, t)| e - t).collect();
    let mean = errors.iter().sum::<f64>() / n as f64;
    let sigma = (errors.iter().map(|e| e * e).sum::<f64>() / (n as f64 - 1.0)).sqrt();
    (sigma, mean)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::stimulus::{Gaussian, Stream};

    fn white(n: usize, sigma: f64) -> Vec<f64> {
        let mut g = Gaussian::new(6, Stream::AngleRandomWalk(0));
        (0..n).map(|_| sigma * g.sample()).collect()
    }

    #[test]
    fn white_noise_density_is_the_arw() {
        // ARW N = 0.1 °/√s at 200 Hz: σ per sample = N √fs.
        let fs: f64 = 200.0;
        let y = white(400_000, 0.1 * fs.sqrt());
        let psd = welch(&y, fs, 4096);
        let density = psd.median_density(1.0, 90.0).unwrap();
        assert!((density / 0.1 - 1.0).abs() < 0.03, "{density}");
        // Parseval: the PSD integrates to the variance.
        let df = psd.frequency_hz[1];
        let power: f64 = psd.psd.iter().sum::<f64>() * df;
        assert!((power / (0.01 * fs) - 1.0).abs() < 0.03, "{power}");
    }

    #[test]
    fn a_sine_shows_up_at_its_frequency() {
        let fs = 100.0;
        let y: Vec<f64> = (0..20_000)
            .map(|k| libm::sin(2.0 * std::f64::consts::PI * 12.5 * k as f64 / fs))
            .collect();
        let psd = welch(&y, fs, 1024);
        let peak = psd
            .psd
            .iter()
            .enumerate()
            .max_by(|a, b| a.1.total_cmp(b.1))
            .unwrap()
            .0;
        assert!(
            (psd.frequency_hz[peak] - 12.5).abs() < 0.1,
            "{}",
            psd.frequency_hz[peak]
        );
    }

    #[test]
    fn autocorrelation_of_an_ar1_process() {
        let mut g = Gaussian::new(7, Stream::AngleRandomWalk(1));
        let mut x = 0.0;
        let y: Vec<f64> = (0..200_000)
            .map(|_| {
                x = 0.8 * x + g.sample();
                x
            })
            .collect();
        let r = autocorrelation(&y, 3);
        assert_eq!(r[0], 1.0);
        for (k, want) in [(1, 0.8), (2, 0.64), (3, 0.512)] {
            assert!((r[k] - want).abs() < 0.01, "r({k}) = {}", r[k]);
        }
    }

    #[test]
    fn one_sigma_error_of_a_known_offset_and_noise() {
        let truth = vec![10.0; 10_000];
        let noise = white(10_000, 0.5);
        let estimate: Vec<f64> = truth.iter().zip(&noise).map(|(t, n)| t + 0.2 + n).collect();
        let (sigma, mean) = one_sigma_error(&estimate, &truth);
        assert!(
            (mean - 0.2).abs() < 0.02 && (sigma - (0.25f64 + 0.04).sqrt()).abs() < 0.02,
            "{sigma} {mean}"
        );
    }
}
