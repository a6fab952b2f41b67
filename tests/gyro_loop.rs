//! `gyrofx loop`: both resonator-level gyros' closed loops against SPEC §1.6's closed forms,
//! through the command line.

mod common;

use common::{fails, ok, write_config};

/// Every figure of one mode from the JSON: (measured, predicted).
fn figure(mode: &serde_json::Value, name: &str) -> (f64, f64) {
    let f = &mode[name];
    (
        f["measured"].as_f64().unwrap(),
        f["predicted"].as_f64().unwrap(),
    )
}

/// Paper 004's gyro (the embedded default): each gyro locks on the coupled resonance, holds q0,
/// and after the 1/SF scaling reads the rate with unity scale factor and the closed-form bias
/// (+B normal, −B′ reverse), within 1 %; the predictions are SPEC §1.6's numbers.
#[test]
fn the_default_gyros_match_the_closed_forms_in_both_modes() {
    let out = ok(&["loop", "--json"]);
    let gyros: serde_json::Value = serde_json::from_str(&out).unwrap();
    let gyros = gyros.as_array().unwrap();
    assert_eq!(gyros.len(), 2);
    for (gyro, name) in gyros.iter().zip(["a", "b"]) {
        assert_eq!(gyro["gyro"], name);
        for (mode, bias) in [("normal", 20.376), ("reverse", -20.395)] {
            let m = &gyro[mode];
            let (measured, predicted) = figure(m, "bias_dps");
            assert!((predicted - bias).abs() < 1e-3, "{mode}: {predicted}");
            assert!(
                (measured / predicted - 1.0).abs() < 0.01,
                "{mode}: {measured}"
            );
            let (sf, _) = figure(m, "scale_factor");
            assert!((sf - 1.0).abs() < 0.01, "{mode}: SF {sf}");
            let (amplitude, q0) = figure(m, "drive_amplitude_m");
            assert!((amplitude / q0 - 1.0).abs() < 0.01 && (q0 - 2e-6).abs() < 1e-12);
            let (f, coupled) = figure(m, "drive_frequency_hz");
            assert!((f - coupled).abs() < 0.01, "{mode}: {f} Hz vs {coupled} Hz");
            let (settling, _) = figure(m, "rate_settling_ms");
            assert!(settling > 50.0 && settling < 150.0, "{mode}: {settling} ms");
        }
        let (_, residual) = figure(gyro, "residual_bias_dps");
        assert!((residual + 0.0094).abs() < 2e-4, "{residual}");
    }
}

/// A structure in the config moves the figures as the closed form says: a larger phase error
/// in normal mode raises B by about 2.9 °/s per degree (SPEC §1.6), measured and predicted
/// alike; bad values are refused naming the key.
#[test]
fn the_config_sets_each_gyros_structure_and_bad_values_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    let config = write_config(
        dir.path(),
        "phase.toml",
        "[resonator_b]\nphase_error_deg = 2.0\n",
    );
    let out = ok(&["loop", "--json", "--config", &config]);
    let gyros: serde_json::Value = serde_json::from_str(&out).unwrap();
    let (a, _) = figure(&gyros[0]["normal"], "bias_dps");
    let (b, b_predicted) = figure(&gyros[1]["normal"], "bias_dps");
    assert!((b - a - 2.9).abs() < 0.1, "B moved {} °/s", b - a);
    assert!((b / b_predicted - 1.0).abs() < 0.01);

    let bad = write_config(dir.path(), "bad.toml", "[resonator_a]\nq_drive = -1.0\n");
    let err = fails(&["loop", "--config", &bad]);
    assert!(err.contains("resonator_a.q_drive = -1"), "{err}");
    let err = fails(&["loop", "--seconds", "0"]);
    assert!(err.contains("--seconds 0 is not allowed"), "{err}");
}
