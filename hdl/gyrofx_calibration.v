// Language: Verilog 2001

`resetall
`timescale 1ns / 1ps
`default_nettype none

/*
 * gyrofx_calibration — calibrated and combined outputs of mode reversal.
 *
 * Purpose: remove each gyro's estimated bias with the sign of its current mode
 *   and combine the valid outputs. Bit-exact with the calibration step of
 *   gyrofx_model::estimator::FixedEstimator.
 *
 * Algorithm:
 *     out_g    = Q(y_g - p_g * bias_g)       p_g = +1 (mode 1) or -1 (mode 0);
 *                                            exact at max(IN_F, BIAS_F) fraction bits
 *     valid_g  = ~blank_g
 *     combined = both valid ? Q((out_a + out_b) / 2) : the valid one (0 if none)
 *     combined_valid = valid_a | valid_b
 *
 * Latency: combinational (0 clocks).
 */
module gyrofx_calibration #(
    // gyro samples
    parameter integer IN_W = 24,
    parameter integer IN_F = 14,
    // bias estimates
    parameter integer BIAS_W = 28,
    parameter integer BIAS_F = 18,
    // calibrated and combined outputs (CAL_F <= max(IN_F, BIAS_F))
    parameter integer CAL_W = 24,
    parameter integer CAL_F = 14,
    // rounding: 0 floor, 1 ceil, 2 zero, 3 nearest, 4 round, 5 convergent
    parameter integer ROUNDING = 3,
    // overflow: 0 wrap, 1 saturate
    parameter integer SATURATE = 1
) (
    input  wire signed [IN_W-1:0]   y_a,
    input  wire signed [IN_W-1:0]   y_b,
    input  wire                     mode_a,
    input  wire                     mode_b,
    input  wire                     blank_a,
    input  wire                     blank_b,
    input  wire signed [BIAS_W-1:0] bias_a,
    input  wire signed [BIAS_W-1:0] bias_b,
    output wire signed [CAL_W-1:0]  out_a,
    output wire signed [CAL_W-1:0]  out_b,
    output wire                     valid_a,
    output wire                     valid_b,
    output wire signed [CAL_W-1:0]  combined,
    output wire                     combined_valid
);

localparam integer F = (IN_F > BIAS_F) ? IN_F : BIAS_F;
localparam integer IN_I = IN_W - IN_F;
localparam integer BIAS_I = BIAS_W - BIAS_F;
localparam integer D_W = ((IN_I > BIAS_I) ? IN_I : BIAS_I) + 1 + F;

wire signed [D_W-1:0] y_a_wide = {{(D_W-IN_W){y_a[IN_W-1]}}, y_a};
wire signed [D_W-1:0] y_b_wide = {{(D_W-IN_W){y_b[IN_W-1]}}, y_b};
wire signed [D_W-1:0] b_a_wide = {{(D_W-BIAS_W){bias_a[BIAS_W-1]}}, bias_a};
wire signed [D_W-1:0] b_b_wide = {{(D_W-BIAS_W){bias_b[BIAS_W-1]}}, bias_b};
wire signed [D_W-1:0] y_a_aligned = y_a_wide <<< (F - IN_F);
wire signed [D_W-1:0] y_b_aligned = y_b_wide <<< (F - IN_F);
wire signed [D_W-1:0] b_a_aligned = b_a_wide <<< (F - BIAS_F);
wire signed [D_W-1:0] b_b_aligned = b_b_wide <<< (F - BIAS_F);
wire signed [D_W-1:0] corrected_a = mode_a ? y_a_aligned - b_a_aligned : y_a_aligned + b_a_aligned;
wire signed [D_W-1:0] corrected_b = mode_b ? y_b_aligned - b_b_aligned : y_b_aligned + b_b_aligned;

/* verilator lint_off PINCONNECTEMPTY */
gyrofx_quantize #(
    .IN_W(D_W), .IN_F(F), .OUT_W(CAL_W), .OUT_F(CAL_F),
    .ROUNDING(ROUNDING), .SATURATE(SATURATE)
) quantize_a (.in(corrected_a), .out(out_a), .overflow());

gyrofx_quantize #(
    .IN_W(D_W), .IN_F(F), .OUT_W(CAL_W), .OUT_F(CAL_F),
    .ROUNDING(ROUNDING), .SATURATE(SATURATE)
) quantize_b (.in(corrected_b), .out(out_b), .overflow());

wire signed [CAL_W:0] pair_sum = {out_a[CAL_W-1], out_a} + {out_b[CAL_W-1], out_b};
wire signed [CAL_W-1:0] pair_mean;
gyrofx_quantize #(
    .IN_W(CAL_W + 1), .IN_F(CAL_F + 1), .OUT_W(CAL_W), .OUT_F(CAL_F),
    .ROUNDING(ROUNDING), .SATURATE(SATURATE)
) quantize_mean (.in(pair_sum), .out(pair_mean), .overflow());
/* verilator lint_on PINCONNECTEMPTY */

assign valid_a = ~blank_a;
assign valid_b = ~blank_b;
assign combined_valid = valid_a | valid_b;
assign combined = (valid_a && valid_b) ? pair_mean :
                  valid_a ? out_a :
                  valid_b ? out_b : {CAL_W{1'b0}};

endmodule

`resetall
