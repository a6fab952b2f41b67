//! [`FixedArKf`]: the bit-accurate AR(1) KF.

use super::plan::Plan;
use crate::fx::requantize;

/// The fixed-point AR(1) KF: `x̂0 = z0`, then `x̂_k = Q(a_k·x̂_{k−1} + K_k·z_k)` (exact sum,
/// one quantizer into the state format) with `(a_k, K_k)` from the plan's schedule, and the
/// output `Q(x̂)` in the output format.
#[derive(Clone, Debug)]
pub struct FixedArKf {
    plan: Plan,
    state: i128,
    steps: usize,
    overflows: u64,
}

impl FixedArKf {
    /// The filter before its first sample.
    pub fn new(plan: &Plan) -> Self {
        FixedArKf {
            plan: plan.clone(),
            state: 0,
            steps: 0,
            overflows: 0,
        }
    }

    /// Quantizer overflows so far (state and output).
    pub fn overflows(&self) -> u64 {
        self.overflows
    }

    /// Filters one sample (input code); returns the output code.
    pub fn step(&mut self, z: i64) -> i64 {
        let p = &self.plan;
        let z = i128::from(z);
        if self.steps == 0 {
            self.state = z << (p.state.frac - p.input.frac);
        } else {
            let [a, k] = p.rom[(self.steps - 1).min(p.rom.len() - 1)];
            let sum = ((a * self.state) << (p.sum_frac - p.a_format.frac - p.state.frac))
                + ((k * z) << (p.sum_frac - p.k_format.frac - p.input.frac));
            let q = requantize(sum, p.sum_frac, p.state, p.rounding, p.overflow);
            self.overflows += u64::from(q.overflowed);
            self.state = q.code;
        }
        self.steps += 1;
        let q = requantize(self.state, p.state.frac, p.output, p.rounding, p.overflow);
        self.overflows += u64::from(q.overflowed);
        q.code as i64
    }
}
