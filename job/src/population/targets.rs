//! The figures a population is judged by, one value per member ([`Figure`]), and targets on
//! them (`residual_dps<=0.01`, [`Target`]). A member meets a target when its figure exists and
//! satisfies it; a member that could not run or whose gyros did not both lock meets none.

use std::fmt;
use std::str::FromStr;

use super::columns::status;
use super::MemberResult;
use gyrofx_model::population::study::MemberFigures;

/// A member's figure: the worse of the two gyros where each has one.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Figure {
    /// `|residual bias after reversal|` of the characterization, the larger gyro's, °/s.
    ResidualDps,
    /// `|bias|` in either mode, the largest, °/s.
    BiasDps,
    /// `|scale factor − 1|` in either mode, the largest (fraction).
    ScaleFactorError,
    /// Rate settling after a switch into either mode, the longest, ms.
    SettlingMs,
    /// Lock time at start-up, the longer gyro's, ms.
    LockMs,
    /// `|mean|` of the chain's calibrated output at rest, °/s.
    OutputMeanDps,
    /// Standard deviation of the chain's calibrated output, °/s.
    OutputStdDps,
    /// Saturations of both loops while figures were measured and in the chain samples the
    /// estimator takes, and the chain's overflows.
    Saturations,
    /// ARW of the calibrated output, °/√h (with noise).
    ArwDegPerSqrtH,
    /// Bias instability of the calibrated output, °/h (with noise).
    BiasInstabilityDegPerH,
}

impl Figure {
    /// Every figure.
    pub const ALL: [Figure; 10] = [
        Figure::ResidualDps,
        Figure::BiasDps,
        Figure::ScaleFactorError,
        Figure::SettlingMs,
        Figure::LockMs,
        Figure::OutputMeanDps,
        Figure::OutputStdDps,
        Figure::Saturations,
        Figure::ArwDegPerSqrtH,
        Figure::BiasInstabilityDegPerH,
    ];

    /// Its name in targets and in `summary.json`.
    pub fn name(self) -> &'static str {
        match self {
            Figure::ResidualDps => "residual_dps",
            Figure::BiasDps => "bias_dps",
            Figure::ScaleFactorError => "scale_factor_error",
            Figure::SettlingMs => "settling_ms",
            Figure::LockMs => "lock_ms",
            Figure::OutputMeanDps => "output_mean_dps",
            Figure::OutputStdDps => "output_std_dps",
            Figure::Saturations => "saturations",
            Figure::ArwDegPerSqrtH => "arw_deg_per_sqrt_h",
            Figure::BiasInstabilityDegPerH => "bias_instability_deg_per_h",
        }
    }

    /// Its value for `figures`.
    pub fn of(self, f: &MemberFigures) -> Option<f64> {
        let per_gyro = |read: &dyn Fn(usize) -> Option<f64>| -> Option<f64> {
            let (a, b) = (read(0)?, read(1)?);
            Some(a.max(b))
        };
        let modes = |g: usize| {
            [
                &f.gyros[g].characterization.normal,
                &f.gyros[g].characterization.reverse,
            ]
        };
        match self {
            Figure::ResidualDps => {
                per_gyro(&|g| Some(f.gyros[g].characterization.residual_bias_dps.measured.abs()))
            }
            Figure::BiasDps => per_gyro(&|g| {
                Some(
                    modes(g)
                        .iter()
                        .map(|m| m.bias_dps.measured.abs())
                        .fold(0.0, f64::max),
                )
            }),
            Figure::ScaleFactorError => per_gyro(&|g| {
                Some(
                    modes(g)
                        .iter()
                        .map(|m| (m.scale_factor.measured - 1.0).abs())
                        .fold(0.0, f64::max),
                )
            }),
            Figure::SettlingMs => per_gyro(&|g| {
                Some(
                    modes(g)
                        .iter()
                        .map(|m| m.rate_settling_ms.measured)
                        .fold(0.0, f64::max),
                )
            }),
            Figure::LockMs => per_gyro(&|g| f.gyros[g].lock.lock_ms),
            Figure::OutputMeanDps => f.chain.output_mean_dps.map(f64::abs),
            Figure::OutputStdDps => f.chain.output_std_dps,
            Figure::Saturations => Some(
                f.gyros
                    .iter()
                    .map(|g| {
                        g.characterization.normal.saturations.total()
                            + g.characterization.reverse.saturations.total()
                            + g.saturations_used
                    })
                    .sum::<u64>() as f64
                    + f.chain.chain_overflows as f64,
            ),
            Figure::ArwDegPerSqrtH => f.chain.arw_deg_per_sqrt_h,
            Figure::BiasInstabilityDegPerH => f.chain.bias_instability_deg_per_h,
        }
    }

    /// Its value for a member: `None` when the member could not run.
    pub fn of_member(self, result: &MemberResult) -> Option<f64> {
        result.figures.as_ref().ok().and_then(|f| self.of(f))
    }
}

impl FromStr for Figure {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        Figure::ALL
            .into_iter()
            .find(|f| f.name() == s)
            .ok_or_else(|| {
                let names: Vec<&str> = Figure::ALL.iter().map(|f| f.name()).collect();
                format!("{s:?} is not a figure; one of {}", names.join(", "))
            })
    }
}

/// What the targets and the summary take of a member: its status and its [`Figure`]s. Plain
/// data (a word and ten numbers), so that a member studied elsewhere (a Python worker on a
/// cluster) is judged and summed as one studied here.
#[derive(Clone, Debug, PartialEq)]
pub struct Record {
    /// [`status`]: `ok`, `unlocked` or `invalid`.
    pub status: &'static str,
    /// Each of [`Figure::ALL`], in that order (`None`: the member has none).
    pub figures: [Option<f64>; Figure::ALL.len()],
}

