//! The state-machine sequencer of mode reversal (SPEC §1.2, paper 004 Figure 5).
//!
//! # What it does
//!
//! Time is cut into measurement intervals of `L` samples; a cycle (a *window* for the bias
//! estimator) is `W` intervals. In interval `i` gyro A runs in mode `pattern[i]` (+1 normal,
//! −1 reversed) and gyro B in the opposite mode, so at every moment one gyro is normal and the
//! other reversed. With a stagger of `S` samples, B's whole schedule runs `S` samples behind
//! A's, so that while one gyro settles after its switch the other is valid and the combined
//! output is uninterrupted.
//!
//! The first `M` samples of **every** interval are blanked (the mode-switch transient):
//! they do not enter the interval means, and the gyro's calibrated output is invalid. In the
//! alternating pattern every interval starts with a switch; in ABBA half of them do — blanking
//! them all keeps one valid count `L − M` per interval, so the means need one reciprocal.
//!
//! # Implementation
//!
//! Each gyro has a position `t` in `0..W·L` in the cycle, kept as a phase counter `t % L` and
//! an interval counter `t / L`: A's starts at 0 after reset, B's at `W·L − S` (B begins `S`
//! samples into the tail of a virtual previous cycle). A sample is blanked when
//! `phase < M`, its interval done when `phase = L − 1`. A window is done at the end of B's last
//! interval, counted only once B has started a full cycle (never on B's partial first one).
//!
//! # Interface (RTL `hdl/gyrofx_sequencer.v`), all for the current sample, 0 clocks latency
//!
//! | port | format | meaning |
//! |------|--------|---------|
//! | `mode_a`, `mode_b` | 1 bit | 1 = normal (+1), 0 = reversed (−1) |
//! | `blank_a`, `blank_b` | 1 bit | the sample is in the first `M` of its interval |
//! | `interval_a`, `interval_b` | `u⌈log2 W⌉` | interval index in the cycle |
//! | `done_a`, `done_b` | 1 bit | last sample of the gyro's interval |
//! | `window_done` | 1 bit | last sample of a complete window (B's last interval) |

/// Mode pattern of gyro A over a cycle.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Pattern {
    /// `+, −, +, −, …` (paper 004).
    Alternating,
    /// `+, −, −, +` repeated (W a multiple of 4): cancels a linearly varying rate.
    Abba,
}

impl Pattern {
    /// Config name.
    pub fn name(&self) -> &'static str {
        match self {
            Pattern::Alternating => "alternating",
            Pattern::Abba => "abba",
        }
    }

    /// A's mode (+1 / −1) in each of the `intervals` intervals.
    pub fn modes(&self, intervals: usize) -> Vec<i8> {
        (0..intervals)
            .map(|i| match self {
                Pattern::Alternating => {
                    if i % 2 == 0 {
                        1
                    } else {
                        -1
                    }
                }
                Pattern::Abba => {
                    if i % 4 == 0 || i % 4 == 3 {
                        1
                    } else {
                        -1
                    }
                }
            })
            .collect()
    }
}

/// Sequencer parameters.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Schedule {
    /// `L`: samples per measurement interval.
    pub interval_length: usize,
    /// `W`: intervals per cycle (the estimator's window).
    pub intervals: usize,
    /// A's mode pattern.
    pub pattern: Pattern,
    /// `M`: blanked samples at the start of each interval.
    pub blank: usize,
    /// `S`: samples by which B's schedule runs behind A's.
    pub stagger: usize,
}

/// Errors of a schedule: each names the parameter, its value and what is allowed.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum ScheduleError {
    /// A parameter outside its range.
    #[error("{name} = {value} is not allowed: {allowed}")]
    Range {
        /// The parameter.
        name: &'static str,
        /// Its value.
        value: usize,
        /// What is allowed.
        allowed: String,
    },
}

