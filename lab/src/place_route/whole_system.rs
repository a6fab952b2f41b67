//! The whole system on one part: the folded system (`system_serial`: both gyros' loops, the
//! serial chain) with the serial mean filter on its published rate, in one top behind one
//! harness, as a sensor board carries them (issue 33's goal: all of it on one UP5K). Each
//! block is proven bit-exact by its own vectors; this design only measures what they take
//! together, so it has no vectors of its own.

use gyrofx_codegen::block::Block;
use gyrofx_codegen::design;
use gyrofx_codegen::text::fill;
use gyrofx_model::fx::Format;

use super::Design;

/// The name it places under (`synth --blocks whole_system_serial`).
pub const NAME: &str = "whole_system_serial";
/// The placed system it wires the mean filter to.
pub const SYSTEM: &str = "system_serial";
/// The placed mean filter it wires to the system.
pub const MEAN_FILTER: &str = "mean_filter_serial";

/// Its top module.
const TOP: &str = "gyrofx_whole_system_serial";
/// The file holding it.
const TOP_FILE: &str = "whole_system_serial.v";
const TEMPLATE: &str = include_str!("../../templates/place_route/whole_system.v");

/// The system's ports that feed the mean filter: its rate and the pulse that publishes it.
const RATE: &str = "rate_out";
const PUBLISHED: &str = "out_valid";
/// The mean filter's sample input and the prefix its outputs take in the top.
const SAMPLE: &str = "x";
const PREFIX: &str = "mean_filter_";

/// The whole system of `system` (the serial system block) and `mean_filter` (the serial mean
/// filter block): both configured wrappers, renamed apart, and a top wiring the system's
/// published rate into the mean filter. Its ports are the system's and the mean filter's
/// outputs, prefixed `mean_filter_`.
///
/// # Panics
/// If the blocks lack the ports it wires (`rate_out`, `out_valid`; `x`), or share a file name
/// with different contents: both are fixed by the registry, not by a config.
pub fn design(system: &Block, mean_filter: &Block) -> Design {
    let parts = [Design::of_block(system), Design::of_block(mean_filter)];
    let configured_file = |part: &Design| format!("{}_configured.v", part.name);
    let mut sources: Vec<String> = Vec::new();
    let mut files: Vec<(String, String)> = Vec::new();
    for part in &parts {
        // The RTL both read once; the configured wrappers after it (below).
        for source in part
            .sources
            .iter()
            .filter(|s| *s != design::CONFIGURED_FILE)
        {
            if !sources.contains(source) {
                sources.push(source.clone());
            }
        }
        for (name, text) in &part.files {
            let name = if name == design::CONFIGURED_FILE {
                configured_file(part)
            } else {
                name.clone()
            };
            match files.iter().find(|(n, _)| *n == name) {
                Some((_, other)) => assert!(
                    other == text,
                    "{} and {} both have a file {name} with other contents",
                    system.name,
                    mean_filter.name
                ),
                None => files.push((name, text.clone())),
            }
        }
    }
    // The configured wrappers, then the top.
    sources.extend(parts.iter().map(configured_file));
    sources.push(TOP_FILE.into());
    let [system_part, mean_filter_part] = parts;
    let filtered: Vec<(String, u32)> = mean_filter_part
        .outputs
        .iter()
        .map(|(name, width)| (format!("{PREFIX}{name}"), *width))
        .collect();
    let mut outputs = system_part.outputs.clone();
    outputs.extend(filtered);
    let rate = system
        .outputs
        .iter()
        .find(|o| o.signal.name == RATE)
        .unwrap_or_else(|| panic!("{} has no {RATE}", system.name))
        .signal
        .format;
    let sample = mean_filter
        .inputs
        .iter()
        .find(|s| s.name == SAMPLE)
        .unwrap_or_else(|| panic!("{} has no {SAMPLE}", mean_filter.name))
        .format;
    assert!(
        system.outputs.iter().any(|o| o.signal.name == PUBLISHED),
        "{} has no {PUBLISHED}",
        system.name
    );
    let top = top_module(&system_part, &mean_filter_part, &outputs, rate, sample);
    files.push((TOP_FILE.into(), top));
    Design {
        name: NAME,
        module: "gyrofx_system_serial + gyrofx_mean_filter_serial",
        top: TOP.into(),
        sources,
        files,
        inputs: system_part.inputs,
        outputs,
        clocked: true,
        clocks_per_sample: system_part.clocks_per_sample,
    }
}

