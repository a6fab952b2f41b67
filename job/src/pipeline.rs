//! When each block's RTL shows a sample's outputs and how soon it takes the next: the one
//! source of these facts. The generated testbenches (through the blocks' IR), the package
//! manifest, the Python classes and the C API read them here, and `tests/blocks.rs` holds the
//! block pages' "Latency" lines to them.
//!
//! A sample is a clock with `ce` high. Registered outputs show it `latency_clocks` clocks after
//! that clock's edge (1: the next clock); the next sample's `ce` may come no sooner than
//! `min_clocks_per_sample` clocks after it (1: every clock). Each RTL block with a minimum above
//! 1 stops a simulation that feeds it faster (a check synthesis ignores).

use crate::config::Architecture;
use crate::error::{Error, Result};
use crate::job::Job;

/// A block's pipeline as its RTL has it, in clocks.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize)]
pub struct Pipeline {
    /// Clocks from a sample's `ce` to its registered outputs (1: valid the next clock).
    pub latency_clocks: u32,
    /// The fewest clocks from one sample's `ce` to the next one's.
    pub min_clocks_per_sample: u32,
}

impl Pipeline {
    /// Outputs `latency_clocks` after `ce`, the next sample `min_clocks_per_sample` later.
    pub const fn new(latency_clocks: u32, min_clocks_per_sample: u32) -> Self {
        Pipeline {
            latency_clocks,
            min_clocks_per_sample,
        }
    }

    /// Clocks a testbench waits, `ce` low, after the one that follows `ce` before the
    /// registered outputs show the sample.
    pub fn settle_clocks(self) -> u32 {
        self.latency_clocks.saturating_sub(1)
    }
}

/// One register stage, a sample every clock: the sequencer, the gyro loop's NCO,
/// demodulator, PI and CIC, the parallel mean filter.
pub const ONE_CLOCK: Pipeline = Pipeline::new(1, 1);

/// `gyrofx_sequencer`.
pub const SEQUENCER: Pipeline = ONE_CLOCK;

/// `gyrofx_bias_estimator`: six register stages, one sample in flight.
pub const ESTIMATOR: Pipeline = Pipeline::new(6, 6);

/// `gyrofx_kf`: four register stages; the next sample may enter after three, when the state
/// update it needs is written.
pub const KF: Pipeline = Pipeline::new(4, 3);

/// `gyrofx_top`: the estimator's stages (the calibration and the KF overlap them).
pub const TOP: Pipeline = ESTIMATOR;

/// `gyrofx_gyro_loop`: four register stages, one ADC sample in flight.
pub const GYRO_LOOP: Pipeline = Pipeline::new(4, 4);

/// The gyro loop as `job` builds it: [`GYRO_LOOP`], or `gyrofx_gyro_loop_serial`, whose
/// schedule's word `t` acts `t + 2` clocks after `ce` (a clock fetches it, a clock decodes its
/// accumulator operands) and its last word loads the outputs the clock after (the next `ce` no
/// sooner).
pub fn gyro_loop(job: &Job) -> Pipeline {
    match &job.loop_schedule {
        Some(schedule) => {
            let latency = schedule.len() as u32 + 2;
            Pipeline::new(latency, latency)
        }
        None => GYRO_LOOP,
    }
}

/// `gyrofx_system`: the loop's four stages, then the chain's (`gyrofx_top`).
const PARALLEL_SYSTEM: Pipeline = Pipeline::new(
    GYRO_LOOP.latency_clocks + TOP.latency_clocks,
    GYRO_LOOP.latency_clocks + TOP.latency_clocks,
);

/// The system as `job` builds it: `gyrofx_system` (the loop's four stages, then the chain's),
/// or `gyrofx_system_serial`, whose outputs all show the clock after the folded pair's longest
/// sample (its words, each acting two clocks after its fetch), every ADC sample; the chain's
/// results come [`system_chain_delay`] samples later, at that same clock.
pub fn system(job: &Job) -> Pipeline {
    match &job.pair_schedule {
        Some(pair) => {
            let latency = pair.len() as u32 + 3;
            Pipeline::new(latency, latency)
        }
        None => PARALLEL_SYSTEM,
    }
}

/// Clocks `gyrofx_system_serial` leaves between the serial chain's results and their
/// publication, beyond the chain's latency: the engine's outputs have held for a clock.
pub const CHAIN_MARGIN_CLOCKS: u32 = 1;

/// ADC samples by which `gyrofx_system_serial` publishes the chain's outputs (`rate_out`,
/// `out_valid`, `bias_a`, `bias_b`, `estimated`) after the sample whose loop outputs the chain
/// took (its `CHAIN_DELAY_SAMPLES`); 0 for `gyrofx_system`, which shows them in that sample.
///
/// The folded pair makes a decimation's rates D samples after the sample that decimates (its
/// deferred segments), and the serial chain then needs `gyrofx_top_serial`'s latency S
/// (clocks), while a new ADC sample may come every `system(job).min_clocks_per_sample` = m
/// clocks: publishing at the K-th sample after, K = D + ⌈(S + [`CHAIN_MARGIN_CLOCKS`]) / m⌉,
/// reads finished results whatever the `ce` cadence (the samples are at least m clocks apart).
pub fn system_chain_delay(job: &Job) -> u32 {
    match (&job.system_serial, &job.pair_schedule) {
        (Some(program), Some(pair)) => {
            let chain = program.settle_clocks() + 1;
            let deferred = pair.deferred.len() as u32;
            deferred + (chain + CHAIN_MARGIN_CLOCKS).div_ceil(system(job).min_clocks_per_sample)
        }
        _ => 0,
    }
}

