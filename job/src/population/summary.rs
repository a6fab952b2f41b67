//! `summary.json`: over the members, each figure's quantiles, the members by status, the
//! yield against each target and against all of them, and the yield against the sequencer's
//! blanking. Built one member at a time ([`Summary::add`]) from the figures alone: memory is a
//! few numbers per member, whatever the run's length.

use serde::Serialize;

use super::targets::{Figure, Record, Target};
use super::{MemberResult, Population, RunSettings, STARTUP_S};

/// The quantiles reported, as fractions.
pub const QUANTILES: [f64; 7] = [0.0, 0.05, 0.25, 0.5, 0.75, 0.95, 1.0];

/// The running summary.
#[derive(Clone, Debug)]
pub struct Summary {
    targets: Vec<Target>,
    values: Vec<Vec<f64>>,
    counts: Counts,
    met: Vec<u64>,
    /// Per member meeting every target: its settling (ms), for the yield against blanking.
    settling_of_good: Vec<f64>,
}

/// Members by status.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize)]
pub struct Counts {
    /// Members studied.
    pub members: u64,
    /// Both gyros locked.
    pub ok: u64,
    /// A gyro did not lock.
    pub unlocked: u64,
    /// A drawn parameter the physics refuses.
    pub invalid: u64,
}

/// One figure's distribution over the members that have it.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct FigureSummary {
    /// [`Figure::name`].
    pub figure: &'static str,
    /// Members that have it.
    pub count: usize,
    /// Its mean (`None` without members).
    pub mean: Option<f64>,
    /// `(fraction, value)` at each of [`QUANTILES`] (linear between order statistics).
    pub quantiles: Vec<(f64, f64)>,
}

/// A target's yield.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct TargetYield {
    /// The target as written back (`residual_dps<=0.01`).
    pub target: String,
    /// Members meeting it.
    pub met: u64,
    /// `met / members`.
    pub yield_fraction: f64,
}

/// The yield at one blanking.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct BlankingYield {
    /// Blanked chain samples after each switch.
    pub blank: usize,
    /// The same in ms.
    pub blank_ms: f64,
    /// Members meeting every target whose settling after a switch fits the blanking, over all
    /// members.
    pub yield_fraction: f64,
}

/// What `summary.json` holds (besides the run's settings, which the writer adds).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Report {
    /// Members by status.
    pub counts: Counts,
    /// Each figure.
    pub figures: Vec<FigureSummary>,
    /// Each target.
    pub targets: Vec<TargetYield>,
    /// Members that ran, locked and met every target, over all members.
    pub yield_fraction: f64,
    /// Against the blanking (0 to the interval length).
    pub yield_against_blanking: Vec<BlankingYield>,
}

/// The `q` quantile (0..=1) of sorted `values`, linear between order statistics.
pub fn quantile(sorted: &[f64], q: f64) -> f64 {
    let position = q * (sorted.len() - 1) as f64;
    let below = libm::floor(position) as usize;
    let above = (below + 1).min(sorted.len() - 1);
    sorted[below] + (sorted[above] - sorted[below]) * (position - below as f64)
}

impl Summary {
    /// An empty summary judging the members by `targets`.
    pub fn new(targets: &[Target]) -> Self {
        Summary {
            targets: targets.to_vec(),
            values: vec![Vec::new(); Figure::ALL.len()],
            counts: Counts::default(),
            met: vec![0; targets.len()],
            settling_of_good: Vec::new(),
        }
    }

    /// Adds a member.
    pub fn add(&mut self, result: &MemberResult) {
        self.add_record(&Record::of(result));
    }

