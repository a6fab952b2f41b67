//! `gyrofx formats`: the table and JSON name every analysed node (the chain's and the gyro
//! loop's) with its proven range and config key, a too-narrow format is reported (and
//! `--strict` fails on it), `--write` gives a config whose configured nodes are proven and which
//! `generate --strict` accepts, and an existing file is not replaced without `--force`.

use crate::common::{fails, gyrofx, ok, run_tool, text};

fn nodes(json: &serde_json::Value) -> Vec<serde_json::Value> {
    json["nodes"].as_array().unwrap().clone()
}

fn node<'a>(nodes: &'a [serde_json::Value], name: &str) -> &'a serde_json::Value {
    nodes
        .iter()
        .find(|n| n["node"] == name)
        .unwrap_or_else(|| panic!("{name} in {nodes:?}"))
}

#[test]
fn the_default_is_analysed_node_by_node() {
    let table = ok(&["formats", "--switches", "0"]);
    for name in [
        "estimator.accumulator",
        "estimator.mean",
        "estimator.bias",
        "estimator.calibrated",
        "kf.error",
        "kf.state",
        "kf.output",
        "mean_filter.output",
    ] {
        assert!(table.contains(name), "{name}: {table}");
    }
    let json: serde_json::Value =
        serde_json::from_str(&ok(&["formats", "--json", "--switches", "0"])).unwrap();
    let nodes = nodes(&json);
    // The loop's nodes, each with the key that sets its format (or none: bit growth, or the
    // NCO's frequency word), and which of them --write leaves.
    for (name, key, written) in [
        (
            "loop.demod_product",
            Some("loop.demod_product_format"),
            true,
        ),
        ("loop.demod_state", Some("loop.demod_state_format"), true),
        ("loop.demod_output", Some("loop.demod_output_format"), true),
        ("loop.agc_error", Some("loop.demod_output_format"), true),
        (
            "loop.pll_integrator",
            Some("loop.pll_integrator_format"),
            true,
        ),
        ("loop.pll_output", None, false),
        (
            "loop.agc_integrator",
            Some("loop.agc_integrator_format"),
            true,
        ),
        ("loop.agc_output", Some("loop.agc_output_format"), false),
        ("loop.dac", Some("loop.dac_format"), false),
        ("loop.cic_comb", None, true),
        ("loop.cic_internal", Some("loop.cic_internal_format"), true),
        ("loop.cic_output", Some("loop.cic_output_format"), true),
        ("loop.output", Some("loop.output_format"), false),
    ] {
        let line = table
            .lines()
            .find(|l| l.split_whitespace().next() == Some(name))
            .unwrap_or_else(|| panic!("{name}: {table}"));
        let n = node(&nodes, name);
        assert_eq!(n["config_key"].as_str(), key, "{n}");
        assert_eq!(n["not_written"].is_null(), written, "{n}");
        if let (Some(key), false) = (key, n["fits"] == true) {
            assert!(line.contains(&format!("(set {key})")), "{line}");
        }
    }
    assert!(
        node(&nodes, "loop.pll_output")["not_written"]
            .as_str()
            .unwrap()
            .contains("loop.nco_phase_bits"),
        "{table}"
    );
    // What stays hand-set has no range to prove, and says why.
    let hand_set = table
        .lines()
        .find(|l| l.starts_with("hand-set, not analysed: [loop]"))
        .unwrap_or_else(|| panic!("{table}"));
    assert!(
        hand_set.contains("NCO") && !hand_set.contains("CIC"),
        "{hand_set}"
    );
    // 2·x·ref at the ADC's full scale against the NCO's largest code (just under 1): just
    // under ±2 FS, in FS.
    let product = node(&nodes, "loop.demod_product");
    assert_eq!(product["unit"], "FS");
    let range = product["range_dps"].as_array().unwrap();
    let (low, high) = (range[0].as_f64().unwrap(), range[1].as_f64().unwrap());
    assert!(high > 1.99 && high < 2.0 && low == -high, "{product}");
    // A full-scale sense signal is some 10⁵ °/s (1e-5 FS per °/s): far beyond the chain's
    // input format, which the loop's output shares.
    let output = node(&nodes, "loop.output");
    assert_eq!(output["fits"], false);
    assert!(output["range_dps"][1].as_f64().unwrap() > 5e4, "{output}");
    assert_eq!(json["loop"]["input_range_fs"][0], -1.0);
    let input = json["input_range_dps"].as_array().unwrap();
    let (low, high) = (input[0].as_f64().unwrap(), input[1].as_f64().unwrap());
    // The calibrated sample is y ∓ b with both at full scale: about twice the input range,
    // one integer bit more than the KF's input format has.
    let calibrated = node(&nodes, "estimator.calibrated");
    assert_eq!(calibrated["fits"], false);
    assert_eq!(
        calibrated["needed_integer_bits"].as_i64().unwrap(),
        calibrated["integer_bits"].as_i64().unwrap() + 1
    );
    let range = calibrated["range_dps"].as_array().unwrap();
    assert!(range[1].as_f64().unwrap() > 1.9 * high && range[0].as_f64().unwrap() < 1.9 * low);
    // Every node whose format is derived by bit growth holds its range.
    for n in &nodes {
        if n["exact"] == true {
            assert_eq!(n["fits"], true, "{n}");
        }
    }
    // The KF's state reaches about the input range (its DC gain is about 1).
    let state = node(&nodes, "kf.state")["range_dps"]
        .as_array()
        .unwrap()
        .clone();
    assert!(state[1].as_f64().unwrap() > 0.99 * high);
}

