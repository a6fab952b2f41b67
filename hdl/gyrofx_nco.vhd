-- Language: VHDL-2008

-- gyrofx_nco — numerically controlled oscillator: phase accumulator and quarter-wave
-- sine ROM, sine and cosine outputs.
--
-- Purpose: the VHDL twin of gyrofx_nco.v (same generics, ports, ROM image and timing):
--   the reference of the gyro's drive and sense loops (SPEC 1.6). Bit-exact with
--   gyrofx_model::gyro_loop::nco::FixedNco.
--
-- Algorithm (per sample, ce high; phases in cycles, u PHASE_W.PHASE_W):
--     phase = acc + offset (+ r)                mod 2^PHASE_W (wraps; r with ERROR_FEEDBACK)
--     t     = floor(phase / 2^(PHASE_W-ADDR_W-2))   ADDR_W+2 bits (gyrofx_quantize, floor)
--     r    <= (phase mod 2^(PHASE_W-ADDR_W-2)) - half a bin   (ERROR_FEEDBACK: the carried
--               truncation error, signed; errors of any run of samples sum to < 1 bin)
--     sin   = +/- ROM(i or 2^ADDR_W-1-i)       i = t mod 2^ADDR_W, quadrant = t / 2^ADDR_W:
--               q 0: ROM(i)  1: ROM(not i)  2: -ROM(i)  3: -ROM(not i)
--     cos   = the same at t + 2^ADDR_W         (a quarter cycle on)
--     acc  <= acc + freq                        mod 2^PHASE_W
--   ROM(k) = round(A * sin(pi/2 * (k + 1/2) / 2^ADDR_W)), A = 2^(SIN_W-1) - 1.
--
-- Pipeline: the ROM addresses and signs are registered at ce (a block-RAM read
--   port); sin_out, cos_out and out_valid are valid 1 clock after ce and hold
--   until the next ce. A clock with rst high clears acc, r and out_valid (rst wins
--   over ce).
--
-- ROM: ROM_FILE (read by gyrofx_mem_pkg at elaboration), 2^ADDR_W words of SIN_W bits.

library ieee;
use ieee.std_logic_1164.all;
use ieee.numeric_std.all;

use work.gyrofx_mem_pkg.all;

entity gyrofx_nco is
    generic (
        -- phase accumulator, frequency word and offset width, bits (cycles)
        PHASE_W : positive := 32;
        -- quarter-wave ROM address width: 2^ADDR_W words (PHASE_W >= ADDR_W + 2)
        ADDR_W : positive := 10;
        -- sine and cosine width, s SIN_W.SIN_W-1
        SIN_W : positive := 18;
        -- 1: carry each truncation error into the next phase (needs PHASE_W > ADDR_W + 2)
        ERROR_FEEDBACK : natural := 1;
        -- quarter-wave sine ROM image (hex, one word per line)
        ROM_FILE : string := "nco_sine.mem"
    );
    port (
        clk       : in  std_logic;
        rst       : in  std_logic;
        ce        : in  std_logic;
        freq      : in  unsigned(PHASE_W - 1 downto 0);
        offset    : in  unsigned(PHASE_W - 1 downto 0);
        sin_out   : out signed(SIN_W - 1 downto 0);
        cos_out   : out signed(SIN_W - 1 downto 0);
        out_valid : out std_logic
    );
end entity;

