//! The least-squares gain matrix of the bias estimator (f64, nalgebra).
//!
//! Over one window of `W` intervals the interval means obey
//!
//! ```text
//! mA(i) = V(tA_i) + pA(i)·bA        mB(i) = V(tB_i) + pB(i)·bB        V(t) = c0 + c1 t + … + c_r t^r
//! ```
//!
//! with `t` in intervals, centred over the window: `tA_i = i − (W−1)/2 − S/(2L)` and
//! `tB_i = tA_i + S/L` (B runs `S` samples behind A). Stacking `m = [mA(0), mB(0), mA(1), …]`
//! and `u = [c0 … c_r, bA, bB]` gives `m = H u`; the estimator is `u = G m`,
//! `G = (HᵀH)⁻¹ Hᵀ`. Only the rows of `bA` and `bB` are needed in hardware.
//!
//! Examples: `W = 2, r = 0`, alternating: `bA = (mA0 − mA1)/2`, `bB = (mB1 − mB0)/2` (paper
//! 004 eqs 49–50). `W = 4, r = 1`, ABBA: every entry is ±1/4 and a linear rate cancels
//! exactly. `W = 2, r = 1` is rank-deficient (`bA − bB` and `c1` are indistinguishable).

use nalgebra::DMatrix;

use crate::sequencer::Schedule;

/// Errors of the estimator design.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum DesignError {
    /// `H` does not have full column rank.
    #[error("the bias estimator is rank-deficient for intervals = {intervals}, rate_order = {rate_order}, pattern {pattern}: H ({rows} x {columns}) has rank {rank} < {columns}, so the biases cannot be separated from the rate model; use more intervals or a lower rate_order")]
    RankDeficient {
        /// `W`.
        intervals: usize,
        /// `r`.
        rate_order: usize,
        /// Pattern name.
        pattern: &'static str,
        /// Rows of H.
        rows: usize,
        /// Columns of H.
        columns: usize,
        /// Numerical rank.
        rank: usize,
    },
}

/// Interval times (in intervals, centred) of A and B.
pub fn interval_times(schedule: &Schedule) -> (Vec<f64>, Vec<f64>) {
    let w = schedule.intervals as f64;
    let offset = schedule.stagger as f64 / schedule.interval_length as f64;
    let a: Vec<f64> = (0..schedule.intervals)
        .map(|i| i as f64 - (w - 1.0) / 2.0 - offset / 2.0)
        .collect();
    let b = a.iter().map(|t| t + offset).collect();
    (a, b)
}

/// The observation matrix `H` (2W × (r + 3)).
pub fn observation_matrix(schedule: &Schedule, rate_order: usize) -> DMatrix<f64> {
    let w = schedule.intervals;
    let modes = schedule.pattern.modes(w);
    let (ta, tb) = interval_times(schedule);
    let columns = rate_order + 3;
    let mut h = DMatrix::zeros(2 * w, columns);
    for i in 0..w {
        let mut power_a = 1.0;
        let mut power_b = 1.0;
        for q in 0..=rate_order {
            h[(2 * i, q)] = power_a;
            h[(2 * i + 1, q)] = power_b;
            power_a *= ta[i];
            power_b *= tb[i];
        }
        h[(2 * i, rate_order + 1)] = f64::from(modes[i]);
        h[(2 * i + 1, rate_order + 2)] = -f64::from(modes[i]);
    }
    h
}

