//! Bad input: a clear error naming the field, the value and what is allowed, a non-zero exit,
//! and no output left behind.

mod cli;
mod files;
mod readers;
mod saturation;

use crate::common::*;

/// Generates with `toml` as config into a fresh folder; asserts failure, that every `needle`
/// is in the message, and that no output (nor staging folder) was left.
fn refused(toml: &str, needles: &[&str]) {
    let dir = tempfile::tempdir().unwrap();
    let config = write_config(dir.path(), "bad.toml", toml);
    let out = dir.path().join("out");
    let log = fails(&[
        "generate",
        "--out",
        out.to_str().unwrap(),
        "--config",
        &config,
    ]);
    for needle in needles {
        assert!(
            log.contains(needle),
            "{toml:?}: expected {needle:?} in:\n{log}"
        );
    }
    assert!(log.starts_with("error: "), "{log}");
    assert!(!out.exists(), "{toml:?} left an output folder");
    let leftovers: Vec<_> = std::fs::read_dir(dir.path())
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|n| n != "bad.toml")
        .collect();
    assert!(leftovers.is_empty(), "{toml:?} left {leftovers:?}");
}

#[test]
fn unknown_config_key() {
    refused(
        "[kf]\nbandwith_hz = [10.0]\n",
        &["unknown key kf.bandwith_hz", "line 2", "bandwidths_hz"],
    );
    refused("sampels = 10\n", &["unknown key sampels", "line 1"]);
}

/// A value of the wrong type names the user's file, its line and the key (not the line of the
/// config merged over the default), in the chain's sections and in the loop's.
#[test]
fn a_value_of_the_wrong_type_names_the_users_line() {
    for (toml, needles) in [
        (
            "seed = 2\nsamples = \"many\"\n",
            &["bad.toml: line 2: samples: invalid type: string \"many\""][..],
        ),
        (
            "# mine\n\n[kf]\ntolerance = \"x\"\n",
            &["line 4: kf.tolerance: invalid type"],
        ),
        (
            "[kf]\nbandwidths_hz = [1.0, \"x\"]\n",
            &["line 2: kf.bandwidths_hz[1]"],
        ),
        (
            "\n[loop]\ndecimation = -3\n",
            &["line 3: loop.decimation: invalid value: integer `-3`"],
        ),
        (
            "[front_end]\ndamping_split_drift = { std = \"a\", correlation_time_s = 1.0 }\n",
            &["line 2: front_end.damping_split_drift.std: invalid type"],
        ),
    ] {
        refused(toml, needles);
    }
}

#[test]
fn widths_out_of_range_and_bad_format_strings() {
    refused(
        "[kf]\nstate_format = \"s0.10\"\n",
        &["kf.state_format = \"s0.10\"", "1..=64"],
    );
    refused(
        "[kf]\ninput_format = \"s65.14\"\n",
        &["kf.input_format = \"s65.14\"", "1..=64"],
    );
    refused(
        "[kf]\noutput_format = \"24.14\"\n",
        &["kf.output_format = \"24.14\"", "s18.16"],
    );
    refused(
        "[kf]\ng1_format = \"s18.x\"\n",
        &["kf.g1_format = \"s18.x\""],
    );
    refused(
        "[kf]\ncoefficient_width = 65\n",
        &["kf.coefficient_width = 65", "1..=64"],
    );
}

