//! The chain run with every registered block's builder: what each block's vectors cover, and
//! streamed files equal to the kept rows.

use super::mean_filter::GROSS_ERROR_PERIOD;
use super::{vector_builders, RomImages, Streaming};
use crate::progress::Progress;
use crate::text::Provenance;
use crate::vectors::{run, Run};
use gyrofx_job::config::Config;
use gyrofx_job::job::Job;
use gyrofx_model::kf::FixedKf;

/// The embedded config with 4000 samples, changed by `edit`, run.
fn run_embedded(edit: impl FnOnce(&mut Config)) -> (Job, Run) {
    let mut config = Config::embedded();
    config.samples = 4000;
    edit(&mut config);
    let job = Job::new(config).unwrap();
    let provenance = Provenance::for_tests();
    let progress = Progress::default();
    let roms = RomImages::new(&job, &provenance);
    let builders = vector_builders(&job, &roms, None).unwrap();
    let run = run(&job, builders, &progress).unwrap();
    let (done, total) = progress.counts();
    assert!(done <= total && total > 0, "{done} of {total}");
    (job, run)
}

/// The run's block called `name`.
fn named<'a>(run: &'a Run, name: &str) -> &'a crate::block::Block {
    run.blocks
        .iter()
        .find(|b| b.name == name)
        .unwrap_or_else(|| panic!("no {name} block in the run"))
}

/// Streamed rows give the bytes the kept rows give (one formatter), the entries name
/// the files' real SHA-256 and size, a left-out block writes nothing, and without the CSV
/// only the hex files are written.
#[test]
fn streamed_vector_files_equal_the_kept_rows() {
    let (job, kept) = run_embedded(|config| config.plant.model = "rate".into());
    let provenance = Provenance::for_tests();
    let roms = RomImages::new(&job, &provenance);
    for (csv, selected) in [(true, None), (false, Some(vec!["kf".to_string()]))] {
        let root = tempfile::tempdir().unwrap();
        let streaming = Streaming {
            root: root.path(),
            csv,
            blocks: selected.as_deref(),
            provenance: &provenance,
        };
        let builders = vector_builders(&job, &roms, Some(streaming)).unwrap();
        let streamed = run(&job, builders, &Progress::default()).unwrap();
        assert_eq!(streamed.samples, kept.samples);
        for (s, k) in streamed.blocks.iter().zip(&kept.blocks) {
            assert_eq!((s.name, s.len()), (k.name, k.len()));
            let wanted = selected
                .as_ref()
                .is_none_or(|names| names.iter().any(|n| n == s.name));
            if !wanted {
                assert!(s.written().is_empty());
                assert!(!root.path().join(s.name).exists(), "{}", s.name);
                continue;
            }
            let (stimulus, expected) = crate::writers::vector_hex(k, &provenance);
            let mut want = vec![stimulus, expected];
            if csv {
                want.push(crate::writers::vector_csv(k, &provenance));
            }
            assert_eq!(s.written().len(), want.len(), "{}", s.name);
            for (entry, text) in s.written().iter().zip(&want) {
                let bytes = std::fs::read(root.path().join(&entry.path)).unwrap();
                assert!(bytes == text.as_bytes(), "{} differs", entry.path);
                assert_eq!(entry.bytes, bytes.len());
                assert_eq!(entry.sha256, gyrofx_job::hash::sha256_hex(&bytes));
            }
        }
        assert_eq!(streamed.report, kept.report);
    }
}

#[test]
fn the_default_run_fills_every_block_and_stays_within_the_bounds() {
    let (job, run) = run_embedded(|_| {});
    let names: Vec<&str> = run.blocks.iter().map(|b| b.name).collect();
    assert_eq!(
        names,
        [
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
            "system"
        ]
    );
    // The system's run: both loops lock during the start-up, the chain then steps once
    // per decimated output, both gyros switch, and the estimator produces estimates.
    let system = super::system::recorded(&run).expect("a resonator package records the system");
    assert_eq!(named(&run, "system").len(), system.samples);
    let lock = system.first_lock_sample.expect("both loops lock");
    assert!(lock < system.startup_samples, "{system:?}");
    assert_eq!(
        system.chain_samples,
        (system.samples - system.startup_samples) / 1000
    );
    assert!(system.switches.iter().all(|s| *s >= 4), "{system:?}");
    let estimate = system.first_estimate_sample.expect("an estimate");
    assert!(estimate > system.startup_samples && system.outputs > 0);
    assert!(system.outputs <= system.chain_samples);
    // The loop's recorded window covers lock acquisition in normal mode, the switch and
    // the re-lock in reverse mode, with a decimated output every 1000 samples.
    let record = super::gyro_loop::recorded(&run).expect("the loop's record");
    let [normal, reverse] = record.first_lock_sample;
    let normal = normal.expect("the loop locks in normal mode");
    let reverse = reverse.expect("the loop re-locks in reverse mode");
    assert!(normal < record.switch_sample && reverse > record.switch_sample);
    assert!(reverse < record.samples);
    assert_eq!(record.outputs, record.samples / 1000);
    assert_eq!(named(&run, "gyro_loop").len(), record.samples);
    // One row per sample plus the reset, in every chain block.
    for b in ["sequencer", "estimator", "top"].map(|name| named(&run, name)) {
        assert_eq!(b.len(), 4001, "{}", b.name);
    }
    for name in ["kf", "chain", "bias"] {
        let stats = run.stats(name).expect(name);
        assert!(stats.max_lsb <= stats.bound_lsb, "{name}: {stats:?}");
    }
    // Each tie input really is a tie from reset, for x1 and the output.
    let kf = FixedKf::new(job.kf());
    for tie in &super::kf::tie_cases(&run).expect("tie cases") {
        assert!(kf.ties(tie.x1.expect("x1 tie"), tie.bw_sel)[0]);
        assert!(kf.ties(tie.rate_hat.expect("output tie"), tie.bw_sel)[2]);
    }
    // Every bw_sel value occurs in the top vectors.
    let top = named(&run, "top");
    let sels: std::collections::BTreeSet<i64> = (0..top.len()).map(|k| top.row(k)[1]).collect();
    assert_eq!(sels.len(), 3);
}

