//! `gyrofx formats`: the proven range of every analysed quantization point of a job, the
//! integer bits that make overflow impossible for any input inside the ADC's range, and the
//! config with those formats.
//!
//! The analysis is [`gyrofx_model::range`] (worst-case peak gain of each linear block, interval
//! arithmetic for the estimator and calibration); here it is applied to the job's plans, named
//! by config key, and printed. Covered: the estimator, the calibration, the KF (the chain from
//! the gyros' samples to the KF's output), the mean filter, and the resonator-level loop
//! ([`gyrofx_model::range::gyro_loop`]: demodulators, PLL, AGC, DAC, CICs and the rate output,
//! for any code of the loop's ADC). One `[loop]` section sets both gyros' formats while their
//! designs (PI gains and limits, setpoints, `1/SF`) follow their resonators, so each loop node's
//! range is the union of gyro A's and gyro B's. What stays hand-set ([`NOT_ANALYSED`]) has no
//! range to prove: the NCO's widths are resolutions, the lock filters are wide enough by
//! construction, coefficient formats are fitted to their values.

use std::fmt::Write as _;

use gyrofx_model::fx::Format;
use gyrofx_model::kf::bound::rate_error_bound_lsb;
use gyrofx_model::range::{self, Interval, NodeRange};
use serde_json::json;

use gyrofx_model::chain;
use gyrofx_model::estimator;

use crate::config::{Config, GyroLoop};
use crate::error::{Error, Result};
use crate::job::{plan_for, Job};

/// One analysed node.
#[derive(Clone, Debug)]
pub struct Row {
    /// What the analysis proved.
    pub node: NodeRange,
    /// The config key that sets its format, when one does (exact nodes follow by bit growth).
    pub key: Option<&'static str>,
    /// Why `--write` does not set the node's format: its key sets other things too, or no key
    /// sets it alone.
    pub shared: Option<&'static str>,
    /// Units of its range.
    pub unit: &'static str,
}

impl Row {
    /// The proven format: the configured fraction bits and the integer bits the range needs.
    pub fn proven(&self) -> Format {
        holding(self.node.range, self.node.format.frac)
    }
}

/// The analysis of a job.
#[derive(Clone, Debug)]
pub struct Analysis {
    /// Record length the bounds hold for, samples.
    pub samples: u64,
    /// `bw_sel` changes the bounds allow for.
    pub switches: u64,
    /// The ADC's range (°/s): the gyros' samples.
    pub input: Interval,
    /// The loop ADC's range (full-scale units): the resonators' pick-off codes.
    pub loop_input: Interval,
    /// Every analysed node, in data-flow order.
    pub rows: Vec<Row>,
    /// How far one `bw_sel` switch can move the KF's states (°/s).
    pub per_switch_dps: f64,
    /// The KF's worst-case `|fixed − float|` at its output after the record, output LSB.
    pub kf_output_error_lsb: f64,
    /// The estimator's worst-case bias error against its float twin, bias LSB.
    pub bias_error_lsb: f64,
    /// The longest record (samples, with `switches`) for which the configured KF state format
    /// is proven; `None` when not even a record of 0 samples is (the switches alone overflow).
    pub kf_state_limit: Option<u64>,
}

/// Fraction bits chosen for an error budget on the chain's output.
#[derive(Clone, Debug, PartialEq)]
pub struct Budget {
    /// The budget: `|rate_hat_fixed − rate_hat_float|`, KF output LSB.
    pub budget_lsb: f64,
    /// The least any fraction bits can give: the output's and the calibrated samples' own
    /// roundings, whose formats are the ADC's and the output's.
    pub floor_lsb: f64,
    /// The interval means' format.
    pub mean: Format,
    /// The bias estimates' format.
    pub bias: Format,
    /// The KF state's format.
    pub state: Format,
    /// The chain's bound with them, output LSB.
    pub bound_lsb: f64,
    /// The mean filter's reciprocal ROM word (`mean_filter.reciprocal_width`): the narrowest
    /// that keeps its block means within the same budget (in °/s) of its float model.
    pub mean_filter_reciprocal_width: u32,
    /// The mean filter's bound with it, in its own output LSB.
    pub mean_filter_bound_lsb: f64,
}

