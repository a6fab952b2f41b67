//! `gyrofx formats`: the proven range of every analysed quantization point of a job, the
//! integer bits that make overflow impossible for any input inside the ADC's range, and the
//! config with those formats.
//!
//! The analysis is [`gyrofx_model::range`] (worst-case peak gain of each linear block, interval
//! arithmetic for the estimator and calibration); here it is applied to the job's plans, named
//! by config key, and printed. Covered: the estimator, the calibration and the KF (the chain
//! from the gyros' samples to the KF's output). Not yet: the mean filter and the gyro loop's
//! points (their formats stay hand-set; the table says so).

use std::fmt::Write as _;

use gyrofx_model::fx::Format;
use gyrofx_model::kf::bound::rate_error_bound_lsb;
use gyrofx_model::range::{self, Interval, NodeRange};
use serde_json::json;

use crate::config::Config;
use crate::error::{Error, Result};
use crate::job::Job;

/// One analysed node.
#[derive(Clone, Debug)]
pub struct Row {
    /// What the analysis proved.
    pub node: NodeRange,
    /// The config key that sets its format, when one does (exact nodes follow by bit growth).
    pub key: Option<&'static str>,
    /// Why the node is not written by `--write`, when it has a key.
    pub shared: Option<&'static str>,
}

impl Row {
    /// The proven format: the configured fraction bits and the integer bits the range needs.
    pub fn proven(&self) -> Format {
        let frac = self.node.format.frac;
        let integer = self.node.needed_integer_bits();
        Format {
            signed: true,
            width: (integer + frac).max(1) as u32,
            frac,
        }
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

/// Blocks whose formats the analysis does not cover yet: they are reported as hand-set.
pub const NOT_ANALYSED: [(&str, &str); 2] = [
    (
        "mean_filter",
        "output_format, reciprocal_width (gross-error rejection: its kept subset is data-dependent)",
    ),
    (
        "loop",
        "demodulator, PLL, AGC, CIC and output formats of the resonator-level loop",
    ),
];

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
            Row { node, key, shared }
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
        }
    }));
    let state_fits = |n: u64| {
        range::kf(&chain.kf, Interval::of_format(chain.kf.input), n, switches)
            .nodes
            .iter()
            .find(|node| node.name == "kf.state")
            .is_some_and(NodeRange::fits)
    };
    let kf_state_limit = state_fits(0).then(|| longest(state_fits));
    Analysis {
        samples,
        switches,
        input,
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
        let _ = writeln!(
            out,
            "{:<22} {:>27}  {:>9}  {:>9}  status",
            "node", "range (°/s)", "proven", "config"
        );
        for row in &self.rows {
            let node = &row.node;
            let spare = node.integer_bits() - node.needed_integer_bits();
            let status = if !node.fits() {
                format!(
                    "OVERFLOW POSSIBLE: needs {} more integer bit{} ({})",
                    -spare,
                    if spare == -1 { "" } else { "s" },
                    row.key
                        .map_or("derived by bit growth".to_string(), |k| format!("set {k}"))
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
                "{:<22} {:>27}  {:>9}  {:>9}  {status}",
                node.name,
                format!("[{:.6}, {:.6}]", node.range.lo, node.range.hi),
                row.proven().to_string(),
                node.format.to_string(),
            );
        }
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
            "hand_set": NOT_ANALYSED.iter().map(|(block, what)| json!({"block": block, "formats": what})).collect::<Vec<_>>(),
        })
    }

    /// `config` with every configured node's proven format (those a key sets alone), checked
    /// by resolving it as `generate` would.
    ///
    /// # Errors
    /// The derived config does not resolve (a format the blocks refuse).
    pub fn derived_config(&self, config: &Config) -> Result<Config> {
        let mut derived = config.clone();
        for row in &self.rows {
            if row.shared.is_some() {
                continue;
            }
            let proven = row.proven().to_string();
            match row.key {
                Some("estimator.mean_format") => derived.estimator.mean_format = proven,
                Some("estimator.bias_format") => derived.estimator.bias_format = proven,
                Some("kf.state_format") => derived.kf.state_format = proven,
                Some("kf.output_format") => derived.kf.output_format = proven,
                _ => {}
            }
        }
        Job::new(derived.clone()).map_err(|e| Error::Config {
            field: "derived formats".into(),
            value: String::new(),
            allowed: format!("a config the blocks accept: {e}"),
        })?;
        Ok(derived)
    }
}
