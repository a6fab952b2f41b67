-- Language: VHDL-2008

-- gyrofx_system — the whole mode-reversal gyro at the ADC rate: gyro A's and B's loops
-- (gyrofx_gyro_loop) feeding the chain (gyrofx_top), whose sequencer commands the loops'
-- modes.
--
-- Purpose: the VHDL twin of gyrofx_system.v (same generics, ports and timing): ADC codes of
--   both axes of both gyros in, DAC codes and the calibrated, filtered rate out (SPEC 1.6
--   and 1). Bit-exact with gyrofx_model::system::FixedSystem; docs/blocks/system.md
--   documents it.
--
-- Algorithm (per ADC sample, ce high):
--     mode_g = enable ? the chain's mode_g : normal      (loop g's mode input)
--     both loops take the sample in mode_g
--     when the loops output a decimated rate (A's out_valid; B's comes with it) and enable
--     was high at that ADC sample, the chain takes y_a = rate_a, y_b = rate_b at the
--     bw_sel of that sample
--   enable low holds the chain and runs both loops in normal mode.
--
-- Timing: ce at most every 5th clock. dac_*, locked_* are valid 4 clocks after ce; the
--   chain's outputs change 10 clocks after the ce of the ADC sample that ends a chain
--   period. A clock with rst high clears every register.

library ieee;
use ieee.std_logic_1164.all;
use ieee.numeric_std.all;

