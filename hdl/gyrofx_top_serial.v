// Language: Verilog 2001

`resetall
`timescale 1ns / 1ps
`default_nettype none

/*
 * gyrofx_top_serial — the mode-reversal chain, time-multiplexed: the sequencer and
 *   gyrofx_serial_engine (one shared multiplier) in place of the parallel
 *   estimator, calibration and KF of gyrofx_top.
 *
 * Purpose: the same chain as gyrofx_top, bit-exact with
 *   gyrofx_model::chain::FixedChain, on a small FPGA: the sample rate (hundreds of
 *   samples/s) leaves thousands of clocks per sample, so one multiplier does the
 *   work of forty.
 *
 * Ports: those of gyrofx_top; mode_a/mode_b describe the sample to be taken at the
 *   next ce (0 clocks), as there.
 *
 * Latency: rate_out/out_valid, bias_a/bias_b/estimated show SETTLE = 4 * (sample
 *   program length) clocks after the ce clock (out_valid high for one clock, low
 *   when both gyros were blanked). ce at most every SETTLE + 1 clocks: a ce while
 *   the engine is busy is ignored by the sequencer too. gyrofx writes the program
 *   for the config and states SETTLE (manifest.json, the block's README).
 *   rst (synchronous) clears the outputs and the sequencer at once; the next
 *   sample's program clears the engine's state before it reads it.
 */
module gyrofx_top_serial #(
    // sequencer
    parameter integer INTERVAL_LENGTH = 150,
    parameter integer INTERVALS = 4,
    parameter [INTERVALS-1:0] PATTERN = 4'b0101,
    parameter integer BLANK = 10,
    parameter integer STAGGER = 0,
    parameter integer PHASE_W = 8,
    parameter integer INTERVAL_W = 2,
    // gyro samples, rate output, bias outputs: widths
    parameter integer IN_W = 24,
    parameter integer OUT_W = 24,
    parameter integer BIAS_W = 28,
    parameter integer SEL_W = 2,
    // KF gain words: bw_sel must be below ROM_DEPTH
    parameter integer ROM_DEPTH = 3,
    // the engine (gyrofx_serial_engine): written by gyrofx for the config
    parameter integer ACC_W = 32,
    parameter integer ADDR_W = 6,
    parameter integer COEF_ADDR_W = 5,
    parameter integer RAM_DEPTH = 64,
    parameter integer COEF_DEPTH = 32,
    parameter integer PROGRAM_DEPTH = 512,
    parameter integer RAM_INDEX_SHIFT = 1,
    parameter integer COEF_INDEX_SHIFT = 2,
    // rounding: 0 floor, 1 ceil, 2 zero, 3 nearest, 4 round, 5 convergent
    parameter integer ROUNDING = 3,
    parameter PROGRAM_FILE = "serial_program.mem",
    parameter COEFFICIENT_FILE = "serial_coefficients.mem"
) (
    input  wire                     clk,
    input  wire                     rst,
    input  wire                     ce,
    input  wire [SEL_W-1:0]         bw_sel,
    input  wire signed [IN_W-1:0]   y_a,
    input  wire signed [IN_W-1:0]   y_b,
    output wire                     mode_a,
    output wire                     mode_b,
    output wire signed [OUT_W-1:0]  rate_out,
    output wire                     out_valid,
    output wire signed [BIAS_W-1:0] bias_a,
    output wire signed [BIAS_W-1:0] bias_b,
    output wire                     estimated
);

initial begin
    if (ROM_DEPTH < 1 || ROM_DEPTH > (1 << SEL_W)) begin
        $display("%m: ROM_DEPTH (%0d) must be 1..2^SEL_W (%0d)", ROM_DEPTH, 1 << SEL_W);
        $finish;
    end
end

wire busy;
wire take = ce && !busy;
wire blank_a;
wire blank_b;
wire [INTERVAL_W-1:0] interval_a;
wire [INTERVAL_W-1:0] interval_b;
wire done_a;
wire done_b;
wire window_done;

gyrofx_sequencer #(
    .INTERVAL_LENGTH(INTERVAL_LENGTH), .INTERVALS(INTERVALS), .PATTERN(PATTERN),
    .BLANK(BLANK), .STAGGER(STAGGER), .PHASE_W(PHASE_W), .INTERVAL_W(INTERVAL_W)
) sequencer (
    .clk(clk), .rst(rst), .ce(take),
    .mode_a(mode_a), .mode_b(mode_b), .blank_a(blank_a), .blank_b(blank_b),
    .interval_a(interval_a), .interval_b(interval_b), .done_a(done_a), .done_b(done_b),
    .window_done(window_done)
);

gyrofx_serial_engine #(
    .IN_W(IN_W), .OUT_W(OUT_W), .BIAS_W(BIAS_W), .SEL_W(SEL_W), .INTERVAL_W(INTERVAL_W),
    .ACC_W(ACC_W), .ADDR_W(ADDR_W), .COEF_ADDR_W(COEF_ADDR_W), .RAM_DEPTH(RAM_DEPTH),
    .COEF_DEPTH(COEF_DEPTH), .PROGRAM_DEPTH(PROGRAM_DEPTH),
    .RAM_INDEX_SHIFT(RAM_INDEX_SHIFT), .COEF_INDEX_SHIFT(COEF_INDEX_SHIFT),
    .ROUNDING(ROUNDING), .PROGRAM_FILE(PROGRAM_FILE), .COEFFICIENT_FILE(COEFFICIENT_FILE)
) engine (
    .clk(clk), .rst(rst), .ce(take), .bw_sel(bw_sel), .y_a(y_a), .y_b(y_b),
    .mode_a(mode_a), .mode_b(mode_b), .blank_a(blank_a), .blank_b(blank_b),
    .done_a(done_a), .done_b(done_b), .window_done(window_done),
    .interval_a(interval_a), .interval_b(interval_b),
    .rate_out(rate_out), .out_valid(out_valid), .bias_a(bias_a), .bias_b(bias_b),
    .estimated(estimated), .busy(busy)
);

`ifndef SYNTHESIS
// Simulation only (yosys defines SYNTHESIS): a ce while the engine still runs the previous
// sample's program would be dropped (take is low), and the vectors would lose a sample without
// a word; stop the simulation instead, naming this instance. gyrofx_job::pipeline gives the
// spacing (the manifest's min_clocks_per_sample).
always @(posedge clk) begin
    if (!rst && ce && busy) begin
        $display("FAIL %m: a sample while the engine still runs the previous one; gyrofx_top_serial takes one at most every min_clocks_per_sample clocks (manifest.json)");
        $fatal(1, "%m: a sample while busy");
    end
end
`endif

endmodule

`resetall
