//! The command line as hostile input: no panic from any numeric flag, usage errors exit 2 and
//! name the flag, checks run before the work, no flag is ignored in silence, sizes are capped,
//! and the analyses refuse what they cannot compute instead of printing NaN.

use std::path::Path;
use std::process::{Command, Output};

use crate::common::*;

/// Runs gyrofx with `args` and no simulator or synthesizer on PATH (explore and synth then stop
/// at their tool check, after every argument check).
fn gyrofx_without_tools(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_gyrofx"))
        .args(args)
        .env("PATH", "")
        .output()
        .expect("the gyrofx binary runs")
}

/// Asserts that `args` exit 2 with one `error:` line that holds every needle and never speaks
/// of a config field (`config:`) the command line did not write.
fn usage_error(args: &[&str], needles: &[&str]) {
    let output = gyrofx(args);
    let log = text(&output);
    assert_eq!(output.status.code(), Some(2), "{args:?}: {log}");
    assert!(log.starts_with("error: "), "{args:?}: {log}");
    assert!(!log.contains("config:"), "{args:?}: {log}");
    for needle in needles {
        assert!(log.contains(needle), "{args:?}: no {needle:?} in {log}");
    }
}

/// A CSV of one `rate_dps` column with `values`, in `dir`.
fn record(dir: &Path, name: &str, values: impl Iterator<Item = f64>) -> String {
    let rows: String = values.map(|v| format!("{v:e}\n")).collect();
    let path = dir.join(name);
    std::fs::write(&path, format!("rate_dps\n{rows}")).unwrap();
    path.to_string_lossy().into_owned()
}

/// A noise-like record of `n` values of about `scale`.
fn noise(dir: &Path, name: &str, n: usize, scale: f64) -> String {
    record(
        dir,
        name,
        (0..n).map(move |k| (((k * 7919) % 1000) as f64 / 1000.0 - 0.5) * scale),
    )
}

/// A seed is written into the manifest's TOML config, whose integers are 64-bit signed: a seed
/// of 2^63 or more is refused by the parser naming --seed and the range (it panicked while
/// writing the manifest), in every command that takes one; the largest seed is written.
#[test]
fn a_seed_beyond_i64_is_refused_by_every_command() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("pkg");
    let out = out.to_str().unwrap();
    let rate = write_config(dir.path(), "rate.toml", "[plant]\nmodel = \"rate\"\n");
    for seed in ["9223372036854775808", "18446744073709551615"] {
        usage_error(
            &[
                "generate",
                "--out",
                out,
                "--config",
                &rate,
                "--samples",
                "200",
                "--seed",
                seed,
            ],
            &["--seed", seed, "0..=9223372036854775807"],
        );
        usage_error(
            &["reproduce", "--paper", "002", "--seed", seed],
            &["--seed", "0..=9223372036854775807"],
        );
    }
    assert!(!Path::new(out).exists(), "nothing written");
    // In a config file the same seed is not a TOML integer: an error of the file, no panic.
    let big = write_config(dir.path(), "big.toml", "seed = 9223372036854775808\n");
    let output = gyrofx(&["generate", "--out", out, "--config", &big]);
    assert_eq!(output.status.code(), Some(1), "{}", text(&output));
    assert!(!text(&output).contains("panicked"));
    ok(&[
        "generate",
        "--out",
        out,
        "--config",
        &rate,
        "--samples",
        "200",
        "--seed",
        "9223372036854775807",
    ]);
    let manifest = std::fs::read_to_string(Path::new(out).join("manifest.json")).unwrap();
    assert!(manifest.contains("9223372036854775807"), "{manifest}");
}

