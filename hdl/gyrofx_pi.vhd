-- Language: VHDL-2008

-- gyrofx_pi — PI controller with a clamped integrator (anti-windup) and a preset.
--
-- Purpose: the VHDL twin of gyrofx_pi.v (same generics, ports and timing): the gyro
--   loop's PLL (phase error in, NCO frequency word out) and AGC (amplitude error in,
--   drive amplitude out), SPEC 1.6. Bit-exact with gyrofx_model::gyro_loop::pi::FixedPi.
--
-- Algorithm (per sample, ce high; e = err):
--     v      = preset ? clamp(preset_value) : v_reg
--     v_reg <= clamp(Q(v + KI * e), INT_MIN, INT_MAX)    INT format; Q rounds into a
--                                                         format wide enough never to wrap
--     u_out <= Q(KP * e + v_reg after the update)        OUT format, ROUNDING/SATURATE
--   Products and sums are exact (add: +1 bit, multiply: widths add), as in the model.
--   A clock with preset high and ce low only loads clamp(preset_value).
--   KP, KI (KP_W, KI_W bits) and INT_MIN, INT_MAX (INT_W bits) are two's-complement
--   vectors, e.g. 18x"10000"; one of another length stops the elaboration.
--
-- Pipeline: one register stage. u_out and out_valid are valid 1 clock after ce. A
--   clock with rst high clears the integrator and out_valid (rst wins over ce and
--   preset).

library ieee;
use ieee.std_logic_1164.all;
use ieee.numeric_std.all;

entity gyrofx_pi is
    generic (
        -- error input: width and fraction bits
        ERR_W : positive := 24;
        ERR_F : integer := 23;
        -- kp: width and fraction bits
        KP_W : positive := 18;
        KP_F : integer := 26;
        -- ki: width and fraction bits
        KI_W : positive := 18;
        KI_F : integer := 34;
        -- integrator: width and fraction bits
        INT_W : positive := 59;
        INT_F : integer := 57;
        -- output: width and fraction bits
        OUT_W : positive := 32;
        OUT_F : integer := 32;
        -- kp and ki codes (the defaults: 2^-10 and 2^-18)
        KP : std_logic_vector := 18x"10000";
        KI : std_logic_vector := 18x"10000";
        -- integrator limits, INT-format codes (the defaults: 0.035 and 0.05 cycles per
        -- sample, 7 and 10 kHz at 200 kHz)
        INT_MIN : std_logic_vector := 59x"11eb851eb851ec";
        INT_MAX : std_logic_vector := 59x"1999999999999a";
        -- rounding: 0 floor, 1 ceil, 2 zero, 3 nearest, 4 round, 5 convergent
        ROUNDING : natural := 3;
        -- overflow at the output: 0 wrap, 1 saturate
        SATURATE : natural := 1
    );
    port (
        clk          : in  std_logic;
        rst          : in  std_logic;
        ce           : in  std_logic;
        err          : in  signed(ERR_W - 1 downto 0);
        preset       : in  std_logic;
        preset_value : in  signed(INT_W - 1 downto 0);
        u_out        : out signed(OUT_W - 1 downto 0);
        out_valid    : out std_logic
    );
end entity;

