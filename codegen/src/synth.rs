//! Synthesis check of the reference RTL with a job's widths: yosys, generic and Xilinx 7-series.
//!
//! The whole chain (`gyrofx_top`) and one gyro's loop (`gyrofx_gyro_loop`) are each elaborated
//! with the job's parameters and ROMs. The check
//! fails on a missing module (`hierarchy -check`), an inferred latch, and on undriven or
//! multiply-driven nets (`check -assert`). Resources come from `stat -json`: generic cells,
//! flip-flops and multipliers (counted before they are merged into `$macc` cells), and the
//! `synth_xilinx` mapping's LUTs, flip-flops, DSP48E1s and block RAMs.

use std::path::Path;
use std::process::Command;

use serde::Serialize;

use crate::block::Block;
use crate::blocks::{self, RomImages};
use crate::error::{Error, Result};
use crate::hdl;
use crate::job::Job;
use crate::output_folder::{self, Kind, Replace};
use crate::package::Package;
use crate::writers::Provenance;

/// Module synthesized: the whole chain.
pub const TOP: &str = "gyrofx_top";
/// Its block in the registry.
const TOP_BLOCK: &str = "top";
/// The second design synthesized: one gyro's loop (gyro A's parameters).
pub const LOOP_TOP: &str = "gyrofx_gyro_loop";
/// Its block in the registry.
const LOOP_BLOCK: &str = "gyro_loop";
/// The folder of the loop's scripts, logs and RTL in the synthesis package.
pub const LOOP_FOLDER: &str = "gyro_loop";

/// Generic (technology-independent) resources of the flattened chain.
#[derive(Clone, Debug, Default, PartialEq, Eq, Serialize)]
pub struct Generic {
    /// Gate-level cells after `synth`.
    pub cells: u64,
    /// Flip-flops (bits).
    pub flip_flops: u64,
    /// `$mul` cells after coarse optimization: one per multiplier in the RTL.
    pub multipliers: u64,
}

/// Xilinx 7-series estimate from `synth_xilinx`.
#[derive(Clone, Debug, Default, PartialEq, Eq, Serialize)]
pub struct Xilinx {
    /// LUT1..LUT6.
    pub luts: u64,
    /// FDRE/FDSE/FDCE/FDPE.
    pub flip_flops: u64,
    /// DSP48E1 slices.
    pub dsp48: u64,
    /// RAMB18E1/RAMB36E1.
    pub block_rams: u64,
    /// CARRY4 chains.
    pub carry4: u64,
}

/// What one synthesis run measured.
#[derive(Clone, Debug, Default, PartialEq, Eq, Serialize)]
pub struct Resources {
    /// Generic mapping.
    pub generic: Generic,
    /// Xilinx 7-series mapping.
    pub xilinx: Xilinx,
}

/// The `chparam` lines that give the block's module its parameters.
fn chparams(block: &Block) -> String {
    block
        .params
        .iter()
        .map(|p| format!("chparam -set {} {} {}\n", p.name, p.value, block.module))
        .collect()
}

/// The RTL of the block's module: its file and its submodules' (for the chain, not the mean
/// filter beside it: yosys would load its ROM image while reading it).
fn sources(block: &Block) -> Vec<&'static (&'static str, &'static str)> {
    hdl::verilog_sources_of(block.module)
}

fn read_sources(block: &Block) -> String {
    let names: Vec<&str> = sources(block).iter().map(|(n, _)| *n).collect();
    format!("read_verilog {}\n", names.join(" "))
}

/// The yosys script of the generic flow for the block's module; writes `coarse.json` and
/// `generic.json`.
pub fn generic_script(top: &Block) -> String {
    let module = top.module;
    format!(
        "{}{}hierarchy -check -top {module}\n\
         synth -flatten -top {module} -run :coarse\n\
         flatten\nproc\n\
         select -assert-none t:$dlatch t:$adlatch t:$dlatchsr\n\
         opt -fast\nwreduce\n\
         tee -q -o coarse.json stat -json\n\
         synth -flatten -top {module} -run coarse:\n\
         select -assert-none t:$dlatch t:$adlatch t:$_DLATCH_*\n\
         check -assert\n\
         tee -q -o generic.json stat -json\n",
        read_sources(top),
        chparams(top)
    )
}

/// The yosys script of the Xilinx 7-series flow for the block's module; writes `xilinx.json`.
pub fn xilinx_script(top: &Block) -> String {
    let module = top.module;
    format!(
        "{}{}hierarchy -check -top {module}\n\
         synth_xilinx -flatten -top {module}\n\
         select -assert-none t:LDCE t:LDPE\n\
         check -assert\n\
         tee -q -o xilinx.json stat -json\n",
        read_sources(top),
        chparams(top)
    )
}