#[test]
fn negative_or_zero_variances_and_sample_rates() {
    refused(
        "[kf]\narw_deg_per_sqrt_h = -4.87\n",
        &["kf.arw_deg_per_sqrt_h = -4.87", "> 0"],
    );
    refused(
        "[kf]\nrrw_deg_per_h_per_sqrt_h = 0.0\n",
        &["kf.rrw_deg_per_h_per_sqrt_h = 0", "> 0"],
    );
    refused("[stimulus]\nfs_hz = 0.0\n", &["stimulus.fs_hz = 0", "> 0"]);
    refused(
        "[stimulus]\nfs_hz = -50.0\n",
        &["stimulus.fs_hz = -50", "> 0"],
    );
    refused(
        "[kf]\nbandwidths_hz = [10.0, 120.0]\n",
        &["kf.bandwidths_hz[1] = 120", "fs/2 = 100"],
    );
    let log = fails(&[
        "design", "--qw", "26", "--qb", "3e-5", "--qn", "-1", "--fs", "200",
    ]);
    assert!(log.contains("--qn -1") && log.contains("> 0"), "{log}");
    let log = fails(&[
        "design", "--qw", "0", "--qb", "3e-5", "--qn", "1e-3", "--fs", "200",
    ]);
    assert!(log.contains("--qw 0"), "{log}");
    let log = fails(&[
        "design", "--qw", "26", "--qb", "3e-5", "--qn", "1e-3", "--fs", "0",
    ]);
    assert!(log.contains("--fs 0"), "{log}");
    let log = fails(&[
        "design",
        "--bandwidth",
        "150",
        "--qb",
        "3e-5",
        "--qn",
        "1e-3",
        "--fs",
        "200",
    ]);
    assert!(log.contains("fs/2 = 100"), "{log}");
}

#[test]
fn bad_mode_reversal_settings() {
    refused(
        "[sequencer]\nblank = 150\n",
        &["sequencer.blank = 150", "less than interval_length = 150"],
    );
    refused(
        "[sequencer]\nstagger = 150\n",
        &["sequencer.stagger = 150", "less than interval_length = 150"],
    );
    refused(
        "[sequencer]\ninterval_length = 0\n",
        &["sequencer.interval_length = 0", "at least 1"],
    );
    refused(
        "[sequencer]\nintervals = 1\n",
        &["sequencer.intervals = 1", "2..=256"],
    );
    refused(
        "[sequencer]\nintervals = 2\n[estimator]\nrate_order = 1\n",
        &["rank-deficient", "intervals = 2, rate_order = 1"],
    );
    refused(
        "[sequencer]\npattern = \"abba\"\nintervals = 6\n",
        &["sequencer.intervals = 6", "multiple of 4"],
    );
    refused(
        "[estimator]\ngain_width = 1\n",
        &[
            "estimator: coefficient gA[mA0]",
            "quantizes to zero in s1.1",
        ],
    );
}

#[test]
fn a_coefficient_that_does_not_fit() {
    // g1 of the 30 Hz entry is about 0.58: s18.18 holds only [-0.5, 0.5).
    refused(
        "[kf]\ng1_format = \"s18.18\"\n",
        &[
            "coefficient g1 for 30 Hz",
            "does not fit s18.18",
            "needs 19 bits",
        ],
    );
    // g2 (~1e-7) vanishes at 17 fraction bits.
    refused(
        "[kf]\ng2_format = \"s18.17\"\n",
        &["coefficient g2", "quantizes to zero in s18.17"],
    );
}

#[test]
fn a_missing_or_nan_csv_cell_names_its_line() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(
        dir.path().join("rate.csv"),
        "t,rate_dps\n0,1.0\n1,2.0\n2,NaN\n",
    )
    .unwrap();
    std::fs::write(dir.path().join("gap.csv"), "t,rate_dps\n0,1.0\n1,\n").unwrap();
    for (file, needle) in [
        (
            "rate.csv",
            "line 4, column \"rate_dps\": NaN is not allowed",
        ),
        ("gap.csv", "line 3, column \"rate_dps\": the cell is empty"),
    ] {
        let config = write_config(
            dir.path(),
            "csv.toml",
            &format!("[stimulus]\nsource = \"csv\"\ncsv_path = \"{file}\"\n"),
        );
        let out = dir.path().join("out");
        let log = fails(&[
            "generate",
            "--out",
            out.to_str().unwrap(),
            "--config",
            &config,
        ]);
        assert!(log.contains(needle) && log.contains(file), "{log}");
        assert!(!out.exists());
        let output = dir.path().join("filtered.csv");
        let input = dir.path().join(file);
        let log = fails(&[
            "filter",
            "--input",
            input.to_str().unwrap(),
            "--fs",
            "200",
            "--output",
            output.to_str().unwrap(),
        ]);
        assert!(log.contains(needle), "{log}");
        assert!(!output.exists());
    }
}

