//! `calibration` — `gyrofx_calibration`, the calibrated and combined outputs of mode reversal
//! (SPEC §1.3, `docs/blocks/calibration.md`). Combinational, inside `gyrofx_top`: it has no
//! vectors of its own; the top's vectors check it.

use super::{mode_params, RomImages, RtlBlock};
use crate::block::{Block, Output, Param, Signal};
use crate::vectors::VectorBuilder;
use gyrofx_job::job::Job;

/// The calibration block.
pub struct Calibration;

impl RtlBlock for Calibration {
    fn name(&self) -> &'static str {
        "calibration"
    }

    fn module(&self) -> &'static str {
        "gyrofx_calibration"
    }

    fn title(&self) -> &'static str {
        "calibrated and combined outputs"
    }

    fn block(&self, job: &Job, _roms: &RomImages) -> Block {
        let est = &job.chain.estimator;
        let mut block = Block::new(
            self.name(),
            self.module(),
            self.title(),
            vec![
                Signal::new("y_a", est.input),
                Signal::new("y_b", est.input),
                Signal::flag("mode_a"),
                Signal::flag("mode_b"),
                Signal::flag("blank_a"),
                Signal::flag("blank_b"),
                Signal::new("bias_a", est.bias),
                Signal::new("bias_b", est.bias),
            ],
            vec![
                Output::combinational(Signal::new("out_a", est.calibrated)),
                Output::combinational(Signal::new("out_b", est.calibrated)),
                Output::combinational(Signal::flag("valid_a")),
                Output::combinational(Signal::flag("valid_b")),
                Output::combinational(Signal::new("combined", est.calibrated)),
                Output::combinational(Signal::flag("combined_valid")),
            ],
        );
        block.clocked = false;
        block
            .params
            .extend(Param::format("IN", est.input, "gyro samples"));
        block
            .params
            .extend(Param::format("BIAS", est.bias, "bias estimates"));
        block.params.extend(Param::format(
            "CAL",
            est.calibrated,
            "calibrated and combined outputs",
        ));
        block.params.extend(mode_params(est.rounding, est.overflow));
        block
    }

    fn has_vectors(&self) -> bool {
        false
    }

    fn vectors<'a>(&self, _job: &'a Job, _block: Block) -> Option<Box<dyn VectorBuilder + 'a>> {
        None
    }
}
