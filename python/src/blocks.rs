//! One class per block, each the Rust model behind the block's RTL ports, and the float twins.
//!
//! One return shape per kind of method, for every block: `step` takes one clock's inputs and
//! returns a dict of that clock's output ports, named as `ports()` lists them, holding codes as
//! the RTL ports carry them (flags 0/1; a mode 1 normal, 0 reverse); `process` does the same
//! for whole numpy records and returns a dict of arrays with the same keys, releasing the GIL
//! while it runs. A float twin returns the same keys, its values in °/s.
//! Inputs outside their port's format are refused, naming the port, the value and the range.

use numpy::{IntoPyArray, PyArray1, PyReadonlyArray1};
use pyo3::prelude::*;
use pyo3::types::PyDict;

use gyrofx_job::golden::{
    self, check_bw_sel, check_codes, slot_from_ports, CHAIN_OUTPUTS, ESTIMATOR_OUTPUTS,
    ESTIMATOR_SLOT_PORTS, SLOT_PORTS,
};
use gyrofx_job::pipeline::Pipeline;
use gyrofx_model::chain::{self, FloatChain};
use gyrofx_model::estimator::{self, FloatEstimator};
use gyrofx_model::fx::Format;
use gyrofx_model::kf::{self, FloatKf};
use gyrofx_model::mean_filter::{self, FloatMeanFilter};
use gyrofx_model::sequencer::{Schedule, Slot};

use crate::refused;

type Array<'py, T> = Bound<'py, PyArray1<T>>;

/// A numpy `int64` array of `values`.
fn int_array(py: Python<'_>, values: Vec<i64>) -> Array<'_, i64> {
    values.into_pyarray(py)
}

/// A record of integer codes as a port takes it: a numpy `int64` array (read in place), or
/// anything numpy makes a one-dimensional integer array of (a list, any integer or bool dtype,
/// either byte order).
#[derive(FromPyObject)]
pub(crate) enum Codes<'py> {
    Native(PyReadonlyArray1<'py, i64>),
    Like(Bound<'py, PyAny>),
}

impl Codes<'_> {
    /// The codes (`port` names them in errors): borrowed from a contiguous `int64` array,
    /// else converted; a record that is not one-dimensional, not integers, or holds a value
    /// no `int64` holds is refused with gyrofx's own message.
    pub(crate) fn resolve(&self, port: &str) -> PyResult<std::borrow::Cow<'_, [i64]>> {
        match self {
            Codes::Native(array) => Ok(match array.as_slice() {
                Ok(slice) => std::borrow::Cow::Borrowed(slice),
                Err(_) => std::borrow::Cow::Owned(array.as_array().to_vec()),
            }),
            Codes::Like(object) => integer_record(object, port).map(std::borrow::Cow::Owned),
        }
    }
}

/// What to say a record may be.
const CODES_ALLOWED: &str =
    "a one-dimensional record of integer codes: a list, or an array of any integer dtype";

/// `object` as numpy sees it, as `int64` codes.
fn integer_record(object: &Bound<'_, PyAny>, port: &str) -> PyResult<Vec<i64>> {
    let numpy = object.py().import("numpy")?;
    let array = numpy.call_method1("asarray", (object,))?;
    let dimensions: usize = array.getattr("ndim")?.extract()?;
    if dimensions != 1 {
        return Err(refused(format!(
            "{port}: {dimensions} dimensions; allowed: {CODES_ALLOWED}"
        )));
    }
    if array.getattr("size")?.extract::<usize>()? == 0 {
        return Ok(Vec::new());
    }
    let dtype = array.getattr("dtype")?;
    let kind: String = dtype.getattr("kind")?.extract()?;
    let name: String = dtype.getattr("name")?.extract()?;
    match kind.as_str() {
        "i" | "b" => {
            let codes = array.call_method1("astype", ("int64",))?;
            let codes: PyReadonlyArray1<'_, i64> = codes.extract()?;
            Ok(codes.as_array().to_vec())
        }
        "u" => {
            let codes = array.call_method1("astype", ("uint64",))?;
            let codes: PyReadonlyArray1<'_, u64> = codes.extract()?;
            codes
                .as_array()
                .iter()
                .enumerate()
                .map(|(index, code)| {
                    i64::try_from(*code).map_err(|_| {
                        refused(format!(
                            "{port}[{index}] = {code}: not a code of any port (at most 2^63 - 1)"
                        ))
                    })
                })
                .collect()
        }
        _ => Err(refused(format!(
            "{port}: an array of {name}; allowed: {CODES_ALLOWED} (quantize real values first: gyrofx.quantize)"
        ))),
    }
}

