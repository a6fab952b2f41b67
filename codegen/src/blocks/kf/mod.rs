//! `kf` — `gyrofx_kf`, the steady-state Kalman filter of paper 000 with one coefficient set per
//! bandwidth (SPEC §1.4, `docs/blocks/kf.md`). Its vectors: the chain's KF inputs, then a
//! directed segment (rounding ties and full scale, each from reset).

use gyrofx_model::kf::bound::rate_error_bound_lsb;
use gyrofx_model::kf::{FixedKf, FloatKf, OverflowCounts, Plan};
use serde::Serialize;
use serde_json::json;

use super::{mode_params, RomImages, RtlBlock};
use crate::block::{Block, Output, Param, Signal};
use crate::block::{DpiParts, DpiStream};
use crate::report;
use crate::rom::{Rom, RomFormat, ROM_FOLDER};
use crate::stats::Accumulator;
use crate::text::fill;
use crate::vectors::{BlockResults, ChainSample, KfCounts, Run, VectorBuilder};
use gyrofx_job::job::Job;
use gyrofx_job::pipeline;

/// The KF block.
pub struct Kf;

/// Name of its coefficient ROM.
pub const ROM: &str = "kf_coefficients";

/// Samples of the full-scale segment at each polarity.
const FULL_SCALE_SAMPLES: usize = 64;

/// Key of the tie cases found ([`TieCases`]) among the block's manifest facts.
const TIE_CASES: &str = "tie_cases";
/// Largest |z| searched for a tie case.
const TIE_SEARCH_LIMIT: i64 = 1 << 16;

/// The tie cases `run`'s KF builder found.
pub fn tie_cases(run: &Run) -> Option<Vec<TieCases>> {
    let fact = run.fact(Kf.name(), TIE_CASES)?;
    Some(serde_json::from_value(fact.clone()).expect("the builder's own tie cases"))
}

/// Tie-case inputs found for one KF ROM entry.
#[derive(Clone, Debug, PartialEq, Serialize, serde::Deserialize)]
pub struct TieCases {
    /// ROM address.
    pub bw_sel: usize,
    /// Input that puts the `x1` update on a tie from reset, if one exists in range.
    pub x1: Option<i64>,
    /// Same for `x2`.
    pub x2: Option<i64>,
    /// Same for the output quantizer.
    pub rate_hat: Option<i64>,
}

/// The KF's parameters without the modes and the ROM file (the top shares them).
pub fn params(kf: &Plan) -> Vec<Param> {
    let mut params = Vec::new();
    params.extend(Param::format("IN", kf.input, "input z"));
    params.extend(Param::format("STATE", kf.state, "states x1, x2"));
    params.extend(Param::format("OUT", kf.output, "output rate_out"));
    params.extend(Param::format("G1", kf.coefficient[0], "coefficient g1"));
    params.extend(Param::format("G2", kf.coefficient[1], "coefficient g2"));
    params.push(Param::integer(
        "SEL_W",
        kf.select_width().into(),
        "bw_sel width",
    ));
    params.push(Param::integer(
        "ROM_DEPTH",
        kf.rom.len() as i64,
        "coefficient sets",
    ));
    params
}

