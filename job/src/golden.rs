//! The blocks as their RTL ports see them, for golden models inside users' testbenches (the
//! Python package, the C ABI and its DPI-C testbenches): codes in, codes out, one call per
//! clock that takes a sample, every input checked against its port.
//!
//! Codes are `i64` exactly as the ports carry them: two's-complement values of the port's
//! format, flags 0/1, a mode 1 normal / 0 reverse, indices from 0. A refused input is an
//! `Err` naming the port, the value and what is allowed; the model's state is then unchanged.

use gyrofx_model::chain::{self, FixedChain};
use gyrofx_model::estimator::{self, FixedEstimator};
use gyrofx_model::fx::Format;
use gyrofx_model::gyro_loop::gyro::{self as gyro_loop, FixedGyroLoop};
use gyrofx_model::kf::{self, FixedKf};
use gyrofx_model::mean_filter::{self, FixedMeanFilter};
use gyrofx_model::resonator::Mode;
use gyrofx_model::sequencer::{self, Schedule, Slot};
use gyrofx_model::system::FixedSystem;

/// The blocks with a golden model here, by folder name: the ones that get cocotb and DPI-C
/// testbenches.
pub const BLOCKS: [&str; 7] = [
    "sequencer",
    "estimator",
    "kf",
    "top",
    "mean_filter",
    "gyro_loop",
    "system",
];

/// A refused input: the message names the port, the value and what is allowed.
pub type PortResult<T> = std::result::Result<T, String>;

/// Checks that `code` is a code of `format`.
pub fn check_code(code: i64, format: Format, port: &str) -> PortResult<()> {
    if format.contains(i128::from(code)) {
        Ok(())
    } else {
        Err(format!(
            "{port} = {code} is not a code of {format}: allowed {}..={}",
            format.min_code(),
            format.max_code()
        ))
    }
}

/// The first code of `codes` outside `format`, as [`check_code`]'s error naming `port[i]`.
pub fn check_codes(codes: &[i64], format: Format, port: &str) -> PortResult<()> {
    // Declared formats are at most 64 bits wide, so their code range fits i64 (u64 aside,
    // whose upper half no i64 reaches).
    let min = i64::try_from(format.min_code()).unwrap_or(i64::MIN);
    let max = i64::try_from(format.max_code()).unwrap_or(i64::MAX);
    if codes
        .iter()
        .fold(false, |bad, c| bad | (*c < min) | (*c > max))
    {
        let index = codes.iter().position(|c| *c < min || *c > max).unwrap_or(0);
        check_code(codes[index], format, &format!("{port}[{index}]"))?;
    }
    Ok(())
}

/// A flag port's value (0 or 1).
pub fn check_flag(value: i64, port: &str) -> PortResult<bool> {
    match value {
        0 => Ok(false),
        1 => Ok(true),
        other => Err(format!("{port} = {other}: a flag is 0 or 1")),
    }
}

/// A mode port (1 normal, 0 reverse) as the loop's mode.
pub fn check_mode(value: i64, port: &str) -> PortResult<Mode> {
    match value {
        1 => Ok(Mode::Normal),
        0 => Ok(Mode::Reverse),
        other => Err(format!(
            "{port} = {other}: a mode is 1 (normal) or 0 (reverse)"
        )),
    }
}

/// A `bw_sel` that addresses a ROM of `depth` entries.
pub fn check_bw_sel(bw_sel: i64, depth: usize, port: &str) -> PortResult<usize> {
    usize::try_from(bw_sel)
        .ok()
        .filter(|b| *b < depth)
        .ok_or_else(|| {
            format!(
                "{port} = {bw_sel} does not address the KF's coefficient ROM: allowed 0..={}",
                depth - 1
            )
        })
}

/// The steady-state KF (`gyrofx_kf`): `z`, `bw_sel` in, `rate_out` out (`out_valid` with it).
#[derive(Clone, Debug)]
pub struct Kf {
    plan: kf::Plan,
    model: FixedKf,
}

impl Kf {
    /// From reset.
    pub fn new(plan: &kf::Plan) -> Kf {
        Kf {
            plan: plan.clone(),
            model: FixedKf::new(plan),
        }
    }

    /// The plan.
    pub fn plan(&self) -> &kf::Plan {
        &self.plan
    }

    /// The model itself (for block-wise processing).
    pub fn model(&mut self) -> &mut FixedKf {
        &mut self.model
    }

