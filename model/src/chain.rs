//! The whole signal chain: sequencer → bias estimator and calibration → steady-state KF.
//!
//! Per sample, the sequencer says the modes and blanking; the gyro samples `y_A`, `y_B` (taken
//! in those modes) are calibrated with the current estimates and combined; the KF steps on
//! the combined value when at least one gyro is valid (otherwise it holds, and the chain's
//! output is not valid for that sample). RTL: `hdl/gyrofx_top.v`; its output registers are
//! valid 1 clock after `ce`, like the KF's.

use crate::estimator::{self, FixedEstimator, FloatEstimator};
use crate::fx::{mode, Rounding};
use crate::kf::{self, FixedKf, FloatKf};
use crate::sequencer::{Sequencer, Slot};

/// Errors of planning the chain.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ChainError {
    /// The blocks' rounding or overflow modes differ (the chain has one of each).
    #[error("the estimator and the KF must share one rounding and one overflow mode")]
    Modes,
    /// The estimator's output and the KF's input formats differ.
    #[error("the KF's input_format ({kf}) must equal the estimator's calibrated_format ({calibrated}): the combined output feeds the KF")]
    Formats {
        /// KF input format.
        kf: String,
        /// Estimator calibrated format.
        calibrated: String,
    },
}

/// The plans of the chain's blocks.
#[derive(Clone, Debug, PartialEq)]
pub struct Plan {
    /// Estimator and calibration (with the sequencer's schedule).
    pub estimator: estimator::Plan,
    /// The KF.
    pub kf: kf::Plan,
}

impl Plan {
    /// Joins the block plans, checking that they connect.
    ///
    /// # Errors
    /// [`ChainError::Formats`] when the combined output's format is not the KF's input, and
    /// [`ChainError::Modes`] when the blocks round or overflow differently.
    pub fn new(estimator: estimator::Plan, kf: kf::Plan) -> Result<Plan, ChainError> {
        if estimator.rounding != kf.rounding || estimator.overflow != kf.overflow {
            return Err(ChainError::Modes);
        }
        if estimator.calibrated != kf.input {
            return Err(ChainError::Formats {
                kf: kf.input.to_string(),
                calibrated: estimator.calibrated.to_string(),
            });
        }
        Ok(Plan { estimator, kf })
    }

    /// Worst-case `|rate_hat_fixed − rate_hat_float|` in output LSB after `samples` KF steps
    /// and `switches` changes of `bw_sel`: the KF's own bound
    /// ([`kf::bound::rate_error_bound_lsb`]) plus the input error — at most
    /// [`estimator::Plan::bias_error_bound`] + 2 rounding errors of the calibrated format —
    /// times the ℓ1 norm `|g1| / (1 − |1 − S|)` of the KF's response from input to `x1`.
    pub fn rate_error_bound_lsb(&self, samples: u64, switches: u64) -> f64 {
        let input_error = self.estimator.bias_error_bound() + self.calibration_rounding();
        kf::bound::rate_error_bound_lsb(&self.kf, samples, switches)
            + self.kf_input_gain() * input_error / self.kf.output.lsb()
    }

    /// The part of [`Plan::rate_error_bound_lsb`] that no guard bits of the estimator or the
    /// KF's state remove, output LSB: the output's rounding and the calibrated samples' two
    /// roundings through the KF's gain (their formats are the output's and the ADC's).
    pub fn rate_error_floor_lsb(&self) -> f64 {
        self.kf.rounding.max_error_lsb()
            + self.kf_input_gain() * self.calibration_rounding() / self.kf.output.lsb()
    }

    /// The calibrated samples' rounding error, °/s: one at the calibration, one at the
    /// combination of both gyros.
    fn calibration_rounding(&self) -> f64 {
        2.0 * self.estimator.rounding.max_error_lsb() * self.estimator.calibrated.lsb()
    }

    /// The ℓ1 norm `max |g1| / (1 − |1 − S|)` over the ROM of the KF's response from its input
    /// to `x1`: how much an input error can move the output.
    pub fn kf_input_gain(&self) -> f64 {
        self.kf
            .quantized_gains()
            .iter()
            .map(|g| g[0].abs() / (1.0 - (1.0 - g[0] - g[1]).abs()))
            .fold(0.0, f64::max)
    }
}

/// One sample of the fixed chain.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Sample {
    /// The sequencer's slot (modes to the gyro front end).
    pub slot: Slot,
    /// Estimator and calibration outputs.
    pub estimator: estimator::Sample,
    /// `rate_hat` code (KF output format) when the KF stepped.
    pub rate: Option<i64>,
}

/// The bit-accurate chain.
#[derive(Clone, Debug)]
pub struct FixedChain {
    rounding: Rounding,
    sequencer: Sequencer,
    estimator: FixedEstimator,
    kf: FixedKf,
}