impl Schedule {
    /// Checks the parameters.
    ///
    /// # Errors
    /// [`ScheduleError::Range`] for `L = 0`, `W < 2`, `M >= L`, `S >= L`, an ABBA window that
    /// is not a multiple of 4, or a cycle beyond 2^31 samples.
    pub fn validate(&self) -> Result<(), ScheduleError> {
        let range = |name, value, allowed: String| {
            Err(ScheduleError::Range {
                name,
                value,
                allowed,
            })
        };
        if self.interval_length == 0 {
            return range("interval_length", 0, "at least 1 sample".into());
        }
        if self.intervals < 2 || self.intervals > 256 {
            return range(
                "intervals",
                self.intervals,
                "2..=256 intervals per window".into(),
            );
        }
        if self.pattern == Pattern::Abba && !self.intervals.is_multiple_of(4) {
            return range(
                "intervals",
                self.intervals,
                "a multiple of 4 for the abba pattern".into(),
            );
        }
        if self.blank >= self.interval_length {
            return range(
                "blank",
                self.blank,
                format!("less than interval_length = {}", self.interval_length),
            );
        }
        if self.stagger >= self.interval_length {
            return range(
                "stagger",
                self.stagger,
                format!("less than interval_length = {}", self.interval_length),
            );
        }
        if self.cycle_length() > 1 << 31 {
            return range(
                "interval_length",
                self.interval_length,
                "a cycle of at most 2^31 samples".into(),
            );
        }
        Ok(())
    }

    /// Samples per cycle, `W·L`.
    pub fn cycle_length(&self) -> usize {
        self.interval_length * self.intervals
    }

    /// Valid samples per interval, `L − M`.
    pub fn valid_count(&self) -> usize {
        self.interval_length - self.blank
    }

    /// Bits of an interval index, at least 1.
    pub fn interval_bits(&self) -> u32 {
        (usize::BITS - (self.intervals - 1).leading_zeros()).max(1)
    }

    /// Bits of a position counter.
    pub fn position_bits(&self) -> u32 {
        (usize::BITS - (self.cycle_length() - 1).leading_zeros()).max(1)
    }
}

/// What the sequencer says about one sample.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub struct Slot {
    /// A's mode, +1 or −1.
    pub mode_a: i8,
    /// B's mode, +1 or −1.
    pub mode_b: i8,
    /// A's sample is blanked.
    pub blank_a: bool,
    /// B's sample is blanked.
    pub blank_b: bool,
    /// A's interval index.
    pub interval_a: usize,
    /// B's interval index.
    pub interval_b: usize,
    /// Last sample of A's interval.
    pub done_a: bool,
    /// Last sample of B's interval.
    pub done_b: bool,
    /// Last sample of a complete window.
    pub window_done: bool,
}

/// The sequencer model: call [`Sequencer::advance`] once per sample. Like the RTL it keeps a
/// phase and an interval counter per gyro (no division per sample).
#[derive(Clone, Debug)]
pub struct Sequencer {
    schedule: Schedule,
    modes: Vec<i8>,
    /// Phase in the interval and interval index, of A and of B.
    phase: [usize; 2],
    interval: [usize; 2],
    /// B has started a full cycle since reset.
    b_started: bool,
}

impl Sequencer {
    /// A sequencer in its reset state. The schedule must be valid ([`Schedule::validate`]).
    pub fn new(schedule: &Schedule) -> Self {
        let mut s = Sequencer {
            modes: schedule.pattern.modes(schedule.intervals),
            schedule: schedule.clone(),
            phase: [0; 2],
            interval: [0; 2],
            b_started: false,
        };
        s.reset();
        s
    }

    /// Synchronous reset: A at position 0, B at `W·L − S`.
    pub fn reset(&mut self) {
        let s = &self.schedule;
        let b_start = (s.cycle_length() - s.stagger) % s.cycle_length();
        self.phase = [0, b_start % s.interval_length];
        self.interval = [0, b_start / s.interval_length];
        self.b_started = s.stagger == 0;
    }

