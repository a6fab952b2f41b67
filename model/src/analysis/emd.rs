//! Empirical mode decomposition (EMD) and the improved complete ensemble EMD with adaptive
//! noise (ICEEMDAN) of Colominas, Schlotthauer and Torres (2014), as paper 004 uses it.
//!
//! # EMD
//!
//! The first mode `E1(s)` of a signal is found by sifting: the upper and lower envelopes are
//! natural cubic splines through the local maxima and minima (each extended past the ends by the
//! mirror images of its two outermost extrema), their mean is subtracted, and this is
//! repeated a fixed [`SIFTS`] = 10 times (the fixed count Wu & Huang recommend for ensemble
//! methods: it keeps EMD a dyadic filter bank on noise, and makes the result a pure function of
//! the input). A signal with fewer than three extrema has no mode left: `E1(s) = 0`. Mode `k`
//! is `E1` of what is left after the first `k − 1`: `Ek(s) = E1(s − E1(s) − … )`.
//!
//! # ICEEMDAN (Colominas et al. 2014, not PyEMD's CEEMDAN, which adds noise differently)
//!
//! With `M(s) = s − E1(s)` (the local mean), `I` white Gaussian realizations `w⁽ⁱ⁾` (seeded, one
//! ChaCha stream each) and their EMD modes scaled by `1/std(E1(w⁽ⁱ⁾))`:
//!
//! ```text
//! r1 = ⟨M(x + β0·E1(w⁽ⁱ⁾))⟩,        d1 = x − r1,        β0 = ε0·std(x)
//! rk = ⟨M(r(k−1) + β(k−1)·Ek(w⁽ⁱ⁾))⟩,  dk = r(k−1) − rk,   β(k−1) = ε0·std(r(k−1))
//! ```
//!
//! (`⟨·⟩` the mean over the realizations), until the residue has fewer than three extrema or
//! `max_modes` are taken. Reconstruction is exact by construction: `x = Σ dk + r_last` (a
//! test checks it to 1e-9).

use crate::stimulus::{Gaussian, Stream};

/// Sifting iterations per mode.
pub const SIFTS: usize = 10;

/// Indices of the local maxima and minima of `s` (interior samples; a plateau counts once, at
/// its first sample).
fn extrema(s: &[f64]) -> (Vec<usize>, Vec<usize>) {
    let (mut maxima, mut minima) = (Vec::new(), Vec::new());
    for i in 1..s.len().saturating_sub(1) {
        if s[i] > s[i - 1] && s[i] >= s[i + 1] {
            maxima.push(i);
        } else if s[i] < s[i - 1] && s[i] <= s[i + 1] {
            minima.push(i);
        }
    }
    (maxima, minima)
}

/// The natural cubic spline through `(knots[j], values[j])` (knots increasing, covering
/// `0..len`), evaluated at `0..len`.
fn spline(knots: &[f64], values: &[f64], len: usize) -> Vec<f64> {
    let n = knots.len();
    if n == 1 {
        return vec![values[0]; len];
    }
    let h: Vec<f64> = knots.windows(2).map(|w| w[1] - w[0]).collect();
    // Second derivatives m: m0 = m(n−1) = 0; tridiagonal system for the interior (Thomas).
    let mut m = vec![0.0; n];
    if n > 2 {
        let size = n - 2;
        let (mut diag, mut rhs) = (vec![0.0; size], vec![0.0; size]);
        for i in 0..size {
            diag[i] = 2.0 * (h[i] + h[i + 1]);
            rhs[i] = 6.0
                * ((values[i + 2] - values[i + 1]) / h[i + 1] - (values[i + 1] - values[i]) / h[i]);
        }
        for i in 1..size {
            let factor = h[i] / diag[i - 1];
            diag[i] -= factor * h[i];
            rhs[i] -= factor * rhs[i - 1];
        }
        m[size] = rhs[size - 1] / diag[size - 1];
        for i in (0..size - 1).rev() {
            m[i + 1] = (rhs[i] - h[i + 1] * m[i + 2]) / diag[i];
        }
    }
    let mut out = Vec::with_capacity(len);
    let mut segment = 0;
    for t in 0..len {
        while segment + 2 < n && t as f64 > knots[segment + 1] {
            segment += 1;
        }
        let (x0, x1) = (knots[segment], knots[segment + 1]);
        let hs = x1 - x0;
        let (a, b) = ((x1 - t as f64) / hs, (t as f64 - x0) / hs);
        out.push(
            a * values[segment]
                + b * values[segment + 1]
                + ((a * a * a - a) * m[segment] + (b * b * b - b) * m[segment + 1]) * hs * hs / 6.0,
        );
    }
    out
}

