// Language: Verilog 2001

`resetall
`timescale 1ns / 1ps
`default_nettype none

/*
 * gyrofx_quantize — requantize a signed fixed-point value (combinational).
 *
 * Purpose: the declared quantization point of gyrofx (SPEC §2). Drops
 *   SHIFT = IN_F - OUT_F fraction bits with the rounding mode ROUNDING, then
 *   wraps or saturates into OUT_W bits. Bit-exact with gyrofx_model::fx::requantize.
 *
 * Algorithm: q = floor(in / 2^SHIFT) + inc, where inc depends on the dropped
 *   remainder r (0 <= r < 2^SHIFT), half = 2^(SHIFT-1):
 *     0 floor      inc = 0
 *     1 ceil       inc = (r != 0)
 *     2 zero       inc = (r != 0) & negative
 *     3 nearest    inc = (r >= half)                      (add half, floor)
 *     4 round      inc = (r > half) | (r == half & ~negative)
 *     5 convergent inc = (r > half) | (r == half & q[0])
 *   then, if q does not fit OUT_W bits: SATURATE ? clamp : keep the low OUT_W bits.
 *
 * Latency: combinational (0 clocks).
 */
module gyrofx_quantize #(
    // input word width, bits
    parameter integer IN_W = 40,
    // input fraction bits
    parameter integer IN_F = 20,
    // output word width, bits
    parameter integer OUT_W = 24,
    // output fraction bits (IN_F - IN_W < OUT_F <= IN_F)
    parameter integer OUT_F = 10,
    // rounding mode: 0 floor, 1 ceil, 2 zero, 3 nearest, 4 round, 5 convergent
    parameter integer ROUNDING = 3,
    // overflow mode: 0 wrap, 1 saturate
    parameter integer SATURATE = 1
) (
    input  wire signed [IN_W-1:0]  in,
    output wire signed [OUT_W-1:0] out,
    // high when the rounded value did not fit OUT_W bits
    output wire                    overflow
);

localparam integer SHIFT = IN_F - OUT_F;
// Rounded quotient: the kept bits plus one bit for the increment.
localparam integer Q_W = IN_W - SHIFT + 1;

initial begin
    if (SHIFT < 0 || SHIFT >= IN_W) begin
        $display("%m: IN_F - OUT_F = %0d must be in 0..IN_W-1 (%0d)", SHIFT, IN_W - 1);
        $finish;
    end
    if (ROUNDING < 0 || ROUNDING > 5) begin
        $display("%m: ROUNDING = %0d must be 0..5", ROUNDING);
        $finish;
    end
end

wire signed [Q_W-1:0] rounded;

generate
    if (SHIFT == 0) begin : g_exact
        assign rounded = {in[IN_W-1], in};
    end else begin : g_round
        wire signed [Q_W-1:0] quotient = {in[IN_W-1], in[IN_W-1:SHIFT]};
        wire [SHIFT-1:0] remainder = in[SHIFT-1:0];
        wire negative = in[IN_W-1];
        wire any_dropped = |remainder;
        wire half_bit = remainder[SHIFT-1];
        wire below_half;
        if (SHIFT == 1) begin : g_one
            assign below_half = 1'b0;
        end else begin : g_more
            assign below_half = |remainder[SHIFT-2:0];
        end
        // (A continuous assignment, not always @*: simulators evaluate it at time 0 too, where
        // an always @* whose inputs never change would leave it X.)
        wire increment =
            ROUNDING == 1 ? any_dropped
            : ROUNDING == 2 ? any_dropped & negative
            : ROUNDING == 3 ? half_bit
            : ROUNDING == 4 ? half_bit & (below_half | ~negative)
            : ROUNDING == 5 ? half_bit & (below_half | quotient[0])
            : 1'b0;
        assign rounded = quotient + $signed({{(Q_W-1){1'b0}}, increment});
    end

    if (Q_W <= OUT_W) begin : g_fits
        assign out = {{(OUT_W-Q_W+1){rounded[Q_W-1]}}, rounded[Q_W-2:0]};
        assign overflow = 1'b0;
    end else begin : g_check
        // Fits when every bit above the output's sign bit equals the sign.
        wire [Q_W-OUT_W:0] top = rounded[Q_W-1:OUT_W-1];
        wire fits = (&top) | ~(|top);
        wire signed [OUT_W-1:0] most_positive = {1'b0, {(OUT_W-1){1'b1}}};
        wire signed [OUT_W-1:0] most_negative = {1'b1, {(OUT_W-1){1'b0}}};
        wire signed [OUT_W-1:0] clamped = rounded[Q_W-1] ? most_negative : most_positive;
        assign out = (fits || SATURATE == 0) ? rounded[OUT_W-1:0] : clamped;
        assign overflow = ~fits;
    end
endgenerate

endmodule

`resetall
