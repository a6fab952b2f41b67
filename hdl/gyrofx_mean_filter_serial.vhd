-- Language: VHDL-2008

-- gyrofx_mean_filter_serial — mean filter with gross-error rejection (paper 003),
-- sequential: the block means of gyrofx_mean_filter, one step a clock.
--
-- Purpose: the VHDL twin of gyrofx_mean_filter_serial.v (same generics, ports, ROM
--   image, state machine and timing). One output per block of WINDOW samples: the
--   mean of the samples within r of the block mean. Bit-exact with
--   gyrofx_model::mean_filter::FixedMeanFilter (and its schedule,
--   gyrofx_model::mean_filter::serial) at a longer latency; no multiplier.
--
-- Algorithm: |WINDOW * s - sum| <= WINDOW * r is, for integer codes and an
--   integer r (THRESHOLD, in input LSB),
--       ceil(sum / WINDOW) - r  <=  s  <=  floor(sum / WINDOW) + r
--   so one division per block leaves two comparisons per sample. After a
--   block's last ce (which stores the sample in the RAM and loads the divider):
--     DIVIDE      SUM_W - 1 clocks  restoring division of sum's magnitude (one's
--                                   complement when negative) by WINDOW
--     BOUNDS      1 clock           kept_low, kept_high; reads sample 0
--     SCAN        WINDOW clocks     keep kept_low <= s <= kept_high: count, kept sum
--     RECIPROCAL  1 clock           reads ROM[count]
--     LOAD        1 clock           the reciprocal into the product's low half
--     MULTIPLY    RECIP_W - 1       shift and add, lowest bit first: high = (high +
--                                   bit * operand) >> 1, the bit shifted out into
--                                   the low half (operand: the kept sum, or the sum
--                                   when none was kept; the reciprocal's sign bit is 0)
--     OUTPUT      1 clock           y = Q(product), kept = count, y_valid
--   THRESHOLD is an IN_W-bit vector (e.g. 24x"1333").
--
-- Latency: y_valid pulses high for one clock LATENCY = SUM_W + WINDOW +
--   RECIP_W + 3 clocks after a block's last ce, counting that ce's clock as the
--   first (the parallel filter's: 1); y and kept change on that edge and hold
--   until the next block's. The next ce or rst may come LATENCY clocks after
--   a block's last ce (the next block's samples share the RAM: a ce sooner
--   corrupts the block being processed, a rst sooner stops it); a block's
--   other samples may come every clock. A clock with rst high starts a new
--   block, stops a block being processed and clears y_valid (rst wins over ce).
--
-- Memories: the samples' RAM and the reciprocal ROM (ROM_FILE, WINDOW + 1 words,
--   read by gyrofx_mem_pkg at elaboration) are both read registered (ram_q,
--   rom_q), so that synthesis can map them to block RAM. The RAM, ram_q and rom_q
--   start at zero (the Verilog model holds X until they are written; no output
--   depends on them before then).
--   The keep decision (the Verilog model's wire keep) is taken in the SCAN branch
--   of the state machine, so that its comparisons see no metavalue at time 0.

library ieee;
use ieee.std_logic_1164.all;
use ieee.numeric_std.all;

use work.gyrofx_mem_pkg.all;

entity gyrofx_mean_filter_serial is
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
        -- r in input LSB (unsigned)
        THRESHOLD : std_logic_vector := 24x"1333";
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

architecture rtl of gyrofx_mean_filter_serial is

    -- Bits of an unsigned number holding 0..value.
    function bits_for(value : natural) return positive is
        variable bits : positive := 1;
    begin
        while 2 ** bits <= value loop
            bits := bits + 1;
        end loop;
        return bits;
    end function;

    function maximum_of(a, b : integer) return integer is
    begin
        if a > b then
            return a;
        end if;
        return b;
    end function;

    -- THRESHOLD as an unsigned code; one of another length stops the elaboration.
    function threshold_of(bits : std_logic_vector) return unsigned is
        variable result : unsigned(IN_W - 1 downto 0) := (others => '0');
    begin
        assert bits'length = IN_W
            report "gyrofx_mean_filter_serial: THRESHOLD has " & integer'image(bits'length)
                & " bits; IN_W = " & integer'image(IN_W)
            severity failure;
        if bits'length = IN_W then
            result := unsigned(bits);
        end if;
        return result;
    end function;

    constant PRODUCT_W : positive := SUM_W + RECIP_W;
    -- The division's dividend and quotient (sum's magnitude) and its remainder (< 2 WINDOW).
    constant MAGNITUDE_W : positive := SUM_W - 1;
    constant REMAINDER_W : positive := COUNT_W + 1;
    -- The kept range: floor(sum / WINDOW) +- r needs one bit more than the input.
    constant BOUND_W : positive := SUM_W + 1;
    constant STEPS : positive := maximum_of(maximum_of(MAGNITUDE_W, WINDOW), RECIP_W);
    -- The step counter also gives the RAM's read address: at least COUNT_W bits.
    constant STEP_W : positive := maximum_of(bits_for(STEPS), COUNT_W);
    -- The product's halves: high (SUM_W + 1 bits: holds high + operand) and low (first the
    -- reciprocal's RECIP_W - 1 magnitude bits, replaced by the product's from the top).
    constant LOW_W : positive := RECIP_W - 1;

    constant IDLE : std_logic_vector(2 downto 0) := "000";
    constant DIVIDE : std_logic_vector(2 downto 0) := "001";
    constant BOUNDS : std_logic_vector(2 downto 0) := "010";
    constant SCAN : std_logic_vector(2 downto 0) := "011";
    constant RECIPROCAL : std_logic_vector(2 downto 0) := "100";
    constant LOAD : std_logic_vector(2 downto 0) := "101";
    constant MULTIPLY : std_logic_vector(2 downto 0) := "110";
    constant OUTPUT : std_logic_vector(2 downto 0) := "111";

    constant THRESHOLD_CODE : unsigned(IN_W - 1 downto 0) := threshold_of(THRESHOLD);
    constant THRESHOLD_BOUND : signed(BOUND_W - 1 downto 0) :=
        signed(resize(THRESHOLD_CODE, BOUND_W));
    constant LAST_INDEX : unsigned(COUNT_W - 1 downto 0) := to_unsigned(WINDOW - 1, COUNT_W);
    constant DIVISOR : unsigned(REMAINDER_W - 1 downto 0) := to_unsigned(WINDOW, REMAINDER_W);
    constant DIVISOR_LESS_ONE : unsigned(COUNT_W - 1 downto 0) := to_unsigned(WINDOW - 1, COUNT_W);
    constant DIVIDE_LAST : unsigned(STEP_W - 1 downto 0) := to_unsigned(MAGNITUDE_W - 1, STEP_W);
    constant SCAN_LAST : unsigned(STEP_W - 1 downto 0) := to_unsigned(WINDOW - 1, STEP_W);
    constant MULTIPLY_LAST : unsigned(STEP_W - 1 downto 0) := to_unsigned(RECIP_W - 2, STEP_W);

    -- The block's samples (block RAM) and the reciprocals (block ROM), both read registered.
    type sample_ram is array (0 to WINDOW - 1) of std_logic_vector(IN_W - 1 downto 0);
    signal ram : sample_ram := (others => (others => '0'));
    signal ram_q : std_logic_vector(IN_W - 1 downto 0) := (others => '0');
    constant ROM : word_array(0 to WINDOW)(RECIP_W - 1 downto 0) :=
        read_mem(ROM_FILE, WINDOW + 1, RECIP_W);
    -- The reciprocals are positive: rom_q's sign bit is always 0.
    signal rom_q : std_logic_vector(RECIP_W - 1 downto 0) := (others => '0');

    signal state : std_logic_vector(2 downto 0) := IDLE;
    signal step : unsigned(STEP_W - 1 downto 0) := (others => '0');
    signal index : unsigned(COUNT_W - 1 downto 0) := (others => '0');
    signal sum : signed(SUM_W - 1 downto 0) := (others => '0');
    signal negative : std_logic := '0';
    signal dividend : unsigned(MAGNITUDE_W - 1 downto 0) := (others => '0');
    signal remainder : unsigned(REMAINDER_W - 1 downto 0) := (others => '0');
    -- The kept range: samples from kept_low to kept_high (inclusive) are kept.
    signal kept_low : signed(BOUND_W - 1 downto 0) := (others => '0');
    signal kept_high : signed(BOUND_W - 1 downto 0) := (others => '0');
    signal count : unsigned(COUNT_W - 1 downto 0) := (others => '0');
    signal kept_sum : signed(SUM_W - 1 downto 0) := (others => '0');
    signal product_high : signed(BOUND_W - 1 downto 0) := (others => '0');
    signal product_low : unsigned(LOW_W - 1 downto 0) := (others => '0');
    signal y_reg : signed(OUT_W - 1 downto 0) := (others => '0');
    signal kept_reg : unsigned(COUNT_W - 1 downto 0) := (others => '0');
    signal valid_reg : std_logic := '0';

    signal take : std_logic;
    signal x_sum : signed(SUM_W - 1 downto 0);
    signal sum_next : signed(SUM_W - 1 downto 0);
    signal shifted : unsigned(REMAINDER_W - 1 downto 0);
    signal trial : unsigned(REMAINDER_W downto 0);
    signal fits : std_logic;
    signal floor_sum : signed(SUM_W - 1 downto 0);
    signal inexact : std_logic;
    signal floor_bound : signed(BOUND_W - 1 downto 0);
    signal inexact_bound : signed(BOUND_W - 1 downto 0);
    signal sample : signed(IN_W - 1 downto 0);
    signal sample_bound : signed(BOUND_W - 1 downto 0);
    signal sample_sum : signed(SUM_W - 1 downto 0);
    signal none_kept : std_logic;
    signal operand : signed(SUM_W - 1 downto 0);
    signal addend : signed(BOUND_W - 1 downto 0);
    signal partial : signed(BOUND_W - 1 downto 0);
    signal product : signed(PRODUCT_W - 1 downto 0);
    signal next_step : unsigned(STEP_W - 1 downto 0);
    signal read_address : unsigned(COUNT_W - 1 downto 0);
    signal y_next : signed(OUT_W - 1 downto 0);