/// The codes of a record, each checked against `format` (`port` names it in errors).
pub(crate) fn port_codes<'a>(
    codes: &'a Codes<'_>,
    format: Format,
    port: &str,
) -> PyResult<std::borrow::Cow<'a, [i64]>> {
    let out = codes.resolve(port)?;
    check_codes(&out, format, port).map_err(refused)?;
    Ok(out)
}

/// Checks that every array has `length` samples.
pub(crate) fn same_length(lengths: &[(&str, usize)]) -> PyResult<usize> {
    let (first, length) = lengths[0];
    for (name, other) in &lengths[1..] {
        if *other != length {
            return Err(refused(format!(
                "{name} has {other} samples but {first} has {length}: the ports' records must be equally long"
            )));
        }
    }
    Ok(length)
}

/// A port `process` takes as one value for the whole record or one per sample (`bw_sel`,
/// `mode`, `enable`).
#[derive(FromPyObject)]
pub(crate) enum PerSample<'py> {
    One(i64),
    Each(Codes<'py>),
}

impl PerSample<'_> {
    /// The values for `samples` samples, each checked by `check` (given the port's name, with
    /// its index for an array).
    pub(crate) fn values<T: Copy>(
        &self,
        samples: usize,
        port: &str,
        check: impl Fn(i64, &str) -> golden::PortResult<T>,
    ) -> PyResult<Vec<T>> {
        match self {
            PerSample::One(value) => Ok(vec![check(*value, port).map_err(refused)?; samples]),
            PerSample::Each(codes) => {
                let array = codes.resolve(port)?;
                same_length(&[("the input", samples), (port, array.len())])?;
                array
                    .iter()
                    .enumerate()
                    .map(|(i, v)| check(*v, &format!("{port}[{i}]")).map_err(refused))
                    .collect()
            }
        }
    }

    /// `bw_sel` for `samples` samples, each addressing a ROM of `rom_depth` entries.
    pub(crate) fn per_sample(&self, samples: usize, rom_depth: usize) -> PyResult<Vec<usize>> {
        self.values(samples, "bw_sel", |b, port| {
            check_bw_sel(b, rom_depth, port)
        })
    }
}

/// The bit-accurate steady-state KF (`gyrofx_kf`): one step per sample; the RTL shows the
/// output with `out_valid` `latency_clocks` after the sample's `ce` and takes a sample at most
/// every `min_clocks_per_sample` clocks (the model returns the output at once).
#[pyclass(module = "gyrofx")]
pub(crate) struct Kf {
    ports: golden::Kf,
    pipeline: Pipeline,
}

impl Kf {
    pub(crate) fn new(plan: &kf::Plan, pipeline: Pipeline) -> Kf {
        Kf {
            ports: golden::Kf::new(plan),
            pipeline,
        }
    }
}

