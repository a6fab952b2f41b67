//! `gyro_loop` — `gyrofx_gyro_loop`, one gyro's digital drive/sense loop at the ADC rate
//! (SPEC §1.6, `docs/blocks/gyro_loop.md`): NCOs, demodulators, PLL, AGC, CICs, the DAC delay
//! line, the lock detector and the mode switch.
//!
//! Its vectors replay a closed-loop run of gyro A: the fixed model closed around the simulated
//! resonator from reset, [`NORMAL_S`] in normal mode (lock acquisition), then [`REVERSE_S`]
//! in reverse mode (the switch and the re-lock). The stimulus is the ADC codes the model saw
//! and the mode; the expected outputs are every DAC code, the lock flag and the decimated
//! rate and quadrature, so the RTL fed the recorded codes must reproduce the closed loop bit
//! for bit. The run is its own (the chain's samples are not used): it is the same for every
//! plant.

use gyrofx_model::fx::Format;
use gyrofx_model::gyro_loop::closed::{record, RecordedSample};
use gyrofx_model::gyro_loop::gyro::Plan;
use gyrofx_model::resonator::Mode;
use serde_json::json;

use super::{flag, mode_params, signed, RomImages, RtlBlock};
use crate::block::{Block, Output, Param, Signal};
use crate::block::{DpiParts, DpiStream};
use crate::rom::Rom;
use crate::vectors::{BlockResults, ChainSample, Run, VectorBuilder};
use gyrofx_job::config::GyroLoop as LoopConfig;
use gyrofx_job::job::Job;
use gyrofx_job::pipeline;

/// The gyro-loop block.
pub struct GyroLoop;

/// Name of the NCOs' sine ROM.
pub const SINE_ROM: &str = "gyro_loop_nco_sine";
/// Name of the CICs' compensator ROM.
pub const TAPS_ROM: &str = "gyro_loop_cic_taps";
/// Name of the folded loop's schedule ROM.
pub const SCHEDULE_ROM: &str = "gyro_loop_schedule";

/// The module with `architecture = "serial"`: the loop folded onto one multiplier, one
/// accumulator and one RAM (`hdl/gyrofx_gyro_loop_serial.v`, `gyrofx_model::gyro_loop::folded`).
pub const SERIAL_MODULE: &str = "gyrofx_gyro_loop_serial";

/// Seconds of normal mode from reset in the vectors (the loop locks in about 80 ms).
pub const NORMAL_S: f64 = 0.1;
/// Seconds of reverse mode after the switch (it re-locks in about 75 ms).
pub const REVERSE_S: f64 = 0.1;
/// Input rate of the recorded run, °/s.
pub const RATE_DPS: f64 = 10.0;

/// Key of what the recorded run covered ([`RecordSummary`]) among the block's manifest facts.
const RECORDED: &str = "recorded";

