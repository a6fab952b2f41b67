//! The vector set: one run of the whole chain (plant, sequencer, estimator, KF) fills the
//! vectors of every block, and a directed segment (resets, rounding ties, full scale) is
//! appended to the KF's. The float golden chain runs beside it.
//!
//! Schedule of the run: `samples` samples of the configured stimulus, `bw_sel` cycling through
//! every ROM entry (each for `samples / (2·entries)` samples), and one reset of the whole chain
//! half-way. The gyros are simulated in the modes the sequencer asks for, resets included.

use gyrofx_model::analysis::allan::{self, Kind};
use gyrofx_model::chain::{FixedChain, FloatChain};
use gyrofx_model::estimator::OverflowCounts as EstimatorOverflows;
use gyrofx_model::kf::bound::rate_error_bound_lsb;
use gyrofx_model::kf::{FixedKf, FloatKf, OverflowCounts, Plan};
use gyrofx_model::mean_filter::{self, FixedMeanFilter, FloatMeanFilter};
use gyrofx_model::sequencer::Sequencer;
use gyrofx_model::stimulus::adc;
use serde::Serialize;

use crate::block::{Block, Output, Param, Signal};
use crate::error::Result;
use crate::job::Job;

/// Fixed-vs-float error of a signal, in LSB of its format.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct ErrorStats {
    /// Samples compared.
    pub samples: u64,
    /// Largest `|fixed − float|` (same quantized coefficients).
    pub max_lsb: f64,
    /// Rms of the same.
    pub rms_lsb: f64,
    /// The derived worst-case bound.
    pub bound_lsb: f64,
    /// Largest `|fixed − ideal|` (ideal: designed coefficients, f64).
    pub ideal_max_lsb: f64,
    /// Rms of the same.
    pub ideal_rms_lsb: f64,
    /// Signal-to-quantization-noise ratio against the ideal model, dB.
    pub sqnr_db: f64,
}

#[derive(Default)]
struct Accumulator {
    count: u64,
    max: f64,
    sum_sq: f64,
    ideal_max: f64,
    ideal_sq: f64,
    signal_sq: f64,
}

impl Accumulator {
    fn add(&mut self, fixed: f64, float: f64, ideal: f64, lsb: f64) {
        let err = (fixed - float) / lsb;
        let ideal_err = (fixed - ideal) / lsb;
        self.count += 1;
        self.max = self.max.max(err.abs());
        self.sum_sq += err * err;
        self.ideal_max = self.ideal_max.max(ideal_err.abs());
        self.ideal_sq += ideal_err * ideal_err;
        self.signal_sq += (ideal / lsb) * (ideal / lsb);
    }

    fn finish(self, bound_lsb: f64) -> ErrorStats {
        let rms = |s: f64| {
            if self.count == 0 {
                0.0
            } else {
                (s / self.count as f64).sqrt()
            }
        };
        ErrorStats {
            samples: self.count,
            max_lsb: self.max,
            rms_lsb: rms(self.sum_sq),
            bound_lsb,
            ideal_max_lsb: self.ideal_max,
            ideal_rms_lsb: rms(self.ideal_sq),
            sqnr_db: if self.ideal_sq > 0.0 {
                10.0 * libm::log10(self.signal_sq / self.ideal_sq)
            } else {
                f64::INFINITY
            },
        }
    }
}

/// Tie-case inputs found for one KF ROM entry.
#[derive(Clone, Debug, PartialEq, Serialize)]
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

/// Overflow counts of every quantization point.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Overflows {
    /// ADC saturations of gyro A and B.
    pub adc: [u64; 2],
    /// Estimator and calibration.
    pub estimator: EstimatorCounts,
    /// The KF in the chain run.
    pub kf_chain: KfCounts,
    /// The KF's directed segment (full scale included).
    pub kf_directed: KfCounts,
    /// The mean filter's output (its full-scale blocks may round past the range).
    pub mean_filter: u64,
}

/// Estimator overflow counts (serializable mirror).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct EstimatorCounts {
    /// Means of A and B.
    pub mean: [u64; 2],
    /// Bias estimates of A and B.
    pub bias: [u64; 2],
    /// Calibrated outputs of A and B.
    pub calibrated: [u64; 2],
    /// Combined output.
    pub combined: u64,
}