#[pymethods]
impl Kf {
    /// Saturations and wraps per quantization point since it was made (a reset keeps them):
    /// a dict of counts, e.g. `{"x1": 0, "x2": 0, "rate_out": 3}` for the KF; empty for a block
    /// that cannot overflow.
    fn overflow_counts<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        overflow_dict(py, self.ports.overflows())
    }

    fn __repr__(&self) -> String {
        block_repr("Kf", &self.ports.ports())
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

    /// Clears the state (the RTL's synchronous reset).
    fn reset(&mut self) {
        self.ports.reset();
    }

    /// One step: `z` a code of the input format, `bw_sel` the ROM address; returns
    /// `{"out_valid": 1, "rate_out": code}` (`rate_out` a code of the output format; every
    /// sample gives one, `latency_clocks` later in the RTL).
    #[pyo3(signature = (z, bw_sel = 0))]
    fn step<'py>(&mut self, py: Python<'py>, z: i64, bw_sel: i64) -> PyResult<Bound<'py, PyDict>> {
        let rate_out = self.ports.step(z, bw_sel).map_err(refused)?;
        value_dict(py, ["out_valid", "rate_out"], [1, rate_out])
    }

    /// `step` over a record: `z` integer codes, `bw_sel` one address or one per sample;
    /// returns a dict of `out_valid`, `rate_out` int64 arrays.
    #[pyo3(signature = (z, bw_sel = PerSample::One(0)), text_signature = "($self, z, bw_sel=0)")]
    fn process<'py>(
        &mut self,
        py: Python<'py>,
        z: Codes<'py>,
        bw_sel: PerSample<'py>,
    ) -> PyResult<Bound<'py, PyDict>> {
        let (input, depth) = (self.ports.plan().input, self.ports.plan().rom.len());
        let z = port_codes(&z, input, "z")?;
        let select = match bw_sel {
            PerSample::One(sel) => {
                vec![check_bw_sel(sel, depth, "bw_sel").map_err(refused)?]
            }
            each => each.per_sample(z.len(), depth)?,
        };
        let model = self.ports.model();
        let out = py.detach(|| {
            let mut out = vec![0i64; z.len()];
            if let [sel] = select[..] {
                model.process(&z, sel, &mut out);
                return out;
            }
            // Each run of one `bw_sel` through the model's block kernel.
            let mut start = 0;
            while start < z.len() {
                let sel = select[start];
                let end = select[start..]
                    .iter()
                    .position(|s| *s != sel)
                    .map_or(z.len(), |p| start + p);
                model.process(&z[start..end], sel, &mut out[start..end]);
                start = end;
            }
            out
        });
        port_dict(py, ["out_valid", "rate_out"], [vec![1; out.len()], out])
    }

    /// The state `[x1, x2]` as codes of the state format.
    fn state(&mut self) -> (i64, i64) {
        let [x1, x2] = self.ports.model().state();
        (x1 as i64, x2 as i64)
    }

    /// The derived bound (LSB of the output format) on |fixed − float twin| after `samples`
    /// steps with `switches` changes of `bw_sel` (the bound the vectors' report checks).
    #[pyo3(signature = (samples, switches = 0))]
    fn error_bound_lsb(&self, samples: u64, switches: u64) -> f64 {
        kf::bound::rate_error_bound_lsb(self.ports.plan(), samples, switches)
    }

    /// Input format (`z`).
    #[getter]
    fn input_format(&self) -> String {
        self.ports.plan().input.to_string()
    }

    /// Output format (`rate_out`).
    #[getter]
    fn output_format(&self) -> String {
        self.ports.plan().output.to_string()
    }
}

/// The KF's float twin, °/s in and out.
#[pyclass(module = "gyrofx")]
pub(crate) struct KfFloat {
    model: FloatKf,
    rom_depth: usize,
}

impl KfFloat {
    pub(crate) fn new(plan: &kf::Plan, ideal: bool) -> KfFloat {
        let gains = if ideal {
            plan.gains.clone()
        } else {
            plan.quantized_gains()
        };
        KfFloat {
            model: FloatKf::new(gains),
            rom_depth: plan.rom.len(),
        }
    }
}

#[pymethods]
impl KfFloat {
    /// Clears the state.
    fn reset(&mut self) {
        self.model.reset();
    }

