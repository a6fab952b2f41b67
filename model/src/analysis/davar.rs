//! Dynamic Allan variance (DAVAR, paper 002): the overlapping Allan deviation of a window that
//! slides along the record, with a fixed window length or one adapted by a PID controller.
//!
//! # Exact recursive windows
//!
//! With the phase `X` of the whole record, the second differences
//! `d_i(m) = X[i+2m] − 2X[i+m] + X[i]` do not depend on the window, so the Allan sum of a
//! window `[a, b)` of samples is `S = Σ_{i=a}^{b−2m} d_i(m)²` — a sliding sum. Each term is
//! rounded once to a fixed point (an `i128` with `2^-F` per unit, F per τ so the largest term
//! has 100 significant bits), and the window sums are updated by adding the terms that enter
//! and subtracting those that leave, in exact integer arithmetic: the recursive result equals
//! a fresh sum over the window bit for bit (a test checks it), and agrees with the f64
//! brute-force deviation to ~1e-15.
//!
//! # Adaptive window
//!
//! The window is centred on each output time; its length follows an incremental PID on a
//! deviation index `e_k` (paper 002): `du = Kp (e_k − e_{k−1}) + Ki e_k + Kd (e_k − 2e_{k−1} +
//! e_{k−2})`, `L_k = clamp(L_{k−1} + du, Lmin, Lmax)`. The paper's index σ/mean is undefined
//! for a gyro at rest (zero mean); gyrofx uses the kurtosis κ of the window's samples, which is
//! scale-free, finite, and 3 for Gaussian noise with a standard error of `√(24/L)`:
//! `e_k = 1 − |κ_k − 3| / (4 √(24/L))`, clipped to `[−4, 1]`. Quiet data (κ within four standard
//! errors of 3) gives `e > 0` and lets the window grow back to `Lmax`; a burst, step or any
//! heavy-tailed disturbance gives `e < 0` and shortens it. The gains are in samples per unit of
//! `e`.

use serde::Serialize;

use super::allan::{self, factors, phase, Grid, Kind};
use super::noise;

/// How the window moves.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Window {
    /// A fixed length, samples.
    Fixed(usize),
    /// Adapted by the PID controller.
    Adaptive(Pid),
}

/// The adaptive window's controller.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Pid {
    /// Shortest window, samples.
    pub min: usize,
    /// Longest window, samples (also the initial length).
    pub max: usize,
    /// Proportional gain, samples per unit of the deviation index.
    pub kp: f64,
    /// Integral gain.
    pub ki: f64,
    /// Derivative gain.
    pub kd: f64,
}

/// A DAVAR: one Allan curve per output time.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Davar {
    /// Centre of each window, s.
    pub time_s: Vec<f64>,
    /// Window length at each time, samples.
    pub window: Vec<usize>,
    /// Averaging times, s.
    pub tau_s: Vec<f64>,
    /// `adev[t][j]`: the deviation at time `t` and `tau_s[j]` (`None` where the window is too
    /// short for that τ).
    pub adev: Vec<Vec<Option<f64>>>,
}

/// Noise coefficients over time (IEEE-952 units), fitted to each window's curve.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Coefficients {
    /// Angle random walk, °/√h.
    pub arw_deg_per_sqrt_h: Vec<f64>,
    /// Bias instability, °/h.
    pub bias_instability_deg_per_h: Vec<f64>,
    /// Rate random walk, °/h/√h.
    pub rrw_deg_per_h_per_sqrt_h: Vec<f64>,
}

/// One sliding sum of fixed-point `d_i(m)²` terms.
struct SlidingSum {
    m: usize,
    scale: f64,
    /// Terms in the window: `[start, end)` of i.
    start: usize,
    end: usize,
    sum: i128,
}

impl SlidingSum {
    fn term(&self, x: &[f64], i: usize) -> i128 {
        let m = self.m;
        let d = x[i + 2 * m] - 2.0 * x[i + m] + x[i];
        (d * d * self.scale).round() as i128
    }

    /// Moves the window of terms to `[start, end)`, adding and removing at the ends.
    fn move_to(&mut self, x: &[f64], start: usize, end: usize) {
        if start >= self.end || end <= self.start {
            self.start = start;
            self.end = start;
            self.sum = 0;
        }
        while self.start < start {
            self.sum -= self.term(x, self.start);
            self.start += 1;
        }
        while self.start > start {
            self.start -= 1;
            self.sum += self.term(x, self.start);
        }
        while self.end < end {
            self.sum += self.term(x, self.end);
            self.end += 1;
        }
        while self.end > end {
            self.end -= 1;
            self.sum -= self.term(x, self.end);
        }
    }
}

