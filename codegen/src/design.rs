//! A block's design as yosys and nextpnr read it: its RTL (the module's file and its
//! submodules'), the ROM images it reads, and the wrapper that instantiates it with the job's
//! parameters ([`configured_module`]). `synth` and place and route both start from it.

use crate::block::Block;
use crate::hdl;

/// One gyro's loop module, whose submodules read ROM images while yosys elaborates them.
pub const LOOP_TOP: &str = "gyrofx_gyro_loop";

/// The module name of a block's wrapper: the block's module with the job's parameters.
pub fn configured_name(module: &str) -> String {
    format!("{module}_configured")
}

/// Each port connected to the signal of its name.
pub fn connections(block: &Block) -> String {
    let mut names = block.clock_ports().to_vec();
    names.extend(block.inputs.iter().map(|s| s.name));
    names.extend(block.outputs.iter().map(|o| o.signal.name));
    names
        .iter()
        .map(|name| format!("    .{name}({name})"))
        .collect::<Vec<_>>()
        .join(",\n")
}

/// The wrapper synthesized instead of the block's module: the module instantiated with the
/// job's parameters, as the testbenches instantiate it.
pub fn configured_module(block: &Block) -> String {
    let params: Vec<String> = block
        .params
        .iter()
        .map(|p| format!("    .{}({})", p.name, p.value))
        .collect();
    format!(
        "`default_nettype none\n\
         // {module} with the job's parameters, passed on an instance (not chparam: see\n\
         // gyrofx's synth docs) so that yosys computes every width as the simulators do.\n\
         module {name} (\n{ports}\n);\n\
         {module} #(\n{params}\n) configured (\n{connections}\n);\n\
         endmodule\n\
         `default_nettype wire\n",
        module = block.module,
        name = configured_name(block.module),
        ports = block.port_declarations().join(",\n"),
        params = params.join(",\n"),
        connections = connections(block),
    )
}

/// The RTL of the block's module: its file and its submodules' (for the chain, not the mean
/// filter beside it: yosys would load its ROM image while reading it).
pub fn sources(module: &str) -> Vec<&'static (&'static str, &'static str)> {
    hdl::verilog_sources_of(module)
}

/// The file holding [`configured_module`].
pub const CONFIGURED_FILE: &str = "configured.v";

/// A block's design files by name: its RTL (the module's file and its submodules'), the ROM
/// images it reads and the wrapper with the job's parameters ([`configured_module`]).
pub fn design_files(block: &Block) -> Vec<(String, String)> {
    let mut files: Vec<(String, String)> = sources(block.module)
        .into_iter()
        .map(|(n, s)| (n.to_string(), s.to_string()))
        .collect();
    files.extend(block.roms.iter().cloned());
    // yosys elaborates every module with its own defaults while reading it, and the loop's
    // NCO and CIC read their ROM images then: give them the images under their default names.
    if block.module == LOOP_TOP {
        let image = |rom: &str| {
            block
                .roms
                .iter()
                .find(|(name, _)| name.starts_with(rom))
                .map(|(_, text)| text.clone())
                .expect("the loop block carries both ROMs")
        };
        files.push(("nco_sine.mem".into(), image("gyro_loop_nco_sine")));
        files.push(("cic_taps.mem".into(), image("gyro_loop_cic_taps")));
    }
    // Likewise the serial engine inside the folded system: its defaults name the serial
    // chain's images, the system carries its own chain's.
    if block.module == "gyrofx_system_serial" {
        for (default, rom) in [
            ("serial_program.mem", "system_serial_program"),
            ("serial_coefficients.mem", "system_serial_coefficients"),
        ] {
            let image = block
                .roms
                .iter()
                .find(|(name, _)| name.starts_with(rom))
                .map(|(_, text)| text.clone())
                .expect("the folded system carries its chain's ROMs");
            files.push((default.into(), image));
        }
    }
    files.push((CONFIGURED_FILE.into(), configured_module(block)));
    files
}