impl RtlBlock for Kf {
    fn name(&self) -> &'static str {
        "kf"
    }

    fn module(&self) -> &'static str {
        "gyrofx_kf"
    }

    fn title(&self) -> &'static str {
        "steady-state Kalman filter"
    }

    fn roms(&self, job: &Job) -> Vec<Rom> {
        vec![Rom::kf(job.kf())]
    }

    fn block(&self, job: &Job, roms: &RomImages) -> Block {
        let kf = job.kf();
        let mut block = Block::new(
            self.name(),
            self.module(),
            self.title(),
            vec![
                Signal::index("bw_sel", kf.select_width()),
                Signal::new("z", kf.input),
            ],
            vec![
                Output::pulse(Signal::flag("out_valid")),
                Output::gated(Signal::new("rate_out", kf.output), "out_valid"),
            ],
        );
        block.dpi = Some(DPI);
        block.cocotb_test = Some(include_str!("cocotb_test.py"));
        block.pipeline = pipeline::KF;
        // The next sample's `e` needs only the new states, not the rounded output.
        block.params = params(kf);
        block.params.extend(mode_params(kf.rounding, kf.overflow));
        let rom = roms.entry(ROM);
        block
            .params
            .push(Param::string("ROM_FILE", &rom.0, "coefficient ROM"));
        block.roms.push(rom);
        block
    }

    fn vectors<'a>(&self, job: &'a Job, mut block: Block) -> Option<Box<dyn VectorBuilder + 'a>> {
        let kf = job.kf();
        block.reserve(job.config.samples + 1);
        Some(Box::new(Vectors {
            plan: kf,
            block,
            float: FloatKf::new(kf.quantized_gains()),
            ideal: FloatKf::new(kf.gains.clone()),
            errors: Accumulator::default(),
            switches: 0,
            previous_sel: None,
        }))
    }

    fn manifest(
        &self,
        job: &Job,
        roms: &RomImages,
        run: &Run,
    ) -> Option<(&'static str, serde_json::Value)> {
        let kf = job.kf();
        let rom = roms.get(ROM);
        Some((
            "kf",
            json!({
                "formats": {
                    "input": kf.input.to_string(),
                    "state": kf.state.to_string(),
                    "output": kf.output.to_string(),
                    "g1": kf.coefficient[0].to_string(),
                    "g2": kf.coefficient[1].to_string(),
                    "error": kf.error.to_string(),
                    "product_g1": kf.product[0].to_string(),
                    "product_g2": kf.product[1].to_string(),
                    "sum_x1": kf.sum[0].to_string(),
                    "sum_x2": kf.sum[1].to_string(),
                },
                "guard_bits": kf.guard_bits(),
                "latency_clocks": pipeline::KF.latency_clocks,
                "min_clocks_per_sample": pipeline::KF.min_clocks_per_sample,
                "designs": report::designs(&job.designs, kf),
                "coefficients": report::coefficients(kf),
                "rom": {"file": RomFormat::Mem.file_name(&rom.rom.name), "depth": kf.rom.len(), "word_bits": rom.rom.width(), "all_formats": ROM_FOLDER,
                        "packing": "word = {g1, g2}: g1 in the high bits; address = bw_sel"},
                "tie_cases": run.fact(self.name(), TIE_CASES),
                "fixed_vs_float": run.stats("kf"),
            }),
        ))
    }
}

/// The KF's inputs in the chain (the combined samples it steps on) with its float twins beside
/// it, then the directed segment.
struct Vectors<'a> {
    plan: &'a Plan,
    block: Block,
    float: FloatKf,
    ideal: FloatKf,
    errors: Accumulator,
    /// Changes of `bw_sel` between KF steps (each may add to the error bound).
    switches: u64,
    previous_sel: Option<usize>,
}

impl VectorBuilder for Vectors<'_> {
    fn reset(&mut self) {
        self.float.reset();
        self.ideal.reset();
        self.block.push(true, &[0, 0], &[0, 0]);
    }

    fn sample(&mut self, sample: &ChainSample) {
        let Some(code) = sample.fixed.rate else {
            return;
        };
        let bw_sel = sample.bw_sel;
        if self.previous_sel.is_some_and(|p| p != bw_sel) {
            self.switches += 1;
        }
        self.previous_sel = Some(bw_sel);
        // The KF block sees exactly the chain's KF inputs.
        let z = sample.fixed.estimator.combined;
        self.block.push(
            false,
            &[bw_sel as i128, i128::from(z)],
            &[1, i128::from(code)],
        );
        let z_real = self.plan.input.to_f64(i128::from(z));
        let float = self.float.step(z_real, bw_sel);
        let ideal = self.ideal.step(z_real, bw_sel);
        let fixed = self.plan.output.to_f64(i128::from(code));
        self.errors.add(fixed, float, ideal, self.plan.output.lsb());
    }

    fn finish(mut self: Box<Self>, results: &mut BlockResults) -> Block {
        let steps = self.errors.count();
        let bound = rate_error_bound_lsb(self.plan, steps, self.switches);
        let ties = find_ties(self.plan);
        let directed = directed_segment(self.plan, &ties, &mut self.block);
        let stats = std::mem::take(&mut self.errors).finish(bound);
        results.stats.push(("kf", stats));
        results
            .overflows
            .push(("kf_directed", json!(KfCounts::from(directed))));
        results.facts.push((TIE_CASES, json!(ties)));
        self.block
    }
}