/// Fixed-point scale for the terms of factor `m`: the largest `d²` gets 100 bits, leaving 27
/// bits of headroom for sums of up to 2^27 terms.
fn scale_for(x: &[f64], m: usize) -> f64 {
    let mut largest = 0.0f64;
    for i in 0..x.len() - 2 * m {
        let d = x[i + 2 * m] - 2.0 * x[i + m] + x[i];
        largest = largest.max(d * d);
    }
    if largest == 0.0 {
        return 1.0;
    }
    let (_, exponent) = libm::frexp(largest);
    crate::fx::pow2(100 - exponent)
}

/// The deviation of the window of `samples` samples from its exact term sum.
fn deviation_of(sum: i128, scale: f64, m: usize, samples: usize) -> Option<f64> {
    let points = samples + 1;
    if points < 2 * m + 2 {
        return None;
    }
    let terms = points - 2 * m;
    Some((sum as f64 / scale / (2.0 * (m * m) as f64 * terms as f64)).sqrt())
}

/// Excess-free kurtosis `E[(y − ȳ)⁴] / σ⁴` of a window (3 for Gaussian noise; 0 variance → 3).
pub fn kurtosis(window: &[f64]) -> f64 {
    let n = window.len() as f64;
    let mean = window.iter().sum::<f64>() / n;
    let (mut m2, mut m4) = (0.0, 0.0);
    for v in window {
        let d = (v - mean) * (v - mean);
        m2 += d;
        m4 += d * d;
    }
    if m2 == 0.0 {
        return 3.0;
    }
    (m4 / n) / ((m2 / n) * (m2 / n))
}

/// DAVAR of a rate record at `rate_hz`: windows centred every `step` samples (from the first
/// centre a full window fits), octave τ up to what the longest window allows.
///
/// # Panics
/// When a window is shorter than 4 samples or longer than the record, or `step` is 0.
pub fn davar(rate: &[f64], rate_hz: f64, window: Window, step: usize) -> Davar {
    davar_reporting(rate, rate_hz, window, step, &mut |_, _| {})
}

/// [`davar`], telling `progress(done, total)` in samples of the record as the windows slide
/// (every 256 windows); the same result.
///
/// # Panics
/// As [`davar`].
pub fn davar_reporting(
    rate: &[f64],
    rate_hz: f64,
    window: Window,
    step: usize,
    progress: &mut dyn FnMut(usize, usize),
) -> Davar {
    assert!(step > 0, "step must be at least 1");
    let longest = match window {
        Window::Fixed(l) => l,
        Window::Adaptive(p) => p.max,
    };
    let shortest = match window {
        Window::Fixed(l) => l,
        Window::Adaptive(p) => p.min,
    };
    assert!(
        shortest >= 4 && longest <= rate.len(),
        "windows of 4..=N samples"
    );
    let x = phase(rate);
    let ms = factors(Kind::Overlapping, Grid::Octave, longest + 1);
    let mut sums: Vec<SlidingSum> = ms
        .iter()
        .map(|&m| SlidingSum {
            m,
            scale: scale_for(&x, m),
            start: 0,
            end: 0,
            sum: 0,
        })
        .collect();
    let half = longest / 2;
    let mut length = longest;
    let mut errors = [0.0f64; 3];
    let (mut time_s, mut windows, mut adev) = (Vec::new(), Vec::new(), Vec::new());
    let mut centre = half;
    while centre + (longest - half) <= rate.len() {
        let a = centre - length / 2;
        let b = a + length;
        let row = sums
            .iter_mut()
            .map(|s| {
                let m = s.m;
                if length + 1 < 2 * m + 2 {
                    return None;
                }
                // Terms i = a ..= b − 2m.
                s.move_to(&x, a, b + 1 - 2 * m);
                deviation_of(s.sum, s.scale, m, length)
            })
            .collect();
        time_s.push(centre as f64 / rate_hz);
        windows.push(length);
        adev.push(row);
        if time_s.len() % 256 == 0 {
            progress(centre, rate.len());
        }
        if let Window::Adaptive(pid) = window {
            let standard_error = (24.0 / length as f64).sqrt();
            let e = (1.0 - (kurtosis(&rate[a..b]) - 3.0).abs() / (4.0 * standard_error))
                .clamp(-4.0, 1.0);
            let du =
                pid.kp * (e - errors[0]) + pid.ki * e + pid.kd * (e - 2.0 * errors[0] + errors[1]);
            errors = [e, errors[0], errors[1]];
            let next = (length as f64 + du)
                .round()
                .clamp(pid.min as f64, pid.max as f64) as usize;
            length = next;
        }
        centre += step;
    }
    Davar {
        time_s,
        window: windows,
        tau_s: ms.iter().map(|m| *m as f64 / rate_hz).collect(),
        adev,
    }
}