    /// One step on `z` (°/s); returns `{"out_valid": 1, "rate_out": °/s}`.
    #[pyo3(signature = (z, bw_sel = 0))]
    fn step<'py>(&mut self, py: Python<'py>, z: f64, bw_sel: i64) -> PyResult<Bound<'py, PyDict>> {
        let bw_sel = check_bw_sel(bw_sel, self.rom_depth, "bw_sel").map_err(refused)?;
        let dict = PyDict::new(py);
        dict.set_item("out_valid", 1)?;
        dict.set_item("rate_out", self.model.step(z, bw_sel))?;
        Ok(dict)
    }

    /// `step` over a record of real values (°/s): a dict of `out_valid` (int64) and
    /// `rate_out` (float64) arrays.
    #[pyo3(signature = (z, bw_sel = PerSample::One(0)), text_signature = "($self, z, bw_sel=0)")]
    fn process<'py>(
        &mut self,
        py: Python<'py>,
        z: PyReadonlyArray1<'py, f64>,
        bw_sel: PerSample<'py>,
    ) -> PyResult<Bound<'py, PyDict>> {
        let z = z.as_array().to_vec();
        let select = bw_sel.per_sample(z.len(), self.rom_depth)?;
        let model = &mut self.model;
        let out = py.detach(|| {
            z.iter()
                .zip(&select)
                .map(|(z, b)| model.step(*z, *b))
                .collect::<Vec<_>>()
        });
        let dict = PyDict::new(py);
        dict.set_item("out_valid", int_array(py, vec![1; out.len()]))?;
        dict.set_item("rate_out", out.into_pyarray(py))?;
        Ok(dict)
    }
}

/// `overflows` as a dict, in the model's order.
pub(crate) fn overflow_dict(
    py: Python<'_>,
    overflows: golden::Overflows,
) -> PyResult<Bound<'_, PyDict>> {
    let dict = PyDict::new(py);
    for (point, count) in overflows {
        dict.set_item(point, count)?;
    }
    Ok(dict)
}

/// `Kf(z: s24.14, bw_sel: u2.0 -> out_valid: u1.0, rate_out: s24.14)`: a block's ports and
/// their formats.
pub(crate) fn block_repr(name: &str, ports: &[golden::ports::Port]) -> String {
    let list = |output: bool| {
        ports
            .iter()
            .filter(|p| p.output == output)
            .map(|p| format!("{}: {}", p.name, p.format))
            .collect::<Vec<_>>()
            .join(", ")
    };
    format!("{name}({} -> {})", list(false), list(true))
}

/// A dict of one value per port: what every `step` returns.
pub(crate) fn value_dict<'py, T, const N: usize>(
    py: Python<'py>,
    names: [&str; N],
    values: [T; N],
) -> PyResult<Bound<'py, PyDict>>
where
    T: IntoPyObject<'py>,
{
    let dict = PyDict::new(py);
    for (name, value) in names.into_iter().zip(values) {
        dict.set_item(name, value)?;
    }
    Ok(dict)
}

/// A dict of one int64 array per port.
pub(crate) fn port_dict<'py, const N: usize>(
    py: Python<'py>,
    names: [&str; N],
    columns: [Vec<i64>; N],
) -> PyResult<Bound<'py, PyDict>> {
    let dict = PyDict::new(py);
    for (name, column) in names.into_iter().zip(columns) {
        dict.set_item(name, int_array(py, column))?;
    }
    Ok(dict)
}

/// The mode-reversal sequencer (`gyrofx_sequencer`): its outputs are combinational, for the
/// current clock, and it advances every clock.
#[pyclass(module = "gyrofx")]
pub(crate) struct Sequencer {
    ports: golden::Sequencer,
    pipeline: Pipeline,
}

impl Sequencer {
    pub(crate) fn new(schedule: &Schedule, pipeline: Pipeline) -> Sequencer {
        Sequencer {
            ports: golden::Sequencer::new(schedule),
            pipeline,
        }
    }
}

#[pymethods]
impl Sequencer {
    /// Saturations and wraps per quantization point since it was made (a reset keeps them):
    /// a dict of counts, e.g. `{"x1": 0, "x2": 0, "rate_out": 3}` for the KF; empty for a block
    /// that cannot overflow.
    fn overflow_counts<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        overflow_dict(py, self.ports.overflows())
    }

    fn __repr__(&self) -> String {
        block_repr("Sequencer", &self.ports.ports())
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

    /// Back to the first sample of the first interval.
    fn reset(&mut self) {
        self.ports.reset();
    }

    /// This clock's slot as a dict of port codes; then advances.
    fn step<'py>(&mut self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let dict = PyDict::new(py);
        for (name, code) in SLOT_PORTS.into_iter().zip(self.ports.step()) {
            dict.set_item(name, code)?;
        }
        Ok(dict)
    }

    /// `samples` clocks: a dict of int64 arrays, one per port.
    fn process<'py>(&mut self, py: Python<'py>, samples: usize) -> PyResult<Bound<'py, PyDict>> {
        let ports = &mut self.ports;
        let columns = py.detach(|| {
            let mut columns: [Vec<i64>; 9] = std::array::from_fn(|_| Vec::with_capacity(samples));
            for _ in 0..samples {
                for (column, code) in columns.iter_mut().zip(ports.step()) {
                    column.push(code);
                }
            }
            columns
        });
        port_dict(py, SLOT_PORTS, columns)
    }
}