/// A CSV stimulus shorter than the run is refused, naming both counts, rather than silently
/// running a record too short to analyse; `--samples` within it runs.
#[test]
fn a_csv_stimulus_shorter_than_the_run_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let rows: String = (0..300).map(|k| format!("{k},1.5\n")).collect();
    std::fs::write(dir.path().join("rate.csv"), format!("t,rate_dps\n{rows}")).unwrap();
    let config = write_config(
        dir.path(),
        "csv.toml",
        "[plant]\nmodel = \"rate\"\n[stimulus]\nsource = \"csv\"\ncsv_path = \"rate.csv\"\n",
    );
    let out = dir.path().join("out");
    let log = fails(&[
        "generate",
        "--out",
        out.to_str().unwrap(),
        "--config",
        &config,
    ]);
    assert!(
        log.contains("rate.csv: column rate_dps has 300 values but samples = 10000")
            && log.contains("samples <= 300"),
        "{log}"
    );
    assert!(!out.exists());
    ok(&[
        "generate",
        "--out",
        out.to_str().unwrap(),
        "--config",
        &config,
        "--samples",
        "300",
    ]);
}

#[test]
fn an_unwritable_output_folder() {
    let dir = tempfile::tempdir().unwrap();
    // A regular file where a parent folder should be: no user, root included, can write there.
    let blocker = dir.path().join("file");
    std::fs::write(&blocker, "not a folder").unwrap();
    let out = blocker.join("out");
    let log = fails(&[
        "generate",
        "--out",
        out.to_str().unwrap(),
        "--samples",
        "100",
    ]);
    assert!(
        log.contains("output folder") && log.contains("file/out"),
        "{log}"
    );
    // A non-empty folder that is not a gyrofx output is never replaced.
    let user = dir.path().join("mine");
    std::fs::create_dir(&user).unwrap();
    std::fs::write(user.join("notes.txt"), "keep me").unwrap();
    let log = fails(&[
        "generate",
        "--out",
        user.to_str().unwrap(),
        "--samples",
        "100",
    ]);
    assert!(log.contains("not a gyrofx output"), "{log}");
    assert_eq!(
        std::fs::read_to_string(user.join("notes.txt")).unwrap(),
        "keep me"
    );
    // A previous gyrofx output is replaced whole; one holding a file gyrofx did not write only
    // with --force (tests/output_folder.rs covers the rest).
    let previous = dir.path().join("previous");
    ok(&[
        "generate",
        "--out",
        previous.to_str().unwrap(),
        "--samples",
        "100",
    ]);
    ok(&[
        "generate",
        "--out",
        previous.to_str().unwrap(),
        "--samples",
        "110",
    ]);
    std::fs::write(previous.join("stale.txt"), "old").unwrap();
    let log = fails(&[
        "generate",
        "--out",
        previous.to_str().unwrap(),
        "--samples",
        "120",
    ]);
    assert!(log.contains("stale.txt"), "{log}");
    ok(&[
        "generate",
        "--out",
        previous.to_str().unwrap(),
        "--samples",
        "120",
        "--force",
    ]);
    assert!(!previous.join("stale.txt").exists());
    let names: Vec<_> = std::fs::read_dir(dir.path())
        .unwrap()
        .map(|e| e.unwrap().file_name())
        .collect();
    assert_eq!(names.len(), 3, "no staging leftovers: {names:?}");
}

