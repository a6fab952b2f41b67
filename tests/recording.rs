//! `generate --recording`: recorded gyro outputs drive the chain's vectors. A package's own top
//! vectors, recorded back (the run before its late reset), give the same codes and outputs
//! bit for bit; the manifest names the recording by its SHA-256; a recording out of step with
//! the sequencer, at another rate or with a missing column is refused with nothing written.

use std::path::Path;

use crate::common::{fails, generate_default, hex_sha256, ok, run_tool};

/// The rows of a vector CSV (`#` lines skipped) as (header, rows of cells).
fn rows(path: &Path) -> (Vec<String>, Vec<Vec<String>>) {
    let text = std::fs::read_to_string(path).unwrap();
    let mut lines = text.lines().filter(|l| !l.starts_with('#'));
    let header = lines
        .next()
        .unwrap()
        .split(',')
        .map(str::to_string)
        .collect();
    let rows = lines
        .map(|l| l.split(',').map(str::to_string).collect())
        .collect();
    (header, rows)
}

fn cell<'a>(header: &[String], row: &'a [String], name: &str) -> &'a str {
    &row[header.iter().position(|h| h == name).unwrap()]
}

/// The package's top rows before the first reset, written as a recording (gyro A and B in
/// °/s and gyro A's mode, plus a column ahead of them to address by index).
fn recording_of(package: &Path, dir: &Path) -> (String, usize) {
    let (header, rows) = rows(&package.join("top/top_vectors.csv"));
    let run: Vec<&Vec<String>> = rows
        .iter()
        .take_while(|r| cell(&header, r, "rst") == "0")
        .collect();
    let mut text = String::from("t,a,b,mode\n");
    for (k, row) in run.iter().enumerate() {
        text.push_str(&format!(
            "{k},{},{},{}\n",
            cell(&header, row, "y_a_dps"),
            cell(&header, row, "y_b_dps"),
            cell(&header, row, "mode_a")
        ));
    }
    let path = dir.join("recording.csv");
    std::fs::write(&path, text).unwrap();
    (path.to_string_lossy().into_owned(), run.len())
}

#[test]
fn a_recorded_run_reproduces_the_chains_vectors_bit_for_bit() {
    let dir = tempfile::tempdir().unwrap();
    let package = generate_default(dir.path(), "3000");
    let (recording, samples) = recording_of(&package, dir.path());
    assert!(samples > 2000, "{samples}");
    let out = dir.path().join("recorded");
    ok(&[
        "generate",
        "--out",
        out.to_str().unwrap(),
        "--recording",
        &recording,
        "--recording-columns",
        "1,b",
        "--recording-rate",
        "200",
        "--recording-mode",
        "mode",
        "--quiet",
    ]);
    let manifest: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("manifest.json")).unwrap()).unwrap();
    assert_eq!(
        manifest["recording"]["sha256"],
        hex_sha256(&std::fs::read(&recording).unwrap())
    );
    assert_eq!(manifest["recording"]["columns"]["gyro_a"], "a");
    assert_eq!(manifest["samples"], samples);
    // Same inputs, same chain from the same start: every port of every row equal. The run
    // steps bw_sel through the ROM in chunks that scale with its length, so the KF's output
    // is compared while both runs are on the same bw_sel.
    let (header, original) = rows(&package.join("top/top_vectors.csv"));
    let (header2, recorded) = rows(&out.join("top/top_vectors.csv"));
    assert_eq!(header, header2);
    let ports = [
        "y_a",
        "y_b",
        "mode_a",
        "mode_b",
        "bias_a",
        "bias_b",
        "estimated",
    ];
    let (mut compared, mut kf_compared, mut same_bandwidth) = (0, 0, true);
    for (a, b) in original.iter().zip(&recorded).take(samples) {
        for port in ports {
            assert_eq!(
                cell(&header, a, port),
                cell(&header, b, port),
                "sample {} port {port}",
                cell(&header, a, "sample")
            );
        }
        same_bandwidth &= cell(&header, a, "bw_sel") == cell(&header, b, "bw_sel");
        if same_bandwidth {
            for port in ["out_valid", "rate_out"] {
                assert_eq!(
                    cell(&header, a, port),
                    cell(&header, b, port),
                    "port {port}"
                );
            }
            kf_compared += 1;
        }
        compared += 1;
    }
    assert_eq!(compared, samples);
    assert!(kf_compared > 400, "{kf_compared}");
    assert!(
        recorded
            .iter()
            .any(|r| cell(&header, r, "estimated") == "1"),
        "the recording reaches an estimate"
    );
    // And the RTL agrees on the recorded vectors.
    let (passed, log) = run_tool("make", &["--no-print-directory", "iverilog-top"], &out);
    assert!(passed && log.contains("PASS"), "{log}");
}