/// The top: `outputs` are the system's, then the mean filter's prefixed.
fn top_module(
    system: &Design,
    mean_filter: &Design,
    outputs: &[(String, u32)],
    rate: Format,
    sample: Format,
) -> String {
    let declare = |direction: &str, (name, width): &(String, u32)| {
        if *width > 1 {
            format!("    {direction} wire [{}:0] {name}", width - 1)
        } else {
            format!("    {direction} wire {name}")
        }
    };
    let mut ports: Vec<String> = ["clk", "rst", "ce"]
        .iter()
        .map(|n| format!("    input wire {n}"))
        .collect();
    ports.extend(system.inputs.iter().map(|p| declare("input", p)));
    ports.extend(outputs.iter().map(|p| declare("output", p)));
    let connect = |names: &mut dyn Iterator<Item = (&str, String)>| {
        names
            .map(|(port, net)| format!("    .{port}({net})"))
            .collect::<Vec<_>>()
            .join(",\n")
    };
    let system_ports = connect(
        &mut ["clk", "rst", "ce"]
            .into_iter()
            .map(|n| (n, n.to_string()))
            .chain(system.inputs.iter().map(|(n, _)| (n.as_str(), n.clone())))
            .chain(system.outputs.iter().map(|(n, _)| (n.as_str(), n.clone()))),
    );
    let mean_filter_ports = connect(
        &mut mean_filter
            .outputs
            .iter()
            .map(|(n, _)| (n.as_str(), format!("{PREFIX}{n}"))),
    );
    fill(
        TEMPLATE,
        &[
            ("name", NAME),
            ("system", system.module),
            ("mean_filter", mean_filter.module),
            ("top", TOP),
            ("ports", &ports.join(",\n")),
            ("system_top", &system.top),
            ("system_ports", &system_ports),
            ("mean_filter_top", &mean_filter.top),
            ("x", &aligned(RATE, rate, sample)),
            ("mean_filter_ports", &mean_filter_ports),
        ],
    )
}

/// The Verilog expression of the signed signal `name` in format `from` as format `to`: its
/// binary point aligned (LSBs dropped by truncation or zeros appended), then sign-extended or
/// its top bits dropped. The default config's rate and the mean filter's input share one
/// format: the signal itself.
fn aligned(name: &str, from: Format, to: Format) -> String {
    if from.width == to.width && from.frac == to.frac {
        return name.to_string();
    }
    let width = |w: i64| u32::try_from(w).expect("a width fits u32");
    let shift = i64::from(to.frac) - i64::from(from.frac);
    let (from_width, to_width) = (i64::from(from.width), i64::from(to.width));
    // The bits kept: name[top:low], then `zeros` zero bits.
    let low = (-shift).clamp(0, from_width);
    let zeros = shift.max(0);
    let available = from_width - low + zeros;
    let mut parts: Vec<String> = Vec::new();
    let top = if available >= to_width {
        (low + to_width - zeros - 1).min(from_width - 1)
    } else {
        let extend = to_width - available;
        parts.push(format!(
            "{{{}{{{name}[{}]}}}}",
            width(extend),
            from_width - 1
        ));
        from_width - 1
    };
    let kept_zeros = zeros.min(to_width);
    if top >= low && to_width > zeros {
        parts.push(format!("{name}[{top}:{low}]"));
    }
    if kept_zeros > 0 {
        parts.push(format!("{}'d0", width(kept_zeros)));
    }
    format!("{{{}}}", parts.join(", "))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn format(width: u32, frac: i32) -> Format {
        Format::new(true, width, frac).unwrap()
    }

    /// Each alignment, checked as the bits it keeps: the same format passes the signal; more
    /// fraction bits append zeros; fewer drop LSBs; a wider word sign-extends, a narrower one
    /// drops the top.
    #[test]
    fn a_rate_is_aligned_to_the_mean_filters_input_format() {
        assert_eq!(aligned("r", format(24, 14), format(24, 14)), "r");
        assert_eq!(
            aligned("r", format(24, 14), format(24, 16)),
            "{r[21:0], 2'd0}"
        );
        assert_eq!(
            aligned("r", format(24, 14), format(24, 12)),
            "{{2{r[23]}}, r[23:2]}"
        );
        assert_eq!(
            aligned("r", format(24, 14), format(28, 14)),
            "{{4{r[23]}}, r[23:0]}"
        );
        assert_eq!(aligned("r", format(24, 14), format(20, 14)), "{r[19:0]}");
        assert_eq!(
            aligned("r", format(24, 14), format(30, 16)),
            "{{4{r[23]}}, r[23:0], 2'd0}"
        );
        assert_eq!(aligned("r", format(24, 14), format(20, 10)), "{r[23:4]}");
    }
}

