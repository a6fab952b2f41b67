//! [`Job`]: a validated config resolved into designs and the plans of every block.
//!
//! config → design → plans → (models, writers): everything downstream reads the job.

use gyrofx_model::chain;
use gyrofx_model::estimator;
use gyrofx_model::kf::design::{design_for_bandwidth, Design, Noise};
use gyrofx_model::kf::{Plan, Spec};
use gyrofx_model::mean_filter;

use crate::config::{Config, GyroLoop, KfSettings, Settings, Source};
use crate::error::{Error, Result};
use crate::input::read_column_prefix;
use crate::recording::Recording;

/// A resolved job.
#[derive(Clone, Debug)]
pub struct Job {
    /// The config as read.
    pub config: Config,
    /// Its typed settings.
    pub settings: Settings,
    /// One KF design per bandwidth, in ROM order.
    pub designs: Vec<Design>,
    /// The chain's plans (estimator with the sequencer's schedule, and the KF).
    pub chain: chain::Plan,
    /// The mean filter's plan.
    pub mean_filter: mean_filter::Plan,
    /// Both gyros' resonator-level loops (resolved for every plant: the loop's RTL block is in
    /// every package).
    pub gyro_loops: [GyroLoop; 2],
    /// The chain of the system vectors (both loops feeding the chain), on its short schedule
    /// ([`crate::system::chain_plan`]); `None` on the rate plant, whose loops' output
    /// need not be the chain's input.
    pub system_chain: Option<chain::Plan>,
    /// Recorded gyro outputs that drive the chain instead of the plant (`generate
    /// --recording`), checked against the config by [`Job::with_recording`].
    pub recording: Option<std::sync::Arc<Recording>>,
    /// The chain compiled for `gyrofx_top_serial`, with `architecture = "serial"`.
    pub serial: Option<gyrofx_model::serial::Program>,
    /// The gyro loop's schedule for `gyrofx_gyro_loop_serial`, with `architecture = "serial"`.
    pub loop_schedule: Option<gyrofx_model::gyro_loop::folded::Schedule>,
    /// The system's chain ([`Job::system_chain`]) compiled for the `gyrofx_top_serial` inside
    /// `gyrofx_system_serial`, with `architecture = "serial"` on a resonator plant.
    pub system_serial: Option<gyrofx_model::serial::Program>,
    /// Both gyros' loops on one folded datapath (`gyrofx_gyro_pair_serial`, inside
    /// `gyrofx_system_serial`), with `architecture = "serial"` on a resonator plant.
    pub pair_schedule: Option<gyrofx_model::gyro_loop::folded::Schedule>,
}

/// Designs one filter per bandwidth of `settings` at `fs_hz` for the noise model (°/√h, °/h/√h).
///
/// # Errors
/// [`Error::Design`] naming the bandwidth that failed.
pub fn design_bandwidths(
    settings: &KfSettings,
    fs_hz: f64,
    arw_deg_per_sqrt_h: f64,
    rrw_deg_per_h_per_sqrt_h: f64,
) -> Result<Vec<Design>> {
    let noise = Noise::from_gyro_units(arw_deg_per_sqrt_h, rrw_deg_per_h_per_sqrt_h, 0.0);
    settings
        .bandwidths_hz
        .iter()
        .enumerate()
        .map(|(i, bw)| {
            design_for_bandwidth(*bw, noise, fs_hz, settings.method, settings.convergence).map_err(
                |source| Error::Design {
                    what: format!("kf.bandwidths_hz[{i}] = {bw} Hz"),
                    source,
                },
            )
        })
        .collect()
}

/// The KF plan for these designs under `settings`.
///
/// # Errors
/// [`Error::Plan`] when a format or coefficient is refused.
pub fn plan_for(settings: &KfSettings, designs: &[Design]) -> Result<Plan> {
    Ok(Plan::new(&Spec {
        input: settings.input,
        state: settings.state,
        output: settings.output,
        coefficients: settings.coefficients,
        rounding: settings.rounding,
        overflow: settings.overflow,
        gains: designs.iter().map(|d| d.g).collect(),
        labels: settings
            .bandwidths_hz
            .iter()
            .map(|bw| format!("{bw} Hz"))
            .collect(),
    })?)
}

