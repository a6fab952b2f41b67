//! Output folders are owned (issue 13, item 1): gyrofx replaces an `--out` folder only when it
//! is empty or a package of the same command holding nothing but the files its manifest lists,
//! unchanged, and the build outputs its marker allows; `--force` overrides. Every refusal is
//! checked by hashing the user's folder before and after. Staging folders are removed on
//! SIGINT and SIGTERM and, when a killed run left them, by the next run.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::{Duration, Instant};

use crate::common::{fails, gyrofx, ok, text, write_config};
use sha2::{Digest, Sha256};

/// A small, fast package: the rate-level plant, 400 samples.
fn generate(dir: &Path, out: &Path, extra: &[&str]) -> std::process::Output {
    let config = write_config(dir, "rate.toml", "[plant]\nmodel = \"rate\"\n");
    let mut args = vec![
        "generate",
        "--config",
        &config,
        "--samples",
        "400",
        "--out",
        out.to_str().unwrap(),
    ];
    args.extend_from_slice(extra);
    gyrofx(&args)
}

/// Every file below `root` (relative path) with the SHA-256 of its content.
fn hashes(root: &Path) -> BTreeMap<PathBuf, String> {
    let mut out = BTreeMap::new();
    let mut pending = vec![root.to_path_buf()];
    while let Some(folder) = pending.pop() {
        for entry in std::fs::read_dir(&folder).unwrap() {
            let path = entry.unwrap().path();
            if path.is_dir() {
                pending.push(path);
            } else {
                let digest = Sha256::digest(std::fs::read(&path).unwrap());
                out.insert(
                    path.strip_prefix(root).unwrap().to_path_buf(),
                    format!("{digest:x}"),
                );
            }
        }
    }
    out
}

/// Names in `dir` that start with `.gyrofx-`.
fn leftovers(dir: &Path) -> Vec<String> {
    std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|n| n.starts_with(".gyrofx-"))
        .collect()
}

/// Waits (at most a minute) until a staging folder exists in `dir`.
fn wait_for_staging(dir: &Path) {
    let start = Instant::now();
    while !leftovers(dir)
        .iter()
        .any(|n| n.starts_with(".gyrofx-staging-"))
    {
        assert!(
            start.elapsed() < Duration::from_secs(60),
            "no staging folder appeared"
        );
        std::thread::sleep(Duration::from_millis(20));
    }
}

#[test]
fn a_package_is_replaced_only_when_it_holds_nothing_but_its_own_unchanged_files() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("pkg");
    let first = generate(dir.path(), &out, &[]);
    assert!(first.status.success(), "{}", text(&first));
    assert!(out.join(".gyrofx-package").is_file());

    // The simulators' work files, as the package's Makefile writes them, do not block a
    // regeneration.
    std::fs::create_dir_all(out.join("kf/obj_verilator")).unwrap();
    std::fs::write(out.join("kf/obj_verilator/Vtb_gyrofx_kf.o"), "obj").unwrap();
    std::fs::write(out.join("kf/tb_gyrofx_kf.vvp"), "vvp").unwrap();
    std::fs::create_dir_all(out.join("top/ghdl_work")).unwrap();
    let again = generate(dir.path(), &out, &[]);
    assert!(again.status.success(), "{}", text(&again));
    assert!(
        !out.join("kf/tb_gyrofx_kf.vvp").exists(),
        "replaced as a whole"
    );

    // A user's file inside the package: refused, named, nothing changed.
    std::fs::write(out.join("kf/my_notes.txt"), "mine").unwrap();
    let before = hashes(&out);
    let refused = generate(dir.path(), &out, &["--seed", "7"]);
    let log = text(&refused);
    assert!(!refused.status.success(), "{log}");
    assert!(
        log.contains("files gyrofx did not write: kf/my_notes.txt") && log.contains("--force"),
        "{log}"
    );
    assert_eq!(hashes(&out), before);

    // A generated file the user edited: refused as changed.
    std::fs::remove_file(out.join("kf/my_notes.txt")).unwrap();
    let csv = out.join("kf/kf_vectors.csv");
    let mut edited = std::fs::read(&csv).unwrap();
    let last = edited.len() - 2;
    edited[last] ^= 1;
    std::fs::write(&csv, &edited).unwrap();
    let before = hashes(&out);
    let log = text(&generate(dir.path(), &out, &[]));
    assert!(
        log.contains("files changed since gyrofx wrote them: kf/kf_vectors.csv"),
        "{log}"
    );
    assert_eq!(hashes(&out), before);

    // --force replaces it anyway.
    let forced = generate(dir.path(), &out, &["--force"]);
    assert!(forced.status.success(), "{}", text(&forced));
    assert_ne!(std::fs::read(&csv).unwrap(), edited);
    assert!(
        leftovers(dir.path()).is_empty(),
        "{:?}",
        leftovers(dir.path())
    );
}

