//! `gyrofx allan` and `gyrofx ar`: JSON fields, agreement with the library on a known record,
//! and bad input.

use crate::common::*;

/// White rate noise from a fixed LCG (the NIST test generator), written as a CSV.
fn white_csv(dir: &std::path::Path, samples: usize) -> String {
    let mut n: u64 = 1_234_567_890;
    let mut text = String::from("# a comment line, as gyrofx writes them\nt,rate_dps\n");
    for k in 0..samples {
        n = 16807 * n % 2_147_483_647;
        text.push_str(&format!("{k},{}\n", n as f64 / 2_147_483_647.0 - 0.5));
    }
    let path = dir.join("white.csv");
    std::fs::write(&path, text).unwrap();
    path.to_string_lossy().into_owned()
}

#[test]
fn json_has_the_documented_fields() {
    let dir = tempfile::tempdir().unwrap();
    let csv = white_csv(dir.path(), 999);
    let out = ok(&[
        "allan", "--input", &csv, "--rate", "1", "--taus", "decade", "--json",
    ]);
    let v: serde_json::Value = serde_json::from_str(&out).unwrap();
    for key in ["tau_s", "adev", "adev_lo", "adev_hi"] {
        assert!(v[key].is_array(), "{key}: {out}");
    }
    // How well the fitted model follows the curve: one count per τ.
    let points = v["tau_s"].as_array().unwrap().len() as u64;
    assert_eq!(v["fit"]["points"].as_u64(), Some(points), "{out}");
    assert!(
        v["fit"]["outside_band"].as_u64().unwrap() <= points,
        "{out}"
    );
    assert!(
        v["fit"]["worst_model_over_measured"].as_f64().unwrap() > 0.0,
        "{out}"
    );
    // White noise: the curve shows N; B is not shown and gets an upper bound instead.
    assert_eq!(v["identified"]["arw_deg_per_sqrt_h"], true, "{out}");
    assert!(v["upper_bound"]["arw_deg_per_sqrt_h"].is_null(), "{out}");
    assert_eq!(
        v["identified"]["bias_instability_deg_per_h"], false,
        "{out}"
    );
    assert!(
        v["upper_bound"]["bias_instability_deg_per_h"]
            .as_f64()
            .unwrap()
            > 0.0,
        "{out}"
    );
    for key in [
        "quantization_urad",
        "arw_deg_per_sqrt_h",
        "bias_instability_deg_per_h",
        "rrw_deg_per_h_per_sqrt_h",
        "rate_ramp_deg_per_h2",
    ] {
        for part in ["value", "lo", "hi"] {
            assert!(
                v["noise"][key][part].is_number(),
                "noise.{key}.{part}: {out}"
            );
        }
    }
    // White uniform noise of σ = 1/√12 at 1 Hz: density √(S/2) = σ/√fs.
    let density = v["noise_density_dps_per_sqrt_hz"].as_f64().unwrap();
    assert!((density * 12f64.sqrt() - 1.0).abs() < 0.15, "{density}");
    // Every confidence interval contains its value.
    let adev = v["adev"].as_array().unwrap();
    for (i, a) in adev.iter().enumerate() {
        let (a, lo, hi) = (
            a.as_f64().unwrap(),
            v["adev_lo"][i].as_f64().unwrap(),
            v["adev_hi"][i].as_f64().unwrap(),
        );
        assert!(lo <= a && a <= hi, "{i}: {lo} {a} {hi}");
    }
    // White noise of a uniform on [-0.5, 0.5): ADEV(1) = σ = 1/√12.
    assert!(
        (adev[0].as_f64().unwrap() - 12f64.sqrt().recip()).abs() < 0.02,
        "{out}"
    );
}

#[test]
fn several_inputs_give_an_array() {
    let dir = tempfile::tempdir().unwrap();
    let csv = white_csv(dir.path(), 500);
    let out = ok(&[
        "allan", "--input", &csv, "--input", &csv, "--rate", "10", "--json",
    ]);
    let v: serde_json::Value = serde_json::from_str(&out).unwrap();
    assert_eq!(v.as_array().unwrap().len(), 2);
    assert_eq!(v[0]["adev"], v[1]["adev"]);
}

