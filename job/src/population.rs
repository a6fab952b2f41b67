//! A population study before anything is written: the config resolved into the nominal loops,
//! the chain and the spreads ([`Population`]), each member's draw and study as pure functions
//! of `(seed, member)` ([`Population::study`]), the rows of `population.csv` ([`columns`]),
//! the targets a member is judged against ([`targets`]) and the summary over the members
//! ([`summary`]). The Python package binds the same functions; `gyrofx population` runs them
//! in parallel and writes the files.

use gyrofx_model::chain;
use gyrofx_model::population::distribution::Spread;
use gyrofx_model::population::draw::{self, GyroPhysics, Member, Parameter};
use gyrofx_model::population::study::{self, MemberFigures, Study};

use crate::config::{Config, GyroLoop};
use crate::error::{Error, Result};
use crate::job::Job;

pub mod columns;
pub mod summary;
pub mod targets;

/// Start-up before the chain runs, s: the loops lock from rest (about 80 ms for paper 004's
/// gyro; spread members take longer).
pub const STARTUP_S: f64 = crate::gyros::RESONATOR_STARTUP_S;

/// Longest `--seconds` of chain run per member.
pub const MAX_SECONDS: f64 = 100_000.0;

/// How every member is run.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RunSettings {
    /// Seconds of chain run after the start-up.
    pub seconds: f64,
    /// Noise and drift in the chain run.
    pub noise: bool,
}

/// A config resolved for a population study.
#[derive(Clone, Debug)]
pub struct Population {
    /// The seed of every member's draws and noise (the config's `seed`).
    pub seed: u64,
    /// The nominal loops of gyro A and B (their plans are every member's).
    pub loops: [GyroLoop; 2],
    /// The chain.
    pub chain: chain::Plan,
    /// The spreads, in the order of the draws.
    pub spreads: Vec<(Parameter, Spread)>,
    /// The constant input rate of the chain run, °/s: 0 (at rest, the output's mean is the
    /// residual bias the chain leaves; the characterization measures the scale factor).
    pub rate_dps: f64,
}

/// One member's draw and what its study gave (or why it could not run: a drawn parameter the
/// physics refuses).
#[derive(Clone, Debug, PartialEq)]
pub struct MemberResult {
    /// The member's physics and drawn values.
    pub member: Member,
    /// Its figures.
    pub figures: std::result::Result<MemberFigures, String>,
}

impl Population {
    /// The population of `config`: its `[population]` spreads around its resonator-level
    /// gyros (`plant.model = "resonator"`), closed by its loops and chain.
    ///
    /// # Errors
    /// [`Error::Config`] for a bad config or a rate-level plant.
    pub fn new(config: &Config) -> Result<Population> {
        if config.plant.model != "resonator" {
            return Err(Error::config(
                "plant.model",
                format!("{:?}", config.plant.model),
                "\"resonator\": a population spreads the resonators' parameters",
            ));
        }
        let job = Job::new(config.clone())?;
        Ok(Population {
            seed: config.seed,
            loops: job.gyro_loops,
            chain: job.chain,
            spreads: config.population.spreads()?,
            rate_dps: 0.0,
        })
    }

    /// The nominal physics of gyro A and B.
    pub fn nominal(&self) -> [GyroPhysics; 2] {
        [0, 1].map(|g| GyroPhysics {
            params: self.loops[g].params,
            front_end: self.loops[g].front_end,
            seed: 0,
        })
    }

    /// Member `index`'s physics.
    pub fn member(&self, index: u64) -> Member {
        draw::member(&self.nominal(), &self.spreads, self.seed, index)
    }

    /// Member `index` drawn and studied: a pure function of the population, `index` and
    /// `settings`.
    pub fn study(&self, index: u64, settings: &RunSettings) -> MemberResult {
        let member = self.member(index);
        let study = Study {
            loops: [&self.loops[0].plan, &self.loops[1].plan],
            chain: &self.chain,
            seconds: settings.seconds,
            startup_s: STARTUP_S,
            noise: settings.noise,
            rate_dps: self.rate_dps,
            bw_sel: 0,
        };
        let figures = study::study(&study, &member);
        MemberResult { member, figures }
    }

    /// The chain rate, Hz.
    pub fn chain_rate_hz(&self) -> f64 {
        self.loops[0].plan.chain_rate_hz()
    }

    /// Gyro-samples one member takes beyond its characterization: both gyros' ADC samples of
    /// the start-up and the chain run.
    pub fn chain_run_gyro_samples(&self, settings: &RunSettings) -> u64 {
        let fs = self.loops[0].plan.adc_rate_hz;
        let decimation = u64::from(self.loops[0].plan.cic.decimation);
        let startup = libm::ceil(STARTUP_S * fs) as u64;
        let chain = libm::ceil(settings.seconds * self.chain_rate_hz()) as u64;
        2 * (startup + chain * decimation)
    }
}

#[cfg(test)]
mod tests;
