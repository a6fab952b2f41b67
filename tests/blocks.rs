//! The block registry against what is written elsewhere about each block: the RTL module's port
//! list (`hdl/<module>.v` and `.vhd`) and the doc page's port table (`docs/blocks/<block>.md`),
//! so that neither can drift from the code.

use std::path::Path;

use gyrofx_codegen::blocks::{RomImages, REGISTRY};
use gyrofx_codegen::text::Provenance;
use gyrofx_job::config::Config;
use gyrofx_job::job::Job;

/// A port: name, direction (`in`/`out`) and format (`s24.14`, `u1.0`).
type Port = (String, String, String);

const CLOCKING: [&str; 3] = ["clk", "rst", "ce"];

fn root() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

/// Every registered block's ports for the embedded default (vector-file order), with the
/// clocking inputs when the block has them (every block but the combinational calibration).
fn registry_ports() -> Vec<(&'static str, &'static str, Vec<Port>)> {
    let job = Job::new(Config::embedded()).unwrap();
    let provenance = Provenance::for_tests();
    let roms = RomImages::new(&job, &provenance);
    REGISTRY
        .iter()
        .map(|b| {
            let block = b.block(&job, &roms);
            let mut ports = Vec::new();
            if b.name() != "calibration" {
                ports.extend(
                    CLOCKING.map(|name| (name.to_string(), "in".to_string(), "u1.0".to_string())),
                );
            }
            ports.extend(
                block
                    .inputs
                    .iter()
                    .map(|s| (s.name.to_string(), "in".into(), s.format.to_string())),
            );
            ports.extend(block.outputs.iter().map(|o| {
                (
                    o.signal.name.to_string(),
                    "out".into(),
                    o.signal.format.to_string(),
                )
            }));
            (b.name(), b.module(), ports)
        })
        .collect()
}

fn sorted<T: Ord>(mut v: Vec<T>) -> Vec<T> {
    v.sort();
    v
}

/// The rows of the `| Port | Direction | Format | Description |` table of a doc page.
fn doc_ports(page: &str) -> Vec<Port> {
    let mut lines = page
        .lines()
        .skip_while(|l| !l.starts_with("| Port | Direction | Format |"));
    lines.next().expect("a port table");
    lines
        .skip(1)
        .take_while(|l| l.starts_with('|'))
        .map(|l| {
            let cells: Vec<String> = l
                .split('|')
                .map(|c| c.trim().trim_matches('`').to_string())
                .collect();
            (cells[1].clone(), cells[2].clone(), cells[3].clone())
        })
        .collect()
}

/// Names and directions of a Verilog module's ports, in order (ANSI header, one per line).
fn verilog_ports(source: &str) -> Vec<(String, String)> {
    // The module's port list ends at the first `);`: functions after it declare inputs too.
    source
        .lines()
        .map(str::trim)
        .skip_while(|l| !l.starts_with("module "))
        .take_while(|l| !l.starts_with(");"))
        .filter_map(|l| {
            let direction = if l.starts_with("input ") {
                "in"
            } else if l.starts_with("output ") {
                "out"
            } else {
                return None;
            };
            let name = l
                .trim_end_matches([',', ')', ';'])
                .split_whitespace()
                .last()?
                .to_string();
            Some((name, direction.to_string()))
        })
        .collect()
}

/// Names and directions of a VHDL entity's ports, in order (`name : in ...;` lines inside
/// `port (`).
fn vhdl_ports(source: &str) -> Vec<(String, String)> {
    let entity = source
        .split("\nentity ")
        .nth(1)
        .expect("an entity")
        .split("\nend entity")
        .next()
        .unwrap();
    let ports = entity.split("port (").nth(1).expect("a port clause");
    ports
        .lines()
        .filter_map(|l| {
            let (name, rest) = l.split_once(':')?;
            let direction = rest.split_whitespace().next()?;
            matches!(direction, "in" | "out").then(|| (name.trim().to_string(), direction.into()))
        })
        .collect()
}

#[test]
fn every_registered_block_has_a_doc_page_whose_port_table_matches_the_registry() {
    for (name, _, ports) in registry_ports() {
        let path = root().join(format!("docs/blocks/{name}.md"));
        let page = std::fs::read_to_string(&path)
            .unwrap_or_else(|e| panic!("{}: {e} (every block has a page)", path.display()));
        assert_eq!(
            sorted(doc_ports(&page)),
            sorted(ports),
            "{}: the port table (name, direction, format for the default config) differs from the registry",
            path.display()
        );
    }
}

#[test]
fn every_registered_block_declares_exactly_its_rtl_modules_ports_in_both_languages() {
    for (name, module, ports) in registry_ports() {
        let declared: Vec<(String, String)> =
            sorted(ports.into_iter().map(|(n, d, _)| (n, d)).collect());
        let verilog = std::fs::read_to_string(root().join(format!("hdl/{module}.v"))).unwrap();
        let verilog = verilog_ports(&verilog);
        assert_eq!(sorted(verilog.clone()), declared, "{name}: hdl/{module}.v");
        let vhdl = std::fs::read_to_string(root().join(format!("hdl/{module}.vhd"))).unwrap();
        assert_eq!(vhdl_ports(&vhdl), verilog, "{name}: hdl/{module}.vhd vs .v");
        // The page lists the ports in the module's order.
        let page = std::fs::read_to_string(root().join(format!("docs/blocks/{name}.md"))).unwrap();
        let documented: Vec<(String, String)> = doc_ports(&page)
            .into_iter()
            .map(|(n, d, _)| (n, d))
            .collect();
        assert_eq!(documented, verilog, "docs/blocks/{name}.md: port order");
    }
}

