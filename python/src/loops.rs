//! The resonator-level blocks: one gyro's loop (`gyrofx_gyro_loop`), the whole system
//! (`gyrofx_system`), the loop's float twin, and the simulated resonator that closes a loop in a
//! testbench (DAC codes in, ADC codes out).
//!
//! Ports as in [`crate::blocks`]: codes exactly as the RTL carries them, a mode 1 normal / 0
//! reverse, flags 0/1; `process` returns a dict of int64 arrays, one per output port.

use pyo3::prelude::*;
use pyo3::types::PyDict;

use gyrofx_job::config::GyroLoop as LoopConfig;
use gyrofx_job::golden::{self, check_code, GYRO_LOOP_OUTPUTS, SYSTEM_OUTPUTS};
use gyrofx_job::pipeline::Pipeline;
use gyrofx_model::chain;
use gyrofx_model::gyro_loop::gyro::{FloatGyroLoop, Plan as LoopPlan};
use gyrofx_model::resonator::{Mode, Resonator as PhysicalResonator};
use gyrofx_model::system::FloatSystem;

use crate::blocks::{port_codes, port_dict, same_length, Codes, PerSample};
use crate::refused;

/// One gyro's digital loop (`gyrofx_gyro_loop`): NCOs, demodulators, PLL, AGC, CICs, lock
/// detector and mode switch. One `step` per ADC sample.
#[pyclass(module = "gyrofx")]
pub(crate) struct GyroLoop {
    ports: golden::GyroLoop,
    pipeline: Pipeline,
}

impl GyroLoop {
    pub(crate) fn new(plan: &LoopPlan, pipeline: Pipeline) -> GyroLoop {
        GyroLoop {
            ports: golden::GyroLoop::new(plan),
            pipeline,
        }
    }
}

