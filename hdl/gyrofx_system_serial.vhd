-- Language: VHDL-2008

-- gyrofx_system_serial — the whole mode-reversal gyro at the ADC rate, folded: gyro A's and
-- B's loops on one folded datapath (gyrofx_gyro_pair_serial) feeding the time-multiplexed
-- chain (gyrofx_top_serial's sequencer and engine), whose sequencer commands the loops' modes,
-- wired as gyrofx_system wires gyrofx_gyro_loop and gyrofx_top (architecture = "serial").
--
-- Purpose: the VHDL twin of gyrofx_system_serial.v (same generics, ports and timing):
--   gyrofx_system on a small FPGA, bit-exact with it except that the chain's results show
--   CHAIN_DELAY_SAMPLES ADC samples later (gyrofx_job::golden::System::of;
--   docs/blocks/system.md, "Folded architecture").
--
-- Algorithm (per ADC sample, ce high), as gyrofx_system's:
--     mode_g = enable ? the chain's mode_g : normal      (loop g's mode input)
--     both loops take the sample in mode_g
--     when the loops output a decimated rate and enable was high at that ADC sample, the
--     chain takes y_a = rate_a, y_b = rate_b at the bw_sel of that sample
--   then, CHAIN_DELAY_SAMPLES ADC samples after the one whose rates the chain took, the
--   outputs rate_out, out_valid (a one-clock pulse), bias_a, bias_b, estimated load what the
--   chain made of them.
--
-- Why the delay: the folded pair takes up to SCHEDULE_LEN + 2 clocks an ADC sample and makes
--   a decimation's rates SCHEDULE_SEGMENTS ADC samples after the sample that decimates; the
--   serial chain takes its program's clocks (over a thousand) a chain sample and runs beside
--   the loops over many ADC samples. Its sequencer takes the sample at the end of the
--   decimating ADC sample, so that its modes change in time for the next one, as in
--   gyrofx_system; its engine starts when the rates are made, on the sequencer's flags as of
--   the take, and its results come within some later ADC sample that depends on the ce
--   cadence. The system publishes them a fixed number of ADC samples later instead,
--   CHAIN_DELAY_SAMPLES = SCHEDULE_SEGMENTS + ceil((chain clocks + margin) / (SCHEDULE_LEN + 3))
--   (gyrofx_job::pipeline::system_chain_delay), whatever the cadence; the engine holds its
--   results until then. CHAIN_DELAY_SAMPLES <= CIC_DECIMATION: the chain finishes between
--   chain samples.
--
-- Timing: ce at most every SCHEDULE_LEN + 3 clocks. Every output shows SCHEDULE_LEN + 3
--   clocks after ce: dac_*, locked_* load with the loops' (by SCHEDULE_LEN + 2 clocks) and
--   hold until the next sample's; mode_a, mode_b (the modes of the next sample) change the
--   clock after the sequencer's take, at the end of a decimating sample's regular part
--   (SCHEDULE_REGULAR + 3 clocks after ce), and hold otherwise; the published chain outputs
--   load at the loops' output clock, SCHEDULE_LEN + 2 clocks after ce, and hold otherwise
--   (out_valid for one clock). A clock with rst high clears every register and the pending
--   publication.
--
-- Generics: the chain's as gyrofx_top_serial's (its program and coefficient ROMs are the
--   system chain's), IN_F the loops' output fraction bits; the loops' as gyrofx_system's
--   (shared ones once, ROUNDING, SATURATE, LATENCY as LOOP_*, per gyro with the prefix A_ or
--   B_), plus the folded pair's schedule (both gyros' loops have the same formats);
--   CHAIN_DELAY_SAMPLES.

library ieee;
use ieee.std_logic_1164.all;
use ieee.numeric_std.all;

