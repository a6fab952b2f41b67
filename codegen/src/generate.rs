//! `generate`: a job → a complete verification package (every block's vectors, ROMs and
//! testbench, the RTL, a Makefile, the report and the manifest), written atomically.

use std::path::Path;

use serde_json::json;

use crate::block::{Block, Timing};
use crate::blocks::{RomImages, Streaming, REGISTRY};
use crate::hdl;
use crate::output_folder::MANIFEST;
use crate::output_folder::{Kind, Replace};
use crate::package::{FileEntry, Package, Staging};
use crate::progress::Progress;
use crate::rom::{self, RomFormat, ROM_FOLDER};
use crate::testbench::{verilog, vhdl};
use crate::text::Provenance;
use crate::vectors::{self, Run};
use crate::writers;
use gyrofx_job::error::Result;
use gyrofx_job::hash::sha256_hex;
use gyrofx_job::job::Job;

/// What `generate` reports back.
#[derive(Debug)]
pub struct Summary {
    /// The run.
    pub run: Run,
    /// Files written, relative paths.
    pub files: Vec<String>,
}

/// Which gyrofx output a [`Provenance`] is for: it names the command that regenerates it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Output {
    /// The verification package (`gyrofx generate`): depends on the seed and the samples.
    Package,
    /// The synthesis check (`gyrofx synth`): depends on the formats only.
    Synthesis,
}

/// The regenerate command for an `output` of a job from the embedded default, a preset and/or
/// a config file.
pub fn provenance(
    job: &Job,
    output: Output,
    preset: Option<&str>,
    config_file: Option<&Path>,
) -> Provenance {
    let config_text = job.config.to_toml();
    let mut command = match output {
        Output::Package => "gyrofx generate --out <folder>",
        Output::Synthesis => "gyrofx synth --out <folder>",
    }
    .to_string();
    if let Some(name) = preset {
        command.push_str(&format!(" --preset {name}"));
    }
    if let Some(path) = config_file {
        command.push_str(&format!(" --config {}", path.display()));
    }
    if output == Output::Package {
        command.push_str(&format!(
            " --seed {} --samples {}",
            job.config.seed, job.config.samples
        ));
    }
    Provenance {
        version: env!("CARGO_PKG_VERSION").to_string(),
        command,
        config_sha256: sha256_hex(config_text.as_bytes()),
    }
}

/// One file of a block's folder: its text, or the entry of a file its rows were streamed to.
pub(crate) enum BlockFile {
    Text(String, String),
    Written(FileEntry),
}

/// Every file of one block's folder, in the package's order: the parameter include, the
/// vector files (streamed already: their entries), the testbenches and the ROM images.
pub(crate) fn block_files(block: &Block, provenance: &Provenance) -> Vec<BlockFile> {
    let text =
        |name: String, content: String| BlockFile::Text(format!("{}/{name}", block.name), content);
    let mut files = vec![text(
        block.file("params.vh"),
        writers::params_vh(block, provenance),
    )];
    files.extend(block.written().iter().cloned().map(BlockFile::Written));
    files.push(text(
        block.file("tb"),
        verilog::testbench(block, provenance),
    ));
    files.push(text(
        block.file("tb.vhd"),
        vhdl::testbench(block, provenance),
    ));
    files.extend(
        block
            .roms
            .iter()
            .map(|(name, content)| text(name.to_string(), content.clone())),
    );
    files
}

/// A package of `blocks` alone, built outside a job with their rows kept (a leaf module of the
/// gyro loop at a plan of its own: [`crate::blocks::nco::block`] and its `push_vectors`): each
/// block's folder as [`build_package`] writes it, the HDL sources and the Makefile, so that
/// `gyrofx verify` and `make` run them as they run a generated package's.
///
/// # Panics
/// When a block's rows were streamed rather than kept.
pub fn blocks_package(blocks: &[Block], provenance: &Provenance) -> Package {
    let mut package = Package::new(Kind::Generate, writers::build_outputs(blocks));
    package.add("Makefile", writers::makefile(blocks, provenance));
    add_rtl(&mut package);
    for block in blocks {
        let (stimulus, expected) = writers::vector_hex(block, provenance);
        for (what, text) in [("stimulus.hex", stimulus), ("expected.hex", expected)] {
            package.add(format!("{}/{}", block.name, block.file(what)), text);
        }
        add_block_files(&mut package, block, provenance);
    }
    package
}

/// Adds the embedded reference RTL under `hdl/`.
fn add_rtl(package: &mut Package) {
    for (name, source) in hdl::RTL_SOURCES.iter().chain(&hdl::VHDL_SOURCES) {
        package.add(format!("hdl/{name}"), *source);
    }
}

