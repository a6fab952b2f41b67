-- Language: VHDL-2008

-- gyrofx_bias_estimator — least-squares bias estimator of mode reversal.
--
-- Purpose: the VHDL twin of gyrofx_bias_estimator.v (same generics, ports, ROM
--   image and timing). Estimates the biases of gyros A and B from their interval
--   means over a window of W intervals (SPEC §1.3). Bit-exact with
--   gyrofx_model::estimator::FixedEstimator (its calibration lives in
--   gyrofx_calibration).
--
-- Algorithm (per gyro g, on ce):
--     total_g  = acc_g + (blank_g ? 0 : y_g)                 exact, ACC_W bits
--     at done_g:   mean_g(interval_g) <= Q(total_g * RECIP)   MEAN format
--                  acc_g <= 0          (else acc_g <= total_g)
--     at window_done (means of this cycle included):
--         new_g  = Q(sum_j G_g(j) * m(j)),  m = (mA0, mB0, mA1, mB1, ...)
--         bias_g <= estimated and SMOOTH > 0
--                   ? Q(bias_g + (new_g - bias_g) / 2^SMOOTH) : new_g
--         estimated <= '1'
--   ROM_FILE holds G: 2*W words for A's row, then 2*W for B's, each GAIN_W bits.
--   RECIP is the RECIP_W-bit code of 1/(L - M) (e.g. 18x"1d41d").
--
-- Pipeline: the running sums update on ce; an interval's end runs five
--   register stages, one sample at a time: the sums (clock 1), their products
--   by RECIP (2), the rounded means stored (3), the gain products (4), the dot
--   products (5); the estimates update on the clock after (bias_a, bias_b,
--   estimated are valid 6 clocks after the ce of a window's last sample).
--   ce at most every 6th clock. rst is synchronous and clears the pipeline too.

library ieee;
use ieee.std_logic_1164.all;
use ieee.numeric_std.all;

use work.gyrofx_mem_pkg.all;

entity gyrofx_bias_estimator is
    generic (
        -- gyro samples: width and fraction bits
        IN_W : positive := 24;
        IN_F : natural := 14;
        -- accumulator width (fraction IN_F): IN_W + bits to count an interval
        ACC_W : positive := 32;
        -- reciprocal 1/(L - M): format and code
        RECIP_W : positive := 18;
        RECIP_F : natural := 24;
        RECIP : std_logic_vector := 18x"1d41d";
        -- interval means
        MEAN_W : positive := 28;
        MEAN_F : natural := 18;
        -- least-squares gains
        GAIN_W : positive := 18;
        GAIN_F : natural := 17;
        -- exact dot product width (fraction GAIN_F + MEAN_F)
        DOT_W : positive := 49;
        -- bias estimates
        BIAS_W : positive := 28;
        BIAS_F : natural := 18;
        -- W intervals per window and the width of an interval index
        INTERVALS : positive := 4;
        INTERVAL_W : positive := 2;
        -- smoothing shift s (0: none)
        SMOOTH : natural := 0;
        -- rounding: 0 floor, 1 ceil, 2 zero, 3 nearest, 4 round, 5 convergent
        ROUNDING : natural := 3;
        -- overflow: 0 wrap, 1 saturate
        SATURATE : natural := 1;
        -- gain ROM image (hex, one word per line)
        ROM_FILE : string := "estimator_gains.mem"
    );
    port (
        clk         : in  std_logic;
        rst         : in  std_logic;
        ce          : in  std_logic;
        y_a         : in  signed(IN_W - 1 downto 0);
        y_b         : in  signed(IN_W - 1 downto 0);
        blank_a     : in  std_logic;
        blank_b     : in  std_logic;
        done_a      : in  std_logic;
        done_b      : in  std_logic;
        interval_a  : in  unsigned(INTERVAL_W - 1 downto 0);
        interval_b  : in  unsigned(INTERVAL_W - 1 downto 0);
        window_done : in  std_logic;
        bias_a      : out signed(BIAS_W - 1 downto 0);
        bias_b      : out signed(BIAS_W - 1 downto 0);
        estimated   : out std_logic
    );
end entity;

architecture rtl of gyrofx_bias_estimator is

    constant TERMS : positive := 2 * INTERVALS;
    constant PRODUCT_W : positive := ACC_W + RECIP_W;
    constant TERM_W : positive := GAIN_W + MEAN_W;
    constant SMOOTH_W : positive := BIAS_W + 2 + SMOOTH;

    constant GAINS : word_array(0 to 2 * TERMS - 1)(GAIN_W - 1 downto 0) :=
        read_mem(ROM_FILE, 2 * TERMS, GAIN_W);
    -- RECIP as a signed code; one of another length stops the elaboration with a message.
    function recip_of(bits : std_logic_vector) return signed is
        variable result : signed(RECIP_W - 1 downto 0) := (others => '0');
    begin
        assert bits'length = RECIP_W
            report "gyrofx_bias_estimator: RECIP has " & integer'image(bits'length)
                & " bits; RECIP_W = " & integer'image(RECIP_W)
            severity failure;
        if bits'length = RECIP_W then
            result := signed(bits);
        end if;
        return result;
    end function;

    constant RECIP_CODE : signed(RECIP_W - 1 downto 0) := recip_of(RECIP);

    type mean_array is array (0 to INTERVALS - 1) of signed(MEAN_W - 1 downto 0);

    signal acc_a_reg : signed(ACC_W - 1 downto 0) := (others => '0');
    signal acc_b_reg : signed(ACC_W - 1 downto 0) := (others => '0');
    signal mean_a_reg : mean_array := (others => (others => '0'));
    signal mean_b_reg : mean_array := (others => (others => '0'));
    signal bias_a_reg : signed(BIAS_W - 1 downto 0) := (others => '0');
    signal bias_b_reg : signed(BIAS_W - 1 downto 0) := (others => '0');
    signal estimated_reg : std_logic := '0';

    type term_array is array (0 to TERMS - 1) of signed(TERM_W - 1 downto 0);

    signal total_a : signed(ACC_W - 1 downto 0);
    signal total_b : signed(ACC_W - 1 downto 0);
    -- The interval's end moving down the pipeline: the sums and which means they end
    -- (stage 1), the scaled sums (2), the means stored (3), the gain products (4), the dot
    -- products (5).
    signal total_a_reg : signed(ACC_W - 1 downto 0) := (others => '0');
    signal total_b_reg : signed(ACC_W - 1 downto 0) := (others => '0');
    signal done_a_stage : std_logic_vector(1 downto 0) := (others => '0');
    signal done_b_stage : std_logic_vector(1 downto 0) := (others => '0');
    signal window_stage : std_logic_vector(4 downto 0) := (others => '0');
    signal interval_a_1 : unsigned(INTERVAL_W - 1 downto 0) := (others => '0');
    signal interval_b_1 : unsigned(INTERVAL_W - 1 downto 0) := (others => '0');
    signal interval_a_2 : unsigned(INTERVAL_W - 1 downto 0) := (others => '0');
    signal interval_b_2 : unsigned(INTERVAL_W - 1 downto 0) := (others => '0');
    signal scaled_a : signed(PRODUCT_W - 1 downto 0) := (others => '0');
    signal scaled_b : signed(PRODUCT_W - 1 downto 0) := (others => '0');
    signal mean_a_new : signed(MEAN_W - 1 downto 0);
    signal mean_b_new : signed(MEAN_W - 1 downto 0);
    signal term_a_reg : term_array := (others => (others => '0'));
    signal term_b_reg : term_array := (others => (others => '0'));
    signal dot_a : signed(DOT_W - 1 downto 0) := (others => '0');
    signal dot_b : signed(DOT_W - 1 downto 0) := (others => '0');
    signal new_a : signed(BIAS_W - 1 downto 0);
    signal new_b : signed(BIAS_W - 1 downto 0);
    signal smooth_a_sum : signed(SMOOTH_W - 1 downto 0);
    signal smooth_b_sum : signed(SMOOTH_W - 1 downto 0);
    signal smooth_a : signed(BIAS_W - 1 downto 0);
    signal smooth_b : signed(BIAS_W - 1 downto 0);
    signal use_smoothing : boolean;

