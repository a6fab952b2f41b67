//! The Verilog 2001 testbench (plus `$fatal`, supported by Icarus and Verilator); the behaviour
//! and the options are those of [`crate::testbench`].

use std::fmt::Write as _;

use super::{header, IDLE_EVERY, MAX_REPORTED};
use crate::block::{Block, Output, Signal, Timing};
use crate::text::{fill, Provenance};

fn declaration(kind: &str, s: &Signal, prefix: &str, init: bool) -> String {
    let signed = if s.format.signed { "signed " } else { "" };
    let range = if s.format.width > 1 {
        format!("[{}:0] ", s.format.width - 1)
    } else {
        String::new()
    };
    let init = if init {
        format!(" = {{{}{{1'b0}}}}", s.format.width)
    } else {
        String::new()
    };
    format!("{kind} {signed}{range}{prefix}{}{init};", s.name)
}

fn real_of(s: &Signal, expr: &str) -> String {
    if s.is_real() {
        format!("$signed({expr}) / (2.0 ** {})", s.format.frac)
    } else {
        format!("{expr} * 1.0")
    }
}

fn mismatch(o: &Output) -> String {
    let s = &o.signal;
    format!(
        "            mismatches = mismatches + 1;
            if (first_mismatch < 0) first_mismatch = index;
            if (max_mismatches > 0 && mismatches >= max_mismatches) stop_at_cap = 1'b1;
            if (mismatches <= max_reported)
                $display(\"MISMATCH sample %0d signal {name} expected %h (%.9g) actual %h (%.9g)\",
                    index, expected_{name}, {expected_real}, {name}, {actual_real});",
        name = s.name,
        expected_real = real_of(s, &format!("expected_{}", s.name)),
        actual_real = real_of(s, s.name),
    )
}

/// The block's module named `dut`, its parameters from `P_<NAME>` (the params file's), each
/// port on the signal of its name.
pub fn instance(block: &Block) -> String {
    let params: Vec<String> = block
        .params
        .iter()
        .map(|p| format!("    .{0}(P_{0})", p.name))
        .collect();
    let mut connections = vec![
        "    .clk(clk)".to_string(),
        "    .rst(rst)".into(),
        "    .ce(ce)".into(),
    ];
    connections.extend(
        block
            .inputs
            .iter()
            .map(|s| format!("    .{0}({0})", s.name)),
    );
    connections.extend(
        block
            .outputs
            .iter()
            .map(|o| format!("    .{0}({0})", o.signal.name)),
    );
    format!(
        "{} #(\n{}\n) dut (\n{}\n);\n",
        block.module,
        params.join(",\n"),
        connections.join(",\n")
    )
}

/// The testbench of `block`: `codegen/templates/testbench/testbench.v` filled with the block's
/// ports, instance, vector checks and per-sample comparisons.
pub fn testbench(block: &Block, provenance: &Provenance) -> String {
    let tb = format!("tb_{}", block.module);
    let mut ports = String::new();
    for s in &block.inputs {
        let _ = writeln!(ports, "{}", declaration("reg", s, "", true));
    }
    for o in &block.outputs {
        let _ = writeln!(ports, "{}", declaration("wire", &o.signal, "", false));
    }
    let mut vector_declarations = String::new();
    for s in &block.inputs {
        let _ = writeln!(
            vector_declarations,
            "{}",
            declaration("reg", s, "vector_", false)
        );
    }
    for o in &block.outputs {
        let _ = writeln!(
            vector_declarations,
            "{}",
            declaration("reg", &o.signal, "expected_", false)
        );
    }
    let declared_count = (1 + block.inputs.len()).max(block.outputs.len());
    for i in 0..declared_count {
        let _ = writeln!(vector_declarations, "reg [8*40-1:0] declared_{i};");
    }
    let rom_checks: String = block
        .roms
        .iter()
        .map(|(rom, _)| fill(ROM_CHECK, &[("rom", rom)]))
        .collect();
    let input_scan = vec!["%h"; 1 + block.inputs.len()].join(" ");
    let mut input_targets = vec!["vector_rst".to_string()];
    input_targets.extend(block.inputs.iter().map(|s| format!("vector_{}", s.name)));
    let output_scan = vec!["%h"; block.outputs.len()].join(" ");
    let output_targets: Vec<String> = block
        .outputs
        .iter()
        .map(|o| format!("expected_{}", o.signal.name))
        .collect();
    fill(
        TESTBENCH,
        &[
            ("provenance", &provenance.line("//")),
            ("tb", &tb),
            ("module", block.module),
            ("title", block.title),
            ("max", &MAX_REPORTED.to_string()),
            ("params", &block.file("params.vh")),
            (
                "timeout_clocks",
                &super::timeout_clocks(block.len(), block.settle_clocks()).to_string(),
            ),
            ("ports", &ports),
            ("instance", &instance(block)),
            ("vector_declarations", &vector_declarations),
            ("rom_checks", &rom_checks),
            ("file_checks", &header_checks(block)),
            ("input_scan", &input_scan),
            ("inputs", &input_targets.join(", ")),
            ("input_count", &input_targets.len().to_string()),
            ("output_scan", &output_scan),
            ("outputs", &output_targets.join(", ")),
            ("output_count", &output_targets.len().to_string()),
            ("checks", &sample_checks(block)),
        ],
    )
}