impl FixedChain {
    /// The chain of `plan`, reset.
    pub fn new(plan: &Plan) -> Self {
        FixedChain {
            rounding: plan.kf.rounding,
            sequencer: Sequencer::new(&plan.estimator.schedule),
            estimator: FixedEstimator::new(&plan.estimator),
            kf: FixedKf::new(&plan.kf),
        }
    }

    /// Synchronous reset of every block.
    pub fn reset(&mut self) {
        self.sequencer.reset();
        self.estimator.reset();
        self.kf.reset();
    }

    /// The modes the next sample will be taken in (`[p_A, p_B]`), without advancing.
    pub fn upcoming_modes(&self) -> [i8; 2] {
        let slot = self.sequencer.clone().advance();
        [slot.mode_a, slot.mode_b]
    }

    /// One sample: gyro codes `y` (input format) at KF bandwidth `bw_sel`.
    #[inline]
    pub fn step(&mut self, y: [i64; 2], bw_sel: usize) -> Sample {
        match self.rounding {
            Rounding::Floor => self.step_mode::<{ mode::FLOOR }>(y, bw_sel),
            Rounding::Ceil => self.step_mode::<{ mode::CEIL }>(y, bw_sel),
            Rounding::Zero => self.step_mode::<{ mode::ZERO }>(y, bw_sel),
            Rounding::Nearest => self.step_mode::<{ mode::NEAREST }>(y, bw_sel),
            Rounding::Round => self.step_mode::<{ mode::ROUND }>(y, bw_sel),
            Rounding::Convergent => self.step_mode::<{ mode::CONVERGENT }>(y, bw_sel),
        }
    }

    /// Runs a block of gyro samples at one `bw_sel`, writing the KF output of each sample to
    /// `rate` (`None` where both gyros were blanked): [`FixedChain::step`] without the
    /// per-sample dispatch and without the per-sample record.
    ///
    /// # Panics
    /// When the slices differ in length.
    pub fn process(&mut self, y: &[[i64; 2]], bw_sel: usize, rate: &mut [Option<i64>]) {
        assert_eq!(
            y.len(),
            rate.len(),
            "input and output blocks differ in length"
        );
        match self.rounding {
            Rounding::Floor => self.process_mode::<{ mode::FLOOR }>(y, bw_sel, rate),
            Rounding::Ceil => self.process_mode::<{ mode::CEIL }>(y, bw_sel, rate),
            Rounding::Zero => self.process_mode::<{ mode::ZERO }>(y, bw_sel, rate),
            Rounding::Nearest => self.process_mode::<{ mode::NEAREST }>(y, bw_sel, rate),
            Rounding::Round => self.process_mode::<{ mode::ROUND }>(y, bw_sel, rate),
            Rounding::Convergent => self.process_mode::<{ mode::CONVERGENT }>(y, bw_sel, rate),
        }
    }

    fn process_mode<const MODE: u8>(
        &mut self,
        y: &[[i64; 2]],
        bw_sel: usize,
        rate: &mut [Option<i64>],
    ) {
        for (yk, out) in y.iter().zip(rate.iter_mut()) {
            *out = self.step_mode::<MODE>(*yk, bw_sel).rate;
        }
    }

    /// One sample with the rounding mode fixed at compile time (every block shares it).
    #[inline(always)]
    fn step_mode<const MODE: u8>(&mut self, y: [i64; 2], bw_sel: usize) -> Sample {
        let slot = self.sequencer.advance();
        let estimator = self.estimator.step_mode::<MODE>(&slot, y);
        let rate = estimator
            .combined_valid
            .then(|| self.kf.step_mode::<MODE>(estimator.combined, bw_sel));
        Sample {
            slot,
            estimator,
            rate,
        }
    }

    /// The estimator (for its overflow counts and state).
    pub fn estimator(&self) -> &FixedEstimator {
        &self.estimator
    }

    /// The KF (for its overflow counts and state).
    pub fn kf(&self) -> &FixedKf {
        &self.kf
    }
}

/// The f64 golden chain with the plan's quantized coefficients (or the designed ones).
#[derive(Clone, Debug)]
pub struct FloatChain {
    sequencer: Sequencer,
    estimator: FloatEstimator,
    kf: FloatKf,
}

/// One sample of the float chain, °/s.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FloatSample {
    /// Estimator outputs.
    pub estimator: estimator::FloatSample,
    /// `rate_hat` when the KF stepped.
    pub rate: Option<f64>,
}

impl FloatChain {
    /// With the quantized coefficients: checks the fixed chain's arithmetic.
    pub fn quantized(plan: &Plan) -> Self {
        FloatChain {
            sequencer: Sequencer::new(&plan.estimator.schedule),
            estimator: FloatEstimator::quantized(&plan.estimator),
            kf: FloatKf::new(plan.kf.quantized_gains()),
        }
    }

