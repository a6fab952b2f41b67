-- Language: VHDL-2008

-- gyrofx_calibration — calibrated and combined outputs of mode reversal.
--
-- Purpose: the VHDL twin of gyrofx_calibration.v (same generics and ports).
--   Removes each gyro's estimated bias with the sign of its current mode and
--   combines the valid outputs. Bit-exact with the calibration step of
--   gyrofx_model::estimator::FixedEstimator.
--
-- Algorithm:
--     out_g    = Q(y_g - p_g * bias_g)       p_g = +1 (mode '1') or -1 (mode '0');
--                                            exact at max(IN_F, BIAS_F) fraction bits
--     valid_g  = not blank_g
--     combined = both valid ? Q((out_a + out_b) / 2) : the valid one (0 if none)
--     combined_valid = valid_a or valid_b
--
-- Latency: combinational (0 clocks).

library ieee;
use ieee.std_logic_1164.all;
use ieee.numeric_std.all;

entity gyrofx_calibration is
    generic (
        -- gyro samples
        IN_W : positive := 24;
        IN_F : natural := 14;
        -- bias estimates
        BIAS_W : positive := 28;
        BIAS_F : natural := 18;
        -- calibrated and combined outputs (CAL_F <= max(IN_F, BIAS_F))
        CAL_W : positive := 24;
        CAL_F : natural := 14;
        -- rounding: 0 floor, 1 ceil, 2 zero, 3 nearest, 4 round, 5 convergent
        ROUNDING : natural := 3;
        -- overflow: 0 wrap, 1 saturate
        SATURATE : natural := 1
    );
    port (
        y_a            : in  signed(IN_W - 1 downto 0);
        y_b            : in  signed(IN_W - 1 downto 0);
        mode_a         : in  std_logic;
        mode_b         : in  std_logic;
        blank_a        : in  std_logic;
        blank_b        : in  std_logic;
        bias_a         : in  signed(BIAS_W - 1 downto 0);
        bias_b         : in  signed(BIAS_W - 1 downto 0);
        out_a          : out signed(CAL_W - 1 downto 0);
        out_b          : out signed(CAL_W - 1 downto 0);
        valid_a        : out std_logic;
        valid_b        : out std_logic;
        combined       : out signed(CAL_W - 1 downto 0);
        combined_valid : out std_logic
    );
end entity;

architecture rtl of gyrofx_calibration is

    function maximum_of(a, b : integer) return integer is
    begin
        if a > b then
            return a;
        end if;
        return b;
    end function;

    constant F : natural := maximum_of(IN_F, BIAS_F);
    constant D_W : positive := maximum_of(IN_W - IN_F, BIAS_W - BIAS_F) + 1 + F;

    signal y_a_aligned : signed(D_W - 1 downto 0);
    signal y_b_aligned : signed(D_W - 1 downto 0);
    signal bias_a_aligned : signed(D_W - 1 downto 0);
    signal bias_b_aligned : signed(D_W - 1 downto 0);
    signal corrected_a : signed(D_W - 1 downto 0);
    signal corrected_b : signed(D_W - 1 downto 0);
    signal calibrated_a : signed(CAL_W - 1 downto 0);
    signal calibrated_b : signed(CAL_W - 1 downto 0);
    signal pair_sum : signed(CAL_W downto 0);
    signal pair_mean : signed(CAL_W - 1 downto 0);
    signal valid_a_now : std_logic;
    signal valid_b_now : std_logic;

begin

    y_a_aligned <= shift_left(resize(y_a, D_W), F - IN_F);
    y_b_aligned <= shift_left(resize(y_b, D_W), F - IN_F);
    bias_a_aligned <= shift_left(resize(bias_a, D_W), F - BIAS_F);
    bias_b_aligned <= shift_left(resize(bias_b, D_W), F - BIAS_F);
    corrected_a <= y_a_aligned - bias_a_aligned when mode_a = '1' else y_a_aligned + bias_a_aligned;
    corrected_b <= y_b_aligned - bias_b_aligned when mode_b = '1' else y_b_aligned + bias_b_aligned;

    quantize_a : entity work.gyrofx_quantize
        generic map (
            IN_W => D_W, IN_F => F, OUT_W => CAL_W, OUT_F => CAL_F,
            ROUNDING => ROUNDING, SATURATE => SATURATE
        )
        port map (value_in => corrected_a, value_out => calibrated_a, overflow => open);

    quantize_b : entity work.gyrofx_quantize
        generic map (
            IN_W => D_W, IN_F => F, OUT_W => CAL_W, OUT_F => CAL_F,
            ROUNDING => ROUNDING, SATURATE => SATURATE
        )
        port map (value_in => corrected_b, value_out => calibrated_b, overflow => open);

    pair_sum <= resize(calibrated_a, CAL_W + 1) + resize(calibrated_b, CAL_W + 1);

    quantize_mean : entity work.gyrofx_quantize
        generic map (
            IN_W => CAL_W + 1, IN_F => CAL_F + 1, OUT_W => CAL_W, OUT_F => CAL_F,
            ROUNDING => ROUNDING, SATURATE => SATURATE
        )
        port map (value_in => pair_sum, value_out => pair_mean, overflow => open);

    valid_a_now <= not blank_a;
    valid_b_now <= not blank_b;

    out_a <= calibrated_a;
    out_b <= calibrated_b;
    valid_a <= valid_a_now;
    valid_b <= valid_b_now;
    combined_valid <= valid_a_now or valid_b_now;
    combined <= pair_mean when valid_a_now = '1' and valid_b_now = '1' else
                calibrated_a when valid_a_now = '1' else
                calibrated_b when valid_b_now = '1' else
                (others => '0');

end architecture;