/// The noise coefficients of each window's curve (white-FM EDF weights: the per-window noise
/// type is not identified).
pub fn coefficients(d: &Davar) -> Coefficients {
    let mut c = Coefficients {
        arw_deg_per_sqrt_h: Vec::new(),
        bias_instability_deg_per_h: Vec::new(),
        rrw_deg_per_h_per_sqrt_h: Vec::new(),
    };
    for (row, length) in d.adev.iter().zip(&d.window) {
        let points: Vec<super::allan::Point> = row
            .iter()
            .zip(&d.tau_s)
            .filter_map(|(dev, tau)| {
                let dev = (*dev)?;
                let m = (tau / d.tau_s[0]).round() as usize;
                let edf = super::allan::edf_overlapping(length + 1, m, 0);
                Some(super::allan::Point {
                    tau_s: *tau,
                    m,
                    dev,
                    lo: dev,
                    hi: dev,
                    edf,
                    alpha: 0,
                    terms: length + 1 - 2 * m,
                })
            })
            .filter(|p| p.dev > 0.0)
            .collect();
        if points.is_empty() {
            c.arw_deg_per_sqrt_h.push(0.0);
            c.bias_instability_deg_per_h.push(0.0);
            c.rrw_deg_per_h_per_sqrt_h.push(0.0);
            continue;
        }
        let terms = noise::fit(&points, allan::Kind::Overlapping);
        // A degenerate window (e.g. all points equal) can make the fit non-finite: NaN,
        // written as null.
        let finite = |v: f64| if v.is_finite() { v } else { f64::NAN };
        c.arw_deg_per_sqrt_h.push(finite(terms.n.value * 60.0));
        c.bias_instability_deg_per_h
            .push(finite(terms.b.value * 3600.0));
        c.rrw_deg_per_h_per_sqrt_h
            .push(finite(terms.k.value * 216_000.0));
    }
    c
}