#[test]
fn verify_refuses_a_folder_that_is_not_a_package_and_unknown_simulators() {
    let dir = tempfile::tempdir().unwrap();
    let log = fails(&[
        "verify",
        "--out",
        dir.path().to_str().unwrap(),
        "--sim",
        "iverilog",
    ]);
    assert!(log.contains("not a gyrofx package"), "{log}");
    let log = fails(&[
        "verify",
        "--out",
        dir.path().to_str().unwrap(),
        "--sim",
        "modelsim",
    ]);
    assert!(log.contains("\"modelsim\" is not supported"), "{log}");
}

/// Usage errors (a bad argument value) exit with 2, as clap's own do; failures of the work
/// exit with 1; every error is one line, its cause not repeated.
#[test]
fn usage_errors_exit_2_failures_exit_1_and_each_error_is_said_once() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out");
    let out = out.to_str().unwrap();
    let missing = dir.path().join("missing.toml");
    for (args, code, needle) in [
        (
            vec![
                "generate",
                "--out",
                out,
                "--config",
                missing.to_str().unwrap(),
            ],
            1,
            "No such file or directory",
        ),
        (
            vec!["generate", "--out", out, "--samples", "1.5"],
            2,
            "'1.5' is not a count",
        ),
        (vec!["reproduce", "--paper", "9"], 2, "--paper \"9\""),
        (
            vec!["allan", "--input", out, "--rate", "-1"],
            2,
            "--rate -1 is not allowed",
        ),
    ] {
        let output = gyrofx(&args);
        let log = text(&output);
        assert_eq!(output.status.code(), Some(code), "{args:?}: {log}");
        assert_eq!(log.matches(needle).count(), 1, "{args:?}: {log}");
        assert!(log.starts_with("error: "), "{log}");
    }
    // A count may be written in exponent form.
    ok(&[
        "generate",
        "--out",
        out,
        "--config",
        &write_config(dir.path(), "rate.toml", "[plant]\nmodel = \"rate\"\n"),
        "--samples",
        "2e2",
    ]);
}

/// A reader that closes stdout early (`gyrofx init | head -1`) ends gyrofx quietly with exit
/// 0, no panic message.
#[test]
fn a_closed_stdout_ends_quietly() {
    for args in [&["init"][..], &["init", "--preset", "gu2019"]] {
        let mut child = std::process::Command::new(env!("CARGO_BIN_EXE_gyrofx"))
            .args(args)
            .stdout(std::process::Stdio::piped())
            .stderr(std::process::Stdio::piped())
            .spawn()
            .unwrap();
        // Closed before the program has started writing.
        drop(child.stdout.take());
        let output = child.wait_with_output().unwrap();
        assert_eq!(output.status.code(), Some(0), "{args:?}");
        assert!(
            output.stderr.is_empty(),
            "{args:?}: {}",
            String::from_utf8_lossy(&output.stderr)
        );
    }
}

/// `filter`: an --output that is the --input is refused untouched; an --output whose folder
/// does not exist fails before the work; a record at a rate other than the default plant's
/// is filtered; the CSV and a plot follow the umask (not a temporary file's 0600).
#[test]
fn filter_guards_its_input_and_writes_files_by_the_umask() {
    let dir = tempfile::tempdir().unwrap();
    let input = dir.path().join("in.csv");
    let rows: String = (0..50)
        .map(|k| format!("{k},{}\n", k as f64 * 0.1))
        .collect();
    std::fs::write(&input, format!("t,rate_dps\n{rows}")).unwrap();
    let before = std::fs::read(&input).unwrap();
    let input_text = input.to_str().unwrap();
    let output = gyrofx(&[
        "filter", "--input", input_text, "--fs", "100", "--output", input_text,
    ]);
    assert_eq!(output.status.code(), Some(2), "{}", text(&output));
    assert!(text(&output).contains("is the --input file"));
    assert_eq!(std::fs::read(&input).unwrap(), before);

    let log = fails(&[
        "filter",
        "--input",
        input_text,
        "--fs",
        "100",
        "--output",
        dir.path().join("no/such/folder/out.csv").to_str().unwrap(),
    ]);
    assert!(
        log.contains("cannot create a file in") && !log.contains(".gyrofx-filter-"),
        "{log}"
    );

    let filtered = dir.path().join("out.csv");
    ok(&[
        "filter",
        "--input",
        input_text,
        "--fs",
        "100",
        "--output",
        filtered.to_str().unwrap(),
    ]);
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt;
        // The test process's umask is what the file must follow: read it back from a file
        // created the ordinary way.
        let probe = dir.path().join("probe");
        std::fs::write(&probe, "").unwrap();
        let expected = std::fs::metadata(&probe).unwrap().permissions().mode() & 0o777;
        let mode = std::fs::metadata(&filtered).unwrap().permissions().mode() & 0o777;
        assert_eq!(mode, expected, "filtered CSV mode {mode:o}");
        let plot = dir.path().join("allan.png");
        ok(&[
            "allan",
            "--input",
            input_text,
            "--rate",
            "100",
            "--plot",
            plot.to_str().unwrap(),
        ]);
        let mode = std::fs::metadata(&plot).unwrap().permissions().mode() & 0o777;
        assert_eq!(mode, expected, "plot mode {mode:o}");
    }
}

