//! How strongly the Allan-variance estimates of one curve move together, from the fitted noise
//! model, so that the terms' intervals count each octave's information once.
//!
//! The estimates at neighbouring τ are differences of the same phase record: at τ and 2τ they
//! share most of their data, and for white FM they correlate by about 0.5. A least-squares fit
//! that weighs them as independent claims more information than the curve holds: on white-noise
//! records its ±1σ interval of N covered the true N in 43 % of records. The fit's covariance is
//! therefore the sandwich `(AᵀWA)⁻¹ AᵀWΣWA (AᵀWA)⁻¹`, with `Σ` the estimates' covariance: each
//! point's own variance `2σ⁴/edf` (as in the weights) and their correlation from the model here.
//!
//! Each estimate is the mean square of a phase difference `d_i = Σ_p α_p x[i + p m]` (taps
//! `(1, −2, 1)` for the Allan variances, `(1, −3, 3, −1)` for the Hadamard). For a Gaussian
//! phase with generalized covariance `G` (its differences' covariances: `E[d_i d'_j] =
//! Σ_p Σ_q α_p β_q G(j − i + q m' − p m)`), the covariance of two mean squares over `n` and
//! `n'` terms is `2 Σ_ℓ count(ℓ) γ(ℓ)² / (n n')`, `γ(ℓ) = E[d_i d'_{i+ℓ}]`. Each term of the
//! model has its own `G`, in samples `h` and phase in ° (τ0 the sample period):
//!
//! - quantization (white PM): `Q² [h = 0]`;
//! - ARW (white FM): `−½ N² τ0 |h|`;
//! - bias instability (flicker FM): `B² τ0² h² ln|h| / (2π)` (the continuous-time form);
//! - RRW (random-walk FM): `K² τ0³ |h|³ / 12`;
//! - a rate ramp is deterministic and adds nothing.
//!
//! Each `G` gives back its term's row of [`basis`](super::basis) for the Allan variance (a test
//! holds them together). The modified and non-overlapping deviations take the overlapping one's
//! correlations at the same τ (their own taps span `3m` points or stride by `m`; the correlation
//! between octaves, which is what matters here, is alike).

use nalgebra::DMatrix;

use super::super::allan::{Kind, Point};

/// Lags at which a pair's `γ²` is summed, at most (a stride over longer spans: `γ` is smooth
/// between a few breakpoints, so the sum is a quadrature of it).
const LAG_SAMPLES: usize = 512;

/// How far past the taps' span flicker noise's `γ` (which falls as `ℓ⁻²`) is summed, in spans.
const FLICKER_TAIL_SPANS: usize = 8;

/// The phase difference of `kind` at factor `m`: tap weights at offsets `p · m`.
fn taps(kind: Kind) -> &'static [f64] {
    match kind {
        Kind::Hadamard => &[1.0, -3.0, 3.0, -1.0],
        _ => &[1.0, -2.0, 1.0],
    }
}

/// The model's squared coefficients `c = [Q², N², B², K², R²]` and sample period.
struct Model {
    c: [f64; 5],
    tau0: f64,
}

impl Model {
    /// The generalized covariance of the phase (°²) at a lag of `h` samples, without the
    /// quantization spike at 0 (summed exactly apart).
    fn smooth(&self, h: f64) -> f64 {
        let h = h.abs();
        let [_, n2, b2, k2, _] = self.c;
        let t = self.tau0;
        let flicker = if h > 0.0 {
            b2 * t * t * h * h * h.ln() / (2.0 * std::f64::consts::PI)
        } else {
            0.0
        };
        -0.5 * n2 * t * h + flicker + k2 * t * t * t * h * h * h / 12.0
    }

    /// `γ(ℓ)` of the differences at factors `ma` (taps `a`) and `mb` (taps `b`), smooth part.
    fn cross_smooth(&self, taps: &[f64], ma: f64, mb: f64, lag: f64) -> f64 {
        let mut sum = 0.0;
        for (p, alpha) in taps.iter().enumerate() {
            for (q, beta) in taps.iter().enumerate() {
                sum += alpha * beta * self.smooth(lag + q as f64 * mb - p as f64 * ma);
            }
        }
        sum
    }

    /// The quantization part of `γ(ℓ)`: `Q²` times the taps meeting at lag `ℓ`.
    fn cross_spike(&self, taps: &[f64], ma: usize, mb: usize, lag: i64) -> f64 {
        let mut sum = 0.0;
        for (p, alpha) in taps.iter().enumerate() {
            for (q, beta) in taps.iter().enumerate() {
                if lag + (q * mb) as i64 - (p * ma) as i64 == 0 {
                    sum += alpha * beta;
                }
            }
        }
        sum * self.c[0]
    }

