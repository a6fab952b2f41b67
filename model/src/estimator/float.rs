//! [`FloatEstimator`]: the f64 golden model of the estimator, same structure as the fixed one.

use crate::sequencer::Slot;

use super::plan::Plan;

/// One sample of the float estimator (°/s).
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub struct FloatSample {
    /// Calibrated outputs.
    pub out: [f64; 2],
    /// Valid flags.
    pub valid: [bool; 2],
    /// Combined output.
    pub combined: f64,
    /// At least one valid.
    pub combined_valid: bool,
    /// Bias estimates used for this sample.
    pub bias: [f64; 2],
}

/// The estimator in f64 with given gains (rows over `[mA0, mB0, …]`) and reciprocal: the
/// plan's quantized ones to check the fixed model's arithmetic, or the designed ones.
#[derive(Clone, Debug)]
pub struct FloatEstimator {
    gains: [Vec<f64>; 2],
    reciprocal: f64,
    smoothing: f64,
    accumulator: [f64; 2],
    means: [Vec<f64>; 2],
    bias: [f64; 2],
    estimated: bool,
}

impl FloatEstimator {
    /// With the plan's quantized gains and reciprocal.
    pub fn quantized(plan: &Plan) -> Self {
        Self::with(plan, plan.quantized_gains(), plan.quantized_reciprocal())
    }

    /// With the designed gains and the exact reciprocal.
    pub fn ideal(plan: &Plan) -> Self {
        Self::with(
            plan,
            plan.gains.clone(),
            1.0 / plan.schedule.valid_count() as f64,
        )
    }

    fn with(plan: &Plan, gains: [Vec<f64>; 2], reciprocal: f64) -> Self {
        let w = plan.schedule.intervals;
        FloatEstimator {
            gains,
            reciprocal,
            smoothing: crate::fx::pow2(-(plan.smoothing_shift as i32)),
            accumulator: [0.0; 2],
            means: [vec![0.0; w], vec![0.0; w]],
            bias: [0.0; 2],
            estimated: false,
        }
    }

    /// Clears the state.
    pub fn reset(&mut self) {
        self.accumulator = [0.0; 2];
        for m in &mut self.means {
            m.iter_mut().for_each(|v| *v = 0.0);
        }
        self.bias = [0.0; 2];
        self.estimated = false;
    }

    /// One sample: `y` in °/s.
    pub fn step(&mut self, slot: &Slot, y: [f64; 2]) -> FloatSample {
        let modes = [f64::from(slot.mode_a), f64::from(slot.mode_b)];
        let valid = [!slot.blank_a, !slot.blank_b];
        let bias_used = self.bias;
        let out = [
            y[0] - modes[0] * self.bias[0],
            y[1] - modes[1] * self.bias[1],
        ];
        let combined = match valid {
            [true, true] => (out[0] + out[1]) / 2.0,
            [true, false] => out[0],
            [false, true] => out[1],
            [false, false] => 0.0,
        };
        let done = [slot.done_a, slot.done_b];
        let interval = [slot.interval_a, slot.interval_b];
        for g in 0..2 {
            if valid[g] {
                self.accumulator[g] += y[g];
            }
            if done[g] {
                self.means[g][interval[g]] = self.accumulator[g] * self.reciprocal;
                self.accumulator[g] = 0.0;
            }
        }
        if slot.window_done {
            for g in 0..2 {
                let new: f64 = self.gains[g]
                    .iter()
                    .enumerate()
                    .map(|(j, c)| c * self.means[j % 2][j / 2])
                    .sum();
                self.bias[g] = if self.estimated {
                    self.bias[g] + self.smoothing * (new - self.bias[g])
                } else {
                    new
                };
            }
            self.estimated = true;
        }
        FloatSample {
            out,
            valid,
            combined,
            combined_valid: valid[0] || valid[1],
            bias: bias_used,
        }
    }

    /// Current estimates, °/s.
    pub fn bias(&self) -> [f64; 2] {
        self.bias
    }
}
