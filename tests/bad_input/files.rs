//! Files and processes: no lost user file, no leftovers, no orphaned children, and `verify`
//! checks what it is given.

use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

use crate::common::*;

/// A small recording for `filter`: `rows` rates in the column `rate_dps`.
fn recording(dir: &Path, rows: usize) -> PathBuf {
    let input = dir.join("in.csv");
    let body: String = (0..rows)
        .map(|k| format!("{k},{}\n", (k % 100) as f64 * 0.1))
        .collect();
    std::fs::write(&input, format!("t,rate_dps\n{body}")).unwrap();
    input
}

/// The pid of a process that has ended (a `true` that was waited for).
fn dead_pid() -> u32 {
    let mut child = Command::new("true").spawn().unwrap();
    let pid = child.id();
    child.wait().unwrap();
    pid
}

/// Names in `dir`, sorted.
fn names_in(dir: &Path) -> Vec<String> {
    let mut names: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    names
}

#[test]
fn an_output_is_never_one_of_the_commands_inputs() {
    let dir = tempfile::tempdir().unwrap();
    let input = recording(dir.path(), 50);
    let config = write_config(dir.path(), "mine.toml", "seed = 7\n");
    let before = std::fs::read(&config).unwrap();
    let output = gyrofx(&[
        "filter",
        "--input",
        input.to_str().unwrap(),
        "--fs",
        "100",
        "--config",
        &config,
        "--output",
        &config,
    ]);
    let log = text(&output);
    assert_eq!(output.status.code(), Some(2), "{log}");
    assert!(
        log.contains("--output") && log.contains("--config") && log.contains("mine.toml"),
        "{log}"
    );
    assert_eq!(std::fs::read(&config).unwrap(), before);
    // A folder that holds the config, even with --force.
    let output = gyrofx(&[
        "generate",
        "--out",
        dir.path().to_str().unwrap(),
        "--config",
        &config,
        "--samples",
        "100",
        "--force",
    ]);
    let log = text(&output);
    assert_eq!(output.status.code(), Some(2), "{log}");
    assert!(log.contains("--out") && log.contains("--config"), "{log}");
    assert_eq!(std::fs::read(&config).unwrap(), before);
    // filter --vectors onto the folder of its --input.
    let output = gyrofx(&[
        "filter",
        "--input",
        input.to_str().unwrap(),
        "--fs",
        "100",
        "--output",
        dir.path().join("f.csv").to_str().unwrap(),
        "--vectors",
        dir.path().to_str().unwrap(),
        "--force",
    ]);
    let log = text(&output);
    assert_eq!(output.status.code(), Some(2), "{log}");
    assert!(
        log.contains("--vectors") && log.contains("--input"),
        "{log}"
    );
    assert!(input.is_file() && !dir.path().join("f.csv").exists());
}

#[test]
fn an_edited_manifest_counts_as_a_changed_file() {
    let dir = tempfile::tempdir().unwrap();
    let out = generate_default(dir.path(), "100");
    let manifest = out.join("manifest.json");
    let mut edited = std::fs::read_to_string(&manifest).unwrap();
    edited.push('\n');
    std::fs::write(&manifest, &edited).unwrap();
    let log = fails(&[
        "generate",
        "--out",
        out.to_str().unwrap(),
        "--samples",
        "100",
    ]);
    assert!(
        log.contains("changed since gyrofx wrote them") && log.contains("manifest.json"),
        "{log}"
    );
    assert_eq!(std::fs::read_to_string(&manifest).unwrap(), edited);
}

#[cfg(unix)]
#[test]
fn an_existing_empty_folder_keeps_its_mode() {
    use std::os::unix::fs::PermissionsExt;
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("private");
    std::fs::create_dir(&out).unwrap();
    std::fs::set_permissions(&out, std::fs::Permissions::from_mode(0o700)).unwrap();
    ok(&[
        "generate",
        "--out",
        out.to_str().unwrap(),
        "--samples",
        "100",
    ]);
    let mode = std::fs::metadata(&out).unwrap().permissions().mode() & 0o7777;
    assert_eq!(mode, 0o700, "mode {mode:o}");
    // Replacing the package keeps it too.
    ok(&[
        "generate",
        "--out",
        out.to_str().unwrap(),
        "--samples",
        "110",
    ]);
    let mode = std::fs::metadata(&out).unwrap().permissions().mode() & 0o7777;
    assert_eq!(mode, 0o700, "mode {mode:o}");
}

