//! `gyrofx explore`: a three-candidate sweep of the KF's state on the default chain (2000
//! samples, its own cost cache) gives one CSV row per candidate with every column, an error that
//! falls as fraction bits are added, flip-flops that grow with the width, and a best.toml that is
//! the cheapest candidate meeting the target and that `generate --strict` accepts; a second run
//! takes every cost from the cache and writes the same CSV; a target nobody meets writes the CSV
//! and plots but no best.toml and exits 1; bad arguments name the flag and leave no folder.

use std::path::{Path, PathBuf};

use crate::common::{gyrofx, ok, text};

const SWEEP: &str = "kf.state_format=s26.16..s28.18";
const SAMPLES: &str = "2000";

/// `gyrofx explore` over [`SWEEP`] on [`SAMPLES`] samples with `cache`, writing `out`, then
/// `extra`.
fn sweep(cache: &Path, out: &Path, extra: &[&str]) -> std::process::Output {
    let mut args = vec![
        "explore",
        "--vary",
        SWEEP,
        "--samples",
        SAMPLES,
        "--cache",
        cache.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ];
    args.extend_from_slice(extra);
    gyrofx(&args)
}

/// The first run, which every check below reads: its folder, cache and output.
struct Fixture {
    _root: tempfile::TempDir,
    root: PathBuf,
    out: PathBuf,
    cache: PathBuf,
    printed: String,
}

fn fixture() -> Fixture {
    let dir = tempfile::tempdir().unwrap();
    let root = dir.path().to_path_buf();
    let out = root.join("sweep");
    let cache = root.join("cache");
    let output = sweep(&cache, &out, &["--jobs", "2", "--quiet"]);
    assert!(output.status.success(), "{}", text(&output));
    let printed = text(&output);
    Fixture {
        _root: dir,
        root,
        out,
        cache,
        printed,
    }
}

/// One test reads the first run in every way: the run is over 100 s of yosys, and the test
/// runner gives each test a process of its own, so a fixture shared by several tests would run
/// once per test.
#[test]
fn the_sweep_its_csv_best_toml_cache_and_unmet_target() {
    let f = fixture();
    every_candidate_has_a_row_with_every_column(&f);
    more_fraction_bits_mean_less_error_and_more_flip_flops(&f);
    best_toml_is_the_cheapest_that_meets_the_target_and_generates_strictly(&f);
    a_second_run_takes_every_cost_from_the_cache_and_writes_the_same_csv(&f);
    a_target_nobody_meets_writes_no_best_toml_and_exits_1(&f);
}

/// The CSV as a header and rows of fields (the files hold no quoted field: checked).
fn table(path: &Path) -> (Vec<String>, Vec<Vec<String>>) {
    let text = std::fs::read_to_string(path).unwrap();
    assert!(!text.contains('"'), "{text}");
    let mut lines = text.lines();
    let header: Vec<String> = lines.next().unwrap().split(',').map(String::from).collect();
    let rows: Vec<Vec<String>> = lines
        .map(|l| l.split(',').map(String::from).collect())
        .collect();
    for row in &rows {
        assert_eq!(row.len(), header.len(), "{row:?}");
    }
    (header, rows)
}

fn column(header: &[String], name: &str) -> usize {
    header
        .iter()
        .position(|h| h == name)
        .unwrap_or_else(|| panic!("no column {name} in {header:?}"))
}

fn number(row: &[String], header: &[String], name: &str) -> f64 {
    let cell = &row[column(header, name)];
    cell.parse()
        .unwrap_or_else(|_| panic!("{name} = {cell:?} is not a number"))
}

fn cache_files(cache: &Path) -> Vec<String> {
    let mut names: Vec<String> = std::fs::read_dir(cache)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    names
}