impl Record {
    /// The record of `result`.
    pub fn of(result: &MemberResult) -> Record {
        Record {
            status: status(result),
            figures: Figure::ALL.map(|figure| figure.of_member(result)),
        }
    }

    /// A record from its parts, as [`Record::of`] gave them.
    ///
    /// # Errors
    /// A status other than the three, or not one figure per [`Figure::ALL`].
    pub fn new(status: &str, figures: &[Option<f64>]) -> Result<Record, String> {
        let status = ["ok", "unlocked", "invalid"]
            .into_iter()
            .find(|s| *s == status)
            .ok_or_else(|| format!("status {status:?} is not one of ok, unlocked, invalid"))?;
        let figures = figures.try_into().map_err(|_| {
            format!(
                "{} figures given: one per figure, {}",
                figures.len(),
                Figure::ALL.len()
            )
        })?;
        Ok(Record { status, figures })
    }

    /// Its value of `figure`.
    pub fn figure(&self, figure: Figure) -> Option<f64> {
        let index = Figure::ALL
            .iter()
            .position(|f| *f == figure)
            .expect("a figure");
        self.figures[index]
    }
}

/// A comparison.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Comparison {
    /// `<=`
    AtMost,
    /// `>=`
    AtLeast,
    /// `<`
    Below,
    /// `>`
    Above,
}

impl Comparison {
    fn symbol(self) -> &'static str {
        match self {
            Comparison::AtMost => "<=",
            Comparison::AtLeast => ">=",
            Comparison::Below => "<",
            Comparison::Above => ">",
        }
    }
}

/// A target on a figure: `residual_dps<=0.01` (`<=`, `>=`, `<` or `>` and a finite number in
/// the figure's unit).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Target {
    /// The figure.
    pub figure: Figure,
    /// How it compares.
    pub comparison: Comparison,
    /// With what.
    pub bound: f64,
}

impl Target {
    /// Whether `value` meets the target.
    pub fn met_by(&self, value: f64) -> bool {
        match self.comparison {
            Comparison::AtMost => value <= self.bound,
            Comparison::AtLeast => value >= self.bound,
            Comparison::Below => value < self.bound,
            Comparison::Above => value > self.bound,
        }
    }

    /// Whether a member meets it: it ran, both gyros locked and its figure meets it.
    pub fn met_by_member(&self, result: &MemberResult) -> bool {
        self.met_by_record(&Record::of(result))
    }

    /// [`Target::met_by_member`] from the member's [`Record`].
    pub fn met_by_record(&self, record: &Record) -> bool {
        record.status == "ok" && record.figure(self.figure).is_some_and(|v| self.met_by(v))
    }
}

impl fmt::Display for Target {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "{}{}{}",
            self.figure.name(),
            self.comparison.symbol(),
            self.bound
        )
    }
}

impl FromStr for Target {
    type Err = String;
    /// # Errors
    /// A sentence naming what is wrong and what is allowed.
    fn from_str(s: &str) -> Result<Self, String> {
        let syntax = "FIGURE<=NUMBER (or >=, <, >), e.g. residual_dps<=0.01";
        let position = s
            .find(['<', '>'])
            .ok_or_else(|| format!("target {s:?} has no comparison: {syntax}"))?;
        let (name, rest) = s.split_at(position);
        let (comparison, number) = [
            ("<=", Comparison::AtMost),
            (">=", Comparison::AtLeast),
            ("<", Comparison::Below),
            (">", Comparison::Above),
        ]
        .into_iter()
        .find_map(|(symbol, c)| rest.strip_prefix(symbol).map(|n| (c, n)))
        .expect("the comparison starts with < or >");
        let figure: Figure = name
            .trim()
            .parse()
            .map_err(|e| format!("target {s:?}: {e}"))?;
        let bound: f64 = number
            .trim()
            .parse()
            .ok()
            .filter(|b: &f64| b.is_finite())
            .ok_or_else(|| {
                format!(
                    "target {s:?}: {:?} is not a finite number: {syntax}",
                    number.trim()
                )
            })?;
        Ok(Target {
            figure,
            comparison,
            bound,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn targets_parse_and_compare() {
        let t: Target = "residual_dps<=0.01".parse().unwrap();
        assert_eq!(t.figure, Figure::ResidualDps);
        assert_eq!(t.comparison, Comparison::AtMost);
        assert!(t.met_by(0.01) && t.met_by(-1.0) && !t.met_by(0.0100001));
        let t: Target = " lock_ms > 50 ".trim().parse().unwrap();
        assert!(t.met_by(50.5) && !t.met_by(50.0));
        let t: Target = "settling_ms>=1e2".parse().unwrap();
        assert_eq!(t.to_string(), "settling_ms>=100");
        assert!(t.met_by(100.0));
        assert!("output_std_dps<0.5".parse::<Target>().unwrap().met_by(0.4));
    }

    #[test]
    fn bad_targets_say_what_is_allowed() {
        for (text, needle) in [
            ("residual_dps=0.01", "has no comparison"),
            (
                "residual<=0.01",
                "\"residual\" is not a figure; one of residual_dps",
            ),
            ("residual_dps<=abc", "\"abc\" is not a finite number"),
            ("residual_dps<=inf", "is not a finite number"),
            ("residual_dps<=", "is not a finite number"),
        ] {
            let err = text.parse::<Target>().unwrap_err();
            assert!(err.contains(needle), "{text}: {err}");
        }
    }
}
