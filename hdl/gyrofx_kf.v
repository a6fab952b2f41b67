// Language: Verilog 2001

`resetall
`timescale 1ns / 1ps
`default_nettype none

/*
 * gyrofx_kf — steady-state Kalman filter for a MEMS gyro (paper 000), innovation form.
 *
 * Purpose: estimate the true rate from the gyro rate z with the constant-gain
 *   filter designed offline by gyrofx; one gain set per bandwidth in a ROM
 *   addressed by bw_sel at run time. Bit-exact with gyrofx_model::kf::FixedKf.
 *
 * Algorithm (per sample, ce high):
 *     e        = z - x1 - x2                  exact, STATE_F fraction bits
 *     x1      <= Q(x1 + g1 * e)               state format, ROUNDING/SATURATE
 *     x2      <= Q(x2 + g2 * e)               state format, ROUNDING/SATURATE
 *     rate_out <= Q(x1 after the update)      output format
 *   Everything before a Q(.) is exact: widths are derived below by the same
 *   rules as the model (add: +1 bit, multiply: widths add).
 *
 * Pipeline: four register stages, one sample at a time: e and the ROM word
 *   (clock 1), the products g1*e and g2*e (clock 2), the states (clock 3),
 *   rate_out from the new x1 (clock 4). rate_out and out_valid are valid 4
 *   clocks after ce; ce at most every 3rd clock (the next e needs the new
 *   states). Registering e, the products and the output's rounding keeps the
 *   recursion's path to one product or one sum and requantizer (timing:
 *   docs/blocks/kf.md). A clock with rst high clears x1, x2, the pipeline and
 *   out_valid (rst wins over ce).
 *
 * ROM: ROM_FILE ($readmemh), ROM_DEPTH words of G1_W+G2_W bits, word = {g1, g2}.
 *   bw_sel must address a word (< ROM_DEPTH).
 */
module gyrofx_kf #(
    // input z: width and fraction bits (°/s)
    parameter integer IN_W = 24,
    parameter integer IN_F = 14,
    // state x1, x2: width and fraction bits (STATE_F >= IN_F: guard bits)
    parameter integer STATE_W = 36,
    parameter integer STATE_F = 26,
    // output rate_out: width and fraction bits (OUT_F <= STATE_F)
    parameter integer OUT_W = 24,
    parameter integer OUT_F = 14,
    // coefficient g1: width and fraction bits
    parameter integer G1_W = 18,
    parameter integer G1_F = 17,
    // coefficient g2: width and fraction bits
    parameter integer G2_W = 18,
    parameter integer G2_F = 38,
    // bw_sel width and number of ROM words
    parameter integer SEL_W = 2,
    parameter integer ROM_DEPTH = 3,
    // rounding: 0 floor, 1 ceil, 2 zero, 3 nearest, 4 round, 5 convergent
    parameter integer ROUNDING = 3,
    // overflow: 0 wrap, 1 saturate
    parameter integer SATURATE = 1,
    // coefficient ROM image for $readmemh
    parameter ROM_FILE = "kf_coefficients.mem"
) (
    input  wire                    clk,
    input  wire                    rst,
    input  wire                    ce,
    input  wire [SEL_W-1:0]        bw_sel,
    input  wire signed [IN_W-1:0]  z,
    output wire signed [OUT_W-1:0] rate_out,
    output wire                    out_valid
);

// Exact intermediate widths: integer bits (with sign) grow by one per add.
localparam integer GUARD = STATE_F - IN_F;
localparam integer IN_I = IN_W - IN_F;
localparam integer STATE_I = STATE_W - STATE_F;
localparam integer D1_I = (IN_I > STATE_I ? IN_I : STATE_I) + 1;     // z - x1
localparam integer E_I = (D1_I > STATE_I ? D1_I : STATE_I) + 1;      // z - x1 - x2
localparam integer E_W = E_I + STATE_F;
localparam integer P1_W = G1_W + E_W;
localparam integer P1_F = G1_F + STATE_F;
localparam integer P2_W = G2_W + E_W;
localparam integer P2_F = G2_F + STATE_F;
localparam integer P1_I = P1_W - P1_F;
localparam integer P2_I = P2_W - P2_F;
localparam integer S1_W = (STATE_I > P1_I ? STATE_I : P1_I) + 1 + P1_F;  // x1 + g1*e
localparam integer S2_W = (STATE_I > P2_I ? STATE_I : P2_I) + 1 + P2_F;  // x2 + g2*e

initial begin
    if (GUARD < 0) begin
        $display("%m: STATE_F (%0d) must be >= IN_F (%0d)", STATE_F, IN_F);
        $finish;
    end
    if (OUT_F > STATE_F) begin
        $display("%m: OUT_F (%0d) must be <= STATE_F (%0d)", OUT_F, STATE_F);
        $finish;
    end
    if (G1_F < 0 || G2_F < 0) begin
        $display("%m: G1_F (%0d) and G2_F (%0d) must be >= 0", G1_F, G2_F);
        $finish;
    end
end

reg [G1_W+G2_W-1:0] rom [0:ROM_DEPTH-1];
initial begin
    $readmemh(ROM_FILE, rom);
end

reg signed [STATE_W-1:0] x1_reg = {STATE_W{1'b0}};
reg signed [STATE_W-1:0] x2_reg = {STATE_W{1'b0}};
reg signed [OUT_W-1:0] rate_reg = {OUT_W{1'b0}};
reg valid_reg = 1'b0;
// The sample's place in the pipeline: [0] e and the gains held, [1] the products, [2] the
// states updated.
reg [2:0] stage = 3'b000;

wire [G1_W+G2_W-1:0] rom_word = rom[bw_sel];
reg signed [G1_W-1:0] g1 = {G1_W{1'b0}};
reg signed [G2_W-1:0] g2 = {G2_W{1'b0}};

// e = z - x1 - x2 at STATE_F fraction bits, exact.
wire signed [E_W-1:0] z_e = {{(E_W-IN_W){z[IN_W-1]}}, z};
wire signed [E_W-1:0] z_aligned = z_e <<< GUARD;
wire signed [E_W-1:0] x1_e = {{(E_W-STATE_W){x1_reg[STATE_W-1]}}, x1_reg};
wire signed [E_W-1:0] x2_e = {{(E_W-STATE_W){x2_reg[STATE_W-1]}}, x2_reg};
wire signed [E_W-1:0] e_next = z_aligned - x1_e - x2_e;
reg signed [E_W-1:0] e = {E_W{1'b0}};

// Products, exact.
reg signed [P1_W-1:0] p1 = {P1_W{1'b0}};
reg signed [P2_W-1:0] p2 = {P2_W{1'b0}};

// Sums x_i + g_i*e at the product's fraction, exact.
wire signed [S1_W-1:0] x1_wide = {{(S1_W-STATE_W){x1_reg[STATE_W-1]}}, x1_reg};
wire signed [S2_W-1:0] x2_wide = {{(S2_W-STATE_W){x2_reg[STATE_W-1]}}, x2_reg};
wire signed [S1_W-1:0] x1_s = x1_wide <<< G1_F;
wire signed [S2_W-1:0] x2_s = x2_wide <<< G2_F;
wire signed [S1_W-1:0] p1_s = {{(S1_W-P1_W){p1[P1_W-1]}}, p1};
wire signed [S2_W-1:0] p2_s = {{(S2_W-P2_W){p2[P2_W-1]}}, p2};
wire signed [S1_W-1:0] s1 = x1_s + p1_s;
wire signed [S2_W-1:0] s2 = x2_s + p2_s;

// The three quantization points.
wire signed [STATE_W-1:0] x1_next;
wire signed [STATE_W-1:0] x2_next;
wire signed [OUT_W-1:0] rate_next;
/* verilator lint_off PINCONNECTEMPTY */
gyrofx_quantize #(
    .IN_W(S1_W), .IN_F(P1_F), .OUT_W(STATE_W), .OUT_F(STATE_F),
    .ROUNDING(ROUNDING), .SATURATE(SATURATE)
) quantize_x1 (
    .in(s1), .out(x1_next), .overflow()
);

gyrofx_quantize #(
    .IN_W(S2_W), .IN_F(P2_F), .OUT_W(STATE_W), .OUT_F(STATE_F),
    .ROUNDING(ROUNDING), .SATURATE(SATURATE)
) quantize_x2 (
    .in(s2), .out(x2_next), .overflow()
);

gyrofx_quantize #(
    .IN_W(STATE_W), .IN_F(STATE_F), .OUT_W(OUT_W), .OUT_F(OUT_F),
    .ROUNDING(ROUNDING), .SATURATE(SATURATE)
) quantize_rate (
    .in(x1_reg), .out(rate_next), .overflow()
);
/* verilator lint_on PINCONNECTEMPTY */

always @(posedge clk) begin
    stage <= {stage[1:0], ce};
    // e, the gains and the products load on every clock: each is read only on the clock after
    // the one that loads the sample's (fewer enables: the iCE40 shares one per logic block).
    e <= e_next;
    g1 <= rom_word[G1_W+G2_W-1:G2_W];
    g2 <= rom_word[G2_W-1:0];
    p1 <= g1 * e;
    p2 <= g2 * e;
    if (stage[1]) begin
        x1_reg <= x1_next;
        x2_reg <= x2_next;
    end
    if (stage[2]) begin
        rate_reg <= rate_next;
    end
    valid_reg <= stage[2];

    if (rst) begin
        x1_reg <= {STATE_W{1'b0}};
        x2_reg <= {STATE_W{1'b0}};
        stage <= 3'b000;
        valid_reg <= 1'b0;
    end
end

assign rate_out = rate_reg;
assign out_valid = valid_reg;

`ifndef SYNTHESIS
// Simulation only (yosys defines SYNTHESIS): the KF takes a sample at most every 3 clocks
// (gyrofx_job::pipeline); a sooner ce stops the simulation, naming this instance.
gyrofx_spacing_check #(
    .MIN_CLOCKS_PER_SAMPLE(3),
    .BLOCK_NAME("gyrofx_kf")
) spacing_check (
    .clk(clk),
    .rst(rst),
    .ce(ce)
);
`endif

endmodule

`resetall