/// The parsers above can fail: a page whose table lost a row or changed a format is caught.
#[test]
fn a_drifted_doc_table_is_caught() {
    let (name, _, ports) = registry_ports().into_iter().find(|b| b.0 == "kf").unwrap();
    let page = std::fs::read_to_string(root().join(format!("docs/blocks/{name}.md"))).unwrap();
    assert_eq!(sorted(doc_ports(&page)), sorted(ports.clone()));
    let drifted = page.replace("| `z` | in | s24.14 |", "| `z` | in | s24.13 |");
    assert_ne!(drifted, page, "the kf page documents z as s24.14");
    assert_ne!(sorted(doc_ports(&drifted)), sorted(ports));
}

/// The `latency_clocks` and `min_clocks_per_sample` of a page's "**Pipeline**" line.
fn doc_pipeline(page: &str) -> Option<(u32, u32)> {
    let line = page.lines().find(|l| l.starts_with("**Pipeline**"))?;
    let number = |key: &str| -> Option<u32> {
        let rest = &line[line.find(&format!("`{key}` = "))? + key.len() + 5..];
        rest.split(|c: char| !c.is_ascii_digit())
            .next()?
            .parse()
            .ok()
    };
    Some((number("latency_clocks")?, number("min_clocks_per_sample")?))
}

/// Each clocked block's page states the pipeline its testbenches run with (the registry's,
/// from `gyrofx_job::pipeline`) for the default config; a changed figure is caught.
#[test]
fn every_clocked_blocks_page_states_its_pipeline() {
    let job = Job::new(Config::embedded()).unwrap();
    let provenance = Provenance::for_tests();
    let roms = RomImages::new(&job, &provenance);
    for registered in REGISTRY {
        let block = registered.block(&job, &roms);
        if !block.clocked {
            continue;
        }
        let path = root().join(format!("docs/blocks/{}.md", block.name));
        let page = std::fs::read_to_string(&path).unwrap();
        let want = (
            block.pipeline.latency_clocks,
            block.pipeline.min_clocks_per_sample,
        );
        assert_eq!(doc_pipeline(&page), Some(want), "{}", path.display());
    }
    let kf = std::fs::read_to_string(root().join("docs/blocks/kf.md")).unwrap();
    let drifted = kf.replace("`latency_clocks` = 4", "`latency_clocks` = 1");
    assert_ne!(doc_pipeline(&drifted), doc_pipeline(&kf));
}

/// The port-level golden models' port lists (`gyrofx_job::golden::ports`, which the Python
/// classes and the C API give) are the package's, name, direction and format, in the vector
/// files' order: for the default config, the serial architecture and narrower formats.
#[test]
fn the_golden_models_ports_are_the_packages() {
    use gyrofx_job::golden;
    let configs = [
        Config::embedded(),
        Config::from_toml("architecture = \"serial\"\n", "serial").unwrap(),
        Config::from_toml(
            "[kf]\nbandwidths_hz = [0.5, 2.0, 5.0, 10.0, 20.0]\ninput_format = \"s20.10\"\n\
             [loop]\noutput_format = \"s20.10\"\ndemod_output_format = \"s24.22\"\n",
            "narrow",
        )
        .unwrap(),
    ];
    let provenance = Provenance::for_tests();
    for config in configs {
        let job = Job::new(config).unwrap();
        let roms = RomImages::new(&job, &provenance);
        let [a, b] = &job.gyro_loops;
        let system_chain = job.system_chain.as_ref().unwrap();
        let models: [(&str, Vec<golden::ports::Port>); 7] = [
            (
                "sequencer",
                golden::Sequencer::new(&job.chain.estimator.schedule).ports(),
            ),
            (
                "estimator",
                golden::Estimator::new(&job.chain.estimator).ports(),
            ),
            ("kf", golden::Kf::new(job.kf()).ports()),
            ("top", golden::Chain::new(&job.chain).ports()),
            (
                "mean_filter",
                golden::MeanFilter::new(&job.mean_filter).ports(),
            ),
            ("gyro_loop", golden::GyroLoop::new(&a.plan).ports()),
            (
                "system",
                golden::System::new([&a.plan, &b.plan], system_chain).ports(),
            ),
        ];
        for (name, ports) in models {
            let block = REGISTRY
                .iter()
                .find(|r| r.name() == name)
                .unwrap()
                .block(&job, &roms);
            let package: Vec<(String, &str, String)> = block
                .inputs
                .iter()
                .map(|s| (s.name.to_string(), "in", s.format.to_string()))
                .chain(block.outputs.iter().map(|o| {
                    (
                        o.signal.name.to_string(),
                        "out",
                        o.signal.format.to_string(),
                    )
                }))
                .collect();
            let model: Vec<(String, &str, String)> = ports
                .iter()
                .map(|p| (p.name.to_string(), p.direction(), p.format.to_string()))
                .collect();
            assert_eq!(model, package, "{name}: {}", job.config.to_toml());
        }
    }
}
