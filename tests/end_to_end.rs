//! generate → verify in Icarus, Verilator and GHDL → pass; and every way it must fail.

use crate::common::*;

/// The package path as the CLI arguments take it.
fn generate_default_str(dir: &std::path::Path, samples: &str) -> String {
    generate_default(dir, samples)
        .to_string_lossy()
        .into_owned()
}

fn pass_lines(log: &str) -> Vec<String> {
    log.lines()
        .filter(|l| l.starts_with("== ") || l.starts_with("PASS"))
        .map(str::to_string)
        .collect()
}

/// The default package (6000 samples) passes every block's testbench in `sim`; then, block by
/// block, one expected bit flipped makes that testbench fail at that sample and signal, and
/// the bit is put back (the file is byte for byte what it was). Icarus runs the last chain
/// block's flip over every chain block to the end: the failing block does not stop the others,
/// which still pass.
fn default_package_passes_and_a_flipped_bit_fails_every_testbench(sim: &str) {
    let dir = tempfile::tempdir().unwrap();
    let out = generate_default_str(dir.path(), "6000");
    let root = std::path::Path::new(&out);
    let log = ok(&["verify", "--out", &out, "--sim", sim]);
    let lines = pass_lines(&log);
    assert_eq!(lines.len(), 2 * BLOCKS.len(), "{sim}: {log}");
    for (pair, block) in lines.chunks(2).zip(BLOCKS) {
        assert_eq!(pair[0], format!("== {block}"), "{sim}: {log}");
        assert!(pair[1].starts_with("PASS n="), "{sim} {block}: {log}");
    }
    if sim == "verilator" {
        for block in BLOCKS {
            let build_log =
                std::fs::read_to_string(root.join(block).join("verilator_build.log")).unwrap();
            assert!(
                !build_log.contains("%Warning"),
                "Verilator warns on the {block} testbench:\n{build_log}"
            );
        }
    }

    for block in BLOCKS {
        let expected = root.join(block).join(format!("{block}_expected.hex"));
        let original = std::fs::read(&expected).unwrap();
        let (signal, sample) = flip_checked_bit(root, block, 1234);
        // Only the flipped block, stopping at its first mismatch (the closed-loop benches
        // take minutes to the end in GHDL), except the last chain block's flip in Icarus.
        let every_chain_block = sim == "iverilog" && block == "mean_filter";
        let blocks = if every_chain_block {
            CHAIN_BLOCKS
        } else {
            block
        };
        let mut args = vec!["verify", "--out", &out, "--sim", sim, "--blocks", blocks];
        if !every_chain_block {
            args.extend(["--max-mismatches", "1"]);
        }
        let log = fails(&args);
        assert!(
            log.contains(&format!("MISMATCH sample {sample} signal {signal}")),
            "{sim} {block}: {log}"
        );
        assert!(log.contains("FAIL mismatches=1 n="), "{sim} {block}: {log}");
        if every_chain_block {
            assert_eq!(
                log.matches("PASS n=").count(),
                CHAIN_BLOCK_COUNT - 1,
                "{sim} {block}: {log}"
            );
        }
        flip_expected_bit(root, block, sample);
        assert!(
            std::fs::read(&expected).unwrap() == original,
            "{block}: the flipped bit is not put back"
        );
    }
}

#[test]
fn default_package_passes_in_icarus_and_a_flipped_bit_fails_every_testbench() {
    default_package_passes_and_a_flipped_bit_fails_every_testbench("iverilog");
}

#[test]
fn default_package_passes_in_verilator_and_a_flipped_bit_fails_every_testbench() {
    default_package_passes_and_a_flipped_bit_fails_every_testbench("verilator");
}

#[test]
fn default_package_passes_in_ghdl_and_a_flipped_bit_fails_every_testbench() {
    default_package_passes_and_a_flipped_bit_fails_every_testbench("ghdl");
}

/// `make sim-iverilog` runs every block of the package. The chain's blocks only: the
/// Makefile's recipes are one pattern for every block, and the closed-loop ones take a minute
/// in Icarus (the Icarus end-to-end test runs them through the same Makefile).
#[test]
fn the_package_runs_without_gyrofx_through_its_makefile() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("pkg");
    let out = out.to_str().unwrap();
    ok(&[
        "generate",
        "--out",
        out,
        "--samples",
        "500",
        "--blocks",
        CHAIN_BLOCKS,
    ]);
    let make = std::process::Command::new("make")
        .args(["-C", out, "sim-iverilog"])
        .output()
        .unwrap();
    assert!(make.status.success(), "{}", text(&make));
    assert_eq!(
        String::from_utf8_lossy(&make.stdout)
            .matches("PASS n=")
            .count(),
        CHAIN_BLOCK_COUNT,
        "{}",
        text(&make)
    );
}