#[pymethods]
impl GyroLoop {
    /// Saturations and wraps per quantization point since it was made (a reset keeps them):
    /// a dict of counts, e.g. `{"x1": 0, "x2": 0, "rate_out": 3}` for the KF; empty for a block
    /// that cannot overflow.
    fn overflow_counts<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        crate::blocks::overflow_dict(py, self.ports.overflows())
    }

    fn __repr__(&self) -> String {
        crate::blocks::block_repr("GyroLoop", &self.ports.ports())
    }

    /// Its ports as the vector files carry them (after `rst`; inputs, then outputs): a list of
    /// `(name, format, direction)`, e.g. `("z", "s24.14", "in")`.
    fn ports(&self) -> Vec<(&'static str, String, &'static str)> {
        self.ports
            .ports()
            .iter()
            .map(|p| (p.name, p.format.to_string(), p.direction()))
            .collect()
    }

    /// Clocks from a sample's `ce` to its registered outputs in the RTL (`gyrofx_job::pipeline`,
    /// as the manifest and the testbenches have it).
    #[getter]
    fn latency_clocks(&self) -> u32 {
        self.pipeline.latency_clocks
    }

    /// The fewest clocks from one sample's `ce` to the next one's in the RTL (its simulation
    /// stops on a faster stream).
    #[getter]
    fn min_clocks_per_sample(&self) -> u32 {
        self.pipeline.min_clocks_per_sample
    }

    /// Clears every register (the RTL's synchronous reset): normal mode, PLL preset.
    fn reset(&mut self) {
        self.ports.reset();
    }

    /// One ADC sample: `adc_x`, `adc_y` (ADC-format codes) and `mode` (1 normal, 0 reverse; a
    /// change takes effect before this sample). Returns a dict of the output ports: `dac_x`,
    /// `dac_y` (DAC codes, the sensed axis 0), `locked`, `out_valid` (1 every `decimation`-th
    /// sample), `rate` and `quadrature` (output-format codes, °/s; they hold between
    /// `out_valid` pulses, as the RTL's do).
    #[pyo3(signature = (adc_x, adc_y, mode = 1))]
    fn step<'py>(
        &mut self,
        py: Python<'py>,
        adc_x: i64,
        adc_y: i64,
        mode: i64,
    ) -> PyResult<Bound<'py, PyDict>> {
        let codes = self.ports.step(adc_x, adc_y, mode).map_err(refused)?;
        let dict = PyDict::new(py);
        for (name, code) in GYRO_LOOP_OUTPUTS.into_iter().zip(codes) {
            dict.set_item(name, code)?;
        }
        Ok(dict)
    }

    /// `step` over records: `adc_x`, `adc_y` int64 arrays, `mode` one value or one per sample;
    /// a dict of int64 arrays, one per output port.
    #[pyo3(signature = (adc_x, adc_y, mode = PerSample::One(1)), text_signature = "($self, adc_x, adc_y, mode=1)")]
    fn process<'py>(
        &mut self,
        py: Python<'py>,
        adc_x: Codes<'py>,
        adc_y: Codes<'py>,
        mode: PerSample<'py>,
    ) -> PyResult<Bound<'py, PyDict>> {
        let adc = self.ports.plan().adc;
        let x = port_codes(&adc_x, adc, "adc_x")?;
        let y = port_codes(&adc_y, adc, "adc_y")?;
        let samples = same_length(&[("adc_x", x.len()), ("adc_y", y.len())])?;
        let modes = mode.values(samples, "mode", golden::check_mode)?;
        let ports = &mut self.ports;
        let columns = py.detach(|| {
            let mut columns: [Vec<i64>; 6] = std::array::from_fn(|_| Vec::with_capacity(samples));
            for ((x, y), mode) in x.iter().zip(y.iter()).zip(&modes) {
                for (column, code) in columns.iter_mut().zip(ports.step_checked([*x, *y], *mode)) {
                    column.push(code);
                }
            }
            columns
        });
        port_dict(py, GYRO_LOOP_OUTPUTS, columns)
    }

    /// ADC sample rate, Hz.
    #[getter]
    fn adc_rate_hz(&self) -> f64 {
        self.ports.plan().adc_rate_hz
    }

    /// ADC samples per `rate` output.
    #[getter]
    fn decimation(&self) -> u32 {
        self.ports.plan().cic.decimation
    }

    /// The ADC ports' format (`s24.23`: full scale ±1).
    #[getter]
    fn adc_format(&self) -> String {
        self.ports.plan().adc.to_string()
    }

    /// The DAC ports' format.
    #[getter]
    fn dac_format(&self) -> String {
        self.ports.plan().dac.to.to_string()
    }

    /// The `rate` and `quadrature` ports' format (°/s).
    #[getter]
    fn output_format(&self) -> String {
        self.ports.plan().output.to.to_string()
    }
}

/// The loop's float twin: the same structure in f64 with the designed offsets, setpoints and
/// scale factors, an exact NCO phase and an unquantized DAC.
#[pyclass(module = "gyrofx")]
pub(crate) struct GyroLoopFloat {
    plan: LoopPlan,
    model: FloatGyroLoop,
}

impl GyroLoopFloat {
    pub(crate) fn new(plan: &LoopPlan) -> GyroLoopFloat {
        GyroLoopFloat {
            plan: plan.clone(),
            model: FloatGyroLoop::new(plan),
        }
    }
}

#[pymethods]
impl GyroLoopFloat {
    /// Back to the state after construction.
    fn reset(&mut self) {
        self.model = FloatGyroLoop::new(&self.plan);
    }

    /// One ADC sample: `adc_x`, `adc_y` in full-scale units (the ADC code times its LSB) and
    /// `mode` (1 normal, 0 reverse). A dict: `dac_x`, `dac_y` (DAC LSB, unquantized),
    /// `locked`, `out_valid`, and `rate`, `quadrature` (°/s, None where `out_valid` is 0).
    #[pyo3(signature = (adc_x, adc_y, mode = 1))]
    fn step<'py>(
        &mut self,
        py: Python<'py>,
        adc_x: f64,
        adc_y: f64,
        mode: i64,
    ) -> PyResult<Bound<'py, PyDict>> {
        let mode = golden::check_mode(mode, "mode").map_err(refused)?;
        let step = self.model.step([adc_x, adc_y], mode);
        let dict = PyDict::new(py);
        dict.set_item("dac_x", step.dac[0])?;
        dict.set_item("dac_y", step.dac[1])?;
        dict.set_item("locked", i64::from(self.model.locked()))?;
        dict.set_item("out_valid", i64::from(step.chain.is_some()))?;
        dict.set_item("rate", step.chain.map(|c| c.rate_dps))?;
        dict.set_item("quadrature", step.chain.map(|c| c.quadrature_dps))?;
        Ok(dict)
    }
}