architecture rtl of gyrofx_nco is

    -- Truncated phase: quadrant (2 bits) and ROM index.
    constant T_W : positive := ADDR_W + 2;
    -- The carried error's width: the phase bits below the truncation (1 when there are none,
    -- and then unused).
    function residue_width return positive is
    begin
        if PHASE_W > T_W then
            return PHASE_W - T_W;
        end if;
        return 1;
    end function;
    constant R_W : positive := residue_width;
    -- Half a bin in phase LSB: the top bit of the carried error.
    function top_bit_only return signed is
        variable bin : signed(R_W - 1 downto 0) := (others => '0');
    begin
        bin(R_W - 1) := '1';
        return bin;
    end function;
    constant HALF_BIN : signed(R_W - 1 downto 0) := top_bit_only;
    constant ROM : word_array(0 to 2 ** ADDR_W - 1)(SIN_W - 1 downto 0) :=
        read_mem(ROM_FILE, 2 ** ADDR_W, SIN_W);

    signal acc_reg : unsigned(PHASE_W - 1 downto 0) := (others => '0');
    signal sin_addr_reg : unsigned(ADDR_W - 1 downto 0) := (others => '0');
    signal cos_addr_reg : unsigned(ADDR_W - 1 downto 0) := (others => '0');
    signal sin_negative_reg : std_logic := '0';
    signal cos_negative_reg : std_logic := '0';
    signal valid_reg : std_logic := '0';
    -- The last truncation error, signed, in phase LSB: [-2^(R_W-1), 2^(R_W-1)).
    signal residue_reg : signed(R_W - 1 downto 0) := (others => '0');
    signal residue_next : signed(R_W - 1 downto 0);

    signal phase_exact : unsigned(PHASE_W - 1 downto 0);
    signal phase : unsigned(PHASE_W - 1 downto 0);
    signal phase_signed : signed(PHASE_W downto 0);
    signal t_signed : signed(T_W downto 0);
    signal t_sin : unsigned(T_W - 1 downto 0);
    signal t_cos : unsigned(T_W - 1 downto 0);
    signal sin_addr : unsigned(ADDR_W - 1 downto 0);
    signal cos_addr : unsigned(ADDR_W - 1 downto 0);
    signal sin_magnitude : signed(SIN_W - 1 downto 0);
    signal cos_magnitude : signed(SIN_W - 1 downto 0);

begin

    assert PHASE_W >= T_W
        report "gyrofx_nco: PHASE_W (" & integer'image(PHASE_W) & ") must be >= ADDR_W + 2 ("
            & integer'image(T_W) & ")"
        severity failure;
    assert ERROR_FEEDBACK = 0 or PHASE_W > T_W
        report "gyrofx_nco: ERROR_FEEDBACK needs PHASE_W (" & integer'image(PHASE_W)
            & ") > ADDR_W + 2"
        severity failure;

    phase_exact <= acc_reg + offset;
    -- With error feedback the carried error joins the phase (sign-extended, mod one cycle).
    phase <= phase_exact + unsigned(resize(residue_reg, PHASE_W)) when ERROR_FEEDBACK /= 0
        else phase_exact;
    -- What is left below the truncation, less half a bin: its top bit inverted, read as signed.
    residue_next <= signed(phase(R_W - 1 downto 0)) xor HALF_BIN;

    -- The phase truncation: the unsigned phase seen as a signed value with a zero sign
    -- bit, floored to T_W fraction bits; it always fits, so only its low T_W bits count.
    phase_signed <= signed('0' & phase);
    quantize_phase : entity work.gyrofx_quantize
        generic map (
            IN_W => PHASE_W + 1, IN_F => PHASE_W, OUT_W => T_W + 1, OUT_F => T_W,
            ROUNDING => 0, SATURATE => 0
        )
        port map (value_in => phase_signed, value_out => t_signed, overflow => open);

    t_sin <= unsigned(t_signed(T_W - 1 downto 0));
    t_cos <= t_sin + to_unsigned(2 ** ADDR_W, T_W);
    sin_addr <= not t_sin(ADDR_W - 1 downto 0) when t_sin(ADDR_W) = '1' else t_sin(ADDR_W - 1 downto 0);
    cos_addr <= not t_cos(ADDR_W - 1 downto 0) when t_cos(ADDR_W) = '1' else t_cos(ADDR_W - 1 downto 0);

    sin_magnitude <= signed(ROM(to_integer(sin_addr_reg)));
    cos_magnitude <= signed(ROM(to_integer(cos_addr_reg)));

    registers : process (clk)
    begin
        if rising_edge(clk) then
            if ce = '1' then
                acc_reg <= acc_reg + freq;
                sin_addr_reg <= sin_addr;
                cos_addr_reg <= cos_addr;
                sin_negative_reg <= t_sin(T_W - 1);
                cos_negative_reg <= t_cos(T_W - 1);
                if ERROR_FEEDBACK /= 0 then
                    residue_reg <= residue_next;
                end if;
            end if;
            valid_reg <= ce;

            if rst = '1' then
                acc_reg <= (others => '0');
                residue_reg <= (others => '0');
                valid_reg <= '0';
            end if;
        end if;
    end process;

    sin_out <= -sin_magnitude when sin_negative_reg = '1' else sin_magnitude;
    cos_out <= -cos_magnitude when cos_negative_reg = '1' else cos_magnitude;
    out_valid <= valid_reg;

end architecture;
