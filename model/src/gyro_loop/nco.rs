//! NCO: a phase accumulator and a quarter-wave sine ROM, giving the loop's sine and cosine
//! references.
//!
//! # What it does
//!
//! Per sample (one `ce`), with `acc` the `P`-bit phase accumulator in cycles:
//!
//! ```text
//! phase = (acc + offset) mod 2^P        u P.P cycles, exact (wraps: a phase is mod 1 cycle)
//! t     = floor(phase / 2^(P−A−2))      u (A+2).(A+2) cycles: the phase-truncation point
//! sin   = ±ROM[k(t)]                    s S.(S−1), exact (ROM codes are quantized offline)
//! cos   = ±ROM[k(t + 2^A)]              the same ROM a quarter cycle on
//! acc  ← (acc + freq) mod 2^P           the next sample's phase
//! ```
//!
//! `freq` (the frequency word, `u P.P` cycles per sample: `f / fs`) and `offset` (`u P.P`
//! cycles: the sense channel's per-mode reference phase) are inputs taken every sample, so
//! the PLL can load a new frequency each sample. A signed PI output `s P.P` can drive `freq`
//! directly: its bits read as unsigned are the same frequency mod `fs`.
//!
//! The ROM holds a quarter wave at the **centres** of its `2^A` phase bins,
//! `ROM[k] = Q(A_nco · sin(π/2 · (k + ½) / 2^A))` with `A_nco = (2^(S−1) − 1) · 2^−(S−1)` (the
//! largest code, so that `−ROM[k]` never overflows). The half-bin offset makes the quadrant
//! mirror a bit inversion and turns the phase's truncation into a rounding to the nearest bin
//! centre. In quadrant `q = t >> A` with `i = t mod 2^A`:
//!
//! | q | 0 | 1 | 2 | 3 |
//! |---|---|---|---|---|
//! | output | `ROM[i]` | `ROM[2^A−1−i]` | `−ROM[i]` | `−ROM[2^A−1−i]` |
//!
//! The drive and sense references are two instances fed the same `freq` (their accumulators
//! stay identical), with `offset` 0 and the per-mode sense phase.
//!
//! # Error feedback (`error_feedback`)
//!
//! Truncated alone, the phase error `e_k` (at most half a bin) averages out only when the bin
//! positions of successive samples spread evenly; where `2^(A+2) f/fs` sits near a fraction of
//! small denominator they do not, and the references hold a static phase error of up to a
//! quarter bin or so (0.026° at `A` = 10: it moved a gyro loop's bias by mdps, issue 32). With
//! error feedback each NCO keeps the phase left below the truncation, less half a bin
//! (`r_k`, signed, `P − A − 2` bits), and adds it to the next sample's phase before
//! truncating:
//!
//! ```text
//! u   = (phase + r_{k−1}) mod 2^P
//! t   = floor(u / 2^(P−A−2))
//! r_k = (u mod 2^(P−A−2)) − 2^(P−A−3)
//! ```
//!
//! Each output is then `r_{k−1} − r_k` from the exact phase (less than a bin), and the errors
//! of any run of samples sum to `r_{−1} − r_{last}`: less than one bin, whatever the frequency.
//! The reset clears `r`.
//!
//! # Quantization points
//!
//! | point | from | to | rounding | overflow |
//! |-------|------|----|----------|----------|
//! | `phase` | `acc + offset`, `u (P+1).P` | `u P.P` cycles | exact | wrap (mod 1 cycle) |
//! | `t` | `u P.P` cycles | `u (A+2).(A+2)` cycles | floor (truncation: the ROM's bin centres make it nearest) | wrap (cannot occur) |
//! | ROM (offline) | `A_nco · sin`, f64 from `libm::sin` | `s S.(S−1)` | convergent | none (`A_nco` fits) |
//!
//! The NCO takes no rounding or overflow mode from the config: its truncation *is* the
//! design, and the ROM is quantized like every coefficient.
//!
//! # Error bound
//!
//! The float twin ([`FloatNco`]) runs the same integer accumulator and outputs
//! `A_nco · sin(2π · phase / 2^P)` of the exact phase. Per output, in output LSB
//! ([`Plan::error_bound_lsb`]): ½ (ROM rounding) + `(2^(S−1) − 1) · π / 2^(A+2)` (the phase is
//! at most half a bin, `π / 2^(A+2)` rad, from the bin centre the ROM holds, and
//! `|sin a − sin b| ≤ |a − b|`), plus a margin for the f64 sine.
//!
//! # Interface (RTL `hdl/gyrofx_nco.v`)
//!
//! | port | dir | format | meaning |
//! |------|-----|--------|---------|
//! | `clk`, `rst`, `ce` | in | 1 bit | clock, synchronous reset (clears `acc`), sample strobe |
//! | `freq` | in | `u P.P` cycles/sample | frequency word of this sample |
//! | `offset` | in | `u P.P` cycles | phase offset of this sample |
//! | `sin_out`, `cos_out` | out | `s S.(S−1)` | the references of the sample taken at the last `ce` |
//! | `out_valid` | out | 1 bit | high for one clock, 1 clock after `ce` |
//!
//! Latency: 1 clock (the ROM addresses are registered at `ce`, as a block-RAM read port).
//! ROM: `ROM_FILE` (`$readmemh`), `2^A` words of `S` bits, [`Plan::rom_codes`].