/// The most guard bits the budget search tries per block.
const MAX_GUARD_BITS: i32 = 40;

/// A signed format of `frac` fraction bits with the integer bits `range` needs.
fn holding(range: Interval, frac: i32) -> Format {
    Format {
        signed: true,
        width: (range.signed_integer_bits(frac) + frac).max(1) as u32,
        frac,
    }
}

/// The estimator of `job` with interval means and bias estimates at `frac` fraction bits
/// (integer bits as their proven ranges need).
fn estimator_at(job: &Job, frac: i32) -> Option<estimator::Plan> {
    let mut spec = job.settings.estimator.clone();
    // Provisional formats wide enough for the analysis, then the proven ones.
    spec.mean = Format::signed(64, frac).ok()?;
    spec.bias = spec.mean;
    let wide = estimator::Plan::new(&spec).ok()?;
    let input = Interval::of_format(wide.input);
    let nodes = range::estimator(&wide, input);
    let range_of = |name: &str| range::find(&nodes, name).map(|n| n.range);
    spec.mean = holding(range_of("estimator.mean")?, frac);
    spec.bias = holding(range_of("estimator.bias")?, frac);
    estimator::Plan::new(&spec).ok()
}

/// The KF of `job` with its state at `frac` fraction bits (integer bits as the proven range
/// needs for the record).
fn kf_at(job: &Job, frac: i32, samples: u64, switches: u64) -> Option<gyrofx_model::kf::Plan> {
    let mut settings = job.settings.kf.clone();
    settings.state = Format::signed(64, frac).ok()?;
    let wide = plan_for(&settings, &job.designs).ok()?;
    let ranges = range::kf(&wide, Interval::of_format(wide.input), samples, switches);
    let state = range::find(&ranges.nodes, "kf.state")?.range;
    settings.state = holding(state, frac);
    plan_for(&settings, &job.designs).ok()
}

/// The narrowest reciprocal ROM word of `job`'s mean filter whose bound
/// ([`gyrofx_model::mean_filter::Plan::error_bound_lsb`]) is within `budget_dps`, and that
/// bound in the filter's output LSB.
///
/// # Errors
/// Why no width from 4 to 64 bits meets it (the output rounding alone, or the widest word).
fn mean_filter_reciprocal_for(
    job: &Job,
    budget_dps: f64,
) -> std::result::Result<(u32, f64), String> {
    let lsb = job.mean_filter.output.lsb();
    let budget_lsb = budget_dps / lsb;
    let mut spec = job.settings.mean_filter;
    let mut best_bound = f64::INFINITY;
    for width in 4..=64 {
        spec.reciprocal_width = width;
        let Ok(plan) = gyrofx_model::mean_filter::Plan::new(&spec) else {
            continue;
        };
        let bound = plan.error_bound_lsb();
        if bound <= budget_lsb {
            return Ok((width, bound));
        }
        best_bound = best_bound.min(bound);
    }
    Err(format!(
        "a budget the mean filter can meet too: its block means (mean_filter.output_format, LSB {lsb:e} °/s) come within {best_bound:.3} of their LSB at best, {budget_lsb:.3} asked"
    ))
}

