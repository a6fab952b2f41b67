//! Noise analysis of rate records (f64): the Allan family of deviations with confidence
//! intervals ([`allan`]), the χ² distribution they need ([`chi2`]), and the five-term noise
//! identification ([`noise`]), autoregressive models ([`ar`]), ICEEMDAN ([`emd`]) and threshold
//! denoising on it ([`denoise`]).

pub mod allan;
pub mod ar;
pub mod chi2;
pub mod davar;
pub mod denoise;
pub mod edf;
pub mod emd;
pub mod noise;
pub mod spectrum;

#[cfg(test)]
mod tests {
    use super::allan::{deviation, phase, Kind};
    use crate::stimulus::{Gaussian, Stream};

    fn overlapping_adev(rate: &[f64], m: usize) -> Option<f64> {
        deviation(Kind::Overlapping, &phase(rate), m, 1.0).map(|(dev, _)| dev)
    }

    #[test]
    fn white_noise_falls_as_one_over_root_tau() {
        // White rate noise of σ per sample: ADEV(m) = σ / √m.
        let mut g = Gaussian::new(5, Stream::AngleRandomWalk(0));
        let rate: Vec<f64> = (0..200_000).map(|_| 2.0 * g.sample()).collect();
        for m in [1usize, 10, 100] {
            let adev = overlapping_adev(&rate, m).unwrap();
            let want = 2.0 / (m as f64).sqrt();
            assert!((adev / want - 1.0).abs() < 0.05, "m {m}: {adev} vs {want}");
        }
        assert_eq!(overlapping_adev(&rate[..10], 5), None);
    }

    #[test]
    fn a_constant_has_zero_deviation_and_a_square_wave_the_known_value() {
        assert_eq!(overlapping_adev(&[3.0; 100], 4), Some(0.0));
        // ±1 alternating every m samples, at τ = m: a window starting j samples into a half
        // period averages (m − 2j)/m and the next one the negative, so the difference is
        // 2(1 − 2j/m) and AVAR = ½·mean(d²) = (2/m) Σ_j (1 − 2j/m)² (0.68 for m = 10).
        let m = 10;
        let square: Vec<f64> = (0..4000)
            .map(|k| if (k / m) % 2 == 0 { 1.0 } else { -1.0 })
            .collect();
        let adev = overlapping_adev(&square, m).unwrap();
        let avar: f64 = (0..m)
            .map(|j| (1.0 - 2.0 * j as f64 / m as f64).powi(2))
            .sum::<f64>()
            * 2.0
            / m as f64;
        assert!(
            (adev - avar.sqrt()).abs() < 1e-3,
            "{adev} vs {}",
            avar.sqrt()
        );
    }
}
