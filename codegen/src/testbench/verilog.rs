//! The Verilog 2001 testbench (plus `$fatal`, supported by Icarus and Verilator); the behaviour
//! and the options are those of [`crate::testbench`].

use std::fmt::Write as _;

use super::{header, MAX_REPORTED};
use crate::block::{Block, Output, Signal, Timing};
use crate::text::Provenance;

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

/// The testbench of `block`.
pub fn testbench(block: &Block, provenance: &Provenance) -> String {
    let tb = format!("tb_{}", block.module);
    let stimulus_fields: Vec<&Signal> = block.inputs.iter().collect();
    let expected_fields: Vec<&Signal> = block.outputs.iter().map(|o| &o.signal).collect();
    let mut out = String::new();
    let _ = writeln!(
        out,
        "// Language: Verilog 2001 (+ $fatal, supported by Icarus and Verilator)"
    );
    let _ = writeln!(out, "{}", provenance.line("//"));
    let _ = writeln!(
        out,
        "`resetall
`timescale 1ns / 1ps
`default_nettype none

/*
 * {tb} — self-checking testbench of {module} ({title}).
 *
 * Reads STIMULUS_FILE and EXPECTED_FILE (one line per clock-enable, hex fields,
 * formats declared on line 2 and checked here), drives one sample per ce with an
 * idle clock after every fourth, and compares combinational outputs before the
 * clock edge and registered outputs 1 clock after it. Prints the first
 * mismatches, then PASS n=<N> [masked=<M>] or FAIL mismatches=<M> n=<N> first=<index>,
 * and exits non-zero ($fatal) on a mismatch, a timeout or a bad vector file.
 * Plusargs: +dump writes {tb}.vcd; +mask=<n> does not compare the first n samples
 * of the run and from every reset sample on (latency mask); +max_reported=<n>
 * prints n mismatches (default {max}); +max_mismatches=<n> stops at the n-th.
 */
module {tb};

`include \"{params}\"

localparam integer CLOCK_PERIOD_NS = 10;
// 64-bit: long vector sets overflow a 32-bit integer.
localparam [63:0] TIMEOUT_NS = 64'd{timeout_clocks} * CLOCK_PERIOD_NS;

reg clk = 1'b0;
always #(CLOCK_PERIOD_NS / 2) clk <= ~clk;
reg rst = 1'b1;
reg ce = 1'b0;",
        module = block.module,
        title = block.title,
        max = MAX_REPORTED,
        params = block.file("params.vh"),
        timeout_clocks = super::timeout_clocks(block.len(), block.settle_clocks),
    );
    for s in &block.inputs {
        let _ = writeln!(out, "{}", declaration("reg", s, "", true));
    }
    for o in &block.outputs {
        let _ = writeln!(out, "{}", declaration("wire", &o.signal, "", false));
    }
    // DUT
    let _ = writeln!(out, "\n{}", instance(block));

    // Variables
    let _ = writeln!(
        out,
        "integer stimulus_fd;
integer expected_fd;
integer rom_fd;
integer fields;
integer index = 0;
integer mismatches = 0;
integer first_mismatch = -1;
integer mask_samples = 0;
integer max_reported = {MAX_REPORTED};
integer max_mismatches = 0;
integer since_reset = 0;
integer masked_count = 0;
reg masked = 1'b0;
reg stop_at_cap = 1'b0;
reg [8*1024-1:0] line;
reg [8*400-1:0] message;
reg vector_rst;"
    );
    for s in &block.inputs {
        let _ = writeln!(out, "{}", declaration("reg", s, "vector_", false));
    }
    for o in &block.outputs {
        let _ = writeln!(out, "{}", declaration("reg", &o.signal, "expected_", false));
    }
    let declared_count = (1 + block.inputs.len()).max(block.outputs.len());
    for i in 0..declared_count {
        let _ = writeln!(out, "reg [8*40-1:0] declared_{i};");
    }

    let _ = writeln!(
        out,
        "
// Prints `message` as a FAIL line and stops with a non-zero exit.
task fail_setup;
    begin
        $display(\"FAIL %0s\", message);
        $fatal(1, \"{tb}: %0s\", message);
    end
endtask

initial begin
    if ($test$plusargs(\"dump\")) begin
        $dumpfile(\"{tb}.vcd\");
        $dumpvars(0, {tb});
    end
end

initial begin
    #(TIMEOUT_NS);
    $display(\"FAIL timeout after %0d ns (%0d of %0d samples)\", TIMEOUT_NS, index, VECTOR_COUNT);
    $fatal(1, \"{tb}: timeout\");
end

initial begin
    if ($value$plusargs(\"mask=%d\", mask_samples) && mask_samples > 0)
        $display(\"mask: %0d samples after each reset\", mask_samples);
    if ($value$plusargs(\"max_reported=%d\", max_reported)) begin end
    if ($value$plusargs(\"max_mismatches=%d\", max_mismatches)) begin end"
    );
    for (rom, _) in &block.roms {
        let _ = writeln!(
            out,
            "    // $readmemh in the DUT only warns about a missing file (Icarus): check it here.
    rom_fd = $fopen(\"{rom}\", \"r\");
    if (rom_fd == 0) begin
        $sformat(message, \"cannot open {rom}\");
        fail_setup;
    end
    $fclose(rom_fd);"
        );
    }
    for (fd, file, fields, with_rst) in [
        ("stimulus_fd", "STIMULUS_FILE", &stimulus_fields, true),
        ("expected_fd", "EXPECTED_FILE", &expected_fields, false),
    ] {
        let wanted = header(fields, with_rst);
        let tokens: Vec<&str> = wanted.trim_start_matches("// ").split(' ').collect();
        let pattern = vec!["%s"; tokens.len()].join(" ");
        let targets: Vec<String> = (0..tokens.len()).map(|i| format!("declared_{i}")).collect();
        let compare: Vec<String> = tokens
            .iter()
            .enumerate()
            .map(|(i, t)| format!("declared_{i} != \"{t}\""))
            .collect();
        let _ = writeln!(
            out,
            "    {fd} = $fopen({file}, \"r\");
    if ({fd} == 0) begin
        $sformat(message, \"cannot open %0s\", {file});
        fail_setup;
    end
    fields = $fgets(line, {fd});
    fields = $fscanf({fd}, \"// {pattern}\\n\", {targets});
    if (fields != {count} || {compare}) begin
        $sformat(message, \"%0s declares {declared_pattern}; the testbench expects {wanted_text}\", {file}, {targets});
        fail_setup;
    end",
            declared_pattern = vec!["%0s"; tokens.len()].join(" "),
            targets = targets.join(", "),
            count = tokens.len(),
            compare = compare.join(" || "),
            wanted_text = wanted.trim_start_matches("// "),
        );
    }

    // Main loop
    let input_scan = vec!["%h"; 1 + block.inputs.len()].join(" ");
    let mut input_targets = vec!["vector_rst".to_string()];
    input_targets.extend(block.inputs.iter().map(|s| format!("vector_{}", s.name)));
    let output_scan = vec!["%h"; block.outputs.len()].join(" ");
    let output_targets: Vec<String> = block
        .outputs
        .iter()
        .map(|o| format!("expected_{}", o.signal.name))
        .collect();
    let _ = writeln!(
        out,
        "
    // Power-on reset.
    rst = 1'b1;
    repeat (2) @(posedge clk);
    @(negedge clk);
    rst = 1'b0;

    for (index = 0; index < VECTOR_COUNT; index = index + 1) begin
        fields = $fscanf(stimulus_fd, \"{input_scan}\\n\", {inputs});
        if (fields != {input_count}) begin
            $sformat(message, \"%0s: line for sample %0d is missing or malformed\", STIMULUS_FILE, index);
            fail_setup;
        end
        fields = $fscanf(expected_fd, \"{output_scan}\\n\", {outputs});
        if (fields != {output_count}) begin
            $sformat(message, \"%0s: line for sample %0d is missing or malformed\", EXPECTED_FILE, index);
            fail_setup;
        end
        if (vector_rst) since_reset = 0;
        masked = since_reset < mask_samples;
        if (masked) masked_count = masked_count + 1;
        since_reset = since_reset + 1;
        rst = vector_rst;
        ce = 1'b1;",
        inputs = input_targets.join(", "),
        input_count = input_targets.len(),
        outputs = output_targets.join(", "),
        output_count = output_targets.len(),
    );
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
    if block.settle_clocks > 0 {
        let _ = writeln!(
            out,
            "        // The pipeline's latency: registered outputs settle these clocks later.\n        repeat ({}) @(negedge clk);",
            block.settle_clocks
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
        "        if (index % 4 == 3) begin\n            @(negedge clk);"
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
    let _ = writeln!(
        out,
        "        end
        if (stop_at_cap) begin
            $display(\"FAIL mismatches=%0d n=%0d first=%0d (stopped at max_mismatches)\", mismatches, index + 1, first_mismatch);
            $fatal(1, \"{tb}: stopped at %0d mismatches\", mismatches);
        end
    end

    if (mismatches == 0) begin
        if (masked_count > 0)
            $display(\"PASS n=%0d masked=%0d\", VECTOR_COUNT, masked_count);
        else
            $display(\"PASS n=%0d\", VECTOR_COUNT);
        $finish;
    end else begin
        $display(\"FAIL mismatches=%0d n=%0d first=%0d\", mismatches, VECTOR_COUNT, first_mismatch);
        $fatal(1, \"{tb}: %0d mismatches\", mismatches);
    end
end

endmodule

`resetall"
    );
    out
}
