use proptest::prelude::*;

use super::*;
use crate::fx::{from_f64, Format, Overflow, Rounding};
use crate::stimulus::{Gaussian, Stream};

/// Paper 003's model: φ = −0.2855, Q = σ_a² = 0.0577; R chosen here (the paper leaves it
/// open): 0.01.
fn spec() -> Spec {
    Spec {
        phi: -0.2855,
        process_variance: 0.0577,
        measurement_variance: 0.01,
        tolerance: 1e-9,
        max_entries: 64,
        input: "s24.14".parse().unwrap(),
        state: "s32.22".parse().unwrap(),
        output: "s24.14".parse().unwrap(),
        coefficient_width: 18,
        rounding: Rounding::Nearest,
        overflow: Overflow::Saturate,
    }
}

#[test]
fn the_schedule_starts_at_q_over_q_plus_r_and_settles_at_the_riccati_solution() {
    let s = spec();
    let gains = schedule(
        s.phi,
        s.process_variance,
        s.measurement_variance,
        1e-12,
        1000,
    );
    let (q, r, phi) = (s.process_variance, s.measurement_variance, s.phi);
    assert!((gains[0] - q / (q + r)).abs() < 1e-15);
    // P⁻² + P⁻(R(1 − φ²) − Q) − QR = 0.
    let b = r * (1.0 - phi * phi) - q;
    let predicted = (-b + (b * b + 4.0 * q * r).sqrt()) / 2.0;
    let steady = predicted / (predicted + r);
    assert!((gains.last().unwrap() - steady).abs() < 1e-10, "{gains:?}");
    assert!(gains.len() < 40, "settles fast: {}", gains.len());
    // A length limit cuts it.
    assert_eq!(schedule(phi, q, r, 1e-12, 3).len(), 3);
}

#[test]
fn the_filter_tracks_an_ar1_drift_better_than_the_raw_measurement() {
    let s = spec();
    let plan = Plan::new(&s).unwrap();
    let mut drift_noise = Gaussian::new(21, Stream::RateRandomWalk(0));
    let mut measurement_noise = Gaussian::new(21, Stream::AngleRandomWalk(0));
    let mut filter = FixedArKf::new(&plan);
    let (mut x, mut raw_sq, mut filtered_sq) = (0.0, 0.0, 0.0);
    let n = 20_000;
    for _ in 0..n {
        x = s.phi * x + s.process_variance.sqrt() * drift_noise.sample();
        let z = x + s.measurement_variance.sqrt() * measurement_noise.sample();
        let code = from_f64(z, s.input, Rounding::Nearest, Overflow::Saturate)
            .unwrap()
            .code;
        let estimate = s.output.to_f64(i128::from(filter.step(code as i64)));
        raw_sq += (z - x) * (z - x);
        filtered_sq += (estimate - x) * (estimate - x);
    }
    let (raw, filtered) = (raw_sq / n as f64, filtered_sq / n as f64);
    assert!((raw / s.measurement_variance - 1.0).abs() < 0.05, "{raw}");
    // The steady-state error variance P = (1 − K)P⁻ = K·R.
    let steady_gain = *plan.gains.last().unwrap();
    let expected = steady_gain * s.measurement_variance;
    assert!(
        filtered < raw && (filtered / expected - 1.0).abs() < 0.05,
        "{filtered} vs {expected}"
    );
    assert_eq!(filter.overflows(), 0);
}

#[test]
fn the_first_output_is_the_first_sample() {
    let plan = Plan::new(&spec()).unwrap();
    let mut fixed = FixedArKf::new(&plan);
    let mut float = FloatArKf::new(&plan);
    assert_eq!(fixed.step(12345), 12345);
    assert_eq!(float.step(0.75), 0.75);
}

#[test]
fn bad_specs_name_the_field() {
    let cases: [(Spec, &str); 6] = [
        (Spec { phi: 1.0, ..spec() }, "ar_kf.phi = 1"),
        (
            Spec {
                process_variance: 0.0,
                ..spec()
            },
            "ar_kf.process_variance = 0",
        ),
        (
            Spec {
                measurement_variance: f64::NAN,
                ..spec()
            },
            "ar_kf.measurement_variance = NaN",
        ),
        (
            Spec {
                max_entries: 0,
                ..spec()
            },
            "ar_kf.max_entries = 0",
        ),
        (
            Spec {
                state: "s24.10".parse().unwrap(),
                ..spec()
            },
            "ar_kf.state_format = s24.10",
        ),
        (
            Spec {
                coefficient_width: 1,
                ..spec()
            },
            "ar_kf.coefficient_width = 1",
        ),
    ];
    for (spec, message) in cases {
        let err = Plan::new(&spec).unwrap_err().to_string();
        assert!(err.contains(message), "{err}");
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(300))]

    /// Fixed vs float with the same quantized schedule: within `error_bound_lsb` over random
    /// models, formats, rounding modes and inputs.
    #[test]
    fn fixed_matches_float_within_the_bound(
        phi in -0.95f64..0.95,
        q in 1e-4f64..1.0,
        r in 1e-4f64..1.0,
        input_width in 10u32..=28,
        guard in 0i32..=12,
        extra_state_integer in 1i32..=3,
        coefficient_width in 8u32..=24,
        rounding in proptest::sample::select(Rounding::ALL.to_vec()),
        seed in any::<u64>(),
    ) {
        let input = Format::signed(input_width, input_width as i32 - 6).unwrap();
        let state_frac = input.frac + guard;
        let state = Format::signed((6 + extra_state_integer + state_frac) as u32, state_frac).unwrap();
        let output = input;
        let plan = match Plan::new(&Spec {
            phi, process_variance: q, measurement_variance: r, tolerance: 1e-9, max_entries: 32,
            input, state, output, coefficient_width, rounding, overflow: Overflow::Saturate,
        }) {
            Ok(plan) => plan,
            // A narrow coefficient may round |a| up to 1: refused, not a failure here.
            Err(_) => return Ok(()),
        };
        let mut fixed = FixedArKf::new(&plan);
        let mut float = FloatArKf::new(&plan);
        let mut noise = Gaussian::new(seed, Stream::AngleRandomWalk(1));
        let bound = plan.error_bound_lsb();
        for _ in 0..300 {
            // Inputs within a quarter of the range: the state (one more integer bit) never
            // overflows.
            let z = (noise.sample() * 2.0).clamp(-7.0, 7.0);
            let code = from_f64(z, input, Rounding::Nearest, Overflow::Saturate).unwrap().code;
            let a = output.to_f64(i128::from(fixed.step(code as i64)));
            let b = float.step(input.to_f64(code));
            let error = (a - b).abs() / output.lsb();
            prop_assert!(error <= bound * (1.0 + 1e-9) + 1e-9, "{error} > {bound}");
        }
        prop_assert_eq!(fixed.overflows(), 0);
    }
}