/// The fewest guard bits (estimator first, then the KF's state) that keep the chain's output
/// within `budget_lsb` of its float model over the record, and the mean filter's narrowest
/// reciprocal word for the same error in °/s.
///
/// # Errors
/// Why the budget is refused: at or below what the fixed roundings give, or not met by any
/// format up to [`MAX_GUARD_BITS`] guard bits.
pub fn fractions_for(
    job: &Job,
    samples: u64,
    switches: u64,
    budget_lsb: f64,
) -> std::result::Result<Budget, String> {
    let chain = &job.chain;
    let floor_lsb = chain.rate_error_floor_lsb();
    let refuse =
        |allowed: String| format!("--output-error {budget_lsb} LSB is not allowed: {allowed}");
    if !budget_lsb.is_finite() {
        return Err(refuse(format!(
            "a finite number of output LSB above {floor_lsb:.3}"
        )));
    }
    if budget_lsb <= floor_lsb {
        return Err(refuse(format!(
            "more than {floor_lsb:.3} LSB: the output's rounding and the calibrated samples' (their formats are kf.output_format and kf.input_format) give that much with any guard bits"
        )));
    }
    let input_frac = chain.estimator.input.frac;
    let output_frac = chain.kf.output.frac;
    let mut best: Option<(i32, Budget)> = None;
    for estimator_guard in 0..=MAX_GUARD_BITS {
        let Some(est) = estimator_at(job, input_frac + estimator_guard) else {
            continue;
        };
        for state_guard in 0..=MAX_GUARD_BITS {
            if best
                .as_ref()
                .is_some_and(|(bits, _)| estimator_guard + state_guard >= *bits)
            {
                break;
            }
            let Some(kf) = kf_at(job, output_frac + state_guard, samples, switches) else {
                continue;
            };
            let Ok(plan) = chain::Plan::new(est.clone(), kf.clone()) else {
                continue;
            };
            let bound_lsb = plan.rate_error_bound_lsb(samples, switches);
            if bound_lsb <= budget_lsb {
                best = Some((
                    estimator_guard + state_guard,
                    Budget {
                        budget_lsb,
                        floor_lsb,
                        mean: est.mean,
                        bias: est.bias,
                        state: kf.state,
                        bound_lsb,
                        mean_filter_reciprocal_width: 0,
                        mean_filter_bound_lsb: 0.0,
                    },
                ));
                break;
            }
        }
    }
    let mut budget = best.map(|(_, b)| b).ok_or_else(|| {
        refuse(format!(
            "a budget that {MAX_GUARD_BITS} guard bits in the estimator and the KF's state can meet for {samples} samples and {switches} switches"
        ))
    })?;
    let (width, bound) =
        mean_filter_reciprocal_for(job, budget_lsb * chain.kf.output.lsb()).map_err(refuse)?;
    budget.mean_filter_reciprocal_width = width;
    budget.mean_filter_bound_lsb = bound;
    Ok(budget)
}

/// Sets the format of `key` in `config`: a format key of an analysed node ([`Row::key`]).
///
/// # Panics
/// On any other key: the keys come from the analysis's rows.
pub fn set_format(config: &mut Config, key: &str, format: Format) {
    let text = format.to_string();
    match key {
        "estimator.mean_format" => config.estimator.mean_format = text,
        "estimator.bias_format" => config.estimator.bias_format = text,
        "kf.state_format" => config.kf.state_format = text,
        "kf.output_format" => config.kf.output_format = text,
        "mean_filter.output_format" => config.mean_filter.output_format = text,
        _ => {
            let field = key
                .strip_prefix("loop.")
                .unwrap_or_else(|| panic!("{key} is not a format key of an analysed node"));
            config.gyro_loop.insert(field.into(), text.into());
        }
    }
}

/// Formats the analysis does not cover, with why none is needed: they are reported as
/// hand-set.
pub const NOT_ANALYSED: [(&str, &str); 1] = [(
    "loop",
    "NCO phase, ROM and sine widths (resolutions: the phase wraps by design, the ROM's largest code is its format's), lock filters (demod_output width + s + 1 bits, cannot overflow), gain and 1/SF widths (fitted to their values)",
)];