    /// `Σ_ℓ count(ℓ) γ(ℓ)²` for a pair of points with `na`, `nb` terms.
    fn covariance_sum(
        &self,
        taps: &[f64],
        (ma, na): (usize, usize),
        (mb, nb): (usize, usize),
    ) -> f64 {
        let count = |lag: i64| -> f64 {
            // Pairs (i, i + ℓ) with 0 ≤ i < na and 0 ≤ i + ℓ < nb.
            let start = 0i64.max(-lag);
            let end = (na as i64).min(nb as i64 - lag);
            (end - start).max(0) as f64
        };
        let span = (taps.len() - 1) * (ma + mb);
        let reach = if self.c[2] > 0.0 {
            span * (1 + FLICKER_TAIL_SPANS)
        } else {
            span
        };
        let reach = reach.min(na.max(nb)) as i64;
        let stride = ((2 * reach + 1) as usize).div_ceil(LAG_SAMPLES).max(1) as i64;
        let (fa, fb) = (ma as f64, mb as f64);
        let mut sum = 0.0;
        let mut lag = -reach;
        while lag <= reach {
            let g = self.cross_smooth(taps, fa, fb, lag as f64);
            sum += stride as f64 * count(lag) * g * g;
            lag += stride;
        }
        if self.c[0] > 0.0 {
            // The quantization spikes sit at the taps' own offsets: summed exactly, with their
            // cross term against the smooth part.
            let mut lags: Vec<i64> = Vec::new();
            for p in 0..taps.len() {
                for q in 0..taps.len() {
                    lags.push((p * ma) as i64 - (q * mb) as i64);
                }
            }
            lags.sort_unstable();
            lags.dedup();
            for lag in lags {
                let spike = self.cross_spike(taps, ma, mb, lag);
                let smooth = self.cross_smooth(taps, fa, fb, lag as f64);
                sum += count(lag) * (spike * spike + 2.0 * spike * smooth);
            }
        }
        sum
    }
}

/// The number of phase-difference positions a point's estimate averages over (a
/// non-overlapping point's `terms` stride by `m`).
fn positions(kind: Kind, point: &Point) -> usize {
    match kind {
        Kind::NonOverlapping => point.terms * point.m,
        _ => point.terms,
    }
    .max(1)
}

/// The correlation matrix of the variance estimates of `curve` (of `kind`) under the model
/// `c = [Q², N², B², K², R²]` (°/s and s units): 1 on the diagonal; the identity where the
/// model has no noise.
pub fn estimate_correlation(curve: &[Point], kind: Kind, c: [f64; 5]) -> DMatrix<f64> {
    let size = curve.len();
    let mut correlation = DMatrix::<f64>::identity(size, size);
    let Some(first) = curve.first() else {
        return correlation;
    };
    let model = Model {
        c,
        tau0: first.tau_s / first.m as f64,
    };
    let taps = taps(kind);
    let at = |p: &Point| (p.m, positions(kind, p));
    let own: Vec<f64> = curve
        .iter()
        .map(|p| model.covariance_sum(taps, at(p), at(p)))
        .collect();
    for a in 0..size {
        for b in a + 1..size {
            let denominator = (own[a] * own[b]).sqrt();
            if denominator > 0.0 {
                let cross = model.covariance_sum(taps, at(&curve[a]), at(&curve[b]));
                let rho = (cross / denominator).clamp(-1.0, 1.0);
                correlation[(a, b)] = rho;
                correlation[(b, a)] = rho;
            }
        }
    }
    correlation
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::analysis::noise::basis;

    fn point(m: usize, terms: usize) -> Point {
        Point {
            tau_s: m as f64 * 0.01,
            m,
            dev: 1.0,
            lo: 0.9,
            hi: 1.1,
            edf: 100.0,
            alpha: 0,
            terms,
        }
    }

    /// Each term's generalized covariance gives back its Allan and Hadamard variance:
    /// `E[d²] / (2τ²)` (`6τ²` for Hadamard) is its row of the basis.
    #[test]
    fn each_terms_covariance_gives_its_variance() {
        let tau0 = 0.01;
        for (kind, norm) in [(Kind::Overlapping, 2.0), (Kind::Hadamard, 6.0)] {
            for m in [4usize, 64, 1000] {
                let tau = m as f64 * tau0;
                let want = basis(kind, tau, m);
                for j in 0..4 {
                    let mut c = [0.0; 5];
                    c[j] = 1.0;
                    let model = Model { c, tau0 };
                    let taps = taps(kind);
                    let smooth = model.cross_smooth(taps, m as f64, m as f64, 0.0);
                    let spike = model.cross_spike(taps, m, m, 0);
                    let variance = (smooth + spike) / (norm * tau * tau);
                    // Flicker: the basis's 0.6643 is √(2 ln 2 / π) to four digits.
                    let tolerance = if j == 2 { 1e-4 } else { 1e-9 };
                    assert!(
                        (variance / want[j] - 1.0).abs() < tolerance,
                        "{kind:?} m {m} term {j}: {variance} against {}",
                        want[j]
                    );
                }
            }
        }
    }

    /// White FM: the mean squares at m and 2m correlate by a fixed amount for long records
    /// (about 0.5), and by nothing at factors far apart.
    #[test]
    fn neighbouring_octaves_correlate_and_distant_ones_do_not() {
        let curve: Vec<Point> = [1usize, 2, 4, 8, 1024]
            .iter()
            .map(|&m| point(m, 1_000_000 - 2 * m))
            .collect();
        let rho = estimate_correlation(&curve, Kind::Overlapping, [0.0, 1.0, 0.0, 0.0, 0.0]);
        assert!((rho[(0, 0)] - 1.0).abs() < 1e-12);
        for a in 0..3 {
            let r = rho[(a, a + 1)];
            assert!((0.3..0.7).contains(&r), "{a}: {r}");
        }
        assert!(rho[(0, 4)].abs() < 0.05, "{}", rho[(0, 4)]);
        assert!(rho[(1, 2)] > rho[(1, 3)]);
    }

    /// Independent estimates (no noise in the model) leave the weights' covariance as it was.
    #[test]
    fn a_noiseless_model_is_the_identity() {
        let curve = vec![point(1, 100), point(2, 98)];
        let rho = estimate_correlation(&curve, Kind::Overlapping, [0.0; 5]);
        assert_eq!(rho, DMatrix::identity(2, 2));
    }
}
