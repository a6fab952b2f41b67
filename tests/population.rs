//! `gyrofx population`: members drawn and studied through the command line, the folder it
//! writes, its determinism whatever `--jobs`, and the refusals that leave nothing behind.

use std::path::Path;

use crate::common::{fails, ok};

/// Short windows (0.4 s) so that a second of chain run holds calibrated output; two spreads.
const CONFIG: &str = "[sequencer]\ninterval_length = 40\nintervals = 2\nblank = 30\n\
[population.resonator]\nq_drive = { distribution = \"normal\", std = 0.1, relative = true }\n\
stiffness_angle_deg = { distribution = \"uniform\", low = 0.2, high = 0.8 }\n";

fn run(dir: &Path, out: &str, jobs: &str, targets: &[&str]) -> String {
    let config = dir.join("p.toml");
    std::fs::write(&config, CONFIG).unwrap();
    let out = dir.join(out);
    let mut args = vec![
        "population",
        "--config",
        config.to_str().unwrap(),
        "--gyros",
        "3",
        "--seconds",
        "1",
        "--jobs",
        jobs,
        "--out",
        out.to_str().unwrap(),
    ];
    for t in targets {
        args.extend(["--target", t]);
    }
    ok(&args)
}

/// Three members on one thread and on two: the same files byte for byte; the CSV has a row per
/// member in order, the summary counts them and applies the targets.
#[test]
fn population_is_the_same_on_any_number_of_threads_and_applies_targets() {
    let dir = tempfile::tempdir().unwrap();
    let targets = ["lock_ms<=1000", "lock_ms<1", "residual_dps<=100"];
    let printed = run(dir.path(), "one", "1", &targets);
    run(dir.path(), "two", "2", &targets);
    assert!(printed.contains("members 3: 3 locked"), "{printed}");
    let files: Vec<String> = {
        let mut f: Vec<String> = std::fs::read_dir(dir.path().join("one"))
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        f.sort();
        f
    };
    for name in [
        "population.csv",
        "summary.json",
        "manifest.json",
        "yield_vs_blanking.svg",
    ] {
        assert!(files.iter().any(|f| f == name), "{name} missing: {files:?}");
    }
    for name in &files {
        let one = std::fs::read(dir.path().join("one").join(name)).unwrap();
        let two = std::fs::read(dir.path().join("two").join(name)).unwrap();
        assert!(one == two, "{name} differs between --jobs 1 and --jobs 2");
    }
    let csv = std::fs::read_to_string(dir.path().join("one/population.csv")).unwrap();
    let rows: Vec<&str> = csv.lines().collect();
    assert_eq!(rows.len(), 4);
    assert!(rows[0].starts_with("member,status,message,a.q_drive,a.stiffness_angle_deg,b.q_drive"));
    for (i, row) in rows[1..].iter().enumerate() {
        assert!(row.starts_with(&format!("{i},ok,,")), "{row}");
    }
    let summary: serde_json::Value = serde_json::from_str(
        &std::fs::read_to_string(dir.path().join("one/summary.json")).unwrap(),
    )
    .unwrap();
    let report = &summary["report"];
    assert_eq!(report["counts"]["members"], 3);
    let yields: Vec<f64> = report["targets"]
        .as_array()
        .unwrap()
        .iter()
        .map(|t| t["yield_fraction"].as_f64().unwrap())
        .collect();
    assert_eq!(yields, [1.0, 0.0, 1.0]);
    // lock_ms<1 fails every member: nothing meets every target, at any blanking.
    assert_eq!(report["yield_fraction"], 0.0);
    assert!(report["yield_against_blanking"]
        .as_array()
        .unwrap()
        .iter()
        .all(|b| b["yield_fraction"] == 0.0));
}

/// A bad target or a bad spread is refused naming what is wrong, before any output.
#[test]
fn bad_targets_and_spreads_leave_nothing_behind() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out");
    let out = out.to_str().unwrap();
    let text = fails(&[
        "population",
        "--gyros",
        "2",
        "--out",
        out,
        "--target",
        "residual<=0.01",
    ]);
    assert!(text.contains("\"residual\" is not a figure"), "{text}");
    let config = dir.path().join("bad.toml");
    std::fs::write(
        &config,
        "[population.resonator]\nq_drive = { distribution = \"gauss\", std = 0.1 }\n",
    )
    .unwrap();
    let text = fails(&[
        "population",
        "--gyros",
        "2",
        "--out",
        out,
        "--config",
        config.to_str().unwrap(),
    ]);
    assert!(
        text.contains("population.resonator.q_drive.distribution = \"gauss\"")
            && text.contains("one of normal, uniform, values"),
        "{text}"
    );
    let text = fails(&["population", "--gyros", "0", "--out", out]);
    assert!(text.contains("--gyros 0 is not allowed"), "{text}");
    let left: Vec<_> = std::fs::read_dir(dir.path()).unwrap().collect();
    assert_eq!(left.len(), 1, "only the config: {left:?}");
}
