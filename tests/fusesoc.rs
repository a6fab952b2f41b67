//! `gyrofx.core`: the reference RTL as a FuseSoC core. Its file lists are the whole of `hdl/`
//! (the VHDL testbench package aside), FuseSoC's lint target (Verilator -Wall) passes on it and
//! fails without a module, and its VHDL target (GHDL) analyses and elaborates the VHDL twin.

use std::path::Path;

use crate::common::run_tool;

const CORE: &str = "gyrofx:gyrofx:chain";

fn root() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

/// Runs the core's `target` with `cores_root` as the only cores root.
fn run_target(cores_root: &Path, target: &str, work: &Path) -> (bool, String) {
    let root = cores_root.to_str().unwrap();
    run_tool(
        "fusesoc",
        &["--cores-root", root, "run", "--target", target, CORE],
        work,
    )
}

fn lint(cores_root: &Path, work: &Path) -> (bool, String) {
    run_target(cores_root, "lint", work)
}

/// The core's `hdl/` files ending in `extension`, sorted.
fn listed_rtl(core: &str, extension: &str) -> Vec<String> {
    let mut listed: Vec<String> = core
        .lines()
        .filter_map(|l| l.trim().strip_prefix("- hdl/"))
        .filter(|n| n.ends_with(extension))
        .map(str::to_string)
        .collect();
    listed.sort();
    listed
}

/// `hdl/` files ending in `extension`, sorted.
fn present_rtl(extension: &str) -> Vec<String> {
    let mut present: Vec<String> = std::fs::read_dir(root().join("hdl"))
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|n| n.ends_with(extension))
        .collect();
    present.sort();
    present
}

#[test]
fn the_core_lists_the_vhdl_twin_which_ghdl_elaborates_through_fusesoc() {
    let core = std::fs::read_to_string(root().join("gyrofx.core")).unwrap();
    let present: Vec<String> = present_rtl(".vhd")
        .into_iter()
        .filter(|n| n != "gyrofx_testbench_pkg.vhd")
        .collect();
    assert_eq!(
        listed_rtl(&core, ".vhd"),
        present,
        "gyrofx.core must list hdl/*.vhd but the testbench package"
    );
    let work = tempfile::tempdir().unwrap();
    let (passed, log) = run_target(root(), "lint_vhdl", work.path());
    assert!(passed, "fusesoc lint_vhdl: {log}");
    assert!(
        log.contains("ghdl -m --std=08"),
        "GHDL must elaborate: {log}"
    );
    assert!(!log.contains("warning"), "{log}");
}

#[test]
fn the_core_lists_every_rtl_file_and_lints_clean_in_fusesoc() {
    let core = std::fs::read_to_string(root().join("gyrofx.core")).unwrap();
    assert!(core.starts_with("CAPI=2:"));
    let present = present_rtl(".v");
    assert_eq!(
        listed_rtl(&core, ".v"),
        present,
        "gyrofx.core must list exactly hdl/*.v"
    );

    let work = tempfile::tempdir().unwrap();
    let (passed, log) = lint(root(), work.path());
    assert!(passed, "fusesoc lint: {log}");

    // The same core without the KF in its file list must fail.
    let copy = tempfile::tempdir().unwrap();
    for folder in ["hdl", "vectors/roms"] {
        std::fs::create_dir_all(copy.path().join(folder)).unwrap();
    }
    for name in &present {
        std::fs::copy(
            root().join("hdl").join(name),
            copy.path().join("hdl").join(name),
        )
        .unwrap();
    }
    for entry in std::fs::read_dir(root().join("vectors/roms")).unwrap() {
        let from = entry.unwrap().path();
        if from.extension().is_some_and(|e| e == "mem") {
            let name = from.file_name().unwrap();
            std::fs::copy(&from, copy.path().join("vectors/roms").join(name)).unwrap();
        }
    }
    let without_kf = core.replace("      - hdl/gyrofx_kf.v\n", "");
    assert_ne!(without_kf, core);
    std::fs::write(copy.path().join("gyrofx.core"), without_kf).unwrap();
    let work = tempfile::tempdir().unwrap();
    let (passed, log) = lint(copy.path(), work.path());
    assert!(
        !passed && log.contains("gyrofx_kf"),
        "lint without gyrofx_kf.v should fail on the missing module: {log}"
    );
}

/// A generated package's own core (`gyrofx_package.core`) runs a block's testbench on its
/// vectors through `fusesoc run` in Icarus, Verilator and GHDL; with one expected bit flipped
/// the same runs fail at that sample.
#[test]
fn a_packages_core_runs_its_testbenches_in_every_simulator_and_a_flipped_bit_fails() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("pkg");
    let out_text = out.to_str().unwrap();
    crate::common::ok(&[
        "generate",
        "--out",
        out_text,
        "--blocks",
        "kf",
        "--samples",
        "300",
        "--no-csv",
    ]);
    let run = |work: &Path, target: &str, tool: &str| {
        std::fs::create_dir_all(work).unwrap();
        run_tool(
            "fusesoc",
            &[
                "--cores-root",
                out_text,
                "run",
                "--target",
                target,
                "--tool",
                tool,
                "gyrofx:package:vectors",
            ],
            work,
        )
    };
    let runs = [
        ("sim_kf", "icarus"),
        ("sim_kf", "verilator"),
        ("sim_kf_vhdl", "ghdl"),
    ];
    for (target, tool) in runs {
        let (ok, log) = run(&dir.path().join("work"), target, tool);
        assert!(ok && log.contains("PASS n="), "{target} {tool}:\n{log}");
    }
    let (signal, sample) = crate::common::flip_checked_bit(&out, "kf", 100);
    for (target, tool) in runs {
        let (ok, log) = run(&dir.path().join("flipped"), target, tool);
        assert!(
            !ok && log.contains(&format!("MISMATCH sample {sample} signal {signal}")),
            "{target} {tool} passed a flipped bit:\n{log}"
        );
    }
}
