// Language: Verilog 2001

`resetall
`timescale 1ns / 1ps
`default_nettype none

/*
 * gyrofx_demodulator — I/Q demodulator: ADC sample times the NCO's sine and
 * cosine, each product low-passed by a first-order leaky integrator.
 *
 * Purpose: amplitude and phase of the resonator's drive and sense signals
 *   (SPEC 1.6). For adc = a sin(theta + phi) and references A sin(theta),
 *   A cos(theta): I = a A cos(phi), Q = a A sin(phi) after the low-pass.
 *   Bit-exact with gyrofx_model::gyro_loop::demodulator::FixedDemodulator.
 *
 * Algorithm (per sample, ce high; per channel, ref = ref_sin for I, ref_cos for Q):
 *     p   = Q(2 * adc * ref)                   PROD format (the 2 is free: one
 *                                               fraction bit less on the exact product)
 *     y  <= Q(y + (p - y) * 2^-SHIFT)          STATE format, computed exactly as
 *                                               (y << SHIFT) + (p - y) at STATE_F + SHIFT
 *     out <= Q(y after the update)             OUT format
 *   Every Q(.) is gyrofx_quantize with ROUNDING/SATURATE. The state holds every
 *   product (STATE_F >= PROD_F, no fewer integer bits), so y never overflows.
 *
 * Pipeline: one register stage. i_out, q_out and out_valid are valid 1 clock
 *   after ce. A clock with rst high clears both states and out_valid (rst wins
 *   over ce).
 */
module gyrofx_demodulator #(
    // ADC sample: width and fraction bits (full-scale units)
    parameter integer ADC_W = 24,
    parameter integer ADC_F = 23,
    // NCO references: width and fraction bits
    parameter integer REF_W = 18,
    parameter integer REF_F = 17,
    // quantized product 2 * adc * ref: width and fraction bits
    parameter integer PROD_W = 32,
    parameter integer PROD_F = 30,
    // low-pass state: width and fraction bits (STATE_F >= PROD_F,
    // STATE_W - STATE_F >= PROD_W - PROD_F)
    parameter integer STATE_W = 40,
    parameter integer STATE_F = 38,
    // I and Q outputs: width and fraction bits (OUT_F <= STATE_F)
    parameter integer OUT_W = 24,
    parameter integer OUT_F = 23,
    // low-pass coefficient 2^-SHIFT (1..24)
    parameter integer SHIFT = 8,
    // rounding: 0 floor, 1 ceil, 2 zero, 3 nearest, 4 round, 5 convergent
    parameter integer ROUNDING = 3,
    // overflow: 0 wrap, 1 saturate
    parameter integer SATURATE = 1
) (
    input  wire                     clk,
    input  wire                     rst,
    input  wire                     ce,
    input  wire signed [ADC_W-1:0]  adc,
    input  wire signed [REF_W-1:0]  ref_sin,
    input  wire signed [REF_W-1:0]  ref_cos,
    output wire signed [OUT_W-1:0]  i_out,
    output wire signed [OUT_W-1:0]  q_out,
    output wire                     out_valid
);

// Exact product 2 * adc * ref: the integer adc * ref at one fraction bit less.
localparam integer X_W = ADC_W + REF_W;
localparam integer X_F = ADC_F + REF_F - 1;
// Exact update (y << SHIFT) + (p - y) at STATE_F + SHIFT fraction bits.
localparam integer U_W = STATE_W + SHIFT + 1;
localparam integer U_F = STATE_F + SHIFT;
// Aligns a product to the state's fraction bits.
localparam integer ALIGN = STATE_F - PROD_F;

initial begin
    if (ALIGN < 0 || STATE_W - STATE_F < PROD_W - PROD_F) begin
        $display("%m: the state (%0d.%0d) must hold every product (%0d.%0d)",
            STATE_W, STATE_F, PROD_W, PROD_F);
        $finish;
    end
    if (SHIFT < 1) begin
        $display("%m: SHIFT (%0d) must be >= 1", SHIFT);
        $finish;
    end
end

reg signed [STATE_W-1:0] y_i_reg = {STATE_W{1'b0}};
reg signed [STATE_W-1:0] y_q_reg = {STATE_W{1'b0}};
reg signed [OUT_W-1:0] i_reg = {OUT_W{1'b0}};
reg signed [OUT_W-1:0] q_reg = {OUT_W{1'b0}};
reg valid_reg = 1'b0;

wire signed [X_W-1:0] x_i = adc * ref_sin;
wire signed [X_W-1:0] x_q = adc * ref_cos;

wire signed [PROD_W-1:0] p_i;
wire signed [PROD_W-1:0] p_q;
wire signed [STATE_W-1:0] y_i_next;
wire signed [STATE_W-1:0] y_q_next;
wire signed [OUT_W-1:0] i_next;
wire signed [OUT_W-1:0] q_next;

/* verilator lint_off PINCONNECTEMPTY */
gyrofx_quantize #(
    .IN_W(X_W), .IN_F(X_F), .OUT_W(PROD_W), .OUT_F(PROD_F),
    .ROUNDING(ROUNDING), .SATURATE(SATURATE)
) quantize_p_i (
    .in(x_i), .out(p_i), .overflow()
);

gyrofx_quantize #(
    .IN_W(X_W), .IN_F(X_F), .OUT_W(PROD_W), .OUT_F(PROD_F),
    .ROUNDING(ROUNDING), .SATURATE(SATURATE)
) quantize_p_q (
    .in(x_q), .out(p_q), .overflow()
);
/* verilator lint_on PINCONNECTEMPTY */

// The updates, exact in U_W bits.
wire signed [U_W-1:0] y_i_wide = {{(U_W-STATE_W){y_i_reg[STATE_W-1]}}, y_i_reg};
wire signed [U_W-1:0] y_q_wide = {{(U_W-STATE_W){y_q_reg[STATE_W-1]}}, y_q_reg};
wire signed [U_W-1:0] p_i_wide = {{(U_W-PROD_W){p_i[PROD_W-1]}}, p_i};
wire signed [U_W-1:0] p_q_wide = {{(U_W-PROD_W){p_q[PROD_W-1]}}, p_q};
wire signed [U_W-1:0] update_i = (y_i_wide <<< SHIFT) + ((p_i_wide <<< ALIGN) - y_i_wide);
wire signed [U_W-1:0] update_q = (y_q_wide <<< SHIFT) + ((p_q_wide <<< ALIGN) - y_q_wide);

/* verilator lint_off PINCONNECTEMPTY */
gyrofx_quantize #(
    .IN_W(U_W), .IN_F(U_F), .OUT_W(STATE_W), .OUT_F(STATE_F),
    .ROUNDING(ROUNDING), .SATURATE(SATURATE)
) quantize_y_i (
    .in(update_i), .out(y_i_next), .overflow()
);

gyrofx_quantize #(
    .IN_W(U_W), .IN_F(U_F), .OUT_W(STATE_W), .OUT_F(STATE_F),
    .ROUNDING(ROUNDING), .SATURATE(SATURATE)
) quantize_y_q (
    .in(update_q), .out(y_q_next), .overflow()
);

gyrofx_quantize #(
    .IN_W(STATE_W), .IN_F(STATE_F), .OUT_W(OUT_W), .OUT_F(OUT_F),
    .ROUNDING(ROUNDING), .SATURATE(SATURATE)
) quantize_i (
    .in(y_i_next), .out(i_next), .overflow()
);

gyrofx_quantize #(
    .IN_W(STATE_W), .IN_F(STATE_F), .OUT_W(OUT_W), .OUT_F(OUT_F),
    .ROUNDING(ROUNDING), .SATURATE(SATURATE)
) quantize_q (
    .in(y_q_next), .out(q_next), .overflow()
);
/* verilator lint_on PINCONNECTEMPTY */

always @(posedge clk) begin
    if (ce) begin
        y_i_reg <= y_i_next;
        y_q_reg <= y_q_next;
        i_reg <= i_next;
        q_reg <= q_next;
    end
    valid_reg <= ce;

    if (rst) begin
        y_i_reg <= {STATE_W{1'b0}};
        y_q_reg <= {STATE_W{1'b0}};
        valid_reg <= 1'b0;
    end
end

assign i_out = i_reg;
assign q_out = q_reg;
assign out_valid = valid_reg;

endmodule

`resetall
