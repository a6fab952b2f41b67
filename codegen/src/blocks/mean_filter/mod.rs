//! The mean filter with gross-error rejection.

pub mod config;
