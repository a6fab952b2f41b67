//! [`Plan`]: a config resolved into every block's formats, ROMs and designs, as `generate`
//! resolves it; the blocks are built from it.

use std::path::PathBuf;
use std::sync::Arc;

use pyo3::prelude::*;
use pyo3::types::PyDict;

use gyrofx_job::config::Config;
use gyrofx_job::golden;
use gyrofx_job::job::Job;
use gyrofx_job::pipeline;

use crate::blocks::{
    Chain, ChainFloat, Estimator, EstimatorFloat, Kf, KfFloat, MeanFilter, MeanFilterFloat,
    Sequencer,
};
use crate::loops::{GyroLoop, GyroLoopFloat, Resonator, System, SystemFloat};
use crate::refused;

/// A resolved gyrofx config: the embedded default overlaid by a preset, a TOML text or a file,
/// checked as the CLI checks it, with every block's plan.
#[pyclass(module = "gyrofx", frozen)]
pub(crate) struct Plan {
    pub(crate) job: Arc<Job>,
}

impl Plan {
    fn resolve(config: gyrofx_job::error::Result<Config>) -> PyResult<Plan> {
        let job = config.and_then(Job::new).map_err(refused)?;
        Ok(Plan { job: Arc::new(job) })
    }
}

#[pymethods]
impl Plan {
    /// The embedded default config (`gyrofx init` prints it).
    #[staticmethod]
    fn default() -> PyResult<Plan> {
        Plan::resolve(Ok(Config::embedded()))
    }

    /// A named preset (gu2019, xue2015, mpu6050) over the default.
    #[staticmethod]
    fn preset(name: &str) -> PyResult<Plan> {
        Plan::resolve(Config::from_preset_and_file(Some(name), None))
    }

    /// A (partial) config in TOML over the default; `origin` names it in errors.
    #[staticmethod]
    #[pyo3(signature = (text, origin = "<toml text>"))]
    fn from_toml(text: &str, origin: &str) -> PyResult<Plan> {
        Plan::resolve(Config::from_toml(text, origin))
    }

    /// A config file over the default (optionally over a preset), as `--config` and `--preset`.
    #[staticmethod]
    #[pyo3(signature = (path, preset = None))]
    fn from_file(path: PathBuf, preset: Option<&str>) -> PyResult<Plan> {
        Plan::resolve(Config::from_preset_and_file(preset, Some(&path)))
    }

    /// The config a `gyrofx generate` package was made from (its `manifest.json`), so the
    /// blocks built here reproduce that package's vectors.
    #[staticmethod]
    fn from_package(folder: PathBuf) -> PyResult<Plan> {
        Plan::resolve(Config::from_package(&folder))
    }

    /// The whole resolved config as TOML (every key present).
    fn toml(&self) -> String {
        self.job.config.to_toml()
    }

    /// The chain's sample rate, Hz.
    #[getter]
    fn fs_hz(&self) -> f64 {
        self.job.config.stimulus.fs_hz
    }

    /// The KF's bandwidths, Hz, in ROM order (`bw_sel` indexes them).
    #[getter]
    fn bandwidths_hz(&self) -> Vec<f64> {
        self.job.settings.kf.bandwidths_hz.clone()
    }

