//! Synthesis check of the reference RTL with a job's widths: yosys, generic and Xilinx 7-series.
//!
//! The whole chain (`gyrofx_top`) and one gyro's loop (`gyrofx_gyro_loop`) are each elaborated
//! with the job's parameters and ROMs. The check
//! fails on a missing module (`hierarchy -check`), an inferred latch, and on undriven or
//! multiply-driven nets (`check -assert`). Resources come from `stat -json`: generic cells,
//! flip-flops and multipliers (counted before they are merged into `$macc` cells), and the
//! `synth_xilinx` mapping's LUTs, flip-flops, DSP48E1s and block RAMs.

use std::path::Path;

use serde::{Deserialize, Serialize};

use gyrofx_codegen::block::Block;
use gyrofx_codegen::blocks::{self, RomImages};

use crate::place_route;
use crate::place_route::PlaceRequest;
use crate::toolchain::Tool;
use gyrofx_codegen::design::{
    configured_name, connections, design_files, sources, CONFIGURED_FILE,
};
use gyrofx_codegen::output_folder::{self, Kind, Replace};
use gyrofx_codegen::package::Package;
use gyrofx_codegen::text::{fill, Provenance};
use gyrofx_job::error::{Error, Result};
use gyrofx_job::job::Job;

/// Module synthesized: the whole chain.
pub const TOP: &str = "gyrofx_top";
/// Its block in the registry.
const TOP_BLOCK: &str = "top";
/// Its block in the registry.
const LOOP_BLOCK: &str = "gyro_loop";
/// The folder of the loop's scripts, logs and RTL in the synthesis package.
pub const LOOP_FOLDER: &str = "gyro_loop";
/// Its block in the registry.
const SYSTEM_BLOCK: &str = "system";
/// The placed block whose place and route also builds the folded system's netlist.
const SYSTEM_PLACED: &str = "system_serial";
/// The folder of the folded system's design and netlist in the synthesis package.
pub const SYSTEM_FOLDER: &str = "system";

/// Generic (technology-independent) resources of the flattened chain.
#[derive(Clone, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct Generic {
    /// Gate-level cells after `synth`.
    pub cells: u64,
    /// Flip-flops (bits).
    pub flip_flops: u64,
    /// `$mul` cells after coarse optimization: one per multiplier in the RTL.
    pub multipliers: u64,
}

/// Xilinx 7-series estimate from `synth_xilinx`.
#[derive(Clone, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
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
#[derive(Clone, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct Resources {
    /// Generic mapping.
    pub generic: Generic,
    /// Xilinx 7-series mapping.
    pub xilinx: Xilinx,
}

/// How the job's parameters reach the synthesized module.
///
/// yosys 0.23's `chparam` makes the values it sets unsigned, so width arithmetic with a negative
/// intermediate (`P2_I = P2_W − P2_F` in the KF) wraps and the netlist no longer matches the RTL.
/// An instance in a generated wrapper passes them as the simulators do.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Parameters {
    /// An instance with the parameters in [`configured_module`] (the only passing `synth` uses).
    Instance,
    /// `chparam -set` on the module itself: kept so that a test can show the netlist check
    /// catching what it did.
    Chparam,
}

/// The name the synthesized netlist's module gets, under the shell named like the RTL module.
fn netlist_name(module: &str) -> String {
    format!("{module}_netlist")
}

/// The netlist file's first module: named like the RTL module, with its parameters (defaults:
/// the job's values), so the package's testbench instantiates it unchanged. The netlist was
/// synthesized for those values only: any other integer or bit-vector value stops the
/// simulation at time 0 (string parameters name ROM images, whose contents the netlist holds).
pub fn netlist_shell(block: &Block) -> String {
    let declarations: Vec<String> = block
        .params
        .iter()
        .map(|p| {
            let kind = if p.kind.is_empty() {
                String::new()
            } else {
                format!("{} ", p.kind)
            };
            format!("    parameter {kind}{} = {}", p.name, p.value)
        })
        .collect();
    let checks: String = block
        .params
        .iter()
        .filter(|p| !p.kind.is_empty())
        .map(|p| {
            format!(
                "    if ({name} != {value}) begin\n\
                 \x20       $display(\"{module} netlist: parameter {name} is %0d; it was synthesized with {value}\", {name});\n\
                 \x20       $fatal(1);\n\
                 \x20   end\n",
                name = p.name,
                value = p.value,
                module = block.module,
            )
        })
        .collect();
    format!(
        "`timescale 1ns / 1ps\n\
         `default_nettype none\n\
         // {module}: the synthesized netlist ({netlist}, below) behind the RTL module's ports and\n\
         // parameters.\n\
         module {module} #(\n{declarations}\n) (\n{ports}\n);\n\
         initial begin\n{checks}end\n\
         {netlist} netlist (\n{connections}\n);\n\
         endmodule\n\
         `default_nettype wire\n",
        module = block.module,
        netlist = netlist_name(block.module),
        declarations = declarations.join(",\n"),
        ports = block.port_declarations().join(",\n"),
        connections = connections(block),
    )
}