#[test]
fn a_vector_file_with_other_formats_or_missing_is_refused() {
    for sim in ["iverilog", "ghdl"] {
        let dir = tempfile::tempdir().unwrap();
        let out = generate_default_str(dir.path(), "300");
        let stimulus = dir.path().join("pkg/kf/kf_stimulus.hex");
        let original = std::fs::read_to_string(&stimulus).unwrap();
        std::fs::write(&stimulus, original.replacen("z:s24.14", "z:s24.13", 1)).unwrap();
        reseal(&dir.path().join("pkg"));
        let log = fails(&["verify", "--out", &out, "--sim", sim, "--blocks", "kf"]);
        assert!(
            log.contains("kf_stimulus.hex declares rst:u1.0 bw_sel:u2.0 z:s24.13; the testbench expects rst:u1.0 bw_sel:u2.0 z:s24.14"),
            "{sim}: {log}"
        );

        // A truncated stimulus file: the testbench names the sample whose line is missing.
        let lines: Vec<&str> = original.lines().take(102).collect();
        std::fs::write(&stimulus, lines.join("\n") + "\n").unwrap();
        reseal(&dir.path().join("pkg"));
        let log = fails(&["verify", "--out", &out, "--sim", sim, "--blocks", "kf"]);
        assert!(
            log.contains("line for sample 100 is missing or malformed"),
            "{sim}: {log}"
        );

        // A field that is not hex.
        std::fs::write(&stimulus, original.replacen("\n0 0 ", "\n0 0 g", 1)).unwrap();
        reseal(&dir.path().join("pkg"));
        let log = fails(&["verify", "--out", &out, "--sim", sim, "--blocks", "kf"]);
        assert!(log.contains("FAIL"), "{sim}: {log}");

        std::fs::remove_file(&stimulus).unwrap();
        reseal(&dir.path().join("pkg"));
        let log = fails(&["verify", "--out", &out, "--sim", sim, "--blocks", "kf"]);
        assert!(log.contains("cannot open kf_stimulus.hex"), "{sim}: {log}");

        std::fs::remove_file(dir.path().join("pkg/kf/kf_coefficients.mem")).unwrap();
        reseal(&dir.path().join("pkg"));
        let log = fails(&["verify", "--out", &out, "--sim", sim, "--blocks", "kf"]);
        assert!(
            log.contains("cannot open kf_coefficients.mem"),
            "{sim}: {log}"
        );
    }
}

/// Every rounding mode, and wrap-around overflow, through the RTL: the quantizer's six modes
/// and both overflow behaviours are bit-exact with the model.
#[test]
fn every_rounding_mode_and_wrapping_overflow_pass_in_icarus_and_ghdl() {
    let dir = tempfile::tempdir().unwrap();
    let mut cases: Vec<(String, String)> = ["floor", "ceil", "zero", "nearest", "round", "convergent"]
        .iter()
        .map(|mode| {
            (
                mode.to_string(),
                format!("samples = 1500\nrounding = \"{mode}\"\n[kf]\nstate_format = \"s30.22\"\ncoefficient_width = 16\n"),
            )
        })
        .collect();
    // A state with only ±2 °/s of range: the full-scale segment overflows and wraps.
    cases.push((
        "wrap".into(),
        "samples = 1500\noverflow = \"wrap\"\n[stimulus]\nrate_dps = 1.0\n[kf]\nstate_format = \"s24.22\"\noutput_format = \"s20.14\"\n".into(),
    ));
    for (name, toml) in cases {
        let config = write_config(dir.path(), &format!("{name}.toml"), &toml);
        let out = dir.path().join(&name);
        let log = ok(&[
            "generate",
            "--out",
            out.to_str().unwrap(),
            "--config",
            &config,
        ]);
        if name == "wrap" {
            assert!(
                !log.contains("overflows: x1 0,"),
                "the wrap case must overflow: {log}"
            );
        }
        let log = ok(&[
            "verify",
            "--out",
            out.to_str().unwrap(),
            "--sim",
            "iverilog,ghdl",
            "--blocks",
            CHAIN_BLOCKS,
        ]);
        assert_eq!(
            log.matches("PASS n=").count(),
            2 * CHAIN_BLOCK_COUNT,
            "{name}: {log}"
        );
    }
}

