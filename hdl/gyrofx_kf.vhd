-- Language: VHDL-2008

-- gyrofx_kf — steady-state Kalman filter for a MEMS gyro (paper 000), innovation form.
--
-- Purpose: the VHDL twin of gyrofx_kf.v (same generics, ports, ROM image and
--   timing). Estimates the true rate from the gyro rate z with the constant-gain
--   filter designed offline by gyrofx; one gain set per bandwidth in a ROM
--   addressed by bw_sel at run time. Bit-exact with gyrofx_model::kf::FixedKf.
--
-- Algorithm (per sample, ce high):
--     e        = z - x1 - x2                  exact, STATE_F fraction bits
--     x1      <= Q(x1 + g1 * e)               state format, ROUNDING/SATURATE
--     x2      <= Q(x2 + g2 * e)               state format, ROUNDING/SATURATE
--     rate_out <= Q(x1 after the update)      output format
--   Everything before a Q(.) is exact: widths are derived below by the same
--   rules as the model (add: +1 bit, multiply: widths add).
--
-- Pipeline: four register stages, one sample at a time: e and the ROM word
--   (clock 1), the products g1*e and g2*e (clock 2), the states (clock 3),
--   rate_out from the new x1 (clock 4). rate_out and out_valid are valid 4
--   clocks after ce; ce at most every 3rd clock (the next e needs the new
--   states). A clock with rst high clears x1, x2, the pipeline and out_valid
--   (rst wins over ce).
--
-- ROM: ROM_FILE (read by gyrofx_mem_pkg at elaboration), ROM_DEPTH words of
--   G1_W+G2_W bits, word = g1 & g2. A bw_sel beyond the ROM selects zero gains
--   (the Verilog model reads X there: do not rely on either).

library ieee;
use ieee.std_logic_1164.all;
use ieee.numeric_std.all;

use work.gyrofx_mem_pkg.all;

entity gyrofx_kf is
    generic (
        -- input z: width and fraction bits (°/s)
        IN_W : positive := 24;
        IN_F : natural := 14;
        -- state x1, x2: width and fraction bits (STATE_F >= IN_F: guard bits)
        STATE_W : positive := 36;
        STATE_F : natural := 26;
        -- output rate_out: width and fraction bits (OUT_F <= STATE_F)
        OUT_W : positive := 24;
        OUT_F : natural := 14;
        -- coefficient g1: width and fraction bits
        G1_W : positive := 18;
        G1_F : natural := 17;
        -- coefficient g2: width and fraction bits
        G2_W : positive := 18;
        G2_F : natural := 38;
        -- bw_sel width and number of ROM words
        SEL_W : positive := 2;
        ROM_DEPTH : positive := 3;
        -- rounding: 0 floor, 1 ceil, 2 zero, 3 nearest, 4 round, 5 convergent
        ROUNDING : natural := 3;
        -- overflow: 0 wrap, 1 saturate
        SATURATE : natural := 1;
        -- coefficient ROM image (hex, one word per line)
        ROM_FILE : string := "kf_coefficients.mem"
    );
    port (
        clk       : in  std_logic;
        rst       : in  std_logic;
        ce        : in  std_logic;
        bw_sel    : in  unsigned(SEL_W - 1 downto 0);
        z         : in  signed(IN_W - 1 downto 0);
        rate_out  : out signed(OUT_W - 1 downto 0);
        out_valid : out std_logic
    );
end entity;

architecture rtl of gyrofx_kf is

    function maximum_of(a, b : integer) return integer is
    begin
        if a > b then
            return a;
        end if;
        return b;
    end function;

    -- Exact intermediate widths: integer bits (with sign) grow by one per add.
    constant GUARD : integer := STATE_F - IN_F;
    constant IN_I : integer := IN_W - IN_F;
    constant STATE_I : integer := STATE_W - STATE_F;
    constant D1_I : integer := maximum_of(IN_I, STATE_I) + 1;    -- z - x1
    constant E_I : integer := maximum_of(D1_I, STATE_I) + 1;     -- z - x1 - x2
    constant E_W : integer := E_I + STATE_F;
    constant P1_W : integer := G1_W + E_W;
    constant P1_F : integer := G1_F + STATE_F;
    constant P2_W : integer := G2_W + E_W;
    constant P2_F : integer := G2_F + STATE_F;
    constant P1_I : integer := P1_W - P1_F;
    constant P2_I : integer := P2_W - P2_F;
    constant S1_W : integer := maximum_of(STATE_I, P1_I) + 1 + P1_F;  -- x1 + g1*e
    constant S2_W : integer := maximum_of(STATE_I, P2_I) + 1 + P2_F;  -- x2 + g2*e

    constant WORD_W : positive := G1_W + G2_W;
    constant ROM : word_array(0 to ROM_DEPTH - 1)(WORD_W - 1 downto 0) :=
        read_mem(ROM_FILE, ROM_DEPTH, WORD_W);

    signal x1_reg : signed(STATE_W - 1 downto 0) := (others => '0');
    signal x2_reg : signed(STATE_W - 1 downto 0) := (others => '0');
    signal rate_reg : signed(OUT_W - 1 downto 0) := (others => '0');
    signal valid_reg : std_logic := '0';

    -- The sample's place in the pipeline: (0) e and the gains held, (1) the products,
    -- (2) the states updated.
    signal stage : std_logic_vector(2 downto 0) := (others => '0');
    signal rom_word : std_logic_vector(WORD_W - 1 downto 0);
    signal g1 : signed(G1_W - 1 downto 0) := (others => '0');
    signal g2 : signed(G2_W - 1 downto 0) := (others => '0');
    signal e_next : signed(E_W - 1 downto 0);
    signal e : signed(E_W - 1 downto 0) := (others => '0');
    signal p1 : signed(P1_W - 1 downto 0) := (others => '0');
    signal p2 : signed(P2_W - 1 downto 0) := (others => '0');
    signal s1 : signed(S1_W - 1 downto 0);
    signal s2 : signed(S2_W - 1 downto 0);
    signal x1_next : signed(STATE_W - 1 downto 0);
    signal x2_next : signed(STATE_W - 1 downto 0);
    signal rate_next : signed(OUT_W - 1 downto 0);