use std::f64::consts::PI;

use super::{field_error, PlanError, Point, RtlParameter};
use crate::fx::{from_f64, Format, Overflow, Rounding};

/// What an NCO is asked to be.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Spec {
    /// `P`: bits of the phase accumulator, the frequency word and the offset. Frequency
    /// resolution `fs / 2^P` (47 µHz at 200 kHz for 32 bits).
    pub phase_bits: u32,
    /// `A`: address bits of the quarter-wave ROM (`2^A` words); the phase is truncated to
    /// `A + 2` bits.
    pub address_bits: u32,
    /// `S`: width of the sine and cosine outputs, `s S.(S−1)`.
    pub sine_width: u32,
    /// Carry each sample's truncation error into the next sample's phase (first-order error
    /// feedback, see the module doc): the references then hold no static phase error at any
    /// frequency, at the price of each output being within one bin of the exact phase instead
    /// of half a bin. Needs `P > A + 2`.
    pub error_feedback: bool,
}

impl Default for Spec {
    /// `P` = 32, `A` = 10, `S` = 18, error feedback: phase error < 0.088° (a 12-bit phase
    /// bin) per sample and no static phase error at any frequency; within 202 output LSB of
    /// the exact sine.
    fn default() -> Self {
        Spec {
            phase_bits: 32,
            address_bits: 10,
            sine_width: 18,
            error_feedback: true,
        }
    }
}

/// Largest ROM address width: a quarter wave of 2^20 words (4 Mbit at 18 bits) is already far
/// beyond what a gyro loop needs.
pub const MAX_ADDRESS_BITS: u32 = 20;
/// Largest accumulator width: the model keeps the phase in an `i64`.
pub const MAX_PHASE_BITS: u32 = 63;

/// The resolved NCO: formats, the truncation point and the sine ROM.
#[derive(Clone, Debug, PartialEq)]
pub struct Plan {
    /// `u P.P`, cycles: accumulator, frequency word, offset, phase.
    pub phase: Format,
    /// `u P.P` → `u (A+2).(A+2)`, floor, wrap: the phase truncation.
    pub truncation: Point,
    /// `A`.
    pub address_bits: u32,
    /// The truncation error is carried into the next sample's phase.
    pub error_feedback: bool,
    /// `s S.(S−1)`: sine, cosine and ROM words.
    pub output: Format,
    /// Rounding of the ROM words (convergent; a test mutates it).
    pub(crate) rom_rounding: Rounding,
    rom: Vec<i128>,
}

impl Plan {
    /// Validates `spec` and builds the ROM with `libm::sin` (deterministic on every platform).
    ///
    /// # Errors
    /// [`PlanError::Field`] for `A` outside `2..=20`, `S` outside `3..=32`, `P` outside
    /// `A+2..=63`.
    pub fn new(spec: &Spec) -> Result<Plan, PlanError> {
        Self::with_rom_rounding(spec, Rounding::Convergent)
    }

    pub(crate) fn with_rom_rounding(
        spec: &Spec,
        rom_rounding: Rounding,
    ) -> Result<Plan, PlanError> {
        let a = spec.address_bits;
        if !(2..=MAX_ADDRESS_BITS).contains(&a) {
            return Err(field_error(
                "nco",
                "address_bits",
                a,
                format!("2..={MAX_ADDRESS_BITS}"),
            ));
        }
        if !(3..=32).contains(&spec.sine_width) {
            return Err(field_error(
                "nco",
                "sine_width",
                spec.sine_width,
                "3..=32 bits",
            ));
        }
        if !(a + 2..=MAX_PHASE_BITS).contains(&spec.phase_bits) {
            return Err(field_error(
                "nco",
                "phase_bits",
                spec.phase_bits,
                format!(
                    "address_bits + 2 = {}..={MAX_PHASE_BITS} (the truncated phase has A + 2 bits)",
                    a + 2
                ),
            ));
        }
        if spec.error_feedback && spec.phase_bits == a + 2 {
            return Err(field_error(
                "nco",
                "error_feedback",
                true,
                format!(
                    "false when phase_bits = address_bits + 2 = {} (no bits below the truncation to carry)",
                    a + 2
                ),
            ));
        }
        let p = spec.phase_bits;
        let phase = Format::new(false, p, p as i32).expect("1..=63 bits");
        let truncated = Format::new(false, a + 2, (a + 2) as i32).expect("4..=22 bits");
        let output = Format::signed(spec.sine_width, spec.sine_width as i32 - 1).expect("3..=32");
        let truncation = Point {
            from: phase,
            to: truncated,
            rounding: Rounding::Floor,
            overflow: Overflow::Wrap,
        };
        let amplitude = output.max_value();
        let bins = f64::from(1u32 << a);
        let rom = (0..1u32 << a)
            .map(|k| {
                let angle = PI / 2.0 * (f64::from(k) + 0.5) / bins;
                from_f64(
                    amplitude * libm::sin(angle),
                    output,
                    rom_rounding,
                    Overflow::Saturate,
                )
                .expect("finite")
                .code
            })
            .collect();
        Ok(Plan {
            phase,
            truncation,
            address_bits: a,
            error_feedback: spec.error_feedback,
            output,
            rom_rounding,
            rom,
        })
    }

