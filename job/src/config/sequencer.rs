//! `[sequencer]`: the mode-reversal schedule, validated into the model's [`Schedule`].

use serde::{Deserialize, Serialize};

use gyrofx_model::sequencer::{Pattern, Schedule, ScheduleError};

use crate::error::{Error, Result};

/// `[sequencer]`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SequencerConfig {
    /// L.
    pub interval_length: usize,
    /// W.
    pub intervals: usize,
    /// `alternating` or `abba`.
    pub pattern: String,
    /// M.
    pub blank: usize,
    /// S.
    pub stagger: usize,
}

impl SequencerConfig {
    /// Checks the pattern name, then the schedule's ranges, and returns the schedule.
    ///
    /// # Errors
    /// [`Error::Config`] naming the first bad field.
    pub fn validate(&self) -> Result<Schedule> {
        let pattern = match self.pattern.as_str() {
            "alternating" => Pattern::Alternating,
            "abba" => Pattern::Abba,
            other => {
                return Err(Error::config(
                    "sequencer.pattern",
                    format!("{other:?}"),
                    "\"alternating\" or \"abba\"",
                ))
            }
        };
        let schedule = Schedule {
            interval_length: self.interval_length,
            intervals: self.intervals,
            pattern,
            blank: self.blank,
            stagger: self.stagger,
        };
        schedule.validate().map_err(|e| match e {
            ScheduleError::Range {
                name,
                value,
                allowed,
            } => Error::config(format!("sequencer.{name}"), value, allowed),
        })?;
        Ok(schedule)
    }
}

#[cfg(test)]
mod tests {
    use crate::config::assert_refused;

    #[test]
    fn bad_sequencer_values_name_field_value_and_what_is_allowed() {
        assert_refused(&[
            (
                "[sequencer]\nblank = 150",
                "sequencer.blank = 150",
                "less than interval_length = 150",
            ),
            (
                "[sequencer]\nstagger = 200",
                "sequencer.stagger = 200",
                "less than interval_length",
            ),
            (
                "[sequencer]\ninterval_length = 0",
                "sequencer.interval_length = 0",
                "at least 1",
            ),
            (
                "[sequencer]\nintervals = 1",
                "sequencer.intervals = 1",
                "2..=256",
            ),
            (
                "[sequencer]\npattern = \"abab\"",
                "sequencer.pattern = \"abab\"",
                "abba",
            ),
        ]);
    }
}
