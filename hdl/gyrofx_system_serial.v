// Language: Verilog 2001

`resetall
`timescale 1ns / 1ps
`default_nettype none

/*
 * gyrofx_system_serial — the whole mode-reversal gyro at the ADC rate, folded: gyro A's and B's
 *   loops on one folded datapath (gyrofx_gyro_pair_serial) feeding the time-multiplexed chain
 *   (gyrofx_top_serial's sequencer and engine), whose sequencer commands the loops' modes,
 *   wired as gyrofx_system wires gyrofx_gyro_loop and gyrofx_top (architecture = "serial").
 *
 * Purpose: gyrofx_system on a small FPGA, bit-exact with it except that the chain's results
 *   show CHAIN_DELAY_SAMPLES ADC samples later (gyrofx_job::golden::System::of;
 *   docs/blocks/system.md, "Folded architecture").
 *
 * Algorithm (per ADC sample, ce high), as gyrofx_system's:
 *     mode_g = enable ? the chain's mode_g : normal      (loop g's mode input)
 *     both loops take the sample in mode_g
 *     when the loops output a decimated rate and enable was high at that ADC sample, the
 *     chain takes y_a = rate_a, y_b = rate_b at the bw_sel of that sample
 *   then, CHAIN_DELAY_SAMPLES ADC samples after the one whose rates the chain took, the
 *   outputs rate_out, out_valid (a one-clock pulse), bias_a, bias_b, estimated load what the
 *   chain made of them.
 *
 * Why the delay: the folded pair takes up to SCHEDULE_LEN + 2 clocks an ADC sample and makes
 *   a decimation's rates SCHEDULE_SEGMENTS ADC samples after the sample that decimates; the
 *   serial chain takes its program's clocks (gyrofx_top_serial's SETTLE + 1, over a thousand)
 *   a chain sample and runs beside the loops over many ADC samples. Its sequencer takes the
 *   sample at the end of the decimating ADC sample, so that its modes change in time for the
 *   next one, as in gyrofx_system; its engine starts when the rates are made, on the
 *   sequencer's flags as of the take, and its results come later, within some later ADC
 *   sample that depends on the ce cadence. The system publishes them a fixed number of ADC
 *   samples later instead, CHAIN_DELAY_SAMPLES = SCHEDULE_SEGMENTS
 *   + ceil((chain clocks + margin) / (SCHEDULE_LEN + 3))
 *   (gyrofx_job::pipeline::system_chain_delay), so that every output is a function of the
 *   samples whatever the cadence: the engine's results hold until then. The chain must
 *   finish between chain samples: CHAIN_DELAY_SAMPLES <= CIC_DECIMATION (gyrofx refuses a
 *   config where it cannot).
 *
 * Timing: ce at most every SCHEDULE_LEN + 3 clocks; adc_* hold from ce until the next ce
 *   (the pair reads them while the sample runs, SCHEDULE_REGULAR + 2 clocks after ce at the
 *   latest; the other inputs are taken at ce). Every output shows SCHEDULE_LEN + 3
 *   clocks after ce: dac_*, locked_* load with the loops' (by SCHEDULE_LEN + 2 clocks) and
 *   hold until the next sample's; mode_a, mode_b (the modes of the next sample) change the
 *   clock after the sequencer's take, at the end of a decimating sample's regular part
 *   (SCHEDULE_REGULAR + 3 clocks after ce), and hold otherwise; the published chain outputs
 *   load at the loops' output clock, SCHEDULE_LEN + 2 clocks after ce, and hold otherwise
 *   (out_valid for one clock). A clock with rst high clears every register and the pending
 *   publication.
 *
 * Parameters: the chain's as gyrofx_top_serial's (its program and coefficient ROMs are the
 *   system chain's), IN_F the loops' output fraction bits; the loops' as gyrofx_system's
 *   (shared ones once, ROUNDING, SATURATE, LATENCY as LOOP_*, per gyro with the prefix A_ or
 *   B_), plus the folded pair's schedule (both gyros' loops have the same formats);
 *   CHAIN_DELAY_SAMPLES.
 */
module gyrofx_system_serial #(
    // chain: sequencer
    parameter integer INTERVAL_LENGTH = 3,
    parameter integer INTERVALS = 4,
    parameter [INTERVALS-1:0] PATTERN = 4'h5,
    parameter integer BLANK = 1,
    parameter integer STAGGER = 0,
    parameter integer PHASE_W = 2,
    parameter integer INTERVAL_W = 2,
    // chain: gyro samples (the loops' rate output, IN_F its fraction bits), rate output and
    // bias outputs: widths
    parameter integer IN_W = 24,
    parameter integer IN_F = 14,
    parameter integer OUT_W = 24,
    parameter integer BIAS_W = 28,
    parameter integer SEL_W = 2,
    // KF gain words: bw_sel must be below ROM_DEPTH
    parameter integer ROM_DEPTH = 3,
    // chain: the engine (gyrofx_serial_engine), written by gyrofx for the system's chain
    parameter integer ACC_W = 32,
    parameter integer ADDR_W = 6,
    parameter integer COEF_ADDR_W = 5,
    parameter integer RAM_DEPTH = 53,
    parameter integer COEF_DEPTH = 29,
    parameter integer PROGRAM_DEPTH = 388,
    parameter integer RAM_INDEX_SHIFT = 1,
    parameter integer COEF_INDEX_SHIFT = 2,
    // chain rounding: 0 floor, 1 ceil, 2 zero, 3 nearest, 4 round, 5 convergent
    parameter integer ROUNDING = 3,
    parameter PROGRAM_FILE = "system_serial_program.mem",
    parameter COEFFICIENT_FILE = "system_serial_coefficients.mem",
    // loops (shared by both gyros): NCOs, demodulators, PLL and AGC formats, CICs, DAC
    parameter integer NCO_PHASE_W = 32,
    parameter integer NCO_ADDR_W = 10,
    parameter integer NCO_SIN_W = 18,
    parameter integer NCO_ERROR_FEEDBACK = 1,
    parameter integer DEMOD_ADC_W = 24,
    parameter integer DEMOD_ADC_F = 23,
    parameter integer DEMOD_REF_W = 18,
    parameter integer DEMOD_REF_F = 17,
    parameter integer DEMOD_PROD_W = 36,
    parameter integer DEMOD_PROD_F = 34,
    parameter integer DEMOD_STATE_W = 44,
    parameter integer DEMOD_STATE_F = 42,
    parameter integer DEMOD_OUT_W = 32,
    parameter integer DEMOD_OUT_F = 30,
    parameter integer DEMOD_SHIFT = 8,
    parameter integer PLL_ERR_W = 32,
    parameter integer PLL_ERR_F = 30,
    parameter integer PLL_INT_W = 40,
    parameter integer PLL_INT_F = 38,
    parameter integer PLL_OUT_W = 32,
    parameter integer PLL_OUT_F = 32,
    parameter integer AGC_ERR_W = 32,
    parameter integer AGC_ERR_F = 30,
    parameter integer AGC_INT_W = 40,
    parameter integer AGC_INT_F = 20,
    parameter integer AGC_OUT_W = 24,
    parameter integer AGC_OUT_F = 6,
    parameter integer CIC_IN_W = 32,
    parameter integer CIC_IN_F = 30,
    parameter integer CIC_STAGES = 3,
    parameter integer CIC_DECIMATION = 1000,
    parameter integer CIC_DELAY = 1,
    parameter integer CIC_SHIFT = 30,
    parameter integer CIC_MID_W = 40,
    parameter integer CIC_MID_F = 38,
    parameter integer CIC_TAPS = 5,
    parameter integer CIC_COEF_W = 18,
    parameter integer CIC_COEF_F = 16,
    parameter integer CIC_OUT_W = 32,
    parameter integer CIC_OUT_F = 30,
    parameter integer DAC_W = 18,
    parameter integer DAC_F = 0,
    // loops: ADC-to-DAC latency (samples), lock detector, rounding and overflow, ROM images
    parameter integer LOOP_LATENCY = 1,
    parameter integer LOCK_SHIFT = 9,
    parameter integer LOCK_HOLD = 2000,
    parameter integer LOOP_ROUNDING = 3,
    parameter integer LOOP_SATURATE = 1,
    parameter NCO_ROM_FILE = "gyro_loop_nco_sine.mem",
    parameter CIC_ROM_FILE = "gyro_loop_cic_taps.mem",
    // gyro A's loop: PI gains and limits, 1/SF format, per-mode values (_N normal, _R reverse)
    parameter integer A_PLL_KP_W = 18,
    parameter integer A_PLL_KP_F = 27,
    parameter integer A_PLL_KI_W = 18,
    parameter integer A_PLL_KI_F = 38,
    parameter signed [A_PLL_KP_W-1:0] A_PLL_KP = 18'sh10625,
    parameter signed [A_PLL_KI_W-1:0] A_PLL_KI = 18'sh17795,
    parameter signed [PLL_INT_W-1:0] A_PLL_INT_MIN = 40'sh292cd0c7b,
    parameter signed [PLL_INT_W-1:0] A_PLL_INT_MAX = 40'sh2a786ac8d,
    parameter integer A_AGC_KP_W = 18,
    parameter integer A_AGC_KP_F = 1,
    parameter integer A_AGC_KI_W = 18,
    parameter integer A_AGC_KI_F = 11,
    parameter signed [A_AGC_KP_W-1:0] A_AGC_KP = 18'sh19a9a,
    parameter signed [A_AGC_KI_W-1:0] A_AGC_KI = 18'sh12624,
    parameter signed [AGC_INT_W-1:0] A_AGC_INT_MIN = 40'sh0,
    parameter signed [AGC_INT_W-1:0] A_AGC_INT_MAX = 40'sh1ffff00000,
    parameter integer A_COEF_W = 24,
    parameter integer A_COEF_F = 6,
    parameter signed [DEMOD_OUT_W-1:0] A_SETPOINT_N = 32'shcccc666,
    parameter signed [DEMOD_OUT_W-1:0] A_SETPOINT_R = 32'shcccc666,
    parameter [NCO_PHASE_W-1:0] A_FREQ_WORD_N = 32'ha7d5617,
    parameter [NCO_PHASE_W-1:0] A_FREQ_WORD_R = 32'ha6bf8ce,
    parameter signed [PLL_INT_W-1:0] A_PLL_PRESET_N = 40'sh29f5585a4,
    parameter signed [PLL_INT_W-1:0] A_PLL_PRESET_R = 40'sh29afe3365,
    parameter [NCO_PHASE_W-1:0] A_DAC_OFFSET_N = 32'hfd38ab7,
    parameter [NCO_PHASE_W-1:0] A_DAC_OFFSET_R = 32'hfbb6e38,
    parameter [NCO_PHASE_W-1:0] A_SENSE_OFFSET_N = 32'h4f56436e,
    parameter [NCO_PHASE_W-1:0] A_SENSE_OFFSET_R = 32'hafd6e2bb,
    parameter signed [A_COEF_W-1:0] A_RATE_COEF_N = 24'sh63db80,
    parameter signed [A_COEF_W-1:0] A_RATE_COEF_R = 24'sh9aa98a,
    parameter signed [A_COEF_W-1:0] A_QUAD_COEF_N = 24'sh9c2480,
    parameter signed [A_COEF_W-1:0] A_QUAD_COEF_R = 24'sh9aa98a,
    parameter signed [63:0] A_LOCK_Q_N = 64'shb70271b,
    parameter signed [63:0] A_LOCK_Q_R = 64'shb70271b,
    parameter signed [63:0] A_LOCK_A_N = 64'sh68db574,
    parameter signed [63:0] A_LOCK_A_R = 64'sh68db574,
    // gyro B's loop: the same
    parameter integer B_PLL_KP_W = 18,
    parameter integer B_PLL_KP_F = 27,
    parameter integer B_PLL_KI_W = 18,
    parameter integer B_PLL_KI_F = 38,
    parameter signed [B_PLL_KP_W-1:0] B_PLL_KP = 18'sh10625,
    parameter signed [B_PLL_KI_W-1:0] B_PLL_KI = 18'sh17795,
    parameter signed [PLL_INT_W-1:0] B_PLL_INT_MIN = 40'sh292cd0c7b,
    parameter signed [PLL_INT_W-1:0] B_PLL_INT_MAX = 40'sh2a786ac8d,
    parameter integer B_AGC_KP_W = 18,
    parameter integer B_AGC_KP_F = 1,
    parameter integer B_AGC_KI_W = 18,
    parameter integer B_AGC_KI_F = 11,
    parameter signed [B_AGC_KP_W-1:0] B_AGC_KP = 18'sh19a9a,
    parameter signed [B_AGC_KI_W-1:0] B_AGC_KI = 18'sh12624,
    parameter signed [AGC_INT_W-1:0] B_AGC_INT_MIN = 40'sh0,
    parameter signed [AGC_INT_W-1:0] B_AGC_INT_MAX = 40'sh1ffff00000,
    parameter integer B_COEF_W = 24,
    parameter integer B_COEF_F = 6,
    parameter signed [DEMOD_OUT_W-1:0] B_SETPOINT_N = 32'shcccc666,
    parameter signed [DEMOD_OUT_W-1:0] B_SETPOINT_R = 32'shcccc666,
    parameter [NCO_PHASE_W-1:0] B_FREQ_WORD_N = 32'ha7d5617,
    parameter [NCO_PHASE_W-1:0] B_FREQ_WORD_R = 32'ha6bf8ce,
    parameter signed [PLL_INT_W-1:0] B_PLL_PRESET_N = 40'sh29f5585a4,
    parameter signed [PLL_INT_W-1:0] B_PLL_PRESET_R = 40'sh29afe3365,
    parameter [NCO_PHASE_W-1:0] B_DAC_OFFSET_N = 32'hfd38ab7,
    parameter [NCO_PHASE_W-1:0] B_DAC_OFFSET_R = 32'hfbb6e38,
    parameter [NCO_PHASE_W-1:0] B_SENSE_OFFSET_N = 32'h4f56436e,
    parameter [NCO_PHASE_W-1:0] B_SENSE_OFFSET_R = 32'hafd6e2bb,
    parameter signed [B_COEF_W-1:0] B_RATE_COEF_N = 24'sh63db80,
    parameter signed [B_COEF_W-1:0] B_RATE_COEF_R = 24'sh9aa98a,
    parameter signed [B_COEF_W-1:0] B_QUAD_COEF_N = 24'sh9c2480,
    parameter signed [B_COEF_W-1:0] B_QUAD_COEF_R = 24'sh9aa98a,
    parameter signed [63:0] B_LOCK_Q_N = 64'shb70271b,
    parameter signed [63:0] B_LOCK_Q_R = 64'shb70271b,
    parameter signed [63:0] B_LOCK_A_N = 64'sh68db574,
    parameter signed [63:0] B_LOCK_A_R = 64'sh68db574,
    // loops: the folded pair's schedule (gyrofx_gyro_pair_serial): image, words of the
    // longest sample, of the regular part, deferred segments, RAM words
    parameter SCHEDULE_FILE = "gyro_pair_schedule.mem",
    parameter integer SCHEDULE_LEN = 117,
    parameter integer SCHEDULE_REGULAR = 103,
    parameter integer SCHEDULE_SEGMENTS = 13,
    parameter integer RAM_WORDS = 64,
    // ADC samples from the one whose rates the chain takes to the one that publishes its
    // outputs (1..CIC_DECIMATION; gyrofx_job::pipeline::system_chain_delay)
    parameter integer CHAIN_DELAY_SAMPLES = 26
) (
    input  wire                           clk,
    input  wire                           rst,
    input  wire                           ce,
    input  wire                           enable,
    input  wire [SEL_W-1:0]               bw_sel,
    input  wire signed [DEMOD_ADC_W-1:0]  adc_a_x,
    input  wire signed [DEMOD_ADC_W-1:0]  adc_a_y,
    input  wire signed [DEMOD_ADC_W-1:0]  adc_b_x,
    input  wire signed [DEMOD_ADC_W-1:0]  adc_b_y,
    output wire signed [DAC_W-1:0]        dac_a_x,
    output wire signed [DAC_W-1:0]        dac_a_y,
    output wire signed [DAC_W-1:0]        dac_b_x,
    output wire signed [DAC_W-1:0]        dac_b_y,
    output wire                           locked_a,
    output wire                           locked_b,
    output wire                           mode_a,
    output wire                           mode_b,
    output wire                           out_valid,
    output wire signed [OUT_W-1:0]        rate_out,
    output wire signed [BIAS_W-1:0]       bias_a,
    output wire signed [BIAS_W-1:0]       bias_b,
    output wire                           estimated
);

// ceil(log2(value)), 0 for value 1.
function integer ceil_log2;
    input integer value;
    begin
        ceil_log2 = 0;
        while ((1 << ceil_log2) < value)
            ceil_log2 = ceil_log2 + 1;
    end
endfunction

// Clocks from ce to the loops' outputs (gyrofx_job::pipeline::gyro_loop): the output clock.
localparam integer LOOP_CLOCKS = SCHEDULE_LEN + 2;
localparam integer COUNT_W = ceil_log2(LOOP_CLOCKS + 1);
localparam integer DELAY_W = ceil_log2(CHAIN_DELAY_SAMPLES + 1);
localparam [COUNT_W-1:0] OUTPUT_COUNT = LOOP_CLOCKS[COUNT_W-1:0];
localparam [DELAY_W-1:0] DELAY = CHAIN_DELAY_SAMPLES[DELAY_W-1:0];
localparam [DELAY_W-1:0] LAST = 1;

initial begin
    if (CHAIN_DELAY_SAMPLES < 1 || CHAIN_DELAY_SAMPLES > CIC_DECIMATION) begin
        $display("%m: CHAIN_DELAY_SAMPLES (%0d) must be 1..CIC_DECIMATION (%0d): the chain finishes between chain samples",
            CHAIN_DELAY_SAMPLES, CIC_DECIMATION);
        $finish;
    end
    if (ROM_DEPTH < 1 || ROM_DEPTH > (1 << SEL_W)) begin
        $display("%m: ROM_DEPTH (%0d) must be 1..2^SEL_W (%0d)", ROM_DEPTH, 1 << SEL_W);
        $finish;
    end
    // The folded pair gives both gyros one datapath: one set of formats.
    if (A_PLL_KP_W != B_PLL_KP_W || A_PLL_KP_F != B_PLL_KP_F || A_PLL_KI_W != B_PLL_KI_W
            || A_PLL_KI_F != B_PLL_KI_F || A_AGC_KP_W != B_AGC_KP_W || A_AGC_KP_F != B_AGC_KP_F
            || A_AGC_KI_W != B_AGC_KI_W || A_AGC_KI_F != B_AGC_KI_F || A_COEF_W != B_COEF_W
            || A_COEF_F != B_COEF_F) begin
        $display("%m: gyro A's and B's loops must share their gains' and 1/SF coefficients' formats (one folded datapath)");
        $finish;
    end
end

// enable and bw_sel as of the ADC sample in flight: the loops' decimated output comes
// SCHEDULE_LEN + 2 clocks after its ce, while the inputs may already describe the next.
reg enable_reg = 1'b0;
reg [SEL_W-1:0] bw_sel_reg = {SEL_W{1'b0}};

always @(posedge clk) begin
    if (ce) begin
        enable_reg <= enable;
        bw_sel_reg <= bw_sel;
    end
    if (rst) begin
        enable_reg <= 1'b0;
        bw_sel_reg <= {SEL_W{1'b0}};
    end
end

wire loop_mode_a = enable ? mode_a : 1'b1;
wire loop_mode_b = enable ? mode_b : 1'b1;
wire signed [IN_W-1:0] rate_a;
wire signed [IN_W-1:0] rate_b;
wire decimating;
wire rates_valid;

/* verilator lint_off PINCONNECTEMPTY */
gyrofx_gyro_pair_serial #(
    .NCO_PHASE_W(NCO_PHASE_W), .NCO_ADDR_W(NCO_ADDR_W), .NCO_SIN_W(NCO_SIN_W),
    .NCO_ERROR_FEEDBACK(NCO_ERROR_FEEDBACK),
    .DEMOD_ADC_W(DEMOD_ADC_W), .DEMOD_ADC_F(DEMOD_ADC_F), .DEMOD_REF_W(DEMOD_REF_W),
    .DEMOD_REF_F(DEMOD_REF_F), .DEMOD_PROD_W(DEMOD_PROD_W), .DEMOD_PROD_F(DEMOD_PROD_F),
    .DEMOD_STATE_W(DEMOD_STATE_W), .DEMOD_STATE_F(DEMOD_STATE_F),
    .DEMOD_OUT_W(DEMOD_OUT_W), .DEMOD_OUT_F(DEMOD_OUT_F), .DEMOD_SHIFT(DEMOD_SHIFT),
    .PLL_ERR_W(PLL_ERR_W), .PLL_ERR_F(PLL_ERR_F), .PLL_KP_W(A_PLL_KP_W), .PLL_KP_F(A_PLL_KP_F),
    .PLL_KI_W(A_PLL_KI_W), .PLL_KI_F(A_PLL_KI_F), .PLL_INT_W(PLL_INT_W), .PLL_INT_F(PLL_INT_F),
    .PLL_OUT_W(PLL_OUT_W), .PLL_OUT_F(PLL_OUT_F), .AGC_ERR_W(AGC_ERR_W), .AGC_ERR_F(AGC_ERR_F),
    .AGC_KP_W(A_AGC_KP_W), .AGC_KP_F(A_AGC_KP_F), .AGC_KI_W(A_AGC_KI_W), .AGC_KI_F(A_AGC_KI_F),
    .AGC_INT_W(AGC_INT_W), .AGC_INT_F(AGC_INT_F), .AGC_OUT_W(AGC_OUT_W), .AGC_OUT_F(AGC_OUT_F),
    .CIC_IN_W(CIC_IN_W), .CIC_IN_F(CIC_IN_F), .CIC_STAGES(CIC_STAGES),
    .CIC_DECIMATION(CIC_DECIMATION), .CIC_DELAY(CIC_DELAY), .CIC_SHIFT(CIC_SHIFT),
    .CIC_MID_W(CIC_MID_W), .CIC_MID_F(CIC_MID_F), .CIC_TAPS(CIC_TAPS),
    .CIC_COEF_W(CIC_COEF_W), .CIC_COEF_F(CIC_COEF_F), .CIC_OUT_W(CIC_OUT_W),
    .CIC_OUT_F(CIC_OUT_F), .DAC_W(DAC_W), .DAC_F(DAC_F), .OUT_W(IN_W), .OUT_F(IN_F),
    .COEF_W(A_COEF_W), .COEF_F(A_COEF_F), .LATENCY(LOOP_LATENCY), .LOCK_SHIFT(LOCK_SHIFT),
    .LOCK_HOLD(LOCK_HOLD),
    .A_PLL_KP(A_PLL_KP), .A_PLL_KI(A_PLL_KI), .A_PLL_INT_MIN(A_PLL_INT_MIN),
    .A_PLL_INT_MAX(A_PLL_INT_MAX), .A_AGC_KP(A_AGC_KP), .A_AGC_KI(A_AGC_KI),
    .A_AGC_INT_MIN(A_AGC_INT_MIN), .A_AGC_INT_MAX(A_AGC_INT_MAX),
    .A_SETPOINT_N(A_SETPOINT_N), .A_SETPOINT_R(A_SETPOINT_R),
    .A_FREQ_WORD_N(A_FREQ_WORD_N), .A_FREQ_WORD_R(A_FREQ_WORD_R),
    .A_PLL_PRESET_N(A_PLL_PRESET_N), .A_PLL_PRESET_R(A_PLL_PRESET_R),
    .A_DAC_OFFSET_N(A_DAC_OFFSET_N), .A_DAC_OFFSET_R(A_DAC_OFFSET_R),
    .A_SENSE_OFFSET_N(A_SENSE_OFFSET_N), .A_SENSE_OFFSET_R(A_SENSE_OFFSET_R),
    .A_RATE_COEF_N(A_RATE_COEF_N), .A_RATE_COEF_R(A_RATE_COEF_R),
    .A_QUAD_COEF_N(A_QUAD_COEF_N), .A_QUAD_COEF_R(A_QUAD_COEF_R),
    .A_LOCK_Q_N(A_LOCK_Q_N), .A_LOCK_Q_R(A_LOCK_Q_R), .A_LOCK_A_N(A_LOCK_A_N),
    .A_LOCK_A_R(A_LOCK_A_R),
    .B_PLL_KP(B_PLL_KP), .B_PLL_KI(B_PLL_KI), .B_PLL_INT_MIN(B_PLL_INT_MIN),
    .B_PLL_INT_MAX(B_PLL_INT_MAX), .B_AGC_KP(B_AGC_KP), .B_AGC_KI(B_AGC_KI),
    .B_AGC_INT_MIN(B_AGC_INT_MIN), .B_AGC_INT_MAX(B_AGC_INT_MAX),
    .B_SETPOINT_N(B_SETPOINT_N), .B_SETPOINT_R(B_SETPOINT_R),
    .B_FREQ_WORD_N(B_FREQ_WORD_N), .B_FREQ_WORD_R(B_FREQ_WORD_R),
    .B_PLL_PRESET_N(B_PLL_PRESET_N), .B_PLL_PRESET_R(B_PLL_PRESET_R),
    .B_DAC_OFFSET_N(B_DAC_OFFSET_N), .B_DAC_OFFSET_R(B_DAC_OFFSET_R),
    .B_SENSE_OFFSET_N(B_SENSE_OFFSET_N), .B_SENSE_OFFSET_R(B_SENSE_OFFSET_R),
    .B_RATE_COEF_N(B_RATE_COEF_N), .B_RATE_COEF_R(B_RATE_COEF_R),
    .B_QUAD_COEF_N(B_QUAD_COEF_N), .B_QUAD_COEF_R(B_QUAD_COEF_R),
    .B_LOCK_Q_N(B_LOCK_Q_N), .B_LOCK_Q_R(B_LOCK_Q_R), .B_LOCK_A_N(B_LOCK_A_N),
    .B_LOCK_A_R(B_LOCK_A_R),
    .ROUNDING(LOOP_ROUNDING), .SATURATE(LOOP_SATURATE), .NCO_ROM_FILE(NCO_ROM_FILE),
    .CIC_ROM_FILE(CIC_ROM_FILE), .SCHEDULE_FILE(SCHEDULE_FILE), .SCHEDULE_LEN(SCHEDULE_LEN),
    .SCHEDULE_REGULAR(SCHEDULE_REGULAR), .SCHEDULE_SEGMENTS(SCHEDULE_SEGMENTS),
    .RAM_WORDS(RAM_WORDS)
) loops (
    .clk(clk), .rst(rst), .ce(ce), .mode_a(loop_mode_a), .mode_b(loop_mode_b),
    .adc_a_x(adc_a_x), .adc_a_y(adc_a_y), .adc_b_x(adc_b_x), .adc_b_y(adc_b_y),
    .dac_a_x(dac_a_x), .dac_a_y(dac_a_y), .dac_b_x(dac_b_x), .dac_b_y(dac_b_y),
    .locked_a(locked_a), .locked_b(locked_b), .decimating(decimating),
    .rate_a(rate_a), .quadrature_a(), .rate_b(rate_b), .quadrature_b(),
    .out_valid(rates_valid)
);
/* verilator lint_on PINCONNECTEMPTY */

// The chain: its sequencer takes the sample at the end of the decimating ADC sample (its modes
// change the clock after, in time for the next ADC sample, as in gyrofx_system); the engine
// (gyrofx_top_serial's, one shared multiplier) starts when the loops' deferred work has made
// that sample's rates, SCHEDULE_SEGMENTS ADC samples later, on the sequencer's flags and the
// bw_sel as of the take.
wire take = decimating && enable_reg;
wire blank_a;
wire blank_b;
wire [INTERVAL_W-1:0] interval_a;
wire [INTERVAL_W-1:0] interval_b;
wire done_a;
wire done_b;
wire window_done;

gyrofx_sequencer #(
    .INTERVAL_LENGTH(INTERVAL_LENGTH), .INTERVALS(INTERVALS), .PATTERN(PATTERN),
    .BLANK(BLANK), .STAGGER(STAGGER), .PHASE_W(PHASE_W), .INTERVAL_W(INTERVAL_W)
) sequencer (
    .clk(clk), .rst(rst), .ce(take),
    .mode_a(mode_a), .mode_b(mode_b), .blank_a(blank_a), .blank_b(blank_b),
    .interval_a(interval_a), .interval_b(interval_b), .done_a(done_a), .done_b(done_b),
    .window_done(window_done)
);

// The sequencer's description of the taken sample, held for the engine, and whether a take
// waits for its rates.
reg taken_reg = 1'b0;
reg [SEL_W-1:0] taken_bw_sel_reg = {SEL_W{1'b0}};
reg taken_mode_a_reg = 1'b1;
reg taken_mode_b_reg = 1'b1;
reg taken_blank_a_reg = 1'b0;
reg taken_blank_b_reg = 1'b0;
reg [INTERVAL_W-1:0] taken_interval_a_reg = {INTERVAL_W{1'b0}};
reg [INTERVAL_W-1:0] taken_interval_b_reg = {INTERVAL_W{1'b0}};
reg taken_done_a_reg = 1'b0;
reg taken_done_b_reg = 1'b0;
reg taken_window_done_reg = 1'b0;
always @(posedge clk) begin
    if (take) begin
        taken_reg <= 1'b1;
        taken_bw_sel_reg <= bw_sel_reg;
        taken_mode_a_reg <= mode_a;
        taken_mode_b_reg <= mode_b;
        taken_blank_a_reg <= blank_a;
        taken_blank_b_reg <= blank_b;
        taken_interval_a_reg <= interval_a;
        taken_interval_b_reg <= interval_b;
        taken_done_a_reg <= done_a;
        taken_done_b_reg <= done_b;
        taken_window_done_reg <= window_done;
    end else if (rates_valid) begin
        taken_reg <= 1'b0;
    end
    if (rst) begin
        taken_reg <= 1'b0;
    end
end

// The engine reads the pair's rates from its outputs, which hold for a decimation, and leaves
// its results where its program assembles them, which hold until the next chain sample's
// program: both outlast the chain's run and the publication's delay (CHAIN_DELAY_SAMPLES <=
// CIC_DECIMATION), so neither is copied (106 flip-flops that would share no logic cell with a
// LUT). The rate is published only when the engine's program made one (chain_valid_reg), as
// the engine's own output register would have held the last one otherwise.
wire chain_ce = rates_valid && taken_reg;
wire signed [OUT_W-1:0] chain_rate;
wire chain_valid;
wire signed [BIAS_W-1:0] chain_bias_a;
wire signed [BIAS_W-1:0] chain_bias_b;
wire chain_estimated;
/* verilator lint_off UNUSEDSIGNAL */
wire chain_busy;
/* verilator lint_on UNUSEDSIGNAL */

gyrofx_serial_engine #(
    .IN_W(IN_W), .OUT_W(OUT_W), .BIAS_W(BIAS_W), .SEL_W(SEL_W), .INTERVAL_W(INTERVAL_W),
    .ACC_W(ACC_W), .ADDR_W(ADDR_W), .COEF_ADDR_W(COEF_ADDR_W), .RAM_DEPTH(RAM_DEPTH),
    .COEF_DEPTH(COEF_DEPTH), .PROGRAM_DEPTH(PROGRAM_DEPTH),
    .RAM_INDEX_SHIFT(RAM_INDEX_SHIFT), .COEF_INDEX_SHIFT(COEF_INDEX_SHIFT),
    .ROUNDING(ROUNDING), .PROGRAM_FILE(PROGRAM_FILE), .COEFFICIENT_FILE(COEFFICIENT_FILE),
    .CAPTURE_SAMPLES(0), .HOLD_RESULTS(0)
) engine (
    .clk(clk), .rst(rst), .ce(chain_ce), .bw_sel(taken_bw_sel_reg), .y_a(rate_a), .y_b(rate_b),
    .mode_a(taken_mode_a_reg), .mode_b(taken_mode_b_reg), .blank_a(taken_blank_a_reg),
    .blank_b(taken_blank_b_reg), .done_a(taken_done_a_reg), .done_b(taken_done_b_reg),
    .window_done(taken_window_done_reg), .interval_a(taken_interval_a_reg),
    .interval_b(taken_interval_b_reg), .rate_out(chain_rate), .out_valid(chain_valid),
    .bias_a(chain_bias_a), .bias_b(chain_bias_b), .estimated(chain_estimated),
    .busy(chain_busy)
);

// Clocks since ce, up to the output clock (OUTPUT_COUNT; 0: none in flight).
reg [COUNT_W-1:0] count_reg = {COUNT_W{1'b0}};
wire output_clock = count_reg == OUTPUT_COUNT;
// Output clocks until the chain's last take is published (0: none pending), and whether the
// engine has pulsed out_valid since it took it (not when both gyros were blanked).
reg [DELAY_W-1:0] pending_reg = {DELAY_W{1'b0}};
reg chain_valid_reg = 1'b0;
reg take_pending_reg = 1'b0;
wire publish = output_clock && pending_reg == LAST;

reg out_valid_reg = 1'b0;
reg signed [OUT_W-1:0] rate_out_reg = {OUT_W{1'b0}};
reg signed [BIAS_W-1:0] bias_a_reg = {BIAS_W{1'b0}};
reg signed [BIAS_W-1:0] bias_b_reg = {BIAS_W{1'b0}};
reg estimated_reg = 1'b0;

always @(posedge clk) begin
    if (ce) begin
        count_reg <= {{(COUNT_W-1){1'b0}}, 1'b1};
    end else if (count_reg != {COUNT_W{1'b0}} && !output_clock) begin
        count_reg <= count_reg + 1'b1;
    end else begin
        count_reg <= {COUNT_W{1'b0}};
    end
    // A take (in this sample, before its output clock) starts the count down at the output
    // clock; DELAY output clocks later, publish.
    if (take) begin
        take_pending_reg <= 1'b1;
    end
    if (output_clock) begin
        if (take_pending_reg || take) begin
            pending_reg <= DELAY;
            take_pending_reg <= 1'b0;
        end else if (pending_reg != {DELAY_W{1'b0}}) begin
            pending_reg <= pending_reg - 1'b1;
        end
    end
    if (publish) begin
        chain_valid_reg <= 1'b0;
    end
    if (chain_valid) begin
        chain_valid_reg <= 1'b1;
    end
    out_valid_reg <= publish && chain_valid_reg;
    if (publish && chain_valid_reg) begin
        rate_out_reg <= chain_rate;
    end
    if (publish) begin
        bias_a_reg <= chain_bias_a;
        bias_b_reg <= chain_bias_b;
        estimated_reg <= chain_estimated;
    end
    if (rst) begin
        count_reg <= {COUNT_W{1'b0}};
        pending_reg <= {DELAY_W{1'b0}};
        take_pending_reg <= 1'b0;
        chain_valid_reg <= 1'b0;
        out_valid_reg <= 1'b0;
        rate_out_reg <= {OUT_W{1'b0}};
        bias_a_reg <= {BIAS_W{1'b0}};
        bias_b_reg <= {BIAS_W{1'b0}};
        estimated_reg <= 1'b0;
    end
end

assign out_valid = out_valid_reg;
assign rate_out = rate_out_reg;
assign bias_a = bias_a_reg;
assign bias_b = bias_b_reg;
assign estimated = estimated_reg;

`ifndef SYNTHESIS
// Simulation only (yosys defines SYNTHESIS): the system takes a sample at most every
// SCHEDULE_LEN + 3 clocks (gyrofx_job::pipeline::system), so that the chain's modes describe
// the next sample; a sooner ce stops the simulation, naming this instance.
gyrofx_spacing_check #(
    .MIN_CLOCKS_PER_SAMPLE(SCHEDULE_LEN + 3),
    .BLOCK_NAME("gyrofx_system_serial")
) spacing_check (
    .clk(clk),
    .rst(rst),
    .ce(ce)
);
`endif

endmodule

`resetall