    /// The quarter-wave ROM: `2^A` codes of [`Plan::output`], `ROM[k] = A_nco · sin(π/2 ·
    /// (k + ½)/2^A)` rounded to nearest (ties to even). What `hdl/gyrofx_nco.v` reads.
    pub fn rom_codes(&self) -> &[i128] {
        &self.rom
    }

    /// `A_nco`, the amplitude of the sine: the output format's largest value.
    pub fn amplitude(&self) -> f64 {
        self.output.max_value()
    }

    /// The frequency word of `frequency_hz` at the sample rate `fs_hz`: `f / fs` cycles per
    /// sample in `u P.P`, rounded to nearest (ties to even), wrapped into one cycle (a negative
    /// frequency is `fs` less).
    ///
    /// # Errors
    /// [`PlanError::Field`] when the ratio is not finite.
    pub fn frequency_word(&self, frequency_hz: f64, fs_hz: f64) -> Result<u64, PlanError> {
        self.cycles_word("frequency_hz", frequency_hz / fs_hz)
    }

    /// The offset word of `degrees`: `degrees / 360` cycles in `u P.P`, rounded to nearest
    /// (ties to even), wrapped into one cycle.
    ///
    /// # Errors
    /// [`PlanError::Field`] when `degrees` is not finite.
    pub fn offset_word(&self, degrees: f64) -> Result<u64, PlanError> {
        self.cycles_word("offset_deg", degrees / 360.0)
    }

    fn cycles_word(&self, field: &'static str, cycles: f64) -> Result<u64, PlanError> {
        let q = from_f64(
            cycles - libm::floor(cycles),
            self.phase,
            Rounding::Convergent,
            Overflow::Wrap,
        )
        .map_err(|_| field_error("nco", field, cycles, "a finite number"))?;
        Ok(q.code as u64)
    }

    /// Worst-case `|sin_fixed − sin_float|` (and the same for cos), in output LSB: the ROM
    /// rounding plus the phase truncation (see the module doc).
    pub fn error_bound_lsb(&self) -> f64 {
        let amplitude_lsb = self.output.max_code() as f64;
        let half_bin_rad = PI / crate::fx::pow2(self.address_bits as i32 + 2);
        // With error feedback the carried error adds up to another half bin.
        let bins = if self.error_feedback { 2.0 } else { 1.0 };
        self.rom_rounding.max_error_lsb()
            + amplitude_lsb * half_bin_rad * bins
            + super::f64_rounding(16.0 * amplitude_lsb)
    }

    /// Parameters of `hdl/gyrofx_nco.v`: `PHASE_W`, `ADDR_W`, `SIN_W`, `ERROR_FEEDBACK`.
    pub fn rtl_parameters(&self) -> Vec<RtlParameter> {
        vec![
            ("PHASE_W", i128::from(self.phase.width)),
            ("ADDR_W", i128::from(self.address_bits)),
            ("SIN_W", i128::from(self.output.width)),
            ("ERROR_FEEDBACK", i128::from(self.error_feedback)),
        ]
    }
}

/// One output of the NCO: the codes of the sine and cosine (output format).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Reference {
    /// `sin` code.
    pub sin: i64,
    /// `cos` code.
    pub cos: i64,
}

/// The bit-accurate NCO.
#[derive(Clone, Debug)]
pub struct FixedNco {
    rom: Vec<i64>,
    /// `P − A − 2`: the truncation is a floor by this shift, and cannot overflow.
    truncation_shift: u32,
    mask: u64,
    address_bits: u32,
    /// With error feedback: the last truncation error, phase LSB in `[−2^(P−A−3), 2^(P−A−3))`.
    residue: Option<i64>,
    /// The phase bits below the truncation, `2^(P−A−2) − 1`.
    below_truncation: u64,
    /// Half a bin, `2^(P−A−3)` phase LSB (0 without error feedback).
    half_bin: i64,
    acc: u64,
}

