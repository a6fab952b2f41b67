//! The bias estimator: mode-reversal bias estimation and calibration.

pub mod config;
