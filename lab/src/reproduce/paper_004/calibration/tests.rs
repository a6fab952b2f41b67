use super::*;
use crate::reproduce::PAPER_004_TABLE_2;
use gyrofx_job::config::Config;

/// The Gauss–Markov Allan variance meets its two limits: a random walk's `2σ²τ/(3T)` far below
/// the correlation time, white noise's `2σ²T/τ` far above, and its hump peaks near 1.89 T at
/// 0.6177 σ.
#[test]
fn gauss_markov_allan_variance_meets_its_limits() {
    let (std, t) = (0.3, 20.0);
    let short = gauss_markov_avar(std, t, 0.02);
    assert!((short / (2.0 * std * std * 0.02 / (3.0 * t)) - 1.0).abs() < 1e-3);
    let long = gauss_markov_avar(std, t, 2e4);
    assert!((long / (2.0 * std * std * t / 2e4) - 1.0).abs() < 1e-2);
    let (peak_tau, peak) = (1..4000)
        .map(|k| {
            let tau = f64::from(k) * 0.01 * t;
            (tau, gauss_markov_avar(std, t, tau).sqrt())
        })
        .fold((0.0, 0.0), |a, b| if b.1 > a.1 { b } else { a });
    assert!((peak_tau / t - 1.89).abs() < 0.02, "{peak_tau}");
    assert!((peak / std - 0.6177).abs() < 1e-3, "{peak}");
}

/// The damping drifts' sensitivities from the closed form's differences are the derivatives
/// of `d_xy/(2m)` with `d_xy = (d1 − d2) sin θ cos θ`: `(d1 − d2) cos 2θ / (2m)` per radian of
/// angle and `(d1 + d2) sin 2θ / (8m)` per unit of split.
#[test]
fn drift_sensitivities_are_the_closed_forms_derivatives() {
    let params = ResonatorParams::paper_004();
    let [phase, angle, split] = bias_sensitivities(&params);
    let [d1, d2] = params.principal_damping();
    let (m, theta) = (params.mass_kg, params.damping_angle_deg.to_radians());
    let deg = 180.0 / std::f64::consts::PI;
    let angle_expected = (d1 - d2) * (2.0 * theta).cos() / (2.0 * m);
    let split_expected = (d1 + d2) * (2.0 * theta).sin() / (8.0 * m) * deg;
    assert!(
        (angle / angle_expected - 1.0).abs() < 1e-4,
        "{angle} {angle_expected}"
    );
    assert!(
        (split / split_expected - 1.0).abs() < 1e-4,
        "{split} {split_expected}"
    );
    // Per degree of phase: about the 166 °/s quadrature's share per degree.
    assert!((2.8..3.0).contains(&phase), "{phase}");
}

/// The `gu2019` preset's `[front_end_a]` and `[front_end_b]` are the calibration for paper
/// 004's raw N and B (to the preset's four digits), and each gyro's closed loop, drift off,
/// shows the paper's N within 6 %.
#[test]
fn the_gu2019_front_ends_are_the_calibration_and_give_the_papers_n() {
    let config = Config::from_preset_and_file(Some("gu2019"), None).unwrap();
    for (g, gyro) in config.gyro_loops().unwrap().iter().enumerate() {
        let floor = loop_floor(gyro).unwrap();
        let [n, b] = [PAPER_004_TABLE_2[1][g], PAPER_004_TABLE_2[2][g]];
        let calibration = calibrate(gyro, n, b, floor).unwrap();
        let derived = calibration.apply(&gyro.front_end);
        let close = |what: &str, preset: f64, derived: f64| {
            assert!(
                (preset / derived - 1.0).abs() < 5e-4,
                "gyro {}: {what} is {preset:e} in the preset, {derived:e} derived (floor {floor:e})",
                gyro.name
            );
        };
        close(
            "pickoff_noise_v_per_sqrt_hz",
            gyro.front_end.pickoff_noise_v_per_sqrt_hz,
            derived.pickoff_noise_v_per_sqrt_hz,
        );
        close(
            "phase_drift.std",
            gyro.front_end.phase_drift.std,
            derived.phase_drift.std,
        );
        close(
            "damping_angle_drift.std",
            gyro.front_end.damping_angle_drift.std,
            derived.damping_angle_drift.std,
        );
        close(
            "damping_split_drift.std",
            gyro.front_end.damping_split_drift.std,
            derived.damping_split_drift.std,
        );
        assert_eq!(
            gyro.front_end,
            PhysicsSettings {
                ..derived_with_times(&gyro.front_end, &derived)
            }
        );
        let white = white_noise(gyro, &gyro.front_end, 1).unwrap();
        assert!(
            (white / n - 1.0).abs() < 0.06,
            "gyro {}: N {white:e}, paper {n:e}",
            gyro.name
        );
        // The drifts' expected floor is the paper's B.
        let floor_adev = FLOOR_TAUS_S
            .iter()
            .map(|&tau| expected_drift_adev(&calibration, tau))
            .fold(f64::INFINITY, f64::min);
        assert!((floor_adev / (0.6643 * b) - 1.0).abs() < 1e-9);
    }
}

/// `preset` with the derived stds replaced by the preset's (so the comparison above covers
/// every other field exactly: correlation times, temperature, gains).
fn derived_with_times(preset: &PhysicsSettings, derived: &PhysicsSettings) -> PhysicsSettings {
    PhysicsSettings {
        pickoff_noise_v_per_sqrt_hz: preset.pickoff_noise_v_per_sqrt_hz,
        phase_drift: GaussMarkov {
            std: preset.phase_drift.std,
            ..derived.phase_drift
        },
        damping_angle_drift: GaussMarkov {
            std: preset.damping_angle_drift.std,
            ..derived.damping_angle_drift
        },
        damping_split_drift: GaussMarkov {
            std: preset.damping_split_drift.std,
            ..derived.damping_split_drift
        },
        ..*derived
    }
}
