// Language: Verilog 2001

`resetall
`timescale 1ns / 1ps
`default_nettype none

/*
 * gyrofx_pi — PI controller with a clamped integrator (anti-windup) and a
 * preset.
 *
 * Purpose: the gyro loop's PLL (phase error in, NCO frequency word out) and
 *   AGC (amplitude error in, drive amplitude out), SPEC 1.6. On a mode switch
 *   the PLL's integrator is preset to the other mode's nominal frequency.
 *   Bit-exact with gyrofx_model::gyro_loop::pi::FixedPi.
 *
 * Algorithm (per sample, ce high; e = err):
 *     v   = preset ? clamp(preset_value) : v_reg
 *     v_reg <= clamp(Q(v + KI * e), INT_MIN, INT_MAX)    INT format; Q rounds into a
 *                                                         format wide enough never to wrap
 *     u_out <= Q(KP * e + v_reg after the update)        OUT format, ROUNDING/SATURATE
 *   Products and sums are exact (add: +1 bit, multiply: widths add), as in the
 *   model. A clock with preset high and ce low only loads clamp(preset_value).
 *
 * Pipeline: one register stage. u_out and out_valid are valid 1 clock after
 *   ce. A clock with rst high clears the integrator and out_valid (rst wins
 *   over ce and preset).
 */
module gyrofx_pi #(
    // error input: width and fraction bits
    parameter integer ERR_W = 24,
    parameter integer ERR_F = 23,
    // kp: width and fraction bits
    parameter integer KP_W = 18,
    parameter integer KP_F = 26,
    // ki: width and fraction bits
    parameter integer KI_W = 18,
    parameter integer KI_F = 34,
    // integrator: width and fraction bits
    parameter integer INT_W = 59,
    parameter integer INT_F = 57,
    // output: width and fraction bits
    parameter integer OUT_W = 32,
    parameter integer OUT_F = 32,
    // kp and ki codes (the defaults: 2^-10 and 2^-18)
    parameter signed [KP_W-1:0] KP = 18'sd65536,
    parameter signed [KI_W-1:0] KI = 18'sd65536,
    // integrator limits, INT-format codes (INT_MIN <= INT_MAX; the defaults: 0.035
    // and 0.05 cycles per sample, 7 and 10 kHz at 200 kHz)
    parameter signed [INT_W-1:0] INT_MIN = 59'sd5044031582654956,
    parameter signed [INT_W-1:0] INT_MAX = 59'sd7205759403792794,
    // rounding: 0 floor, 1 ceil, 2 zero, 3 nearest, 4 round, 5 convergent
    parameter integer ROUNDING = 3,
    // overflow at the output: 0 wrap, 1 saturate
    parameter integer SATURATE = 1
) (
    input  wire                     clk,
    input  wire                     rst,
    input  wire                     ce,
    input  wire signed [ERR_W-1:0]  err,
    input  wire                     preset,
    input  wire signed [INT_W-1:0]  preset_value,
    output wire signed [OUT_W-1:0]  u_out,
    output wire                     out_valid
);

// Integer bits (with sign) of each node; an exact sum has the finer fraction
// and one integer bit more than the wider operand.
localparam integer INT_I = INT_W - INT_F;
localparam integer KIE_W = KI_W + ERR_W;
localparam integer KIE_F = KI_F + ERR_F;
localparam integer KIE_I = KIE_W - KIE_F;
localparam integer UPD_F = INT_F > KIE_F ? INT_F : KIE_F;
localparam integer UPD_I = (INT_I > KIE_I ? INT_I : KIE_I) + 1;
localparam integer UPD_W = UPD_I + UPD_F;
// The rounded update before the clamp: one bit more than the sum's integer part.
localparam integer RND_W = UPD_I + 1 + INT_F;
localparam integer KPE_W = KP_W + ERR_W;
localparam integer KPE_F = KP_F + ERR_F;
localparam integer KPE_I = KPE_W - KPE_F;
localparam integer SUM_F = INT_F > KPE_F ? INT_F : KPE_F;
localparam integer SUM_I = (INT_I > KPE_I ? INT_I : KPE_I) + 1;
localparam integer SUM_W = SUM_I + SUM_F;

initial begin
    if (INT_MIN > INT_MAX) begin
        $display("%m: INT_MIN must be <= INT_MAX");
        $finish;
    end
end

reg signed [INT_W-1:0] v_reg = {INT_W{1'b0}};
reg signed [OUT_W-1:0] u_reg = {OUT_W{1'b0}};
reg valid_reg = 1'b0;

wire signed [INT_W-1:0] preset_clamped =
    preset_value < INT_MIN ? INT_MIN : (preset_value > INT_MAX ? INT_MAX : preset_value);
wire signed [INT_W-1:0] v = preset ? preset_clamped : v_reg;

// v + KI * e at UPD_F fraction bits, exact.
wire signed [KIE_W-1:0] ki_e = KI * err;
wire signed [UPD_W-1:0] v_update = {{(UPD_W-INT_W){v[INT_W-1]}}, v};
wire signed [UPD_W-1:0] ki_e_update = {{(UPD_W-KIE_W){ki_e[KIE_W-1]}}, ki_e};
wire signed [UPD_W-1:0] update = (v_update <<< (UPD_F - INT_F)) + (ki_e_update <<< (UPD_F - KIE_F));

wire signed [RND_W-1:0] rounded;
/* verilator lint_off PINCONNECTEMPTY */
gyrofx_quantize #(
    .IN_W(UPD_W), .IN_F(UPD_F), .OUT_W(RND_W), .OUT_F(INT_F),
    .ROUNDING(ROUNDING), .SATURATE(0)
) quantize_v (
    .in(update), .out(rounded), .overflow()
);
/* verilator lint_on PINCONNECTEMPTY */

// The clamp: the limits bound the result, so its low INT_W bits are exact.
wire signed [RND_W-1:0] low = {{(RND_W-INT_W){INT_MIN[INT_W-1]}}, INT_MIN};
wire signed [RND_W-1:0] high = {{(RND_W-INT_W){INT_MAX[INT_W-1]}}, INT_MAX};
/* verilator lint_off UNUSEDSIGNAL */
wire signed [RND_W-1:0] clamped = rounded < low ? low : (rounded > high ? high : rounded);
/* verilator lint_on UNUSEDSIGNAL */
wire signed [INT_W-1:0] v_next = clamped[INT_W-1:0];

// KP * e + v_next at SUM_F fraction bits, exact.
wire signed [KPE_W-1:0] kp_e = KP * err;
wire signed [SUM_W-1:0] kp_e_sum = {{(SUM_W-KPE_W){kp_e[KPE_W-1]}}, kp_e};
wire signed [SUM_W-1:0] v_sum = {{(SUM_W-INT_W){v_next[INT_W-1]}}, v_next};
wire signed [SUM_W-1:0] sum = (kp_e_sum <<< (SUM_F - KPE_F)) + (v_sum <<< (SUM_F - INT_F));

wire signed [OUT_W-1:0] u_next;
/* verilator lint_off PINCONNECTEMPTY */
gyrofx_quantize #(
    .IN_W(SUM_W), .IN_F(SUM_F), .OUT_W(OUT_W), .OUT_F(OUT_F),
    .ROUNDING(ROUNDING), .SATURATE(SATURATE)
) quantize_u (
    .in(sum), .out(u_next), .overflow()
);
/* verilator lint_on PINCONNECTEMPTY */

always @(posedge clk) begin
    if (ce) begin
        v_reg <= v_next;
        u_reg <= u_next;
    end else if (preset) begin
        v_reg <= preset_clamped;
    end
    valid_reg <= ce;

    if (rst) begin
        v_reg <= {INT_W{1'b0}};
        valid_reg <= 1'b0;
    end
end

assign u_out = u_reg;
assign out_valid = valid_reg;

endmodule

`resetall