#[test]
fn several_columns_give_several_series() {
    let dir = tempfile::tempdir().unwrap();
    let out = generate_default(dir.path(), "3000");
    let csv = out.join("top/top_vectors.csv");
    let json = ok(&[
        "allan",
        "--input",
        csv.to_str().unwrap(),
        "--column",
        "y_a_dps",
        "--column",
        "y_b_dps",
        "--rate",
        "200",
        "--json",
    ]);
    let v: serde_json::Value = serde_json::from_str(&json).unwrap();
    assert_eq!(v.as_array().unwrap().len(), 2);
    assert_eq!(v[1]["column"], "y_b_dps");
    assert_ne!(v[0]["adev"], v[1]["adev"]);
}

#[test]
fn a_generated_csv_is_valid_input() {
    let dir = tempfile::tempdir().unwrap();
    let out = generate_default(dir.path(), "3000");
    let csv = out.join("top/top_vectors.csv");
    let log = ok(&[
        "allan",
        "--input",
        csv.to_str().unwrap(),
        "--column",
        "true_rate_dps",
        "--rate",
        "200",
    ]);
    assert!(log.contains("angle random walk N"), "{log}");

    // The table says what the JSON of the same run says: the series, a row per τ with its
    // deviation, and every noise term.
    let csv = csv.to_str().unwrap();
    let args = [
        "allan", "--input", csv, "--column", "y_a_dps", "--rate", "200",
    ];
    let table = ok(&args);
    let json: serde_json::Value =
        serde_json::from_str(&ok(&[&args[..], &["--json"]].concat())).unwrap();
    let samples = json["samples"].as_u64().unwrap();
    assert!(
        table.starts_with(&format!(
            "{csv} ({samples} samples at 200 Hz, column y_a_dps), Overlapping deviation\n"
        )),
        "{table}"
    );
    let rows: Vec<(f64, f64)> = table
        .lines()
        .filter_map(|line| {
            let fields: Vec<&str> = line.split_whitespace().collect();
            Some((fields.first()?.parse().ok()?, fields.get(1)?.parse().ok()?))
        })
        .collect();
    let taus = json["tau_s"].as_array().unwrap();
    assert_eq!(rows.len(), taus.len(), "{table}");
    for ((tau, dev), (want_tau, want_dev)) in rows
        .iter()
        .zip(taus.iter().zip(json["adev"].as_array().unwrap()))
    {
        let (want_tau, want_dev) = (want_tau.as_f64().unwrap(), want_dev.as_f64().unwrap());
        assert!(
            (tau - want_tau).abs() <= 1e-6 * want_tau,
            "{tau} {want_tau}"
        );
        assert!(
            (dev - want_dev).abs() <= 1e-6 * want_dev,
            "{dev} {want_dev}"
        );
    }
    for term in [
        "quantization Q",
        "angle random walk N",
        "bias instability B",
        "rate random walk K",
        "rate ramp R",
        "Kalibr: noise density",
        "noise density (Welch",
        "slope readings",
    ] {
        assert_eq!(table.matches(term).count(), 1, "{term}: {table}");
    }
}

#[test]
fn bad_input_is_refused_clearly() {
    let dir = tempfile::tempdir().unwrap();
    let write = |name: &str, text: &str| {
        let p = dir.path().join(name);
        std::fs::write(&p, text).unwrap();
        p.to_string_lossy().into_owned()
    };
    let empty = write("empty.csv", "");
    let word = write("word.csv", "t,rate_dps\n0,1\n1,2\n2,x\n3,4\n4,5\n");
    let nan = write("nan.csv", "t,rate_dps\n0,1\n1,NaN\n2,3\n3,4\n4,5\n");
    let short = write("short.csv", "t,rate_dps\n0,1\n1,2\n");
    let good = white_csv(dir.path(), 100);
    for (args, needle) in [
        (vec!["--input", &empty, "--rate", "1"], "empty"),
        (
            vec!["--input", &word, "--rate", "1"],
            "line 4, column \"rate_dps\": \"x\" is not a number",
        ),
        (
            vec!["--input", &nan, "--rate", "1"],
            "line 3, column \"rate_dps\": NaN is not allowed",
        ),
        (
            vec!["--input", &short, "--rate", "1"],
            "2 samples are too few",
        ),
        (
            vec!["--input", &good, "--rate", "0"],
            "--rate 0 is not allowed",
        ),
        (
            vec!["--input", &good, "--rate", "-5"],
            "--rate -5 is not allowed",
        ),
        (
            vec!["--input", &good, "--rate", "1", "--taus", "weekly"],
            "'weekly' is not a tau grid",
        ),
        (
            vec!["--input", &good, "--rate", "1", "--column", "gyro"],
            "no column named \"gyro\"",
        ),
    ] {
        let mut all = vec!["allan"];
        all.extend(args);
        let log = fails(&all);
        assert!(log.contains(needle), "{all:?}: {log}");
    }
}

