-- Language: VHDL-2008

-- gyrofx_top — the mode-reversal signal chain: sequencer, bias estimator,
--   calibration and steady-state KF.
--
-- Purpose: the VHDL twin of gyrofx_top.v (same generics, ports, ROM images and
--   timing). From the samples of two collinear gyros (taken in the modes this
--   entity requests on mode_a / mode_b), produces the calibrated, filtered rate.
--   Bit-exact with gyrofx_model::chain::FixedChain.
--
-- Algorithm (per ce): the sequencer describes the current sample; the
--   calibration removes the current bias estimates and combines the valid
--   outputs (registered); the KF steps on the combined value when at least
--   one gyro is valid (its ce is the registered ce and combined_valid); the
--   estimator accumulates the sample and updates the estimates at a window's
--   end.
--
-- Latency: mode_a/mode_b describe the sample to be taken at the next ce
--   (0 clocks: drive the gyro front end with them); rate_out/out_valid,
--   bias_a/bias_b/estimated are valid 6 clocks after ce (out_valid low when
--   both gyros were blanked; the estimates are those after the sample).
--   ce at most every 6th clock (the estimator's pipeline).

library ieee;
use ieee.std_logic_1164.all;
use ieee.numeric_std.all;

entity gyrofx_top is
    generic (
        -- sequencer (PATTERN: rightmost bit = interval 0)
        INTERVAL_LENGTH : positive := 150;
        INTERVALS : positive := 4;
        PATTERN : std_logic_vector := "0101";
        BLANK : natural := 10;
        STAGGER : natural := 0;
        PHASE_W : positive := 8;
        INTERVAL_W : positive := 2;
        -- gyro samples (also the KF input and the calibrated format)
        IN_W : positive := 24;
        IN_F : natural := 14;
        -- estimator
        ACC_W : positive := 32;
        RECIP_W : positive := 18;
        RECIP_F : natural := 24;
        RECIP : std_logic_vector := 18x"1d41d";
        MEAN_W : positive := 28;
        MEAN_F : natural := 18;
        GAIN_W : positive := 18;
        GAIN_F : natural := 17;
        DOT_W : positive := 49;
        BIAS_W : positive := 28;
        BIAS_F : natural := 18;
        SMOOTH : natural := 0;
        GAIN_ROM_FILE : string := "estimator_gains.mem";
        -- KF
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
        -- rounding: 0 floor, 1 ceil, 2 zero, 3 nearest, 4 round, 5 convergent
        ROUNDING : natural := 3;
        -- overflow: 0 wrap, 1 saturate
        SATURATE : natural := 1
    );
    port (
        clk       : in  std_logic;
        rst       : in  std_logic;
        ce        : in  std_logic;
        bw_sel    : in  unsigned(SEL_W - 1 downto 0);
        y_a       : in  signed(IN_W - 1 downto 0);
        y_b       : in  signed(IN_W - 1 downto 0);
        mode_a    : out std_logic;
        mode_b    : out std_logic;
        rate_out  : out signed(OUT_W - 1 downto 0);
        out_valid : out std_logic;
        bias_a    : out signed(BIAS_W - 1 downto 0);
        bias_b    : out signed(BIAS_W - 1 downto 0);
        estimated : out std_logic
    );
end entity;

architecture rtl of gyrofx_top is

    signal mode_a_now : std_logic;
    signal mode_b_now : std_logic;
    signal blank_a : std_logic;
    signal blank_b : std_logic;
    signal interval_a : unsigned(INTERVAL_W - 1 downto 0);
    signal interval_b : unsigned(INTERVAL_W - 1 downto 0);
    signal done_a : std_logic;
    signal done_b : std_logic;
    signal window_done : std_logic;
    signal bias_a_now : signed(BIAS_W - 1 downto 0);
    signal bias_b_now : signed(BIAS_W - 1 downto 0);
    signal combined : signed(IN_W - 1 downto 0);
    signal combined_valid : std_logic;
    signal kf_ce : std_logic := '0';
    signal combined_reg : signed(IN_W - 1 downto 0) := (others => '0');
    signal bw_sel_reg : unsigned(SEL_W - 1 downto 0) := (others => '0');
    signal kf_rate : signed(OUT_W - 1 downto 0);
    signal kf_valid : std_logic;
    signal rate_reg : signed(OUT_W - 1 downto 0) := (others => '0');
    signal valid_reg : std_logic := '0';

begin

    sequencer : entity work.gyrofx_sequencer
        generic map (
            INTERVAL_LENGTH => INTERVAL_LENGTH, INTERVALS => INTERVALS, PATTERN => PATTERN,
            BLANK => BLANK, STAGGER => STAGGER, PHASE_W => PHASE_W, INTERVAL_W => INTERVAL_W
        )
        port map (
            clk => clk, rst => rst, ce => ce,
            mode_a => mode_a_now, mode_b => mode_b_now, blank_a => blank_a, blank_b => blank_b,
            interval_a => interval_a, interval_b => interval_b, done_a => done_a, done_b => done_b,
            window_done => window_done
        );

    estimator : entity work.gyrofx_bias_estimator
        generic map (
            IN_W => IN_W, IN_F => IN_F, ACC_W => ACC_W, RECIP_W => RECIP_W, RECIP_F => RECIP_F,
            RECIP => RECIP, MEAN_W => MEAN_W, MEAN_F => MEAN_F, GAIN_W => GAIN_W, GAIN_F => GAIN_F,
            DOT_W => DOT_W, BIAS_W => BIAS_W, BIAS_F => BIAS_F, INTERVALS => INTERVALS,
            INTERVAL_W => INTERVAL_W, SMOOTH => SMOOTH, ROUNDING => ROUNDING, SATURATE => SATURATE,
            ROM_FILE => GAIN_ROM_FILE
        )
        port map (
            clk => clk, rst => rst, ce => ce, y_a => y_a, y_b => y_b,
            blank_a => blank_a, blank_b => blank_b, done_a => done_a, done_b => done_b,
            interval_a => interval_a, interval_b => interval_b, window_done => window_done,
            bias_a => bias_a_now, bias_b => bias_b_now, estimated => estimated
        );

    calibration : entity work.gyrofx_calibration
        generic map (
            IN_W => IN_W, IN_F => IN_F, BIAS_W => BIAS_W, BIAS_F => BIAS_F,
            CAL_W => IN_W, CAL_F => IN_F, ROUNDING => ROUNDING, SATURATE => SATURATE
        )
        port map (
            y_a => y_a, y_b => y_b, mode_a => mode_a_now, mode_b => mode_b_now,
            blank_a => blank_a, blank_b => blank_b, bias_a => bias_a_now, bias_b => bias_b_now,
            out_a => open, out_b => open, valid_a => open, valid_b => open,
            combined => combined, combined_valid => combined_valid
        );

    -- The calibration's output is registered: the KF takes it one clock after ce.
    calibration_register : process (clk)
    begin
        if rising_edge(clk) then
            if ce = '1' then
                combined_reg <= combined;
                bw_sel_reg <= bw_sel;
            end if;
            kf_ce <= ce and combined_valid;
            if rst = '1' then
                kf_ce <= '0';
            end if;
        end if;
    end process;

    kf : entity work.gyrofx_kf
        generic map (
            IN_W => IN_W, IN_F => IN_F, STATE_W => STATE_W, STATE_F => STATE_F,
            OUT_W => OUT_W, OUT_F => OUT_F, G1_W => G1_W, G1_F => G1_F, G2_W => G2_W, G2_F => G2_F,
            SEL_W => SEL_W, ROM_DEPTH => ROM_DEPTH, ROUNDING => ROUNDING, SATURATE => SATURATE,
            ROM_FILE => KF_ROM_FILE
        )
        port map (
            clk => clk, rst => rst, ce => kf_ce, bw_sel => bw_sel_reg, z => combined_reg,
            rate_out => kf_rate, out_valid => kf_valid
        );

    -- One more register on the rate, so that it comes with the estimates.
    output_register : process (clk)
    begin
        if rising_edge(clk) then
            if kf_valid = '1' then
                rate_reg <= kf_rate;
            end if;
            valid_reg <= kf_valid;
            if rst = '1' then
                valid_reg <= '0';
            end if;
        end if;
    end process;

    rate_out <= rate_reg;
    out_valid <= valid_reg;

    mode_a <= mode_a_now;
    mode_b <= mode_b_now;
    bias_a <= bias_a_now;
    bias_b <= bias_b_now;

    -- pragma translate_off
    -- Simulation only: the chain takes a sample at most every 6 clocks (gyrofx_job::pipeline);
    -- a sooner ce stops the simulation, naming this instance.
    spacing_check : entity work.gyrofx_spacing_check
        generic map (MIN_CLOCKS_PER_SAMPLE => 6, BLOCK_NAME => "gyrofx_top")
        port map (clk => clk, rst => rst, ce => ce);
    -- pragma translate_on
end architecture;