/// The `chparam` lines that give `module` its parameters ([`Parameters::Chparam`]).
fn chparams(module: &str, params: &[(String, String)]) -> String {
    params
        .iter()
        .map(|(name, value)| format!("chparam -set {name} {value} {module}\n"))
        .collect()
}

/// The folder of a design's netlist: `<module>.v`, the shell ([`netlist_shell`]), and
/// `<module>_netlist.v`, yosys's gate-level netlist (plain Verilog: gates as expressions,
/// flip-flops as `always` blocks).
pub const NETLIST_FOLDER: &str = "netlist";

/// The two files of a design's netlist, relative to its synthesis folder: the shell, then the
/// netlist.
pub fn netlist_files(module: &str) -> [String; 2] {
    [
        format!("{NETLIST_FOLDER}/{module}.v"),
        format!("{NETLIST_FOLDER}/{}.v", netlist_name(module)),
    ]
}

/// The script's first lines: read the RTL and elaborate `module` with `params` (name, Verilog
/// value) passed as `parameters` says; then the synthesized design's top (returned).
fn elaborate(
    module: &str,
    params: &[(String, String)],
    parameters: Parameters,
) -> (String, String) {
    let names: Vec<&str> = sources(module).iter().map(|(n, _)| *n).collect();
    match parameters {
        Parameters::Instance => {
            let top = configured_name(module);
            (
                format!(
                    "read_verilog {} {CONFIGURED_FILE}\nhierarchy -check -top {top}\n",
                    names.join(" ")
                ),
                top,
            )
        }
        Parameters::Chparam => (
            format!(
                "read_verilog {}\n{}hierarchy -check -top {module}\n",
                names.join(" "),
                chparams(module, params),
            ),
            module.to_string(),
        ),
    }
}

/// The yosys script of the generic flow for `module` with `params` (name, Verilog value);
/// writes `coarse.json`, `generic.json` and the gate-level netlist
/// (`netlist/<module>_netlist.v`, [`netlist_files`]).
pub fn generic_script(module: &str, params: &[(String, String)], parameters: Parameters) -> String {
    let (elaborate, top) = elaborate(module, params, parameters);
    let [_, netlist] = netlist_files(module);
    fill(
        GENERIC_SCRIPT,
        &[
            ("elaborate", &elaborate),
            ("top", &top),
            ("netlist_module", &netlist_name(module)),
            ("netlist", &netlist),
        ],
    )
}

/// The yosys script of the Xilinx 7-series flow for `module` with `params`; writes
/// `xilinx.json`.
pub fn xilinx_script(module: &str, params: &[(String, String)], parameters: Parameters) -> String {
    let (elaborate, top) = elaborate(module, params, parameters);
    fill(XILINX_SCRIPT, &[("elaborate", &elaborate), ("top", &top)])
}

/// The flows' scripts (`lab/templates/yosys/`): after the elaboration, the generic flow stops at
/// the coarse netlist to count multipliers and check for latches before optimization can hide
/// them, then maps to gates and writes the netlist; the Xilinx flow maps to 7-series cells.
const GENERIC_SCRIPT: &str = include_str!("../templates/yosys/generic.ys");
const XILINX_SCRIPT: &str = include_str!("../templates/yosys/xilinx.ys");

