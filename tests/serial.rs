//! `architecture = "serial"`: the time-multiplexed chain (`gyrofx_top_serial`) passes the same
//! top vectors bit-exact in Icarus, Verilator and GHDL and against the C model through DPI-C, a
//! flipped bit fails every testbench, and bad values are refused; so do the sequential mean
//! filter, the folded gyro loop and the folded system (`gyrofx_system_serial`) with their own
//! vectors. (Their cocotb tests: `python/tests/test_cocotb.py`.)

use crate::common::*;

/// Short intervals so that 1 300 samples hold five windows (estimates, smoothing, resets of
/// the accumulators), B staggered.
const SERIAL: &str = "samples = 1300\narchitecture = \"serial\"\n[sequencer]\ninterval_length = 60\nblank = 30\nstagger = 7\n";

fn generate(dir: &std::path::Path, config: &str) -> String {
    let path = dir.join("serial.toml");
    std::fs::write(&path, config).unwrap();
    let out = dir.join("pkg");
    ok(&[
        "generate",
        "--config",
        path.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
        "--quiet",
    ]);
    out.to_string_lossy().into_owned()
}

fn manifest(out: &str) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(format!("{out}/manifest.json")).unwrap()).unwrap()
}

/// `block` of the package at `out` passes its `lines` vectors in Icarus, Verilator and GHDL and
/// against the C model through DPI-C (live, its samples spaced by the block's latency), and
/// one expected bit flipped from sample `from` on fails every simulator at that sample.
fn passes_everywhere_and_a_flipped_bit_fails(out: &str, block: &str, lines: u64, from: usize) {
    passes_and_a_flipped_bit_fails(out, block, lines, from, &SIMULATORS);
}

/// As [`passes_everywhere_and_a_flipped_bit_fails`], the whole vectors in `full` only: every
/// simulator still runs the testbench up to the flipped bit.
fn passes_and_a_flipped_bit_fails(out: &str, block: &str, lines: u64, from: usize, full: &[&str]) {
    for sim in full {
        let log = ok(&["verify", "--out", out, "--sim", sim, "--blocks", block]);
        assert!(log.contains(&format!("PASS n={lines}")), "{sim}: {log}");
    }
    let output = std::process::Command::new(env!("CARGO_BIN_EXE_gyrofx"))
        .args(["verify", "--out", out, "--sim", "dpi", "--blocks", block])
        .env("GYROFX_CAPI_LIB", capi_library())
        .output()
        .unwrap();
    let log = String::from_utf8_lossy(&output.stdout).into_owned()
        + &String::from_utf8_lossy(&output.stderr);
    assert!(
        output.status.success() && log.contains("dpi: passed"),
        "{log}"
    );

    let (signal, sample) = flip_checked_bit(std::path::Path::new(out), block, from);
    for sim in SIMULATORS {
        let log = fails(&[
            "verify",
            "--out",
            out,
            "--sim",
            sim,
            "--blocks",
            block,
            "--max-mismatches",
            "1",
        ]);
        assert!(
            log.contains(&format!("MISMATCH sample {sample} signal {signal}")),
            "{sim}: {log}"
        );
    }
}

#[test]
fn the_serial_top_passes_the_top_vectors_in_every_simulator_and_a_flipped_bit_fails() {
    let dir = tempfile::tempdir().unwrap();
    let out = generate(dir.path(), SERIAL);
    let m = manifest(&out);
    let chain = &m["chain"];
    assert_eq!(chain["architecture"], "serial");
    let instructions = chain["serial"]["instructions"].as_u64().unwrap();
    // 4 clocks an instruction, outputs the clock after the last.
    assert_eq!(
        chain["latency_clocks"].as_u64().unwrap(),
        4 * instructions + 1
    );
    let top = std::path::Path::new(&out).join("top");
    assert!(top.join("tb_gyrofx_top_serial.v").exists());
    assert!(top.join("serial_program.mem").exists());
    assert!(!top.join("tb_gyrofx_top.v").exists());
    passes_everywhere_and_a_flipped_bit_fails(&out, "top", 1301, 700);
}

