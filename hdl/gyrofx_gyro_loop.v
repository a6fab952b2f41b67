// Language: Verilog 2001

`resetall
`timescale 1ns / 1ps
`default_nettype none

/*
 * gyrofx_gyro_loop — one vibratory gyro's digital loop: drive PLL and AGC, sense
 * demodulation, CIC decimation and the mode switch of mode reversal.
 *
 * Purpose: closes the drive loop around the resonator (ADC codes of both axes
 *   in, DAC codes out) and turns the sense axis into the chain's rate in deg/s
 *   (SPEC 1.6). Bit-exact with gyrofx_model::gyro_loop::FixedGyroLoop; the
 *   architecture, design equations and quantization points are documented
 *   there and in docs/blocks/gyro_loop.md.
 *
 * Algorithm (per ADC sample, ce high; mode 1 normal: drive x, sense y; 0
 *   reverse: drive y, sense x; _N / _R parameters are the two modes' values):
 *     on a change of mode (and at the first sample after reset), before the
 *     sample: PLL integrator <= PLL_PRESET, NCO word <= FREQ_WORD, AGC
 *     integrator, both demodulators, the lock filters and counter and the DAC
 *     delay line cleared
 *     (sin_D, cos_D) = NCO(freq, 0), cos_T = NCO(freq, DAC_OFFSET),
 *     (sin_S, cos_S) = NCO(freq, SENSE_OFFSET)            three accumulators, one word
 *     (I_D, Q_D) = demod(adc_drive), (I_S, Q_S) = demod(adc_sense)
 *     freq <= PLL(Q_D)                 taken by the NCOs at the next sample
 *     e_A = Q(SETPOINT - I_D)          demodulator output format
 *     dac = Q(AGC(e_A) * cos_T)        DAC format; output LATENCY samples later
 *     z_Q <= z_Q - (z_Q >>> LOCK_SHIFT) + Q_D, the same for z_A with e_A;
 *     locked = both |z| < LOCK_* for LOCK_HOLD samples in a row
 *     every DECIMATION-th sample: rate = Q(RATE_COEF * CIC(I_S)),
 *     quadrature = Q(QUAD_COEF * CIC(Q_S)), out_valid pulses
 *
 * Pipeline: four register stages (NCOs, demodulators, PLL/AGC/CICs, outputs).
 *   dac_x, dac_y, locked, rate, quadrature and out_valid are valid 4 clocks
 *   after ce (3 clocks after the clock that follows it); ce must come at most
 *   every 4th clock. dac_x/dac_y/locked hold until the next sample's outputs;
 *   out_valid is a one-clock pulse and rate/quadrature hold between pulses. A
 *   clock with rst high clears every register (rst wins over ce); the first
 *   sample after it starts the mode it asks for.
 *
 * ROMs: NCO_ROM_FILE (the NCOs' quarter-wave sine) and CIC_ROM_FILE (the
 *   droop compensator's taps), $readmemh images.
 */
module gyrofx_gyro_loop #(
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
    parameter NCO_ROM_FILE = "nco_sine.mem",
    parameter CIC_ROM_FILE = "cic_taps.mem"
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

localparam integer Z_W = DEMOD_OUT_W + LOCK_SHIFT + 1;
localparam integer DRIVE_W = AGC_OUT_W + NCO_SIN_W;
localparam integer DRIVE_F = AGC_OUT_F + NCO_SIN_W - 1;
localparam integer RATE_W = CIC_OUT_W + COEF_W;
localparam integer RATE_F = CIC_OUT_F + COEF_F;
localparam integer DELAY_N = LATENCY > 0 ? LATENCY : 1;

// ---- stage 0: mode, switch actions, NCOs ----------------------------------
reg mode_reg = 1'b1;
reg start_reg = 1'b1;
reg ce_1_reg = 1'b0;
reg ce_2_reg = 1'b0;
reg ce_3_reg = 1'b0;
reg [NCO_PHASE_W-1:0] freq_reg = {NCO_PHASE_W{1'b0}};
reg signed [DEMOD_ADC_W-1:0] adc_x_reg = {DEMOD_ADC_W{1'b0}};
reg signed [DEMOD_ADC_W-1:0] adc_y_reg = {DEMOD_ADC_W{1'b0}};

// The enter actions of a mode change apply before this sample.
wire switching = ce && (mode != mode_reg || start_reg);
wire [NCO_PHASE_W-1:0] freq_now = switching ? (mode ? FREQ_WORD_N : FREQ_WORD_R) : freq_reg;
wire [NCO_PHASE_W-1:0] dac_offset = mode ? DAC_OFFSET_N : DAC_OFFSET_R;
wire [NCO_PHASE_W-1:0] sense_offset = mode ? SENSE_OFFSET_N : SENSE_OFFSET_R;

wire signed [NCO_SIN_W-1:0] drive_sin;
wire signed [NCO_SIN_W-1:0] drive_cos;
/* verilator lint_off UNUSEDSIGNAL */
wire signed [NCO_SIN_W-1:0] transmit_sin;
/* verilator lint_on UNUSEDSIGNAL */
wire signed [NCO_SIN_W-1:0] transmit_cos;
wire signed [NCO_SIN_W-1:0] sense_sin;
wire signed [NCO_SIN_W-1:0] sense_cos;

/* verilator lint_off PINCONNECTEMPTY */
gyrofx_nco #(
    .PHASE_W(NCO_PHASE_W), .ADDR_W(NCO_ADDR_W), .SIN_W(NCO_SIN_W),
    .ERROR_FEEDBACK(NCO_ERROR_FEEDBACK), .ROM_FILE(NCO_ROM_FILE)
) nco_drive (
    .clk(clk), .rst(rst), .ce(ce), .freq(freq_now), .offset({NCO_PHASE_W{1'b0}}),
    .sin_out(drive_sin), .cos_out(drive_cos), .out_valid()
);

gyrofx_nco #(
    .PHASE_W(NCO_PHASE_W), .ADDR_W(NCO_ADDR_W), .SIN_W(NCO_SIN_W),
    .ERROR_FEEDBACK(NCO_ERROR_FEEDBACK), .ROM_FILE(NCO_ROM_FILE)
) nco_transmit (
    .clk(clk), .rst(rst), .ce(ce), .freq(freq_now), .offset(dac_offset),
    .sin_out(transmit_sin), .cos_out(transmit_cos), .out_valid()
);

gyrofx_nco #(
    .PHASE_W(NCO_PHASE_W), .ADDR_W(NCO_ADDR_W), .SIN_W(NCO_SIN_W),
    .ERROR_FEEDBACK(NCO_ERROR_FEEDBACK), .ROM_FILE(NCO_ROM_FILE)
) nco_sense (
    .clk(clk), .rst(rst), .ce(ce), .freq(freq_now), .offset(sense_offset),
    .sin_out(sense_sin), .cos_out(sense_cos), .out_valid()
);
/* verilator lint_on PINCONNECTEMPTY */

// ---- stage 1: demodulators -------------------------------------------------
wire signed [DEMOD_ADC_W-1:0] adc_drive = mode_reg ? adc_x_reg : adc_y_reg;
wire signed [DEMOD_ADC_W-1:0] adc_sense = mode_reg ? adc_y_reg : adc_x_reg;
wire signed [DEMOD_OUT_W-1:0] i_drive;
wire signed [DEMOD_OUT_W-1:0] q_drive;
wire signed [DEMOD_OUT_W-1:0] i_sense;
wire signed [DEMOD_OUT_W-1:0] q_sense;

/* verilator lint_off PINCONNECTEMPTY */
gyrofx_demodulator #(
    .ADC_W(DEMOD_ADC_W), .ADC_F(DEMOD_ADC_F), .REF_W(DEMOD_REF_W), .REF_F(DEMOD_REF_F),
    .PROD_W(DEMOD_PROD_W), .PROD_F(DEMOD_PROD_F), .STATE_W(DEMOD_STATE_W),
    .STATE_F(DEMOD_STATE_F), .OUT_W(DEMOD_OUT_W), .OUT_F(DEMOD_OUT_F), .SHIFT(DEMOD_SHIFT),
    .ROUNDING(ROUNDING), .SATURATE(SATURATE)
) demodulator_drive (
    .clk(clk), .rst(rst || switching), .ce(ce_1_reg), .adc(adc_drive),
    .ref_sin(drive_sin), .ref_cos(drive_cos), .i_out(i_drive), .q_out(q_drive), .out_valid()
);

gyrofx_demodulator #(
    .ADC_W(DEMOD_ADC_W), .ADC_F(DEMOD_ADC_F), .REF_W(DEMOD_REF_W), .REF_F(DEMOD_REF_F),
    .PROD_W(DEMOD_PROD_W), .PROD_F(DEMOD_PROD_F), .STATE_W(DEMOD_STATE_W),
    .STATE_F(DEMOD_STATE_F), .OUT_W(DEMOD_OUT_W), .OUT_F(DEMOD_OUT_F), .SHIFT(DEMOD_SHIFT),
    .ROUNDING(ROUNDING), .SATURATE(SATURATE)
) demodulator_sense (
    .clk(clk), .rst(rst || switching), .ce(ce_1_reg), .adc(adc_sense),
    .ref_sin(sense_sin), .ref_cos(sense_cos), .i_out(i_sense), .q_out(q_sense), .out_valid()
);
/* verilator lint_on PINCONNECTEMPTY */

// ---- stage 2: PLL, AGC, CICs -----------------------------------------------
wire signed [DEMOD_OUT_W-1:0] setpoint = mode_reg ? SETPOINT_N : SETPOINT_R;
wire signed [DEMOD_OUT_W:0] error_exact =
    {setpoint[DEMOD_OUT_W-1], setpoint} - {i_drive[DEMOD_OUT_W-1], i_drive};
wire signed [DEMOD_OUT_W-1:0] agc_error;

/* verilator lint_off PINCONNECTEMPTY */
gyrofx_quantize #(
    .IN_W(DEMOD_OUT_W + 1), .IN_F(DEMOD_OUT_F), .OUT_W(DEMOD_OUT_W), .OUT_F(DEMOD_OUT_F),
    .ROUNDING(ROUNDING), .SATURATE(SATURATE)
) quantize_agc_error (
    .in(error_exact), .out(agc_error), .overflow()
);
/* verilator lint_on PINCONNECTEMPTY */

wire signed [PLL_OUT_W-1:0] pll_out;
wire signed [AGC_OUT_W-1:0] amplitude;

/* verilator lint_off PINCONNECTEMPTY */
gyrofx_pi #(
    .ERR_W(PLL_ERR_W), .ERR_F(PLL_ERR_F), .KP_W(PLL_KP_W), .KP_F(PLL_KP_F),
    .KI_W(PLL_KI_W), .KI_F(PLL_KI_F), .INT_W(PLL_INT_W), .INT_F(PLL_INT_F),
    .OUT_W(PLL_OUT_W), .OUT_F(PLL_OUT_F), .KP(PLL_KP), .KI(PLL_KI),
    .INT_MIN(PLL_INT_MIN), .INT_MAX(PLL_INT_MAX), .ROUNDING(ROUNDING), .SATURATE(SATURATE)
) pll (
    .clk(clk), .rst(rst), .ce(ce_2_reg), .err(q_drive), .preset(switching),
    .preset_value(mode ? PLL_PRESET_N : PLL_PRESET_R), .u_out(pll_out), .out_valid()
);

gyrofx_pi #(
    .ERR_W(AGC_ERR_W), .ERR_F(AGC_ERR_F), .KP_W(AGC_KP_W), .KP_F(AGC_KP_F),
    .KI_W(AGC_KI_W), .KI_F(AGC_KI_F), .INT_W(AGC_INT_W), .INT_F(AGC_INT_F),
    .OUT_W(AGC_OUT_W), .OUT_F(AGC_OUT_F), .KP(AGC_KP), .KI(AGC_KI),
    .INT_MIN(AGC_INT_MIN), .INT_MAX(AGC_INT_MAX), .ROUNDING(ROUNDING), .SATURATE(SATURATE)
) agc (
    .clk(clk), .rst(rst || switching), .ce(ce_2_reg), .err(agc_error), .preset(1'b0),
    .preset_value({AGC_INT_W{1'b0}}), .u_out(amplitude), .out_valid()
);
/* verilator lint_on PINCONNECTEMPTY */

wire signed [CIC_OUT_W-1:0] cic_i;
wire signed [CIC_OUT_W-1:0] cic_q;
wire cic_valid;

/* verilator lint_off PINCONNECTEMPTY */
gyrofx_cic #(
    .IN_W(CIC_IN_W), .IN_F(CIC_IN_F), .STAGES(CIC_STAGES), .DECIMATION(CIC_DECIMATION),
    .DELAY(CIC_DELAY), .SHIFT(CIC_SHIFT), .MID_W(CIC_MID_W), .MID_F(CIC_MID_F),
    .TAPS(CIC_TAPS), .COEF_W(CIC_COEF_W), .COEF_F(CIC_COEF_F), .OUT_W(CIC_OUT_W),
    .OUT_F(CIC_OUT_F), .ROUNDING(ROUNDING), .SATURATE(SATURATE), .ROM_FILE(CIC_ROM_FILE)
) cic_in_phase (
    .clk(clk), .rst(rst), .ce(ce_2_reg), .x(i_sense), .y(cic_i), .y_valid(cic_valid)
);

gyrofx_cic #(
    .IN_W(CIC_IN_W), .IN_F(CIC_IN_F), .STAGES(CIC_STAGES), .DECIMATION(CIC_DECIMATION),
    .DELAY(CIC_DELAY), .SHIFT(CIC_SHIFT), .MID_W(CIC_MID_W), .MID_F(CIC_MID_F),
    .TAPS(CIC_TAPS), .COEF_W(CIC_COEF_W), .COEF_F(CIC_COEF_F), .OUT_W(CIC_OUT_W),
    .OUT_F(CIC_OUT_F), .ROUNDING(ROUNDING), .SATURATE(SATURATE), .ROM_FILE(CIC_ROM_FILE)
) cic_quadrature (
    .clk(clk), .rst(rst), .ce(ce_2_reg), .x(q_sense), .y(cic_q), .y_valid()
);
/* verilator lint_on PINCONNECTEMPTY */

// ---- stage 3: NCO word, DAC and its delay line, lock detector, outputs -----
wire signed [DRIVE_W-1:0] drive_exact = amplitude * transmit_cos;
wire signed [DAC_W-1:0] drive;

/* verilator lint_off PINCONNECTEMPTY */
gyrofx_quantize #(
    .IN_W(DRIVE_W), .IN_F(DRIVE_F), .OUT_W(DAC_W), .OUT_F(DAC_F),
    .ROUNDING(ROUNDING), .SATURATE(SATURATE)
) quantize_dac (
    .in(drive_exact), .out(drive), .overflow()
);
/* verilator lint_on PINCONNECTEMPTY */

// The DAC code of sample k is output at sample k + LATENCY; delay_reg[j] holds
// sample k-1-j's.
reg signed [DAC_W-1:0] delay_reg [0:DELAY_N-1];
wire signed [DAC_W-1:0] dac_now = LATENCY == 0 ? drive : delay_reg[DELAY_N-1];

// Lock filters: z <= z - floor(z / 2^LOCK_SHIFT) + e, exact in Z_W bits.
reg signed [Z_W-1:0] z_q_reg = {Z_W{1'b0}};
reg signed [Z_W-1:0] z_a_reg = {Z_W{1'b0}};
reg [31:0] lock_count_reg = 32'd0;
// (Signed operands only: one unsigned operand would make >>> a logical shift.)
wire signed [Z_W-1:0] q_wide = {{(Z_W-DEMOD_OUT_W){q_drive[DEMOD_OUT_W-1]}}, q_drive};
wire signed [Z_W-1:0] e_wide = {{(Z_W-DEMOD_OUT_W){agc_error[DEMOD_OUT_W-1]}}, agc_error};
wire signed [Z_W-1:0] z_q_next = z_q_reg - (z_q_reg >>> LOCK_SHIFT) + q_wide;
wire signed [Z_W-1:0] z_a_next = z_a_reg - (z_a_reg >>> LOCK_SHIFT) + e_wide;
// |z| < limit in 66 bits: wide enough for |z| (Z_W <= 64) and the 64-bit limits.
wire signed [65:0] z_q_wide = {{(66-Z_W){z_q_next[Z_W-1]}}, z_q_next};
wire signed [65:0] z_a_wide = {{(66-Z_W){z_a_next[Z_W-1]}}, z_a_next};
wire signed [65:0] z_q_abs = z_q_wide < 66'sd0 ? -z_q_wide : z_q_wide;
wire signed [65:0] z_a_abs = z_a_wide < 66'sd0 ? -z_a_wide : z_a_wide;
wire signed [63:0] lock_q = mode_reg ? LOCK_Q_N : LOCK_Q_R;
wire signed [63:0] lock_a = mode_reg ? LOCK_A_N : LOCK_A_R;
wire within_limits = z_q_abs < {{2{lock_q[63]}}, lock_q} && z_a_abs < {{2{lock_a[63]}}, lock_a};
wire [31:0] lock_hold = LOCK_HOLD;
wire [31:0] lock_count_next =
    within_limits ? (lock_count_reg >= lock_hold ? lock_hold : lock_count_reg + 32'd1) : 32'd0;

// Rate and quadrature, deg/s.
wire signed [COEF_W-1:0] rate_coef = mode_reg ? RATE_COEF_N : RATE_COEF_R;
wire signed [COEF_W-1:0] quad_coef = mode_reg ? QUAD_COEF_N : QUAD_COEF_R;
wire signed [RATE_W-1:0] rate_exact = rate_coef * cic_i;
wire signed [RATE_W-1:0] quad_exact = quad_coef * cic_q;
wire signed [OUT_W-1:0] rate_next;
wire signed [OUT_W-1:0] quad_next;

/* verilator lint_off PINCONNECTEMPTY */
gyrofx_quantize #(
    .IN_W(RATE_W), .IN_F(RATE_F), .OUT_W(OUT_W), .OUT_F(OUT_F),
    .ROUNDING(ROUNDING), .SATURATE(SATURATE)
) quantize_rate (
    .in(rate_exact), .out(rate_next), .overflow()
);

gyrofx_quantize #(
    .IN_W(RATE_W), .IN_F(RATE_F), .OUT_W(OUT_W), .OUT_F(OUT_F),
    .ROUNDING(ROUNDING), .SATURATE(SATURATE)
) quantize_quadrature (
    .in(quad_exact), .out(quad_next), .overflow()
);
/* verilator lint_on PINCONNECTEMPTY */

reg signed [DAC_W-1:0] dac_x_reg = {DAC_W{1'b0}};
reg signed [DAC_W-1:0] dac_y_reg = {DAC_W{1'b0}};
reg signed [OUT_W-1:0] rate_reg = {OUT_W{1'b0}};
reg signed [OUT_W-1:0] quad_reg = {OUT_W{1'b0}};
reg out_valid_reg = 1'b0;
reg locked_reg = 1'b0;

integer i;
integer j;
initial begin
    for (i = 0; i < DELAY_N; i = i + 1) begin
        delay_reg[i] = {DAC_W{1'b0}};
    end
end

always @(posedge clk) begin
    ce_1_reg <= ce;
    ce_2_reg <= ce_1_reg;
    ce_3_reg <= ce_2_reg;
    out_valid_reg <= 1'b0;

    if (ce) begin
        mode_reg <= mode;
        start_reg <= 1'b0;
        adc_x_reg <= adc_x;
        adc_y_reg <= adc_y;
    end
    if (switching) begin
        z_q_reg <= {Z_W{1'b0}};
        z_a_reg <= {Z_W{1'b0}};
        lock_count_reg <= 32'd0;
        for (j = 0; j < DELAY_N; j = j + 1) begin
            delay_reg[j] <= {DAC_W{1'b0}};
        end
    end

    if (ce_3_reg) begin
        freq_reg <= pll_out[NCO_PHASE_W-1:0];
        dac_x_reg <= mode_reg ? dac_now : {DAC_W{1'b0}};
        dac_y_reg <= mode_reg ? {DAC_W{1'b0}} : dac_now;
        delay_reg[0] <= drive;
        for (j = 1; j < DELAY_N; j = j + 1) begin
            delay_reg[j] <= delay_reg[j-1];
        end
        z_q_reg <= z_q_next;
        z_a_reg <= z_a_next;
        lock_count_reg <= lock_count_next;
        locked_reg <= lock_count_next >= lock_hold;
        if (cic_valid) begin
            rate_reg <= rate_next;
            quad_reg <= quad_next;
            out_valid_reg <= 1'b1;
        end
    end

    if (rst) begin
        mode_reg <= 1'b1;
        start_reg <= 1'b1;
        ce_1_reg <= 1'b0;
        ce_2_reg <= 1'b0;
        ce_3_reg <= 1'b0;
        freq_reg <= {NCO_PHASE_W{1'b0}};
        adc_x_reg <= {DEMOD_ADC_W{1'b0}};
        adc_y_reg <= {DEMOD_ADC_W{1'b0}};
        z_q_reg <= {Z_W{1'b0}};
        z_a_reg <= {Z_W{1'b0}};
        lock_count_reg <= 32'd0;
        for (j = 0; j < DELAY_N; j = j + 1) begin
            delay_reg[j] <= {DAC_W{1'b0}};
        end
        dac_x_reg <= {DAC_W{1'b0}};
        dac_y_reg <= {DAC_W{1'b0}};
        rate_reg <= {OUT_W{1'b0}};
        quad_reg <= {OUT_W{1'b0}};
        out_valid_reg <= 1'b0;
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
// Simulation only (yosys defines SYNTHESIS): the loop takes a sample at most every 4 clocks
// (gyrofx_job::pipeline); a sooner ce stops the simulation, naming this instance.
gyrofx_spacing_check #(
    .MIN_CLOCKS_PER_SAMPLE(4),
    .BLOCK_NAME("gyrofx_gyro_loop")
) spacing_check (
    .clk(clk),
    .rst(rst),
    .ce(ce)
);
`endif

endmodule

`resetall