/// The block's parameters as (name, Verilog value).
pub fn parameter_values(block: &Block) -> Vec<(String, String)> {
    block
        .params
        .iter()
        .map(|p| (p.name.clone(), p.value.clone()))
        .collect()
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
    let finished = Tool::Yosys
        .run_in(dir, &["-q", "-l", log, "-s", script])
        .map_err(|e| Error::Synthesis(format!("cannot run yosys (is it installed?): {e}")))?;
    if !finished.success {
        let text = std::fs::read_to_string(dir.join(log)).unwrap_or_default();
        let tail: Vec<&str> = text.lines().rev().take(20).collect();
        let tail: Vec<&str> = tail.into_iter().rev().collect();
        return Err(Error::Synthesis(format!(
            "synthesis check failed ({script}):\n{}\n{}",
            tail.join("\n"),
            finished.stderr
        )));
    }
    Ok(())
}

/// One of the two yosys flows every design goes through.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Flow {
    /// yosys's generic `synth`: cells, flip-flops, multipliers.
    Generic,
    /// `synth_xilinx`: LUTs, flip-flops, DSP48s, block RAMs, carries.
    Xilinx,
}

impl Flow {
    /// Runs the flow in `dir`, which must hold the RTL, the ROM images and the scripts.
    fn run(self, dir: &Path) -> Result<()> {
        match self {
            Flow::Generic => yosys(dir, "generic.ys", "generic.log"),
            Flow::Xilinx => yosys(dir, "xilinx.ys", "xilinx.log"),
        }
    }
}

/// Runs both flows in `dir`, which must hold the RTL, the ROM images and the scripts.
///
/// # Errors
/// [`Error::Synthesis`] when yosys is missing or a check fails (with the log's tail).
pub fn measure(dir: &Path) -> Result<Resources> {
    Flow::Generic.run(dir)?;
    Flow::Xilinx.run(dir)?;
    resources(dir)
}

/// What both flows measured in `dir`, from their statistics files.
fn resources(dir: &Path) -> Result<Resources> {
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
        "yosys, flattened, with the config's parameters ({}), passed on an instance in `{CONFIGURED_FILE}`.\n\
         Checks passed: every module present, no latch, no undriven or multiply-driven net.\n\
         Gate-level netlist: `{NETLIST_FOLDER}/` (`gyrofx verify --out <package> --netlist <this folder>` \
         runs the package's testbench on it).\n\n\
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
    system: Option<(&Block, &Resources)>,
    synthesis: &Synthesis,
    provenance: &Provenance,
) -> String {
    format!(
        "<!-- {} -->\n# Synthesis check: {}\n\n{}\n\
         # Synthesis check: {} (gyro A; files in `{LOOP_FOLDER}/`)\n\n{}\n\
         An estimate before place and route: the ROMs are small enough to map to LUTs, and \
         `synth_xilinx` splits a product wider than 25x18 over several DSP48E1s. A sensor \
         board runs two loops beside the chain.\n",
        provenance.line("").trim_start(),
        top.module,
        report_section(top, &synthesis.chain),
        gyro_loop.module,
        report_section(gyro_loop, &synthesis.gyro_loop),
    ) + &system.map_or(String::new(), |(block, resources)| {
        format!(
            "\n# Synthesis check: {} (both folded loops and the serial chain; files in \
             `{SYSTEM_FOLDER}/`)\n\n{}",
            block.module,
            report_section(block, resources)
        )
    }) + &place_route_section(&synthesis.placements)
}

/// The report's place-and-route section (empty when nothing was placed).
fn place_route_section(placements: &[place_route::Placement]) -> String {
    if placements.is_empty() {
        return String::new();
    }
    format!(
        "\n# Place and route\n\n\
         Each block alone with the config's parameters, inside a harness that feeds its inputs \
         from one shift register and shifts its captured outputs out (4 pins; every path register \
         to register). LUT, FF, DSP and BRAM count the block's own cells (yosys `stat` of its \
         module, kept apart from the harness); fits and Fmax come from nextpnr (seed 1) on \
         block and harness together: iCE40 through the system's yosys `synth_ice40` and \
         nextpnr-ice40, ECP5 through YoWASP's yosys `synth_ecp5` and nextpnr-ecp5 (Debian has \
         no nextpnr-ecp5). Xilinx: the system yosys's `synth_xilinx` figures against a \
         {xilinx}; no open place and route for 7-series is available here, so no Fmax. A \
         sample needs `clocks/sample` clocks; the max sample rate is Fmax over that. Files: \
         `{folder}/<block>/<target>/` (yosys statistics `stat.json`, nextpnr's `report.json` \
         and log; `run.sh`, run from the block's folder, re-derives them and writes yosys's \
         log).\n\n{tools}\n{table}\n\
         Critical paths (nextpnr; names inside the block, ports of the block by their name):\n\n{paths}",
        xilinx = place_route::Target::Xilinx.device().name,
        folder = place_route::FOLDER,
        tools = place_route::tools_table(placements),
        table = place_route::table(placements),
        paths = place_route::critical_paths(placements),
    )
}

