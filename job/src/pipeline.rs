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
pub const SYSTEM: Pipeline = Pipeline::new(
    GYRO_LOOP.latency_clocks + TOP.latency_clocks,
    GYRO_LOOP.latency_clocks + TOP.latency_clocks,
);

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
