//! A bound on `|rate_hat_fixed − rate_hat_float|`, and the guard-bit rule behind the default.
//!
//! Both models run the same quantized gains on the same input codes, so they differ only by
//! the rounding of the two state registers (and the float model's own rounding). Let
//! `ε = x_fixed − x_float`; each sample adds a rounding error `δ` with
//! `|δ_i| ≤ u q_x` (`q_x` the state LSB, `u` = 1/2 for `nearest`, `round`, `convergent`, 1 for
//! `floor`, `ceil`, `zero`) and `ε ← (I − gH) ε + δ`.
//!
//! Split `ε = a·[1, −1] + (h/S)·g` with `h = ε1 + ε2 = Hε` and `S = g1 + g2`:
//!
//! - `h ← (1 − S) h + Hδ`, a stable scalar recursion: `|h| ≤ H_max = 2 u q_x / (1 − ρ)` with
//!   `ρ = max |1 − S|` over the ROM.
//! - `a ← a + α`, `α = (g2 δ1 − g1 δ2)/S`: the direction `[1, −1]` is the eigenvector of `A`
//!   with eigenvalue exactly 1 (`H[1, −1]ᵀ = 0`), so the filter never sees, and never corrects,
//!   errors there. `|α| ≤ u q_x (|g1| + |g2|)/|S|` per sample: the error **random-walks**.
//! - a `bw_sel` switch keeps `ε` but re-splits it: `a` jumps by at most
//!   `H_max · max|g1/S − g1'/S'|`.
//!
//! So after `n` samples and `m` switches, with `ε1 = a + (g1/S) h`:
//!
//! `|ε1| ≤ n·max(u q_x (|g1|+|g2|)/|S|) + m·H_max·max|Δ(g1/S)| + max|g1/S|·H_max`,
//!
//! plus the same expression for the float model's own rounding (a per-sample error of at most
//! `2⁻⁵² M (1 + 9 max|g|)` per component, `M` = 4× the largest input or state value), plus the
//! output rounding `u q_out`. [`rate_error_bound_lsb`] evaluates it; property tests check it
//! over random formats, gains and inputs. It holds while no quantizer overflows.
//!
//! # Guard bits of the default
//!
//! The bound is linear in `n` because it assumes every rounding error has the worst sign. With
//! round-to-nearest the errors are zero-mean and roughly uniform (rms `q_x/√12`), and
//! `g1 ≫ g2` makes `α ≈ −δ2`, so `a` is a random walk of rms `q_x √(n/12)`. For `n = 10⁶`
//! that is `289 q_x`; with 12 guard bits (`q_x = q_out/4096`) it is 0.07 output LSB, so a
//! 6-sigma excursion (0.42 LSB) plus the output rounding (0.5 LSB) stays within 1 output LSB.
//! Directed rounding (`floor`) instead drifts `a` by ~`q_x/2` per sample (about 122 LSB after
//! 10⁶ samples at 12 guard bits): use a round-to-nearest mode for the state.

use super::plan::Plan;

/// Worst-case `|rate_hat_fixed − rate_hat_float|`, in output LSB, after `samples` samples with
/// at most `switches` changes of `bw_sel` (see the module doc). Both models use the plan's
/// quantized gains. Valid while no quantizer overflows.
pub fn rate_error_bound_lsb(plan: &Plan, samples: u64, switches: u64) -> f64 {
    let gains = plan.quantized_gains();
    let q_x = plan.state.lsb();
    let q_out = plan.output.lsb();
    let u = plan.rounding.max_error_lsb();
    let n = samples as f64;
    let m = switches as f64;

    let mut rho: f64 = 0.0;
    let mut alpha_per_unit: f64 = 0.0;
    let mut largest_gain: f64 = 0.0;
    let ratios: Vec<f64> = gains.iter().map(|g| g[0] / (g[0] + g[1])).collect();
    for g in &gains {
        let s = g[0] + g[1];
        rho = rho.max((1.0 - s).abs());
        alpha_per_unit = alpha_per_unit.max((g[0].abs() + g[1].abs()) / s.abs());
        largest_gain = largest_gain.max(g[0].abs()).max(g[1].abs());
    }
    if rho >= 1.0 {
        return f64::INFINITY;
    }
    let largest_ratio = ratios.iter().fold(0.0f64, |a, r| a.max(r.abs()));
    let ratio_jump = ratios
        .iter()
        .flat_map(|a| ratios.iter().map(move |b| (a - b).abs()))
        .fold(0.0f64, f64::max);

    let epsilon_one = |per_sample: f64| {
        let h_max = 2.0 * per_sample / (1.0 - rho);
        n * per_sample * alpha_per_unit + m * h_max * ratio_jump + largest_ratio * h_max
    };
    let fixed = epsilon_one(u * q_x);
    let magnitude = 4.0 * plan.state.max_value().max(plan.input.max_value());
    let float = epsilon_one(crate::fx::pow2(-52) * magnitude * (1.0 + 9.0 * largest_gain));
    (fixed + float) / q_out + plan.rounding.max_error_lsb()
}

/// Expected rms of the unobservable random walk after `samples` samples with
/// round-to-nearest state rounding, in output LSB: `2^-guard · √(n/12)` (see the module doc).
pub fn random_walk_rms_lsb(plan: &Plan, samples: u64) -> f64 {
    crate::fx::pow2(-plan.guard_bits()) * (samples as f64 / 12.0).sqrt()
}