begin

    assert GUARD >= 0
        report "gyrofx_kf: STATE_F (" & integer'image(STATE_F) & ") must be >= IN_F ("
            & integer'image(IN_F) & ")"
        severity failure;
    assert OUT_F <= STATE_F
        report "gyrofx_kf: OUT_F (" & integer'image(OUT_F) & ") must be <= STATE_F ("
            & integer'image(STATE_F) & ")"
        severity failure;

    rom_word <= ROM(to_integer(bw_sel)) when to_integer(bw_sel) < ROM_DEPTH else (others => '0');

    -- e = z - x1 - x2 at STATE_F fraction bits, exact.
    e_next <= shift_left(resize(z, E_W), GUARD) - resize(x1_reg, E_W) - resize(x2_reg, E_W);

    -- Sums x_i + g_i*e at the product's fraction, exact (the products are registers).
    s1 <= shift_left(resize(x1_reg, S1_W), G1_F) + resize(p1, S1_W);
    s2 <= shift_left(resize(x2_reg, S2_W), G2_F) + resize(p2, S2_W);

    -- The three quantization points.
    quantize_x1 : entity work.gyrofx_quantize
        generic map (
            IN_W => S1_W, IN_F => P1_F, OUT_W => STATE_W, OUT_F => STATE_F,
            ROUNDING => ROUNDING, SATURATE => SATURATE
        )
        port map (value_in => s1, value_out => x1_next, overflow => open);

    quantize_x2 : entity work.gyrofx_quantize
        generic map (
            IN_W => S2_W, IN_F => P2_F, OUT_W => STATE_W, OUT_F => STATE_F,
            ROUNDING => ROUNDING, SATURATE => SATURATE
        )
        port map (value_in => s2, value_out => x2_next, overflow => open);

    quantize_rate : entity work.gyrofx_quantize
        generic map (
            IN_W => STATE_W, IN_F => STATE_F, OUT_W => OUT_W, OUT_F => OUT_F,
            ROUNDING => ROUNDING, SATURATE => SATURATE
        )
        port map (value_in => x1_reg, value_out => rate_next, overflow => open);

    registers : process (clk)
    begin
        if rising_edge(clk) then
            stage <= stage(1 downto 0) & ce;
            if ce = '1' then
                e <= e_next;
                g1 <= signed(rom_word(WORD_W - 1 downto G2_W));
                g2 <= signed(rom_word(G2_W - 1 downto 0));
            end if;
            if stage(0) = '1' then
                p1 <= g1 * e;
                p2 <= g2 * e;
            end if;
            if stage(1) = '1' then
                x1_reg <= x1_next;
                x2_reg <= x2_next;
            end if;
            if stage(2) = '1' then
                rate_reg <= rate_next;
            end if;
            valid_reg <= stage(2);

            if rst = '1' then
                x1_reg <= (others => '0');
                x2_reg <= (others => '0');
                stage <= (others => '0');
                valid_reg <= '0';
            end if;
        end if;
    end process;

    rate_out <= rate_reg;
    out_valid <= valid_reg;

    -- pragma translate_off
    -- Simulation only: the KF takes a sample at most every 3 clocks (gyrofx_job::pipeline);
    -- a sooner ce stops the simulation, naming this instance.
    spacing_check : entity work.gyrofx_spacing_check
        generic map (MIN_CLOCKS_PER_SAMPLE => 3, BLOCK_NAME => "gyrofx_kf")
        port map (clk => clk, rst => rst, ce => ce);
    -- pragma translate_on
end architecture;