#[test]
fn root_home_and_current_folders_are_refused_before_any_work() {
    let dir = tempfile::tempdir().unwrap();
    let home = dir.path().join("home");
    let work = home.join("a/work");
    std::fs::create_dir_all(&work).unwrap();
    std::fs::write(work.join("notes.txt"), "keep me").unwrap();
    for (out, needle) in [
        ("/", "filesystem root"),
        (".", "current folder"),
        ("..", "current folder"),
        (home.to_str().unwrap(), "home folder"),
    ] {
        let start = Instant::now();
        let output = Command::new(env!("CARGO_BIN_EXE_gyrofx"))
            .args(["generate", "--out", out, "--samples", "100", "--force"])
            .current_dir(&work)
            .env("HOME", &home)
            .output()
            .unwrap();
        let log = text(&output);
        assert_eq!(output.status.code(), Some(2), "--out {out}: {log}");
        assert!(
            log.contains("--out") && log.contains(needle),
            "--out {out}: {log}"
        );
        assert!(start.elapsed() < Duration::from_secs(10), "--out {out}");
        assert_eq!(names_in(&work), ["notes.txt"], "--out {out}");
        assert_eq!(names_in(&home), ["a"], "--out {out}");
    }
}

/// Spawns gyrofx with `args`, `envs`, its output discarded.
fn spawn(args: &[&str], envs: &[(&str, &Path)]) -> Child {
    let mut command = Command::new(env!("CARGO_BIN_EXE_gyrofx"));
    command
        .args(args)
        .stdout(Stdio::null())
        .stderr(Stdio::piped());
    for (key, value) in envs {
        command.env(key, value);
    }
    command.spawn().unwrap()
}

/// Waits (up to 60 s) until `ready` holds.
fn wait_until(what: &str, mut ready: impl FnMut() -> bool) {
    let start = Instant::now();
    while !ready() {
        assert!(
            start.elapsed() < Duration::from_secs(60),
            "waited for {what}"
        );
        std::thread::sleep(Duration::from_millis(20));
    }
}

#[test]
fn a_second_run_into_the_same_folder_fails_at_once() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("pkg");
    let mut first = Command::new(env!("CARGO_BIN_EXE_gyrofx"))
        .args([
            "generate",
            "--out",
            out.to_str().unwrap(),
            "--samples",
            "100",
        ])
        .env("GYROFX_TEST_HOLD_STAGING_MS", "4000")
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .unwrap();
    let staging = || {
        names_in(dir.path())
            .iter()
            .any(|n| n.starts_with(".gyrofx-staging-"))
    };
    wait_until("the first run's staging folder", staging);
    let start = Instant::now();
    let log = fails(&[
        "generate",
        "--out",
        out.to_str().unwrap(),
        "--samples",
        "100",
    ]);
    assert!(start.elapsed() < Duration::from_secs(5), "{log}");
    assert!(
        log.contains(&format!("another gyrofx (pid {}) is writing", first.id())),
        "{log}"
    );
    assert!(first.wait().unwrap().success());
    // A lock whose process is gone is taken over.
    std::fs::write(dir.path().join(".gyrofx-lock-pkg"), dead_pid().to_string()).unwrap();
    ok(&[
        "generate",
        "--out",
        out.to_str().unwrap(),
        "--samples",
        "100",
    ]);
    assert_eq!(names_in(dir.path()), ["pkg"]);
}

/// The pids of every descendant of `pid` (from /proc's parent links).
fn descendants(pid: u32) -> Vec<u32> {
    let mut parents = Vec::new();
    for entry in std::fs::read_dir("/proc").unwrap().flatten() {
        let Ok(child) = entry.file_name().to_string_lossy().parse::<u32>() else {
            continue;
        };
        let Ok(stat) = std::fs::read_to_string(entry.path().join("stat")) else {
            continue;
        };
        // pid (comm) state ppid ...: comm may hold spaces, so split after its ')'.
        let Some(parent) = stat
            .rsplit_once(')')
            .and_then(|(_, rest)| rest.split_whitespace().nth(1))
            .and_then(|p| p.parse::<u32>().ok())
        else {
            continue;
        };
        parents.push((child, parent));
    }
    let mut found = vec![pid];
    let mut k = 0;
    while k < found.len() {
        let parent = found[k];
        found.extend(
            parents
                .iter()
                .filter(|(_, p)| *p == parent)
                .map(|(c, _)| *c),
        );
        k += 1;
    }
    found.remove(0);
    found
}

/// Whether `pid` runs (exists and is not a zombie).
fn alive(pid: u32) -> bool {
    std::fs::read_to_string(format!("/proc/{pid}/stat")).is_ok_and(|stat| {
        stat.rsplit_once(')')
            .and_then(|(_, rest)| rest.split_whitespace().next())
            .is_some_and(|state| state != "Z" && state != "X")
    })
}