begin

    assert ACC_W > IN_W and DOT_W >= TERM_W
        report "gyrofx_bias_estimator: ACC_W (" & integer'image(ACC_W) & ") must exceed IN_W ("
            & integer'image(IN_W) & "), DOT_W (" & integer'image(DOT_W)
            & ") hold GAIN_W + MEAN_W"
        severity failure;

    -- Running sums including the current sample.
    total_a <= acc_a_reg + (resize(y_a, ACC_W) and (ACC_W - 1 downto 0 => not blank_a));
    total_b <= acc_b_reg + (resize(y_b, ACC_W) and (ACC_W - 1 downto 0 => not blank_b));

    -- Interval means: the scaled sums are registers, multiplied only at an interval's end
    -- (which keeps GHDL, whose numeric_std multiplies bit by bit, fast).

    quantize_mean_a : entity work.gyrofx_quantize
        generic map (
            IN_W => PRODUCT_W, IN_F => IN_F + RECIP_F, OUT_W => MEAN_W, OUT_F => MEAN_F,
            ROUNDING => ROUNDING, SATURATE => SATURATE
        )
        port map (value_in => scaled_a, value_out => mean_a_new, overflow => open);

    quantize_mean_b : entity work.gyrofx_quantize
        generic map (
            IN_W => PRODUCT_W, IN_F => IN_F + RECIP_F, OUT_W => MEAN_W, OUT_F => MEAN_F,
            ROUNDING => ROUNDING, SATURATE => SATURATE
        )
        port map (value_in => scaled_b, value_out => mean_b_new, overflow => open);

    quantize_new_a : entity work.gyrofx_quantize
        generic map (
            IN_W => DOT_W, IN_F => GAIN_F + MEAN_F, OUT_W => BIAS_W, OUT_F => BIAS_F,
            ROUNDING => ROUNDING, SATURATE => SATURATE
        )
        port map (value_in => dot_a, value_out => new_a, overflow => open);

    quantize_new_b : entity work.gyrofx_quantize
        generic map (
            IN_W => DOT_W, IN_F => GAIN_F + MEAN_F, OUT_W => BIAS_W, OUT_F => BIAS_F,
            ROUNDING => ROUNDING, SATURATE => SATURATE
        )
        port map (value_in => dot_b, value_out => new_b, overflow => open);

    -- Smoothing: bias + (new - bias) / 2^SMOOTH, exact at BIAS_F + SMOOTH fraction bits.
    smooth_a_sum <= shift_left(resize(bias_a_reg, SMOOTH_W), SMOOTH)
        + (resize(new_a, SMOOTH_W) - resize(bias_a_reg, SMOOTH_W));
    smooth_b_sum <= shift_left(resize(bias_b_reg, SMOOTH_W), SMOOTH)
        + (resize(new_b, SMOOTH_W) - resize(bias_b_reg, SMOOTH_W));

    quantize_smooth_a : entity work.gyrofx_quantize
        generic map (
            IN_W => SMOOTH_W, IN_F => BIAS_F + SMOOTH, OUT_W => BIAS_W, OUT_F => BIAS_F,
            ROUNDING => ROUNDING, SATURATE => SATURATE
        )
        port map (value_in => smooth_a_sum, value_out => smooth_a, overflow => open);

    quantize_smooth_b : entity work.gyrofx_quantize
        generic map (
            IN_W => SMOOTH_W, IN_F => BIAS_F + SMOOTH, OUT_W => BIAS_W, OUT_F => BIAS_F,
            ROUNDING => ROUNDING, SATURATE => SATURATE
        )
        port map (value_in => smooth_b_sum, value_out => smooth_b, overflow => open);

    use_smoothing <= estimated_reg = '1' and SMOOTH > 0;

    registers : process (clk)
        variable sum_a : signed(DOT_W - 1 downto 0);
        variable sum_b : signed(DOT_W - 1 downto 0);
        variable mean : signed(MEAN_W - 1 downto 0);
    begin
        if rising_edge(clk) then
            done_a_stage <= done_a_stage(0) & (ce and done_a);
            done_b_stage <= done_b_stage(0) & (ce and done_b);
            window_stage <= window_stage(3 downto 0) & (ce and window_done);
            if ce = '1' then
                if done_a = '1' then
                    acc_a_reg <= (others => '0');
                else
                    acc_a_reg <= total_a;
                end if;
                if done_b = '1' then
                    acc_b_reg <= (others => '0');
                else
                    acc_b_reg <= total_b;
                end if;
                total_a_reg <= total_a;
                total_b_reg <= total_b;
                interval_a_1 <= interval_a;
                interval_b_1 <= interval_b;
            end if;
            if done_a_stage(0) = '1' then
                scaled_a <= total_a_reg * RECIP_CODE;
                interval_a_2 <= interval_a_1;
            end if;
            if done_b_stage(0) = '1' then
                scaled_b <= total_b_reg * RECIP_CODE;
                interval_b_2 <= interval_b_1;
            end if;
            if done_a_stage(1) = '1' then
                mean_a_reg(to_integer(interval_a_2)) <= mean_a_new;
            end if;
            if done_b_stage(1) = '1' then
                mean_b_reg(to_integer(interval_b_2)) <= mean_b_new;
            end if;
            -- The gain products of the window's means, then their sums, which wrap at DOT_W
            -- bits exactly like the Verilog chain of adders.
            if window_stage(2) = '1' then
                for j in 0 to TERMS - 1 loop
                    if j mod 2 = 0 then
                        mean := mean_a_reg(j / 2);
                    else
                        mean := mean_b_reg(j / 2);
                    end if;
                    term_a_reg(j) <= signed(GAINS(j)) * mean;
                    term_b_reg(j) <= signed(GAINS(TERMS + j)) * mean;
                end loop;
            end if;
            if window_stage(3) = '1' then
                sum_a := (others => '0');
                sum_b := (others => '0');
                for j in 0 to TERMS - 1 loop
                    sum_a := sum_a + resize(term_a_reg(j), DOT_W);
                    sum_b := sum_b + resize(term_b_reg(j), DOT_W);
                end loop;
                dot_a <= sum_a;
                dot_b <= sum_b;
            end if;
            if window_stage(4) = '1' then
                if use_smoothing then
                    bias_a_reg <= smooth_a;
                    bias_b_reg <= smooth_b;
                else
                    bias_a_reg <= new_a;
                    bias_b_reg <= new_b;
                end if;
                estimated_reg <= '1';
            end if;

            if rst = '1' then
                done_a_stage <= (others => '0');
                done_b_stage <= (others => '0');
                window_stage <= (others => '0');
                acc_a_reg <= (others => '0');
                acc_b_reg <= (others => '0');
                mean_a_reg <= (others => (others => '0'));
                mean_b_reg <= (others => (others => '0'));
                bias_a_reg <= (others => '0');
                bias_b_reg <= (others => '0');
                estimated_reg <= '0';
            end if;
        end if;
    end process;

    bias_a <= bias_a_reg;
    bias_b <= bias_b_reg;
    estimated <= estimated_reg;

    -- pragma translate_off
    -- Simulation only: the estimator takes a sample at most every 6 clocks (gyrofx_job::pipeline);
    -- a sooner ce stops the simulation, naming this instance.
    spacing_check : entity work.gyrofx_spacing_check
        generic map (MIN_CLOCKS_PER_SAMPLE => 6, BLOCK_NAME => "gyrofx_bias_estimator")
        port map (clk => clk, rst => rst, ce => ce);
    -- pragma translate_on
end architecture;
