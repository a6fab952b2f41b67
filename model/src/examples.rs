//! The worked example of paper 000 that the embedded default config also describes (a codegen
//! test checks that they agree): for tests, benchmarks and documentation.

use crate::chain;
use crate::estimator;
use crate::fx::{Overflow, Rounding};
use crate::kf::design::{design_for_bandwidth, Convergence, Method, Noise};
use crate::kf::{self as kf_block, CoefficientFormat, Spec};
use crate::sequencer::{Pattern, Schedule};
use crate::stimulus::{Scenario, SingleGyro};

/// Sample rate of the example, Hz.
pub const FS_HZ: f64 = 200.0;
/// ARW of the example gyro, °/√h (paper 000, Table 2).
pub const ARW_DEG_PER_SQRT_H: f64 = 4.87;
/// RRW of the example gyro, °/h/√h (paper 000, §3.2).
pub const RRW_DEG_PER_H_PER_SQRT_H: f64 = 1200.0;
/// Bandwidths of the coefficient ROM, Hz (paper 000, Table 2).
pub const BANDWIDTHS_HZ: [f64; 3] = [10.0, 20.0, 30.0];

/// The KF spec: direct method, s24.14 in and out, s36.26 state, 18-bit coefficients,
/// nearest / saturate.
pub fn kf_spec() -> Spec {
    let noise = Noise::from_gyro_units(ARW_DEG_PER_SQRT_H, RRW_DEG_PER_H_PER_SQRT_H, 0.0);
    let gains = BANDWIDTHS_HZ
        .iter()
        .map(|bw| {
            design_for_bandwidth(*bw, noise, FS_HZ, Method::Direct, Convergence::default())
                .expect("the example is designable")
                .g
        })
        .collect();
    Spec {
        input: "s24.14".parse().expect("valid"),
        state: "s36.26".parse().expect("valid"),
        output: "s24.14".parse().expect("valid"),
        coefficients: [CoefficientFormat::Auto { width: 18 }; 2],
        rounding: Rounding::Nearest,
        overflow: Overflow::Saturate,
        gains,
        labels: BANDWIDTHS_HZ.iter().map(|bw| format!("{bw} Hz")).collect(),
    }
}

/// The gyro: a 20 °/s, 0.5 Hz swing (paper 000's Table 4), 0.5 °/s initial bias.
pub fn gyro() -> SingleGyro {
    SingleGyro {
        fs_hz: FS_HZ,
        scenario: Scenario::Sine {
            amplitude_dps: 20.0,
            frequency_hz: 0.5,
        },
        initial_bias_dps: 0.5,
        arw_deg_per_sqrt_h: ARW_DEG_PER_SQRT_H,
        rrw_deg_per_h_per_sqrt_h: RRW_DEG_PER_H_PER_SQRT_H,
    }
}

/// The example chain: the KF of [`kf_spec`] (with `rounding`) behind an alternating sequencer
/// of four intervals of `interval_length` samples, `blank` blanked, B `stagger` behind, and a
/// constant-rate estimator with 4 guard bits and smoothing shift `smoothing`.
pub fn chain_plan(
    interval_length: usize,
    blank: usize,
    stagger: usize,
    smoothing: u32,
    rounding: Rounding,
) -> chain::Plan {
    let mut spec = kf_spec();
    spec.rounding = rounding;
    let estimator = estimator::Plan::new(&estimator::Spec {
        schedule: Schedule {
            interval_length,
            intervals: 4,
            pattern: Pattern::Alternating,
            blank,
            stagger,
        },
        rate_order: 0,
        input: spec.input,
        mean: "s28.18".parse().expect("valid"),
        bias: "s28.18".parse().expect("valid"),
        calibrated: spec.input,
        gain: CoefficientFormat::Auto { width: 18 },
        reciprocal: CoefficientFormat::Auto { width: 18 },
        smoothing_shift: smoothing,
        rounding,
        overflow: Overflow::Saturate,
    })
    .expect("the example is plannable");
    chain::Plan::new(
        estimator,
        kf_block::Plan::new(&spec).expect("the example is plannable"),
    )
    .expect("the example's blocks connect")
}
