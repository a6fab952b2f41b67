//! Bounded memory (issue 13, item 2): `generate` streams the chain through its writers, so its
//! peak RSS does not grow with `--samples`. Each run's own peak is read from `wait4`'s rusage
//! for that child alone, so the other tests' children (yosys, simulators) running beside it in
//! the one test binary do not count.

use crate::common::write_config;

/// Runs `command` and returns its exit status and its own peak RSS, KiB (Linux reports
/// `ru_maxrss` in KiB).
fn run_with_peak_kib(command: &mut std::process::Command) -> (i32, i64) {
    let child = command.spawn().unwrap();
    let pid = child.id() as libc::pid_t;
    let mut status = 0;
    let mut usage: libc::rusage = unsafe { std::mem::zeroed() };
    // SAFETY: `status` and `usage` are valid and writable; `pid` is our child, reaped here and
    // never by `Child` (which is dropped without a wait).
    let waited = unsafe { libc::wait4(pid, &mut status, 0, &mut usage) };
    assert_eq!(waited, pid, "wait4");
    drop(child);
    (status, usage.ru_maxrss)
}

#[test]
fn generate_peak_memory_does_not_grow_with_the_samples() {
    let dir = tempfile::tempdir().unwrap();
    let config = write_config(dir.path(), "rate.toml", "[plant]\nmodel = \"rate\"\n");
    let mut peaks = Vec::new();
    for samples in ["20000", "1000000"] {
        let out = dir.path().join(format!("out-{samples}"));
        let (status, peak) = run_with_peak_kib(
            std::process::Command::new(env!("CARGO_BIN_EXE_gyrofx"))
                .args([
                    "generate",
                    "--config",
                    &config,
                    "--samples",
                    samples,
                    "--quiet",
                    "--out",
                    out.to_str().unwrap(),
                ])
                .stdout(std::process::Stdio::null()),
        );
        assert_eq!(
            status, 0,
            "generate --samples {samples}: wait status {status}"
        );
        peaks.push(peak);
        std::fs::remove_dir_all(&out).unwrap();
    }
    let [small, large] = [peaks[0], peaks[1]];
    // Held in memory, 1e6 samples took about 1 GB (0.93 KB per sample); streamed, the peak
    // is that of the small run plus batch buffers.
    assert!(
        large < small + 40 * 1024 && large < 150 * 1024,
        "peak RSS {small} KiB at 2e4 samples, {large} KiB at 1e6"
    );
}