/// What `gyrofx synth` measured: the chain and one gyro's loop.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct Synthesis {
    /// The chain's module: `gyrofx_top`, or `gyrofx_top_serial` with
    /// `architecture = "serial"`.
    #[serde(skip)]
    pub chain_module: &'static str,
    /// The chain.
    pub chain: Resources,
    /// The loop's module: `gyrofx_gyro_loop`, or `gyrofx_gyro_loop_serial` (folded).
    #[serde(skip)]
    pub loop_module: &'static str,
    /// `gyrofx_gyro_loop` (gyro A's parameters).
    pub gyro_loop: Resources,
    /// `gyrofx_system_serial`, when the folded system was placed (its netlist is built then:
    /// its flows take minutes, which its place and route has already taken).
    pub system: Option<Resources>,
    /// Its module, when it was synthesized.
    #[serde(skip)]
    pub system_module: Option<&'static str>,
    /// Each placed block on each target (none unless asked for).
    pub placements: Vec<place_route::Placement>,
}

/// One design's inputs (RTL, ROM images, wrapper, netlist shell, both scripts) by file name.
fn inputs(top: &Block) -> Vec<(String, String)> {
    let mut inputs = design_files(top);
    let [shell, _] = netlist_files(top.module);
    inputs.push((shell, netlist_shell(top)));
    let params = parameter_values(top);
    inputs.push((
        "generic.ys".into(),
        generic_script(top.module, &params, Parameters::Instance),
    ));
    inputs.push((
        "xilinx.ys".into(),
        xilinx_script(top.module, &params, Parameters::Instance),
    ));
    inputs
}

/// Writes `inputs` into `dir` (`work`, or a folder below it).
fn write_inputs(work: &Path, dir: &Path, inputs: &[(String, String)]) -> Result<()> {
    let netlists = dir.join(NETLIST_FOLDER);
    // Below the work folder only, never the work folder itself: after a signal has removed
    // it, this fails instead of bringing it back to be left behind.
    output_folder::create_below(work, &netlists).map_err(|e| Error::io(&netlists, e))?;
    for (name, text) in inputs {
        let path = dir.join(name);
        std::fs::write(&path, text).map_err(|e| Error::io(&path, e))?;
    }
    Ok(())
}

/// One piece of `synth`'s work; all of them run side by side in one pool.
#[derive(Clone, Copy, Debug)]
enum Task<'a> {
    /// A yosys flow on the design whose inputs are in this folder.
    Flow(&'a Path, Flow),
    /// One block on one target.
    Place(place_route::Task),
}

/// Runs `inputs` through both flows in `dir` (`work`, or a folder below it).
fn run_in(work: &Path, dir: &Path, inputs: &[(String, String)]) -> Result<Resources> {
    write_inputs(work, dir, inputs)?;
    measure(dir)
}

