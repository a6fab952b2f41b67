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

/// Runs an external tool in `cwd`; a missing tool is a failure, never a skip.
pub fn run_tool(program: &str, args: &[&str], cwd: &Path) -> (bool, String) {
    let output = Command::new(program)
        .args(args)
        .current_dir(cwd)
        .output()
        .unwrap_or_else(|e| {
            panic!("{program} must be installed (scripts/test.sh installs it): {e}")
        });
    (output.status.success(), text(&output))
}

/// Generates the default config's package with `samples` samples into `dir/pkg`.
pub fn generate_default(dir: &Path, samples: &str) -> PathBuf {
    let out = dir.join("pkg");
    ok(&[
        "generate",
        "--out",
        out.to_str().unwrap(),
        "--samples",
        samples,
    ]);
    out
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

/// Flips the lowest bit of the last field on the line of `sample` in a block's expected file,
/// and returns that field's name (from the file's header line).
pub fn flip_expected_bit(package: &Path, block: &str, sample: usize) -> String {
    let path = package.join(block).join(format!("{block}_expected.hex"));
    let content = std::fs::read_to_string(&path).unwrap();
    let mut lines: Vec<String> = content.lines().map(str::to_string).collect();
    let signal = lines[1]
        .rsplit(' ')
        .next()
        .unwrap()
        .split(':')
        .next()
        .unwrap()
        .to_string();
    let line = &mut lines[2 + sample];
    let (head, last) = line
        .rsplit_once(' ')
        .map(|(h, l)| (format!("{h} "), l.to_string()))
        .unwrap_or((String::new(), line.clone()));
    let flipped = u64::from_str_radix(&last, 16).unwrap() ^ 1;
    *line = format!("{head}{flipped:0width$x}", width = last.len());
    std::fs::write(&path, lines.join("\n") + "\n").unwrap();
    reseal(package);
    signal
}

/// Makes a package's manifest (and the marker's record of the manifest's SHA-256) describe its
/// files as they are now: after a test changed or removed a file on purpose, `gyrofx verify`
/// (which refuses a package that differs from its manifest) runs the testbenches on it, to see
/// what they make of the change.
pub fn reseal(package: &Path) {
    let manifest_path = package.join("manifest.json");
    let mut manifest: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&manifest_path).unwrap()).unwrap();
    let files = manifest["files"].as_array_mut().unwrap();
    files.retain(|f| package.join(f["path"].as_str().unwrap()).is_file());
    for entry in files.iter_mut() {
        let data = std::fs::read(package.join(entry["path"].as_str().unwrap())).unwrap();
        entry["sha256"] = hex_sha256(&data).into();
        entry["bytes"] = data.len().into();
    }
    let text = serde_json::to_string_pretty(&manifest).unwrap() + "\n";
    std::fs::write(&manifest_path, &text).unwrap();
    let marker_path = package.join(".gyrofx-package");
    let mut marker: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&marker_path).unwrap()).unwrap();
    marker["manifest_sha256"] = hex_sha256(text.as_bytes()).into();
    std::fs::write(
        &marker_path,
        serde_json::to_string_pretty(&marker).unwrap() + "\n",
    )
    .unwrap();
}

/// Like [`flip_expected_bit`], at the first sample from `from` where the last output is
/// compared: where the manifest gates it by a strobe (`only_where`), a line with the strobe 1;
/// where it gates others itself, a line where it is 1.
/// Returns the field flipped and the sample.
pub fn flip_checked_bit(package: &Path, block: &str, from: usize) -> (String, usize) {
    let manifest: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(package.join("manifest.json")).unwrap())
            .unwrap();
    let fields = manifest["blocks"][block]["expected"]["fields"]
        .as_array()
        .expect("the block's expected fields in the manifest");
    let strobe_name = fields.last().unwrap()["only_where"]
        .as_str()
        .map(|gate| gate.trim_end_matches(" = 1").to_string());
    let mut strobe = strobe_name.map(|name| {
        fields
            .iter()
            .position(|f| f["name"] == name.as_str())
            .expect("the strobe among the outputs")
    });
    // A last output that gates others (a decimator's `y_valid`) is flipped where it is 1: at a
    // 0, the flip would also expose the outputs it gates.
    let last = fields.last().unwrap()["name"].as_str().unwrap().to_string();
    if fields
        .iter()
        .any(|f| f["only_where"].as_str() == Some(&format!("{last} = 1")))
    {
        strobe = Some(fields.len() - 1);
    }
    let path = package.join(block).join(format!("{block}_expected.hex"));
    let content = std::fs::read_to_string(&path).unwrap();
    let lines: Vec<&str> = content.lines().collect();
    let sample = (from..lines.len() - 2)
        .find(|k| strobe.is_none_or(|i| lines[2 + k].split(' ').nth(i) == Some("1")))
        .expect("a compared sample");
    (flip_expected_bit(package, block, sample), sample)
}

/// The blocks of a resonator-plant package (the default's), in Makefile order.
pub const BLOCKS: [&str; 11] = [
    "sequencer",
    "estimator",
    "kf",
    "top",
    "mean_filter",
    "nco",
    "demodulator",
    "pi",
    "cic",
    "gyro_loop",
    "system",
];

/// The chain's blocks (every block but the gyro loop and the system, whose 40 000-sample
/// closed-loop testbenches take a minute or more in GHDL), as `verify --blocks` takes them: tests about the
/// chain run only these.
pub const CHAIN_BLOCKS: &str = "sequencer,estimator,kf,top,mean_filter";

/// How many blocks [`CHAIN_BLOCKS`] names.
pub const CHAIN_BLOCK_COUNT: usize = 5;

/// Every simulator `gyrofx verify` runs.
pub const SIMULATORS: [&str; 3] = ["iverilog", "verilator", "ghdl"];

/// SHA-256 through `sha256sum`, independent of the code under test.
pub fn hex_sha256(data: &[u8]) -> String {
    use std::io::Write;
    let mut child = std::process::Command::new("sha256sum")
        .stdin(std::process::Stdio::piped())
        .stdout(std::process::Stdio::piped())
        .spawn()
        .expect("sha256sum runs");
    child.stdin.take().unwrap().write_all(data).unwrap();
    let out = child.wait_with_output().unwrap();
    String::from_utf8(out.stdout)
        .unwrap()
        .split_whitespace()
        .next()
        .unwrap()
        .to_string()
}

/// `libgyrofx_capi.a` of this build. The test build writes it: `gyrofx-capi` is a
/// dev-dependency of these tests, and cargo compiles a library with every crate type it
/// declares (`staticlib` too) even as a dependency, into the profile's `deps/` folder (a
/// separate `cargo build -p gyrofx-capi` compiled the model a second time with other features).
/// A plain build's copy beside the binaries serves where that one is missing.
pub fn capi_library() -> PathBuf {
    let exe = std::env::current_exe().unwrap();
    let deps = exe.parent().unwrap();
    let profile = deps.parent().unwrap();
    let candidates = [
        deps.join("libgyrofx_capi.a"),
        profile.join("libgyrofx_capi.a"),
    ];
    candidates
        .iter()
        .find(|library| library.is_file())
        .unwrap_or_else(|| {
            panic!(
                "{} is missing: the test build makes it (cargo build -p gyrofx-capi puts it in {})",
                candidates[0].display(),
                profile.display()
            )
        })
        .clone()
}