/// The record length the table gives for the KF's state is the edge: proven at it, not one
/// sample later.
#[test]
fn the_state_limit_is_where_the_proof_ends() {
    let json: serde_json::Value =
        serde_json::from_str(&ok(&["formats", "--json", "--switches", "0"])).unwrap();
    let limit = json["kf"]["state_proven_up_to_samples"].as_u64().unwrap();
    let fits = |samples: u64| {
        let json: serde_json::Value = serde_json::from_str(&ok(&[
            "formats",
            "--json",
            "--switches",
            "0",
            "--samples",
            &samples.to_string(),
        ]))
        .unwrap();
        node(&nodes(&json), "kf.state")["fits"] == true
    };
    assert!(fits(limit) && !fits(limit + 1), "{limit}");
}

#[test]
fn a_narrow_format_is_reported_and_strict_fails_on_it() {
    let dir = tempfile::tempdir().unwrap();
    let config = dir.path().join("narrow.toml");
    std::fs::write(&config, "[kf]\nstate_format = \"s32.26\"\n").unwrap();
    let config = config.to_str().unwrap();
    // A short record without switches: the state needs the ADC's 10 integer bits (±512 °/s).
    let table = ok(&[
        "formats",
        "--config",
        config,
        "--samples",
        "1000",
        "--switches",
        "0",
    ]);
    let line = table.lines().find(|l| l.starts_with("kf.state")).unwrap();
    assert!(
        line.contains("OVERFLOW POSSIBLE: needs 4 more integer bits (set kf.state_format)"),
        "{line}"
    );
    let message = fails(&["formats", "--config", config, "--strict"]);
    assert!(message.contains("kf.state"), "{message}");
    let output = gyrofx(&["formats", "--config", config, "--strict"]);
    assert_eq!(output.status.code(), Some(1), "{}", text(&output));
}

/// One integer bit less than the default's product format needs (its range is just under
/// ±2 FS) is reported on the product's line, naming the key; `--strict` exits 1.
#[test]
fn a_narrow_loop_format_is_reported_and_strict_fails_on_it() {
    let line = |table: &str| {
        table
            .lines()
            .find(|l| l.starts_with("loop.demod_product"))
            .unwrap_or_else(|| panic!("{table}"))
            .to_string()
    };
    let default = line(&ok(&["formats", "--switches", "0"]));
    assert!(
        default.contains("s36.34") && default.contains("proven"),
        "{default}"
    );
    let dir = tempfile::tempdir().unwrap();
    let config = dir.path().join("narrow.toml");
    std::fs::write(&config, "[loop]\ndemod_product_format = \"s35.34\"\n").unwrap();
    let config = config.to_str().unwrap();
    let table = ok(&["formats", "--config", config, "--switches", "0"]);
    let narrow = line(&table);
    assert!(
        narrow.contains(
            "OVERFLOW POSSIBLE: needs 1 more integer bit (set loop.demod_product_format)"
        ),
        "{narrow}"
    );
    // The state keeps its own format, proven as before: it holds every product (the plan
    // requires it), saturated or not.
    let state = table
        .lines()
        .find(|l| l.starts_with("loop.demod_state"))
        .unwrap();
    assert!(!state.contains("OVERFLOW"), "{state}");
    let output = gyrofx(&["formats", "--config", config, "--strict"]);
    assert_eq!(output.status.code(), Some(1), "{}", text(&output));
    assert!(
        text(&output).contains("set loop.demod_product_format"),
        "{}",
        text(&output)
    );
}