/// Runs gyrofx with `args` (TMPDIR private), sends `signal` once it has started a child, and
/// checks that it ends with every child and leaves nothing in `dir` but `keep` nor in TMPDIR.
fn signal_ends_the_children(dir: &Path, args: &[&str], signal: i32, keep: &[&str]) {
    let temp = dir.join("tmp");
    std::fs::create_dir(&temp).unwrap();
    let mut gyrofx = spawn(args, &[("TMPDIR", &temp)]);
    let pid = gyrofx.id();
    let mut children = Vec::new();
    wait_until("a child of gyrofx", || {
        children = descendants(pid);
        !children.is_empty() || gyrofx.try_wait().unwrap().is_some()
    });
    assert!(gyrofx.try_wait().unwrap().is_none(), "{args:?} ended early");
    // Those it starts in the next moments count too.
    std::thread::sleep(Duration::from_millis(300));
    children = descendants(pid);
    unsafe { libc::kill(pid as i32, signal) };
    let status = gyrofx.wait().unwrap();
    assert_eq!(status.code(), Some(130), "{args:?}");
    std::thread::sleep(Duration::from_millis(100));
    let survivors: Vec<u32> = children.into_iter().filter(|c| alive(*c)).collect();
    assert!(
        survivors.is_empty(),
        "{args:?}: children survived: {survivors:?}"
    );
    let mut left = names_in(dir);
    left.retain(|n| n != "tmp" && !keep.contains(&n.as_str()));
    assert!(left.is_empty(), "{args:?} left {left:?}");
    assert!(
        names_in(&temp).is_empty(),
        "{args:?} left {:?}",
        names_in(&temp)
    );
}

#[cfg(unix)]
#[test]
fn a_signal_to_verify_ends_make_and_the_simulator() {
    let dir = tempfile::tempdir().unwrap();
    let pkg = generate_default(dir.path(), "100");
    signal_ends_the_children(
        dir.path(),
        &[
            "verify",
            "--out",
            pkg.to_str().unwrap(),
            "--blocks",
            "gyro_loop,system",
            "--quiet",
        ],
        libc::SIGTERM,
        &["pkg"],
    );
}

#[cfg(unix)]
#[test]
fn a_signal_to_synth_ends_yosys_and_removes_its_work_folder() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("synth");
    signal_ends_the_children(
        dir.path(),
        &["synth", "--out", out.to_str().unwrap(), "--quiet"],
        libc::SIGINT,
        &[],
    );
}

#[test]
fn later_runs_remove_what_killed_runs_left() {
    let dir = tempfile::tempdir().unwrap();
    let input = recording(dir.path(), 50);
    let gone = dead_pid();
    let stale_file = format!(".gyrofx-filter-{gone}-abc123.csv");
    let stale_staging = format!(".gyrofx-staging-{gone}-0001");
    std::fs::write(dir.path().join(&stale_file), "partial").unwrap();
    std::fs::create_dir(dir.path().join(&stale_staging)).unwrap();
    // A live process's temporary file is not touched.
    let live = format!(".gyrofx-filter-{}-abc123.csv", std::process::id());
    std::fs::write(dir.path().join(&live), "in use").unwrap();
    ok(&[
        "filter",
        "--input",
        input.to_str().unwrap(),
        "--fs",
        "100",
        "--output",
        dir.path().join("out.csv").to_str().unwrap(),
    ]);
    assert_eq!(names_in(dir.path()), [live.as_str(), "in.csv", "out.csv"]);
}

#[test]
fn a_refused_generate_leaves_no_parent_folders() {
    let dir = tempfile::tempdir().unwrap();
    let config = write_config(
        dir.path(),
        "fast.toml",
        "[plant]\nmodel = \"rate\"\n[stimulus]\nscenario = \"constant\"\nrate_dps = 600.0\n",
    );
    let out = dir.path().join("a/b/pkg");
    let log = fails(&[
        "generate",
        "--out",
        out.to_str().unwrap(),
        "--config",
        &config,
        "--samples",
        "400",
        "--strict",
    ]);
    assert!(log.contains("--strict"), "{log}");
    assert_eq!(names_in(dir.path()), ["fast.toml"]);
}

#[test]
fn verify_checks_the_package_against_its_manifest() {
    let dir = tempfile::tempdir().unwrap();
    let pkg = generate_default(dir.path(), "100");
    let params = pkg.join("kf/kf_params.vh");
    let params_text = std::fs::read_to_string(&params).unwrap();
    let line = params_text
        .lines()
        .find(|l| l.contains("VECTOR_COUNT ="))
        .unwrap()
        .to_string();
    std::fs::write(
        &params,
        params_text.replace(&line, "localparam integer VECTOR_COUNT = 10;"),
    )
    .unwrap();
    let manifest = pkg.join("manifest.json");
    let edited = std::fs::read_to_string(&manifest)
        .unwrap()
        .replace("\"seed\": ", "\"seed\":  ");
    std::fs::write(&manifest, edited).unwrap();
    let output = gyrofx(&[
        "verify",
        "--out",
        pkg.to_str().unwrap(),
        "--blocks",
        "kf",
        "--quiet",
    ]);
    let log = text(&output);
    assert_eq!(output.status.code(), Some(1), "{log}");
    assert!(!log.contains("PASS"), "{log}");
    assert!(
        log.contains("kf/kf_params.vh") && log.contains("manifest.json"),
        "{log}"
    );
    assert!(log.contains("VECTOR_COUNT"), "{log}");
    // A missing file is named too.
    std::fs::remove_file(pkg.join("kf/kf_expected.hex")).unwrap();
    let log = fails(&[
        "verify",
        "--out",
        pkg.to_str().unwrap(),
        "--blocks",
        "kf",
        "--quiet",
    ]);
    assert!(
        log.contains("kf/kf_expected.hex") && log.contains("missing"),
        "{log}"
    );
}