/// Units of a loop node's range.
fn loop_unit(name: &str) -> &'static str {
    match name {
        "loop.pll_integrator" | "loop.pll_output" => "cycles/sample",
        "loop.agc_integrator" | "loop.agc_output" | "loop.dac" => "DAC LSB",
        "loop.output" => "°/s",
        _ => "FS",
    }
}

/// The config key of a loop node, and why `--write` leaves it when it does.
fn loop_key(name: &str) -> (Option<&'static str>, Option<&'static str>) {
    match name {
        "loop.demod_product" => (Some("loop.demod_product_format"), None),
        "loop.demod_state" => (Some("loop.demod_state_format"), None),
        // Both are quantized into one format: --write gives it the wider of the two.
        "loop.demod_output" | "loop.agc_error" => (Some("loop.demod_output_format"), None),
        "loop.pll_integrator" => (Some("loop.pll_integrator_format"), None),
        "loop.pll_output" => (
            None,
            Some("the NCO's frequency word, s P.P cycles per sample with P = loop.nco_phase_bits"),
        ),
        "loop.agc_integrator" => (Some("loop.agc_integrator_format"), None),
        "loop.agc_output" => (
            Some("loop.agc_output_format"),
            Some("loop.agc_output_format limits the drive at the DAC's full scale on purpose: a wider one moves the saturation to the DAC, which clips the drive's sine"),
        ),
        "loop.dac" => (
            Some("loop.dac_format"),
            Some("loop.dac_format is the DAC's (one LSB is front_end.dac_newton_per_lsb) and sets the AGC's limits"),
        ),
        "loop.cic_internal" => (Some("loop.cic_internal_format"), None),
        "loop.cic_output" => (Some("loop.cic_output_format"), None),
        "loop.output" => (
            Some("loop.output_format"),
            Some("loop.output_format is the chain's input format (kf.input_format, with the resonator plant): the rate saturates beyond it"),
        ),
        _ => (None, None),
    }
}

/// The loop's rows over both gyros: each node's range is the union of both gyros' (one
/// `[loop]` section sets both formats).
fn loop_rows(loops: &[GyroLoop; 2]) -> Vec<Row> {
    let [a, b] = loops.each_ref().map(|l| range::gyro_loop::gyro(&l.plan));
    a.into_iter()
        .zip(b)
        .map(|(mut node, other)| {
            debug_assert_eq!((node.name, node.format), (other.name, other.format));
            node.range = node.range.union(other.range);
            let (key, shared) = loop_key(node.name);
            Row {
                unit: loop_unit(node.name),
                node,
                key,
                shared,
            }
        })
        .collect()
}

/// Analyses `job` for a record of `samples` samples with at most `switches` changes of
/// `bw_sel`.
pub fn analyse(job: &Job, samples: u64, switches: u64) -> Analysis {
    let chain = &job.chain;
    let input = Interval::of_format(chain.estimator.input);
    let mut rows: Vec<Row> = range::estimator(&chain.estimator, input)
        .into_iter()
        .map(|node| {
            let (key, shared) = match node.name {
                "estimator.mean" => (Some("estimator.mean_format"), None),
                "estimator.bias" => (Some("estimator.bias_format"), None),
                "estimator.calibrated" => (
                    Some("kf.input_format"),
                    Some("kf.input_format is also the ADC's (the gyros' samples): a wider one widens the inputs; the calibration saturates instead"),
                ),
                _ => (None, None),
            };
            Row {
                node,
                key,
                shared,
                unit: "°/s",
            }
        })
        .collect();
    // The KF sees the calibrated samples after their (saturating) quantizer: its input range is
    // its input format's.
    let kf_ranges = range::kf(
        &chain.kf,
        Interval::of_format(chain.kf.input),
        samples,
        switches,
    );
    rows.extend(kf_ranges.nodes.into_iter().map(|node| {
        let key = match node.name {
            "kf.state" => Some("kf.state_format"),
            "kf.output" => Some("kf.output_format"),
            _ => None,
        };
        Row {
            node,
            key,
            shared: None,
            unit: "°/s",
        }
    }));
    rows.extend(
        range::mean_filter(&job.mean_filter)
            .into_iter()
            .map(|node| {
                let key =
                    (node.name == "mean_filter.output").then_some("mean_filter.output_format");
                Row {
                    node,
                    key,
                    shared: None,
                    unit: "°/s",
                }
            }),
    );
    rows.extend(loop_rows(&job.gyro_loops));
    let loop_input = job
        .gyro_loops
        .each_ref()
        .map(|l| Interval::of_format(l.plan.adc))
        .into_iter()
        .reduce(Interval::union)
        .expect("two gyros");
    let state_fits = |n: u64| {
        let ranges = range::kf(&chain.kf, Interval::of_format(chain.kf.input), n, switches);
        range::find(&ranges.nodes, "kf.state").is_some_and(NodeRange::fits)
    };
    let kf_state_limit = state_fits(0).then(|| longest(state_fits));
    Analysis {
        samples,
        switches,
        input,
        loop_input,
        rows,
        per_switch_dps: kf_ranges.per_switch,
        kf_output_error_lsb: rate_error_bound_lsb(&chain.kf, samples, switches),
        bias_error_lsb: chain.estimator.bias_error_bound() / chain.estimator.bias.lsb(),
        kf_state_limit,
    }
}

