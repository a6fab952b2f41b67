//! `mean_filter` — `gyrofx_mean_filter`, the mean filter with gross-error rejection of paper
//! 003, a block beside the chain (SPEC §1.5, `docs/blocks/mean_filter.md`). Its vectors: gyro
//! A's ADC samples with gross errors added, the chain's reset, then directed blocks.

use gyrofx_model::mean_filter::{serial, FixedMeanFilter, FloatMeanFilter, Plan};
use serde_json::json;

use super::{mode_params, Placement, RomImages, RtlBlock};
use crate::block::{Block, Output, Param, Signal};
use crate::block::{DpiParts, DpiStream};
use crate::rom::{Rom, RomFormat, ROM_FOLDER};
use crate::stats::Accumulator;
use crate::vectors::{BlockResults, ChainSample, Run, VectorBuilder};
use gyrofx_job::config::Architecture;
use gyrofx_job::job::Job;
use gyrofx_job::pipeline;

/// The mean-filter block.
pub struct MeanFilter;

/// The module with `architecture = "serial"`: one step a clock, no multiplier
/// (`hdl/gyrofx_mean_filter_serial.v`, `gyrofx_model::mean_filter::serial`).
pub const SERIAL_MODULE: &str = "gyrofx_mean_filter_serial";

/// Name of its reciprocal ROM.
pub const ROM: &str = "mean_filter_reciprocals";

/// Gross errors added to gyro A's samples (the plant has none): every `GROSS_ERROR_PERIOD`-th
/// sample, ±`GROSS_ERROR_SCALE`·r, alternating in sign.
pub const GROSS_ERROR_PERIOD: usize = 53;
const GROSS_ERROR_SCALE: i128 = 8;