/// The envelope through the extrema `at` of `s` (not empty), extended past each end by the
/// mirror images of its two outermost extrema (Rilling et al.'s end rule, simplified): the
/// spline then runs through the ends instead of being pinned to the end samples.
fn envelope(s: &[f64], at: &[usize]) -> Vec<f64> {
    let last = (s.len() - 1) as f64;
    let outer = at.len().min(2);
    let mut knots = Vec::with_capacity(at.len() + 4);
    let mut values = Vec::with_capacity(at.len() + 4);
    for &i in at[..outer].iter().rev() {
        knots.push(-(i as f64));
        values.push(s[i]);
    }
    // An extremum at index 0 would mirror onto itself.
    if knots.last() == Some(&0.0) || knots.last() == Some(&-0.0) {
        knots.pop();
        values.pop();
    }
    for &i in at {
        knots.push(i as f64);
        values.push(s[i]);
    }
    for &i in at[at.len() - outer..].iter().rev() {
        let mirrored = 2.0 * last - i as f64;
        if mirrored > *knots.last().expect("knots") {
            knots.push(mirrored);
            values.push(s[i]);
        }
    }
    if knots.len() == 1 || knots[0] > 0.0 || *knots.last().expect("knots") < last {
        // Too few extrema to span the record: hold the end values flat.
        if knots[0] > 0.0 {
            knots.insert(0, 0.0);
            values.insert(0, values[0]);
        }
        if *knots.last().expect("knots") < last {
            knots.push(last);
            values.push(*values.last().expect("values"));
        }
    }
    spline(&knots, &values, s.len())
}

/// Whether `s` has a mode to extract (at least three extrema).
fn oscillates(s: &[f64]) -> bool {
    let (maxima, minima) = extrema(s);
    maxima.len() + minima.len() >= 3
}

/// `E1(s)`: the first EMD mode of `s` ([`SIFTS`] sifting iterations), or zeros when `s` has
/// fewer than three extrema.
pub fn first_mode(s: &[f64]) -> Vec<f64> {
    if s.len() < 3 || !oscillates(s) {
        return vec![0.0; s.len()];
    }
    let mut h = s.to_vec();
    for _ in 0..SIFTS {
        let (maxima, minima) = extrema(&h);
        if maxima.is_empty() || minima.is_empty() {
            break;
        }
        let upper = envelope(&h, &maxima);
        let lower = envelope(&h, &minima);
        for (value, (u, l)) in h.iter_mut().zip(upper.iter().zip(&lower)) {
            *value -= 0.5 * (u + l);
        }
    }
    h
}

/// The first `count` EMD modes of `s` (fewer when what is left stops oscillating).
pub fn modes(s: &[f64], count: usize) -> Vec<Vec<f64>> {
    let mut rest = s.to_vec();
    let mut out = Vec::new();
    while out.len() < count && oscillates(&rest) {
        let mode = first_mode(&rest);
        for (r, m) in rest.iter_mut().zip(&mode) {
            *r -= m;
        }
        out.push(mode);
    }
    out
}

