// Language: Verilog 2001

`resetall
`timescale 1ns / 1ps
`default_nettype none

/*
 * gyrofx_top — the mode-reversal signal chain: sequencer, bias estimator,
 *   calibration and steady-state KF.
 *
 * Purpose: from the samples of two collinear gyros (taken in the modes this
 *   module requests on mode_a / mode_b), produce the calibrated, filtered rate.
 *   Bit-exact with gyrofx_model::chain::FixedChain.
 *
 * Algorithm (per ce): the sequencer describes the current sample; the
 *   calibration removes the current bias estimates and combines the valid
 *   outputs (registered); the KF steps on the combined value when at least
 *   one gyro is valid (its ce is the registered ce & combined_valid); the
 *   estimator accumulates the sample and updates the estimates at a window's
 *   end.
 *
 * Latency: mode_a/mode_b describe the sample to be taken at the next ce
 *   (0 clocks: drive the gyro front end with them); rate_out/out_valid,
 *   bias_a/bias_b/estimated are valid 6 clocks after ce (out_valid low when
 *   both gyros were blanked; the estimates are those after the sample).
 *   ce at most every 6th clock (the estimator's pipeline); the sample rate
 *   leaves thousands. Timing: docs/blocks/top.md.
 */
module gyrofx_top #(
    // sequencer
    parameter integer INTERVAL_LENGTH = 150,
    parameter integer INTERVALS = 4,
    parameter [INTERVALS-1:0] PATTERN = 4'b0101,
    parameter integer BLANK = 10,
    parameter integer STAGGER = 0,
    parameter integer PHASE_W = 8,
    parameter integer INTERVAL_W = 2,
    // gyro samples (also the KF input and the calibrated format)
    parameter integer IN_W = 24,
    parameter integer IN_F = 14,
    // estimator
    parameter integer ACC_W = 32,
    parameter integer RECIP_W = 18,
    parameter integer RECIP_F = 24,
    parameter [RECIP_W-1:0] RECIP = 18'd119837,
    parameter integer MEAN_W = 28,
    parameter integer MEAN_F = 18,
    parameter integer GAIN_W = 18,
    parameter integer GAIN_F = 17,
    parameter integer DOT_W = 49,
    parameter integer BIAS_W = 28,
    parameter integer BIAS_F = 18,
    parameter integer SMOOTH = 0,
    parameter GAIN_ROM_FILE = "estimator_gains.mem",
    // KF
    parameter integer STATE_W = 36,
    parameter integer STATE_F = 26,
    parameter integer OUT_W = 24,
    parameter integer OUT_F = 14,
    parameter integer G1_W = 18,
    parameter integer G1_F = 17,
    parameter integer G2_W = 18,
    parameter integer G2_F = 38,
    parameter integer SEL_W = 2,
    parameter integer ROM_DEPTH = 3,
    parameter KF_ROM_FILE = "kf_coefficients.mem",
    // rounding: 0 floor, 1 ceil, 2 zero, 3 nearest, 4 round, 5 convergent
    parameter integer ROUNDING = 3,
    // overflow: 0 wrap, 1 saturate
    parameter integer SATURATE = 1
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
    .clk(clk), .rst(rst), .ce(ce),
    .mode_a(mode_a), .mode_b(mode_b), .blank_a(blank_a), .blank_b(blank_b),
    .interval_a(interval_a), .interval_b(interval_b), .done_a(done_a), .done_b(done_b),
    .window_done(window_done)
);

gyrofx_bias_estimator #(
    .IN_W(IN_W), .IN_F(IN_F), .ACC_W(ACC_W), .RECIP_W(RECIP_W), .RECIP_F(RECIP_F),
    .RECIP(RECIP), .MEAN_W(MEAN_W), .MEAN_F(MEAN_F), .GAIN_W(GAIN_W), .GAIN_F(GAIN_F),
    .DOT_W(DOT_W), .BIAS_W(BIAS_W), .BIAS_F(BIAS_F), .INTERVALS(INTERVALS),
    .INTERVAL_W(INTERVAL_W), .SMOOTH(SMOOTH), .ROUNDING(ROUNDING), .SATURATE(SATURATE),
    .ROM_FILE(GAIN_ROM_FILE)
) estimator (
    .clk(clk), .rst(rst), .ce(ce), .y_a(y_a), .y_b(y_b),
    .blank_a(blank_a), .blank_b(blank_b), .done_a(done_a), .done_b(done_b),
    .interval_a(interval_a), .interval_b(interval_b), .window_done(window_done),
    .bias_a(bias_a), .bias_b(bias_b), .estimated(estimated)
);

wire signed [IN_W-1:0] combined;
wire combined_valid;
/* verilator lint_off PINCONNECTEMPTY */
gyrofx_calibration #(
    .IN_W(IN_W), .IN_F(IN_F), .BIAS_W(BIAS_W), .BIAS_F(BIAS_F),
    .CAL_W(IN_W), .CAL_F(IN_F), .ROUNDING(ROUNDING), .SATURATE(SATURATE)
) calibration (
    .y_a(y_a), .y_b(y_b), .mode_a(mode_a), .mode_b(mode_b),
    .blank_a(blank_a), .blank_b(blank_b), .bias_a(bias_a), .bias_b(bias_b),
    .out_a(), .out_b(), .valid_a(), .valid_b(),
    .combined(combined), .combined_valid(combined_valid)
);
/* verilator lint_on PINCONNECTEMPTY */

// The calibration's output is registered: the KF takes it one clock after ce, so the
// estimator's bias registers never reach the KF's products in one clock.
reg signed [IN_W-1:0] combined_reg = {IN_W{1'b0}};
reg [SEL_W-1:0] bw_sel_reg = {SEL_W{1'b0}};
reg kf_ce = 1'b0;
always @(posedge clk) begin
    if (ce) begin
        combined_reg <= combined;
        bw_sel_reg <= bw_sel;
    end
    kf_ce <= ce && combined_valid;
    if (rst) kf_ce <= 1'b0;
end

wire signed [OUT_W-1:0] kf_rate;
wire kf_valid;
gyrofx_kf #(
    .IN_W(IN_W), .IN_F(IN_F), .STATE_W(STATE_W), .STATE_F(STATE_F),
    .OUT_W(OUT_W), .OUT_F(OUT_F), .G1_W(G1_W), .G1_F(G1_F), .G2_W(G2_W), .G2_F(G2_F),
    .SEL_W(SEL_W), .ROM_DEPTH(ROM_DEPTH), .ROUNDING(ROUNDING), .SATURATE(SATURATE),
    .ROM_FILE(KF_ROM_FILE)
) kf (
    .clk(clk), .rst(rst), .ce(kf_ce), .bw_sel(bw_sel_reg), .z(combined_reg),
    .rate_out(kf_rate), .out_valid(kf_valid)
);

// One more register on the rate, so that it comes with the estimates (6 clocks after ce).
reg signed [OUT_W-1:0] rate_reg = {OUT_W{1'b0}};
reg valid_reg = 1'b0;
always @(posedge clk) begin
    if (kf_valid) rate_reg <= kf_rate;
    valid_reg <= kf_valid;
    if (rst) valid_reg <= 1'b0;
end
assign rate_out = rate_reg;
assign out_valid = valid_reg;

`ifndef SYNTHESIS
// Simulation only (yosys defines SYNTHESIS): the chain takes a sample at most every 6 clocks
// (gyrofx_job::pipeline); a sooner ce stops the simulation, naming this instance.
gyrofx_spacing_check #(
    .MIN_CLOCKS_PER_SAMPLE(6),
    .BLOCK_NAME("gyrofx_top")
) spacing_check (
    .clk(clk),
    .rst(rst),
    .ce(ce)
);
`endif

endmodule

`resetall
