//! The float twin of the CIC decimator and compensator.

use super::*;

/// The float twin: the CIC as one direct-form FIR (its integer impulse response, `N − 1`
/// samples late as the registered cascade is), times `2^−shift`, then the compensator with
/// the quantized taps, in f64.
#[derive(Clone, Debug)]
pub struct FloatCic {
    impulse: Vec<f64>,
    delay: usize,
    decimation: u32,
    history: Vec<f64>,
    newest: usize,
    phase: u32,
    taps: Vec<f64>,
    line: Vec<f64>,
}

impl FloatCic {
    /// The twin of `plan`'s decimator.
    pub fn new(plan: &Plan) -> Self {
        let box_length = (plan.decimation * plan.differential_delay) as usize;
        // (1 + z^-1 + ... + z^-(RM-1))^N by running sums, in exact integers.
        let mut h: Vec<u128> = vec![1];
        for _ in 0..plan.stages {
            let mut next = vec![0u128; h.len() + box_length - 1];
            let mut running = 0u128;
            for (i, slot) in next.iter_mut().enumerate() {
                if i < h.len() {
                    running += h[i];
                }
                if i >= box_length {
                    running -= h[i - box_length];
                }
                *slot = running;
            }
            h = next;
        }
        let scale = crate::fx::pow2(-(plan.shift as i32));
        let impulse: Vec<f64> = h.iter().map(|v| *v as f64 * scale).collect();
        let delay = plan.stages as usize - 1;
        FloatCic {
            history: vec![0.0; impulse.len() + delay],
            impulse,
            delay,
            decimation: plan.decimation,
            newest: 0,
            phase: 0,
            taps: plan.tap_values(),
            line: vec![0.0; plan.taps.len()],
        }
    }

    /// History, delay line and phase to 0.
    pub fn reset(&mut self) {
        self.history.iter_mut().for_each(|v| *v = 0.0);
        self.line.iter_mut().for_each(|v| *v = 0.0);
        self.newest = 0;
        self.phase = 0;
    }

    /// One input (real); the output (real) after every `R`-th.
    pub fn step(&mut self, x: f64) -> Option<f64> {
        let len = self.history.len();
        self.newest = (self.newest + 1) % len;
        self.history[self.newest] = x;
        self.phase += 1;
        if self.phase < self.decimation {
            return None;
        }
        self.phase = 0;
        let c: f64 = self
            .impulse
            .iter()
            .enumerate()
            .map(|(j, h)| h * self.history[(self.newest + 2 * len - self.delay - j) % len])
            .sum();
        self.line.rotate_right(1);
        self.line[0] = c;
        Some(self.taps.iter().zip(&self.line).map(|(h, c)| h * c).sum())
    }
}
