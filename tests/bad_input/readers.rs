//! Every command that reads a CSV record (allan, ar, davar, filter, generate's recording and
//! CSV stimulus) takes it by one set of rules, in bounded memory: no silent decimal comma, no
//! dropped blank line, no file without line ends held whole, no pipe read twice.

use std::path::{Path, PathBuf};

use crate::common::*;

/// The command lines that read `csv` (a file with a `rate_dps` column, and for the recording
/// `y_a_dps,y_b_dps`): a name for messages and the arguments.
fn readers(dir: &Path, csv: &Path) -> Vec<(&'static str, Vec<String>)> {
    let csv = csv.to_str().unwrap().to_string();
    let stimulus = write_config(
        dir,
        "stimulus.toml",
        &format!("[plant]\nmodel = \"rate\"\n[stimulus]\nsource = \"csv\"\ncsv_path = {csv:?}\n"),
    );
    let out = |name: &str| dir.join(name).to_str().unwrap().to_string();
    let strings = |args: &[&str]| args.iter().map(|a| a.to_string()).collect::<Vec<_>>();
    vec![
        (
            "allan",
            strings(&["allan", "--input", &csv, "--rate", "200", "--quiet"]),
        ),
        ("ar", strings(&["ar", "--input", &csv])),
        (
            "davar",
            strings(&[
                "davar", "--input", &csv, "--rate", "200", "--window", "5", "--quiet",
            ]),
        ),
        (
            "filter",
            strings(&[
                "filter",
                "--input",
                &csv,
                "--fs",
                "200",
                "--output",
                &out("filtered.csv"),
            ]),
        ),
        (
            "generate --recording",
            strings(&[
                "generate",
                "--out",
                &out("package"),
                "--recording",
                &csv,
                "--recording-rate",
                "200",
                "--samples",
                "16",
                "--quiet",
            ]),
        ),
        (
            "generate with a CSV stimulus",
            strings(&[
                "generate",
                "--out",
                &out("package"),
                "--config",
                &stimulus,
                "--samples",
                "16",
                "--quiet",
            ]),
        ),
    ]
}

/// Runs every reader on `csv`; each must fail with every needle in its message and leave no
/// output.
fn every_reader_refuses(dir: &Path, csv: &Path, needles: &[&str]) {
    for (name, args) in readers(dir, csv) {
        let args: Vec<&str> = args.iter().map(String::as_str).collect();
        let output = gyrofx(&args);
        let log = text(&output);
        assert_eq!(output.status.code(), Some(1), "{name}: {log}");
        for needle in needles {
            assert!(
                log.contains(needle),
                "{name}: expected {needle:?} in:\n{log}"
            );
        }
        assert!(
            log.lines().count() <= 3,
            "{name}: one short error, not:\n{log}"
        );
        assert!(!dir.join("filtered.csv").exists(), "{name} left its output");
        assert!(!dir.join("package").exists(), "{name} left its output");
    }
}

/// A record with a `rate_dps` column and the recording's two, `rows` rows, one cell of row
/// `odd_row` replaced by `odd_cell` (all three columns of that row).
fn record(dir: &Path, name: &str, rows: usize, odd_row: Option<(usize, &str)>) -> PathBuf {
    let mut text = String::from("t,rate_dps,y_a_dps,y_b_dps\n");
    for k in 0..rows {
        match odd_row {
            Some((row, cells)) if row == k => text.push_str(cells),
            _ => text.push_str(&format!("{k},{0}.5,{0}.25,-{0}.25\n", k % 7)),
        }
    }
    let path = dir.join(name);
    std::fs::write(&path, text).unwrap();
    path
}

/// `10,25` read as `10` was a silently wrong result: now the row's extra cell is an error
/// naming the line, with the decimal comma named.
#[test]
fn a_decimal_comma_is_refused_by_every_reader() {
    let dir = tempfile::tempdir().unwrap();
    let csv = record(dir.path(), "comma.csv", 40, Some((5, "5,10,25,3,5,-3,5\n")));
    every_reader_refuses(
        dir.path(),
        &csv,
        &[
            "comma.csv",
            "line 7 has 7 cells but the header has 4",
            "decimal comma",
        ],
    );
    let csv = record(dir.path(), "short.csv", 40, Some((3, "3,1.5,2.5\n")));
    every_reader_refuses(
        dir.path(),
        &csv,
        &["line 5 has 3 cells but the header has 4"],
    );
}

/// A blank line inside the data shifted every later sample: now it is an error where a value is
/// required and a reported gap where gaps are allowed (allan, ar, davar); trailing blank lines
/// are fine.
#[test]
fn a_blank_line_inside_the_data_is_refused_or_reported() {
    let dir = tempfile::tempdir().unwrap();
    let csv = record(dir.path(), "blank.csv", 40, Some((12, "\n")));
    for (name, args) in readers(dir.path(), &csv) {
        let args: Vec<&str> = args.iter().map(String::as_str).collect();
        let output = gyrofx(&args);
        let log = text(&output);
        if ["allan", "ar", "davar"].contains(&name) {
            assert!(output.status.success(), "{name}: {log}");
            assert!(
                log.contains("skipped 1 row"),
                "{name} must report the gap: {log}"
            );
        } else {
            assert_eq!(output.status.code(), Some(1), "{name}: {log}");
            assert!(log.contains("line 14 is blank"), "{name}: {log}");
        }
    }
    let trailing = dir.path().join("trailing.csv");
    let mut text = std::fs::read_to_string(record(dir.path(), "x.csv", 40, None)).unwrap();
    text.push_str("\n\n  \n");
    std::fs::write(&trailing, text).unwrap();
    for (name, args) in readers(dir.path(), &trailing) {
        let args: Vec<&str> = args.iter().map(String::as_str).collect();
        let log = ok(&args);
        assert!(!log.contains("skipped"), "{name}: {log}");
        let _ = std::fs::remove_file(dir.path().join("filtered.csv"));
        let _ = std::fs::remove_dir_all(dir.path().join("package"));
    }
}

