//! One class per block, each the Rust model behind the block's RTL ports, and the float twins.
//!
//! `step` takes one clock's inputs and returns that clock's outputs as the RTL ports carry them
//! (codes; flags 0/1; a mode 1 normal, 0 reverse); `process` does the same for whole numpy
//! records and returns a dict of arrays, one per output port, releasing the GIL while it runs.
//! Inputs outside their port's format are refused, naming the port, the value and the range.

use numpy::{IntoPyArray, PyArray1, PyReadonlyArray1};
use pyo3::prelude::*;
use pyo3::types::PyDict;

use gyrofx_model::chain::{self, FixedChain, FloatChain};
use gyrofx_model::estimator::{self, FixedEstimator, FloatEstimator};
use gyrofx_model::fx::Format;
use gyrofx_model::kf::{self, FixedKf, FloatKf};
use gyrofx_model::mean_filter::{self, FixedMeanFilter, FloatMeanFilter};
use gyrofx_model::sequencer::{self, Schedule, Slot};

use crate::codes::check_code;
use crate::refused;

type Array<'py, T> = Bound<'py, PyArray1<T>>;

/// A numpy `int64` array of `values`.
fn int_array(py: Python<'_>, values: Vec<i64>) -> Array<'_, i64> {
    values.into_pyarray(py)
}

/// The codes of a numpy array, each checked against `format` (`port` names it in errors).
fn port_codes<'a>(
    codes: &'a PyReadonlyArray1<'_, i64>,
    format: Format,
    port: &str,
) -> PyResult<std::borrow::Cow<'a, [i64]>> {
    // A contiguous array is read in place; a strided one is copied.
    let out = match codes.as_slice() {
        Ok(slice) => std::borrow::Cow::Borrowed(slice),
        Err(_) => std::borrow::Cow::Owned(codes.as_array().to_vec()),
    };
    // Declared formats are at most 64 bits wide: their code range fits i64 (u64 aside, whose
    // top half no i64 reaches).
    let min = i64::try_from(format.min_code()).unwrap_or(i64::MIN);
    let max = i64::try_from(format.max_code()).unwrap_or(i64::MAX);
    if out
        .iter()
        .fold(false, |bad, c| bad | (*c < min) | (*c > max))
    {
        let index = out.iter().position(|c| *c < min || *c > max).unwrap_or(0);
        check_code(out[index], format, &format!("{port}[{index}]"))?;
    }
    Ok(out)
}

/// Checks that every array has `length` samples.
fn same_length(lengths: &[(&str, usize)]) -> PyResult<usize> {
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

/// A `bw_sel` that addresses the KF's ROM.
fn check_bw_sel(bw_sel: i64, rom_depth: usize, what: &str) -> PyResult<usize> {
    usize::try_from(bw_sel)
        .ok()
        .filter(|b| *b < rom_depth)
        .ok_or_else(|| {
            refused(format!(
                "{what} = {bw_sel} does not address the KF's coefficient ROM: allowed 0..={}",
                rom_depth - 1
            ))
        })
}

/// `bw_sel` for `process`: one value for the whole record or one per sample.
#[derive(FromPyObject)]
pub(crate) enum BandwidthSelect<'py> {
    One(i64),
    Each(PyReadonlyArray1<'py, i64>),
}

impl BandwidthSelect<'_> {
    fn per_sample(&self, samples: usize, rom_depth: usize) -> PyResult<Vec<usize>> {
        match self {
            BandwidthSelect::One(b) => Ok(vec![check_bw_sel(*b, rom_depth, "bw_sel")?; samples]),
            BandwidthSelect::Each(array) => {
                let array = array.as_array();
                same_length(&[("the input", samples), ("bw_sel", array.len())])?;
                array
                    .iter()
                    .enumerate()
                    .map(|(i, b)| check_bw_sel(*b, rom_depth, &format!("bw_sel[{i}]")))
                    .collect()
            }
        }
    }
}

/// The bit-accurate steady-state KF (`gyrofx_kf`): one step per clock, output registered with
/// `out_valid` one clock later in the RTL (the model returns it at once).
#[pyclass(module = "gyrofx")]
pub(crate) struct Kf {
    plan: kf::Plan,
    model: FixedKf,
}

impl Kf {
    pub(crate) fn new(plan: &kf::Plan) -> Kf {
        Kf {
            plan: plan.clone(),
            model: FixedKf::new(plan),
        }
    }
}

