//! Steady-state Kalman filter (paper 000): design, plan, fixed-point model, float golden model.
//!
//! # What it does
//!
//! Estimates the true rate from one gyro (or the combined mode-reversal output) with the model
//! `z = ω + b + n`, both `ω` and `b` random walks, using a constant gain found offline
//! ([`design`]). Both discretisations reduce to the innovation recursion
//!
//! ```text
//! e = z − x1 − x2          (exact)
//! x1 ← Q(x1 + g1·e)        (state format)
//! x2 ← Q(x2 + g2·e)        (state format)
//! rate_hat = Q(x1)         (output format)
//! ```
//!
//! two multipliers per sample. `ω̂/z = g1 / (1 − (1 − g1 − g2) z⁻¹)`: a first-order low-pass
//! with DC gain `g1/(g1+g2)` and an exact −3 dB point ([`design::bandwidth_hz`]).
//!
//! # Why the eigenvalue at 1 stays exactly 1
//!
//! `A = I − gH` has the eigenvector `[1, −1]` with eigenvalue 1 for *any* `g`, because
//! `H·[1, −1]ᵀ = 0`. The fixed-point model keeps this exactly: a state offset of `c` LSB along
//! `[1, −1]` leaves `e` unchanged, and adding a whole number of LSB before a quantizer commutes
//! with it, so the offset survives every later sample unchanged, bit for bit (a test shows it).
//! Coefficient quantization therefore cannot push this eigenvalue outside the unit circle;
//! only the other one, `1 − (g1 + g2)`, moves, and [`Plan::new`] refuses a design where it
//! leaves `[−1, 1]`. The price is that rounding errors random-walk along `[1, −1]`
//! ([`bound`]); the state's guard bits keep that walk below an output LSB.
//!
//! # Parameters
//!
//! | parameter | meaning | default |
//! |-----------|---------|---------|
//! | `input_format` | format of `z`, °/s (its range is the ADC full scale) | `s24.14` (±512 °/s) |
//! | `state_format` | format of `x1`, `x2`, °/s | `s36.26` (12 guard bits) |
//! | `output_format` | format of `rate_hat`, °/s | `s24.14` |
//! | `coefficient_width` | width of `g1`, `g2`; fraction bits chosen per coefficient | 18 |
//! | `rounding`, `overflow` | at the state and output quantizers | `nearest`, `saturate` |
//! | `bandwidths_hz` | one ROM entry per bandwidth, addressed by `bw_sel` | 10, 20, 30 Hz |
//!
//! # Interface (RTL `hdl/gyrofx_kf.v`)
//!
//! | port | dir | format | meaning |
//! |------|-----|--------|---------|
//! | `clk` | in | 1 bit | clock |
//! | `rst` | in | 1 bit | synchronous reset, active high: clears `x1`, `x2`, `out_valid` |
//! | `ce` | in | 1 bit | sample strobe: one sample per clock with `ce` high |
//! | `bw_sel` | in | `u{select_width}.0` | ROM address: bandwidth of this sample |
//! | `z` | in | `input_format` | gyro rate |
//! | `rate_out` | out | `output_format` | `rate_hat` of the sample taken at the last `ce` |
//! | `out_valid` | out | 1 bit | high for one clock, 1 clock after `ce` |
//!
//! Latency: `rate_out` is valid 1 clock after `ce` (registered output). A sample with `rst`
//! high resets and produces no output.
//!
//! # Quantization points
//!
//! Exactly three, all with the configured rounding and overflow modes: the two state updates
//! and the output. Intermediate formats are in [`Plan`]. Coefficients are quantized once,
//! offline, to nearest (ties to even), and never wrap: a coefficient that does not fit is an
//! error.
//!
//! Vectors: `vectors/kf/`; model: [`FixedKf`], golden model: [`FloatKf`].

pub mod bound;
pub mod design;
mod fixed;
mod float;
mod plan;

pub use fixed::{FixedKf, OverflowCounts};
pub use float::FloatKf;
pub use plan::{signed_bits_needed, CoefficientFormat, Plan, PlanError, Spec, COEFFICIENT_NAMES};

#[cfg(test)]
mod tests;
