//! The port-level golden model of one gyro's loop (`gyrofx_gyro_loop`).

use super::{check_code, check_mode, PortResult};
use gyrofx_model::gyro_loop::gyro as gyro_loop;
use gyrofx_model::gyro_loop::gyro::FixedGyroLoop;
use gyrofx_model::resonator::Mode;

/// The gyro loop's output ports (`gyrofx_gyro_loop`), in the RTL's order.
pub const GYRO_LOOP_OUTPUTS: [&str; 6] = [
    "dac_x",
    "dac_y",
    "locked",
    "out_valid",
    "rate",
    "quadrature",
];

/// One gyro's loop (`gyrofx_gyro_loop`): the ADC codes of both axes and the mode in, the DAC
/// codes, the lock flag and, every `DECIMATION`-th sample, the rate and quadrature out.
#[derive(Clone, Debug)]
pub struct GyroLoop {
    plan: gyro_loop::Plan,
    model: FixedGyroLoop,
    /// `(rate, quadrature)` of the last decimated output: the RTL holds them between pulses.
    held: [i64; 2],
}

impl GyroLoop {
    /// Saturations and wraps per quantization point since it was made ([`Overflows`]).
    pub fn overflows(&self) -> super::Overflows {
        super::overflows::gyro_loop(&self.model)
    }

    /// Its ports as the vector files carry them ([`super::ports`]).
    pub fn ports(&self) -> Vec<super::ports::Port> {
        super::ports::gyro_loop(&self.plan)
    }

    /// From reset.
    pub fn new(plan: &gyro_loop::Plan) -> GyroLoop {
        GyroLoop {
            plan: plan.clone(),
            model: FixedGyroLoop::new(plan),
            held: [0; 2],
        }
    }

    /// The plan.
    pub fn plan(&self) -> &gyro_loop::Plan {
        &self.plan
    }

    /// The synchronous reset.
    pub fn reset(&mut self) {
        self.model.reset();
        self.held = [0; 2];
    }

    /// The checked inputs of one sample.
    ///
    /// # Errors
    /// An ADC code outside the ADC format or a mode other than 0/1.
    pub fn check(&self, adc_x: i64, adc_y: i64, mode: i64, suffix: &str) -> PortResult<Mode> {
        check_code(adc_x, self.plan.adc, &format!("adc_x{suffix}"))?;
        check_code(adc_y, self.plan.adc, &format!("adc_y{suffix}"))?;
        check_mode(mode, &format!("mode{suffix}"))
    }

    /// One ADC sample: the output ports ([`GYRO_LOOP_OUTPUTS`] order) after it; `rate` and
    /// `quadrature` hold their last decimated values where `out_valid` is 0, as the RTL's do.
    ///
    /// # Errors
    /// As [`GyroLoop::check`].
    pub fn step(&mut self, adc_x: i64, adc_y: i64, mode: i64) -> PortResult<[i64; 6]> {
        let mode = self.check(adc_x, adc_y, mode, "")?;
        Ok(self.step_checked([adc_x, adc_y], mode))
    }

    /// [`GyroLoop::step`] on checked inputs.
    pub fn step_checked(&mut self, adc: [i64; 2], mode: Mode) -> [i64; 6] {
        let step = self.model.step(adc, mode);
        if let Some(c) = step.chain {
            self.held = [c.rate, c.quadrature];
        }
        [
            step.dac[0],
            step.dac[1],
            i64::from(self.model.locked()),
            i64::from(step.chain.is_some()),
            self.held[0],
            self.held[1],
        ]
    }
}
