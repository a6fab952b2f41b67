//! `system` — `gyrofx_system`, the whole gyro at the ADC rate: gyro A's and B's loops
//! (`gyrofx_gyro_loop`) feeding the mode-reversal chain (`gyrofx_top`), whose sequencer
//! commands the loops' modes (`gyrofx_model::system`, `docs/blocks/system.md`).
//!
//! It is in the package when the resonator plant feeds the chain (the loops' output format is
//! then the chain's input format). Its vectors replay the system closed around both simulated
//! resonators from reset: [`STARTUP_S`] with `enable` low (both loops lock in normal mode, the
//! chain holds), then two estimator windows with `enable` high. A window of the configured
//! schedule is 4 × 150 chain samples of 1000 ADC samples each, far too long for a testbench,
//! so the system's chain runs a short schedule ([`gyrofx_job::system::schedule`]: L = [`INTERVAL_LENGTH`],
//! M = [`BLANK`], the configured W, pattern and stagger direction) with its own estimator
//! plan and gain ROM; the KF is the configured one. The vectors prove the wiring bit for bit
//! — each chain period taken in the mode the sequencer describes, the loops' rates into the
//! estimator, the KF on their calibrated combination — not the estimates' accuracy, which
//! the blanking of so short an interval cannot give (the `top` and `gyro_loop` vectors and
//! the report cover that).
//!
//! With `architecture = "serial"` the block is `gyrofx_system_serial`: both loops folded
//! (`gyrofx_gyro_loop_serial`, one schedule ROM), the chain time-multiplexed
//! (`gyrofx_top_serial`, the system chain's program and coefficient ROMs). Its vectors are the
//! same run with the chain's outputs (`out_valid`, `rate_out`, `bias_a`, `bias_b`, `estimated`)
//! [`gyrofx_job::pipeline::system_chain_delay`] lines later, as its port-level model
//! ([`gyrofx_job::golden::System::of`]) has them.

use gyrofx_model::chain;
use gyrofx_model::gyro_loop::gyro::Plan as LoopPlan;
use gyrofx_model::resonator::Mode;
use gyrofx_model::system::{record, GyroPhysics, RecordedSample};
use serde_json::json;

use super::{flag, gyro_loop, kf, top, Placement, RomImages, RtlBlock};
use crate::block::{Block, Output, Param, Signal};
use crate::rom::Rom;
use crate::vectors::{BlockResults, ChainSample, Run, VectorBuilder};
use gyrofx_job::config::GyroLoop as LoopConfig;
use gyrofx_job::error::{Error, Result};
use gyrofx_job::job::Job;
use gyrofx_job::pipeline;

use crate::block::{DpiParts, DpiStream};
use crate::text::fill;
use gyrofx_job::system::{BLANK, INTERVAL_LENGTH};

/// The system block.
pub struct System;

/// Name of the system chain's estimator gain ROM (its schedule's, not the configured one's).
pub const GAINS_ROM: &str = "system_estimator_gains";
/// Name of the system chain's program ROM for `gyrofx_system_serial`.
pub const SERIAL_PROGRAM_ROM: &str = "system_serial_program";
/// Name of the system chain's coefficient ROM for `gyrofx_system_serial`.
pub const SERIAL_COEFFICIENT_ROM: &str = "system_serial_coefficients";

/// The module with `architecture = "serial"`.
pub const SERIAL_MODULE: &str = "gyrofx_system_serial";
/// Name of the folded pair's schedule ROM (`gyrofx_gyro_pair_serial` inside
/// `gyrofx_system_serial`).
pub const PAIR_SCHEDULE_ROM: &str = "gyro_pair_schedule";

/// Estimator windows after the start-up.
pub const WINDOWS: usize = 2;
/// Seconds of start-up with `enable` low, rounded up to whole chain periods (the loops lock in
/// about 80 ms).
pub const STARTUP_S: f64 = 0.1;

/// Key of what the recorded run covered ([`SystemSummary`]) among the block's manifest facts.
const RECORDED: &str = "recorded";
/// Input rate of the recorded run, °/s.
pub const RATE_DPS: f64 = 10.0;