/// Population standard deviation of `s`.
pub(crate) fn std_dev(s: &[f64]) -> f64 {
    let n = s.len() as f64;
    let mean = s.iter().sum::<f64>() / n;
    (s.iter().map(|v| (v - mean) * (v - mean)).sum::<f64>() / n).sqrt()
}

/// ICEEMDAN settings.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Ensemble {
    /// Noise realizations `I`.
    pub realizations: usize,
    /// Noise amplitude `ε0` (relative to the standard deviation of what is decomposed).
    pub noise_amplitude: f64,
    /// Most modes (`0`: up to `log2 N`).
    pub max_modes: usize,
    /// Seed of the noise.
    pub seed: u64,
}

impl Default for Ensemble {
    /// Colominas et al.'s usual settings: 100 realizations, ε0 = 0.2.
    fn default() -> Self {
        Ensemble {
            realizations: 100,
            noise_amplitude: 0.2,
            max_modes: 0,
            seed: 1,
        }
    }
}

/// A decomposition: the modes (IMFs, highest frequency first) and the residue.
#[derive(Clone, Debug, PartialEq)]
pub struct Decomposition {
    /// `d1, d2, …`.
    pub modes: Vec<Vec<f64>>,
    /// What is left: the trend.
    pub residue: Vec<f64>,
}

impl Decomposition {
    /// `Σ dk + residue`.
    pub fn reconstruct(&self) -> Vec<f64> {
        let mut out = self.residue.clone();
        for mode in &self.modes {
            for (o, d) in out.iter_mut().zip(mode) {
                *o += d;
            }
        }
        out
    }
}

