-- Language: VHDL-2008

-- gyrofx_demodulator — I/Q demodulator: ADC sample times the NCO's sine and cosine,
-- each product low-passed by a first-order leaky integrator.
--
-- Purpose: the VHDL twin of gyrofx_demodulator.v (same generics, ports and timing):
--   amplitude and phase of the resonator's drive and sense signals (SPEC 1.6). For
--   adc = a sin(theta + phi) and references A sin(theta), A cos(theta):
--   I = a A cos(phi), Q = a A sin(phi). Bit-exact with
--   gyrofx_model::gyro_loop::demodulator::FixedDemodulator.
--
-- Algorithm (per sample, ce high; per channel, ref = ref_sin for I, ref_cos for Q):
--     p   = Q(2 * adc * ref)                   PROD format (the 2: one fraction bit
--                                               less on the exact product)
--     y  <= Q(y + (p - y) * 2^-SHIFT)          STATE format, computed exactly as
--                                               (y << SHIFT) + (p - y) at STATE_F + SHIFT
--     out <= Q(y after the update)             OUT format
--   Every Q(.) is gyrofx_quantize with ROUNDING/SATURATE. The state holds every
--   product (STATE_F >= PROD_F, no fewer integer bits), so y never overflows.
--
-- Pipeline: one register stage. i_out, q_out and out_valid are valid 1 clock after
--   ce. A clock with rst high clears both states and out_valid (rst wins over ce).

library ieee;
use ieee.std_logic_1164.all;
use ieee.numeric_std.all;

entity gyrofx_demodulator is
    generic (
        -- ADC sample: width and fraction bits (full-scale units)
        ADC_W : positive := 24;
        ADC_F : integer := 23;
        -- NCO references: width and fraction bits
        REF_W : positive := 18;
        REF_F : integer := 17;
        -- quantized product 2 * adc * ref: width and fraction bits
        PROD_W : positive := 32;
        PROD_F : integer := 30;
        -- low-pass state: width and fraction bits (holds every product)
        STATE_W : positive := 40;
        STATE_F : integer := 38;
        -- I and Q outputs: width and fraction bits (OUT_F <= STATE_F)
        OUT_W : positive := 24;
        OUT_F : integer := 23;
        -- low-pass coefficient 2^-SHIFT (1..24)
        SHIFT : positive := 8;
        -- rounding: 0 floor, 1 ceil, 2 zero, 3 nearest, 4 round, 5 convergent
        ROUNDING : natural := 3;
        -- overflow: 0 wrap, 1 saturate
        SATURATE : natural := 1
    );
    port (
        clk       : in  std_logic;
        rst       : in  std_logic;
        ce        : in  std_logic;
        adc       : in  signed(ADC_W - 1 downto 0);
        ref_sin   : in  signed(REF_W - 1 downto 0);
        ref_cos   : in  signed(REF_W - 1 downto 0);
        i_out     : out signed(OUT_W - 1 downto 0);
        q_out     : out signed(OUT_W - 1 downto 0);
        out_valid : out std_logic
    );
end entity;

architecture rtl of gyrofx_demodulator is

    -- Exact product 2 * adc * ref: the integer adc * ref at one fraction bit less.
    constant X_W : positive := ADC_W + REF_W;
    constant X_F : integer := ADC_F + REF_F - 1;
    -- Exact update (y << SHIFT) + (p - y) at STATE_F + SHIFT fraction bits.
    constant U_W : positive := STATE_W + SHIFT + 1;
    constant U_F : integer := STATE_F + SHIFT;
    -- Aligns a product to the state's fraction bits.
    constant ALIGN : integer := STATE_F - PROD_F;

    type state_pair is array (0 to 1) of signed(STATE_W - 1 downto 0);
    type out_pair is array (0 to 1) of signed(OUT_W - 1 downto 0);
    type exact_pair is array (0 to 1) of signed(X_W - 1 downto 0);
    type product_pair is array (0 to 1) of signed(PROD_W - 1 downto 0);
    type update_pair is array (0 to 1) of signed(U_W - 1 downto 0);

    signal y_reg : state_pair := (others => (others => '0'));
    signal out_reg : out_pair := (others => (others => '0'));
    signal valid_reg : std_logic := '0';

    signal exact : exact_pair;
    signal product : product_pair;
    signal update : update_pair;
    signal y_next : state_pair;
    signal out_next : out_pair;

begin

    assert ALIGN >= 0 and STATE_W - STATE_F >= PROD_W - PROD_F
        report "gyrofx_demodulator: the state must hold every product"
        severity failure;

    exact(0) <= adc * ref_sin;
    exact(1) <= adc * ref_cos;

    g_channel : for c in 0 to 1 generate
        quantize_p : entity work.gyrofx_quantize
            generic map (
                IN_W => X_W, IN_F => X_F, OUT_W => PROD_W, OUT_F => PROD_F,
                ROUNDING => ROUNDING, SATURATE => SATURATE
            )
            port map (value_in => exact(c), value_out => product(c), overflow => open);

        update(c) <= shift_left(resize(y_reg(c), U_W), SHIFT)
            + (shift_left(resize(product(c), U_W), ALIGN) - resize(y_reg(c), U_W));

        quantize_y : entity work.gyrofx_quantize
            generic map (
                IN_W => U_W, IN_F => U_F, OUT_W => STATE_W, OUT_F => STATE_F,
                ROUNDING => ROUNDING, SATURATE => SATURATE
            )
            port map (value_in => update(c), value_out => y_next(c), overflow => open);

        quantize_out : entity work.gyrofx_quantize
            generic map (
                IN_W => STATE_W, IN_F => STATE_F, OUT_W => OUT_W, OUT_F => OUT_F,
                ROUNDING => ROUNDING, SATURATE => SATURATE
            )
            port map (value_in => y_next(c), value_out => out_next(c), overflow => open);
    end generate;

    registers : process (clk)
    begin
        if rising_edge(clk) then
            if ce = '1' then
                y_reg <= y_next;
                out_reg <= out_next;
            end if;
            valid_reg <= ce;

            if rst = '1' then
                y_reg <= (others => (others => '0'));
                valid_reg <= '0';
            end if;
        end if;
    end process;

    i_out <= out_reg(0);
    q_out <= out_reg(1);
    out_valid <= valid_reg;

end architecture;
