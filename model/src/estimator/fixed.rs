//! [`FixedEstimator`]: the bit-accurate bias estimator with calibration and combination.

use crate::fx::{mode, Quantizer, Rounding};
use crate::sequencer::Slot;

use super::plan::Plan;

/// What the estimator produces for one sample.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub struct Sample {
    /// Calibrated outputs `out_A`, `out_B` (calibrated format).
    pub out: [i64; 2],
    /// Each gyro's sample is valid (not blanked).
    pub valid: [bool; 2],
    /// Mean of the valid calibrated outputs (calibrated format).
    pub combined: i64,
    /// At least one gyro is valid.
    pub combined_valid: bool,
    /// Bias estimates used for this sample (bias format).
    pub bias: [i64; 2],
    /// A window has produced an estimate since reset.
    pub estimated: bool,
}

/// Overflow counts per quantization point.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct OverflowCounts {
    /// Interval means of A and B.
    pub mean: [u64; 2],
    /// New bias estimates of A and B (and their smoothing).
    pub bias: [u64; 2],
    /// Calibrated outputs of A and B, on valid samples only: a blanked sample's output is
    /// computed but used nowhere, and right after a switch the resonator loop's transient can
    /// saturate it by design.
    pub calibrated: [u64; 2],
    /// Combined output.
    pub combined: u64,
}

/// The fixed-point estimator: accumulate valid samples per interval, latch the interval means,
/// at each window end `b_new = Q(G m)` (smoothed), and calibrate every sample with the
/// estimates of the previous windows.
#[derive(Clone, Debug)]
pub struct FixedEstimator {
    plan: Plan,
    accumulator: [i128; 2],
    means: [Vec<i128>; 2],
    bias: [i128; 2],
    estimated: bool,
    mean_q: [Quantizer; 2],
    bias_q: [Quantizer; 2],
    smooth_q: [Quantizer; 2],
    calibrated_q: [Quantizer; 2],
    combined_q: Quantizer,
    /// `y − p·b` and `out_A + out_B` fit 62 bits: the 64-bit path applies.
    narrow: bool,
    /// Shifts aligning `y` and `b` to `calibration_frac`.
    y_shift: u32,
    b_shift: u32,
}

impl FixedEstimator {
    /// The model of `plan`, in its reset state.
    pub fn new(plan: &Plan) -> Self {
        let q = |from_frac, to| Quantizer::new(from_frac, to, plan.rounding, plan.overflow);
        let calibration_frac = plan.input.frac.max(plan.bias.frac);
        let w = plan.schedule.intervals;
        FixedEstimator {
            plan: plan.clone(),
            accumulator: [0; 2],
            means: [vec![0; w], vec![0; w]],
            bias: [0; 2],
            estimated: false,
            mean_q: [0, 1].map(|_| q(plan.input.frac + plan.reciprocal.frac, plan.mean)),
            bias_q: [0, 1].map(|_| q(plan.dot.frac, plan.bias)),
            smooth_q: [0, 1].map(|_| q(plan.bias.frac + plan.smoothing_shift as i32, plan.bias)),
            calibrated_q: [0, 1].map(|_| q(calibration_frac, plan.calibrated)),
            combined_q: q(plan.calibrated.frac + 1, plan.calibrated),
            y_shift: (calibration_frac - plan.input.frac) as u32,
            b_shift: (calibration_frac - plan.bias.frac) as u32,
            narrow: {
                let int = (plan.input.int_bits()).max(plan.bias.int_bits()) + 1;
                int + calibration_frac <= 62 && plan.calibrated.width <= 61
            },
        }
    }

    /// Synchronous reset: clears accumulators, means and estimates (not the overflow counts).
    pub fn reset(&mut self) {
        self.accumulator = [0; 2];
        for m in &mut self.means {
            m.iter_mut().for_each(|v| *v = 0);
        }
        self.bias = [0; 2];
        self.estimated = false;
    }

    /// One sample: the sequencer's `slot` and the gyro codes `y` (input format).
    pub fn step(&mut self, slot: &Slot, y: [i64; 2]) -> Sample {
        match self.plan.rounding {
            Rounding::Floor => self.step_mode::<{ mode::FLOOR }>(slot, y),
            Rounding::Ceil => self.step_mode::<{ mode::CEIL }>(slot, y),
            Rounding::Zero => self.step_mode::<{ mode::ZERO }>(slot, y),
            Rounding::Nearest => self.step_mode::<{ mode::NEAREST }>(slot, y),
            Rounding::Round => self.step_mode::<{ mode::ROUND }>(slot, y),
            Rounding::Convergent => self.step_mode::<{ mode::CONVERGENT }>(slot, y),
        }
    }

