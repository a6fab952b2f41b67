//! `cic` — `gyrofx_cic`, the gyro loop's decimating CIC filter and its droop compensator
//! (SPEC §1.6, `docs/blocks/cic.md`): one output every `DECIMATION` samples, with `y_valid`.
//!
//! Its vectors drive the CIC of gyro A's loop plan with its own stimulus (the chain's samples
//! are not used): full scale long enough for the integrators to wrap, the most negative code,
//! random codes with a reset in the middle of a decimation period, then a reset with `ce` high
//! and three more periods. [`push_vectors`] does the same for any plan, which the tests use for
//! other orders, rates and formats.

use gyrofx_model::gyro_loop::cic::{FixedCic, Plan};

use super::gyro_loop::TAPS_ROM;
use super::{flag, leaf_params, OwnStimulus, RomImages, RtlBlock, Words};
use crate::block::{Block, Output, Signal};
use crate::vectors::VectorBuilder;
use gyrofx_job::job::Job;
use gyrofx_job::pipeline;

/// The CIC block.
pub struct Cic;

/// Mixed into the config's seed for this block's random codes.
const STREAM: u64 = 0x6369_6300;

/// Decimated outputs in the package's vectors (before the final reset).
const OUTPUTS: usize = 12;

impl RtlBlock for Cic {
    fn name(&self) -> &'static str {
        "cic"
    }

    fn module(&self) -> &'static str {
        "gyrofx_cic"
    }

    fn title(&self) -> &'static str {
        "the gyro loop's decimating CIC filter with its droop compensator"
    }

    fn block(&self, job: &Job, roms: &RomImages) -> Block {
        block(&job.gyro_loops[0].plan.cic, roms.entry(TAPS_ROM))
    }

    fn vectors<'a>(&self, job: &'a Job, block: Block) -> Option<Box<dyn VectorBuilder + 'a>> {
        let plan = &job.gyro_loops[0].plan.cic;
        let seed = job.config.seed ^ STREAM;
        let samples = OUTPUTS * plan.decimation as usize;
        Some(OwnStimulus::boxed(block, move |block| {
            push_vectors(block, plan, samples, seed);
        }))
    }

    fn placement(&self) -> super::Placement {
        super::Placement::No
    }
}

/// The block of a CIC of `plan` reading the compensator's ROM image `rom` (file name, text),
/// without vectors.
pub fn block(plan: &Plan, rom: (String, String)) -> Block {
    let mut block = Block::new(
        Cic.name(),
        Cic.module(),
        Cic.title(),
        vec![Signal::new("x", plan.input).with_unit("fs")],
        vec![
            Output::gated(Signal::new("y", plan.output.to).with_unit("fs"), "y_valid"),
            Output::pulse(Signal::flag("y_valid")),
        ],
    );
    block.pipeline = pipeline::ONE_CLOCK;
    block.params = leaf_params(
        &plan.rtl_parameters(),
        Some((plan.output.rounding, plan.output.overflow)),
        Some(&rom.0),
        "CIC",
    );
    block.roms.push(rom);
    block
}

/// Pushes `samples` directed and random samples (random codes from `seed`), then a reset and
/// three decimation periods, and the fixed model's outputs after each (`y` a don't-care, 0,
/// where `y_valid` is 0); returns how many values the model wrapped or saturated.
pub fn push_vectors(block: &mut Block, plan: &Plan, samples: usize, seed: u64) -> u64 {
    let mut model = FixedCic::new(plan);
    let mut words = Words::new(seed);
    let x_format = plan.input;
    let r = plan.decimation as usize;
    let mut stimulus: Vec<(bool, i128)> = Vec::new();
    stimulus.extend((0..samples / 4).map(|_| (false, x_format.max_code())));
    stimulus.extend((0..samples / 4).map(|_| (false, x_format.min_code())));
    for k in 0..samples / 2 {
        stimulus.push((k == samples / 4 + r / 3, words.code(x_format)));
    }
    stimulus.push((true, 3));
    stimulus.extend((0..3 * r).map(|_| (false, words.code(x_format))));
    block.reserve(stimulus.len());
    for (rst, x) in stimulus {
        let outputs = if rst {
            model.reset();
            [0, 0]
        } else {
            match model.step(x as i64) {
                Some(y) => [y.into(), flag(true)],
                None => [0, 0],
            }
        };
        block.push(rst, &[x], &outputs);
    }
    let counts = model.overflow_counts();
    counts.cic + counts.output
}