#[test]
fn wrap_convergent_and_smoothing_run_bit_exact_in_the_serial_top() {
    let dir = tempfile::tempdir().unwrap();
    let config = SERIAL.replacen(
        "[sequencer]",
        "rounding = \"convergent\"\noverflow = \"wrap\"\n[sequencer]",
        1,
    ) + "[estimator]\nsmoothing_shift = 2\n";
    let out = generate(dir.path(), &config);
    let log = ok(&[
        "verify", "--out", &out, "--sim", "iverilog", "--blocks", "top",
    ]);
    assert!(log.contains("PASS n=1301"), "{log}");
}

#[test]
fn an_unknown_architecture_is_refused_by_name_with_nothing_written() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("bad.toml");
    std::fs::write(&path, "architecture = \"pipelined\"\n").unwrap();
    let out = dir.path().join("pkg");
    let err = fails(&[
        "generate",
        "--config",
        path.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(
        err.contains("architecture") && err.contains("pipelined") && err.contains("serial"),
        "{err}"
    );
    assert!(!out.exists());
}

/// Odd widths in the serial top's RTL: a 1-limb rate (s14.6), 4-limb states, an 18-bit sample,
/// an abba pattern with 6 intervals... each with a different rounding, against its vectors in
/// Icarus.
#[test]
fn other_formats_and_modes_run_bit_exact_in_the_serial_top() {
    let cases = [
        (
            "zero",
            "saturate",
            "[sequencer]\ninterval_length = 50\nintervals = 8\npattern = \"abba\"\nblank = 25\nstagger = 30\n\
             [estimator]\nmean_format = \"s22.12\"\nbias_format = \"s20.11\"\n\
             [kf]\ninput_format = \"s18.8\"\nstate_format = \"s47.30\"\noutput_format = \"s14.6\"\n\
             [mean_filter]\noutput_format = \"s18.8\"\n[loop]\noutput_format = \"s18.8\"\n",
        ),
        (
            "round",
            "wrap",
            "[sequencer]\ninterval_length = 45\nblank = 27\n\
             [estimator]\nmean_format = \"s31.21\"\nbias_format = \"s30.20\"\nsmoothing_shift = 1\n\
             [kf]\ninput_format = \"s16.7\"\nstate_format = \"s31.20\"\noutput_format = \"s16.7\"\n\
             [mean_filter]\noutput_format = \"s16.7\"\n[loop]\noutput_format = \"s16.7\"\n",
        ),
    ];
    for (rounding, overflow, tables) in cases {
        let dir = tempfile::tempdir().unwrap();
        let config = format!(
            "samples = 900\narchitecture = \"serial\"\nrounding = \"{rounding}\"\noverflow = \"{overflow}\"\n{tables}"
        );
        let out = generate(dir.path(), &config);
        let log = ok(&[
            "verify", "--out", &out, "--sim", "iverilog", "--blocks", "top",
        ]);
        assert!(log.contains("PASS n=901"), "{rounding}/{overflow}: {log}");
    }
}

/// `architecture = "serial"` makes the mean filter beside the chain `gyrofx_mean_filter_serial`:
/// its own vectors (the parallel filter's, at the sequential latency) pass bit-exact in every
/// simulator and against the C model through DPI-C, and a flipped bit fails them.
#[test]
fn the_serial_mean_filter_passes_its_vectors_in_every_simulator_and_a_flipped_bit_fails() {
    let dir = tempfile::tempdir().unwrap();
    let out = generate(dir.path(), SERIAL);
    let m = manifest(&out);
    let mf = &m["mean_filter"];
    assert_eq!(mf["architecture"], "serial");
    assert_eq!(mf["module"], "gyrofx_mean_filter_serial");
    // Division over the sum's magnitude bits, bounds, the scan, the ROM read, the load, the
    // multiply over the reciprocal's magnitude bits, the output; counting the ce's clock.
    let width = |node: &str| {
        let format: String = mf["formats"][node].as_str().unwrap().into();
        format[1..format.find('.').unwrap()].parse::<u64>().unwrap()
    };
    let window = mf["window"].as_u64().unwrap();
    let latency = 1 + (width("sum") - 1) + 1 + window + 1 + 1 + (width("reciprocal") - 1) + 1;
    assert_eq!(mf["latency_clocks"].as_u64().unwrap(), latency);
    assert_eq!(mf["min_clocks_per_sample"].as_u64().unwrap(), latency);
    // The samples are compared with a kept range one bit wider than the sum, not a deviation.
    assert!(mf["formats"]["deviation"].is_null(), "{mf}");
    assert_eq!(width("kept_range"), width("sum") + 1);
    let folder = std::path::Path::new(&out).join("mean_filter");
    assert!(folder.join("tb_gyrofx_mean_filter_serial.v").exists());
    assert!(folder.join("tb_gyrofx_mean_filter_serial.vhd").exists());
    assert!(!folder.join("tb_gyrofx_mean_filter.v").exists());
    let lines = m["blocks"]["mean_filter"]["vectors"].as_u64().unwrap();
    passes_everywhere_and_a_flipped_bit_fails(&out, "mean_filter", lines, 600);
}

/// `architecture = "serial"` folds the gyro loop (`gyrofx_gyro_loop_serial`): the parallel
/// loop's vectors (gyro A's closed loop through lock and a switch) pass bit-exact in Verilator
/// and GHDL and against the C model through DPI-C at the schedule's spacing, and a flipped bit
/// fails them and Icarus, after the samples before it passed.
#[test]
fn the_folded_gyro_loop_passes_the_loop_vectors_in_every_simulator_and_a_flipped_bit_fails() {
    let dir = tempfile::tempdir().unwrap();
    let out = generate(dir.path(), SERIAL);
    let m = manifest(&out);
    let gyro_loop = &m["gyro_loop"];
    assert_eq!(gyro_loop["architecture"], "serial");
    // A word acts two clocks after its fetch (the clock between decodes its accumulator
    // operands); the outputs load at the schedule's last word, the clock after which the next
    // sample may come; the decimating sample is the longest.
    let schedule = &gyro_loop["schedule"];
    let clocks = schedule["clocks"].as_u64().unwrap();
    assert!(schedule["regular_clocks"].as_u64().unwrap() < clocks);
    assert_eq!(gyro_loop["latency_clocks"].as_u64().unwrap(), clocks + 2);
    assert_eq!(
        gyro_loop["min_clocks_per_sample"].as_u64().unwrap(),
        clocks + 2
    );
    let folder = std::path::Path::new(&out).join("gyro_loop");
    assert!(folder.join("tb_gyrofx_gyro_loop_serial.v").exists());
    assert!(folder.join("tb_gyrofx_gyro_loop_serial.vhd").exists());
    assert!(folder.join("gyro_loop_schedule.mem").exists());
    assert!(!folder.join("tb_gyrofx_gyro_loop.v").exists());
    let lines = m["blocks"]["gyro_loop"]["vectors"].as_u64().unwrap();
    // 40 000 samples of 116 clocks: Icarus (90 s) runs the Verilog Verilator proves whole up to
    // the flipped bit only; GHDL runs the VHDL twin whole (120 s).
    passes_and_a_flipped_bit_fails(&out, "gyro_loop", lines, 700, &["verilator", "ghdl"]);
}

/// The sequential mean filter at other windows, formats and modes: an odd window, a window of
/// hundreds (a 33-bit sum), a threshold of 0 (only samples on the mean kept), narrow
/// reciprocals; in Icarus against the vectors of each.
#[test]
fn other_windows_formats_and_modes_run_bit_exact_in_the_serial_mean_filter() {
    let cases = [
        (
            "convergent",
            "wrap",
            "[mean_filter]\nwindow = 7\nthreshold_dps = 0.05\nreciprocal_width = 12\n",
        ),
        (
            "floor",
            "saturate",
            "[mean_filter]\nwindow = 300\nthreshold_dps = 1.5\noutput_format = \"s20.12\"\n",
        ),
        (
            "ceil",
            "saturate",
            "[mean_filter]\nwindow = 2\nthreshold_dps = 0.0\nreciprocal_width = 40\n",
        ),
    ];
    for (rounding, overflow, table) in cases {
        let dir = tempfile::tempdir().unwrap();
        let config = format!(
            "samples = 900\narchitecture = \"serial\"\nrounding = \"{rounding}\"\noverflow = \"{overflow}\"\n{table}"
        );
        let out = generate(dir.path(), &config);
        let lines = manifest(&out)["blocks"]["mean_filter"]["vectors"]
            .as_u64()
            .unwrap();
        let log = ok(&[
            "verify",
            "--out",
            &out,
            "--sim",
            "iverilog",
            "--blocks",
            "mean_filter",
        ]);
        assert!(
            log.contains(&format!("PASS n={lines}")),
            "{rounding}/{overflow}: {log}"
        );
    }
}

/// The serial variants stop a simulation that feeds them too fast, as the pipelined blocks do
/// (a simulation-only check in both languages): the serial top's and the serial mean filter's
/// testbenches, made to wait one clock less than `min_clocks_per_sample` between samples (the
/// mean filter: between blocks), stop naming the instance in Icarus, Verilator and GHDL instead
/// of running on to mismatches; untouched, they pass.
#[test]
fn the_serial_variants_fed_one_clock_too_soon_stop_the_simulation() {
    use gyrofx_lab::simulate::{self, Options, Simulator};
    let dir = tempfile::tempdir().unwrap();
    let out = generate(
        dir.path(),
        "samples = 300\narchitecture = \"serial\"\n[sequencer]\ninterval_length = 60\nblank = 30\n",
    );
    let out = std::path::Path::new(&out);
    let manifest = manifest(out.to_str().unwrap());
    let cases = [
        (
            "top",
            "gyrofx_top_serial",
            manifest["chain"]["min_clocks_per_sample"].as_u64().unwrap(),
            "a sample while the engine still runs the previous one",
        ),
        (
            "mean_filter",
            "gyrofx_mean_filter_serial",
            manifest["mean_filter"]["min_clocks_per_sample"]
                .as_u64()
                .unwrap(),
            "a sample while the previous block is being processed",
        ),
    ];
    for (block, module, spacing, message) in cases {
        let only = Options {
            blocks: Some(vec![block.to_string()]),
            ..Options::default()
        };
        assert!(simulate::run(out, Simulator::Icarus, &only)
            .unwrap()
            .passed());
        let settle = spacing - 1;
        for (file, waits, sooner) in [
            (
                format!("tb_{module}.v"),
                format!("repeat ({settle}) @(negedge clk);"),
                format!("repeat ({}) @(negedge clk);", settle - 1),
            ),
            (
                format!("tb_{module}.vhd"),
                format!("for settle in 1 to {settle} loop"),
                format!("for settle in 1 to {} loop", settle - 1),
            ),
        ] {
            let path = out.join(block).join(&file);
            let text = std::fs::read_to_string(&path).unwrap();
            assert!(text.contains(&waits), "{file} waits {settle} clocks");
            std::fs::write(&path, text.replace(&waits, &sooner)).unwrap();
        }
        for simulator in [Simulator::Icarus, Simulator::Verilator, Simulator::Ghdl] {
            let outcome = simulate::run(out, simulator, &only).unwrap();
            let log = &outcome.blocks[0].log;
            assert!(!outcome.passed(), "{module} {simulator:?}: {log}");
            assert!(
                log.contains(message) && log.contains("dut"),
                "{module} {simulator:?}: {log}"
            );
            assert!(
                !log.contains("FAIL mismatches="),
                "{module} {simulator:?} ran on: {log}"
            );
        }
    }
}

/// `architecture = "serial"` makes the system `gyrofx_system_serial`: both gyros' loops on one
/// folded datapath (`gyrofx_gyro_pair_serial`) feeding the serial chain. Its vectors (the parallel system's closed run, the chain's outputs
/// `chain_delay_samples` lines later) pass bit-exact in Verilator and against the C model
/// through DPI-C; Verilator runs them again with the last one's `estimated` flipped and fails at
/// that sample only; Icarus, Verilator and GHDL fail at a flipped bit early on. GHDL's run of
/// every sample (4.5 min of CPU, the longest of the suite) runs with `GYROFX_SLOW_TESTS=1`
/// (offline; CI's budget): the pair's VHDL is the system's alone, so its run up to sample 700
/// is the VHDL pair's CI check.
#[test]
fn the_folded_system_passes_the_system_vectors_and_a_flipped_bit_fails() {
    let dir = tempfile::tempdir().unwrap();
    let out = generate(dir.path(), SERIAL);
    let m = manifest(&out);
    let system = &m["system"];
    assert_eq!(system["architecture"], "serial");
    assert_eq!(system["module"], "gyrofx_system_serial");
    // Both loops on one folded datapath, every sample within 120 clocks (a 200 kHz ADC at
    // 24 MHz); every output the clock after the pair's longest sample (fetch and decode, then
    // the outputs), every ADC sample; the chain's results after the pair's deferred segments
    // and the fewest samples that cover its program.
    let pair = &system["folded_loops"];
    assert_eq!(pair["module"], "gyrofx_gyro_pair_serial");
    let pair_clocks = pair["longest_sample_words"].as_u64().unwrap() + 3;
    assert!(pair_clocks <= 120, "{pair}");
    assert_eq!(system["latency_clocks"].as_u64().unwrap(), pair_clocks);
    assert_eq!(
        system["min_clocks_per_sample"].as_u64().unwrap(),
        pair_clocks
    );
    let chain = system["serial_chain"]["latency_clocks"].as_u64().unwrap();
    let delay = system["chain_delay_samples"].as_u64().unwrap();
    let segments = pair["deferred_segments"].as_u64().unwrap();
    assert_eq!(delay, segments + (chain + 1).div_ceil(pair_clocks));
    let folder = std::path::Path::new(&out).join("system");
    for file in [
        "tb_gyrofx_system_serial.v",
        "tb_gyrofx_system_serial.vhd",
        "system_serial_program.mem",
        "gyro_pair_schedule.mem",
    ] {
        assert!(folder.join(file).exists(), "{file}");
    }
    assert!(!folder.join("tb_gyrofx_system.v").exists());
    let params = std::fs::read_to_string(folder.join("system_params.vh")).unwrap();
    assert!(
        params.contains(&format!("P_CHAIN_DELAY_SAMPLES = {delay};")),
        "{params}"
    );
    let lines = m["blocks"]["system"]["vectors"].as_u64().unwrap();
    let log = ok(&[
        "verify",
        "--out",
        &out,
        "--sim",
        "verilator",
        "--blocks",
        "system",
    ]);
    assert!(log.contains(&format!("PASS n={lines}")), "{log}");
    let output = std::process::Command::new(env!("CARGO_BIN_EXE_gyrofx"))
        .args([
            "verify", "--out", &out, "--sim", "dpi", "--blocks", "system",
        ])
        .env("GYROFX_CAPI_LIB", capi_library())
        .output()
        .unwrap();
    let log = String::from_utf8_lossy(&output.stdout).into_owned()
        + &String::from_utf8_lossy(&output.stderr);
    assert!(
        output.status.success() && log.contains("dpi: passed"),
        "{log}"
    );

    let fail_at = |sims: &[&str], sample: usize| {
        for sim in sims {
            let log = fails(&[
                "verify",
                "--out",
                &out,
                "--sim",
                sim,
                "--blocks",
                "system",
                "--max-mismatches",
                "1",
            ]);
            // Every sample before it passed.
            assert!(
                log.contains(&format!("MISMATCH sample {sample} signal estimated"))
                    && log.contains(&format!(" first={sample} ")),
                "{sim}: {log}"
            );
        }
    };
    // Early: `estimated` is still its reset value there, through the delay.
    let package = std::path::Path::new(&out);
    assert_eq!(flip_expected_bit(package, "system", 700), "estimated");
    fail_at(&["iverilog", "verilator", "ghdl"], 700);
    flip_expected_bit(package, "system", 700);
    // Last: the published estimate; Verilator passes every sample before it.
    let last = lines as usize - 1;
    let expected = std::fs::read_to_string(folder.join("system_expected.hex")).unwrap();
    assert!(
        expected.lines().nth(2 + last).unwrap().ends_with(" 1"),
        "the run ends estimated"
    );
    flip_expected_bit(package, "system", last);
    if std::env::var("GYROFX_SLOW_TESTS").as_deref() == Ok("1") {
        fail_at(&["verilator", "ghdl"], last);
    } else {
        fail_at(&["verilator"], last);
    }
}