fn every_candidate_has_a_row_with_every_column(f: &Fixture) {
    let (header, rows) = table(&f.out.join("explore.csv"));
    for name in [
        "candidate",
        "kf.state_format",
        "status",
        "proven",
        "overflows",
        "error_rms_lsb",
        "error_max_lsb",
        "error_rms_dps",
        "error_max_dps",
        "adev_error_1s_dps",
        "adev_output_1s_dps",
        "adev_share",
        "arw_quantization_deg_per_sqrt_h",
        "arw_share",
        "chain_cells",
        "chain_generic_flip_flops",
        "chain_multipliers",
        "chain_luts",
        "chain_flip_flops",
        "chain_dsp48",
        "luts",
        "dsp48",
        "meets_target",
        "best",
    ] {
        column(&header, name);
    }
    let formats: Vec<&str> = rows
        .iter()
        .map(|r| r[column(&header, "kf.state_format")].as_str())
        .collect();
    assert_eq!(formats, ["s26.16", "s27.17", "s28.18"]);
    for (i, row) in rows.iter().enumerate() {
        assert_eq!(row[0], i.to_string());
        assert_eq!(row[column(&header, "status")], "ok", "{row:?}");
        let proven = &row[column(&header, "proven")];
        assert!(proven == "yes" || proven.starts_with("no: "), "{proven}");
        // The definitions the help gives: the shares are ratios of the measured figures, the
        // ARW is σ(1 s)·√(1 s) in °/√h over the default sensor's 4.87 °/√h.
        let adev = number(row, &header, "adev_error_1s_dps");
        let output = number(row, &header, "adev_output_1s_dps");
        let arw = number(row, &header, "arw_quantization_deg_per_sqrt_h");
        assert!(adev > 0.0 && output > adev, "{row:?}");
        assert!(
            (number(row, &header, "adev_share") - adev / output).abs() <= 1e-12 * adev / output
        );
        assert!((arw - adev * 60.0).abs() <= 1e-9 * arw, "{arw} {adev}");
        assert!((number(row, &header, "arw_share") - arw / 4.87).abs() <= 1e-9 * arw);
        // Two units of one error: the output format's LSB is s24.14's, 2^-14 °/s.
        let lsb = 2f64.powi(-14);
        for stat in ["rms", "max"] {
            let in_lsb = number(row, &header, &format!("error_{stat}_lsb"));
            let in_dps = number(row, &header, &format!("error_{stat}_dps"));
            assert!((in_dps - in_lsb * lsb).abs() <= 1e-9 * in_dps, "{row:?}");
        }
        assert!(
            number(row, &header, "error_max_lsb") >= number(row, &header, "error_rms_lsb"),
            "{row:?}"
        );
    }
    assert!(
        f.printed.contains("3 synthesized by yosys"),
        "{}",
        f.printed
    );
    assert_eq!(cache_files(&f.cache).len(), 3, "one cost per candidate");
    for file in ["pareto.png", "pareto.svg", "manifest.json"] {
        assert!(f.out.join(file).is_file(), "{file}");
    }
}

fn more_fraction_bits_mean_less_error_and_more_flip_flops(f: &Fixture) {
    let (header, rows) = table(&f.out.join("explore.csv"));
    let rms: Vec<f64> = rows
        .iter()
        .map(|r| number(r, &header, "error_rms_dps"))
        .collect();
    // Two more fraction bits in the state: its rounding, a quarter as large, moves the output
    // less (the output's own rounding stays).
    assert!(rms[2] < rms[0], "rms error in °/s: {rms:?}");
    let flip_flops: Vec<f64> = rows
        .iter()
        .map(|r| number(r, &header, "chain_flip_flops"))
        .collect();
    // The state's two registers (x1, x2) each grow by a bit per candidate.
    for pair in flip_flops.windows(2) {
        assert!(pair[1] >= pair[0] + 2.0, "{flip_flops:?}");
    }
    let generic: Vec<f64> = rows
        .iter()
        .map(|r| number(r, &header, "chain_generic_flip_flops"))
        .collect();
    assert!(generic.windows(2).all(|p| p[1] > p[0]), "{generic:?}");
}

fn best_toml_is_the_cheapest_that_meets_the_target_and_generates_strictly(f: &Fixture) {
    let (header, rows) = table(&f.out.join("explore.csv"));
    let cost = |r: &Vec<String>| {
        (
            number(r, &header, "dsp48") as u64,
            number(r, &header, "luts") as u64,
            number(r, &header, "flip_flops") as u64,
        )
    };
    let meeting: Vec<&Vec<String>> = rows
        .iter()
        .filter(|r| {
            number(r, &header, "arw_share") <= 0.01 && number(r, &header, "overflows") == 0.0
        })
        .collect();
    assert!(!meeting.is_empty());
    let cheapest = meeting.iter().map(|r| cost(r)).min().unwrap();
    let best: Vec<&Vec<String>> = rows
        .iter()
        .filter(|r| r[column(&header, "best")] == "true")
        .collect();
    assert_eq!(best.len(), 1, "{rows:?}");
    let best = best[0];
    assert_eq!(best[column(&header, "meets_target")], "true");
    assert!(number(best, &header, "arw_share") <= 0.01);
    assert_eq!(cost(best), cheapest);
    let toml = std::fs::read_to_string(f.out.join("best.toml")).unwrap();
    let state = &best[column(&header, "kf.state_format")];
    assert!(
        toml.lines()
            .any(|l| l.replace(' ', "") == format!("state_format=\"{state}\"")),
        "{toml}"
    );
    let package = f.root.join("best-package");
    ok(&[
        "generate",
        "--config",
        f.out.join("best.toml").to_str().unwrap(),
        "--strict",
        "--samples",
        SAMPLES,
        "--blocks",
        "top",
        "--no-csv",
        "--quiet",
        "--out",
        package.to_str().unwrap(),
    ]);
    let manifest = std::fs::read_to_string(package.join("manifest.json")).unwrap();
    assert!(manifest.contains(&format!("\"state_format\": \"{state}\"")));
}

fn a_second_run_takes_every_cost_from_the_cache_and_writes_the_same_csv(f: &Fixture) {
    let before = cache_files(&f.cache);
    let again = f.root.join("again");
    let output = sweep(&f.cache, &again, &["--jobs", "1", "--quiet"]);
    assert!(output.status.success(), "{}", text(&output));
    let printed = text(&output);
    assert!(
        printed.contains("0 synthesized by yosys, 3 from the cache"),
        "{printed}"
    );
    assert_eq!(cache_files(&f.cache), before);
    assert_eq!(
        std::fs::read(again.join("explore.csv")).unwrap(),
        std::fs::read(f.out.join("explore.csv")).unwrap(),
        "other scheduling (--jobs 1), same CSV"
    );
}

