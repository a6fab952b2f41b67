//! The port-level golden model of the whole gyro (`gyrofx_system`, and
//! `gyrofx_system_serial`: the same with the chain's outputs [`crate::pipeline::system_chain_delay`]
//! ADC samples later).

use std::collections::VecDeque;

use super::{check_bw_sel, check_code, check_flag, PortResult};
use gyrofx_model::chain;
use gyrofx_model::gyro_loop::gyro as gyro_loop;
use gyrofx_model::resonator::Mode;
use gyrofx_model::system::FixedSystem;

use crate::job::Job;

/// The system's output ports (`gyrofx_system`), in the RTL's order.
pub const SYSTEM_OUTPUTS: [&str; 13] = [
    "dac_a_x",
    "dac_a_y",
    "dac_b_x",
    "dac_b_y",
    "locked_a",
    "locked_b",
    "mode_a",
    "mode_b",
    "out_valid",
    "rate_out",
    "bias_a",
    "bias_b",
    "estimated",
];

/// The system's input ports after `enable` and `bw_sel`, in the RTL's order.
pub const SYSTEM_ADC_PORTS: [&str; 4] = ["adc_a_x", "adc_a_y", "adc_b_x", "adc_b_y"];

/// Why a plan has no system: the rate plant's loops do not feed its chain.
pub const NO_SYSTEM: &str = "plant.model = \"rate\" has no system block (its loops do not feed the chain): allowed with plant.model = \"resonator\"";

/// The whole gyro (`gyrofx_system`): both gyros' loops feeding the chain, whose sequencer
/// commands their modes.
#[derive(Clone, Debug)]
pub struct System {
    loops: [gyro_loop::Plan; 2],
    chain: chain::Plan,
    model: FixedSystem,
    /// `rate_out` of the chain's last output: the RTL holds it between pulses.
    held: i64,
    /// The chain's outputs (`out_valid`, `rate_out`, `bias_a`, `bias_b`, `estimated`) of the
    /// last `chain_delay` samples, oldest first: what the serial system publishes ([`System::of`]).
    delayed: VecDeque<[i64; 5]>,
    chain_delay: usize,
}

impl System {
    /// Saturations and wraps per quantization point since it was made ([`Overflows`]).
    pub fn overflows(&self) -> super::Overflows {
        let mut out = Vec::new();
        for (prefix, gyro) in ["a.", "b."].into_iter().zip(self.model.loops()) {
            out.extend(super::overflows::prefixed(
                prefix,
                super::overflows::gyro_loop(gyro),
            ));
        }
        out.extend(super::overflows::chain(self.model.chain()));
        out
    }

    /// Its ports as the vector files carry them ([`super::ports`]).
    pub fn ports(&self) -> Vec<super::ports::Port> {
        super::ports::system(&self.loops[0], &self.chain)
    }

    /// From reset: gyro A's and B's loop plans and the system's chain plan (`gyrofx_system`:
    /// the chain's outputs in the sample that produced them).
    pub fn new(loops: [&gyro_loop::Plan; 2], chain: &chain::Plan) -> System {
        System {
            loops: loops.map(Clone::clone),
            chain: chain.clone(),
            model: FixedSystem::new(loops, chain),
            held: 0,
            delayed: VecDeque::new(),
            chain_delay: 0,
        }
    }

    /// The system `job` builds, from reset: `gyrofx_system`, or with `architecture = "serial"`
    /// `gyrofx_system_serial`, whose chain outputs (`out_valid`, `rate_out`, `bias_a`, `bias_b`,
    /// `estimated`) are those of [`System::new`]
    /// [`crate::pipeline::system_chain_delay`] samples earlier (their reset values before).
    /// `None` on the rate plant ([`NO_SYSTEM`]).
    pub fn of(job: &Job) -> Option<System> {
        let chain = job.system_chain.as_ref()?;
        let [a, b] = &job.gyro_loops;
        let mut system = System::new([&a.plan, &b.plan], chain);
        system.chain_delay = crate::pipeline::system_chain_delay(job) as usize;
        system.reset();
        Some(system)
    }

    /// ADC samples by which the chain's outputs come after the sample that produced them
    /// (0: `gyrofx_system`).
    pub fn chain_delay(&self) -> usize {
        self.chain_delay
    }

    /// Gyro A's and B's loop plans.
    pub fn loops(&self) -> &[gyro_loop::Plan; 2] {
        &self.loops
    }

    /// The chain's plan (its short schedule).
    pub fn chain_plan(&self) -> &chain::Plan {
        &self.chain
    }

    /// The synchronous reset.
    pub fn reset(&mut self) {
        self.model = FixedSystem::new([&self.loops[0], &self.loops[1]], &self.chain);
        self.held = 0;
        self.delayed = std::iter::repeat_n([0; 5], self.chain_delay).collect();
    }