/// The mean filter's vectors: one output per block of 20, kept counts from 0 (every
/// sample rejected) to 20, the gross errors rejected, and fixed within the bound of float.
#[test]
fn the_mean_filter_vectors_cover_every_case_within_the_bound() {
    // r = 3 °/s, about 2.6 sigma of the default gyro: only the gross errors (8 r) go.
    let (_, run) = run_embedded(|config| config.mean_filter.threshold_dps = 3.0);
    let block = named(&run, "mean_filter");
    // rst, x, y_valid, y, kept
    let outputs: Vec<&[i64]> = (0..block.len())
        .map(|k| block.row(k))
        .filter(|row| row[2] == 1)
        .collect();
    // 4000 samples with a reset at 3600: 180 + 20 blocks, then 6 directed ones.
    assert_eq!(outputs.len(), 180 + 20 + 6);
    let kept: std::collections::BTreeSet<i64> = outputs.iter().map(|row| row[4]).collect();
    assert!(
        kept.contains(&0) && kept.contains(&20) && kept.contains(&19),
        "{kept:?}"
    );
    // Every block with a gross error (before the reset, blocks start at multiples of 20)
    // drops at least that sample.
    let gross_blocks: Vec<usize> = (0..180)
        .filter(|b| (20 * b..20 * b + 20).any(|k| k % GROSS_ERROR_PERIOD == GROSS_ERROR_PERIOD / 3))
        .collect();
    assert!(gross_blocks.len() > 50, "{}", gross_blocks.len());
    for b in gross_blocks {
        assert!(outputs[b][4] < 20, "block {b} kept its gross error");
    }
    let stats = run
        .stats("mean_filter")
        .expect("the mean filter's statistics");
    assert!(stats.max_lsb <= stats.bound_lsb);
    assert!(stats.samples >= 200);
}

/// The blocks with a golden model (those the Python and C bindings step) are exactly those
/// with a cocotb test and a DPI-C testbench, in the package's order.
#[test]
fn every_block_with_a_golden_model_has_a_cocotb_test_and_dpi_parts() {
    with_default_blocks(|blocks, _| {
        let with_test: Vec<&str> = blocks
            .iter()
            .filter(|b| b.cocotb_test.is_some())
            .map(|b| b.name)
            .collect();
        assert_eq!(with_test, gyrofx_job::golden::BLOCKS);
        for block in blocks {
            assert_eq!(
                block.dpi.is_some(),
                block.cocotb_test.is_some(),
                "{}",
                block.name
            );
            if let Some(test) = block.cocotb_test {
                let timing = test
                    .lines()
                    .filter(|line| line.starts_with("TIMING = tb.Timing("))
                    .count();
                assert_eq!(
                    timing, 1,
                    "{}: one TIMING line for gyrofx to set",
                    block.name
                );
                assert!(
                    !crate::cocotb::test_names(test).is_empty(),
                    "{}: no @cocotb.test()",
                    block.name
                );
            }
        }
    });
}

/// The package's cocotb files: the TIMING line from the block's pipeline, `tests.json` naming
/// every cocotb test, no copy of the shared helpers (they are `gyrofx.cocotb`).
#[test]
fn cocotb_tests_get_their_timing_and_are_listed_for_pytest() {
    with_default_blocks(|blocks, provenance| {
        let files = crate::cocotb::files(blocks, provenance);
        let file = |path: &str| {
            files
                .iter()
                .find(|(p, _)| p == path)
                .map(|(_, text)| text.as_str())
                .unwrap_or_else(|| panic!("{path} not written"))
        };
        assert!(file("cocotb/test_kf.py")
            .contains("\nTIMING = tb.Timing(latency_clocks=4, min_clocks_per_sample=3)\n"));
        assert!(file("cocotb/test_estimator.py")
            .contains("\nTIMING = tb.Timing(latency_clocks=6, min_clocks_per_sample=6)\n"));
        assert!(files.iter().all(|(p, _)| !p.ends_with("gyrofx_cocotb.py")));
        let tests: serde_json::Value = serde_json::from_str(file("cocotb/tests.json")).unwrap();
        let listed = tests["blocks"].as_array().unwrap();
        assert_eq!(listed.len(), gyrofx_job::golden::BLOCKS.len());
        let kf = listed.iter().find(|b| b["name"] == "kf").unwrap();
        assert_eq!(kf["toplevel"], "cocotb_gyrofx_kf");
        assert_eq!(
            kf["tests"],
            serde_json::json!(["random_stimulus", "directed_full_scale"])
        );
        assert_eq!(kf["latency_clocks"], 4);
        for source in tests["sources"].as_array().unwrap() {
            assert!(source.as_str().unwrap().starts_with("hdl/"));
        }
    });
}

/// The default config's blocks (100 samples), and the provenance they were built with.
fn with_default_blocks(check: impl FnOnce(&[crate::block::Block], &crate::text::Provenance)) {
    let mut config = gyrofx_job::config::Config::embedded();
    config.samples = 100;
    let job = Job::new(config).unwrap();
    let provenance = crate::text::Provenance::for_tests();
    let roms = RomImages::new(&job, &provenance);
    let blocks: Vec<_> = super::of(&job).map(|b| b.block(&job, &roms)).collect();
    check(&blocks, &provenance);
}
