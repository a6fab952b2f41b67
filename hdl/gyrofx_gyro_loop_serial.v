// Language: Verilog 2001

`resetall
`timescale 1ns / 1ps
`default_nettype none

/*
 * gyrofx_gyro_loop_serial — the gyro loop of gyrofx_gyro_loop, folded: its arithmetic runs
 * one operation at a time on one multiplier, one accumulator and one RAM, under a schedule.
 *
 * Purpose: the same loop, bit for bit (same ports, same parameters, same vectors), in a
 *   fraction of the parallel design's multipliers and logic, for a small FPGA
 *   (architecture = "serial"). Bit-exact with gyrofx_model::gyro_loop::FixedGyroLoop; the
 *   schedule is gyrofx_model::gyro_loop::folded::Schedule, proven there clock by clock
 *   (FoldedGyroLoop) and documented in docs/blocks/gyro_loop.md.
 *
 * Datapath (per clock, as the schedule's control word says; fields in
 *   gyrofx_model::gyro_loop::folded::Control):
 *     sine ROM read:  ref <= +/-ROM[address of acc_nco + offset + residue], a cosine read
 *                     also stores that reference's truncation error (error feedback)
 *     multiplier:     a_limb <= limb_k(a), b <= b           (operand registers; the issue)
 *                     prod_j <= a_limb * b_limb_j         (j < B_LIMBS, signed 16x16 each)
 *                     pp <= (sum_j prod_j << 15j) << (15k + the PI's alignment)
 *                     (a 15-bit limb of a times all of b, at its weight, three clocks
 *                     after its issue; the weight travels with it)
 *     accumulator:    acc <= x + y                        (x: acc, 0, RAM word, setpoint, PI
 *                     integrator aligned; y: pp, -RAM word, p, -I, I, ...)
 *     RAM:            rd <= ram[read address] (0 when its gate says; the PLL integrator
 *                     operand the PLL preset instead, when its gate says);
 *                     ram[write address] <= acc, a quantized acc, rd or c
 *     quantization:   one point a clock loads its register from acc (gyrofx_quantize at
 *                     the formats of the parallel loop's point); the demodulator's output
 *                     point reads the state register y every clock into its own register
 *     (Every multiplexer into the multiplier, the multiplier and every quantizer end in a
 *     register before the accumulator's adder: the schedule, not the logic, takes the
 *     clocks.)
 *   Every sample runs the schedule's first SCHEDULE_REGULAR words; a decimating one (every
 *   CIC_DECIMATION-th) all SCHEDULE_LEN.
 *
 * Pipeline: ce takes the sample (inputs, mode, switch clears); the schedule's word t acts
 *   t + 2 clocks after ce (fetched, then its accumulator operands decoded). dac_x, dac_y
 *   and locked load at the schedule's DAC and lock words; rate, quadrature and out_valid
 *   (one clock) at its end. The next ce may come SCHEDULE_LEN + 2 clocks after ce
 *   (gyrofx_job::pipeline). A clock with rst high stops the schedule and clears every register a sample reads before it loads it (the pipeline's
 *   operand, product and read registers load again before they are read); the RAM keeps its
 *   words, which the next samples' read gates ignore until they are written again.
 *
 * ROMs: NCO_ROM_FILE (quarter-wave sine), CIC_ROM_FILE (compensator taps), SCHEDULE_FILE
 *   (SCHEDULE_LEN control words of 64 bits), $readmemh images.
 */
module gyrofx_gyro_loop_serial #(
    // NCOs: phase bits, quarter-wave ROM address bits, sine width, truncation error feedback
    parameter integer NCO_PHASE_W = 32,
    parameter integer NCO_ADDR_W = 10,
    parameter integer NCO_SIN_W = 18,
    parameter integer NCO_ERROR_FEEDBACK = 1,
    // demodulators (both): ADC, reference, product, state and output formats, low-pass shift
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
    // PLL: error, gains, integrator and output (the NCO word, s NCO_PHASE_W.NCO_PHASE_W)
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
    parameter signed [PLL_KP_W-1:0] PLL_KP = 18'sd67109,
    parameter signed [PLL_KI_W-1:0] PLL_KI = 18'sd96149,
    parameter signed [PLL_INT_W-1:0] PLL_INT_MIN = 40'sd11052846203,
    parameter signed [PLL_INT_W-1:0] PLL_INT_MAX = 40'sd11400555661,
    // AGC: error, gains, integrator and output (DAC LSB)
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
    parameter signed [AGC_KP_W-1:0] AGC_KP = 18'sd105114,
    parameter signed [AGC_KI_W-1:0] AGC_KI = 18'sd75300,
    parameter signed [AGC_INT_W-1:0] AGC_INT_MIN = 40'sd0,
    parameter signed [AGC_INT_W-1:0] AGC_INT_MAX = 40'sd137437904896,
    // CICs (both): input, stages, decimation, delay, shift, scaled output, taps, output
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
    // lock detector: filter shift and the samples both errors must stay inside
    parameter integer LOCK_SHIFT = 9,
    parameter integer LOCK_HOLD = 2000,
    // per mode (_N normal, _R reverse): AGC setpoint (demodulator output format),
    // nominal NCO word and PLL preset, DAC and sense reference offsets (cycles,
    // u NCO_PHASE_W.NCO_PHASE_W), 1/SF of the rate and quadrature, lock limits
    parameter signed [DEMOD_OUT_W-1:0] SETPOINT_N = 32'sd214746726,
    parameter signed [DEMOD_OUT_W-1:0] SETPOINT_R = 32'sd214746726,
    parameter [NCO_PHASE_W-1:0] FREQ_WORD_N = 32'd175986199,
    parameter [NCO_PHASE_W-1:0] FREQ_WORD_R = 32'd174848206,
    parameter signed [PLL_INT_W-1:0] PLL_PRESET_N = 40'sd11263116708,
    parameter signed [PLL_INT_W-1:0] PLL_PRESET_R = 40'sd11190285157,
    parameter [NCO_PHASE_W-1:0] DAC_OFFSET_N = 32'd265521847,
    parameter [NCO_PHASE_W-1:0] DAC_OFFSET_R = 32'd263941688,
    parameter [NCO_PHASE_W-1:0] SENSE_OFFSET_N = 32'd1331053422,
    parameter [NCO_PHASE_W-1:0] SENSE_OFFSET_R = 32'd2950095547,
    parameter signed [COEF_W-1:0] RATE_COEF_N = 24'sd6544256,
    parameter signed [COEF_W-1:0] RATE_COEF_R = -24'sd6641270,
    parameter signed [COEF_W-1:0] QUAD_COEF_N = -24'sd6544256,
    parameter signed [COEF_W-1:0] QUAD_COEF_R = -24'sd6641270,
    parameter signed [63:0] LOCK_Q_N = 64'sd191899419,
    parameter signed [63:0] LOCK_Q_R = 64'sd191899419,
    parameter signed [63:0] LOCK_A_N = 64'sd109950324,
    parameter signed [63:0] LOCK_A_R = 64'sd109950324,
    // rounding: 0 floor, 1 ceil, 2 zero, 3 nearest, 4 round, 5 convergent
    parameter integer ROUNDING = 3,
    // overflow: 0 wrap, 1 saturate
    parameter integer SATURATE = 1,
    // ROM images for $readmemh
    parameter NCO_ROM_FILE = "gyro_loop_nco_sine.mem",
    parameter CIC_ROM_FILE = "gyro_loop_cic_taps.mem",
    // the schedule: image, words, words of a sample that does not decimate, RAM words
    parameter SCHEDULE_FILE = "gyro_loop_schedule.mem",
    parameter integer SCHEDULE_LEN = 114,
    parameter integer SCHEDULE_REGULAR = 54,
    parameter integer RAM_WORDS = 28
) (
    input  wire                           clk,
    input  wire                           rst,
    input  wire                           ce,
    input  wire                           mode,
    input  wire signed [DEMOD_ADC_W-1:0]  adc_x,
    input  wire signed [DEMOD_ADC_W-1:0]  adc_y,
    output wire signed [DAC_W-1:0]        dac_x,
    output wire signed [DAC_W-1:0]        dac_y,
    output wire signed [OUT_W-1:0]        rate,
    output wire signed [OUT_W-1:0]        quadrature,
    output wire                           out_valid,
    output wire                           locked
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
localparam integer RAM_W = max2(max2(max2(DEMOD_STATE_W, V_W), max2(AGC_INT_W, Z_W)),
    max2(REG_W, CIC_MID_W)) + 1;
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
localparam integer PC_W = SCHEDULE_LEN > 1 ? ceil_log2(SCHEDULE_LEN) : 1;
localparam integer RAM_ADDR_W = RAM_WORDS > 1 ? ceil_log2(RAM_WORDS) : 1;
localparam integer TAP_ADDR_W = CIC_TAPS > 1 ? ceil_log2(CIC_TAPS) : 1;

initial begin
    if (CIC_DELAY != 1) begin
        $display("%m: the folded loop's CICs have a differential delay of 1, not %0d", CIC_DELAY);
        $finish;
    end
    if (AGC_ERR_W != DEMOD_OUT_W || AGC_ERR_F != DEMOD_OUT_F || PLL_ERR_W != DEMOD_OUT_W) begin
        $display("%m: the PI errors' formats must be the demodulator output's");
        $finish;
    end
    if (CIC_TAPS > 15 || A_LIMBS > 8 || DEMOD_STATE_F < DEMOD_PROD_F || CIC_DECIMATION < 2) begin
        $display("%m: the schedule's fields hold CIC_TAPS <= 15 (%0d) and operands of <= 8 limbs (%0d); DEMOD_STATE_F (%0d) must be >= DEMOD_PROD_F (%0d), CIC_DECIMATION (%0d) >= 2",
            CIC_TAPS, A_LIMBS, DEMOD_STATE_F, DEMOD_PROD_F, CIC_DECIMATION);
        $finish;
    end
    if (RAM_WORDS > 128 || SCHEDULE_REGULAR > SCHEDULE_LEN) begin
        $display("%m: RAM_WORDS (%0d) must be <= 128 and SCHEDULE_REGULAR (%0d) <= SCHEDULE_LEN (%0d)",
            RAM_WORDS, SCHEDULE_REGULAR, SCHEDULE_LEN);
        $finish;
    end
end

// ---- control: the schedule ROM, the sample's flags ------------------------------------------
reg [63:0] schedule [0:SCHEDULE_LEN-1];
initial begin
    $readmemh(SCHEDULE_FILE, schedule);
end

reg busy_reg = 1'b0;
reg [PC_W-1:0] pc_reg = {PC_W{1'b0}};
// The word fetched (the schedule ROM's output register), then the word executing a clock
// later: the clock between decodes the accumulator's operands from the fetched word.
reg [63:0] fetched_reg = 64'd0;
// (Its x and y bits are decoded from fetched_reg a clock earlier, not read here.)
/* verilator lint_off UNUSEDSIGNAL */
reg [63:0] control_reg = 64'd0;
/* verilator lint_on UNUSEDSIGNAL */
reg executing_reg = 1'b0;
reg executing_last_reg = 1'b0;
reg mode_reg = 1'b1;
reg start_reg = 1'b1;
reg switching_reg = 1'b0;
reg first_reg = 1'b0;
reg decimate_reg = 1'b0;
reg [CNT_W-1:0] count_reg = {CNT_W{1'b0}};
reg [3:0] seen_reg = 4'd0;
reg signed [DEMOD_ADC_W-1:0] adc_x_reg = {DEMOD_ADC_W{1'b0}};
reg signed [DEMOD_ADC_W-1:0] adc_y_reg = {DEMOD_ADC_W{1'b0}};

/* verilator lint_off UNUSEDSIGNAL */
wire [31:0] last_count = CIC_DECIMATION - 1;
/* verilator lint_on UNUSEDSIGNAL */
wire switching = mode != mode_reg || start_reg;
wire [PC_W-1:0] schedule_end = decimate_reg ? SCHEDULE_LEN[PC_W-1:0] - 1'b1
                                             : SCHEDULE_REGULAR[PC_W-1:0] - 1'b1;
wire last_word = busy_reg && pc_reg == schedule_end;
wire fetch = (ce && !rst) || (busy_reg && !last_word);
wire [PC_W-1:0] fetch_address = ce ? {PC_W{1'b0}} : pc_reg + 1'b1;

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
// The folded pair's fields (which gyro each unit serves, the decimating-only write): 0 in a
// one-gyro schedule.
wire [6:0] pair_bits = control_reg[63:57];
/* verilator lint_on UNUSEDSIGNAL */

wire rom_en = executing_reg && rom_field != 3'd0;
wire accumulate_en = executing_reg && accumulate_reg;
wire read_en = executing_reg && read_field;
wire write_en = executing_reg && write_field;
wire [3:0] point = executing_reg ? quantize_field : 4'd0;

// ---- NCO: one accumulator, three references' truncation errors, the sine ROM -------------
reg [NCO_PHASE_W-1:0] nco_acc_reg = {NCO_PHASE_W{1'b0}};
reg [NCO_PHASE_W-1:0] freq_reg = {NCO_PHASE_W{1'b0}};
reg signed [R_W-1:0] residue_reg [0:2];
reg [NCO_SIN_W-1:0] nco_rom [0:(1 << NCO_ADDR_W)-1];
reg [NCO_SIN_W-1:0] ref_magnitude_reg = {NCO_SIN_W{1'b0}};
reg ref_negative_reg = 1'b0;
initial begin
    $readmemh(NCO_ROM_FILE, nco_rom);
    residue_reg[0] = {R_W{1'b0}};
    residue_reg[1] = {R_W{1'b0}};
    residue_reg[2] = {R_W{1'b0}};
end

// rom_field: 1 drive sin, 2 drive cos, 3 transmit cos, 4 sense sin, 5 sense cos.
wire [1:0] nco_index = rom_field == 3'd3 ? 2'd1 : (rom_field >= 3'd4 ? 2'd2 : 2'd0);
wire cosine = rom_field == 3'd2 || rom_field == 3'd3 || rom_field == 3'd5;
wire [NCO_PHASE_W-1:0] nco_offset =
    nco_index == 2'd0 ? {NCO_PHASE_W{1'b0}}
    : nco_index == 2'd1 ? (mode_reg ? DAC_OFFSET_N : DAC_OFFSET_R)
    : (mode_reg ? SENSE_OFFSET_N : SENSE_OFFSET_R);
wire signed [R_W-1:0] residue = residue_reg[nco_index];
wire [NCO_PHASE_W-1:0] residue_extended = {{(NCO_PHASE_W - R_W){residue[R_W-1]}}, residue};
wire [NCO_PHASE_W-1:0] phase_exact = nco_acc_reg + nco_offset;
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
// (gyrofx_model::gyro_loop::folded::Control::merge refuses it), so the block RAM needs no
// logic around it to return the old word then. The read register has no initial value, as a
// block RAM's has none: it loads before it is read.
(* no_rw_check *)
reg [RAM_W-1:0] ram [0:RAM_WORDS-1];
reg [RAM_W-1:0] ram_data_reg;
// The read register's gates: it reads as 0 (a cleared word), or the PLL integrator operand as
// the PLL's preset. The accumulator's operands take them in their selects, decoded a clock
// early; the other readers of the word (a delay line's shift, the multiplier, the previous
// read) in their multiplexers.
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
// gate_field: 1 switch, 2 preset, 3 first sample, 4 fewer than seen decimations.
wire read_zero = (gate_field == 3'd1 && switching_reg) || (gate_field == 3'd3 && first_reg)
    || (gate_field == 3'd4 && seen_reg < seen_field);
wire read_preset = gate_field == 3'd2 && switching_reg;
// The gates as they stand when the word being decoded acts: this clock's read sets them.
wire zero_next = read_en ? read_zero : read_zero_reg;
wire preset_next = read_en ? read_preset : read_preset_reg;

// The accumulator's x and y decoded from the fetched word into one-hot selects, a clock
// before the word executes: a clock runs an AND-OR of registered selects into the adder, not
// the ROM's output through a decoder (gyrofx_model::gyro_loop::folded::AccX, AccY codes). A
// read gated to 0 selects nothing; the PLL's preset is an x source of its own; a negated y
// is selected inverted and the adder's carry in adds the 1. Nothing but one AND-OR level
// stands between a register and the adder.
wire [3:0] x_field = fetched_reg[22:19];
wire [3:0] y_field = fetched_reg[26:23];
// (x code 1 and y code 0 select nothing, 0: their bits stay 0; x code 4 and the preset select
// through setpoint_select_reg and preset_select_reg; x codes 6 and 8, either PI's sum, the
// integrator register at the one alignment both take.)
/* verilator lint_off UNUSEDSIGNAL */
reg [8:0] x_select_reg = 9'd0;
reg [9:0] y_select_reg = 10'd0;
/* verilator lint_on UNUSEDSIGNAL */
// A constant of two modes, per bit: set in both modes' values, in this mode's only (normal,
// reverse); so that each bit of the operand is one registered select or 0.
reg [2:0] setpoint_select_reg = 3'd0;
reg [2:0] preset_select_reg = 3'd0;
reg y_carry_reg = 1'b0;
// The RAM write's source (data_field's codes), decoded as the operands are.
wire [2:0] data_field_next = fetched_reg[52:50];
reg [5:0] write_select_reg = 6'd0;
wire [3:0] a_field_next = fetched_reg[7:4];
reg [7:0] a_select_reg = 8'd0;
wire x_preset = x_field == 4'd5 && preset_next;
always @(posedge clk) begin
    x_select_reg <= {1'b0, x_field == 4'd7 && !zero_next, x_field == 4'd6 || x_field == 4'd8,
        x_field == 4'd5 && !zero_next && !preset_next, 1'b0, x_field == 4'd3 && !zero_next,
        x_field == 4'd2 && !zero_next, 1'b0, x_field == 4'd0};
    setpoint_select_reg <= {x_field == 4'd4 && !mode_reg, x_field == 4'd4 && mode_reg,
        x_field == 4'd4};
    preset_select_reg <= {x_preset && !mode_reg, x_preset && mode_reg, x_preset};
    y_select_reg <= {y_field == 4'd9, y_field == 4'd8, y_field == 4'd7 && !zero_next,
        y_field == 4'd6, y_field == 4'd5, y_field == 4'd4, y_field == 4'd3,
        y_field == 4'd2 && !zero_next, y_field == 4'd1, 1'b0};
    y_carry_reg <= ((y_field == 4'd2 || y_field == 4'd7) && !zero_next) || y_field == 4'd4;
    a_select_reg <= {a_field_next == 4'd8, a_field_next == 4'd7 && !zero_next,
        a_field_next == 4'd6, a_field_next == 4'd5, a_field_next == 4'd4, a_field_next == 4'd3,
        (a_field_next == 4'd1 && !mode_reg) || (a_field_next == 4'd2 && mode_reg),
        (a_field_next == 4'd1 && mode_reg) || (a_field_next == 4'd2 && !mode_reg)};
    write_select_reg <= {data_field_next == 3'd5, data_field_next == 3'd4 && !zero_next,
        data_field_next == 3'd3, data_field_next == 3'd2, data_field_next == 3'd1,
        data_field_next == 3'd0};
    accumulate_reg <= x_field != 4'd0 || y_field != 4'd0;
end

// ---- multiplier: a 15-bit limb of a times all of b -------------------------------------------
reg signed [DEMOD_OUT_W-1:0] drive_q_reg = {DEMOD_OUT_W{1'b0}};
reg signed [AGC_ERR_W-1:0] amplitude_error_reg = {AGC_ERR_W{1'b0}};
reg signed [AGC_OUT_W-1:0] amplitude_reg = {AGC_OUT_W{1'b0}};
reg signed [CIC_MID_W-1:0] c_reg = {CIC_MID_W{1'b0}};
reg signed [CIC_OUT_W-1:0] cic_output_reg = {CIC_OUT_W{1'b0}};
reg [CIC_COEF_W-1:0] taps_rom [0:CIC_TAPS-1];
initial begin
    $readmemh(CIC_ROM_FILE, taps_rom);
end

// Every a operand sign-extended to A_EXT_W bits (the RAM word holds a CIC output c), as an
// AND-OR of one-hot selects decoded a clock early (a_select_reg: the ADC codes of x and y,
// whichever axis the mode drives, Q_D, e_A, the amplitude, c, the delay line's word unless
// its read is gated to 0, the compensator's output).
// (Continuous assignments, not always @*: a simulator evaluates them at time 0 too. The top
// bit, a guard bit, is never a limb's.)
/* verilator lint_off UNUSEDSIGNAL */
wire signed [A_EXT_W-1:0] a_value =
      ({A_EXT_W{a_select_reg[0]}} & {{(A_EXT_W-DEMOD_ADC_W){adc_x_reg[DEMOD_ADC_W-1]}}, adc_x_reg})
    | ({A_EXT_W{a_select_reg[1]}} & {{(A_EXT_W-DEMOD_ADC_W){adc_y_reg[DEMOD_ADC_W-1]}}, adc_y_reg})
    | ({A_EXT_W{a_select_reg[2]}} & {{(A_EXT_W-DEMOD_OUT_W){drive_q_reg[DEMOD_OUT_W-1]}}, drive_q_reg})
    | ({A_EXT_W{a_select_reg[3]}} & {{(A_EXT_W-AGC_ERR_W){amplitude_error_reg[AGC_ERR_W-1]}}, amplitude_error_reg})
    | ({A_EXT_W{a_select_reg[4]}} & {{(A_EXT_W-AGC_OUT_W){amplitude_reg[AGC_OUT_W-1]}}, amplitude_reg})
    | ({A_EXT_W{a_select_reg[5]}} & {{(A_EXT_W-CIC_MID_W){c_reg[CIC_MID_W-1]}}, c_reg})
    | ({A_EXT_W{a_select_reg[6]}} & {{(A_EXT_W-CIC_MID_W){rd[CIC_MID_W-1]}}, rd[CIC_MID_W-1:0]})
    | ({A_EXT_W{a_select_reg[7]}} & {{(A_EXT_W-CIC_OUT_W){cic_output_reg[CIC_OUT_W-1]}}, cic_output_reg});
/* verilator lint_on UNUSEDSIGNAL */
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
wire signed [COEF_W-1:0] rate_coef = mode_reg ? RATE_COEF_N : RATE_COEF_R;
wire signed [COEF_W-1:0] quad_coef = mode_reg ? QUAD_COEF_N : QUAD_COEF_R;
// (Its top bit, a guard bit, is never a limb's.)
/* verilator lint_off UNUSEDSIGNAL */
wire signed [B_EXT_W-1:0] b_value =
    b_field == 3'd0 ? {{(B_EXT_W-NCO_SIN_W){reference[NCO_SIN_W-1]}}, reference}
    : b_field == 3'd1 ? {{(B_EXT_W-PLL_KI_W){PLL_KI[PLL_KI_W-1]}}, PLL_KI}
    : b_field == 3'd2 ? {{(B_EXT_W-PLL_KP_W){PLL_KP[PLL_KP_W-1]}}, PLL_KP}
    : b_field == 3'd3 ? {{(B_EXT_W-AGC_KI_W){AGC_KI[AGC_KI_W-1]}}, AGC_KI}
    : b_field == 3'd4 ? {{(B_EXT_W-AGC_KP_W){AGC_KP[AGC_KP_W-1]}}, AGC_KP}
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
// The two modes' constants, and the bits set in both, in the normal's only, in the reverse's.
function signed [ACC_W-1:0] preset_aligned;
    input signed [PLL_INT_W-1:0] preset;
    reg signed [PLL_INT_W-1:0] clamped;
    begin
        clamped = preset < PLL_INT_MIN ? PLL_INT_MIN : (preset > PLL_INT_MAX ? PLL_INT_MAX : preset);
        preset_aligned = {{(ACC_W-PLL_INT_W){clamped[PLL_INT_W-1]}}, clamped} <<< (PLL_UPD_F - PLL_INT_F);
    end
endfunction
localparam signed [ACC_W-1:0] SETPOINT_N_ACC = {{(ACC_W-DEMOD_OUT_W){SETPOINT_N[DEMOD_OUT_W-1]}}, SETPOINT_N};
localparam signed [ACC_W-1:0] SETPOINT_R_ACC = {{(ACC_W-DEMOD_OUT_W){SETPOINT_R[DEMOD_OUT_W-1]}}, SETPOINT_R};
localparam signed [ACC_W-1:0] PRESET_N_ACC = preset_aligned(PLL_PRESET_N);
localparam signed [ACC_W-1:0] PRESET_R_ACC = preset_aligned(PLL_PRESET_R);
function [ACC_W-1:0] of_modes;
    input [2:0] select;
    input [ACC_W-1:0] normal;
    input [ACC_W-1:0] reverse;
    begin
        of_modes = ({ACC_W{select[0]}} & normal & reverse) | ({ACC_W{select[1]}} & normal & ~reverse)
            | ({ACC_W{select[2]}} & ~normal & reverse);
    end
endfunction
wire signed [ACC_W-1:0] previous_rd_acc = {{(ACC_W-RAM_W){previous_rd_reg[RAM_W-1]}}, previous_rd_reg};
wire signed [ACC_W-1:0] v_acc = {{(ACC_W-V_W){v_reg[V_W-1]}}, v_reg};
wire signed [ACC_W-1:0] p_acc = {{(ACC_W-DEMOD_PROD_W){p_reg[DEMOD_PROD_W-1]}}, p_reg};
// Q_O of the state register, registered: the value of the clock before.
reg signed [DEMOD_OUT_W-1:0] output_reg = {DEMOD_OUT_W{1'b0}};
always @(posedge clk) begin
    output_reg <= demod_output;
end
wire signed [ACC_W-1:0] output_acc = {{(ACC_W-DEMOD_OUT_W){output_reg[DEMOD_OUT_W-1]}}, output_reg};
wire signed [ACC_W-1:0] drive_q_acc = {{(ACC_W-DEMOD_OUT_W){drive_q_reg[DEMOD_OUT_W-1]}}, drive_q_reg};
wire signed [ACC_W-1:0] error_acc =
    {{(ACC_W-AGC_ERR_W){amplitude_error_reg[AGC_ERR_W-1]}}, amplitude_error_reg};

// x and y as AND-ORs of the selects decoded a clock early (at most one select is high; none:
// x = 0, y = 0).
wire signed [ACC_W-1:0] x_value =
      ({ACC_W{x_select_reg[0]}} & acc_reg)
    | ({ACC_W{x_select_reg[2]}} & rd_acc)
    | ({ACC_W{x_select_reg[3]}} & (rd_acc <<< DEMOD_SHIFT))
    | of_modes(setpoint_select_reg, SETPOINT_N_ACC, SETPOINT_R_ACC)
    | ({ACC_W{x_select_reg[5]}} & shifted(rd_acc, PLL_READ_SHIFT))
    | of_modes(preset_select_reg, PRESET_N_ACC, PRESET_R_ACC)
    | ({ACC_W{x_select_reg[6]}} & (v_acc <<< V_SUM_SHIFT))
    | ({ACC_W{x_select_reg[7]}} & shifted(rd_acc, AGC_READ_SHIFT));

// y, a negated one inverted (x + ~y + 1: the carry in adds the 1).
wire signed [ACC_W-1:0] y_value =
      ({ACC_W{y_select_reg[1]}} & pp_reg)
    | ({ACC_W{y_select_reg[2]}} & ~rd_acc)
    | ({ACC_W{y_select_reg[3]}} & (p_acc <<< DEMOD_ALIGN))
    | ({ACC_W{y_select_reg[4]}} & ~output_acc)
    | ({ACC_W{y_select_reg[5]}} & output_acc)
    | ({ACC_W{y_select_reg[6]}} & previous_rd_acc)
    | ({ACC_W{y_select_reg[7]}} & ~(rd_acc >>> LOCK_SHIFT))
    | ({ACC_W{y_select_reg[8]}} & drive_q_acc)
    | ({ACC_W{y_select_reg[9]}} & error_acc);
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

// The PI integrators' clamps: the limits bound the result, so its low INT_W bits are exact.
// They compare the floor q of the update (the accumulator's bits), beside the rounding's carry
// rather than after it: the rounded value is q + inc (inc 0 or 1, its low bit q's flipped
// when inc is 1), below the low limit L when q < L - 1 or q = L - 1 and inc = 0, above the
// high one H when q > H or q = H and inc = 1.
localparam integer PLL_DROP = PLL_UPD_F - PLL_INT_F;
localparam signed [PLL_RND_W-1:0] PLL_LOW = {{(PLL_RND_W-PLL_INT_W){PLL_INT_MIN[PLL_INT_W-1]}}, PLL_INT_MIN};
localparam signed [PLL_RND_W-1:0] PLL_HIGH = {{(PLL_RND_W-PLL_INT_W){PLL_INT_MAX[PLL_INT_W-1]}}, PLL_INT_MAX};
localparam signed [PLL_RND_W-1:0] PLL_LOW_LESS = PLL_LOW - 1;
wire signed [PLL_RND_W-1:0] pll_floor = {acc_reg[PLL_UPD_W-1], acc_reg[PLL_UPD_W-1:PLL_DROP]};
wire pll_increment = pll_rounded[0] ^ pll_floor[0];
wire pll_below = pll_floor < PLL_LOW_LESS || (pll_floor == PLL_LOW_LESS && !pll_increment);
wire pll_above = pll_floor > PLL_HIGH || (pll_floor == PLL_HIGH && pll_increment);
localparam integer AGC_DROP = AGC_UPD_F - AGC_INT_F;
localparam signed [AGC_RND_W-1:0] AGC_LOW = {{(AGC_RND_W-AGC_INT_W){AGC_INT_MIN[AGC_INT_W-1]}}, AGC_INT_MIN};
localparam signed [AGC_RND_W-1:0] AGC_HIGH = {{(AGC_RND_W-AGC_INT_W){AGC_INT_MAX[AGC_INT_W-1]}}, AGC_INT_MAX};
localparam signed [AGC_RND_W-1:0] AGC_LOW_LESS = AGC_LOW - 1;
wire signed [AGC_RND_W-1:0] agc_floor = {acc_reg[AGC_UPD_W-1], acc_reg[AGC_UPD_W-1:AGC_DROP]};
wire agc_increment = agc_rounded[0] ^ agc_floor[0];
wire agc_below = agc_floor < AGC_LOW_LESS || (agc_floor == AGC_LOW_LESS && !agc_increment);
wire agc_above = agc_floor > AGC_HIGH || (agc_floor == AGC_HIGH && agc_increment);
// v_reg's next value at either PI's point (its low INT_W bits, sign-extended): the point's
// rounded update and limits chosen first (the point is known early), the comparisons last.
wire pll_point = quantize_field == 4'd5;
wire [V_W-1:0] v_rounded = pll_point
    ? {{(V_W-PLL_INT_W){pll_rounded[PLL_INT_W-1]}}, pll_rounded[PLL_INT_W-1:0]} << PLL_V_SHIFT
    : {{(V_W-AGC_INT_W){agc_rounded[AGC_INT_W-1]}}, agc_rounded[AGC_INT_W-1:0]} << AGC_V_SHIFT;
wire [V_W-1:0] v_low = pll_point
    ? {{(V_W-PLL_INT_W){PLL_INT_MIN[PLL_INT_W-1]}}, PLL_INT_MIN} << PLL_V_SHIFT
    : {{(V_W-AGC_INT_W){AGC_INT_MIN[AGC_INT_W-1]}}, AGC_INT_MIN} << AGC_V_SHIFT;
wire [V_W-1:0] v_high = pll_point
    ? {{(V_W-PLL_INT_W){PLL_INT_MAX[PLL_INT_W-1]}}, PLL_INT_MAX} << PLL_V_SHIFT
    : {{(V_W-AGC_INT_W){AGC_INT_MAX[AGC_INT_W-1]}}, AGC_INT_MAX} << AGC_V_SHIFT;
wire v_below = pll_point ? pll_below : agc_below;
wire v_above = pll_point ? pll_above : agc_above;
wire [V_W-1:0] v_next = v_below ? v_low : (v_above ? v_high : v_rounded);

// The lock filters' check |z| < limit as -limit < z < limit: two comparisons side by side, not
// a negation then one, in Z_W + 2 bits. |z| < 2^(Z_W-1), so a limit clipped to +-2^Z_W decides
// as the 64-bit one does.
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
localparam signed [CMP_W-1:0] LIMIT_Q_N = clipped(LOCK_Q_N);
localparam signed [CMP_W-1:0] LIMIT_Q_R = clipped(LOCK_Q_R);
localparam signed [CMP_W-1:0] LIMIT_A_N = clipped(LOCK_A_N);
localparam signed [CMP_W-1:0] LIMIT_A_R = clipped(LOCK_A_R);
wire signed [Z_W-1:0] z = acc_reg[Z_W-1:0];
wire signed [CMP_W-1:0] z_cmp = {{2{z[Z_W-1]}}, z};
wire signed [CMP_W-1:0] lock_limit = quantize_field == 4'd14 ? (mode_reg ? LIMIT_Q_N : LIMIT_Q_R)
                                                           : (mode_reg ? LIMIT_A_N : LIMIT_A_R);
wire signed [CMP_W-1:0] lock_floor = quantize_field == 4'd14 ? (mode_reg ? -LIMIT_Q_N : -LIMIT_Q_R)
                                                           : (mode_reg ? -LIMIT_A_N : -LIMIT_A_R);
wire within_limit = z_cmp < lock_limit && z_cmp > lock_floor;

// ---- RAM writes ---------------------------------------------------------------------------
// What a write stores, as an AND-OR of one-hot selects decoded a clock early (data_field:
// 0 the accumulator at the CIC registers' width, 1 at the lock filters', 2 y, 3 v, 4 the read
// register, 5 c). The narrow sources share one multiplexer whose sign extends past them.
localparam integer NARROW_W = max2(max2(Z_W, DEMOD_STATE_W), max2(V_W, CIC_MID_W));
wire [NARROW_W-1:0] write_narrow =
      ({NARROW_W{write_select_reg[1]}} & {{(NARROW_W-Z_W){z[Z_W-1]}}, z})
    | ({NARROW_W{write_select_reg[2]}} & {{(NARROW_W-DEMOD_STATE_W){y_reg[DEMOD_STATE_W-1]}}, y_reg})
    | ({NARROW_W{write_select_reg[3]}} & {{(NARROW_W-V_W){v_reg[V_W-1]}}, v_reg})
    | ({NARROW_W{write_select_reg[5]}} & {{(NARROW_W-CIC_MID_W){c_reg[CIC_MID_W-1]}}, c_reg});
wire [RAM_W-1:0] write_data =
      {{(RAM_W-NARROW_W){write_narrow[NARROW_W-1]}}, write_narrow}
    | ({RAM_W{write_select_reg[4]}} & rd)
    | ({RAM_W{write_select_reg[0]}} & {{(RAM_W-REG_W){acc_reg[REG_W-1]}}, acc_reg[REG_W-1:0]});

// The DAC point loads the driven axis's code and clears the other's (clears: synchronous
// resets, not multiplexers).
always @(posedge clk) begin
    if (rst || (point == 4'd9 && !mode_reg)) begin
        dac_x_reg <= {DAC_W{1'b0}};
    end else if (point == 4'd9) begin
        dac_x_reg <= dac_now;
    end
    if (rst || (point == 4'd9 && mode_reg)) begin
        dac_y_reg <= {DAC_W{1'b0}};
    end else if (point == 4'd9) begin
        dac_y_reg <= dac_now;
    end
end

// The DAC codes' delay line shifts at the DAC point and clears in a sample that switches mode;
// the lock count counts on the clock after the lock check and clears when the check fails or
// the mode switches (clears: synchronous resets).
always @(posedge clk) begin
    if (rst || (ce && switching && point != 4'd9)) begin
        for (d = 0; d < DELAY_N; d = d + 1) begin
            delay_reg[d] <= {DAC_W{1'b0}};
        end
    end else if (point == 4'd9) begin
        delay_reg[0] <= drive;
        for (d = 1; d < DELAY_N; d = d + 1) begin
            delay_reg[d] <= delay_reg[d-1];
        end
    end
    if (rst || (count_pending_reg && !inside_reg) || (ce && switching && !count_pending_reg)) begin
        lock_count_reg <= {COUNT_W{1'b0}};
    end else if (count_pending_reg) begin
        lock_count_reg <= lock_count_reg >= lock_hold ? lock_hold : lock_count_reg + 1'b1;
    end
end

// The NCO's frequency word: the PLL's output, or in the first sample of a mode (from ce) its
// nominal word; bit by bit, so that a bit both modes' words share is a synchronous set or
// reset, not a multiplexer.
genvar f;
generate
    for (f = 0; f < NCO_PHASE_W; f = f + 1) begin : g_freq
        always @(posedge clk) begin
            if (rst) begin
                freq_reg[f] <= 1'b0;
            end else if (point == 4'd6) begin
                freq_reg[f] <= pll_out[f];
            end else if (ce && switching) begin
                freq_reg[f] <= mode ? FREQ_WORD_N[f] : FREQ_WORD_R[f];
            end
        end
    end
endgenerate

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

// ---- the sample, the registers the points load, the outputs ---------------------------------
reg signed [DAC_W-1:0] delay_reg [0:DELAY_N-1];
wire signed [DAC_W-1:0] dac_now = LATENCY == 0 ? drive : delay_reg[DELAY_N-1];
reg signed [DAC_W-1:0] dac_x_reg = {DAC_W{1'b0}};
reg signed [DAC_W-1:0] dac_y_reg = {DAC_W{1'b0}};
reg signed [OUT_W-1:0] rate_reg = {OUT_W{1'b0}};
reg signed [OUT_W-1:0] quad_reg = {OUT_W{1'b0}};
reg out_valid_reg = 1'b0;
reg inside_q_reg = 1'b0;
// Both filters' check, registered at the second one's point: the count and locked load on the
// clock after it, so that no clock runs the comparison and the count's increment in series.
reg inside_reg = 1'b0;
reg count_pending_reg = 1'b0;
reg [COUNT_W-1:0] lock_count_reg = {COUNT_W{1'b0}};
reg locked_reg = 1'b0;
/* verilator lint_off UNUSEDSIGNAL */
wire [31:0] lock_hold_word = LOCK_HOLD;
/* verilator lint_on UNUSEDSIGNAL */
wire [COUNT_W-1:0] lock_hold = lock_hold_word[COUNT_W-1:0];
wire [COUNT_W-1:0] lock_count_next = inside_reg
    ? (lock_count_reg >= lock_hold ? lock_hold : lock_count_reg + 1'b1) : {COUNT_W{1'b0}};

integer i;
integer d;
initial begin
    for (i = 0; i < DELAY_N; i = i + 1) begin
        delay_reg[i] = {DAC_W{1'b0}};
    end
end

always @(posedge clk) begin
    out_valid_reg <= 1'b0;

    if (ce) begin
        busy_reg <= 1'b1;
        pc_reg <= {PC_W{1'b0}};
        mode_reg <= mode;
        start_reg <= 1'b0;
        switching_reg <= switching;
        first_reg <= start_reg;
        adc_x_reg <= adc_x;
        adc_y_reg <= adc_y;
        decimate_reg <= count_reg == last_count[CNT_W-1:0];
        count_reg <= count_reg == last_count[CNT_W-1:0] ? {CNT_W{1'b0}} : count_reg + 1'b1;
    end else if (busy_reg) begin
        if (last_word) begin
            busy_reg <= 1'b0;
        end else begin
            pc_reg <= pc_reg + 1'b1;
        end
    end
    if (executing_reg && executing_last_reg && decimate_reg && seen_reg < MOST_SEEN[3:0]) begin
        seen_reg <= seen_reg + 4'd1;
    end

    if (rom_en) begin
        ref_negative_reg <= t[T_W-1];
        if (cosine && NCO_ERROR_FEEDBACK != 0) begin
            residue_reg[nco_index] <= phase[R_W-1:0] ^ HALF_BIN;
        end
    end
    if (executing_reg && advance_field) begin
        nco_acc_reg <= nco_acc_reg + freq_reg;
    end
    if (read_en) begin
        read_zero_reg <= read_zero;
        read_preset_reg <= read_preset;
    end
    if (accumulate_en) begin
        acc_reg <= acc_next;
    end

    case (point)
        4'd1: p_reg <= p_next;
        4'd2: y_reg <= y_next;
        4'd3: drive_q_reg <= output_reg;
        4'd4: amplitude_error_reg <= error_next;
        4'd5: v_reg <= v_next;
        4'd7: v_reg <= v_next;
        4'd8: amplitude_reg <= agc_out;
        4'd9: begin
        end
        4'd10: c_reg <= c_next;
        4'd11: cic_output_reg <= cic_output_next;
        4'd12: rate_reg <= rate_next;
        4'd13: begin
            quad_reg <= rate_next;
            out_valid_reg <= 1'b1;
        end
        4'd14: inside_q_reg <= within_limit;
        4'd15: inside_reg <= inside_q_reg && within_limit;
        default: begin
        end
    endcase
    count_pending_reg <= point == 4'd15;
    if (count_pending_reg) begin
        locked_reg <= lock_count_next >= lock_hold;
    end

    if (rst) begin
        busy_reg <= 1'b0;
        pc_reg <= {PC_W{1'b0}};
        mode_reg <= 1'b1;
        start_reg <= 1'b1;
        switching_reg <= 1'b0;
        first_reg <= 1'b0;
        decimate_reg <= 1'b0;
        count_reg <= {CNT_W{1'b0}};
        seen_reg <= 4'd0;
        adc_x_reg <= {DEMOD_ADC_W{1'b0}};
        adc_y_reg <= {DEMOD_ADC_W{1'b0}};
        nco_acc_reg <= {NCO_PHASE_W{1'b0}};
        residue_reg[0] <= {R_W{1'b0}};
        residue_reg[1] <= {R_W{1'b0}};
        residue_reg[2] <= {R_W{1'b0}};
        read_zero_reg <= 1'b0;
        read_preset_reg <= 1'b0;
        acc_reg <= {ACC_W{1'b0}};
        p_reg <= {DEMOD_PROD_W{1'b0}};
        y_reg <= {DEMOD_STATE_W{1'b0}};
        v_reg <= {V_W{1'b0}};
        drive_q_reg <= {DEMOD_OUT_W{1'b0}};
        amplitude_error_reg <= {AGC_ERR_W{1'b0}};
        amplitude_reg <= {AGC_OUT_W{1'b0}};
        c_reg <= {CIC_MID_W{1'b0}};
        cic_output_reg <= {CIC_OUT_W{1'b0}};
        rate_reg <= {OUT_W{1'b0}};
        quad_reg <= {OUT_W{1'b0}};
        out_valid_reg <= 1'b0;
        inside_q_reg <= 1'b0;
        inside_reg <= 1'b0;
        count_pending_reg <= 1'b0;
        locked_reg <= 1'b0;
    end
end

assign dac_x = dac_x_reg;
assign dac_y = dac_y_reg;
assign rate = rate_reg;
assign quadrature = quad_reg;
assign out_valid = out_valid_reg;
assign locked = locked_reg;

`ifndef SYNTHESIS
// Simulation only (yosys defines SYNTHESIS): a sample takes the schedule's clocks
// (gyrofx_job::pipeline); a sooner ce stops the simulation, naming this instance.
gyrofx_spacing_check #(
    .MIN_CLOCKS_PER_SAMPLE(SCHEDULE_LEN + 2),
    .BLOCK_NAME("gyrofx_gyro_loop_serial")
) spacing_check (
    .clk(clk),
    .rst(rst),
    .ce(ce)
);
`endif

endmodule

`resetall