#[test]
fn a_foreign_folder_or_another_kind_of_package_is_refused_untouched() {
    let dir = tempfile::tempdir().unwrap();

    // A user's folder that happens to hold a manifest.json.
    let user = dir.path().join("mine");
    std::fs::create_dir_all(user.join("sub")).unwrap();
    std::fs::write(user.join("manifest.json"), "{\"files\": []}").unwrap();
    std::fs::write(user.join("sub/data.csv"), "1,2,3\n").unwrap();
    let before = hashes(&user);
    let log = text(&generate(dir.path(), &user, &[]));
    assert!(log.contains("not a gyrofx output"), "{log}");
    assert!(
        log.contains("manifest.json") && log.contains("sub/data.csv"),
        "{log}"
    );
    assert_eq!(hashes(&user), before);

    // A file where the folder should be.
    let file = dir.path().join("file");
    std::fs::write(&file, "x").unwrap();
    let log = text(&generate(dir.path(), &file, &[]));
    assert!(log.contains("is not a folder"), "{log}");
    assert_eq!(std::fs::read(&file).unwrap(), b"x");

    // synth and reproduce onto a generate package: refused before any work starts.
    let package = dir.path().join("pkg");
    assert!(generate(dir.path(), &package, &[]).status.success());
    let before = hashes(&package);
    let log = fails(&["synth", "--out", package.to_str().unwrap()]);
    assert!(
        log.contains("holds a `gyrofx generate` package, which `gyrofx synth` does not replace"),
        "{log}"
    );
    let log = fails(&[
        "reproduce",
        "--paper",
        "003",
        "--out",
        package.to_str().unwrap(),
    ]);
    assert!(log.contains("`gyrofx reproduce` does not replace"), "{log}");
    assert_eq!(hashes(&package), before);

    // --force needs --out on reproduce.
    let log = fails(&["reproduce", "--paper", "003", "--force"]);
    assert!(log.contains("--out"), "{log}");

    // An empty folder is used.
    let empty = dir.path().join("empty");
    std::fs::create_dir(&empty).unwrap();
    assert!(generate(dir.path(), &empty, &[]).status.success());
    assert!(leftovers(dir.path()).is_empty());
}

#[test]
fn stale_staging_folders_of_a_killed_run_are_removed_by_the_next_run() {
    let dir = tempfile::tempdir().unwrap();
    // A process id above Linux's largest (2^22): its process cannot exist.
    let stale = dir.path().join(".gyrofx-staging-4194999-abcdef");
    std::fs::create_dir_all(stale.join("kf")).unwrap();
    std::fs::write(stale.join("kf/kf_vectors.csv"), "half-written").unwrap();
    let old = dir.path().join(".gyrofx-old-4194999-pkg");
    std::fs::create_dir_all(&old).unwrap();
    // Named like one but without a process id, and recent: left alone.
    let lookalike = dir.path().join(".gyrofx-staging-mine");
    std::fs::create_dir_all(&lookalike).unwrap();

    let out = dir.path().join("pkg");
    assert!(generate(dir.path(), &out, &[]).status.success());
    assert!(!stale.exists() && !old.exists());
    assert!(lookalike.exists());
}

/// Starts a generate whose staging folder is held for 20 s, waits until it exists, sends
/// `signal` and returns the exit code; asserts that nothing is left behind.
fn interrupt(signal: &str) -> Option<i32> {
    let dir = tempfile::tempdir().unwrap();
    let config = write_config(dir.path(), "rate.toml", "[plant]\nmodel = \"rate\"\n");
    let out = dir.path().join("pkg");
    let mut child = Command::new(env!("CARGO_BIN_EXE_gyrofx"))
        .args([
            "generate",
            "--config",
            &config,
            "--samples",
            "400",
            "--out",
            out.to_str().unwrap(),
        ])
        .env("GYROFX_TEST_HOLD_STAGING_MS", "20000")
        .stdout(std::process::Stdio::null())
        .stderr(std::process::Stdio::null())
        .spawn()
        .unwrap();
    wait_for_staging(dir.path());
    let status = Command::new("kill")
        .args([signal, &child.id().to_string()])
        .status()
        .unwrap();
    assert!(status.success());
    let code = child.wait().unwrap().code();
    assert!(
        leftovers(dir.path()).is_empty(),
        "{signal}: {:?}",
        leftovers(dir.path())
    );
    assert!(!out.exists(), "{signal}: no partial output");
    code
}