/// Whether loop parameter `name` differs between the gyros (each loop gets its own, `A_` or
/// `B_` prefixed): the per-mode values and everything designed from the gyro's physics.
fn per_gyro(name: &str) -> bool {
    name.ends_with("_N")
        || name.ends_with("_R")
        || name.starts_with("PLL_K")
        || name.starts_with("AGC_K")
        || name.starts_with("COEF_")
        || matches!(
            name,
            "PLL_INT_MIN" | "PLL_INT_MAX" | "AGC_INT_MIN" | "AGC_INT_MAX"
        )
}

/// The loops' parameters as `gyrofx_system` takes them: the shared ones once (the loop's
/// `ROUNDING`, `SATURATE` and `LATENCY` as `LOOP_*`; its output format is the chain's `IN_*`),
/// then gyro A's own, then gyro B's. Both loops read the ROM images `sine_file` and
/// `taps_file` (gyro A's).
///
/// # Errors
/// [`Error::Config`] when a parameter the RTL shares (a format, the CIC, the lock detector)
/// or a ROM image differs between the two gyros' loop designs.
pub fn loop_params(loops: [&LoopPlan; 2], sine_file: &str, taps_file: &str) -> Result<Vec<Param>> {
    let [a, b] = loops.map(|plan| gyro_loop::parameters(plan, sine_file, taps_file));
    let differs = |what: String, a: String, b: String| {
        Error::Config {
        field: "resonator_b (system block)".into(),
        value: format!("{what} = {b} for gyro B, {a} for gyro A"),
        allowed: "gyrofx_system gives both loops one value of it: resonators whose loop designs share it (the [loop] section sets it for both)".into(),
    }
    };
    let codes = |plan: &LoopPlan| {
        [
            Rom::gyro_loop_sine(&plan.nco).codes,
            Rom::gyro_loop_cic(&plan.cic).codes,
        ]
    };
    let [rom_a, rom_b] = loops.map(codes);
    for ((name, a), b) in ["NCO_ROM_FILE", "CIC_ROM_FILE"]
        .iter()
        .zip(&rom_a)
        .zip(&rom_b)
    {
        if a != b {
            return Err(differs(
                format!("the ROM image of {name}"),
                "one image".into(),
                "another".into(),
            ));
        }
    }
    let mut shared = Vec::new();
    let mut own = [Vec::new(), Vec::new()];
    for (pa, pb) in a.into_iter().zip(b) {
        if per_gyro(&pa.name) {
            for (g, mut p) in [pa, pb].into_iter().enumerate() {
                p.name = format!("{}_{}", ["A", "B"][g], p.name);
                own[g].push(p);
            }
            continue;
        }
        if pa.value != pb.value {
            return Err(differs(pa.name.clone(), pa.value, pb.value));
        }
        match pa.name.as_str() {
            "OUT_W" | "OUT_F" => {}
            "ROUNDING" | "SATURATE" | "LATENCY" => {
                let mut p = pa;
                p.name = format!("LOOP_{}", p.name);
                shared.push(p);
            }
            _ => shared.push(pa),
        }
    }
    shared.extend(own.into_iter().flatten());
    Ok(shared)
}

/// `gyrofx_gyro_pair_serial`'s schedule parameters for `schedule` (a pair's), its image
/// `schedule_file`.
pub fn pair_schedule_params(
    schedule: &gyrofx_model::gyro_loop::folded::Schedule,
    schedule_file: &str,
) -> [Param; 5] {
    [
        Param::string(
            "SCHEDULE_FILE",
            schedule_file,
            "the folded pair's schedule ROM image (control words)",
        ),
        Param::integer(
            "SCHEDULE_LEN",
            schedule.len() as i64,
            "control words of the longest sample",
        ),
        Param::integer(
            "SCHEDULE_REGULAR",
            schedule.regular as i64,
            "control words of every sample (both gyros' regular parts)",
        ),
        Param::integer(
            "SCHEDULE_SEGMENTS",
            schedule.deferred.len() as i64,
            "deferred segments: samples from a decimating one to its rates",
        ),
        Param::integer(
            "RAM_WORDS",
            schedule.ram_words() as i64,
            "RAM words: both loops' states",
        ),
    ]
}