    /// The synchronous reset.
    pub fn reset(&mut self) {
        self.model.reset();
    }

    /// One sample: `rate_out`.
    ///
    /// # Errors
    /// `z` outside the input format or `bw_sel` beyond the ROM.
    pub fn step(&mut self, z: i64, bw_sel: i64) -> PortResult<i64> {
        check_code(z, self.plan.input, "z")?;
        let bw_sel = check_bw_sel(bw_sel, self.plan.rom.len(), "bw_sel")?;
        Ok(self.model.step(z, bw_sel))
    }
}

/// The sequencer's output ports, in the RTL's order.
pub const SLOT_PORTS: [&str; 9] = [
    "mode_a",
    "mode_b",
    "blank_a",
    "blank_b",
    "interval_a",
    "interval_b",
    "done_a",
    "done_b",
    "window_done",
];

/// A slot as its ports' codes, in [`SLOT_PORTS`] order.
pub fn slot_codes(slot: &Slot) -> [i64; 9] {
    [
        i64::from(slot.mode_a > 0),
        i64::from(slot.mode_b > 0),
        i64::from(slot.blank_a),
        i64::from(slot.blank_b),
        slot.interval_a as i64,
        slot.interval_b as i64,
        i64::from(slot.done_a),
        i64::from(slot.done_b),
        i64::from(slot.window_done),
    ]
}

/// The mode-reversal sequencer (`gyrofx_sequencer`): no inputs; each call is one clock that
/// takes a sample, returning that clock's (combinational) slot, then advancing.
#[derive(Clone, Debug)]
pub struct Sequencer {
    model: sequencer::Sequencer,
}

impl Sequencer {
    /// From reset.
    pub fn new(schedule: &Schedule) -> Sequencer {
        Sequencer {
            model: sequencer::Sequencer::new(schedule),
        }
    }

    /// The synchronous reset.
    pub fn reset(&mut self) {
        self.model.reset();
    }

    /// This clock's slot ([`SLOT_PORTS`] order); then advances.
    pub fn step(&mut self) -> [i64; 9] {
        slot_codes(&self.model.advance())
    }
}

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

/// The mean filter with gross-error rejection (`gyrofx_mean_filter`): `x` in; on a block's last
/// sample `y_valid` with `(y, kept)`.
#[derive(Clone, Debug)]
pub struct MeanFilter {
    plan: mean_filter::Plan,
    model: FixedMeanFilter,
}

impl MeanFilter {
    /// From reset.
    pub fn new(plan: &mean_filter::Plan) -> MeanFilter {
        MeanFilter {
            plan: plan.clone(),
            model: FixedMeanFilter::new(plan),
        }
    }

    /// The plan.
    pub fn plan(&self) -> &mean_filter::Plan {
        &self.plan
    }

    /// The synchronous reset.
    pub fn reset(&mut self) {
        self.model.reset();
    }

    /// One sample: `Some((y, kept))` on a block's last sample.
    ///
    /// # Errors
    /// `x` outside the input format.
    pub fn step(&mut self, x: i64) -> PortResult<Option<(i64, i64)>> {
        check_code(x, self.plan.input, "x")?;
        Ok(self.step_checked(x))
    }

    /// [`MeanFilter::step`] on a checked input.
    pub fn step_checked(&mut self, x: i64) -> Option<(i64, i64)> {
        self.model.step(x).map(|m| (m.y, i64::from(m.kept)))
    }
}

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
}

impl System {
    /// From reset: gyro A's and B's loop plans and the system's chain plan.
    pub fn new(loops: [&gyro_loop::Plan; 2], chain: &chain::Plan) -> System {
        System {
            loops: loops.map(Clone::clone),
            chain: chain.clone(),
            model: FixedSystem::new(loops, chain),
            held: 0,
        }
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
    /// where `out_valid` is 0, as the RTL's does.
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
        [
            step.dac[0][0],
            step.dac[0][1],
            step.dac[1][0],
            step.dac[1][1],
            i64::from(step.locked[0]),
            i64::from(step.locked[1]),
            i64::from(upcoming[0] == Mode::Normal),
            i64::from(upcoming[1] == Mode::Normal),
            i64::from(rate.is_some()),
            self.held,
            bias_a as i64,
            bias_b as i64,
            i64::from(estimator.estimated()),
        ]
    }
}