    /// Adds a member from its [`Record`]: the same as [`Summary::add`] with its result.
    pub fn add_record(&mut self, record: &Record) {
        self.counts.members += 1;
        match record.status {
            "ok" => self.counts.ok += 1,
            "unlocked" => self.counts.unlocked += 1,
            _ => self.counts.invalid += 1,
        }
        for (value, values) in record.figures.iter().zip(&mut self.values) {
            if let Some(v) = value.filter(|v| v.is_finite()) {
                values.push(v);
            }
        }
        let mut all = record.status == "ok";
        for (target, met) in self.targets.iter().zip(&mut self.met) {
            if target.met_by_record(record) {
                *met += 1;
            } else {
                all = false;
            }
        }
        if all {
            if let Some(settling) = record.figure(Figure::SettlingMs) {
                self.settling_of_good.push(settling);
            }
        }
    }

    /// The report; `interval_length` and `chain_rate_hz` (Hz) set the blanking axis.
    pub fn report(&self, interval_length: usize, chain_rate_hz: f64) -> Report {
        let members = self.counts.members.max(1) as f64;
        let figures = Figure::ALL
            .iter()
            .zip(&self.values)
            .map(|(figure, values)| {
                let mut sorted = values.clone();
                sorted.sort_by(f64::total_cmp);
                FigureSummary {
                    figure: figure.name(),
                    count: sorted.len(),
                    mean: (!sorted.is_empty())
                        .then(|| sorted.iter().sum::<f64>() / sorted.len() as f64),
                    quantiles: if sorted.is_empty() {
                        Vec::new()
                    } else {
                        QUANTILES
                            .iter()
                            .map(|q| (*q, quantile(&sorted, *q)))
                            .collect()
                    },
                }
            })
            .collect();
        let targets = self
            .targets
            .iter()
            .zip(&self.met)
            .map(|(t, met)| TargetYield {
                target: t.to_string(),
                met: *met,
                yield_fraction: *met as f64 / members,
            })
            .collect();
        let yield_against_blanking = (0..=interval_length)
            .map(|blank| {
                let blank_ms = blank as f64 * 1e3 / chain_rate_hz;
                let fit = self
                    .settling_of_good
                    .iter()
                    .filter(|s| **s <= blank_ms)
                    .count();
                BlankingYield {
                    blank,
                    blank_ms,
                    yield_fraction: fit as f64 / members,
                }
            })
            .collect();
        Report {
            counts: self.counts,
            figures,
            targets,
            yield_fraction: self.settling_of_good.len() as f64 / members,
            yield_against_blanking,
        }
    }

    /// Each figure's values so far, in the order the members were added (for histograms).
    pub fn values(&self, figure: Figure) -> &[f64] {
        let index = Figure::ALL
            .iter()
            .position(|f| *f == figure)
            .expect("a figure");
        &self.values[index]
    }
}

/// The spreads as `summary.json` lists them, one line each (`q_drive: Normal { .. }`).
pub fn spreads(population: &Population) -> Vec<String> {
    population
        .spreads
        .iter()
        .map(|(parameter, spread)| format!("{}: {spread:?}", parameter.name()))
        .collect()
}

/// `summary.json`'s text: the run's settings (the seed, the members, `settings`, the start-up,
/// the chain rate in Hz and the spreads) and `report`, pretty-printed and `\n` ended. Nothing in
/// it depends on the threads, the machines or the clock.
pub fn json_text(
    population: &Population,
    members: u64,
    settings: &RunSettings,
    report: &Report,
) -> String {
    let json = serde_json::json!({
        "tool": "gyrofx",
        "seed": population.seed,
        "members": members,
        "seconds": settings.seconds,
        "noise": settings.noise,
        "startup_s": STARTUP_S,
        "chain_rate_hz": population.chain_rate_hz(),
        "spreads": spreads(population),
        "report": report,
    });
    serde_json::to_string_pretty(&json).expect("the summary serializes") + "\n"
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn quantiles_interpolate_between_order_statistics() {
        let sorted = [1.0, 2.0, 3.0, 4.0, 5.0];
        assert_eq!(quantile(&sorted, 0.0), 1.0);
        assert_eq!(quantile(&sorted, 0.5), 3.0);
        assert_eq!(quantile(&sorted, 1.0), 5.0);
        assert_eq!(quantile(&sorted, 0.125), 1.5);
        assert_eq!(quantile(&[7.0], 0.95), 7.0);
    }
}