/// Adds a block's folder ([`block_files`]).
fn add_block_files(package: &mut Package, block: &Block, provenance: &Provenance) {
    for file in block_files(block, provenance) {
        match file {
            BlockFile::Text(path, text) => package.add(path, text),
            BlockFile::Written(entry) => package.add_written(entry),
        }
    }
}

pub(crate) fn block_manifest(block: &Block) -> serde_json::Value {
    let fields = |signals: Vec<(&str, String)>| -> Vec<serde_json::Value> {
        signals
            .into_iter()
            .map(|(n, f)| json!({"name": n, "format": f}))
            .collect()
    };
    let mut inputs = vec![("rst", "u1.0".to_string())];
    inputs.extend(block.inputs.iter().map(|s| (s.name, s.format.to_string())));
    let outputs: Vec<serde_json::Value> = block
        .outputs
        .iter()
        .map(|o| {
            json!({
                "name": o.signal.name,
                "format": o.signal.format.to_string(),
                "checked": match o.timing {
                    Timing::Combinational => "before the clock edge that takes the sample (not on resets)".to_string(),
                    Timing::Registered if block.settle_clocks() == 0 => "1 clock after the sample's ce".to_string(),
                    Timing::Registered => format!("{} clocks after the sample's ce (a pipeline of {} settle clocks)", 1 + block.settle_clocks(), block.settle_clocks()),
                },
                "only_where": o.gate.map(|g| format!("{g} = 1")),
                "pulse": o.pulse,
            })
        })
        .collect();
    json!({
        "module": block.module,
        "vectors": block.len(),
        "params": block.params.iter().map(|p| json!({"name": p.name, "value": p.value, "what": p.comment})).collect::<Vec<_>>(),
        "stimulus": {"file": format!("{}/{}", block.name, block.file("stimulus.hex")), "fields": fields(inputs)},
        "expected": {"file": format!("{}/{}", block.name, block.file("expected.hex")), "fields": outputs},
        "roms": block.roms.iter().map(|(n, _)| format!("{}/{n}", block.name)).collect::<Vec<_>>(),
    })
}

/// Builds the package for `job`: the blocks' vector files are streamed into `staging` as the
/// chain runs (memory does not grow with the samples), every other file is built in memory
/// for [`Package::write_staged`]. `progress` follows the phases and the chain run's simulated
/// samples.
///
/// # Errors
/// Stimulus errors (a bad CSV file); write errors.
pub fn build_package(
    job: &Job,
    contents: &Contents,
    provenance: &Provenance,
    progress: &Progress,
    staging: &Staging,
) -> Result<(Package, Summary)> {
    progress.set_phase("chain run");
    let roms = RomImages::new(job, provenance);
    let streaming = Streaming {
        root: staging.path(),
        csv: contents.csv,
        blocks: contents.blocks.as_deref(),
        provenance,
    };
    let builders = crate::blocks::vector_builders(job, &roms, Some(streaming))?;
    let mut run = vectors::run(job, builders, progress)?;
    if let Some(names) = &contents.blocks {
        run.blocks.retain(|b| names.iter().any(|n| n == b.name));
    }
    progress.set_phase("files");
    let mut package = Package::new(Kind::Generate, writers::build_outputs(&run.blocks));
    package.add("README.md", writers::package_readme(&run, provenance));
    package.add("Makefile", writers::makefile(&run.blocks, provenance));
    package.add(
        crate::fusesoc::CORE_FILE,
        crate::fusesoc::core(&run.blocks, provenance),
    );
    package.add("report.md", writers::report_md(&run, provenance));
    add_rtl(&mut package);
    for image in roms.iter() {
        for format in RomFormat::ALL {
            package.add(
                format!("{ROM_FOLDER}/{}", format.file_name(&image.rom.name)),
                rom::write(&image.rom, format, provenance),
            );
        }
    }
    for (path, text) in crate::cocotb::files(&run.blocks, provenance)
        .into_iter()
        .chain(crate::dpi::files(&run.blocks, provenance))
    {
        package.add(path, text);
    }
    for block in &run.blocks {
        add_block_files(&mut package, block, provenance);
    }

    let blocks: serde_json::Map<String, serde_json::Value> = run
        .blocks
        .iter()
        .map(|b| (b.name.to_string(), block_manifest(b)))
        .collect();
    let mut manifest = json!({
        "tool": "gyrofx",
        "version": provenance.version,
        "command": provenance.command,
        "seed": job.config.seed,
        "config_sha256": provenance.config_sha256,
        "config": job.config,
        "samples": run.samples,
        "encoding": "vector files: one line per clock-enable; fields separated by one space, each a zero-padded two's-complement hex word of its format's width; line 1 is a generated-by comment, line 2 names the fields and formats",
        "blocks": blocks,
        "overflow_counts": run.overflows,
        "report": run.report,
    });
    let sections = manifest.as_object_mut().expect("an object");
    if let Some(recording) = &job.recording {
        sections.insert("recording".into(), recording.manifest(run.samples));
    }
    for block in crate::blocks::of(job) {
        if let Some((key, section)) = block.manifest(job, &roms, &run) {
            sections.insert(key.to_string(), section);
        }
    }
    // Which formats are proven for this run's length and bw_sel switches, and which hand-set.
    let switches = crate::vectors::bw_sel_switches(run.samples, job.kf().rom.len());
    sections.insert(
        "formats".into(),
        gyrofx_job::formats::analyse(job, run.samples as u64, switches).json(),
    );
    sections.insert("files".to_string(), json!(package.entries()));
    let mut text = serde_json::to_string_pretty(&manifest).expect("manifest serializes");
    text.push('\n');
    package.add(MANIFEST, text);
    let files = package.paths();
    Ok((package, Summary { run, files }))
}

