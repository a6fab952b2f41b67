-- Language: VHDL-2008

-- gyrofx_gyro_pair_serial — gyro A's and gyro B's loops of gyrofx_gyro_loop on one folded
-- datapath: one multiplier, one accumulator and one RAM under one schedule, for the two-gyro
-- system on a small FPGA (gyrofx_system_serial).
--
-- Purpose: the VHDL twin of gyrofx_gyro_pair_serial.v (same generics, ports, ROM images,
--   schedule and timing, clock by clock): each gyro's loop bit for bit
--   (gyrofx_model::gyro_loop::FixedGyroLoop: the same DAC codes and lock flags every sample,
--   the same decimated rate and quadrature), in about the logic of one folded loop
--   (gyrofx_gyro_loop_serial). The schedule is gyrofx_model::gyro_loop::folded::Schedule::pair,
--   proven clock by clock by FoldedPair.
--
-- Datapath: gyrofx_gyro_loop_serial's, shared by the gyros. Each gyro has its own mode, NCO
--   (accumulator, frequency word, truncation errors), Q_D, e_A and amplitude registers, DAC
--   codes and their delay line, lock filter check and count, rate and quadrature, and its own
--   RAM words; each unit of a control word (the sine ROM read, the NCO advance, the
--   multiplier's issue, the accumulator, the RAM read's gate, the quantization point) works on
--   the gyro its field of the word names (bits 57 to 62). The datapath's other registers are
--   shared; the schedule keeps their values apart. Here each gyro's registers are an array
--   indexed by the gyro (0 A, 1 B), the Verilog's _a and _b registers.
--
-- Schedule: every sample runs both gyros' regular part (SCHEDULE_REGULAR words). The
--   decimating sample (every CIC_DECIMATION-th) also copies each CIC's last integrator to a
--   RAM word (writes marked decimating-only, bit 63); the combs, the compensators (partial
--   sums in RAM) and the 1/SF products follow in SCHEDULE_SEGMENTS segments of
--   SCHEDULE_LEN - SCHEDULE_REGULAR words, one in each of the next samples, after the regular
--   part. The schedule ROM holds the regular part, then the segments.
--
-- Pipeline: ce takes the sample (inputs, modes, switch clears); a word acts two clocks after
--   it is fetched (the clock between decodes the accumulator's operands from it). dac_*,
--   locked_* load at the schedule's DAC and lock words; decimating pulses for one clock after
--   the last word of a decimating sample, out_valid after the last word of the sample whose
--   segment completes the decimated outputs (SCHEDULE_SEGMENTS samples later), with rate_a,
--   quadrature_a, rate_b, quadrature_b loaded (the 1/SF of the mode each gyro's decimating
--   sample was taken in). The next ce may come SCHEDULE_LEN + 2 clocks after ce
--   (gyrofx_job::pipeline). A clock with rst high stops the schedule and clears every
--   register a sample reads before it loads it; the RAM keeps its words, which the read gates
--   ignore until they are written again (as in the Verilog, the control word, the decoded
--   operands, the sine ROM's, the multiplier's and the RAM's read registers and the segment's
--   ROM addresses are not cleared: nothing reads them before the schedule loads them again).
--
-- ROMs: NCO_ROM_FILE (quarter-wave sine), CIC_ROM_FILE (compensator taps), SCHEDULE_FILE
--   (SCHEDULE_REGULAR + SCHEDULE_SEGMENTS * (SCHEDULE_LEN - SCHEDULE_REGULAR) control words
--   of 64 bits, one 16-digit hex word a line), read by gyrofx_mem_pkg at elaboration, which
--   wants at least that many words in each file and reads the first ones (as $readmemh into
--   the Verilog's array). A schedule or tap address beyond its ROM's words and a RAM address
--   beyond RAM_WORDS read zero, and a RAM write there is dropped (the Verilog model reads X):
--   a schedule from gyrofx makes no such access. The RAM and every register start at zero
--   (the Verilog model's products and RAM read register hold X until they first load).

library ieee;
use ieee.std_logic_1164.all;
use ieee.numeric_std.all;

use work.gyrofx_mem_pkg.all;

entity gyrofx_gyro_pair_serial is
    generic (
        -- NCOs: phase bits, quarter-wave ROM address bits, sine width, truncation error feedback
        NCO_PHASE_W : positive := 32;
        NCO_ADDR_W : positive := 10;
        NCO_SIN_W : positive := 18;
        NCO_ERROR_FEEDBACK : natural := 1;
        -- demodulators (all): ADC, reference, product, state and output formats, low-pass shift
        DEMOD_ADC_W : positive := 24;
        DEMOD_ADC_F : integer := 23;
        DEMOD_REF_W : positive := 18;
        DEMOD_REF_F : integer := 17;
        DEMOD_PROD_W : positive := 36;
        DEMOD_PROD_F : integer := 34;
        DEMOD_STATE_W : positive := 44;
        DEMOD_STATE_F : integer := 42;
        DEMOD_OUT_W : positive := 32;
        DEMOD_OUT_F : integer := 30;
        DEMOD_SHIFT : positive := 8;
        -- PLLs: error, gains, integrator and output formats (both gyros)
        PLL_ERR_W : positive := 32;
        PLL_ERR_F : integer := 30;
        PLL_KP_W : positive := 18;
        PLL_KP_F : integer := 27;
        PLL_KI_W : positive := 18;
        PLL_KI_F : integer := 38;
        PLL_INT_W : positive := 40;
        PLL_INT_F : integer := 38;
        PLL_OUT_W : positive := 32;
        PLL_OUT_F : integer := 32;
        -- AGCs: error, gains, integrator and output formats (both gyros)
        AGC_ERR_W : positive := 32;
        AGC_ERR_F : integer := 30;
        AGC_KP_W : positive := 18;
        AGC_KP_F : integer := 1;
        AGC_KI_W : positive := 18;
        AGC_KI_F : integer := 11;
        AGC_INT_W : positive := 40;
        AGC_INT_F : integer := 20;
        AGC_OUT_W : positive := 24;
        AGC_OUT_F : integer := 6;
        -- CICs (all): input, stages, decimation, delay, shift, scaled output, taps, output
        CIC_IN_W : positive := 32;
        CIC_IN_F : integer := 30;
        CIC_STAGES : positive := 3;
        CIC_DECIMATION : positive := 1000;
        CIC_DELAY : positive := 1;
        CIC_SHIFT : natural := 30;
        CIC_MID_W : positive := 40;
        CIC_MID_F : integer := 38;
        CIC_TAPS : positive := 5;
        CIC_COEF_W : positive := 18;
        CIC_COEF_F : integer := 16;
        CIC_OUT_W : positive := 32;
        CIC_OUT_F : integer := 30;
        -- DAC codes, rate/quadrature output (deg/s) and the 1/SF coefficients' format
        DAC_W : positive := 18;
        DAC_F : integer := 0;
        OUT_W : positive := 24;
        OUT_F : integer := 14;
        COEF_W : positive := 24;
        COEF_F : integer := 6;
        -- ADC-to-DAC latency, samples (0..8)
        LATENCY : natural := 1;
        -- lock detectors: filter shift and the samples both errors must stay inside
        LOCK_SHIFT : positive := 9;
        LOCK_HOLD : natural := 2000;
        -- gyro A: PI gains and integrator limits; per mode (_N normal, _R reverse) the AGC
        -- setpoint, nominal NCO word and PLL preset, DAC and sense reference offsets, 1/SF of
        -- the rate and quadrature, lock limits (as gyrofx_gyro_loop's generics of those names)
        A_PLL_KP : std_logic_vector := 18x"10625";
        A_PLL_KI : std_logic_vector := 18x"17795";
        A_PLL_INT_MIN : std_logic_vector := 40x"292cd0c7b";
        A_PLL_INT_MAX : std_logic_vector := 40x"2a786ac8d";
        A_AGC_KP : std_logic_vector := 18x"19a9a";
        A_AGC_KI : std_logic_vector := 18x"12624";
        A_AGC_INT_MIN : std_logic_vector := 40x"0";
        A_AGC_INT_MAX : std_logic_vector := 40x"1ffff00000";
        A_SETPOINT_N : std_logic_vector := 32x"cccc666";
        A_SETPOINT_R : std_logic_vector := 32x"cccc666";
        A_FREQ_WORD_N : std_logic_vector := 32x"a7d5617";
        A_FREQ_WORD_R : std_logic_vector := 32x"a6bf8ce";
        A_PLL_PRESET_N : std_logic_vector := 40x"29f5585a4";
        A_PLL_PRESET_R : std_logic_vector := 40x"29afe3365";
        A_DAC_OFFSET_N : std_logic_vector := 32x"fd38ab7";
        A_DAC_OFFSET_R : std_logic_vector := 32x"fbb6e38";
        A_SENSE_OFFSET_N : std_logic_vector := 32x"4f56436e";
        A_SENSE_OFFSET_R : std_logic_vector := 32x"afd6e2bb";
        A_RATE_COEF_N : std_logic_vector := 24x"63db80";
        A_RATE_COEF_R : std_logic_vector := 24x"9aa98a";
        A_QUAD_COEF_N : std_logic_vector := 24x"9c2480";
        A_QUAD_COEF_R : std_logic_vector := 24x"9aa98a";
        A_LOCK_Q_N : std_logic_vector := 64x"b70271b";
        A_LOCK_Q_R : std_logic_vector := 64x"b70271b";
        A_LOCK_A_N : std_logic_vector := 64x"68db574";
        A_LOCK_A_R : std_logic_vector := 64x"68db574";
        -- gyro B: the same
        B_PLL_KP : std_logic_vector := 18x"10625";
        B_PLL_KI : std_logic_vector := 18x"17795";
        B_PLL_INT_MIN : std_logic_vector := 40x"292cd0c7b";
        B_PLL_INT_MAX : std_logic_vector := 40x"2a786ac8d";
        B_AGC_KP : std_logic_vector := 18x"19a9a";
        B_AGC_KI : std_logic_vector := 18x"12624";
        B_AGC_INT_MIN : std_logic_vector := 40x"0";
        B_AGC_INT_MAX : std_logic_vector := 40x"1ffff00000";
        B_SETPOINT_N : std_logic_vector := 32x"cccc666";
        B_SETPOINT_R : std_logic_vector := 32x"cccc666";
        B_FREQ_WORD_N : std_logic_vector := 32x"a7d5617";
        B_FREQ_WORD_R : std_logic_vector := 32x"a6bf8ce";
        B_PLL_PRESET_N : std_logic_vector := 40x"29f5585a4";
        B_PLL_PRESET_R : std_logic_vector := 40x"29afe3365";
        B_DAC_OFFSET_N : std_logic_vector := 32x"fd38ab7";
        B_DAC_OFFSET_R : std_logic_vector := 32x"fbb6e38";
        B_SENSE_OFFSET_N : std_logic_vector := 32x"4f56436e";
        B_SENSE_OFFSET_R : std_logic_vector := 32x"afd6e2bb";
        B_RATE_COEF_N : std_logic_vector := 24x"63db80";
        B_RATE_COEF_R : std_logic_vector := 24x"9aa98a";
        B_QUAD_COEF_N : std_logic_vector := 24x"9c2480";
        B_QUAD_COEF_R : std_logic_vector := 24x"9aa98a";
        B_LOCK_Q_N : std_logic_vector := 64x"b70271b";
        B_LOCK_Q_R : std_logic_vector := 64x"b70271b";
        B_LOCK_A_N : std_logic_vector := 64x"68db574";
        B_LOCK_A_R : std_logic_vector := 64x"68db574";
        -- rounding: 0 floor, 1 ceil, 2 zero, 3 nearest, 4 round, 5 convergent
        ROUNDING : natural := 3;
        -- overflow: 0 wrap, 1 saturate
        SATURATE : natural := 1;
        -- ROM images (hex, one word per line)
        NCO_ROM_FILE : string := "gyro_loop_nco_sine.mem";
        CIC_ROM_FILE : string := "gyro_loop_cic_taps.mem";
        -- the schedule: image, words of the longest sample, of the regular part, deferred
        -- segments, RAM words
        SCHEDULE_FILE : string := "gyro_pair_schedule.mem";
        SCHEDULE_LEN : positive := 117;
        SCHEDULE_REGULAR : positive := 103;
        SCHEDULE_SEGMENTS : positive := 13;
        RAM_WORDS : positive := 64
    );
    port (
        clk          : in  std_logic;
        rst          : in  std_logic;
        ce           : in  std_logic;
        -- gyro g's mode ('1' normal: drive x, sense y; '0' reverse) and ADC codes
        mode_a       : in  std_logic;
        mode_b       : in  std_logic;
        adc_a_x      : in  signed(DEMOD_ADC_W - 1 downto 0);
        adc_a_y      : in  signed(DEMOD_ADC_W - 1 downto 0);
        adc_b_x      : in  signed(DEMOD_ADC_W - 1 downto 0);
        adc_b_y      : in  signed(DEMOD_ADC_W - 1 downto 0);
        dac_a_x      : out signed(DAC_W - 1 downto 0);
        dac_a_y      : out signed(DAC_W - 1 downto 0);
        dac_b_x      : out signed(DAC_W - 1 downto 0);
        dac_b_y      : out signed(DAC_W - 1 downto 0);
        locked_a     : out std_logic;
        locked_b     : out std_logic;
        -- a decimating sample's last word has acted (one clock): the parallel loops' outputs
        -- come in this sample
        decimating   : out std_logic;
        -- both gyros' decimated outputs, valid with out_valid (one clock)
        rate_a       : out signed(OUT_W - 1 downto 0);
        quadrature_a : out signed(OUT_W - 1 downto 0);
        rate_b       : out signed(OUT_W - 1 downto 0);
        quadrature_b : out signed(OUT_W - 1 downto 0);
        out_valid    : out std_logic
    );
end entity;

architecture rtl of gyrofx_gyro_pair_serial is

    -- `bits` as a code of `width` bits; another length stops the elaboration.
    function code_of(name : string; bits : std_logic_vector; width : positive)
        return std_logic_vector is
        variable result : std_logic_vector(width - 1 downto 0) := (others => '0');
    begin
        assert bits'length = width
            report "gyrofx_gyro_pair_serial: " & name & " has " & integer'image(bits'length)
                & " bits; " & integer'image(width) & " are needed"
            severity failure;
        if bits'length = width then
            result := bits;
        end if;
        return result;
    end function;

    -- The largest of `values` (the Verilog's nested max2).
    function largest(values : integer_vector) return integer is
        variable result : integer := values(values'left);
    begin
        for i in values'range loop
            result := maximum(result, values(i));
        end loop;
        return result;
    end function;

    -- value shifted left by amount, or right by -amount (exact where used: the low bits
    -- shifted out are zeros).
    function shifted(value : signed; amount : integer) return signed is
    begin
        if amount >= 0 then
            return shift_left(value, amount);
        else
            return shift_right(value, -amount);
        end if;
    end function;

    -- ceil(log2(value)), 0 for value 1.
    function ceil_log2(value : positive) return natural is
        variable bits : natural := 0;
    begin
        while 2 ** bits < value loop
            bits := bits + 1;
        end loop;
        return bits;
    end function;

    -- ceil(log2(rm^stage_count)), exact (gyrofx_cic's register growth).
    function growth_bits(stage_count : positive; rm : positive) return natural is
        variable gain : unsigned(255 downto 0) := to_unsigned(1, 256);
        variable bound : unsigned(255 downto 0) := to_unsigned(1, 256);
        variable bits : natural := 0;
    begin
        for s in 1 to stage_count loop
            gain := resize(gain * to_unsigned(rm, 32), 256);
        end loop;
        while bound < gain loop
            bound := shift_left(bound, 1);
            bits := bits + 1;
        end loop;
        return bits;
    end function;

    -- Clocks a width-bit signed operand takes: 15-bit limbs, the top one up to 16 bits signed.
    function limbs(width : positive) return positive is
    begin
        return maximum((width - 1 + 14) / 15, 1);
    end function;

    -- A gyro's index from its field bit: 0 gyro A, 1 gyro B.
    function gyro_of(bit : std_logic) return natural is
    begin
        if bit = '1' then
            return 1;
        end if;
        return 0;
    end function;

    -- Gyro g's field bit.
    constant GYRO_BIT : std_logic_vector(0 to 1) := "01";

    -- The index of a (gyro, mode) pair in a constant of four (the Verilog's gyro_mode order):
    -- 0 A normal, 1 A reverse, 2 B normal, 3 B reverse.
    function gyro_mode(gyro : std_logic; mode : std_logic) return natural is
    begin
        if mode = '1' then
            return 2 * gyro_of(gyro);
        end if;
        return 2 * gyro_of(gyro) + 1;
    end function;

    -- ---- the exact formats of the parallel loop's points (its blocks' constants) ----
    -- demodulator: 2 * adc * ref, the low-pass update
    constant X_W : positive := DEMOD_ADC_W + DEMOD_REF_W;
    constant X_F : integer := DEMOD_ADC_F + DEMOD_REF_F - 1;
    constant U_W : positive := DEMOD_STATE_W + DEMOD_SHIFT + 1;
    constant U_F : integer := DEMOD_STATE_F + DEMOD_SHIFT;
    constant DEMOD_ALIGN : integer := DEMOD_STATE_F - DEMOD_PROD_F;
    -- AGC error: setpoint - I
    constant EA_W : positive := DEMOD_OUT_W + 1;
    -- PI (gyrofx_pi): v + ki * e at UPD_F, kp * e + v at SUM_F
    constant PLL_INT_I : integer := PLL_INT_W - PLL_INT_F;
    constant PLL_KIE_W : positive := PLL_KI_W + PLL_ERR_W;
    constant PLL_KIE_F : integer := PLL_KI_F + PLL_ERR_F;
    constant PLL_UPD_F : integer := maximum(PLL_INT_F, PLL_KIE_F);
    constant PLL_UPD_W : positive := maximum(PLL_INT_I, PLL_KIE_W - PLL_KIE_F) + 1 + PLL_UPD_F;
    constant PLL_RND_W : positive := maximum(PLL_INT_I, PLL_KIE_W - PLL_KIE_F) + 2 + PLL_INT_F;
    constant PLL_KPE_W : positive := PLL_KP_W + PLL_ERR_W;
    constant PLL_KPE_F : integer := PLL_KP_F + PLL_ERR_F;
    constant PLL_SUM_F : integer := maximum(PLL_INT_F, PLL_KPE_F);
    constant PLL_SUM_W : positive := maximum(PLL_INT_I, PLL_KPE_W - PLL_KPE_F) + 1 + PLL_SUM_F;
    constant AGC_INT_I : integer := AGC_INT_W - AGC_INT_F;
    constant AGC_KIE_W : positive := AGC_KI_W + AGC_ERR_W;
    constant AGC_KIE_F : integer := AGC_KI_F + AGC_ERR_F;
    constant AGC_UPD_F : integer := maximum(AGC_INT_F, AGC_KIE_F);
    constant AGC_UPD_W : positive := maximum(AGC_INT_I, AGC_KIE_W - AGC_KIE_F) + 1 + AGC_UPD_F;
    constant AGC_RND_W : positive := maximum(AGC_INT_I, AGC_KIE_W - AGC_KIE_F) + 2 + AGC_INT_F;
    constant AGC_KPE_W : positive := AGC_KP_W + AGC_ERR_W;
    constant AGC_KPE_F : integer := AGC_KP_F + AGC_ERR_F;
    constant AGC_SUM_F : integer := maximum(AGC_INT_F, AGC_KPE_F);
    constant AGC_SUM_W : positive := maximum(AGC_INT_I, AGC_KPE_W - AGC_KPE_F) + 1 + AGC_SUM_F;
    -- DAC: amplitude * cos
    constant DRIVE_W : positive := AGC_OUT_W + NCO_SIN_W;
    constant DRIVE_F : integer := AGC_OUT_F + NCO_SIN_W - 1;
    -- CIC (gyrofx_cic): registers, the compensator's sum
    constant REG_W : positive := CIC_IN_W + growth_bits(CIC_STAGES, CIC_DECIMATION * CIC_DELAY);
    constant FIR_W : positive := CIC_MID_W + CIC_COEF_W + ceil_log2(CIC_TAPS);
    constant FIR_F : integer := CIC_MID_F + CIC_COEF_F;
    -- rate and quadrature: 1/SF * CIC output
    constant RATE_W : positive := CIC_OUT_W + COEF_W;
    constant RATE_F : integer := CIC_OUT_F + COEF_F;
    -- lock filters
    constant Z_W : positive := DEMOD_OUT_W + LOCK_SHIFT + 1;

    -- ---- the datapath's widths ----
    -- b operands: the references, the four PI gains, the taps, the 1/SF coefficients
    constant B_W : positive :=
        largest((NCO_SIN_W, COEF_W, CIC_COEF_W, PLL_KP_W, PLL_KI_W, AGC_KP_W, AGC_KI_W));
    constant B_LIMBS : positive := limbs(B_W);
    constant B_EXT_W : positive := 15 * B_LIMBS + 2;
    -- a limb times all of b, summed: 16 + B_EXT_W bits
    constant PP_W : positive := 16 + B_EXT_W;
    -- (Each one bit wider than its widest value, so that every value sign-extends into it.)
    constant ACC_W : positive := largest((X_W, U_W, EA_W, DRIVE_W, PLL_UPD_W, PLL_SUM_W,
        AGC_UPD_W, AGC_SUM_W, REG_W, FIR_W, RATE_W, Z_W, PP_W)) + 1;
    -- The PI integrators as v_reg and the RAM hold them: one of them shifted left so that both
    -- PIs' output sums take v_reg at one alignment (one x source, not two), and their words
    -- read into their updates' fraction bits (a negative shift is right: the word's low bits
    -- are the shift's zeros).
    constant PLL_V_SHIFT : natural :=
        maximum((PLL_SUM_F - PLL_INT_F) - (AGC_SUM_F - AGC_INT_F), 0);
    constant AGC_V_SHIFT : natural :=
        maximum((AGC_SUM_F - AGC_INT_F) - (PLL_SUM_F - PLL_INT_F), 0);
    constant V_SUM_SHIFT : natural := PLL_SUM_F - PLL_INT_F - PLL_V_SHIFT;
    constant PLL_READ_SHIFT : integer := PLL_UPD_F - PLL_INT_F - PLL_V_SHIFT;
    constant AGC_READ_SHIFT : integer := AGC_UPD_F - AGC_INT_F - AGC_V_SHIFT;
    constant V_W : positive := maximum(PLL_INT_W + PLL_V_SHIFT, AGC_INT_W + AGC_V_SHIFT);
    -- The RAM also holds the compensators' partial sums (FIR_W bits) between samples.
    constant RAM_W : positive :=
        largest((DEMOD_STATE_W, V_W, AGC_INT_W, Z_W, REG_W, CIC_MID_W, FIR_W)) + 1;
    -- a operands: ADC codes, the demodulator output (PLL error), the AGC error and output, the
    -- CIC output (and its delay line), the compensator output
    constant A_W : positive :=
        largest((DEMOD_ADC_W, DEMOD_OUT_W, AGC_ERR_W, AGC_OUT_W, CIC_MID_W, CIC_OUT_W));
    constant A_LIMBS : positive := limbs(A_W);
    constant A_EXT_W : positive := 15 * A_LIMBS + 2;
    -- the PI products' extra alignments (0 unless a product has fewer fraction bits than its sum)
    constant PLL_KI_ALIGN : natural := PLL_UPD_F - PLL_KIE_F;
    constant PLL_KP_ALIGN : natural := PLL_SUM_F - PLL_KPE_F;
    constant AGC_KI_ALIGN : natural := AGC_UPD_F - AGC_KIE_F;
    constant AGC_KP_ALIGN : natural := AGC_SUM_F - AGC_KPE_F;
    -- the PI integrators' drops from their updates' fraction bits (the PLL's preset aligned)
    constant PLL_UPD_SHIFT : natural := PLL_UPD_F - PLL_INT_F;
    constant AGC_UPD_SHIFT : natural := AGC_UPD_F - AGC_INT_F;
    constant T_W : positive := NCO_ADDR_W + 2;
    constant R_W : positive := maximum(NCO_PHASE_W - T_W, 1);
    constant DELAY_N : positive := maximum(LATENCY, 1);
    constant MOST_SEEN : natural := maximum(CIC_TAPS - 1, CIC_DELAY);
    -- (The Verilog's ceil_log2(CIC_DECIMATION): at least 1 bit here, as in gyrofx_cic.)
    constant CNT_W : positive := maximum(ceil_log2(CIC_DECIMATION), 1);
    -- The lock count: 0 ..= LOCK_HOLD.
    constant COUNT_W : positive := maximum(ceil_log2(LOCK_HOLD + 1), 1);
    -- The schedule ROM: the regular part, then the segments.
    constant SEGMENT_LEN : integer := SCHEDULE_LEN - SCHEDULE_REGULAR;
    constant SCHEDULE_DEPTH : positive :=
        maximum(SCHEDULE_REGULAR + SCHEDULE_SEGMENTS * SEGMENT_LEN, 1);
    constant PC_W : positive := maximum(ceil_log2(SCHEDULE_DEPTH + 1), 1);
    constant SEGMENT_W : positive := maximum(ceil_log2(SCHEDULE_SEGMENTS + 1), 1);
    constant RAM_ADDR_W : positive := maximum(ceil_log2(RAM_WORDS), 1);
    constant TAP_ADDR_W : positive := maximum(ceil_log2(CIC_TAPS), 1);

    -- Values of any one width, one per gyro (0 A, 1 B) or per (gyro, mode) (gyro_mode's order).
    type signed_array is array (natural range <>) of signed;
    type unsigned_array is array (natural range <>) of unsigned;

    -- Each gyro's gains and integrator limits.
    constant PLL_KP_C : signed_array(0 to 1)(PLL_KP_W - 1 downto 0) := (
        signed(code_of("A_PLL_KP", A_PLL_KP, PLL_KP_W)),
        signed(code_of("B_PLL_KP", B_PLL_KP, PLL_KP_W)));
    constant PLL_KI_C : signed_array(0 to 1)(PLL_KI_W - 1 downto 0) := (
        signed(code_of("A_PLL_KI", A_PLL_KI, PLL_KI_W)),
        signed(code_of("B_PLL_KI", B_PLL_KI, PLL_KI_W)));
    constant PLL_INT_MIN_C : signed_array(0 to 1)(PLL_INT_W - 1 downto 0) := (
        signed(code_of("A_PLL_INT_MIN", A_PLL_INT_MIN, PLL_INT_W)),
        signed(code_of("B_PLL_INT_MIN", B_PLL_INT_MIN, PLL_INT_W)));
    constant PLL_INT_MAX_C : signed_array(0 to 1)(PLL_INT_W - 1 downto 0) := (
        signed(code_of("A_PLL_INT_MAX", A_PLL_INT_MAX, PLL_INT_W)),
        signed(code_of("B_PLL_INT_MAX", B_PLL_INT_MAX, PLL_INT_W)));
    constant AGC_KP_C : signed_array(0 to 1)(AGC_KP_W - 1 downto 0) := (
        signed(code_of("A_AGC_KP", A_AGC_KP, AGC_KP_W)),
        signed(code_of("B_AGC_KP", B_AGC_KP, AGC_KP_W)));
    constant AGC_KI_C : signed_array(0 to 1)(AGC_KI_W - 1 downto 0) := (
        signed(code_of("A_AGC_KI", A_AGC_KI, AGC_KI_W)),
        signed(code_of("B_AGC_KI", B_AGC_KI, AGC_KI_W)));
    constant AGC_INT_MIN_C : signed_array(0 to 1)(AGC_INT_W - 1 downto 0) := (
        signed(code_of("A_AGC_INT_MIN", A_AGC_INT_MIN, AGC_INT_W)),
        signed(code_of("B_AGC_INT_MIN", B_AGC_INT_MIN, AGC_INT_W)));
    constant AGC_INT_MAX_C : signed_array(0 to 1)(AGC_INT_W - 1 downto 0) := (
        signed(code_of("A_AGC_INT_MAX", A_AGC_INT_MAX, AGC_INT_W)),
        signed(code_of("B_AGC_INT_MAX", B_AGC_INT_MAX, AGC_INT_W)));
    -- Each (gyro, mode)'s values: A normal, A reverse, B normal, B reverse.
    constant SETPOINT_C : signed_array(0 to 3)(DEMOD_OUT_W - 1 downto 0) := (
        signed(code_of("A_SETPOINT_N", A_SETPOINT_N, DEMOD_OUT_W)),
        signed(code_of("A_SETPOINT_R", A_SETPOINT_R, DEMOD_OUT_W)),
        signed(code_of("B_SETPOINT_N", B_SETPOINT_N, DEMOD_OUT_W)),
        signed(code_of("B_SETPOINT_R", B_SETPOINT_R, DEMOD_OUT_W)));
    constant FREQ_WORD_C : unsigned_array(0 to 3)(NCO_PHASE_W - 1 downto 0) := (
        unsigned(code_of("A_FREQ_WORD_N", A_FREQ_WORD_N, NCO_PHASE_W)),
        unsigned(code_of("A_FREQ_WORD_R", A_FREQ_WORD_R, NCO_PHASE_W)),
        unsigned(code_of("B_FREQ_WORD_N", B_FREQ_WORD_N, NCO_PHASE_W)),
        unsigned(code_of("B_FREQ_WORD_R", B_FREQ_WORD_R, NCO_PHASE_W)));
    constant PLL_PRESET_C : signed_array(0 to 3)(PLL_INT_W - 1 downto 0) := (
        signed(code_of("A_PLL_PRESET_N", A_PLL_PRESET_N, PLL_INT_W)),
        signed(code_of("A_PLL_PRESET_R", A_PLL_PRESET_R, PLL_INT_W)),
        signed(code_of("B_PLL_PRESET_N", B_PLL_PRESET_N, PLL_INT_W)),
        signed(code_of("B_PLL_PRESET_R", B_PLL_PRESET_R, PLL_INT_W)));
    constant DAC_OFFSET_C : unsigned_array(0 to 3)(NCO_PHASE_W - 1 downto 0) := (
        unsigned(code_of("A_DAC_OFFSET_N", A_DAC_OFFSET_N, NCO_PHASE_W)),
        unsigned(code_of("A_DAC_OFFSET_R", A_DAC_OFFSET_R, NCO_PHASE_W)),
        unsigned(code_of("B_DAC_OFFSET_N", B_DAC_OFFSET_N, NCO_PHASE_W)),
        unsigned(code_of("B_DAC_OFFSET_R", B_DAC_OFFSET_R, NCO_PHASE_W)));
    constant SENSE_OFFSET_C : unsigned_array(0 to 3)(NCO_PHASE_W - 1 downto 0) := (
        unsigned(code_of("A_SENSE_OFFSET_N", A_SENSE_OFFSET_N, NCO_PHASE_W)),
        unsigned(code_of("A_SENSE_OFFSET_R", A_SENSE_OFFSET_R, NCO_PHASE_W)),
        unsigned(code_of("B_SENSE_OFFSET_N", B_SENSE_OFFSET_N, NCO_PHASE_W)),
        unsigned(code_of("B_SENSE_OFFSET_R", B_SENSE_OFFSET_R, NCO_PHASE_W)));
    constant RATE_COEF_C : signed_array(0 to 3)(COEF_W - 1 downto 0) := (
        signed(code_of("A_RATE_COEF_N", A_RATE_COEF_N, COEF_W)),
        signed(code_of("A_RATE_COEF_R", A_RATE_COEF_R, COEF_W)),
        signed(code_of("B_RATE_COEF_N", B_RATE_COEF_N, COEF_W)),
        signed(code_of("B_RATE_COEF_R", B_RATE_COEF_R, COEF_W)));
    constant QUAD_COEF_C : signed_array(0 to 3)(COEF_W - 1 downto 0) := (
        signed(code_of("A_QUAD_COEF_N", A_QUAD_COEF_N, COEF_W)),
        signed(code_of("A_QUAD_COEF_R", A_QUAD_COEF_R, COEF_W)),
        signed(code_of("B_QUAD_COEF_N", B_QUAD_COEF_N, COEF_W)),
        signed(code_of("B_QUAD_COEF_R", B_QUAD_COEF_R, COEF_W)));
    constant LOCK_Q_C : signed_array(0 to 3)(63 downto 0) := (
        signed(code_of("A_LOCK_Q_N", A_LOCK_Q_N, 64)), signed(code_of("A_LOCK_Q_R", A_LOCK_Q_R, 64)),
        signed(code_of("B_LOCK_Q_N", B_LOCK_Q_N, 64)), signed(code_of("B_LOCK_Q_R", B_LOCK_Q_R, 64)));
    constant LOCK_A_C : signed_array(0 to 3)(63 downto 0) := (
        signed(code_of("A_LOCK_A_N", A_LOCK_A_N, 64)), signed(code_of("A_LOCK_A_R", A_LOCK_A_R, 64)),
        signed(code_of("B_LOCK_A_N", B_LOCK_A_N, 64)), signed(code_of("B_LOCK_A_R", B_LOCK_A_R, 64)));

    -- The lock filters' check |z| < limit as -limit < z < limit, in Z_W + 2 bits: |z| <
    -- 2^(Z_W-1), so a limit clipped to +-2^Z_W decides as the 64-bit one does.
    constant CMP_W : positive := Z_W + 2;
    function clipped(limit : signed(63 downto 0)) return signed is
        variable wide : signed(66 downto 0) := resize(limit, 67);
        constant CAP : signed(66 downto 0) := shift_left(to_signed(1, 67), Z_W);
    begin
        if wide > CAP then
            wide := CAP;
        elsif wide < -CAP then
            wide := -CAP;
        end if;
        return wide(CMP_W - 1 downto 0);
    end function;
    constant LIMIT_Q : signed_array(0 to 3)(CMP_W - 1 downto 0) :=
        (clipped(LOCK_Q_C(0)), clipped(LOCK_Q_C(1)), clipped(LOCK_Q_C(2)), clipped(LOCK_Q_C(3)));
    constant LIMIT_A : signed_array(0 to 3)(CMP_W - 1 downto 0) :=
        (clipped(LOCK_A_C(0)), clipped(LOCK_A_C(1)), clipped(LOCK_A_C(2)), clipped(LOCK_A_C(3)));

    -- A gyro's PLL preset, clamped to its limits, at the update's fraction bits.
    function preset_aligned(preset : signed; low : signed; high : signed) return signed is
        variable clamped : signed(PLL_INT_W - 1 downto 0) := preset;
    begin
        if preset < low then
            clamped := low;
        elsif preset > high then
            clamped := high;
        end if;
        return shift_left(resize(clamped, ACC_W), PLL_UPD_SHIFT);
    end function;
    constant PRESET_ACC : signed_array(0 to 3)(ACC_W - 1 downto 0) := (
        preset_aligned(PLL_PRESET_C(0), PLL_INT_MIN_C(0), PLL_INT_MAX_C(0)),
        preset_aligned(PLL_PRESET_C(1), PLL_INT_MIN_C(0), PLL_INT_MAX_C(0)),
        preset_aligned(PLL_PRESET_C(2), PLL_INT_MIN_C(1), PLL_INT_MAX_C(1)),
        preset_aligned(PLL_PRESET_C(3), PLL_INT_MIN_C(1), PLL_INT_MAX_C(1)));

    -- The PI integrators' limits at the rounded update's width, for the clamps, and as v_reg
    -- holds them.
    constant PLL_HIGH : signed_array(0 to 1)(PLL_RND_W - 1 downto 0) :=
        (resize(PLL_INT_MAX_C(0), PLL_RND_W), resize(PLL_INT_MAX_C(1), PLL_RND_W));
    constant PLL_LOW_LESS : signed_array(0 to 1)(PLL_RND_W - 1 downto 0) :=
        (resize(PLL_INT_MIN_C(0), PLL_RND_W) - 1, resize(PLL_INT_MIN_C(1), PLL_RND_W) - 1);
    constant AGC_HIGH : signed_array(0 to 1)(AGC_RND_W - 1 downto 0) :=
        (resize(AGC_INT_MAX_C(0), AGC_RND_W), resize(AGC_INT_MAX_C(1), AGC_RND_W));
    constant AGC_LOW_LESS : signed_array(0 to 1)(AGC_RND_W - 1 downto 0) :=
        (resize(AGC_INT_MIN_C(0), AGC_RND_W) - 1, resize(AGC_INT_MIN_C(1), AGC_RND_W) - 1);
    function pll_held(value : signed) return signed is
    begin
        return shift_left(resize(value, V_W), PLL_V_SHIFT);
    end function;
    function agc_held(value : signed) return signed is
    begin
        return shift_left(resize(value, V_W), AGC_V_SHIFT);
    end function;
    constant PLL_V_LOW : signed_array(0 to 1)(V_W - 1 downto 0) :=
        (pll_held(PLL_INT_MIN_C(0)), pll_held(PLL_INT_MIN_C(1)));
    constant PLL_V_HIGH : signed_array(0 to 1)(V_W - 1 downto 0) :=
        (pll_held(PLL_INT_MAX_C(0)), pll_held(PLL_INT_MAX_C(1)));
    constant AGC_V_LOW : signed_array(0 to 1)(V_W - 1 downto 0) :=
        (agc_held(AGC_INT_MIN_C(0)), agc_held(AGC_INT_MIN_C(1)));
    constant AGC_V_HIGH : signed_array(0 to 1)(V_W - 1 downto 0) :=
        (agc_held(AGC_INT_MAX_C(0)), agc_held(AGC_INT_MAX_C(1)));

    -- The regular part's last word; where the first segment starts and ends; the count's last;
    -- the last segment.
    constant REGULAR_LAST : unsigned(PC_W - 1 downto 0) := to_unsigned(SCHEDULE_REGULAR - 1, PC_W);
    constant REGULAR_WORD : unsigned(PC_W - 1 downto 0) := to_unsigned(SCHEDULE_REGULAR, PC_W);
    constant SEGMENT_WORDS : unsigned(PC_W - 1 downto 0) :=
        to_unsigned(maximum(SEGMENT_LEN, 0) mod 2 ** PC_W, PC_W);
    constant LAST_COUNT : unsigned(CNT_W - 1 downto 0) := to_unsigned(CIC_DECIMATION - 1, CNT_W);
    constant LAST_SEGMENT : unsigned(SEGMENT_W - 1 downto 0) :=
        to_unsigned(SCHEDULE_SEGMENTS - 1, SEGMENT_W);
    -- The Verilog's MOST_SEEN[3:0]: the seen count is 4 bits, as the control word's field.
    constant SEEN_LIMIT : unsigned(3 downto 0) := to_unsigned(MOST_SEEN mod 16, 4);
    -- Half a bin in phase LSB: the top bit of the carried error.
    function top_bit_only return signed is
        variable bin : signed(R_W - 1 downto 0) := (others => '0');
    begin
        bin(R_W - 1) := '1';
        return bin;
    end function;
    constant HALF_BIN : signed(R_W - 1 downto 0) := top_bit_only;

    constant SCHEDULE : word_array(0 to SCHEDULE_DEPTH - 1)(63 downto 0) :=
        read_mem(SCHEDULE_FILE, SCHEDULE_DEPTH, 64);
    constant NCO_ROM : word_array(0 to 2 ** NCO_ADDR_W - 1)(NCO_SIN_W - 1 downto 0) :=
        read_mem(NCO_ROM_FILE, 2 ** NCO_ADDR_W, NCO_SIN_W);
    constant TAPS_ROM : word_array(0 to CIC_TAPS - 1)(CIC_COEF_W - 1 downto 0) :=
        read_mem(CIC_ROM_FILE, CIC_TAPS, CIC_COEF_W);

    type ram_array is array (0 to RAM_WORDS - 1) of std_logic_vector(RAM_W - 1 downto 0);
    -- residues 0..2 gyro A's (drive, transmit, sense), 3..5 gyro B's
    type residue_array is array (0 to 5) of signed(R_W - 1 downto 0);
    type limb_array is array (0 to B_LIMBS - 1) of signed(15 downto 0);
    type product_array is array (0 to B_LIMBS - 1) of signed(31 downto 0);
    type delay_array is array (0 to DELAY_N - 1) of signed(DAC_W - 1 downto 0);
    type delay_pair is array (0 to 1) of delay_array;

    -- ---- control: the schedule ROM, the sample's flags ----
    signal busy_reg : std_logic := '0';
    signal pc_reg : unsigned(PC_W - 1 downto 0) := (others => '0');
    -- The word fetched (the schedule ROM's output register), then the word executing a clock
    -- later: the clock between decodes the accumulator's and the multiplier's operands from it.
    signal fetched_reg : std_logic_vector(63 downto 0) := (others => '0');
    signal control_reg : std_logic_vector(63 downto 0) := (others => '0');
    signal executing_reg : std_logic := '0';
    signal executing_last_reg : std_logic := '0';
    -- The fetched word's x and y codes, registered (the Verilog's one-hot selects), with the
    -- accumulate gyro and its mode, the issue gyro's mode, and the read gates as they stand
    -- when it acts (a read gated to 0 selects nothing; the PLL's preset is an x source of its
    -- own); whether it accumulates.
    signal x_code_reg : unsigned(3 downto 0) := (others => '0');
    signal y_code_reg : unsigned(3 downto 0) := (others => '0');
    signal accumulate_gyro_reg : std_logic := '0';
    signal accumulate_mode_reg : std_logic := '0';
    signal issue_mode_reg : std_logic := '0';
    signal operand_zero_reg : std_logic := '0';
    signal operand_preset_reg : std_logic := '0';
    signal accumulate_reg : std_logic := '0';
    signal start_reg : std_logic := '1';
    signal first_reg : std_logic := '0';
    signal decimate_reg : std_logic := '0';
    signal count_reg : unsigned(CNT_W - 1 downto 0) := (others => '0');
    signal seen_reg : unsigned(3 downto 0) := (others => '0');
    -- The deferred segments: whether one is due in the next sample, which, where its words
    -- start and end in the ROM; whether this sample runs it, and whether it is the last.
    signal due_reg : std_logic := '0';
    signal segment_reg : unsigned(SEGMENT_W - 1 downto 0) := (others => '0');
    signal base_reg : unsigned(PC_W - 1 downto 0) := (others => '0');
    signal segment_end_reg : unsigned(PC_W - 1 downto 0) := (others => '0');
    signal running_reg : std_logic := '0';
    signal final_reg : std_logic := '0';
    signal at_regular_last : std_logic;
    signal last_word : std_logic;
    signal fetch : std_logic;
    signal fetch_address : unsigned(PC_W - 1 downto 0);
    signal decimates : std_logic;
    signal sample_end : std_logic;

    -- The control word's fields (gyrofx_model::gyro_loop::folded::Control): a fixed layout,
    -- whose widest fields a small loop does not use in full; bits 57 to 62 name the gyro each
    -- unit serves, bit 63 marks a decimating-only write.
    signal rom_field : unsigned(2 downto 0);
    signal advance_field : std_logic;
    signal a_field : unsigned(3 downto 0);
    signal limb_field : unsigned(2 downto 0);
    signal top_field : std_logic;
    signal b_field : unsigned(2 downto 0);
    signal tap_field : unsigned(3 downto 0);
    signal x_field : unsigned(3 downto 0);
    signal y_field : unsigned(3 downto 0);
    signal read_field : std_logic;
    signal read_address_field : unsigned(6 downto 0);
    signal gate_field : unsigned(2 downto 0);
    signal seen_field : unsigned(3 downto 0);
    signal write_field : std_logic;
    signal write_address_field : unsigned(6 downto 0);
    signal data_field : unsigned(2 downto 0);
    signal quantize_field : unsigned(3 downto 0);
    signal rom_gyro_field : std_logic;
    signal advance_gyro_field : std_logic;
    signal issue_gyro_field : std_logic;
    signal accumulate_gyro_field : std_logic;
    signal read_gyro_field : std_logic;
    signal quantize_gyro_field : std_logic;
    signal decimating_write_field : std_logic;
    -- The fetched word's issue gyro (its mode is decoded with the operands).
    signal issue_gyro_next : std_logic;
    signal rom_en : std_logic;
    signal accumulate_en : std_logic;
    signal read_en : std_logic;
    signal write_en : std_logic;
    signal point : unsigned(3 downto 0);
    -- The point's gyro: gyro g's registers load at gyro_point(g).
    signal gyro_point : unsigned_array(0 to 1)(3 downto 0);

    -- ---- each gyro's sample registers ----
    signal mode_reg : std_logic_vector(0 to 1) := (others => '1');
    signal switching_reg : std_logic_vector(0 to 1) := (others => '0');
    -- The mode of the last decimating sample (its 1/SF coefficients, applied samples later).
    signal decimation_mode_reg : std_logic_vector(0 to 1) := (others => '1');
    signal adc_x_reg : signed_array(0 to 1)(DEMOD_ADC_W - 1 downto 0) :=
        (others => (others => '0'));
    signal adc_y_reg : signed_array(0 to 1)(DEMOD_ADC_W - 1 downto 0) :=
        (others => (others => '0'));
    signal mode_in : std_logic_vector(0 to 1);
    signal switching : std_logic_vector(0 to 1);

    -- ---- NCOs: per gyro one accumulator and three references' truncation errors; one sine ROM
    signal nco_acc_reg : unsigned_array(0 to 1)(NCO_PHASE_W - 1 downto 0) :=
        (others => (others => '0'));
    signal freq_reg : unsigned_array(0 to 1)(NCO_PHASE_W - 1 downto 0) :=
        (others => (others => '0'));
    signal residue_reg : residue_array := (others => (others => '0'));
    signal ref_magnitude_reg : std_logic_vector(NCO_SIN_W - 1 downto 0) := (others => '0');
    signal ref_negative_reg : std_logic := '0';
    signal nco_index : natural range 0 to 2;
    signal residue_index : natural range 0 to 5;
    signal cosine : std_logic;
    signal rom_mode : std_logic;
    signal nco_offset : unsigned(NCO_PHASE_W - 1 downto 0);
    signal phase_exact : unsigned(NCO_PHASE_W - 1 downto 0);
    signal phase : unsigned(NCO_PHASE_W - 1 downto 0);
    signal t_sin : unsigned(T_W - 1 downto 0);
    signal t : unsigned(T_W - 1 downto 0);
    signal rom_address : unsigned(NCO_ADDR_W - 1 downto 0);
    signal reference : signed(NCO_SIN_W - 1 downto 0);

    -- ---- RAM of states ----
    signal ram : ram_array := (others => (others => '0'));
    signal ram_data_reg : std_logic_vector(RAM_W - 1 downto 0) := (others => '0');
    -- The read register's gates: it reads as 0 (a cleared word), or the PLL integrator
    -- operand as the PLL's preset.
    signal read_zero_reg : std_logic := '0';
    signal read_preset_reg : std_logic := '0';
    signal previous_rd_reg : signed(RAM_W - 1 downto 0) := (others => '0');
    signal rd : signed(RAM_W - 1 downto 0);
    signal read_switching : std_logic;
    signal read_zero : std_logic;
    signal read_preset : std_logic;
    signal zero_next : std_logic;
    signal preset_next : std_logic;
    -- The word as the operands and the RAM write read it (0 when gated).
    signal operand_rd : signed(RAM_W - 1 downto 0);
    signal read_address : unsigned(RAM_ADDR_W - 1 downto 0);
    signal write_address : unsigned(RAM_ADDR_W - 1 downto 0);
    signal write_data : signed(RAM_W - 1 downto 0);

    -- ---- multiplier: a 15-bit limb of a times all of b ----
    signal drive_q_reg : signed_array(0 to 1)(DEMOD_OUT_W - 1 downto 0) :=
        (others => (others => '0'));
    signal amplitude_error_reg : signed_array(0 to 1)(AGC_ERR_W - 1 downto 0) :=
        (others => (others => '0'));
    signal amplitude_reg : signed_array(0 to 1)(AGC_OUT_W - 1 downto 0) :=
        (others => (others => '0'));
    signal c_reg : signed(CIC_MID_W - 1 downto 0) := (others => '0');
    signal cic_output_reg : signed(CIC_OUT_W - 1 downto 0) := (others => '0');
    -- The operand registers, and the product's weight with them (the limb and the PI
    -- alignment its b takes), one clock on beside the products.
    signal a_limb_reg : signed(15 downto 0) := (others => '0');
    signal b_reg : signed(B_EXT_W - 2 downto 0) := (others => '0');
    signal limb_reg : unsigned(2 downto 0) := (others => '0');
    signal align_reg : unsigned(2 downto 0) := (others => '0');
    signal product_limb_reg : unsigned(2 downto 0) := (others => '0');
    signal product_align_reg : unsigned(2 downto 0) := (others => '0');
    signal product_reg : product_array := (others => (others => '0'));
    signal pp_reg : signed(ACC_W - 1 downto 0) := (others => '0');
    signal issue_gyro : natural range 0 to 1;
    signal adc_drive : signed(DEMOD_ADC_W - 1 downto 0);
    signal adc_sense : signed(DEMOD_ADC_W - 1 downto 0);
    signal a_value : signed(A_EXT_W - 1 downto 0);
    signal a_limb : signed(15 downto 0);
    signal tap_address : unsigned(TAP_ADDR_W - 1 downto 0);
    signal tap : signed(CIC_COEF_W - 1 downto 0);
    signal issue_decimation_mode : std_logic;
    signal rate_coef : signed(COEF_W - 1 downto 0);
    signal quad_coef : signed(COEF_W - 1 downto 0);
    signal b_value : signed(B_EXT_W - 1 downto 0);
    signal b_limb : limb_array;

    -- ---- accumulator: acc <= x + y ----
    signal acc_reg : signed(ACC_W - 1 downto 0) := (others => '0');
    signal p_reg : signed(DEMOD_PROD_W - 1 downto 0) := (others => '0');
    signal y_reg : signed(DEMOD_STATE_W - 1 downto 0) := (others => '0');
    signal v_reg : signed(V_W - 1 downto 0) := (others => '0');
    signal demod_output : signed(DEMOD_OUT_W - 1 downto 0);
    -- Q_O of the state register, registered: the value of the clock before.
    signal output_reg : signed(DEMOD_OUT_W - 1 downto 0) := (others => '0');
    signal accumulate_gyro : natural range 0 to 1;
    signal accumulate_pair : natural range 0 to 3;
    signal x_value : signed(ACC_W - 1 downto 0);
    signal y_value : signed(ACC_W - 1 downto 0);
    signal y_negate : std_logic;
    signal acc_next : signed(ACC_W - 1 downto 0);

    -- ---- quantization points, at the parallel loop's formats ----
    signal p_next : signed(DEMOD_PROD_W - 1 downto 0);
    signal y_next : signed(DEMOD_STATE_W - 1 downto 0);
    signal error_next : signed(DEMOD_OUT_W - 1 downto 0);
    signal pll_rounded : signed(PLL_RND_W - 1 downto 0);
    signal pll_out : signed(PLL_OUT_W - 1 downto 0);
    signal agc_rounded : signed(AGC_RND_W - 1 downto 0);
    signal agc_out : signed(AGC_OUT_W - 1 downto 0);
    signal drive : signed(DAC_W - 1 downto 0);
    signal c_next : signed(CIC_MID_W - 1 downto 0);
    signal cic_output_next : signed(CIC_OUT_W - 1 downto 0);
    signal rate_next : signed(OUT_W - 1 downto 0);
    signal point_gyro : natural range 0 to 1;
    signal point_mode : std_logic;
    signal pll_point : std_logic;
    signal pll_floor : signed(PLL_RND_W - 1 downto 0);
    signal pll_increment : std_logic;
    signal pll_below : std_logic;
    signal pll_above : std_logic;
    signal agc_floor : signed(AGC_RND_W - 1 downto 0);
    signal agc_increment : std_logic;
    signal agc_below : std_logic;
    signal agc_above : std_logic;
    signal v_rounded : signed(V_W - 1 downto 0);
    signal v_low : signed(V_W - 1 downto 0);
    signal v_high : signed(V_W - 1 downto 0);
    signal v_below : std_logic;
    signal v_above : std_logic;
    signal v_next : signed(V_W - 1 downto 0);
    signal z : signed(Z_W - 1 downto 0);
    signal z_cmp : signed(CMP_W - 1 downto 0);
    signal lock_limit : signed(CMP_W - 1 downto 0);
    signal lock_floor : signed(CMP_W - 1 downto 0);
    signal within_limit : std_logic;

    -- ---- each gyro's DAC, lock count and outputs ----
    signal delay_reg : delay_pair := (others => (others => (others => '0')));
    signal dac_now : signed_array(0 to 1)(DAC_W - 1 downto 0);
    signal dac_x_reg : signed_array(0 to 1)(DAC_W - 1 downto 0) := (others => (others => '0'));
    signal dac_y_reg : signed_array(0 to 1)(DAC_W - 1 downto 0) := (others => (others => '0'));
    signal rate_reg : signed_array(0 to 1)(OUT_W - 1 downto 0) := (others => (others => '0'));
    signal quad_reg : signed_array(0 to 1)(OUT_W - 1 downto 0) := (others => (others => '0'));
    signal out_valid_reg : std_logic := '0';
    signal decimating_reg : std_logic := '0';
    -- Each gyro's phase check, then both checks registered at the second point: the count and
    -- locked load on the clock after it.
    signal inside_q_reg : std_logic_vector(0 to 1) := (others => '0');
    signal inside_reg : std_logic_vector(0 to 1) := (others => '0');
    signal count_pending_reg : std_logic_vector(0 to 1) := (others => '0');
    signal lock_count_reg : unsigned_array(0 to 1)(COUNT_W - 1 downto 0) :=
        (others => (others => '0'));
    signal locked_reg : std_logic_vector(0 to 1) := (others => '0');
    signal lock_count_next : unsigned_array(0 to 1)(COUNT_W - 1 downto 0);

begin

    assert CIC_DELAY = 1
        report "gyrofx_gyro_pair_serial: the folded loops' CICs have a differential delay of 1, "
            & "not " & integer'image(CIC_DELAY)
        severity failure;
    assert AGC_ERR_W = DEMOD_OUT_W and AGC_ERR_F = DEMOD_OUT_F and PLL_ERR_W = DEMOD_OUT_W
        report "gyrofx_gyro_pair_serial: the PI errors' formats must be the demodulator output's"
        severity failure;
    assert CIC_TAPS <= 15 and A_LIMBS <= 8 and DEMOD_ALIGN >= 0
        report "gyrofx_gyro_pair_serial: the schedule's fields hold CIC_TAPS <= 15 ("
            & integer'image(CIC_TAPS) & ") and operands of <= 8 limbs ("
            & integer'image(A_LIMBS) & "); DEMOD_STATE_F (" & integer'image(DEMOD_STATE_F)
            & ") must be >= DEMOD_PROD_F (" & integer'image(DEMOD_PROD_F) & ")"
        severity failure;
    assert RAM_WORDS <= 128 and SEGMENT_LEN >= 1 and SCHEDULE_SEGMENTS < CIC_DECIMATION
        report "gyrofx_gyro_pair_serial: RAM_WORDS (" & integer'image(RAM_WORDS)
            & ") must be <= 128, SCHEDULE_LEN (" & integer'image(SCHEDULE_LEN)
            & ") > SCHEDULE_REGULAR (" & integer'image(SCHEDULE_REGULAR)
            & "), 1 <= SCHEDULE_SEGMENTS (" & integer'image(SCHEDULE_SEGMENTS)
            & ") < CIC_DECIMATION (" & integer'image(CIC_DECIMATION) & ")"
        severity failure;

    -- ---- control: the schedule ROM, the sample's flags ----
    -- The regular part, then (a sample after a decimating one) the due segment's words.
    at_regular_last <= '1' when pc_reg = REGULAR_LAST else '0';
    last_word <= '1' when busy_reg = '1'
                          and ((running_reg = '1' and pc_reg = segment_end_reg)
                               or (running_reg = '0' and at_regular_last = '1')) else '0';
    -- A word is fetched two clocks before it acts (word 0 at ce), its operands decoded the
    -- clock between.
    fetch <= (ce and not rst) or (busy_reg and not last_word);
    fetch_address <= (others => '0') when ce = '1' else
                     base_reg when at_regular_last = '1' else
                     pc_reg + 1;

    -- The fetched word's slices the decode reads: x, y, the accumulate gyro, the issue gyro.
    x_field <= unsigned(fetched_reg(22 downto 19));
    y_field <= unsigned(fetched_reg(26 downto 23));
    accumulate_gyro_field <= fetched_reg(60);
    issue_gyro_next <= fetched_reg(59);

    schedule_rom : process (clk)
    begin
        if rising_edge(clk) then
            if fetch = '1' then
                if to_integer(fetch_address) < SCHEDULE_DEPTH then
                    fetched_reg <= SCHEDULE(to_integer(fetch_address));
                else
                    fetched_reg <= (others => '0');
                end if;
            end if;
            control_reg <= fetched_reg;
            executing_reg <= busy_reg and not rst;
            executing_last_reg <= last_word and not rst;
            x_code_reg <= x_field;
            y_code_reg <= y_field;
            accumulate_gyro_reg <= accumulate_gyro_field;
            if accumulate_gyro_field = '1' then
                accumulate_mode_reg <= mode_reg(1);
            else
                accumulate_mode_reg <= mode_reg(0);
            end if;
            if issue_gyro_next = '1' then
                issue_mode_reg <= mode_reg(1);
            else
                issue_mode_reg <= mode_reg(0);
            end if;
            operand_zero_reg <= zero_next;
            operand_preset_reg <= preset_next;
            if x_field /= 0 or y_field /= 0 then
                accumulate_reg <= '1';
            else
                accumulate_reg <= '0';
            end if;
        end if;
    end process;

    rom_field <= unsigned(control_reg(2 downto 0));
    advance_field <= control_reg(3);
    a_field <= unsigned(control_reg(7 downto 4));
    limb_field <= unsigned(control_reg(10 downto 8));
    top_field <= control_reg(11);
    b_field <= unsigned(control_reg(14 downto 12));
    tap_field <= unsigned(control_reg(18 downto 15));
    read_field <= control_reg(27);
    read_address_field <= unsigned(control_reg(34 downto 28));
    gate_field <= unsigned(control_reg(37 downto 35));
    seen_field <= unsigned(control_reg(41 downto 38));
    write_field <= control_reg(42);
    write_address_field <= unsigned(control_reg(49 downto 43));
    data_field <= unsigned(control_reg(52 downto 50));
    quantize_field <= unsigned(control_reg(56 downto 53));
    rom_gyro_field <= control_reg(57);
    advance_gyro_field <= control_reg(58);
    issue_gyro_field <= control_reg(59);
    read_gyro_field <= control_reg(61);
    quantize_gyro_field <= control_reg(62);
    decimating_write_field <= control_reg(63);

    -- The word acts only while the schedule runs: the last one stays in control_reg after it.
    rom_en <= '1' when executing_reg = '1' and rom_field /= 0 else '0';
    accumulate_en <= executing_reg and accumulate_reg;
    read_en <= executing_reg and read_field;
    -- A decimating-only write (the CICs' last integrators' snapshot) in a decimating sample only.
    write_en <= executing_reg and write_field
                and (not decimating_write_field or decimate_reg);
    point <= quantize_field when executing_reg = '1' else (others => '0');
    gyro_point(0) <= point when quantize_gyro_field = '0' else (others => '0');
    gyro_point(1) <= point when quantize_gyro_field = '1' else (others => '0');

    -- ---- each gyro's sample registers ----
    mode_in <= (mode_a, mode_b);
    g_switching : for g in 0 to 1 generate
        switching(g) <= '1' when mode_in(g) /= mode_reg(g) or start_reg = '1' else '0';
    end generate;

    -- ---- NCOs: per gyro one accumulator and three references' truncation errors; one sine ROM
    -- rom_field: 1 drive sin, 2 drive cos, 3 transmit cos, 4 sense sin, 5 sense cos.
    nco_index <= 1 when rom_field = 3 else 2 when rom_field >= 4 else 0;
    residue_index <= nco_index + 3 when rom_gyro_field = '1' else nco_index;
    cosine <= '1' when rom_field = 2 or rom_field = 3 or rom_field = 5 else '0';
    rom_mode <= mode_reg(1) when rom_gyro_field = '1' else mode_reg(0);
    nco_offset <= (others => '0') when nco_index = 0 else
                  DAC_OFFSET_C(gyro_mode(rom_gyro_field, rom_mode)) when nco_index = 1 else
                  SENSE_OFFSET_C(gyro_mode(rom_gyro_field, rom_mode));
    phase_exact <= nco_acc_reg(gyro_of(rom_gyro_field)) + nco_offset;
    -- With error feedback the reference's carried error joins the phase (sign-extended, mod
    -- one cycle).
    phase <= phase_exact + unsigned(resize(residue_reg(residue_index), NCO_PHASE_W))
        when NCO_ERROR_FEEDBACK /= 0 else phase_exact;
    t_sin <= phase(NCO_PHASE_W - 1 downto NCO_PHASE_W - T_W);
    -- The cosine: the same at a quarter cycle on.
    t <= t_sin + to_unsigned(2 ** NCO_ADDR_W, T_W) when cosine = '1' else t_sin;
    rom_address <= not t(NCO_ADDR_W - 1 downto 0) when t(NCO_ADDR_W) = '1'
                   else t(NCO_ADDR_W - 1 downto 0);
    sine_rom : process (clk)
    begin
        if rising_edge(clk) then
            if rom_en = '1' then
                ref_magnitude_reg <= NCO_ROM(to_integer(rom_address));
            end if;
        end if;
    end process;

    reference <= -signed(ref_magnitude_reg) when ref_negative_reg = '1'
                 else signed(ref_magnitude_reg);

    -- ---- RAM of states ----
    rd <= signed(ram_data_reg);
    -- gate_field: 1 switch, 2 preset, 3 first sample, 4 fewer than seen decimations; a switch
    -- of the read's gyro.
    read_switching <= switching_reg(1) when read_gyro_field = '1' else switching_reg(0);
    read_zero <= '1' when (gate_field = 1 and read_switching = '1')
                          or (gate_field = 3 and first_reg = '1')
                          or (gate_field = 4 and seen_reg < seen_field) else '0';
    read_preset <= '1' when gate_field = 2 and read_switching = '1' else '0';
    -- The gates as they stand when the word being decoded acts: this clock's read sets them.
    zero_next <= read_zero when read_en = '1' else read_zero_reg;
    preset_next <= read_preset when read_en = '1' else read_preset_reg;
    operand_rd <= (others => '0') when operand_zero_reg = '1' else rd;

    -- ---- multiplier: a 15-bit limb of a times all of b ----
    -- The issue's gyro's operands: the ADC code of its driven axis (a code 1) or its sensed
    -- one (2), in its mode as the word was decoded.
    issue_gyro <= gyro_of(issue_gyro_field);
    adc_drive <= adc_x_reg(issue_gyro) when issue_mode_reg = '1' else adc_y_reg(issue_gyro);
    adc_sense <= adc_y_reg(issue_gyro) when issue_mode_reg = '1' else adc_x_reg(issue_gyro);

    -- Every a operand sign-extended to A_EXT_W bits (the RAM word holds a CIC output c).
    a_operand : process (all)
    begin
        case to_integer(a_field) is
            when 1 => a_value <= resize(adc_drive, A_EXT_W);
            when 2 => a_value <= resize(adc_sense, A_EXT_W);
            when 3 => a_value <= resize(drive_q_reg(issue_gyro), A_EXT_W);
            when 4 => a_value <= resize(amplitude_error_reg(issue_gyro), A_EXT_W);
            when 5 => a_value <= resize(amplitude_reg(issue_gyro), A_EXT_W);
            when 6 => a_value <= resize(c_reg, A_EXT_W);
            when 7 => a_value <= resize(operand_rd(CIC_MID_W - 1 downto 0), A_EXT_W);
            when 8 => a_value <= resize(cic_output_reg, A_EXT_W);
            when others => a_value <= (others => '0');
        end case;
    end process;
    -- Limb k of a: bits 15k .. 15k + 15 (the Verilog's chain of A_LIMBS choices: a limb
    -- field beyond A_LIMBS - 1 selects limb 0, which no schedule issues).
    a_limb_select : process (all)
        variable bits : signed(15 downto 0);
    begin
        bits := a_value(15 downto 0);
        for n in 1 to A_LIMBS - 1 loop
            if limb_field = to_unsigned(n, 3) then
                bits := a_value(15 * n + 15 downto 15 * n);
            end if;
        end loop;
        if top_field = '1' then
            a_limb <= bits;
        else
            a_limb <= '0' & bits(14 downto 0);
        end if;
    end process;

    -- (tap_field[TAP_ADDR_W-1:0] in the Verilog: the same bits up to 16 taps.)
    tap_address <= resize(tap_field, TAP_ADDR_W);
    tap <= signed(TAPS_ROM(to_integer(tap_address))) when to_integer(tap_address) < CIC_TAPS
           else (others => '0');
    -- The issue's gyro's gains, and its 1/SF of the mode its last decimating sample was taken in.
    issue_decimation_mode <= decimation_mode_reg(issue_gyro);
    rate_coef <= RATE_COEF_C(gyro_mode(issue_gyro_field, issue_decimation_mode));
    quad_coef <= QUAD_COEF_C(gyro_mode(issue_gyro_field, issue_decimation_mode));

    -- (Its top bit, a guard bit, is never a limb's.)
    b_operand : process (all)
    begin
        case to_integer(b_field) is
            when 0 => b_value <= resize(reference, B_EXT_W);
            when 1 => b_value <= resize(PLL_KI_C(issue_gyro), B_EXT_W);
            when 2 => b_value <= resize(PLL_KP_C(issue_gyro), B_EXT_W);
            when 3 => b_value <= resize(AGC_KI_C(issue_gyro), B_EXT_W);
            when 4 => b_value <= resize(AGC_KP_C(issue_gyro), B_EXT_W);
            when 5 => b_value <= resize(tap, B_EXT_W);
            when 6 => b_value <= resize(rate_coef, B_EXT_W);
            when others => b_value <= resize(quad_coef, B_EXT_W);
        end case;
    end process;

    -- Limb j of b: 15 unsigned bits, the top one signed; each product one 16x16.
    g_b_limbs : for j in 0 to B_LIMBS - 1 generate
        g_top : if j = B_LIMBS - 1 generate
            b_limb(j) <= b_reg(15 * j + 15 downto 15 * j);
        end generate;
        g_low : if j < B_LIMBS - 1 generate
            b_limb(j) <= '0' & b_reg(15 * j + 14 downto 15 * j);
        end generate;
    end generate;

    -- The operands registered; the products registered; then summed at b's limbs' weights
    -- (the Verilog's chain of one adder per limb, in one expression), aligned for a PI and
    -- weighted by a's limb into pp. As in the Verilog's loop, a limb k matches
    -- product_limb_reg at k's low 3 bits.
    multiplier : process (clk)
        variable sum : signed(PP_W - 1 downto 0);
        variable aligned : signed(ACC_W - 1 downto 0);
        variable weighted : signed(ACC_W - 1 downto 0);
    begin
        if rising_edge(clk) then
            sum := resize(product_reg(0), PP_W);
            for j in 1 to B_LIMBS - 1 loop
                sum := sum + shift_left(resize(product_reg(j), PP_W), 15 * j);
            end loop;
            case to_integer(product_align_reg) is
                when 1 => aligned := shift_left(resize(sum, ACC_W), PLL_KI_ALIGN);
                when 2 => aligned := shift_left(resize(sum, ACC_W), PLL_KP_ALIGN);
                when 3 => aligned := shift_left(resize(sum, ACC_W), AGC_KI_ALIGN);
                when 4 => aligned := shift_left(resize(sum, ACC_W), AGC_KP_ALIGN);
                when others => aligned := resize(sum, ACC_W);
            end case;
            weighted := aligned;
            for k in 1 to A_LIMBS - 1 loop
                if product_limb_reg = to_unsigned(k mod 8, 3) then
                    weighted := shift_left(aligned, 15 * k);
                end if;
            end loop;
            pp_reg <= weighted;
            for j in 0 to B_LIMBS - 1 loop
                product_reg(j) <= a_limb_reg * b_limb(j);
            end loop;
            product_limb_reg <= limb_reg;
            product_align_reg <= align_reg;
            a_limb_reg <= a_limb;
            b_reg <= b_value(B_EXT_W - 2 downto 0);
            limb_reg <= limb_field;
            if b_field >= 1 and b_field <= 4 then
                align_reg <= b_field;
            else
                align_reg <= (others => '0');
            end if;
            output_reg <= demod_output;
        end if;
    end process;

    -- ---- accumulator: acc <= x + y ----
    -- The accumulate gyro's registers and (gyro, mode) constants, as the word was decoded.
    accumulate_gyro <= gyro_of(accumulate_gyro_reg);
    accumulate_pair <= gyro_mode(accumulate_gyro_reg, accumulate_mode_reg);

    x_operand : process (all)
    begin
        case to_integer(x_code_reg) is
            when 0 => x_value <= acc_reg;
            when 2 => x_value <= resize(operand_rd, ACC_W);
            when 3 => x_value <= shift_left(resize(operand_rd, ACC_W), DEMOD_SHIFT);
            when 4 => x_value <= resize(SETPOINT_C(accumulate_pair), ACC_W);
            when 5 =>
                if operand_preset_reg = '1' then
                    x_value <= PRESET_ACC(accumulate_pair);
                else
                    x_value <= shifted(resize(operand_rd, ACC_W), PLL_READ_SHIFT);
                end if;
            when 6 | 8 => x_value <= shift_left(resize(v_reg, ACC_W), V_SUM_SHIFT);
            when 7 => x_value <= shifted(resize(operand_rd, ACC_W), AGC_READ_SHIFT);
            -- (1: zero; no schedule writes the others.)
            when others => x_value <= (others => '0');
        end case;
    end process;

    -- y, and whether it enters negated (x + not y + 1).
    y_operand : process (all)
    begin
        y_negate <= '0';
        case to_integer(y_code_reg) is
            when 1 => y_value <= pp_reg;
            when 2 =>
                y_value <= resize(operand_rd, ACC_W);
                y_negate <= '1';
            when 3 => y_value <= shift_left(resize(p_reg, ACC_W), DEMOD_ALIGN);
            when 4 =>
                y_value <= resize(output_reg, ACC_W);
                y_negate <= '1';
            when 5 => y_value <= resize(output_reg, ACC_W);
            when 6 => y_value <= resize(previous_rd_reg, ACC_W);
            when 7 =>
                y_value <= shift_right(resize(operand_rd, ACC_W), LOCK_SHIFT);
                y_negate <= '1';
            when 8 => y_value <= resize(drive_q_reg(accumulate_gyro), ACC_W);
            when 9 => y_value <= resize(amplitude_error_reg(accumulate_gyro), ACC_W);
            when others => y_value <= (others => '0');
        end case;
    end process;

    -- One adder: a subtraction is x + not y with a carry in of 1.
    acc_next <= x_value + y_value when y_negate = '0'
                else x_value + (not y_value) + signed'("01");

    -- ---- quantization points, at the parallel loop's formats ----
    quantize_product : entity work.gyrofx_quantize
        generic map (
            IN_W => X_W, IN_F => X_F, OUT_W => DEMOD_PROD_W, OUT_F => DEMOD_PROD_F,
            ROUNDING => ROUNDING, SATURATE => SATURATE
        )
        port map (value_in => acc_reg(X_W - 1 downto 0), value_out => p_next, overflow => open);

    quantize_state : entity work.gyrofx_quantize
        generic map (
            IN_W => U_W, IN_F => U_F, OUT_W => DEMOD_STATE_W, OUT_F => DEMOD_STATE_F,
            ROUNDING => ROUNDING, SATURATE => SATURATE
        )
        port map (value_in => acc_reg(U_W - 1 downto 0), value_out => y_next, overflow => open);

    quantize_output : entity work.gyrofx_quantize
        generic map (
            IN_W => DEMOD_STATE_W, IN_F => DEMOD_STATE_F, OUT_W => DEMOD_OUT_W,
            OUT_F => DEMOD_OUT_F, ROUNDING => ROUNDING, SATURATE => SATURATE
        )
        port map (value_in => y_reg, value_out => demod_output, overflow => open);

    quantize_agc_error : entity work.gyrofx_quantize
        generic map (
            IN_W => EA_W, IN_F => DEMOD_OUT_F, OUT_W => DEMOD_OUT_W, OUT_F => DEMOD_OUT_F,
            ROUNDING => ROUNDING, SATURATE => SATURATE
        )
        port map (
            value_in => acc_reg(EA_W - 1 downto 0), value_out => error_next, overflow => open
        );

    quantize_pll_integrator : entity work.gyrofx_quantize
        generic map (
            IN_W => PLL_UPD_W, IN_F => PLL_UPD_F, OUT_W => PLL_RND_W, OUT_F => PLL_INT_F,
            ROUNDING => ROUNDING, SATURATE => 0
        )
        port map (
            value_in => acc_reg(PLL_UPD_W - 1 downto 0), value_out => pll_rounded, overflow => open
        );

    quantize_pll_output : entity work.gyrofx_quantize
        generic map (
            IN_W => PLL_SUM_W, IN_F => PLL_SUM_F, OUT_W => PLL_OUT_W, OUT_F => PLL_OUT_F,
            ROUNDING => ROUNDING, SATURATE => SATURATE
        )
        port map (
            value_in => acc_reg(PLL_SUM_W - 1 downto 0), value_out => pll_out, overflow => open
        );

    quantize_agc_integrator : entity work.gyrofx_quantize
        generic map (
            IN_W => AGC_UPD_W, IN_F => AGC_UPD_F, OUT_W => AGC_RND_W, OUT_F => AGC_INT_F,
            ROUNDING => ROUNDING, SATURATE => 0
        )
        port map (
            value_in => acc_reg(AGC_UPD_W - 1 downto 0), value_out => agc_rounded, overflow => open
        );

    quantize_agc_output : entity work.gyrofx_quantize
        generic map (
            IN_W => AGC_SUM_W, IN_F => AGC_SUM_F, OUT_W => AGC_OUT_W, OUT_F => AGC_OUT_F,
            ROUNDING => ROUNDING, SATURATE => SATURATE
        )
        port map (
            value_in => acc_reg(AGC_SUM_W - 1 downto 0), value_out => agc_out, overflow => open
        );

    quantize_dac : entity work.gyrofx_quantize
        generic map (
            IN_W => DRIVE_W, IN_F => DRIVE_F, OUT_W => DAC_W, OUT_F => DAC_F,
            ROUNDING => ROUNDING, SATURATE => SATURATE
        )
        port map (value_in => acc_reg(DRIVE_W - 1 downto 0), value_out => drive, overflow => open);

    quantize_cic : entity work.gyrofx_quantize
        generic map (
            IN_W => REG_W, IN_F => CIC_IN_F + CIC_SHIFT, OUT_W => CIC_MID_W, OUT_F => CIC_MID_F,
            ROUNDING => ROUNDING, SATURATE => SATURATE
        )
        port map (value_in => acc_reg(REG_W - 1 downto 0), value_out => c_next, overflow => open);

    quantize_compensator : entity work.gyrofx_quantize
        generic map (
            IN_W => FIR_W, IN_F => FIR_F, OUT_W => CIC_OUT_W, OUT_F => CIC_OUT_F,
            ROUNDING => ROUNDING, SATURATE => SATURATE
        )
        port map (
            value_in => acc_reg(FIR_W - 1 downto 0), value_out => cic_output_next, overflow => open
        );

    quantize_rate : entity work.gyrofx_quantize
        generic map (
            IN_W => RATE_W, IN_F => RATE_F, OUT_W => OUT_W, OUT_F => OUT_F,
            ROUNDING => ROUNDING, SATURATE => SATURATE
        )
        port map (
            value_in => acc_reg(RATE_W - 1 downto 0), value_out => rate_next, overflow => open
        );

    -- The PI integrators' clamps (gyrofx_gyro_loop_serial's), at the point's gyro's limits:
    -- the limits bound the result, so its low INT_W bits are exact. They compare the floor q
    -- of the update (the accumulator's bits), beside the rounding's carry rather than after
    -- it: the rounded value is q + inc (inc 0 or 1, its low bit q's flipped when inc is 1),
    -- below the low limit L when q < L - 1 or q = L - 1 and inc = 0, above the high one H
    -- when q > H or q = H and inc = 1.
    point_gyro <= gyro_of(quantize_gyro_field);
    pll_point <= '1' when quantize_field = 5 else '0';
    pll_floor <= resize(acc_reg(PLL_UPD_W - 1 downto PLL_UPD_SHIFT), PLL_RND_W);
    pll_increment <= pll_rounded(0) xor pll_floor(0);
    pll_below <= '1' when pll_floor < PLL_LOW_LESS(point_gyro)
                          or (pll_floor = PLL_LOW_LESS(point_gyro) and pll_increment = '0')
                 else '0';
    pll_above <= '1' when pll_floor > PLL_HIGH(point_gyro)
                          or (pll_floor = PLL_HIGH(point_gyro) and pll_increment = '1')
                 else '0';
    agc_floor <= resize(acc_reg(AGC_UPD_W - 1 downto AGC_UPD_SHIFT), AGC_RND_W);
    agc_increment <= agc_rounded(0) xor agc_floor(0);
    agc_below <= '1' when agc_floor < AGC_LOW_LESS(point_gyro)
                          or (agc_floor = AGC_LOW_LESS(point_gyro) and agc_increment = '0')
                 else '0';
    agc_above <= '1' when agc_floor > AGC_HIGH(point_gyro)
                          or (agc_floor = AGC_HIGH(point_gyro) and agc_increment = '1')
                 else '0';
    -- v_reg's next value at either PI's point: the point's rounded update and limits.
    v_rounded <= pll_held(pll_rounded(PLL_INT_W - 1 downto 0)) when pll_point = '1'
                 else agc_held(agc_rounded(AGC_INT_W - 1 downto 0));
    v_low <= PLL_V_LOW(point_gyro) when pll_point = '1' else AGC_V_LOW(point_gyro);
    v_high <= PLL_V_HIGH(point_gyro) when pll_point = '1' else AGC_V_HIGH(point_gyro);
    v_below <= pll_below when pll_point = '1' else agc_below;
    v_above <= pll_above when pll_point = '1' else agc_above;
    v_next <= v_low when v_below = '1' else v_high when v_above = '1' else v_rounded;

    -- The lock filters' check, -limit < z < limit (CMP_W, LIMIT_*), the limit of the point's
    -- gyro and mode.
    point_mode <= mode_reg(point_gyro);
    z <= acc_reg(Z_W - 1 downto 0);
    z_cmp <= resize(z, CMP_W);
    lock_limit <= LIMIT_Q(gyro_mode(quantize_gyro_field, point_mode)) when quantize_field = 14
                  else LIMIT_A(gyro_mode(quantize_gyro_field, point_mode));
    lock_floor <= -LIMIT_Q(gyro_mode(quantize_gyro_field, point_mode)) when quantize_field = 14
                  else -LIMIT_A(gyro_mode(quantize_gyro_field, point_mode));
    within_limit <= '1' when z_cmp < lock_limit and z_cmp > lock_floor else '0';

    -- ---- RAM writes (and its registered read, before this clock's write) ----
    read_address <= read_address_field(RAM_ADDR_W - 1 downto 0);
    write_address <= write_address_field(RAM_ADDR_W - 1 downto 0);

    -- data_field: 0 the accumulator at the CIC registers' width, 1 at the lock filters', 2 y,
    -- 3 v, 4 the read register (0 when its read was gated), 5 c, 6 the accumulator at the
    -- compensator sum's width.
    ram_data : process (all)
    begin
        case to_integer(data_field) is
            when 0 => write_data <= resize(acc_reg(REG_W - 1 downto 0), RAM_W);
            when 1 => write_data <= resize(z, RAM_W);
            when 2 => write_data <= resize(y_reg, RAM_W);
            when 3 => write_data <= resize(v_reg, RAM_W);
            when 4 => write_data <= operand_rd;
            when 5 => write_data <= resize(c_reg, RAM_W);
            when 6 => write_data <= resize(acc_reg(FIR_W - 1 downto 0), RAM_W);
            when others => write_data <= (others => '0');
        end case;
    end process;

    states_ram : process (clk)
    begin
        if rising_edge(clk) then
            if write_en = '1' and to_integer(write_address) < RAM_WORDS then
                ram(to_integer(write_address)) <= std_logic_vector(write_data);
            end if;
            if read_en = '1' then
                if to_integer(read_address) < RAM_WORDS then
                    ram_data_reg <= ram(to_integer(read_address));
                else
                    ram_data_reg <= (others => '0');
                end if;
            end if;
        end if;
    end process;

    -- ---- each gyro's DAC and lock count ----
    g_gyros : for g in 0 to 1 generate
        -- The DAC code of sample k is output at sample k + LATENCY; delay_reg(g)(j) holds
        -- sample k-1-j's.
        dac_now(g) <= drive when LATENCY = 0 else delay_reg(g)(DELAY_N - 1);
        lock_count_next(g) <= (others => '0') when inside_reg(g) = '0' else
                              to_unsigned(LOCK_HOLD, COUNT_W)
                                  when lock_count_reg(g) >= LOCK_HOLD else
                              lock_count_reg(g) + 1;
    end generate;

    -- ---- the sample: control, the registers the points load ----
    decimates <= '1' when count_reg = LAST_COUNT else '0';
    sample_end <= executing_reg and executing_last_reg;

    -- Later assignments win, as with the Verilog's nonblocking ones: a point's load over the
    -- sample's clears, rst over everything.
    registers : process (clk)
    begin
        if rising_edge(clk) then
            out_valid_reg <= '0';
            decimating_reg <= '0';
            -- The read register of the clock before, 0 when its read was gated.
            if read_zero_reg = '1' then
                previous_rd_reg <= (others => '0');
            else
                previous_rd_reg <= rd;
            end if;

            if ce = '1' then
                busy_reg <= '1';
                pc_reg <= (others => '0');
                mode_reg <= mode_in;
                start_reg <= '0';
                switching_reg <= switching;
                first_reg <= start_reg;
                adc_x_reg <= (adc_a_x, adc_b_x);
                adc_y_reg <= (adc_a_y, adc_b_y);
                decimate_reg <= decimates;
                if decimates = '1' then
                    count_reg <= (others => '0');
                    decimation_mode_reg <= mode_in;
                else
                    count_reg <= count_reg + 1;
                end if;
                running_reg <= due_reg;
                if segment_reg = LAST_SEGMENT then
                    final_reg <= '1';
                else
                    final_reg <= '0';
                end if;
                for g in 0 to 1 loop
                    if switching(g) = '1' then
                        lock_count_reg(g) <= (others => '0');
                        delay_reg(g) <= (others => (others => '0'));
                        -- The first sample of a mode runs at its nominal word (the PLL's output
                        -- point loads the next one's, after the NCO's advance).
                        freq_reg(g) <= FREQ_WORD_C(gyro_mode(GYRO_BIT(g), mode_in(g)));
                    end if;
                end loop;
            elsif busy_reg = '1' then
                if last_word = '1' then
                    busy_reg <= '0';
                else
                    pc_reg <= fetch_address;
                end if;
            end if;
            -- A sample's end: a decimating one makes the first segment due; one that ran a
            -- segment the next, or, after the last, the outputs valid.
            if sample_end = '1' then
                if decimate_reg = '1' then
                    decimating_reg <= '1';
                    due_reg <= '1';
                    segment_reg <= (others => '0');
                    base_reg <= REGULAR_WORD;
                    segment_end_reg <= REGULAR_WORD + SEGMENT_WORDS - 1;
                elsif running_reg = '1' then
                    if final_reg = '1' then
                        due_reg <= '0';
                        out_valid_reg <= '1';
                        if seen_reg < SEEN_LIMIT then
                            seen_reg <= seen_reg + 1;
                        end if;
                    else
                        segment_reg <= segment_reg + 1;
                        base_reg <= base_reg + SEGMENT_WORDS;
                        segment_end_reg <= segment_end_reg + SEGMENT_WORDS;
                    end if;
                end if;
            end if;

            if rom_en = '1' then
                ref_negative_reg <= t(T_W - 1);
                if cosine = '1' and NCO_ERROR_FEEDBACK /= 0 then
                    -- What is left below the truncation, less half a bin: its top bit
                    -- inverted, read as signed.
                    residue_reg(residue_index) <= signed(phase(R_W - 1 downto 0)) xor HALF_BIN;
                end if;
            end if;
            if executing_reg = '1' and advance_field = '1' then
                if advance_gyro_field = '1' then
                    nco_acc_reg(1) <= nco_acc_reg(1) + freq_reg(1);
                else
                    nco_acc_reg(0) <= nco_acc_reg(0) + freq_reg(0);
                end if;
            end if;
            if read_en = '1' then
                read_zero_reg <= read_zero;
                read_preset_reg <= read_preset;
            end if;
            if accumulate_en = '1' then
                acc_reg <= acc_next;
            end if;

            -- The shared registers' points.
            case to_integer(point) is
                when 1 => p_reg <= p_next;
                when 2 => y_reg <= y_next;
                when 5 | 7 => v_reg <= v_next;
                when 10 => c_reg <= c_next;
                when 11 => cic_output_reg <= cic_output_next;
                when others =>
                    null;
            end case;
            -- Each gyro's.
            for g in 0 to 1 loop
                case to_integer(gyro_point(g)) is
                    when 3 => drive_q_reg(g) <= output_reg;
                    when 4 => amplitude_error_reg(g) <= error_next;
                    when 6 => freq_reg(g) <= unsigned(pll_out(NCO_PHASE_W - 1 downto 0));
                    when 8 => amplitude_reg(g) <= agc_out;
                    when 9 =>
                        -- The driven axis's code; the other's cleared.
                        if mode_reg(g) = '1' then
                            dac_x_reg(g) <= dac_now(g);
                            dac_y_reg(g) <= (others => '0');
                        else
                            dac_x_reg(g) <= (others => '0');
                            dac_y_reg(g) <= dac_now(g);
                        end if;
                        delay_reg(g)(0) <= drive;
                        for j in 1 to DELAY_N - 1 loop
                            delay_reg(g)(j) <= delay_reg(g)(j - 1);
                        end loop;
                    when 12 => rate_reg(g) <= rate_next;
                    when 13 => quad_reg(g) <= rate_next;
                    when 14 => inside_q_reg(g) <= within_limit;
                    when 15 => inside_reg(g) <= inside_q_reg(g) and within_limit;
                    when others =>
                        null;
                end case;
                if gyro_point(g) = 15 then
                    count_pending_reg(g) <= '1';
                else
                    count_pending_reg(g) <= '0';
                end if;
                if count_pending_reg(g) = '1' then
                    lock_count_reg(g) <= lock_count_next(g);
                    if lock_count_next(g) >= LOCK_HOLD then
                        locked_reg(g) <= '1';
                    else
                        locked_reg(g) <= '0';
                    end if;
                end if;
            end loop;

            if rst = '1' then
                busy_reg <= '0';
                pc_reg <= (others => '0');
                mode_reg <= (others => '1');
                start_reg <= '1';
                switching_reg <= (others => '0');
                first_reg <= '0';
                decimate_reg <= '0';
                count_reg <= (others => '0');
                seen_reg <= (others => '0');
                due_reg <= '0';
                segment_reg <= (others => '0');
                running_reg <= '0';
                final_reg <= '0';
                decimation_mode_reg <= (others => '1');
                adc_x_reg <= (others => (others => '0'));
                adc_y_reg <= (others => (others => '0'));
                nco_acc_reg <= (others => (others => '0'));
                freq_reg <= (others => (others => '0'));
                residue_reg <= (others => (others => '0'));
                read_zero_reg <= '0';
                read_preset_reg <= '0';
                acc_reg <= (others => '0');
                p_reg <= (others => '0');
                y_reg <= (others => '0');
                v_reg <= (others => '0');
                drive_q_reg <= (others => (others => '0'));
                amplitude_error_reg <= (others => (others => '0'));
                amplitude_reg <= (others => (others => '0'));
                c_reg <= (others => '0');
                cic_output_reg <= (others => '0');
                delay_reg <= (others => (others => (others => '0')));
                dac_x_reg <= (others => (others => '0'));
                dac_y_reg <= (others => (others => '0'));
                rate_reg <= (others => (others => '0'));
                quad_reg <= (others => (others => '0'));
                out_valid_reg <= '0';
                decimating_reg <= '0';
                inside_q_reg <= (others => '0');
                inside_reg <= (others => '0');
                count_pending_reg <= (others => '0');
                lock_count_reg <= (others => (others => '0'));
                locked_reg <= (others => '0');
            end if;
        end if;
    end process;

    dac_a_x <= dac_x_reg(0);
    dac_a_y <= dac_y_reg(0);
    dac_b_x <= dac_x_reg(1);
    dac_b_y <= dac_y_reg(1);
    locked_a <= locked_reg(0);
    locked_b <= locked_reg(1);
    decimating <= decimating_reg;
    rate_a <= rate_reg(0);
    quadrature_a <= quad_reg(0);
    rate_b <= rate_reg(1);
    quadrature_b <= quad_reg(1);
    out_valid <= out_valid_reg;

    -- pragma translate_off
    -- Simulation only: a sample takes the schedule's clocks (gyrofx_job::pipeline); a sooner
    -- ce stops the simulation, naming this instance.
    spacing_check : entity work.gyrofx_spacing_check
        generic map (
            MIN_CLOCKS_PER_SAMPLE => SCHEDULE_LEN + 2, BLOCK_NAME => "gyrofx_gyro_pair_serial"
        )
        port map (clk => clk, rst => rst, ce => ce);
    -- pragma translate_on
end architecture;
