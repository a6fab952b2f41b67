//! `pi` — `gyrofx_pi`, the gyro loop's PI controller with a clamped integrator and a preset
//! (SPEC §1.6, `docs/blocks/pi.md`); the package's block is the PLL's (the AGC's is the same
//! module at other formats and gains).
//!
//! Its vectors drive the PI of gyro A's PLL with its own stimulus (the chain's samples are not
//! used): wind-up against both integrator limits and back, presets inside, above and at both
//! ends of the integrator's range, with `ce` and alone (held into the testbench's idle clock,
//! where `ce` is low), a reset that wins over both, then random errors and presets with
//! resets. [`push_vectors`] does the same for any plan, which the tests use for other gains
//! and formats.

use gyrofx_model::gyro_loop::pi::{FixedPi, Plan};

use super::{flag, leaf_params, OwnStimulus, RomImages, RtlBlock, Words};
use crate::block::{Block, Output, Signal};
use crate::testbench::idle_clock_after;
use crate::vectors::VectorBuilder;
use gyrofx_job::job::Job;
use gyrofx_job::pipeline;

/// The PI block.
pub struct Pi;

/// Mixed into the config's seed for this block's random codes.
const STREAM: u64 = 0x7069_0000;

/// Samples at either end of the error range (the integrator winds up against its limit).
const WIND_UP_SAMPLES: usize = 600;
/// Random samples after the directed ones.
const RANDOM_SAMPLES: usize = 2500;

impl RtlBlock for Pi {
    fn name(&self) -> &'static str {
        "pi"
    }

    fn module(&self) -> &'static str {
        "gyrofx_pi"
    }

    fn title(&self) -> &'static str {
        "the PLL's PI controller: clamped integrator and preset"
    }

    fn block(&self, job: &Job, _roms: &RomImages) -> Block {
        block(&job.gyro_loops[0].plan.pll)
    }

    fn vectors<'a>(&self, job: &'a Job, block: Block) -> Option<Box<dyn VectorBuilder + 'a>> {
        let plan = &job.gyro_loops[0].plan.pll;
        let seed = job.config.seed ^ STREAM;
        Some(OwnStimulus::boxed(block, move |block| {
            push_vectors(block, plan, seed);
        }))
    }

    fn placement(&self) -> super::Placement {
        super::Placement::No
    }
}

/// The block of a PI of `plan`, without vectors.
pub fn block(plan: &Plan) -> Block {
    let mut block = Block::new(
        Pi.name(),
        Pi.module(),
        Pi.title(),
        vec![
            Signal::new("err", plan.input).with_unit("fs"),
            Signal::flag("preset"),
            Signal::new("preset_value", plan.integrator).with_unit(""),
        ],
        vec![
            Output::gated(
                Signal::new("u_out", plan.output.to).with_unit(""),
                "out_valid",
            ),
            Output::pulse(Signal::flag("out_valid")),
        ],
    );
    block.pipeline = pipeline::ONE_CLOCK;
    block.params = leaf_params(
        &plan.rtl_parameters(),
        Some((plan.output.rounding, plan.output.overflow)),
        None,
        "PI",
    );
    block
}

/// One sample of the PI's stimulus.
#[derive(Clone, Copy, Debug)]
struct Drive {
    rst: bool,
    err: i128,
    preset: bool,
    value: i128,
}

impl Drive {
    fn error(err: i128) -> Self {
        Drive {
            rst: false,
            err,
            preset: false,
            value: 0,
        }
    }

    fn preset(err: i128, value: i128) -> Self {
        Drive {
            preset: true,
            value,
            ..Drive::error(err)
        }
    }
}

/// The directed samples: wind-up both ways, then each preset value loaded with `ce` on a
/// sample without an idle clock after it, and again on one with: there it loads alone too
/// (`ce` low), undoing the sample's update, which a large error toward the middle of the
/// limits makes show in the outputs that follow.
fn directed(plan: &Plan) -> Vec<Drive> {
    let (e_format, v_format) = (plan.input, plan.integrator);
    let mut stimulus = Vec::new();
    stimulus.extend((0..WIND_UP_SAMPLES).map(|_| Drive::error(e_format.max_code())));
    stimulus.extend((0..WIND_UP_SAMPLES).map(|_| Drive::error(e_format.min_code())));
    let mid = (plan.limits[0] + plan.limits[1]) / 2;
    let above = (plan.limits[1] + 1).min(v_format.max_code());
    for value in [mid, above, v_format.min_code(), v_format.max_code()] {
        while idle_clock_after(stimulus.len()) {
            stimulus.push(Drive::error(-7));
        }
        stimulus.push(Drive::preset(3, value));
        stimulus.extend((0..4).map(|_| Drive::error(-7)));
        while !idle_clock_after(stimulus.len()) {
            stimulus.push(Drive::error(-7));
        }
        let inward = if value >= mid {
            e_format.min_code() / 2
        } else {
            e_format.max_code() / 2
        };
        stimulus.push(Drive::preset(inward, value));
        stimulus.extend((0..4).map(|_| Drive::error(11)));
    }
    stimulus.push(Drive {
        rst: true,
        ..Drive::preset(5, mid)
    });
    stimulus
}

/// Pushes the PI's directed and random samples (random codes from `seed`) and the fixed
/// model's outputs after each (`u_out` a don't-care, 0, after a reset sample). The testbenches
/// hold the inputs through the idle clock after every fourth sample, so a preset there loads
/// again with `ce` low: the model does the same. Returns how many updates the integrator's
/// limits clamped plus how many outputs wrapped or saturated.
pub fn push_vectors(block: &mut Block, plan: &Plan, seed: u64) -> u64 {
    let mut model = FixedPi::new(plan);
    let mut words = Words::new(seed);
    let mut stimulus = directed(plan);
    for _ in 0..RANDOM_SAMPLES {
        let r = words.next();
        stimulus.push(Drive {
            rst: r.is_multiple_of(600),
            err: words.code(plan.input),
            preset: r.is_multiple_of(97),
            value: words.code(plan.integrator),
        });
    }
    block.reserve(stimulus.len());
    for (index, drive) in stimulus.into_iter().enumerate() {
        let outputs = if drive.rst {
            model.reset();
            [0, 0]
        } else {
            if drive.preset {
                model.preset(drive.value as i64);
            }
            [model.step(drive.err as i64).into(), flag(true)]
        };
        if drive.preset && idle_clock_after(index) {
            model.preset(drive.value as i64);
        }
        block.push(
            drive.rst,
            &[drive.err, flag(drive.preset), drive.value],
            &outputs,
        );
    }
    let counts = model.overflow_counts();
    counts.integrator_clamped + counts.output
}