/// The bit-accurate least-squares bias estimator (`gyrofx_bias_estimator`): the sequencer's
/// slot comes in on ports, the bias estimates go out registered.
#[pyclass(module = "gyrofx")]
pub(crate) struct Estimator {
    ports: golden::Estimator,
    pipeline: Pipeline,
}

impl Estimator {
    pub(crate) fn new(plan: &estimator::Plan, pipeline: Pipeline) -> Estimator {
        Estimator {
            ports: golden::Estimator::new(plan),
            pipeline,
        }
    }
}

#[pymethods]
impl Estimator {
    /// Saturations and wraps per quantization point since it was made (a reset keeps them):
    /// a dict of counts, e.g. `{"x1": 0, "x2": 0, "rate_out": 3}` for the KF; empty for a block
    /// that cannot overflow.
    fn overflow_counts<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        overflow_dict(py, self.ports.overflows())
    }

    fn __repr__(&self) -> String {
        block_repr("Estimator", &self.ports.ports())
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

    /// Clears the sums and the estimates.
    fn reset(&mut self) {
        self.ports.reset();
    }

    /// One clock: both gyros' samples (input-format codes) and the sequencer's slot; returns a
    /// dict of `bias_a`, `bias_b`, `estimated` after the clock.
    #[allow(clippy::too_many_arguments)]
    fn step<'py>(
        &mut self,
        py: Python<'py>,
        y_a: i64,
        y_b: i64,
        blank_a: i64,
        blank_b: i64,
        done_a: i64,
        done_b: i64,
        interval_a: i64,
        interval_b: i64,
        window_done: i64,
    ) -> PyResult<Bound<'py, PyDict>> {
        let outputs = self
            .ports
            .step(
                [y_a, y_b],
                [
                    blank_a,
                    blank_b,
                    done_a,
                    done_b,
                    interval_a,
                    interval_b,
                    window_done,
                ],
            )
            .map_err(refused)?;
        value_dict(py, ESTIMATOR_OUTPUTS, outputs)
    }

    /// `step` over records: `y_a`, `y_b` and the seven slot ports as int64 arrays of one
    /// length (a `Sequencer.process` dict supplies the slot); returns a dict of `bias_a`,
    /// `bias_b`, `estimated` arrays.
    #[allow(clippy::too_many_arguments)]
    fn process<'py>(
        &mut self,
        py: Python<'py>,
        y_a: Codes<'py>,
        y_b: Codes<'py>,
        blank_a: Codes<'py>,
        blank_b: Codes<'py>,
        done_a: Codes<'py>,
        done_b: Codes<'py>,
        interval_a: Codes<'py>,
        interval_b: Codes<'py>,
        window_done: Codes<'py>,
    ) -> PyResult<Bound<'py, PyDict>> {
        let input = self.ports.plan().input;
        let y_a = port_codes(&y_a, input, "y_a")?;
        let y_b = port_codes(&y_b, input, "y_b")?;
        let slot_records = [
            blank_a,
            blank_b,
            done_a,
            done_b,
            interval_a,
            interval_b,
            window_done,
        ];
        let views = ESTIMATOR_SLOT_PORTS
            .iter()
            .zip(&slot_records)
            .map(|(name, record)| record.resolve(name))
            .collect::<PyResult<Vec<_>>>()?;
        let mut lengths = vec![("y_a", y_a.len()), ("y_b", y_b.len())];
        lengths.extend(
            ESTIMATOR_SLOT_PORTS
                .iter()
                .zip(&views)
                .map(|(name, view)| (*name, view.len())),
        );
        let samples = same_length(&lengths)?;
        let slots = (0..samples)
            .map(|i| {
                let ports: [i64; 7] = std::array::from_fn(|p| views[p][i]);
                self.ports.slot(ports, &format!("[{i}]")).map_err(refused)
            })
            .collect::<PyResult<Vec<Slot>>>()?;
        let ports = &mut self.ports;
        let columns = py.detach(|| {
            let mut columns: [Vec<i64>; 3] = std::array::from_fn(|_| Vec::with_capacity(samples));
            for ((slot, a), b) in slots.iter().zip(y_a.iter()).zip(y_b.iter()) {
                for (column, code) in columns.iter_mut().zip(ports.step_slot(slot, [*a, *b])) {
                    column.push(code);
                }
            }
            columns
        });
        port_dict(py, ESTIMATOR_OUTPUTS, columns)
    }

    /// Input format (`y_a`, `y_b`).
    #[getter]
    fn input_format(&self) -> String {
        self.ports.plan().input.to_string()
    }

    /// Bias format (`bias_a`, `bias_b`).
    #[getter]
    fn bias_format(&self) -> String {
        self.ports.plan().bias.to_string()
    }
}

