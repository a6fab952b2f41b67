//! The compensator's design: the CIC's and the taps' responses and Lawson's minimax fit.

use super::*;

/// `n·2^−53 / (1 − n·2^−53)`: the relative error bound of `n` rounded f64 operations, doubled
/// for margin.
pub(super) fn gamma(n: f64) -> f64 {
    let u = crate::fx::pow2(-53);
    2.0 * n * u / (1.0 - n * u)
}

/// `[sin(π M f) / (R M sin(π f / R))]^N`, 1 at `f = 0`.
pub(super) fn cic_response(stages: u32, decimation: u32, delay: u32, f: f64) -> f64 {
    if f == 0.0 {
        return 1.0;
    }
    let r = f64::from(decimation);
    let m = f64::from(delay);
    let ratio = libm::sin(PI * m * f) / (r * m * libm::sin(PI * f / r));
    libm::pow(ratio, f64::from(stages))
}

/// `h_c + 2 Σ_k h_{c+k} cos(2π k f)` of symmetric taps with centre `c`.
pub(super) fn zero_phase_response(taps: &[f64], f: f64) -> f64 {
    let centre = taps.len() / 2;
    taps[centre]
        + (1..=centre)
            .map(|k| 2.0 * taps[centre + k] * libm::cos(2.0 * PI * k as f64 * f))
            .sum::<f64>()
}

/// Iterations of Lawson's reweighting, which turns the least-squares fit into (nearly) the
/// minimax one.
pub(super) const LAWSON_ITERATIONS: usize = 40;

/// The compensator with the flattest cascade: minimises `max |H_c(f)·H_h(f) − 1|` over
/// `[0, passband]` (Lawson's iteratively reweighted least squares on a grid), scaled to DC
/// gain `correction` exactly; returns all `T` taps.
pub(super) fn design_compensator(spec: &Spec, correction: f64) -> Vec<f64> {
    let half = (spec.taps / 2) as usize;
    if half == 0 {
        return vec![correction];
    }
    let grid: Vec<f64> = (0..DESIGN_POINTS)
        .map(|i| spec.passband * i as f64 / (DESIGN_POINTS - 1) as f64)
        .collect();
    let droop: Vec<f64> = grid
        .iter()
        .map(|f| cic_response(spec.stages, spec.decimation, spec.differential_delay, *f))
        .collect();
    // Row i: the cascade's response at f_i is the sum over k of c_k times this.
    let row = |i: usize, k: usize| {
        let cosine = if k == 0 {
            1.0
        } else {
            2.0 * libm::cos(2.0 * PI * k as f64 * grid[i])
        };
        droop[i] * cosine
    };
    let mut weights = vec![1.0 / DESIGN_POINTS as f64; DESIGN_POINTS];
    let mut c = nalgebra::DVector::zeros(half + 1);
    for _ in 0..LAWSON_ITERATIONS {
        let a = nalgebra::DMatrix::from_fn(DESIGN_POINTS, half + 1, |i, k| {
            libm::sqrt(weights[i]) * row(i, k)
        });
        let target = nalgebra::DVector::from_fn(DESIGN_POINTS, |i, _| libm::sqrt(weights[i]));
        c = a
            .svd(true, true)
            .solve(&target, 1e-12)
            .expect("the SVD was computed with both U and V");
        let errors: Vec<f64> = (0..DESIGN_POINTS)
            .map(|i| ((0..=half).map(|k| c[k] * row(i, k)).sum::<f64>() - 1.0).abs())
            .collect();
        let total: f64 = weights.iter().zip(&errors).map(|(w, e)| w * e).sum();
        if total == 0.0 {
            break;
        }
        for (w, e) in weights.iter_mut().zip(&errors) {
            *w *= e / total;
        }
    }
    let dc: f64 = c[0] + 2.0 * c.iter().skip(1).sum::<f64>();
    let scale = correction / dc;
    (0..spec.taps as usize)
        .map(|t| c[t.abs_diff(half)] * scale)
        .collect()
}
