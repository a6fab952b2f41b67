// Language: Verilog 2001 (+ $fatal, supported by Icarus and Verilator)
{{HEADER}}
`resetall
`timescale 1ns / 1ps
`default_nettype none

/*
 * tb_gyrofx_kf — self-checking testbench of gyrofx_kf.
 *
 * Reads KF_STIMULUS_FILE and KF_EXPECTED_FILE (one line per clock-enable, hex
 * fields, formats declared on line 2 and checked against the parameters),
 * drives one sample per ce with an idle clock after every fourth, and compares
 * out_valid and rate_out bit-exactly 1 clock after each ce (and out_valid low
 * on idle clocks). Prints the first KF_MAX_REPORTED mismatches with sample index,
 * signal, expected and actual (hex and real), then one summary line:
 *     PASS n=<N>      or      FAIL mismatches=<M> n=<N> first=<index>
 * and exits non-zero ($fatal) on a mismatch, a timeout, or a vector file that
 * is missing, malformed or declares other formats.
 *
 * Plusargs: +dump writes tb_gyrofx_kf.vcd.
 */
module tb_gyrofx_kf;

`include "gyrofx_kf_params.vh"

localparam integer KF_MAX_REPORTED = 10;
localparam integer CLOCK_PERIOD_NS = 10;
// 64-bit: long vector sets overflow a 32-bit integer.
localparam [63:0] TIMEOUT_NS = (64'd3 * KF_VECTOR_COUNT + 64'd100) * CLOCK_PERIOD_NS;

reg clk = 1'b0;
always #(CLOCK_PERIOD_NS / 2) clk <= ~clk;