/// Sub-block parameters under the top's prefix, except the rounding and overflow (the top's)
/// and the PIs' codes ([`pi_codes`]).
fn prefixed(prefix: &str, parameters: Vec<(&'static str, i128)>, what: &str) -> Vec<Param> {
    parameters
        .into_iter()
        .filter(|(name, _)| {
            !matches!(
                *name,
                "ROUNDING" | "SATURATE" | "KP" | "KI" | "INT_MIN" | "INT_MAX"
            )
        })
        .map(|(name, value)| {
            Param::integer(
                &format!("{prefix}_{name}"),
                value as i64,
                format!("{what}: {name}"),
            )
        })
        .collect()
}

/// The PI's coefficient and limit codes as bit vectors of their formats.
fn pi_codes(prefix: &str, plan: &gyrofx_model::gyro_loop::pi::Plan, what: &str) -> Vec<Param> {
    vec![
        signed(
            &format!("{prefix}_KP"),
            plan.kp.format.width,
            plan.kp.code,
            format!(
                "{what} kp = {:e} ({})",
                plan.kp.format.to_f64(plan.kp.code),
                plan.kp.format
            ),
        ),
        signed(
            &format!("{prefix}_KI"),
            plan.ki.format.width,
            plan.ki.code,
            format!(
                "{what} ki = {:e} ({})",
                plan.ki.format.to_f64(plan.ki.code),
                plan.ki.format
            ),
        ),
        signed(
            &format!("{prefix}_INT_MIN"),
            plan.integrator.width,
            plan.limits[0],
            format!("{what} integrator lower limit ({})", plan.integrator),
        ),
        signed(
            &format!("{prefix}_INT_MAX"),
            plan.integrator.width,
            plan.limits[1],
            format!("{what} integrator upper limit ({})", plan.integrator),
        ),
    ]
}

/// Every parameter of `hdl/gyrofx_gyro_loop.v` for `plan`, in the RTL's order.
pub fn parameters(plan: &Plan, sine_file: &str, taps_file: &str) -> Vec<Param> {
    let mut p = Vec::new();
    p.extend(prefixed("NCO", plan.nco.rtl_parameters(), "NCO"));
    p.extend(prefixed(
        "DEMOD",
        plan.demodulator.rtl_parameters(),
        "demodulators",
    ));
    for (prefix, pi, what) in [("PLL", &plan.pll, "PLL"), ("AGC", &plan.agc, "AGC")] {
        p.extend(prefixed(prefix, pi.rtl_parameters(), what));
        p.extend(pi_codes(prefix, pi, what));
    }
    p.extend(prefixed("CIC", plan.cic.rtl_parameters(), "CICs"));
    p.extend(Param::format("DAC", plan.dac.to, "DAC codes"));
    p.extend(Param::format(
        "OUT",
        plan.output.to,
        "rate and quadrature, °/s",
    ));
    let coefficient: Format = plan.modes[0].rate_coefficient.format;
    p.extend(Param::format("COEF", coefficient, "1/SF coefficients"));
    p.push(Param::integer(
        "LATENCY",
        plan.latency.into(),
        "ADC-to-DAC latency, samples",
    ));
    p.push(Param::integer(
        "LOCK_SHIFT",
        plan.lock.shift.into(),
        "lock filters' shift",
    ));
    p.push(Param::integer(
        "LOCK_HOLD",
        plan.lock.hold_samples.into(),
        "samples inside the limits before locked",
    ));
    let [normal, reverse] = &plan.modes;
    let demod = plan.demodulator.output.to;
    let phase = plan.nco.phase.width;
    let per_mode = |name: &str, f: &dyn Fn(&gyrofx_model::gyro_loop::gyro::ModePlan) -> Param| {
        [normal, reverse].map(|m| {
            let mut param = f(m);
            param.name = format!("{name}_{}", if m.mode == Mode::Normal { "N" } else { "R" });
            param
        })
    };
    p.extend(per_mode("SETPOINT", &|m| {
        signed(
            "",
            demod.width,
            m.setpoint_code.into(),
            format!("AGC setpoint {} ({demod})", m.setpoint),
        )
    }));
    p.extend(per_mode("FREQ_WORD", &|m| {
        Param::bits(
            "",
            phase,
            m.frequency_word.into(),
            format!("nominal NCO word, {} Hz", m.nominal_frequency_hz),
        )
    }));
    p.extend(per_mode("PLL_PRESET", &|m| {
        signed(
            "",
            plan.pll.integrator.width,
            m.pll_preset.into(),
            format!("PLL preset ({})", plan.pll.integrator),
        )
    }));
    p.extend(per_mode("DAC_OFFSET", &|m| {
        Param::bits(
            "",
            phase,
            m.dac_offset_word.into(),
            format!("DAC reference offset, {} cycles", m.dac_offset),
        )
    }));
    p.extend(per_mode("SENSE_OFFSET", &|m| {
        Param::bits(
            "",
            phase,
            m.sense_offset_word.into(),
            format!("sense reference offset, {} cycles", m.sense_offset),
        )
    }));
    p.extend(per_mode("RATE_COEF", &|m| {
        signed(
            "",
            coefficient.width,
            m.rate_coefficient.code,
            format!("1/SF of the rate, {:e}", m.rate_coefficient.value),
        )
    }));
    p.extend(per_mode("QUAD_COEF", &|m| {
        signed(
            "",
            coefficient.width,
            m.quadrature_coefficient.code,
            format!(
                "1/SF of the quadrature, {:e}",
                m.quadrature_coefficient.value
            ),
        )
    }));
    p.extend(per_mode("LOCK_Q", &|m| {
        signed(
            "",
            64,
            m.lock_limits[0].into(),
            "lock limit of the filtered phase error",
        )
    }));
    p.extend(per_mode("LOCK_A", &|m| {
        signed(
            "",
            64,
            m.lock_limits[1].into(),
            "lock limit of the filtered amplitude error",
        )
    }));
    p.extend(mode_params(plan.output.rounding, plan.output.overflow));
    p.push(Param::string("NCO_ROM_FILE", sine_file, "NCO sine ROM"));
    p.push(Param::string(
        "CIC_ROM_FILE",
        taps_file,
        "CIC compensator ROM",
    ));
    p
}

/// `gyrofx_gyro_loop_serial`'s parameters beyond `gyrofx_gyro_loop`'s: the schedule read from
/// `schedule_file`, its lengths and the RAM's words (`gyrofx_system_serial` takes them too).
pub fn schedule_params(
    schedule: &gyrofx_model::gyro_loop::folded::Schedule,
    schedule_file: &str,
) -> [Param; 4] {
    [
        Param::string(
            "SCHEDULE_FILE",
            schedule_file,
            "the schedule ROM image (control words)",
        ),
        Param::integer(
            "SCHEDULE_LEN",
            schedule.len() as i64,
            "control words: clocks of a decimating sample",
        ),
        Param::integer(
            "SCHEDULE_REGULAR",
            schedule.regular as i64,
            "clocks of every sample",
        ),
        Param::integer(
            "RAM_WORDS",
            schedule.words.count() as i64,
            "RAM words: the loop's states",
        ),
    ]
}

impl RtlBlock for GyroLoop {
    fn name(&self) -> &'static str {
        "gyro_loop"
    }

    fn module(&self) -> &'static str {
        "gyrofx_gyro_loop"
    }

    fn title(&self) -> &'static str {
        "one gyro's drive/sense loop: NCOs, demodulators, PLL, AGC, CICs, mode switch"
    }

    /// `gyrofx_gyro_loop_serial` is placed beside it.
    fn placement(&self) -> super::Placement {
        super::Placement::WithSerial("gyro_loop_serial")
    }

    fn roms(&self, job: &Job) -> Vec<Rom> {
        let plan = &job.gyro_loops[0].plan;
        let mut roms = vec![
            Rom::gyro_loop_sine(&plan.nco),
            Rom::gyro_loop_cic(&plan.cic),
        ];
        if let Some(schedule) = &job.loop_schedule {
            roms.push(Rom::gyro_loop_schedule(schedule));
        }
        roms
    }

    fn block(&self, job: &Job, roms: &RomImages) -> Block {
        let plan = &job.gyro_loops[0].plan;
        let mut block = Block::new(
            self.name(),
            self.module(),
            self.title(),
            vec![
                Signal::flag("mode"),
                Signal::new("adc_x", plan.adc).with_unit("fs"),
                Signal::new("adc_y", plan.adc).with_unit("fs"),
            ],
            vec![
                Output::registered(Signal::new("dac_x", plan.dac.to).with_unit("")),
                Output::registered(Signal::new("dac_y", plan.dac.to).with_unit("")),
                Output::registered(Signal::flag("locked")),
                Output::pulse(Signal::flag("out_valid")),
                Output::gated(Signal::new("rate", plan.output.to), "out_valid"),
                Output::gated(Signal::new("quadrature", plan.output.to), "out_valid"),
            ],
        );
        block.dpi = Some(DPI);
        block.cocotb_test = Some(include_str!("cocotb_test.py"));
        block.pipeline = pipeline::gyro_loop(job);
        block.params = parameters(plan, &roms.entry(SINE_ROM).0, &roms.entry(TAPS_ROM).0);
        block.roms.push(roms.entry(SINE_ROM));
        block.roms.push(roms.entry(TAPS_ROM));
        if job.loop_schedule.is_none() {
            // The parallel loop's NCO and CIC read their images under their defaults' names.
            block.elaboration_images = vec![
                ("nco_sine.mem".into(), roms.entry(SINE_ROM).1),
                ("cic_taps.mem".into(), roms.entry(TAPS_ROM).1),
            ];
        }
        if let Some(schedule) = &job.loop_schedule {
            block.module = SERIAL_MODULE;
            block.title = "one gyro's drive/sense loop, folded onto one multiplier, one accumulator and one RAM";
            let rom = roms.entry(SCHEDULE_ROM);
            block.params.extend(schedule_params(schedule, &rom.0));
            block.roms.push(rom);
        }
        block
    }

    fn vectors<'a>(&self, job: &'a Job, block: Block) -> Option<Box<dyn VectorBuilder + 'a>> {
        Some(Box::new(Vectors {
            gyro: &job.gyro_loops[0],
            seed: job.config.seed,
            block,
        }))
    }

    fn manifest(
        &self,
        job: &Job,
        _roms: &RomImages,
        run: &Run,
    ) -> Option<(&'static str, serde_json::Value)> {
        let plan = &job.gyro_loops[0].plan;
        Some((
            "gyro_loop",
            json!({
                "gyro": "a",
                "adc_rate_hz": plan.adc_rate_hz,
                "decimation": plan.cic.decimation,
                "latency_samples": plan.latency,
                "architecture": if job.loop_schedule.is_some() { "serial" } else { "parallel" },
                "latency_clocks": pipeline::gyro_loop(job).latency_clocks,
                "min_clocks_per_sample": pipeline::gyro_loop(job).min_clocks_per_sample,
                "schedule": job.loop_schedule.as_ref().map(|s| json!({
                    "clocks": s.len(),
                    "regular_clocks": s.regular,
                    "ram_words": s.words.count(),
                    "templates": s.placements.iter().map(|p| json!({
                        "name": p.name, "first": p.first, "last": p.last,
                    })).collect::<Vec<_>>(),
                })),
                "formats": {
                    "adc": plan.adc.to_string(),
                    "nco": plan.nco.output.to_string(),
                    "demodulator": plan.demodulator.output.to.to_string(),
                    "pll_integrator": plan.pll.integrator.to_string(),
                    "agc_output": plan.agc.output.to.to_string(),
                    "dac": plan.dac.to.to_string(),
                    "cic": plan.cic.output.to.to_string(),
                    "output": plan.output.to.to_string(),
                },
                "stimulus": format!(
                    "gyro A's fixed loop closed around its resonator from reset at {RATE_DPS} °/s: {NORMAL_S} s normal mode (lock), then {REVERSE_S} s reverse (switch and re-lock); the ADC codes it saw and the mode"
                ),
                "recorded": run.fact(self.name(), RECORDED),
            }),
        ))
    }
}