#[cfg(test)]
mod design_tests {
    use super::super::{harness, PlaceRequest, Prepared, FOLDER};
    use super::*;
    use gyrofx_codegen::blocks::RomImages;
    use gyrofx_codegen::text::Provenance;
    use gyrofx_job::config::Config;
    use gyrofx_job::job::Job;

    /// The whole system's folder holds both blocks' configured wrappers apart, each source
    /// once, and a top that drives the mean filter from the system's published rate, aligned
    /// to the mean filter's input format when the KF's output has another; its top, read with
    /// every source, passes Verilator's lint with every warning (what yosys then synthesizes).
    /// An unconnected port, a width mismatch or a missing source fails it.
    #[test]
    fn the_whole_system_wires_the_mean_filter_to_the_published_rate_and_lints_clean() {
        let provenance = Provenance::for_tests();
        // The default (the rate is s24.14, the mean filter's input too), and a KF output two
        // bits wider with two more fraction bits (the mean filter drops them).
        for (overlay, x) in [
            ("", "rate_out"),
            ("[kf]\noutput_format = \"s26.16\"\n", "{rate_out[25:2]}"),
        ] {
            let job = Job::new(Config::from_toml(overlay, "test").unwrap()).unwrap();
            let roms = RomImages::new(&job, &provenance);
            let work = tempfile::tempdir().unwrap();
            let request = PlaceRequest {
                targets: vec![],
                blocks: vec![NAME],
                jobs: 1,
            };
            let prepared =
                Prepared::new(&job, &roms, &provenance, &request, vec![], work.path()).unwrap();
            let design = &prepared.designs[0];
            assert_eq!(design.top, TOP);
            assert!(design.sources.ends_with(&[
                "system_serial_configured.v".to_string(),
                "mean_filter_serial_configured.v".to_string(),
                TOP_FILE.to_string()
            ]));
            let mut once = design.sources.clone();
            once.sort();
            once.dedup();
            assert_eq!(once.len(), design.sources.len(), "{:?}", design.sources);
            let top = &design.files.iter().find(|(n, _)| n == TOP_FILE).unwrap().1;
            assert!(
                top.contains(&format!(".ce(out_valid),\n    .x({x}),")),
                "{overlay}: {top}"
            );
            assert!(harness(design).contains("gyrofx_whole_system_serial dut ("));
            let dir = work.path().join(FOLDER).join(NAME);
            let lint = std::process::Command::new("verilator")
                .args([
                    "--lint-only",
                    "-Wall",
                    "-Wno-DECLFILENAME",
                    "--top-module",
                    TOP,
                ])
                .args(&design.sources)
                .current_dir(&dir)
                .output()
                .expect("verilator runs (scripts/test.sh installs it)");
            assert!(
                lint.status.success(),
                "{overlay}: {}",
                String::from_utf8_lossy(&lint.stderr)
            );
        }
    }
}