/// The estimator's float twin, °/s: `step` returns the bias estimates after the clock.
#[pyclass(module = "gyrofx")]
pub(crate) struct EstimatorFloat {
    schedule: Schedule,
    modes: Vec<i8>,
    model: FloatEstimator,
}

impl EstimatorFloat {
    pub(crate) fn new(plan: &estimator::Plan, ideal: bool) -> EstimatorFloat {
        EstimatorFloat {
            schedule: plan.schedule.clone(),
            modes: plan.schedule.pattern.modes(plan.schedule.intervals),
            model: if ideal {
                FloatEstimator::ideal(plan)
            } else {
                FloatEstimator::quantized(plan)
            },
        }
    }
}

#[pymethods]
impl EstimatorFloat {
    /// Clears the sums and the estimates.
    fn reset(&mut self) {
        self.model.reset();
    }

    /// One clock on `y_a`, `y_b` (°/s) and the slot's ports; returns a dict of `bias_a`,
    /// `bias_b` (°/s).
    #[allow(clippy::too_many_arguments)]
    fn step<'py>(
        &mut self,
        py: Python<'py>,
        y_a: f64,
        y_b: f64,
        blank_a: i64,
        blank_b: i64,
        done_a: i64,
        done_b: i64,
        interval_a: i64,
        interval_b: i64,
        window_done: i64,
    ) -> PyResult<Bound<'py, PyDict>> {
        let slot = slot_from_ports(
            &self.schedule,
            &self.modes,
            [
                blank_a,
                blank_b,
                done_a,
                done_b,
                interval_a,
                interval_b,
                window_done,
            ],
            "",
        )
        .map_err(refused)?;
        self.model.step(&slot, [y_a, y_b]);
        let [a, b] = self.model.bias();
        value_dict(py, ["bias_a", "bias_b"], [a, b])
    }
}

/// The bit-accurate mean filter with gross-error rejection (`gyrofx_mean_filter`).
#[pyclass(module = "gyrofx")]
pub(crate) struct MeanFilter {
    ports: golden::MeanFilter,
    pipeline: Pipeline,
}

impl MeanFilter {
    pub(crate) fn new(plan: &mean_filter::Plan, pipeline: Pipeline) -> MeanFilter {
        MeanFilter {
            ports: golden::MeanFilter::new(plan),
            pipeline,
        }
    }
}

