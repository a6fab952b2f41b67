//! The sequencer: the mode-reversal schedule.

pub mod config;