/// `--taus many` gives ten factors per decade; `--taus all` refuses a record too long for its
/// N² time before any work, naming the limit and the alternatives; the Hadamard deviation
/// leaves the rate ramp out (its third difference cancels a ramp) rather than print a number.
#[test]
fn tau_grids_and_the_kinds_terms() {
    let dir = tempfile::tempdir().unwrap();
    let csv = white_csv(dir.path(), 10_000);
    let json = |kind: &str, taus: &str| -> serde_json::Value {
        let out = ok(&[
            "allan", "--input", &csv, "--rate", "1", "--taus", taus, "--kind", kind, "--json",
        ]);
        serde_json::from_str(&out).unwrap()
    };
    let many = json("overlapping", "many");
    let taus: Vec<f64> = many["tau_s"]
        .as_array()
        .unwrap()
        .iter()
        .map(|t| t.as_f64().unwrap())
        .collect();
    assert_eq!(taus.len(), 34, "{taus:?}"); // 1 … 3981 (max 4999): 7 distinct in the first decade
    assert_eq!(&taus[..8], &[1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 8.0, 10.0]);
    let hadamard = json("hadamard", "octave");
    assert!(hadamard["noise"]["rate_ramp_deg_per_h2"]["value"].is_null());
    assert!(
        hadamard["noise"]["arw_deg_per_sqrt_h"]["value"]
            .as_f64()
            .unwrap()
            > 0.0
    );
    let text = ok(&[
        "allan", "--input", &csv, "--rate", "1", "--kind", "hadamard",
    ]);
    assert!(
        text.contains("the Hadamard variance cancels a rate ramp"),
        "{text}"
    );
    // White noise of variance 1/12 at 1 Hz: N = sqrt(1/12) °/√s for every kind.
    for kind in ["overlapping", "nonoverlapping", "modified", "hadamard"] {
        let n = json(kind, "octave")["noise"]["arw_deg_per_sqrt_h"]["value"]
            .as_f64()
            .unwrap();
        let want = (1.0f64 / 12.0).sqrt() * 60.0;
        assert!((n / want - 1.0).abs() < 0.05, "{kind}: N {n} vs {want}");
    }

    let long = dir.path().join("long.csv");
    let mut text = String::with_capacity(2_100_000 * 2);
    text.push_str("rate_dps\n");
    for k in 0..1_000_001u32 {
        text.push_str(if k % 2 == 0 { "1\n" } else { "0\n" });
    }
    std::fs::write(&long, text).unwrap();
    let long = long.to_string_lossy().into_owned();
    let log = fails(&["allan", "--input", &long, "--rate", "1", "--taus", "all"]);
    assert!(
        log.contains("1000001 samples")
            && log.contains("at most 1000000")
            && log.contains("--taus many"),
        "{log}"
    );
}

/// White noise with a ×8 burst from 90 s to 100 s at 100 Hz.
fn burst_csv(dir: &std::path::Path) -> String {
    let mut n: u64 = 987_654_321;
    let mut text = String::from("t,rate_dps\n");
    for k in 0..20_000 {
        // Sum of 12 uniforms − 6: near-Gaussian, unit variance.
        let mut g = -6.0;
        for _ in 0..12 {
            n = 16807 * n % 2_147_483_647;
            g += n as f64 / 2_147_483_647.0;
        }
        let scale = if (9000..10_000).contains(&k) {
            8.0
        } else {
            1.0
        };
        text.push_str(&format!("{k},{}\n", g * scale));
    }
    let path = dir.join("burst.csv");
    std::fs::write(&path, text).unwrap();
    path.to_string_lossy().into_owned()
}