/// Adds a design's inputs, report files, yosys outputs and netlist under `prefix` (`""` or
/// `"gyro_loop/"`).
fn add_design(
    package: &mut Package,
    prefix: &str,
    work: &Path,
    block: &Block,
    inputs: &[(String, String)],
) -> Result<()> {
    let [_, netlist] = netlist_files(block.module);
    let path = work.join(&netlist);
    let data = std::fs::read(&path).map_err(|e| Error::io(&path, e))?;
    package.add(format!("{prefix}{netlist}"), data);
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

/// Synthesizes the chain and one gyro's loop for `job`, places and routes the blocks `place`
/// asks for, and writes the scripts, logs, stat files, report and manifest to `out`
/// atomically (the loop's under `gyro_loop/`, the placements' under `place_and_route/`), if
/// `out` may be replaced ([`output_folder::check`], checked first); nothing is written when a
/// check fails.
///
/// # Errors
/// A failed check or a missing yosys or nextpnr ([`Error::Synthesis`]), or an I/O error.
pub fn synthesize(
    job: &Job,
    out: &Path,
    replace: Replace,
    provenance: &Provenance,
    place: &PlaceRequest,
) -> Result<Synthesis> {
    output_folder::check(out, Kind::Synth, replace)?;
    let tools = place_route::check_tools(&place.targets)?;
    let roms = RomImages::new(job, provenance);
    let top = blocks::find(TOP_BLOCK).block(job, &roms);
    let gyro_loop = blocks::find(LOOP_BLOCK).block(job, &roms);
    let chain_inputs = inputs(&top);
    let loop_inputs = inputs(&gyro_loop);
    // The folded system (the job has its chain program in the serial architecture).
    let system = (job.system_serial.is_some()
        && !place.targets.is_empty()
        && place.blocks.contains(&SYSTEM_PLACED))
    .then(|| blocks::find(SYSTEM_BLOCK).block(job, &roms));
    let system_inputs = system.as_ref().map(inputs);

    let work = output_folder::WorkFolder::new()
        .map_err(|e| Error::io(Path::new("temporary folder"), e))?;
    let loop_work = work.path().join(LOOP_FOLDER);
    let system_work = work.path().join(SYSTEM_FOLDER);
    write_inputs(work.path(), &loop_work, &loop_inputs)?;
    write_inputs(work.path(), work.path(), &chain_inputs)?;
    if let Some(system_inputs) = &system_inputs {
        write_inputs(work.path(), &system_work, system_inputs)?;
    }
    let placing = if place.targets.is_empty() {
        None
    } else {
        Some(place_route::Prepared::new(
            job,
            &roms,
            provenance,
            place,
            tools,
            work.path(),
        )?)
    };
    // The longest first (the loop's flows, over a minute each at the defaults), so that none
    // runs alone at the end.
    let mut tasks = Vec::new();
    if system.is_some() {
        tasks.extend([
            Task::Flow(&system_work, Flow::Generic),
            Task::Flow(&system_work, Flow::Xilinx),
        ]);
    }
    tasks.extend([
        Task::Flow(&loop_work, Flow::Generic),
        Task::Flow(&loop_work, Flow::Xilinx),
        Task::Flow(work.path(), Flow::Generic),
        Task::Flow(work.path(), Flow::Xilinx),
    ]);
    tasks.extend(placing.iter().flat_map(|p| p.tasks()).map(Task::Place));
    let placed = crate::pool::try_map(&tasks, place.jobs, |task| match *task {
        Task::Flow(dir, flow) => flow.run(dir).map(|()| None),
        Task::Place(task) => placing
            .as_ref()
            .expect("only placing has place tasks")
            .place(task)
            .map(Some),
    })?;
    let synthesis = Synthesis {
        chain_module: top.module,
        chain: resources(work.path())?,
        loop_module: gyro_loop.module,
        gyro_loop: resources(&loop_work)?,
        system: system
            .as_ref()
            .map(|_| resources(&system_work))
            .transpose()?,
        system_module: system.as_ref().map(|block| block.module),
        placements: placed.into_iter().flatten().collect(),
    };

    let mut package = Package::new(Kind::Synth, Vec::new());
    if let Some(placing) = &placing {
        placing.add_to(&mut package)?;
    }
    package.add(
        "report.md",
        report(
            &top,
            &gyro_loop,
            system.as_ref().zip(synthesis.system.as_ref()),
            &synthesis,
            provenance,
        ),
    );
    if !synthesis.placements.is_empty() {
        package.add(
            "place_and_route.md",
            place_route::page(
                &synthesis.placements,
                &format!("<!-- {} -->", provenance.line("").trim()),
            ),
        );
    }
    add_design(&mut package, "", work.path(), &top, &chain_inputs)?;
    add_design(
        &mut package,
        &format!("{LOOP_FOLDER}/"),
        &loop_work,
        &gyro_loop,
        &loop_inputs,
    )?;
    if let (Some(system), Some(system_inputs)) = (&system, &system_inputs) {
        add_design(
            &mut package,
            &format!("{SYSTEM_FOLDER}/"),
            &system_work,
            system,
            system_inputs,
        )?;
    }
    let parameters_of = |block: &Block| {
        parameter_values(block)
            .into_iter()
            .collect::<std::collections::BTreeMap<_, _>>()
    };
    let mut netlists = vec![
        serde_json::json!({"block": TOP_BLOCK, "module": top.module, "files": netlist_files(top.module)}),
        serde_json::json!({"block": LOOP_BLOCK, "module": gyro_loop.module, "files": netlist_files(gyro_loop.module).map(|f| format!("{LOOP_FOLDER}/{f}"))}),
    ];
    if let Some(system) = &system {
        netlists.push(serde_json::json!({
            "block": SYSTEM_BLOCK,
            "module": system.module,
            "files": netlist_files(system.module).map(|f| format!("{SYSTEM_FOLDER}/{f}")),
        }));
    }
    let manifest = serde_json::json!({
        "tool": "gyrofx",
        "version": provenance.version,
        "config_sha256": provenance.config_sha256,
        "config": job.config,
        "top": top.module,
        "parameters": parameters_of(&top),
        "resources": synthesis.chain,
        "gyro_loop": {
            "top": gyro_loop.module,
            "gyro": "a",
            "folder": LOOP_FOLDER,
            "parameters": parameters_of(&gyro_loop),
            "resources": synthesis.gyro_loop,
        },
        "netlists": netlists,
        "netlist_cells": "yosys's internal gate library: simulate with its simcells.v",
        "place_and_route": synthesis.placements,
        "files": package.entries(),
    });
    let mut text = serde_json::to_string_pretty(&manifest).expect("manifest serializes");
    text.push('\n');
    package.add(gyrofx_codegen::output_folder::MANIFEST, text);
    package.write_atomically(out, replace)?;
    Ok(synthesis)
}

/// A design [`cost`] synthesizes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Design {
    /// `gyrofx_top`: sequencer, estimator, calibration, KF.
    Chain,
    /// `gyrofx_gyro_loop` with gyro A's parameters.
    GyroLoop,
}

