//! The Kalman filter: a ROM of steady-state gains per bandwidth.

pub mod config;
