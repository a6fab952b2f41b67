//! The port-level golden model of the whole chain (`gyrofx_top`).

use super::{check_bw_sel, check_code, PortResult};
use gyrofx_model::chain;
use gyrofx_model::chain::FixedChain;

/// The chain's output ports (`gyrofx_top`), in the RTL's order.
pub const CHAIN_OUTPUTS: [&str; 7] = [
    "mode_a",
    "mode_b",
    "out_valid",
    "rate_out",
    "bias_a",
    "bias_b",
    "estimated",
];

/// The whole chain (`gyrofx_top`): sequencer, estimator, calibration, KF.
#[derive(Clone, Debug)]
pub struct Chain {
    plan: chain::Plan,
    model: FixedChain,
}

impl Chain {
    /// Saturations and wraps per quantization point since it was made ([`Overflows`]).
    pub fn overflows(&self) -> super::Overflows {
        super::overflows::chain(&self.model)
    }

    /// Its ports as the vector files carry them ([`super::ports`]).
    pub fn ports(&self) -> Vec<super::ports::Port> {
        super::ports::chain(&self.plan)
    }

    /// From reset.
    pub fn new(plan: &chain::Plan) -> Chain {
        Chain {
            plan: plan.clone(),
            model: FixedChain::new(plan),
        }
    }

    /// The plan.
    pub fn plan(&self) -> &chain::Plan {
        &self.plan
    }

    /// The synchronous reset.
    pub fn reset(&mut self) {
        self.model.reset();
    }

    /// The modes `[mode_a, mode_b]` (1 normal, 0 reverse) of the next sample.
    pub fn next_modes(&self) -> [i64; 2] {
        let [a, b] = self.model.upcoming_modes();
        [i64::from(a > 0), i64::from(b > 0)]
    }

    /// The checked inputs of one sample: `(y, bw_sel)`.
    ///
    /// # Errors
    /// A sample outside the input format or `bw_sel` beyond the ROM.
    pub fn check(&self, y_a: i64, y_b: i64, bw_sel: i64, suffix: &str) -> PortResult<usize> {
        let input = self.plan.estimator.input;
        check_code(y_a, input, &format!("y_a{suffix}"))?;
        check_code(y_b, input, &format!("y_b{suffix}"))?;
        check_bw_sel(bw_sel, self.plan.kf.rom.len(), &format!("bw_sel{suffix}"))
    }

    /// One sample: the output ports ([`CHAIN_OUTPUTS`] order; `rate_out` 0 where `out_valid`
    /// is 0).
    ///
    /// # Errors
    /// As [`Chain::check`].
    pub fn step(&mut self, y_a: i64, y_b: i64, bw_sel: i64) -> PortResult<[i64; 7]> {
        let bw_sel = self.check(y_a, y_b, bw_sel, "")?;
        Ok(self.step_checked([y_a, y_b], bw_sel))
    }

    /// [`Chain::step`] on checked inputs.
    pub fn step_checked(&mut self, y: [i64; 2], bw_sel: usize) -> [i64; 7] {
        let sample = self.model.step(y, bw_sel);
        let [bias_a, bias_b] = self.model.estimator().bias();
        [
            i64::from(sample.slot.mode_a > 0),
            i64::from(sample.slot.mode_b > 0),
            i64::from(sample.rate.is_some()),
            sample.rate.unwrap_or(0),
            bias_a as i64,
            bias_b as i64,
            i64::from(self.model.estimator().estimated()),
        ]
    }
}
