//! `--target METRIC<=LIMIT`: what a candidate must meet to be chosen.

use super::measure::Metrics;

/// A metric of [`Metrics`] a target can bound.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Metric {
    /// [`Metrics::arw_share`]: the quantization noise's ARW over the sensor's.
    ArwShare,
    /// [`Metrics::adev_share`]: the quantization noise's ADEV at 1 s over the output's.
    AdevShare,
    /// [`Metrics::max_lsb`].
    MaxErrorLsb,
    /// [`Metrics::rms_lsb`].
    RmsErrorLsb,
    /// [`Metrics::max_dps`].
    MaxErrorDps,
    /// [`Metrics::rms_dps`].
    RmsErrorDps,
}

impl Metric {
    /// Every metric, in the order the help lists them.
    pub const ALL: [Metric; 6] = [
        Metric::ArwShare,
        Metric::AdevShare,
        Metric::MaxErrorLsb,
        Metric::RmsErrorLsb,
        Metric::MaxErrorDps,
        Metric::RmsErrorDps,
    ];

    /// Its name on the command line.
    pub fn name(self) -> &'static str {
        match self {
            Metric::ArwShare => "arw-share",
            Metric::AdevShare => "adev-share",
            Metric::MaxErrorLsb => "max-error-lsb",
            Metric::RmsErrorLsb => "rms-error-lsb",
            Metric::MaxErrorDps => "max-error-dps",
            Metric::RmsErrorDps => "rms-error-dps",
        }
    }

    /// Its CSV column.
    pub fn column(self) -> &'static str {
        match self {
            Metric::ArwShare => "arw_share",
            Metric::AdevShare => "adev_share",
            Metric::MaxErrorLsb => "error_max_lsb",
            Metric::RmsErrorLsb => "error_rms_lsb",
            Metric::MaxErrorDps => "error_max_dps",
            Metric::RmsErrorDps => "error_rms_dps",
        }
    }

    /// What it is, with its unit (the plots' axis).
    pub fn label(self) -> &'static str {
        match self {
            Metric::ArwShare => "quantization ARW / sensor ARW",
            Metric::AdevShare => "quantization ADEV(1 s) / output ADEV(1 s)",
            Metric::MaxErrorLsb => "max |fixed − float| (output LSB)",
            Metric::RmsErrorLsb => "rms fixed − float (output LSB)",
            Metric::MaxErrorDps => "max |fixed − float| (°/s)",
            Metric::RmsErrorDps => "rms fixed − float (°/s)",
        }
    }

    /// Its value in `metrics`.
    pub fn of(self, metrics: &Metrics) -> f64 {
        match self {
            Metric::ArwShare => metrics.arw_share,
            Metric::AdevShare => metrics.adev_share,
            Metric::MaxErrorLsb => metrics.max_lsb,
            Metric::RmsErrorLsb => metrics.rms_lsb,
            Metric::MaxErrorDps => metrics.max_dps,
            Metric::RmsErrorDps => metrics.rms_dps,
        }
    }
}

/// `METRIC<=LIMIT`: a candidate meets it when its metric is at most the limit.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Target {
    /// What is bounded.
    pub metric: Metric,
    /// The bound, in the metric's unit (≥ 0, finite).
    pub limit: f64,
}

impl Default for Target {
    /// `arw-share<=0.01`: quantization noise at most 1 % of the sensor's ARW.
    fn default() -> Self {
        Target {
            metric: Metric::ArwShare,
            limit: 0.01,
        }
    }
}

impl std::fmt::Display for Target {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}<={}", self.metric.name(), self.limit)
    }
}

impl std::str::FromStr for Target {
    type Err = String;

    /// Parses `METRIC<=LIMIT`, e.g. `arw-share<=0.01`: a known metric, `<=`, a finite number
    /// ≥ 0. Spaces around the parts are allowed; nothing else is.
    fn from_str(text: &str) -> Result<Target, String> {
        let names: Vec<&str> = Metric::ALL.iter().map(|m| m.name()).collect();
        let shape = format!(
            "METRIC<=LIMIT with METRIC one of {} and LIMIT a number >= 0, e.g. arw-share<=0.01",
            names.join(", ")
        );
        let refuse = |why: String| format!("--target {text} is not allowed: {why}");
        let Some((name, limit)) = text.split_once("<=") else {
            return Err(refuse(format!("no '<=': give {shape}")));
        };
        let name = name.trim();
        let Some(metric) = Metric::ALL.into_iter().find(|m| m.name() == name) else {
            return Err(refuse(format!("'{name}' is not a metric: give {shape}")));
        };
        let limit = limit.trim();
        match limit.parse::<f64>() {
            Ok(value) if value.is_finite() && value >= 0.0 => Ok(Target {
                metric,
                limit: value,
            }),
            _ => Err(refuse(format!(
                "'{limit}' is not a limit: give a finite number >= 0 in the metric's unit ({})",
                metric.label()
            ))),
        }
    }
}

impl Target {
    /// Whether `metrics` meet it.
    pub fn met(&self, metrics: &Metrics) -> bool {
        self.metric.of(metrics) <= self.limit
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn targets_parse_strictly() {
        let t: Target = "rms-error-dps <= 1e-5".parse().unwrap();
        assert_eq!(t.metric, Metric::RmsErrorDps);
        assert_eq!(t.limit, 1e-5);
        assert_eq!(Target::default().to_string(), "arw-share<=0.01");
        for (text, says) in [
            ("arw-share<0.01", "no '<='"),
            ("noise<=0.01", "'noise' is not a metric"),
            ("arw-share<=-1", "'-1' is not a limit"),
            ("arw-share<=nan", "'nan' is not a limit"),
            ("arw-share<=", "'' is not a limit"),
        ] {
            let message = text.parse::<Target>().unwrap_err();
            assert!(
                message.starts_with(&format!("--target {text} is not allowed: ")),
                "{message}"
            );
            assert!(message.contains(says), "{text}: {message}");
        }
    }
}
