//! The bit-accurate CIC decimator and compensator.

use super::*;

/// Two's-complement words the integrators and combs run in: `i64` when `B ≤ 64`, else
/// `i128`. A comb output fits `B` bits, so computing mod `2^64` (or `2^128`) gives it exactly.
pub(super) trait Word: Copy + Default {
    fn wrapping_add(self, other: Self) -> Self;
    fn wrapping_sub(self, other: Self) -> Self;
    fn from_code(code: i64) -> Self;
    fn to_code(self) -> i128;
}

impl Word for i64 {
    #[inline(always)]
    fn wrapping_add(self, other: Self) -> Self {
        i64::wrapping_add(self, other)
    }
    #[inline(always)]
    fn wrapping_sub(self, other: Self) -> Self {
        i64::wrapping_sub(self, other)
    }
    #[inline(always)]
    fn from_code(code: i64) -> Self {
        code
    }
    #[inline(always)]
    fn to_code(self) -> i128 {
        i128::from(self)
    }
}

impl Word for i128 {
    #[inline(always)]
    fn wrapping_add(self, other: Self) -> Self {
        i128::wrapping_add(self, other)
    }
    #[inline(always)]
    fn wrapping_sub(self, other: Self) -> Self {
        i128::wrapping_sub(self, other)
    }
    #[inline(always)]
    fn from_code(code: i64) -> Self {
        i128::from(code)
    }
    #[inline(always)]
    fn to_code(self) -> i128 {
        self
    }
}

/// Integrators `v_1..v_N` and each comb's last two inputs, in fixed arrays (no allocation).
#[derive(Clone, Debug, Default)]
pub(super) struct Registers<W> {
    integrators: [W; MAX_STAGES as usize],
    combs: [[W; 2]; MAX_STAGES as usize],
}

impl<W: Word> Registers<W> {
    /// The registered cascade: every stage adds its predecessor's value of the last sample.
    #[inline(always)]
    fn integrate(&mut self, x: i64, stages: usize) {
        for j in (1..stages).rev() {
            self.integrators[j] = self.integrators[j].wrapping_add(self.integrators[j - 1]);
        }
        self.integrators[0] = self.integrators[0].wrapping_add(W::from_code(x));
    }

    /// The comb chain on `v_N`; returns `w_N`, exact.
    #[inline(always)]
    fn comb(&mut self, stages: usize, delay: usize) -> i128 {
        let mut w = self.integrators[stages - 1];
        for d in &mut self.combs[..stages] {
            let out = w.wrapping_sub(d[delay - 1]);
            d[1] = d[0];
            d[0] = w;
            w = out;
        }
        w.to_code()
    }

    fn integrator_codes(&self, stages: usize, register: Format) -> Vec<i128> {
        self.integrators[..stages]
            .iter()
            .map(|v| register.wrap(v.to_code()))
            .collect()
    }
}

#[derive(Clone, Debug)]
pub(super) enum Engine {
    Narrow(Registers<i64>),
    Wide(Registers<i128>),
}

/// Overflow counts of the CIC's quantization points.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct OverflowCounts {
    /// Scaled comb outputs that did not fit the CIC output format.
    pub cic: u64,
    /// Compensator sums that did not fit the output format.
    pub output: u64,
}

/// The bit-accurate CIC decimator and compensator.
#[derive(Clone, Debug)]
pub struct FixedCic {
    pub(super) engine: Engine,
    register: Format,
    stages: usize,
    delay: usize,
    decimation: u32,
    phase: u32,
    cic: Quantizer,
    output: Quantizer,
    taps: [i64; MAX_TAPS as usize],
    tap_count: usize,
    /// `c[m], c[m−1], …` (CIC output codes).
    line: [i64; MAX_TAPS as usize],
}

impl FixedCic {
    /// The decimator of `plan`, every register at 0, at the start of a decimation period.
    pub fn new(plan: &Plan) -> Self {
        let engine = if plan.register.width <= 64 {
            Engine::Narrow(Registers::default())
        } else {
            Engine::Wide(Registers::default())
        };
        let mut taps = [0i64; MAX_TAPS as usize];
        for (t, h) in taps.iter_mut().zip(&plan.taps) {
            *t = h.code as i64;
        }
        FixedCic {
            engine,
            register: plan.register,
            stages: plan.stages as usize,
            delay: plan.differential_delay as usize,
            decimation: plan.decimation,
            phase: 0,
            cic: plan.cic.quantizer(),
            output: plan.output.quantizer(),
            taps,
            tap_count: plan.taps.len(),
            line: [0; MAX_TAPS as usize],
        }
    }

    /// Synchronous reset: registers, delay line and decimation phase to 0 (not the counts).
    pub fn reset(&mut self) {
        self.engine = match self.engine {
            Engine::Narrow(_) => Engine::Narrow(Registers::default()),
            Engine::Wide(_) => Engine::Wide(Registers::default()),
        };
        self.line = [0; MAX_TAPS as usize];
        self.phase = 0;
    }

    /// One input sample (input format code); the output code (output format) after every
    /// `R`-th.
    #[inline]
    pub fn step(&mut self, x: i64) -> Option<i64> {
        let (stages, delay) = (self.stages, self.delay);
        match &mut self.engine {
            Engine::Narrow(r) => r.integrate(x, stages),
            Engine::Wide(r) => r.integrate(x, stages),
        }
        self.phase += 1;
        if self.phase < self.decimation {
            return None;
        }
        self.phase = 0;
        let w = match &mut self.engine {
            Engine::Narrow(r) => r.comb(stages, delay),
            Engine::Wide(r) => r.comb(stages, delay),
        };
        let c = self.cic.apply(w) as i64;
        let n = self.tap_count;
        self.line.copy_within(0..n - 1, 1);
        self.line[0] = c;
        let sum: i128 = self.taps[..n]
            .iter()
            .zip(&self.line[..n])
            .map(|(h, c)| i128::from(*h) * i128::from(*c))
            .sum();
        Some(self.output.apply(sum) as i64)
    }

    /// Runs a block of input samples, writing each output to the front of `out`; returns how
    /// many were written.
    ///
    /// # Panics
    /// When `out` is too short for the outputs of `x`.
    pub fn process(&mut self, x: &[i64], out: &mut [i64]) -> usize {
        let mut written = 0;
        for xi in x {
            if let Some(y) = self.step(*xi) {
                out[written] = y;
                written += 1;
            }
        }
        written
    }

    /// The compensator's delay line `c[m], c[m−1], …` (CIC output format codes), newest first:
    /// what the last output was computed from.
    pub fn compensator_line(&self) -> &[i64] {
        &self.line[..self.tap_count]
    }

    /// Input samples since the last output (or reset): `0..R`.
    pub fn phase(&self) -> u32 {
        self.phase
    }

    /// The integrator registers `v_1..v_N` as the RTL holds them (`B`-bit codes).
    pub fn integrators(&self) -> Vec<i128> {
        match &self.engine {
            Engine::Narrow(r) => r.integrator_codes(self.stages, self.register),
            Engine::Wide(r) => r.integrator_codes(self.stages, self.register),
        }
    }

    /// Counts since construction.
    pub fn overflow_counts(&self) -> OverflowCounts {
        OverflowCounts {
            cic: self.cic.overflow_count,
            output: self.output.overflow_count,
        }
    }
}
