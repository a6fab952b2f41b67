//! No silent saturation in the resonator-level loops: `gyrofx loop` and `gyrofx generate` name
//! every node of a fixed gyro loop that saturated or wrapped, and `--strict` refuses.

use crate::common::*;

/// Gyro A's damping axes at 45° with a low sense Q: a mode-split bias of about 14 300 °/s,
/// far beyond the ±512 °/s of the loop's output format, so its rate output is pinned.
const BIASED_A: &str = "[resonator_a]\ndamping_angle_deg = 45.0\nq_sense = 40.0\n";

/// A PLL pull range (0.2 mHz) narrower than the default gyro's coupled drive resonance is
/// from its nominal frequency (0.9 mHz): the PLL integrator is held at its limit for good, an
/// internal node, while every output stays in range.
const NARROW_PULL_RANGE: &str = "[loop]\npll_pull_range_hz = 0.0002\n";

/// `gyrofx loop` with `toml`, short averages; the output, exit code and stdout alone.
fn run_loop(toml: &str, extra: &[&str]) -> (std::process::Output, String) {
    let dir = tempfile::tempdir().unwrap();
    let config = write_config(dir.path(), "loop.toml", toml);
    let mut args = vec!["loop", "--config", &config, "--seconds", "0.05", "--quiet"];
    args.extend_from_slice(extra);
    let output = gyrofx(&args);
    let stdout = String::from_utf8_lossy(&output.stdout).into_owned();
    (output, stdout)
}

/// The table line `gyro mode saturations …` of `table`.
fn saturation_line<'t>(table: &'t str, gyro: &str, mode: &str) -> &'t str {
    table
        .lines()
        .find(|line| {
            let words: Vec<&str> = line.split_whitespace().collect();
            words.len() > 3 && words[0] == gyro && words[1] == mode && words[2] == "saturations"
        })
        .unwrap_or_else(|| panic!("no saturations line for gyro {gyro} {mode} in:\n{table}"))
}

#[test]
fn loop_names_a_saturated_rate_output_in_its_table_and_warns() {
    let (output, table) = run_loop(BIASED_A, &[]);
    let log = text(&output);
    assert!(output.status.success(), "{log}");
    for mode in ["normal", "reverse"] {
        let line = saturation_line(&table, "a", mode);
        assert!(line.contains("rate_output "), "{line}");
        assert_eq!(
            saturation_line(&table, "b", mode).split_whitespace().nth(3),
            Some("none")
        );
    }
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(
        stderr.contains(
            "warning: the fixed loop saturated or wrapped while the figures were measured"
        ) && stderr.contains("gyro a normal: ")
            && stderr.contains("rate_output ")
            && stderr.contains("clipped and not trustworthy")
            && !stderr.contains("gyro b"),
        "{stderr}"
    );
}

#[test]
fn loop_json_counts_saturations_per_gyro_and_mode() {
    let (output, json) = run_loop(BIASED_A, &["--json"]);
    assert!(output.status.success(), "{}", text(&output));
    let figures: serde_json::Value = serde_json::from_str(&json).unwrap();
    for mode in ["normal", "reverse"] {
        let a = &figures[0][mode]["saturations"];
        assert!(a["rate_output"].as_u64().unwrap() > 0, "{a}");
        let b = &figures[1][mode]["saturations"];
        assert_eq!(b["rate_output"].as_u64(), Some(0), "{b}");
        assert!(figures[1][mode]["transient_saturations"].is_object());
    }
}

#[test]
fn loop_names_a_saturated_internal_node() {
    let (output, table) = run_loop(NARROW_PULL_RANGE, &[]);
    assert!(output.status.success(), "{}", text(&output));
    let line = saturation_line(&table, "a", "normal");
    assert!(
        line.contains("pll_integrator ") && !line.contains("rate_output"),
        "{line}"
    );
}

#[test]
fn loop_strict_refuses_saturated_figures_and_prints_none() {
    let (output, stdout) = run_loop(BIASED_A, &["--strict"]);
    let log = text(&output);
    assert_eq!(output.status.code(), Some(1), "{log}");
    assert!(
        log.contains("error: --strict: the fixed loop saturated")
            && log.contains("gyro a normal: ")
            && log.contains("rate_output "),
        "{log}"
    );
    assert!(stdout.is_empty(), "nothing printed with --strict: {stdout}");
}

#[test]
fn loop_of_the_default_config_reports_no_saturation() {
    let (output, table) = run_loop("", &["--strict"]);
    assert!(output.status.success(), "{}", text(&output));
    for gyro in ["a", "b"] {
        for mode in ["normal", "reverse"] {
            let line = saturation_line(&table, gyro, mode);
            assert_eq!(line.split_whitespace().nth(3), Some("none"), "{line}");
        }
    }
    assert!(!text(&output).contains("warning"), "{}", text(&output));
}

#[test]
fn generate_names_a_saturated_loop_output_and_strict_writes_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let config = write_config(dir.path(), "biased.toml", BIASED_A);
    let out = dir.path().join("out");
    let out = out.to_str().unwrap();
    let args = [
        "generate",
        "--out",
        out,
        "--config",
        &config,
        "--samples",
        "600",
    ];
    let log = ok(&args);
    let overflow_line = log
        .lines()
        .find(|l| l.starts_with("overflows:"))
        .unwrap_or_else(|| panic!("no overflow line in:\n{log}"));
    assert!(
        overflow_line.contains("loop A [rate_output ") && overflow_line.contains(" B [none]"),
        "{overflow_line}"
    );
    assert!(
        log.contains("warning: quantizers overflowed or saturated on the chain run's data: loop A rate_output "),
        "{log}"
    );
    let manifest: serde_json::Value =
        serde_json::from_slice(&std::fs::read(dir.path().join("out/manifest.json")).unwrap())
            .unwrap();
    let counts = &manifest["overflow_counts"]["gyro_loop"];
    assert!(
        counts[0]["used"]["rate_output"].as_u64().unwrap() > 0,
        "{counts}"
    );
    assert_eq!(
        counts[1]["used"]["rate_output"].as_u64(),
        Some(0),
        "{counts}"
    );

    let strict = dir.path().join("strict");
    let output = gyrofx(&[
        "generate",
        "--out",
        strict.to_str().unwrap(),
        "--config",
        &config,
        "--samples",
        "600",
        "--strict",
    ]);
    let log = text(&output);
    assert_eq!(output.status.code(), Some(1), "{log}");
    assert!(
        log.contains("--strict: quantizers overflowed") && log.contains("loop A rate_output "),
        "{log}"
    );
    assert!(!strict.exists(), "--strict wrote {}", strict.display());
}

#[test]
fn generate_of_the_default_config_reports_no_loop_saturation() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out");
    let log = ok(&[
        "generate",
        "--out",
        out.to_str().unwrap(),
        "--samples",
        "600",
        "--strict",
    ]);
    assert!(log.contains("loop A [none] B [none]"), "{log}");
    assert!(!log.contains("warning"), "{log}");
}
