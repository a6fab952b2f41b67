//! Equivalent degrees of freedom of every Allan-family variance for power-law noise, by the
//! method of Greenhall & Riley ("Uncertainty of stability variances based on finite
//! differences", PTTI 2003), which allantools' `edf_greenhall` also follows.
//!
//! An estimate `σ̂² = (1/M) Σ_i z_i²` averages `M` squared outputs of a filter on the phase:
//! the `d`-th difference (`d` = 2 for the Allan variances, 3 for the Hadamard) of phase
//! averages over `τ/F` (`F = m`: point samples, the unmodified variances; `F = 1`: averages
//! over `τ`, the modified one), taken every `m/S` samples (`S = m`: overlapping; `S = 1`:
//! non-overlapping). For Gaussian `z` with autocovariance `R`,
//!
//! `1/edf = Var(σ̂²) / (2 E[σ̂²]²) = [R(0)² + 2 Σ_{j=1}^{J−1} (1 − j/M) R(j)² + (1 − J/M) R(J)²] / (M R(0)²)`
//!
//! with `J = min(M, (d+1)S)` lags, beyond which `R` vanishes (or nearly: flicker noise).
//! `R(j) ∝ sz(j/S)`, from the generalized autocovariance of power-law phase noise of exponent
//! `α` (lags `t` in units of `τ`):
//!
//! - `sw(t)`: `−|t|` (α = 2), `t² ln|t|` (1), `|t|³` (0), `−t⁴ ln|t|` (−1), `−|t|⁵` (−2)
//! - `sx(t) = F² [2 sw(t) − sw(t − 1/F) − sw(t + 1/F)]`, or `sw(t)` of `α + 2` as `F → ∞`:
//!   the unmodified variances take the limit for FM noise (α ≤ 0), exact for the point-sampled
//!   phase of white FM (the running sum of a white rate record), and `F = m` for PM noise
//! - `sz(t) = Σ_k (−1)^k C(2d, d+k) sx(t + k)`, `k = −d … d`
//!
//! Where `J` is large the sum is an integral over the (piecewise smooth) `sz²`, taken piece by
//! piece between integer lags by Gauss–Legendre; Greenhall's published tables approximate the
//! same limit.

/// Lags summed term by term; more become an integral.
const EXACT_LAGS: usize = 512;

/// Which variance: the difference order and the estimator's averaging and overlap.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Estimator {
    /// Difference order: 2 for the Allan variances, 3 for the Hadamard variance.
    pub d: u32,
    /// Phase averages over τ (the modified variance) rather than point samples.
    pub modified: bool,
    /// A term at every sample rather than every `m`-th.
    pub overlapping: bool,
}

fn xlogx2(t: f64) -> f64 {
    // t² ln|t| → 0 at 0
    if t == 0.0 {
        0.0
    } else {
        t * t * libm::log(t.abs())
    }
}

/// `sw(t)` for noise exponent `alpha` (2 … −2, and −3, −4 for the Hadamard variance).
fn sw(t: f64, alpha: i32) -> f64 {
    let a = t.abs();
    match alpha {
        2 => -a,
        1 => xlogx2(t),
        0 => a * a * a,
        -1 => -t * t * xlogx2(t),
        -2 => -a.powi(5),
        -3 => t.powi(4) * xlogx2(t),
        _ => a.powi(7),
    }
}

/// `sx(t)`; `f = None` is the `F → ∞` limit.
fn sx(t: f64, f: Option<f64>, alpha: i32) -> f64 {
    match f {
        Some(f) => f * f * (2.0 * sw(t, alpha) - sw(t - 1.0 / f, alpha) - sw(t + 1.0 / f, alpha)),
        None => sw(t, alpha + 2),
    }
}

fn binomial(n: u32, k: u32) -> f64 {
    (0..k).fold(1.0, |acc, i| acc * f64::from(n - i) / f64::from(i + 1))
}

/// `sz(t)`.
fn sz(t: f64, f: Option<f64>, alpha: i32, d: u32) -> f64 {
    let d_i = d as i32;
    (-d_i..=d_i)
        .map(|k| {
            let sign = if k % 2 == 0 { 1.0 } else { -1.0 };
            sign * binomial(2 * d, (d_i + k) as u32) * sx(t + f64::from(k), f, alpha)
        })
        .sum()
}

/// 8-point Gauss–Legendre nodes and weights on [−1, 1].
const GAUSS: [(f64, f64); 8] = [
    (-0.960_289_856_497_536_3, 0.101_228_536_290_376_26),
    (-0.796_666_477_413_626_7, 0.222_381_034_453_374_47),
    (-0.525_532_409_916_329, 0.313_706_645_877_887_3),
    (-0.183_434_642_495_649_8, 0.362_683_783_378_362),
    (0.183_434_642_495_649_8, 0.362_683_783_378_362),
    (0.525_532_409_916_329, 0.313_706_645_877_887_3),
    (0.796_666_477_413_626_7, 0.222_381_034_453_374_47),
    (0.960_289_856_497_536_3, 0.101_228_536_290_376_26),
];