/// The testbench and its two per-item parts (`codegen/templates/testbench/`).
const TESTBENCH: &str = include_str!("../../templates/testbench/testbench.v");
const ROM_CHECK: &str = include_str!("../../templates/testbench/rom_check.v");
const HEADER_CHECK: &str = include_str!("../../templates/testbench/header_check.v");

/// The checks that the stimulus and expected files open and declare the fields, in the
/// order and formats, that the testbench reads.
fn header_checks(block: &Block) -> String {
    let stimulus_fields: Vec<&Signal> = block.inputs.iter().collect();
    let expected_fields: Vec<&Signal> = block.outputs.iter().map(|o| &o.signal).collect();
    let mut out = String::new();
    for (fd, file, fields, with_rst) in [
        ("stimulus_fd", "STIMULUS_FILE", &stimulus_fields, true),
        ("expected_fd", "EXPECTED_FILE", &expected_fields, false),
    ] {
        let wanted = header(fields, with_rst);
        let tokens: Vec<&str> = wanted.trim_start_matches("// ").split(' ').collect();
        let targets: Vec<String> = (0..tokens.len()).map(|i| format!("declared_{i}")).collect();
        let compare: Vec<String> = tokens
            .iter()
            .enumerate()
            .map(|(i, t)| format!("declared_{i} != \"{t}\""))
            .collect();
        out.push_str(&fill(
            HEADER_CHECK,
            &[
                ("fd", fd),
                ("file", file),
                ("pattern", &vec!["%s"; tokens.len()].join(" ")),
                ("targets", &targets.join(", ")),
                ("count", &tokens.len().to_string()),
                ("compare", &compare.join(" || ")),
                ("declared_pattern", &vec!["%0s"; tokens.len()].join(" ")),
                ("wanted_text", wanted.trim_start_matches("// ")),
            ],
        ));
    }
    out
}

/// One sample's drive and comparisons, inside the main loop: the inputs, the combinational
/// outputs before the clock edge, the registered ones after the pipeline's latency, and the
/// idle clock after every fourth sample.
fn sample_checks(block: &Block) -> String {
    let mut out = String::new();
    for s in &block.inputs {
        let _ = writeln!(out, "        {0} = vector_{0};", s.name);
    }
    let combinational: Vec<&Output> = block
        .outputs
        .iter()
        .filter(|o| o.timing == Timing::Combinational)
        .collect();
    if !combinational.is_empty() {
        let _ = writeln!(
            out,
            "        #1;\n        if (!vector_rst && !masked) begin"
        );
        for o in &combinational {
            let _ = writeln!(
                out,
                "        if ({0} !== expected_{0}) begin\n{1}\n        end",
                o.signal.name,
                mismatch(o)
            );
        }
        let _ = writeln!(out, "        end");
    }
    let _ = writeln!(
        out,
        "        @(negedge clk);\n        rst = 1'b0;\n        ce = 1'b0;"
    );
    if block.settle_clocks() > 0 {
        let _ = writeln!(
            out,
            "        // The pipeline's latency: registered outputs settle these clocks later.\n        repeat ({}) @(negedge clk);",
            block.settle_clocks()
        );
    }
    for o in block
        .outputs
        .iter()
        .filter(|o| o.timing == Timing::Registered)
    {
        let condition = match o.gate {
            Some(gate) => format!(
                "!masked && expected_{gate} == 1'b1 && {0} !== expected_{0}",
                o.signal.name
            ),
            None => format!("!masked && {0} !== expected_{0}", o.signal.name),
        };
        let _ = writeln!(
            out,
            "        if ({condition}) begin\n{}\n        end",
            mismatch(o)
        );
    }
    // Idle clock: pulses low, other ungated registered outputs held.
    let _ = writeln!(
        out,
        "        if (index % {IDLE_EVERY} == {}) begin\n            @(negedge clk);",
        IDLE_EVERY - 1
    );
    for o in block
        .outputs
        .iter()
        .filter(|o| o.timing == Timing::Registered && o.gate.is_none())
    {
        if o.pulse {
            let _ = writeln!(
                out,
                "            expected_{0} = {{{1}{{1'b0}}}};",
                o.signal.name, o.signal.format.width
            );
        }
        let _ = writeln!(
            out,
            "            if (!masked && {0} !== expected_{0}) begin\n{1}\n            end",
            o.signal.name,
            mismatch(o).replace("\n            ", "\n                ")
        );
    }
    let _ = writeln!(out, "        end");
    out
}