/// The largest `n` with `holds(n)`, for a monotone `holds` true at 0 (at most 2⁶²).
fn longest(holds: impl Fn(u64) -> bool) -> u64 {
    let (mut good, mut bad) = (0u64, 1u64);
    while holds(bad) {
        good = bad;
        if bad >= 1 << 62 {
            return bad;
        }
        bad *= 2;
    }
    while bad - good > 1 {
        let middle = good + (bad - good) / 2;
        if holds(middle) {
            good = middle;
        } else {
            bad = middle;
        }
    }
    good
}

impl Analysis {
    /// Nodes whose configured format cannot hold their proven range.
    pub fn overflows(&self) -> impl Iterator<Item = &Row> {
        self.rows.iter().filter(|r| !r.node.fits())
    }

    /// The table `gyrofx formats` prints.
    pub fn text(&self) -> String {
        let mut out = String::new();
        let _ = writeln!(
            out,
            "proven ranges for any input in the ADC's range [{}, {}] °/s, a record of {} samples and up to {} bw_sel switches:",
            self.input.lo, self.input.hi, self.samples, self.switches
        );
        let range_of = |row: &Row| format!("[{:.6}, {:.6}]", row.node.range.lo, row.node.range.hi);
        // The widest range sets the column (the CIC's comb holds ±2·10⁹ FS).
        let width = self
            .rows
            .iter()
            .map(|row| range_of(row).chars().count())
            .max()
            .unwrap_or(0)
            .max(27);
        let _ = writeln!(
            out,
            "{:<22} {:>width$} {:<13}  {:>9}  {:>9}  status",
            "node", "range", "unit", "proven", "config"
        );
        for row in &self.rows {
            let node = &row.node;
            let spare = node.integer_bits() - node.needed_integer_bits();
            let status = if !node.fits() {
                format!(
                    "OVERFLOW POSSIBLE: needs {} more integer bit{} ({})",
                    -spare,
                    if spare == -1 { "" } else { "s" },
                    match (row.key, row.shared) {
                        (Some(key), _) => format!("set {key}"),
                        (None, Some(why)) => why.to_string(),
                        (None, None) => "derived by bit growth".to_string(),
                    }
                )
            } else if node.exact {
                "exact (bit growth)".to_string()
            } else if spare > 0 {
                format!(
                    "proven; {spare} integer bit{} to spare",
                    if spare == 1 { "" } else { "s" }
                )
            } else {
                "proven, tight".to_string()
            };
            let _ = writeln!(
                out,
                "{:<22} {:>width$} {:<13}  {:>9}  {:>9}  {status}",
                node.name,
                range_of(row),
                row.unit,
                row.proven().to_string(),
                node.format.to_string(),
            );
        }
        let _ = writeln!(
            out,
            "loop: for any code of the loop's ADC [{}, {}] FS and any NCO reference (a held one too), both gyros' designs; ranges assume the nodes before them hold theirs, as after --write",
            self.loop_input.lo, self.loop_input.hi
        );
        let _ = writeln!(
            out,
            "kf: one bw_sel switch can move x1 and x2 by {:.3e} °/s (the eigenvalue-1 direction is never corrected); the state format {}",
            self.per_switch_dps,
            match self.kf_state_limit {
                Some(n) if n >= 1 << 62 => "is proven for any record length".to_string(),
                Some(n) if n >= self.samples => format!("is proven for this record, and up to {n} samples at this switch count (worst-case rounding, all one way)"),
                Some(n) => format!("is proven only for records up to {n} samples at this switch count (worst-case rounding, all one way), not this one"),
                None => "is not proven for any record at this switch count".to_string(),
            }
        );
        let _ = writeln!(
            out,
            "errors against the float model: kf output ≤ {:.3} LSB after this record; bias ≤ {:.3} LSB",
            self.kf_output_error_lsb, self.bias_error_lsb
        );
        for (block, what) in NOT_ANALYSED {
            let _ = writeln!(out, "hand-set, not analysed: [{block}] {what}");
        }
        out
    }