#[test]
fn write_gives_a_proven_config_that_generate_accepts_and_keeps_existing_files() {
    let dir = tempfile::tempdir().unwrap();
    let derived = dir.path().join("derived.toml");
    let derived_text = derived.to_str().unwrap();
    ok(&["formats", "--switches", "100", "--write", derived_text]);
    let json: serde_json::Value = serde_json::from_str(&ok(&[
        "formats",
        "--config",
        derived_text,
        "--switches",
        "100",
        "--json",
    ]))
    .unwrap();
    for n in nodes(&json) {
        // Every node --write sets is now proven, the loop's too; the shared formats are left as
        // they were.
        if n["config_key"].is_string() && n["not_written"].is_null() {
            assert_eq!(n["fits"], true, "{n}");
        }
    }
    // The loop's written keys hold the proven formats of the default (the wider where two
    // nodes share a key); the others are as they were.
    let default: serde_json::Value =
        serde_json::from_str(&ok(&["formats", "--switches", "100", "--json"])).unwrap();
    let before = nodes(&default);
    let after = nodes(&json);
    let width = |f: &serde_json::Value| -> u32 {
        let text = f.as_str().unwrap();
        text[1..text.find('.').unwrap()].parse().unwrap()
    };
    for n in before
        .iter()
        .filter(|n| n["node"].as_str().unwrap().starts_with("loop."))
    {
        let Some(key) = n["config_key"].as_str() else {
            continue;
        };
        let written = node(&after, n["node"].as_str().unwrap())["format"].clone();
        if n["not_written"].is_null() {
            let widest = before
                .iter()
                .filter(|m| m["config_key"] == key)
                .max_by_key(|m| width(&m["proven_format"]))
                .unwrap();
            assert_eq!(written, widest["proven_format"], "{key}");
        } else {
            assert_eq!(written, n["format"], "{key} is left as it was");
        }
    }
    let out = dir.path().join("pkg");
    ok(&[
        "generate",
        "--config",
        derived_text,
        "--out",
        out.to_str().unwrap(),
        "--samples",
        "2000",
        "--strict",
        "--quiet",
    ]);
    for target in ["iverilog-kf", "iverilog-mean_filter"] {
        let (passed, log) = run_tool("make", &["--no-print-directory", target], &out);
        assert!(passed && log.contains("PASS"), "{target}: {log}");
    }
    // An existing file: refused (exit 2), unchanged; --force replaces it.
    std::fs::write(&derived, "mine").unwrap();
    let output = gyrofx(&["formats", "--write", derived_text]);
    assert_eq!(output.status.code(), Some(2), "{}", text(&output));
    assert!(text(&output).contains("give --force"), "{}", text(&output));
    assert_eq!(std::fs::read_to_string(&derived).unwrap(), "mine");
    ok(&["formats", "--write", derived_text, "--force"]);
    assert!(std::fs::read_to_string(&derived)
        .unwrap()
        .starts_with("# written by gyrofx formats"));
}

/// A package's manifest says, per node, whether its format is proven for the run, as
/// `gyrofx formats` says for the same record length and switches.
#[test]
fn the_manifest_records_which_formats_are_proven() {
    let dir = tempfile::tempdir().unwrap();
    let package = crate::common::generate_default(dir.path(), "1000");
    let manifest: serde_json::Value =
        serde_json::from_slice(&std::fs::read(package.join("manifest.json")).unwrap()).unwrap();
    let formats = &manifest["formats"];
    assert_eq!(formats["samples"], 1000);
    let switches = formats["switches"].as_u64().unwrap();
    assert!(switches >= 2, "the run cycles bw_sel: {switches}");
    let json: serde_json::Value = serde_json::from_str(&ok(&[
        "formats",
        "--json",
        "--samples",
        "1000",
        "--switches",
        &switches.to_string(),
    ]))
    .unwrap();
    assert_eq!(formats["nodes"], json["nodes"]);
    assert!(!formats["hand_set"].as_array().unwrap().is_empty());
}