    /// [`FixedEstimator::step`] with the plan's rounding mode fixed at compile time.
    #[inline(always)]
    pub(crate) fn step_mode<const MODE: u8>(&mut self, slot: &Slot, y: [i64; 2]) -> Sample {
        let modes = [slot.mode_a, slot.mode_b];
        let valid = [!slot.blank_a, !slot.blank_b];
        let bias_used = [self.bias[0] as i64, self.bias[1] as i64];

        // Calibration with the estimates of earlier windows.
        let mut out = [0i64; 2];
        if self.narrow {
            for g in 0..2 {
                let y_aligned = y[g] << self.y_shift;
                let b_aligned = (self.bias[g] as i64) << self.b_shift;
                let corrected = if modes[g] > 0 {
                    y_aligned - b_aligned
                } else {
                    y_aligned + b_aligned
                };
                let count = self.calibrated_q[g].overflow_count;
                out[g] = self.calibrated_q[g].apply_mode_i64::<MODE>(corrected);
                if !valid[g] {
                    self.calibrated_q[g].overflow_count = count;
                }
            }
        }
        for g in (0..2).filter(|_| !self.narrow) {
            let y_aligned = i128::from(y[g]) << self.y_shift;
            let b_aligned = self.bias[g] << self.b_shift;
            let corrected = if modes[g] > 0 {
                y_aligned - b_aligned
            } else {
                y_aligned + b_aligned
            };
            let count = self.calibrated_q[g].overflow_count;
            out[g] = self.calibrated_q[g].apply_mode::<MODE>(corrected) as i64;
            if !valid[g] {
                self.calibrated_q[g].overflow_count = count;
            }
        }
        let combined = match valid {
            [true, true] if self.narrow => self.combined_q.apply_mode_i64::<MODE>(out[0] + out[1]),
            [true, true] => self
                .combined_q
                .apply_mode::<MODE>(i128::from(out[0]) + i128::from(out[1]))
                as i64,
            [true, false] => out[0],
            [false, true] => out[1],
            [false, false] => 0,
        };

        // Interval means.
        let done = [slot.done_a, slot.done_b];
        let interval = [slot.interval_a, slot.interval_b];
        for g in 0..2 {
            if valid[g] {
                self.accumulator[g] += i128::from(y[g]);
            }
            if done[g] {
                let scaled = self.accumulator[g] * self.plan.reciprocal_code;
                self.means[g][interval[g]] = self.mean_q[g].apply_mode::<MODE>(scaled);
                self.accumulator[g] = 0;
            }
        }

        // Window: u = G m over m = [mA0, mB0, mA1, mB1, …], applied from the next sample.
        if slot.window_done {
            for g in 0..2 {
                let dot: i128 = self.plan.rom[g]
                    .iter()
                    .enumerate()
                    .map(|(j, c)| c * self.means[j % 2][j / 2])
                    .sum();
                let new = self.bias_q[g].apply_mode::<MODE>(dot);
                self.bias[g] = if self.estimated && self.plan.smoothing_shift > 0 {
                    let s = self.plan.smoothing_shift;
                    let smoothed = (self.bias[g] << s) + (new - self.bias[g]);
                    self.smooth_q[g].apply_mode::<MODE>(smoothed)
                } else {
                    new
                };
            }
            self.estimated = true;
        }

        Sample {
            out,
            valid,
            combined,
            combined_valid: valid[0] || valid[1],
            bias: bias_used,
            estimated: self.estimated,
        }
    }

    /// Current bias estimates (bias format).
    pub fn bias(&self) -> [i128; 2] {
        self.bias
    }

    /// Whether a window has produced an estimate since reset.
    pub fn estimated(&self) -> bool {
        self.estimated
    }

    /// Overflow counts since construction.
    pub fn overflow_counts(&self) -> OverflowCounts {
        let c = |q: &[Quantizer; 2]| [q[0].overflow_count, q[1].overflow_count];
        OverflowCounts {
            mean: c(&self.mean_q),
            bias: [
                self.bias_q[0].overflow_count + self.smooth_q[0].overflow_count,
                self.bias_q[1].overflow_count + self.smooth_q[1].overflow_count,
            ],
            calibrated: c(&self.calibrated_q),
            combined: self.combined_q.overflow_count,
        }
    }
}