    /// Every quantization point's format, by `block.signal` (`"kf.input": "s18.14"`, ...).
    fn formats<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let dict = PyDict::new(py);
        for (name, format) in formats(&self.job) {
            dict.set_item(name, format)?;
        }
        Ok(dict)
    }

    /// The bit-accurate KF (`gyrofx_kf`).
    fn kf(&self) -> Kf {
        Kf::new(self.job.kf(), pipeline::KF)
    }

    /// The KF's float twin: with the quantized gains (`ideal=False`, the fixed KF's arithmetic
    /// without rounding) or the designed ones (`ideal=True`).
    #[pyo3(signature = (ideal = false))]
    fn kf_float(&self, ideal: bool) -> KfFloat {
        KfFloat::new(self.job.kf(), ideal)
    }

    /// The mode-reversal sequencer (`gyrofx_sequencer`).
    fn sequencer(&self) -> Sequencer {
        Sequencer::new(&self.job.chain.estimator.schedule, pipeline::SEQUENCER)
    }

    /// The bit-accurate bias estimator (`gyrofx_bias_estimator`).
    fn estimator(&self) -> Estimator {
        Estimator::new(&self.job.chain.estimator, pipeline::ESTIMATOR)
    }

    /// The estimator's float twin (quantized or designed gains).
    #[pyo3(signature = (ideal = false))]
    fn estimator_float(&self, ideal: bool) -> EstimatorFloat {
        EstimatorFloat::new(&self.job.chain.estimator, ideal)
    }

    /// The bit-accurate mean filter with gross-error rejection (`gyrofx_mean_filter`).
    fn mean_filter(&self) -> MeanFilter {
        MeanFilter::new(&self.job.mean_filter, pipeline::mean_filter(&self.job))
    }

    /// The mean filter's float twin.
    fn mean_filter_float(&self) -> MeanFilterFloat {
        MeanFilterFloat::new(&self.job.mean_filter)
    }

    /// The whole chain: sequencer, estimator, calibration and KF (`gyrofx_top`).
    fn chain(&self) -> Chain {
        Chain::new(&self.job.chain, pipeline::top(&self.job))
    }

    /// The chain's float twin (quantized or designed coefficients).
    #[pyo3(signature = (ideal = false))]
    fn chain_float(&self, ideal: bool) -> ChainFloat {
        ChainFloat::new(&self.job.chain, ideal)
    }

    /// One gyro's digital loop (`gyrofx_gyro_loop`, or `gyrofx_gyro_loop_serial`'s timing with
    /// `architecture = "serial"`): gyro `"a"` (the block's vectors and RTL
    /// parameters) or `"b"`.
    #[pyo3(signature = (gyro = "a"))]
    fn gyro_loop(&self, gyro: &str) -> PyResult<GyroLoop> {
        Ok(GyroLoop::new(
            &self.gyro(gyro)?.plan,
            pipeline::gyro_loop(&self.job),
        ))
    }

    /// The loop's float twin, gyro `"a"` or `"b"`.
    #[pyo3(signature = (gyro = "a"))]
    fn gyro_loop_float(&self, gyro: &str) -> PyResult<GyroLoopFloat> {
        Ok(GyroLoopFloat::new(&self.gyro(gyro)?.plan))
    }

    /// The whole gyro at the ADC rate (`gyrofx_system`): both loops and the chain on the
    /// system's short schedule; with `architecture = "serial"` `gyrofx_system_serial`'s timing
    /// and its chain outputs `chain_delay_samples` samples later. Only resonator plants have it.
    fn system(&self) -> PyResult<System> {
        let ports = golden::System::of(&self.job).ok_or_else(|| refused(golden::NO_SYSTEM))?;
        Ok(System::new(ports, pipeline::system(&self.job)))
    }

    /// The system's float twin (quantized coefficients).
    fn system_float(&self) -> PyResult<SystemFloat> {
        let (loops, chain) = self.system_plans()?;
        Ok(SystemFloat::new(loops, chain))
    }

    /// The simulated resonator of gyro `"a"` or `"b"` with its front end: DAC codes in, ADC
    /// codes out. `seed` defaults to the one `generate` uses for that gyro (2·seed, 2·seed + 1),
    /// so a loop closed around it from reset retraces the vectors' run; `noise=False` switches
    /// its noise and drift off.
    #[pyo3(signature = (gyro = "a", seed = None, noise = true))]
    fn resonator(&self, gyro: &str, seed: Option<u64>, noise: bool) -> PyResult<Resonator> {
        let index = gyro_index(gyro)?;
        let seed = seed.unwrap_or_else(|| {
            self.job
                .config
                .seed
                .wrapping_mul(2)
                .wrapping_add(index as u64)
        });
        Resonator::new(&self.job.gyro_loops[index], seed, noise)
    }

    fn __repr__(&self) -> String {
        let kf = self.job.kf();
        format!(
            "gyrofx.Plan(fs_hz={}, bandwidths_hz={:?}, kf {} -> {})",
            self.job.config.stimulus.fs_hz, self.job.settings.kf.bandwidths_hz, kf.input, kf.output
        )
    }
}

