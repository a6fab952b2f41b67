//! `top` — `gyrofx_top`, the whole mode-reversal chain: sequencer, bias estimator,
//! calibration and KF (SPEC §1, `docs/blocks/top.md`). Its vectors are the chain run itself,
//! with the float, ideal and true rates beside the fixed output in the CSV.

use gyrofx_model::chain::Plan;
use gyrofx_model::serial::Program;
use serde_json::json;

use super::{estimator, flag, kf, mode_bit, mode_params, sequencer};
use super::{Placement, RomImages, RtlBlock};
use crate::block::{Block, Output, Param, Signal};
use crate::block::{DpiParts, DpiStream};
use crate::rom::Rom;
use crate::stats::Accumulator;
use crate::text::fill;
use crate::vectors::{BlockResults, ChainSample, Run, VectorBuilder};
use gyrofx_job::job::Job;
use gyrofx_job::pipeline;

/// The top block.
pub struct Top;

/// `gyrofx_top`'s parameters for `plan`, its ROMs read from `gain_rom_file` and
/// `kf_rom_file`: the submodules' parameters, each once — the sequencer's schedule, the
/// estimator's formats (its W and interval width are the sequencer's) and the KF's (its input
/// is the calibrated output) — then the rounding and overflow.
pub fn chain_params(plan: &Plan, gain_rom_file: &str, kf_rom_file: &str) -> Vec<Param> {
    let est = &plan.estimator;
    let mut params = sequencer::params(&est.schedule);
    params.extend(
        estimator::params(est)
            .into_iter()
            .filter(|p| p.name != "INTERVALS" && p.name != "INTERVAL_W"),
    );
    params.push(Param::string(
        "GAIN_ROM_FILE",
        gain_rom_file,
        "estimator gain ROM",
    ));
    params.extend(
        kf::params(&plan.kf)
            .into_iter()
            .filter(|p| p.name != "IN_W" && p.name != "IN_F"),
    );
    params.push(Param::string(
        "KF_ROM_FILE",
        kf_rom_file,
        "KF coefficient ROM",
    ));
    params.extend(mode_params(est.rounding, est.overflow));
    params
}

/// `gyrofx_top_serial`'s parameters: the sequencer's, the port widths, the engine's memories
/// and widths from the compiled `program`, its ROM files, the rounding.
pub fn serial_params(
    plan: &Plan,
    program: &Program,
    program_file: &str,
    coefficient_file: &str,
) -> Vec<Param> {
    let est = &plan.estimator;
    let int = |name: &str, value: usize, comment: &str| Param::integer(name, value as i64, comment);
    let mut params = sequencer::params(&est.schedule);
    params.extend([
        int("IN_W", est.input.width as usize, "gyro sample width"),
        int("OUT_W", plan.kf.output.width as usize, "rate output width"),
        int("BIAS_W", est.bias.width as usize, "bias output width"),
        int("SEL_W", plan.kf.select_width() as usize, "bw_sel width"),
        int(
            "ROM_DEPTH",
            plan.kf.rom.len(),
            "KF gain words (bw_sel < ROM_DEPTH)",
        ),
        int(
            "ACC_W",
            program.accumulator_bits as usize,
            "column accumulator width",
        ),
        int(
            "ADDR_W",
            program.layout.address_bits as usize,
            "data RAM address width",
        ),
        int(
            "COEF_ADDR_W",
            program.layout.coefficient_bits as usize,
            "coefficient ROM address width",
        ),
        int("RAM_DEPTH", program.ram_words.max(1), "data RAM words"),
        int(
            "COEF_DEPTH",
            program.coefficients.len().max(1),
            "coefficient ROM words",
        ),
        int("PROGRAM_DEPTH", program.sample.len(), "program ROM words"),
        int(
            "RAM_INDEX_SHIFT",
            program.ram_index_shift as usize,
            "interval index stride (log2 words)",
        ),
        int(
            "COEF_INDEX_SHIFT",
            program.coefficient_index_shift as usize,
            "bw_sel stride (log2 words)",
        ),
        int(
            "ROUNDING",
            est.rounding.rtl_code() as usize,
            "0 floor, 1 ceil, 2 zero, 3 nearest, 4 round, 5 convergent",
        ),
    ]);
    params.push(Param::string("PROGRAM_FILE", program_file, "program ROM"));
    params.push(Param::string(
        "COEFFICIENT_FILE",
        coefficient_file,
        "coefficient ROM",
    ));
    params
}