begin

    assert WINDOW >= 2 and 2 ** COUNT_W > WINDOW
        report "gyrofx_mean_filter_serial: WINDOW (" & integer'image(WINDOW)
            & ") must be >= 2 and fit COUNT_W (" & integer'image(COUNT_W) & ") bits"
        severity failure;
    assert SUM_W >= IN_W + 1 and RECIP_W >= 3
        report "gyrofx_mean_filter_serial: SUM_W (" & integer'image(SUM_W) & ") or RECIP_W ("
            & integer'image(RECIP_W) & ") too narrow"
        severity failure;

    -- Taking a sample: the running sum restarts at a block's first.
    take <= ce and not rst;
    x_sum <= resize(x, SUM_W);
    sum_next <= x_sum when index = 0 else sum + x_sum;

    -- One restoring division step: the next dividend bit into the remainder, WINDOW out if it fits.
    shifted <= remainder(REMAINDER_W - 2 downto 0) & dividend(MAGNITUDE_W - 1);
    trial <= ('0' & shifted) - ('0' & DIVISOR);
    fits <= not trial(REMAINDER_W);

    -- floor(sum / WINDOW) = not floor(not sum / WINDOW) for a negative sum, exact when the
    -- remainder is WINDOW - 1.
    floor_sum <= not signed(resize(dividend, SUM_W)) when negative = '1'
                 else signed(resize(dividend, SUM_W));
    inexact <= '1' when negative = '1' and remainder(COUNT_W - 1 downto 0) /= DIVISOR_LESS_ONE else
               '1' when negative = '0' and remainder /= 0 else
               '0';
    floor_bound <= resize(floor_sum, BOUND_W);
    inexact_bound <= to_signed(1, BOUND_W) when inexact = '1' else to_signed(0, BOUND_W);

    sample <= signed(ram_q);
    sample_bound <= resize(sample, BOUND_W);
    sample_sum <= resize(sample, SUM_W);

    none_kept <= '1' when count = 0 else '0';
    operand <= sum when none_kept = '1' else kept_sum;
    addend <= resize(operand, BOUND_W) when product_low(0) = '1' else (others => '0');
    partial <= product_high + addend;
    product <= product_high & signed(product_low);

    next_step <= step + 1;
    -- Sample 0 is read in BOUNDS, sample k + 1 while sample k is scanned.
    read_address <= resize(next_step, COUNT_W) when state = SCAN and step /= SCAN_LAST
                    else (others => '0');

    quantize_y : entity work.gyrofx_quantize
        generic map (
            IN_W => PRODUCT_W, IN_F => IN_F + RECIP_F, OUT_W => OUT_W, OUT_F => OUT_F,
            ROUNDING => ROUNDING, SATURATE => SATURATE
        )
        port map (value_in => product, value_out => y_next, overflow => open);

    memories : process (clk)
    begin
        if rising_edge(clk) then
            if take = '1' then
                ram(to_integer(index)) <= std_logic_vector(x);
            end if;
            ram_q <= ram(to_integer(read_address));
            rom_q <= ROM(to_integer(count));
        end if;
    end process;

    registers : process (clk)
    begin
        if rising_edge(clk) then
            valid_reg <= '0';
            case state is
                when DIVIDE =>
                    if fits = '1' then
                        remainder <= trial(REMAINDER_W - 1 downto 0);
                    else
                        remainder <= shifted;
                    end if;
                    dividend <= dividend(MAGNITUDE_W - 2 downto 0) & fits;
                    step <= next_step;
                    if step = DIVIDE_LAST then
                        state <= BOUNDS;
                    end if;
                when BOUNDS =>
                    kept_low <= floor_bound + inexact_bound - THRESHOLD_BOUND;
                    kept_high <= floor_bound + THRESHOLD_BOUND;
                    count <= (others => '0');
                    kept_sum <= (others => '0');
                    step <= (others => '0');
                    state <= SCAN;
                when SCAN =>
                    -- keep: kept_low <= s <= kept_high
                    if sample_bound >= kept_low and sample_bound <= kept_high then
                        count <= count + 1;
                        kept_sum <= kept_sum + sample_sum;
                    end if;
                    step <= next_step;
                    if step = SCAN_LAST then
                        state <= RECIPROCAL;
                    end if;
                when RECIPROCAL =>
                    state <= LOAD;
                when LOAD =>
                    product_high <= (others => '0');
                    product_low <= unsigned(rom_q(LOW_W - 1 downto 0));
                    step <= (others => '0');
                    state <= MULTIPLY;
                when MULTIPLY =>
                    product_high <= partial(BOUND_W - 1) & partial(BOUND_W - 1 downto 1);
                    product_low <= partial(0) & product_low(LOW_W - 1 downto 1);
                    step <= next_step;
                    if step = MULTIPLY_LAST then
                        state <= OUTPUT;
                    end if;
                when OUTPUT =>
                    y_reg <= y_next;
                    kept_reg <= count;
                    valid_reg <= '1';
                    state <= IDLE;
                when others =>
                    state <= IDLE;
            end case;

            if take = '1' then
                sum <= sum_next;
                if index = LAST_INDEX then
                    index <= (others => '0');
                    negative <= sum_next(SUM_W - 1);
                    if sum_next(SUM_W - 1) = '1' then
                        dividend <= not unsigned(sum_next(MAGNITUDE_W - 1 downto 0));
                    else
                        dividend <= unsigned(sum_next(MAGNITUDE_W - 1 downto 0));
                    end if;
                    remainder <= (others => '0');
                    step <= (others => '0');
                    state <= DIVIDE;
                else
                    index <= index + 1;
                end if;
            end if;

            if rst = '1' then
                index <= (others => '0');
                state <= IDLE;
                valid_reg <= '0';
            end if;
        end if;
    end process;

    y <= y_reg;
    kept <= kept_reg;
    y_valid <= valid_reg;

    -- pragma translate_off
    -- Simulation only: a ce while the previous block is still being processed would overwrite
    -- the RAM it reads; stop the simulation instead, naming this instance (the next block may
    -- start min_clocks_per_sample clocks after a block's last ce, gyrofx_job::pipeline).
    spacing_check : process (clk)
    begin
        if rising_edge(clk) then
            assert not (take = '1' and state /= IDLE)
                report spacing_check'path_name & ": a sample while the previous block is being processed; "
                    & "gyrofx_mean_filter_serial takes the next block's first sample at most every "
                    & "min_clocks_per_sample clocks after a block's last (manifest.json)"
                severity failure;
        end if;
    end process;
    -- pragma translate_on

end architecture;