/// Disturbances: runs of windows whose shortest-τ deviation exceeds `factor` × the median over
/// all windows, runs less than two output steps apart merged; each as (start, end) in s
/// (window centres).
pub fn disturbances(d: &Davar, factor: f64) -> Vec<(f64, f64)> {
    let first: Vec<f64> = d
        .adev
        .iter()
        .filter_map(|row| row.first().copied().flatten())
        .collect();
    if first.is_empty() {
        return Vec::new();
    }
    let mut sorted = first.clone();
    sorted.sort_by(f64::total_cmp);
    let median = sorted[sorted.len() / 2];
    let mut runs = Vec::new();
    let mut open: Option<f64> = None;
    for (t, row) in d.time_s.iter().zip(&d.adev) {
        let high = row
            .first()
            .copied()
            .flatten()
            .is_some_and(|v| v > factor * median);
        match (high, open) {
            (true, None) => open = Some(*t),
            (false, Some(start)) => {
                runs.push((start, *t));
                open = None;
            }
            _ => {}
        }
    }
    if let (Some(start), Some(end)) = (open, d.time_s.last()) {
        runs.push((start, *end));
    }
    let step = if d.time_s.len() > 1 {
        d.time_s[1] - d.time_s[0]
    } else {
        0.0
    };
    let mut merged: Vec<(f64, f64)> = Vec::new();
    for run in runs {
        match merged.last_mut() {
            Some(last) if run.0 - last.1 <= 2.0 * step => last.1 = run.1,
            _ => merged.push(run),
        }
    }
    merged
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::analysis::allan::deviation;
    use crate::stimulus::{Gaussian, Stream};

    fn white(n: usize, seed: u64) -> Vec<f64> {
        let mut g = Gaussian::new(seed, Stream::AngleRandomWalk(0));
        (0..n).map(|_| 0.3 + g.sample()).collect()
    }

    #[test]
    fn recursive_windows_equal_fresh_sums_exactly_and_the_brute_force_closely() {
        let y = white(5000, 1);
        let x = phase(&y);
        let d = davar(&y, 10.0, Window::Fixed(301), 7);
        for (t, row) in d.adev.iter().enumerate() {
            let a = (d.time_s[t] * 10.0).round() as usize - 301 / 2;
            for (j, tau) in d.tau_s.iter().enumerate() {
                let m = (tau * 10.0).round() as usize;
                let got = row[j].unwrap();
                // A fresh integer sum over the same terms: identical bits.
                let fresh = SlidingSum {
                    m,
                    scale: scale_for(&x, m),
                    start: a,
                    end: a,
                    sum: 0,
                };
                let mut fresh = fresh;
                fresh.move_to(&x, a, a + 302 - 2 * m);
                assert_eq!(
                    got,
                    deviation_of(fresh.sum, fresh.scale, m, 301).unwrap(),
                    "t {t} m {m}"
                );
                // The f64 brute force on the window alone.
                let brute = deviation(Kind::Overlapping, &phase(&y[a..a + 301]), m, 10.0)
                    .unwrap()
                    .0;
                assert!(
                    (got / brute - 1.0).abs() < 1e-12,
                    "t {t} m {m}: {got} vs {brute}"
                );
            }
        }
    }

    #[test]
    fn a_burst_is_found_and_the_adaptive_window_shortens_over_it() {
        let mut y = white(20_000, 2);
        for v in &mut y[9000..10_000] {
            *v *= 8.0;
        }
        let fixed = davar(&y, 100.0, Window::Fixed(1001), 50);
        let runs = disturbances(&fixed, 2.0);
        assert_eq!(runs.len(), 1, "{runs:?}");
        let (start, end) = runs[0];
        // Centred windows see the burst up to half a window (5 s) early and late.
        assert!(
            (84.0..=91.0).contains(&start) && (100.0..=106.0).contains(&end),
            "{runs:?}"
        );

        let pid = Pid {
            min: 201,
            max: 1001,
            kp: 40.0,
            ki: 20.0,
            kd: 0.0,
        };
        let adaptive = davar(&y, 100.0, Window::Adaptive(pid), 50);
        let near = |t: f64| {
            adaptive
                .time_s
                .iter()
                .position(|s| (s - t).abs() < 0.3)
                .map(|i| adaptive.window[i])
                .unwrap()
        };
        assert_eq!(near(30.0), 1001, "quiet: the longest window");
        assert!(
            near(92.0) < 600,
            "at the burst's edge the window shortens: {}",
            near(92.0)
        );
        let runs = disturbances(&adaptive, 2.0);
        assert_eq!(runs.len(), 1, "{runs:?}");
        assert!(
            runs[0].0 >= start,
            "the adaptive window sees the start later (closer): {runs:?}"
        );
    }

    #[test]
    fn coefficients_over_time_track_the_noise_level() {
        let mut y = white(30_000, 3); // 1 °/s per sample at 100 Hz: N = 0.1 °/√s = 6 °/√h
        for v in &mut y[15_000..] {
            *v *= 3.0;
        }
        let d = davar(&y, 100.0, Window::Fixed(3001), 1000);
        let c = coefficients(&d);
        let first = c.arw_deg_per_sqrt_h[1];
        let last = *c.arw_deg_per_sqrt_h.last().unwrap();
        assert!((first / 6.0 - 1.0).abs() < 0.15, "{first}");
        assert!((last / 18.0 - 1.0).abs() < 0.15, "{last}");
    }

    #[test]
    fn kurtosis_of_gaussian_noise_is_three() {
        let y = white(200_000, 4);
        assert!((kurtosis(&y) - 3.0).abs() < 0.05);
        assert_eq!(kurtosis(&[1.0; 10]), 3.0);
    }

    #[test]
    fn the_reported_davar_is_the_davar_and_reports_progress() {
        let y = white(40_000, 5);
        let mut last = (0, 0);
        let reported = davar_reporting(&y, 100.0, Window::Fixed(1001), 10, &mut |done, total| {
            assert!(done >= last.0 && done <= total);
            last = (done, total);
        });
        let plain = davar(&y, 100.0, Window::Fixed(1001), 10);
        assert_eq!(reported.adev, plain.adev);
        assert_eq!(reported.time_s, plain.time_s);
        assert_eq!(last.1, y.len());
        assert!(last.0 > y.len() / 2, "{last:?}");
    }
}