#[test]
fn recordings_out_of_step_at_another_rate_or_without_a_column_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    let package = generate_default(dir.path(), "1000");
    let (recording, _) = recording_of(&package, dir.path());
    // Shifted by one row: the mode column no longer follows the sequencer.
    let text = std::fs::read_to_string(&recording).unwrap();
    let mut lines: Vec<&str> = text.lines().collect();
    lines.remove(1);
    let shifted = dir.path().join("shifted.csv");
    std::fs::write(&shifted, lines.join("\n") + "\n").unwrap();
    let out = dir.path().join("out");
    let base = |file: &str, rate: &str, columns: &str| -> Vec<String> {
        [
            "generate",
            "--out",
            out.to_str().unwrap(),
            "--recording",
            file,
            "--recording-columns",
            columns,
            "--recording-rate",
            rate,
            "--recording-mode",
            "mode",
        ]
        .map(String::from)
        .to_vec()
    };
    let run = |args: Vec<String>| {
        let refs: Vec<&str> = args.iter().map(String::as_str).collect();
        fails(&refs)
    };
    let message = run(base(shifted.to_str().unwrap(), "200", "a,b"));
    assert!(
        message.contains("line 151 (row 149), column \"mode\"")
            && message.contains("the configured sequencer runs it"),
        "{message}"
    );
    let message = run(base(&recording, "100", "a,b"));
    assert!(
        message.contains("100 Hz is not the config's stimulus.fs_hz = 200 Hz"),
        "{message}"
    );
    let message = run(base(&recording, "200", "a,gyro_b"));
    assert!(
        message.contains("no column \"gyro_b\"") && message.contains("t, a, b, mode"),
        "{message}"
    );
    let mut too_many = base(&recording, "200", "a,b");
    too_many.extend(["--samples".to_string(), "100000".to_string()]);
    let message = run(too_many);
    assert!(message.contains("at most the recording's"), "{message}");
    let message = run(vec![
        "generate".into(),
        "--out".into(),
        out.to_str().unwrap().into(),
        "--recording".into(),
        recording.clone(),
    ]);
    assert!(message.contains("--recording-rate"), "{message}");
    // A bad cell deep in the file and a mode that is no mode: the line and column named
    // before anything is written (the file is checked whole before the run).
    let mut lines: Vec<String> = text.lines().map(String::from).collect();
    let last = lines.len() - 1;
    let mut cells: Vec<&str> = lines[last].split(',').collect();
    cells[1] = "NaN-ish";
    lines[last] = cells.join(",");
    let broken = dir.path().join("broken.csv");
    std::fs::write(&broken, lines.join("\n") + "\n").unwrap();
    let message = run(base(broken.to_str().unwrap(), "200", "a,b"));
    assert!(
        message.contains(&format!("line {}", last + 1)) && message.contains("is not a number"),
        "{message}"
    );
    let mut lines: Vec<String> = text.lines().map(String::from).collect();
    let mode = lines[500].rsplit_once(',').unwrap().0.to_string();
    lines[500] = format!("{mode},2");
    let bad_mode = dir.path().join("bad_mode.csv");
    std::fs::write(&bad_mode, lines.join("\n") + "\n").unwrap();
    let message = run(base(bad_mode.to_str().unwrap(), "200", "a,b"));
    assert!(
        message.contains("line 501, column \"mode\": 2 is not a mode"),
        "{message}"
    );
    assert!(!out.exists(), "nothing written after a refusal");
}