/// `--output-error` chooses fraction bits whose chain bound, in the package generated from the
/// written config, is within the budget and whose measured error is below it; a budget under
/// the fixed roundings is a usage error naming the least one, and °/s budgets convert.
#[test]
fn an_output_error_budget_is_met_by_the_written_config() {
    let dir = tempfile::tempdir().unwrap();
    let derived = dir.path().join("budget.toml");
    let derived_text = derived.to_str().unwrap();
    let table = ok(&[
        "formats",
        "--output-error",
        "2",
        "--samples",
        "3000",
        "--switches",
        "20",
        "--write",
        derived_text,
    ]);
    assert!(
        table.contains("for an output error of at most 2.000 LSB"),
        "{table}"
    );
    let out = dir.path().join("pkg");
    ok(&[
        "generate",
        "--config",
        derived_text,
        "--out",
        out.to_str().unwrap(),
        "--samples",
        "3000",
        "--strict",
        "--quiet",
    ]);
    let manifest: serde_json::Value =
        serde_json::from_slice(&std::fs::read(out.join("manifest.json")).unwrap()).unwrap();
    let chain = &manifest["chain"]["fixed_vs_float"];
    assert!(manifest["formats"]["switches"].as_u64().unwrap() <= 20);
    assert!(chain["bound_lsb"].as_f64().unwrap() <= 2.0, "{chain}");
    assert!(chain["max_lsb"].as_f64().unwrap() <= chain["bound_lsb"].as_f64().unwrap());
    // The mean filter's reciprocal word was chosen for the same budget: its block means too.
    let written = std::fs::read_to_string(&derived).unwrap();
    let width_line = table
        .lines()
        .last()
        .unwrap()
        .split("mean_filter.reciprocal_width = ")
        .nth(1)
        .unwrap()
        .split(' ')
        .next()
        .unwrap()
        .to_string();
    assert!(
        written.contains(&format!("reciprocal_width = {width_line}")),
        "{width_line}: {written}"
    );
    let filter = &manifest["mean_filter"]["fixed_vs_float"];
    assert!(filter["max_lsb"].as_f64().unwrap() <= 2.0, "{filter}");
    assert!(filter["bound_lsb"].as_f64().unwrap() <= 2.0, "{filter}");
    let output = gyrofx(&["formats", "--output-error", "1"]);
    assert_eq!(output.status.code(), Some(2), "{}", text(&output));
    assert!(
        text(&output).contains("--output-error 1 LSB is not allowed: more than 1.5"),
        "{}",
        text(&output)
    );
    // 2^-13 °/s is two output LSB of s24.14.
    let dps = ok(&["formats", "--output-error", "0.0001220703125dps"]);
    let lsb = ok(&["formats", "--output-error", "2"]);
    let last = |t: &str| t.lines().last().unwrap().to_string();
    assert_eq!(last(&dps), last(&lsb));
    assert!(last(&lsb).contains("at most 2.000 LSB"), "{lsb}");
}