    /// The analysis as JSON.
    pub fn json(&self) -> serde_json::Value {
        let nodes: Vec<_> = self
            .rows
            .iter()
            .map(|row| {
                let node = &row.node;
                json!({
                    "node": node.name,
                    "what": node.what,
                    "range_dps": [node.range.lo, node.range.hi],
                    "unit": row.unit,
                    "format": node.format.to_string(),
                    "proven_format": row.proven().to_string(),
                    "needed_integer_bits": node.needed_integer_bits(),
                    "integer_bits": node.integer_bits(),
                    "fits": node.fits(),
                    "exact": node.exact,
                    "config_key": row.key,
                    "not_written": row.shared,
                })
            })
            .collect();
        json!({
            "input_range_dps": [self.input.lo, self.input.hi],
            "samples": self.samples,
            "switches": self.switches,
            "nodes": nodes,
            "kf": {
                "per_switch_dps": self.per_switch_dps,
                "output_error_bound_lsb": self.kf_output_error_lsb,
                "state_proven_up_to_samples": self.kf_state_limit,
            },
            "estimator": {"bias_error_bound_lsb": self.bias_error_lsb},
            "loop": {"input_range_fs": [self.loop_input.lo, self.loop_input.hi]},
            "hand_set": NOT_ANALYSED.iter().map(|(block, what)| json!({"block": block, "formats": what})).collect::<Vec<_>>(),
        })
    }