/// A quantizer that saturates on the run's data is a warning naming the signals; `--strict`
/// makes it an error that writes nothing.
#[test]
fn overflow_is_a_warning_and_strict_makes_it_an_error() {
    let dir = tempfile::tempdir().unwrap();
    let config = write_config(
        dir.path(),
        "fast.toml",
        "[plant]\nmodel = \"rate\"\n[stimulus]\nscenario = \"constant\"\nrate_dps = 600.0\n",
    );
    let out = dir.path().join("out");
    let out = out.to_str().unwrap();
    let output = gyrofx(&[
        "generate",
        "--out",
        out,
        "--config",
        &config,
        "--samples",
        "400",
    ]);
    let log = text(&output);
    assert!(output.status.success(), "{log}");
    assert!(
        log.contains("warning: quantizers overflowed or saturated on the chain run's data: ADC A 400, ADC B 400"),
        "{log}"
    );
    let strict = dir.path().join("strict");
    let output = gyrofx(&[
        "generate",
        "--out",
        strict.to_str().unwrap(),
        "--config",
        &config,
        "--samples",
        "400",
        "--strict",
    ]);
    assert_eq!(output.status.code(), Some(1), "{}", text(&output));
    assert!(text(&output).contains("--strict: quantizers overflowed"));
    assert!(!strict.exists());
    // The default's run saturates nothing (a resonator loop's switching transient saturates
    // only blanked samples, which are not counted).
    let clean = gyrofx(&["generate", "--out", out, "--samples", "400", "--strict"]);
    assert!(clean.status.success(), "{}", text(&clean));
    assert!(!text(&clean).contains("warning"), "{}", text(&clean));
}