impl RtlBlock for MeanFilter {
    fn name(&self) -> &'static str {
        "mean_filter"
    }

    fn module(&self) -> &'static str {
        "gyrofx_mean_filter"
    }

    /// `gyrofx_mean_filter_serial` is placed beside it, with the job's mean filter whatever
    /// its `architecture`.
    fn placement(&self) -> Placement {
        Placement::WithSerial("mean_filter_serial")
    }

    fn title(&self) -> &'static str {
        "mean filter with gross-error rejection (paper 003)"
    }

    fn roms(&self, job: &Job) -> Vec<Rom> {
        vec![Rom::mean_filter(&job.mean_filter)]
    }

    fn block(&self, job: &Job, roms: &RomImages) -> Block {
        let plan = &job.mean_filter;
        let mut block = Block::new(
            self.name(),
            self.module(),
            self.title(),
            vec![Signal::new("x", plan.input)],
            vec![
                Output::pulse(Signal::flag("y_valid")),
                Output::gated(Signal::new("y", plan.output), "y_valid"),
                Output::gated(Signal::index("kept", plan.count_bits), "y_valid"),
            ],
        );
        block.dpi = Some(DPI);
        block.cocotb_test = Some(include_str!("cocotb_test.py"));
        block.pipeline = pipeline::mean_filter(job);
        block
            .params
            .extend(Param::format("IN", plan.input, "input x"));
        block
            .params
            .extend(Param::format("OUT", plan.output, "output y"));
        block.params.push(Param::integer(
            "WINDOW",
            plan.window.into(),
            "L: samples per block",
        ));
        block.params.push(Param::integer(
            "COUNT_W",
            plan.count_bits.into(),
            "kept count width",
        ));
        block.params.push(Param::integer(
            "SUM_W",
            plan.sum.width.into(),
            format!("block sum: {}", plan.sum),
        ));
        if job.settings.architecture == Architecture::Serial {
            block.module = SERIAL_MODULE;
            block.title = "mean filter with gross-error rejection (paper 003), sequential";
            block.params.push(Param::bits(
                "THRESHOLD",
                plan.input.width,
                plan.threshold_code as u128,
                format!("r in input LSB ({} °/s)", plan.threshold_dps()),
            ));
        } else {
            block.params.push(Param::integer(
                "DEV_W",
                plan.deviation.width.into(),
                format!("L*x - sum: {}", plan.deviation),
            ));
            block.params.push(Param::bits(
                "SCALED_THRESHOLD",
                plan.deviation.width,
                plan.scaled_threshold as u128,
                format!("L*r in input LSB (r = {} °/s)", plan.threshold_dps()),
            ));
        }
        block
            .params
            .extend(Param::format("RECIP", plan.reciprocal, "reciprocals 1/n"));
        block
            .params
            .extend(mode_params(plan.rounding, plan.overflow));
        let rom = roms.entry(ROM);
        block
            .params
            .push(Param::string("ROM_FILE", &rom.0, "reciprocal ROM"));
        block.roms.push(rom);
        block
    }

    fn vectors<'a>(&self, job: &'a Job, mut block: Block) -> Option<Box<dyn VectorBuilder + 'a>> {
        let plan = &job.mean_filter;
        block.reserve(job.config.samples + 1);
        Some(Box::new(Vectors {
            plan,
            block,
            fixed: FixedMeanFilter::new(plan),
            float: FloatMeanFilter::new(plan),
            ideal: FloatMeanFilter::with_threshold(plan.window, plan.threshold_dps()),
            errors: Accumulator::default(),
            overflows: 0,
        }))
    }

    fn manifest(
        &self,
        job: &Job,
        roms: &RomImages,
        run: &Run,
    ) -> Option<(&'static str, serde_json::Value)> {
        let mf = &job.mean_filter;
        let rom = roms.get(ROM);
        // Parallel: a sample every clock, the mean 1 clock after a block's last, every sample
        // compared by its deviation L·x − sum. Serial: the next ce or rst no sooner than the
        // mean, the samples compared with a kept range.
        let (architecture, module, (compared, compared_format)) = match job.settings.architecture {
            Architecture::Parallel => ("parallel", self.module(), ("deviation", mf.deviation)),
            Architecture::Serial => (
                "serial",
                SERIAL_MODULE,
                ("kept_range", serial::kept_range_format(mf)),
            ),
        };
        let timing = pipeline::mean_filter(job);
        let section = json!({
                "window": mf.window,
                "threshold_dps": job.config.mean_filter.threshold_dps,
                "threshold_quantized_dps": mf.threshold_dps(),
                "threshold_code": mf.threshold_code as i64,
                "formats": {
                    "input": mf.input.to_string(),
                    "output": mf.output.to_string(),
                    "sum": mf.sum.to_string(),
                    compared: compared_format.to_string(),
                    "reciprocal": mf.reciprocal.to_string(),
                    "product": mf.product.to_string(),
                },
                "rom": {"file": RomFormat::Mem.file_name(&rom.rom.name), "depth": mf.rom.len(), "word_bits": rom.rom.width(), "all_formats": ROM_FOLDER,
                        "order": "address = samples kept n: 1/n; address 0: 1/L (every sample rejected)"},
                "stimulus": "gyro A's ADC samples with a gross error of 8 r every 53rd sample, the chain's reset, then directed blocks (samples at exactly r, at r + 1 LSB, all rejected, full scale, a full-scale spike)",
                "architecture": architecture,
                "module": module,
                "latency_clocks": timing.latency_clocks,
                "min_clocks_per_sample": timing.min_clocks_per_sample,
                "fixed_vs_float": run.stats("mean_filter"),
        });
        Some(("mean_filter", section))
    }
}

/// Gyro A's samples with gross errors through the fixed filter and its float twins (same
/// quantized threshold; ideal: the threshold unquantized).
struct Vectors<'a> {
    plan: &'a Plan,
    block: Block,
    fixed: FixedMeanFilter,
    float: FloatMeanFilter,
    ideal: FloatMeanFilter,
    errors: Accumulator,
    /// Outputs that rounded past the output range (full-scale blocks may).
    overflows: u64,
}