/// `--residual-budget` (issue 32): at the defaults 1 mdps needs the phase trim and an 11-bit
/// ROM; the written config carries them, `gyrofx loop` on it departs from the configured-phase
/// residual by less than the target, and the JSON's worst cases are within it.
#[test]
fn a_residual_budget_is_met_by_the_loop_of_the_written_config() {
    let dir = tempfile::tempdir().unwrap();
    let written = dir.path().join("budget.toml");
    let written_text = written.to_str().unwrap();
    let json: serde_json::Value = serde_json::from_str(&ok(&[
        "formats",
        "--residual-budget",
        "1mdps",
        "--json",
        "--write",
        written_text,
    ]))
    .unwrap();
    let report = &json["residual_budget"];
    let chosen = &report["chosen"];
    assert_eq!(chosen["nco_address_bits"], 11, "{report}");
    assert_eq!(chosen["phase_trim"], true, "{report}");
    assert_eq!(report["configured"]["nco_address_bits"], 10);
    let config = std::fs::read_to_string(&written).unwrap();
    for line in [
        "nco_address_bits = 11".to_string(),
        format!("nco_phase_bits = {}", chosen["nco_phase_bits"]),
        "phase_trim = true".to_string(),
    ] {
        assert!(config.contains(&line), "{line} in {config}");
    }
    let loops: serde_json::Value = serde_json::from_str(&ok(&[
        "loop",
        "--config",
        written_text,
        "--json",
        "--quiet",
    ]))
    .unwrap();
    for gyro in loops.as_array().unwrap() {
        let measured = gyro["residual_bias_dps"]["measured"].as_f64().unwrap();
        let configured = gyro["residual_configured_phase_dps"].as_f64().unwrap();
        assert!((measured - configured).abs() < 1e-3, "{gyro}");
    }
    // The budget's derived parts sum to what `gyrofx loop` predicts on the written config, up
    // to the offset word's rounding (bounded in the budget): two paths through the model.
    let gyros = loops.as_array().unwrap();
    for (budget, gyro) in report["gyros"].as_array().unwrap().iter().zip(gyros) {
        let chosen = &budget["chosen"];
        let mut derived = chosen["configured_dps"].as_f64().unwrap();
        let mut word = f64::NAN;
        for part in chosen["parts"].as_array().unwrap() {
            derived += part["cost"]["derived"].as_f64().unwrap_or(0.0);
            if part["name"] == "offset word" {
                word = part["cost"]["bound"].as_f64().unwrap();
            }
        }
        let predicted = gyro["residual_bias_dps"]["predicted"].as_f64().unwrap();
        assert!(
            (derived - predicted).abs() <= word + 1e-12,
            "{derived} against {predicted}"
        );
        assert!(budget["chosen_measured"]["clipped"].is_null(), "{budget}");
    }
    let table = ok(&["formats", "--residual-budget", "1mdps"]);
    assert!(!table.contains("warning"), "{table}");
}

/// gu2019's loop clips its outputs while the budget measures it: the table says the measured
/// residual is clipped, naming the nodes, rather than passing it off as the loop's.
#[test]
fn a_budget_measured_through_a_saturating_loop_says_so() {
    let table = ok(&[
        "formats",
        "--preset",
        "gu2019",
        "--residual-budget",
        "1mdps",
    ]);
    assert!(
        table.contains("loop saturated while it was measured (")
            && table.contains("quadrature_output"),
        "{table}"
    );
}

/// Bad input as a new user gives it: one clear error each, exit 2 (1 for a missing file), and
/// nothing written.
#[test]
fn bad_input_is_refused_naming_what_is_allowed_and_writes_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let target = dir.path().join("out.toml");
    let target_text = target.to_str().unwrap();
    let folder = dir.path().to_str().unwrap();
    let missing = dir.path().join("missing.toml");
    for (args, code, message) in [
        (
            vec!["--output-error", "nan"],
            2,
            "a finite number of output LSB",
        ),
        (
            vec!["--output-error", "-3dps"],
            2,
            "is not allowed: more than 1.5",
        ),
        (vec!["--output-error", "lots"], 2, "is not a budget"),
        (vec!["--residual-budget", "1"], 2, "is not a target"),
        (
            vec!["--residual-budget", "-1mdps"],
            2,
            "a positive residual bias",
        ),
        (
            vec!["--residual-budget", "0.001mdps"],
            2,
            "the finest leaves",
        ),
        (vec!["--write", folder, "--force"], 2, "is a folder"),
        (
            vec!["--config", missing.to_str().unwrap()],
            1,
            "missing.toml",
        ),
        (vec!["--preset", "nope"], 2, "one of gu2019"),
    ] {
        let mut full = vec!["formats"];
        if args[0] != "--write" {
            full.extend(["--write", target_text]);
        }
        full.extend(args.iter().copied());
        let output = gyrofx(&full);
        assert_eq!(
            output.status.code(),
            Some(code),
            "{args:?}: {}",
            text(&output)
        );
        assert!(
            text(&output).contains(message),
            "{args:?}: {}",
            text(&output)
        );
        assert!(!target.exists(), "{args:?} wrote {target_text}");
        assert_eq!(
            std::fs::read_dir(dir.path()).unwrap().count(),
            0,
            "{args:?} left a file behind"
        );
    }
}
