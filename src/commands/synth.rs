//! `gyrofx synth`: the chain through yosys (generic and Xilinx 7-series) as a structural check,
//! with the resource report, scripts and logs written atomically.

use std::process::ExitCode;

use anyhow::Result;

use gyrofx_codegen::generate::Output;
use gyrofx_codegen::job::Job;
use gyrofx_codegen::synth::{synthesize, LOOP_TOP, TOP};

use super::options::{ConfigSource, OutputFolder};

/// Synthesize the chain with the config's widths in yosys (generic and Xilinx 7-series):
/// fails on a latch, an undriven or multiply-driven net or a missing module; writes the
/// resource report, scripts and logs atomically.
#[derive(clap::Args)]
pub struct Args {
    #[command(flatten)]
    out: OutputFolder,
    #[command(flatten)]
    source: ConfigSource,
    /// No progress spinner (it shows only on a terminal).
    #[arg(long)]
    quiet: bool,
}

/// Synthesizes the chain and prints the resources of both targets.
pub fn run(args: Args) -> Result<ExitCode> {
    let Args {
        out: folder,
        source,
        quiet,
    } = args;
    let out = folder.out.as_path();
    let config = source.load()?;
    let job = Job::new(config)?;
    let provenance = source.provenance(&job, Output::Synthesis);
    let spinner = super::progress::spinner("synth: yosys on the chain and the gyro loop", quiet);
    let synthesis = synthesize(&job, out, folder.replace(), &provenance);
    spinner.finish_and_clear();
    let synthesis = synthesis?;
    println!(
        "synthesis check passed: {TOP}, {LOOP_TOP}; report in {}",
        out.join("report.md").display()
    );
    for (module, resources) in [(TOP, &synthesis.chain), (LOOP_TOP, &synthesis.gyro_loop)] {
        let (g, x) = (&resources.generic, &resources.xilinx);
        println!(
            "{module} generic: {} cells, {} flip-flops, {} multipliers; xilinx 7-series: {} LUTs, {} flip-flops, {} DSP48E1, {} block RAM",
            g.cells, g.flip_flops, g.multipliers, x.luts, x.flip_flops, x.dsp48, x.block_rams
        );
    }
    Ok(ExitCode::SUCCESS)
}
