//! The reference RTL embedded in the binary: every Verilog-2001 and VHDL-2008 source of `hdl/`,
//! in compile order (a unit before its users), and the sources one module needs.

/// The reference RTL, embedded so that every package is self-contained.
pub const RTL_SOURCES: [(&str, &str); 20] = [
    (
        "gyrofx_quantize.v",
        include_str!("../../hdl/gyrofx_quantize.v"),
    ),
    (
        "gyrofx_spacing_check.v",
        include_str!("../../hdl/gyrofx_spacing_check.v"),
    ),
    ("gyrofx_kf.v", include_str!("../../hdl/gyrofx_kf.v")),
    (
        "gyrofx_sequencer.v",
        include_str!("../../hdl/gyrofx_sequencer.v"),
    ),
    (
        "gyrofx_bias_estimator.v",
        include_str!("../../hdl/gyrofx_bias_estimator.v"),
    ),
    (
        "gyrofx_calibration.v",
        include_str!("../../hdl/gyrofx_calibration.v"),
    ),
    ("gyrofx_top.v", include_str!("../../hdl/gyrofx_top.v")),
    (
        "gyrofx_serial_engine.v",
        include_str!("../../hdl/gyrofx_serial_engine.v"),
    ),
    (
        "gyrofx_top_serial.v",
        include_str!("../../hdl/gyrofx_top_serial.v"),
    ),
    (
        "gyrofx_mean_filter.v",
        include_str!("../../hdl/gyrofx_mean_filter.v"),
    ),
    (
        "gyrofx_mean_filter_serial.v",
        include_str!("../../hdl/gyrofx_mean_filter_serial.v"),
    ),
    ("gyrofx_nco.v", include_str!("../../hdl/gyrofx_nco.v")),
    (
        "gyrofx_demodulator.v",
        include_str!("../../hdl/gyrofx_demodulator.v"),
    ),
    ("gyrofx_pi.v", include_str!("../../hdl/gyrofx_pi.v")),
    ("gyrofx_cic.v", include_str!("../../hdl/gyrofx_cic.v")),
    (
        "gyrofx_gyro_loop.v",
        include_str!("../../hdl/gyrofx_gyro_loop.v"),
    ),
    (
        "gyrofx_gyro_loop_serial.v",
        include_str!("../../hdl/gyrofx_gyro_loop_serial.v"),
    ),
    (
        "gyrofx_gyro_pair_serial.v",
        include_str!("../../hdl/gyrofx_gyro_pair_serial.v"),
    ),
    ("gyrofx_system.v", include_str!("../../hdl/gyrofx_system.v")),
    (
        "gyrofx_system_serial.v",
        include_str!("../../hdl/gyrofx_system_serial.v"),
    ),
];

/// The sources of `sources` (file name, text) that `roots` need: their files, and those of
/// every unit `references` finds named in a needed file's text, transitively, in the order of
/// `sources` (compile order). `extension` turns a unit name into its file name.
fn closure(
    sources: &'static [(&'static str, &'static str)],
    extension: &str,
    roots: &[&str],
    references: fn(&str) -> Vec<String>,
) -> Vec<&'static (&'static str, &'static str)> {
    let file = |unit: &str| format!("{unit}{extension}");
    let mut needed: Vec<String> = roots.iter().map(|r| r.to_string()).collect();
    let mut next = 0;
    while next < needed.len() {
        let name = file(&needed[next]);
        next += 1;
        let Some((_, source)) = sources.iter().find(|(n, _)| *n == name) else {
            continue;
        };
        for unit in references(source) {
            if unit.starts_with("gyrofx_") && !needed.contains(&unit) {
                needed.push(unit);
            }
        }
    }
    sources
        .iter()
        .filter(|(n, _)| needed.iter().any(|m| file(m) == *n))
        .collect()
}

/// The Verilog sources `module` is made of: its own file and those of every module it
/// instantiates, transitively, in [`RTL_SOURCES`] order. Found from the RTL text itself (an
/// instance line starts with the module name and ` #(`), so it cannot drift from the RTL.
pub fn verilog_sources_of(module: &str) -> Vec<&'static (&'static str, &'static str)> {
    closure(&RTL_SOURCES, ".v", &[module], |source| {
        source
            .lines()
            .filter_map(|line| line.split_once(" #("))
            .map(|(instance, _)| instance.trim().to_string())
            .collect()
    })
}

