//! The golden vector set of the default config (`vectors/`): any change to the model, the
//! writers or the default shows up here. Regenerate on purpose with
//! `GYROFX_UPDATE_GOLDEN=1 cargo test --test main golden::` (or scripts/update-golden.sh).

use std::path::Path;

use crate::common::*;

const GOLDEN: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/vectors");

/// Package files too large to keep in the repository at every regeneration (the system's CSV,
/// 9 MB, is its hex files in decimal with real values); `vectors/manifest.json` pins them.
const NOT_COPIED: [&str; 1] = ["system/system_vectors.csv"];

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
        .filter(|p| !NOT_COPIED.contains(&p.to_str().unwrap()))
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
    // The files not kept are pinned by their SHA-256 in the golden manifest, which is itself
    // compared below.
    let manifest: serde_json::Value =
        serde_json::from_slice(&std::fs::read(golden.join("manifest.json")).unwrap()).unwrap();
    for file in NOT_COPIED {
        let entry = manifest["files"]
            .as_array()
            .unwrap()
            .iter()
            .find(|f| f["path"] == file)
            .unwrap_or_else(|| panic!("{file} in the golden manifest"));
        let data = std::fs::read(out.join(file)).unwrap();
        assert_eq!(
            entry["sha256"].as_str().unwrap(),
            hex_sha256(&data),
            "{file} differs from the golden manifest's SHA-256; regenerate with GYROFX_UPDATE_GOLDEN=1 cargo test --test main golden:: if the change is intended"
        );
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
                "{} differs from the golden copy (first differing line {:?}); regenerate with GYROFX_UPDATE_GOLDEN=1 cargo test --test main golden:: if the change is intended",
                file.display(),
                first
            );
        }
    }
}
