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
    let terms = Terms::of(plan);
    if terms.rho >= 1.0 {
        return f64::INFINITY;
    }
    let q_out = plan.output.lsb();
    let u = plan.rounding.max_error_lsb();
    let fixed = terms.epsilon(
        u * plan.state.lsb(),
        samples,
        switches,
        terms.largest_ratio[0],
    );
    let magnitude = 4.0 * plan.state.max_value().max(plan.input.max_value());
    let float = terms.epsilon(
        crate::fx::pow2(-52) * magnitude * (1.0 + 9.0 * terms.largest_gain),
        samples,
        switches,
        terms.largest_ratio[0],
    );
    (fixed + float) / q_out + plan.rounding.max_error_lsb()
}

/// Worst-case `|x_fixed − x_exact|` of the two state registers `[x1, x2]` (real units, °/s)
/// after `samples` samples with at most `switches` changes of `bw_sel`: the fixed model's
/// rounding against exact arithmetic on the same quantized gains (the module doc's `ε1`, and
/// `ε2 = −a + (g2/S) h` alike). Infinite when a ROM entry's pole is not inside the unit circle.
pub fn state_error_bounds(plan: &Plan, samples: u64, switches: u64) -> [f64; 2] {
    let terms = Terms::of(plan);
    if terms.rho >= 1.0 {
        return [f64::INFINITY; 2];
    }
    let per_sample = plan.rounding.max_error_lsb() * plan.state.lsb();
    terms
        .largest_ratio
        .map(|ratio| terms.epsilon(per_sample, samples, switches, ratio))
}

/// The quantities of the module doc over the plan's quantized ROM.
struct Terms {
    /// `max |1 − S|`.
    rho: f64,
    /// `max (|g1| + |g2|)/|S|`.
    alpha_per_unit: f64,
    /// `max |g|`.
    largest_gain: f64,
    /// `max |g1/S|`, `max |g2/S|`.
    largest_ratio: [f64; 2],
    /// `max |g1/S − g1'/S'|` over pairs of entries.
    ratio_jump: f64,
}

impl Terms {
    fn of(plan: &Plan) -> Terms {
        let gains = plan.quantized_gains();
        let mut terms = Terms {
            rho: 0.0,
            alpha_per_unit: 0.0,
            largest_gain: 0.0,
            largest_ratio: [0.0; 2],
            ratio_jump: 0.0,
        };
        let ratios: Vec<f64> = gains.iter().map(|g| g[0] / (g[0] + g[1])).collect();
        for g in &gains {
            let s = g[0] + g[1];
            terms.rho = terms.rho.max((1.0 - s).abs());
            terms.alpha_per_unit = terms
                .alpha_per_unit
                .max((g[0].abs() + g[1].abs()) / s.abs());
            terms.largest_gain = terms.largest_gain.max(g[0].abs()).max(g[1].abs());
            for (largest, gain) in terms.largest_ratio.iter_mut().zip(g) {
                *largest = largest.max((gain / s).abs());
            }
        }
        terms.ratio_jump = ratios
            .iter()
            .flat_map(|a| ratios.iter().map(move |b| (a - b).abs()))
            .fold(0.0f64, f64::max);
        terms
    }

    /// `n·δ·α + m·H_max·jump + ratio·H_max` for a per-sample error `δ` per component.
    fn epsilon(&self, per_sample: f64, samples: u64, switches: u64, ratio: f64) -> f64 {
        let h_max = 2.0 * per_sample / (1.0 - self.rho);
        samples as f64 * per_sample * self.alpha_per_unit
            + switches as f64 * h_max * self.ratio_jump
            + ratio * h_max
    }
}

/// Expected rms of the unobservable random walk after `samples` samples with
/// round-to-nearest state rounding, in output LSB: `2^-guard · √(n/12)` (see the module doc).
pub fn random_walk_rms_lsb(plan: &Plan, samples: u64) -> f64 {
    crate::fx::pow2(-plan.guard_bits()) * (samples as f64 / 12.0).sqrt()
}
