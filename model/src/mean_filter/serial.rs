//! The sequential schedule of `gyrofx_mean_filter_serial`: the same block means as
//! [`super::block_mean`], computed one step a clock with one adder per phase, no multiplier,
//! and the block's samples in a RAM.
//!
//! # Why bounds instead of deviations
//!
//! The parallel filter tests `|L·x − sum| ≤ L·r` for every sample: a product per sample. With
//! `r` an integer number of input LSB, that test is the same as
//!
//! ```text
//! ceil(sum / L) − r  ≤  x  ≤  floor(sum / L) + r
//! ```
//!
//! (`L·x ≤ sum + L·r ⇔ x ≤ sum/L + r ⇔ x ≤ floor(sum/L) + r` for an integer `x`, and the same
//! for the lower side), so one division per block turns the test into two comparisons per
//! sample. The division is restoring, `SUM_W − 1` steps on `sum`'s magnitude, with the one's
//! complement of a negative sum (`!sum = −sum − 1 ≥ 0`): `floor(sum/L) = !floor(!sum/L)`, and
//! the division is exact when the remainder is `L − 1`.
//!
//! # Phases, a clock each step, after a block's last `ce`
//!
//! | phase | clocks | what |
//! |-------|--------|------|
//! | divide | `SUM_W − 1` | one quotient bit a clock (the dividend is loaded by the last `ce`) |
//! | bounds | 1 | `kept_low`, `kept_high`; reads sample 0 |
//! | scan | `L` | keep `kept_low ≤ x ≤ kept_high`: count, kept sum; reads the next sample |
//! | reciprocal | 1 | reads `ROM[n]` |
//! | load | 1 | the reciprocal's `RECIP_W − 1` magnitude bits into the product's low half (its sign bit is 0) |
//! | multiply | `RECIP_W − 1` | shift and add, lowest bit first: `high = (high + bit·operand) >> 1`, the bit shifted out into the low half (operand: the kept sum; `n = 0`: the plain sum) |
//! | output | 1 | `y = Q({high, low})`, `kept = n`, `y_valid` |
//!
//! so `y_valid` pulses [`latency_clocks`] clocks after the block's last `ce` (counting the
//! clock of that `ce` as the first, as the parallel filter's 1). The adder of the multiply is
//! `SUM_W + 1` bits wide, not the product's `SUM_W + RECIP_W`: `|high| ≤ |operand|` after
//! every step.

use super::fixed::{quantized_mean, BlockMean};
use super::plan::Plan;
use crate::fx::Format;

/// Clocks from a block's last `ce` until `y_valid` pulses (the parallel filter's 1):
/// `1 + (SUM_W − 1) + 1 + L + 1 + 1 + (RECIP_W − 1) + 1 = SUM_W + L + RECIP_W + 3`. It is also the
/// fewest clocks from that `ce` to the next `ce` or `rst` (the next block's samples share the
/// RAM; a reset stops the block being processed).
pub fn latency_clocks(plan: &Plan) -> u32 {
    plan.sum.width + plan.window + plan.reciprocal.width + 3
}

/// The kept range's bounds (and the product's high half): `SUM_W + 1` bits, as `sum`'s
/// fraction, enough for `floor(sum/L) ± r` and for `high + operand`.
pub fn kept_range_format(plan: &Plan) -> Format {
    Format::intermediate(true, plan.sum.width + 1, plan.sum.frac)
        .expect("the plan's product already holds more bits")
}

/// `floor(sum / window)` and whether the division left a remainder, as the RTL computes them:
/// restoring division of `sum`'s magnitude (one's complement when negative) over its
/// `sum_width − 1` bits.
///
/// # Panics
/// When `sum` does not fit `sum_width` signed bits or `window` is 0.
pub fn floor_divide(sum: i128, sum_width: u32, window: u32) -> (i128, bool) {
    assert!(window > 0, "a window of at least one sample");
    let half = 1i128 << (sum_width - 1);
    assert!((-half..half).contains(&sum), "{sum} fits s{sum_width}");
    let negative = sum < 0;
    let magnitude = if negative { !sum } else { sum };
    let divisor = i128::from(window);
    let (mut quotient, mut remainder) = (0i128, 0i128);
    for bit in (0..sum_width - 1).rev() {
        remainder = (remainder << 1) | ((magnitude >> bit) & 1);
        quotient <<= 1;
        if remainder >= divisor {
            remainder -= divisor;
            quotient |= 1;
        }
    }
    if negative {
        (!quotient, remainder != divisor - 1)
    } else {
        (quotient, remainder != 0)
    }
}

/// The inclusive range of sample codes a block with this `sum` keeps:
/// `(ceil(sum/L) − r, floor(sum/L) + r)`.
pub fn kept_range(plan: &Plan, sum: i128) -> (i128, i128) {
    let (floor, inexact) = floor_divide(sum, plan.sum.width, plan.window);
    let ceil = floor + i128::from(inexact);
    (ceil - plan.threshold_code, floor + plan.threshold_code)
}

/// `operand · reciprocal` by shift and add, the reciprocal's bits from the lowest, as the RTL's
/// multiply phase does: the high half takes `operand` when the low half's bit 0 is set and
/// shifts right into the low half (`reciprocal` is a non-negative code of `width` bits).
pub fn shift_add_product(operand: i128, reciprocal: i128, width: u32) -> i128 {
    assert!(reciprocal >= 0, "reciprocals are positive");
    let low_bits = width - 1;
    let (mut high, mut low) = (0i128, reciprocal);
    for _ in 0..low_bits {
        let partial = high + (low & 1) * operand;
        low = (low >> 1) | ((partial & 1) << (low_bits - 1));
        high = partial >> 1;
    }
    (high << low_bits) | low
}

/// One whole block's result by the serial schedule: bit-exact with [`super::block_mean`].
///
/// # Panics
/// When `block` does not hold exactly `plan.window` samples.
pub fn block_mean(plan: &Plan, block: &[i64]) -> BlockMean {
    assert_eq!(block.len(), plan.window as usize, "one whole block");
    let sum: i128 = block.iter().map(|&x| i128::from(x)).sum();
    let (low, high) = kept_range(plan, sum);
    let (mut kept, mut kept_sum) = (0u32, 0i128);
    for &x in block {
        let x = i128::from(x);
        if low <= x && x <= high {
            kept += 1;
            kept_sum += x;
        }
    }
    let operand = if kept == 0 { sum } else { kept_sum };
    let product = shift_add_product(operand, plan.rom[kept as usize], plan.reciprocal.width);
    quantized_mean(plan, product, kept)
}