/// For each ROM entry, an input that from reset lands each quantization point exactly on a
/// tie. From reset a state update is `Q(g·z·2^a)`, which is a tie only when `z`'s lowest set
/// bit sits at one particular position, so powers of two (both signs) are tried first; then
/// every |z| up to [`TIE_SEARCH_LIMIT`] (positive first) for what is still missing.
pub fn find_ties(plan: &Plan) -> Vec<TieCases> {
    let kf = FixedKf::new(plan);
    let max = plan.input.max_code() as i64;
    let limit = TIE_SEARCH_LIMIT.min(max);
    let powers = (0..plan.input.width - 1).map(|bit| 1i64 << bit);
    let candidates: Vec<i64> = powers
        .chain(1..=limit)
        .flat_map(|magnitude| [magnitude, -magnitude])
        .collect();
    (0..plan.rom.len())
        .map(|bw_sel| {
            let mut found: [Option<i64>; 3] = [None; 3];
            for z in &candidates {
                let ties = kf.ties(*z, bw_sel);
                for (slot, tie) in found.iter_mut().zip(ties) {
                    if tie && slot.is_none() {
                        *slot = Some(*z);
                    }
                }
                if found.iter().all(Option::is_some) {
                    break;
                }
            }
            TieCases {
                bw_sel,
                x1: found[0],
                x2: found[1],
                rate_hat: found[2],
            }
        })
        .collect()
}

/// Appends the directed rows to the KF block: per ROM entry a reset and each tie input, then a
/// reset and full-scale inputs at the widest bandwidth. Returns that segment's overflows.
fn directed_segment(plan: &Plan, ties: &[TieCases], block: &mut Block) -> OverflowCounts {
    let mut kf = FixedKf::new(plan);
    let mut push = |kf: &mut FixedKf, rst: bool, sel: usize, z: i64| {
        if rst {
            kf.reset();
            block.push(true, &[sel as i128, 0], &[0, 0]);
        } else {
            let rate = kf.step(z, sel);
            block.push(false, &[sel as i128, i128::from(z)], &[1, i128::from(rate)]);
        }
    };
    for tie in ties {
        for z in [tie.x1, tie.x2, tie.rate_hat].into_iter().flatten() {
            push(&mut kf, true, tie.bw_sel, 0);
            push(&mut kf, false, tie.bw_sel, z);
        }
    }
    let widest = plan.rom.len() - 1;
    let (max, min) = (plan.input.max_code() as i64, plan.input.min_code() as i64);
    push(&mut kf, true, widest, 0);
    for (z, count) in [
        (max, FULL_SCALE_SAMPLES),
        (min, FULL_SCALE_SAMPLES),
        (max, 8),
        (0, 16),
    ] {
        for _ in 0..count {
            push(&mut kf, false, widest, z);
        }
    }
    kf.overflow_counts()
}

/// The DPI-C testbench's parts ([`DpiParts`]): one sample every `pipeline::KF.min_clocks_per_sample` clocks, the rate
/// against the model as a stream.
const DPI: DpiParts = DpiParts {
    imports: include_str!("dpi_imports.svh"),
    handles: "kf = gyrofx_kf_new(plan);",
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
    let every = block.clocks_per_sample();
    fill(
        include_str!("dpi_step.sv").trim_end(),
        &[
            ("idle", &(every - 1).to_string()),
            ("every", &every.to_string()),
        ],
    )
}