/// The inputs of one design of `job` (RTL, ROM images, wrapper, shell, scripts) by file name.
/// ROM images carry a provenance comment that [`cache_key`] leaves out.
pub fn design_inputs(job: &Job, design: Design) -> Vec<(String, String)> {
    let provenance = Provenance {
        version: env!("CARGO_PKG_VERSION").to_string(),
        command: "gyrofx explore".to_string(),
        config_sha256: "0".repeat(64),
    };
    let roms = RomImages::new(job, &provenance);
    let name = match design {
        Design::Chain => TOP_BLOCK,
        Design::GyroLoop => LOOP_BLOCK,
    };
    inputs(&blocks::find(name).block(job, &roms))
}

/// What identifies a synthesis result: the SHA-256 (hex) of every input file's name and
/// content, comment lines left out (two jobs with the same RTL, parameters and ROM words get the
/// same key), and the yosys version it runs.
pub fn cache_key(inputs: &[(String, String)]) -> String {
    let mut text = String::new();
    text.push_str(&yosys_version());
    let mut sorted: Vec<&(String, String)> = inputs.iter().collect();
    sorted.sort();
    for (name, content) in sorted {
        text.push_str(name);
        text.push('\n');
        for line in content
            .lines()
            .filter(|l| !l.trim_start().starts_with("//"))
        {
            text.push_str(line);
            text.push('\n');
        }
    }
    gyrofx_job::hash::sha256_hex(text.as_bytes())
}

/// `yosys -V`, or empty when yosys is missing (the synthesis then fails with its own error).
fn yosys_version() -> String {
    static VERSION: std::sync::OnceLock<String> = std::sync::OnceLock::new();
    VERSION
        .get_or_init(|| Tool::Yosys.version().unwrap_or_default())
        .clone()
}

/// Synthesizes `inputs` ([`design_inputs`]) in a temporary folder, removed afterwards, and
/// returns what both flows measured.
///
/// # Errors
/// Those of [`measure`].
pub fn cost(inputs: &[(String, String)]) -> Result<Resources> {
    let work = output_folder::WorkFolder::new()
        .map_err(|e| Error::io(Path::new("temporary folder"), e))?;
    run_in(work.path(), work.path(), inputs)
}

#[cfg(test)]
mod tests {
    /// A flow that starts after a signal has removed the work folder fails, and does not bring
    /// the folder back to be left behind.
    #[test]
    fn a_removed_work_folder_is_not_recreated() {
        let dir = tempfile::tempdir().unwrap();
        let work = dir.path().join("work");
        let error = super::run_in(&work, &work.join(super::LOOP_FOLDER), &[]).unwrap_err();
        assert!(error.to_string().contains("netlist"), "{error}");
        assert!(!work.exists(), "the work folder came back");
    }
}