/// Refuses loops whose folded schedules differ: `gyrofx_system_serial` gives both one
/// schedule ROM (`SCHEDULE_FILE`), gyro A's.
///
/// # Errors
/// [`Error::Config`] on `resonator_b` naming `SCHEDULE_FILE`.
pub fn check_schedules(loops: [&LoopPlan; 2]) -> Result<()> {
    let [a, b] = loops.map(|plan| {
        gyrofx_model::gyro_loop::folded::Schedule::new(plan)
            .map(|s| Rom::gyro_loop_schedule(&s).codes)
            .map_err(|e| e.to_string())
    });
    if a == b {
        return Ok(());
    }
    Err(Error::Config {
        field: "resonator_b (system block, architecture = \"serial\")".into(),
        value: "the folded loop's schedule (SCHEDULE_FILE) of gyro B differs from gyro A's".into(),
        allowed: "gyrofx_system_serial gives both folded loops one schedule ROM: resonators whose loop designs share their formats (the [loop] section sets them for both)".into(),
    })
}

impl RtlBlock for System {
    fn check(&self, job: &Job) -> Result<()> {
        // gyrofx_system gives both loops one value of every shared parameter: refuse
        // resonators whose loop designs differ in one (ROM file names do not matter).
        let loops = [&job.gyro_loops[0].plan, &job.gyro_loops[1].plan];
        loop_params(loops, "", "")?;
        // gyrofx_system_serial gives them one schedule too, and its chain must finish a
        // sample before the next.
        if job.loop_schedule.is_some() {
            check_schedules(loops)?;
        }
        pipeline::check_system(job)
    }