fn a_target_nobody_meets_writes_no_best_toml_and_exits_1(f: &Fixture) {
    let out = f.root.join("unmet");
    let output = sweep(&f.cache, &out, &["--target", "max-error-lsb<=0", "--quiet"]);
    assert_eq!(output.status.code(), Some(1), "{}", text(&output));
    assert!(
        text(&output).contains("no best.toml: no candidate meets max-error-lsb<=0"),
        "{}",
        text(&output)
    );
    assert!(!out.join("best.toml").exists());
    for file in ["explore.csv", "pareto.png", "pareto.svg"] {
        assert!(out.join(file).is_file(), "{file}");
    }
    let (header, rows) = table(&out.join("explore.csv"));
    assert_eq!(rows.len(), 3);
    for row in &rows {
        assert!(number(row, &header, "error_max_lsb") > 0.0);
        assert_eq!(row[column(&header, "meets_target")], "false");
        assert_eq!(row[column(&header, "best")], "false");
    }
}

#[test]
fn bad_arguments_name_the_flag_and_leave_no_folder() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out");
    let cache = dir.path().join("cache");
    let run = |extra: &[&str]| {
        let mut args = vec![
            "explore",
            "--out",
            out.to_str().unwrap(),
            "--cache",
            cache.to_str().unwrap(),
        ];
        args.extend_from_slice(extra);
        let output = gyrofx(&args);
        assert_eq!(output.status.code(), Some(2), "{args:?}: {}", text(&output));
        assert!(!out.exists(), "{args:?} left {}", out.display());
        text(&output)
    };
    for (args, says) in [
        (
            vec!["--vary", "kf.state_format=s30.20..s32.21"],
            "--vary kf.state_format=s30.20..s32.21 is not allowed: s30.20 and s32.21 share neither their integer bits",
        ),
        (
            vec!["--vary", "kf.state_format=s30.20"],
            "--vary kf.state_format=s30.20 is not allowed: 's30.20' is not a range of formats",
        ),
        (
            vec!["--vary", "kf.state_format=s30.20..t31.21"],
            "'t31.21' is not a format",
        ),
        (
            vec!["--vary", "kf.gain_format=s18.17..s19.18"],
            "kf.gain_format is not a format explore can sweep",
        ),
        (
            vec!["--vary", "kf.input_format=s24.14..s25.15"],
            "kf.input_format is not a format explore can sweep (kf.input_format is also the ADC's",
        ),
        (
            vec![
                "--vary",
                "kf.state_format=s30.20..s31.21",
                "--target",
                "arw-share<0.01",
            ],
            "--target arw-share<0.01 is not allowed: no '<='",
        ),
        (
            vec![
                "--vary",
                "kf.state_format=s30.20..s31.21",
                "--target",
                "noise<=0.01",
            ],
            "--target noise<=0.01 is not allowed: 'noise' is not a metric",
        ),
        (
            vec![
                "--vary",
                "kf.state_format=s30.20..s31.21",
                "--target",
                "arw-share<=-1",
            ],
            "'-1' is not a limit",
        ),
        (
            vec!["--vary", "kf.state_format=s10.0..s60.50", "--vary", "estimator.mean_format=s20.10..s30.20"],
            "561 candidates are more than the 200 one run explores",
        ),
        (
            vec!["--vary", "kf.state_format=s30.20..s31.21", "--samples", "999"],
            "--samples 999 is too short",
        ),
        (vec!["--guard-bits", "0..60"], "--guard-bits 0..60 is not allowed"),
        (vec![], "--vary KEY=FORMAT..FORMAT (repeatable) or --guard-bits A..B"),
    ] {
        let message = run(&args);
        assert!(message.contains(says), "{args:?}: {message}");
    }
    // The allowed keys are listed.
    let message = run(&["--vary", "foo=s30.20..s31.21"]);
    for key in [
        "estimator.mean_format",
        "kf.state_format",
        "loop.cic_output_format",
    ] {
        assert!(message.contains(key), "{message}");
    }
}

#[test]
fn a_folder_gyrofx_did_not_write_is_refused_before_any_work() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("mine");
    std::fs::create_dir(&out).unwrap();
    std::fs::write(out.join("notes.txt"), "mine").unwrap();
    let output = sweep(&dir.path().join("cache"), &out, &[]);
    assert!(!output.status.success(), "{}", text(&output));
    let message = text(&output);
    assert!(message.contains("notes.txt"), "{message}");
    assert_eq!(
        std::fs::read_to_string(out.join("notes.txt")).unwrap(),
        "mine"
    );
    // Refused before the sweep ran: nothing was synthesized into the cache.
    assert!(
        !dir.path().join("cache").exists() || cache_files(&dir.path().join("cache")).is_empty()
    );
}