    /// The modes `[mode_a, mode_b]` (1 normal, 0 reverse) the loops take at the next sample if
    /// `enable` is high there: what a plant needs before it produces that sample.
    pub fn next_modes(&self) -> [i64; 2] {
        self.model
            .upcoming_modes()
            .map(|m| i64::from(m == Mode::Normal))
    }

    /// The checked inputs of one sample: `(enable, bw_sel)`.
    ///
    /// # Errors
    /// A flag other than 0/1, `bw_sel` beyond the ROM or an ADC code outside its format.
    pub fn check(
        &self,
        enable: i64,
        bw_sel: i64,
        adc: [i64; 4],
        suffix: &str,
    ) -> PortResult<(bool, usize)> {
        let enable = check_flag(enable, &format!("enable{suffix}"))?;
        let bw_sel = check_bw_sel(bw_sel, self.chain.kf.rom.len(), &format!("bw_sel{suffix}"))?;
        for (code, port) in adc.into_iter().zip(SYSTEM_ADC_PORTS) {
            check_code(code, self.loops[0].adc, &format!("{port}{suffix}"))?;
        }
        Ok((enable, bw_sel))
    }

    /// One ADC sample: the output ports ([`SYSTEM_OUTPUTS`] order) after it, `mode_a`/`mode_b`
    /// the modes of the next sample when `enable` is high; `rate_out` holds its last value
    /// where `out_valid` is 0, as the RTL's does. The chain's outputs are those of
    /// [`System::chain_delay`] samples before (0 after a reset until then).
    ///
    /// # Errors
    /// As [`System::check`].
    pub fn step(&mut self, enable: i64, bw_sel: i64, adc: [i64; 4]) -> PortResult<[i64; 13]> {
        let (enable, bw_sel) = self.check(enable, bw_sel, adc, "")?;
        Ok(self.step_checked(enable, bw_sel, adc))
    }

    /// [`System::step`] on checked inputs.
    pub fn step_checked(&mut self, enable: bool, bw_sel: usize, adc: [i64; 4]) -> [i64; 13] {
        let step = self
            .model
            .step([[adc[0], adc[1]], [adc[2], adc[3]]], enable, bw_sel);
        let rate = step.chain.and_then(|c| c.rate);
        if let Some(rate) = rate {
            self.held = rate;
        }
        let upcoming = self.model.upcoming_modes();
        let estimator = self.model.chain().estimator();
        let [bias_a, bias_b] = estimator.bias();
        let mut chain = [
            i64::from(rate.is_some()),
            self.held,
            bias_a as i64,
            bias_b as i64,
            i64::from(estimator.estimated()),
        ];
        if self.chain_delay > 0 {
            self.delayed.push_back(chain);
            chain = self.delayed.pop_front().expect("chain_delay entries");
        }
        let [out_valid, rate_out, bias_a, bias_b, estimated] = chain;
        [
            step.dac[0][0],
            step.dac[0][1],
            step.dac[1][0],
            step.dac[1][1],
            i64::from(step.locked[0]),
            i64::from(step.locked[1]),
            i64::from(upcoming[0] == Mode::Normal),
            i64::from(upcoming[1] == Mode::Normal),
            out_valid,
            rate_out,
            bias_a,
            bias_b,
            estimated,
        ]
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::config::Config;

    /// The serial system is the parallel one with the chain's five outputs
    /// `system_chain_delay` samples later (reset values before), the loops' and the modes as
    /// they are; a reset clears the delay.
    #[test]
    fn the_serial_system_is_the_parallel_one_with_the_chains_outputs_delayed() {
        let config = Config::from_toml("architecture = \"serial\"\n", "t").unwrap();
        let job = Job::new(config).unwrap();
        let mut serial = System::of(&job).unwrap();
        let k = serial.chain_delay();
        assert_eq!(k, crate::pipeline::system_chain_delay(&job) as usize);
        assert!(k > 1);
        let [a, b] = &job.gyro_loops;
        let mut parallel = System::new([&a.plan, &b.plan], job.system_chain.as_ref().unwrap());
        let decimation = a.plan.cic.decimation as usize;
        let mut rows = Vec::new();
        let mut valid = 0;
        for round in 0..2 {
            for n in 0..2 * decimation + k + 3 {
                let code = |i: usize| ((n * 7919 + i * 104_729) % 2001) as i64 - 1000;
                let adc = [code(0), code(1), code(2), code(3)];
                let p = parallel.step(1, 0, adc).unwrap();
                let s = serial.step(1, 0, adc).unwrap();
                assert_eq!(s[..8], p[..8], "round {round} sample {n}: loops and modes");
                rows.push(p);
                let want = if n >= k {
                    rows[rows.len() - 1 - k]
                } else {
                    [0; 13]
                };
                assert_eq!(s[8..], want[8..], "round {round} sample {n}: chain outputs");
                valid += s[8];
            }
            parallel.reset();
            serial.reset();
            rows.clear();
        }
        assert!(valid > 0, "the run covers published chain outputs");
    }
}