#[test]
fn davar_finds_the_burst_and_the_adaptive_window_is_closer() {
    let dir = tempfile::tempdir().unwrap();
    let csv = burst_csv(dir.path());
    let fixed: serde_json::Value = serde_json::from_str(&ok(&[
        "davar", "--input", &csv, "--rate", "100", "--window", "1001", "--json",
    ]))
    .unwrap();
    let adaptive: serde_json::Value = serde_json::from_str(&ok(&[
        "davar",
        "--input",
        &csv,
        "--rate",
        "100",
        "--window",
        "1001",
        "--adaptive",
        "--json",
    ]))
    .unwrap();
    for v in [&fixed, &adaptive] {
        for key in ["time_s", "window", "tau_s", "adev"] {
            assert!(v["davar"][key].is_array(), "{key}");
        }
        for key in [
            "arw_deg_per_sqrt_h",
            "bias_instability_deg_per_h",
            "rrw_deg_per_h_per_sqrt_h",
        ] {
            assert!(v["coefficients"][key].is_array(), "{key}");
        }
        assert_eq!(
            v["disturbances"].as_array().unwrap().len(),
            1,
            "{}",
            v["disturbances"]
        );
    }
    let span = |v: &serde_json::Value| {
        let d = &v["disturbances"][0];
        (d["start_s"].as_f64().unwrap(), d["end_s"].as_f64().unwrap())
    };
    let (fs, fe) = span(&fixed);
    let (a_s, ae) = span(&adaptive);
    assert!(
        fs < 90.0 && fe > 100.0 && fs > 84.0 && fe < 106.0,
        "fixed {fs}..{fe}"
    );
    assert!(
        (ae - a_s) <= (fe - fs),
        "adaptive {a_s}..{ae} vs fixed {fs}..{fe}"
    );
    let windows = adaptive["davar"]["window"].as_array().unwrap();
    assert!(
        windows.iter().any(|w| w.as_u64().unwrap() < 1001),
        "the adaptive window shortens"
    );
}

#[test]
fn davar_bad_input() {
    let dir = tempfile::tempdir().unwrap();
    let csv = white_csv(dir.path(), 1000);
    for (args, needle) in [
        (
            vec!["--window", "5000"],
            "--window 5000 is not allowed: it must be 4..=1000",
        ),
        (vec!["--window", "2"], "--window 2 is not allowed"),
        (
            vec!["--window", "500", "--adaptive", "--min-window", "600"],
            "--min-window 600 is not allowed",
        ),
        (
            vec!["--window", "500", "--step", "0"],
            "--step 0 is not allowed",
        ),
    ] {
        let mut all = vec!["davar", "--input", &csv, "--rate", "10"];
        all.extend(args);
        let log = fails(&all);
        assert!(log.contains(needle), "{all:?}: {log}");
    }
    let log = fails(&["davar", "--input", &csv, "--rate", "0"]);
    assert!(log.contains("--rate 0 is not allowed"), "{log}");
}

#[test]
fn plots_are_written_as_png_or_svg() {
    let dir = tempfile::tempdir().unwrap();
    let csv = burst_csv(dir.path());
    let png = dir.path().join("allan.png");
    let svg = dir.path().join("davar.svg");
    ok(&[
        "allan",
        "--input",
        &csv,
        "--rate",
        "100",
        "--plot",
        png.to_str().unwrap(),
    ]);
    ok(&[
        "davar",
        "--input",
        &csv,
        "--rate",
        "100",
        "--window",
        "1001",
        "--plot",
        svg.to_str().unwrap(),
    ]);
    let bytes = std::fs::read(&png).unwrap();
    assert_eq!(&bytes[..8], b"\x89PNG\r\n\x1a\n", "a PNG file");
    let text = std::fs::read_to_string(&svg).unwrap();
    assert!(
        text.contains("<svg") && text.contains("Dynamic Allan deviation"),
        "an SVG with its title"
    );

    let log = fails(&[
        "allan",
        "--input",
        &csv,
        "--rate",
        "100",
        "--plot",
        dir.path().join("a.jpg").to_str().unwrap(),
    ]);
    assert!(log.contains("must end in .png or .svg"), "{log}");
    let constant = dir.path().join("constant.csv");
    std::fs::write(
        &constant,
        "t,rate_dps\n".to_string() + &(0..100).map(|k| format!("{k},1.5\n")).collect::<String>(),
    )
    .unwrap();
    let refused = dir.path().join("refused.png");
    let log = fails(&[
        "allan",
        "--input",
        constant.to_str().unwrap(),
        "--rate",
        "1",
        "--plot",
        refused.to_str().unwrap(),
    ]);
    assert!(log.contains("nothing to plot"), "{log}");
    let names: Vec<String> = std::fs::read_dir(dir.path())
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    assert!(
        !names
            .iter()
            .any(|n| n.contains("refused") || n.starts_with(".gyrofx-plot")),
        "{names:?}"
    );
}