/// Extreme values of every command's numeric flags: the exit code is 0, 1 or 2 (never 101, a
/// panic, nor a signal) and stderr has no panic message. Runs the binary on several threads.
#[test]
fn no_numeric_flag_value_panics() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let csv = noise(d, "noise.csv", 500, 1.0);
    let rate = write_config(d, "rate.toml", "[plant]\nmodel = \"rate\"\n");
    let path = |name: &str| d.join(name).to_string_lossy().into_owned();
    let values = [
        "0",
        "-0",
        "-1",
        "1",
        "1e308",
        "-1e308",
        "1e-320",
        "NaN",
        "inf",
        "9223372036854775808",
        "18446744073709551615",
        "18446744073709551616",
        "99999999999999999999999999999999999999999999",
    ];
    // Each template's `V` is replaced by every value; `OUT` by a fresh path.
    let templates: Vec<Vec<String>> = [
        "generate --out OUT --config RATE --samples V",
        "generate --out OUT --config RATE --samples 200 --seed V",
        "reproduce --paper 000 --samples V",
        "reproduce --paper 000 --samples 1 --seed V",
        "allan --input CSV --rate V",
        "davar --input CSV --rate V --window 100",
        "davar --input CSV --rate 100 --window V",
        "davar --input CSV --rate 100 --window 100 --step V",
        "davar --input CSV --rate 100 --window 100 --adaptive --min-window V",
        "davar --input CSV --rate 100 --window 100 --adaptive --kp V",
        "ar --input CSV --max-order V",
        "design --qb V --qn 1e-4 --fs 100 --qw 1e-3",
        "design --qb 1e-6 --qn V --fs 100 --qw 1e-3",
        "design --qb 1e-6 --qn 1e-4 --fs V --qw 1e-3",
        "design --qb 1e-6 --qn 1e-4 --fs 100 --qw V",
        "design --qb 1e-6 --qn 1e-4 --fs 100 --bandwidth V",
        "design --qb 1e-6 --qn 1e-4 --fs 100 --qw 1e-3 --coefficient-width V",
        "filter --input CSV --fs V --output OUT.csv",
        "filter --input CSV --fs 100 --bandwidth V --output OUT.csv",
        "loop --seconds V",
        "loop --seconds 0.001 --rate-dps V",
        "verify --out OUT --mask V",
        "verify --out OUT --max-reported V --max-mismatches V",
        "formats --samples V",
        "formats --switches V",
        "formats --output-error V",
        "formats --residual-budget V",
        "explore --out OUT --guard-bits 0..0 --samples V",
        "explore --out OUT --guard-bits 0..0 --jobs V",
        "synth --out OUT --target xilinx --jobs V",
    ]
    .iter()
    .map(|t| t.split(' ').map(str::to_string).collect())
    .collect();
    let mut cases: Vec<Vec<String>> = Vec::new();
    for template in &templates {
        for value in values {
            let out = path(&format!("out{}", cases.len()));
            cases.push(
                template
                    .iter()
                    .map(|word| match word.as_str() {
                        "V" => value.to_string(),
                        "OUT" => out.clone(),
                        "OUT.csv" => format!("{out}.csv"),
                        "CSV" => csv.clone(),
                        "RATE" => rate.clone(),
                        other => other.to_string(),
                    })
                    .collect(),
            );
        }
    }
    let failures: Vec<String> = std::thread::scope(|scope| {
        let workers: Vec<_> = cases
            .chunks(cases.len().div_ceil(4))
            .map(|chunk| {
                scope.spawn(move || {
                    let mut failures = Vec::new();
                    for args in chunk {
                        let args: Vec<&str> = args.iter().map(String::as_str).collect();
                        let output = gyrofx_without_tools(&args);
                        let stderr = String::from_utf8_lossy(&output.stderr);
                        let code = output.status.code();
                        if !matches!(code, Some(0..=2)) || stderr.contains("panicked") {
                            failures.push(format!("{args:?}: exit {code:?}: {stderr}"));
                        }
                    }
                    failures
                })
            })
            .collect();
        workers
            .into_iter()
            .flat_map(|w| w.join().unwrap())
            .collect()
    });
    assert!(
        failures.is_empty(),
        "{} of {} cases failed:\n{}",
        failures.len(),
        cases.len(),
        failures.join("\n")
    );
}

