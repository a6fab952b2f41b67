//! Noise-term identification from an Allan curve (IEEE Std 952 / paper 002):
//!
//! `σ²(τ) = 3Q²/τ² + N²/τ + (0.6643 B)² + K²τ/3 + R²τ²/2`
//!
//! (Q quantization, N angle random walk, B bias instability, K rate random walk, R rate ramp;
//! σ in °/s, τ in s). The variance is linear in `c = [Q², N², B², K², R²]`, so the fit is a
//! weighted linear least squares with `c ≥ 0`, weighted by the inverse variance of each AVAR
//! estimate, `edf / (2σ⁴)` (χ² with `edf` degrees of freedom). With five unknowns the exact
//! non-negative solution is found by solving the unconstrained problem on each of the 31
//! non-empty sets of active terms and keeping the feasible one with the least weighted
//! residual. Each coefficient's interval is ±1 standard error from the covariance
//! `(AᵀWA)⁻¹` of the chosen set, mapped through the square root (and clipped at 0).
//!
//! A term is only identifiable where it dominates the curve over a few octaves: with RRW
//! below the flicker floor until the last octaves (few terms, small EDF), K and R trade off
//! there (a record with B = 10 °/h and K = 30 °/h/√h gave K 39 % low and a spurious R).
//!
//! Classic slope readings are given beside it: N at τ = 1 s on a −½ line, K at τ = 3 s on a
//! +½ line (each line through the curve's points whose local log-log slope is within 0.15 of
//! the line's), B = min σ / 0.6643.

use nalgebra::{DMatrix, DVector};
use serde::Serialize;

use super::allan::Point;

/// The flicker floor factor: `σ_floor = 0.6643 B` (√(2 ln 2 / π)).
pub const FLICKER_FLOOR: f64 = 0.664_3;

/// One identified coefficient, in the unit its name says.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Estimate {
    /// Best estimate.
    pub value: f64,
    /// Lower end of the ±1 standard-error interval.
    pub lo: f64,
    /// Upper end.
    pub hi: f64,
}

impl Estimate {
    fn scaled(self, factor: f64) -> Estimate {
        Estimate {
            value: self.value * factor,
            lo: self.lo * factor,
            hi: self.hi * factor,
        }
    }
}

/// The five terms in the analysis units (°/s and s): Q in °, N in °/√s, B in °/s, K in °/s/√s,
/// R in °/s².
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Terms {
    /// Quantization noise, °.
    pub q: Estimate,
    /// Angle random walk, °/√s.
    pub n: Estimate,
    /// Bias instability, °/s.
    pub b: Estimate,
    /// Rate random walk, °/s/√s.
    pub k: Estimate,
    /// Rate ramp, °/s².
    pub r: Estimate,
}

/// The terms in IEEE-952 units (Q µrad, N °/√h, B °/h, K °/h/√h, R °/h²) and Kalibr units.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Report {
    /// Quantization noise, µrad.
    pub quantization_urad: Estimate,
    /// Angle random walk, °/√h.
    pub arw_deg_per_sqrt_h: Estimate,
    /// Bias instability, °/h.
    pub bias_instability_deg_per_h: Estimate,
    /// Rate random walk, °/h/√h.
    pub rrw_deg_per_h_per_sqrt_h: Estimate,
    /// Rate ramp, °/h².
    pub rate_ramp_deg_per_h2: Estimate,
    /// Kalibr's gyroscope noise density, rad/s/√Hz (= N in rad/√s).
    pub kalibr_noise_density_rad_per_s_per_sqrt_hz: f64,
    /// Kalibr's gyroscope random walk, rad/s²/√Hz (= K in rad/s/√s).
    pub kalibr_random_walk_rad_per_s2_per_sqrt_hz: f64,
    /// Slope readings: N (°/√h) from the −½ line at τ = 1 s, if the curve has one.
    pub slope_arw_deg_per_sqrt_h: Option<f64>,
    /// Slope readings: K (°/h/√h) from the +½ line at τ = 3 s, if the curve has one.
    pub slope_rrw_deg_per_h_per_sqrt_h: Option<f64>,
    /// Slope readings: B (°/h) = min σ / 0.6643.
    pub slope_bias_instability_deg_per_h: f64,
}