/// An AR(1) record x_k = φ x_{k−1} + u_k with φ = −0.2855 (paper 003's drift) and uniform u
/// from the same LCG, written as a CSV.
fn ar1_csv(dir: &std::path::Path, samples: usize) -> String {
    let mut n: u64 = 42;
    let mut x = 0.0;
    let mut text = String::from("k,drift\n");
    for k in 0..samples {
        n = 16807 * n % 2_147_483_647;
        x = -0.2855 * x + (n as f64 / 2_147_483_647.0 - 0.5);
        text.push_str(&format!("{k},{x}\n"));
    }
    let path = dir.join("ar1.csv");
    std::fs::write(&path, text).unwrap();
    path.to_string_lossy().into_owned()
}

#[test]
fn ar_fits_the_orders_and_names_the_aic_choice() {
    let dir = tempfile::tempdir().unwrap();
    let csv = ar1_csv(dir.path(), 20_000);
    let out = ok(&["ar", "--input", &csv, "--column", "drift", "--json"]);
    let v: serde_json::Value = serde_json::from_str(&out).unwrap();
    assert_eq!(v["samples"], 20_000);
    let models = v["models"].as_array().unwrap();
    assert_eq!(models.len(), 3);
    let phi = models[0]["coefficients"][0].as_f64().unwrap();
    assert!((phi + 0.2855).abs() < 0.02, "{phi}");
    // Uniform u on [−1/2, 1/2): variance 1/12.
    let variance = models[0]["noise_variance"].as_f64().unwrap();
    assert!((variance * 12.0 - 1.0).abs() < 0.03, "{variance}");
    let chosen = v["aic_order"].as_u64().unwrap() as usize;
    let smallest = models
        .iter()
        .min_by(|a, b| {
            a["aic"]
                .as_f64()
                .unwrap()
                .total_cmp(&b["aic"].as_f64().unwrap())
        })
        .unwrap();
    assert_eq!(smallest["order"].as_u64().unwrap() as usize, chosen);
    let table = ok(&["ar", "--input", &csv, "--column", "drift"]);
    assert!(
        table.contains("<- AIC") && table.contains("20000 samples"),
        "{table}"
    );

    let log = fails(&[
        "ar",
        "--input",
        &csv,
        "--column",
        "drift",
        "--max-order",
        "0",
    ]);
    assert!(
        log.contains("'0' for '--max-order") && log.contains("1..=1000"),
        "{log}"
    );
    let short = ar1_csv(dir.path(), 4);
    let log = fails(&["ar", "--input", &short, "--column", "drift"]);
    assert!(log.contains("4 samples are too few for AR(3)"), "{log}");
    let log = fails(&["ar", "--input", &csv, "--column", "rate"]);
    assert!(log.contains("rate"), "{log}");
}

