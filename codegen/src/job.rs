//! [`Job`]: a validated config resolved into designs, the fixed-point plan and the stimulus.
//!
//! config → design → plan → (models, writers): everything downstream reads the job.

use gyrofx_model::kf::design::{design_for_bandwidth, Design, Noise};
use gyrofx_model::kf::{Plan, Spec};
use gyrofx_model::stimulus::{adc, SingleGyro};

use crate::config::{Config, KfSettings, Source};
use crate::error::{Error, Result};
use crate::input::read_column;

/// A resolved job.
#[derive(Clone, Debug)]
pub struct Job {
    /// The config as read.
    pub config: Config,
    /// The stimulus source.
    pub source: Source,
    /// The KF settings.
    pub settings: KfSettings,
    /// One design per bandwidth, in ROM order.
    pub designs: Vec<Design>,
    /// The fixed-point plan.
    pub plan: Plan,
}

/// The stimulus of the vector set.
#[derive(Clone, Debug, PartialEq)]
pub struct Stimulus {
    /// ADC codes (input format).
    pub z: Vec<i64>,
    /// True rate, °/s, where known (synthetic source).
    pub true_rate: Option<Vec<f64>>,
    /// Samples the ADC saturated.
    pub adc_saturations: u64,
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

/// The plan for these designs under `settings`.
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
    /// Validates `config` and resolves it.
    ///
    /// # Errors
    /// The first config, design or plan error.
    pub fn new(config: Config) -> Result<Job> {
        let (source, settings) = config.validate()?;
        let designs = design_bandwidths(
            &settings,
            config.stimulus.fs_hz,
            config.kf.arw_deg_per_sqrt_h,
            config.kf.rrw_deg_per_h_per_sqrt_h,
        )?;
        let plan = plan_for(&settings, &designs)?;
        Ok(Job {
            config,
            source,
            settings,
            designs,
            plan,
        })
    }

    /// Simulates (or reads) the stimulus and quantizes it with the ADC into the input format.
    /// A CSV longer than `samples` is cut; a shorter one sets the count.
    ///
    /// # Errors
    /// [`Error::Input`] / [`Error::Io`] for a bad CSV file.
    pub fn stimulus(&self) -> Result<Stimulus> {
        let s = &self.config.stimulus;
        let (analog, true_rate) = match &self.source {
            Source::Synthetic(scenario) => {
                let gyro = SingleGyro {
                    fs_hz: s.fs_hz,
                    scenario: *scenario,
                    initial_bias_dps: s.initial_bias_dps,
                    arw_deg_per_sqrt_h: s.arw_deg_per_sqrt_h,
                    rrw_deg_per_h_per_sqrt_h: s.rrw_deg_per_h_per_sqrt_h,
                };
                let record = gyro.simulate(self.config.samples, self.config.seed);
                (record.analog, Some(record.true_rate))
            }
            Source::Csv { path, column } => {
                let mut values = read_column(path, column)?;
                values.truncate(self.config.samples);
                (values, None)
            }
        };
        let (z, adc_saturations) = adc(&analog, self.plan.input);
        Ok(Stimulus {
            z,
            true_rate,
            adc_saturations,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The model's worked example (used by its tests and benchmarks) is the embedded default.
    #[test]
    fn the_embedded_default_is_the_models_example() {
        let job = Job::new(Config::embedded()).unwrap();
        let example = Plan::new(&gyrofx_model::examples::kf_spec()).unwrap();
        assert_eq!(job.plan, example);
        let gyro = gyrofx_model::examples::gyro();
        let s = &job.config.stimulus;
        assert_eq!(
            (
                s.fs_hz,
                s.initial_bias_dps,
                s.arw_deg_per_sqrt_h,
                s.rrw_deg_per_h_per_sqrt_h
            ),
            (
                gyro.fs_hz,
                gyro.initial_bias_dps,
                gyro.arw_deg_per_sqrt_h,
                gyro.rrw_deg_per_h_per_sqrt_h
            )
        );
        assert_eq!(job.source, Source::Synthetic(gyro.scenario));
    }
}