/// The whole gyro at the ADC rate (`gyrofx_system`): gyro A's and B's loops feeding the chain
/// (on the system's short schedule), whose sequencer commands the loops' modes.
#[pyclass(module = "gyrofx")]
pub(crate) struct System {
    ports: golden::System,
    pipeline: Pipeline,
}

impl System {
    /// `ports`: the job's system ([`golden::System::of`]), `pipeline` its RTL's.
    pub(crate) fn new(ports: golden::System, pipeline: Pipeline) -> System {
        System { ports, pipeline }
    }
}

#[pymethods]
impl System {
    /// Saturations and wraps per quantization point since it was made (a reset keeps them):
    /// a dict of counts, e.g. `{"x1": 0, "x2": 0, "rate_out": 3}` for the KF; empty for a block
    /// that cannot overflow.
    fn overflow_counts<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        crate::blocks::overflow_dict(py, self.ports.overflows())
    }

    fn __repr__(&self) -> String {
        crate::blocks::block_repr("System", &self.ports.ports())
    }

    /// Its ports as the vector files carry them (after `rst`; inputs, then outputs): a list of
    /// `(name, format, direction)`, e.g. `("z", "s24.14", "in")`.
    fn ports(&self) -> Vec<(&'static str, String, &'static str)> {
        self.ports
            .ports()
            .iter()
            .map(|p| (p.name, p.format.to_string(), p.direction()))
            .collect()
    }

    /// Clocks from a sample's `ce` to its registered outputs in the RTL (`gyrofx_job::pipeline`,
    /// as the manifest and the testbenches have it).
    #[getter]
    fn latency_clocks(&self) -> u32 {
        self.pipeline.latency_clocks
    }

    /// The fewest clocks from one sample's `ce` to the next one's in the RTL (its simulation
    /// stops on a faster stream).
    #[getter]
    fn min_clocks_per_sample(&self) -> u32 {
        self.pipeline.min_clocks_per_sample
    }

    /// ADC samples by which the chain's outputs (`out_valid`, `rate_out`, `bias_a`, `bias_b`,
    /// `estimated`) come after the sample that produced them: 0 for `gyrofx_system`,
    /// `gyrofx_system_serial`'s `CHAIN_DELAY_SAMPLES` with `architecture = "serial"`.
    #[getter]
    fn chain_delay_samples(&self) -> usize {
        self.ports.chain_delay()
    }

    /// Clears every register.
    fn reset(&mut self) {
        self.ports.reset();
    }

    /// The modes `(mode_a, mode_b)` (1 normal, 0 reverse) the loops take at the next `step`
    /// if its `enable` is 1 (both normal if 0): what the resonators need first.
    fn next_modes(&self) -> (i64, i64) {
        let [a, b] = self.ports.next_modes();
        (a, b)
    }

    /// One ADC sample: `enable` (0 holds the chain and runs both loops in normal mode, the
    /// start-up), `bw_sel`, and both gyros' ADC codes. A dict of the output ports
    /// (`dac_a_x` ... `estimated`); `mode_a`, `mode_b` are the modes of the next sample,
    /// `rate_out` holds between `out_valid` pulses.
    #[pyo3(signature = (adc_a_x, adc_a_y, adc_b_x, adc_b_y, enable = 1, bw_sel = 0))]
    #[allow(clippy::too_many_arguments)]
    fn step<'py>(
        &mut self,
        py: Python<'py>,
        adc_a_x: i64,
        adc_a_y: i64,
        adc_b_x: i64,
        adc_b_y: i64,
        enable: i64,
        bw_sel: i64,
    ) -> PyResult<Bound<'py, PyDict>> {
        let codes = self
            .ports
            .step(enable, bw_sel, [adc_a_x, adc_a_y, adc_b_x, adc_b_y])
            .map_err(refused)?;
        let dict = PyDict::new(py);
        for (name, code) in SYSTEM_OUTPUTS.into_iter().zip(codes) {
            dict.set_item(name, code)?;
        }
        Ok(dict)
    }

    /// `step` over records: four int64 ADC arrays; `enable` and `bw_sel` one value or one per
    /// sample. A dict of int64 arrays, one per output port.
    #[pyo3(signature = (adc_a_x, adc_a_y, adc_b_x, adc_b_y, enable = PerSample::One(1), bw_sel = PerSample::One(0)), text_signature = "($self, adc_a_x, adc_a_y, adc_b_x, adc_b_y, enable=1, bw_sel=0)")]
    #[allow(clippy::too_many_arguments)]
    fn process<'py>(
        &mut self,
        py: Python<'py>,
        adc_a_x: Codes<'py>,
        adc_a_y: Codes<'py>,
        adc_b_x: Codes<'py>,
        adc_b_y: Codes<'py>,
        enable: PerSample<'py>,
        bw_sel: PerSample<'py>,
    ) -> PyResult<Bound<'py, PyDict>> {
        let adc = self.ports.loops()[0].adc;
        let records = [
            port_codes(&adc_a_x, adc, "adc_a_x")?,
            port_codes(&adc_a_y, adc, "adc_a_y")?,
            port_codes(&adc_b_x, adc, "adc_b_x")?,
            port_codes(&adc_b_y, adc, "adc_b_y")?,
        ];
        let samples = same_length(&[
            ("adc_a_x", records[0].len()),
            ("adc_a_y", records[1].len()),
            ("adc_b_x", records[2].len()),
            ("adc_b_y", records[3].len()),
        ])?;
        let enable = enable.values(samples, "enable", golden::check_flag)?;
        let select = bw_sel.per_sample(samples, self.ports.chain_plan().kf.rom.len())?;
        let ports = &mut self.ports;
        let columns = py.detach(|| {
            let mut columns: [Vec<i64>; 13] = std::array::from_fn(|_| Vec::with_capacity(samples));
            for k in 0..samples {
                let adc = [0, 1, 2, 3].map(|i| records[i][k]);
                for (column, code) in columns
                    .iter_mut()
                    .zip(ports.step_checked(enable[k], select[k], adc))
                {
                    column.push(code);
                }
            }
            columns
        });
        port_dict(py, SYSTEM_OUTPUTS, columns)
    }

    /// ADC samples per chain sample.
    #[getter]
    fn decimation(&self) -> u32 {
        self.ports.loops()[0].cic.decimation
    }

    /// Chain samples per estimator window (the system's short schedule).
    #[getter]
    fn window(&self) -> usize {
        self.ports.chain_plan().estimator.schedule.cycle_length()
    }
}