/// The basis functions of `σ²(τ)` for `[Q², N², B², K², R²]`.
fn basis(tau: f64) -> [f64; 5] {
    [
        3.0 / (tau * tau),
        1.0 / tau,
        FLICKER_FLOOR * FLICKER_FLOOR,
        tau / 3.0,
        tau * tau / 2.0,
    ]
}

/// A feasible solution on one set of active terms.
struct Candidate {
    /// Weighted residual.
    cost: f64,
    /// Indices of the active terms.
    active: Vec<usize>,
    /// Their squared coefficients.
    c: DVector<f64>,
    /// Their covariance.
    covariance: DMatrix<f64>,
}

/// Fits the five terms to an Allan curve (overlapping ADEV with EDFs).
///
/// # Panics
/// On an empty curve.
pub fn fit(curve: &[Point]) -> Terms {
    assert!(!curve.is_empty(), "an Allan curve to fit");
    let zero = Estimate {
        value: 0.0,
        lo: 0.0,
        hi: 0.0,
    };
    if curve.iter().all(|p| p.dev == 0.0) {
        // A constant record: no noise, and weights 1/σ⁴ that would divide by zero.
        return Terms {
            q: zero,
            n: zero,
            b: zero,
            k: zero,
            r: zero,
        };
    }
    let rows = curve.len();
    let weights: Vec<f64> = curve
        .iter()
        .map(|p| p.edf / (2.0 * p.dev.powi(4)).max(f64::MIN_POSITIVE))
        .collect();
    let mut best: Option<Candidate> = None;
    for mask in 1u32..32 {
        let active: Vec<usize> = (0..5).filter(|j| mask & (1 << j) != 0).collect();
        if active.len() > rows {
            continue;
        }
        let a = DMatrix::from_fn(rows, active.len(), |i, j| basis(curve[i].tau_s)[active[j]]);
        let w = DMatrix::from_diagonal(&DVector::from_vec(weights.clone()));
        let y = DVector::from_iterator(rows, curve.iter().map(|p| p.dev * p.dev));
        let normal = a.transpose() * &w * &a;
        let Some(covariance) = normal.clone().try_inverse() else {
            continue;
        };
        let c = &covariance * a.transpose() * &w * &y;
        if c.iter().any(|v| *v < 0.0) {
            continue;
        }
        let residual = &y - &a * &c;
        let cost = (residual.transpose() * &w * &residual)[(0, 0)];
        if best.as_ref().is_none_or(|b| cost < b.cost) {
            best = Some(Candidate {
                cost,
                active,
                c,
                covariance,
            });
        }
    }
    let mut terms = [zero; 5];
    if let Some(Candidate {
        active,
        c,
        covariance,
        ..
    }) = best
    {
        for (k, j) in active.iter().enumerate() {
            let sigma = covariance[(k, k)].max(0.0).sqrt();
            terms[*j] = Estimate {
                value: c[k].sqrt(),
                lo: (c[k] - sigma).max(0.0).sqrt(),
                hi: (c[k] + sigma).sqrt(),
            };
        }
    }
    Terms {
        q: terms[0],
        n: terms[1],
        b: terms[2],
        k: terms[3],
        r: terms[4],
    }
}

/// Reads a line of log-log `slope` through the points whose local slope is within 0.15 of it
/// and evaluates it at `at_tau`.
fn slope_reading(curve: &[Point], slope: f64, at_tau: f64) -> Option<f64> {
    let mut intercepts = Vec::new();
    for w in curve.windows(3) {
        let local = (w[2].dev.ln() - w[0].dev.ln()) / (w[2].tau_s.ln() - w[0].tau_s.ln());
        if (local - slope).abs() < 0.15 {
            intercepts.push(w[1].dev.ln() - slope * w[1].tau_s.ln());
        }
    }
    if intercepts.is_empty() {
        return None;
    }
    let mean = intercepts.iter().sum::<f64>() / intercepts.len() as f64;
    Some((mean + slope * at_tau.ln()).exp())
}