    /// The slot of the current sample, then advances to the next sample.
    #[inline(always)]
    pub fn advance(&mut self) -> Slot {
        let s = &self.schedule;
        let last_phase = s.interval_length - 1;
        if self.phase[1] == 0 && self.interval[1] == 0 {
            self.b_started = true;
        }
        let done = [self.phase[0] == last_phase, self.phase[1] == last_phase];
        let slot = Slot {
            mode_a: self.modes[self.interval[0]],
            mode_b: -self.modes[self.interval[1]],
            blank_a: self.phase[0] < s.blank,
            blank_b: self.phase[1] < s.blank,
            interval_a: self.interval[0],
            interval_b: self.interval[1],
            done_a: done[0],
            done_b: done[1],
            window_done: done[1] && self.interval[1] == s.intervals - 1 && self.b_started,
        };
        for ((phase, interval), done) in self.phase.iter_mut().zip(&mut self.interval).zip(done) {
            if done {
                *phase = 0;
                *interval = if *interval == s.intervals - 1 {
                    0
                } else {
                    *interval + 1
                };
            } else {
                *phase += 1;
            }
        }
        slot
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn schedule(l: usize, w: usize, pattern: Pattern, m: usize, s: usize) -> Schedule {
        Schedule {
            interval_length: l,
            intervals: w,
            pattern,
            blank: m,
            stagger: s,
        }
    }

    #[test]
    fn one_gyro_normal_the_other_reversed_without_stagger() {
        let mut seq = Sequencer::new(&schedule(5, 4, Pattern::Alternating, 2, 0));
        let slots: Vec<Slot> = (0..60).map(|_| seq.advance()).collect();
        for (k, s) in slots.iter().enumerate() {
            assert_eq!(s.mode_a, -s.mode_b, "sample {k}");
            assert_eq!(s.mode_a, if (k / 5) % 2 == 0 { 1 } else { -1 });
            assert_eq!(s.blank_a, k % 5 < 2);
            assert_eq!(s.done_a, k % 5 == 4);
            assert_eq!(s.window_done, k % 20 == 19, "sample {k}");
        }
    }

    #[test]
    fn abba_pattern() {
        assert_eq!(Pattern::Abba.modes(8), vec![1, -1, -1, 1, 1, -1, -1, 1]);
        assert_eq!(Pattern::Alternating.modes(3), vec![1, -1, 1]);
    }

    #[test]
    fn stagger_delays_b_and_skips_its_partial_first_window() {
        let (l, w, m, st) = (6, 2, 2, 3);
        let mut seq = Sequencer::new(&schedule(l, w, Pattern::Alternating, m, st));
        let slots: Vec<Slot> = (0..60).map(|_| seq.advance()).collect();
        for k in st..60 {
            // B does at k what A did at k - S, with the opposite mode.
            let (a, b) = (slots[k - st], slots[k]);
            assert_eq!(b.mode_b, -a.mode_a, "sample {k}");
            assert_eq!(
                (b.blank_b, b.done_b, b.interval_b),
                (a.blank_a, a.done_a, a.interval_a)
            );
        }
        // With S >= M one gyro is always valid.
        assert!(slots.iter().all(|s| !(s.blank_a && s.blank_b)));
        // The first window ends S + W·L − 1 samples in; B's partial first interval never closes one.
        let windows: Vec<usize> = (0..60).filter(|k| slots[*k].window_done).collect();
        assert_eq!(
            windows,
            vec![st + 12 - 1, st + 24 - 1, st + 36 - 1, st + 48 - 1]
        );
    }

    #[test]
    fn bad_schedules_name_the_parameter() {
        let cases = [
            (
                schedule(0, 4, Pattern::Alternating, 0, 0),
                "interval_length = 0",
            ),
            (schedule(10, 1, Pattern::Alternating, 0, 0), "intervals = 1"),
            (schedule(10, 4, Pattern::Alternating, 10, 0), "blank = 10"),
            (schedule(10, 4, Pattern::Alternating, 2, 12), "stagger = 12"),
            (schedule(10, 6, Pattern::Abba, 2, 0), "intervals = 6"),
        ];
        for (s, want) in cases {
            let err = s.validate().unwrap_err().to_string();
            assert!(err.contains(want), "{err}");
        }
        schedule(150, 4, Pattern::Alternating, 10, 0)
            .validate()
            .unwrap();
    }
}