/// The system's float twin: both loops' twins feeding the chain's twin (quantized
/// coefficients), the same modes and chain steps.
#[pyclass(module = "gyrofx")]
pub(crate) struct SystemFloat {
    loops: [LoopPlan; 2],
    chain: chain::Plan,
    model: FloatSystem,
}

impl SystemFloat {
    pub(crate) fn new(loops: [&LoopPlan; 2], chain: &chain::Plan) -> SystemFloat {
        SystemFloat {
            loops: loops.map(Clone::clone),
            chain: chain.clone(),
            model: FloatSystem::new(loops, chain),
        }
    }
}

#[pymethods]
impl SystemFloat {
    /// Back to the state after construction.
    fn reset(&mut self) {
        self.model = FloatSystem::new([&self.loops[0], &self.loops[1]], &self.chain);
    }

    /// The modes `(mode_a, mode_b)` (1 normal, 0 reverse) the loops take at the next `step` if
    /// its `enable` is 1.
    fn next_modes(&self) -> (i64, i64) {
        let [a, b] = self
            .model
            .upcoming_modes()
            .map(|m| i64::from(m == Mode::Normal));
        (a, b)
    }

    /// One ADC sample, both gyros' `[x, y]` in full-scale units. A dict: `dac_a_x` ...
    /// `dac_b_y` (DAC LSB, unquantized), `locked_a`, `locked_b`, `mode_a`, `mode_b` (the next
    /// sample's), `out_valid`, and `rate_out`, `bias_a`, `bias_b` (°/s; None where the chain did
    /// not give them this sample).
    #[pyo3(signature = (adc_a_x, adc_a_y, adc_b_x, adc_b_y, enable = 1, bw_sel = 0))]
    #[allow(clippy::too_many_arguments)]
    fn step<'py>(
        &mut self,
        py: Python<'py>,
        adc_a_x: f64,
        adc_a_y: f64,
        adc_b_x: f64,
        adc_b_y: f64,
        enable: i64,
        bw_sel: i64,
    ) -> PyResult<Bound<'py, PyDict>> {
        let enable = golden::check_flag(enable, "enable").map_err(refused)?;
        let bw_sel =
            golden::check_bw_sel(bw_sel, self.chain.kf.rom.len(), "bw_sel").map_err(refused)?;
        let step = self
            .model
            .step([[adc_a_x, adc_a_y], [adc_b_x, adc_b_y]], enable, bw_sel);
        let (mode_a, mode_b) = self.next_modes();
        let rate = step.chain.and_then(|c| c.rate);
        let dict = PyDict::new(py);
        for (name, value) in ["dac_a_x", "dac_a_y", "dac_b_x", "dac_b_y"]
            .into_iter()
            .zip(step.dac.as_flattened())
        {
            dict.set_item(name, *value)?;
        }
        dict.set_item("locked_a", i64::from(step.locked[0]))?;
        dict.set_item("locked_b", i64::from(step.locked[1]))?;
        dict.set_item("mode_a", mode_a)?;
        dict.set_item("mode_b", mode_b)?;
        dict.set_item("out_valid", i64::from(rate.is_some()))?;
        dict.set_item("rate_out", rate)?;
        dict.set_item("bias_a", step.chain.map(|c| c.estimator.bias[0]))?;
        dict.set_item("bias_b", step.chain.map(|c| c.estimator.bias[1]))?;
        Ok(dict)
    }
}