/// ROM names of the serial engine.
pub const SERIAL_PROGRAM_ROM: &str = "serial_program";
/// The serial engine's coefficient ROM.
pub const SERIAL_COEFFICIENT_ROM: &str = "serial_coefficients";

impl RtlBlock for Top {
    fn name(&self) -> &'static str {
        "top"
    }

    fn module(&self) -> &'static str {
        "gyrofx_top"
    }

    /// `gyrofx_top_serial` is placed beside it, compiled from the job's chain whatever its
    /// `architecture` (with `architecture = "serial"`, `top` is the same design).
    fn placement(&self) -> Placement {
        Placement::WithSerial("top_serial")
    }

    fn roms(&self, job: &Job) -> Vec<Rom> {
        match &job.serial {
            Some(program) => vec![
                Rom::serial_program(program),
                Rom::serial_coefficients(program),
            ],
            None => Vec::new(),
        }
    }

    fn title(&self) -> &'static str {
        "the whole mode-reversal chain"
    }

    fn block(&self, job: &Job, roms: &RomImages) -> Block {
        let est = &job.chain.estimator;
        let kf = job.kf();
        let mut block = Block::new(
            self.name(),
            self.module(),
            self.title(),
            vec![
                Signal::index("bw_sel", kf.select_width()),
                Signal::new("y_a", est.input),
                Signal::new("y_b", est.input),
            ],
            vec![
                Output::combinational(Signal::flag("mode_a")),
                Output::combinational(Signal::flag("mode_b")),
                Output::pulse(Signal::flag("out_valid")),
                Output::gated(Signal::new("rate_out", kf.output), "out_valid"),
                Output::registered(Signal::new("bias_a", est.bias)),
                Output::registered(Signal::new("bias_b", est.bias)),
                Output::registered(Signal::flag("estimated")),
            ],
        );
        block.dpi = Some(DPI);
        block.cocotb_test = Some(include_str!("cocotb_test.py"));
        block.extra = vec!["float_rate_dps", "ideal_rate_dps", "true_rate_dps"];
        block.pipeline = pipeline::top(job);
        if let Some(program) = &job.serial {
            let code = roms.entry(SERIAL_PROGRAM_ROM);
            let limbs = roms.entry(SERIAL_COEFFICIENT_ROM);
            block.module = "gyrofx_top_serial";
            block.title = "the whole mode-reversal chain, time-multiplexed";
            block.params = serial_params(&job.chain, program, &code.0, &limbs.0);
            block.roms.push(code);
            block.roms.push(limbs);
            return block;
        }
        let gains = roms.entry(estimator::ROM);
        let coefficients = roms.entry(kf::ROM);
        block.params = chain_params(&job.chain, &gains.0, &coefficients.0);
        block.roms.push(gains);
        block.roms.push(coefficients);
        block
    }

    fn vectors<'a>(&self, job: &'a Job, mut block: Block) -> Option<Box<dyn VectorBuilder + 'a>> {
        let rows = job.config.samples + 2;
        block.reserve(rows);
        Some(Box::new(Vectors {
            plan: &job.chain,
            block,
            errors: Accumulator::default(),
            switches: 0,
            previous_sel: None,
        }))
    }

    fn manifest(
        &self,
        job: &Job,
        _roms: &RomImages,
        run: &Run,
    ) -> Option<(&'static str, serde_json::Value)> {
        let est = &job.chain.estimator;
        let architecture = if job.serial.is_some() {
            "serial"
        } else {
            "parallel"
        };
        let timing = pipeline::top(job);
        let mut chain = json!({
            "rounding": est.rounding.name(),
            "overflow": est.overflow.name(),
            "architecture": architecture,
            "latency_clocks": timing.latency_clocks,
            "min_clocks_per_sample": timing.min_clocks_per_sample,
            "fixed_vs_float": run.stats("chain"),
        });
        if let Some(program) = &job.serial {
            chain["serial"] = json!({
                "module": "gyrofx_top_serial",
                "instructions": program.sample.len(),
                "clocks_per_instruction": gyrofx_model::serial::isa::CLOCKS_PER_INSTRUCTION,
                "ram_words": program.ram_words,
                "state_words": program.state_words,
                "coefficient_words": program.coefficients.len(),
                "accumulator_bits": program.accumulator_bits,
                "program_word_bits": program.layout.word_bits(),
            });
        }
        Some(("chain", chain))
    }
}