#[test]
fn one_seed_gives_byte_identical_packages_and_another_seed_differs() {
    let dir = tempfile::tempdir().unwrap();
    let a = dir.path().join("a");
    let b = dir.path().join("b");
    let c = dir.path().join("c");
    ok(&[
        "generate",
        "--out",
        a.to_str().unwrap(),
        "--samples",
        "3000",
        "--seed",
        "42",
    ]);
    ok(&[
        "generate",
        "--out",
        b.to_str().unwrap(),
        "--samples",
        "3000",
        "--seed",
        "42",
    ]);
    ok(&[
        "generate",
        "--out",
        c.to_str().unwrap(),
        "--samples",
        "3000",
        "--seed",
        "43",
    ]);
    let files = files_below(&a);
    assert_eq!(files, files_below(&b));
    assert!(files.len() >= 10);
    for file in &files {
        assert_eq!(
            std::fs::read(a.join(file)).unwrap(),
            std::fs::read(b.join(file)).unwrap(),
            "{file:?}"
        );
    }
    let stimulus = |p: &std::path::Path| std::fs::read(p.join("kf/kf_stimulus.hex")).unwrap();
    assert_ne!(stimulus(&a), stimulus(&c));
}

#[test]
fn the_manifest_lists_every_file_with_its_sha256() {
    let dir = tempfile::tempdir().unwrap();
    let out = generate_default_str(dir.path(), "200");
    let root = std::path::Path::new(&out);
    let manifest: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(root.join("manifest.json")).unwrap())
            .unwrap();
    let listed = manifest["files"].as_array().unwrap();
    let on_disk = files_below(root);
    assert_eq!(
        listed.len() + 2,
        on_disk.len(),
        "every file but the manifest itself and the marker, which holds the manifest's hash"
    );
    let marker: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(root.join(".gyrofx-package")).unwrap())
            .unwrap();
    assert_eq!(
        marker["manifest_sha256"].as_str().unwrap(),
        hex_sha256(&std::fs::read(root.join("manifest.json")).unwrap())
    );
    for entry in listed {
        let path = entry["path"].as_str().unwrap();
        let data = std::fs::read(root.join(path)).unwrap();
        assert_eq!(
            entry["sha256"].as_str().unwrap(),
            hex_sha256(&data),
            "{path}"
        );
    }
    assert_eq!(manifest["seed"], 1);
    assert_eq!(manifest["kf"]["formats"]["state"], "s36.26");
    assert_eq!(manifest["overflow_counts"]["kf_chain"]["x1"], 0);
    for what in [
        &manifest["kf"]["fixed_vs_float"],
        &manifest["chain"]["fixed_vs_float"],
        &manifest["estimator"]["fixed_vs_float_bias"],
    ] {
        assert!(
            what["max_lsb"].as_f64().unwrap() <= what["bound_lsb"].as_f64().unwrap(),
            "{what}"
        );
    }
    assert_eq!(manifest["blocks"]["top"]["module"], "gyrofx_top");
    assert!(
        manifest["kf"]["fixed_vs_float"]["max_lsb"]
            .as_f64()
            .unwrap()
            <= 1.0
    );
    assert_eq!(manifest["config"]["rounding"], "nearest");
}

#[test]
fn filter_agrees_with_the_generated_vectors() {
    // The KF block's CSV holds its input (the chain's combined output) in °/s; filtering it
    // at the first bandwidth must reproduce the expected codes up to the first bw_sel switch.
    let dir = tempfile::tempdir().unwrap();
    let out = generate_default_str(dir.path(), "1200");
    let csv = std::fs::read_to_string(dir.path().join("pkg/kf/kf_vectors.csv")).unwrap();
    let rows: Vec<Vec<String>> = csv
        .lines()
        .skip(2)
        .map(|l| l.split(',').map(str::to_string).collect::<Vec<String>>())
        .take_while(|r| r[2] == "0" && r[1] == "0")
        .collect();
    assert!(rows.len() >= 100, "{}", rows.len());
    let mut input = String::from("t,rate_dps\n");
    for (k, r) in rows.iter().enumerate() {
        input.push_str(&format!("{k},{}\n", r[4]));
    }
    let input_path = dir.path().join("in.csv");
    std::fs::write(&input_path, input).unwrap();
    let output_path = dir.path().join("out.csv");
    ok(&[
        "filter",
        "--input",
        input_path.to_str().unwrap(),
        "--fs",
        "200",
        "--bandwidth",
        "10",
        "--output",
        output_path.to_str().unwrap(),
    ]);
    let filtered = std::fs::read_to_string(&output_path).unwrap();
    let codes: Vec<&str> = filtered
        .lines()
        .skip(1)
        .map(|l| l.split(',').nth(3).unwrap())
        .collect();
    assert_eq!(codes.len(), rows.len());
    for (k, (got, row)) in codes.iter().zip(&rows).enumerate() {
        assert_eq!(*got, row[6], "sample {k}");
    }
    let _ = out;
}