/// A simulated gyro resonator with its front end (DAC, pick-offs, noise, ADC): DAC codes in,
/// ADC codes out, one call per ADC sample. It closes a loop in a testbench, as `generate`
/// closes it for the vectors.
#[pyclass(module = "gyrofx")]
pub(crate) struct Resonator {
    model: PhysicalResonator,
    dac: gyrofx_model::fx::Format,
}

impl Resonator {
    pub(crate) fn new(gyro: &LoopConfig, seed: u64, noise: bool) -> PyResult<Resonator> {
        let mut front_end = gyro.front_end;
        front_end.noise = noise;
        let model = PhysicalResonator::new(&gyro.params, &front_end, seed)
            .map_err(|e| refused(format!("resonator of gyro {}: {e}", gyro.name)))?;
        Ok(Resonator {
            model,
            dac: gyro.plan.dac.to,
        })
    }
}

#[pymethods]
impl Resonator {
    /// The input rate, °/s.
    fn set_rate_dps(&mut self, rate_dps: f64) {
        self.model.set_rate(rate_dps.to_radians());
    }

    /// The mode its pick-off front end follows (1 normal, 0 reverse): set it from the sample on
    /// which the loop takes the new mode.
    fn set_mode(&mut self, mode: i64) -> PyResult<()> {
        let mode = golden::check_mode(mode, "mode").map_err(refused)?;
        self.model.set_mode(mode);
        Ok(())
    }

    /// One ADC sample: the DAC codes the loop drives; returns a dict of the ADC codes
    /// `adc_x`, `adc_y` it reads next (the loop's input ports).
    fn step<'py>(
        &mut self,
        py: Python<'py>,
        dac_x: i64,
        dac_y: i64,
    ) -> PyResult<Bound<'py, PyDict>> {
        check_code(dac_x, self.dac, "dac_x").map_err(refused)?;
        check_code(dac_y, self.dac, "dac_y").map_err(refused)?;
        let adc = self.model.step_codes([dac_x, dac_y]);
        crate::blocks::value_dict(py, ["adc_x", "adc_y"], adc)
    }

    /// ADC sample rate, Hz.
    #[getter]
    fn sample_rate_hz(&self) -> f64 {
        self.model.sample_rate_hz()
    }

    /// ADC samples that clipped so far.
    #[getter]
    fn adc_saturations(&self) -> u64 {
        self.model.adc_saturations()
    }
}
