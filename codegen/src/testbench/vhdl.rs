//! The VHDL-2008 testbench (run by GHDL `--std=08`); the behaviour and the options are those of
//! [`crate::testbench`]. It reads the vector files with textio through `gyrofx_testbench_pkg`
//! (shipped with the RTL), instantiates the VHDL twin of the block's module with the same
//! parameters, and ends with `std.env.finish` on a pass and `std.env.stop(1)` otherwise.

use std::fmt::Write as _;

use super::{header, timeout_clocks, IDLE_EVERY, MAX_REPORTED};
use crate::block::{Block, Output, Signal, Timing};
use crate::text::{fill, Provenance};

/// The port type of `s` in the VHDL RTL: signed data, `std_logic` flags, unsigned indices.
fn port_type(s: &Signal) -> String {
    let top = s.format.width - 1;
    if s.format.signed {
        format!("signed({top} downto 0)")
    } else if s.flag {
        "std_logic".into()
    } else {
        format!("unsigned({top} downto 0)")
    }
}

/// `vector` (a `std_logic_vector` variable) converted to the port type of `s`.
fn from_bits(s: &Signal, vector: &str) -> String {
    if s.format.signed {
        format!("signed({vector})")
    } else if s.flag {
        format!("{vector}(0)")
    } else {
        format!("unsigned({vector})")
    }
}

/// The port `s` as a `std_logic_vector` for an exact comparison.
fn to_bits(s: &Signal) -> String {
    if s.flag {
        format!("bits({})", s.name)
    } else {
        format!("std_logic_vector({})", s.name)
    }
}

fn vector_variable(s: &Signal, prefix: &str) -> String {
    format!(
        "    variable {prefix}{} : std_logic_vector({} downto 0);",
        s.name,
        s.format.width - 1
    )
}

/// `check(...)` of output `o` at `indent`.
fn check(o: &Output, indent: &str) -> String {
    let s = &o.signal;
    format!(
        "{indent}check(\"{name}\", expected_{name}, {actual}, {frac}, {signed});",
        name = s.name,
        actual = to_bits(s),
        frac = s.format.frac,
        signed = s.format.signed,
    )
}

/// The VHDL testbench of `block`: `codegen/templates/testbench/testbench.vhd` filled with the
/// block's constants, signals, instance, vector reads and per-sample comparisons.
pub fn testbench(block: &Block, provenance: &Provenance) -> String {
    let lines = |items: Vec<String>| -> String { items.iter().map(|l| format!("{l}\n")).collect() };
    let constants = lines(
        block
            .params
            .iter()
            .map(|p| {
                format!(
                    "    constant P_{} : {} := {}; -- {}",
                    p.name, p.vhdl_type, p.vhdl_value, p.comment
                )
            })
            .collect(),
    );
    let mut signals: Vec<String> = block
        .inputs
        .iter()
        .map(|s| {
            let zero = if s.flag { "'0'" } else { "(others => '0')" };
            format!("    signal {} : {} := {zero};", s.name, port_type(s))
        })
        .collect();
    signals.extend(
        block
            .outputs
            .iter()
            .map(|o| format!("    signal {} : {};", o.signal.name, port_type(&o.signal))),
    );
    let generics: Vec<String> = block
        .params
        .iter()
        .map(|p| format!("            {0} => P_{0}", p.name))
        .collect();
    let mut ports = vec![
        "            clk => clk".to_string(),
        "            rst => rst".into(),
        "            ce => ce".into(),
    ];
    ports.extend(
        block
            .inputs
            .iter()
            .chain(block.outputs.iter().map(|o| &o.signal))
            .map(|s| format!("            {0} => {0}", s.name)),
    );
    let mut variables: Vec<String> = block
        .inputs
        .iter()
        .map(|s| format!("    {}", vector_variable(s, "vector_")))
        .collect();
    variables.extend(
        block
            .outputs
            .iter()
            .map(|o| format!("    {}", vector_variable(&o.signal, "expected_"))),
    );
    let read_inputs = lines(
        block
            .inputs
            .iter()
            .map(|s| {
                format!(
                    "                read_field(text_line, vector_{}, ok);",
                    s.name
                )
            })
            .collect(),
    );
    let read_outputs = lines(
        block
            .outputs
            .iter()
            .map(|o| {
                format!(
                    "                read_field(text_line, expected_{}, ok);",
                    o.signal.name
                )
            })
            .collect(),
    );
    let stimulus_header = header(&block.inputs.iter().collect::<Vec<_>>(), true);
    let expected_header = header(
        &block.outputs.iter().map(|o| &o.signal).collect::<Vec<_>>(),
        false,
    );
    fill(
        TESTBENCH,
        &[
            ("provenance", &provenance.line("--")),
            ("tb", &format!("tb_{}", block.module)),
            ("module", block.module),
            ("title", block.title),
            ("stimulus", &block.file("stimulus.hex")),
            ("expected", &block.file("expected.hex")),
            ("max", &MAX_REPORTED.to_string()),
            ("constants", &constants),
            ("count", &block.len().to_string()),
            (
                "timeout",
                &timeout_clocks(block.len(), block.settle_clocks()).to_string(),
            ),
            ("signals", &lines(signals)),
            ("generics", &generics.join(",\n")),
            ("ports", &ports.join(",\n")),
            ("variables", &lines(variables)),
            ("stimulus_header", stimulus_header.trim_start_matches("// ")),
            ("expected_header", expected_header.trim_start_matches("// ")),
            ("read_inputs", &read_inputs),
            ("read_outputs", &read_outputs),
            ("sample_checks", &sample_checks(block)),
        ],
    )
}