/// Cell counts of the one (flattened) module in a `stat -json` file.
fn cell_counts(dir: &Path, file: &str) -> Result<(u64, Vec<(String, u64)>)> {
    let path = dir.join(file);
    let text = std::fs::read_to_string(&path).map_err(|e| Error::io(&path, e))?;
    let json: serde_json::Value = serde_json::from_str(&text)
        .map_err(|e| Error::Synthesis(format!("yosys wrote unreadable {file}: {e}")))?;
    let module = json["modules"]
        .as_object()
        .and_then(|m| m.values().next())
        .ok_or_else(|| Error::Synthesis(format!("{file} lists no module")))?;
    let total = module["num_cells"].as_u64().unwrap_or(0);
    let by_type = module["num_cells_by_type"]
        .as_object()
        .map(|m| {
            m.iter()
                .map(|(k, v)| (k.clone(), v.as_u64().unwrap_or(0)))
                .collect()
        })
        .unwrap_or_default();
    Ok((total, by_type))
}

fn count(by_type: &[(String, u64)], keep: impl Fn(&str) -> bool) -> u64 {
    by_type
        .iter()
        .filter(|(k, _)| keep(k))
        .map(|(_, n)| n)
        .sum()
}

fn yosys(dir: &Path, script: &str, log: &str) -> Result<()> {
    let output = Command::new("yosys")
        .args(["-q", "-l", log, "-s", script])
        .current_dir(dir)
        .output()
        .map_err(|e| Error::Synthesis(format!("cannot run yosys (is it installed?): {e}")))?;
    if !output.status.success() {
        let text = std::fs::read_to_string(dir.join(log)).unwrap_or_default();
        let tail: Vec<&str> = text.lines().rev().take(20).collect();
        let tail: Vec<&str> = tail.into_iter().rev().collect();
        return Err(Error::Synthesis(format!(
            "synthesis check failed ({script}):\n{}\n{}",
            tail.join("\n"),
            String::from_utf8_lossy(&output.stderr)
        )));
    }
    Ok(())
}

/// Runs both flows in `dir`, which must hold the RTL, the ROM images and the scripts.
///
/// # Errors
/// [`Error::Synthesis`] when yosys is missing or a check fails (with the log's tail).
pub fn measure(dir: &Path) -> Result<Resources> {
    yosys(dir, "generic.ys", "generic.log")?;
    yosys(dir, "xilinx.ys", "xilinx.log")?;
    let (_, coarse) = cell_counts(dir, "coarse.json")?;
    let (cells, generic) = cell_counts(dir, "generic.json")?;
    let (_, xilinx) = cell_counts(dir, "xilinx.json")?;
    Ok(Resources {
        generic: Generic {
            cells,
            flip_flops: count(&generic, |k| k.contains("DFF")),
            multipliers: count(&coarse, |k| k == "$mul"),
        },
        xilinx: Xilinx {
            luts: count(&xilinx, |k| k.starts_with("LUT")),
            flip_flops: count(&xilinx, |k| ["FDRE", "FDSE", "FDCE", "FDPE"].contains(&k)),
            dsp48: count(&xilinx, |k| k.starts_with("DSP48")),
            block_rams: count(&xilinx, |k| k.starts_with("RAMB")),
            carry4: count(&xilinx, |k| k == "CARRY4"),
        },
    })
}

/// One design's section of the report.
fn report_section(top: &Block, resources: &Resources) -> String {
    let g = &resources.generic;
    let x = &resources.xilinx;
    let widths: Vec<String> = top
        .params
        .iter()
        .filter(|p| p.name.ends_with("_W"))
        .map(|p| format!("{}={}", p.name, p.value))
        .collect();
    format!(
        "yosys, flattened, with the config's parameters ({}).\n\
         Checks passed: every module present, no latch, no undriven or multiply-driven net.\n\n\
         | generic | count |\n|---|---|\n| cells | {} |\n| flip-flops | {} |\n| multipliers | {} |\n\n\
         | Xilinx 7-series (`synth_xilinx`) | count |\n|---|---|\n| LUTs | {} |\n| flip-flops | {} |\n\
         | DSP48E1 | {} |\n| block RAM | {} |\n| CARRY4 | {} |\n",
        widths.join(", "),
        g.cells,
        g.flip_flops,
        g.multipliers,
        x.luts,
        x.flip_flops,
        x.dsp48,
        x.block_rams,
        x.carry4
    )
}

/// The synthesis folder's report: the chain, then one gyro's loop.
fn report(
    top: &Block,
    gyro_loop: &Block,
    synthesis: &Synthesis,
    provenance: &Provenance,
) -> String {
    format!(
        "<!-- {} -->\n# Synthesis check: {TOP}\n\n{}\n\
         # Synthesis check: {LOOP_TOP} (gyro A; files in `{LOOP_FOLDER}/`)\n\n{}\n\
         An estimate before place and route: the ROMs are small enough to map to LUTs, and \
         `synth_xilinx` splits a product wider than 25x18 over several DSP48E1s. A sensor \
         board runs two loops beside the chain.\n",
        provenance.line("").trim_start(),
        report_section(top, &synthesis.chain),
        report_section(gyro_loop, &synthesis.gyro_loop),
    )
}

/// What `gyrofx synth` measured: the chain and one gyro's loop.
#[derive(Clone, Debug, Default, PartialEq, Eq, Serialize)]
pub struct Synthesis {
    /// `gyrofx_top`.
    pub chain: Resources,
    /// `gyrofx_gyro_loop` (gyro A's parameters).
    pub gyro_loop: Resources,
}

