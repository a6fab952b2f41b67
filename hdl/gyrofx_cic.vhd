-- Language: VHDL-2008

-- gyrofx_cic — CIC decimator with a droop-compensation FIR.
--
-- Purpose: the VHDL twin of gyrofx_cic.v (same generics, ports, ROM image and timing):
--   the sense channel's rate from the ADC rate fs down to the chain's rate
--   fs / DECIMATION (SPEC 1.6). Bit-exact with gyrofx_model::gyro_loop::cic::FixedCic.
--
-- Algorithm:
--   at every ce (fs), STAGES registered integrators, REG_W bits, wrapping:
--     v_1 <= v_1 + x,   v_j <= v_j + v_(j-1)            (old values: a registered cascade)
--   at every DECIMATION-th ce (fs / DECIMATION), on w_0 = v_STAGES after this update:
--     w_j = w_(j-1) - w_(j-1) from DELAY decimated samples ago    STAGES combs, wrapping
--     c   = Q(w_STAGES * 2^-SHIFT)              MID format (gyrofx_quantize)
--     y  <= Q(sum_t h_t * c[m - t])             OUT format; h from ROM_FILE, TAPS words
--   REG_W = IN_W + ceil(STAGES * log2(DECIMATION * DELAY)) (Hogenauer), derived here
--   exactly in integers: the combs undo every integrator wrap.
--
-- Pipeline: one register stage. y and y_valid are valid 1 clock after every
--   DECIMATION-th ce (counted from reset). A clock with rst high clears every
--   register, the decimation phase and y_valid (rst wins over ce).
--
-- ROM: ROM_FILE (read by gyrofx_mem_pkg at elaboration), TAPS words of COEF_W bits,
--   h_0 first (symmetric).

library ieee;
use ieee.std_logic_1164.all;
use ieee.numeric_std.all;

use work.gyrofx_mem_pkg.all;

entity gyrofx_cic is
    generic (
        -- input x: width and fraction bits
        IN_W : positive := 24;
        IN_F : integer := 23;
        -- integrator and comb stages (1..8)
        STAGES : positive := 3;
        -- decimation R (2..65536) and the comb's differential delay M (1 or 2)
        DECIMATION : positive := 1000;
        DELAY : positive := 1;
        -- the comb output is scaled by 2^-SHIFT
        SHIFT : natural := 30;
        -- scaled CIC output c: width and fraction bits
        MID_W : positive := 28;
        MID_F : integer := 27;
        -- compensator taps (odd) and their width and fraction bits
        TAPS : positive := 5;
        COEF_W : positive := 18;
        COEF_F : integer := 16;
        -- output y: width and fraction bits
        OUT_W : positive := 24;
        OUT_F : integer := 23;
        -- rounding: 0 floor, 1 ceil, 2 zero, 3 nearest, 4 round, 5 convergent
        ROUNDING : natural := 3;
        -- overflow: 0 wrap, 1 saturate
        SATURATE : natural := 1;
        -- compensator taps image (hex, one word per line)
        ROM_FILE : string := "cic_taps.mem"
    );
    port (
        clk     : in  std_logic;
        rst     : in  std_logic;
        ce      : in  std_logic;
        x       : in  signed(IN_W - 1 downto 0);
        y       : out signed(OUT_W - 1 downto 0);
        y_valid : out std_logic
    );
end entity;

architecture rtl of gyrofx_cic is

    -- ceil(log2(rm^stage_count)), exact: the smallest b with 2^b >= rm^stage_count.
    function growth_bits(stage_count : positive; rm : positive) return natural is
        variable gain : unsigned(255 downto 0) := to_unsigned(1, 256);
        variable bound : unsigned(255 downto 0) := to_unsigned(1, 256);
        variable bits : natural := 0;
    begin
        for s in 1 to stage_count loop
            gain := resize(gain * to_unsigned(rm, 32), 256);
        end loop;
        while bound < gain loop
            bound := shift_left(bound, 1);
            bits := bits + 1;
        end loop;
        return bits;
    end function;

    -- ceil(log2(value)), 0 for value 1.
    function ceil_log2(value : positive) return natural is
        variable bits : natural := 0;
    begin
        while 2 ** bits < value loop
            bits := bits + 1;
        end loop;
        return bits;
    end function;

    constant GROWTH : natural := growth_bits(STAGES, DECIMATION * DELAY);
    constant REG_W : positive := IN_W + GROWTH;
    constant CNT_W : positive := maximum(ceil_log2(DECIMATION), 1);
    constant PROD_W : positive := MID_W + COEF_W;
    constant ACC_W : positive := PROD_W + ceil_log2(TAPS);
    constant LAST_COUNT : unsigned(CNT_W - 1 downto 0) := to_unsigned(DECIMATION - 1, CNT_W);
    constant TAPS_ROM : word_array(0 to TAPS - 1)(COEF_W - 1 downto 0) :=
        read_mem(ROM_FILE, TAPS, COEF_W);

    type register_array is array (natural range <>) of signed(REG_W - 1 downto 0);
    type mid_array is array (natural range <>) of signed(MID_W - 1 downto 0);

    signal integrators : register_array(0 to STAGES - 1) := (others => (others => '0'));
    signal d1 : register_array(0 to STAGES - 1) := (others => (others => '0'));
    signal d2 : register_array(0 to STAGES - 1) := (others => (others => '0'));
    signal line_reg : mid_array(0 to TAPS - 2) := (others => (others => '0'));
    signal count_reg : unsigned(CNT_W - 1 downto 0) := (others => '0');
    signal y_reg : signed(OUT_W - 1 downto 0) := (others => '0');
    signal valid_reg : std_logic := '0';

    signal x_wide : signed(REG_W - 1 downto 0);
    signal last_next : signed(REG_W - 1 downto 0);
    signal comb_source : signed(REG_W - 1 downto 0);
    signal comb_in : register_array(0 to STAGES - 1);
    signal comb_out : signed(REG_W - 1 downto 0);
    signal c_next : signed(MID_W - 1 downto 0);
    signal line_next : mid_array(0 to TAPS - 1);
    signal fir_sum : signed(ACC_W - 1 downto 0);
    signal y_next : signed(OUT_W - 1 downto 0);
    signal decimate : std_logic;