#[pymethods]
impl Kf {
    /// Clears the state (the RTL's synchronous reset).
    fn reset(&mut self) {
        self.model.reset();
    }

    /// One step: `z` a code of the input format, `bw_sel` the ROM address; returns `rate_out`
    /// (a code of the output format).
    #[pyo3(signature = (z, bw_sel = 0))]
    fn step(&mut self, z: i64, bw_sel: i64) -> PyResult<i64> {
        check_code(z, self.plan.input, "z")?;
        let bw_sel = check_bw_sel(bw_sel, self.plan.rom.len(), "bw_sel")?;
        Ok(self.model.step(z, bw_sel))
    }

    /// `step` over a record: `z` an int64 array, `bw_sel` one address or one per sample;
    /// returns `rate_out` as an int64 array.
    #[pyo3(signature = (z, bw_sel = BandwidthSelect::One(0)))]
    fn process<'py>(
        &mut self,
        py: Python<'py>,
        z: PyReadonlyArray1<'py, i64>,
        bw_sel: BandwidthSelect<'py>,
    ) -> PyResult<Array<'py, i64>> {
        let z = port_codes(&z, self.plan.input, "z")?;
        let model = &mut self.model;
        if let BandwidthSelect::One(sel) = bw_sel {
            let sel = check_bw_sel(sel, self.plan.rom.len(), "bw_sel")?;
            let out = py.detach(|| {
                let mut out = vec![0i64; z.len()];
                model.process(&z, sel, &mut out);
                out
            });
            return Ok(int_array(py, out));
        }
        let select = bw_sel.per_sample(z.len(), self.plan.rom.len())?;
        let out = py.detach(|| {
            // Each run of one `bw_sel` through the model's block kernel.
            let mut out = vec![0i64; z.len()];
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
        Ok(int_array(py, out))
    }

    /// The state `[x1, x2]` as codes of the state format.
    fn state(&self) -> (i64, i64) {
        let [x1, x2] = self.model.state();
        (x1 as i64, x2 as i64)
    }

    /// The derived bound (LSB of the output format) on |fixed − float twin| after `samples`
    /// steps with `switches` changes of `bw_sel` (the bound the vectors' report checks).
    #[pyo3(signature = (samples, switches = 0))]
    fn error_bound_lsb(&self, samples: u64, switches: u64) -> f64 {
        kf::bound::rate_error_bound_lsb(&self.plan, samples, switches)
    }

    /// Input format (`z`).
    #[getter]
    fn input_format(&self) -> String {
        self.plan.input.to_string()
    }

    /// Output format (`rate_out`).
    #[getter]
    fn output_format(&self) -> String {
        self.plan.output.to_string()
    }

    /// Clocks from `z` to `rate_out` in the reference RTL.
    #[getter]
    fn latency_clocks(&self) -> u32 {
        1
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

    /// One step on `z` (°/s); returns the rate estimate (°/s).
    #[pyo3(signature = (z, bw_sel = 0))]
    fn step(&mut self, z: f64, bw_sel: i64) -> PyResult<f64> {
        let bw_sel = check_bw_sel(bw_sel, self.rom_depth, "bw_sel")?;
        Ok(self.model.step(z, bw_sel))
    }

    /// `step` over a float64 record.
    #[pyo3(signature = (z, bw_sel = BandwidthSelect::One(0)))]
    fn process<'py>(
        &mut self,
        py: Python<'py>,
        z: PyReadonlyArray1<'py, f64>,
        bw_sel: BandwidthSelect<'py>,
    ) -> PyResult<Array<'py, f64>> {
        let z = z.as_array().to_vec();
        let select = bw_sel.per_sample(z.len(), self.rom_depth)?;
        let model = &mut self.model;
        let out = py.detach(|| {
            z.iter()
                .zip(&select)
                .map(|(z, b)| model.step(*z, *b))
                .collect::<Vec<_>>()
        });
        Ok(out.into_pyarray(py))
    }
}

