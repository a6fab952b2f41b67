//! The golden vector set of the default config (`vectors/`): any change to the model, the
//! writers or the default shows up here. Regenerate on purpose with
//! `GYROFX_UPDATE_GOLDEN=1 cargo test --test golden` (or scripts/update-golden.sh).

mod common;

use std::path::Path;

use common::*;

const GOLDEN: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/vectors");

#[test]
fn default_package_matches_the_golden_vectors() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("pkg");
    ok(&["generate", "--out", out.to_str().unwrap()]);
    let golden = Path::new(GOLDEN);
    // The package without the RTL (that is hdl/ itself): vectors, ROM, include, testbench,
    // Makefile, README, manifest.
    let produced: Vec<_> = files_below(&out)
        .into_iter()
        .filter(|p| !p.starts_with("hdl"))
        .collect();
    if std::env::var_os("GYROFX_UPDATE_GOLDEN").is_some() {
        let _ = std::fs::remove_dir_all(golden);
        for file in &produced {
            let target = golden.join(file);
            std::fs::create_dir_all(target.parent().unwrap()).unwrap();
            std::fs::copy(out.join(file), target).unwrap();
        }
        eprintln!(
            "updated {} golden files in {}",
            produced.len(),
            golden.display()
        );
        return;
    }
    assert_eq!(
        produced,
        files_below(golden),
        "the package's file list differs from vectors/ (regenerate with GYROFX_UPDATE_GOLDEN=1 if intended)"
    );
    for file in &produced {
        let want = std::fs::read(golden.join(file)).unwrap();
        let got = std::fs::read(out.join(file)).unwrap();
        if want != got {
            let first = want
                .split(|b| *b == b'\n')
                .zip(got.split(|b| *b == b'\n'))
                .position(|(a, b)| a != b)
                .map(|i| i + 1);
            panic!(
                "{} differs from the golden copy (first differing line {:?}); regenerate with GYROFX_UPDATE_GOLDEN=1 cargo test --test golden if the change is intended",
                file.display(),
                first
            );
        }
    }
}