#[test]
fn reproduce_prints_and_writes_the_papers_tables_and_refuses_the_rest() {
    let dir = tempfile::tempdir().unwrap();
    let folder = dir.path().join("003");
    let output = gyrofx(&[
        "reproduce",
        "--paper",
        "003",
        "--out",
        folder.to_str().unwrap(),
    ]);
    assert!(output.status.success(), "{}", text(&output));
    let out = String::from_utf8_lossy(&output.stdout).into_owned();
    assert_eq!(
        std::fs::read_to_string(folder.join("report.md")).unwrap(),
        out
    );
    let png = std::fs::read(folder.join("allan.png")).unwrap();
    assert!(png.starts_with(b"\x89PNG"), "allan.png is a PNG");
    let manifest = std::fs::read_to_string(folder.join("manifest.json")).unwrap();
    assert!(
        manifest.contains("allan.png") && manifest.contains("--paper 003"),
        "{manifest}"
    );
    // A folder that is not a gyrofx output is not replaced.
    let foreign = dir.path().join("foreign");
    std::fs::create_dir(&foreign).unwrap();
    std::fs::write(foreign.join("notes.txt"), "mine").unwrap();
    let log = fails(&[
        "reproduce",
        "--paper",
        "003",
        "--out",
        foreign.to_str().unwrap(),
    ]);
    assert!(log.contains("not a gyrofx output"), "{log}");
    assert_eq!(
        std::fs::read_to_string(foreign.join("notes.txt")).unwrap(),
        "mine"
    );
    assert!(
        out.contains("| paper | 0.0667 | 0.0528 | 0.0021 |"),
        "{out}"
    );
    let out = ok(&["reproduce", "--paper", "000", "--samples", "50000"]);
    assert!(
        out.contains("## Table 4") && out.contains("unity DC gain"),
        "{out}"
    );
    let out = ok(&["reproduce", "--paper", "002"]);
    assert!(out.contains("| adaptive | 235.5–285.4 |"), "{out}");
    let log = fails(&["reproduce", "--paper", "7"]);
    assert!(log.contains("\"7\" is not one of the papers"), "{log}");
    let log = fails(&["reproduce", "--paper", "000", "--samples", "100"]);
    assert!(log.contains("--samples 100 is too few"), "{log}");
}

#[test]
fn reproduce_paper_004_compares_its_table_2() {
    let out = ok(&["reproduce", "--paper", "004", "--samples", "20000"]);
    assert!(out.contains("| N (°/√s) | 1.180e-4 \\|"), "{out}");
    assert!(out.contains("ADEV at 1 s"), "{out}");
    // Through the real loops (the first Table 2): the calibrated front ends give each raw
    // gyro the paper's N with its drifts off, and reversal cancels the drift at long τ.
    let gyrofx_cells = |label: &str| -> Vec<f64> {
        out.lines()
            .find(|l| l.starts_with(&format!("| {label}")))
            .unwrap_or_else(|| panic!("no {label} row: {out}"))
            .split(" | ")
            .skip(1)
            .filter_map(|cell| {
                cell.rsplit("\\| ")
                    .next()?
                    .trim_end_matches(" |")
                    .parse()
                    .ok()
            })
            .collect()
    };
    let adev_128 = gyrofx_cells("ADEV at 128 s");
    assert_eq!(adev_128.len(), 4, "{adev_128:?}");
    assert!(
        adev_128[2] < 0.25 * adev_128[0].min(adev_128[1]),
        "reversal left the drift: {adev_128:?}"
    );
    for (gyro, paper) in [("A", 1.18e-4), ("B", 2.04e-4)] {
        let row = out
            .lines()
            .find(|l| l.starts_with(&format!("| {gyro} | ")))
            .unwrap_or_else(|| panic!("no calibration row of {gyro}: {out}"));
        let measured: f64 = row
            .trim_end_matches(" |")
            .rsplit("| ")
            .next()
            .unwrap()
            .parse()
            .unwrap();
        assert!((measured / paper - 1.0).abs() < 0.06, "{row}");
    }
    // At resonator level: the damping coupling is the same in both modes and leaves nothing
    // after reversal; the quadrature leak leaves the residual, measured on the closed loop
    // within a few mdps of its closed form.
    let row = |gyro: &str, term: &str| -> Vec<String> {
        out.lines()
            .find(|l| l.starts_with(&format!("| {gyro} | {term}")))
            .unwrap_or_else(|| panic!("no {gyro} {term} row: {out}"))
            .split('|')
            .map(|c| c.trim().to_string())
            .collect()
    };
    for gyro in ["a", "b"] {
        let damping = row(gyro, "damping coupling");
        assert_eq!(damping[3], damping[4], "{damping:?}");
        assert_eq!(damping[5], "+0.00e0", "{damping:?}");
        let leak = row(gyro, "quadrature leak");
        let left: f64 = leak[5].parse().unwrap();
        assert!(left < -5e-3 && left > -2e-2, "{leak:?}");
        let bias = row(gyro, "bias, measured");
        let residual: Vec<f64> = bias[5]
            .split(['(', ')', ' '])
            .filter_map(|t| t.parse().ok())
            .collect();
        assert!((residual[0] - residual[1]).abs() < 5e-3, "{bias:?}");
    }
    assert!(out.contains("**Cancelled exactly:**") && out.contains("**Left:**"));
    // The default trims the phase: the text says what the trim adds against the sense phase
    // at the locked frequency, and the two nearly cancel (the PLL's modulation is the rest,
    // 1.5e-4° here).
    let degrees_after = |marker: &str| -> Vec<f64> {
        let rest = out
            .split(marker)
            .nth(1)
            .unwrap_or_else(|| panic!("{marker}: {out}"));
        rest.split(['°', '(', ' ', '/'])
            .filter_map(|t| t.parse().ok())
            .take(2)
            .collect()
    };
    let trim = degrees_after("its phase trim (`[loop] phase_trim`, the default) adds ");
    let locked = degrees_after("the coupled resonance the drive locks on (");
    for (t, l) in trim.iter().zip(&locked) {
        assert!(
            t * l < 0.0 && (t + l).abs() < 2e-4,
            "trim {trim:?}, locked {locked:?}"
        );
    }
    assert_eq!((trim.len(), locked.len()), (2, 2), "{out}");
    let log = fails(&["reproduce", "--paper", "004", "--samples", "100"]);
    assert!(log.contains("--samples 100 is too few"), "{log}");
}