/// The output folder is checked again when the run ends: a file a user put into the old
/// package while `generate` ran is kept, the new package is not moved in (exit 1), and the
/// staging folder is gone.
#[test]
fn a_package_changed_during_the_run_is_not_replaced() {
    let dir = tempfile::tempdir().unwrap();
    let config = write_config(dir.path(), "rate.toml", "[plant]\nmodel = \"rate\"\n");
    let out = dir.path().join("pkg");
    assert!(generate(dir.path(), &out, &[]).status.success());
    let child = Command::new(env!("CARGO_BIN_EXE_gyrofx"))
        .args(["generate", "--config", &config, "--samples", "400", "--out"])
        .arg(&out)
        .env("GYROFX_TEST_HOLD_STAGING_MS", "3000")
        .stdout(std::process::Stdio::null())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    wait_for_staging(dir.path());
    std::fs::write(out.join("notes.txt"), "mine").unwrap();
    let before = hashes(&out);
    let output = child.wait_with_output().unwrap();
    assert_eq!(output.status.code(), Some(1));
    assert!(text(&output).contains("notes.txt"), "{}", text(&output));
    assert_eq!(hashes(&out), before, "the user's folder is untouched");
    assert!(
        leftovers(dir.path()).is_empty(),
        "{:?}",
        leftovers(dir.path())
    );
}

#[test]
fn sigint_and_sigterm_remove_the_staging_folder() {
    assert_eq!(interrupt("-INT"), Some(130));
    assert_eq!(interrupt("-TERM"), Some(130));
}

#[test]
fn the_force_flag_is_documented_on_every_writing_command() {
    for command in ["generate", "synth", "reproduce"] {
        let help = ok(&[command, "--help"]);
        assert!(help.contains("--force"), "{command}: {help}");
    }
}

/// A package verified in GHDL, then moved, verifies again: the Makefile analyses into a fresh
/// GHDL work library each time, so a library that names the old paths cannot go stale.
#[test]
fn a_moved_package_verifies_in_ghdl() {
    let dir = tempfile::tempdir().unwrap();
    let first = dir.path().join("first");
    assert!(generate(dir.path(), &first, &[]).status.success());
    let log = ok(&[
        "verify",
        "--out",
        first.to_str().unwrap(),
        "--sim",
        "ghdl",
        "--blocks",
        "kf",
    ]);
    assert!(log.contains("ghdl: passed"), "{log}");
    let moved = dir.path().join("moved");
    std::fs::rename(&first, &moved).unwrap();
    let log = ok(&[
        "verify",
        "--out",
        moved.to_str().unwrap(),
        "--sim",
        "ghdl",
        "--blocks",
        "kf",
    ]);
    assert!(log.contains("ghdl: passed"), "{log}");
}

/// `generate --blocks` writes only the named blocks' folders and Makefile targets, `--no-csv`
/// leaves out the CSV twins, and the package still verifies; an unknown block is a usage error
/// that writes nothing.
#[test]
fn generate_writes_only_the_blocks_asked_for() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("pkg");
    let output = generate(dir.path(), &out, &["--blocks", "kf,top", "--no-csv"]);
    assert!(output.status.success(), "{}", text(&output));
    for block in ["sequencer", "estimator", "mean_filter", "gyro_loop"] {
        assert!(!out.join(block).exists(), "{block}");
    }
    assert!(out.join("kf/kf_expected.hex").is_file());
    assert!(!out.join("kf/kf_vectors.csv").exists());
    let makefile = std::fs::read_to_string(out.join("Makefile")).unwrap();
    assert!(
        makefile.contains("sim-iverilog: iverilog-kf iverilog-top\n"),
        "{makefile}"
    );
    let log = ok(&["verify", "--out", out.to_str().unwrap()]);
    assert_eq!(log.matches("PASS n=").count(), 2, "{log}");

    let other = dir.path().join("other");
    let output = generate(dir.path(), &other, &["--blocks", "kf,foo"]);
    assert_eq!(output.status.code(), Some(2));
    assert!(text(&output).contains("--blocks foo: no such block"));
    assert!(!other.exists());
}

/// Progress: on a terminal `verify` shows a bar with percent and ETA, `--quiet` hides it, and
/// with stderr not a terminal nothing extra is printed. The terminal is `script`'s
/// pseudo-terminal (util-linux, on every Debian).
#[test]
fn verify_shows_progress_only_on_a_terminal() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("pkg");
    assert!(generate(dir.path(), &out, &["--blocks", "kf"])
        .status
        .success());
    let command = |quiet: &str| {
        format!(
            "{} verify --out {} {quiet}",
            env!("CARGO_BIN_EXE_gyrofx"),
            out.display()
        )
    };
    let on_terminal = |quiet: &str| {
        let output = Command::new("script")
            .args(["-qec", &command(quiet), "/dev/null"])
            .output()
            .expect("script (util-linux) runs");
        assert!(output.status.success(), "{}", text(&output));
        text(&output)
    };
    let shown = on_terminal("");
    assert!(shown.contains("100%") && shown.contains("ETA"), "{shown}");
    let hidden = on_terminal("--quiet");
    assert!(
        !hidden.contains("ETA") && hidden.contains("PASS n="),
        "{hidden}"
    );
    let piped = ok(&["verify", "--out", out.to_str().unwrap()]);
    assert!(!piped.contains("ETA") && !piped.contains('\r'), "{piped}");
}
