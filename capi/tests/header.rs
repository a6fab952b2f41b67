//! The committed C header is what cbindgen makes of the code: a changed signature without a
//! regenerated header fails here. `GYROFX_UPDATE_HEADER=1 cargo test -p gyrofx-capi --test
//! header` rewrites it.

use std::path::Path;

#[test]
fn the_header_matches_the_code() {
    let crate_dir = Path::new(env!("CARGO_MANIFEST_DIR"));
    let config =
        cbindgen::Config::from_file(crate_dir.join("cbindgen.toml")).expect("cbindgen.toml");
    let mut generated = Vec::new();
    cbindgen::Builder::new()
        .with_crate(crate_dir)
        .with_config(config)
        .generate()
        .expect("cbindgen parses the crate")
        .write(&mut generated);
    let generated = String::from_utf8(generated).expect("UTF-8");
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
