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

/// Lowest sample rate (Hz) the Allan and DAVAR analyses take: τ = m/rate and the noise fit's
/// τ⁴ and τ⁻⁴ terms (times variances up to 10³⁰⁰) stay finite between this and
/// [`MAX_RATE_HZ`] for any record length up to 2⁵³.
pub const MIN_RATE_HZ: f64 = 1e-9;

/// Highest sample rate (Hz) the Allan and DAVAR analyses take (see [`MIN_RATE_HZ`]).
pub const MAX_RATE_HZ: f64 = 1e9;

/// Smallest magnitude (in the record's unit) a record's largest value may have: below it the
/// squares the analyses sum lose their precision or underflow to 0 (about 1e-150), and the
/// noise fit's weights, inverse squared variances (σ⁻⁴, about 1e280 at this peak), overflow
/// into NaN noise terms.
pub const MIN_PEAK: f64 = 1e-70;

/// Largest magnitude a value of a record of `samples` samples may have for the analyses'
/// sums of squares (of phases up to `samples`·max|y|) to stay finite: 10¹⁵⁰ / samples.
pub fn max_magnitude(samples: usize) -> f64 {
    1e150 / samples.max(1) as f64
}

/// Why a record is outside the magnitudes the analyses compute correctly.
#[derive(Debug, Clone, Copy, PartialEq, thiserror::Error)]
pub enum MagnitudeError {
    /// A value whose square (summed over the record) would overflow.
    #[error("value {index} = {value:e} is beyond ±{limit:.1e}: the sums of squares of {samples} such samples would overflow")]
    TooLarge {
        /// Its index in the record.
        index: usize,
        /// The value.
        value: f64,
        /// The largest magnitude allowed ([`max_magnitude`]).
        limit: f64,
        /// The record's length.
        samples: usize,
    },
    /// A record whose every value is so small that its squares underflow.
    #[error("the largest value is {peak:e}, below {MIN_PEAK:e}: its squares underflow to 0 (scale the record, e.g. into other units)")]
    TooSmall {
        /// The record's largest magnitude.
        peak: f64,
    },
}

/// Checks that every value of `record` is within [`max_magnitude`] and that its largest is at
/// least [`MIN_PEAK`] (a record of zeros passes: its deviations are exactly 0).
///
/// # Errors
/// The first value too large, or the peak too small.
pub fn check_magnitudes(record: &[f64]) -> Result<(), MagnitudeError> {
    let limit = max_magnitude(record.len());
    if let Some((index, value)) = record.iter().enumerate().find(|(_, v)| v.abs() > limit) {
        return Err(MagnitudeError::TooLarge {
            index,
            value: *value,
            limit,
            samples: record.len(),
        });
    }
    let peak = record.iter().fold(0.0f64, |peak, v| peak.max(v.abs()));
    if peak > 0.0 && peak < MIN_PEAK {
        return Err(MagnitudeError::TooSmall { peak });
    }
    Ok(())
}

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