/// ICEEMDAN of `x` (see the module docs).
///
/// # Panics
/// When `x` has fewer than 4 samples or `ensemble.realizations` is 0.
pub fn iceemdan(x: &[f64], ensemble: &Ensemble) -> Decomposition {
    assert!(x.len() >= 4, "at least 4 samples to decompose");
    assert!(ensemble.realizations > 0, "at least one noise realization");
    let n = x.len();
    let max_modes = if ensemble.max_modes == 0 {
        (usize::BITS - n.leading_zeros()) as usize
    } else {
        ensemble.max_modes
    };
    // Each realization's EMD modes, scaled by 1/std of its first mode.
    let noise_modes: Vec<Vec<Vec<f64>>> = (0..ensemble.realizations)
        .map(|i| {
            let mut source = Gaussian::new(ensemble.seed, Stream::DecompositionNoise(i as u32));
            let w = source.samples(n, 1.0);
            let mut m = modes(&w, max_modes);
            let scale = m.first().map_or(1.0, |first| std_dev(first));
            if scale > 0.0 {
                for mode in &mut m {
                    mode.iter_mut().for_each(|v| *v /= scale);
                }
            }
            m
        })
        .collect();
    let local_mean = |s: &[f64]| -> Vec<f64> {
        let mode = first_mode(s);
        s.iter().zip(&mode).map(|(a, b)| a - b).collect()
    };
    let mut out = Vec::new();
    let mut previous = x.to_vec();
    for k in 0..max_modes {
        if !oscillates(&previous) {
            break;
        }
        let beta = ensemble.noise_amplitude * std_dev(&previous);
        let mut mean = vec![0.0; n];
        for realization in &noise_modes {
            let noisy: Vec<f64> = match realization.get(k) {
                Some(noise) => previous
                    .iter()
                    .zip(noise)
                    .map(|(r, w)| r + beta * w)
                    .collect(),
                None => previous.clone(),
            };
            for (m, v) in mean.iter_mut().zip(local_mean(&noisy)) {
                *m += v;
            }
        }
        let count = ensemble.realizations as f64;
        mean.iter_mut().for_each(|m| *m /= count);
        let mode: Vec<f64> = previous.iter().zip(&mean).map(|(p, m)| p - m).collect();
        out.push(mode);
        previous = mean;
    }
    Decomposition {
        modes: out,
        residue: previous,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sine(n: usize, period: f64, amplitude: f64) -> Vec<f64> {
        (0..n)
            .map(|k| amplitude * libm::sin(2.0 * std::f64::consts::PI * k as f64 / period))
            .collect()
    }

    fn correlation(a: &[f64], b: &[f64]) -> f64 {
        let dot: f64 = a.iter().zip(b).map(|(x, y)| x * y).sum();
        let na: f64 = a.iter().map(|x| x * x).sum::<f64>().sqrt();
        let nb: f64 = b.iter().map(|x| x * x).sum::<f64>().sqrt();
        dot / (na * nb)
    }

    #[test]
    fn the_spline_interpolates_its_knots_and_a_line_exactly() {
        let knots = [0.0, 3.0, 7.0, 12.0, 20.0];
        let values = [1.0, -2.0, 0.5, 4.0, -1.0];
        let s = spline(&knots, &values, 21);
        for (k, v) in knots.iter().zip(values) {
            assert!((s[*k as usize] - v).abs() < 1e-12, "{k}");
        }
        let line: Vec<f64> = knots.iter().map(|k| 2.0 * k - 3.0).collect();
        let s = spline(&knots, &line, 21);
        for (t, v) in s.iter().enumerate() {
            assert!((v - (2.0 * t as f64 - 3.0)).abs() < 1e-9, "{t}");
        }
    }

    #[test]
    fn emd_separates_two_well_separated_sines() {
        let n = 2048;
        let fast = sine(n, 16.0, 1.0);
        let slow = sine(n, 256.0, 2.0);
        let x: Vec<f64> = fast.iter().zip(&slow).map(|(a, b)| a + b).collect();
        let m = modes(&x, 2);
        // Away from the ends, where the end rule bends the envelopes.
        let inner = 128..n - 128;
        let c0 = correlation(&m[0][inner.clone()], &fast[inner.clone()]);
        let c1 = correlation(&m[1][inner.clone()], &slow[inner]);
        assert!(c0 > 0.99 && c1 > 0.99, "{c0} {c1}");
    }

    #[test]
    fn iceemdan_reconstructs_exactly_and_separates_the_sines() {
        let n = 1024;
        let fast = sine(n, 16.0, 1.0);
        let slow = sine(n, 256.0, 2.0);
        let x: Vec<f64> = fast.iter().zip(&slow).map(|(a, b)| a + b + 0.5).collect();
        let ensemble = Ensemble {
            realizations: 20,
            ..Ensemble::default()
        };
        let d = iceemdan(&x, &ensemble);
        let back = d.reconstruct();
        for (a, b) in back.iter().zip(&x) {
            assert!((a - b).abs() < 1e-9);
        }
        // The fast sine is one of the first modes (the noise may take the very first).
        let inner = 64..n - 64;
        let best = d
            .modes
            .iter()
            .map(|m| correlation(&m[inner.clone()], &fast[inner.clone()]))
            .fold(0.0, f64::max);
        assert!(best > 0.95, "{best}");
        // Determinism: the same seed, the same bits.
        assert_eq!(iceemdan(&x, &ensemble), d);
        let other = iceemdan(
            &x,
            &Ensemble {
                seed: 2,
                ..ensemble
            },
        );
        assert_ne!(other.modes[0], d.modes[0]);
    }

    #[test]
    fn white_noise_modes_halve_in_frequency() {
        // EMD on white noise is a dyadic filter bank: each mode has about half the extrema of
        // the previous one.
        let mut g = Gaussian::new(3, Stream::DecompositionNoise(999));
        let w = g.samples(4096, 1.0);
        let m = modes(&w, 5);
        let counts: Vec<usize> = m
            .iter()
            .map(|mode| {
                let (a, b) = extrema(mode);
                a.len() + b.len()
            })
            .collect();
        for pair in counts.windows(2) {
            let ratio = pair[0] as f64 / pair[1] as f64;
            assert!((1.6..2.6).contains(&ratio), "{counts:?}");
        }
    }
}
