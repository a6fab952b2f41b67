//! Mean filter with gross-error rejection (paper 003): plan, fixed-point model, float golden
//! model.
//!
//! # What it does
//!
//! Cuts the input into blocks of `L` samples (not a moving average: one output per block, so
//! the output rate is `fs / L`). For each block it takes the mean `m`, drops every sample with
//! `|x_i − m| > r` (a gross error), and outputs the mean of the samples kept. Paper 003 uses
//! `L = 20`, `r = 0.3 °/s`.
//!
//! ```text
//! sum   = Σ x_i                                  exact
//! keep_i = |L·x_i − sum| ≤ L·r                   exact: |x_i − m| ≤ r without a division
//! n     = Σ keep_i,  kept = Σ keep_i·x_i         exact
//! (n, kept) = (L, sum) when n = 0                every sample rejected: the plain mean
//! y     = Q(kept · recip(n))                     output format, the one quantization point
//! ```
//!
//! `recip(n)` is a ROM of `1/n` for `n = 1..L` (address 0 holds `1/L`, which the `n = 0`
//! fallback uses). `r` is quantized once to the input format's LSB (nearest); the comparison
//! is then exact, so the fixed model keeps exactly the samples the float model keeps on the
//! same inputs with the same quantized `r` (the float model's `L·x_i − sum` is exact in f64
//! while the input width plus `log2 L` stays under 53 bits).
//!
//! # Parameters
//!
//! | parameter | meaning | default |
//! |-----------|---------|---------|
//! | `window` | `L`, samples per block, 2..=1024 | 20 |
//! | `threshold_dps` | `r`, °/s, ≥ 0 and within the input range | 0.3 |
//! | `output_format` | format of `y`, °/s | the input format |
//! | `reciprocal_width` | width of the `1/n` codes, `s<w>.<w−2>` | 18 |
//! | `rounding`, `overflow` | at the output quantizer | `nearest`, `saturate` |
//!
//! # Interface (RTL `hdl/gyrofx_mean_filter.v`)
//!
//! | port | dir | format | meaning |
//! |------|-----|--------|---------|
//! | `clk`, `rst`, `ce` | in | 1 bit | clock, synchronous reset (clears the block), sample strobe |
//! | `x` | in | input format | gyro rate |
//! | `y` | out | output format | mean of the kept samples of the last block |
//! | `kept` | out | `u<bits of L>.0` | samples kept in that block (0: all rejected, plain mean) |
//! | `y_valid` | out | 1 bit | high for one clock, 1 clock after a block's last `ce` |
//!
//! Error vs the float golden model on the same inputs: at most
//! [`Plan::error_bound_lsb`] output LSB (the reciprocal's quantization times the largest
//! kept sum, plus the output rounding), checked by a property test.
//!
//! Vectors: `vectors/mean_filter/`; model: [`FixedMeanFilter`], golden model:
//! [`FloatMeanFilter`]; the schedule of the sequential RTL (`gyrofx_mean_filter_serial`, one
//! division per block and two comparisons per sample): [`serial`].

mod fixed;
mod float;
mod plan;
pub mod serial;

pub use fixed::{block_mean, BlockMean, FixedMeanFilter};
pub use float::FloatMeanFilter;
pub use plan::{Plan, PlanError, Spec, MAX_WINDOW};

#[cfg(test)]
mod tests;
