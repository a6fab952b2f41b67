//! `generate`: a job → a complete verification package (vectors, ROM, testbench, RTL,
//! Makefile, manifest), written atomically.

use std::path::Path;

use serde::Serialize;
use serde_json::json;

use gyrofx_model::kf::OverflowCounts;

use crate::error::Result;
use crate::job::Job;
use crate::package::{sha256_hex, Package, MANIFEST};
use crate::report;
use crate::vectors::{self, Vectors};
use crate::writers::{self, names, Provenance};

/// What `generate` reports back.
#[derive(Clone, Debug)]
pub struct Summary {
    /// The vector set.
    pub vectors: Vectors,
    /// ADC saturations in the stimulus.
    pub adc_saturations: u64,
    /// Files written, relative paths.
    pub files: Vec<String>,
}

/// The regenerate command for a job from the embedded default or a config file.
pub fn provenance(job: &Job, config_file: Option<&Path>) -> Provenance {
    let config_text = job.config.to_toml();
    let mut command = "gyrofx generate --out <folder>".to_string();
    if let Some(path) = config_file {
        command.push_str(&format!(" --config {}", path.display()));
    }
    command.push_str(&format!(
        " --seed {} --samples {}",
        job.config.seed, job.config.samples
    ));
    Provenance {
        version: env!("CARGO_PKG_VERSION").to_string(),
        command,
        config_sha256: sha256_hex(config_text.as_bytes()),
    }
}

#[derive(Serialize)]
struct OverflowReport {
    x1: u64,
    x2: u64,
    rate_hat: u64,
    adc_saturations: u64,
}

/// Builds every file of the package for `job`, in memory. `progress` is told the phase.
///
/// # Errors
/// Stimulus errors (a bad CSV file).
pub fn build_package(
    job: &Job,
    provenance: &Provenance,
    progress: &mut dyn FnMut(&str),
) -> Result<(Package, Summary)> {
    progress("stimulus");
    let stimulus = job.stimulus()?;
    progress("models");
    let vectors = vectors::build(&job.plan, &stimulus);
    progress("files");
    let plan = &job.plan;
    let (stimulus_hex, expected_hex, csv) = writers::vector_files(plan, &vectors, provenance);
    let mut package = Package::new();
    package.add(
        "README.md",
        writers::package_readme(plan, &vectors, provenance),
    );
    package.add("Makefile", writers::makefile(provenance));
    for (name, source) in writers::RTL_SOURCES {
        package.add(format!("hdl/{name}"), source);
    }
    package.add(
        format!("kf/{}", names::ROM),
        writers::rom_mem(plan, provenance),
    );
    package.add(
        format!("kf/{}", names::PARAMS),
        writers::params_vh(plan, vectors.rows.len(), provenance),
    );
    package.add(format!("kf/{}", names::STIMULUS), stimulus_hex);
    package.add(format!("kf/{}", names::EXPECTED), expected_hex);
    package.add(format!("kf/{}", names::CSV), csv);
    package.add(
        format!("kf/{}", names::TESTBENCH),
        writers::testbench(provenance),
    );

    let OverflowCounts { x1, x2, rate_hat } = vectors.overflow;
    let field_list = |fields: &[(&str, String)]| -> Vec<serde_json::Value> {
        fields
            .iter()
            .map(|(n, f)| json!({"name": n, "format": f}))
            .collect()
    };
    let manifest = json!({
        "tool": "gyrofx",
        "version": provenance.version,
        "command": provenance.command,
        "seed": job.config.seed,
        "config_sha256": provenance.config_sha256,
        "config": job.config,
        "kf": {
            "formats": {
                "input": plan.input.to_string(),
                "state": plan.state.to_string(),
                "output": plan.output.to_string(),
                "g1": plan.coefficient[0].to_string(),
                "g2": plan.coefficient[1].to_string(),
                "error": plan.error.to_string(),
                "product_g1": plan.product[0].to_string(),
                "product_g2": plan.product[1].to_string(),
                "sum_x1": plan.sum[0].to_string(),
                "sum_x2": plan.sum[1].to_string(),
            },
            "guard_bits": plan.guard_bits(),
            "rounding": plan.rounding.name(),
            "overflow": plan.overflow.name(),
            "latency_clocks": 1,
            "designs": report::designs(&job.designs, plan),
            "coefficients": report::coefficients(plan),
            "rom": {
                "file": format!("kf/{}", names::ROM),
                "depth": plan.rom.len(),
                "word_bits": writers::rom_word_width(plan),
                "packing": "word = {g1, g2}: g1 in the high bits; address = bw_sel",
            },
            "overflow_counts": OverflowReport { x1, x2, rate_hat, adc_saturations: stimulus.adc_saturations },
            "fixed_vs_float": vectors.stats,
            "tie_cases": vectors.ties,
            "vectors": {
                "count": vectors.rows.len(),
                "stimulus_samples": stimulus.z.len(),
                "encoding": "one line per clock-enable; fields separated by one space, each a zero-padded two's-complement hex word of its format's width; line 1 is a generated-by comment, line 2 names the fields and formats",
                "stimulus": {"file": format!("kf/{}", names::STIMULUS), "fields": field_list(&writers::stimulus_fields(plan))},
                "expected": {"file": format!("kf/{}", names::EXPECTED), "fields": field_list(&writers::expected_fields(plan)),
                             "timing": "compared 1 clock after each ce; rate_out only where valid = 1"},
                "csv": format!("kf/{}", names::CSV),
            },
        },
        "files": package.entries(),
    });
    let mut text = serde_json::to_string_pretty(&manifest).expect("manifest serializes");
    text.push('\n');
    package.add(MANIFEST, text);
    let files = package.paths();
    Ok((
        package,
        Summary {
            vectors,
            adc_saturations: stimulus.adc_saturations,
            files,
        },
    ))
}

/// Builds the package for `job` and writes it to `out` atomically.
///
/// # Errors
/// Stimulus errors, and [`crate::Error::Output`] / [`crate::Error::Io`] when `out` cannot be
/// written (nothing is left behind).
pub fn generate(
    job: &Job,
    out: &Path,
    config_file: Option<&Path>,
    progress: &mut dyn FnMut(&str),
) -> Result<Summary> {
    let provenance = provenance(job, config_file);
    let (package, summary) = build_package(job, &provenance, progress)?;
    progress("writing");
    package.write_atomically(out)?;
    Ok(summary)
}
