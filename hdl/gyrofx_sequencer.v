// Language: Verilog 2001

`resetall
`timescale 1ns / 1ps
`default_nettype none

/*
 * gyrofx_sequencer — state-machine sequencer of mode reversal (paper 004, Fig. 5).
 *
 * Purpose: cut time into intervals of INTERVAL_LENGTH samples, W = INTERVALS
 *   intervals per cycle (the bias estimator's window); gyro A runs in mode
 *   PATTERN[i] in interval i, gyro B in the opposite mode, with B's whole
 *   schedule STAGGER samples behind A's. Bit-exact with gyrofx_model::sequencer.
 *
 * Algorithm: per gyro a phase counter (0..L-1) and an interval counter
 *   (0..W-1), advanced on ce. After reset A is at (0, 0); B at position
 *   W*L - STAGGER (the tail of a virtual previous cycle). For the current sample:
 *     mode    = PATTERN[interval] (A), ~PATTERN[interval] (B); 1 = normal
 *     blank   = phase < BLANK
 *     done    = phase == L - 1
 *     window_done = done_b & interval_b == W - 1 & B has started a full cycle
 *
 * Latency: outputs describe the current sample (combinational from the
 *   counters, 0 clocks); the counters advance on ce. rst is synchronous.
 */
module gyrofx_sequencer #(
    // L: samples per measurement interval
    parameter integer INTERVAL_LENGTH = 150,
    // W: intervals per cycle
    parameter integer INTERVALS = 4,
    // A's mode per interval, bit i for interval i: 1 = normal, 0 = reversed
    parameter [INTERVALS-1:0] PATTERN = 4'b0101,
    // M: blanked samples at the start of every interval
    parameter integer BLANK = 10,
    // S: samples by which B runs behind A
    parameter integer STAGGER = 0,
    // width of the phase counter; width of an interval index, ceil(log2(INTERVALS))
    parameter integer PHASE_W = 8,
    parameter integer INTERVAL_W = 2
) (
    input  wire                  clk,
    input  wire                  rst,
    input  wire                  ce,
    output wire                  mode_a,
    output wire                  mode_b,
    output wire                  blank_a,
    output wire                  blank_b,
    output wire [INTERVAL_W-1:0] interval_a,
    output wire [INTERVAL_W-1:0] interval_b,
    output wire                  done_a,
    output wire                  done_b,
    output wire                  window_done
);

// B's position after reset: W*L - S (mod W*L).
localparam integer B_START_INTERVAL = (STAGGER == 0) ? 0 : INTERVALS - 1;
localparam integer B_START_PHASE = (STAGGER == 0) ? 0 : INTERVAL_LENGTH - STAGGER;

initial begin
    if (INTERVAL_LENGTH < 1 || INTERVALS < 2 || INTERVALS > 256) begin
        $display("%m: INTERVAL_LENGTH (%0d) must be >= 1 and INTERVALS (%0d) 2..256", INTERVAL_LENGTH, INTERVALS);
        $finish;
    end
    if (BLANK >= INTERVAL_LENGTH || STAGGER >= INTERVAL_LENGTH) begin
        $display("%m: BLANK (%0d) and STAGGER (%0d) must be < INTERVAL_LENGTH (%0d)", BLANK, STAGGER, INTERVAL_LENGTH);
        $finish;
    end
    if ((1 << PHASE_W) < INTERVAL_LENGTH || (1 << INTERVAL_W) < INTERVALS) begin
        $display("%m: PHASE_W (%0d) or INTERVAL_W (%0d) too narrow", PHASE_W, INTERVAL_W);
        $finish;
    end
end

localparam [31:0] LAST_PHASE_32 = INTERVAL_LENGTH - 1;
localparam [31:0] LAST_INTERVAL_32 = INTERVALS - 1;
localparam [31:0] BLANK_32 = BLANK;
localparam [31:0] B_PHASE_32 = B_START_PHASE;
localparam [31:0] B_INTERVAL_32 = B_START_INTERVAL;
localparam [PHASE_W-1:0] LAST_PHASE = LAST_PHASE_32[PHASE_W-1:0];
localparam [INTERVAL_W-1:0] LAST_INTERVAL = LAST_INTERVAL_32[INTERVAL_W-1:0];
localparam [PHASE_W-1:0] BLANK_PHASES = BLANK_32[PHASE_W-1:0];
localparam [PHASE_W-1:0] B_PHASE_RESET = B_PHASE_32[PHASE_W-1:0];
localparam [INTERVAL_W-1:0] B_INTERVAL_RESET = B_INTERVAL_32[INTERVAL_W-1:0];

reg [PHASE_W-1:0] phase_a_reg = {PHASE_W{1'b0}};
reg [INTERVAL_W-1:0] interval_a_reg = {INTERVAL_W{1'b0}};
reg [PHASE_W-1:0] phase_b_reg = B_PHASE_RESET;
reg [INTERVAL_W-1:0] interval_b_reg = B_INTERVAL_RESET;
reg b_started_reg = (STAGGER == 0);

assign interval_a = interval_a_reg;
assign interval_b = interval_b_reg;
assign mode_a = PATTERN[interval_a_reg];
assign mode_b = ~PATTERN[interval_b_reg];
generate
    if (BLANK == 0) begin : g_no_blanking
        assign blank_a = 1'b0;
        assign blank_b = 1'b0;
    end else begin : g_blanking
        assign blank_a = phase_a_reg < BLANK_PHASES;
        assign blank_b = phase_b_reg < BLANK_PHASES;
    end
endgenerate
assign done_a = phase_a_reg == LAST_PHASE;
assign done_b = phase_b_reg == LAST_PHASE;
assign window_done = done_b && interval_b_reg == LAST_INTERVAL && b_started_reg;

always @(posedge clk) begin
    if (ce) begin
        if (done_a) begin
            phase_a_reg <= {PHASE_W{1'b0}};
            interval_a_reg <= (interval_a_reg == LAST_INTERVAL) ? {INTERVAL_W{1'b0}} : interval_a_reg + 1'b1;
        end else begin
            phase_a_reg <= phase_a_reg + 1'b1;
        end
        if (done_b) begin
            phase_b_reg <= {PHASE_W{1'b0}};
            interval_b_reg <= (interval_b_reg == LAST_INTERVAL) ? {INTERVAL_W{1'b0}} : interval_b_reg + 1'b1;
        end else begin
            phase_b_reg <= phase_b_reg + 1'b1;
        end
        if (phase_b_reg == {PHASE_W{1'b0}} && interval_b_reg == {INTERVAL_W{1'b0}}) begin
            b_started_reg <= 1'b1;
        end
    end

    if (rst) begin
        phase_a_reg <= {PHASE_W{1'b0}};
        interval_a_reg <= {INTERVAL_W{1'b0}};
        phase_b_reg <= B_PHASE_RESET;
        interval_b_reg <= B_INTERVAL_RESET;
        b_started_reg <= (STAGGER == 0);
    end
end

endmodule

`resetall