/// The names of a slot's ports, in the RTL's order.
const SLOT_PORTS: [&str; 9] = [
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
fn slot_codes(slot: &Slot) -> [i64; 9] {
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

/// A dict of one int64 array per port.
fn port_dict<'py, const N: usize>(
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
    model: sequencer::Sequencer,
}

impl Sequencer {
    pub(crate) fn new(schedule: &Schedule) -> Sequencer {
        Sequencer {
            model: sequencer::Sequencer::new(schedule),
        }
    }
}

#[pymethods]
impl Sequencer {
    /// Back to the first sample of the first interval.
    fn reset(&mut self) {
        self.model.reset();
    }

    /// This clock's slot as a dict of port codes; then advances.
    fn step<'py>(&mut self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let codes = slot_codes(&self.model.advance());
        let dict = PyDict::new(py);
        for (name, code) in SLOT_PORTS.into_iter().zip(codes) {
            dict.set_item(name, code)?;
        }
        Ok(dict)
    }

    /// `samples` clocks: a dict of int64 arrays, one per port.
    fn process<'py>(&mut self, py: Python<'py>, samples: usize) -> PyResult<Bound<'py, PyDict>> {
        let model = &mut self.model;
        let columns = py.detach(|| {
            let mut columns: [Vec<i64>; 9] = std::array::from_fn(|_| Vec::with_capacity(samples));
            for _ in 0..samples {
                for (column, code) in columns.iter_mut().zip(slot_codes(&model.advance())) {
                    column.push(code);
                }
            }
            columns
        });
        port_dict(py, SLOT_PORTS, columns)
    }
}