/// Every bad flag value is a usage error (exit 2) that names the flag and its value, not a
/// config field the flag was copied into.
#[test]
fn usage_errors_name_the_flag_and_exit_2() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let csv = noise(d, "noise.csv", 500, 1.0);
    let out = d.join("out");
    let out = out.to_str().unwrap();
    let output_csv = d.join("filtered.csv");
    let output_csv = output_csv.to_str().unwrap();
    let cases: Vec<(Vec<&str>, Vec<&str>)> = vec![
        (
            vec!["generate", "--out", out, "--samples", "0"],
            vec!["--samples", "1..=20000000"],
        ),
        (
            vec!["generate", "--out", out, "--preset", "nosuch"],
            vec!["--preset \"nosuch\"", "gu2019"],
        ),
        (
            vec!["synth", "--out", out, "--preset", "nosuch"],
            vec!["--preset \"nosuch\""],
        ),
        (
            vec!["init", "--preset", "nosuch"],
            vec!["--preset \"nosuch\""],
        ),
        (
            vec!["formats", "--preset", "nosuch"],
            vec!["--preset \"nosuch\""],
        ),
        (
            vec!["formats", "--samples", "0"],
            vec!["--samples", "1..=20000000"],
        ),
        (
            vec!["verify", "--out", out, "--sim", "bogus"],
            vec!["--sim bogus", "iverilog"],
        ),
        (
            vec![
                "filter", "--input", &csv, "--fs", "0", "--output", output_csv,
            ],
            vec!["--fs 0 is not allowed", "> 0"],
        ),
        (
            vec![
                "filter",
                "--input",
                &csv,
                "--fs",
                "100",
                "--bandwidth",
                "60",
                "--output",
                output_csv,
            ],
            vec!["--bandwidth 60 is not allowed", "fs/2 = 50"],
        ),
        (
            vec![
                "filter", "--input", &csv, "--fs", "1e308", "--output", output_csv,
            ],
            vec!["--fs 1e308"],
        ),
        (
            vec![
                "design", "--qb", "0", "--qn", "1e-4", "--fs", "100", "--qw", "1",
            ],
            vec!["--qb 0 is not allowed", "> 0"],
        ),
        (
            vec![
                "design", "--qb", "1e-6", "--qn", "nan", "--fs", "100", "--qw", "1",
            ],
            vec!["--qn NaN is not allowed"],
        ),
        (
            vec![
                "design", "--qb", "1e-6", "--qn", "1e-4", "--fs", "-1", "--qw", "1",
            ],
            vec!["--fs -1 is not allowed"],
        ),
        (
            vec![
                "design", "--qb", "1e-6", "--qn", "1e-4", "--fs", "100", "--qw", "-1",
            ],
            vec!["--qw -1 is not allowed"],
        ),
        (
            vec![
                "design",
                "--qb",
                "1e-6",
                "--qn",
                "1e-4",
                "--fs",
                "100",
                "--bandwidth",
                "0",
            ],
            vec!["--bandwidth 0 is not allowed", "fs/2 = 50"],
        ),
        (
            vec![
                "design", "--qb", "1e-6", "--qn", "1e-4", "--fs", "1e308", "--qw", "1",
            ],
            vec!["--fs 1e308", "cannot be designed"],
        ),
        (
            vec![
                "design", "--qb", "1e-6", "--qn", "1e-4", "--fs", "100", "--qw", "1", "--method",
                "bogus",
            ],
            vec!["--method bogus", "direct or paper"],
        ),
        (
            vec![
                "design",
                "--qb",
                "1e-6",
                "--qn",
                "1e-4",
                "--fs",
                "100",
                "--qw",
                "1",
                "--coefficient-width",
                "0",
            ],
            vec!["--coefficient-width 0 is not allowed", "2..=64"],
        ),
        (
            vec!["allan", "--input", &csv, "--rate", "1e308"],
            vec!["--rate 1e308 is not allowed", "1e-9..=1e9 Hz"],
        ),
        (
            vec!["davar", "--input", &csv, "--rate", "1e-320"],
            vec!["--rate 1e-320 is not allowed", "1e-9..=1e9 Hz"],
        ),
        (
            vec![
                "davar",
                "--input",
                &csv,
                "--rate",
                "100",
                "--window",
                "100",
                "--step",
                "18446744073709551615",
            ],
            vec!["--step 18446744073709551615 is not allowed", "1..=500"],
        ),
        (
            vec!["ar", "--input", &csv, "--max-order", "0"],
            vec!["--max-order", "1..=1000"],
        ),
    ];
    for (args, needles) in &cases {
        usage_error(args, needles);
    }
    assert!(!Path::new(out).exists() && !Path::new(output_csv).exists());
}

/// The paths a command writes at the end are checked before its work: a missing folder, a
/// folder for a file, a parent that is a file. A flag that does nothing without another is
/// refused.
#[test]
fn output_paths_are_checked_before_the_work_and_no_flag_is_ignored() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let csv = noise(d, "noise.csv", 500, 1.0);
    let missing = d.join("missing").join("x.png");
    let missing = missing.to_str().unwrap();
    let under_a_file = Path::new(&csv).join("x.svg");
    let under_a_file = under_a_file.to_str().unwrap();
    let folder = d.join("folder.svg");
    std::fs::create_dir(&folder).unwrap();
    let folder = folder.to_str().unwrap();
    for plot in [missing, under_a_file, folder] {
        usage_error(
            &["allan", "--input", &csv, "--rate", "100", "--plot", plot],
            &["--plot", plot],
        );
        usage_error(
            &[
                "davar", "--input", &csv, "--rate", "100", "--window", "100", "--plot", plot,
            ],
            &["--plot", plot],
        );
        usage_error(&["loop", "--plot", plot], &["--plot", plot]);
    }
    let junit = d.join("missing").join("junit.xml");
    let junit = junit.to_str().unwrap();
    usage_error(
        &["verify", "--out", d.to_str().unwrap(), "--junit", junit],
        &["--junit", junit, "does not exist"],
    );
    let out = d.join("out");
    let out = out.to_str().unwrap();
    for (args, needle) in [
        (vec!["formats", "--force"], "--write"),
        (
            vec!["generate", "--out", out, "--recording-units", "rad/s"],
            "--recording",
        ),
        (
            vec!["generate", "--out", out, "--recording-rate", "100"],
            "--recording",
        ),
        (
            vec!["generate", "--out", out, "--recording-columns", "1,2"],
            "--recording",
        ),
        (
            vec!["generate", "--out", out, "--recording-mode", "mode"],
            "--recording",
        ),
        (
            vec![
                "design",
                "--qb",
                "1e-6",
                "--qn",
                "1e-4",
                "--fs",
                "100",
                "--qw",
                "1",
                "--bandwidth",
                "3",
            ],
            "--bandwidth",
        ),
    ] {
        let output = gyrofx(&args);
        let log = text(&output);
        assert_eq!(output.status.code(), Some(2), "{args:?}: {log}");
        assert!(log.contains(needle), "{args:?}: {log}");
    }
    assert!(!Path::new(out).exists());
}

