//! `nco` — `gyrofx_nco`, the gyro loop's numerically controlled oscillator (SPEC §1.6,
//! `docs/blocks/nco.md`): a phase accumulator, phase truncation and a quarter-wave sine ROM,
//! sine and cosine out one clock after `ce`.
//!
//! Its vectors drive the NCO of gyro A's loop plan with its own stimulus (the chain's samples
//! are not used): every ROM bin in order, then backwards with a quarter-cycle offset (both
//! quadrant folds of the ROM), a reset with `ce` high, the largest frequency word, then random
//! words and offsets with a reset every 700 samples. [`push_vectors`] does the same for any
//! plan, which the tests use for other widths.

use gyrofx_model::gyro_loop::nco::{FixedNco, Plan};

use super::gyro_loop::SINE_ROM;
use super::{flag, leaf_params, OwnStimulus, RomImages, RtlBlock, Words};
use crate::block::{Block, Output, Signal};
use crate::vectors::VectorBuilder;
use gyrofx_job::job::Job;
use gyrofx_job::pipeline;

/// The NCO block.
pub struct Nco;

/// Mixed into the config's seed for this block's random words.
const STREAM: u64 = 0x6e63_6f00;

/// Random samples after the directed ones.
const RANDOM_SAMPLES: usize = 2000;

impl RtlBlock for Nco {
    fn name(&self) -> &'static str {
        "nco"
    }

    fn module(&self) -> &'static str {
        "gyrofx_nco"
    }

    fn title(&self) -> &'static str {
        "the gyro loop's NCO: phase accumulator, truncation, quarter-wave sine ROM"
    }

    fn block(&self, job: &Job, roms: &RomImages) -> Block {
        block(&job.gyro_loops[0].plan.nco, roms.entry(SINE_ROM))
    }

    fn vectors<'a>(&self, job: &'a Job, block: Block) -> Option<Box<dyn VectorBuilder + 'a>> {
        let plan = &job.gyro_loops[0].plan.nco;
        let seed = job.config.seed ^ STREAM;
        Some(OwnStimulus::boxed(block, move |block| {
            push_vectors(block, plan, seed);
        }))
    }

    fn placement(&self) -> super::Placement {
        super::Placement::No
    }
}

/// The block of an NCO of `plan` reading the sine ROM image `rom` (file name, text), without
/// vectors.
pub fn block(plan: &Plan, rom: (String, String)) -> Block {
    let mut block = Block::new(
        Nco.name(),
        Nco.module(),
        Nco.title(),
        vec![
            Signal::new("freq", plan.phase).with_unit(""),
            Signal::new("offset", plan.phase).with_unit(""),
        ],
        vec![
            Output::gated(
                Signal::new("sin_out", plan.output).with_unit("fs"),
                "out_valid",
            ),
            Output::gated(
                Signal::new("cos_out", plan.output).with_unit("fs"),
                "out_valid",
            ),
            Output::pulse(Signal::flag("out_valid")),
        ],
    );
    block.pipeline = pipeline::ONE_CLOCK;
    block.params = leaf_params(&plan.rtl_parameters(), None, Some(&rom.0), "NCO");
    block.roms.push(rom);
    block
}

/// Pushes the NCO's directed and random samples (random words from `seed`) and the fixed
/// model's outputs after each: `sin_out` and `cos_out` are don't-cares (0) after a reset
/// sample, whose `out_valid` is 0.
pub fn push_vectors(block: &mut Block, plan: &Plan, seed: u64) {
    let mut model = FixedNco::new(plan);
    let mut words = Words::new(seed);
    let phase = plan.phase;
    let mask = u64::MAX >> (64 - phase.width);
    let bin = 1u64 << (phase.width - plan.address_bits - 2);
    let bins = 1usize << (plan.address_bits + 2);
    let mut stimulus: Vec<(bool, u64, u64)> = Vec::new();
    stimulus.extend((0..bins.min(4096)).map(|_| (false, bin, 0)));
    stimulus.extend((0..64).map(|_| (false, bin.wrapping_neg(), 1 << (phase.width - 2))));
    stimulus.push((true, 5, 5));
    stimulus.extend((0..32).map(|_| (false, mask, 0)));
    for k in 0..RANDOM_SAMPLES {
        stimulus.push((k % 700 == 699, words.next(), words.next()));
    }
    block.reserve(stimulus.len());
    for (rst, freq, offset) in stimulus {
        let (freq, offset) = (freq & mask, offset & mask);
        let outputs = if rst {
            model.reset();
            [0, 0, 0]
        } else {
            let r = model.step(freq, offset);
            [r.sin.into(), r.cos.into(), flag(true)]
        };
        block.push(rst, &[freq.into(), offset.into()], &outputs);
    }
}
