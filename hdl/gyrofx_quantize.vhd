-- Language: VHDL-2008

-- gyrofx_quantize — requantize a signed fixed-point value (combinational).
--
-- Purpose: the declared quantization point of gyrofx (SPEC §2); the VHDL twin of
--   gyrofx_quantize.v. Drops SHIFT = IN_F - OUT_F fraction bits with the rounding
--   mode ROUNDING, then wraps or saturates into OUT_W bits. Bit-exact with
--   gyrofx_model::fx::requantize.
--
-- Algorithm: q = floor(in / 2^SHIFT) + inc, where inc depends on the dropped
--   remainder r (0 <= r < 2^SHIFT), half = 2^(SHIFT-1):
--     0 floor      inc = 0
--     1 ceil       inc = (r /= 0)
--     2 zero       inc = (r /= 0) and negative
--     3 nearest    inc = (r >= half)                      (add half, floor)
--     4 round      inc = (r > half) or (r = half and not negative)
--     5 convergent inc = (r > half) or (r = half and q(0))
--   then, if q does not fit OUT_W bits: SATURATE = 1 ? clamp : keep the low OUT_W bits.
--
-- Ports: value_in / value_out (in and out are reserved words in VHDL).
-- Latency: combinational (0 clocks).

library ieee;
use ieee.std_logic_1164.all;
use ieee.numeric_std.all;

entity gyrofx_quantize is
    generic (
        -- input word width and fraction bits
        IN_W : positive := 40;
        IN_F : integer := 20;
        -- output word width and fraction bits (IN_F - IN_W < OUT_F <= IN_F)
        OUT_W : positive := 24;
        OUT_F : integer := 10;
        -- rounding mode: 0 floor, 1 ceil, 2 zero, 3 nearest, 4 round, 5 convergent
        ROUNDING : natural := 3;
        -- overflow mode: 0 wrap, 1 saturate
        SATURATE : natural := 1
    );
    port (
        value_in  : in  signed(IN_W - 1 downto 0);
        value_out : out signed(OUT_W - 1 downto 0);
        -- high when the rounded value did not fit OUT_W bits
        overflow  : out std_logic
    );
end entity;

architecture rtl of gyrofx_quantize is

    constant SHIFT : integer := IN_F - OUT_F;
    -- Rounded quotient: the kept bits plus one bit for the increment.
    constant Q_W : positive := IN_W - SHIFT + 1;

    signal rounded : signed(Q_W - 1 downto 0);

begin

    assert SHIFT >= 0 and SHIFT < IN_W
        report "gyrofx_quantize: IN_F - OUT_F = " & integer'image(SHIFT)
            & " must be in 0.." & integer'image(IN_W - 1)
        severity failure;
    assert ROUNDING <= 5
        report "gyrofx_quantize: ROUNDING = " & integer'image(ROUNDING) & " must be 0..5"
        severity failure;

    -- Each part is one process with variables, not a signal per step: a simulator then
    -- evaluates a quantization point in two delta cycles instead of seven (the closed loops
    -- have dozens of them; their GHDL runs took a third longer).
    g_exact : if SHIFT = 0 generate
        rounded <= resize(value_in, Q_W);
    end generate;

    g_round : if SHIFT > 0 generate
        round : process (value_in)
            variable quotient : signed(Q_W - 1 downto 0);
            variable remainder : std_logic_vector(SHIFT - 1 downto 0);
            variable negative : std_logic;
            variable any_dropped : std_logic;
            variable half_bit : std_logic;
            variable below_half : std_logic;
            variable increment : std_logic;
        begin
            quotient := resize(value_in(IN_W - 1 downto SHIFT), Q_W);
            remainder := std_logic_vector(value_in(SHIFT - 1 downto 0));
            negative := value_in(IN_W - 1);
            any_dropped := or remainder;
            half_bit := remainder(SHIFT - 1);
            below_half := '0';
            if SHIFT > 1 then
                below_half := or remainder(SHIFT - 2 downto 0);
            end if;
            case ROUNDING is
                when 1 => increment := any_dropped;
                when 2 => increment := any_dropped and negative;
                when 3 => increment := half_bit;
                when 4 => increment := half_bit and (below_half or not negative);
                when 5 => increment := half_bit and (below_half or quotient(0));
                when others => increment := '0';
            end case;
            rounded <= quotient + signed'('0' & increment);
        end process;
    end generate;

    g_fits : if Q_W <= OUT_W generate
        value_out <= resize(rounded, OUT_W);
        overflow <= '0';
    end generate;

    g_check : if Q_W > OUT_W generate
        check : process (rounded)
            -- Fits when every bit above the output's sign bit equals the sign.
            variable top : std_logic_vector(Q_W - OUT_W downto 0);
            variable fits : std_logic;
        begin
            top := std_logic_vector(rounded(Q_W - 1 downto OUT_W - 1));
            fits := (and top) or not (or top);
            if fits = '1' or SATURATE = 0 then
                value_out <= rounded(OUT_W - 1 downto 0);
            elsif rounded(Q_W - 1) = '1' then
                value_out <= ('1', others => '0');
            else
                value_out <= ('0', others => '1');
            end if;
            overflow <= not fits;
        end process;
    end generate;

end architecture;
