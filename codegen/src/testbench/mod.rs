//! The self-checking testbench of a [`Block`](crate::block::Block), generated in Verilog 2001
//! ([`verilog`], run by Icarus and Verilator) and VHDL-2008 ([`vhdl`], run by GHDL).
//!
//! Both read the same `<block>_stimulus.hex` and `<block>_expected.hex` (one line per
//! clock-enable; line 1 a generated-by comment, line 2 the fields and formats, checked against
//! the testbench's own), drive one sample per `ce` with an idle clock after every fourth, and
//! compare: combinational outputs before the clock edge (not on reset samples), registered
//! outputs 1 clock after it (gated ones only where their gate is expected 1), and on idle
//! clocks pulses low and other registered outputs held. Inputs keep their values through the
//! settle and idle clocks: a strobe that acts without `ce` (the PI's `preset`) acts there too,
//! and the expected outputs say so ([`idle_clock_after`]). Both print the same lines:
//!
//! - `MISMATCH sample <k> signal <name> expected <hex> (<real>) actual <hex> (<real>)` for the
//!   first mismatches,
//! - then `PASS n=<N>` (`PASS n=<N> masked=<M>` with a mask) or
//!   `FAIL mismatches=<M> n=<N> first=<k>`,
//!
//! and exit non-zero on a mismatch, a timeout, or a missing, short or mis-declared vector file or
//! ROM image (Verilog `$fatal`, VHDL `std.env.stop(1)`).
//!
//! Options (Verilog plusarg / VHDL generic, set with GHDL's `-g<NAME>=<value>`):
//!
//! | plusarg | generic | default | meaning |
//! |---|---|---|---|
//! | `+mask=<n>` | `MASK_SAMPLES` | 0 | latency mask: the first n samples of the run and from every reset sample on are driven but not compared (counted as masked) |
//! | `+max_reported=<n>` | `MAX_REPORTED` | 10 | mismatches printed |
//! | `+max_mismatches=<n>` | `MAX_MISMATCHES` | 0 | stop at the n-th mismatch (0: run every sample) |
//! | `+dump` | GHDL `--vcd=<file>` / `--wave=<file>` | off | waveform dump (`tb_<module>.vcd` in Verilog) |

use crate::block::Signal;

pub mod verilog;
pub mod vhdl;

/// The testbenches add an idle clock (`ce` low) after every `IDLE_EVERY`-th sample.
pub const IDLE_EVERY: usize = 4;

/// Whether the testbenches add an idle clock after sample `index` (0-based).
pub fn idle_clock_after(index: usize) -> bool {
    index % IDLE_EVERY == IDLE_EVERY - 1
}

/// Mismatches printed unless the run says otherwise.
pub const MAX_REPORTED: u32 = 10;

/// Field line of a vector file: `// rst:u1.0 name:format ...`.
pub fn header(fields: &[&Signal], with_rst: bool) -> String {
    let mut parts: Vec<String> = Vec::new();
    if with_rst {
        parts.push("rst:u1.0".into());
    }
    parts.extend(fields.iter().map(|s| format!("{}:{}", s.name, s.format)));
    format!("// {}", parts.join(" "))
}

/// Clocks the testbench may take for `vectors` samples before it declares a timeout: one per
/// sample, one idle per four, `settle` per sample, the reset and slack.
pub fn timeout_clocks(vectors: usize, settle: u32) -> u64 {
    (3 + u64::from(settle)) * vectors as u64 + 100
}
