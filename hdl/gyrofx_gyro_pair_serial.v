// Language: Verilog 2001

`resetall
`timescale 1ns / 1ps
`default_nettype none

/*
 * gyrofx_gyro_pair_serial — gyro A's and gyro B's loops of gyrofx_gyro_loop on one folded
 * datapath: one multiplier, one accumulator and one RAM under one schedule, for the two-gyro
 * system on a small FPGA (gyrofx_system_serial).
 *
 * Purpose: each gyro's loop bit for bit (gyrofx_model::gyro_loop::FixedGyroLoop: the same DAC
 *   codes and lock flags every sample, the same decimated rate and quadrature), in about the
 *   logic of one folded loop (gyrofx_gyro_loop_serial). The schedule is
 *   gyrofx_model::gyro_loop::folded::Schedule::pair, proven clock by clock by FoldedPair.
 *
 * Datapath: gyrofx_gyro_loop_serial's, shared by the gyros. Each gyro has its own mode, NCO
 *   (accumulator, frequency word, truncation errors), Q_D, e_A and amplitude registers, DAC
 *   codes and their delay line, lock filter check and count, rate and quadrature, and its own
 *   RAM words; each unit of a control word (the sine ROM read, the NCO advance, the
 *   multiplier's issue, the accumulator, the RAM read's gate, the quantization point) works on
 *   the gyro its field of the word names (bits 57 to 62). The datapath's other registers are
 *   shared; the schedule keeps their values apart.
 *
 * Schedule: every sample runs both gyros' regular part (SCHEDULE_REGULAR words). The
 *   decimating sample (every CIC_DECIMATION-th) also copies each CIC's last integrator to a
 *   RAM word (writes marked decimating-only, bit 63); the combs, the compensators (partial
 *   sums in RAM) and the 1/SF products follow in SCHEDULE_SEGMENTS segments of
 *   SCHEDULE_LEN - SCHEDULE_REGULAR words, one in each of the next samples, after the regular
 *   part. The schedule ROM holds the regular part, then the segments.
 *
 * Pipeline: ce takes the sample (modes, switch clears); a word acts two clocks after it is
 *   fetched. The ADC codes are not captured: the schedule reads adc_* while the sample's
 *   regular part runs, so they must hold from ce until SCHEDULE_REGULAR + 2 clocks after it
 *   (as an ADC interface's data register does until its next conversion; the system's
 *   testbenches hold them until the next ce). Registers of their own would be 96 flip-flops
 *   that share no logic cell with a LUT: what kept the whole system from one UP5K. dac_*, locked_* load at the schedule's DAC and lock words; decimating
 *   pulses for one clock after the last word of a decimating sample, out_valid after the last
 *   word of the sample whose segment completes the four decimated outputs (SCHEDULE_SEGMENTS
 *   samples later), with rate_a, quadrature_a, rate_b, quadrature_b loaded (the 1/SF of the
 *   mode each gyro's decimating sample was taken in). The next ce may come SCHEDULE_LEN + 2
 *   clocks after ce (gyrofx_job::pipeline). A clock with rst high stops the schedule and
 *   clears every register a sample reads before it loads it; the RAM keeps its words, which
 *   the read gates ignore until they are written again.
 *
 * ROMs: NCO_ROM_FILE (quarter-wave sine), CIC_ROM_FILE (compensator taps), SCHEDULE_FILE
 *   (SCHEDULE_REGULAR + SCHEDULE_SEGMENTS * (SCHEDULE_LEN - SCHEDULE_REGULAR) control words of
 *   64 bits), $readmemh images.
 */
module gyrofx_gyro_pair_serial #(
    // NCOs: phase bits, quarter-wave ROM address bits, sine width, truncation error feedback
    parameter integer NCO_PHASE_W = 32,
    parameter integer NCO_ADDR_W = 10,
    parameter integer NCO_SIN_W = 18,
    parameter integer NCO_ERROR_FEEDBACK = 1,
    // demodulators (all): ADC, reference, product, state and output formats, low-pass shift
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
    // PLLs: error, gains, integrator and output formats (both gyros)
    parameter integer PLL_ERR_W = 32,
    parameter integer PLL_ERR_F = 30,
    parameter integer PLL_KP_W = 18,
    parameter integer PLL_KP_F = 27,
    parameter integer PLL_KI_W = 18,
    parameter integer PLL_KI_F = 38,
    parameter integer PLL_INT_W = 40,
    parameter integer PLL_INT_F = 38,
    parameter integer PLL_OUT_W = 32,
    parameter integer PLL_OUT_F = 32,
    // AGCs: error, gains, integrator and output formats (both gyros)
    parameter integer AGC_ERR_W = 32,
    parameter integer AGC_ERR_F = 30,
    parameter integer AGC_KP_W = 18,
    parameter integer AGC_KP_F = 1,
    parameter integer AGC_KI_W = 18,
    parameter integer AGC_KI_F = 11,
    parameter integer AGC_INT_W = 40,
    parameter integer AGC_INT_F = 20,
    parameter integer AGC_OUT_W = 24,
    parameter integer AGC_OUT_F = 6,
    // CICs (all): input, stages, decimation, delay, shift, scaled output, taps, output
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
    // DAC codes, rate/quadrature output (deg/s) and the 1/SF coefficients' format
    parameter integer DAC_W = 18,
    parameter integer DAC_F = 0,
    parameter integer OUT_W = 24,
    parameter integer OUT_F = 14,
    parameter integer COEF_W = 24,
    parameter integer COEF_F = 6,
    // ADC-to-DAC latency, samples (0..8)
    parameter integer LATENCY = 1,
    // lock detectors: filter shift and the samples both errors must stay inside
    parameter integer LOCK_SHIFT = 9,
    parameter integer LOCK_HOLD = 2000,
    // gyro A: PI gains and integrator limits; per mode (_N normal, _R reverse) the AGC
    // setpoint, nominal NCO word and PLL preset, DAC and sense reference offsets, 1/SF of the
    // rate and quadrature, lock limits (as gyrofx_gyro_loop's parameters of those names)
    parameter signed [PLL_KP_W-1:0] A_PLL_KP = 18'sd67109,
    parameter signed [PLL_KI_W-1:0] A_PLL_KI = 18'sd96149,
    parameter signed [PLL_INT_W-1:0] A_PLL_INT_MIN = 40'sd11052846203,
    parameter signed [PLL_INT_W-1:0] A_PLL_INT_MAX = 40'sd11400555661,
    parameter signed [AGC_KP_W-1:0] A_AGC_KP = 18'sd105114,
    parameter signed [AGC_KI_W-1:0] A_AGC_KI = 18'sd75300,
    parameter signed [AGC_INT_W-1:0] A_AGC_INT_MIN = 40'sd0,
    parameter signed [AGC_INT_W-1:0] A_AGC_INT_MAX = 40'sd137437904896,
    parameter signed [DEMOD_OUT_W-1:0] A_SETPOINT_N = 32'sd214746726,
    parameter signed [DEMOD_OUT_W-1:0] A_SETPOINT_R = 32'sd214746726,
    parameter [NCO_PHASE_W-1:0] A_FREQ_WORD_N = 32'd175986199,
    parameter [NCO_PHASE_W-1:0] A_FREQ_WORD_R = 32'd174848206,
    parameter signed [PLL_INT_W-1:0] A_PLL_PRESET_N = 40'sd11263116708,
    parameter signed [PLL_INT_W-1:0] A_PLL_PRESET_R = 40'sd11190285157,
    parameter [NCO_PHASE_W-1:0] A_DAC_OFFSET_N = 32'd265521847,
    parameter [NCO_PHASE_W-1:0] A_DAC_OFFSET_R = 32'd263941688,
    parameter [NCO_PHASE_W-1:0] A_SENSE_OFFSET_N = 32'd1331053422,
    parameter [NCO_PHASE_W-1:0] A_SENSE_OFFSET_R = 32'd2950095547,
    parameter signed [COEF_W-1:0] A_RATE_COEF_N = 24'sd6544256,
    parameter signed [COEF_W-1:0] A_RATE_COEF_R = -24'sd6641270,
    parameter signed [COEF_W-1:0] A_QUAD_COEF_N = -24'sd6544256,
    parameter signed [COEF_W-1:0] A_QUAD_COEF_R = -24'sd6641270,
    parameter signed [63:0] A_LOCK_Q_N = 64'sd191899419,
    parameter signed [63:0] A_LOCK_Q_R = 64'sd191899419,
    parameter signed [63:0] A_LOCK_A_N = 64'sd109950324,
    parameter signed [63:0] A_LOCK_A_R = 64'sd109950324,
    // gyro B: the same
    parameter signed [PLL_KP_W-1:0] B_PLL_KP = 18'sd67109,
    parameter signed [PLL_KI_W-1:0] B_PLL_KI = 18'sd96149,
    parameter signed [PLL_INT_W-1:0] B_PLL_INT_MIN = 40'sd11052846203,
    parameter signed [PLL_INT_W-1:0] B_PLL_INT_MAX = 40'sd11400555661,
    parameter signed [AGC_KP_W-1:0] B_AGC_KP = 18'sd105114,
    parameter signed [AGC_KI_W-1:0] B_AGC_KI = 18'sd75300,
    parameter signed [AGC_INT_W-1:0] B_AGC_INT_MIN = 40'sd0,
    parameter signed [AGC_INT_W-1:0] B_AGC_INT_MAX = 40'sd137437904896,
    parameter signed [DEMOD_OUT_W-1:0] B_SETPOINT_N = 32'sd214746726,
    parameter signed [DEMOD_OUT_W-1:0] B_SETPOINT_R = 32'sd214746726,
    parameter [NCO_PHASE_W-1:0] B_FREQ_WORD_N = 32'd175986199,
    parameter [NCO_PHASE_W-1:0] B_FREQ_WORD_R = 32'd174848206,
    parameter signed [PLL_INT_W-1:0] B_PLL_PRESET_N = 40'sd11263116708,
    parameter signed [PLL_INT_W-1:0] B_PLL_PRESET_R = 40'sd11190285157,
    parameter [NCO_PHASE_W-1:0] B_DAC_OFFSET_N = 32'd265521847,
    parameter [NCO_PHASE_W-1:0] B_DAC_OFFSET_R = 32'd263941688,
    parameter [NCO_PHASE_W-1:0] B_SENSE_OFFSET_N = 32'd1331053422,
    parameter [NCO_PHASE_W-1:0] B_SENSE_OFFSET_R = 32'd2950095547,
    parameter signed [COEF_W-1:0] B_RATE_COEF_N = 24'sd6544256,
    parameter signed [COEF_W-1:0] B_RATE_COEF_R = -24'sd6641270,
    parameter signed [COEF_W-1:0] B_QUAD_COEF_N = -24'sd6544256,
    parameter signed [COEF_W-1:0] B_QUAD_COEF_R = -24'sd6641270,
    parameter signed [63:0] B_LOCK_Q_N = 64'sd191899419,
    parameter signed [63:0] B_LOCK_Q_R = 64'sd191899419,
    parameter signed [63:0] B_LOCK_A_N = 64'sd109950324,
    parameter signed [63:0] B_LOCK_A_R = 64'sd109950324,
    // rounding: 0 floor, 1 ceil, 2 zero, 3 nearest, 4 round, 5 convergent
    parameter integer ROUNDING = 3,
    // overflow: 0 wrap, 1 saturate
    parameter integer SATURATE = 1,
    // ROM images for $readmemh
    parameter NCO_ROM_FILE = "gyro_loop_nco_sine.mem",
    parameter CIC_ROM_FILE = "gyro_loop_cic_taps.mem",
    // the schedule: image, words of the longest sample, of the regular part, deferred
    // segments, RAM words
    parameter SCHEDULE_FILE = "gyro_pair_schedule.mem",
    parameter integer SCHEDULE_LEN = 117,
    parameter integer SCHEDULE_REGULAR = 103,
    parameter integer SCHEDULE_SEGMENTS = 13,
    parameter integer RAM_WORDS = 64
) (
    input  wire                           clk,
    input  wire                           rst,
    input  wire                           ce,
    // gyro g's mode (1 normal: drive x, sense y; 0 reverse) and ADC codes
    input  wire                           mode_a,
    input  wire                           mode_b,
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
    // a decimating sample's last word has acted (one clock): the parallel loops' outputs
    // come in this sample
    output wire                           decimating,
    // both gyros' decimated outputs, valid with out_valid (one clock)
    output wire signed [OUT_W-1:0]        rate_a,
    output wire signed [OUT_W-1:0]        quadrature_a,
    output wire signed [OUT_W-1:0]        rate_b,
    output wire signed [OUT_W-1:0]        quadrature_b,
    output wire                           out_valid
);

function integer max2;
    input integer a;
    input integer b;
    begin
        max2 = a > b ? a : b;
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

// ceil(log2((rm)^stages)), exact (gyrofx_cic's register growth).
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

// Clocks a width-bit signed operand takes: 15-bit limbs, the top one up to 16 bits signed.
function integer limbs;
    input integer width;
    begin
        limbs = (width - 1 + 14) / 15;
        if (limbs < 1)
            limbs = 1;
    end
endfunction

// ---- the exact formats of the parallel loop's points (its blocks' localparams) -----------
// demodulator: 2 * adc * ref, the low-pass update
localparam integer X_W = DEMOD_ADC_W + DEMOD_REF_W;
localparam integer X_F = DEMOD_ADC_F + DEMOD_REF_F - 1;
localparam integer U_W = DEMOD_STATE_W + DEMOD_SHIFT + 1;
localparam integer U_F = DEMOD_STATE_F + DEMOD_SHIFT;
localparam integer DEMOD_ALIGN = DEMOD_STATE_F - DEMOD_PROD_F;
// AGC error: setpoint - I
localparam integer EA_W = DEMOD_OUT_W + 1;
// PI (gyrofx_pi): v + ki * e at UPD_F, kp * e + v at SUM_F
localparam integer PLL_INT_I = PLL_INT_W - PLL_INT_F;
localparam integer PLL_KIE_W = PLL_KI_W + PLL_ERR_W;
localparam integer PLL_KIE_F = PLL_KI_F + PLL_ERR_F;
localparam integer PLL_UPD_F = max2(PLL_INT_F, PLL_KIE_F);
localparam integer PLL_UPD_W = max2(PLL_INT_I, PLL_KIE_W - PLL_KIE_F) + 1 + PLL_UPD_F;
localparam integer PLL_RND_W = max2(PLL_INT_I, PLL_KIE_W - PLL_KIE_F) + 2 + PLL_INT_F;
localparam integer PLL_KPE_W = PLL_KP_W + PLL_ERR_W;
localparam integer PLL_KPE_F = PLL_KP_F + PLL_ERR_F;
localparam integer PLL_SUM_F = max2(PLL_INT_F, PLL_KPE_F);
localparam integer PLL_SUM_W = max2(PLL_INT_I, PLL_KPE_W - PLL_KPE_F) + 1 + PLL_SUM_F;
localparam integer AGC_INT_I = AGC_INT_W - AGC_INT_F;
localparam integer AGC_KIE_W = AGC_KI_W + AGC_ERR_W;
localparam integer AGC_KIE_F = AGC_KI_F + AGC_ERR_F;
localparam integer AGC_UPD_F = max2(AGC_INT_F, AGC_KIE_F);
localparam integer AGC_UPD_W = max2(AGC_INT_I, AGC_KIE_W - AGC_KIE_F) + 1 + AGC_UPD_F;
localparam integer AGC_RND_W = max2(AGC_INT_I, AGC_KIE_W - AGC_KIE_F) + 2 + AGC_INT_F;
localparam integer AGC_KPE_W = AGC_KP_W + AGC_ERR_W;
localparam integer AGC_KPE_F = AGC_KP_F + AGC_ERR_F;
localparam integer AGC_SUM_F = max2(AGC_INT_F, AGC_KPE_F);
localparam integer AGC_SUM_W = max2(AGC_INT_I, AGC_KPE_W - AGC_KPE_F) + 1 + AGC_SUM_F;
// DAC: amplitude * cos
localparam integer DRIVE_W = AGC_OUT_W + NCO_SIN_W;
localparam integer DRIVE_F = AGC_OUT_F + NCO_SIN_W - 1;
// CIC (gyrofx_cic): registers, the compensator's sum
localparam integer REG_W = CIC_IN_W + growth_bits(CIC_STAGES, CIC_DECIMATION * CIC_DELAY);
localparam integer FIR_W = CIC_MID_W + CIC_COEF_W + ceil_log2(CIC_TAPS);
localparam integer FIR_F = CIC_MID_F + CIC_COEF_F;
// rate and quadrature: 1/SF * CIC output
localparam integer RATE_W = CIC_OUT_W + COEF_W;
localparam integer RATE_F = CIC_OUT_F + COEF_F;
// lock filters
localparam integer Z_W = DEMOD_OUT_W + LOCK_SHIFT + 1;

// ---- the datapath's widths -----------------------------------------------------------------
// (Each one bit wider than its widest value, so that every value sign-extends into it.)
localparam integer ACC_W = max2(max2(max2(X_W, U_W), max2(EA_W, DRIVE_W)),
    max2(max2(max2(PLL_UPD_W, PLL_SUM_W), max2(AGC_UPD_W, AGC_SUM_W)),
    max2(max2(max2(REG_W, FIR_W), max2(RATE_W, Z_W)), 16 + 15 * limbs(max2(max2(max2(NCO_SIN_W,
    COEF_W), max2(CIC_COEF_W, PLL_KP_W)), max2(PLL_KI_W, max2(AGC_KP_W, AGC_KI_W)))) + 2))) + 1;
// The PI integrators as v_reg and the RAM hold them: one of them shifted left so that both
// PIs' output sums take v_reg at one alignment (one x source, not two).
localparam integer PLL_SUM_SHIFT = PLL_SUM_F - PLL_INT_F;
localparam integer AGC_SUM_SHIFT = AGC_SUM_F - AGC_INT_F;
localparam integer PLL_V_SHIFT = PLL_SUM_SHIFT > AGC_SUM_SHIFT ? PLL_SUM_SHIFT - AGC_SUM_SHIFT : 0;
localparam integer AGC_V_SHIFT = AGC_SUM_SHIFT > PLL_SUM_SHIFT ? AGC_SUM_SHIFT - PLL_SUM_SHIFT : 0;
localparam integer V_SUM_SHIFT = PLL_SUM_SHIFT - PLL_V_SHIFT;
localparam integer V_W = max2(PLL_INT_W + PLL_V_SHIFT, AGC_INT_W + AGC_V_SHIFT);
// The integrators' words read into their updates' fraction bits (a negative shift is right:
// the word's low bits are the shift's zeros).
localparam integer PLL_READ_SHIFT = PLL_UPD_F - PLL_INT_F - PLL_V_SHIFT;
localparam integer AGC_READ_SHIFT = AGC_UPD_F - AGC_INT_F - AGC_V_SHIFT;
// The RAM also holds the compensators' partial sums (FIR_W bits) between samples.
localparam integer RAM_W = max2(max2(max2(DEMOD_STATE_W, V_W), max2(AGC_INT_W, Z_W)),
    max2(max2(REG_W, CIC_MID_W), FIR_W)) + 1;
// a operands: ADC codes, the demodulator output (PLL error), the AGC error and output, the
// CIC output (and its delay line), the compensator output
localparam integer A_W = max2(max2(DEMOD_ADC_W, DEMOD_OUT_W), max2(max2(AGC_ERR_W, AGC_OUT_W),
    max2(CIC_MID_W, CIC_OUT_W)));
localparam integer A_LIMBS = limbs(A_W);
localparam integer A_EXT_W = 15 * A_LIMBS + 2;
// b operands: the references, the four PI gains, the taps, the 1/SF coefficients
localparam integer B_W = max2(max2(max2(NCO_SIN_W, COEF_W), max2(CIC_COEF_W, PLL_KP_W)),
    max2(PLL_KI_W, max2(AGC_KP_W, AGC_KI_W)));
localparam integer B_LIMBS = limbs(B_W);
localparam integer B_EXT_W = 15 * B_LIMBS + 2;
localparam integer PP_W = 16 + B_EXT_W;
// the PI products' extra alignments (0 unless a product has fewer fraction bits than its sum)
localparam integer PLL_KI_ALIGN = PLL_UPD_F - PLL_KIE_F;
localparam integer PLL_KP_ALIGN = PLL_SUM_F - PLL_KPE_F;
localparam integer AGC_KI_ALIGN = AGC_UPD_F - AGC_KIE_F;
localparam integer AGC_KP_ALIGN = AGC_SUM_F - AGC_KPE_F;
localparam integer T_W = NCO_ADDR_W + 2;
localparam integer R_W = (NCO_PHASE_W > T_W) ? NCO_PHASE_W - T_W : 1;
localparam integer DELAY_N = LATENCY > 0 ? LATENCY : 1;
localparam integer MOST_SEEN = CIC_TAPS - 1 > CIC_DELAY ? CIC_TAPS - 1 : CIC_DELAY;
localparam integer CNT_W = ceil_log2(CIC_DECIMATION);
// The lock count: 0 ..= LOCK_HOLD.
localparam integer COUNT_W = LOCK_HOLD > 0 ? ceil_log2(LOCK_HOLD + 1) : 1;
// The schedule ROM: the regular part, then the segments.
localparam integer SEGMENT_LEN = SCHEDULE_LEN - SCHEDULE_REGULAR;
localparam integer SCHEDULE_DEPTH = SCHEDULE_REGULAR + SCHEDULE_SEGMENTS * SEGMENT_LEN;
localparam integer PC_W = ceil_log2(SCHEDULE_DEPTH + 1);
localparam integer SEGMENT_W = ceil_log2(SCHEDULE_SEGMENTS + 1);
localparam integer RAM_ADDR_W = RAM_WORDS > 1 ? ceil_log2(RAM_WORDS) : 1;
localparam integer TAP_ADDR_W = CIC_TAPS > 1 ? ceil_log2(CIC_TAPS) : 1;

initial begin
    if (CIC_DELAY != 1) begin
        $display("%m: the folded loops' CICs have a differential delay of 1, not %0d", CIC_DELAY);
        $finish;
    end
    if (AGC_ERR_W != DEMOD_OUT_W || AGC_ERR_F != DEMOD_OUT_F || PLL_ERR_W != DEMOD_OUT_W) begin
        $display("%m: the PI errors' formats must be the demodulator output's");
        $finish;
    end
    if (CIC_TAPS > 15 || A_LIMBS > 8 || DEMOD_STATE_F < DEMOD_PROD_F) begin
        $display("%m: the schedule's fields hold CIC_TAPS <= 15 (%0d) and operands of <= 8 limbs (%0d); DEMOD_STATE_F (%0d) must be >= DEMOD_PROD_F (%0d)",
            CIC_TAPS, A_LIMBS, DEMOD_STATE_F, DEMOD_PROD_F);
        $finish;
    end
    if (RAM_WORDS > 128 || SCHEDULE_SEGMENTS < 1 || SEGMENT_LEN < 1
            || SCHEDULE_SEGMENTS >= CIC_DECIMATION) begin
        $display("%m: RAM_WORDS (%0d) must be <= 128, SCHEDULE_LEN (%0d) > SCHEDULE_REGULAR (%0d), 1 <= SCHEDULE_SEGMENTS (%0d) < CIC_DECIMATION (%0d)",
            RAM_WORDS, SCHEDULE_LEN, SCHEDULE_REGULAR, SCHEDULE_SEGMENTS, CIC_DECIMATION);
        $finish;
    end
end

// ---- control: the schedule ROM, the sample's flags ------------------------------------------
reg [63:0] schedule [0:SCHEDULE_DEPTH-1];
initial begin
    $readmemh(SCHEDULE_FILE, schedule);
end

reg busy_reg = 1'b0;
reg [PC_W-1:0] pc_reg = {PC_W{1'b0}};
// The word fetched (the schedule ROM's output register), then the word executing a clock
// later: the clock between decodes the accumulator's and the multiplier's operands from it.
reg [63:0] fetched_reg = 64'd0;
/* verilator lint_off UNUSEDSIGNAL */
reg [63:0] control_reg = 64'd0;
/* verilator lint_on UNUSEDSIGNAL */
reg executing_reg = 1'b0;
reg executing_last_reg = 1'b0;
reg start_reg = 1'b1;
reg first_reg = 1'b0;
reg decimate_reg = 1'b0;
reg [CNT_W-1:0] count_reg = {CNT_W{1'b0}};
reg [3:0] seen_reg = 4'd0;
// The deferred segments: whether one is due in the next sample, which, where its words start
// and end in the ROM; whether this sample runs it, and whether it is the last.
reg due_reg = 1'b0;
reg [SEGMENT_W-1:0] segment_reg = {SEGMENT_W{1'b0}};
reg [PC_W-1:0] base_reg = {PC_W{1'b0}};
reg [PC_W-1:0] segment_end_reg = {PC_W{1'b0}};
reg running_reg = 1'b0;
reg final_reg = 1'b0;

/* verilator lint_off UNUSEDSIGNAL */
wire [31:0] last_count = CIC_DECIMATION - 1;
wire [31:0] regular_word = SCHEDULE_REGULAR;
wire [31:0] segment_words = SEGMENT_LEN;
wire [31:0] last_segment_word = SCHEDULE_SEGMENTS - 1;
/* verilator lint_on UNUSEDSIGNAL */
wire [PC_W-1:0] regular_last = regular_word[PC_W-1:0] - 1'b1;
wire at_regular_last = pc_reg == regular_last;
wire last_word = busy_reg && (running_reg ? pc_reg == segment_end_reg : at_regular_last);
wire fetch = (ce && !rst) || (busy_reg && !last_word);
wire [PC_W-1:0] fetch_address = ce ? {PC_W{1'b0}} : (at_regular_last ? base_reg : pc_reg + 1'b1);

always @(posedge clk) begin
    if (fetch) begin
        fetched_reg <= schedule[fetch_address];
    end
    control_reg <= fetched_reg;
    executing_reg <= busy_reg && !rst;
    executing_last_reg <= last_word && !rst;
end

// Whether the executing word accumulates (decoded with its operands, below).
reg accumulate_reg = 1'b0;

// The control word's fields (gyrofx_model::gyro_loop::folded::Control): a fixed layout, whose
// widest fields a small loop does not use in full.
/* verilator lint_off UNUSEDSIGNAL */
wire [2:0] rom_field = control_reg[2:0];
wire advance_field = control_reg[3];
wire [3:0] a_field = control_reg[7:4];
wire [2:0] limb_field = control_reg[10:8];
wire top_field = control_reg[11];
wire [2:0] b_field = control_reg[14:12];
wire [3:0] tap_field = control_reg[18:15];
wire read_field = control_reg[27];
wire [6:0] read_address_field = control_reg[34:28];
wire [2:0] gate_field = control_reg[37:35];
wire [3:0] seen_field = control_reg[41:38];
wire write_field = control_reg[42];
wire [6:0] write_address_field = control_reg[49:43];
wire [2:0] data_field = control_reg[52:50];
wire [3:0] quantize_field = control_reg[56:53];
wire rom_gyro_field = control_reg[57];
wire advance_gyro_field = control_reg[58];
wire issue_gyro_field = control_reg[59];
wire read_gyro_field = control_reg[61];
wire quantize_gyro_field = control_reg[62];
wire decimating_write_field = control_reg[63];
/* verilator lint_on UNUSEDSIGNAL */

wire rom_en = executing_reg && rom_field != 3'd0;
wire accumulate_en = executing_reg && accumulate_reg;
wire read_en = executing_reg && read_field;
wire write_en = executing_reg && write_field && (!decimating_write_field || decimate_reg);
wire [3:0] point = executing_reg ? quantize_field : 4'd0;
// The point's gyro: gyro g's registers load at point_g.
wire [3:0] point_a = quantize_gyro_field ? 4'd0 : point;
wire [3:0] point_b = quantize_gyro_field ? point : 4'd0;

// ---- each gyro's sample registers ----------------------------------------------------------
reg mode_a_reg = 1'b1;
reg mode_b_reg = 1'b1;
reg switching_a_reg = 1'b0;
reg switching_b_reg = 1'b0;
// The mode of the last decimating sample (its 1/SF coefficients, applied samples later).
reg decimation_mode_a_reg = 1'b1;
reg decimation_mode_b_reg = 1'b1;
wire switching_a = mode_a != mode_a_reg || start_reg;
wire switching_b = mode_b != mode_b_reg || start_reg;

// ---- NCOs: per gyro one accumulator and three references' truncation errors; one sine ROM --
reg [NCO_PHASE_W-1:0] nco_acc_a_reg = {NCO_PHASE_W{1'b0}};
reg [NCO_PHASE_W-1:0] nco_acc_b_reg = {NCO_PHASE_W{1'b0}};
reg [NCO_PHASE_W-1:0] freq_a_reg = {NCO_PHASE_W{1'b0}};
reg [NCO_PHASE_W-1:0] freq_b_reg = {NCO_PHASE_W{1'b0}};
// The six truncation errors in a block RAM, word {gyro, reference} (reference 0 drive,
// 1 transmit, 2 sense): as registers they were 120 flip-flops that share no logic cell with a
// LUT. A word written since rst is valid (residue_valid_reg), else it reads as 0, as rst
// cleared the registers. A cosine writes its reference's word; the schedule never reads that
// word in the next clock (gyrofx_model::gyro_loop::folded's tests hold it), so the read needs
// no bypass.
(* no_rw_check *)
reg [R_W-1:0] residue_ram [0:7];
reg [R_W-1:0] residue_q;
reg [7:0] residue_valid_reg = 8'd0;
reg residue_read_valid_reg = 1'b0;
reg [2:0] residue_address_reg = 3'd0;
reg [NCO_SIN_W-1:0] nco_rom [0:(1 << NCO_ADDR_W)-1];
reg [NCO_SIN_W-1:0] ref_magnitude_reg = {NCO_SIN_W{1'b0}};
reg ref_negative_reg = 1'b0;
integer r;
initial begin
    $readmemh(NCO_ROM_FILE, nco_rom);
    for (r = 0; r < 8; r = r + 1) begin
        residue_ram[r] = {R_W{1'b0}};
    end
end

// The read's reference decoded from the fetched word a clock before it acts (rom field: 1 drive
// sin, 2 drive cos, 3 transmit cos, 4 sense sin, 5 sense cos), so that a clock runs the phase's
// adders and the ROM's address, not the field's decoding: the reference's offset (its gyro's
// and mode's), the word of its truncation error and whether it is a cosine.
wire [2:0] rom_field_next = fetched_reg[2:0];
wire rom_gyro_next = fetched_reg[57];
wire rom_mode_next = rom_gyro_next ? mode_b_reg : mode_a_reg;
wire [1:0] nco_index_next = rom_field_next == 3'd3 ? 2'd1 : (rom_field_next >= 3'd4 ? 2'd2 : 2'd0);
reg [NCO_PHASE_W-1:0] nco_offset_reg = {NCO_PHASE_W{1'b0}};
reg cosine_reg = 1'b0;
wire [2:0] residue_address_next = {rom_gyro_next, nco_index_next};
always @(posedge clk) begin
    nco_offset_reg <= nco_index_next == 2'd1
        ? (rom_gyro_next ? (rom_mode_next ? B_DAC_OFFSET_N : B_DAC_OFFSET_R)
                         : (rom_mode_next ? A_DAC_OFFSET_N : A_DAC_OFFSET_R))
        : nco_index_next == 2'd2
        ? (rom_gyro_next ? (rom_mode_next ? B_SENSE_OFFSET_N : B_SENSE_OFFSET_R)
                         : (rom_mode_next ? A_SENSE_OFFSET_N : A_SENSE_OFFSET_R))
        : {NCO_PHASE_W{1'b0}};
    residue_address_reg <= residue_address_next;
    residue_q <= residue_ram[residue_address_next];
    residue_read_valid_reg <= residue_valid_reg[residue_address_next];
    cosine_reg <= rom_field_next == 3'd2 || rom_field_next == 3'd3 || rom_field_next == 3'd5;
end
wire cosine = cosine_reg;
wire signed [R_W-1:0] residue = {R_W{residue_read_valid_reg}} & residue_q;
wire [NCO_PHASE_W-1:0] residue_extended = {{(NCO_PHASE_W - R_W){residue[R_W-1]}}, residue};
wire [NCO_PHASE_W-1:0] nco_acc = rom_gyro_field ? nco_acc_b_reg : nco_acc_a_reg;
wire [NCO_PHASE_W-1:0] phase_exact = nco_acc + nco_offset_reg;
wire [NCO_PHASE_W-1:0] phase = NCO_ERROR_FEEDBACK != 0 ? phase_exact + residue_extended
                                                       : phase_exact;
localparam [R_W-1:0] ONES = {R_W{1'b1}};
localparam [R_W-1:0] HALF_BIN = ONES ^ (ONES >> 1);
wire [T_W-1:0] t_sin = phase[NCO_PHASE_W-1:NCO_PHASE_W-T_W];
wire [T_W-1:0] t = cosine ? t_sin + {2'b01, {NCO_ADDR_W{1'b0}}} : t_sin;
wire [NCO_ADDR_W-1:0] rom_address = t[NCO_ADDR_W] ? ~t[NCO_ADDR_W-1:0] : t[NCO_ADDR_W-1:0];

always @(posedge clk) begin
    if (rom_en) begin
        ref_magnitude_reg <= nco_rom[rom_address];
    end
end

wire signed [NCO_SIN_W-1:0] reference = ref_negative_reg ? -$signed(ref_magnitude_reg)
                                                          : $signed(ref_magnitude_reg);

// ---- RAM of states ---------------------------------------------------------------------------
// The schedule never reads and writes one word in the same clock
// (gyrofx_model::gyro_loop::folded::Control::merge refuses it). The read register has no
// initial value, as a block RAM's has none: it loads before it is read.
(* no_rw_check *)
reg [RAM_W-1:0] ram [0:RAM_WORDS-1];
reg [RAM_W-1:0] ram_data_reg;
reg read_zero_reg = 1'b0;
reg read_preset_reg = 1'b0;
reg signed [RAM_W-1:0] previous_rd_reg = {RAM_W{1'b0}};
integer w;
initial begin
    for (w = 0; w < RAM_WORDS; w = w + 1) begin
        ram[w] = {RAM_W{1'b0}};
    end
end

wire signed [RAM_W-1:0] rd = $signed(ram_data_reg);
// gate_field: 1 switch, 2 preset, 3 first sample, 4 fewer than seen decimations; a switch of
// the read's gyro.
wire read_switching = read_gyro_field ? switching_b_reg : switching_a_reg;
wire read_zero = (gate_field == 3'd1 && read_switching) || (gate_field == 3'd3 && first_reg)
    || (gate_field == 3'd4 && seen_reg < seen_field);
wire read_preset = gate_field == 3'd2 && read_switching;
wire zero_next = read_en ? read_zero : read_zero_reg;
wire preset_next = read_en ? read_preset : read_preset_reg;

// The accumulator's x and y and the multiplier's a decoded from the fetched word into one-hot
// selects, a clock before the word executes (gyrofx_model::gyro_loop::folded::AccX, AccY,
// ASource codes), each with the gyro its field names: a clock runs an AND-OR of registered
// selects into the adder. A read gated to 0 selects nothing; the PLL's preset is an x source
// of its own; a negated y is selected inverted and the adder's carry in adds the 1.
wire [3:0] x_field = fetched_reg[22:19];
wire [3:0] y_field = fetched_reg[26:23];
wire accumulate_gyro_next = fetched_reg[60];
wire issue_gyro_next = fetched_reg[59];
wire accumulate_mode_next = accumulate_gyro_next ? mode_b_reg : mode_a_reg;
/* verilator lint_off UNUSEDSIGNAL */
reg [8:0] x_select_reg = 9'd0;
reg [11:0] y_select_reg = 12'd0;
// The y selects again, for the adder's high half: one register driving all ACC_W bits of the
// y operand's AND-OR was the UP5K's critical path (its fan-out routed ahead of the carry chain);
// keep stops yosys merging the copy back.
(* keep *) reg [11:0] y_select_high_reg = 12'd0;
/* verilator lint_on UNUSEDSIGNAL */
// A constant of two gyros and two modes: one select per (gyro, mode), A normal, A reverse,
// B normal, B reverse.
reg [3:0] setpoint_select_reg = 4'd0;
reg [3:0] preset_select_reg = 4'd0;
reg y_carry_reg = 1'b0;
wire [2:0] data_field_next = fetched_reg[52:50];
reg [6:0] write_select_reg = 7'd0;
wire [3:0] a_field_next = fetched_reg[7:4];
wire issue_mode_next = issue_gyro_next ? mode_b_reg : mode_a_reg;
reg [12:0] a_select_reg = 13'd0;
wire x_preset = x_field == 4'd5 && preset_next;
wire x_setpoint = x_field == 4'd4;
// One select per (gyro, mode) of the word's accumulate gyro.
function [3:0] gyro_mode;
    input selected;
    input gyro;
    input mode;
    begin
        gyro_mode = {selected && gyro && !mode, selected && gyro && mode,
            selected && !gyro && !mode, selected && !gyro && mode};
    end
endfunction
// The driven axis's ADC code (a code 1) or the sensed one's (2) of the issue's gyro: x when
// the mode drives x and a is 1, or senses it and a is 2.
wire a_adc = a_field_next == 4'd1 || a_field_next == 4'd2;
wire a_x = (a_field_next == 4'd1) == issue_mode_next;
wire [11:0] y_select_next = {y_field == 4'd9 && accumulate_gyro_next,
    y_field == 4'd8 && accumulate_gyro_next,
    y_field == 4'd9 && !accumulate_gyro_next, y_field == 4'd8 && !accumulate_gyro_next,
    y_field == 4'd7 && !zero_next,
    y_field == 4'd6, y_field == 4'd5, y_field == 4'd4, y_field == 4'd3,
    y_field == 4'd2 && !zero_next, y_field == 4'd1, 1'b0};
always @(posedge clk) begin
    x_select_reg <= {1'b0, x_field == 4'd7 && !zero_next, x_field == 4'd6 || x_field == 4'd8,
        x_field == 4'd5 && !zero_next && !preset_next, 1'b0, x_field == 4'd3 && !zero_next,
        x_field == 4'd2 && !zero_next, 1'b0, x_field == 4'd0};
    setpoint_select_reg <= gyro_mode(x_setpoint, accumulate_gyro_next, accumulate_mode_next);
    preset_select_reg <= gyro_mode(x_preset, accumulate_gyro_next, accumulate_mode_next);
    y_select_reg <= y_select_next;
    y_select_high_reg <= y_select_next;
    y_carry_reg <= ((y_field == 4'd2 || y_field == 4'd7) && !zero_next) || y_field == 4'd4;
    a_select_reg <= {
        a_field_next == 4'd5 && issue_gyro_next, a_field_next == 4'd4 && issue_gyro_next,
        a_field_next == 4'd3 && issue_gyro_next,
        a_adc && issue_gyro_next && !a_x, a_adc && issue_gyro_next && a_x,
        a_field_next == 4'd8, a_field_next == 4'd7 && !zero_next,
        a_field_next == 4'd6,
        a_field_next == 4'd5 && !issue_gyro_next, a_field_next == 4'd4 && !issue_gyro_next,
        a_field_next == 4'd3 && !issue_gyro_next,
        a_adc && !issue_gyro_next && !a_x, a_adc && !issue_gyro_next && a_x};
    write_select_reg <= {data_field_next == 3'd6, data_field_next == 3'd5,
        data_field_next == 3'd4 && !zero_next, data_field_next == 3'd3, data_field_next == 3'd2,
        data_field_next == 3'd1, data_field_next == 3'd0};
    accumulate_reg <= x_field != 4'd0 || y_field != 4'd0;
end

// ---- multiplier: a 15-bit limb of a times all of b -------------------------------------------
reg signed [DEMOD_OUT_W-1:0] drive_q_a_reg = {DEMOD_OUT_W{1'b0}};
reg signed [DEMOD_OUT_W-1:0] drive_q_b_reg = {DEMOD_OUT_W{1'b0}};
reg signed [AGC_ERR_W-1:0] amplitude_error_a_reg = {AGC_ERR_W{1'b0}};
reg signed [AGC_ERR_W-1:0] amplitude_error_b_reg = {AGC_ERR_W{1'b0}};
reg signed [AGC_OUT_W-1:0] amplitude_a_reg = {AGC_OUT_W{1'b0}};
reg signed [AGC_OUT_W-1:0] amplitude_b_reg = {AGC_OUT_W{1'b0}};
reg signed [CIC_MID_W-1:0] c_reg = {CIC_MID_W{1'b0}};
reg signed [CIC_OUT_W-1:0] cic_output_reg = {CIC_OUT_W{1'b0}};
reg [CIC_COEF_W-1:0] taps_rom [0:CIC_TAPS-1];
initial begin
    $readmemh(CIC_ROM_FILE, taps_rom);
end

// A signed value sign-extended to A_EXT_W bits, where its select is high (else 0).
`define GYROFX_A_OPERAND(select, value, width) ({A_EXT_W{select}} & {{(A_EXT_W-(width)){value[(width)-1]}}, value})
// Every a operand as an AND-OR of one-hot selects decoded a clock early (a_select_reg: per
// gyro the ADC codes of x and y, Q_D, e_A, the amplitude; c, the RAM word unless its read is
// gated to 0, the compensator's output). (The top bit, a guard bit, is never a limb's.)
/* verilator lint_off UNUSEDSIGNAL */
wire signed [A_EXT_W-1:0] a_value =
      `GYROFX_A_OPERAND(a_select_reg[0], adc_a_x, DEMOD_ADC_W)
    | `GYROFX_A_OPERAND(a_select_reg[1], adc_a_y, DEMOD_ADC_W)
    | `GYROFX_A_OPERAND(a_select_reg[2], drive_q_a_reg, DEMOD_OUT_W)
    | `GYROFX_A_OPERAND(a_select_reg[3], amplitude_error_a_reg, AGC_ERR_W)
    | `GYROFX_A_OPERAND(a_select_reg[4], amplitude_a_reg, AGC_OUT_W)
    | `GYROFX_A_OPERAND(a_select_reg[5], c_reg, CIC_MID_W)
    | ({A_EXT_W{a_select_reg[6]}} & {{(A_EXT_W-CIC_MID_W){rd[CIC_MID_W-1]}}, rd[CIC_MID_W-1:0]})
    | `GYROFX_A_OPERAND(a_select_reg[7], cic_output_reg, CIC_OUT_W)
    | `GYROFX_A_OPERAND(a_select_reg[8], adc_b_x, DEMOD_ADC_W)
    | `GYROFX_A_OPERAND(a_select_reg[9], adc_b_y, DEMOD_ADC_W)
    | `GYROFX_A_OPERAND(a_select_reg[10], drive_q_b_reg, DEMOD_OUT_W)
    | `GYROFX_A_OPERAND(a_select_reg[11], amplitude_error_b_reg, AGC_ERR_W)
    | `GYROFX_A_OPERAND(a_select_reg[12], amplitude_b_reg, AGC_OUT_W);