reg rst = 1'b1;
reg ce = 1'b0;
reg [KF_SEL_W-1:0] bw_sel = {KF_SEL_W{1'b0}};
reg signed [KF_IN_W-1:0] z = {KF_IN_W{1'b0}};
wire signed [KF_OUT_W-1:0] rate_out;
wire out_valid;

gyrofx_kf #(
    .IN_W(KF_IN_W), .IN_F(KF_IN_F),
    .STATE_W(KF_STATE_W), .STATE_F(KF_STATE_F),
    .OUT_W(KF_OUT_W), .OUT_F(KF_OUT_F),
    .G1_W(KF_G1_W), .G1_F(KF_G1_F),
    .G2_W(KF_G2_W), .G2_F(KF_G2_F),
    .SEL_W(KF_SEL_W), .ROM_DEPTH(KF_ROM_DEPTH),
    .ROUNDING(KF_ROUNDING), .SATURATE(KF_SATURATE),
    .ROM_FILE(KF_ROM_FILE)
) dut (
    .clk(clk), .rst(rst), .ce(ce), .bw_sel(bw_sel), .z(z),
    .rate_out(rate_out), .out_valid(out_valid)
);

integer rom_fd;
integer stimulus_fd;
integer expected_fd;
integer fields;
integer index;
integer mismatches = 0;
integer first_mismatch = -1;
reg [8*1024-1:0] line;
reg [8*160-1:0] message;
reg [8*32-1:0] declared_0, declared_1, declared_2;
reg [8*32-1:0] wanted_0, wanted_1, wanted_2;
reg vector_rst;
reg [KF_SEL_W-1:0] vector_sel;
reg [KF_IN_W-1:0] vector_z;
reg expected_valid;
reg [KF_OUT_W-1:0] expected_rate;
real expected_real;
real actual_real;

// Prints `message` as a FAIL line and stops with a non-zero exit.
task fail_setup;
    begin
        $display("FAIL %0s", message);
        $fatal(1, "tb_gyrofx_kf: %0s", message);
    end
endtask

task report_mismatch;
    input integer sample;
    input [8*16-1:0] signal;
    begin
        mismatches = mismatches + 1;
        if (first_mismatch < 0) first_mismatch = sample;
        if (mismatches <= KF_MAX_REPORTED) begin
            expected_real = $signed(expected_rate);
            actual_real = $signed(rate_out);
            $display("MISMATCH sample %0d signal %0s expected valid=%b rate_out=%h (%.9g) actual valid=%b rate_out=%h (%.9g)",
                sample, signal, expected_valid, expected_rate, expected_real / (2.0 ** KF_OUT_F),
                out_valid, rate_out, actual_real / (2.0 ** KF_OUT_F));
        end
    end
endtask

initial begin
    if ($test$plusargs("dump")) begin
        $dumpfile("tb_gyrofx_kf.vcd");
        $dumpvars(0, tb_gyrofx_kf);
    end
end

initial begin
    #(TIMEOUT_NS);
    $display("FAIL timeout after %0d ns (%0d of %0d samples)", TIMEOUT_NS, index, KF_VECTOR_COUNT);
    $fatal(1, "tb_gyrofx_kf: timeout");
end

initial begin
    // $readmemh in the DUT only warns about a missing file (Icarus): check it here.
    rom_fd = $fopen(KF_ROM_FILE, "r");
    if (rom_fd == 0) begin
        $sformat(message, "cannot open %0s", KF_ROM_FILE);
        fail_setup;
    end
    $fclose(rom_fd);
    stimulus_fd = $fopen(KF_STIMULUS_FILE, "r");
    if (stimulus_fd == 0) begin
        $sformat(message, "cannot open %0s", KF_STIMULUS_FILE);
        fail_setup;
    end
    expected_fd = $fopen(KF_EXPECTED_FILE, "r");
    if (expected_fd == 0) begin
        $sformat(message, "cannot open %0s", KF_EXPECTED_FILE);
        fail_setup;
    end

    // Line 1: generated-by comment. Line 2: the field formats.
    fields = $fgets(line, stimulus_fd);
    fields = $fscanf(stimulus_fd, "// %s %s %s\n", declared_0, declared_1, declared_2);
    $sformat(wanted_0, "rst:u1.0");
    $sformat(wanted_1, "bw_sel:u%0d.0", KF_SEL_W);
    $sformat(wanted_2, "z:s%0d.%0d", KF_IN_W, KF_IN_F);
    if (fields != 3 || declared_0 != wanted_0 || declared_1 != wanted_1 || declared_2 != wanted_2) begin
        $sformat(message, "%0s declares formats %0s %0s %0s; the testbench's parameters are %0s %0s %0s",
            KF_STIMULUS_FILE, declared_0, declared_1, declared_2, wanted_0, wanted_1, wanted_2);
        fail_setup;
    end
    fields = $fgets(line, expected_fd);
    fields = $fscanf(expected_fd, "// %s %s\n", declared_0, declared_1);
    $sformat(wanted_0, "valid:u1.0");
    $sformat(wanted_1, "rate_out:s%0d.%0d", KF_OUT_W, KF_OUT_F);
    if (fields != 2 || declared_0 != wanted_0 || declared_1 != wanted_1) begin
        $sformat(message, "%0s declares formats %0s %0s; the testbench's parameters are %0s %0s",
            KF_EXPECTED_FILE, declared_0, declared_1, wanted_0, wanted_1);
        fail_setup;
    end

    // Power-on reset.
    index = 0;
    rst = 1'b1;
    repeat (2) @(posedge clk);
    @(negedge clk);
    rst = 1'b0;

    for (index = 0; index < KF_VECTOR_COUNT; index = index + 1) begin
        fields = $fscanf(stimulus_fd, "%h %h %h\n", vector_rst, vector_sel, vector_z);
        if (fields != 3) begin
            $display("FAIL %0s: line for sample %0d is missing or malformed", KF_STIMULUS_FILE, index);
            $fatal(1, "tb_gyrofx_kf: bad stimulus file");
        end
        fields = $fscanf(expected_fd, "%h %h\n", expected_valid, expected_rate);
        if (fields != 2) begin
            $display("FAIL %0s: line for sample %0d is missing or malformed", KF_EXPECTED_FILE, index);
            $fatal(1, "tb_gyrofx_kf: bad expected file");
        end
        rst = vector_rst;
        ce = 1'b1;
        bw_sel = vector_sel;
        z = vector_z;
        @(negedge clk);
        rst = 1'b0;
        ce = 1'b0;
        if (out_valid !== expected_valid || (expected_valid && rate_out !== expected_rate))
            report_mismatch(index, "rate_out");
        if (index % 4 == 3) begin
            @(negedge clk);
            expected_valid = 1'b0;
            if (out_valid !== 1'b0) report_mismatch(index, "out_valid");
        end
    end

    if (mismatches == 0) begin
        $display("PASS n=%0d", KF_VECTOR_COUNT);
        $finish;
    end else begin
        $display("FAIL mismatches=%0d n=%0d first=%0d", mismatches, KF_VECTOR_COUNT, first_mismatch);
        $fatal(1, "tb_gyrofx_kf: %0d mismatches", mismatches);
    end
end

endmodule

`resetall