impl Plan {
    /// Both loops' plans and the system's chain (resonator plants only).
    fn system_plans(
        &self,
    ) -> PyResult<(
        [&gyrofx_model::gyro_loop::gyro::Plan; 2],
        &gyrofx_model::chain::Plan,
    )> {
        let chain = self
            .job
            .system_chain
            .as_ref()
            .ok_or_else(|| refused(gyrofx_job::golden::NO_SYSTEM))?;
        let [a, b] = &self.job.gyro_loops;
        Ok(([&a.plan, &b.plan], chain))
    }

    fn gyro(&self, gyro: &str) -> PyResult<&gyrofx_job::config::GyroLoop> {
        Ok(&self.job.gyro_loops[gyro_index(gyro)?])
    }
}

/// `"a"` 0, `"b"` 1.
fn gyro_index(gyro: &str) -> PyResult<usize> {
    match gyro {
        "a" | "A" => Ok(0),
        "b" | "B" => Ok(1),
        other => Err(refused(format!("gyro = {other:?}: allowed \"a\" or \"b\""))),
    }
}

/// The formats of every block's quantization points, in a fixed order.
fn formats(job: &Job) -> Vec<(String, String)> {
    let kf = job.kf();
    let estimator = &job.chain.estimator;
    let mean = &job.mean_filter;
    let mut out: Vec<(&str, gyrofx_model::fx::Format)> = vec![
        ("kf.input", kf.input),
        ("kf.state", kf.state),
        ("kf.output", kf.output),
        ("kf.g1", kf.coefficient[0]),
        ("kf.g2", kf.coefficient[1]),
        ("kf.error", kf.error),
        ("kf.product_g1", kf.product[0]),
        ("kf.product_g2", kf.product[1]),
        ("kf.sum_x1", kf.sum[0]),
        ("kf.sum_x2", kf.sum[1]),
        ("estimator.input", estimator.input),
        ("estimator.accumulator", estimator.accumulator),
        ("estimator.reciprocal", estimator.reciprocal),
        ("estimator.mean", estimator.mean),
        ("estimator.gain", estimator.gain),
        ("estimator.dot", estimator.dot),
        ("estimator.bias", estimator.bias),
        ("estimator.calibrated", estimator.calibrated),
        ("mean_filter.input", mean.input),
        ("mean_filter.output", mean.output),
        ("mean_filter.sum", mean.sum),
        ("mean_filter.deviation", mean.deviation),
        ("mean_filter.reciprocal", mean.reciprocal),
        ("mean_filter.product", mean.product),
    ];
    let gyro = &job.gyro_loops[0].plan;
    out.extend([
        ("gyro_loop.adc", gyro.adc),
        ("gyro_loop.nco_phase", gyro.nco.phase),
        ("gyro_loop.nco_sine", gyro.nco.output),
        ("gyro_loop.demod_product", gyro.demodulator.product.to),
        ("gyro_loop.demod_state", gyro.demodulator.state.to),
        ("gyro_loop.demod_output", gyro.demodulator.output.to),
        ("gyro_loop.pll_integrator", gyro.pll.integrator),
        ("gyro_loop.pll_output", gyro.pll.output.to),
        ("gyro_loop.agc_error", gyro.agc_error.to),
        ("gyro_loop.agc_integrator", gyro.agc.integrator),
        ("gyro_loop.agc_output", gyro.agc.output.to),
        ("gyro_loop.dac", gyro.dac.to),
        ("gyro_loop.cic_internal", gyro.cic.cic.to),
        ("gyro_loop.cic_output", gyro.cic.output.to),
        ("gyro_loop.output", gyro.output.to),
    ]);
    out.into_iter()
        .map(|(name, format)| (name.to_string(), format.to_string()))
        .collect()
}