/// A one-column CSV needs no `--column` in any command that reads one column; a file of
/// several columns, none `rate_dps`, is refused with exit 2 naming them, and nothing written.
#[test]
fn a_one_column_record_needs_no_column_flag() {
    let dir = tempfile::tempdir().unwrap();
    let mut n: u64 = 42;
    let mut one = String::from("gyro_z\n");
    let mut three = String::from("t,gyro_x,gyro_z\n");
    for k in 0..3000 {
        n = 16807 * n % 2_147_483_647;
        let value = n as f64 / 2_147_483_647.0 - 0.5;
        one.push_str(&format!("{value}\n"));
        three.push_str(&format!("{k},{},{value}\n", -value));
    }
    let one_path = dir.path().join("one.csv");
    let three_path = dir.path().join("three.csv");
    std::fs::write(&one_path, one).unwrap();
    std::fs::write(&three_path, three).unwrap();
    let (one, three) = (one_path.to_str().unwrap(), three_path.to_str().unwrap());
    let allan_one = ok(&["allan", "--input", one, "--rate", "100", "--json"]);
    let allan_named = ok(&[
        "allan", "--input", three, "--column", "gyro_z", "--rate", "100", "--json",
    ]);
    let adev =
        |text: &str| serde_json::from_str::<serde_json::Value>(text).unwrap()["adev"].clone();
    assert_eq!(
        adev(&allan_one),
        adev(&allan_named),
        "the same column, the same deviation"
    );
    ok(&[
        "davar", "--input", one, "--rate", "100", "--window", "500", "--step", "500", "--json",
    ]);
    ok(&["ar", "--input", one, "--max-order", "2"]);
    let filtered = dir.path().join("filtered.csv");
    ok(&[
        "filter",
        "--input",
        one,
        "--fs",
        "200",
        "--output",
        filtered.to_str().unwrap(),
    ]);
    assert!(filtered.is_file());
    std::fs::remove_file(&filtered).unwrap();
    for command in [
        vec!["allan", "--input", three, "--rate", "100"],
        vec!["ar", "--input", three],
        vec![
            "filter",
            "--input",
            three,
            "--fs",
            "200",
            "--output",
            filtered.to_str().unwrap(),
        ],
    ] {
        let output = gyrofx(&command);
        let log = text(&output);
        assert_eq!(output.status.code(), Some(2), "{command:?}: {log}");
        assert!(
            log.contains("--column is needed: the file has 3 columns (t, gyro_x, gyro_z)"),
            "{command:?}: {log}"
        );
    }
    assert!(!filtered.exists(), "nothing written");
}

