//! Each golden block's saturations and wraps per quantization point, for the bindings'
//! `overflow_counts`: what the RTL's quantizers did to the samples stepped so far.

use gyrofx_model::chain::FixedChain;
use gyrofx_model::estimator::FixedEstimator;
use gyrofx_model::gyro_loop::gyro::{FixedGyroLoop, LoopNode};
use gyrofx_model::kf::FixedKf;

/// `(quantization point, count)` in a fixed order: the values that did not fit the point's
/// format (saturated or wrapped, as the plan says) since the model was made; a reset keeps
/// them. A block with no quantizer that can overflow (the sequencer; the mean filter, whose
/// formats are proven to hold every value) has none.
pub type Overflows = Vec<(String, u64)>;

/// The KF's state registers `x1`, `x2` and its output `rate_out`.
pub(crate) fn kf(model: &FixedKf) -> Overflows {
    let counts = model.overflow_counts();
    named(&[
        ("x1", counts.x1),
        ("x2", counts.x2),
        ("rate_out", counts.rate_hat),
    ])
}

/// The estimator's interval means, bias estimates (with their smoothing), calibrated outputs
/// and combined output.
pub(crate) fn estimator(model: &FixedEstimator) -> Overflows {
    let counts = model.overflow_counts();
    named(&[
        ("mean_a", counts.mean[0]),
        ("mean_b", counts.mean[1]),
        ("bias_a", counts.bias[0]),
        ("bias_b", counts.bias[1]),
        ("calibrated_a", counts.calibrated[0]),
        ("calibrated_b", counts.calibrated[1]),
        ("combined", counts.combined),
    ])
}

/// The chain's estimator and KF, prefixed `estimator.` and `kf.`.
pub(crate) fn chain(model: &FixedChain) -> Overflows {
    let mut out = prefixed("estimator.", estimator(model.estimator()));
    out.extend(prefixed("kf.", kf(model.kf())));
    out
}

/// Every node of a gyro loop (the report's node names).
pub(crate) fn gyro_loop(model: &FixedGyroLoop) -> Overflows {
    let overflows = model.overflows();
    LoopNode::ALL
        .iter()
        .map(|node| (node.name().to_string(), overflows.get(*node)))
        .collect()
}

/// `overflows` with each point's name after `prefix`.
pub(crate) fn prefixed(prefix: &str, overflows: Overflows) -> Overflows {
    overflows
        .into_iter()
        .map(|(name, count)| (format!("{prefix}{name}"), count))
        .collect()
}

fn named(counts: &[(&str, u64)]) -> Overflows {
    counts
        .iter()
        .map(|(name, count)| (name.to_string(), *count))
        .collect()
}
