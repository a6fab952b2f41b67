//! Helpers of the end-to-end tests: run the gyrofx binary, make configs and folders.
#![allow(dead_code)]

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

/// Runs the gyrofx binary with `args`.
pub fn gyrofx(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_gyrofx"))
        .args(args)
        .output()
        .expect("the gyrofx binary runs")
}

/// Stdout and stderr of `output`, together.
pub fn text(output: &Output) -> String {
    format!(
        "{}{}",
        String::from_utf8_lossy(&output.stdout),
        String::from_utf8_lossy(&output.stderr)
    )
}

/// Runs gyrofx and asserts success, returning its output text.
pub fn ok(args: &[&str]) -> String {
    let output = gyrofx(args);
    assert!(
        output.status.success(),
        "gyrofx {args:?} failed:\n{}",
        text(&output)
    );
    text(&output)
}

/// Runs gyrofx and asserts failure, returning its output text.
pub fn fails(args: &[&str]) -> String {
    let output = gyrofx(args);
    assert!(
        !output.status.success(),
        "gyrofx {args:?} should fail:\n{}",
        text(&output)
    );
    text(&output)
}

/// Writes `toml` to `dir/name` and returns its path as a string.
pub fn write_config(dir: &Path, name: &str, toml: &str) -> String {
    let path = dir.join(name);
    std::fs::write(&path, toml).unwrap();
    path.to_string_lossy().into_owned()
}

/// Every file below `root`, relative, sorted.
pub fn files_below(root: &Path) -> Vec<PathBuf> {
    let mut out = Vec::new();
    let mut stack = vec![root.to_path_buf()];
    while let Some(dir) = stack.pop() {
        for entry in std::fs::read_dir(&dir).unwrap() {
            let path = entry.unwrap().path();
            if path.is_dir() {
                stack.push(path);
            } else {
                out.push(path.strip_prefix(root).unwrap().to_path_buf());
            }
        }
    }
    out.sort();
    out
}

/// Flips the lowest bit of the `rate_out` field on the line of `sample` in an expected file.
pub fn flip_expected_bit(package: &Path, sample: usize) {
    let path = package.join("kf/kf_expected.hex");
    let content = std::fs::read_to_string(&path).unwrap();
    let mut lines: Vec<String> = content.lines().map(str::to_string).collect();
    let line = &mut lines[2 + sample];
    let (valid, rate) = line.split_once(' ').unwrap();
    assert_eq!(valid, "1", "sample {sample} must be a valid output");
    let flipped = u64::from_str_radix(rate, 16).unwrap() ^ 1;
    *line = format!("{valid} {flipped:0width$x}", width = rate.len());
    std::fs::write(&path, lines.join("\n") + "\n").unwrap();
}