/// The rows of `G = (HᵀH)⁻¹Hᵀ` that give `bA` and `bB`, each over the 2W stacked means.
///
/// # Errors
/// [`DesignError::RankDeficient`] when `H` has a singular value below `1e-9` of its largest.
pub fn bias_rows(schedule: &Schedule, rate_order: usize) -> Result<[Vec<f64>; 2], DesignError> {
    let h = observation_matrix(schedule, rate_order);
    let (rows, columns) = h.shape();
    let singular = h.clone().svd(false, false).singular_values;
    let largest = singular.max();
    let rank = singular.iter().filter(|s| **s > 1e-9 * largest).count();
    if rank < columns || rows < columns {
        return Err(DesignError::RankDeficient {
            intervals: schedule.intervals,
            rate_order,
            pattern: schedule.pattern.name(),
            rows,
            columns,
            rank,
        });
    }
    let normal = (h.transpose() * &h)
        .try_inverse()
        .expect("full column rank makes HᵀH invertible");
    let g = normal * h.transpose();
    let row = |r: usize| (0..rows).map(|j| g[(r, j)]).collect();
    Ok([row(rate_order + 1), row(rate_order + 2)])
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sequencer::Pattern;

    fn schedule(w: usize, pattern: Pattern, stagger: usize) -> Schedule {
        Schedule {
            interval_length: 100,
            intervals: w,
            pattern,
            blank: 10,
            stagger,
        }
    }

    fn close(a: &[f64], b: &[f64]) -> bool {
        a.iter().zip(b).all(|(x, y)| (x - y).abs() < 1e-12)
    }

    #[test]
    fn paper_case_is_plus_minus_one_half() {
        let [a, b] = bias_rows(&schedule(2, Pattern::Alternating, 0), 0).unwrap();
        // m = [mA0, mB0, mA1, mB1]
        assert!(close(&a, &[0.5, 0.0, -0.5, 0.0]), "{a:?}");
        assert!(close(&b, &[0.0, -0.5, 0.0, 0.5]), "{b:?}");
    }

    #[test]
    fn abba_with_a_linear_rate_is_all_quarters_and_cancels_a_ramp() {
        let s = schedule(4, Pattern::Abba, 0);
        let [a, b] = bias_rows(&s, 1).unwrap();
        for g in a.iter().chain(&b) {
            assert!((g.abs() - 0.25).abs() < 1e-12 || g.abs() < 1e-12, "{g}");
        }
        // Means of a linear rate plus the biases: recovered exactly.
        let (ta, tb) = interval_times(&s);
        let modes = s.pattern.modes(4);
        let (ba, bb) = (0.7, -0.3);
        let m: Vec<f64> = (0..4)
            .flat_map(|i| {
                [
                    2.0 + 0.5 * ta[i] + f64::from(modes[i]) * ba,
                    2.0 + 0.5 * tb[i] - f64::from(modes[i]) * bb,
                ]
            })
            .collect();
        let dot = |g: &[f64]| g.iter().zip(&m).map(|(x, y)| x * y).sum::<f64>();
        assert!((dot(&a) - ba).abs() < 1e-12 && (dot(&b) - bb).abs() < 1e-12);
    }

    #[test]
    fn two_intervals_with_a_linear_rate_are_rank_deficient() {
        let err = bias_rows(&schedule(2, Pattern::Alternating, 0), 1).unwrap_err();
        assert!(
            matches!(
                err,
                DesignError::RankDeficient {
                    rank: 3,
                    columns: 4,
                    ..
                }
            ),
            "{err}"
        );
        assert!(err.to_string().contains("intervals = 2, rate_order = 1"));
    }

    #[test]
    fn estimates_are_unbiased_for_any_window_model_and_stagger() {
        for (w, pattern, r, stagger) in [
            (4, Pattern::Alternating, 0, 0),
            (4, Pattern::Alternating, 1, 30),
            (8, Pattern::Abba, 2, 55),
            (6, Pattern::Alternating, 2, 0),
        ] {
            let s = schedule(w, pattern, stagger);
            let [a, b] = bias_rows(&s, r).unwrap();
            let h = observation_matrix(&s, r);
            // G H = I on the bias rows: the estimate of u from H u is u.
            for (row, unknown) in [(&a, r + 1), (&b, r + 2)] {
                for col in 0..r + 3 {
                    let v: f64 = (0..2 * w).map(|j| row[j] * h[(j, col)]).sum();
                    let want = if col == unknown { 1.0 } else { 0.0 };
                    assert!((v - want).abs() < 1e-9, "W {w} r {r}: {v} vs {want}");
                }
            }
        }
    }
}
