//! The overlapping Allan deviation at fixed averaging factors, one rate sample at a time, in
//! memory that does not grow with the record: for reports on runs of any length.
//!
//! The phase is the running sum of `y[k] − y[0]` (the first sample stands in for the mean,
//! which a stream does not know yet) with Neumaier's compensated summation, so each phase point
//! is within about one ulp of its exact value however long the run; a ring holds the last
//! `2·max(m) + 1` points. The sums are those of [`super::deviation`]'s overlapping kind, which
//! the tests match to 1e-9 relative.

use super::{max_factor, Kind};

/// Overlapping ADEV at fixed factors, fed sample by sample ([`OverlappingStream::push`]).
#[derive(Clone, Debug)]
pub struct OverlappingStream {
    factors: Vec<usize>,
    rate_hz: f64,
    reference: f64,
    phase: f64,
    compensation: f64,
    ring: Vec<f64>,
    points: usize,
    sums: Vec<f64>,
}

impl OverlappingStream {
    /// Accumulators for the averaging `factors` (each ≥ 1) of a record at `rate_hz`.
    ///
    /// # Panics
    /// On a factor of 0.
    pub fn new(factors: &[usize], rate_hz: f64) -> Self {
        assert!(
            factors.iter().all(|m| *m >= 1),
            "averaging factors are >= 1"
        );
        let longest = factors.iter().copied().max().unwrap_or(1);
        OverlappingStream {
            factors: factors.to_vec(),
            rate_hz,
            reference: 0.0,
            phase: 0.0,
            compensation: 0.0,
            ring: vec![0.0; 2 * longest + 1],
            points: 0,
            sums: vec![0.0; factors.len()],
        }
    }

    /// Rate samples pushed.
    pub fn samples(&self) -> usize {
        self.points.saturating_sub(1)
    }

    /// Adds the next rate sample.
    pub fn push(&mut self, y: f64) {
        if self.points == 0 {
            self.reference = y;
            self.store(0.0);
        }
        // Neumaier: the low-order bits lost by each addition, added back when read.
        let step = y - self.reference;
        let sum = self.phase + step;
        self.compensation += if self.phase.abs() >= step.abs() {
            (self.phase - sum) + step
        } else {
            (step - sum) + self.phase
        };
        self.phase = sum;
        self.store(sum + self.compensation);
    }

    fn store(&mut self, x: f64) {
        let len = self.ring.len();
        let n = self.points;
        self.ring[n % len] = x;
        self.points += 1;
        for (m, s) in self.factors.iter().zip(&mut self.sums) {
            if n >= 2 * m {
                let d = x - 2.0 * self.ring[(n - m) % len] + self.ring[(n - 2 * m) % len];
                *s += d * d;
            }
        }
    }

    /// Per factor, the deviation (rate units) and its number of terms, as
    /// [`super::deviation`] gives them: `None` where the record is too short.
    pub fn deviations(&self) -> Vec<Option<(f64, usize)>> {
        let max = max_factor(Kind::Overlapping, self.points);
        self.factors
            .iter()
            .zip(&self.sums)
            .map(|(m, s)| {
                if *m > max {
                    return None;
                }
                let terms = self.points - 2 * m;
                let tau0 = 1.0 / self.rate_hz;
                let tau = *m as f64 * tau0;
                let variance = s * tau0 * tau0 / (2.0 * terms as f64 * tau * tau);
                Some((variance.sqrt(), terms))
            })
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::stimulus::{Gaussian, Stream};

    /// Against the batch deviation (mean removed, plain sums) on biased, drifting, noisy
    /// records: 1e-9 relative at every factor, the same term counts, `None` where it is.
    #[test]
    fn matches_the_batch_deviation() {
        for (seed, n, bias, drift) in [
            (1, 1000, 0.0, 0.0),
            (2, 50_000, 20.0, 1e-4),
            (3, 7, 1.0, 0.0),
        ] {
            let mut g = Gaussian::new(seed, Stream::AngleRandomWalk(0));
            let y: Vec<f64> = (0..n)
                .map(|k| bias + drift * k as f64 + 0.1 * g.sample())
                .collect();
            let factors = [1, 2, 3, 10, 100, 1000, 10_000, 30_000];
            let mut stream = OverlappingStream::new(&factors, 200.0);
            for v in &y {
                stream.push(*v);
            }
            assert_eq!(stream.samples(), n);
            let x = crate::analysis::allan::phase(&y);
            for (m, got) in factors.iter().zip(stream.deviations()) {
                let want = crate::analysis::allan::deviation(Kind::Overlapping, &x, *m, 200.0);
                match (got, want) {
                    (Some((a, ta)), Some((b, tb))) => {
                        assert_eq!(ta, tb);
                        assert!((a / b - 1.0).abs() < 1e-9, "n {n} m {m}: {a} vs {b}");
                    }
                    (None, None) => {}
                    other => panic!("n {n} m {m}: {other:?}"),
                }
            }
        }
    }
}