entity gyrofx_system_serial is
    generic (
        -- chain: sequencer (PATTERN: rightmost bit = interval 0)
        INTERVAL_LENGTH : positive := 3;
        INTERVALS : positive := 4;
        PATTERN : std_logic_vector := 4x"5";
        BLANK : natural := 1;
        STAGGER : natural := 0;
        PHASE_W : positive := 2;
        INTERVAL_W : positive := 2;
        -- chain: gyro samples (the loops' rate output, IN_F its fraction bits), rate output and
        -- bias outputs: widths
        IN_W : positive := 24;
        IN_F : natural := 14;
        OUT_W : positive := 24;
        BIAS_W : positive := 28;
        SEL_W : positive := 2;
        -- KF gain words: bw_sel must be below ROM_DEPTH
        ROM_DEPTH : positive := 3;
        -- chain: the engine (gyrofx_serial_engine), written by gyrofx for the system's chain
        ACC_W : positive := 32;
        ADDR_W : positive := 6;
        COEF_ADDR_W : positive := 5;
        RAM_DEPTH : positive := 53;
        COEF_DEPTH : positive := 29;
        PROGRAM_DEPTH : positive := 388;
        RAM_INDEX_SHIFT : natural := 1;
        COEF_INDEX_SHIFT : natural := 2;
        -- chain rounding: 0 floor, 1 ceil, 2 zero, 3 nearest, 4 round, 5 convergent
        ROUNDING : natural := 3;
        PROGRAM_FILE : string := "system_serial_program.mem";
        COEFFICIENT_FILE : string := "system_serial_coefficients.mem";
        -- loops (shared by both gyros): NCOs, demodulators, PLL and AGC formats, CICs, DAC
        NCO_PHASE_W : positive := 32;
        NCO_ADDR_W : positive := 10;
        NCO_SIN_W : positive := 18;
        NCO_ERROR_FEEDBACK : natural := 1;
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
        PLL_ERR_W : positive := 32;
        PLL_ERR_F : integer := 30;
        PLL_INT_W : positive := 40;
        PLL_INT_F : integer := 38;
        PLL_OUT_W : positive := 32;
        PLL_OUT_F : integer := 32;
        AGC_ERR_W : positive := 32;
        AGC_ERR_F : integer := 30;
        AGC_INT_W : positive := 40;
        AGC_INT_F : integer := 20;
        AGC_OUT_W : positive := 24;
        AGC_OUT_F : integer := 6;
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
        DAC_W : positive := 18;
        DAC_F : integer := 0;
        -- loops: ADC-to-DAC latency (samples), lock detector, rounding and overflow, ROM images
        LOOP_LATENCY : natural := 1;
        LOCK_SHIFT : positive := 9;
        LOCK_HOLD : natural := 2000;
        LOOP_ROUNDING : natural := 3;
        LOOP_SATURATE : natural := 1;
        NCO_ROM_FILE : string := "gyro_loop_nco_sine.mem";
        CIC_ROM_FILE : string := "gyro_loop_cic_taps.mem";
        -- gyro A's loop: PI gains and limits, 1/SF format, per-mode values (_N normal, _R reverse)
        A_PLL_KP_W : positive := 18;
        A_PLL_KP_F : integer := 27;
        A_PLL_KI_W : positive := 18;
        A_PLL_KI_F : integer := 38;
        A_PLL_KP : std_logic_vector := 18x"10625";
        A_PLL_KI : std_logic_vector := 18x"17795";
        A_PLL_INT_MIN : std_logic_vector := 40x"292cd0c7b";
        A_PLL_INT_MAX : std_logic_vector := 40x"2a786ac8d";
        A_AGC_KP_W : positive := 18;
        A_AGC_KP_F : integer := 1;
        A_AGC_KI_W : positive := 18;
        A_AGC_KI_F : integer := 11;
        A_AGC_KP : std_logic_vector := 18x"19a9a";
        A_AGC_KI : std_logic_vector := 18x"12624";
        A_AGC_INT_MIN : std_logic_vector := 40x"0";
        A_AGC_INT_MAX : std_logic_vector := 40x"1ffff00000";
        A_COEF_W : positive := 24;
        A_COEF_F : integer := 6;
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
        -- gyro B's loop: the same
        B_PLL_KP_W : positive := 18;
        B_PLL_KP_F : integer := 27;
        B_PLL_KI_W : positive := 18;
        B_PLL_KI_F : integer := 38;
        B_PLL_KP : std_logic_vector := 18x"10625";
        B_PLL_KI : std_logic_vector := 18x"17795";
        B_PLL_INT_MIN : std_logic_vector := 40x"292cd0c7b";
        B_PLL_INT_MAX : std_logic_vector := 40x"2a786ac8d";
        B_AGC_KP_W : positive := 18;
        B_AGC_KP_F : integer := 1;
        B_AGC_KI_W : positive := 18;
        B_AGC_KI_F : integer := 11;
        B_AGC_KP : std_logic_vector := 18x"19a9a";
        B_AGC_KI : std_logic_vector := 18x"12624";
        B_AGC_INT_MIN : std_logic_vector := 40x"0";
        B_AGC_INT_MAX : std_logic_vector := 40x"1ffff00000";
        B_COEF_W : positive := 24;
        B_COEF_F : integer := 6;
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
        -- loops: the folded pair's schedule (gyrofx_gyro_pair_serial): image, words of the
        -- longest sample, of the regular part, deferred segments, RAM words
        SCHEDULE_FILE : string := "gyro_pair_schedule.mem";
        SCHEDULE_LEN : positive := 117;
        SCHEDULE_REGULAR : positive := 103;
        SCHEDULE_SEGMENTS : positive := 13;
        RAM_WORDS : positive := 64;
        -- ADC samples from the one whose rates the chain takes to the one that publishes its
        -- outputs (1..CIC_DECIMATION; gyrofx_job::pipeline::system_chain_delay)
        CHAIN_DELAY_SAMPLES : positive := 26
    );
    port (
        clk       : in  std_logic;
        rst       : in  std_logic;
        ce        : in  std_logic;
        enable    : in  std_logic;
        bw_sel    : in  unsigned(SEL_W - 1 downto 0);
        adc_a_x   : in  signed(DEMOD_ADC_W - 1 downto 0);
        adc_a_y   : in  signed(DEMOD_ADC_W - 1 downto 0);
        adc_b_x   : in  signed(DEMOD_ADC_W - 1 downto 0);
        adc_b_y   : in  signed(DEMOD_ADC_W - 1 downto 0);
        dac_a_x   : out signed(DAC_W - 1 downto 0);
        dac_a_y   : out signed(DAC_W - 1 downto 0);
        dac_b_x   : out signed(DAC_W - 1 downto 0);
        dac_b_y   : out signed(DAC_W - 1 downto 0);
        locked_a  : out std_logic;
        locked_b  : out std_logic;
        mode_a    : out std_logic;
        mode_b    : out std_logic;
        out_valid : out std_logic;
        rate_out  : out signed(OUT_W - 1 downto 0);
        bias_a    : out signed(BIAS_W - 1 downto 0);
        bias_b    : out signed(BIAS_W - 1 downto 0);
        estimated : out std_logic
    );
end entity;

architecture rtl of gyrofx_system_serial is

    -- Clocks from ce to the loops' outputs (gyrofx_job::pipeline::gyro_loop): the output clock.
    constant LOOP_CLOCKS : positive := SCHEDULE_LEN + 2;

    -- enable and bw_sel as of the ADC sample in flight: the loops' decimated output comes
    -- SCHEDULE_LEN + 2 clocks after its ce, while the inputs may already describe the next.
    signal enable_reg : std_logic := '0';
    signal bw_sel_reg : unsigned(SEL_W - 1 downto 0) := (others => '0');
    signal chain_mode_a : std_logic;
    signal chain_mode_b : std_logic;
    signal loop_mode_a : std_logic;
    signal loop_mode_b : std_logic;
    signal rate_a : signed(IN_W - 1 downto 0);
    signal rate_b : signed(IN_W - 1 downto 0);
    signal decimating : std_logic;
    signal rates_valid : std_logic;

    -- The chain's sequencer: its take and its description of the sample taken.
    signal take : std_logic;
    signal blank_a : std_logic;
    signal blank_b : std_logic;
    signal interval_a : unsigned(INTERVAL_W - 1 downto 0);
    signal interval_b : unsigned(INTERVAL_W - 1 downto 0);
    signal done_a : std_logic;
    signal done_b : std_logic;
    signal window_done : std_logic;
    -- That description, held for the engine, and whether a take waits for its rates.
    signal taken_reg : std_logic := '0';
    signal taken_bw_sel_reg : unsigned(SEL_W - 1 downto 0) := (others => '0');
    signal taken_mode_a_reg : std_logic := '1';
    signal taken_mode_b_reg : std_logic := '1';
    signal taken_blank_a_reg : std_logic := '0';
    signal taken_blank_b_reg : std_logic := '0';
    signal taken_interval_a_reg : unsigned(INTERVAL_W - 1 downto 0) := (others => '0');
    signal taken_interval_b_reg : unsigned(INTERVAL_W - 1 downto 0) := (others => '0');
    signal taken_done_a_reg : std_logic := '0';
    signal taken_done_b_reg : std_logic := '0';
    signal taken_window_done_reg : std_logic := '0';

    signal chain_ce : std_logic;
    signal chain_rate : signed(OUT_W - 1 downto 0);
    signal chain_valid : std_logic;
    signal chain_bias_a : signed(BIAS_W - 1 downto 0);
    signal chain_bias_b : signed(BIAS_W - 1 downto 0);
    signal chain_estimated : std_logic;

    -- Clocks since ce, up to the output clock (0: none in flight).
    signal count_reg : natural range 0 to LOOP_CLOCKS := 0;
    signal output_clock : std_logic;
    -- Output clocks until the chain's last take is published (0: none pending), whether the
    -- engine has pulsed out_valid since it took it (not when both gyros were blanked), and
    -- whether a take of this sample waits for its output clock.
    signal pending_reg : natural range 0 to CHAIN_DELAY_SAMPLES := 0;
    signal chain_valid_reg : std_logic := '0';
    signal take_pending_reg : std_logic := '0';
    signal publish : std_logic;

    signal out_valid_reg : std_logic := '0';
    signal rate_out_reg : signed(OUT_W - 1 downto 0) := (others => '0');
    signal bias_a_reg : signed(BIAS_W - 1 downto 0) := (others => '0');
    signal bias_b_reg : signed(BIAS_W - 1 downto 0) := (others => '0');
    signal estimated_reg : std_logic := '0';

begin

    assert CHAIN_DELAY_SAMPLES <= CIC_DECIMATION
        report "gyrofx_system_serial: CHAIN_DELAY_SAMPLES (" & integer'image(CHAIN_DELAY_SAMPLES)
            & ") must be 1..CIC_DECIMATION (" & integer'image(CIC_DECIMATION)
            & "): the chain finishes between chain samples"
        severity failure;
    assert ROM_DEPTH <= 2 ** SEL_W
        report "gyrofx_system_serial: ROM_DEPTH (" & integer'image(ROM_DEPTH)
            & ") must be 1..2^SEL_W (" & integer'image(2 ** SEL_W) & ")"
        severity failure;
    -- The folded pair gives both gyros one datapath: one set of formats.
    assert A_PLL_KP_W = B_PLL_KP_W and A_PLL_KP_F = B_PLL_KP_F and A_PLL_KI_W = B_PLL_KI_W
        and A_PLL_KI_F = B_PLL_KI_F and A_AGC_KP_W = B_AGC_KP_W and A_AGC_KP_F = B_AGC_KP_F
        and A_AGC_KI_W = B_AGC_KI_W and A_AGC_KI_F = B_AGC_KI_F and A_COEF_W = B_COEF_W
        and A_COEF_F = B_COEF_F
        report "gyrofx_system_serial: gyro A's and B's loops must share their gains' and 1/SF "
            & "coefficients' formats (one folded datapath)"
        severity failure;

    process (clk)
    begin
        if rising_edge(clk) then
            if ce = '1' then
                enable_reg <= enable;
                bw_sel_reg <= bw_sel;
            end if;
            if rst = '1' then
                enable_reg <= '0';
                bw_sel_reg <= (others => '0');
            end if;
        end if;
    end process;

    loop_mode_a <= chain_mode_a when enable = '1' else '1';
    loop_mode_b <= chain_mode_b when enable = '1' else '1';

    loops : entity work.gyrofx_gyro_pair_serial
        generic map (
            NCO_PHASE_W => NCO_PHASE_W, NCO_ADDR_W => NCO_ADDR_W, NCO_SIN_W => NCO_SIN_W,
            NCO_ERROR_FEEDBACK => NCO_ERROR_FEEDBACK,
            DEMOD_ADC_W => DEMOD_ADC_W, DEMOD_ADC_F => DEMOD_ADC_F, DEMOD_REF_W => DEMOD_REF_W,
            DEMOD_REF_F => DEMOD_REF_F, DEMOD_PROD_W => DEMOD_PROD_W,
            DEMOD_PROD_F => DEMOD_PROD_F, DEMOD_STATE_W => DEMOD_STATE_W,
            DEMOD_STATE_F => DEMOD_STATE_F, DEMOD_OUT_W => DEMOD_OUT_W,
            DEMOD_OUT_F => DEMOD_OUT_F, DEMOD_SHIFT => DEMOD_SHIFT, PLL_ERR_W => PLL_ERR_W,
            PLL_ERR_F => PLL_ERR_F, PLL_KP_W => A_PLL_KP_W, PLL_KP_F => A_PLL_KP_F,
            PLL_KI_W => A_PLL_KI_W, PLL_KI_F => A_PLL_KI_F, PLL_INT_W => PLL_INT_W,
            PLL_INT_F => PLL_INT_F, PLL_OUT_W => PLL_OUT_W, PLL_OUT_F => PLL_OUT_F,
            AGC_ERR_W => AGC_ERR_W, AGC_ERR_F => AGC_ERR_F, AGC_KP_W => A_AGC_KP_W,
            AGC_KP_F => A_AGC_KP_F, AGC_KI_W => A_AGC_KI_W, AGC_KI_F => A_AGC_KI_F,
            AGC_INT_W => AGC_INT_W, AGC_INT_F => AGC_INT_F, AGC_OUT_W => AGC_OUT_W,
            AGC_OUT_F => AGC_OUT_F,
            CIC_IN_W => CIC_IN_W, CIC_IN_F => CIC_IN_F, CIC_STAGES => CIC_STAGES,
            CIC_DECIMATION => CIC_DECIMATION, CIC_DELAY => CIC_DELAY, CIC_SHIFT => CIC_SHIFT,
            CIC_MID_W => CIC_MID_W, CIC_MID_F => CIC_MID_F, CIC_TAPS => CIC_TAPS,
            CIC_COEF_W => CIC_COEF_W, CIC_COEF_F => CIC_COEF_F, CIC_OUT_W => CIC_OUT_W,
            CIC_OUT_F => CIC_OUT_F, DAC_W => DAC_W, DAC_F => DAC_F, OUT_W => IN_W,
            OUT_F => IN_F, COEF_W => A_COEF_W, COEF_F => A_COEF_F, LATENCY => LOOP_LATENCY,
            LOCK_SHIFT => LOCK_SHIFT, LOCK_HOLD => LOCK_HOLD,
            A_PLL_KP => A_PLL_KP, A_PLL_KI => A_PLL_KI, A_PLL_INT_MIN => A_PLL_INT_MIN,
            A_PLL_INT_MAX => A_PLL_INT_MAX, A_AGC_KP => A_AGC_KP, A_AGC_KI => A_AGC_KI,
            A_AGC_INT_MIN => A_AGC_INT_MIN, A_AGC_INT_MAX => A_AGC_INT_MAX,
            A_SETPOINT_N => A_SETPOINT_N, A_SETPOINT_R => A_SETPOINT_R,
            A_FREQ_WORD_N => A_FREQ_WORD_N, A_FREQ_WORD_R => A_FREQ_WORD_R,
            A_PLL_PRESET_N => A_PLL_PRESET_N, A_PLL_PRESET_R => A_PLL_PRESET_R,
            A_DAC_OFFSET_N => A_DAC_OFFSET_N, A_DAC_OFFSET_R => A_DAC_OFFSET_R,
            A_SENSE_OFFSET_N => A_SENSE_OFFSET_N, A_SENSE_OFFSET_R => A_SENSE_OFFSET_R,
            A_RATE_COEF_N => A_RATE_COEF_N, A_RATE_COEF_R => A_RATE_COEF_R,
            A_QUAD_COEF_N => A_QUAD_COEF_N, A_QUAD_COEF_R => A_QUAD_COEF_R,
            A_LOCK_Q_N => A_LOCK_Q_N, A_LOCK_Q_R => A_LOCK_Q_R, A_LOCK_A_N => A_LOCK_A_N,
            A_LOCK_A_R => A_LOCK_A_R,
            B_PLL_KP => B_PLL_KP, B_PLL_KI => B_PLL_KI, B_PLL_INT_MIN => B_PLL_INT_MIN,
            B_PLL_INT_MAX => B_PLL_INT_MAX, B_AGC_KP => B_AGC_KP, B_AGC_KI => B_AGC_KI,
            B_AGC_INT_MIN => B_AGC_INT_MIN, B_AGC_INT_MAX => B_AGC_INT_MAX,
            B_SETPOINT_N => B_SETPOINT_N, B_SETPOINT_R => B_SETPOINT_R,
            B_FREQ_WORD_N => B_FREQ_WORD_N, B_FREQ_WORD_R => B_FREQ_WORD_R,
            B_PLL_PRESET_N => B_PLL_PRESET_N, B_PLL_PRESET_R => B_PLL_PRESET_R,
            B_DAC_OFFSET_N => B_DAC_OFFSET_N, B_DAC_OFFSET_R => B_DAC_OFFSET_R,
            B_SENSE_OFFSET_N => B_SENSE_OFFSET_N, B_SENSE_OFFSET_R => B_SENSE_OFFSET_R,
            B_RATE_COEF_N => B_RATE_COEF_N, B_RATE_COEF_R => B_RATE_COEF_R,
            B_QUAD_COEF_N => B_QUAD_COEF_N, B_QUAD_COEF_R => B_QUAD_COEF_R,
            B_LOCK_Q_N => B_LOCK_Q_N, B_LOCK_Q_R => B_LOCK_Q_R, B_LOCK_A_N => B_LOCK_A_N,
            B_LOCK_A_R => B_LOCK_A_R,
            ROUNDING => LOOP_ROUNDING, SATURATE => LOOP_SATURATE, NCO_ROM_FILE => NCO_ROM_FILE,
            CIC_ROM_FILE => CIC_ROM_FILE, SCHEDULE_FILE => SCHEDULE_FILE,
            SCHEDULE_LEN => SCHEDULE_LEN, SCHEDULE_REGULAR => SCHEDULE_REGULAR,
            SCHEDULE_SEGMENTS => SCHEDULE_SEGMENTS, RAM_WORDS => RAM_WORDS
        )
        port map (
            clk => clk, rst => rst, ce => ce, mode_a => loop_mode_a, mode_b => loop_mode_b,
            adc_a_x => adc_a_x, adc_a_y => adc_a_y, adc_b_x => adc_b_x, adc_b_y => adc_b_y,
            dac_a_x => dac_a_x, dac_a_y => dac_a_y, dac_b_x => dac_b_x, dac_b_y => dac_b_y,
            locked_a => locked_a, locked_b => locked_b, decimating => decimating,
            rate_a => rate_a, quadrature_a => open, rate_b => rate_b, quadrature_b => open,
            out_valid => rates_valid
        );

    -- The chain: its sequencer takes the sample at the end of the decimating ADC sample (its
    -- modes change the clock after, in time for the next ADC sample, as in gyrofx_system);
    -- the engine (gyrofx_top_serial's, one shared multiplier) starts when the loops' deferred
    -- work has made that sample's rates, SCHEDULE_SEGMENTS ADC samples later, on the
    -- sequencer's flags and the bw_sel as of the take.
    take <= decimating and enable_reg;

    sequencer : entity work.gyrofx_sequencer
        generic map (
            INTERVAL_LENGTH => INTERVAL_LENGTH, INTERVALS => INTERVALS, PATTERN => PATTERN,
            BLANK => BLANK, STAGGER => STAGGER, PHASE_W => PHASE_W, INTERVAL_W => INTERVAL_W
        )
        port map (
            clk => clk, rst => rst, ce => take,
            mode_a => chain_mode_a, mode_b => chain_mode_b, blank_a => blank_a,
            blank_b => blank_b, interval_a => interval_a, interval_b => interval_b,
            done_a => done_a, done_b => done_b, window_done => window_done
        );

    -- The sequencer's description of the taken sample, held for the engine, and whether a
    -- take waits for its rates.
    process (clk)
    begin
        if rising_edge(clk) then
            if take = '1' then
                taken_reg <= '1';
                taken_bw_sel_reg <= bw_sel_reg;
                taken_mode_a_reg <= chain_mode_a;
                taken_mode_b_reg <= chain_mode_b;
                taken_blank_a_reg <= blank_a;
                taken_blank_b_reg <= blank_b;
                taken_interval_a_reg <= interval_a;
                taken_interval_b_reg <= interval_b;
                taken_done_a_reg <= done_a;
                taken_done_b_reg <= done_b;
                taken_window_done_reg <= window_done;
            elsif rates_valid = '1' then
                taken_reg <= '0';
            end if;
            if rst = '1' then
                taken_reg <= '0';
            end if;
        end if;
    end process;

    chain_ce <= rates_valid and taken_reg;

    engine : entity work.gyrofx_serial_engine
        generic map (
            IN_W => IN_W, OUT_W => OUT_W, BIAS_W => BIAS_W, SEL_W => SEL_W,
            INTERVAL_W => INTERVAL_W, ACC_W => ACC_W, ADDR_W => ADDR_W,
            COEF_ADDR_W => COEF_ADDR_W, RAM_DEPTH => RAM_DEPTH, COEF_DEPTH => COEF_DEPTH,
            PROGRAM_DEPTH => PROGRAM_DEPTH, RAM_INDEX_SHIFT => RAM_INDEX_SHIFT,
            COEF_INDEX_SHIFT => COEF_INDEX_SHIFT, ROUNDING => ROUNDING,
            PROGRAM_FILE => PROGRAM_FILE, COEFFICIENT_FILE => COEFFICIENT_FILE,
            -- The rates hold at the pair's outputs for a decimation and the results where the
            -- program assembles them until the next chain sample's program: both outlast the
            -- chain and the publication's delay, so neither is copied (as the Verilog).
            CAPTURE_SAMPLES => 0, HOLD_RESULTS => 0
        )
        port map (
            clk => clk, rst => rst, ce => chain_ce, bw_sel => taken_bw_sel_reg, y_a => rate_a,
            y_b => rate_b, mode_a => taken_mode_a_reg, mode_b => taken_mode_b_reg,
            blank_a => taken_blank_a_reg, blank_b => taken_blank_b_reg,
            done_a => taken_done_a_reg, done_b => taken_done_b_reg,
            window_done => taken_window_done_reg, interval_a => taken_interval_a_reg,
            interval_b => taken_interval_b_reg, rate_out => chain_rate,
            out_valid => chain_valid, bias_a => chain_bias_a, bias_b => chain_bias_b,
            estimated => chain_estimated, busy => open
        );

    output_clock <= '1' when count_reg = LOOP_CLOCKS else '0';
    publish <= '1' when output_clock = '1' and pending_reg = 1 else '0';

    process (clk)
    begin
        if rising_edge(clk) then
            if ce = '1' then
                count_reg <= 1;
            elsif count_reg /= 0 and output_clock = '0' then
                count_reg <= count_reg + 1;
            else
                count_reg <= 0;
            end if;
            -- A take (in this sample, before its output clock) starts the count down at the
            -- output clock; CHAIN_DELAY_SAMPLES output clocks later, publish.
            if take = '1' then
                take_pending_reg <= '1';
            end if;
            if output_clock = '1' then
                if take_pending_reg = '1' or take = '1' then
                    pending_reg <= CHAIN_DELAY_SAMPLES;
                    take_pending_reg <= '0';
                elsif pending_reg /= 0 then
                    pending_reg <= pending_reg - 1;
                end if;
            end if;
            if publish = '1' then
                chain_valid_reg <= '0';
            end if;
            if chain_valid = '1' then
                chain_valid_reg <= '1';
            end if;
            out_valid_reg <= publish and chain_valid_reg;
            -- The rate only when the engine's program made one.
            if publish = '1' and chain_valid_reg = '1' then
                rate_out_reg <= chain_rate;
            end if;
            if publish = '1' then
                bias_a_reg <= chain_bias_a;
                bias_b_reg <= chain_bias_b;
                estimated_reg <= chain_estimated;
            end if;
            if rst = '1' then
                count_reg <= 0;
                pending_reg <= 0;
                take_pending_reg <= '0';
                chain_valid_reg <= '0';
                out_valid_reg <= '0';
                rate_out_reg <= (others => '0');
                bias_a_reg <= (others => '0');
                bias_b_reg <= (others => '0');
                estimated_reg <= '0';
            end if;
        end if;
    end process;

    mode_a <= chain_mode_a;
    mode_b <= chain_mode_b;
    out_valid <= out_valid_reg;
    rate_out <= rate_out_reg;
    bias_a <= bias_a_reg;
    bias_b <= bias_b_reg;
    estimated <= estimated_reg;

    -- pragma translate_off
    -- Simulation only: the system takes a sample at most every SCHEDULE_LEN + 3 clocks
    -- (gyrofx_job::pipeline::system), so that the chain's modes describe the next sample; a
    -- sooner ce stops the simulation, naming this instance.
    spacing_check : entity work.gyrofx_spacing_check
        generic map (MIN_CLOCKS_PER_SAMPLE => SCHEDULE_LEN + 3, BLOCK_NAME => "gyrofx_system_serial")
        port map (clk => clk, rst => rst, ce => ce);
    -- pragma translate_on
end architecture;
