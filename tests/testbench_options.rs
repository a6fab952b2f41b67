//! The testbench options, the same in every simulator through the package's Makefile (MASK,
//! MAX_REPORTED, MAX_MISMATCHES, WAVES) and through `gyrofx verify` (and its JUnit summary).

use std::path::Path;

use crate::common::*;

/// Runs `make <sim>-kf` in the package with `variables`; (exit ok, output).
fn make_kf(package: &Path, sim: &str, variables: &[&str]) -> (bool, String) {
    let mut args = vec!["--no-print-directory", "-C", package.to_str().unwrap()];
    let target = format!("{sim}-kf");
    args.push(&target);
    args.extend_from_slice(variables);
    run_tool("make", &args, package)
}

fn mismatch_lines(log: &str) -> usize {
    log.lines().filter(|l| l.starts_with("MISMATCH ")).count()
}

#[test]
fn mask_cap_report_limit_and_waves_work_in_every_simulator() {
    let dir = tempfile::tempdir().unwrap();
    let package = generate_default(dir.path(), "400");
    // Mismatches at samples 1, 2 (inside a mask of 3) and at 50..=57 (outside).
    flip_expected_bit(&package, "kf", 1);
    flip_expected_bit(&package, "kf", 2);
    for sample in 50..=57 {
        flip_expected_bit(&package, "kf", sample);
    }
    for sim in SIMULATORS {
        let (ok, log) = make_kf(&package, sim, &[]);
        assert!(!ok, "{sim}: {log}");
        assert!(log.contains("FAIL mismatches=10 n="), "{sim}: {log}");
        assert!(
            log.contains("MISMATCH sample 1 signal rate_out"),
            "{sim}: {log}"
        );
        assert_eq!(mismatch_lines(&log), 10, "{sim}: {log}");

        // The mask hides the first two; the rest still fail.
        let (ok, log) = make_kf(&package, sim, &["MASK=3"]);
        assert!(!ok, "{sim}: {log}");
        assert!(log.contains("FAIL mismatches=8 n="), "{sim}: {log}");
        assert!(!log.contains("MISMATCH sample 1 "), "{sim}: {log}");

        let (ok, log) = make_kf(&package, sim, &["MAX_REPORTED=2"]);
        assert!(!ok, "{sim}: {log}");
        assert_eq!(mismatch_lines(&log), 2, "{sim}: {log}");
        assert!(log.contains("FAIL mismatches=10 n="), "{sim}: {log}");

        // The cap stops the run at the fourth mismatch (sample 51).
        let (ok, log) = make_kf(&package, sim, &["MAX_MISMATCHES=4"]);
        assert!(!ok, "{sim}: {log}");
        assert!(
            log.contains("FAIL mismatches=4 n=52 first=1 (stopped at"),
            "{sim}: {log}"
        );

        let vcd = package.join("kf/tb_gyrofx_kf.vcd");
        let _ = std::fs::remove_file(&vcd);
        let (_, log) = make_kf(&package, sim, &["WAVES=1", "MAX_MISMATCHES=1"]);
        let dump = std::fs::read_to_string(&vcd).unwrap_or_else(|e| panic!("{sim}: {e}\n{log}"));
        assert!(
            dump.contains("$enddefinitions") && dump.contains("rate_out"),
            "{sim}: not a VCD with rate_out"
        );
    }
    // A mask over the whole run passes and says how much it masked.
    for sim in ["iverilog", "ghdl"] {
        let (ok, log) = make_kf(&package, sim, &["MASK=100000"]);
        assert!(ok, "{sim}: {log}");
        assert!(
            log.contains("PASS n=") && log.contains(" masked="),
            "{sim}: {log}"
        );
    }
}

#[test]
fn verify_writes_a_junit_summary_per_simulator_and_block() {
    let dir = tempfile::tempdir().unwrap();
    let package = generate_default(dir.path(), "300");
    let junit = dir.path().join("results.xml");
    let out = package.to_str().unwrap();
    ok(&[
        "verify",
        "--out",
        out,
        "--sim",
        "iverilog",
        "--blocks",
        CHAIN_BLOCKS,
        "--junit",
        junit.to_str().unwrap(),
    ]);
    // The chain's blocks: a test case per block is one code path whatever the block, and the
    // closed-loop benches take a minute in Icarus, minutes in GHDL.
    let xml = std::fs::read_to_string(&junit).unwrap();
    let tests = format!("tests=\"{CHAIN_BLOCK_COUNT}\" failures=\"0\"");
    assert!(xml.contains(&tests), "{xml}");
    for block in CHAIN_BLOCKS.split(',') {
        assert!(
            xml.contains(&format!("classname=\"gyrofx.iverilog\" name=\"{block}\"")),
            "{block}: {xml}"
        );
    }

    let signal = flip_expected_bit(&package, "top", 120);
    fails(&[
        "verify",
        "--out",
        out,
        "--sim",
        "ghdl",
        "--blocks",
        CHAIN_BLOCKS,
        "--junit",
        junit.to_str().unwrap(),
    ]);
    let xml = std::fs::read_to_string(&junit).unwrap();
    assert!(
        xml.contains(&format!(
            "<testsuite name=\"ghdl\" tests=\"{CHAIN_BLOCK_COUNT}\" failures=\"1\""
        )),
        "{xml}"
    );
    let top = xml.split("name=\"top\"").nth(1).expect("a top testcase");
    assert!(
        top.contains("<failure message=\"FAIL mismatches=1 n=")
            && top.contains(&format!("MISMATCH sample 120 signal {signal}")),
        "{xml}"
    );
    // A bad option value is refused before anything runs.
    let log = fails(&["verify", "--out", out, "--sim", "modelsim"]);
    assert!(
        log.contains("\"modelsim\"") && log.contains("ghdl"),
        "{log}"
    );
}
