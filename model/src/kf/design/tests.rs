//! Tests of the KF design: units, the Riccati gain against the closed form, the cut-off, the
//! inverse design and the inputs it refuses.

use super::*;
use proptest::prelude::*;

fn paper_default() -> Noise {
    // 4.87 °/√h ARW (paper 000 Table 2), 1200 °/h^1.5 RRW (paper 000 §3.2).
    Noise::from_gyro_units(4.87, 1200.0, 26.0)
}

fn rel(a: f64, b: f64) -> f64 {
    ((a - b) / b).abs()
}

#[test]
fn unit_conversions_follow_the_spec() {
    let n = Noise::from_gyro_units(60.0, 216_000.0, 1.0);
    assert_eq!((n.q_n, n.q_b), (1.0, 1.0));
}

#[test]
fn riccati_matches_the_closed_form_on_the_default() {
    let noise = paper_default();
    let (k, iterations) = riccati_gain(&noise, 200.0, Convergence::default()).unwrap();
    let exact = closed_form_gain(&noise, 200.0);
    assert!(rel(k[0], exact[0]) < 1e-9, "{k:?} vs {exact:?}");
    assert!(rel(k[1], exact[1]) < 1e-9, "{k:?} vs {exact:?}");
    assert!(iterations > 1);
    // g2 is about a millionth of g1 here: the reason each coefficient gets its own format.
    assert!(k[1] / k[0] < 1e-5 && k[1] / k[0] > 1e-7, "{k:?}");
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]
    #[test]
    fn riccati_matches_the_closed_form(
        log_qw in -4.0f64..3.0, log_qb in -10.0f64..-1.0, log_qn in -6.0f64..-1.0,
        fs in prop::sample::select(vec![50.0, 100.0, 200.0, 1000.0]),
    ) {
        let noise = Noise { q_w: 10f64.powf(log_qw), q_b: 10f64.powf(log_qb), q_n: 10f64.powf(log_qn) };
        let (k, _) = riccati_gain(&noise, fs, Convergence::default()).unwrap();
        let exact = closed_form_gain(&noise, fs);
        prop_assert!(rel(k[0], exact[0]) < 1e-9, "{:?} vs {:?}", k, exact);
        prop_assert!(rel(k[1], exact[1]) < 1e-9, "{:?} vs {:?}", k, exact);
    }

    #[test]
    fn paper_form_reduces_to_the_innovation_recursion(
        k1 in 1e-4f64..1.5, ratio in 1e-9f64..1.0, fs in 10.0f64..1000.0,
    ) {
        let k = [k1, k1 * ratio];
        let g = innovation_gain(k, Method::Paper);
        let (a, b) = paper_matrices(k, fs);
        let expected_a = Matrix2::new(1.0 - g[0], -g[0], -g[1], 1.0 - g[1]);
        prop_assert!((a - expected_a).abs().max() < 1e-12, "{} vs {}", a, expected_a);
        prop_assert!(rel(b[0], g[0]) < 1e-9 && rel(b[1], g[1]) < 1e-9, "{} vs {:?}", b, g);
    }

    #[test]
    fn bandwidth_is_the_half_power_point(s in 0.001f64..0.82, ratio in 0.0f64..1e-3, fs in 10.0f64..1000.0) {
        let g = [s / (1.0 + ratio), s * ratio / (1.0 + ratio)];
        let f = bandwidth_hz(g, fs).unwrap();
        let at_dc = magnitude(g, fs, 0.0);
        prop_assert!(rel(at_dc, dc_gain(g)) < 1e-12);
        let at_f = magnitude(g, fs, f) / at_dc;
        prop_assert!((at_f - std::f64::consts::FRAC_1_SQRT_2).abs() < 1e-9, "{}", at_f);
        // Monotone low-pass: just below and above the cut-off bracket 1/√2.
        prop_assert!(magnitude(g, fs, f * 0.99) / at_dc > std::f64::consts::FRAC_1_SQRT_2);
    }
}

#[test]
fn no_cutoff_for_wide_filters() {
    assert!(bandwidth_hz([0.9, 0.0], 100.0).is_none());
    assert!(bandwidth_hz([0.0, 0.0], 100.0).is_none());
    let edge = 2.0 * std::f64::consts::SQRT_2 - 2.0; // cut-off exactly at Nyquist
    let f = bandwidth_hz([edge - 1e-12, 0.0], 100.0).unwrap();
    assert!((f - 50.0).abs() < 1e-3, "{f}");
}

#[test]
fn inverse_design_hits_the_target_for_both_methods() {
    for method in [Method::Direct, Method::Paper] {
        for target in [10.0, 20.0, 30.0] {
            let d = design_for_bandwidth(
                target,
                paper_default(),
                200.0,
                method,
                Convergence::default(),
            )
            .unwrap();
            let got = d.bandwidth_hz.unwrap();
            assert!(rel(got, target) < 1e-8, "{method:?} {target}: {got}");
            assert!(d.dc_gain < 1.0 && d.dc_gain > 0.999_99);
        }
    }
}

#[test]
fn bad_inputs_name_the_parameter() {
    let mut noise = paper_default();
    noise.q_n = -1.0;
    let err = riccati_gain(&noise, 200.0, Convergence::default()).unwrap_err();
    assert_eq!(
        err,
        DesignError::NotPositive {
            name: "q_n",
            value: -1.0
        }
    );
    assert!(err.to_string().contains("q_n = -1"));
    let err = riccati_gain(&paper_default(), 0.0, Convergence::default()).unwrap_err();
    assert!(err.to_string().contains("fs = 0"));
    let err = riccati_gain(
        &paper_default(),
        200.0,
        Convergence {
            tolerance: 1e-14,
            max_iterations: 3,
        },
    )
    .unwrap_err();
    assert!(matches!(
        err,
        DesignError::NotConverged {
            max_iterations: 3,
            ..
        }
    ));
    let err = design_for_bandwidth(
        120.0,
        paper_default(),
        200.0,
        Method::Direct,
        Convergence::default(),
    )
    .unwrap_err();
    assert!(err.to_string().contains("at most 100 Hz"), "{err}");
}

/// The paper's discretisation saturates below fs/2 (g1 -> 1 - 1/e): a target above its
/// limit is refused with the limit, not with an infinite q_w, and just below it designs.
#[test]
fn paper_method_refuses_bandwidths_beyond_its_saturation_with_the_limit() {
    let err = design_for_bandwidth(
        38.0,
        paper_default(),
        200.0,
        Method::Paper,
        Convergence::default(),
    )
    .unwrap_err();
    let DesignError::BandwidthUnreachable { max_hz, .. } = err else {
        panic!("{err}");
    };
    assert!(max_hz > 30.0 && max_hz < 38.0, "{max_hz}");
    let d = design_for_bandwidth(
        0.98 * max_hz,
        paper_default(),
        200.0,
        Method::Paper,
        Convergence::default(),
    )
    .unwrap();
    let got = d.bandwidth_hz.expect("a bandwidth");
    assert!(rel(got, 0.98 * max_hz) < 1e-6, "{got}");
}