#[pymethods]
impl MeanFilter {
    /// Saturations and wraps per quantization point since it was made (a reset keeps them):
    /// a dict of counts, e.g. `{"x1": 0, "x2": 0, "rate_out": 3}` for the KF; empty for a block
    /// that cannot overflow.
    fn overflow_counts<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        overflow_dict(py, self.ports.overflows())
    }

    fn __repr__(&self) -> String {
        block_repr("MeanFilter", &self.ports.ports())
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

    /// Drops the current block's samples.
    fn reset(&mut self) {
        self.ports.reset();
    }

    /// One sample `x` (input-format code); returns a dict of `y_valid`, `y`, `kept`: `y_valid`
    /// 1 on the block's last sample, else 0 with `y` and `kept` 0 (as `process` has them).
    fn step<'py>(&mut self, py: Python<'py>, x: i64) -> PyResult<Bound<'py, PyDict>> {
        let (valid, y, kept) = match self.ports.step(x).map_err(refused)? {
            Some((y, kept)) => (1, y, kept),
            None => (0, 0, 0),
        };
        value_dict(py, ["y_valid", "y", "kept"], [valid, y, kept])
    }

    /// `step` over a record: a dict of `y_valid`, `y`, `kept` int64 arrays, one entry per input
    /// sample (`y` and `kept` are 0 where `y_valid` is 0).
    fn process<'py>(&mut self, py: Python<'py>, x: Codes<'py>) -> PyResult<Bound<'py, PyDict>> {
        let x = port_codes(&x, self.ports.plan().input, "x")?;
        let ports = &mut self.ports;
        let columns = py.detach(|| {
            let mut columns: [Vec<i64>; 3] = std::array::from_fn(|_| Vec::with_capacity(x.len()));
            for x in x.iter() {
                let (valid, y, kept) = match ports.step_checked(*x) {
                    Some((y, kept)) => (1, y, kept),
                    None => (0, 0, 0),
                };
                columns[0].push(valid);
                columns[1].push(y);
                columns[2].push(kept);
            }
            columns
        });
        port_dict(py, ["y_valid", "y", "kept"], columns)
    }

    /// Samples per block (`L`).
    #[getter]
    fn window(&self) -> u32 {
        self.ports.plan().window
    }

    /// Input format (`x`).
    #[getter]
    fn input_format(&self) -> String {
        self.ports.plan().input.to_string()
    }

    /// Output format (`y`).
    #[getter]
    fn output_format(&self) -> String {
        self.ports.plan().output.to_string()
    }
}

/// The mean filter's float twin, °/s.
#[pyclass(module = "gyrofx")]
pub(crate) struct MeanFilterFloat {
    model: FloatMeanFilter,
}

impl MeanFilterFloat {
    pub(crate) fn new(plan: &mean_filter::Plan) -> MeanFilterFloat {
        MeanFilterFloat {
            model: FloatMeanFilter::new(plan),
        }
    }
}

#[pymethods]
impl MeanFilterFloat {
    /// Drops the current block's samples.
    fn reset(&mut self) {
        self.model.reset();
    }

    /// One sample (°/s); a dict of `y_valid`, `y` (the block's mean, °/s), `kept`, as
    /// `MeanFilter.step` has them (0 where `y_valid` is 0).
    fn step<'py>(&mut self, py: Python<'py>, x: f64) -> PyResult<Bound<'py, PyDict>> {
        let (valid, y, kept) = match self.model.step(x) {
            Some((y, kept)) => (1, y, kept),
            None => (0, 0.0, 0),
        };
        let dict = PyDict::new(py);
        dict.set_item("y_valid", valid)?;
        dict.set_item("y", y)?;
        dict.set_item("kept", kept)?;
        Ok(dict)
    }
}

/// The whole chain (`gyrofx_top`): sequencer, estimator, calibration, KF.
#[pyclass(module = "gyrofx")]
pub(crate) struct Chain {
    ports: golden::Chain,
    pipeline: Pipeline,
}

impl Chain {
    pub(crate) fn new(plan: &chain::Plan, pipeline: Pipeline) -> Chain {
        Chain {
            ports: golden::Chain::new(plan),
            pipeline,
        }
    }
}

