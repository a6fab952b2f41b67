//! The manifest's schema page, generated from the golden package's `vectors/manifest.json`
//! (which `tests/golden.rs` holds to what `generate` writes): every key path with its JSON
//! type and the default package's value, under a description of its section that this file
//! keeps (a new section without one fails here).

use std::collections::BTreeMap;
use std::fmt::Write as _;

use serde_json::Value;

use super::{generated_page, guide, repository};

/// What each top-level section of `manifest.json` holds.
const SECTIONS: &[(&str, &str)] = &[
    ("tool", "The writer: always `gyrofx`."),
    ("version", "gyrofx's version that wrote the package."),
    (
        "command",
        "The command line that rewrites the package (the folder left as `<folder>`).",
    ),
    ("seed", "The seed of every random stream of the run."),
    ("samples", "Samples of the chain run."),
    (
        "config_sha256",
        "SHA-256 of the resolved config's TOML, every key (the Python `Plan.toml()`): two \
         packages of one config share it.",
    ),
    (
        "config",
        "The resolved config, every key: see [the default config](default-config.md) for \
         each key's meaning, unit and default.",
    ),
    (
        "encoding",
        "How the vector files are written (one line per clock-enable, hex words).",
    ),
    (
        "files",
        "Every file of the package with its size and SHA-256: what `generate` checks before it \
         replaces a folder.",
    ),
    (
        "blocks",
        "Per registered block (`<block>`: kf, sequencer, …): its RTL module, parameters, ROMs, \
         and its stimulus and expected files with each field's format and when it is checked.",
    ),
    (
        "formats",
        "The proven formats: per analysed node its range and whether its format holds for this \
         run's length and `bw_sel` switches; the blocks still hand-set.",
    ),
    (
        "kf",
        "The KF: its designs per bandwidth, ROM, formats, pipeline, tie cases and the \
         fixed-versus-float error against its derived bound.",
    ),
    (
        "estimator",
        "The bias estimator: gains, schedule, formats, pipeline and fixed-versus-float bias.",
    ),
    (
        "mean_filter",
        "The mean filter: architecture, window, threshold, ROM, formats, pipeline and \
         fixed-versus-float error.",
    ),
    (
        "chain",
        "The whole chain: architecture, pipeline, rounding, overflow and fixed-versus-float \
         error.",
    ),
    (
        "gyro_loop",
        "The gyro loop's record: which gyro, rates, decimation, formats and pipeline.",
    ),
    (
        "system",
        "The system's record: rates, decimation, schedule and pipeline.",
    ),
    (
        "overflow_counts",
        "Saturations and wraps per quantization point over the run, by part.",
    ),
    (
        "report",
        "The lines of `report.md` (bias error and Allan deviation of raw, calibrated and \
         filtered rates) and the τ they use.",
    ),
];

/// A JSON value's type name.
fn type_name(value: &Value) -> &'static str {
    match value {
        Value::Null => "null",
        Value::Bool(_) => "boolean",
        Value::Number(n) if n.is_i64() || n.is_u64() => "integer",
        Value::Number(_) => "number",
        Value::String(_) => "string",
        Value::Array(_) => "array",
        Value::Object(_) => "object",
    }
}

/// A short rendering of a scalar (the first one seen at a path).
fn example(value: &Value) -> String {
    let text = value.to_string();
    if text.chars().count() > 40 {
        format!("{}…", text.chars().take(39).collect::<String>())
    } else {
        text
    }
}

/// Every key path under `value` (arrays as `[]`, the blocks' names as `<block>`), with the
/// types seen there and the first scalar value.
fn walk(value: &Value, path: &str, out: &mut BTreeMap<String, (Vec<&'static str>, String)>) {
    let entry = out
        .entry(path.to_string())
        .or_insert_with(|| (Vec::new(), String::new()));
    let kind = type_name(value);
    if !entry.0.contains(&kind) {
        entry.0.push(kind);
    }
    match value {
        Value::Object(map) => {
            for (key, item) in map {
                let key = if path == "blocks" { "<block>" } else { key };
                walk(item, &format!("{path}.{key}"), out);
            }
        }
        Value::Array(items) => {
            for item in items {
                walk(item, &format!("{path}[]"), out);
            }
        }
        scalar => {
            if entry.1.is_empty() && !scalar.is_null() {
                entry.1 = example(scalar);
            }
        }
    }
}

/// The schema page of `manifest`.
fn schema_page(manifest: &Value) -> String {
    let mut page = String::from(
        "# The manifest's schema\n\n<!-- Generated from vectors/manifest.json by \
         tests/docs/manifest_schema.rs: GYROFX_UPDATE_DOCS=1 cargo test --test main docs:: \
         rewrites it -->\n\nEvery package's `manifest.json`, section by section: each key path \
         (`[]` an array's items, `<block>` any block), its JSON type and the default package's \
         value; `version` names the writer, and CHANGELOG.md names any key that changes. How a \
         package is laid out: [the package](package.md).\n",
    );
    let Value::Object(sections) = manifest else {
        panic!("manifest.json is an object")
    };
    for (name, description) in SECTIONS {
        let value = &sections[*name];
        let _ = writeln!(page, "\n## `{name}`\n\n{description}\n");
        if *name == "config" {
            continue;
        }
        let mut paths = BTreeMap::new();
        walk(value, name, &mut paths);
        let _ = writeln!(page, "| key | type | default package |\n|---|---|---|");
        for (path, (types, value)) in paths {
            let value = value.replace('|', "\\|");
            let _ = writeln!(page, "| `{path}` | {} | {value} |", types.join(" or "));
        }
    }
    page
}

/// The golden package's manifest (`vectors/manifest.json`: the default config's package, which
/// `tests/golden.rs` holds to what `generate` writes).
pub(super) fn golden_manifest() -> Value {
    let text = std::fs::read(repository().join("vectors/manifest.json")).unwrap();
    serde_json::from_slice(&text).unwrap()
}

#[test]
fn the_manifest_schema_is_generated_from_the_golden_manifest() {
    generated_page(
        &guide().join("reference/manifest.md"),
        &schema_page(&golden_manifest()),
    );
}

/// Every section of the manifest has a description here, and every description a section.
#[test]
fn every_manifest_section_is_described() {
    let manifest = golden_manifest();
    let Value::Object(sections) = &manifest else {
        panic!("manifest.json is an object")
    };
    let described: Vec<&str> = SECTIONS.iter().map(|(name, _)| *name).collect();
    for key in sections.keys() {
        assert!(
            described.contains(&key.as_str()),
            "manifest section `{key}` has no description in tests/docs/manifest_schema.rs"
        );
    }
    for name in described {
        assert!(
            sections.contains_key(name),
            "tests/docs/manifest_schema.rs describes `{name}`, which the manifest no longer has"
        );
    }
}
