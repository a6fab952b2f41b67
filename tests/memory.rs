//! Bounded memory (issue 13, item 2): `generate` streams the chain through its writers, so its
//! peak RSS does not grow with `--samples`. Alone in its test binary: the peak is read with
//! `getrusage(RUSAGE_CHILDREN)`, which covers every child this process has waited for.

mod common;

use common::write_config;

/// Largest peak RSS of the waited-for children so far, KiB (Linux reports `ru_maxrss` in KiB).
fn children_peak_kib() -> i64 {
    let mut usage: libc::rusage = unsafe { std::mem::zeroed() };
    // SAFETY: `usage` is a valid, writable rusage.
    let status = unsafe { libc::getrusage(libc::RUSAGE_CHILDREN, &mut usage) };
    assert_eq!(status, 0, "getrusage");
    usage.ru_maxrss
}

#[test]
fn generate_peak_memory_does_not_grow_with_the_samples() {
    let dir = tempfile::tempdir().unwrap();
    let config = write_config(dir.path(), "rate.toml", "[plant]\nmodel = \"rate\"\n");
    let mut peaks = Vec::new();
    for samples in ["20000", "1000000"] {
        let out = dir.path().join(format!("out-{samples}"));
        let status = std::process::Command::new(env!("CARGO_BIN_EXE_gyrofx"))
            .args([
                "generate",
                "--config",
                &config,
                "--samples",
                samples,
                "--quiet",
            ])
            .arg("--out")
            .arg(&out)
            .stdout(std::process::Stdio::null())
            .status()
            .unwrap();
        assert!(status.success(), "generate --samples {samples}");
        // The high-water mark only rises: the larger run's peak is read after it.
        peaks.push(children_peak_kib());
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