entity gyrofx_system is
    generic (
        -- chain: sequencer (PATTERN: rightmost bit = interval 0)
        INTERVAL_LENGTH : positive := 150;
        INTERVALS : positive := 4;
        PATTERN : std_logic_vector := 4x"5";
        BLANK : natural := 30;
        STAGGER : natural := 0;
        PHASE_W : positive := 8;
        INTERVAL_W : positive := 2;
        -- chain: gyro samples (the loops' rate output, the KF input and the calibrated format)
        IN_W : positive := 24;
        IN_F : natural := 14;
        -- chain: estimator
        ACC_W : positive := 32;
        RECIP_W : positive := 18;
        RECIP_F : natural := 23;
        RECIP : std_logic_vector := 18x"11111";
        MEAN_W : positive := 28;
        MEAN_F : natural := 18;
        GAIN_W : positive := 18;
        GAIN_F : natural := 18;
        DOT_W : positive := 49;
        BIAS_W : positive := 28;
        BIAS_F : natural := 18;
        SMOOTH : natural := 0;
        GAIN_ROM_FILE : string := "estimator_gains.mem";
        -- chain: KF
        STATE_W : positive := 36;
        STATE_F : natural := 26;
        OUT_W : positive := 24;
        OUT_F : natural := 14;
        G1_W : positive := 18;
        G1_F : natural := 17;
        G2_W : positive := 18;
        G2_F : natural := 38;
        SEL_W : positive := 2;
        ROM_DEPTH : positive := 3;
        KF_ROM_FILE : string := "kf_coefficients.mem";
        -- chain rounding: 0 floor, 1 ceil, 2 zero, 3 nearest, 4 round, 5 convergent; overflow: 0 wrap, 1 saturate
        ROUNDING : natural := 3;
        SATURATE : natural := 1;
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
        NCO_ROM_FILE : string := "nco_sine.mem";
        CIC_ROM_FILE : string := "cic_taps.mem";
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
        B_LOCK_A_R : std_logic_vector := 64x"68db574"
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

architecture rtl of gyrofx_system is

    -- enable and bw_sel as of the ADC sample in flight: the loops' decimated output comes 4
    -- clocks after its ce, while the inputs may already describe the next.
    signal enable_reg : std_logic := '0';
    signal bw_sel_reg : unsigned(SEL_W - 1 downto 0) := (others => '0');
    signal chain_mode_a : std_logic;
    signal chain_mode_b : std_logic;
    signal loop_mode_a : std_logic;
    signal loop_mode_b : std_logic;
    signal rate_a : signed(IN_W - 1 downto 0);
    signal rate_b : signed(IN_W - 1 downto 0);
    signal loop_valid : std_logic;
    signal chain_ce : std_logic;

begin

    process (clk)
    begin
        if rising_edge(clk) then
            if rst = '1' then
                enable_reg <= '0';
                bw_sel_reg <= (others => '0');
            elsif ce = '1' then
                enable_reg <= enable;
                bw_sel_reg <= bw_sel;
            end if;
        end if;
    end process;

    loop_mode_a <= chain_mode_a when enable = '1' else '1';
    loop_mode_b <= chain_mode_b when enable = '1' else '1';

    loop_a : entity work.gyrofx_gyro_loop
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
            PLL_KP => A_PLL_KP, PLL_KI => A_PLL_KI, PLL_INT_MIN => A_PLL_INT_MIN,
            PLL_INT_MAX => A_PLL_INT_MAX, AGC_ERR_W => AGC_ERR_W, AGC_ERR_F => AGC_ERR_F,
            AGC_KP_W => A_AGC_KP_W, AGC_KP_F => A_AGC_KP_F, AGC_KI_W => A_AGC_KI_W,
            AGC_KI_F => A_AGC_KI_F, AGC_INT_W => AGC_INT_W, AGC_INT_F => AGC_INT_F,
            AGC_OUT_W => AGC_OUT_W, AGC_OUT_F => AGC_OUT_F, AGC_KP => A_AGC_KP,
            AGC_KI => A_AGC_KI, AGC_INT_MIN => A_AGC_INT_MIN, AGC_INT_MAX => A_AGC_INT_MAX,
            CIC_IN_W => CIC_IN_W, CIC_IN_F => CIC_IN_F, CIC_STAGES => CIC_STAGES,
            CIC_DECIMATION => CIC_DECIMATION, CIC_DELAY => CIC_DELAY, CIC_SHIFT => CIC_SHIFT,
            CIC_MID_W => CIC_MID_W, CIC_MID_F => CIC_MID_F, CIC_TAPS => CIC_TAPS,
            CIC_COEF_W => CIC_COEF_W, CIC_COEF_F => CIC_COEF_F, CIC_OUT_W => CIC_OUT_W,
            CIC_OUT_F => CIC_OUT_F, DAC_W => DAC_W, DAC_F => DAC_F, OUT_W => IN_W,
            OUT_F => IN_F, COEF_W => A_COEF_W, COEF_F => A_COEF_F, LATENCY => LOOP_LATENCY,
            LOCK_SHIFT => LOCK_SHIFT, LOCK_HOLD => LOCK_HOLD, SETPOINT_N => A_SETPOINT_N,
            SETPOINT_R => A_SETPOINT_R, FREQ_WORD_N => A_FREQ_WORD_N,
            FREQ_WORD_R => A_FREQ_WORD_R, PLL_PRESET_N => A_PLL_PRESET_N,
            PLL_PRESET_R => A_PLL_PRESET_R, DAC_OFFSET_N => A_DAC_OFFSET_N,
            DAC_OFFSET_R => A_DAC_OFFSET_R, SENSE_OFFSET_N => A_SENSE_OFFSET_N,
            SENSE_OFFSET_R => A_SENSE_OFFSET_R, RATE_COEF_N => A_RATE_COEF_N,
            RATE_COEF_R => A_RATE_COEF_R, QUAD_COEF_N => A_QUAD_COEF_N,
            QUAD_COEF_R => A_QUAD_COEF_R, LOCK_Q_N => A_LOCK_Q_N, LOCK_Q_R => A_LOCK_Q_R,
            LOCK_A_N => A_LOCK_A_N, LOCK_A_R => A_LOCK_A_R, ROUNDING => LOOP_ROUNDING,
            SATURATE => LOOP_SATURATE, NCO_ROM_FILE => NCO_ROM_FILE,
            CIC_ROM_FILE => CIC_ROM_FILE
        )
        port map (
            clk => clk, rst => rst, ce => ce, mode => loop_mode_a, adc_x => adc_a_x,
            adc_y => adc_a_y, dac_x => dac_a_x, dac_y => dac_a_y, rate => rate_a,
            quadrature => open, out_valid => loop_valid, locked => locked_a
        );

    -- B decimates by the same factor from the same reset: its out_valid is A's.
    loop_b : entity work.gyrofx_gyro_loop
        generic map (
            NCO_PHASE_W => NCO_PHASE_W, NCO_ADDR_W => NCO_ADDR_W, NCO_SIN_W => NCO_SIN_W,
            NCO_ERROR_FEEDBACK => NCO_ERROR_FEEDBACK,
            DEMOD_ADC_W => DEMOD_ADC_W, DEMOD_ADC_F => DEMOD_ADC_F, DEMOD_REF_W => DEMOD_REF_W,
            DEMOD_REF_F => DEMOD_REF_F, DEMOD_PROD_W => DEMOD_PROD_W,
            DEMOD_PROD_F => DEMOD_PROD_F, DEMOD_STATE_W => DEMOD_STATE_W,
            DEMOD_STATE_F => DEMOD_STATE_F, DEMOD_OUT_W => DEMOD_OUT_W,
            DEMOD_OUT_F => DEMOD_OUT_F, DEMOD_SHIFT => DEMOD_SHIFT, PLL_ERR_W => PLL_ERR_W,
            PLL_ERR_F => PLL_ERR_F, PLL_KP_W => B_PLL_KP_W, PLL_KP_F => B_PLL_KP_F,
            PLL_KI_W => B_PLL_KI_W, PLL_KI_F => B_PLL_KI_F, PLL_INT_W => PLL_INT_W,
            PLL_INT_F => PLL_INT_F, PLL_OUT_W => PLL_OUT_W, PLL_OUT_F => PLL_OUT_F,
            PLL_KP => B_PLL_KP, PLL_KI => B_PLL_KI, PLL_INT_MIN => B_PLL_INT_MIN,
            PLL_INT_MAX => B_PLL_INT_MAX, AGC_ERR_W => AGC_ERR_W, AGC_ERR_F => AGC_ERR_F,
            AGC_KP_W => B_AGC_KP_W, AGC_KP_F => B_AGC_KP_F, AGC_KI_W => B_AGC_KI_W,
            AGC_KI_F => B_AGC_KI_F, AGC_INT_W => AGC_INT_W, AGC_INT_F => AGC_INT_F,
            AGC_OUT_W => AGC_OUT_W, AGC_OUT_F => AGC_OUT_F, AGC_KP => B_AGC_KP,
            AGC_KI => B_AGC_KI, AGC_INT_MIN => B_AGC_INT_MIN, AGC_INT_MAX => B_AGC_INT_MAX,
            CIC_IN_W => CIC_IN_W, CIC_IN_F => CIC_IN_F, CIC_STAGES => CIC_STAGES,
            CIC_DECIMATION => CIC_DECIMATION, CIC_DELAY => CIC_DELAY, CIC_SHIFT => CIC_SHIFT,
            CIC_MID_W => CIC_MID_W, CIC_MID_F => CIC_MID_F, CIC_TAPS => CIC_TAPS,
            CIC_COEF_W => CIC_COEF_W, CIC_COEF_F => CIC_COEF_F, CIC_OUT_W => CIC_OUT_W,
            CIC_OUT_F => CIC_OUT_F, DAC_W => DAC_W, DAC_F => DAC_F, OUT_W => IN_W,
            OUT_F => IN_F, COEF_W => B_COEF_W, COEF_F => B_COEF_F, LATENCY => LOOP_LATENCY,
            LOCK_SHIFT => LOCK_SHIFT, LOCK_HOLD => LOCK_HOLD, SETPOINT_N => B_SETPOINT_N,
            SETPOINT_R => B_SETPOINT_R, FREQ_WORD_N => B_FREQ_WORD_N,
            FREQ_WORD_R => B_FREQ_WORD_R, PLL_PRESET_N => B_PLL_PRESET_N,
            PLL_PRESET_R => B_PLL_PRESET_R, DAC_OFFSET_N => B_DAC_OFFSET_N,
            DAC_OFFSET_R => B_DAC_OFFSET_R, SENSE_OFFSET_N => B_SENSE_OFFSET_N,
            SENSE_OFFSET_R => B_SENSE_OFFSET_R, RATE_COEF_N => B_RATE_COEF_N,
            RATE_COEF_R => B_RATE_COEF_R, QUAD_COEF_N => B_QUAD_COEF_N,
            QUAD_COEF_R => B_QUAD_COEF_R, LOCK_Q_N => B_LOCK_Q_N, LOCK_Q_R => B_LOCK_Q_R,
            LOCK_A_N => B_LOCK_A_N, LOCK_A_R => B_LOCK_A_R, ROUNDING => LOOP_ROUNDING,
            SATURATE => LOOP_SATURATE, NCO_ROM_FILE => NCO_ROM_FILE,
            CIC_ROM_FILE => CIC_ROM_FILE
        )
        port map (
            clk => clk, rst => rst, ce => ce, mode => loop_mode_b, adc_x => adc_b_x,
            adc_y => adc_b_y, dac_x => dac_b_x, dac_y => dac_b_y, rate => rate_b,
            quadrature => open, out_valid => open, locked => locked_b
        );

    chain_ce <= loop_valid and enable_reg;

    chain : entity work.gyrofx_top
        generic map (
            INTERVAL_LENGTH => INTERVAL_LENGTH, INTERVALS => INTERVALS, PATTERN => PATTERN,
            BLANK => BLANK, STAGGER => STAGGER, PHASE_W => PHASE_W, INTERVAL_W => INTERVAL_W,
            IN_W => IN_W, IN_F => IN_F, ACC_W => ACC_W, RECIP_W => RECIP_W, RECIP_F => RECIP_F,
            RECIP => RECIP, MEAN_W => MEAN_W, MEAN_F => MEAN_F, GAIN_W => GAIN_W, GAIN_F => GAIN_F,
            DOT_W => DOT_W, BIAS_W => BIAS_W, BIAS_F => BIAS_F, SMOOTH => SMOOTH,
            GAIN_ROM_FILE => GAIN_ROM_FILE, STATE_W => STATE_W, STATE_F => STATE_F, OUT_W => OUT_W,
            OUT_F => OUT_F, G1_W => G1_W, G1_F => G1_F, G2_W => G2_W, G2_F => G2_F, SEL_W => SEL_W,
            ROM_DEPTH => ROM_DEPTH, KF_ROM_FILE => KF_ROM_FILE, ROUNDING => ROUNDING,
            SATURATE => SATURATE
        )
        port map (
            clk => clk, rst => rst, ce => chain_ce, bw_sel => bw_sel_reg, y_a => rate_a,
            y_b => rate_b, mode_a => chain_mode_a, mode_b => chain_mode_b, rate_out => rate_out,
            out_valid => out_valid, bias_a => bias_a, bias_b => bias_b, estimated => estimated
        );

    mode_a <= chain_mode_a;
    mode_b <= chain_mode_b;

    -- pragma translate_off
    -- Simulation only: the system takes a sample at most every 10 clocks (gyrofx_job::pipeline);
    -- a sooner ce stops the simulation, naming this instance.
    spacing_check : entity work.gyrofx_spacing_check
        generic map (MIN_CLOCKS_PER_SAMPLE => 10, BLOCK_NAME => "gyrofx_system")
        port map (clk => clk, rst => rst, ce => ce);
    -- pragma translate_on
end architecture;
