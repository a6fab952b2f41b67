//! [`FloatMeanFilter`]: the float golden model of the mean filter.

use super::plan::Plan;

/// The float mean filter: the same blocks, the same quantized threshold `r`, an exact mean of
/// the kept samples (no reciprocal ROM, no output quantization).
#[derive(Clone, Debug)]
pub struct FloatMeanFilter {
    window: usize,
    threshold: f64,
    block: Vec<f64>,
}

impl FloatMeanFilter {
    /// The golden model of `plan` (its window and quantized threshold).
    pub fn new(plan: &Plan) -> Self {
        FloatMeanFilter::with_threshold(plan.window, plan.threshold_dps())
    }

    /// The filter with window `window` and threshold `threshold_dps` as given (the "ideal"
    /// model: `r` unquantized).
    pub fn with_threshold(window: u32, threshold_dps: f64) -> Self {
        FloatMeanFilter {
            window: window as usize,
            threshold: threshold_dps,
            block: Vec::with_capacity(window as usize),
        }
    }

    /// Drops the samples of the current block.
    pub fn reset(&mut self) {
        self.block.clear();
    }

    /// Takes one sample (°/s); after a block's last, returns its kept mean (°/s) and the number
    /// of samples kept (0: all rejected, plain mean).
    pub fn step(&mut self, x: f64) -> Option<(f64, u32)> {
        self.block.push(x);
        if self.block.len() < self.window {
            return None;
        }
        let n = self.window as f64;
        let sum: f64 = self.block.iter().sum();
        // |x − sum/n| > r as n·x − sum against n·r: the same test as the fixed model, exact in
        // f64 for inputs of up to ~53 − log2(L) significant bits.
        let kept: Vec<f64> = self
            .block
            .iter()
            .copied()
            .filter(|x| (n * x - sum).abs() <= n * self.threshold)
            .collect();
        self.block.clear();
        if kept.is_empty() {
            Some((sum / n, 0))
        } else {
            Some((
                kept.iter().sum::<f64>() / kept.len() as f64,
                kept.len() as u32,
            ))
        }
    }
}