/// `gyrofx denoise`: paper 004's denoising on a user's record. A slow sine in white noise
/// keeps its sine and loses most of its white noise (the ADEV at the shortest τ falls, at the
/// longest it stays); one seed gives the same bytes twice; bad settings exit 2 with nothing
/// written.
#[test]
fn denoise_cleans_white_noise_off_a_record_and_refuses_bad_settings() {
    let dir = tempfile::tempdir().unwrap();
    let mut n: u64 = 7;
    let mut record = String::from("gyro_z\n");
    for k in 0..6000 {
        // Uniform noise of σ ≈ 0.29 from the NIST LCG over a 0.5 °/s sine of 2000 samples.
        n = 16807 * n % 2_147_483_647;
        let noise = n as f64 / 2_147_483_647.0 - 0.5;
        let sine = 0.5 * (2.0 * std::f64::consts::PI * k as f64 / 2000.0).sin();
        record.push_str(&format!("{}\n", sine + noise));
    }
    let input = dir.path().join("record.csv");
    std::fs::write(&input, record).unwrap();
    let input = input.to_str().unwrap();
    let output = dir.path().join("denoised.csv");
    let out = output.to_str().unwrap();
    let settings = [
        "--rate",
        "100",
        "--block",
        "2000",
        "--overlap",
        "200",
        "--realizations",
        "10",
    ];
    let run = |extra: &[&str]| {
        let mut args = vec!["denoise", "--input", input, "--output", out, "--json"];
        args.extend_from_slice(&settings);
        args.extend_from_slice(extra);
        ok(&args)
    };
    let report: serde_json::Value = serde_json::from_str(&run(&[])).unwrap();
    let first = std::fs::read(&output).unwrap();
    let rows = String::from_utf8(first.clone()).unwrap();
    assert!(rows.starts_with("sample,rate_dps,denoised_dps\n"));
    assert_eq!(rows.lines().count(), 6001);
    assert_eq!(report["blocks"], 3);
    assert_eq!(report["column"], "gyro_z");
    let adev = |which: &str, k: usize| report[which]["adev"][k].as_f64().unwrap();
    assert!(adev("after", 0) < 0.2 * adev("before", 0), "{report}");
    // Where the sine dominates (the largest deviation, τ near a quarter period), it is kept.
    let count = report["before"]["adev"].as_array().unwrap().len();
    let peak = (0..count)
        .max_by(|a, b| adev("before", *a).total_cmp(&adev("before", *b)))
        .unwrap();
    assert!(
        (adev("after", peak) / adev("before", peak) - 1.0).abs() < 0.05,
        "{report}"
    );
    run(&[]);
    assert_eq!(
        std::fs::read(&output).unwrap(),
        first,
        "one seed, the same bytes"
    );
    std::fs::remove_file(&output).unwrap();
    for (flag, value, message) in [
        (
            "--rule",
            "medium",
            "--rule medium is not allowed: soft or hard",
        ),
        ("--block", "8", "--block 8 is not allowed"),
        (
            "--overlap",
            "5000",
            "--overlap 5000 is not allowed: it must be below --block",
        ),
        ("--realizations", "0", "--realizations 0 is not allowed"),
        (
            "--noise-amplitude",
            "-1",
            "--noise-amplitude -1 is not allowed",
        ),
    ] {
        let mut args = vec![
            "denoise", "--input", input, "--output", out, "--rate", "100",
        ];
        if flag != "--overlap" {
            args.extend_from_slice(&["--overlap", "4"]);
        }
        args.extend_from_slice(&[flag, value]);
        let result = gyrofx(&args);
        let log = text(&result);
        assert_eq!(result.status.code(), Some(2), "{flag}: {log}");
        assert!(log.contains(message), "{flag}: {log}");
        assert!(!output.exists(), "{flag}: nothing written");
    }
    // A file of someone else's at --output is refused and kept, for denoise and filter alike;
    // --force replaces it. (The command's own earlier output is replaced without it, above.)
    std::fs::write(&output, "my notes\n").unwrap();
    for command in [
        vec![
            "denoise",
            "--input",
            input,
            "--output",
            out,
            "--rate",
            "100",
            "--overlap",
            "4",
        ],
        vec!["filter", "--input", input, "--output", out, "--fs", "100"],
    ] {
        let result = gyrofx(&command);
        let log = text(&result);
        assert_eq!(result.status.code(), Some(2), "{command:?}: {log}");
        assert!(log.contains("exists and gyrofx did not write it"), "{log}");
        assert_eq!(std::fs::read_to_string(&output).unwrap(), "my notes\n");
    }
    let mut forced = vec!["denoise", "--input", input, "--output", out, "--force"];
    forced.extend_from_slice(&settings);
    ok(&forced);
    assert!(std::fs::read_to_string(&output)
        .unwrap()
        .starts_with("sample,rate_dps,denoised_dps\n"));
}