/// Builds the vectors from the recorded run at the end; the chain's samples are not used.
struct Vectors<'a> {
    gyro: &'a LoopConfig,
    seed: u64,
    block: Block,
}

impl VectorBuilder for Vectors<'_> {
    fn reset(&mut self) {}

    fn sample(&mut self, _sample: &ChainSample) {}

    fn finish(mut self: Box<Self>, results: &mut BlockResults) -> Block {
        let plan = &self.gyro.plan;
        let normal = (NORMAL_S * plan.adc_rate_hz).round() as usize;
        let total = normal + (REVERSE_S * plan.adc_rate_hz).round() as usize;
        let samples = record(
            plan,
            &self.gyro.params,
            &self.gyro.front_end,
            self.seed.wrapping_mul(2),
            RATE_DPS,
            total,
            normal,
        )
        .expect("the config check validated the physics");
        self.block.reserve(samples.len());
        let mut last = (0i128, 0i128);
        let mut summary = RecordSummary::default();
        for (k, s) in samples.iter().enumerate() {
            let RecordedSample {
                adc,
                mode,
                step,
                locked,
            } = *s;
            if let Some(c) = step.chain {
                last = (c.rate.into(), c.quadrature.into());
                summary.outputs += 1;
            }
            if locked && summary.first_lock_sample[usize::from(mode == Mode::Reverse)].is_none() {
                summary.first_lock_sample[usize::from(mode == Mode::Reverse)] = Some(k);
            }
            self.block.push(
                false,
                &[flag(mode == Mode::Normal), adc[0].into(), adc[1].into()],
                &[
                    step.dac[0].into(),
                    step.dac[1].into(),
                    flag(locked),
                    flag(step.chain.is_some()),
                    last.0,
                    last.1,
                ],
            );
        }
        summary.samples = samples.len();
        summary.switch_sample = normal;
        results.facts.push((RECORDED, json!(summary)));
        self.block
    }
}