/// The equivalent degrees of freedom of `estimator` at averaging factor `m` on `phase_points`
/// phase points, for power-law noise of exponent `alpha` (2 white PM … −2 random-walk FM);
/// `None` where the estimator has no term.
pub fn edf(estimator: Estimator, alpha: i32, m: usize, phase_points: usize) -> Option<f64> {
    let Estimator {
        d,
        modified,
        overlapping,
    } = estimator;
    if m == 0 {
        return None;
    }
    let mf = m as f64;
    // F (None: ∞) and the phase points one term spans.
    let (f, span) = if modified {
        (Some(1.0), m + m * d as usize)
    } else if alpha >= 1 {
        (Some(mf), 1 + m * d as usize)
    } else {
        (None, 1 + m * d as usize)
    };
    if phase_points < span {
        return None;
    }
    let s = if overlapping { m } else { 1 };
    let terms = 1 + s * (phase_points - span) / m;
    let lags = terms.min((d as usize + 1) * s);
    let sf = s as f64;
    let mt = terms as f64;
    let r0 = sz(0.0, f, alpha, d);
    let weight = |j: f64| 1.0 - j / mt;
    let sum = if !modified && alpha == 2 {
        // White PM: R is non-zero only at whole multiples of τ (j a multiple of S).
        let mut sum = r0 * r0;
        let mut j = s;
        while j <= lags {
            let r = sz(j as f64 / sf, f, alpha, d);
            let w = if j == lags { 1.0 } else { 2.0 };
            sum += w * weight(j as f64) * r * r;
            j += s;
        }
        sum
    } else if lags <= EXACT_LAGS || f.is_some_and(|f| f > 1.0) {
        let mut sum = r0 * r0;
        for j in 1..lags {
            let r = sz(j as f64 / sf, f, alpha, d);
            sum += 2.0 * weight(j as f64) * r * r;
        }
        let r = sz(lags as f64 / sf, f, alpha, d);
        sum + weight(lags as f64) * r * r
    } else {
        // 2 S ∫_0^{J/S} (1 − tS/M) sz(t)² dt, piece by piece between integer t.
        let end = lags as f64 / sf;
        let mut integral = 0.0;
        let mut a = 0.0;
        while a < end {
            let b = (a + 1.0).min(end);
            let (mid, half) = ((a + b) / 2.0, (b - a) / 2.0);
            for (x, w) in GAUSS {
                let t = mid + half * x;
                let r = sz(t, f, alpha, d);
                integral += w * half * weight(t * sf) * r * r;
            }
            a = b;
        }
        2.0 * sf * integral
    };
    if !(r0 != 0.0 && sum.is_finite() && sum > 0.0) {
        return None;
    }
    Some((r0 * r0 * mt / sum).max(1.0))
}

#[cfg(test)]
mod tests {
    use super::*;

    const OVERLAPPING: Estimator = Estimator {
        d: 2,
        modified: false,
        overlapping: true,
    };
    const NON_OVERLAPPING: Estimator = Estimator {
        d: 2,
        modified: false,
        overlapping: false,
    };

    /// White FM, non-overlapping: adjacent first differences of the τ-averages correlate by
    /// −½ and no others, so 1/edf = (1 + 2·¼·(1 − 1/M))/M (terms M).
    #[test]
    fn non_overlapping_white_fm_is_two_thirds_of_the_terms() {
        let (n, m) = (10_001, 10);
        let terms = 1 + (n - 1 - 2 * m) / m;
        let mt = terms as f64;
        let want = mt / (1.0 + 0.5 * (1.0 - 1.0 / mt));
        let got = edf(NON_OVERLAPPING, 0, m, n).unwrap();
        assert!((got / want - 1.0).abs() < 1e-3, "{got} vs {want}");
    }

    /// White PM at m = 1 (every variance is the same there): z = x[i+2] − 2x[i+1] + x[i] of
    /// white x: R(0) = 6, R(1) = −4, R(2) = 1.
    #[test]
    fn white_pm_at_one_sample_from_the_filter_taps() {
        let n = 1001;
        let terms = (n - 2) as f64;
        let sum = 36.0 + 2.0 * (1.0 - 1.0 / terms) * 16.0 + 2.0 * (1.0 - 2.0 / terms) * 1.0;
        let want = 36.0 * terms / sum;
        let got = edf(OVERLAPPING, 2, 1, n).unwrap();
        assert!((got / want - 1.0).abs() < 1e-9, "{got} vs {want}");
    }

    /// The overlapping ADEV against SP 1065 Table 5's approximations (Howe, Allan & Barnes),
    /// which Greenhall's values approach within about 10 % where the table holds.
    #[test]
    fn overlapping_agrees_with_the_sp1065_approximations() {
        let n = 100_001;
        for alpha in [2, 0, -1, -2] {
            for m in [4, 16, 64, 256, 1024, 4096] {
                let table = super::super::allan::edf_overlapping(n, m, alpha);
                let got = edf(OVERLAPPING, alpha, m, n).unwrap();
                assert!(
                    (got / table - 1.0).abs() < 0.15,
                    "alpha {alpha} m {m}: Greenhall {got}, SP 1065 {table}"
                );
            }
        }
    }

    /// The integral taken for many lags continues the exact sum without a step.
    #[test]
    fn the_integral_continues_the_exact_sum() {
        let modified = Estimator {
            d: 2,
            modified: true,
            overlapping: true,
        };
        let n = 1_000_001;
        for alpha in [0, -1, -2] {
            // m = 170 sums 510 lags exactly, m = 171 integrates over 513.
            let below = edf(modified, alpha, 170, n).unwrap() * 170.0;
            let above = edf(modified, alpha, 171, n).unwrap() * 171.0;
            assert!(
                (above / below - 1.0).abs() < 0.01,
                "alpha {alpha}: {below} {above}"
            );
        }
    }

    /// Fewer terms give fewer degrees of freedom, and no term gives none.
    #[test]
    fn edf_shrinks_with_the_record_and_ends_with_it() {
        let hadamard = Estimator {
            d: 3,
            modified: false,
            overlapping: true,
        };
        let long = edf(hadamard, -1, 8, 100_000).unwrap();
        let short = edf(hadamard, -1, 8, 10_000).unwrap();
        assert!(long > 5.0 * short, "{long} {short}");
        assert_eq!(edf(hadamard, -1, 8, 3 * 8), None);
        assert!(edf(hadamard, -1, 8, 3 * 8 + 1).is_some());
    }
}
