// Language: Verilog 2001

`resetall
`timescale 1ns / 1ps
`default_nettype none

/*
 * gyrofx_nco — numerically controlled oscillator: phase accumulator and
 * quarter-wave sine ROM, sine and cosine outputs.
 *
 * Purpose: the reference of the gyro's drive and sense loops (SPEC 1.6). The
 *   drive and sense references are two instances fed the same freq (their
 *   accumulators stay identical) with offsets 0 and the per-mode sense phase.
 *   Bit-exact with gyrofx_model::gyro_loop::nco::FixedNco.
 *
 * Algorithm (per sample, ce high; phases in cycles, u PHASE_W.PHASE_W):
 *     phase = acc + offset (+ r)                mod 2^PHASE_W (wraps; r with ERROR_FEEDBACK)
 *     t     = floor(phase / 2^(PHASE_W-ADDR_W-2))   ADDR_W+2 bits (gyrofx_quantize, floor)
 *     r    <= (phase mod 2^(PHASE_W-ADDR_W-2)) - half a bin   (ERROR_FEEDBACK: the carried
 *               truncation error, signed; errors of any run of samples sum to < 1 bin)
 *     sin   = +/- ROM[i or 2^ADDR_W-1-i]       i = t mod 2^ADDR_W, quadrant = t >> ADDR_W:
 *               q 0: ROM[i]  1: ROM[~i]  2: -ROM[i]  3: -ROM[~i]
 *     cos   = the same at t + 2^ADDR_W         (a quarter cycle on)
 *     acc  <= acc + freq                        mod 2^PHASE_W
 *   ROM[k] = round(A * sin(pi/2 * (k + 1/2) / 2^ADDR_W)), A = 2^(SIN_W-1) - 1:
 *   bin centres, so the mirror is a bit inversion and -ROM[k] never overflows.
 *
 * Pipeline: the ROM addresses and signs are registered at ce (a block-RAM read
 *   port); sin_out, cos_out and out_valid are valid 1 clock after ce and hold
 *   until the next ce. A clock with rst high clears acc, r and out_valid (rst
 *   wins over ce).
 *
 * ROM: ROM_FILE ($readmemh), 2^ADDR_W words of SIN_W bits (s SIN_W.SIN_W-1).
 */
module gyrofx_nco #(
    // phase accumulator, frequency word and offset width, bits (cycles, u PHASE_W.PHASE_W)
    parameter integer PHASE_W = 32,
    // quarter-wave ROM address width: 2^ADDR_W words (PHASE_W >= ADDR_W + 2)
    parameter integer ADDR_W = 10,
    // sine and cosine width, s SIN_W.SIN_W-1
    parameter integer SIN_W = 18,
    // 1: carry each truncation error into the next phase (needs PHASE_W > ADDR_W + 2)
    parameter integer ERROR_FEEDBACK = 1,
    // quarter-wave sine ROM image for $readmemh
    parameter ROM_FILE = "nco_sine.mem"
) (
    input  wire                     clk,
    input  wire                     rst,
    input  wire                     ce,
    input  wire [PHASE_W-1:0]       freq,
    input  wire [PHASE_W-1:0]       offset,
    output wire signed [SIN_W-1:0]  sin_out,
    output wire signed [SIN_W-1:0]  cos_out,
    output wire                     out_valid
);

// Truncated phase: quadrant (2 bits) and ROM index.
localparam integer T_W = ADDR_W + 2;
// The carried error's width: the phase bits below the truncation (1 when there are none, and
// then unused).
localparam integer R_W = (PHASE_W > T_W) ? PHASE_W - T_W : 1;

initial begin
    if (PHASE_W < T_W) begin
        $display("%m: PHASE_W (%0d) must be >= ADDR_W + 2 (%0d)", PHASE_W, T_W);
        $finish;
    end
    if (ERROR_FEEDBACK != 0 && PHASE_W == T_W) begin
        $display("%m: ERROR_FEEDBACK needs PHASE_W (%0d) > ADDR_W + 2", PHASE_W);
        $finish;
    end
end

reg [SIN_W-1:0] rom [0:(1 << ADDR_W)-1];
initial begin
    $readmemh(ROM_FILE, rom);
end

reg [PHASE_W-1:0] acc_reg = {PHASE_W{1'b0}};
reg [ADDR_W-1:0] sin_addr_reg = {ADDR_W{1'b0}};
reg [ADDR_W-1:0] cos_addr_reg = {ADDR_W{1'b0}};
reg sin_negative_reg = 1'b0;
reg cos_negative_reg = 1'b0;
reg valid_reg = 1'b0;
// The last truncation error, signed, in phase LSB: [-2^(R_W-1), 2^(R_W-1)).
reg signed [R_W-1:0] residue_reg = {R_W{1'b0}};

wire [PHASE_W-1:0] phase_exact = acc_reg + offset;
// With error feedback the carried error joins the phase (sign-extended, mod one cycle).
wire [PHASE_W-1:0] residue_extended = {{(PHASE_W - R_W){residue_reg[R_W-1]}}, residue_reg};
wire [PHASE_W-1:0] phase = (ERROR_FEEDBACK != 0) ? phase_exact + residue_extended : phase_exact;
// What is left below the truncation, less half a bin: its top bit inverted, read as signed.
localparam [R_W-1:0] ONES = {R_W{1'b1}};
localparam [R_W-1:0] HALF_BIN = ONES ^ (ONES >> 1);
wire signed [R_W-1:0] residue_next = phase[R_W-1:0] ^ HALF_BIN;

// The phase truncation: an unsigned phase seen as a signed value with a zero
// sign bit, floored to T_W fraction bits; it always fits, so only its low
// T_W bits are used.
wire signed [PHASE_W:0] phase_signed = {1'b0, phase};
/* verilator lint_off UNUSEDSIGNAL */
wire signed [T_W:0] t_signed;
/* verilator lint_on UNUSEDSIGNAL */
/* verilator lint_off PINCONNECTEMPTY */
gyrofx_quantize #(
    .IN_W(PHASE_W + 1), .IN_F(PHASE_W), .OUT_W(T_W + 1), .OUT_F(T_W),
    .ROUNDING(0), .SATURATE(0)
) quantize_phase (
    .in(phase_signed), .out(t_signed), .overflow()
);
/* verilator lint_on PINCONNECTEMPTY */

wire [T_W-1:0] t_sin = t_signed[T_W-1:0];
wire [T_W-1:0] t_cos = t_sin + {2'b01, {ADDR_W{1'b0}}};
wire [ADDR_W-1:0] sin_addr = t_sin[ADDR_W] ? ~t_sin[ADDR_W-1:0] : t_sin[ADDR_W-1:0];
wire [ADDR_W-1:0] cos_addr = t_cos[ADDR_W] ? ~t_cos[ADDR_W-1:0] : t_cos[ADDR_W-1:0];

wire signed [SIN_W-1:0] sin_magnitude = rom[sin_addr_reg];
wire signed [SIN_W-1:0] cos_magnitude = rom[cos_addr_reg];

always @(posedge clk) begin
    if (ce) begin
        acc_reg <= acc_reg + freq;
        sin_addr_reg <= sin_addr;
        cos_addr_reg <= cos_addr;
        sin_negative_reg <= t_sin[T_W-1];
        cos_negative_reg <= t_cos[T_W-1];
        if (ERROR_FEEDBACK != 0) begin
            residue_reg <= residue_next;
        end
    end
    valid_reg <= ce;

    if (rst) begin
        acc_reg <= {PHASE_W{1'b0}};
        residue_reg <= {R_W{1'b0}};
        valid_reg <= 1'b0;
    end
end

assign sin_out = sin_negative_reg ? -sin_magnitude : sin_magnitude;
assign cos_out = cos_negative_reg ? -cos_magnitude : cos_magnitude;
assign out_valid = valid_reg;

endmodule

`resetall