impl Job {
    /// This job with `architecture = "serial"`: the chain compiled for `gyrofx_top_serial`
    /// (itself when it already is).
    ///
    /// # Errors
    /// [`Error::Config`] when the chain has no serial program.
    pub fn serial_variant(&self) -> Result<Job> {
        let mut job = self.clone();
        if job.serial.is_none() {
            job.serial = Some(compile_serial(&job.chain)?);
            job.loop_schedule = Some(schedule_loop(&job.gyro_loops)?);
            job.system_serial = match &job.system_chain {
                Some(chain) => Some(compile_serial(chain)?),
                None => None,
            };
            job.pair_schedule = match &job.system_chain {
                Some(_) => Some(schedule_pair(&job.gyro_loops)?),
                None => None,
            };
            job.config.architecture = "serial".into();
            job.settings.architecture = crate::config::Architecture::Serial;
        }
        Ok(job)
    }

    /// Validates `config` and resolves it.
    ///
    /// # Errors
    /// The first config, design or plan error.
    pub fn new(config: Config) -> Result<Job> {
        let settings = config.validate()?;
        let gyro_loops = match &settings.resonator {
            Some(loops) => loops.clone(),
            None => config.gyro_loops()?,
        };
        let designs = design_bandwidths(
            &settings.kf,
            config.stimulus.fs_hz,
            config.kf.arw_deg_per_sqrt_h,
            config.kf.rrw_deg_per_h_per_sqrt_h,
        )?;
        let kf = plan_for(&settings.kf, &designs)?;
        let estimator = estimator::Plan::new(&settings.estimator).map_err(Error::Estimator)?;
        let chain = chain::Plan::new(estimator, kf).map_err(|e| Error::Config {
            field: "estimator / kf formats".into(),
            value: String::new(),
            allowed: e.to_string(),
        })?;
        let mean_filter =
            mean_filter::Plan::new(&settings.mean_filter).map_err(Error::MeanFilter)?;
        let system_chain = match settings.resonator {
            Some(_) => Some(crate::system::chain_plan(&settings.estimator, &chain.kf)?),
            None => None,
        };
        let (serial, loop_schedule, system_serial, pair_schedule) = match settings.architecture {
            crate::config::Architecture::Parallel => (None, None, None, None),
            crate::config::Architecture::Serial => (
                Some(compile_serial(&chain)?),
                Some(schedule_loop(&gyro_loops)?),
                match &system_chain {
                    Some(chain) => Some(compile_serial(chain)?),
                    None => None,
                },
                match &system_chain {
                    Some(_) => Some(schedule_pair(&gyro_loops)?),
                    None => None,
                },
            ),
        };
        Ok(Job {
            config,
            settings,
            designs,
            chain,
            mean_filter,
            gyro_loops,
            system_chain,
            recording: None,
            serial,
            loop_schedule,
            system_serial,
            pair_schedule,
        })
    }

    /// The job with `recording` driving the chain: its rate must be the config's and its
    /// modes (when it has a mode column) the sequencer's over the job's samples, which must
    /// not exceed its rows.
    ///
    /// # Errors
    /// A recording shorter than the job's samples, at another rate, or out of step.
    pub fn with_recording(mut self, recording: Recording) -> Result<Job> {
        let samples = self.config.samples;
        if recording.len() < samples {
            return Err(Error::Config {
                field: "samples".into(),
                value: samples.to_string(),
                allowed: format!(
                    "at most the recording's {} rows (leave --samples out to use them all)",
                    recording.len()
                ),
            });
        }
        recording.check(
            self.config.stimulus.fs_hz,
            &self.chain.estimator.schedule,
            samples,
        )?;
        self.recording = Some(std::sync::Arc::new(recording));
        Ok(self)
    }

    /// The KF's plan.
    pub fn kf(&self) -> &Plan {
        &self.chain.kf
    }

    /// The true rate Ω for `samples` samples, °/s: the scenario, or the CSV's first `samples`
    /// values.
    ///
    /// # Errors
    /// [`Error::Input`] / [`Error::Io`] for a bad CSV file, or one with fewer than `samples`
    /// values (silently running a shorter record would leave the report nothing to analyse).
    pub fn true_rate(&self, samples: usize) -> Result<Vec<f64>> {
        let source = self.rate_source(samples)?;
        Ok((0..samples).map(|k| source.at(k)).collect())
    }