/// Peak resident memory (KiB) of `gyrofx args`, with its output. Measured from a small
/// Python parent: a child's peak on Linux includes its parent's memory at the fork, which for
/// this test binary (other tests' data) would be far above gyrofx's own.
fn peak_memory_kib(args: &[&str]) -> (std::process::Output, i64) {
    let script = "import resource, subprocess, sys\n\
                  code = subprocess.run(sys.argv[1:]).returncode\n\
                  peak = resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss\n\
                  print(f'peak_kib={peak}', file=sys.stderr)\n\
                  sys.exit(code)";
    let output = std::process::Command::new("python3")
        .arg("-c")
        .arg(script)
        .arg(env!("CARGO_BIN_EXE_gyrofx"))
        .args(args)
        .output()
        .expect("python3 runs (scripts/test.sh needs it too)");
    let stderr = String::from_utf8_lossy(&output.stderr);
    let peak = stderr
        .lines()
        .find_map(|l| l.strip_prefix("peak_kib="))
        .and_then(|p| p.trim().parse().ok())
        .unwrap_or_else(|| panic!("no peak in {stderr}"));
    (output, peak)
}

/// A file without line ends was held whole (1 GB in 20 s from /dev/zero); a file of NUL bytes
/// ended up printed as "the header". Now both stop at the first line, in bounded memory, with
/// a short message; devices and pipes are refused at once.
#[test]
fn files_without_line_ends_nul_bytes_pipes_and_devices_are_refused_in_bounded_memory() {
    let dir = tempfile::tempdir().unwrap();
    let long = dir.path().join("long.csv");
    std::fs::write(&long, vec![b'7'; 96 << 20]).unwrap();
    let nul = dir.path().join("nul.csv");
    std::fs::write(&nul, vec![0u8; 8 << 20]).unwrap();
    for (path, needle) in [
        (&long, "line 1 is longer than 1048576 bytes"),
        (&nul, "line 1, byte 1 is a NUL byte"),
    ] {
        let file = path.to_str().unwrap();
        for args in [
            &["allan", "--input", file, "--rate", "200", "--quiet"][..],
            &[
                "generate",
                "--out",
                dir.path().join("p").to_str().unwrap(),
                "--recording",
                file,
                "--recording-rate",
                "200",
                "--quiet",
            ],
        ] {
            let (output, peak_kib) = peak_memory_kib(args);
            let log = text(&output);
            assert_eq!(output.status.code(), Some(1), "{args:?}: {log}");
            assert!(log.contains(needle), "{args:?}: {log}");
            assert!(
                log.len() < 600,
                "{args:?}: a short message, not {} bytes",
                log.len()
            );
            assert!(peak_kib < 64 << 10, "{args:?}: peak memory {peak_kib} KiB");
        }
    }
    for device in ["/dev/zero", "/dev/null"] {
        for args in [
            &["allan", "--input", device, "--rate", "200"][..],
            &["ar", "--input", device],
            &[
                "generate",
                "--out",
                dir.path().join("p").to_str().unwrap(),
                "--recording",
                device,
                "--recording-rate",
                "200",
            ],
            &[
                "generate",
                "--out",
                dir.path().join("p").to_str().unwrap(),
                "--config",
                device,
            ],
        ] {
            let log = fails(args);
            assert!(
                log.contains("is a character device, not a regular file"),
                "{args:?}: {log}"
            );
        }
    }
    let fifo = dir.path().join("fifo.csv");
    let path = std::ffi::CString::new(fifo.to_str().unwrap()).unwrap();
    assert_eq!(unsafe { libc::mkfifo(path.as_ptr(), 0o600) }, 0);
    let fifo = fifo.to_str().unwrap();
    for args in [
        &["allan", "--input", fifo, "--rate", "200"][..],
        &[
            "generate",
            "--out",
            dir.path().join("p").to_str().unwrap(),
            "--recording",
            fifo,
            "--recording-rate",
            "200",
        ],
    ] {
        let log = fails_within_seconds(args, 60);
        assert!(
            log.contains("is a pipe or FIFO, not a regular file"),
            "{args:?}: {log}"
        );
    }
    assert!(!dir.path().join("p").exists());
}

/// Runs gyrofx and asserts that it fails within `seconds` (a reader that opened a FIFO with no
/// writer would wait forever: it is killed and the test fails).
fn fails_within_seconds(args: &[&str], seconds: u64) -> String {
    let mut child = std::process::Command::new(env!("CARGO_BIN_EXE_gyrofx"))
        .args(args)
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    let start = std::time::Instant::now();
    while child.try_wait().unwrap().is_none() {
        if start.elapsed().as_secs() > seconds {
            let _ = child.kill();
            let _ = child.wait();
            panic!("{args:?} still runs after {seconds} s");
        }
        std::thread::sleep(std::time::Duration::from_millis(20));
    }
    let output = child.wait_with_output().unwrap();
    assert_eq!(output.status.code(), Some(1), "{args:?}: {}", text(&output));
    text(&output)
}