/// One design's inputs (RTL, ROM images, both scripts) by file name.
fn inputs(top: &Block) -> Vec<(String, String)> {
    let mut inputs: Vec<(String, String)> = sources(top)
        .into_iter()
        .map(|(n, s)| (n.to_string(), s.to_string()))
        .collect();
    inputs.extend(top.roms.iter().cloned());
    // yosys elaborates every module with its own defaults while reading it, and the loop's
    // NCO and CIC read their ROM images then: give them the images under their default names.
    if top.module == LOOP_TOP {
        let image = |rom: &str| {
            top.roms
                .iter()
                .find(|(name, _)| name.starts_with(rom))
                .map(|(_, text)| text.clone())
                .expect("the loop block carries both ROMs")
        };
        inputs.push(("nco_sine.mem".into(), image("gyro_loop_nco_sine")));
        inputs.push(("cic_taps.mem".into(), image("gyro_loop_cic_taps")));
    }
    inputs.push(("generic.ys".into(), generic_script(top)));
    inputs.push(("xilinx.ys".into(), xilinx_script(top)));
    inputs
}

/// Writes `inputs` into `dir` and runs both flows there.
fn run_in(dir: &Path, inputs: &[(String, String)]) -> Result<Resources> {
    std::fs::create_dir_all(dir).map_err(|e| Error::io(dir, e))?;
    for (name, text) in inputs {
        let path = dir.join(name);
        std::fs::write(&path, text).map_err(|e| Error::io(&path, e))?;
    }
    measure(dir)
}

/// Adds a design's inputs, report files and yosys outputs under `prefix` (`""` or
/// `"gyro_loop/"`).
fn add_design(
    package: &mut Package,
    prefix: &str,
    work: &Path,
    inputs: &[(String, String)],
) -> Result<()> {
    for (name, text) in inputs {
        package.add(format!("{prefix}{name}"), text.as_str());
    }
    for name in [
        "generic.log",
        "xilinx.log",
        "coarse.json",
        "generic.json",
        "xilinx.json",
    ] {
        let path = work.join(name);
        let data = std::fs::read(&path).map_err(|e| Error::io(&path, e))?;
        package.add(format!("{prefix}yosys/{name}"), data);
    }
    Ok(())
}

/// Synthesizes the chain and one gyro's loop for `job` and writes the scripts, logs, stat
/// files, report and manifest to `out` atomically (the loop's under `gyro_loop/`), if `out`
/// may be replaced ([`output_folder::check`], checked first); nothing is written when a check
/// fails.
///
/// # Errors
/// A failed check or a missing yosys ([`Error::Synthesis`]), or an I/O error.
pub fn synthesize(
    job: &Job,
    out: &Path,
    replace: Replace,
    provenance: &Provenance,
) -> Result<Synthesis> {
    output_folder::check(out, Kind::Synth, replace)?;
    let roms = RomImages::new(job, provenance);
    let top = blocks::find(TOP_BLOCK).block(job, &roms);
    let gyro_loop = blocks::find(LOOP_BLOCK).block(job, &roms);
    let chain_inputs = inputs(&top);
    let loop_inputs = inputs(&gyro_loop);

    let work = tempfile::tempdir().map_err(|e| Error::io(Path::new("temporary folder"), e))?;
    let loop_work = work.path().join(LOOP_FOLDER);
    // The two designs are independent: synthesize them side by side.
    let (chain, looped) = std::thread::scope(|scope| {
        let looped = scope.spawn(|| run_in(&loop_work, &loop_inputs));
        let chain = run_in(work.path(), &chain_inputs);
        (chain, looped.join().expect("synthesis does not panic"))
    });
    let synthesis = Synthesis {
        chain: chain?,
        gyro_loop: looped?,
    };

    let mut package = Package::new(Kind::Synth, Vec::new());
    package.add(
        "report.md",
        report(&top, &gyro_loop, &synthesis, provenance),
    );
    add_design(&mut package, "", work.path(), &chain_inputs)?;
    add_design(
        &mut package,
        &format!("{LOOP_FOLDER}/"),
        &loop_work,
        &loop_inputs,
    )?;
    let parameters = |block: &Block| {
        block
            .params
            .iter()
            .map(|p| (p.name.clone(), p.value.clone()))
            .collect::<std::collections::BTreeMap<_, _>>()
    };
    let manifest = serde_json::json!({
        "tool": "gyrofx",
        "version": provenance.version,
        "config_sha256": provenance.config_sha256,
        "config": job.config,
        "top": TOP,
        "parameters": parameters(&top),
        "resources": synthesis.chain,
        "gyro_loop": {
            "top": LOOP_TOP,
            "gyro": "a",
            "folder": LOOP_FOLDER,
            "parameters": parameters(&gyro_loop),
            "resources": synthesis.gyro_loop,
        },
        "files": package.entries(),
    });
    let mut text = serde_json::to_string_pretty(&manifest).expect("manifest serializes");
    text.push('\n');
    package.add(crate::package::MANIFEST, text);
    package.write_atomically(out, replace)?;
    Ok(synthesis)
}
