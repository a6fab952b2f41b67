//! `estimator` — `gyrofx_bias_estimator`, the least-squares bias estimator of mode reversal:
//! interval means and `b = G m` at every window end (SPEC §1.3, `docs/blocks/estimator.md`).

use gyrofx_model::estimator::Plan;
use serde_json::json;

use super::{flag, mode_params, RomImages, RtlBlock};
use crate::block::DpiParts;
use crate::block::{Block, Output, Param, Signal};
use crate::rom::{Rom, RomFormat, ROM_FOLDER};
use crate::stats::Accumulator;
use crate::text::fill;
use crate::vectors::{BlockResults, ChainSample, Run, VectorBuilder};
use gyrofx_job::job::Job;
use gyrofx_job::pipeline;

/// The estimator block.
pub struct Estimator;

/// Name of its gain ROM.
pub const ROM: &str = "estimator_gains";

/// The estimator's parameters without the modes and the ROM file (the top shares them).
pub fn params(est: &Plan) -> Vec<Param> {
    let schedule = &est.schedule;
    let mut params = Vec::new();
    params.extend(Param::format("IN", est.input, "gyro samples"));
    params.push(Param::integer(
        "ACC_W",
        est.accumulator.width.into(),
        format!("accumulator: {}", est.accumulator),
    ));
    params.extend(Param::format("RECIP", est.reciprocal, "reciprocal 1/(L-M)"));
    params.push(Param::bits(
        "RECIP",
        est.reciprocal.width,
        est.reciprocal.to_bits(est.reciprocal_code),
        format!("1/{}", schedule.valid_count()),
    ));
    params.extend(Param::format("MEAN", est.mean, "interval means"));
    params.extend(Param::format("GAIN", est.gain, "least-squares gains"));
    params.push(Param::integer(
        "DOT_W",
        est.dot.width.into(),
        format!("dot product: {}", est.dot),
    ));
    params.extend(Param::format("BIAS", est.bias, "bias estimates"));
    params.push(Param::integer("INTERVALS", schedule.intervals as i64, "W"));
    params.push(Param::integer(
        "INTERVAL_W",
        schedule.interval_bits().into(),
        "interval index width",
    ));
    params.push(Param::integer(
        "SMOOTH",
        est.smoothing_shift.into(),
        "smoothing shift",
    ));
    params
}

impl RtlBlock for Estimator {
    fn name(&self) -> &'static str {
        "estimator"
    }

    fn module(&self) -> &'static str {
        "gyrofx_bias_estimator"
    }

    fn title(&self) -> &'static str {
        "least-squares bias estimator"
    }

    fn roms(&self, job: &Job) -> Vec<Rom> {
        vec![Rom::estimator(&job.chain.estimator)]
    }

    fn block(&self, job: &Job, roms: &RomImages) -> Block {
        let est = &job.chain.estimator;
        let mut inputs = vec![Signal::new("y_a", est.input), Signal::new("y_b", est.input)];
        inputs.extend(super::sequencer::slot_signals(&est.schedule));
        let mut block = Block::new(
            self.name(),
            self.module(),
            self.title(),
            inputs,
            vec![
                Output::registered(Signal::new("bias_a", est.bias)),
                Output::registered(Signal::new("bias_b", est.bias)),
                Output::registered(Signal::flag("estimated")),
            ],
        );
        block.dpi = Some(DPI);
        block.cocotb_test = Some(include_str!("cocotb_test.py"));
        block.params = params(est);
        block.params.extend(mode_params(est.rounding, est.overflow));
        let rom = roms.entry(ROM);
        block
            .params
            .push(Param::string("ROM_FILE", &rom.0, "gain ROM"));
        block.roms.push(rom);
        block.pipeline = pipeline::ESTIMATOR;
        block
    }

    fn vectors<'a>(&self, job: &'a Job, mut block: Block) -> Option<Box<dyn VectorBuilder + 'a>> {
        block.reserve(job.config.samples + 1);
        Some(Box::new(Vectors {
            plan: &job.chain.estimator,
            block,
            bias: Accumulator::default(),
        }))
    }

    fn manifest(
        &self,
        job: &Job,
        roms: &RomImages,
        run: &Run,
    ) -> Option<(&'static str, serde_json::Value)> {
        let est = &job.chain.estimator;
        let rom = roms.get(ROM);
        Some((
            "estimator",
            json!({
                "schedule": {
                    "interval_length": est.schedule.interval_length,
                    "intervals": est.schedule.intervals,
                    "pattern": est.schedule.pattern.name(),
                    "blank": est.schedule.blank,
                    "stagger": est.schedule.stagger,
                },
                "rate_order": est.rate_order,
                "latency_clocks": pipeline::ESTIMATOR.latency_clocks,
                "min_clocks_per_sample": pipeline::ESTIMATOR.min_clocks_per_sample,
                "formats": {
                    "input": est.input.to_string(),
                    "accumulator": est.accumulator.to_string(),
                    "reciprocal": est.reciprocal.to_string(),
                    "mean": est.mean.to_string(),
                    "gain": est.gain.to_string(),
                    "dot": est.dot.to_string(),
                    "bias": est.bias.to_string(),
                    "calibrated": est.calibrated.to_string(),
                },
                "reciprocal": {"value": 1.0 / est.schedule.valid_count() as f64, "quantized": est.quantized_reciprocal(), "code": est.reciprocal_code as i64},
                "gains": {"designed": est.gains, "quantized": est.quantized_gains(), "all_shifts": est.gains_are_shifts(),
                          "rom": {"file": RomFormat::Mem.file_name(&rom.rom.name), "word_bits": rom.rom.width(), "all_formats": ROM_FOLDER, "order": "bias_a row over [mA0, mB0, mA1, ...], then bias_b row"}},
                "smoothing_shift": est.smoothing_shift,
                "fixed_vs_float_bias": run.stats("bias"),
            }),
        ))
    }
}