/// What the recorded run covered, as `run`'s gyro-loop builder reported it.
pub fn recorded(run: &Run) -> Option<RecordSummary> {
    let fact = run.fact(GyroLoop.name(), RECORDED)?;
    Some(serde_json::from_value(fact.clone()).expect("the builder's own summary"))
}

/// What the recorded run covered (the manifest's `gyro_loop.recorded`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub struct RecordSummary {
    /// ADC samples.
    pub samples: usize,
    /// The first sample in reverse mode.
    pub switch_sample: usize,
    /// The first sample with `locked` high in normal, then reverse mode.
    pub first_lock_sample: [Option<usize>; 2],
    /// Decimated outputs.
    pub outputs: usize,
}

/// The DPI-C testbench's parts ([`DpiParts`]): a mode switch every 701 samples, the DACs and lock
/// after the latency, the rates as a stream; 12 000 samples give a dozen rates.
const DPI: DpiParts = DpiParts {
    imports: include_str!("dpi_imports.svh"),
    handles: "gyro_loop = gyrofx_gyro_loop_new(plan, 0);",
    step: dpi_step,
    stream: Some(DpiStream {
        valid: "out_valid",
        value: "rate",
        second: Some("quadrature"),
    }),
    samples: 12_000,
};

/// One sample of the DPI-C testbench's stimulus loop.
fn dpi_step(block: &Block) -> String {
    crate::text::fill(
        include_str!("dpi_step.sv").trim_end(),
        &[("settle", &block.settle_clocks().to_string())],
    )
}