    /// `config` with every configured node's proven format (those `--write` may set; nodes
    /// sharing a key get the widest of theirs), and the fraction bits of `budget` when one is
    /// given, checked by resolving it as `generate` would.
    ///
    /// # Errors
    /// The derived config does not resolve (a format the blocks refuse).
    pub fn derived_config(&self, config: &Config, budget: Option<&Budget>) -> Result<Config> {
        let mut derived = config.clone();
        let mut proven: Vec<(&str, Format)> = Vec::new();
        for row in self.rows.iter().filter(|r| r.shared.is_none()) {
            let Some(key) = row.key else { continue };
            let format = row.proven();
            match proven.iter_mut().find(|(k, _)| *k == key) {
                // Rows of one key share its fraction bits: the wider holds both.
                Some((_, widest)) if format.width > widest.width => *widest = format,
                Some(_) => {}
                None => proven.push((key, format)),
            }
        }
        for (key, format) in proven {
            set_format(&mut derived, key, format);
        }
        if let Some(budget) = budget {
            derived.estimator.mean_format = budget.mean.to_string();
            derived.estimator.bias_format = budget.bias.to_string();
            derived.kf.state_format = budget.state.to_string();
            derived.mean_filter.reciprocal_width = budget.mean_filter_reciprocal_width;
        }
        Job::new(derived.clone()).map_err(|e| Error::Config {
            field: "derived formats".into(),
            value: String::new(),
            allowed: format!("a config the blocks accept: {e}"),
        })?;
        Ok(derived)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn default_job() -> Job {
        Job::new(Config::embedded()).unwrap()
    }

    /// The budget search meets the budget with the fewest state guard bits for its estimator
    /// formats: one fraction bit fewer in the state misses it.
    #[test]
    fn the_chosen_fractions_meet_the_budget_and_one_bit_less_does_not() {
        let job = default_job();
        for budget_lsb in [1.6, 2.0, 3.0, 10.0] {
            let budget = fractions_for(&job, 10_000, 10, budget_lsb).unwrap();
            assert!(budget.bound_lsb <= budget_lsb, "{budget:?}");
            let est = estimator_at(&job, budget.mean.frac).unwrap();
            assert_eq!(est.mean, budget.mean);
            if budget.state.frac > job.chain.kf.output.frac {
                let kf = kf_at(&job, budget.state.frac - 1, 10_000, 10).unwrap();
                let plan = chain::Plan::new(est, kf).unwrap();
                assert!(
                    plan.rate_error_bound_lsb(10_000, 10) > budget_lsb,
                    "{budget:?}"
                );
            }
            // Every chosen format holds its proven range.
            let kf = kf_at(&job, budget.state.frac, 10_000, 10).unwrap();
            let ranges = range::kf(&kf, Interval::of_format(kf.input), 10_000, 10);
            assert!(ranges
                .nodes
                .iter()
                .find(|n| n.name == "kf.state")
                .unwrap()
                .fits());
        }
    }

    /// The mean filter's reciprocal word is the narrowest meeting the budget: one bit narrower
    /// misses it; a wider budget never asks for a wider word.
    #[test]
    fn the_mean_filters_reciprocal_is_the_narrowest_meeting_the_budget() {
        let job = default_job();
        let bound_at = |width: u32| {
            let mut spec = job.settings.mean_filter;
            spec.reciprocal_width = width;
            gyrofx_model::mean_filter::Plan::new(&spec)
                .unwrap()
                .error_bound_lsb()
        };
        let mut previous = u32::MAX;
        for budget_lsb in [1.6, 2.0, 3.0, 10.0, 1000.0] {
            let budget = fractions_for(&job, 10_000, 10, budget_lsb).unwrap();
            let width = budget.mean_filter_reciprocal_width;
            // The same °/s budget in the filter's LSB (its output format is the KF's here).
            assert_eq!(job.mean_filter.output.lsb(), job.chain.kf.output.lsb());
            assert!(budget.mean_filter_bound_lsb <= budget_lsb, "{budget:?}");
            assert_eq!(budget.mean_filter_bound_lsb, bound_at(width));
            assert!(width == 4 || bound_at(width - 1) > budget_lsb, "{budget:?}");
            assert!(width <= previous, "{budget_lsb}: {width} after {previous}");
            previous = width;
        }
        // The filter's own output rounding (0.5 LSB) is below the chain's floor (1.5 LSB), so
        // any budget the chain accepts the filter can meet.
        assert!(bound_at(64) < 1.5);
    }

    #[test]
    fn budgets_below_the_fixed_roundings_are_refused_naming_the_floor() {
        let job = default_job();
        let message = fractions_for(&job, 1000, 0, 1.0).unwrap_err();
        assert!(
            message.contains("--output-error 1 LSB is not allowed: more than 1.5"),
            "{message}"
        );
        assert!(fractions_for(&job, 1000, 0, f64::NAN).is_err());
    }
}