    /// The true rate sample by sample: computed from the scenario, or the CSV column's first
    /// `samples` values (which are read whole).
    ///
    /// # Errors
    /// As [`Job::true_rate`].
    pub fn rate_source(&self, samples: usize) -> Result<RateSource> {
        Ok(match &self.settings.source {
            Source::Synthetic(scenario) => RateSource::Synthetic {
                scenario: *scenario,
                period_s: 1.0 / self.config.stimulus.fs_hz,
            },
            Source::Csv { path, column } => {
                RateSource::Recorded(recorded_rate(path, column, samples)?)
            }
        })
    }
}

/// The first `samples` values of `column` in the CSV file at `path` (the rows after them are
/// not read).
fn recorded_rate(path: &std::path::Path, column: &str, samples: usize) -> Result<Vec<f64>> {
    let values = read_column_prefix(path, column, samples)?;
    if values.len() < samples {
        return Err(crate::error::Error::Input {
            path: path.to_path_buf(),
            message: format!(
                "column {column} has {} values but samples = {samples}: give \
                 samples <= {} (in the config or with --samples), or a longer record",
                values.len(),
                values.len()
            ),
        });
    }
    Ok(values)
}

/// The true rate of a run, sample by sample ([`Job::rate_source`]).
#[derive(Clone, Debug)]
pub enum RateSource {
    /// The scenario at `k · period_s`.
    Synthetic {
        /// The scenario.
        scenario: gyrofx_model::stimulus::Scenario,
        /// Sample period, s.
        period_s: f64,
    },
    /// A recorded column.
    Recorded(Vec<f64>),
}

impl RateSource {
    /// The true rate at sample `k`, °/s.
    ///
    /// # Panics
    /// Beyond a recorded column's end ([`Job::rate_source`] reads at least the run's samples).
    pub fn at(&self, k: usize) -> f64 {
        match self {
            RateSource::Synthetic { scenario, period_s } => scenario.rate_at(k as f64 * period_s),
            RateSource::Recorded(values) => values[k],
        }
    }
}

/// The chain's serial program; a chain it cannot hold is a config error on `architecture`.
fn compile_serial(chain: &chain::Plan) -> Result<gyrofx_model::serial::Program> {
    gyrofx_model::serial::compile(chain).map_err(|e| Error::Config {
        field: "architecture".into(),
        value: "\"serial\"".into(),
        allowed: e.to_string(),
    })
}

/// The folded gyro loop's schedule (both gyros' loops share their structure); a loop it cannot
/// fold is a config error on `architecture`.
fn schedule_loop(loops: &[GyroLoop; 2]) -> Result<gyrofx_model::gyro_loop::folded::Schedule> {
    gyrofx_model::gyro_loop::folded::Schedule::new(&loops[0].plan).map_err(|e| Error::Config {
        field: "architecture".into(),
        value: "\"serial\"".into(),
        allowed: e.to_string(),
    })
}

/// Both gyros' folded loops on one datapath (the system's); a pair it cannot fold is a config
/// error on `loop.decimation` (the deferred work must end before the next decimation) or
/// `architecture`.
fn schedule_pair(loops: &[GyroLoop; 2]) -> Result<gyrofx_model::gyro_loop::folded::Schedule> {
    use gyrofx_model::gyro_loop::folded::{Schedule, ScheduleError};
    Schedule::pair(&loops[0].plan).map_err(|e| match e {
        ScheduleError::Decimation {
            segments,
            decimation,
        } => Error::Config {
            field: "loop.decimation (with architecture = \"serial\")".into(),
            value: decimation.to_string(),
            allowed: format!(
                "at least {}: the folded system's loops defer each decimation's compensators into the next {segments} samples",
                segments + 1
            ),
        },
        other => Error::Config {
            field: "architecture".into(),
            value: "\"serial\"".into(),
            allowed: other.to_string(),
        },
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The model's worked example (used by its tests and benchmarks) is the embedded default's
    /// KF.
    #[test]
    fn the_embedded_default_kf_is_the_models_example() {
        let job = Job::new(Config::embedded()).unwrap();
        let example = Plan::new(&gyrofx_model::examples::kf_spec()).unwrap();
        assert_eq!(job.kf(), &example);
        assert_eq!(job.config.stimulus.fs_hz, gyrofx_model::examples::FS_HZ);
    }
}
