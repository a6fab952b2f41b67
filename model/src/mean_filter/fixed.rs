//! [`FixedMeanFilter`]: the bit-accurate mean filter with gross-error rejection.

use super::plan::Plan;
use crate::fx::requantize;

/// One block's result.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct BlockMean {
    /// The mean of the kept samples (output format code).
    pub y: i64,
    /// Samples kept; 0 when every sample was rejected (then `y` is the plain mean).
    pub kept: u32,
    /// The output quantizer overflowed (wrapped or saturated).
    pub overflowed: bool,
}

/// The fixed-point mean filter: collects `L` samples, then keeps those within `r` of the block
/// mean and outputs their mean, exactly as the module docs and the RTL do.
#[derive(Clone, Debug)]
pub struct FixedMeanFilter {
    plan: Plan,
    block: Vec<i64>,
}

impl FixedMeanFilter {
    /// The filter at the start of a block.
    pub fn new(plan: &Plan) -> Self {
        FixedMeanFilter {
            plan: plan.clone(),
            block: Vec::with_capacity(plan.window as usize),
        }
    }

    /// Drops the samples of the current block (the RTL's reset).
    pub fn reset(&mut self) {
        self.block.clear();
    }

    /// Samples of the current block so far.
    pub fn phase(&self) -> usize {
        self.block.len()
    }

    /// Takes one sample (input format code); returns the block's result after its `L`-th.
    pub fn step(&mut self, x: i64) -> Option<BlockMean> {
        self.block.push(x);
        if self.block.len() < self.plan.window as usize {
            return None;
        }
        let result = block_mean(&self.plan, &self.block);
        self.block.clear();
        Some(result)
    }
}

/// The result of one whole block of `plan.window` samples.
///
/// # Panics
/// When `block` does not hold exactly `plan.window` samples.
pub fn block_mean(plan: &Plan, block: &[i64]) -> BlockMean {
    assert_eq!(block.len(), plan.window as usize, "one whole block");
    let window = i128::from(plan.window);
    let sum: i128 = block.iter().map(|&x| i128::from(x)).sum();
    let (mut kept, mut kept_sum) = (0u32, 0i128);
    for &x in block {
        let deviation = window * i128::from(x) - sum;
        if deviation.abs() <= plan.scaled_threshold {
            kept += 1;
            kept_sum += i128::from(x);
        }
    }
    let (address, total) = if kept == 0 {
        (0, sum)
    } else {
        (kept as usize, kept_sum)
    };
    quantized_mean(plan, total * plan.rom[address], kept)
}

/// The block's result from its exact product `operand · ROM[kept]` (format `plan.product`):
/// the one quantization point.
pub(super) fn quantized_mean(plan: &Plan, product: i128, kept: u32) -> BlockMean {
    let q = requantize(
        product,
        plan.product.frac,
        plan.output,
        plan.rounding,
        plan.overflow,
    );
    BlockMean {
        y: q.code as i64,
        kept,
        overflowed: q.overflowed,
    }
}
