-- Language: VHDL-2008

-- gyrofx_mean_filter — mean filter with gross-error rejection (paper 003).
--
-- Purpose: the VHDL twin of gyrofx_mean_filter.v (same generics, ports, ROM image
--   and timing). One output per block of WINDOW samples: the mean of the samples
--   within r of the block mean. Bit-exact with
--   gyrofx_model::mean_filter::FixedMeanFilter.
--
-- Algorithm (at a block's last ce, over its WINDOW samples s_i, the current x last):
--     sum    = sum_i s_i                                   exact, SUM_W bits
--     keep_i = |WINDOW * s_i - sum| <= SCALED_THRESHOLD    exact (= WINDOW * r in input LSB)
--     n      = sum_i keep_i,  kept_sum = sum_i keep_i * s_i
--     y     <= Q((n = 0 ? sum : kept_sum) * ROM(n))       output format
--     kept  <= n
--   ROM(n) = 1/n for n = 1..WINDOW and ROM(0) = 1/WINDOW (every sample rejected:
--   the plain mean). SCALED_THRESHOLD is a DEV_W-bit vector (e.g. 30x"17ffc").
--
-- Latency: y, kept and y_valid are registered: y_valid pulses 1 clock after a
--   block's last ce. A clock with rst high starts a new block and clears
--   y_valid (rst wins over ce).

library ieee;
use ieee.std_logic_1164.all;
use ieee.numeric_std.all;

use work.gyrofx_mem_pkg.all;

entity gyrofx_mean_filter is
    generic (
        -- input x: width and fraction bits (°/s)
        IN_W : positive := 24;
        IN_F : natural := 14;
        -- output y: width and fraction bits
        OUT_W : positive := 24;
        OUT_F : integer := 14;
        -- samples per block (2..1024) and the width of a count 0..WINDOW
        WINDOW : positive := 20;
        COUNT_W : positive := 5;
        -- exact block sum: IN_W + ceil(log2 WINDOW) bits
        SUM_W : positive := 29;
        -- exact deviation WINDOW * s - sum, and WINDOW * r in input LSB
        DEV_W : positive := 30;
        SCALED_THRESHOLD : std_logic_vector := 30x"17ffc";
        -- reciprocal codes 1/n: width and fraction bits
        RECIP_W : positive := 18;
        RECIP_F : natural := 16;
        -- rounding: 0 floor, 1 ceil, 2 zero, 3 nearest, 4 round, 5 convergent
        ROUNDING : natural := 3;
        -- overflow: 0 wrap, 1 saturate
        SATURATE : natural := 1;
        -- reciprocal ROM image (hex, one word per line): WINDOW + 1 words, address = kept count
        ROM_FILE : string := "mean_filter_reciprocals.mem"
    );
    port (
        clk     : in  std_logic;
        rst     : in  std_logic;
        ce      : in  std_logic;
        x       : in  signed(IN_W - 1 downto 0);
        y       : out signed(OUT_W - 1 downto 0);
        kept    : out unsigned(COUNT_W - 1 downto 0);
        y_valid : out std_logic
    );
end entity;

architecture rtl of gyrofx_mean_filter is

    constant PRODUCT_W : positive := SUM_W + RECIP_W;

    -- SCALED_THRESHOLD as a signed code; one of another length stops the elaboration.
    function threshold_of(bits : std_logic_vector) return signed is
        variable result : signed(DEV_W - 1 downto 0) := (others => '0');
    begin
        assert bits'length = DEV_W
            report "gyrofx_mean_filter: SCALED_THRESHOLD has " & integer'image(bits'length)
                & " bits; DEV_W = " & integer'image(DEV_W)
            severity failure;
        if bits'length = DEV_W then
            result := signed(bits);
        end if;
        return result;
    end function;

    constant THRESHOLD : signed(DEV_W - 1 downto 0) := threshold_of(SCALED_THRESHOLD);
    constant ROM : word_array(0 to WINDOW)(RECIP_W - 1 downto 0) :=
        read_mem(ROM_FILE, WINDOW + 1, RECIP_W);
    constant LAST_PHASE : unsigned(COUNT_W - 1 downto 0) := to_unsigned(WINDOW - 1, COUNT_W);
    constant WINDOW_DEV : signed(DEV_W - 1 downto 0) := to_signed(WINDOW, DEV_W);

    type sample_array is array (0 to WINDOW - 1) of signed(IN_W - 1 downto 0);

    -- The block's earlier samples (the last entry is unused: the current x is the last).
    signal stored : sample_array := (others => (others => '0'));
    signal phase_reg : unsigned(COUNT_W - 1 downto 0) := (others => '0');
    signal y_reg : signed(OUT_W - 1 downto 0) := (others => '0');
    signal kept_reg : unsigned(COUNT_W - 1 downto 0) := (others => '0');
    signal valid_reg : std_logic := '0';

    signal last : std_logic;
    signal count : unsigned(COUNT_W - 1 downto 0);
    signal product : signed(PRODUCT_W - 1 downto 0);
    signal y_next : signed(OUT_W - 1 downto 0);