#[test]
fn init_prints_the_default_config_which_generates_the_same_vectors() {
    let dir = tempfile::tempdir().unwrap();
    let config = write_config(dir.path(), "default.toml", &ok(&["init"]));
    let a = dir.path().join("a");
    let b = dir.path().join("b");
    ok(&[
        "generate",
        "--out",
        a.to_str().unwrap(),
        "--config",
        &config,
        "--samples",
        "500",
    ]);
    ok(&["generate", "--out", b.to_str().unwrap(), "--samples", "500"]);
    let body = |p: &std::path::Path| {
        let text = std::fs::read_to_string(p.join("kf/kf_expected.hex")).unwrap();
        text.lines().skip(1).collect::<Vec<_>>().join("\n")
    };
    assert_eq!(body(&a), body(&b));
}

#[test]
fn design_json_has_the_documented_fields() {
    let out = ok(&[
        "design", "--qw", "26", "--qb", "3.1e-5", "--qn", "6.6e-3", "--fs", "200", "--json",
    ]);
    let v: serde_json::Value = serde_json::from_str(&out).unwrap();
    for key in [
        "k",
        "g",
        "bandwidth_hz",
        "dc_gain",
        "iterations",
        "coefficients",
    ] {
        assert!(!v[key].is_null(), "{key} missing in {out}");
    }
    assert_eq!(v["k"], v["g"], "direct method: g = K");
    let c = &v["coefficients"][0];
    for key in ["name", "value", "format", "code", "quantized", "error"] {
        assert!(!c[key].is_null(), "coefficient {key} missing");
    }
    let bw = ok(&[
        "design",
        "--bandwidth",
        "20",
        "--qb",
        "3.1e-5",
        "--qn",
        "6.6e-3",
        "--fs",
        "200",
        "--method",
        "paper",
        "--json",
    ]);
    let v: serde_json::Value = serde_json::from_str(&bw).unwrap();
    assert!((v["bandwidth_hz"].as_f64().unwrap() - 20.0).abs() < 1e-6);
    assert_ne!(v["k"], v["g"], "paper method: g = K (1 - e^-S)/S");
}

#[test]
fn every_preset_generates_and_passes_in_icarus_and_ghdl() {
    let dir = tempfile::tempdir().unwrap();
    for preset in ["gu2019", "xue2015", "mpu6050"] {
        let text = ok(&["init", "--preset", preset]);
        assert!(text.contains(&format!("Preset {preset}")), "{text}");
        let out = dir.path().join(preset);
        ok(&[
            "generate",
            "--preset",
            preset,
            "--samples",
            "2500",
            "--out",
            out.to_str().unwrap(),
        ]);
        let log = ok(&[
            "verify",
            "--out",
            out.to_str().unwrap(),
            "--sim",
            "iverilog,ghdl",
            "--blocks",
            CHAIN_BLOCKS,
        ]);
        assert_eq!(
            log.matches("PASS n=").count(),
            2 * CHAIN_BLOCK_COUNT,
            "{preset}: {log}"
        );
        let manifest = std::fs::read_to_string(out.join("manifest.json")).unwrap();
        assert!(manifest.contains(&format!("--preset {preset}")), "{preset}");
    }
    let log = fails(&["init", "--preset", "adxrs300"]);
    assert!(
        log.contains("--preset \"adxrs300\"") && log.contains("gu2019"),
        "{log}"
    );
}

/// The gu2019 report shows what mode reversal is for: the bias is removed and the long-τ
/// Allan deviation falls below both raw gyros'. On the preset's rate-level gyros (the paper's
/// measured noise; 1200 s at resonator level would take minutes here).
#[test]
fn mode_reversal_removes_the_drift_in_the_report() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("gu");
    let rate = write_config(dir.path(), "rate.toml", "[plant]\nmodel = \"rate\"\n");
    ok(&[
        "generate",
        "--preset",
        "gu2019",
        "--config",
        &rate,
        "--samples",
        "60000",
        "--out",
        out.to_str().unwrap(),
    ]);
    let manifest: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("manifest.json")).unwrap()).unwrap();
    let report = &manifest["report"];
    let line = |i: usize| &report["lines"][i];
    let bias = |i: usize| line(i)["bias_error_dps"].as_f64().unwrap().abs();
    let last = report["tau_s"].as_array().unwrap().len() - 1;
    let adev = |i: usize| line(i)["adev_dps"][last].as_f64().unwrap();
    assert!(bias(0) > 0.5 && bias(1) > 0.5, "raw biases: {report}");
    assert!(
        bias(2) < bias(1) / 100.0 && bias(3) < bias(1) / 100.0,
        "{report}"
    );
    assert!(
        adev(2) < adev(0) && adev(2) < adev(1),
        "τ = {}: {report}",
        report["tau_s"][last]
    );
    assert!(std::fs::read_to_string(out.join("report.md"))
        .unwrap()
        .contains("| calibrated, combined |"));
}

