pub mod estimator;
pub mod kf;
pub mod mean_filter;
pub mod sequencer;