begin

    assert WINDOW >= 2 and 2 ** COUNT_W > WINDOW
        report "gyrofx_mean_filter: WINDOW (" & integer'image(WINDOW)
            & ") must be >= 2 and fit COUNT_W (" & integer'image(COUNT_W) & ") bits"
        severity failure;
    assert DEV_W >= IN_W + COUNT_W + 1 and SUM_W >= IN_W + 1
        report "gyrofx_mean_filter: DEV_W (" & integer'image(DEV_W) & ") or SUM_W ("
            & integer'image(SUM_W) & ") too narrow"
        severity failure;

    last <= '1' when phase_reg = LAST_PHASE else '0';

    -- Sum, keep decisions, kept sum and count. Only a block's last sample uses them:
    -- elsewhere the product is 0, which spares the simulator a WINDOW-sample pass per
    -- sample for one AND per bit.
    block_mean : process (all)
        variable value : signed(IN_W - 1 downto 0);
        variable sum : signed(SUM_W - 1 downto 0);
        variable deviation : signed(DEV_W - 1 downto 0);
        variable kept_sum : signed(SUM_W - 1 downto 0);
        variable kept_count : unsigned(COUNT_W - 1 downto 0);
        variable total : signed(SUM_W - 1 downto 0);
    begin
        sum := (others => '0');
        kept_sum := (others => '0');
        kept_count := (others => '0');
        total := (others => '0');
        if last = '1' then
            for k in 0 to WINDOW - 1 loop
                if k = WINDOW - 1 then
                    value := x;
                else
                    value := stored(k);
                end if;
                sum := sum + resize(value, SUM_W);
            end loop;
            for k in 0 to WINDOW - 1 loop
                if k = WINDOW - 1 then
                    value := x;
                else
                    value := stored(k);
                end if;
                deviation := resize(WINDOW_DEV * resize(value, DEV_W), DEV_W) - resize(sum, DEV_W);
                if deviation <= THRESHOLD and deviation >= -THRESHOLD then
                    kept_sum := kept_sum + resize(value, SUM_W);
                    kept_count := kept_count + 1;
                end if;
            end loop;
            if kept_count = 0 then
                total := sum;
            else
                total := kept_sum;
            end if;
        end if;
        count <= kept_count;
        product <= total * signed(ROM(to_integer(kept_count)));
    end process;

    quantize_y : entity work.gyrofx_quantize
        generic map (
            IN_W => PRODUCT_W, IN_F => IN_F + RECIP_F, OUT_W => OUT_W, OUT_F => OUT_F,
            ROUNDING => ROUNDING, SATURATE => SATURATE
        )
        port map (value_in => product, value_out => y_next, overflow => open);

    registers : process (clk)
    begin
        if rising_edge(clk) then
            valid_reg <= '0';
            if ce = '1' then
                if last = '1' then
                    phase_reg <= (others => '0');
                    y_reg <= y_next;
                    kept_reg <= count;
                    valid_reg <= '1';
                else
                    if rst = '0' then
                        stored(to_integer(phase_reg)) <= x;
                    end if;
                    phase_reg <= phase_reg + 1;
                end if;
            end if;

            if rst = '1' then
                phase_reg <= (others => '0');
                valid_reg <= '0';
            end if;
        end if;
    end process;

    y <= y_reg;
    kept <= kept_reg;
    y_valid <= valid_reg;

end architecture;
