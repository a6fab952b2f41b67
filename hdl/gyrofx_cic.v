// Language: Verilog 2001

`resetall
`timescale 1ns / 1ps
`default_nettype none

/*
 * gyrofx_cic — CIC decimator with a droop-compensation FIR.
 *
 * Purpose: the sense channel's rate from the ADC rate fs down to the chain's
 *   rate fs / DECIMATION (SPEC 1.6). Bit-exact with
 *   gyrofx_model::gyro_loop::cic::FixedCic.
 *
 * Algorithm:
 *   at every ce (fs), STAGES registered integrators, REG_W bits, wrapping:
 *     v_1 <= v_1 + x,   v_j <= v_j + v_(j-1)            (old values: a registered cascade)
 *   at every DECIMATION-th ce (fs / DECIMATION), on w_0 = v_STAGES after this update:
 *     w_j = w_(j-1) - w_(j-1) from DELAY decimated samples ago    STAGES combs, wrapping
 *     c   = Q(w_STAGES * 2^-SHIFT)              MID format (gyrofx_quantize)
 *     y  <= Q(sum_t h_t * c[m - t])             OUT format; h from ROM_FILE, TAPS words
 *   REG_W = IN_W + ceil(STAGES * log2(DECIMATION * DELAY)) (Hogenauer), derived
 *   here exactly in integers: the combs undo every integrator wrap.
 *
 * Pipeline: one register stage. y and y_valid are valid 1 clock after every
 *   DECIMATION-th ce (counted from reset). The whole comb chain and the FIR run
 *   in that one clock: TAPS multipliers, fine at the decimated rate; pipeline
 *   them for speed at the cost of latency. A clock with rst high clears every
 *   register, the decimation phase and y_valid (rst wins over ce).
 *
 * ROM: ROM_FILE ($readmemh), TAPS words of COEF_W bits, h_0 first (symmetric).
 */
module gyrofx_cic #(
    // input x: width and fraction bits
    parameter integer IN_W = 24,
    parameter integer IN_F = 23,
    // integrator and comb stages (1..8)
    parameter integer STAGES = 3,
    // decimation R (2..65536) and the comb's differential delay M (1 or 2)
    parameter integer DECIMATION = 1000,
    parameter integer DELAY = 1,
    // the comb output is scaled by 2^-SHIFT
    parameter integer SHIFT = 30,
    // scaled CIC output c: width and fraction bits
    parameter integer MID_W = 28,
    parameter integer MID_F = 27,
    // compensator taps (odd) and their width and fraction bits
    parameter integer TAPS = 5,
    parameter integer COEF_W = 18,
    parameter integer COEF_F = 16,
    // output y: width and fraction bits
    parameter integer OUT_W = 24,
    parameter integer OUT_F = 23,
    // rounding: 0 floor, 1 ceil, 2 zero, 3 nearest, 4 round, 5 convergent
    parameter integer ROUNDING = 3,
    // overflow: 0 wrap, 1 saturate
    parameter integer SATURATE = 1,
    // compensator taps image for $readmemh
    parameter ROM_FILE = "cic_taps.mem"
) (
    input  wire                     clk,
    input  wire                     rst,
    input  wire                     ce,
    input  wire signed [IN_W-1:0]   x,
    output wire signed [OUT_W-1:0]  y,
    output wire                     y_valid
);

// ceil(log2((rm)^stages)), exact: the smallest b with 2^b >= rm^stages.
function integer growth_bits;
    input integer stages;
    input integer rm;
    reg [255:0] gain;
    reg [255:0] factor;
    integer s;
    begin
        gain = 256'd1;
        factor = {224'd0, rm[31:0]};
        for (s = 0; s < stages; s = s + 1)
            gain = gain * factor;
        growth_bits = 0;
        while ((256'd1 << growth_bits) < gain)
            growth_bits = growth_bits + 1;
    end
endfunction

// ceil(log2(value)), 0 for value 1.
function integer ceil_log2;
    input integer value;
    begin
        ceil_log2 = 0;
        while ((1 << ceil_log2) < value)
            ceil_log2 = ceil_log2 + 1;
    end
endfunction

localparam integer GROWTH = growth_bits(STAGES, DECIMATION * DELAY);
localparam integer REG_W = IN_W + GROWTH;
localparam integer CNT_W = ceil_log2(DECIMATION);
// The count of the ce that completes a decimation period.
localparam integer LAST_COUNT = DECIMATION - 1;
localparam integer PROD_W = MID_W + COEF_W;
localparam integer ACC_W = PROD_W + ceil_log2(TAPS);

initial begin
    if (STAGES < 1 || STAGES > 8 || DECIMATION < 2 || DELAY < 1 || DELAY > 2) begin
        $display("%m: STAGES (%0d) must be 1..8, DECIMATION (%0d) >= 2, DELAY (%0d) 1 or 2",
            STAGES, DECIMATION, DELAY);
        $finish;
    end
    if (TAPS < 1 || TAPS % 2 == 0) begin
        $display("%m: TAPS (%0d) must be odd", TAPS);
        $finish;
    end
end

reg [COEF_W-1:0] taps_rom [0:TAPS-1];
initial begin
    $readmemh(ROM_FILE, taps_rom);
end

reg [CNT_W-1:0] count_reg = {CNT_W{1'b0}};
reg signed [OUT_W-1:0] y_reg = {OUT_W{1'b0}};
reg valid_reg = 1'b0;

/* verilator lint_off UNUSEDSIGNAL */
wire [31:0] last_count = LAST_COUNT;
/* verilator lint_on UNUSEDSIGNAL */
wire decimate = ce && count_reg == last_count[CNT_W-1:0];

wire signed [REG_W-1:0] x_wide = {{(REG_W-IN_W){x[IN_W-1]}}, x};


// The integrators (stage g adds stage g-1's value) and the comb chain (stage g
// takes stage g-1's output); the comb input is the last integrator's next value.
genvar g;
generate
    for (g = 0; g < STAGES; g = g + 1) begin : g_integrator
        reg signed [REG_W-1:0] v_reg = {REG_W{1'b0}};
        wire signed [REG_W-1:0] in_value;
        if (g == 0) begin : g_first
            assign in_value = x_wide;
        end else begin : g_next
            assign in_value = g_integrator[g-1].v_reg;
        end
        always @(posedge clk) begin
            if (ce) begin
                v_reg <= v_reg + in_value;
            end
            if (rst) begin
                v_reg <= {REG_W{1'b0}};
            end
        end
    end

    for (g = 0; g < STAGES; g = g + 1) begin : g_comb
        reg signed [REG_W-1:0] d1_reg = {REG_W{1'b0}};
        wire signed [REG_W-1:0] delayed;
        wire signed [REG_W-1:0] in_value;
        wire signed [REG_W-1:0] out_value = in_value - delayed;
        if (g == 0) begin : g_first
            assign in_value = g_integrator[STAGES-1].v_reg + g_integrator[STAGES-1].in_value;
        end else begin : g_next
            assign in_value = g_comb[g-1].out_value;
        end
        always @(posedge clk) begin
            if (decimate) begin
                d1_reg <= in_value;
            end
            if (rst) begin
                d1_reg <= {REG_W{1'b0}};
            end
        end
        if (DELAY == 2) begin : g_two
            reg signed [REG_W-1:0] d2_reg = {REG_W{1'b0}};
            always @(posedge clk) begin
                if (decimate) begin
                    d2_reg <= d1_reg;
                end
                if (rst) begin
                    d2_reg <= {REG_W{1'b0}};
                end
            end
            assign delayed = d2_reg;
        end else begin : g_one
            assign delayed = d1_reg;
        end
    end
endgenerate

wire signed [REG_W-1:0] comb_out = g_comb[STAGES-1].out_value;
wire signed [MID_W-1:0] c_next;
/* verilator lint_off PINCONNECTEMPTY */
gyrofx_quantize #(
    .IN_W(REG_W), .IN_F(IN_F + SHIFT), .OUT_W(MID_W), .OUT_F(MID_F),
    .ROUNDING(ROUNDING), .SATURATE(SATURATE)
) quantize_c (
    .in(comb_out), .out(c_next), .overflow()
);
/* verilator lint_on PINCONNECTEMPTY */

// Compensator: tap g multiplies c[m - g] of this decimated sample (c_next for
// g = 0, the delay line for the others) and adds to the exact sum of taps < g.
generate
    for (g = 0; g < TAPS; g = g + 1) begin : g_tap
        wire signed [COEF_W-1:0] h = taps_rom[g];
        wire signed [MID_W-1:0] c_value;
        wire signed [PROD_W-1:0] product = h * c_value;
        wire signed [ACC_W-1:0] sum;
        if (g == 0) begin : g_first
            assign c_value = c_next;
            assign sum = {{(ACC_W-PROD_W){product[PROD_W-1]}}, product};
        end else begin : g_next
            reg signed [MID_W-1:0] c_reg = {MID_W{1'b0}};
            always @(posedge clk) begin
                if (decimate) begin
                    c_reg <= g_tap[g-1].c_value;
                end
                if (rst) begin
                    c_reg <= {MID_W{1'b0}};
                end
            end
            assign c_value = c_reg;
            assign sum = g_tap[g-1].sum + {{(ACC_W-PROD_W){product[PROD_W-1]}}, product};
        end
    end
endgenerate

wire signed [ACC_W-1:0] fir_sum = g_tap[TAPS-1].sum;
wire signed [OUT_W-1:0] y_next;
/* verilator lint_off PINCONNECTEMPTY */
gyrofx_quantize #(
    .IN_W(ACC_W), .IN_F(MID_F + COEF_F), .OUT_W(OUT_W), .OUT_F(OUT_F),
    .ROUNDING(ROUNDING), .SATURATE(SATURATE)
) quantize_y (
    .in(fir_sum), .out(y_next), .overflow()
);
/* verilator lint_on PINCONNECTEMPTY */

always @(posedge clk) begin
    if (ce) begin
        count_reg <= decimate ? {CNT_W{1'b0}} : count_reg + 1'b1;
    end
    if (decimate) begin
        y_reg <= y_next;
    end
    valid_reg <= decimate;

    if (rst) begin
        count_reg <= {CNT_W{1'b0}};
        valid_reg <= 1'b0;
    end
end

assign y = y_reg;
assign y_valid = valid_reg;

endmodule

`resetall
