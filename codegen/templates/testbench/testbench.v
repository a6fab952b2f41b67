// Language: Verilog 2001 (+ $fatal, supported by Icarus and Verilator)
@provenance@
`resetall
`timescale 1ns / 1ps
`default_nettype none

/*
 * @tb@ — self-checking testbench of @module@ (@title@).
 *
 * Reads STIMULUS_FILE and EXPECTED_FILE (one line per clock-enable, hex fields,
 * formats declared on line 2 and checked here), drives one sample per ce with an
 * idle clock after every fourth, and compares combinational outputs before the
 * clock edge and registered outputs 1 clock after it. Prints the first
 * mismatches, then PASS n=<N> [masked=<M>] or FAIL mismatches=<M> n=<N> first=<index>,
 * and exits non-zero ($fatal) on a mismatch, a timeout or a bad vector file.
 * Plusargs: +dump writes @tb@.vcd; +mask=<n> does not compare the first n samples
 * of the run and from every reset sample on (latency mask); +max_reported=<n>
 * prints n mismatches (default @max@); +max_mismatches=<n> stops at the n-th.
 */
module @tb@;

`include "@params@"

localparam integer CLOCK_PERIOD_NS = 10;
// 64-bit: long vector sets overflow a 32-bit integer.
localparam [63:0] TIMEOUT_NS = 64'd@timeout_clocks@ * CLOCK_PERIOD_NS;

reg clk = 1'b0;
always #(CLOCK_PERIOD_NS / 2) clk <= ~clk;
reg rst = 1'b1;
reg ce = 1'b0;
@ports@
@instance@
integer stimulus_fd;
integer expected_fd;
integer rom_fd;
integer fields;
integer index = 0;
integer mismatches = 0;
integer first_mismatch = -1;
integer mask_samples = 0;
integer max_reported = @max@;
integer max_mismatches = 0;
integer since_reset = 0;
integer masked_count = 0;
reg masked = 1'b0;
reg stop_at_cap = 1'b0;
reg [8*1024-1:0] line;
reg [8*400-1:0] message;
reg vector_rst;
@vector_declarations@
// Prints `message` as a FAIL line and stops with a non-zero exit.
task fail_setup;
    begin
        $display("FAIL %0s", message);
        $fatal(1, "@tb@: %0s", message);
    end
endtask

initial begin
    if ($test$plusargs("dump")) begin
        $dumpfile("@tb@.vcd");
        $dumpvars(0, @tb@);
    end
end

initial begin
    #(TIMEOUT_NS);
    $display("FAIL timeout after %0d ns (%0d of %0d samples)", TIMEOUT_NS, index, VECTOR_COUNT);
    $fatal(1, "@tb@: timeout");
end

initial begin
    if ($value$plusargs("mask=%d", mask_samples) && mask_samples > 0)
        $display("mask: %0d samples after each reset", mask_samples);
    if ($value$plusargs("max_reported=%d", max_reported)) begin end
    if ($value$plusargs("max_mismatches=%d", max_mismatches)) begin end
@rom_checks@@file_checks@
    // Power-on reset.
    rst = 1'b1;
    repeat (2) @(posedge clk);
    @(negedge clk);
    rst = 1'b0;

    for (index = 0; index < VECTOR_COUNT; index = index + 1) begin
        fields = $fscanf(stimulus_fd, "@input_scan@\n", @inputs@);
        if (fields != @input_count@) begin
            $sformat(message, "%0s: line for sample %0d is missing or malformed", STIMULUS_FILE, index);
            fail_setup;
        end
        fields = $fscanf(expected_fd, "@output_scan@\n", @outputs@);
        if (fields != @output_count@) begin
            $sformat(message, "%0s: line for sample %0d is missing or malformed", EXPECTED_FILE, index);
            fail_setup;
        end
        if (vector_rst) since_reset = 0;
        masked = since_reset < mask_samples;
        if (masked) masked_count = masked_count + 1;
        since_reset = since_reset + 1;
        rst = vector_rst;
        ce = 1'b1;
@checks@        if (stop_at_cap) begin
            $display("FAIL mismatches=%0d n=%0d first=%0d (stopped at max_mismatches)", mismatches, index + 1, first_mismatch);
            $fatal(1, "@tb@: stopped at %0d mismatches", mismatches);
        end
    end

    if (mismatches == 0) begin
        if (masked_count > 0)
            $display("PASS n=%0d masked=%0d", VECTOR_COUNT, masked_count);
        else
            $display("PASS n=%0d", VECTOR_COUNT);
        $finish;
    end else begin
        $display("FAIL mismatches=%0d n=%0d first=%0d", mismatches, VECTOR_COUNT, first_mismatch);
        $fatal(1, "@tb@: %0d mismatches", mismatches);
    end
end

endmodule

`resetall