/// Every count that sizes memory or threads is capped before the work, the cap in the message.
#[test]
fn sizes_are_capped_before_the_work() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out");
    let out = out.to_str().unwrap();
    for (args, needles) in [
        (
            vec!["reproduce", "--paper", "000", "--samples", "1e9"],
            vec!["--samples", "1..=20000000"],
        ),
        (
            vec!["generate", "--out", out, "--samples", "20000001"],
            vec!["--samples", "1..=20000000"],
        ),
        (
            vec![
                "explore",
                "--out",
                out,
                "--guard-bits",
                "0..1",
                "--jobs",
                "1e15",
            ],
            vec!["--jobs", "1..=256"],
        ),
        (
            vec![
                "synth", "--out", out, "--target", "xilinx", "--jobs", "100000",
            ],
            vec!["--jobs", "1..=256"],
        ),
        (
            vec!["ar", "--input", out, "--max-order", "18446744073709551615"],
            vec!["--max-order", "1..=1000"],
        ),
    ] {
        usage_error(&args, &needles);
    }
    assert!(!Path::new(out).exists());
}

/// `ar`, `davar` and `allan` refuse records whose sums of squares would overflow or underflow
/// (they printed NaN, or zeros) and rates outside 1e-9..=1e9 Hz (NaN deviations); at the
/// limits they compute, and nothing they print is NaN.
#[test]
fn analyses_refuse_magnitudes_and_rates_they_cannot_compute() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let huge = noise(d, "huge.csv", 500, 1e200);
    let tiny = noise(d, "tiny.csv", 500, 1e-200);
    for input in [&huge, &tiny] {
        for args in [
            vec!["ar", "--input", input],
            vec!["allan", "--input", input, "--rate", "100"],
            vec![
                "davar", "--input", input, "--rate", "100", "--window", "100",
            ],
        ] {
            let output = gyrofx(&args);
            let log = text(&output);
            assert_eq!(output.status.code(), Some(1), "{args:?}: {log}");
            assert!(!log.contains("NaN") && !log.contains("panicked"), "{log}");
            let needle = if input == &huge {
                "would overflow"
            } else {
                "underflow"
            };
            assert!(log.contains(needle), "{args:?}: {log}");
        }
    }
    // At the largest magnitude allowed for 500 samples, and at the smallest peak.
    let largest = noise(d, "largest.csv", 500, 1.9e147);
    let smallest = noise(d, "smallest.csv", 500, 2.1e-70);
    let normal = noise(d, "normal.csv", 500, 1.0);
    for input in [&largest, &smallest] {
        let log = ok(&["ar", "--input", input, "--json"]);
        assert!(!log.contains("NaN") && !log.contains("null"), "{log}");
    }
    for (input, rate) in [
        (&largest, "100"),
        (&smallest, "100"),
        (&normal, "1e9"),
        (&normal, "1e-9"),
    ] {
        for kind in ["overlapping", "hadamard", "modified"] {
            let log = ok(&["allan", "--input", input, "--rate", rate, "--kind", kind]);
            assert!(!log.contains("NaN") && !log.contains("inf"), "{log}");
        }
        // JSON writes a NaN as null: every deviation and bound must be a number.
        let json: serde_json::Value =
            serde_json::from_str(&ok(&["allan", "--input", input, "--rate", rate, "--json"]))
                .unwrap();
        for key in ["tau_s", "adev", "adev_lo", "adev_hi"] {
            let all_numbers = json[key].as_array().unwrap().iter().all(|v| v.is_f64());
            assert!(all_numbers, "{key}: {json}");
        }
        let log = ok(&["davar", "--input", input, "--rate", rate, "--window", "100"]);
        assert!(!log.contains("NaN") && !log.contains("inf"), "{log}");
    }
    for rate in ["1.1e9", "9e-10", "1e308", "1e-320"] {
        for command in ["allan", "davar"] {
            let output = gyrofx(&[command, "--input", &normal, "--rate", rate]);
            let log = text(&output);
            assert_eq!(output.status.code(), Some(2), "{command} {rate}: {log}");
            assert!(
                log.contains("--rate") && log.contains("1e-9..=1e9"),
                "{log}"
            );
        }
    }
}