begin

    assert STAGES <= 8 and DECIMATION >= 2 and DELAY <= 2 and TAPS mod 2 = 1
        report "gyrofx_cic: STAGES must be 1..8, DECIMATION >= 2, DELAY 1 or 2, TAPS odd"
        severity failure;

    decimate <= ce when count_reg = LAST_COUNT else '0';
    x_wide <= resize(x, REG_W);

    g_one_stage : if STAGES = 1 generate
        last_next <= integrators(0) + x_wide;
    end generate;
    g_stages : if STAGES > 1 generate
        last_next <= integrators(STAGES - 1) + integrators(STAGES - 2);
    end generate;

    -- The comb chain, the quantizer after it and the compensator matter only at a decimated
    -- sample, the only one whose results are registered: they take the last integrator's next
    -- value then and zero in between, so that a simulator evaluates their wide products once
    -- per output sample instead of at every input sample (about a third of the gyro loop's
    -- GHDL run time). In hardware this is one AND per bit.
    comb_source <= last_next when decimate = '1' else (others => '0');

    -- The comb chain on the last integrator's next value.
    combs : process (all)
        variable w : signed(REG_W - 1 downto 0);
    begin
        w := comb_source;
        for s in 0 to STAGES - 1 loop
            comb_in(s) <= w;
            if DELAY = 2 then
                w := w - d2(s);
            else
                w := w - d1(s);
            end if;
        end loop;
        comb_out <= w;
    end process;

    quantize_c : entity work.gyrofx_quantize
        generic map (
            IN_W => REG_W, IN_F => IN_F + SHIFT, OUT_W => MID_W, OUT_F => MID_F,
            ROUNDING => ROUNDING, SATURATE => SATURATE
        )
        port map (value_in => comb_out, value_out => c_next, overflow => open);

    -- The compensator: tap t multiplies c[m - t] of this decimated sample.
    line_next(0) <= c_next;
    g_line : for t in 1 to TAPS - 1 generate
        line_next(t) <= line_reg(t - 1);
    end generate;

    fir : process (all)
        variable acc : signed(ACC_W - 1 downto 0);
    begin
        acc := (others => '0');
        for t in 0 to TAPS - 1 loop
            acc := acc + resize(signed(TAPS_ROM(t)) * line_next(t), ACC_W);
        end loop;
        fir_sum <= acc;
    end process;

    quantize_y : entity work.gyrofx_quantize
        generic map (
            IN_W => ACC_W, IN_F => MID_F + COEF_F, OUT_W => OUT_W, OUT_F => OUT_F,
            ROUNDING => ROUNDING, SATURATE => SATURATE
        )
        port map (value_in => fir_sum, value_out => y_next, overflow => open);

    registers : process (clk)
    begin
        if rising_edge(clk) then
            if ce = '1' then
                integrators(0) <= integrators(0) + x_wide;
                for s in 1 to STAGES - 1 loop
                    integrators(s) <= integrators(s) + integrators(s - 1);
                end loop;
                if decimate = '1' then
                    count_reg <= (others => '0');
                else
                    count_reg <= count_reg + 1;
                end if;
            end if;
            if decimate = '1' then
                d1 <= comb_in;
                d2 <= d1;
                for t in 0 to TAPS - 2 loop
                    line_reg(t) <= line_next(t);
                end loop;
                y_reg <= y_next;
            end if;
            valid_reg <= decimate;

            if rst = '1' then
                integrators <= (others => (others => '0'));
                d1 <= (others => (others => '0'));
                d2 <= (others => (others => '0'));
                line_reg <= (others => (others => '0'));
                count_reg <= (others => '0');
                valid_reg <= '0';
            end if;
        end if;
    end process;

    y <= y_reg;
    y_valid <= valid_reg;

end architecture;
