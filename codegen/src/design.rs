//! A block's design as yosys and nextpnr read it: its RTL (the module's file and its
//! submodules'), the ROM images it reads, and the wrapper that instantiates it with the job's
//! parameters ([`configured_module`]). `synth` and place and route both start from it.

use crate::block::Block;
use crate::hdl;

/// One gyro's loop module in the parallel architecture.
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
    files.extend(block.elaboration_images.iter().cloned());
    files.push((CONFIGURED_FILE.into(), configured_module(block)));
    files
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::blocks::{checked_job, find, RomImages};
    use crate::text::Provenance;
    use gyrofx_job::config::Config;

    /// A synthesis run gets the ROM images the submodules read under their defaults' names,
    /// as each block declares them: the parallel loop's NCO and CIC images, and the folded
    /// system's own chain program under the serial engine's default names.
    #[test]
    fn the_design_carries_each_submodules_images_under_its_default_names() {
        let provenance = Provenance::for_tests();
        let file = |files: &[(String, String)], name: &str| -> String {
            files
                .iter()
                .find(|(n, _)| n == name)
                .unwrap_or_else(|| panic!("no {name}"))
                .1
                .clone()
        };
        let rom = |block: &Block, prefix: &str| -> String {
            block
                .roms
                .iter()
                .find(|(n, _)| n.starts_with(prefix))
                .unwrap_or_else(|| panic!("no {prefix} ROM"))
                .1
                .clone()
        };
        let job = checked_job(Config::embedded()).unwrap();
        let roms = RomImages::new(&job, &provenance);
        let parallel = find("gyro_loop").block(&job, &roms);
        let files = design_files(&parallel);
        assert_eq!(
            file(&files, "nco_sine.mem"),
            rom(&parallel, "gyro_loop_nco_sine")
        );
        assert_eq!(
            file(&files, "cic_taps.mem"),
            rom(&parallel, "gyro_loop_cic_taps")
        );

        let serial = Config::from_toml("architecture = \"serial\"\n", "test").unwrap();
        let job = checked_job(serial).unwrap();
        let roms = RomImages::new(&job, &provenance);
        let system = find("system").block(&job, &roms);
        assert_eq!(system.module, "gyrofx_system_serial");
        let files = design_files(&system);
        assert_eq!(
            file(&files, "serial_program.mem"),
            rom(&system, "system_serial_program")
        );
        assert_eq!(
            file(&files, "serial_coefficients.mem"),
            rom(&system, "system_serial_coefficients")
        );
        // The folded loop names its images by parameter: nothing under a default name.
        let folded = find("gyro_loop").block(&job, &roms);
        assert!(design_files(&folded)
            .iter()
            .all(|(n, _)| n != "nco_sine.mem"));
    }
}