/// KF overflow counts (serializable mirror).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct KfCounts {
    /// State x1.
    pub x1: u64,
    /// State x2.
    pub x2: u64,
    /// Output.
    pub rate_hat: u64,
}

impl From<OverflowCounts> for KfCounts {
    fn from(c: OverflowCounts) -> Self {
        KfCounts {
            x1: c.x1,
            x2: c.x2,
            rate_hat: c.rate_hat,
        }
    }
}

impl From<EstimatorOverflows> for EstimatorCounts {
    fn from(c: EstimatorOverflows) -> Self {
        EstimatorCounts {
            mean: c.mean,
            bias: c.bias,
            calibrated: c.calibrated,
            combined: c.combined,
        }
    }
}

/// One line of the report: a signal's bias error and Allan deviation.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct ReportLine {
    /// What the signal is.
    pub signal: String,
    /// Mean of (signal − true rate), °/s.
    pub bias_error_dps: f64,
    /// Allan deviation at each of [`Report::tau_s`], °/s (null where the record is too short).
    pub adev_dps: Vec<Option<f64>>,
}

/// What mode reversal and the KF did: raw gyros (run without reversal, same noise), the
/// calibrated combined output, and the filtered output.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Report {
    /// Samples analysed.
    pub samples: usize,
    /// Averaging times, s.
    pub tau_s: Vec<f64>,
    /// One line per signal.
    pub lines: Vec<ReportLine>,
}

/// Everything the run produced.
#[derive(Clone, Debug)]
pub struct Run {
    /// The blocks' vectors: sequencer, estimator, kf, top, mean_filter.
    pub blocks: Vec<Block>,
    /// KF block: fixed vs float on its own inputs (chain part), in output LSB.
    pub kf_stats: ErrorStats,
    /// Chain output: fixed vs the float chain, in output LSB.
    pub chain_stats: ErrorStats,
    /// Bias estimates: fixed vs float, in LSB of the bias format.
    pub bias_stats: ErrorStats,
    /// Mean filter outputs that fit: fixed vs float (same quantized r), in output LSB; ideal:
    /// r unquantized.
    pub mean_filter_stats: ErrorStats,
    /// Overflow counts.
    pub overflows: Overflows,
    /// KF tie cases found.
    pub ties: Vec<TieCases>,
    /// The Allan report.
    pub report: Report,
    /// Chain samples (excluding resets).
    pub samples: usize,
}

/// Samples of the full-scale segment at each polarity.
const FULL_SCALE_SAMPLES: usize = 64;
/// Largest |z| searched for a tie case.
const TIE_SEARCH_LIMIT: i64 = 1 << 16;

fn flag(b: bool) -> i128 {
    i128::from(b)
}

fn mode_bit(p: i8) -> i128 {
    i128::from(p > 0)
}