/// The fit and the slope readings in IEEE-952 and Kalibr units.
pub fn report(curve: &[Point], terms: &Terms) -> Report {
    let radians = std::f64::consts::PI / 180.0;
    let min = curve.iter().map(|p| p.dev).fold(f64::INFINITY, f64::min);
    Report {
        quantization_urad: terms.q.scaled(radians * 1e6),
        arw_deg_per_sqrt_h: terms.n.scaled(60.0),
        bias_instability_deg_per_h: terms.b.scaled(3600.0),
        rrw_deg_per_h_per_sqrt_h: terms.k.scaled(216_000.0),
        rate_ramp_deg_per_h2: terms.r.scaled(3600.0 * 3600.0),
        kalibr_noise_density_rad_per_s_per_sqrt_hz: terms.n.value * radians,
        kalibr_random_walk_rad_per_s2_per_sqrt_hz: terms.k.value * radians,
        slope_arw_deg_per_sqrt_h: slope_reading(curve, -0.5, 1.0).map(|n| n * 60.0),
        slope_rrw_deg_per_h_per_sqrt_h: slope_reading(curve, 0.5, 3.0).map(|k| k * 216_000.0),
        slope_bias_instability_deg_per_h: min / FLICKER_FLOOR * 3600.0,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::analysis::allan::{curve, Grid, Kind};
    use crate::plant::{GyroErrors, Plant};

    /// A record with known N, B, K from the plant (one gyro, normal mode only).
    fn record(arw: f64, bi: f64, rrw: f64, samples: usize, seed: u64) -> Vec<f64> {
        let gyro = GyroErrors {
            sf_ppm: 0.0,
            sf_mode_mismatch_ppm: 0.0,
            bias_dps: 0.0,
            bias_mode_mismatch_dps: 0.0,
            arw_deg_per_sqrt_h: arw,
            bias_instability_deg_per_h: bi,
            rrw_deg_per_h_per_sqrt_h: rrw,
            rate_ramp_deg_per_h2: 0.0,
            settle_tau_s: 0.0,
        };
        let plant = Plant {
            fs_hz: 100.0,
            gyros: [gyro, gyro],
            bi_tau_min_s: 0.5,
            bi_tau_max_s: 2000.0,
        };
        let n = samples;
        let [a, _] = plant.simulate(&vec![0.0; n], &vec![[1, 1]; n], seed).y;
        a
    }

    #[test]
    fn recovers_n_within_3_percent_and_b_k_within_25_percent() {
        // 2^20 samples at 100 Hz (2.9 h): ARW 0.5 °/√h, B 10 °/h, RRW 100 °/h/√h, so that
        // each term dominates the curve over a few octaves (RRW from τ ≈ 50 s on).
        for seed in [7, 8, 9] {
            let y = record(0.5, 10.0, 100.0, 1 << 20, seed);
            let c = curve(Kind::Overlapping, &y, 100.0, Grid::Octave);
            let terms = fit(&c);
            let r = report(&c, &terms);
            let n = r.arw_deg_per_sqrt_h.value;
            let b = r.bias_instability_deg_per_h.value;
            let k = r.rrw_deg_per_h_per_sqrt_h.value;
            assert!((n / 0.5 - 1.0).abs() < 0.03, "seed {seed}: N = {n}: {r:?}");
            assert!((b / 10.0 - 1.0).abs() < 0.25, "seed {seed}: B = {b}: {r:?}");
            assert!(
                (k / 100.0 - 1.0).abs() < 0.25,
                "seed {seed}: K = {k}: {r:?}"
            );
            assert!(r.arw_deg_per_sqrt_h.lo <= n && n <= r.arw_deg_per_sqrt_h.hi);
            if let Some(slope_n) = r.slope_arw_deg_per_sqrt_h {
                assert!((slope_n / 0.5 - 1.0).abs() < 0.1, "seed {seed}: {slope_n}");
            }
        }
    }

    #[test]
    fn a_term_that_is_absent_comes_out_zero_or_small() {
        // White noise only: N alone, no K, no R.
        let y = record(1.0, 0.0, 0.0, 1 << 18, 3);
        let c = curve(Kind::Overlapping, &y, 100.0, Grid::Octave);
        let r = report(&c, &fit(&c));
        assert!((r.arw_deg_per_sqrt_h.value - 1.0).abs() < 0.03, "{r:?}");
        assert!(r.rrw_deg_per_h_per_sqrt_h.value < 2.0, "{r:?}");
        assert!(r.rate_ramp_deg_per_h2.value < 10.0, "{r:?}");
    }
}