impl FixedNco {
    /// The NCO of `plan`, accumulator at 0.
    pub fn new(plan: &Plan) -> Self {
        FixedNco {
            rom: plan.rom.iter().map(|c| *c as i64).collect(),
            truncation_shift: plan.phase.width - (plan.address_bits + 2),
            mask: u64::MAX >> (64 - plan.phase.width),
            address_bits: plan.address_bits,
            residue: plan.error_feedback.then_some(0),
            below_truncation: (1u64 << (plan.phase.width - plan.address_bits - 2)) - 1,
            half_bin: if plan.error_feedback {
                1 << (plan.phase.width - plan.address_bits - 3)
            } else {
                0
            },
            acc: 0,
        }
    }

    /// Synchronous reset: the accumulator (and the carried error) to 0.
    pub fn reset(&mut self) {
        self.acc = 0;
        self.residue = self.residue.map(|_| 0);
    }

    /// The accumulator (`u P.P` cycles): the phase of the next sample without offset.
    pub fn accumulator(&self) -> u64 {
        self.acc
    }

    /// One sample: the references at `accumulator + offset`, then the accumulator advances by
    /// `freq`. `freq` and `offset` are `u P.P` codes (higher bits are ignored, as the RTL's
    /// ports have only `P`).
    #[inline]
    pub fn step(&mut self, freq: u64, offset: u64) -> Reference {
        let mut phase = self.acc.wrapping_add(offset) & self.mask;
        self.acc = self.acc.wrapping_add(freq) & self.mask;
        if let Some(residue) = self.residue.as_mut() {
            // The carried error, then the new one: the phase below the truncation, less
            // half a bin (the ROM holds bin centres), in [−half, half).
            phase = phase.wrapping_add(*residue as u64) & self.mask;
            *residue = (phase & self.below_truncation) as i64 - self.half_bin;
        }
        // The plan's truncation point: floor of the unsigned phase into A + 2 bits.
        let t = (phase >> self.truncation_shift) as u32;
        let quarter = 1u32 << self.address_bits;
        Reference {
            sin: self.lookup(t),
            cos: self.lookup(t.wrapping_add(quarter)),
        }
    }

    /// `±ROM[...]` of the truncated phase `t` (only its low `A + 2` bits count).
    #[inline(always)]
    fn lookup(&self, t: u32) -> i64 {
        let a = self.address_bits;
        let index = t & ((1 << a) - 1);
        let mirrored = (t >> a) & 1 == 1;
        let negative = (t >> (a + 1)) & 1 == 1;
        let address = if mirrored {
            (1 << a) - 1 - index
        } else {
            index
        };
        let magnitude = self.rom[address as usize];
        if negative {
            -magnitude
        } else {
            magnitude
        }
    }

    /// Runs a block: one output per `(freq, offset)` pair.
    ///
    /// # Panics
    /// When the slices differ in length.
    pub fn process(&mut self, freq: &[u64], offset: &[u64], out: &mut [Reference]) {
        assert!(
            freq.len() == offset.len() && freq.len() == out.len(),
            "input and output blocks differ in length"
        );
        for ((f, o), r) in freq.iter().zip(offset).zip(out.iter_mut()) {
            *r = self.step(*f, *o);
        }
    }
}

/// The float twin: the same integer accumulator, and `A_nco · sin`, `A_nco · cos` of the exact
/// phase (`libm`), as reals.
#[derive(Clone, Debug)]
pub struct FloatNco {
    amplitude: f64,
    mask: u64,
    cycle: f64,
    acc: u64,
}

impl FloatNco {
    /// The twin of `plan`'s NCO.
    pub fn new(plan: &Plan) -> Self {
        FloatNco {
            amplitude: plan.amplitude(),
            mask: u64::MAX >> (64 - plan.phase.width),
            cycle: crate::fx::pow2(plan.phase.width as i32),
            acc: 0,
        }
    }

    /// Accumulator to 0.
    pub fn reset(&mut self) {
        self.acc = 0;
    }

    /// One sample: `[sin, cos]` (reals, amplitude `A_nco`).
    pub fn step(&mut self, freq: u64, offset: u64) -> [f64; 2] {
        let phase = self.acc.wrapping_add(offset) & self.mask;
        self.acc = self.acc.wrapping_add(freq) & self.mask;
        let angle = 2.0 * PI * (phase as f64 / self.cycle);
        [
            self.amplitude * libm::sin(angle),
            self.amplitude * libm::cos(angle),
        ]
    }
}

#[cfg(test)]
mod tests;