/// The VHDL sources a testbench of `module` analyses: the module's file, the testbench package,
/// and every unit they name as `work.<unit>` (entities they instantiate, packages they use),
/// transitively, in [`VHDL_SOURCES`] (compile) order. Read from the VHDL text itself, like
/// [`verilog_sources_of`], so it cannot drift from the RTL. Analysing these alone, not the
/// whole `hdl/`, is what makes a short GHDL run short: analysis took most of it.
pub fn vhdl_sources_of(module: &str) -> Vec<&'static (&'static str, &'static str)> {
    closure(
        &VHDL_SOURCES,
        ".vhd",
        &[module, "gyrofx_testbench_pkg"],
        |source| {
            source
                .match_indices("work.")
                .map(|(start, _)| {
                    source[start + "work.".len()..]
                        .chars()
                        .take_while(|c| c.is_ascii_alphanumeric() || *c == '_')
                        .collect()
                })
                .collect()
        },
    )
}

/// The reference RTL in VHDL-2008, in compile order (packages first), and the package the VHDL
/// testbenches share (last: simulation only).
pub const VHDL_SOURCES: [(&str, &str); 22] = [
    (
        "gyrofx_mem_pkg.vhd",
        include_str!("../../hdl/gyrofx_mem_pkg.vhd"),
    ),
    (
        "gyrofx_quantize.vhd",
        include_str!("../../hdl/gyrofx_quantize.vhd"),
    ),
    (
        "gyrofx_spacing_check.vhd",
        include_str!("../../hdl/gyrofx_spacing_check.vhd"),
    ),
    ("gyrofx_kf.vhd", include_str!("../../hdl/gyrofx_kf.vhd")),
    (
        "gyrofx_sequencer.vhd",
        include_str!("../../hdl/gyrofx_sequencer.vhd"),
    ),
    (
        "gyrofx_bias_estimator.vhd",
        include_str!("../../hdl/gyrofx_bias_estimator.vhd"),
    ),
    (
        "gyrofx_calibration.vhd",
        include_str!("../../hdl/gyrofx_calibration.vhd"),
    ),
    ("gyrofx_top.vhd", include_str!("../../hdl/gyrofx_top.vhd")),
    (
        "gyrofx_mean_filter.vhd",
        include_str!("../../hdl/gyrofx_mean_filter.vhd"),
    ),
    (
        "gyrofx_mean_filter_serial.vhd",
        include_str!("../../hdl/gyrofx_mean_filter_serial.vhd"),
    ),
    ("gyrofx_nco.vhd", include_str!("../../hdl/gyrofx_nco.vhd")),
    (
        "gyrofx_demodulator.vhd",
        include_str!("../../hdl/gyrofx_demodulator.vhd"),
    ),
    ("gyrofx_pi.vhd", include_str!("../../hdl/gyrofx_pi.vhd")),
    ("gyrofx_cic.vhd", include_str!("../../hdl/gyrofx_cic.vhd")),
    (
        "gyrofx_gyro_loop.vhd",
        include_str!("../../hdl/gyrofx_gyro_loop.vhd"),
    ),
    (
        "gyrofx_gyro_loop_serial.vhd",
        include_str!("../../hdl/gyrofx_gyro_loop_serial.vhd"),
    ),
    (
        "gyrofx_gyro_pair_serial.vhd",
        include_str!("../../hdl/gyrofx_gyro_pair_serial.vhd"),
    ),
    (
        "gyrofx_system.vhd",
        include_str!("../../hdl/gyrofx_system.vhd"),
    ),
    (
        "gyrofx_serial_engine.vhd",
        include_str!("../../hdl/gyrofx_serial_engine.vhd"),
    ),
    (
        "gyrofx_top_serial.vhd",
        include_str!("../../hdl/gyrofx_top_serial.vhd"),
    ),
    (
        "gyrofx_system_serial.vhd",
        include_str!("../../hdl/gyrofx_system_serial.vhd"),
    ),
    (
        "gyrofx_testbench_pkg.vhd",
        include_str!("../../hdl/gyrofx_testbench_pkg.vhd"),
    ),
];