    fn name(&self) -> &'static str {
        "system"
    }

    fn module(&self) -> &'static str {
        "gyrofx_system"
    }

    fn title(&self) -> &'static str {
        "the whole gyro: both loops feeding the chain, which commands their modes"
    }

    fn in_package(&self, job: &Job) -> bool {
        job.system_chain.is_some()
    }

    /// Two loops and the chain: the parallel system is larger than the one parallel loop,
    /// which already fits no target, so only `gyrofx_system_serial` is placed, as
    /// `system_serial`.
    fn placement(&self) -> Placement {
        Placement::SerialOnly("system_serial")
    }

    fn roms(&self, job: &Job) -> Vec<Rom> {
        if let Some(program) = &job.system_serial {
            let mut code = Rom::serial_program(program);
            let mut limbs = Rom::serial_coefficients(program);
            for (rom, name) in [
                (&mut code, SERIAL_PROGRAM_ROM),
                (&mut limbs, SERIAL_COEFFICIENT_ROM),
            ] {
                rom.name = name.into();
                rom.description = format!(
                    "{} (the system vectors' chain, L = {INTERVAL_LENGTH}, M = {BLANK})",
                    rom.description
                );
            }
            let mut roms = vec![code, limbs];
            roms.extend(job.pair_schedule.as_ref().map(Rom::gyro_pair_schedule));
            return roms;
        }
        match &job.system_chain {
            Some(plan) => {
                let mut rom = Rom::estimator(&plan.estimator);
                rom.name = GAINS_ROM.into();
                rom.description = format!(
                    "{} (the system vectors' schedule, L = {INTERVAL_LENGTH}, M = {BLANK})",
                    rom.description
                );
                vec![rom]
            }
            None => Vec::new(),
        }
    }

    fn block(&self, job: &Job, roms: &RomImages) -> Block {
        let plan = job
            .system_chain
            .as_ref()
            .expect("the system block is in resonator packages only");
        let est = &plan.estimator;
        let kf = &plan.kf;
        let adc = job.gyro_loops[0].plan.adc;
        let dac = job.gyro_loops[0].plan.dac.to;
        let mut block = Block::new(
            self.name(),
            self.module(),
            self.title(),
            vec![
                Signal::flag("enable"),
                Signal::index("bw_sel", kf.select_width()),
                Signal::new("adc_a_x", adc).with_unit("fs"),
                Signal::new("adc_a_y", adc).with_unit("fs"),
                Signal::new("adc_b_x", adc).with_unit("fs"),
                Signal::new("adc_b_y", adc).with_unit("fs"),
            ],
            vec![
                Output::registered(Signal::new("dac_a_x", dac).with_unit("")),
                Output::registered(Signal::new("dac_a_y", dac).with_unit("")),
                Output::registered(Signal::new("dac_b_x", dac).with_unit("")),
                Output::registered(Signal::new("dac_b_y", dac).with_unit("")),
                Output::registered(Signal::flag("locked_a")),
                Output::registered(Signal::flag("locked_b")),
                Output::registered(Signal::flag("mode_a")),
                Output::registered(Signal::flag("mode_b")),
                Output::pulse(Signal::flag("out_valid")),
                Output::gated(Signal::new("rate_out", kf.output), "out_valid"),
                Output::registered(Signal::new("bias_a", est.bias)),
                Output::registered(Signal::new("bias_b", est.bias)),
                Output::registered(Signal::flag("estimated")),
            ],
        );
        block.dpi = Some(DPI);
        block.cocotb_test = Some(include_str!("cocotb_test.py"));
        block.pipeline = pipeline::system(job);
        block.extra = vec!["loop_rate_a_dps", "loop_rate_b_dps"];
        if let (Some(program), Some(schedule)) = (&job.system_serial, &job.pair_schedule) {
            let code = roms.entry(SERIAL_PROGRAM_ROM);
            let limbs = roms.entry(SERIAL_COEFFICIENT_ROM);
            block.module = SERIAL_MODULE;
            block.title = "the whole gyro, folded: both folded loops feeding the serial chain, which commands their modes";
            block.params = top::serial_params(plan, program, &code.0, &limbs.0);
            // The loops' output fraction bits beside the chain's input width.
            let at = block
                .params
                .iter()
                .position(|p| p.name == "IN_W")
                .expect("the serial chain has IN_W")
                + 1;
            block.params.insert(
                at,
                Param::integer(
                    "IN_F",
                    plan.estimator.input.frac.into(),
                    "the loops' rate output: fraction bits",
                ),
            );
            let sine = roms.entry(gyro_loop::SINE_ROM);
            let taps = roms.entry(gyro_loop::TAPS_ROM);
            let rom = roms.entry(PAIR_SCHEDULE_ROM);
            block.params.extend(
                loop_params(
                    [&job.gyro_loops[0].plan, &job.gyro_loops[1].plan],
                    &sine.0,
                    &taps.0,
                )
                .expect("checked_job checked that the loops share what the RTL shares"),
            );
            block.params.extend(pair_schedule_params(schedule, &rom.0));
            block.params.push(Param::integer(
                "CHAIN_DELAY_SAMPLES",
                pipeline::system_chain_delay(job).into(),
                "ADC samples from the chain's take to its outputs",
            ));
            // The serial engine inside reads the serial chain's images under its defaults'
            // names; the system carries its own chain's.
            block.elaboration_images = vec![
                ("serial_program.mem".into(), code.1.clone()),
                ("serial_coefficients.mem".into(), limbs.1.clone()),
            ];
            block.roms.extend([code, limbs, sine, taps, rom]);
            return block;
        }
        let gains = roms.entry(GAINS_ROM);
        let coefficients = roms.entry(kf::ROM);
        block.params = top::chain_params(plan, &gains.0, &coefficients.0);
        let sine = roms.entry(gyro_loop::SINE_ROM);
        let taps = roms.entry(gyro_loop::TAPS_ROM);
        block.params.extend(
            loop_params(
                [&job.gyro_loops[0].plan, &job.gyro_loops[1].plan],
                &sine.0,
                &taps.0,
            )
            .expect("checked_job checked that the loops share what the RTL shares"),
        );
        block.roms.push(gains);
        block.roms.push(coefficients);
        block.roms.push(sine);
        block.roms.push(taps);
        block
    }

    fn vectors<'a>(&self, job: &'a Job, block: Block) -> Option<Box<dyn VectorBuilder + 'a>> {
        Some(Box::new(Vectors {
            job,
            plan: job.system_chain.as_ref()?,
            block,
        }))
    }

    fn manifest(
        &self,
        job: &Job,
        _roms: &RomImages,
        run: &Run,
    ) -> Option<(&'static str, serde_json::Value)> {
        let plan = job.system_chain.as_ref()?;
        let schedule = &plan.estimator.schedule;
        let lp = &job.gyro_loops[0].plan;
        let timing = pipeline::system(job);
        Some((
            "system",
            json!({
                "adc_rate_hz": lp.adc_rate_hz,
                "decimation": lp.cic.decimation,
                "architecture": if job.system_serial.is_some() { "serial" } else { "parallel" },
                "module": if job.system_serial.is_some() { SERIAL_MODULE } else { self.module() },
                "latency_clocks": timing.latency_clocks,
                "min_clocks_per_sample": timing.min_clocks_per_sample,
                "chain_delay_samples": pipeline::system_chain_delay(job),
                "serial_chain": job.system_serial.as_ref().map(|program| json!({
                    "instructions": program.sample.len(),
                    "latency_clocks": program.settle_clocks() + 1,
                    "ram_words": program.ram_words,
                    "coefficient_words": program.coefficients.len(),
                })),
                "folded_loops": job.pair_schedule.as_ref().map(|pair| json!({
                    "module": "gyrofx_gyro_pair_serial",
                    "regular_words": pair.regular,
                    "longest_sample_words": pair.len(),
                    "deferred_segments": pair.deferred.len(),
                    "ram_words": pair.ram_words(),
                })),
                "schedule": {
                    "interval_length": schedule.interval_length,
                    "intervals": schedule.intervals,
                    "pattern": schedule.pattern.name(),
                    "blank": schedule.blank,
                    "stagger": schedule.stagger,
                },
                "stimulus": format!(
                    "gyro A's and B's loops closed around their resonators from reset at {RATE_DPS} °/s: enable low for {STARTUP_S} s (rounded up to whole chain periods; both lock in normal mode), then high for {WINDOWS} windows of the schedule above; bw_sel 0 in the first window, then the next ROM entry"
                ),
                "recorded": run.fact(self.name(), RECORDED),
            }),
        ))
    }
}