/* verilator lint_on UNUSEDSIGNAL */
`undef GYROFX_A_OPERAND
// Limb k of a: a chain of A_LIMBS choices (bits 15k .. 15k + 15), not a barrel shifter.
genvar n;
generate
    for (n = 0; n < A_LIMBS; n = n + 1) begin : g_limb
        wire [15:0] bits;
        if (n == 0) begin : g_first
            assign bits = a_value[15:0];
        end else begin : g_next
            assign bits = limb_field == n ? a_value[15 * n + 15:15 * n] : g_limb[n-1].bits;
        end
    end
endgenerate
/* verilator lint_off UNUSEDSIGNAL */
wire [15:0] a_limb_bits = g_limb[A_LIMBS-1].bits;
/* verilator lint_on UNUSEDSIGNAL */
wire signed [15:0] a_limb = top_field ? $signed(a_limb_bits) : $signed({1'b0, a_limb_bits[14:0]});

wire signed [CIC_COEF_W-1:0] tap = taps_rom[tap_field[TAP_ADDR_W-1:0]];
// The issue's gyro's gains, and its 1/SF of the mode its last decimating sample was taken in.
wire issue_decimation_mode = issue_gyro_field ? decimation_mode_b_reg : decimation_mode_a_reg;
wire signed [PLL_KI_W-1:0] pll_ki = issue_gyro_field ? B_PLL_KI : A_PLL_KI;
wire signed [PLL_KP_W-1:0] pll_kp = issue_gyro_field ? B_PLL_KP : A_PLL_KP;
wire signed [AGC_KI_W-1:0] agc_ki = issue_gyro_field ? B_AGC_KI : A_AGC_KI;
wire signed [AGC_KP_W-1:0] agc_kp = issue_gyro_field ? B_AGC_KP : A_AGC_KP;
wire signed [COEF_W-1:0] rate_coef = issue_gyro_field
    ? (issue_decimation_mode ? B_RATE_COEF_N : B_RATE_COEF_R)
    : (issue_decimation_mode ? A_RATE_COEF_N : A_RATE_COEF_R);
wire signed [COEF_W-1:0] quad_coef = issue_gyro_field
    ? (issue_decimation_mode ? B_QUAD_COEF_N : B_QUAD_COEF_R)
    : (issue_decimation_mode ? A_QUAD_COEF_N : A_QUAD_COEF_R);
/* verilator lint_off UNUSEDSIGNAL */
wire signed [B_EXT_W-1:0] b_value =
    b_field == 3'd0 ? {{(B_EXT_W-NCO_SIN_W){reference[NCO_SIN_W-1]}}, reference}
    : b_field == 3'd1 ? {{(B_EXT_W-PLL_KI_W){pll_ki[PLL_KI_W-1]}}, pll_ki}
    : b_field == 3'd2 ? {{(B_EXT_W-PLL_KP_W){pll_kp[PLL_KP_W-1]}}, pll_kp}
    : b_field == 3'd3 ? {{(B_EXT_W-AGC_KI_W){agc_ki[AGC_KI_W-1]}}, agc_ki}
    : b_field == 3'd4 ? {{(B_EXT_W-AGC_KP_W){agc_kp[AGC_KP_W-1]}}, agc_kp}
    : b_field == 3'd5 ? {{(B_EXT_W-CIC_COEF_W){tap[CIC_COEF_W-1]}}, tap}
    : b_field == 3'd6 ? {{(B_EXT_W-COEF_W){rate_coef[COEF_W-1]}}, rate_coef}
    : {{(B_EXT_W-COEF_W){quad_coef[COEF_W-1]}}, quad_coef};
/* verilator lint_on UNUSEDSIGNAL */
// The operand registers, and the product's weight with them: the limb and the PI alignment
// its b takes (b_field 1..4: PLL ki, PLL kp, AGC ki, AGC kp).
reg signed [15:0] a_limb_reg = 16'sd0;
reg signed [B_EXT_W-2:0] b_reg = {(B_EXT_W-1){1'b0}};
reg [2:0] limb_reg = 3'd0;
reg [2:0] align_reg = 3'd0;
reg [2:0] product_limb_reg = 3'd0;
reg [2:0] product_align_reg = 3'd0;
always @(posedge clk) begin
    a_limb_reg <= a_limb;
    b_reg <= b_value[B_EXT_W-2:0];
    limb_reg <= limb_field;
    align_reg <= (b_field >= 3'd1 && b_field <= 3'd4) ? b_field : 3'd0;
    product_limb_reg <= limb_reg;
    product_align_reg <= align_reg;
end

genvar j;
generate
    for (j = 0; j < B_LIMBS; j = j + 1) begin : g_multiplier
        // Limb j of b: 15 unsigned bits, the top one signed; each product one 16x16.
        wire signed [15:0] b_limb;
        if (j == B_LIMBS - 1) begin : g_top
            assign b_limb = b_reg[15 * j + 15:15 * j];
        end else begin : g_low
            assign b_limb = {1'b0, b_reg[15 * j + 14:15 * j]};
        end
        // No initial value: the DSP's output register has none; it loads 0 in the first clock.
        reg signed [31:0] product_reg;
        always @(posedge clk) begin
            product_reg <= a_limb_reg * b_limb;
        end
        wire signed [PP_W-1:0] product_wide = {{(PP_W-32){product_reg[31]}}, product_reg};
        // The products summed at their limbs' weights, one stage per limb.
        wire signed [PP_W-1:0] sum;
        if (j == 0) begin : g_first
            assign sum = product_wide;
        end else begin : g_next
            assign sum = g_multiplier[j-1].sum + (product_wide <<< (15 * j));
        end
    end
endgenerate

wire signed [PP_W-1:0] product_sum = g_multiplier[B_LIMBS-1].sum;
wire signed [ACC_W-1:0] product_acc = {{(ACC_W-PP_W){product_sum[PP_W-1]}}, product_sum};

// The product at its PI's alignment, then at its limb's weight (limb 0 unshifted).
wire signed [ACC_W-1:0] product_aligned =
    product_align_reg == 3'd1 ? product_acc <<< PLL_KI_ALIGN
    : product_align_reg == 3'd2 ? product_acc <<< PLL_KP_ALIGN
    : product_align_reg == 3'd3 ? product_acc <<< AGC_KI_ALIGN
    : product_align_reg == 3'd4 ? product_acc <<< AGC_KP_ALIGN
    : product_acc;
genvar k;
generate
    for (k = 0; k < A_LIMBS; k = k + 1) begin : g_weight
        wire signed [ACC_W-1:0] weighted;
        if (k == 0) begin : g_first
            assign weighted = product_aligned;
        end else begin : g_next
            assign weighted = product_limb_reg == k ? product_aligned <<< (15 * k)
                                                    : g_weight[k-1].weighted;
        end
    end
endgenerate

reg signed [ACC_W-1:0] pp_reg = {ACC_W{1'b0}};
always @(posedge clk) begin
    pp_reg <= g_weight[A_LIMBS-1].weighted;
end

// ---- accumulator: acc <= x + y -------------------------------------------------------------
reg signed [ACC_W-1:0] acc_reg = {ACC_W{1'b0}};
reg signed [DEMOD_PROD_W-1:0] p_reg = {DEMOD_PROD_W{1'b0}};
reg signed [DEMOD_STATE_W-1:0] y_reg = {DEMOD_STATE_W{1'b0}};
reg signed [V_W-1:0] v_reg = {V_W{1'b0}};
wire signed [DEMOD_OUT_W-1:0] demod_output;

wire signed [ACC_W-1:0] rd_acc = {{(ACC_W-RAM_W){rd[RAM_W-1]}}, rd};
// value << amount, or >> -amount (exact where used: the low bits shifted out are zeros).
function signed [ACC_W-1:0] shifted;
    input signed [ACC_W-1:0] value;
    input integer amount;
    begin
        if (amount >= 0) begin
            shifted = value <<< amount;
        end else begin
            shifted = value >>> (-amount);
        end
    end
endfunction
// A gyro's PLL preset, clamped to its limits, at the update's fraction bits.
function signed [ACC_W-1:0] preset_aligned;
    input signed [PLL_INT_W-1:0] preset;
    input signed [PLL_INT_W-1:0] low;
    input signed [PLL_INT_W-1:0] high;
    reg signed [PLL_INT_W-1:0] clamped;
    begin
        clamped = preset < low ? low : (preset > high ? high : preset);
        preset_aligned = {{(ACC_W-PLL_INT_W){clamped[PLL_INT_W-1]}}, clamped} <<< (PLL_UPD_F - PLL_INT_F);
    end
endfunction
function signed [ACC_W-1:0] setpoint_wide;
    input signed [DEMOD_OUT_W-1:0] setpoint;
    begin
        setpoint_wide = {{(ACC_W-DEMOD_OUT_W){setpoint[DEMOD_OUT_W-1]}}, setpoint};
    end
endfunction
// A constant of the four (gyro, mode) pairs under their one-hot selects (gyro_mode's order).
function [ACC_W-1:0] of_four;
    input [3:0] select;
    input [ACC_W-1:0] a_normal;
    input [ACC_W-1:0] a_reverse;
    input [ACC_W-1:0] b_normal;
    input [ACC_W-1:0] b_reverse;
    begin
        of_four = ({ACC_W{select[0]}} & a_normal) | ({ACC_W{select[1]}} & a_reverse)
            | ({ACC_W{select[2]}} & b_normal) | ({ACC_W{select[3]}} & b_reverse);
    end
endfunction
localparam signed [ACC_W-1:0] A_PRESET_N_ACC = preset_aligned(A_PLL_PRESET_N, A_PLL_INT_MIN, A_PLL_INT_MAX);
localparam signed [ACC_W-1:0] A_PRESET_R_ACC = preset_aligned(A_PLL_PRESET_R, A_PLL_INT_MIN, A_PLL_INT_MAX);
localparam signed [ACC_W-1:0] B_PRESET_N_ACC = preset_aligned(B_PLL_PRESET_N, B_PLL_INT_MIN, B_PLL_INT_MAX);
localparam signed [ACC_W-1:0] B_PRESET_R_ACC = preset_aligned(B_PLL_PRESET_R, B_PLL_INT_MIN, B_PLL_INT_MAX);
wire signed [ACC_W-1:0] previous_rd_acc = {{(ACC_W-RAM_W){previous_rd_reg[RAM_W-1]}}, previous_rd_reg};
wire signed [ACC_W-1:0] v_acc = {{(ACC_W-V_W){v_reg[V_W-1]}}, v_reg};
wire signed [ACC_W-1:0] p_acc = {{(ACC_W-DEMOD_PROD_W){p_reg[DEMOD_PROD_W-1]}}, p_reg};
// Q_O of the state register, registered: the value of the clock before.
reg signed [DEMOD_OUT_W-1:0] output_reg = {DEMOD_OUT_W{1'b0}};
always @(posedge clk) begin
    output_reg <= demod_output;
end
wire signed [ACC_W-1:0] output_acc = {{(ACC_W-DEMOD_OUT_W){output_reg[DEMOD_OUT_W-1]}}, output_reg};
wire signed [ACC_W-1:0] drive_q_a_acc = {{(ACC_W-DEMOD_OUT_W){drive_q_a_reg[DEMOD_OUT_W-1]}}, drive_q_a_reg};
wire signed [ACC_W-1:0] drive_q_b_acc = {{(ACC_W-DEMOD_OUT_W){drive_q_b_reg[DEMOD_OUT_W-1]}}, drive_q_b_reg};
wire signed [ACC_W-1:0] error_a_acc =
    {{(ACC_W-AGC_ERR_W){amplitude_error_a_reg[AGC_ERR_W-1]}}, amplitude_error_a_reg};
wire signed [ACC_W-1:0] error_b_acc =
    {{(ACC_W-AGC_ERR_W){amplitude_error_b_reg[AGC_ERR_W-1]}}, amplitude_error_b_reg};

// x and y as AND-ORs of the selects decoded a clock early (at most one select is high; none:
// x = 0, y = 0).
wire signed [ACC_W-1:0] x_value =
      ({ACC_W{x_select_reg[0]}} & acc_reg)
    | ({ACC_W{x_select_reg[2]}} & rd_acc)
    | ({ACC_W{x_select_reg[3]}} & (rd_acc <<< DEMOD_SHIFT))
    | of_four(setpoint_select_reg, setpoint_wide(A_SETPOINT_N), setpoint_wide(A_SETPOINT_R),
        setpoint_wide(B_SETPOINT_N), setpoint_wide(B_SETPOINT_R))
    | ({ACC_W{x_select_reg[5]}} & shifted(rd_acc, PLL_READ_SHIFT))
    | of_four(preset_select_reg, A_PRESET_N_ACC, A_PRESET_R_ACC, B_PRESET_N_ACC, B_PRESET_R_ACC)
    | ({ACC_W{x_select_reg[6]}} & (v_acc <<< V_SUM_SHIFT))
    | ({ACC_W{x_select_reg[7]}} & shifted(rd_acc, AGC_READ_SHIFT));

// y, a negated one inverted (x + ~y + 1: the carry in adds the 1).
// Each half of the adder takes its y from its own copy of the selects; each copy's other
// half is left unused.
/* verilator lint_off UNUSEDSIGNAL */
wire signed [ACC_W-1:0] y_value_low =
      ({ACC_W{y_select_reg[1]}} & pp_reg)
    | ({ACC_W{y_select_reg[2]}} & ~rd_acc)
    | ({ACC_W{y_select_reg[3]}} & (p_acc <<< DEMOD_ALIGN))
    | ({ACC_W{y_select_reg[4]}} & ~output_acc)
    | ({ACC_W{y_select_reg[5]}} & output_acc)
    | ({ACC_W{y_select_reg[6]}} & previous_rd_acc)
    | ({ACC_W{y_select_reg[7]}} & ~(rd_acc >>> LOCK_SHIFT))
    | ({ACC_W{y_select_reg[8]}} & drive_q_a_acc)
    | ({ACC_W{y_select_reg[9]}} & error_a_acc)
    | ({ACC_W{y_select_reg[10]}} & drive_q_b_acc)
    | ({ACC_W{y_select_reg[11]}} & error_b_acc);
wire signed [ACC_W-1:0] y_value_high =
      ({ACC_W{y_select_high_reg[1]}} & pp_reg)
    | ({ACC_W{y_select_high_reg[2]}} & ~rd_acc)
    | ({ACC_W{y_select_high_reg[3]}} & (p_acc <<< DEMOD_ALIGN))
    | ({ACC_W{y_select_high_reg[4]}} & ~output_acc)
    | ({ACC_W{y_select_high_reg[5]}} & output_acc)
    | ({ACC_W{y_select_high_reg[6]}} & previous_rd_acc)
    | ({ACC_W{y_select_high_reg[7]}} & ~(rd_acc >>> LOCK_SHIFT))
    | ({ACC_W{y_select_high_reg[8]}} & drive_q_a_acc)
    | ({ACC_W{y_select_high_reg[9]}} & error_a_acc)
    | ({ACC_W{y_select_high_reg[10]}} & drive_q_b_acc)
    | ({ACC_W{y_select_high_reg[11]}} & error_b_acc);
/* verilator lint_on UNUSEDSIGNAL */
wire signed [ACC_W-1:0] y_value = {y_value_high[ACC_W-1:ACC_W/2], y_value_low[ACC_W/2-1:0]};
wire signed [ACC_W-1:0] acc_next = x_value + y_value + {{(ACC_W-1){1'b0}}, y_carry_reg};

// ---- quantization points, at the parallel loop's formats -----------------------------------
wire signed [DEMOD_PROD_W-1:0] p_next;
wire signed [DEMOD_STATE_W-1:0] y_next;
wire signed [DEMOD_OUT_W-1:0] error_next;
// (The integrators' rounded updates: v takes their low INT_W bits, the clamp the rest.)
/* verilator lint_off UNUSEDSIGNAL */
wire signed [PLL_RND_W-1:0] pll_rounded;
/* verilator lint_on UNUSEDSIGNAL */
wire signed [PLL_OUT_W-1:0] pll_out;
/* verilator lint_off UNUSEDSIGNAL */
wire signed [AGC_RND_W-1:0] agc_rounded;
/* verilator lint_on UNUSEDSIGNAL */
wire signed [AGC_OUT_W-1:0] agc_out;
wire signed [DAC_W-1:0] drive;
wire signed [CIC_MID_W-1:0] c_next;
wire signed [CIC_OUT_W-1:0] cic_output_next;
wire signed [OUT_W-1:0] rate_next;

/* verilator lint_off PINCONNECTEMPTY */
gyrofx_quantize #(
    .IN_W(X_W), .IN_F(X_F), .OUT_W(DEMOD_PROD_W), .OUT_F(DEMOD_PROD_F),
    .ROUNDING(ROUNDING), .SATURATE(SATURATE)
) quantize_product (
    .in(acc_reg[X_W-1:0]), .out(p_next), .overflow()
);
gyrofx_quantize #(
    .IN_W(U_W), .IN_F(U_F), .OUT_W(DEMOD_STATE_W), .OUT_F(DEMOD_STATE_F),
    .ROUNDING(ROUNDING), .SATURATE(SATURATE)
) quantize_state (
    .in(acc_reg[U_W-1:0]), .out(y_next), .overflow()
);
gyrofx_quantize #(
    .IN_W(DEMOD_STATE_W), .IN_F(DEMOD_STATE_F), .OUT_W(DEMOD_OUT_W), .OUT_F(DEMOD_OUT_F),
    .ROUNDING(ROUNDING), .SATURATE(SATURATE)
) quantize_output (
    .in(y_reg), .out(demod_output), .overflow()
);
gyrofx_quantize #(
    .IN_W(EA_W), .IN_F(DEMOD_OUT_F), .OUT_W(DEMOD_OUT_W), .OUT_F(DEMOD_OUT_F),
    .ROUNDING(ROUNDING), .SATURATE(SATURATE)
) quantize_agc_error (
    .in(acc_reg[EA_W-1:0]), .out(error_next), .overflow()
);
gyrofx_quantize #(
    .IN_W(PLL_UPD_W), .IN_F(PLL_UPD_F), .OUT_W(PLL_RND_W), .OUT_F(PLL_INT_F),
    .ROUNDING(ROUNDING), .SATURATE(0)
) quantize_pll_integrator (
    .in(acc_reg[PLL_UPD_W-1:0]), .out(pll_rounded), .overflow()
);
gyrofx_quantize #(
    .IN_W(PLL_SUM_W), .IN_F(PLL_SUM_F), .OUT_W(PLL_OUT_W), .OUT_F(PLL_OUT_F),
    .ROUNDING(ROUNDING), .SATURATE(SATURATE)
) quantize_pll_output (
    .in(acc_reg[PLL_SUM_W-1:0]), .out(pll_out), .overflow()
);
gyrofx_quantize #(
    .IN_W(AGC_UPD_W), .IN_F(AGC_UPD_F), .OUT_W(AGC_RND_W), .OUT_F(AGC_INT_F),
    .ROUNDING(ROUNDING), .SATURATE(0)
) quantize_agc_integrator (
    .in(acc_reg[AGC_UPD_W-1:0]), .out(agc_rounded), .overflow()
);
gyrofx_quantize #(
    .IN_W(AGC_SUM_W), .IN_F(AGC_SUM_F), .OUT_W(AGC_OUT_W), .OUT_F(AGC_OUT_F),
    .ROUNDING(ROUNDING), .SATURATE(SATURATE)
) quantize_agc_output (
    .in(acc_reg[AGC_SUM_W-1:0]), .out(agc_out), .overflow()
);
gyrofx_quantize #(
    .IN_W(DRIVE_W), .IN_F(DRIVE_F), .OUT_W(DAC_W), .OUT_F(DAC_F),
    .ROUNDING(ROUNDING), .SATURATE(SATURATE)
) quantize_dac (
    .in(acc_reg[DRIVE_W-1:0]), .out(drive), .overflow()
);
gyrofx_quantize #(
    .IN_W(REG_W), .IN_F(CIC_IN_F + CIC_SHIFT), .OUT_W(CIC_MID_W), .OUT_F(CIC_MID_F),
    .ROUNDING(ROUNDING), .SATURATE(SATURATE)
) quantize_cic (
    .in(acc_reg[REG_W-1:0]), .out(c_next), .overflow()
);
gyrofx_quantize #(
    .IN_W(FIR_W), .IN_F(FIR_F), .OUT_W(CIC_OUT_W), .OUT_F(CIC_OUT_F),
    .ROUNDING(ROUNDING), .SATURATE(SATURATE)
) quantize_compensator (
    .in(acc_reg[FIR_W-1:0]), .out(cic_output_next), .overflow()
);
gyrofx_quantize #(
    .IN_W(RATE_W), .IN_F(RATE_F), .OUT_W(OUT_W), .OUT_F(OUT_F),
    .ROUNDING(ROUNDING), .SATURATE(SATURATE)
) quantize_rate (
    .in(acc_reg[RATE_W-1:0]), .out(rate_next), .overflow()
);
/* verilator lint_on PINCONNECTEMPTY */

// The PI integrators' clamps (gyrofx_gyro_loop_serial's): they compare the floor q of the
// update beside the rounding's carry; each gyro's limits side by side, the point's gyro's
// chosen after.
localparam integer PLL_DROP = PLL_UPD_F - PLL_INT_F;
localparam integer AGC_DROP = AGC_UPD_F - AGC_INT_F;
function signed [PLL_RND_W-1:0] pll_limit;
    input signed [PLL_INT_W-1:0] limit;
    begin
        pll_limit = {{(PLL_RND_W-PLL_INT_W){limit[PLL_INT_W-1]}}, limit};
    end
endfunction
function signed [AGC_RND_W-1:0] agc_limit;
    input signed [AGC_INT_W-1:0] limit;
    begin
        agc_limit = {{(AGC_RND_W-AGC_INT_W){limit[AGC_INT_W-1]}}, limit};
    end
endfunction
localparam signed [PLL_RND_W-1:0] A_PLL_LOW_LESS = pll_limit(A_PLL_INT_MIN) - 1;
localparam signed [PLL_RND_W-1:0] A_PLL_HIGH = pll_limit(A_PLL_INT_MAX);
localparam signed [PLL_RND_W-1:0] B_PLL_LOW_LESS = pll_limit(B_PLL_INT_MIN) - 1;
localparam signed [PLL_RND_W-1:0] B_PLL_HIGH = pll_limit(B_PLL_INT_MAX);
localparam signed [AGC_RND_W-1:0] A_AGC_LOW_LESS = agc_limit(A_AGC_INT_MIN) - 1;
localparam signed [AGC_RND_W-1:0] A_AGC_HIGH = agc_limit(A_AGC_INT_MAX);
localparam signed [AGC_RND_W-1:0] B_AGC_LOW_LESS = agc_limit(B_AGC_INT_MIN) - 1;
localparam signed [AGC_RND_W-1:0] B_AGC_HIGH = agc_limit(B_AGC_INT_MAX);
wire signed [PLL_RND_W-1:0] pll_floor = {acc_reg[PLL_UPD_W-1], acc_reg[PLL_UPD_W-1:PLL_DROP]};
wire pll_increment = pll_rounded[0] ^ pll_floor[0];
wire signed [AGC_RND_W-1:0] agc_floor = {acc_reg[AGC_UPD_W-1], acc_reg[AGC_UPD_W-1:AGC_DROP]};
wire agc_increment = agc_rounded[0] ^ agc_floor[0];
// Each comparison with a limit in two halves side by side, the upper signed and the lower
// unsigned (less: the upper less, or equal and the lower less), so that no carry chain runs
// the whole width: eight of them, and a gyro's choice after, would not meet 24 MHz otherwise.
localparam integer PLL_H = PLL_RND_W / 2;
localparam integer AGC_H = AGC_RND_W / 2;
`define GYROFX_LESS(value, limit, w, h) (($signed(value[w-1:h]) < $signed(limit[w-1:h])) || (value[w-1:h] == limit[w-1:h] && value[h-1:0] < limit[h-1:0]))
`define GYROFX_MORE(value, limit, w, h) (($signed(value[w-1:h]) > $signed(limit[w-1:h])) || (value[w-1:h] == limit[w-1:h] && value[h-1:0] > limit[h-1:0]))
wire pll_below_a = `GYROFX_LESS(pll_floor, A_PLL_LOW_LESS, PLL_RND_W, PLL_H)
    || (pll_floor == A_PLL_LOW_LESS && !pll_increment);