/// The chain's inputs and outputs for every sample, the fixed-vs-float statistics of its
/// output, and the float, ideal and true rates for the CSV.
struct Vectors<'a> {
    plan: &'a Plan,
    block: Block,
    errors: Accumulator,
    /// Changes of `bw_sel` between KF steps (each may add to the error bound).
    switches: u64,
    previous_sel: Option<usize>,
}

impl VectorBuilder for Vectors<'_> {
    fn reset(&mut self) {
        self.block
            .push_with_extra(true, &[0, 0, 0], &[0; 7], &[f64::NAN; 3]);
    }

    fn sample(&mut self, sample: &ChainSample) {
        let fixed = sample.fixed;
        let s = &fixed.slot;
        self.block.push_with_extra(
            false,
            &[
                sample.bw_sel as i128,
                i128::from(sample.y[0]),
                i128::from(sample.y[1]),
            ],
            &[
                mode_bit(s.mode_a),
                mode_bit(s.mode_b),
                flag(fixed.rate.is_some()),
                fixed.rate.map(i128::from).unwrap_or(0),
                sample.bias_after[0],
                sample.bias_after[1],
                flag(sample.estimated),
            ],
            &[
                sample.float.rate.unwrap_or(f64::NAN),
                sample.ideal.rate.unwrap_or(f64::NAN),
                sample.true_rate_dps,
            ],
        );
        if let Some(code) = fixed.rate {
            if self.previous_sel.is_some_and(|p| p != sample.bw_sel) {
                self.switches += 1;
            }
            self.previous_sel = Some(sample.bw_sel);
            let output = self.plan.kf.output;
            self.errors.add(
                output.to_f64(i128::from(code)),
                sample.float.rate.unwrap_or(f64::NAN),
                sample.ideal.rate.unwrap_or(f64::NAN),
                output.lsb(),
            );
        }
    }

    fn finish(mut self: Box<Self>, results: &mut BlockResults) -> Block {
        let bound = self
            .plan
            .rate_error_bound_lsb(self.errors.count(), self.switches);
        results
            .stats
            .push(("chain", std::mem::take(&mut self.errors).finish(bound)));
        self.block
    }
}

/// The DPI-C testbench's parts ([`DpiParts`]): the modes before the edge, the rate as a stream, the
/// estimates after the latency.
const DPI: DpiParts = DpiParts {
    imports: include_str!("dpi_imports.svh"),
    handles: "chain = gyrofx_chain_new(plan);",
    step: dpi_step,
    stream: Some(DpiStream {
        valid: "out_valid",
        value: "rate_out",
        second: None,
    }),
    samples: 4000,
};

/// One sample of the DPI-C testbench's stimulus loop.
fn dpi_step(block: &Block) -> String {
    fill(
        include_str!("dpi_step.sv").trim_end(),
        &[("settle", &block.settle_clocks().to_string())],
    )
}