/// The estimator's inputs and bias registers for every sample of the chain run, and the bias
/// estimates' fixed-vs-float statistics.
struct Vectors<'a> {
    plan: &'a Plan,
    block: Block,
    bias: Accumulator,
}

impl VectorBuilder for Vectors<'_> {
    fn reset(&mut self) {
        self.block.push(true, &[0; 9], &[0, 0, 0]);
    }

    fn sample(&mut self, sample: &ChainSample) {
        let s = &sample.fixed.slot;
        let y = sample.y;
        self.block.push(
            false,
            &[
                i128::from(y[0]),
                i128::from(y[1]),
                flag(s.blank_a),
                flag(s.blank_b),
                flag(s.done_a),
                flag(s.done_b),
                s.interval_a as i128,
                s.interval_b as i128,
                flag(s.window_done),
            ],
            &[
                sample.bias_after[0],
                sample.bias_after[1],
                flag(sample.estimated),
            ],
        );
        // Bias estimates: fixed vs float, every sample (the ones in use).
        let lsb = self.plan.bias.lsb();
        for g in 0..2 {
            self.bias.add(
                self.plan
                    .bias
                    .to_f64(i128::from(sample.fixed.estimator.bias[g])),
                sample.float.estimator.bias[g],
                sample.ideal.estimator.bias[g],
                lsb,
            );
        }
    }

    fn finish(self: Box<Self>, results: &mut BlockResults) -> Block {
        let bound = self.plan.bias_error_bound() / self.plan.bias.lsb();
        results.stats.push(("bias", self.bias.finish(bound)));
        self.block
    }
}

/// The DPI-C testbench's parts ([`DpiParts`]): the slots from the sequencer's own model (the
/// estimator's protocol), the estimates after the latency.
const DPI: DpiParts = DpiParts {
    imports: concat!(
        include_str!("../sequencer/dpi_imports.svh"),
        include_str!("dpi_imports.svh")
    ),
    handles:
        "sequencer = gyrofx_sequencer_new(plan);\n        estimator = gyrofx_estimator_new(plan);",
    step: dpi_step,
    stream: None,
    samples: 4000,
};

/// One sample of the DPI-C testbench's stimulus loop.
fn dpi_step(block: &Block) -> String {
    fill(
        include_str!("dpi_step.sv").trim_end(),
        &[("settle", &block.settle_clocks().to_string())],
    )
}