/// What a package holds.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Contents {
    /// Only these blocks' folders and Makefile targets (all when `None`); every block's
    /// vectors are still computed and the manifest still reports the whole run.
    pub blocks: Option<Vec<String>>,
    /// The `<block>_vectors.csv` twins of the hex files.
    pub csv: bool,
}

impl Default for Contents {
    /// Every block, with its CSV.
    fn default() -> Self {
        Contents {
            blocks: None,
            csv: true,
        }
    }
}

impl Contents {
    /// Refuses a block name the registry does not have.
    ///
    /// # Errors
    /// A message naming the block and listing the registry's.
    pub fn check(&self) -> std::result::Result<(), String> {
        let known: Vec<&str> = REGISTRY.iter().map(|b| b.name()).collect();
        match self
            .blocks
            .iter()
            .flatten()
            .find(|n| !known.contains(&n.as_str()))
        {
            Some(unknown) => Err(format!(
                "--blocks {unknown}: no such block; the package's blocks are {}",
                known.join(", ")
            )),
            None => Ok(()),
        }
    }
}

impl Contents {
    /// Refuses a block that `job`'s package does not have (the system block on the rate
    /// plant).
    ///
    /// # Errors
    /// A message naming the block and listing the package's.
    pub fn check_for(&self, job: &Job) -> std::result::Result<(), String> {
        let present: Vec<&str> = crate::blocks::of(job).map(|b| b.name()).collect();
        match self
            .blocks
            .iter()
            .flatten()
            .find(|n| !present.contains(&n.as_str()))
        {
            Some(absent) => Err(format!(
                "--blocks {absent}: not in this package (the system block needs plant.model = \"resonator\"); its blocks are {}",
                present.join(", ")
            )),
            None => Ok(()),
        }
    }
}

/// How [`generate`] treats its output folder and overflows, and what it writes.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Options {
    /// Whether an existing folder may be replaced.
    pub replace: Replace,
    /// Refuse to write when a quantizer overflowed on the run's data
    /// ([`crate::vectors::Overflows::in_chain_run`]).
    pub strict: bool,
    /// What the package holds.
    pub contents: Contents,
}

/// `name count, name count, …` of [`crate::vectors::Overflows::in_chain_run`].
pub fn overflow_list(overflowed: &[(String, u64)]) -> String {
    overflowed
        .iter()
        .map(|(name, n)| format!("{name} {n}"))
        .collect::<Vec<_>>()
        .join(", ")
}

/// Builds the package for `job` and writes it to `out` atomically, if `out` may be replaced
/// ([`output_folder::check`], checked before the work starts); with `options.strict`, only if
/// no quantizer overflowed on the run's data.
///
/// # Errors
/// Stimulus errors, and [`crate::Error::Output`] / [`crate::Error::Io`] when `out` cannot be
/// written (nothing is left behind).
pub fn generate(
    job: &Job,
    out: &Path,
    options: Options,
    provenance: &Provenance,
    progress: &Progress,
) -> Result<Summary> {
    let staging = Staging::create(out, Kind::Generate, options.replace)?;
    let (package, summary) = build_package(job, &options.contents, provenance, progress, &staging)?;
    let overflowed = summary.run.overflows.in_chain_run();
    if options.strict && !overflowed.is_empty() {
        // The staging folder goes with `staging`: nothing is written.
        return Err(gyrofx_job::error::Error::Overflow(overflow_list(
            &overflowed,
        )));
    }
    progress.set_phase("writing");
    package.write_staged(staging)?;
    Ok(summary)
}