architecture rtl of gyrofx_pi is

    function maximum_of(a, b : integer) return integer is
    begin
        if a > b then
            return a;
        end if;
        return b;
    end function;

    -- `bits` as a signed code of `width` bits; another length stops the elaboration.
    function code_of(name : string; bits : std_logic_vector; width : positive) return signed is
        variable result : signed(width - 1 downto 0) := (others => '0');
    begin
        assert bits'length = width
            report "gyrofx_pi: " & name & " has " & integer'image(bits'length)
                & " bits; " & integer'image(width) & " are needed"
            severity failure;
        if bits'length = width then
            result := signed(bits);
        end if;
        return result;
    end function;

    -- Integer bits (with sign) of each node; an exact sum has the finer fraction and one
    -- integer bit more than the wider operand.
    constant INT_I : integer := INT_W - INT_F;
    constant KIE_W : positive := KI_W + ERR_W;
    constant KIE_F : integer := KI_F + ERR_F;
    constant KIE_I : integer := KIE_W - KIE_F;
    constant UPD_F : integer := maximum_of(INT_F, KIE_F);
    constant UPD_I : integer := maximum_of(INT_I, KIE_I) + 1;
    constant UPD_W : positive := UPD_I + UPD_F;
    -- The rounded update before the clamp: one bit more than the sum's integer part.
    constant RND_W : positive := UPD_I + 1 + INT_F;
    constant KPE_W : positive := KP_W + ERR_W;
    constant KPE_F : integer := KP_F + ERR_F;
    constant KPE_I : integer := KPE_W - KPE_F;
    constant SUM_F : integer := maximum_of(INT_F, KPE_F);
    constant SUM_I : integer := maximum_of(INT_I, KPE_I) + 1;
    constant SUM_W : positive := SUM_I + SUM_F;

    constant KP_CODE : signed(KP_W - 1 downto 0) := code_of("KP", KP, KP_W);
    constant KI_CODE : signed(KI_W - 1 downto 0) := code_of("KI", KI, KI_W);
    constant LOW : signed(INT_W - 1 downto 0) := code_of("INT_MIN", INT_MIN, INT_W);
    constant HIGH : signed(INT_W - 1 downto 0) := code_of("INT_MAX", INT_MAX, INT_W);

    signal v_reg : signed(INT_W - 1 downto 0) := (others => '0');
    signal u_reg : signed(OUT_W - 1 downto 0) := (others => '0');
    signal valid_reg : std_logic := '0';

    signal preset_clamped : signed(INT_W - 1 downto 0);
    signal v : signed(INT_W - 1 downto 0);
    signal ki_e : signed(KIE_W - 1 downto 0);
    signal update : signed(UPD_W - 1 downto 0);
    signal rounded : signed(RND_W - 1 downto 0);
    signal v_next : signed(INT_W - 1 downto 0);
    signal kp_e : signed(KPE_W - 1 downto 0);
    signal sum : signed(SUM_W - 1 downto 0);
    signal u_next : signed(OUT_W - 1 downto 0);

begin

    assert LOW <= HIGH
        report "gyrofx_pi: INT_MIN must be <= INT_MAX"
        severity failure;

    preset_clamped <= LOW when preset_value < LOW else
                      HIGH when preset_value > HIGH else
                      preset_value;
    v <= preset_clamped when preset = '1' else v_reg;

    -- v + KI * e at UPD_F fraction bits, exact.
    ki_e <= KI_CODE * err;
    update <= shift_left(resize(v, UPD_W), UPD_F - INT_F)
        + shift_left(resize(ki_e, UPD_W), UPD_F - KIE_F);

    quantize_v : entity work.gyrofx_quantize
        generic map (
            IN_W => UPD_W, IN_F => UPD_F, OUT_W => RND_W, OUT_F => INT_F,
            ROUNDING => ROUNDING, SATURATE => 0
        )
        port map (value_in => update, value_out => rounded, overflow => open);

    -- The clamp: the limits bound the result, so its low INT_W bits are exact.
    v_next <= LOW when rounded < resize(LOW, RND_W) else
              HIGH when rounded > resize(HIGH, RND_W) else
              rounded(INT_W - 1 downto 0);

    -- KP * e + v_next at SUM_F fraction bits, exact.
    kp_e <= KP_CODE * err;
    sum <= shift_left(resize(kp_e, SUM_W), SUM_F - KPE_F)
        + shift_left(resize(v_next, SUM_W), SUM_F - INT_F);

    quantize_u : entity work.gyrofx_quantize
        generic map (
            IN_W => SUM_W, IN_F => SUM_F, OUT_W => OUT_W, OUT_F => OUT_F,
            ROUNDING => ROUNDING, SATURATE => SATURATE
        )
        port map (value_in => sum, value_out => u_next, overflow => open);

    registers : process (clk)
    begin
        if rising_edge(clk) then
            if ce = '1' then
                v_reg <= v_next;
                u_reg <= u_next;
            elsif preset = '1' then
                v_reg <= preset_clamped;
            end if;
            valid_reg <= ce;

            if rst = '1' then
                v_reg <= (others => '0');
                valid_reg <= '0';
            end if;
        end if;
    end process;

    u_out <= u_reg;
    out_valid <= valid_reg;

end architecture;