/// Refuses a serial system whose chain cannot finish a sample before the next chain sample
/// (the system block's check: only `gyrofx_system_serial` needs it):
/// [`system_chain_delay`] must not exceed the loops' decimation (chain samples are that many
/// ADC samples apart), so that the engine is free for the next one and its results are
/// published before they change.
///
/// # Errors
/// [`Error::Config`] naming `loop.decimation` and `architecture`.
pub fn check_system(job: &Job) -> Result<()> {
    let Some(program) = &job.system_serial else {
        return Ok(());
    };
    let delay = system_chain_delay(job);
    let decimation = job.gyro_loops[0].plan.cic.decimation;
    if u64::from(delay) <= u64::from(decimation) {
        return Ok(());
    }
    let clocks = system(job).min_clocks_per_sample;
    let chain = program.settle_clocks() + 1;
    Err(Error::Config {
        field: "loop.decimation (with architecture = \"serial\")".into(),
        value: format!(
            "{decimation}: a chain sample every {decimation} ADC samples of at least {clocks} clocks ({} clocks)",
            u64::from(decimation) * u64::from(clocks)
        ),
        allowed: format!(
            "at least {delay}: gyrofx_system_serial's chain (gyrofx_top_serial, {chain} clocks a sample, + {CHAIN_MARGIN_CLOCKS}) must finish between chain samples; raise loop.decimation or set architecture = \"parallel\""
        ),
    })
}

/// The chain as `job` builds it: [`TOP`], or `gyrofx_top_serial`, whose sample program takes
/// its instructions' clocks and frees the engine just after.
pub fn top(job: &Job) -> Pipeline {
    match &job.serial {
        Some(program) => {
            let latency = program.settle_clocks() + 1;
            Pipeline::new(latency, latency)
        }
        None => TOP,
    }
}

/// The mean filter as `job` builds it: [`ONE_CLOCK`], or `gyrofx_mean_filter_serial`, which
/// takes a block's mean over that many clocks after its last `ce` (the next `ce` or `rst` no
/// sooner).
pub fn mean_filter(job: &Job) -> Pipeline {
    match job.settings.architecture {
        Architecture::Parallel => ONE_CLOCK,
        Architecture::Serial => {
            let latency = gyrofx_model::mean_filter::serial::latency_clocks(&job.mean_filter);
            Pipeline::new(latency, latency)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::config::Config;

    fn serial() -> Job {
        Job::new(Config::from_toml("architecture = \"serial\"\n", "t").unwrap()).unwrap()
    }

    /// The serial system shows every output the clock after the folded loops' and publishes the
    /// chain's the fewest samples after that cover the serial chain's clocks and the margin.
    #[test]
    fn the_serial_systems_delay_covers_its_chain_in_the_fewest_samples() {
        let parallel = Job::new(Config::embedded()).unwrap();
        assert_eq!(system(&parallel), PARALLEL_SYSTEM);
        assert_eq!(system_chain_delay(&parallel), 0);
        let job = serial();
        let timing = system(&job);
        let pair = job.pair_schedule.as_ref().unwrap();
        assert_eq!(
            timing.latency_clocks,
            pair.len() as u32 + 3,
            "the outputs the clock after the pair's longest sample's (fetch, decode, words)"
        );
        assert_eq!(timing.min_clocks_per_sample, timing.latency_clocks);
        let chain = job.system_serial.as_ref().unwrap().settle_clocks() + 1;
        // The engine starts when the pair's deferred segments have made the rates.
        let k = system_chain_delay(&job) - pair.deferred.len() as u32;
        assert!(k * timing.min_clocks_per_sample >= chain + CHAIN_MARGIN_CLOCKS);
        assert!((k - 1) * timing.min_clocks_per_sample < chain + CHAIN_MARGIN_CLOCKS);
        assert!(check_system(&job).is_ok());
    }

    /// A chain that cannot finish between chain samples is refused, naming the fields and the
    /// decimation it needs.
    #[test]
    fn a_chain_slower_than_the_chain_samples_is_refused_naming_the_fields() {
        let mut job = serial();
        let k = system_chain_delay(&job);
        job.gyro_loops[0].plan.cic.decimation = k;
        assert!(check_system(&job).is_ok());
        job.gyro_loops[0].plan.cic.decimation = k - 1;
        let error = check_system(&job).unwrap_err().to_string();
        for word in ["loop.decimation", "architecture", &format!("at least {k}")] {
            assert!(error.contains(word), "{word}: {error}");
        }
    }
}