impl Vectors<'_> {
    fn step(&mut self, code: i64) {
        let plan = self.plan;
        let real = plan.input.to_f64(i128::from(code));
        let a = self.fixed.step(code);
        let b = self.float.step(real);
        let c = self.ideal.step(real);
        match (a, b, c) {
            (Some(a), Some((b, _)), Some((c, _))) => {
                // The bound holds where the output fits (full scale may round past it).
                if a.overflowed {
                    self.overflows += 1;
                } else {
                    self.errors
                        .add(plan.output.to_f64(i128::from(a.y)), b, c, plan.output.lsb());
                }
                self.block.push(
                    false,
                    &[i128::from(code)],
                    &[1, i128::from(a.y), i128::from(a.kept)],
                );
            }
            _ => self.block.push(false, &[i128::from(code)], &[0, 0, 0]),
        }
    }
}

impl VectorBuilder for Vectors<'_> {
    fn reset(&mut self) {
        self.fixed.reset();
        self.float.reset();
        self.ideal.reset();
        self.block.push(true, &[0], &[0, 0, 0]);
    }

    fn sample(&mut self, sample: &ChainSample) {
        let k = sample.index;
        let gross = if k % GROSS_ERROR_PERIOD == GROSS_ERROR_PERIOD / 3 {
            let sign = if (k / GROSS_ERROR_PERIOD).is_multiple_of(2) {
                1
            } else {
                -1
            };
            sign * GROSS_ERROR_SCALE * self.plan.threshold_code.max(1)
        } else {
            0
        };
        let (min, max) = (self.plan.input.min_code(), self.plan.input.max_code());
        let code = (i128::from(sample.y[0]) + gross).clamp(min, max) as i64;
        self.step(code);
    }

    fn finish(mut self: Box<Self>, results: &mut BlockResults) -> Block {
        for sample in directed(self.plan) {
            match sample {
                Some(code) => self.step(code),
                None => self.reset(),
            }
        }
        let bound = self.plan.error_bound_lsb();
        let stats = std::mem::take(&mut self.errors).finish(bound);
        results.stats.push(("mean_filter", stats));
        results
            .overflows
            .push(("mean_filter", serde_json::json!(self.overflows)));
        self.block
    }
}

/// The directed blocks, after a reset (`None`): every sample kept at exactly `±r` from the
/// mean and every one rejected one LSB farther, every sample rejected (two clusters: the plain
/// mean), full scale positive and negative, and one gross error at full scale.
fn directed(plan: &Plan) -> Vec<Option<i64>> {
    let window = plan.window as usize;
    let r = plan.threshold_code as i64;
    let (min, max) = (plan.input.min_code() as i64, plan.input.max_code() as i64);
    let alternating = |offset: i64| -> Vec<Option<i64>> {
        (0..window)
            .map(|i| {
                let sign = if i.is_multiple_of(2) { 1 } else { -1 };
                // An odd window's last sample sits on the mean.
                let value = if !window.is_multiple_of(2) && i == window - 1 {
                    0
                } else {
                    sign * offset
                };
                Some(value.clamp(min, max))
            })
            .collect()
    };
    let mut samples = vec![None];
    samples.extend(alternating(r));
    samples.extend(alternating(r + 1));
    samples.extend(alternating(3 * r + 2));
    samples.extend(vec![Some(max); window]);
    samples.extend(vec![Some(min); window]);
    let mut spike = vec![Some(0); window];
    spike[window / 2] = Some(max);
    samples.extend(spike);
    samples
}

/// The DPI-C testbench's parts ([`DpiParts`]): each mean and its kept count against the model as a
/// stream.
const DPI: DpiParts = DpiParts {
    imports: include_str!("dpi_imports.svh"),
    handles: "filter = gyrofx_mean_filter_new(plan);",
    step: dpi_step,
    stream: Some(DpiStream {
        valid: "y_valid",
        value: "y",
        second: Some("kept"),
    }),
    samples: 4000,
};

/// One sample of the DPI-C testbench's stimulus loop.
fn dpi_step(block: &Block) -> String {
    let mut step = include_str!("dpi_step.sv").trim_end().to_string();
    if block.settle_clocks() > 0 {
        // The sequential filter: the next sample once a block's mean is out.
        step.push_str(&format!(
            "\n            @(negedge clk);\n            ce = 1'b0;\n            repeat ({}) @(posedge clk);",
            block.settle_clocks()
        ));
    }
    step
}