/// The chain testbench notices a one-rule change in the RTL, in either language: the
/// requantizer's round-half-up replaced by truncation (the vectors still expect the model's
/// rounding).
#[test]
fn truncating_instead_of_rounding_in_the_rtl_fails_the_chain_testbench() {
    let mutations = [
        (
            "iverilog",
            "gyrofx_quantize.v",
            ": ROUNDING == 3 ? half_bit\n",
            ": ROUNDING == 3 ? 1'b0\n",
        ),
        (
            "ghdl",
            "gyrofx_quantize.vhd",
            "when 3 => increment := half_bit;",
            "when 3 => increment := '0';",
        ),
    ];
    for (sim, file, rounding, truncation) in mutations {
        let dir = tempfile::tempdir().unwrap();
        let out = generate_default_str(dir.path(), "3000");
        let quantizer = std::path::Path::new(&out).join("hdl").join(file);
        let source = std::fs::read_to_string(&quantizer).unwrap();
        let truncating = source.replace(rounding, truncation);
        assert_ne!(source, truncating, "the mutation must apply to {file}");
        std::fs::write(&quantizer, truncating).unwrap();
        reseal(std::path::Path::new(&out));
        let log = fails(&["verify", "--out", &out, "--sim", sim, "--blocks", "top"]);
        let top = log
            .split("== top")
            .nth(1)
            .unwrap_or_else(|| panic!("{sim}: no top section: {log}"));
        assert!(top.contains("FAIL mismatches="), "{sim}: {log}");
        assert!(
            top.contains("rate_out"),
            "{sim}: the filtered rate must differ: {log}"
        );
    }
}

/// Samples sooner than a block's `min_clocks_per_sample` stop the simulation in every simulator
/// (the RTL's simulation-only check) instead of giving wrong outputs without a word: the KF's
/// testbench, made to feed a sample every second clock (one settle clock instead of three),
/// stops at the second sample naming the instance. The untouched testbench passes.
#[test]
fn a_kf_fed_every_second_clock_stops_the_simulation_in_every_simulator() {
    use gyrofx_lab::simulate::{self, Options, Simulator};
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("pkg");
    let out_text = out.to_str().unwrap();
    ok(&[
        "generate",
        "--out",
        out_text,
        "--blocks",
        "kf",
        "--samples",
        "200",
        "--no-csv",
    ]);
    let kf_only = Options {
        blocks: Some(vec!["kf".to_string()]),
        ..Options::default()
    };
    let passed = simulate::run(&out, Simulator::Icarus, &kf_only).unwrap();
    assert!(passed.passed(), "{:?}", passed.blocks[0].log);
    for (file, settle, faster) in [
        (
            "tb_gyrofx_kf.v",
            "repeat (3) @(negedge clk);",
            "@(negedge clk);",
        ),
        (
            "tb_gyrofx_kf.vhd",
            "for settle in 1 to 3 loop",
            "for settle in 1 to 1 loop",
        ),
    ] {
        let path = out.join("kf").join(file);
        let text = std::fs::read_to_string(&path).unwrap();
        assert!(text.contains(settle), "{file} waits three settle clocks");
        std::fs::write(&path, text.replace(settle, faster)).unwrap();
    }
    for simulator in [Simulator::Icarus, Simulator::Verilator, Simulator::Ghdl] {
        let outcome = simulate::run(&out, simulator, &kf_only).unwrap();
        let log = &outcome.blocks[0].log;
        assert!(!outcome.passed(), "{simulator:?}: {log}");
        assert!(
            log.contains(
                "a sample 2 clocks after the previous one; gyrofx_kf takes one at most every 3 clocks"
            ) && log.contains("dut"),
            "{simulator:?}: {log}"
        );
        assert!(
            !log.contains("FAIL mismatches="),
            "{simulator:?} ran on: {log}"
        );
    }
}
