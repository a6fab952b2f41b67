//! The port-level golden model of the bias estimator (`gyrofx_bias_estimator`).

use super::{check_code, check_flag, PortResult};
use gyrofx_model::estimator;
use gyrofx_model::estimator::FixedEstimator;
use gyrofx_model::sequencer::Schedule;
use gyrofx_model::sequencer::Slot;

/// The estimator's slot inputs, in its port order (after `y_a`, `y_b`).
pub const ESTIMATOR_SLOT_PORTS: [&str; 7] = [
    "blank_a",
    "blank_b",
    "done_a",
    "done_b",
    "interval_a",
    "interval_b",
    "window_done",
];

/// The estimator's outputs, in the RTL's order.
pub const ESTIMATOR_OUTPUTS: [&str; 3] = ["bias_a", "bias_b", "estimated"];

/// The slot the estimator's input ports describe ([`ESTIMATOR_SLOT_PORTS`] order; its modes
/// follow from the schedule). `suffix` follows each port name in errors (`[17]`).
///
/// # Errors
/// A flag other than 0/1 or an interval beyond the schedule's.
pub fn slot_from_ports(
    schedule: &Schedule,
    modes: &[i8],
    ports: [i64; 7],
    suffix: &str,
) -> PortResult<Slot> {
    let flag = |value: i64, name: &str| check_flag(value, &format!("{name}{suffix}"));
    let interval = |value: i64, name: &str| -> PortResult<usize> {
        usize::try_from(value)
            .ok()
            .filter(|i| *i < schedule.intervals)
            .ok_or_else(|| {
                format!(
                    "{name}{suffix} = {value}: allowed 0..={} (the sequencer's intervals)",
                    schedule.intervals - 1
                )
            })
    };
    let [blank_a, blank_b, done_a, done_b, interval_a, interval_b, window_done] = ports;
    let interval_a = interval(interval_a, "interval_a")?;
    let interval_b = interval(interval_b, "interval_b")?;
    Ok(Slot {
        mode_a: modes[interval_a],
        mode_b: -modes[interval_b],
        blank_a: flag(blank_a, "blank_a")?,
        blank_b: flag(blank_b, "blank_b")?,
        interval_a,
        interval_b,
        done_a: flag(done_a, "done_a")?,
        done_b: flag(done_b, "done_b")?,
        window_done: flag(window_done, "window_done")?,
    })
}

/// The least-squares bias estimator (`gyrofx_bias_estimator`): both gyros' samples and the
/// sequencer's slot in, the registered bias estimates out.
#[derive(Clone, Debug)]
pub struct Estimator {
    plan: estimator::Plan,
    modes: Vec<i8>,
    model: FixedEstimator,
}

impl Estimator {
    /// Saturations and wraps per quantization point since it was made ([`Overflows`]).
    pub fn overflows(&self) -> super::Overflows {
        super::overflows::estimator(&self.model)
    }

    /// Its ports as the vector files carry them ([`super::ports`]).
    pub fn ports(&self) -> Vec<super::ports::Port> {
        super::ports::estimator(&self.plan)
    }

    /// From reset.
    pub fn new(plan: &estimator::Plan) -> Estimator {
        Estimator {
            plan: plan.clone(),
            modes: plan.schedule.pattern.modes(plan.schedule.intervals),
            model: FixedEstimator::new(plan),
        }
    }

    /// The plan.
    pub fn plan(&self) -> &estimator::Plan {
        &self.plan
    }

    /// The synchronous reset.
    pub fn reset(&mut self) {
        self.model.reset();
    }

    /// The slot of the ports (checked), for [`Estimator::step_slot`].
    ///
    /// # Errors
    /// As [`slot_from_ports`].
    pub fn slot(&self, ports: [i64; 7], suffix: &str) -> PortResult<Slot> {
        slot_from_ports(&self.plan.schedule, &self.modes, ports, suffix)
    }

    /// One sample: `[bias_a, bias_b, estimated]` after the clock.
    ///
    /// # Errors
    /// A sample outside the input format or a bad slot port.
    pub fn step(&mut self, y: [i64; 2], slot: [i64; 7]) -> PortResult<[i64; 3]> {
        check_code(y[0], self.plan.input, "y_a")?;
        check_code(y[1], self.plan.input, "y_b")?;
        let slot = self.slot(slot, "")?;
        Ok(self.step_slot(&slot, y))
    }

    /// [`Estimator::step`] on inputs already checked.
    pub fn step_slot(&mut self, slot: &Slot, y: [i64; 2]) -> [i64; 3] {
        self.model.step(slot, y);
        let [a, b] = self.model.bias();
        [a as i64, b as i64, i64::from(self.model.estimated())]
    }
}
