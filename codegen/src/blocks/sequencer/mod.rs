//! `sequencer` — `gyrofx_sequencer`, the state-machine sequencer of mode reversal: each gyro's
//! mode, blanking, interval index and interval/window strobes (SPEC §1.2,
//! `docs/blocks/sequencer.md`).

use gyrofx_model::sequencer::Schedule;

use super::{flag, mode_bit, RomImages, RtlBlock};
use crate::block::DpiParts;
use crate::block::{Block, Output, Param, Signal};
use crate::vectors::{BlockResults, ChainSample, VectorBuilder};
use gyrofx_job::job::Job;
use gyrofx_job::pipeline;

/// The sequencer block.
pub struct Sequencer;

/// The sequencer's parameters (also the top's, which instantiates it).
pub fn params(schedule: &Schedule) -> Vec<Param> {
    let phase_bits = (usize::BITS - (schedule.interval_length - 1).leading_zeros()).max(1);
    let pattern: u128 = schedule
        .pattern
        .modes(schedule.intervals)
        .iter()
        .enumerate()
        .map(|(i, m)| u128::from(*m > 0) << i)
        .sum();
    vec![
        Param::integer(
            "INTERVAL_LENGTH",
            schedule.interval_length as i64,
            "L: samples per interval",
        ),
        Param::integer(
            "INTERVALS",
            schedule.intervals as i64,
            "W: intervals per window",
        ),
        Param::bits(
            "PATTERN",
            schedule.intervals as u32,
            pattern,
            format!(
                "A's modes, bit i = interval i ({})",
                schedule.pattern.name()
            ),
        ),
        Param::integer(
            "BLANK",
            schedule.blank as i64,
            "M: blanked samples per interval",
        ),
        Param::integer("STAGGER", schedule.stagger as i64, "S: B's delay, samples"),
        Param::integer("PHASE_W", phase_bits.into(), "phase counter width"),
        Param::integer(
            "INTERVAL_W",
            schedule.interval_bits().into(),
            "interval index width",
        ),
    ]
}

/// The slot signals the sequencer hands the estimator (its outputs after the modes).
pub fn slot_signals(schedule: &Schedule) -> [Signal; 7] {
    let interval_bits = schedule.interval_bits();
    [
        Signal::flag("blank_a"),
        Signal::flag("blank_b"),
        Signal::flag("done_a"),
        Signal::flag("done_b"),
        Signal::index("interval_a", interval_bits),
        Signal::index("interval_b", interval_bits),
        Signal::flag("window_done"),
    ]
}

impl RtlBlock for Sequencer {
    fn name(&self) -> &'static str {
        "sequencer"
    }

    fn module(&self) -> &'static str {
        "gyrofx_sequencer"
    }

    fn title(&self) -> &'static str {
        "state-machine sequencer"
    }

    fn block(&self, job: &Job, _roms: &RomImages) -> Block {
        let schedule = &job.chain.estimator.schedule;
        let interval_bits = schedule.interval_bits();
        let mut block = Block::new(
            self.name(),
            self.module(),
            self.title(),
            vec![],
            vec![
                Output::combinational(Signal::flag("mode_a")),
                Output::combinational(Signal::flag("mode_b")),
                Output::combinational(Signal::flag("blank_a")),
                Output::combinational(Signal::flag("blank_b")),
                Output::combinational(Signal::index("interval_a", interval_bits)),
                Output::combinational(Signal::index("interval_b", interval_bits)),
                Output::combinational(Signal::flag("done_a")),
                Output::combinational(Signal::flag("done_b")),
                Output::combinational(Signal::flag("window_done")),
            ],
        );
        block.dpi = Some(DPI);
        block.pipeline = pipeline::SEQUENCER;
        block.cocotb_test = Some(include_str!("cocotb_test.py"));
        block.params = params(schedule);
        block
    }

    fn vectors<'a>(&self, job: &'a Job, mut block: Block) -> Option<Box<dyn VectorBuilder + 'a>> {
        block.reserve(job.config.samples + 1);
        Some(Box::new(Vectors { block }))
    }
}

/// The sequencer's outputs for every sample of the chain run.
struct Vectors {
    block: Block,
}

impl VectorBuilder for Vectors {
    fn reset(&mut self) {
        self.block.push(true, &[], &[0; 9]);
    }

    fn sample(&mut self, sample: &ChainSample) {
        let s = &sample.fixed.slot;
        self.block.push(
            false,
            &[],
            &[
                mode_bit(s.mode_a),
                mode_bit(s.mode_b),
                flag(s.blank_a),
                flag(s.blank_b),
                s.interval_a as i128,
                s.interval_b as i128,
                flag(s.done_a),
                flag(s.done_b),
                flag(s.window_done),
            ],
        );
    }

    fn finish(self: Box<Self>, _results: &mut BlockResults) -> Block {
        self.block
    }
}

/// The DPI-C testbench's parts ([`DpiParts`]): every output against the model before the clock
/// edge.
const DPI: DpiParts = DpiParts {
    imports: concat!(
        include_str!("dpi_imports.svh"),
        include_str!("../estimator/dpi_imports.svh")
    ),
    handles: "sequencer = gyrofx_sequencer_new(plan);",
    step: dpi_step,
    stream: None,
    samples: 4000,
};

/// One sample of the DPI-C testbench's stimulus loop.
fn dpi_step(_block: &Block) -> String {
    include_str!("dpi_step.sv").trim_end().to_string()
}
