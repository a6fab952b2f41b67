//! `gyrofx filter --vectors DIR`: the KF's vectors of a recorded record, proven in Icarus and
//! GHDL, consistent with the filtered CSV, with the recording's SHA-256 in the manifest; a
//! foreign folder and `--strict` leave nothing behind.

use std::path::Path;

use crate::common::{fails, files_below, flip_expected_bit, hex_sha256, ok, run_tool};

/// A record of `n` rates (°/s): a slow sine plus a deterministic ripple, with a header.
fn record(dir: &Path, n: usize, scale: f64) -> String {
    let mut text = String::from("t,rate_dps\n");
    for k in 0..n {
        let t = k as f64 / 100.0;
        let rate = scale * ((t * 0.7).sin() * 20.0 + ((k * 37 % 101) as f64 - 50.0) * 0.05);
        text.push_str(&format!("{t},{rate}\n"));
    }
    let path = dir.join("record.csv");
    std::fs::write(&path, text).unwrap();
    path.to_string_lossy().into_owned()
}

#[test]
fn the_vectors_of_a_filtered_record_pass_and_match_the_filtered_csv() {
    let dir = tempfile::tempdir().unwrap();
    let input = record(dir.path(), 3000, 1.0);
    let output = dir.path().join("filtered.csv");
    let vectors = dir.path().join("vectors");
    ok(&[
        "filter",
        "--input",
        &input,
        "--fs",
        "100",
        "--output",
        output.to_str().unwrap(),
        "--vectors",
        vectors.to_str().unwrap(),
    ]);
    // The manifest names the recording by its SHA-256 and keeps the config.
    let manifest: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(vectors.join("manifest.json")).unwrap())
            .unwrap();
    let recording = &manifest["recording"];
    assert_eq!(
        recording["sha256"],
        hex_sha256(&std::fs::read(&input).unwrap())
    );
    assert_eq!(recording["samples"], 3000);
    assert_eq!(manifest["config"]["stimulus"]["fs_hz"], 100.0);
    // The vectors' rate codes are the filtered CSV's, row for row (after the reset row).
    let column = |path: &Path, name: &str| -> Vec<String> {
        let text = std::fs::read_to_string(path).unwrap();
        let mut lines = text.lines().filter(|l| !l.starts_with('#'));
        let header: Vec<&str> = lines.next().unwrap().split(',').collect();
        let index = header.iter().position(|h| *h == name).unwrap();
        lines
            .map(|l| l.split(',').nth(index).unwrap().to_string())
            .collect()
    };
    let from_vectors = column(&vectors.join("kf/kf_vectors.csv"), "rate_out");
    let from_filter = column(&output, "rate_code");
    assert_eq!(from_vectors.len(), 3001);
    assert_eq!(&from_vectors[1..], &from_filter[..]);
    // The testbenches prove the RTL on them.
    for target in ["iverilog-kf", "ghdl-kf"] {
        let (passed, log) = run_tool("make", &["--no-print-directory", target], &vectors);
        assert!(passed && log.contains("PASS n=3001"), "{target}: {log}");
    }
    let signal = flip_expected_bit(&vectors, "kf", 1500);
    let (passed, log) = run_tool("make", &["--no-print-directory", "iverilog-kf"], &vectors);
    assert!(
        !passed && log.contains(&format!("signal {signal}")),
        "{log}"
    );
}

#[test]
fn a_foreign_vectors_folder_is_refused_before_any_output_and_strict_leaves_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let input = record(dir.path(), 500, 1.0);
    let output = dir.path().join("filtered.csv");
    let mine = dir.path().join("mine");
    std::fs::create_dir(&mine).unwrap();
    std::fs::write(mine.join("notes.txt"), "mine").unwrap();
    let message = fails(&[
        "filter",
        "--input",
        &input,
        "--fs",
        "100",
        "--output",
        output.to_str().unwrap(),
        "--vectors",
        mine.to_str().unwrap(),
    ]);
    assert!(message.contains("notes.txt"), "{message}");
    assert!(
        !output.exists(),
        "no filtered CSV after a refused --vectors"
    );
    assert_eq!(
        std::fs::read_to_string(mine.join("notes.txt")).unwrap(),
        "mine"
    );
    // Saturating input under --strict: neither the CSV nor the vectors folder.
    let loud = record(dir.path(), 500, 1e6);
    let vectors = dir.path().join("vectors");
    let message = fails(&[
        "filter",
        "--input",
        &loud,
        "--fs",
        "100",
        "--strict",
        "--output",
        output.to_str().unwrap(),
        "--vectors",
        vectors.to_str().unwrap(),
    ]);
    assert!(message.contains("--strict"), "{message}");
    assert!(!output.exists() && !vectors.exists());
    let leftovers: Vec<_> = files_below(dir.path())
        .into_iter()
        .filter(|p| p.to_string_lossy().contains(".gyrofx-"))
        .collect();
    assert!(leftovers.is_empty(), "{leftovers:?}");
}
