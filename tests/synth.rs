//! `gyrofx synth`: the chain synthesizes in yosys with the config's widths, wider formats cost
//! more, and the check fails on a latch or a missing module without writing anything.

mod common;

use std::path::Path;

use common::*;
use gyrofx_codegen::synth::measure;

fn manifest(dir: &Path) -> serde_json::Value {
    let text = std::fs::read_to_string(dir.join("manifest.json")).unwrap();
    serde_json::from_str(&text).unwrap()
}

fn resource(manifest: &serde_json::Value, flow: &str, what: &str) -> u64 {
    manifest["resources"][flow][what]
        .as_u64()
        .unwrap_or_else(|| panic!("manifest has no resources.{flow}.{what}"))
}

fn copy_folder(from: &Path, to: &Path) {
    std::fs::create_dir_all(to).unwrap();
    for entry in std::fs::read_dir(from).unwrap() {
        let entry = entry.unwrap();
        if entry.file_type().unwrap().is_file() {
            std::fs::copy(entry.path(), to.join(entry.file_name())).unwrap();
        }
    }
}

#[test]
fn the_chain_synthesizes_and_wider_formats_cost_more_and_latches_fail() {
    let dir = tempfile::tempdir().unwrap();
    let narrow = dir.path().join("narrow");
    let log = ok(&["synth", "--out", narrow.to_str().unwrap()]);
    assert!(log.contains("synthesis check passed"), "{log}");
    let narrow_manifest = manifest(&narrow);
    let report = std::fs::read_to_string(narrow.join("report.md")).unwrap();
    for flow_what in [("generic", "flip_flops"), ("xilinx", "luts")] {
        let n = resource(&narrow_manifest, flow_what.0, flow_what.1);
        assert!(n > 0, "{flow_what:?}");
        assert!(report.contains(&format!("| {n} |")), "report lacks {n}");
    }
    // The KF's two gain products and the estimator's products are real multipliers.
    assert!(resource(&narrow_manifest, "generic", "multipliers") >= 2);
    // One gyro's loop is synthesized beside the chain: its demodulators' four products, the
    // PIs' four, the DAC's and the two 1/SF products at least.
    let loop_resources = &narrow_manifest["gyro_loop"]["resources"];
    assert!(loop_resources["generic"]["multipliers"].as_u64().unwrap() >= 11);
    assert!(loop_resources["xilinx"]["luts"].as_u64().unwrap() > 0);
    let loop_luts = loop_resources["xilinx"]["luts"].as_u64().unwrap();
    assert!(report.contains("gyrofx_gyro_loop") && report.contains(&format!("| {loop_luts} |")));
    for file in [
        "gyro_loop/generic.ys",
        "gyro_loop/yosys/xilinx.json",
        "gyro_loop/gyrofx_gyro_loop.v",
    ] {
        assert!(narrow.join(file).is_file(), "{file}");
    }
    for file in [
        "generic.ys",
        "xilinx.ys",
        "yosys/generic.log",
        "gyrofx_top.v",
    ] {
        assert!(narrow.join(file).is_file(), "{file}");
    }

    let config = write_config(
        dir.path(),
        "wide.toml",
        "[kf]\nstate_format = \"s48.38\"\ncoefficient_width = 25\n",
    );
    let wide = dir.path().join("wide");
    ok(&[
        "synth",
        "--out",
        wide.to_str().unwrap(),
        "--config",
        &config,
    ]);
    let wide_manifest = manifest(&wide);
    for (flow, what) in [
        ("generic", "flip_flops"),
        ("generic", "cells"),
        ("xilinx", "flip_flops"),
        ("xilinx", "luts"),
    ] {
        let (n, w) = (
            resource(&narrow_manifest, flow, what),
            resource(&wide_manifest, flow, what),
        );
        assert!(w > n, "{flow} {what}: wide {w} should exceed narrow {n}");
    }
    // 24 more state bits in two registers.
    assert_eq!(
        resource(&wide_manifest, "generic", "flip_flops")
            - resource(&narrow_manifest, "generic", "flip_flops"),
        2 * (48 - 36)
    );

    // The same scripts on a requantizer whose rounding branch no longer always assigns.
    let latched = dir.path().join("latched");
    copy_folder(&narrow, &latched);
    let source = std::fs::read_to_string(latched.join("gyrofx_quantize.v")).unwrap();
    let broken = source.replace(
        "3: increment = half_bit;",
        "3: if (half_bit) increment = 1'b1;",
    );
    assert_ne!(source, broken, "the mutation must apply");
    std::fs::write(latched.join("gyrofx_quantize.v"), broken).unwrap();
    let error = measure(&latched).unwrap_err().to_string();
    assert!(error.contains("synthesis check failed"), "{error}");
    assert!(error.contains("dlatch"), "{error}");

    let missing = dir.path().join("missing");
    copy_folder(&narrow, &missing);
    std::fs::remove_file(missing.join("gyrofx_kf.v")).unwrap();
    let error = measure(&missing).unwrap_err().to_string();
    assert!(error.contains("gyrofx_kf"), "{error}");

    // A config error leaves no output folder.
    let bad = write_config(dir.path(), "bad.toml", "[kf]\ncoefficient_width = 0\n");
    let none = dir.path().join("none");
    let error = fails(&["synth", "--out", none.to_str().unwrap(), "--config", &bad]);
    assert!(error.contains("kf.coefficient_width"), "{error}");
    assert!(!none.exists());
}
