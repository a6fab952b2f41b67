// Language: Verilog 2001

`resetall
`timescale 1ns / 1ps
`default_nettype none

/*
 * gyrofx_mean_filter — mean filter with gross-error rejection (paper 003).
 *
 * Purpose: one output per block of WINDOW samples: the mean of the samples
 *   within r of the block mean. Bit-exact with
 *   gyrofx_model::mean_filter::FixedMeanFilter.
 *
 * Algorithm (at a block's last ce, over its WINDOW samples s_i, the current x last):
 *     sum    = sum_i s_i                                   exact, SUM_W bits
 *     keep_i = |WINDOW * s_i - sum| <= SCALED_THRESHOLD    exact (= WINDOW * r in input LSB)
 *     n      = sum_i keep_i,  kept_sum = sum_i keep_i * s_i
 *     y     <= Q((n == 0 ? sum : kept_sum) * ROM[n])      output format
 *     kept  <= n
 *   ROM[n] = 1/n for n = 1..WINDOW and ROM[0] = 1/WINDOW (every sample rejected:
 *   the plain mean). Every sample of a block is compared in parallel, in the
 *   clock of its last ce: WINDOW adders and comparators; fine for paper 003's
 *   WINDOW = 20. gyrofx_mean_filter_serial computes the same means one step a
 *   clock (architecture = "serial").
 *
 * Latency: y, kept and y_valid are registered: y_valid pulses 1 clock after a
 *   block's last ce. A clock with rst high starts a new block and clears
 *   y_valid (rst wins over ce).
 */
module gyrofx_mean_filter #(
    // input x: width and fraction bits (°/s)
    parameter integer IN_W = 24,
    parameter integer IN_F = 14,
    // output y: width and fraction bits
    parameter integer OUT_W = 24,
    parameter integer OUT_F = 14,
    // samples per block (2..1024) and the width of a count 0..WINDOW
    parameter integer WINDOW = 20,
    parameter integer COUNT_W = 5,
    // exact block sum: IN_W + ceil(log2 WINDOW) bits
    parameter integer SUM_W = 29,
    // exact deviation WINDOW * s - sum: IN_W + COUNT_W + 1 bits, and WINDOW * r in input LSB
    parameter integer DEV_W = 30,
    parameter [DEV_W-1:0] SCALED_THRESHOLD = 30'd98300,
    // reciprocal codes 1/n: width and fraction bits
    parameter integer RECIP_W = 18,
    parameter integer RECIP_F = 16,
    // rounding: 0 floor, 1 ceil, 2 zero, 3 nearest, 4 round, 5 convergent
    parameter integer ROUNDING = 3,
    // overflow: 0 wrap, 1 saturate
    parameter integer SATURATE = 1,
    // reciprocal ROM image for $readmemh: WINDOW + 1 words, address = kept count
    parameter ROM_FILE = "mean_filter_reciprocals.mem"
) (
    input  wire                    clk,
    input  wire                    rst,
    input  wire                    ce,
    input  wire signed [IN_W-1:0]  x,
    output wire signed [OUT_W-1:0] y,
    output wire [COUNT_W-1:0]      kept,
    output wire                    y_valid
);

localparam integer PRODUCT_W = SUM_W + RECIP_W;

initial begin
    if (WINDOW < 2 || (1 << COUNT_W) <= WINDOW) begin
        $display("%m: WINDOW (%0d) must be >= 2 and fit COUNT_W (%0d) bits", WINDOW, COUNT_W);
        $finish;
    end
    if (DEV_W < IN_W + COUNT_W + 1 || SUM_W < IN_W + 1) begin
        $display("%m: DEV_W (%0d) or SUM_W (%0d) too narrow", DEV_W, SUM_W);
        $finish;
    end
end

reg [RECIP_W-1:0] rom [0:WINDOW];
initial begin
    $readmemh(ROM_FILE, rom);
end

localparam [31:0] LAST_32 = WINDOW - 1;
localparam [COUNT_W-1:0] LAST_PHASE = LAST_32[COUNT_W-1:0];
localparam [31:0] WINDOW_32 = WINDOW;
localparam signed [DEV_W-1:0] THRESHOLD = SCALED_THRESHOLD;

// WINDOW as a DEV_W-bit multiplier: DEV_W may be wider or narrower than 32.
wire signed [DEV_W-1:0] window_dev;
generate
    if (DEV_W > 32) begin : g_wide
        assign window_dev = {{(DEV_W-32){1'b0}}, WINDOW_32};
    end else begin : g_narrow
        assign window_dev = WINDOW_32[DEV_W-1:0];
    end
endgenerate

reg [COUNT_W-1:0] phase_reg = {COUNT_W{1'b0}};
reg signed [OUT_W-1:0] y_reg = {OUT_W{1'b0}};
reg [COUNT_W-1:0] kept_reg = {COUNT_W{1'b0}};
reg valid_reg = 1'b0;

wire last = phase_reg == LAST_PHASE;

genvar k;
generate
    // The block's earlier samples, one register each; the current x is its last.
    for (k = 0; k < WINDOW - 1; k = k + 1) begin : g_store
        localparam [31:0] INDEX_32 = k;
        reg signed [IN_W-1:0] stored = {IN_W{1'b0}};
        always @(posedge clk) begin
            if (ce && !rst && phase_reg == INDEX_32[COUNT_W-1:0]) begin
                stored <= x;
            end
        end
    end

    // The block sum, chained.
    for (k = 0; k < WINDOW; k = k + 1) begin : g_sum
        wire signed [IN_W-1:0] value;
        if (k == WINDOW - 1) begin : g_current
            assign value = x;
        end else begin : g_stored
            assign value = g_store[k].stored;
        end
        wire signed [SUM_W-1:0] value_sum = {{(SUM_W-IN_W){value[IN_W-1]}}, value};
        wire signed [SUM_W-1:0] running;
        if (k == 0) begin : g_first
            assign running = value_sum;
        end else begin : g_next
            assign running = g_sum[k - 1].running + value_sum;
        end
    end
endgenerate

wire signed [SUM_W-1:0] sum = g_sum[WINDOW - 1].running;
wire signed [DEV_W-1:0] sum_dev = {{(DEV_W-SUM_W){sum[SUM_W-1]}}, sum};

generate
    // Keep or reject each sample; the kept sum and count, chained.
    for (k = 0; k < WINDOW; k = k + 1) begin : g_keep
        wire signed [IN_W-1:0] value = g_sum[k].value;
        wire signed [DEV_W-1:0] value_dev = {{(DEV_W-IN_W){value[IN_W-1]}}, value};
        wire signed [DEV_W-1:0] deviation = window_dev * value_dev - sum_dev;
        wire keep = (deviation <= THRESHOLD) && (deviation >= -THRESHOLD);
        wire signed [SUM_W-1:0] kept_value = keep ? g_sum[k].value_sum : {SUM_W{1'b0}};
        wire signed [SUM_W-1:0] kept_sum;
        wire [COUNT_W-1:0] count;
        if (k == 0) begin : g_first
            assign kept_sum = kept_value;
            assign count = {{(COUNT_W-1){1'b0}}, keep};
        end else begin : g_next
            assign kept_sum = g_keep[k - 1].kept_sum + kept_value;
            assign count = g_keep[k - 1].count + {{(COUNT_W-1){1'b0}}, keep};
        end
    end
endgenerate

wire [COUNT_W-1:0] count = g_keep[WINDOW - 1].count;
wire none_kept = count == {COUNT_W{1'b0}};
wire signed [SUM_W-1:0] total = none_kept ? sum : g_keep[WINDOW - 1].kept_sum;
wire signed [RECIP_W-1:0] recip = rom[count];
wire signed [PRODUCT_W-1:0] product = total * recip;
wire signed [OUT_W-1:0] y_next;

/* verilator lint_off PINCONNECTEMPTY */
gyrofx_quantize #(
    .IN_W(PRODUCT_W), .IN_F(IN_F + RECIP_F), .OUT_W(OUT_W), .OUT_F(OUT_F),
    .ROUNDING(ROUNDING), .SATURATE(SATURATE)
) quantize_y (.in(product), .out(y_next), .overflow());
/* verilator lint_on PINCONNECTEMPTY */

always @(posedge clk) begin
    valid_reg <= 1'b0;
    if (ce) begin
        if (last) begin
            phase_reg <= {COUNT_W{1'b0}};
            y_reg <= y_next;
            kept_reg <= count;
            valid_reg <= 1'b1;
        end else begin
            phase_reg <= phase_reg + 1'b1;
        end
    end

    if (rst) begin
        phase_reg <= {COUNT_W{1'b0}};
        valid_reg <= 1'b0;
    end
end

assign y = y_reg;
assign kept = kept_reg;
assign y_valid = valid_reg;

endmodule

`resetall