#[pymethods]
impl Chain {
    /// Saturations and wraps per quantization point since it was made (a reset keeps them):
    /// a dict of counts, e.g. `{"x1": 0, "x2": 0, "rate_out": 3}` for the KF; empty for a block
    /// that cannot overflow.
    fn overflow_counts<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        overflow_dict(py, self.ports.overflows())
    }

    fn __repr__(&self) -> String {
        block_repr("Chain", &self.ports.ports())
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

    /// Clears every block.
    fn reset(&mut self) {
        self.ports.reset();
    }

    /// The modes `(mode_a, mode_b)` (1 normal, 0 reverse) the next `step` runs in: what a
    /// plant needs before it produces that sample.
    fn next_modes(&self) -> (i64, i64) {
        let [a, b] = self.ports.next_modes();
        (a, b)
    }

    /// One clock: both gyros' samples (input-format codes) and `bw_sel`; returns a dict of the
    /// output ports (`rate_out` is 0 where `out_valid` is 0).
    #[pyo3(signature = (y_a, y_b, bw_sel = 0))]
    fn step<'py>(
        &mut self,
        py: Python<'py>,
        y_a: i64,
        y_b: i64,
        bw_sel: i64,
    ) -> PyResult<Bound<'py, PyDict>> {
        let codes = self.ports.step(y_a, y_b, bw_sel).map_err(refused)?;
        let dict = PyDict::new(py);
        for (name, code) in CHAIN_OUTPUTS.into_iter().zip(codes) {
            dict.set_item(name, code)?;
        }
        Ok(dict)
    }

    /// `step` over records: a dict of int64 arrays, one per output port.
    #[pyo3(signature = (y_a, y_b, bw_sel = PerSample::One(0)), text_signature = "($self, y_a, y_b, bw_sel=0)")]
    fn process<'py>(
        &mut self,
        py: Python<'py>,
        y_a: Codes<'py>,
        y_b: Codes<'py>,
        bw_sel: PerSample<'py>,
    ) -> PyResult<Bound<'py, PyDict>> {
        let input = self.ports.plan().estimator.input;
        let y_a = port_codes(&y_a, input, "y_a")?;
        let y_b = port_codes(&y_b, input, "y_b")?;
        let samples = same_length(&[("y_a", y_a.len()), ("y_b", y_b.len())])?;
        let select = bw_sel.per_sample(samples, self.ports.plan().kf.rom.len())?;
        let ports = &mut self.ports;
        let columns = py.detach(|| {
            let mut columns: [Vec<i64>; 7] = std::array::from_fn(|_| Vec::with_capacity(samples));
            for ((a, b), sel) in y_a.iter().zip(y_b.iter()).zip(&select) {
                for (column, code) in columns.iter_mut().zip(ports.step_checked([*a, *b], *sel)) {
                    column.push(code);
                }
            }
            columns
        });
        port_dict(py, CHAIN_OUTPUTS, columns)
    }
}

/// The chain's float twin, °/s.
#[pyclass(module = "gyrofx")]
pub(crate) struct ChainFloat {
    model: FloatChain,
    rom_depth: usize,
}

impl ChainFloat {
    pub(crate) fn new(plan: &chain::Plan, ideal: bool) -> ChainFloat {
        ChainFloat {
            model: if ideal {
                FloatChain::ideal(plan)
            } else {
                FloatChain::quantized(plan)
            },
            rom_depth: plan.kf.rom.len(),
        }
    }
}

#[pymethods]
impl ChainFloat {
    /// Clears every block.
    fn reset(&mut self) {
        self.model.reset();
    }

    /// One clock on `y_a`, `y_b` (°/s): a dict of `out_valid`, `rate` (°/s, or None),
    /// `bias_a`, `bias_b` (°/s).
    #[pyo3(signature = (y_a, y_b, bw_sel = 0))]
    fn step<'py>(
        &mut self,
        py: Python<'py>,
        y_a: f64,
        y_b: f64,
        bw_sel: i64,
    ) -> PyResult<Bound<'py, PyDict>> {
        let bw_sel = check_bw_sel(bw_sel, self.rom_depth, "bw_sel").map_err(refused)?;
        let sample = self.model.step([y_a, y_b], bw_sel);
        let dict = PyDict::new(py);
        dict.set_item("out_valid", i64::from(sample.rate.is_some()))?;
        dict.set_item("rate_out", sample.rate)?;
        dict.set_item("bias_a", sample.estimator.bias[0])?;
        dict.set_item("bias_b", sample.estimator.bias[1])?;
        Ok(dict)
    }
}
