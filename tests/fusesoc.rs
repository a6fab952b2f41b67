//! `gyrofx.core`: the reference RTL as a FuseSoC core. Its file list is the whole of `hdl/`,
//! and FuseSoC's lint target (Verilator -Wall) passes on it and fails without a module.

mod common;

use std::path::Path;

use common::run_tool;

const CORE: &str = "gyrofx:gyrofx:chain";

fn root() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

/// Runs the core's lint target with `cores_root` as the only cores root.
fn lint(cores_root: &Path, work: &Path) -> (bool, String) {
    let root = cores_root.to_str().unwrap();
    run_tool(
        "fusesoc",
        &["--cores-root", root, "run", "--target", "lint", CORE],
        work,
    )
}

fn listed_rtl(core: &str) -> Vec<String> {
    core.lines()
        .filter_map(|l| l.trim().strip_prefix("- hdl/"))
        .map(str::to_string)
        .collect()
}

#[test]
fn the_core_lists_every_rtl_file_and_lints_clean_in_fusesoc() {
    let core = std::fs::read_to_string(root().join("gyrofx.core")).unwrap();
    assert!(core.starts_with("CAPI=2:"));
    let mut listed = listed_rtl(&core);
    listed.sort();
    let mut present: Vec<String> = std::fs::read_dir(root().join("hdl"))
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|n| n.ends_with(".v"))
        .collect();
    present.sort();
    assert_eq!(listed, present, "gyrofx.core must list exactly hdl/*.v");

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
    for rom in ["kf_coefficients.mem", "estimator_gains.mem"] {
        let from = root().join("vectors/roms").join(rom);
        std::fs::copy(from, copy.path().join("vectors/roms").join(rom)).unwrap();
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