    /// With the designed coefficients: what the word lengths cost.
    pub fn ideal(plan: &Plan) -> Self {
        FloatChain {
            sequencer: Sequencer::new(&plan.estimator.schedule),
            estimator: FloatEstimator::ideal(&plan.estimator),
            kf: FloatKf::new(plan.kf.gains.clone()),
        }
    }

    /// Clears the state.
    pub fn reset(&mut self) {
        self.sequencer.reset();
        self.estimator.reset();
        self.kf.reset();
    }

    /// The modes the next sample will be taken in (`[p_A, p_B]`), without advancing.
    pub fn upcoming_modes(&self) -> [i8; 2] {
        let slot = self.sequencer.clone().advance();
        [slot.mode_a, slot.mode_b]
    }

    /// One sample, `y` in °/s.
    pub fn step(&mut self, y: [f64; 2], bw_sel: usize) -> FloatSample {
        let slot = self.sequencer.advance();
        let estimator = self.estimator.step(&slot, y);
        let rate = estimator
            .combined_valid
            .then(|| self.kf.step(estimator.combined, bw_sel));
        FloatSample { estimator, rate }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fx::{from_f64, Overflow, Rounding};
    use proptest::prelude::*;

    fn plans(stagger: usize, rounding: Rounding) -> Plan {
        crate::examples::chain_plan(40, 5, stagger, 1, rounding)
    }

    #[test]
    fn formats_must_connect() {
        let p = plans(0, Rounding::Nearest);
        let mut kf_spec = crate::examples::kf_spec();
        kf_spec.input = "s24.13".parse().unwrap();
        let err = Plan::new(p.estimator, kf::Plan::new(&kf_spec).unwrap()).unwrap_err();
        assert!(err.to_string().contains("s24.13") && err.to_string().contains("s24.14"));
    }

    #[test]
    fn the_kf_holds_while_both_gyros_are_blanked() {
        let p = plans(0, Rounding::Nearest);
        let mut chain = FixedChain::new(&p);
        let out: Vec<Sample> = (0..400).map(|_| chain.step([100, -100], 0)).collect();
        for s in &out {
            assert_eq!(s.rate.is_some(), !(s.slot.blank_a && s.slot.blank_b));
        }
        assert_eq!(out.iter().filter(|s| s.rate.is_none()).count(), 10 * 5);
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(40))]
        #[test]
        fn fixed_chain_stays_within_the_composed_bound(
            stagger in 0usize..20,
            rounding in prop::sample::select(vec![Rounding::Nearest, Rounding::Convergent, Rounding::Floor]),
            noise in prop::collection::vec(-2.0f64..2.0, 500),
            rate in -100.0f64..100.0,
        ) {
            let p = plans(stagger, rounding);
            let mut fixed = FixedChain::new(&p);
            let mut float = FloatChain::quantized(&p);
            let mut worst: f64 = 0.0;
            let mut steps = 0u64;
            let n = 2000;
            for k in 0..n {
                let modes = fixed.upcoming_modes();
                let y = [0, 1].map(|g| {
                    let v = rate + f64::from(modes[g]) * [0.4, -0.2][g] + noise[(k * 3 + g) % 500];
                    from_f64(v, p.kf.input, Rounding::Nearest, Overflow::Saturate).unwrap().code as i64
                });
                let bw = (k / 700) % 3;
                let a = fixed.step(y, bw);
                let b = float.step([p.kf.input.to_f64(i128::from(y[0])), p.kf.input.to_f64(i128::from(y[1]))], bw);
                prop_assert_eq!(a.rate.is_some(), b.rate.is_some());
                if let (Some(x), Some(r)) = (a.rate, b.rate) {
                    steps += 1;
                    worst = worst.max((p.kf.output.to_f64(i128::from(x)) - r).abs() / p.kf.output.lsb());
                }
            }
            let bound = p.rate_error_bound_lsb(steps, 2);
            prop_assert!(worst <= bound, "{} > {}", worst, bound);
        }

        /// The block API gives exactly the per-sample results.
        #[test]
        fn process_equals_step(stagger in 0usize..20, noise in prop::collection::vec(-3.0f64..3.0, 400)) {
            let p = plans(stagger, Rounding::Convergent);
            let y: Vec<[i64; 2]> = (0..1200)
                .map(|k| [0, 1].map(|g| (noise[(k + 7 * g) % 400] * 16384.0) as i64 + 5000))
                .collect();
            let mut by_step = FixedChain::new(&p);
            let stepped: Vec<Option<i64>> = y.iter().map(|v| by_step.step(*v, 1).rate).collect();
            let mut by_block = FixedChain::new(&p);
            let mut block = vec![None; y.len()];
            by_block.process(&y, 1, &mut block);
            prop_assert_eq!(stepped, block);
        }
    }
}
