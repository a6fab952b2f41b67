//! `demodulator` — `gyrofx_demodulator`, the gyro loop's I/Q demodulator (SPEC §1.6,
//! `docs/blocks/demodulator.md`): the ADC code times the NCO's sine and cosine, each product
//! low-passed by a one-pole filter, I and Q out one clock after `ce`.
//!
//! Its vectors drive the demodulator of gyro A's loop plan with its own stimulus (the chain's
//! samples are not used): the extreme products (the most negative code times the most negative
//! reference and their neighbours), a tone demodulated by an NCO-like reference long enough
//! for the low-pass to settle, a reset with `ce` high, then random codes with a reset in the
//! middle. [`push_vectors`] does the same for any plan, which the tests use for formats that
//! wrap and saturate.

use gyrofx_model::gyro_loop::demodulator::{FixedDemodulator, Plan};
use gyrofx_model::gyro_loop::nco::{self, FixedNco, Reference};

use super::{flag, leaf_params, OwnStimulus, RomImages, RtlBlock, Words};
use crate::block::{Block, Output, Signal};
use crate::vectors::VectorBuilder;
use gyrofx_job::job::Job;
use gyrofx_job::pipeline;

/// The demodulator block.
pub struct Demodulator;

/// Mixed into the config's seed for this block's random codes.
const STREAM: u64 = 0x6465_6d00;

/// Samples of the demodulated tone, and of random codes.
const TONE_SAMPLES: usize = 1500;
const RANDOM_SAMPLES: usize = 1500;

impl RtlBlock for Demodulator {
    fn name(&self) -> &'static str {
        "demodulator"
    }

    fn module(&self) -> &'static str {
        "gyrofx_demodulator"
    }

    fn title(&self) -> &'static str {
        "the gyro loop's I/Q demodulator: products and one-pole low-passes"
    }

    fn block(&self, job: &Job, _roms: &RomImages) -> Block {
        block(&job.gyro_loops[0].plan.demodulator)
    }

    fn vectors<'a>(&self, job: &'a Job, block: Block) -> Option<Box<dyn VectorBuilder + 'a>> {
        let plan = &job.gyro_loops[0].plan.demodulator;
        let seed = job.config.seed ^ STREAM;
        Some(OwnStimulus::boxed(block, move |block| {
            push_vectors(block, plan, seed);
        }))
    }

    fn placement(&self) -> super::Placement {
        super::Placement::No
    }
}

/// The block of a demodulator of `plan`, without vectors.
pub fn block(plan: &Plan) -> Block {
    let mut block = Block::new(
        Demodulator.name(),
        Demodulator.module(),
        Demodulator.title(),
        vec![
            Signal::new("adc", plan.input).with_unit("fs"),
            Signal::new("ref_sin", plan.reference).with_unit("fs"),
            Signal::new("ref_cos", plan.reference).with_unit("fs"),
        ],
        vec![
            Output::gated(
                Signal::new("i_out", plan.output.to).with_unit("fs"),
                "out_valid",
            ),
            Output::gated(
                Signal::new("q_out", plan.output.to).with_unit("fs"),
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
        "demodulator",
    );
    block
}

/// Pushes the demodulator's directed and random samples (random codes from `seed`) and the
/// fixed model's outputs after each (`i_out`, `q_out` don't-cares, 0, after a reset sample);
/// returns how many values the model wrapped or saturated.
///
/// # Panics
/// When the reference is not 3 to 32 bits wide (an NCO's sine).
pub fn push_vectors(block: &mut Block, plan: &Plan, seed: u64) -> u64 {
    let mut model = FixedDemodulator::new(plan);
    let mut words = Words::new(seed);
    let (x_format, r_format) = (plan.input, plan.reference);
    let mut stimulus: Vec<(bool, [i128; 3])> = Vec::new();
    let corners = [x_format.min_code(), x_format.max_code(), 0, -1];
    let r_corners = [r_format.min_code(), r_format.max_code(), 1, -1];
    for (k, x) in corners.iter().enumerate() {
        for r in r_corners {
            stimulus.extend((0..5).map(|_| (false, [*x, r, r_corners[k]])));
        }
    }
    let tone = nco::Plan::new(&nco::Spec {
        phase_bits: 32,
        address_bits: 8,
        sine_width: r_format.width,
        error_feedback: false,
    })
    .expect("the reference is an NCO's sine");
    let mut reference = FixedNco::new(&tone);
    let freq = tone
        .frequency_word(8195.0, 200_000.0)
        .expect("a frequency below Nyquist");
    let amplitude = (x_format.max_code() / 2) as f64;
    for n in 0..TONE_SAMPLES {
        let r = reference.step(freq, 0);
        // libm, not the platform's sin: the codes are the same on every platform.
        let x = libm::round(amplitude * libm::sin(0.2578 * n as f64 + 0.7)) as i128;
        stimulus.push((false, [x, r.sin.into(), r.cos.into()]));
    }
    stimulus.push((true, [1, 1, 1]));
    for k in 0..RANDOM_SAMPLES {
        let codes = [
            words.code(x_format),
            words.code(r_format),
            words.code(r_format),
        ];
        stimulus.push((k == 900, codes));
    }
    block.reserve(stimulus.len());
    for (rst, [x, sin, cos]) in stimulus {
        let outputs = if rst {
            model.reset();
            [0, 0, 0]
        } else {
            let reference = Reference {
                sin: sin as i64,
                cos: cos as i64,
            };
            let out = model.step(x as i64, reference);
            [out.i.into(), out.q.into(), flag(true)]
        };
        block.push(rst, &[x, sin, cos], &outputs);
    }
    let counts = model.overflow_counts();
    counts
        .product
        .iter()
        .chain(&counts.state)
        .chain(&counts.output)
        .sum()
}
