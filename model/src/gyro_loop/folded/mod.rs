//! The folded gyro loop: the same loop as [`super::gyro::FixedGyroLoop`], bit for bit, with its
//! arithmetic time-multiplexed onto one multiplier, one accumulator and one RAM, so that it fits
//! a small FPGA (`architecture = "serial"`, `hdl/gyrofx_gyro_loop_serial.v`).
//!
//! # Datapath
//!
//! ```text
//!  sine ROM ─► ref ─┐                                      ┌─► pp ─┐
//!  a operands ──────┴─► a limb, b ─► a limb × b (B limbs) ─┘       ├─► acc ◄─ x (RAM word, setpoint, integrator…)
//!                                                                   │    │
//!  RAM (states) ─► rd ─► prev_rd          y ─► Q_O(y) ───────────────┘    └─► quantization points ─► registers, RAM
//! ```
//!
//! - **Multiplier.** Each clock it may take one 15-bit limb of an `a` operand (sign-extended;
//!   the top limb signed, the others unsigned) and all of a `b` operand, split into
//!   `B = ⌈(W_b − 1)/15⌉` limbs, into its operand registers; on the next clock `B` signed
//!   16×16 products, one SB_MAC16 or DSP slice each, registered; on the next, their sum at
//!   the limb's weight `2^(15·limb)` and the PI's alignment (`pp`), which the accumulator
//!   adds [`PRODUCT_LATENCY`] clocks after the issue. A `W`-bit `a` takes `⌈(W − 1)/15⌉`
//!   clocks.
//! - **Accumulator.** `acc <= x + y` ([`AccX`], [`AccY`]), wide enough for every exact sum of
//!   the loop ([`Datapath::accumulator_width`]); partial sums wrap, the exact results fit.
//! - **Quantization points** read the accumulator's low bits as the exact value's format
//!   and load their register ([`Quantize`]), rounding and saturating as the parallel loop's
//!   points do, in the same order for each value. The demodulator's output point `Q_O`
//!   reads the state register `y` every clock into its own register, so its readers see
//!   the `y` of the clock before (no clock runs a quantizer into the accumulator's adder).
//! - **RAM.** Every state: the four demodulator low-pass states, the two PI integrators, the
//!   two lock filters, the CICs' integrators and combs, the compensators' delay lines. One
//!   read and one write a clock, never of the same word (a block RAM's read of the word it
//!   writes is undefined; [`Control::merge`] refuses it); a read lands in `rd` on the next
//!   clock; a quantized state
//!   is written from the register its point loaded, the clock after ([`WriteData`]). Clears
//!   at a mode switch and at reset are read gates ([`ReadGate`]), not clocks spent writing
//!   zeros.
//! - **NCO.** One accumulator and the three references' truncation errors; a ROM read
//!   computes the reference's phase and address.
//!
//! The RTL fetches each control word two clocks before it acts and decodes the accumulator's
//! operand selects from it in the clock between (with the read gates: a word gated to 0
//! selects nothing, the PLL's preset is an operand of its own); the model's clocks are the
//! words' own.
//!
//! The schedule ([`Schedule`]) is derived from the loop's plan: which unit does what in each
//! clock of a sample, the regular part every sample and the decimation part (combs,
//! compensators, `1/SF`) every `R`-th. [`FoldedGyroLoop`] runs it clock by clock as the RTL
//! does, which is how the tests prove the schedule against the parallel model.
//!
//! # The pair
//!
//! [`Schedule::pair`] puts both gyros of the system on this one datapath ([`FoldedPair`]), so
//! that the whole system fits a small FPGA. Every unit's work in a clock names its gyro (the
//! control word's gyro fields): each gyro has its own mode, NCO, `Q_D`, `e_A`, amplitude, DAC,
//! lock and outputs, and its own RAM words; the datapath's registers are shared, and the
//! schedule keeps their values apart as for one gyro. Both regular parts run every sample
//! (their templates interleaved); the decimation's work would not fit beside them, so the
//! decimating sample only snapshots each CIC's last integrator (a RAM write that acts only
//! then), and the combs, the compensators (their taps in groups, partial sums in RAM) and the
//! `1/SF` products run in the spare clocks of the following samples (`deferred` segments).
//! Each gyro's DAC codes and lock flags are the parallel loop's in every sample; its decimated
//! outputs come [`FoldedPair::output_delay`] samples after the sample that decimates, the
//! `1/SF` of the mode that sample was taken in.

mod control;
mod machine;
mod schedule;
#[cfg(test)]
mod tests;

pub use control::{
    ASource, AccX, AccY, Accumulate, BSource, Busy, Control, Issue, Quantize, Read, ReadGate,
    RomRead, Write, WriteData, ADDRESS_BITS, CONTROL_BITS, FIELDS, LIMB_BITS, PRODUCT_LATENCY,
};
pub use machine::{FoldedGyroLoop, FoldedPair, PairStep};
pub use schedule::{Schedule, ScheduleError, Words, PAIR_SAMPLE_WORDS};

use super::gyro::Plan;

/// Clocks a `width`-bit signed operand takes in the multiplier: 15-bit limbs, the top one
/// signed and up to 16 bits.
pub fn limbs(width: u32) -> u32 {
    width.saturating_sub(1).div_ceil(LIMB_BITS).max(1)
}

/// The widths the folded datapath needs for `plan`, as the RTL derives them from its
/// parameters.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Datapath {
    /// The accumulator: every exact sum of the loop and a limb's product fit, with a guard bit
    /// (so that every value sign-extends into it in Verilog-2001).
    pub accumulator_width: u32,
    /// The lock filters' `z`: `W_out + s + 1` bits.
    pub lock_width: u32,
}

impl Datapath {
    /// The widths of `plan`'s folded loop.
    pub fn new(plan: &Plan) -> Datapath {
        let demod = &plan.demodulator;
        let cic = &plan.cic;
        let lock_width = demod.output.to.width + plan.lock.shift + 1;
        let sums = [
            demod.product.from.width,
            demod.state.from.width,
            plan.agc_error.from.width,
            plan.pll.integrator_point.from.width,
            plan.pll.output.from.width,
            plan.agc.integrator_point.from.width,
            plan.agc.output.from.width,
            plan.dac.from.width,
            cic.register.width,
            cic.output.from.width,
            plan.output.from.width,
            lock_width,
        ];
        let b_width = [
            plan.nco.output.width,
            plan.pll.kp.format.width,
            plan.pll.ki.format.width,
            plan.agc.kp.format.width,
            plan.agc.ki.format.width,
            cic.taps[0].format.width,
            plan.modes[0].rate_coefficient.format.width,
            plan.modes[0].quadrature_coefficient.format.width,
        ]
        .into_iter()
        .max()
        .unwrap_or(1);
        // A limb's product with all of b: 16 bits times b's limbs and a guard bit.
        let product = 16 + LIMB_BITS * limbs(b_width) + 2;
        Datapath {
            accumulator_width: sums.into_iter().max().unwrap_or(1).max(product) + 1,
            lock_width,
        }
    }
}

/// `value`'s low `width` bits as a signed number.
pub(crate) fn sign_extend(value: i128, width: u32) -> i128 {
    if width >= 128 {
        return value;
    }
    let shift = 128 - width;
    (value << shift) >> shift
}