/// The slot the estimator's ports describe (its modes follow from the schedule).
fn slot_from_ports(
    schedule: &Schedule,
    modes: &[i8],
    ports: [i64; 7],
    what: &str,
) -> PyResult<Slot> {
    let flag = |value: i64, name: &str| -> PyResult<bool> {
        match value {
            0 => Ok(false),
            1 => Ok(true),
            other => Err(refused(format!("{name}{what} = {other}: a flag is 0 or 1"))),
        }
    };
    let interval = |value: i64, name: &str| -> PyResult<usize> {
        usize::try_from(value)
            .ok()
            .filter(|i| *i < schedule.intervals)
            .ok_or_else(|| {
                refused(format!(
                    "{name}{what} = {value}: allowed 0..={} (the sequencer's intervals)",
                    schedule.intervals - 1
                ))
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

/// The estimator's slot inputs, in its port order (after `y_a`, `y_b`).
const ESTIMATOR_SLOT_PORTS: [&str; 7] = [
    "blank_a",
    "blank_b",
    "done_a",
    "done_b",
    "interval_a",
    "interval_b",
    "window_done",
];

/// The bit-accurate least-squares bias estimator (`gyrofx_bias_estimator`): the sequencer's
/// slot comes in on ports, the bias estimates go out registered.
#[pyclass(module = "gyrofx")]
pub(crate) struct Estimator {
    plan: estimator::Plan,
    modes: Vec<i8>,
    model: FixedEstimator,
}

impl Estimator {
    pub(crate) fn new(plan: &estimator::Plan) -> Estimator {
        Estimator {
            plan: plan.clone(),
            modes: plan.schedule.pattern.modes(plan.schedule.intervals),
            model: FixedEstimator::new(plan),
        }
    }

    fn outputs(&self) -> [i64; 3] {
        let [a, b] = self.model.bias();
        [a as i64, b as i64, i64::from(self.model.estimated())]
    }
}

#[pymethods]
impl Estimator {
    /// Clears the sums and the estimates.
    fn reset(&mut self) {
        self.model.reset();
    }

    /// One clock: both gyros' samples (input-format codes) and the sequencer's slot; returns
    /// `(bias_a, bias_b, estimated)` after the clock.
    #[allow(clippy::too_many_arguments)]
    fn step(
        &mut self,
        y_a: i64,
        y_b: i64,
        blank_a: i64,
        blank_b: i64,
        done_a: i64,
        done_b: i64,
        interval_a: i64,
        interval_b: i64,
        window_done: i64,
    ) -> PyResult<(i64, i64, i64)> {
        check_code(y_a, self.plan.input, "y_a")?;
        check_code(y_b, self.plan.input, "y_b")?;
        let slot = slot_from_ports(
            &self.plan.schedule,
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
        )?;
        self.model.step(&slot, [y_a, y_b]);
        let [a, b, estimated] = self.outputs();
        Ok((a, b, estimated))
    }

    /// `step` over records: `y_a`, `y_b` and the seven slot ports as int64 arrays of one
    /// length (a `Sequencer.process` dict supplies the slot); returns a dict of `bias_a`,
    /// `bias_b`, `estimated` arrays.
    #[allow(clippy::too_many_arguments)]
    fn process<'py>(
        &mut self,
        py: Python<'py>,
        y_a: PyReadonlyArray1<'py, i64>,
        y_b: PyReadonlyArray1<'py, i64>,
        blank_a: PyReadonlyArray1<'py, i64>,
        blank_b: PyReadonlyArray1<'py, i64>,
        done_a: PyReadonlyArray1<'py, i64>,
        done_b: PyReadonlyArray1<'py, i64>,
        interval_a: PyReadonlyArray1<'py, i64>,
        interval_b: PyReadonlyArray1<'py, i64>,
        window_done: PyReadonlyArray1<'py, i64>,
    ) -> PyResult<Bound<'py, PyDict>> {
        let y_a = port_codes(&y_a, self.plan.input, "y_a")?;
        let y_b = port_codes(&y_b, self.plan.input, "y_b")?;
        let slot_arrays = [
            blank_a,
            blank_b,
            done_a,
            done_b,
            interval_a,
            interval_b,
            window_done,
        ];
        let mut lengths = vec![("y_a", y_a.len()), ("y_b", y_b.len())];
        lengths.extend(
            ESTIMATOR_SLOT_PORTS
                .iter()
                .zip(&slot_arrays)
                .map(|(name, array)| (*name, array.len().unwrap_or(0))),
        );
        let samples = same_length(&lengths)?;
        let views: Vec<_> = slot_arrays.iter().map(|a| a.as_array()).collect();
        let slots = (0..samples)
            .map(|i| {
                let ports: [i64; 7] = std::array::from_fn(|p| views[p][i]);
                slot_from_ports(&self.plan.schedule, &self.modes, ports, &format!("[{i}]"))
            })
            .collect::<PyResult<Vec<Slot>>>()?;
        let this = &mut *self;
        let columns = py.detach(|| {
            let mut columns: [Vec<i64>; 3] = std::array::from_fn(|_| Vec::with_capacity(samples));
            for ((slot, a), b) in slots.iter().zip(y_a.iter()).zip(y_b.iter()) {
                this.model.step(slot, [*a, *b]);
                for (column, code) in columns.iter_mut().zip(this.outputs()) {
                    column.push(code);
                }
            }
            columns
        });
        port_dict(py, ["bias_a", "bias_b", "estimated"], columns)
    }

    /// Input format (`y_a`, `y_b`).
    #[getter]
    fn input_format(&self) -> String {
        self.plan.input.to_string()
    }

    /// Bias format (`bias_a`, `bias_b`).
    #[getter]
    fn bias_format(&self) -> String {
        self.plan.bias.to_string()
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

    /// One clock on `y_a`, `y_b` (°/s) and the slot's ports; returns `(bias_a, bias_b)` (°/s).
    #[allow(clippy::too_many_arguments)]
    fn step(
        &mut self,
        y_a: f64,
        y_b: f64,
        blank_a: i64,
        blank_b: i64,
        done_a: i64,
        done_b: i64,
        interval_a: i64,
        interval_b: i64,
        window_done: i64,
    ) -> PyResult<(f64, f64)> {
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
        )?;
        self.model.step(&slot, [y_a, y_b]);
        let [a, b] = self.model.bias();
        Ok((a, b))
    }
}

/// The bit-accurate mean filter with gross-error rejection (`gyrofx_mean_filter`).
#[pyclass(module = "gyrofx")]
pub(crate) struct MeanFilter {
    plan: mean_filter::Plan,
    model: FixedMeanFilter,
}

impl MeanFilter {
    pub(crate) fn new(plan: &mean_filter::Plan) -> MeanFilter {
        MeanFilter {
            plan: plan.clone(),
            model: FixedMeanFilter::new(plan),
        }
    }
}

#[pymethods]
impl MeanFilter {
    /// Drops the current block's samples.
    fn reset(&mut self) {
        self.model.reset();
    }

    /// One sample `x` (input-format code); returns `(y, kept)` on the block's last sample
    /// (`y_valid`), else `None`.
    fn step(&mut self, x: i64) -> PyResult<Option<(i64, i64)>> {
        check_code(x, self.plan.input, "x")?;
        Ok(self.model.step(x).map(|m| (m.y, i64::from(m.kept))))
    }

    /// `step` over a record: a dict of `y_valid`, `y`, `kept` int64 arrays, one entry per input
    /// sample (`y` and `kept` are 0 where `y_valid` is 0).
    fn process<'py>(
        &mut self,
        py: Python<'py>,
        x: PyReadonlyArray1<'py, i64>,
    ) -> PyResult<Bound<'py, PyDict>> {
        let x = port_codes(&x, self.plan.input, "x")?;
        let model = &mut self.model;
        let columns = py.detach(|| {
            let mut columns: [Vec<i64>; 3] = std::array::from_fn(|_| Vec::with_capacity(x.len()));
            for x in x.iter() {
                let (valid, y, kept) = match model.step(*x) {
                    Some(m) => (1, m.y, i64::from(m.kept)),
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
        self.plan.window
    }

    /// Input format (`x`).
    #[getter]
    fn input_format(&self) -> String {
        self.plan.input.to_string()
    }

    /// Output format (`y`).
    #[getter]
    fn output_format(&self) -> String {
        self.plan.output.to_string()
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

    /// One sample (°/s); `(mean, kept)` on the block's last sample, else `None`.
    fn step(&mut self, x: f64) -> Option<(f64, u32)> {
        self.model.step(x)
    }
}

/// The chain's output ports (`gyrofx_top`), in the RTL's order.
const CHAIN_PORTS: [&str; 7] = [
    "mode_a",
    "mode_b",
    "out_valid",
    "rate_out",
    "bias_a",
    "bias_b",
    "estimated",
];

/// The whole chain (`gyrofx_top`): sequencer, estimator, calibration, KF.
#[pyclass(module = "gyrofx")]
pub(crate) struct Chain {
    plan: chain::Plan,
    model: FixedChain,
}

impl Chain {
    pub(crate) fn new(plan: &chain::Plan) -> Chain {
        Chain {
            plan: plan.clone(),
            model: FixedChain::new(plan),
        }
    }

    fn step_codes(&mut self, y: [i64; 2], bw_sel: usize) -> [i64; 7] {
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

#[pymethods]
impl Chain {
    /// Clears every block.
    fn reset(&mut self) {
        self.model.reset();
    }

    /// The modes `(mode_a, mode_b)` (1 normal, 0 reverse) the next `step` runs in: what a
    /// plant needs before it produces that sample.
    fn next_modes(&self) -> (i64, i64) {
        let [a, b] = self.model.upcoming_modes();
        (i64::from(a > 0), i64::from(b > 0))
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
        let input = self.plan.estimator.input;
        check_code(y_a, input, "y_a")?;
        check_code(y_b, input, "y_b")?;
        let bw_sel = check_bw_sel(bw_sel, self.plan.kf.rom.len(), "bw_sel")?;
        let codes = self.step_codes([y_a, y_b], bw_sel);
        let dict = PyDict::new(py);
        for (name, code) in CHAIN_PORTS.into_iter().zip(codes) {
            dict.set_item(name, code)?;
        }
        Ok(dict)
    }

    /// `step` over records: a dict of int64 arrays, one per output port.
    #[pyo3(signature = (y_a, y_b, bw_sel = BandwidthSelect::One(0)))]
    fn process<'py>(
        &mut self,
        py: Python<'py>,
        y_a: PyReadonlyArray1<'py, i64>,
        y_b: PyReadonlyArray1<'py, i64>,
        bw_sel: BandwidthSelect<'py>,
    ) -> PyResult<Bound<'py, PyDict>> {
        let input = self.plan.estimator.input;
        let y_a = port_codes(&y_a, input, "y_a")?;
        let y_b = port_codes(&y_b, input, "y_b")?;
        let samples = same_length(&[("y_a", y_a.len()), ("y_b", y_b.len())])?;
        let select = bw_sel.per_sample(samples, self.plan.kf.rom.len())?;
        let this = &mut *self;
        let columns = py.detach(|| {
            let mut columns: [Vec<i64>; 7] = std::array::from_fn(|_| Vec::with_capacity(samples));
            for ((a, b), sel) in y_a.iter().zip(y_b.iter()).zip(&select) {
                for (column, code) in columns.iter_mut().zip(this.step_codes([*a, *b], *sel)) {
                    column.push(code);
                }
            }
            columns
        });
        port_dict(py, CHAIN_PORTS, columns)
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
        let bw_sel = check_bw_sel(bw_sel, self.rom_depth, "bw_sel")?;
        let sample = self.model.step([y_a, y_b], bw_sel);
        let dict = PyDict::new(py);
        dict.set_item("out_valid", i64::from(sample.rate.is_some()))?;
        dict.set_item("rate", sample.rate)?;
        dict.set_item("bias_a", sample.estimator.bias[0])?;
        dict.set_item("bias_b", sample.estimator.bias[1])?;
        Ok(dict)
    }
}