wire pll_above_a = `GYROFX_MORE(pll_floor, A_PLL_HIGH, PLL_RND_W, PLL_H)
    || (pll_floor == A_PLL_HIGH && pll_increment);
wire pll_below_b = `GYROFX_LESS(pll_floor, B_PLL_LOW_LESS, PLL_RND_W, PLL_H)
    || (pll_floor == B_PLL_LOW_LESS && !pll_increment);
wire pll_above_b = `GYROFX_MORE(pll_floor, B_PLL_HIGH, PLL_RND_W, PLL_H)
    || (pll_floor == B_PLL_HIGH && pll_increment);
wire agc_below_a = `GYROFX_LESS(agc_floor, A_AGC_LOW_LESS, AGC_RND_W, AGC_H)
    || (agc_floor == A_AGC_LOW_LESS && !agc_increment);
wire agc_above_a = `GYROFX_MORE(agc_floor, A_AGC_HIGH, AGC_RND_W, AGC_H)
    || (agc_floor == A_AGC_HIGH && agc_increment);
wire agc_below_b = `GYROFX_LESS(agc_floor, B_AGC_LOW_LESS, AGC_RND_W, AGC_H)
    || (agc_floor == B_AGC_LOW_LESS && !agc_increment);
wire agc_above_b = `GYROFX_MORE(agc_floor, B_AGC_HIGH, AGC_RND_W, AGC_H)
    || (agc_floor == B_AGC_HIGH && agc_increment);
`undef GYROFX_LESS
`undef GYROFX_MORE
// v_reg's next value at either PI's point: the point's rounded update and limits chosen first
// (the point and its gyro are known early), the comparisons last.
wire pll_point = quantize_field == 4'd5;
wire point_gyro = quantize_gyro_field;
function [V_W-1:0] pll_held;
    input signed [PLL_INT_W-1:0] value;
    begin
        pll_held = {{(V_W-PLL_INT_W){value[PLL_INT_W-1]}}, value} << PLL_V_SHIFT;
    end
endfunction
function [V_W-1:0] agc_held;
    input signed [AGC_INT_W-1:0] value;
    begin
        agc_held = {{(V_W-AGC_INT_W){value[AGC_INT_W-1]}}, value} << AGC_V_SHIFT;
    end
endfunction
wire [V_W-1:0] v_rounded = pll_point ? pll_held(pll_rounded[PLL_INT_W-1:0])
                                     : agc_held(agc_rounded[AGC_INT_W-1:0]);
wire [V_W-1:0] v_low = pll_point
    ? (point_gyro ? pll_held(B_PLL_INT_MIN) : pll_held(A_PLL_INT_MIN))
    : (point_gyro ? agc_held(B_AGC_INT_MIN) : agc_held(A_AGC_INT_MIN));
wire [V_W-1:0] v_high = pll_point
    ? (point_gyro ? pll_held(B_PLL_INT_MAX) : pll_held(A_PLL_INT_MAX))
    : (point_gyro ? agc_held(B_AGC_INT_MAX) : agc_held(A_AGC_INT_MAX));
wire v_below = pll_point ? (point_gyro ? pll_below_b : pll_below_a)
                         : (point_gyro ? agc_below_b : agc_below_a);
wire v_above = pll_point ? (point_gyro ? pll_above_b : pll_above_a)
                         : (point_gyro ? agc_above_b : agc_above_a);
wire [V_W-1:0] v_next = v_below ? v_low : (v_above ? v_high : v_rounded);

// The lock filters' check |z| < limit as -limit < z < limit (gyrofx_gyro_loop_serial's), the
// limit of the point's gyro and mode.
localparam integer CMP_W = Z_W + 2;
function signed [CMP_W-1:0] clipped;
    input signed [63:0] limit;
    reg signed [66:0] wide;
    reg signed [66:0] cap;
    begin
        wide = {{3{limit[63]}}, limit};
        cap = 67'sd1 <<< Z_W;
        wide = wide > cap ? cap : (wide < -cap ? -cap : wide);
        clipped = wide[CMP_W-1:0];
    end
endfunction
wire signed [Z_W-1:0] z = acc_reg[Z_W-1:0];
wire signed [CMP_W-1:0] z_cmp = {{2{z[Z_W-1]}}, z};
wire point_mode = point_gyro ? mode_b_reg : mode_a_reg;
wire phase_check = quantize_field == 4'd14;
wire signed [CMP_W-1:0] lock_limit = point_gyro
    ? (phase_check ? (point_mode ? clipped(B_LOCK_Q_N) : clipped(B_LOCK_Q_R))
                   : (point_mode ? clipped(B_LOCK_A_N) : clipped(B_LOCK_A_R)))
    : (phase_check ? (point_mode ? clipped(A_LOCK_Q_N) : clipped(A_LOCK_Q_R))
                   : (point_mode ? clipped(A_LOCK_A_N) : clipped(A_LOCK_A_R)));
wire signed [CMP_W-1:0] lock_floor = point_gyro
    ? (phase_check ? (point_mode ? -clipped(B_LOCK_Q_N) : -clipped(B_LOCK_Q_R))
                   : (point_mode ? -clipped(B_LOCK_A_N) : -clipped(B_LOCK_A_R)))
    : (phase_check ? (point_mode ? -clipped(A_LOCK_Q_N) : -clipped(A_LOCK_Q_R))
                   : (point_mode ? -clipped(A_LOCK_A_N) : -clipped(A_LOCK_A_R)));
wire within_limit = z_cmp < lock_limit && z_cmp > lock_floor;

// ---- RAM writes ---------------------------------------------------------------------------
// What a write stores, as an AND-OR of one-hot selects decoded a clock early (data_field:
// 0 the accumulator at the CIC registers' width, 1 at the lock filters', 2 y, 3 v, 4 the read
// register, 5 c, 6 the accumulator at the compensator sum's width).
localparam integer NARROW_W = max2(max2(Z_W, DEMOD_STATE_W), max2(V_W, CIC_MID_W));
wire [NARROW_W-1:0] write_narrow =
      ({NARROW_W{write_select_reg[1]}} & {{(NARROW_W-Z_W){z[Z_W-1]}}, z})
    | ({NARROW_W{write_select_reg[2]}} & {{(NARROW_W-DEMOD_STATE_W){y_reg[DEMOD_STATE_W-1]}}, y_reg})
    | ({NARROW_W{write_select_reg[3]}} & {{(NARROW_W-V_W){v_reg[V_W-1]}}, v_reg})
    | ({NARROW_W{write_select_reg[5]}} & {{(NARROW_W-CIC_MID_W){c_reg[CIC_MID_W-1]}}, c_reg});
wire [RAM_W-1:0] write_data =
      {{(RAM_W-NARROW_W){write_narrow[NARROW_W-1]}}, write_narrow}
    | ({RAM_W{write_select_reg[4]}} & rd)
    | ({RAM_W{write_select_reg[0]}} & {{(RAM_W-REG_W){acc_reg[REG_W-1]}}, acc_reg[REG_W-1:0]})
    | ({RAM_W{write_select_reg[6]}} & {{(RAM_W-FIR_W){acc_reg[FIR_W-1]}}, acc_reg[FIR_W-1:0]});

// The read register of the clock before, 0 when its read was gated (a synchronous clear).
always @(posedge clk) begin
    if (read_zero_reg) begin
        previous_rd_reg <= {RAM_W{1'b0}};
    end else begin
        previous_rd_reg <= rd;
    end
end

always @(posedge clk) begin
    if (write_en) begin
        ram[write_address_field[RAM_ADDR_W-1:0]] <= write_data;
    end
    if (read_en) begin
        ram_data_reg <= ram[read_address_field[RAM_ADDR_W-1:0]];
    end
end

// ---- each gyro's DAC, lock count and frequency word ------------------------------------------
/* verilator lint_off UNUSEDSIGNAL */
wire [31:0] lock_hold_word = LOCK_HOLD;
/* verilator lint_on UNUSEDSIGNAL */
wire [COUNT_W-1:0] lock_hold = lock_hold_word[COUNT_W-1:0];
reg signed [DAC_W-1:0] delay_a_reg [0:DELAY_N-1];
reg signed [DAC_W-1:0] delay_b_reg [0:DELAY_N-1];
wire signed [DAC_W-1:0] dac_a_now = LATENCY == 0 ? drive : delay_a_reg[DELAY_N-1];
wire signed [DAC_W-1:0] dac_b_now = LATENCY == 0 ? drive : delay_b_reg[DELAY_N-1];
reg signed [DAC_W-1:0] dac_a_x_reg = {DAC_W{1'b0}};
reg signed [DAC_W-1:0] dac_a_y_reg = {DAC_W{1'b0}};
reg signed [DAC_W-1:0] dac_b_x_reg = {DAC_W{1'b0}};
reg signed [DAC_W-1:0] dac_b_y_reg = {DAC_W{1'b0}};
reg signed [OUT_W-1:0] rate_a_reg = {OUT_W{1'b0}};
reg signed [OUT_W-1:0] quad_a_reg = {OUT_W{1'b0}};
reg signed [OUT_W-1:0] rate_b_reg = {OUT_W{1'b0}};
reg signed [OUT_W-1:0] quad_b_reg = {OUT_W{1'b0}};
reg out_valid_reg = 1'b0;
reg decimating_reg = 1'b0;
// Each gyro's phase check, then both checks registered at the second point: the count and
// locked load on the clock after it.
reg inside_q_a_reg = 1'b0;
reg inside_q_b_reg = 1'b0;
reg inside_a_reg = 1'b0;
reg inside_b_reg = 1'b0;
reg count_pending_a_reg = 1'b0;
reg count_pending_b_reg = 1'b0;
reg [COUNT_W-1:0] lock_count_a_reg = {COUNT_W{1'b0}};
reg [COUNT_W-1:0] lock_count_b_reg = {COUNT_W{1'b0}};
reg locked_a_reg = 1'b0;
reg locked_b_reg = 1'b0;
wire [COUNT_W-1:0] lock_count_a_next = inside_a_reg
    ? (lock_count_a_reg >= lock_hold ? lock_hold : lock_count_a_reg + 1'b1) : {COUNT_W{1'b0}};
wire [COUNT_W-1:0] lock_count_b_next = inside_b_reg
    ? (lock_count_b_reg >= lock_hold ? lock_hold : lock_count_b_reg + 1'b1) : {COUNT_W{1'b0}};

integer i;
integer d;
initial begin
    for (i = 0; i < DELAY_N; i = i + 1) begin
        delay_a_reg[i] = {DAC_W{1'b0}};
        delay_b_reg[i] = {DAC_W{1'b0}};
    end
end

// The DAC point loads its gyro's driven axis's code and clears the other's (clears:
// synchronous resets, not multiplexers).
always @(posedge clk) begin
    if (rst || (point_a == 4'd9 && !mode_a_reg)) begin
        dac_a_x_reg <= {DAC_W{1'b0}};
    end else if (point_a == 4'd9) begin
        dac_a_x_reg <= dac_a_now;
    end
    if (rst || (point_a == 4'd9 && mode_a_reg)) begin
        dac_a_y_reg <= {DAC_W{1'b0}};
    end else if (point_a == 4'd9) begin
        dac_a_y_reg <= dac_a_now;
    end
    if (rst || (point_b == 4'd9 && !mode_b_reg)) begin
        dac_b_x_reg <= {DAC_W{1'b0}};
    end else if (point_b == 4'd9) begin
        dac_b_x_reg <= dac_b_now;
    end
    if (rst || (point_b == 4'd9 && mode_b_reg)) begin
        dac_b_y_reg <= {DAC_W{1'b0}};
    end else if (point_b == 4'd9) begin
        dac_b_y_reg <= dac_b_now;
    end
end

// Each gyro's DAC delay line shifts at its DAC point and clears in a sample that switches its
// mode; its lock count counts on the clock after its lock check and clears when the check
// fails or its mode switches (clears: synchronous resets).
always @(posedge clk) begin
    if (rst || (ce && switching_a && point_a != 4'd9)) begin
        for (d = 0; d < DELAY_N; d = d + 1) begin
            delay_a_reg[d] <= {DAC_W{1'b0}};
        end
    end else if (point_a == 4'd9) begin
        delay_a_reg[0] <= drive;
        for (d = 1; d < DELAY_N; d = d + 1) begin
            delay_a_reg[d] <= delay_a_reg[d-1];
        end
    end
    if (rst || (ce && switching_b && point_b != 4'd9)) begin
        for (d = 0; d < DELAY_N; d = d + 1) begin
            delay_b_reg[d] <= {DAC_W{1'b0}};
        end
    end else if (point_b == 4'd9) begin
        delay_b_reg[0] <= drive;
        for (d = 1; d < DELAY_N; d = d + 1) begin
            delay_b_reg[d] <= delay_b_reg[d-1];
        end
    end
    if (rst || (count_pending_a_reg && !inside_a_reg) || (ce && switching_a && !count_pending_a_reg)) begin
        lock_count_a_reg <= {COUNT_W{1'b0}};
    end else if (count_pending_a_reg) begin
        lock_count_a_reg <= lock_count_a_next;
    end
    if (rst || (count_pending_b_reg && !inside_b_reg) || (ce && switching_b && !count_pending_b_reg)) begin
        lock_count_b_reg <= {COUNT_W{1'b0}};
    end else if (count_pending_b_reg) begin
        lock_count_b_reg <= lock_count_b_next;
    end
end

// Each gyro's NCO frequency word: its PLL's output, or in the first sample of a mode (from
// ce) its nominal word, bit by bit (a bit both modes' words share is a synchronous set or
// reset, not a multiplexer).
genvar f;
generate
    for (f = 0; f < NCO_PHASE_W; f = f + 1) begin : g_freq
        always @(posedge clk) begin
            if (rst) begin
                freq_a_reg[f] <= 1'b0;
            end else if (point_a == 4'd6) begin
                freq_a_reg[f] <= pll_out[f];
            end else if (ce && switching_a) begin
                freq_a_reg[f] <= mode_a ? A_FREQ_WORD_N[f] : A_FREQ_WORD_R[f];
            end
            if (rst) begin
                freq_b_reg[f] <= 1'b0;
            end else if (point_b == 4'd6) begin
                freq_b_reg[f] <= pll_out[f];
            end else if (ce && switching_b) begin
                freq_b_reg[f] <= mode_b ? B_FREQ_WORD_N[f] : B_FREQ_WORD_R[f];
            end
        end
    end
endgenerate

// ---- the sample: control, the registers the points load ------------------------------------
wire decimates = count_reg == last_count[CNT_W-1:0];
wire sample_end = executing_reg && executing_last_reg;
always @(posedge clk) begin
    out_valid_reg <= 1'b0;
    decimating_reg <= 1'b0;

    if (ce) begin
        busy_reg <= 1'b1;
        pc_reg <= {PC_W{1'b0}};
        mode_a_reg <= mode_a;
        mode_b_reg <= mode_b;
        start_reg <= 1'b0;
        switching_a_reg <= switching_a;
        switching_b_reg <= switching_b;
        first_reg <= start_reg;
        decimate_reg <= decimates;
        count_reg <= decimates ? {CNT_W{1'b0}} : count_reg + 1'b1;
        if (decimates) begin
            decimation_mode_a_reg <= mode_a;
            decimation_mode_b_reg <= mode_b;
        end
        running_reg <= due_reg;
        final_reg <= segment_reg == last_segment_word[SEGMENT_W-1:0];
    end else if (busy_reg) begin
        if (last_word) begin
            busy_reg <= 1'b0;
        end else begin
            pc_reg <= fetch_address;
        end
    end
    // A sample's end: a decimating one makes the first segment due; one that ran a segment
    // the next, or, after the last, the outputs valid.
    if (sample_end) begin
        if (decimate_reg) begin
            decimating_reg <= 1'b1;
            due_reg <= 1'b1;
            segment_reg <= {SEGMENT_W{1'b0}};
            base_reg <= regular_word[PC_W-1:0];
            segment_end_reg <= regular_word[PC_W-1:0] + segment_words[PC_W-1:0] - 1'b1;
        end else if (running_reg) begin
            if (final_reg) begin
                due_reg <= 1'b0;
                out_valid_reg <= 1'b1;
                if (seen_reg < MOST_SEEN[3:0]) begin
                    seen_reg <= seen_reg + 4'd1;
                end
            end else begin
                segment_reg <= segment_reg + 1'b1;
                base_reg <= base_reg + segment_words[PC_W-1:0];
                segment_end_reg <= segment_end_reg + segment_words[PC_W-1:0];
            end
        end
    end

    if (rom_en) begin
        ref_negative_reg <= t[T_W-1];
        if (cosine && NCO_ERROR_FEEDBACK != 0) begin
            residue_ram[residue_address_reg] <= phase[R_W-1:0] ^ HALF_BIN;
            residue_valid_reg[residue_address_reg] <= 1'b1;
        end
    end
    if (executing_reg && advance_field) begin
        if (advance_gyro_field) begin
            nco_acc_b_reg <= nco_acc_b_reg + freq_b_reg;
        end else begin
            nco_acc_a_reg <= nco_acc_a_reg + freq_a_reg;
        end
    end
    if (read_en) begin
        read_zero_reg <= read_zero;
        read_preset_reg <= read_preset;
    end
    if (accumulate_en) begin
        acc_reg <= acc_next;
    end

    // The shared registers' points.
    case (point)
        4'd1: p_reg <= p_next;
        4'd2: y_reg <= y_next;
        4'd5: v_reg <= v_next;
        4'd7: v_reg <= v_next;
        4'd10: c_reg <= c_next;
        4'd11: cic_output_reg <= cic_output_next;
        default: begin
        end
    endcase
    // Each gyro's.
    case (point_a)
        4'd3: drive_q_a_reg <= output_reg;
        4'd4: amplitude_error_a_reg <= error_next;
        4'd8: amplitude_a_reg <= agc_out;
        4'd12: rate_a_reg <= rate_next;
        4'd13: quad_a_reg <= rate_next;
        4'd14: inside_q_a_reg <= within_limit;
        4'd15: inside_a_reg <= inside_q_a_reg && within_limit;
        default: begin
        end
    endcase
    case (point_b)
        4'd3: drive_q_b_reg <= output_reg;
        4'd4: amplitude_error_b_reg <= error_next;
        4'd8: amplitude_b_reg <= agc_out;
        4'd12: rate_b_reg <= rate_next;
        4'd13: quad_b_reg <= rate_next;
        4'd14: inside_q_b_reg <= within_limit;
        4'd15: inside_b_reg <= inside_q_b_reg && within_limit;
        default: begin
        end
    endcase
    count_pending_a_reg <= point_a == 4'd15;
    count_pending_b_reg <= point_b == 4'd15;
    if (count_pending_a_reg) begin
        locked_a_reg <= lock_count_a_next >= lock_hold;
    end
    if (count_pending_b_reg) begin
        locked_b_reg <= lock_count_b_next >= lock_hold;
    end

    if (rst) begin
        busy_reg <= 1'b0;
        pc_reg <= {PC_W{1'b0}};
        mode_a_reg <= 1'b1;
        mode_b_reg <= 1'b1;
        start_reg <= 1'b1;
        switching_a_reg <= 1'b0;
        switching_b_reg <= 1'b0;
        first_reg <= 1'b0;
        decimate_reg <= 1'b0;
        count_reg <= {CNT_W{1'b0}};
        seen_reg <= 4'd0;
        due_reg <= 1'b0;
        segment_reg <= {SEGMENT_W{1'b0}};
        running_reg <= 1'b0;
        final_reg <= 1'b0;
        decimation_mode_a_reg <= 1'b1;
        decimation_mode_b_reg <= 1'b1;
        nco_acc_a_reg <= {NCO_PHASE_W{1'b0}};
        nco_acc_b_reg <= {NCO_PHASE_W{1'b0}};
        residue_valid_reg <= 8'd0;
        read_zero_reg <= 1'b0;
        read_preset_reg <= 1'b0;
        acc_reg <= {ACC_W{1'b0}};
        p_reg <= {DEMOD_PROD_W{1'b0}};
        y_reg <= {DEMOD_STATE_W{1'b0}};
        v_reg <= {V_W{1'b0}};
        drive_q_a_reg <= {DEMOD_OUT_W{1'b0}};
        drive_q_b_reg <= {DEMOD_OUT_W{1'b0}};
        amplitude_error_a_reg <= {AGC_ERR_W{1'b0}};
        amplitude_error_b_reg <= {AGC_ERR_W{1'b0}};
        amplitude_a_reg <= {AGC_OUT_W{1'b0}};
        amplitude_b_reg <= {AGC_OUT_W{1'b0}};
        c_reg <= {CIC_MID_W{1'b0}};
        cic_output_reg <= {CIC_OUT_W{1'b0}};
        rate_a_reg <= {OUT_W{1'b0}};
        quad_a_reg <= {OUT_W{1'b0}};
        rate_b_reg <= {OUT_W{1'b0}};
        quad_b_reg <= {OUT_W{1'b0}};
        out_valid_reg <= 1'b0;
        decimating_reg <= 1'b0;
        inside_q_a_reg <= 1'b0;
        inside_q_b_reg <= 1'b0;
        inside_a_reg <= 1'b0;
        inside_b_reg <= 1'b0;
        count_pending_a_reg <= 1'b0;
        count_pending_b_reg <= 1'b0;
        locked_a_reg <= 1'b0;
        locked_b_reg <= 1'b0;
    end
end

assign dac_a_x = dac_a_x_reg;
assign dac_a_y = dac_a_y_reg;
assign dac_b_x = dac_b_x_reg;
assign dac_b_y = dac_b_y_reg;
assign locked_a = locked_a_reg;
assign locked_b = locked_b_reg;
assign decimating = decimating_reg;
assign rate_a = rate_a_reg;
assign quadrature_a = quad_a_reg;
assign rate_b = rate_b_reg;
assign quadrature_b = quad_b_reg;
assign out_valid = out_valid_reg;

`ifndef SYNTHESIS
// Simulation only (yosys defines SYNTHESIS): a sample takes the schedule's clocks
// (gyrofx_job::pipeline); a sooner ce stops the simulation, naming this instance.
gyrofx_spacing_check #(
    .MIN_CLOCKS_PER_SAMPLE(SCHEDULE_LEN + 2),
    .BLOCK_NAME("gyrofx_gyro_pair_serial")
) spacing_check (
    .clk(clk),
    .rst(rst),
    .ce(ce)
);
`endif

endmodule

`resetall
