// Language: Verilog 2001

`resetall
`timescale 1ns / 1ps
`default_nettype none

/*
 * gyrofx_serial_engine — the time-multiplexed chain: one 16x16 signed multiplier,
 *   one column accumulator, a data RAM of 15-bit limbs, run by a program.
 *
 * Purpose: compute the calibration, the KF and the bias estimator of one sample
 *   exactly as gyrofx_model::chain::FixedChain does (same exact sums, same
 *   quantization points, same order), with a program that gyrofx derives from the
 *   config (PROGRAM_FILE, COEFFICIENT_FILE). Bit-exact with
 *   gyrofx_model::serial::Engine, which executes the same program.
 *
 * Values: every value is held as limbs of 15 bits in 16-bit RAM words, least
 *   significant first; low limbs zero-extended, the top limb sign-extended.
 *
 * Program word (WORD_W = 11 + ADDR_W + COEF_ADDR_W bits, most significant
 *   first): op (4), cond (4), ram_index (2), coefficient by bw_sel (1),
 *   address (ADDR_W), coefficient (COEF_ADDR_W). The opcodes and conditions are
 *   documented in gyrofx_model::serial::isa (docs/blocks/serial.md).
 *
 * Timing: each instruction takes 4 clocks (fetch, read RAM and coefficient,
 *   multiply, execute). On ce (when idle) the inputs and the sequencer's flags are
 *   captured (the samples not when CAPTURE_SAMPLES = 0) and the sample program runs from address 0 to its End: the outputs
 *   show 4 * (sample program length) clocks after the ce clock, out_valid for one
 *   clock. ce while busy is ignored. rst (synchronous, wins over ce) clears the
 *   outputs at once and stops a running program; the first sample after it runs
 *   the program's clearing instructions (condition "fresh") before it reads the
 *   state, so a ce may follow rst on the next clock.
 */
module gyrofx_serial_engine #(
    // gyro samples, rate output, bias outputs: widths
    parameter integer IN_W = 24,
    parameter integer OUT_W = 24,
    parameter integer BIAS_W = 28,
    // bw_sel and interval index widths
    parameter integer SEL_W = 2,
    parameter integer INTERVAL_W = 2,
    // column accumulator width (the largest column sum, signed; at least 17)
    parameter integer ACC_W = 32,
    // data RAM and coefficient ROM: address widths and words
    parameter integer ADDR_W = 6,
    parameter integer COEF_ADDR_W = 5,
    parameter integer RAM_DEPTH = 64,
    parameter integer COEF_DEPTH = 32,
    // program ROM words
    parameter integer PROGRAM_DEPTH = 512,
    // run-time indexes: interval << RAM_INDEX_SHIFT, bw_sel << COEF_INDEX_SHIFT
    parameter integer RAM_INDEX_SHIFT = 1,
    parameter integer COEF_INDEX_SHIFT = 2,
    // rounding: 0 floor, 1 ceil, 2 zero, 3 nearest, 4 round, 5 convergent
    parameter integer ROUNDING = 3,
    // ROM images for $readmemh
    parameter PROGRAM_FILE = "serial_program.mem",
    parameter COEFFICIENT_FILE = "serial_coefficients.mem",
    // 1: y_a, y_b and the flags captured at ce. 0: y_a, y_b read from the ports while the
    // program runs (the driver holds them from ce until out_valid; the flags are captured
    // either way)
    parameter integer CAPTURE_SAMPLES = 1,
    // 1: rate_out, bias_a, bias_b, estimated load at End and hold until the next End. 0: they
    // show the results as the program assembles them, final from End until the next
    // sample's program writes them (a driver that publishes them later keeps its own copy)
    parameter integer HOLD_RESULTS = 1
) (
    input  wire                     clk,
    input  wire                     rst,
    input  wire                     ce,
    input  wire [SEL_W-1:0]         bw_sel,
    input  wire signed [IN_W-1:0]   y_a,
    input  wire signed [IN_W-1:0]   y_b,
    input  wire                     mode_a,
    input  wire                     mode_b,
    input  wire                     blank_a,
    input  wire                     blank_b,
    input  wire                     done_a,
    input  wire                     done_b,
    input  wire                     window_done,
    input  wire [INTERVAL_W-1:0]    interval_a,
    input  wire [INTERVAL_W-1:0]    interval_b,
    output wire signed [OUT_W-1:0]  rate_out,
    output wire                     out_valid,
    output wire signed [BIAS_W-1:0] bias_a,
    output wire signed [BIAS_W-1:0] bias_b,
    output wire                     estimated,
    // high while a program runs (ce is ignored)
    output wire                     busy
);

localparam integer LIMB = 15;
localparam integer IN_LIMBS = (IN_W + LIMB - 1) / LIMB;
localparam integer RATE_LIMBS = (OUT_W + LIMB - 1) / LIMB;
localparam integer BIAS_LIMBS = (BIAS_W + LIMB - 1) / LIMB;
localparam integer WORD_W = 11 + ADDR_W + COEF_ADDR_W;
localparam integer PC_W = (PROGRAM_DEPTH > 2) ? $clog2(PROGRAM_DEPTH) : 1;
localparam integer PRODUCT_W = (ACC_W > 32) ? ACC_W : 32;

// Opcodes (gyrofx_model::serial::isa::Op).
localparam [3:0] OP_ZERO = 4'd0, OP_MAC = 4'd1, OP_MAC_INPUT = 4'd2, OP_EMIT = 4'd3,
                 OP_EMIT_TOP = 4'd4, OP_DROP = 4'd5, OP_DROP_HALF = 4'd6, OP_SIGN = 4'd7,
                 OP_ROUND = 4'd8, OP_HIGH = 4'd9, OP_FITS = 4'd10, OP_STORE_LOW = 4'd11,
                 OP_STORE_TOP = 4'd12, OP_OUT = 4'd13, OP_SET_ESTIMATED = 4'd14,
                 OP_END = 4'd15;

initial begin
    if (ACC_W < 17 || ADDR_W <= INTERVAL_W || COEF_ADDR_W <= SEL_W) begin
        $display("%m: ACC_W (%0d) must be at least 17, ADDR_W (%0d) exceed INTERVAL_W (%0d), COEF_ADDR_W (%0d) exceed SEL_W (%0d)",
                 ACC_W, ADDR_W, INTERVAL_W, COEF_ADDR_W, SEL_W);
        $finish;
    end
end

reg [WORD_W-1:0] program_rom [0:PROGRAM_DEPTH-1];
reg [15:0] coefficient_rom [0:COEF_DEPTH-1];
// Read and written at one address every instruction, but the word read in the clock that
// writes it (phase 3) is never used (the next instruction reads again in its phase 1), so the
// block RAM needs no read-first bypass.
(* no_rw_check *)
reg [15:0] ram [0:RAM_DEPTH-1];
integer k;
initial begin
    $readmemh(PROGRAM_FILE, program_rom);
    $readmemh(COEFFICIENT_FILE, coefficient_rom);
    for (k = 0; k < RAM_DEPTH; k = k + 1) ram[k] = 16'h0000;
end

// Sequencing.
reg running = 1'b0;
reg [1:0] phase = 2'd0;
reg [PC_W-1:0] pc = {PC_W{1'b0}};
reg [WORD_W-1:0] instruction = {WORD_W{1'b0}};

// The sample, captured at ce.
reg signed [LIMB*IN_LIMBS-1:0] y_a_reg = {LIMB*IN_LIMBS{1'b0}};
reg signed [LIMB*IN_LIMBS-1:0] y_b_reg = {LIMB*IN_LIMBS{1'b0}};
reg [SEL_W-1:0] bw_sel_reg = {SEL_W{1'b0}};
reg [INTERVAL_W-1:0] interval_a_reg = {INTERVAL_W{1'b0}};
reg [INTERVAL_W-1:0] interval_b_reg = {INTERVAL_W{1'b0}};
reg valid_a = 1'b0;
reg valid_b = 1'b0;
reg done_a_reg = 1'b0;
reg done_b_reg = 1'b0;
reg window_reg = 1'b0;
reg mode_a_reg = 1'b0;
reg mode_b_reg = 1'b0;

// Datapath.
reg signed [ACC_W-1:0] acc = {ACC_W{1'b0}};
reg signed [15:0] a_word = 16'sd0;
reg signed [15:0] b_word = 16'sd0;
reg signed [15:0] input_word = 16'sd0;
// No initial value, as the multiplier block's output register has none (yosys folds only such
// a register into it): it loads every clock, three before it is first read.
reg signed [31:0] product;
reg half = 1'b0;
reg sticky = 1'b0;
reg negative = 1'b0;
reg high_zero = 1'b1;
reg high_ones = 1'b1;
reg fits = 1'b0;
reg estimated_state = 1'b0;
// No sample since reset: the program clears the state first.
reg fresh = 1'b1;

// Outputs: shifted in limb by limb, shown at End.
reg [LIMB*RATE_LIMBS-1:0] rate_shadow = {LIMB*RATE_LIMBS{1'b0}};
reg [LIMB*BIAS_LIMBS-1:0] bias_a_shadow = {LIMB*BIAS_LIMBS{1'b0}};
reg [LIMB*BIAS_LIMBS-1:0] bias_b_shadow = {LIMB*BIAS_LIMBS{1'b0}};
reg signed [OUT_W-1:0] rate_reg = {OUT_W{1'b0}};
reg signed [BIAS_W-1:0] bias_a_reg = {BIAS_W{1'b0}};
reg signed [BIAS_W-1:0] bias_b_reg = {BIAS_W{1'b0}};
reg estimated_reg = 1'b0;
reg valid_reg = 1'b0;

// Instruction fields.
wire [3:0] op = instruction[WORD_W-1 -: 4];
wire [3:0] cond = instruction[WORD_W-5 -: 4];
wire [1:0] ram_index = instruction[WORD_W-9 -: 2];
wire by_bw_sel = instruction[WORD_W-11];
wire [ADDR_W-1:0] address_field = instruction[COEF_ADDR_W +: ADDR_W];
wire [COEF_ADDR_W-1:0] coefficient_field = instruction[0 +: COEF_ADDR_W];

wire [ADDR_W-1:0] index_value = (ram_index == 2'd1) ? {{(ADDR_W-INTERVAL_W){1'b0}}, interval_a_reg} :
                                (ram_index == 2'd2) ? {{(ADDR_W-INTERVAL_W){1'b0}}, interval_b_reg} :
                                {ADDR_W{1'b0}};
wire [ADDR_W-1:0] ram_address = address_field + (index_value << RAM_INDEX_SHIFT);
wire [COEF_ADDR_W-1:0] select_value = by_bw_sel ? {{(COEF_ADDR_W-SEL_W){1'b0}}, bw_sel_reg}
                                                : {COEF_ADDR_W{1'b0}};
wire [COEF_ADDR_W-1:0] coefficient_address = coefficient_field + (select_value << COEF_INDEX_SHIFT);

// The samples sign-extended to whole limbs.
wire signed [LIMB*IN_LIMBS-1:0] y_a_ext;
wire signed [LIMB*IN_LIMBS-1:0] y_b_ext;
generate
    if (LIMB * IN_LIMBS > IN_W) begin : g_extend
        assign y_a_ext = {{(LIMB*IN_LIMBS-IN_W){y_a[IN_W-1]}}, y_a};
        assign y_b_ext = {{(LIMB*IN_LIMBS-IN_W){y_b[IN_W-1]}}, y_b};
    end else begin : g_whole
        assign y_a_ext = y_a;
        assign y_b_ext = y_b;
    end
endgenerate

// The samples the program reads: captured at ce, or the ports themselves.
wire signed [LIMB*IN_LIMBS-1:0] y_a_sample = CAPTURE_SAMPLES != 0 ? y_a_reg : y_a_ext;
wire signed [LIMB*IN_LIMBS-1:0] y_b_sample = CAPTURE_SAMPLES != 0 ? y_b_reg : y_b_ext;

// Input limbs: y_a's, then y_b's (the top ones sign-extended).
integer j;
always @* begin
    input_word = 16'sd0;
    for (j = 0; j < IN_LIMBS; j = j + 1) begin
        if (address_field == j[ADDR_W-1:0]) begin
            input_word = (j == IN_LIMBS - 1) ? {y_a_sample[LIMB*j+LIMB-1], y_a_sample[LIMB*j +: LIMB]}
                                             : {1'b0, y_a_sample[LIMB*j +: LIMB]};
        end
        if (address_field == j[ADDR_W-1:0] + IN_LIMBS[ADDR_W-1:0]) begin
            input_word = (j == IN_LIMBS - 1) ? {y_b_sample[LIMB*j+LIMB-1], y_b_sample[LIMB*j +: LIMB]}
                                             : {1'b0, y_b_sample[LIMB*j +: LIMB]};
        end
    end
end

reg holds;
always @* begin
    case (cond)
        4'd0: holds = 1'b1;
        4'd1: holds = valid_a;
        4'd2: holds = valid_b;
        4'd3: holds = done_a_reg;
        4'd4: holds = done_b_reg;
        4'd5: holds = window_reg;
        4'd6: holds = mode_a_reg;
        4'd7: holds = ~mode_a_reg;
        4'd8: holds = mode_b_reg;
        4'd9: holds = ~mode_b_reg;
        4'd10: holds = valid_a & valid_b;
        4'd11: holds = valid_a & ~valid_b;
        4'd12: holds = ~valid_a & valid_b;
        4'd13: holds = valid_a | valid_b;
        4'd14: holds = window_reg & estimated_state;
        default: holds = fresh;
    endcase
end

// The rounding increment from the dropped bits, the sign and the quotient's LSB.
reg increment;
always @* begin
    case (ROUNDING)
        1: increment = half | sticky;
        2: increment = (half | sticky) & negative;
        3: increment = half;
        4: increment = half & (sticky | ~negative);
        5: increment = half & (sticky | acc[0]);
        default: increment = 1'b0;
    endcase
end

wire [LIMB-1:0] low = acc[LIMB-1:0];
wire signed [ACC_W-1:0] shifted = acc >>> LIMB;
// An accumulator narrower than 32 bits (a config's ACC_W) leaves the product's top bits unread.
/* verilator lint_off UNUSEDSIGNAL */
wire signed [PRODUCT_W-1:0] product_wide = product;
/* verilator lint_on UNUSEDSIGNAL */
wire signed [ACC_W-1:0] addend = (op == OP_ROUND) ? {{(ACC_W-1){1'b0}}, increment}
                                                  : product_wide[ACC_W-1:0];
wire execute = running && phase == 2'd3;
wire signed [15:0] a_operand = (op == OP_MAC_INPUT) ? input_word : a_word;
// An output register with the RAM word's limb shifted in from the top.
// (Its lowest limb drops out.)
/* verilator lint_off UNUSEDSIGNAL */
wire [LIMB*(RATE_LIMBS+1)-1:0] rate_next = {a_word[LIMB-1:0], rate_shadow};
wire [LIMB*(BIAS_LIMBS+1)-1:0] bias_a_next = {a_word[LIMB-1:0], bias_a_shadow};
wire [LIMB*(BIAS_LIMBS+1)-1:0] bias_b_next = {a_word[LIMB-1:0], bias_b_shadow};
/* verilator lint_on UNUSEDSIGNAL */
wire act = execute && holds;

reg write_enable;
reg [15:0] write_data;
always @* begin
    write_enable = 1'b0;
    write_data = {1'b0, low};
    case (op)
        OP_EMIT: write_enable = act;
        OP_EMIT_TOP: begin
            write_enable = act;
            write_data = {low[LIMB-1], low};
        end
        OP_STORE_LOW: begin
            write_enable = act;
            if (!fits) write_data = negative ? 16'h0000 : 16'h7fff;
        end
        OP_STORE_TOP: begin
            write_enable = act;
            write_data = fits ? {low[LIMB-1], low} : (negative ? ~b_word : b_word);
        end
        default: write_enable = 1'b0;
    endcase
end

// Memories: registered reads on every clock (the fields are steady from phase 1 on).
always @(posedge clk) begin
    instruction <= program_rom[pc];
    b_word <= coefficient_rom[coefficient_address];
    a_word <= ram[ram_address];
    if (write_enable) ram[ram_address] <= write_data;
    product <= a_operand * b_word;
end

always @(posedge clk) begin
    valid_reg <= 1'b0;
    if (running) phase <= phase + 2'd1;
    if (!running && ce) begin
        running <= 1'b1;
        phase <= 2'd0;
        pc <= {PC_W{1'b0}};
        y_a_reg <= y_a_ext;
        y_b_reg <= y_b_ext;
        bw_sel_reg <= bw_sel;
        interval_a_reg <= interval_a;
        interval_b_reg <= interval_b;
        valid_a <= ~blank_a;
        valid_b <= ~blank_b;
        done_a_reg <= done_a;
        done_b_reg <= done_b;
        window_reg <= window_done;
        mode_a_reg <= mode_a;
        mode_b_reg <= mode_b;
    end
    if (execute) begin
        // End keeps pc on itself: the idle engine fetches no word past the program.
        if (op != OP_END) pc <= pc + {{(PC_W-1){1'b0}}, 1'b1};
        if (op == OP_END) begin
            running <= 1'b0;
            fresh <= 1'b0;
            if (valid_a | valid_b) rate_reg <= rate_shadow[OUT_W-1:0];
            bias_a_reg <= bias_a_shadow[BIAS_W-1:0];
            bias_b_reg <= bias_b_shadow[BIAS_W-1:0];
            estimated_reg <= estimated_state;
            valid_reg <= valid_a | valid_b;
        end
    end
    if (act) begin
        case (op)
            OP_ZERO: begin
                acc <= {ACC_W{1'b0}};
                half <= 1'b0;
                sticky <= 1'b0;
                high_zero <= 1'b1;
                high_ones <= 1'b1;
            end
            OP_MAC, OP_MAC_INPUT, OP_ROUND: acc <= acc + addend;
            OP_EMIT, OP_EMIT_TOP, OP_STORE_LOW, OP_STORE_TOP: acc <= shifted;
            OP_DROP: begin
                sticky <= sticky | (|low);
                acc <= shifted;
            end
            OP_DROP_HALF: begin
                half <= low[LIMB-1];
                sticky <= sticky | (|low[LIMB-2:0]);
                acc <= shifted;
            end
            OP_SIGN: negative <= a_word[15];
            OP_HIGH: begin
                high_zero <= high_zero & ~(|low);
                high_ones <= high_ones & (&low);
                acc <= shifted;
            end
            OP_FITS: fits <= ((acc == {ACC_W{1'b0}}) && high_zero) ||
                             ((acc == {ACC_W{1'b1}}) && high_ones);
            OP_OUT: begin
                case (coefficient_field[1:0])
                    2'd0: rate_shadow <= rate_next[LIMB*(RATE_LIMBS+1)-1:LIMB];
                    2'd1: bias_a_shadow <= bias_a_next[LIMB*(BIAS_LIMBS+1)-1:LIMB];
                    default: bias_b_shadow <= bias_b_next[LIMB*(BIAS_LIMBS+1)-1:LIMB];
                endcase
            end
            OP_SET_ESTIMATED: estimated_state <= 1'b1;
            default: ;
        endcase
    end
    if (rst) begin
        running <= 1'b0;
        fresh <= 1'b1;
        rate_shadow <= {LIMB*RATE_LIMBS{1'b0}};
        bias_a_shadow <= {LIMB*BIAS_LIMBS{1'b0}};
        bias_b_shadow <= {LIMB*BIAS_LIMBS{1'b0}};
        rate_reg <= {OUT_W{1'b0}};
        bias_a_reg <= {BIAS_W{1'b0}};
        bias_b_reg <= {BIAS_W{1'b0}};
        estimated_state <= 1'b0;
        estimated_reg <= 1'b0;
        valid_reg <= 1'b0;
    end
end

assign rate_out = HOLD_RESULTS != 0 ? rate_reg : rate_shadow[OUT_W-1:0];
assign out_valid = valid_reg;
assign bias_a = HOLD_RESULTS != 0 ? bias_a_reg : bias_a_shadow[BIAS_W-1:0];
assign bias_b = HOLD_RESULTS != 0 ? bias_b_reg : bias_b_shadow[BIAS_W-1:0];
assign estimated = HOLD_RESULTS != 0 ? estimated_reg : estimated_state;
assign busy = running;

endmodule

`resetall
