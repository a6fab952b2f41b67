//! [`FloatArKf`]: the float golden model of the AR(1) KF.

use super::plan::Plan;

/// The float AR(1) KF with the plan's quantized coefficients (or, with
/// [`FloatArKf::designed`], the designed ones): `x̂0 = z0`, `x̂_k = a_k·x̂_{k−1} + K_k·z_k`.
#[derive(Clone, Debug)]
pub struct FloatArKf {
    coefficients: Vec<(f64, f64)>,
    state: f64,
    steps: usize,
}

impl FloatArKf {
    /// With the plan's quantized schedule.
    pub fn new(plan: &Plan) -> Self {
        FloatArKf {
            coefficients: (0..plan.rom.len()).map(|i| plan.quantized(i)).collect(),
            state: 0.0,
            steps: 0,
        }
    }

    /// With the designed (unquantized) schedule.
    pub fn designed(plan: &Plan) -> Self {
        FloatArKf {
            coefficients: plan
                .gains
                .iter()
                .map(|k| ((1.0 - k) * plan.phi, *k))
                .collect(),
            state: 0.0,
            steps: 0,
        }
    }

    /// Filters one sample.
    pub fn step(&mut self, z: f64) -> f64 {
        if self.steps == 0 {
            self.state = z;
        } else {
            let (a, k) = self.coefficients[(self.steps - 1).min(self.coefficients.len() - 1)];
            self.state = a * self.state + k * z;
        }
        self.steps += 1;
        self.state
    }
}
