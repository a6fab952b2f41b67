//! The committed C header is what cbindgen makes of the code: a changed signature without a
//! regenerated header fails here. `GYROFX_UPDATE_HEADER=1 cargo test -p gyrofx-capi --test
//! header` rewrites it.
//!
//! cbindgen is the command-line tool (Debian's `cbindgen` package; scripts/test.sh installs
//! it), not the crate: as a dev-dependency it compiled syn and itself in every test build,
//! about a minute of a fresh CI run. A missing cbindgen fails this test, it does not skip it.

use std::path::Path;
use std::process::Command;

#[test]
fn the_header_matches_the_code() {
    let crate_dir = Path::new(env!("CARGO_MANIFEST_DIR"));
    let output = Command::new("cbindgen")
        .args(["--config", "cbindgen.toml", "--crate", "gyrofx-capi"])
        .current_dir(crate_dir)
        .output()
        .unwrap_or_else(|e| {
            panic!("cannot run cbindgen ({e}): install it (apt-get install cbindgen, or cargo install cbindgen)")
        });
    assert!(
        output.status.success(),
        "cbindgen failed:\n{}",
        String::from_utf8_lossy(&output.stderr)
    );
    let generated = String::from_utf8(output.stdout).expect("UTF-8");
    let header = crate_dir.join("include/gyrofx.h");
    if std::env::var_os("GYROFX_UPDATE_HEADER").is_some() {
        std::fs::write(&header, &generated).unwrap();
    }
    let committed = std::fs::read_to_string(&header).unwrap_or_default();
    assert!(
        committed == generated,
        "capi/include/gyrofx.h differs from cbindgen's output: run GYROFX_UPDATE_HEADER=1 cargo test -p gyrofx-capi --test header"
    );
}