/// Builds the vectors from the recorded run at the end; the chain's samples are not used.
struct Vectors<'a> {
    job: &'a Job,
    plan: &'a chain::Plan,
    block: Block,
}

/// What the recorded system run covered, as `run`'s system builder reported it (resonator
/// packages only).
pub fn recorded(run: &Run) -> Option<SystemSummary> {
    let fact = run.fact(System.name(), RECORDED)?;
    Some(serde_json::from_value(fact.clone()).expect("the builder's own summary"))
}

/// What the recorded system run covered (the manifest's `system.recorded`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub struct SystemSummary {
    /// ADC samples.
    pub samples: usize,
    /// ADC samples with `enable` low.
    pub startup_samples: usize,
    /// Chain samples (the chain's steps).
    pub chain_samples: usize,
    /// The first ADC sample after which both loops were locked.
    pub first_lock_sample: Option<usize>,
    /// The first ADC sample with an estimate.
    pub first_estimate_sample: Option<usize>,
    /// KF outputs.
    pub outputs: usize,
    /// Mode switches of gyro A and of gyro B.
    pub switches: [usize; 2],
}

fn mode_flag(mode: Mode) -> i128 {
    flag(mode == Mode::Normal)
}

impl VectorBuilder for Vectors<'_> {
    fn reset(&mut self) {}

    fn sample(&mut self, _sample: &ChainSample) {}

    fn finish(mut self: Box<Self>, results: &mut BlockResults) -> Block {
        let loops: [&LoopConfig; 2] = [&self.job.gyro_loops[0], &self.job.gyro_loops[1]];
        let schedule = &self.plan.estimator.schedule;
        let decimation = loops[0].plan.cic.decimation as usize;
        let chain_rate_hz = loops[0].plan.chain_rate_hz();
        let startup = (STARTUP_S * chain_rate_hz).ceil() as usize * decimation;
        let window = schedule.cycle_length() * decimation;
        let samples = startup + WINDOWS * window;
        let entries = self.plan.kf.gains.len();
        let seed = self.job.config.seed;
        let physics = [0, 1].map(|g| GyroPhysics {
            params: &loops[g].params,
            front_end: &loops[g].front_end,
            seed: seed.wrapping_mul(2).wrapping_add(g as u64),
        });
        self.block.reserve(samples);
        let mut summary = SystemSummary {
            samples,
            startup_samples: startup,
            ..SystemSummary::default()
        };
        let nan = f64::NAN;
        let output_lsb = loops[0].plan.output.to.lsb();
        let mut previous_modes = [Mode::Normal; 2];
        let mut last_rate = 0i128;
        let mut k = 0usize;
        // gyrofx_system_serial's chain outputs come this many lines later (reset values first).
        let delay = pipeline::system_chain_delay(self.job) as usize;
        let mut delayed: std::collections::VecDeque<[i128; 5]> =
            std::iter::repeat_n([0; 5], delay).collect();
        let block = &mut self.block;
        // bw_sel: 0 in the first window, the next entry after it (the chain's ROM switch).
        let bw_sel_of = |k: usize| usize::from(k >= startup + window).min(entries - 1);
        record(
            [&loops[0].plan, &loops[1].plan],
            self.plan,
            physics,
            RATE_DPS,
            samples,
            startup,
            bw_sel_of,
            |s: &RecordedSample| {
                let step = &s.step;
                let mut loop_rates = [nan; 2];
                for g in 0..2 {
                    if step.modes[g] != previous_modes[g] {
                        summary.switches[g] += 1;
                        previous_modes[g] = step.modes[g];
                    }
                    loop_rates[g] = step.rates.map_or(nan, |r| r[g] as f64 * output_lsb);
                }
                if summary.first_lock_sample.is_none() && step.locked == [true; 2] {
                    summary.first_lock_sample = Some(k);
                }
                let chain = step.chain;
                if chain.is_some() {
                    summary.chain_samples += 1;
                }
                if let Some(code) = chain.and_then(|c| c.rate) {
                    last_rate = code.into();
                    summary.outputs += 1;
                }
                if s.estimated && summary.first_estimate_sample.is_none() {
                    summary.first_estimate_sample = Some(k);
                }
                delayed.push_back([
                    flag(chain.is_some_and(|c| c.rate.is_some())),
                    last_rate,
                    s.bias[0],
                    s.bias[1],
                    flag(s.estimated),
                ]);
                let [out_valid, rate_out, bias_a, bias_b, estimated] =
                    delayed.pop_front().expect("one in, one out");
                block.push_with_extra(
                    false,
                    &[
                        flag(s.enable),
                        bw_sel_of(k) as i128,
                        s.adc[0][0].into(),
                        s.adc[0][1].into(),
                        s.adc[1][0].into(),
                        s.adc[1][1].into(),
                    ],
                    &[
                        step.dac[0][0].into(),
                        step.dac[0][1].into(),
                        step.dac[1][0].into(),
                        step.dac[1][1].into(),
                        flag(step.locked[0]),
                        flag(step.locked[1]),
                        mode_flag(s.upcoming[0]),
                        mode_flag(s.upcoming[1]),
                        out_valid,
                        rate_out,
                        bias_a,
                        bias_b,
                        estimated,
                    ],
                    &loop_rates,
                );
                k += 1;
            },
        )
        .expect("the config check validated the physics");
        results.facts.push((RECORDED, json!(summary)));
        self.block
    }
}