/// The VHDL testbench (`codegen/templates/testbench/`).
const TESTBENCH: &str = include_str!("../../templates/testbench/testbench.vhd");

/// One sample's drive and comparisons, inside the main loop: the inputs, the combinational
/// outputs before the clock edge, the registered ones after the pipeline's latency, and the
/// idle clock after every fourth sample.
fn sample_checks(block: &Block) -> String {
    let mut out = String::new();
    for s in &block.inputs {
        let _ = writeln!(
            out,
            "            {} <= {};",
            s.name,
            from_bits(s, &format!("vector_{}", s.name))
        );
    }
    let combinational: Vec<&Output> = block
        .outputs
        .iter()
        .filter(|o| o.timing == Timing::Combinational)
        .collect();
    if !combinational.is_empty() {
        let _ = writeln!(
            out,
            "            wait for 1 ns;\n            if vector_rst(0) = '0' and not masked then"
        );
        for o in &combinational {
            let _ = writeln!(out, "{}", check(o, "                "));
        }
        let _ = writeln!(out, "            end if;");
    }
    let _ = writeln!(
        out,
        "            wait until falling_edge(clk);
            rst <= '0';
            ce <= '0';"
    );
    if block.settle_clocks() > 0 {
        let _ = writeln!(
            out,
            "            -- The pipeline's latency: registered outputs settle these clocks later.
            for settle in 1 to {} loop
                wait until falling_edge(clk);
            end loop;",
            block.settle_clocks()
        );
    }
    let _ = writeln!(out, "            if not masked then");
    for o in block
        .outputs
        .iter()
        .filter(|o| o.timing == Timing::Registered)
    {
        match o.gate {
            Some(gate) => {
                let _ = writeln!(
                    out,
                    "                if expected_{gate} = \"1\" then\n{}\n                end if;",
                    check(o, "                    ")
                );
            }
            None => {
                let _ = writeln!(out, "{}", check(o, "                "));
            }
        }
    }
    // Idle clock: pulses low, other ungated registered outputs held.
    let _ = writeln!(
        out,
        "            end if;
            if index mod {IDLE_EVERY} = {} then
                wait until falling_edge(clk);",
        IDLE_EVERY - 1
    );
    let held: Vec<&Output> = block
        .outputs
        .iter()
        .filter(|o| o.timing == Timing::Registered && o.gate.is_none())
        .collect();
    for o in &held {
        if o.pulse {
            let _ = writeln!(
                out,
                "                expected_{} := (others => '0');",
                o.signal.name
            );
        }
    }
    if !held.is_empty() {
        let _ = writeln!(out, "                if not masked then");
        for o in &held {
            let _ = writeln!(out, "{}", check(o, "                    "));
        }
        let _ = writeln!(out, "                end if;");
    }
    let _ = writeln!(out, "            end if;");
    out
}
