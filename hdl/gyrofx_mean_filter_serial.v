// Language: Verilog 2001

`resetall
`timescale 1ns / 1ps
`default_nettype none

/*
 * gyrofx_mean_filter_serial — mean filter with gross-error rejection (paper 003),
 * sequential: the block means of gyrofx_mean_filter, one step a clock.
 *
 * Purpose: one output per block of WINDOW samples: the mean of the samples
 *   within r of the block mean. Bit-exact with
 *   gyrofx_model::mean_filter::FixedMeanFilter (and its schedule,
 *   gyrofx_model::mean_filter::serial) at a longer latency; no multiplier.
 *
 * Algorithm: |WINDOW * s - sum| <= WINDOW * r is, for integer codes and an
 *   integer r (THRESHOLD, in input LSB),
 *       ceil(sum / WINDOW) - r  <=  s  <=  floor(sum / WINDOW) + r
 *   so one division per block leaves two comparisons per sample. After a
 *   block's last ce (which stores the sample in the RAM and loads the divider):
 *     DIVIDE      SUM_W - 1 clocks  restoring division of sum's magnitude (one's
 *                                   complement when negative) by WINDOW
 *     BOUNDS      1 clock           kept_low, kept_high; reads sample 0
 *     SCAN        WINDOW clocks     keep kept_low <= s <= kept_high: count, kept sum
 *     RECIPROCAL  1 clock           reads ROM[count]
 *     LOAD        1 clock           the reciprocal into the product's low half
 *     MULTIPLY    RECIP_W - 1       shift and add, lowest bit first: high = (high +
 *                                   bit * operand) >> 1, the bit shifted out into
 *                                   the low half (operand: the kept sum, or the sum
 *                                   when none was kept; the reciprocal's sign bit is 0)
 *     OUTPUT      1 clock           y = Q(product), kept = count, y_valid
 *
 * Latency: y_valid pulses high for one clock LATENCY = SUM_W + WINDOW +
 *   RECIP_W + 3 clocks after a block's last ce, counting that ce's clock as the
 *   first (the parallel filter's: 1); y and kept change on that edge and hold
 *   until the next block's. The next ce or rst may come LATENCY clocks after
 *   a block's last ce (the next block's samples share the RAM: a ce sooner
 *   corrupts the block being processed, a rst sooner stops it); a block's
 *   other samples may come every clock. A clock with rst high starts a new
 *   block, stops a block being processed and clears y_valid (rst wins over ce).
 */
module gyrofx_mean_filter_serial #(
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
    // r in input LSB (unsigned)
    parameter [IN_W-1:0] THRESHOLD = 24'd4915,
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

// Bits of an unsigned number holding 0..value.
function integer bits_for;
    input integer value;
    integer bits;
    begin
        bits = 1;
        while ((1 << bits) <= value) begin
            bits = bits + 1;
        end
        bits_for = bits;
    end
endfunction

localparam integer PRODUCT_W = SUM_W + RECIP_W;
// The division's dividend and quotient (sum's magnitude) and its remainder (< 2 WINDOW).
localparam integer MAGNITUDE_W = SUM_W - 1;
localparam integer REMAINDER_W = COUNT_W + 1;
// The kept range: floor(sum / WINDOW) +- r needs one bit more than the input.
localparam integer BOUND_W = SUM_W + 1;
localparam integer STEPS = (MAGNITUDE_W > WINDOW)
    ? ((MAGNITUDE_W > RECIP_W) ? MAGNITUDE_W : RECIP_W)
    : ((WINDOW > RECIP_W) ? WINDOW : RECIP_W);
// The step counter also gives the RAM's read address: at least COUNT_W bits.
localparam integer STEP_W = (bits_for(STEPS) > COUNT_W) ? bits_for(STEPS) : COUNT_W;
// The product's halves: high (SUM_W + 1 bits: holds high + operand) and low (first the
// reciprocal's RECIP_W - 1 magnitude bits, replaced by the product's from the top).
localparam integer LOW_W = RECIP_W - 1;

initial begin
    if (WINDOW < 2 || (1 << COUNT_W) <= WINDOW) begin
        $display("%m: WINDOW (%0d) must be >= 2 and fit COUNT_W (%0d) bits", WINDOW, COUNT_W);
        $finish;
    end
    if (SUM_W < IN_W + 1 || RECIP_W < 3) begin
        $display("%m: SUM_W (%0d) or RECIP_W (%0d) too narrow", SUM_W, RECIP_W);
        $finish;
    end
end

localparam [2:0] IDLE = 3'd0;
localparam [2:0] DIVIDE = 3'd1;
localparam [2:0] BOUNDS = 3'd2;
localparam [2:0] SCAN = 3'd3;
localparam [2:0] RECIPROCAL = 3'd4;
localparam [2:0] LOAD = 3'd5;
localparam [2:0] MULTIPLY = 3'd6;
localparam [2:0] OUTPUT = 3'd7;

localparam [31:0] WINDOW_32 = WINDOW;
localparam [31:0] LAST_32 = WINDOW - 1;
localparam [31:0] DIVIDE_LAST_32 = MAGNITUDE_W - 1;
localparam [31:0] MULTIPLY_LAST_32 = RECIP_W - 2;
localparam [COUNT_W-1:0] LAST_INDEX = LAST_32[COUNT_W-1:0];
localparam [REMAINDER_W-1:0] DIVISOR = WINDOW_32[REMAINDER_W-1:0];
localparam [COUNT_W-1:0] DIVISOR_LESS_ONE = LAST_32[COUNT_W-1:0];
localparam [STEP_W-1:0] DIVIDE_LAST = DIVIDE_LAST_32[STEP_W-1:0];
localparam [STEP_W-1:0] SCAN_LAST = LAST_32[STEP_W-1:0];
localparam [STEP_W-1:0] MULTIPLY_LAST = MULTIPLY_LAST_32[STEP_W-1:0];

// The block's samples (block RAM) and the reciprocals (block ROM), both read registered.
// A ce writes a sample while the read address rests at 0; the word read in that clock is never
// used (BOUNDS reads sample 0 again), so the block RAM needs no read-first bypass.
(* no_rw_check *)
reg [IN_W-1:0] ram [0:WINDOW-1];
reg [IN_W-1:0] ram_q;
reg [RECIP_W-1:0] rom [0:WINDOW];
// The reciprocals are positive: rom_q's sign bit is always 0.
/* verilator lint_off UNUSEDSIGNAL */
reg [RECIP_W-1:0] rom_q;
/* verilator lint_on UNUSEDSIGNAL */
initial begin
    $readmemh(ROM_FILE, rom);
end

reg [2:0] state = IDLE;
reg [STEP_W-1:0] step = {STEP_W{1'b0}};
reg [COUNT_W-1:0] index = {COUNT_W{1'b0}};
reg signed [SUM_W-1:0] sum = {SUM_W{1'b0}};
reg negative = 1'b0;
reg [MAGNITUDE_W-1:0] dividend = {MAGNITUDE_W{1'b0}};
reg [REMAINDER_W-1:0] remainder = {REMAINDER_W{1'b0}};
// The kept range: samples from kept_low to kept_high (inclusive) are kept.
reg signed [BOUND_W-1:0] kept_low = {BOUND_W{1'b0}};
reg signed [BOUND_W-1:0] kept_high = {BOUND_W{1'b0}};
reg [COUNT_W-1:0] count = {COUNT_W{1'b0}};
reg signed [SUM_W-1:0] kept_sum = {SUM_W{1'b0}};
reg signed [BOUND_W-1:0] product_high = {BOUND_W{1'b0}};
reg [LOW_W-1:0] product_low = {LOW_W{1'b0}};
reg signed [OUT_W-1:0] y_reg = {OUT_W{1'b0}};
reg [COUNT_W-1:0] kept_reg = {COUNT_W{1'b0}};
reg valid_reg = 1'b0;

// Taking a sample: the running sum restarts at a block's first.
wire take = ce && !rst;
wire signed [SUM_W-1:0] x_sum = {{(SUM_W-IN_W){x[IN_W-1]}}, x};
wire signed [SUM_W-1:0] sum_next = (index == {COUNT_W{1'b0}}) ? x_sum : sum + x_sum;

// One restoring division step: the next dividend bit into the remainder, WINDOW out if it fits.
wire [REMAINDER_W-1:0] shifted = {remainder[REMAINDER_W-2:0], dividend[MAGNITUDE_W-1]};
wire [REMAINDER_W:0] trial = {1'b0, shifted} - {1'b0, DIVISOR};
wire fits = !trial[REMAINDER_W];

// floor(sum / WINDOW) = !floor(!sum / WINDOW) for a negative sum, exact when the
// remainder is WINDOW - 1.
wire signed [SUM_W-1:0] floor_sum = negative ? ~{1'b0, dividend} : {1'b0, dividend};
wire inexact = negative ? (remainder[COUNT_W-1:0] != DIVISOR_LESS_ONE)
                        : (remainder != {REMAINDER_W{1'b0}});
wire signed [BOUND_W-1:0] floor_bound = {floor_sum[SUM_W-1], floor_sum};
wire signed [BOUND_W-1:0] threshold_bound = {{(BOUND_W-IN_W){1'b0}}, THRESHOLD};
wire signed [BOUND_W-1:0] inexact_bound = {{(BOUND_W-1){1'b0}}, inexact};

wire signed [IN_W-1:0] sample = ram_q;
wire signed [BOUND_W-1:0] sample_bound = {{(BOUND_W-IN_W){sample[IN_W-1]}}, sample};
wire signed [SUM_W-1:0] sample_sum = {{(SUM_W-IN_W){sample[IN_W-1]}}, sample};
wire keep = (sample_bound >= kept_low) && (sample_bound <= kept_high);

wire none_kept = count == {COUNT_W{1'b0}};
wire signed [SUM_W-1:0] operand = none_kept ? sum : kept_sum;
wire signed [BOUND_W-1:0] addend = product_low[0] ? {operand[SUM_W-1], operand} : {BOUND_W{1'b0}};
wire signed [BOUND_W-1:0] partial = product_high + addend;
wire signed [PRODUCT_W-1:0] product = {product_high, product_low};

wire [STEP_W-1:0] next_step = step + 1'b1;
// Sample 0 is read in BOUNDS, sample k + 1 while sample k is scanned.
wire [COUNT_W-1:0] read_address = (state == SCAN && step != SCAN_LAST)
    ? next_step[COUNT_W-1:0] : {COUNT_W{1'b0}};

wire signed [OUT_W-1:0] y_next;

/* verilator lint_off PINCONNECTEMPTY */
gyrofx_quantize #(
    .IN_W(PRODUCT_W), .IN_F(IN_F + RECIP_F), .OUT_W(OUT_W), .OUT_F(OUT_F),
    .ROUNDING(ROUNDING), .SATURATE(SATURATE)
) quantize_y (.in(product), .out(y_next), .overflow());
/* verilator lint_on PINCONNECTEMPTY */

always @(posedge clk) begin
    if (take) begin
        ram[index] <= x;
    end
    ram_q <= ram[read_address];
    rom_q <= rom[count];
end

always @(posedge clk) begin
    valid_reg <= 1'b0;
    case (state)
        DIVIDE: begin
            remainder <= fits ? trial[REMAINDER_W-1:0] : shifted;
            dividend <= {dividend[MAGNITUDE_W-2:0], fits};
            step <= next_step;
            if (step == DIVIDE_LAST) begin
                state <= BOUNDS;
            end
        end
        BOUNDS: begin
            kept_low <= floor_bound + inexact_bound - threshold_bound;
            kept_high <= floor_bound + threshold_bound;
            count <= {COUNT_W{1'b0}};
            kept_sum <= {SUM_W{1'b0}};
            step <= {STEP_W{1'b0}};
            state <= SCAN;
        end
        SCAN: begin
            if (keep) begin
                count <= count + 1'b1;
                kept_sum <= kept_sum + sample_sum;
            end
            step <= next_step;
            if (step == SCAN_LAST) begin
                state <= RECIPROCAL;
            end
        end
        RECIPROCAL: begin
            state <= LOAD;
        end
        LOAD: begin
            product_high <= {BOUND_W{1'b0}};
            product_low <= rom_q[LOW_W-1:0];
            step <= {STEP_W{1'b0}};
            state <= MULTIPLY;
        end
        MULTIPLY: begin
            product_high <= {partial[BOUND_W-1], partial[BOUND_W-1:1]};
            product_low <= {partial[0], product_low[LOW_W-1:1]};
            step <= next_step;
            if (step == MULTIPLY_LAST) begin
                state <= OUTPUT;
            end
        end
        OUTPUT: begin
            y_reg <= y_next;
            kept_reg <= count;
            valid_reg <= 1'b1;
            state <= IDLE;
        end
        default: begin
            state <= IDLE;
        end
    endcase

    if (take) begin
        sum <= sum_next;
        if (index == LAST_INDEX) begin
            index <= {COUNT_W{1'b0}};
            negative <= sum_next[SUM_W-1];
            dividend <= sum_next[SUM_W-1] ? ~sum_next[MAGNITUDE_W-1:0] : sum_next[MAGNITUDE_W-1:0];
            remainder <= {REMAINDER_W{1'b0}};
            step <= {STEP_W{1'b0}};
            state <= DIVIDE;
        end else begin
            index <= index + 1'b1;
        end
    end

    if (rst) begin
        index <= {COUNT_W{1'b0}};
        state <= IDLE;
        valid_reg <= 1'b0;
    end
end

assign y = y_reg;
assign kept = kept_reg;
assign y_valid = valid_reg;

`ifndef SYNTHESIS
// Simulation only (yosys defines SYNTHESIS): a ce while the previous block is still being
// processed would overwrite the RAM it reads; stop the simulation instead, naming this
// instance. The next block may start LATENCY clocks after a block's last ce
// (gyrofx_job::pipeline, the manifest's min_clocks_per_sample).
always @(posedge clk) begin
    if (take && state != IDLE) begin
        $display("FAIL %m: a sample while the previous block is being processed; gyrofx_mean_filter_serial takes the next block's first sample at most every min_clocks_per_sample clocks after a block's last (manifest.json)");
        $fatal(1, "%m: a sample while busy");
    end
end
`endif

endmodule

`resetall