/// The DPI-C testbench's parts ([`DpiParts`]): enable from sample 500, every output after the
/// latency, the rate as a stream; 14 000 samples let the chain finish an estimator window.
const DPI: DpiParts = DpiParts {
    imports: include_str!("dpi_imports.svh"),
    handles: "system = gyrofx_system_new(plan);",
    step: dpi_step,
    stream: Some(DpiStream {
        valid: "out_valid",
        value: "rate_out",
        second: None,
    }),
    samples: 14_000,
};

/// One sample of the DPI-C testbench's stimulus loop.
fn dpi_step(block: &Block) -> String {
    fill(
        include_str!("dpi_step.sv").trim_end(),
        &[("settle", &block.settle_clocks().to_string())],
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use gyrofx_job::config::{preset, Config, PRESETS};

    fn resonator_jobs() -> Vec<(String, Job)> {
        let mut jobs = vec![("default".to_string(), Job::new(Config::embedded()).unwrap())];
        for (name, _) in PRESETS {
            let config = Config::from_toml(preset(name).unwrap(), name).unwrap();
            let job = Job::new(config).unwrap();
            if job.system_chain.is_some() {
                jobs.push((name.to_string(), job));
            }
        }
        jobs
    }

    #[test]
    fn both_gyros_get_the_same_parameter_names_and_the_shared_ones_once() {
        for (name, job) in resonator_jobs() {
            let loops = [&job.gyro_loops[0].plan, &job.gyro_loops[1].plan];
            let params = loop_params(loops, "s.mem", "t.mem").unwrap();
            let names: Vec<&str> = params.iter().map(|p| p.name.as_str()).collect();
            let own = |prefix: &str| -> Vec<&str> {
                names
                    .iter()
                    .filter_map(|n| n.strip_prefix(prefix))
                    .collect()
            };
            assert!(!own("A_").is_empty(), "{name}");
            assert_eq!(own("A_"), own("B_"), "{name}");
            let mut unique = names.clone();
            unique.sort_unstable();
            unique.dedup();
            assert_eq!(unique.len(), names.len(), "{name}: a name twice");
            // The loop's output format is the chain's input: not a parameter of its own.
            assert!(
                !names.contains(&"OUT_W") && names.contains(&"LOOP_ROUNDING"),
                "{name}"
            );
            // Every per-gyro name is one the loop RTL has.
            let whole = gyro_loop::parameters(loops[0], "s.mem", "t.mem");
            for n in own("A_") {
                assert!(whole.iter().any(|p| p.name == n), "{name}: {n}");
            }
        }
    }

    #[test]
    fn loops_that_differ_in_a_shared_parameter_are_refused_naming_it() {
        let job = Job::new(Config::embedded()).unwrap();
        let a = job.gyro_loops[0].plan.clone();
        let mut b = job.gyro_loops[1].plan.clone();
        b.lock.shift += 1;
        let error = loop_params([&a, &b], "s.mem", "t.mem")
            .unwrap_err()
            .to_string();
        assert!(
            error.contains("LOCK_SHIFT") && error.contains("resonator_b"),
            "{error}"
        );
        let mut b = job.gyro_loops[1].plan.clone();
        b.cic.taps[0].code += 1;
        let error = loop_params([&a, &b], "s.mem", "t.mem")
            .unwrap_err()
            .to_string();
        assert!(error.contains("CIC_ROM_FILE"), "{error}");
    }

    /// The serial system's check refuses a chain that cannot finish between chain samples,
    /// naming the fields; the parallel system has no such bound.
    #[test]
    fn a_serial_chain_slower_than_the_chain_samples_is_refused_by_the_blocks_check() {
        let config = Config::from_toml("architecture = \"serial\"\n", "t").unwrap();
        let mut job = Job::new(config).unwrap();
        assert!(System.check(&job).is_ok());
        let fewer = pipeline::system_chain_delay(&job) - 1;
        for gyro in &mut job.gyro_loops {
            gyro.plan.cic.decimation = fewer;
        }
        let error = System.check(&job).unwrap_err().to_string();
        assert!(error.contains("loop.decimation"), "{error}");
        let mut parallel = Job::new(Config::embedded()).unwrap();
        for gyro in &mut parallel.gyro_loops {
            gyro.plan.cic.decimation = 1;
        }
        assert!(System.check(&parallel).is_ok());
    }

    /// `gyrofx_system_serial` gives both folded loops gyro A's schedule: loops whose schedules
    /// differ are refused, naming the parameter.
    #[test]
    fn loops_whose_folded_schedules_differ_are_refused_naming_the_rom() {
        let job = Job::new(Config::embedded()).unwrap();
        let a = job.gyro_loops[0].plan.clone();
        assert!(check_schedules([&a, &job.gyro_loops[1].plan]).is_ok());
        let mut b = a.clone();
        b.cic.taps.pop();
        let error = check_schedules([&a, &b]).unwrap_err().to_string();
        assert!(
            error.contains("SCHEDULE_FILE") && error.contains("resonator_b"),
            "{error}"
        );
    }
}