#[cfg(test)]
mod tests {
    use super::{verilog_sources_of, vhdl_sources_of};

    fn names(module: &str) -> Vec<&'static str> {
        verilog_sources_of(module).iter().map(|(n, _)| *n).collect()
    }

    /// The chain's sources are found by following its instances: every submodule and the
    /// requantizer, not the mean filter beside it; a leaf block needs only itself and the
    /// requantizer.
    #[test]
    fn a_modules_sources_follow_its_instances() {
        assert_eq!(
            names("gyrofx_top"),
            [
                "gyrofx_quantize.v",
                "gyrofx_spacing_check.v",
                "gyrofx_kf.v",
                "gyrofx_sequencer.v",
                "gyrofx_bias_estimator.v",
                "gyrofx_calibration.v",
                "gyrofx_top.v",
            ]
        );
        assert_eq!(
            names("gyrofx_mean_filter"),
            ["gyrofx_quantize.v", "gyrofx_mean_filter.v"]
        );
        assert_eq!(
            names("gyrofx_mean_filter_serial"),
            ["gyrofx_quantize.v", "gyrofx_mean_filter_serial.v"]
        );
        assert_eq!(names("gyrofx_sequencer"), ["gyrofx_sequencer.v"]);
        assert_eq!(
            names("gyrofx_gyro_loop"),
            [
                "gyrofx_quantize.v",
                "gyrofx_spacing_check.v",
                "gyrofx_nco.v",
                "gyrofx_demodulator.v",
                "gyrofx_pi.v",
                "gyrofx_cic.v",
                "gyrofx_gyro_loop.v",
            ]
        );
    }

    /// A VHDL testbench analyses its DUT's units, the packages they use and the testbench
    /// package, in compile order: the KF's bench not the loop's files, the system's every
    /// file but the serial chain's and the mean filter (beside the chain, not in it).
    #[test]
    fn a_vhdl_benchs_sources_follow_its_instances_and_packages() {
        let names = |module: &str| -> Vec<&'static str> {
            vhdl_sources_of(module).iter().map(|(n, _)| *n).collect()
        };
        assert_eq!(
            names("gyrofx_kf"),
            [
                "gyrofx_mem_pkg.vhd",
                "gyrofx_quantize.vhd",
                "gyrofx_spacing_check.vhd",
                "gyrofx_kf.vhd",
                "gyrofx_testbench_pkg.vhd",
            ]
        );
        assert_eq!(
            names("gyrofx_sequencer"),
            [
                "gyrofx_mem_pkg.vhd",
                "gyrofx_sequencer.vhd",
                "gyrofx_testbench_pkg.vhd",
            ]
        );
        let system = names("gyrofx_system");
        let left_out = [
            "gyrofx_gyro_loop_serial.vhd",
            "gyrofx_gyro_pair_serial.vhd",
            "gyrofx_mean_filter.vhd",
            "gyrofx_mean_filter_serial.vhd",
            "gyrofx_serial_engine.vhd",
            "gyrofx_top_serial.vhd",
            "gyrofx_system_serial.vhd",
        ];
        let expected: Vec<&str> = super::VHDL_SOURCES
            .iter()
            .map(|(n, _)| *n)
            .filter(|n| !left_out.contains(n))
            .collect();
        assert_eq!(system, expected);
        // The folded system: the folded pair and the serial chain's sequencer and engine, not
        // the parallel loops and chain, nor the one-gyro folded loop and gyrofx_top_serial.
        let folded = names("gyrofx_system_serial");
        for file in [
            "gyrofx_gyro_pair_serial.vhd",
            "gyrofx_serial_engine.vhd",
            "gyrofx_sequencer.vhd",
            "gyrofx_spacing_check.vhd",
        ] {
            assert!(folded.contains(&file), "{file}: {folded:?}");
        }
        for file in [
            "gyrofx_gyro_loop.vhd",
            "gyrofx_gyro_loop_serial.vhd",
            "gyrofx_top.vhd",
            "gyrofx_top_serial.vhd",
            "gyrofx_system.vhd",
        ] {
            assert!(!folded.contains(&file), "{file}: {folded:?}");
        }
        assert_eq!(folded.last(), Some(&"gyrofx_testbench_pkg.vhd"));
    }
}