/// The blocks (sequencer, estimator, KF, top, mean filter) with their parameters and ROM file
/// names, without vectors.
pub fn empty_blocks(
    job: &Job,
    rom_kf: &str,
    rom_estimator: &str,
    rom_mean_filter: &str,
) -> [Block; 5] {
    let est = &job.chain.estimator;
    let kf = job.kf();
    let schedule = &est.schedule;
    let interval_bits = schedule.interval_bits();
    let phase_bits = (usize::BITS - (schedule.interval_length - 1).leading_zeros()).max(1);
    let pattern: u128 = schedule
        .pattern
        .modes(schedule.intervals)
        .iter()
        .enumerate()
        .map(|(i, m)| u128::from(*m > 0) << i)
        .sum();
    let sequencer_params = vec![
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
        Param::integer("INTERVAL_W", interval_bits.into(), "interval index width"),
    ];
    let mut estimator_params = Vec::new();
    estimator_params.extend(Param::format("IN", est.input, "gyro samples"));
    estimator_params.push(Param::integer(
        "ACC_W",
        est.accumulator.width.into(),
        format!("accumulator: {}", est.accumulator),
    ));
    estimator_params.extend(Param::format("RECIP", est.reciprocal, "reciprocal 1/(L-M)"));
    estimator_params.push(Param::bits(
        "RECIP",
        est.reciprocal.width,
        est.reciprocal.to_bits(est.reciprocal_code),
        format!("1/{}", schedule.valid_count()),
    ));
    estimator_params.extend(Param::format("MEAN", est.mean, "interval means"));
    estimator_params.extend(Param::format("GAIN", est.gain, "least-squares gains"));
    estimator_params.push(Param::integer(
        "DOT_W",
        est.dot.width.into(),
        format!("dot product: {}", est.dot),
    ));
    estimator_params.extend(Param::format("BIAS", est.bias, "bias estimates"));
    estimator_params.push(Param::integer("INTERVALS", schedule.intervals as i64, "W"));
    estimator_params.push(Param::integer(
        "INTERVAL_W",
        interval_bits.into(),
        "interval index width",
    ));
    estimator_params.push(Param::integer(
        "SMOOTH",
        est.smoothing_shift.into(),
        "smoothing shift",
    ));
    let modes = [
        Param::integer(
            "ROUNDING",
            est.rounding.rtl_code().into(),
            est.rounding.name(),
        ),
        Param::integer(
            "SATURATE",
            est.overflow.rtl_code().into(),
            est.overflow.name(),
        ),
    ];
    let mut kf_params = Vec::new();
    kf_params.extend(Param::format("IN", kf.input, "input z"));
    kf_params.extend(Param::format("STATE", kf.state, "states x1, x2"));
    kf_params.extend(Param::format("OUT", kf.output, "output rate_out"));
    kf_params.extend(Param::format("G1", kf.coefficient[0], "coefficient g1"));
    kf_params.extend(Param::format("G2", kf.coefficient[1], "coefficient g2"));
    kf_params.push(Param::integer(
        "SEL_W",
        kf.select_width().into(),
        "bw_sel width",
    ));
    kf_params.push(Param::integer(
        "ROM_DEPTH",
        kf.rom.len() as i64,
        "coefficient sets",
    ));

    let bias = Signal::new("bias_a", est.bias);
    let bias_b = Signal::new("bias_b", est.bias);
    let slot_inputs = |v: &mut Vec<Signal>| {
        v.extend([
            Signal::flag("blank_a"),
            Signal::flag("blank_b"),
            Signal::flag("done_a"),
            Signal::flag("done_b"),
            Signal::index("interval_a", interval_bits),
            Signal::index("interval_b", interval_bits),
            Signal::flag("window_done"),
        ])
    };

    let mut sequencer = Block::new(
        "sequencer",
        "gyrofx_sequencer",
        "state-machine sequencer",
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
    sequencer.params = sequencer_params.clone();

    let mut est_inputs = vec![Signal::new("y_a", est.input), Signal::new("y_b", est.input)];
    slot_inputs(&mut est_inputs);
    let mut estimator = Block::new(
        "estimator",
        "gyrofx_bias_estimator",
        "least-squares bias estimator",
        est_inputs,
        vec![
            Output::registered(bias.clone()),
            Output::registered(bias_b.clone()),
            Output::registered(Signal::flag("estimated")),
        ],
    );
    estimator.params = estimator_params.clone();
    estimator.params.extend(modes.clone());
    estimator
        .params
        .push(Param::string("ROM_FILE", rom_estimator, "gain ROM"));

    let select = Signal::index("bw_sel", kf.select_width());
    let mut kf_block = Block::new(
        "kf",
        "gyrofx_kf",
        "steady-state Kalman filter",
        vec![select.clone(), Signal::new("z", kf.input)],
        vec![
            Output::pulse(Signal::flag("out_valid")),
            Output::gated(Signal::new("rate_out", kf.output), "out_valid"),
        ],
    );
    kf_block.params = kf_params.clone();
    kf_block.params.extend(modes.clone());
    kf_block
        .params
        .push(Param::string("ROM_FILE", rom_kf, "coefficient ROM"));

    let mut top = Block::new(
        "top",
        "gyrofx_top",
        "the whole mode-reversal chain",
        vec![
            select,
            Signal::new("y_a", est.input),
            Signal::new("y_b", est.input),
        ],
        vec![
            Output::combinational(Signal::flag("mode_a")),
            Output::combinational(Signal::flag("mode_b")),
            Output::pulse(Signal::flag("out_valid")),
            Output::gated(Signal::new("rate_out", kf.output), "out_valid"),
            Output::registered(bias),
            Output::registered(bias_b),
            Output::registered(Signal::flag("estimated")),
        ],
    );
    top.params = sequencer_params;
    top.params.extend(
        estimator_params
            .into_iter()
            .filter(|p| p.name != "INTERVALS" && p.name != "INTERVAL_W"),
    );
    top.params.push(Param::string(
        "GAIN_ROM_FILE",
        rom_estimator,
        "estimator gain ROM",
    ));
    top.params.extend(
        kf_params
            .into_iter()
            .filter(|p| p.name != "IN_W" && p.name != "IN_F"),
    );
    top.params
        .push(Param::string("KF_ROM_FILE", rom_kf, "KF coefficient ROM"));
    top.params.extend(modes.clone());
    let mean_filter = mean_filter_block(&job.mean_filter, modes.to_vec(), rom_mean_filter);
    [sequencer, estimator, kf_block, top, mean_filter]
}

/// The mean filter's block (no vectors): parameters from its plan.
fn mean_filter_block(plan: &mean_filter::Plan, modes: Vec<Param>, rom: &str) -> Block {
    let mut block = Block::new(
        "mean_filter",
        "gyrofx_mean_filter",
        "mean filter with gross-error rejection (paper 003)",
        vec![Signal::new("x", plan.input)],
        vec![
            Output::pulse(Signal::flag("y_valid")),
            Output::gated(Signal::new("y", plan.output), "y_valid"),
            Output::gated(Signal::index("kept", plan.count_bits), "y_valid"),
        ],
    );
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
    block
        .params
        .extend(Param::format("RECIP", plan.reciprocal, "reciprocals 1/n"));
    block.params.extend(modes);
    block
        .params
        .push(Param::string("ROM_FILE", rom, "reciprocal ROM"));
    block
}

/// Gross errors added to gyro A's samples for the mean filter's vectors (the plant has none):
/// every `GROSS_ERROR_PERIOD`-th sample, ±`GROSS_ERROR_SCALE`·r, alternating in sign.
const GROSS_ERROR_PERIOD: usize = 53;
const GROSS_ERROR_SCALE: i128 = 8;

/// Fills the mean filter's block: gyro A's ADC samples `x` with gross errors added, a reset at
/// `reset_at`, then a directed segment (see [`mean_filter_directed`]). Returns the fixed vs
/// float statistics and the output overflows.
fn mean_filter_vectors(
    plan: &mean_filter::Plan,
    x: &[i64],
    reset_at: Option<usize>,
    block: &mut Block,
) -> (ErrorStats, u64) {
    let mut fixed = FixedMeanFilter::new(plan);
    let mut float = FloatMeanFilter::new(plan);
    let mut ideal = FloatMeanFilter::with_threshold(plan.window, plan.threshold_dps());
    let mut acc = Accumulator::default();
    let mut overflows = 0u64;
    let lsb = plan.output.lsb();
    let (min, max) = (plan.input.min_code(), plan.input.max_code());
    let mut samples: Vec<Option<i64>> = x
        .iter()
        .enumerate()
        .map(|(k, &code)| {
            let gross = if k % GROSS_ERROR_PERIOD == GROSS_ERROR_PERIOD / 3 {
                let sign = if (k / GROSS_ERROR_PERIOD).is_multiple_of(2) {
                    1
                } else {
                    -1
                };
                sign * GROSS_ERROR_SCALE * plan.threshold_code.max(1)
            } else {
                0
            };
            Some((i128::from(code) + gross).clamp(min, max) as i64)
        })
        .collect();
    if let Some(at) = reset_at {
        samples.insert(at.min(samples.len()), None);
    }
    samples.extend(mean_filter_directed(plan));
    block.reserve(samples.len());
    for sample in samples {
        let Some(code) = sample else {
            fixed.reset();
            float.reset();
            ideal.reset();
            block.push(true, &[0], &[0, 0, 0]);
            continue;
        };
        let real = plan.input.to_f64(i128::from(code));
        let a = fixed.step(code);
        let b = float.step(real);
        let c = ideal.step(real);
        match (a, b, c) {
            (Some(a), Some((b, _)), Some((c, _))) => {
                // The bound holds where the output fits (full scale may round past it).
                if a.overflowed {
                    overflows += 1;
                } else {
                    acc.add(plan.output.to_f64(i128::from(a.y)), b, c, lsb);
                }
                block.push(
                    false,
                    &[i128::from(code)],
                    &[1, i128::from(a.y), i128::from(a.kept)],
                );
            }
            _ => block.push(false, &[i128::from(code)], &[0, 0, 0]),
        }
    }
    (acc.finish(plan.error_bound_lsb()), overflows)
}

/// The mean filter's directed blocks, after a reset: every sample kept at exactly `±r` from
/// the mean and every one rejected one LSB farther, every sample rejected (two clusters: the
/// plain mean), full scale positive and negative, and one gross error at full scale.
fn mean_filter_directed(plan: &mean_filter::Plan) -> Vec<Option<i64>> {
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

/// Runs the chain for `job` and builds every block's vectors. `rom_kf` / `rom_estimator` are
/// the ROM image names and contents.
///
/// # Errors
/// Stimulus errors (a bad CSV file).
pub fn run(
    job: &Job,
    rom_kf: (String, String),
    rom_estimator: (String, String),
    rom_mean_filter: (String, String),
) -> Result<Run> {
    let plan = &job.chain;
    let kf = job.kf();
    let est = &plan.estimator;
    let rate = job.true_rate(job.config.samples)?;
    let n = rate.len();
    let entries = kf.rom.len();
    let chunk = (n / (2 * entries)).max(1);
    // One reset of the whole chain, late in the run, so that the report has a long stretch of
    // calibrated output before it.
    let reset_at = if n >= 20 { Some(n - n / 10) } else { None };

    // The modes the sequencer asks for, resets included: the plant runs in them.
    let mut sequencer = Sequencer::new(&est.schedule);
    let mut modes = Vec::with_capacity(n);
    for k in 0..n {
        if reset_at == Some(k) {
            sequencer.reset();
        }
        let slot = sequencer.advance();
        modes.push([slot.mode_a, slot.mode_b]);
    }
    let plant = &job.settings.plant;
    let seed = job.config.seed;
    let record = plant.simulate(&rate, &modes, seed);
    let (ya, sat_a) = adc(&record.y[0], est.input);
    let (yb, sat_b) = adc(&record.y[1], est.input);

    let [mut seq_block, mut est_block, mut kf_block, mut top_block, mut mean_filter_block] =
        empty_blocks(job, &rom_kf.0, &rom_estimator.0, &rom_mean_filter.0);
    mean_filter_block.roms.push(rom_mean_filter);
    for block in [
        &mut seq_block,
        &mut est_block,
        &mut kf_block,
        &mut top_block,
    ] {
        block.reserve(n + 1);
    }
    est_block.roms.push(rom_estimator.clone());
    kf_block.roms.push(rom_kf.clone());
    top_block.roms.push(rom_estimator);
    top_block.roms.push(rom_kf);

    // Report: the same gyros run without reversal (same noise streams), simulated on the other
    // core while the chain runs.
    std::thread::scope(|scope| -> Result<Run> {
        let raw_record = scope.spawn(|| plant.simulate(&rate, &vec![[1i8, 1i8]; n], seed));
        let mut fixed = FixedChain::new(plan);
        let mut float = FloatChain::quantized(plan);
        let mut ideal = FloatChain::ideal(plan);
        let mut kf_float = FloatKf::new(kf.quantized_gains());
        let mut kf_ideal = FloatKf::new(kf.gains.clone());
        let (mut kf_acc, mut chain_acc, mut bias_acc) = (
            Accumulator::default(),
            Accumulator::default(),
            Accumulator::default(),
        );
        let mut chain_switches = 0u64;
        let mut previous_sel = None;
        let out_lsb = kf.output.lsb();
        let bias_lsb = est.bias.lsb();
        let (mut combined_series, mut filtered_series) =
            (Vec::with_capacity(n), Vec::with_capacity(n));
        let mut true_series = Vec::with_capacity(n);
        let mut first_estimate: Option<usize> = None;
        let mut extra_float = Vec::with_capacity(n + 2);
        let mut extra_ideal = Vec::with_capacity(n + 2);
        let mut extra_true = Vec::with_capacity(n + 2);
        let zero_outputs_top = [0i128; 7];

        for k in 0..n {
            if reset_at == Some(k) {
                fixed.reset();
                float.reset();
                ideal.reset();
                kf_float.reset();
                kf_ideal.reset();
                seq_block.push(true, &[], &[0; 9]);
                est_block.push(true, &[0; 9], &[0, 0, 0]);
                kf_block.push(true, &[0, 0], &[0, 0]);
                top_block.push(true, &[0, 0, 0], &zero_outputs_top);
                for extra in [&mut extra_float, &mut extra_ideal, &mut extra_true] {
                    extra.push(f64::NAN);
                }
            }
            let bw_sel = (k / chunk) % entries;
            let y = [ya[k], yb[k]];
            let y_real = [
                est.input.to_f64(i128::from(y[0])),
                est.input.to_f64(i128::from(y[1])),
            ];
            let a = fixed.step(y, bw_sel);
            let b = float.step(y_real, bw_sel);
            let c = ideal.step(y_real, bw_sel);
            let s = a.slot;
            let slot_codes = [
                flag(s.blank_a),
                flag(s.blank_b),
                flag(s.done_a),
                flag(s.done_b),
                s.interval_a as i128,
                s.interval_b as i128,
                flag(s.window_done),
            ];
            seq_block.push(
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
            let bias_after = fixed.estimator().bias();
            let estimated = flag(fixed.estimator().estimated());
            let [s0, s1, s2, s3, s4, s5, s6] = slot_codes;
            let est_inputs = [
                i128::from(y[0]),
                i128::from(y[1]),
                s0,
                s1,
                s2,
                s3,
                s4,
                s5,
                s6,
            ];
            est_block.push(
                false,
                &est_inputs,
                &[bias_after[0], bias_after[1], estimated],
            );
            let rate_code = a.rate.map(i128::from).unwrap_or(0);
            top_block.push(
                false,
                &[bw_sel as i128, i128::from(y[0]), i128::from(y[1])],
                &[
                    mode_bit(s.mode_a),
                    mode_bit(s.mode_b),
                    flag(a.rate.is_some()),
                    rate_code,
                    bias_after[0],
                    bias_after[1],
                    estimated,
                ],
            );
            extra_float.push(b.rate.unwrap_or(f64::NAN));
            extra_ideal.push(c.rate.unwrap_or(f64::NAN));
            extra_true.push(rate[k]);

            // Bias estimates: fixed vs float, every sample (the ones in use).
            for g in 0..2 {
                bias_acc.add(
                    est.bias.to_f64(i128::from(a.estimator.bias[g])),
                    b.estimator.bias[g],
                    c.estimator.bias[g],
                    bias_lsb,
                );
            }
            if let Some(code) = a.rate {
                if previous_sel.is_some_and(|p| p != bw_sel) {
                    chain_switches += 1;
                }
                previous_sel = Some(bw_sel);
                let fixed_real = kf.output.to_f64(i128::from(code));
                chain_acc.add(
                    fixed_real,
                    b.rate.unwrap_or(f64::NAN),
                    c.rate.unwrap_or(f64::NAN),
                    out_lsb,
                );
                // The KF block sees exactly the chain's KF inputs.
                let z = a.estimator.combined;
                kf_block.push(
                    false,
                    &[bw_sel as i128, i128::from(z)],
                    &[1, i128::from(code)],
                );
                let z_real = kf.input.to_f64(i128::from(z));
                let kf_b = kf_float.step(z_real, bw_sel);
                let kf_c = kf_ideal.step(z_real, bw_sel);
                kf_acc.add(fixed_real, kf_b, kf_c, out_lsb);
                filtered_series.push(fixed_real);
            } else {
                filtered_series.push(*filtered_series.last().unwrap_or(&0.0));
            }
            let combined = if a.estimator.combined_valid {
                est.calibrated.to_f64(i128::from(a.estimator.combined))
            } else {
                *combined_series.last().unwrap_or(&0.0)
            };
            combined_series.push(combined);
            true_series.push(rate[k]);
            if first_estimate.is_none() && a.estimator.estimated {
                first_estimate = Some(k);
            }
        }
        let kf_chain_overflows = fixed.kf().overflow_counts();
        let estimator_overflows = fixed.estimator().overflow_counts();
        let kf_steps = kf_acc.count;
        let kf_stats = kf_acc.finish(rate_error_bound_lsb(kf, kf_steps, chain_switches));
        let chain_stats = chain_acc.finish(plan.rate_error_bound_lsb(kf_steps, chain_switches));
        let bias_stats = bias_acc.finish(est.bias_error_bound() / bias_lsb);

        // The KF's directed segment: ties and full scale, each from reset.
        let ties = find_ties(kf);
        let directed_overflows = directed_segment(kf, &ties, &mut kf_block);
        top_block.extra = vec![
            ("float_rate_dps", extra_float),
            ("ideal_rate_dps", extra_ideal),
            ("true_rate_dps", extra_true),
        ];

        let (mean_filter_stats, mean_filter_overflows) =
            mean_filter_vectors(&job.mean_filter, &ya, reset_at, &mut mean_filter_block);

        let raw = raw_record
            .join()
            .expect("the plant simulation does not panic");
        let fs = job.config.stimulus.fs_hz;
        // Only calibrated samples: from the first estimate to the reset.
        let start = first_estimate.unwrap_or(n).min(n);
        let end = reset_at.unwrap_or(n).max(start);
        let report = report(
            fs,
            &rate[start..end],
            [
                &raw.y[0][start..end],
                &raw.y[1][start..end],
                &combined_series[start..end],
                &filtered_series[start..end],
            ],
        );
        Ok(Run {
            blocks: vec![seq_block, est_block, kf_block, top_block, mean_filter_block],
            kf_stats,
            chain_stats,
            bias_stats,
            mean_filter_stats,
            overflows: Overflows {
                adc: [sat_a, sat_b],
                estimator: estimator_overflows.into(),
                kf_chain: kf_chain_overflows.into(),
                kf_directed: directed_overflows.into(),
                mean_filter: mean_filter_overflows,
            },
            ties,
            report,
            samples: n,
        })
    })
}

fn report(fs: f64, rate: &[f64], signals: [&[f64]; 4]) -> Report {
    let names = [
        "raw gyro A (no reversal)",
        "raw gyro B (no reversal)",
        "calibrated, combined",
        "filtered (KF output)",
    ];
    let tau_s: Vec<f64> = [0.1, 1.0, 10.0, 100.0, 1000.0]
        .into_iter()
        .filter(|tau| ((tau * fs).round() as usize) * 3 <= rate.len() && tau * fs >= 1.0)
        .collect();
    let lines = names
        .iter()
        .zip(signals)
        .map(|(name, signal)| {
            let errors: Vec<f64> = signal.iter().zip(rate).map(|(s, r)| s - r).collect();
            ReportLine {
                signal: name.to_string(),
                bias_error_dps: errors.iter().sum::<f64>() / errors.len().max(1) as f64,
                adev_dps: {
                    let x = allan::phase(&errors);
                    tau_s
                        .iter()
                        .map(|tau| {
                            allan::deviation(Kind::Overlapping, &x, (tau * fs).round() as usize, fs)
                                .map(|(dev, _)| dev)
                        })
                        .collect()
                },
            }
        })
        .collect();
    Report {
        samples: rate.len(),
        tau_s,
        lines,
    }
}

/// For each ROM entry, an input that from reset lands each quantization point exactly on a
/// tie. From reset a state update is `Q(g·z·2^a)`, which is a tie only when `z`'s lowest set
/// bit sits at one particular position, so powers of two (both signs) are tried first; then
/// every |z| up to [`TIE_SEARCH_LIMIT`] (positive first) for what is still missing.
fn find_ties(plan: &Plan) -> Vec<TieCases> {
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::config::Config;

    /// The embedded config with 4000 samples, changed by `edit`, run (ROM images unnamed).
    fn run_embedded(edit: impl FnOnce(&mut Config)) -> (Job, Run) {
        let mut config = Config::embedded();
        config.samples = 4000;
        edit(&mut config);
        let job = Job::new(config).unwrap();
        let unnamed = |name: &str| (name.to_string(), String::new());
        let run = run(
            &job,
            unnamed("kf.mem"),
            unnamed("est.mem"),
            unnamed("mf.mem"),
        )
        .unwrap();
        (job, run)
    }

    #[test]
    fn the_default_run_fills_every_block_and_stays_within_the_bounds() {
        let (job, run) = run_embedded(|_| {});
        let names: Vec<&str> = run.blocks.iter().map(|b| b.name).collect();
        assert_eq!(
            names,
            ["sequencer", "estimator", "kf", "top", "mean_filter"]
        );
        // One row per sample plus the reset, in every chain block.
        for b in [&run.blocks[0], &run.blocks[1], &run.blocks[3]] {
            assert_eq!(b.len(), 4001, "{}", b.name);
        }
        assert!(run.kf_stats.max_lsb <= run.kf_stats.bound_lsb);
        assert!(run.chain_stats.max_lsb <= run.chain_stats.bound_lsb);
        assert!(run.bias_stats.max_lsb <= run.bias_stats.bound_lsb);
        // Each tie input really is a tie from reset, for x1 and the output.
        let kf = FixedKf::new(job.kf());
        for tie in &run.ties {
            assert!(kf.ties(tie.x1.expect("x1 tie"), tie.bw_sel)[0]);
            assert!(kf.ties(tie.rate_hat.expect("output tie"), tie.bw_sel)[2]);
        }
        // Every bw_sel value occurs in the top vectors.
        let sels: std::collections::BTreeSet<i64> = (0..run.blocks[3].len())
            .map(|k| run.blocks[3].row(k)[1])
            .collect();
        assert_eq!(sels.len(), 3);
    }

    /// The mean filter's vectors: one output per block of 20, kept counts from 0 (every
    /// sample rejected) to 20, the gross errors rejected, and fixed within the bound of float.
    #[test]
    fn the_mean_filter_vectors_cover_every_case_within_the_bound() {
        // r = 3 °/s, about 2.6 sigma of the default gyro: only the gross errors (8 r) go.
        let (_, run) = run_embedded(|config| config.mean_filter.threshold_dps = 3.0);
        let block = &run.blocks[4];
        // rst, x, y_valid, y, kept
        let outputs: Vec<&[i64]> = (0..block.len())
            .map(|k| block.row(k))
            .filter(|row| row[2] == 1)
            .collect();
        // 4000 samples with a reset at 3600: 180 + 20 blocks, then 6 directed ones.
        assert_eq!(outputs.len(), 180 + 20 + 6);
        let kept: std::collections::BTreeSet<i64> = outputs.iter().map(|row| row[4]).collect();
        assert!(
            kept.contains(&0) && kept.contains(&20) && kept.contains(&19),
            "{kept:?}"
        );
        // Every block with a gross error (before the reset, blocks start at multiples of 20)
        // drops at least that sample.
        let gross_blocks: Vec<usize> = (0..180)
            .filter(|b| {
                (20 * b..20 * b + 20).any(|k| k % GROSS_ERROR_PERIOD == GROSS_ERROR_PERIOD / 3)
            })
            .collect();
        assert!(gross_blocks.len() > 50, "{}", gross_blocks.len());
        for b in gross_blocks {
            assert!(outputs[b][4] < 20, "block {b} kept its gross error");
        }
        assert!(run.mean_filter_stats.max_lsb <= run.mean_filter_stats.bound_lsb);
        assert!(run.mean_filter_stats.samples >= 200);
    }
}