/// `allan` and `davar` refuse what they cannot analyse, naming it: values whose Allan sums
/// would overflow (the row), a non-finite PID gain, PID options without
/// `--adaptive`, an unknown kind (usage errors exit 2); the plot's title names the kind.
#[test]
fn allan_and_davar_refuse_what_they_cannot_analyse() {
    let dir = tempfile::tempdir().unwrap();
    let write = |name: &str, values: &[f64]| {
        let rows: String = values.iter().map(|v| format!("{v:e}\n")).collect();
        let path = dir.path().join(name);
        std::fs::write(&path, format!("rate_dps\n{rows}")).unwrap();
        path.to_string_lossy().into_owned()
    };
    let mut huge = vec![0.5; 100];
    huge[37] = 1e300;
    let huge = write("huge.csv", &huge);
    let log = fails(&["allan", "--input", &huge, "--rate", "100"]);
    assert!(
        log.contains("value 37 = 1e300") && log.contains("overflow"),
        "{log}"
    );
    // A constant record: every deviation 0, every noise term 0 (it was Q = NaN).
    let constant = write("constant.csv", &[2.5; 100]);
    let log = ok(&["allan", "--input", &constant, "--rate", "100"]);
    assert!(
        log.contains("quantization Q") && !log.contains("NaN"),
        "{log}"
    );
    let json = ok(&["allan", "--input", &constant, "--rate", "100", "--json"]);
    assert!(
        !json.contains("NaN") && !json.contains("null,\n    \"lo\""),
        "{json}"
    );

    let noise: Vec<f64> = (0..4000)
        .map(|k| ((k * 7919) % 1000) as f64 / 1000.0)
        .collect();
    let noise = write("noise.csv", &noise);
    for (args, needle) in [
        (
            vec![
                "davar",
                "--input",
                &noise,
                "--rate",
                "100",
                "--window",
                "401",
                "--adaptive",
                "--kp",
                "nan",
            ],
            "--kp NaN is not allowed",
        ),
        (
            vec![
                "davar", "--input", &noise, "--rate", "100", "--window", "401", "--kp", "3",
            ],
            "--adaptive",
        ),
        (
            vec![
                "allan", "--input", &noise, "--rate", "100", "--kind", "total",
            ],
            "--kind total is not a deviation",
        ),
        (
            vec![
                "allan", "--input", &noise, "--rate", "100", "--taus", "some",
            ],
            "--taus",
        ),
    ] {
        let output = gyrofx(&args);
        let log = text(&output);
        assert_eq!(output.status.code(), Some(2), "{args:?}: {log}");
        assert!(log.contains(needle), "{args:?}: {log}");
    }
    let svg = dir.path().join("hadamard.svg");
    ok(&[
        "allan",
        "--input",
        &noise,
        "--rate",
        "100",
        "--kind",
        "hadamard",
        "--plot",
        svg.to_str().unwrap(),
    ]);
    let text = std::fs::read_to_string(&svg).unwrap();
    assert!(text.contains("Hadamard deviation") && !text.contains(">Allan deviation<"));
}

/// `filter` on a record beyond the KF's input range: a warning with the counts and the output
/// written; with `--strict` an error, exit 1 and no output file.
#[test]
fn filter_warns_of_saturation_and_strict_refuses_it() {
    let dir = tempfile::tempdir().unwrap();
    // s24.14 holds ±512 °/s: three samples at 1000 °/s saturate it.
    let rows: String = (0..200)
        .map(|k| format!("{k},{}\n", if (50..53).contains(&k) { 1000.0 } else { 1.0 }))
        .collect();
    let input = dir.path().join("rate.csv");
    std::fs::write(&input, format!("t,rate_dps\n{rows}")).unwrap();
    let output = dir.path().join("filtered.csv");
    let args = |strict: bool| {
        let mut a = vec![
            "filter".to_string(),
            "--input".into(),
            input.to_string_lossy().into_owned(),
            "--fs".into(),
            "200".into(),
            "--output".into(),
            output.to_string_lossy().into_owned(),
        ];
        if strict {
            a.push("--strict".into());
        }
        a
    };
    let strict = args(true);
    let strict: Vec<&str> = strict.iter().map(String::as_str).collect();
    let log = fails(&strict);
    assert!(
        log.contains("--strict") && log.contains("saturated the KF's input format s24.14 3 times"),
        "{log}"
    );
    assert!(!output.exists());
    let lenient = args(false);
    let lenient: Vec<&str> = lenient.iter().map(String::as_str).collect();
    let log = ok(&lenient);
    assert!(log.contains("warning:") && log.contains("3 times"), "{log}");
    let text = std::fs::read_to_string(&output).unwrap();
    assert_eq!(text.lines().count(), 201, "header and one row per sample");
    // The saturated input is written as the format's largest value, not as 1000.
    let row = text.lines().nth(51).unwrap();
    let z: f64 = row.split(',').nth(1).unwrap().parse().unwrap();
    assert!(z < 512.0 && z > 511.99, "{row}");
}
