// Language: Verilog 2001

`resetall
`timescale 1ns / 1ps
`default_nettype none

/*
 * gyrofx_bias_estimator — least-squares bias estimator of mode reversal.
 *
 * Purpose: estimate the biases of gyros A and B from their interval means over
 *   a window of W intervals (SPEC §1.3). Bit-exact with
 *   gyrofx_model::estimator::FixedEstimator (its calibration lives in
 *   gyrofx_calibration).
 *
 * Algorithm (per gyro g, on ce):
 *     total_g  = acc_g + (blank_g ? 0 : y_g)                 exact, ACC_W bits
 *     at done_g:   mean_g[interval_g] <= Q(total_g * RECIP)   MEAN format
 *                  acc_g <= 0          (else acc_g <= total_g)
 *     at window_done (means of this cycle included):
 *         new_g  = Q(sum_j G_g[j] * m[j]),  m = {mA0, mB0, mA1, mB1, ...}
 *         bias_g <= estimated && SMOOTH > 0
 *                   ? Q(bias_g + (new_g - bias_g) / 2^SMOOTH) : new_g
 *         estimated <= 1
 *   ROM_FILE holds G: 2*W words for A's row, then 2*W for B's, each GAIN_W bits.
 *   Power-of-two gains are constants that synthesis reduces to shifts.
 *
 * Pipeline: the running sums update on ce; an interval's end runs five
 *   register stages, one sample at a time: the sums (clock 1), their products
 *   by RECIP (2), the rounded means stored (3), the gain products (4), the dot
 *   products (5); the estimates update on the clock after (bias_a, bias_b,
 *   estimated are valid 6 clocks after the ce of a window's last sample).
 *   ce at most every 6th clock: a sample's calibration reads the estimates of
 *   the windows before it. One product, sum or requantizer per clock
 *   (timing: docs/blocks/estimator.md). rst is synchronous and clears the
 *   pipeline too.
 */
module gyrofx_bias_estimator #(
    // gyro samples: width and fraction bits
    parameter integer IN_W = 24,
    parameter integer IN_F = 14,
    // accumulator width (fraction IN_F): IN_W + bits to count an interval
    parameter integer ACC_W = 32,
    // reciprocal 1/(L - M): format and code
    parameter integer RECIP_W = 18,
    parameter integer RECIP_F = 24,
    parameter [RECIP_W-1:0] RECIP = 18'd119837,
    // interval means
    parameter integer MEAN_W = 28,
    parameter integer MEAN_F = 18,
    // least-squares gains
    parameter integer GAIN_W = 18,
    parameter integer GAIN_F = 17,
    // exact dot product width (fraction GAIN_F + MEAN_F)
    parameter integer DOT_W = 49,
    // bias estimates
    parameter integer BIAS_W = 28,
    parameter integer BIAS_F = 18,
    // W intervals per window and the width of an interval index
    parameter integer INTERVALS = 4,
    parameter integer INTERVAL_W = 2,
    // smoothing shift s (0: none)
    parameter integer SMOOTH = 0,
    // rounding: 0 floor, 1 ceil, 2 zero, 3 nearest, 4 round, 5 convergent
    parameter integer ROUNDING = 3,
    // overflow: 0 wrap, 1 saturate
    parameter integer SATURATE = 1,
    // gain ROM image for $readmemh
    parameter ROM_FILE = "estimator_gains.mem"
) (
    input  wire                    clk,
    input  wire                    rst,
    input  wire                    ce,
    input  wire signed [IN_W-1:0]  y_a,
    input  wire signed [IN_W-1:0]  y_b,
    input  wire                    blank_a,
    input  wire                    blank_b,
    input  wire                    done_a,
    input  wire                    done_b,
    input  wire [INTERVAL_W-1:0]   interval_a,
    input  wire [INTERVAL_W-1:0]   interval_b,
    input  wire                    window_done,
    output wire signed [BIAS_W-1:0] bias_a,
    output wire signed [BIAS_W-1:0] bias_b,
    output wire                    estimated
);

localparam integer TERMS = 2 * INTERVALS;
localparam integer PRODUCT_W = ACC_W + RECIP_W;
localparam integer TERM_W = GAIN_W + MEAN_W;
localparam integer SMOOTH_W = BIAS_W + 2 + SMOOTH;

initial begin
    if (ACC_W <= IN_W || DOT_W < TERM_W) begin
        $display("%m: ACC_W (%0d) must exceed IN_W (%0d), DOT_W (%0d) hold GAIN_W + MEAN_W", ACC_W, IN_W, DOT_W);
        $finish;
    end
end

reg [GAIN_W-1:0] gain_rom [0:2*TERMS-1];
initial begin
    $readmemh(ROM_FILE, gain_rom);
end

reg signed [ACC_W-1:0] acc_a_reg = {ACC_W{1'b0}};
reg signed [ACC_W-1:0] acc_b_reg = {ACC_W{1'b0}};
reg signed [MEAN_W-1:0] mean_a_reg [0:INTERVALS-1];
reg signed [MEAN_W-1:0] mean_b_reg [0:INTERVALS-1];
reg signed [BIAS_W-1:0] bias_a_reg = {BIAS_W{1'b0}};
reg signed [BIAS_W-1:0] bias_b_reg = {BIAS_W{1'b0}};
reg estimated_reg = 1'b0;

integer i;
initial begin
    for (i = 0; i < INTERVALS; i = i + 1) begin
        mean_a_reg[i] = {MEAN_W{1'b0}};
        mean_b_reg[i] = {MEAN_W{1'b0}};
    end
end

// The interval's end moving down the pipeline: the sums and which means they end (stage 1),
// the scaled sums (2), the means stored (3), the gain products (4), the dot products (5).
reg signed [ACC_W-1:0] total_a_reg = {ACC_W{1'b0}};
reg signed [ACC_W-1:0] total_b_reg = {ACC_W{1'b0}};
reg [1:0] done_a_stage = 2'b00;
reg [1:0] done_b_stage = 2'b00;
reg [4:0] window_stage = 5'b00000;
reg [INTERVAL_W-1:0] interval_a_1 = {INTERVAL_W{1'b0}};
reg [INTERVAL_W-1:0] interval_b_1 = {INTERVAL_W{1'b0}};
reg [INTERVAL_W-1:0] interval_a_2 = {INTERVAL_W{1'b0}};
reg [INTERVAL_W-1:0] interval_b_2 = {INTERVAL_W{1'b0}};

// Running sums including the current sample.
wire signed [ACC_W-1:0] y_a_acc = blank_a ? {ACC_W{1'b0}} : {{(ACC_W-IN_W){y_a[IN_W-1]}}, y_a};
wire signed [ACC_W-1:0] y_b_acc = blank_b ? {ACC_W{1'b0}} : {{(ACC_W-IN_W){y_b[IN_W-1]}}, y_b};
wire signed [ACC_W-1:0] total_a = acc_a_reg + y_a_acc;
wire signed [ACC_W-1:0] total_b = acc_b_reg + y_b_acc;

// Interval means.
wire signed [RECIP_W-1:0] recip = RECIP;
reg signed [PRODUCT_W-1:0] scaled_a = {PRODUCT_W{1'b0}};
reg signed [PRODUCT_W-1:0] scaled_b = {PRODUCT_W{1'b0}};
wire signed [MEAN_W-1:0] mean_a_new;
wire signed [MEAN_W-1:0] mean_b_new;

/* verilator lint_off PINCONNECTEMPTY */
gyrofx_quantize #(
    .IN_W(PRODUCT_W), .IN_F(IN_F + RECIP_F), .OUT_W(MEAN_W), .OUT_F(MEAN_F),
    .ROUNDING(ROUNDING), .SATURATE(SATURATE)
) quantize_mean_a (.in(scaled_a), .out(mean_a_new), .overflow());

gyrofx_quantize #(
    .IN_W(PRODUCT_W), .IN_F(IN_F + RECIP_F), .OUT_W(MEAN_W), .OUT_F(MEAN_F),
    .ROUNDING(ROUNDING), .SATURATE(SATURATE)
) quantize_mean_b (.in(scaled_b), .out(mean_b_new), .overflow());

// Dot products over the means of this window (this sample's new means stored by now).
wire signed [DOT_W-1:0] dot_a_next;
wire signed [DOT_W-1:0] dot_b_next;
reg signed [DOT_W-1:0] dot_a = {DOT_W{1'b0}};
reg signed [DOT_W-1:0] dot_b = {DOT_W{1'b0}};

genvar j;
generate
    for (j = 0; j < TERMS; j = j + 1) begin : g_term
        wire signed [MEAN_W-1:0] mean;
        if (j % 2 == 0) begin : g_a
            assign mean = mean_a_reg[j / 2];
        end else begin : g_b
            assign mean = mean_b_reg[j / 2];
        end
        wire signed [GAIN_W-1:0] gain_a = gain_rom[j];
        wire signed [GAIN_W-1:0] gain_b = gain_rom[TERMS + j];
        reg signed [TERM_W-1:0] term_a = {TERM_W{1'b0}};
        reg signed [TERM_W-1:0] term_b = {TERM_W{1'b0}};
        // Loaded on every clock: read only on the clock after the one that loads the window's.
        always @(posedge clk) begin
            term_a <= gain_a * mean;
            term_b <= gain_b * mean;
        end
        wire signed [DOT_W-1:0] term_a_wide = {{(DOT_W-TERM_W){term_a[TERM_W-1]}}, term_a};
        wire signed [DOT_W-1:0] term_b_wide = {{(DOT_W-TERM_W){term_b[TERM_W-1]}}, term_b};
        // Running sums, chained from block to block.
        wire signed [DOT_W-1:0] sum_a;
        wire signed [DOT_W-1:0] sum_b;
        if (j == 0) begin : g_first
            assign sum_a = term_a_wide;
            assign sum_b = term_b_wide;
        end else begin : g_next
            assign sum_a = g_term[j - 1].sum_a + term_a_wide;
            assign sum_b = g_term[j - 1].sum_b + term_b_wide;
        end
    end
endgenerate

assign dot_a_next = g_term[TERMS - 1].sum_a;
assign dot_b_next = g_term[TERMS - 1].sum_b;

wire signed [BIAS_W-1:0] new_a;
wire signed [BIAS_W-1:0] new_b;
gyrofx_quantize #(
    .IN_W(DOT_W), .IN_F(GAIN_F + MEAN_F), .OUT_W(BIAS_W), .OUT_F(BIAS_F),
    .ROUNDING(ROUNDING), .SATURATE(SATURATE)
) quantize_new_a (.in(dot_a), .out(new_a), .overflow());

gyrofx_quantize #(
    .IN_W(DOT_W), .IN_F(GAIN_F + MEAN_F), .OUT_W(BIAS_W), .OUT_F(BIAS_F),
    .ROUNDING(ROUNDING), .SATURATE(SATURATE)
) quantize_new_b (.in(dot_b), .out(new_b), .overflow());

// Smoothing: bias + (new - bias) / 2^SMOOTH, exact at BIAS_F + SMOOTH fraction bits.
wire signed [SMOOTH_W-1:0] old_a_wide = {{(SMOOTH_W-BIAS_W){bias_a_reg[BIAS_W-1]}}, bias_a_reg};
wire signed [SMOOTH_W-1:0] old_b_wide = {{(SMOOTH_W-BIAS_W){bias_b_reg[BIAS_W-1]}}, bias_b_reg};
wire signed [SMOOTH_W-1:0] new_a_wide = {{(SMOOTH_W-BIAS_W){new_a[BIAS_W-1]}}, new_a};
wire signed [SMOOTH_W-1:0] new_b_wide = {{(SMOOTH_W-BIAS_W){new_b[BIAS_W-1]}}, new_b};
wire signed [SMOOTH_W-1:0] smooth_a_sum = (old_a_wide <<< SMOOTH) + (new_a_wide - old_a_wide);
wire signed [SMOOTH_W-1:0] smooth_b_sum = (old_b_wide <<< SMOOTH) + (new_b_wide - old_b_wide);
wire signed [BIAS_W-1:0] smooth_a;
wire signed [BIAS_W-1:0] smooth_b;
gyrofx_quantize #(
    .IN_W(SMOOTH_W), .IN_F(BIAS_F + SMOOTH), .OUT_W(BIAS_W), .OUT_F(BIAS_F),
    .ROUNDING(ROUNDING), .SATURATE(SATURATE)
) quantize_smooth_a (.in(smooth_a_sum), .out(smooth_a), .overflow());

gyrofx_quantize #(
    .IN_W(SMOOTH_W), .IN_F(BIAS_F + SMOOTH), .OUT_W(BIAS_W), .OUT_F(BIAS_F),
    .ROUNDING(ROUNDING), .SATURATE(SATURATE)
) quantize_smooth_b (.in(smooth_b_sum), .out(smooth_b), .overflow());
/* verilator lint_on PINCONNECTEMPTY */

wire use_smoothing = estimated_reg && (SMOOTH > 0);

always @(posedge clk) begin
    done_a_stage <= {done_a_stage[0], ce && done_a};
    done_b_stage <= {done_b_stage[0], ce && done_b};
    window_stage <= {window_stage[3:0], ce && window_done};
    if (ce) begin
        acc_a_reg <= done_a ? {ACC_W{1'b0}} : total_a;
        acc_b_reg <= done_b ? {ACC_W{1'b0}} : total_b;
    end
    // The pipeline's data registers load on every clock: each is read only on the clock after
    // the one that loads the sample's (fewer enables: the iCE40 shares one per logic block).
    total_a_reg <= total_a;
    total_b_reg <= total_b;
    interval_a_1 <= interval_a;
    interval_b_1 <= interval_b;
    scaled_a <= total_a_reg * recip;
    scaled_b <= total_b_reg * recip;
    interval_a_2 <= interval_a_1;
    interval_b_2 <= interval_b_1;
    dot_a <= dot_a_next;
    dot_b <= dot_b_next;
    if (done_a_stage[1]) mean_a_reg[interval_a_2] <= mean_a_new;
    if (done_b_stage[1]) mean_b_reg[interval_b_2] <= mean_b_new;
    if (window_stage[4]) begin
        bias_a_reg <= use_smoothing ? smooth_a : new_a;
        bias_b_reg <= use_smoothing ? smooth_b : new_b;
        estimated_reg <= 1'b1;
    end

    if (rst) begin
        done_a_stage <= 2'b00;
        done_b_stage <= 2'b00;
        window_stage <= 5'b00000;
        acc_a_reg <= {ACC_W{1'b0}};
        acc_b_reg <= {ACC_W{1'b0}};
        for (i = 0; i < INTERVALS; i = i + 1) begin
            mean_a_reg[i] <= {MEAN_W{1'b0}};
            mean_b_reg[i] <= {MEAN_W{1'b0}};
        end
        bias_a_reg <= {BIAS_W{1'b0}};
        bias_b_reg <= {BIAS_W{1'b0}};
        estimated_reg <= 1'b0;
    end
end

assign bias_a = bias_a_reg;
assign bias_b = bias_b_reg;
assign estimated = estimated_reg;

`ifndef SYNTHESIS
// Simulation only (yosys defines SYNTHESIS): the estimator takes a sample at most every 6 clocks
// (gyrofx_job::pipeline); a sooner ce stops the simulation, naming this instance.
gyrofx_spacing_check #(
    .MIN_CLOCKS_PER_SAMPLE(6),
    .BLOCK_NAME("gyrofx_bias_estimator")
) spacing_check (
    .clk(clk),
    .rst(rst),
    .ce(ce)
);
`endif

endmodule

`resetall
