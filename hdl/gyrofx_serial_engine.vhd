-- Language: VHDL-2008

-- gyrofx_serial_engine — the time-multiplexed chain: one 16x16 signed multiplier,
--   one column accumulator, a data RAM of 15-bit limbs, run by a program.
--
-- Purpose: the VHDL twin of gyrofx_serial_engine.v (same generics, ports, ROM
--   images and timing). Computes the calibration, the KF and the bias estimator of
--   one sample exactly as gyrofx_model::chain::FixedChain does (same exact sums,
--   same quantization points, same order), with a program that gyrofx derives from
--   the config (PROGRAM_FILE, COEFFICIENT_FILE). Bit-exact with
--   gyrofx_model::serial::Engine, which executes the same program.
--
-- Values: every value is held as limbs of 15 bits in 16-bit RAM words, least
--   significant first; low limbs zero-extended, the top limb sign-extended.
--
-- Program word (WORD_W = 11 + ADDR_W + COEF_ADDR_W bits, most significant
--   first): op (4), cond (4), ram_index (2), coefficient by bw_sel (1),
--   address (ADDR_W), coefficient (COEF_ADDR_W). The opcodes and conditions are
--   documented in gyrofx_model::serial::isa (docs/blocks/serial.md).
--
-- Timing: each instruction takes 4 clocks (fetch, read RAM and coefficient,
--   multiply, execute). On ce (when idle) the inputs and the sequencer's flags are
--   captured and the sample program runs from address 0 to its End: the outputs
--   show 4 * (sample program length) clocks after the ce clock, out_valid for one
--   clock. ce while busy is ignored. rst (synchronous, wins over ce) clears the
--   outputs at once and stops a running program; the first sample after it runs
--   the program's clearing instructions (condition "fresh") before it reads the
--   state, so a ce may follow rst on the next clock.
--
-- ROMs: PROGRAM_FILE (PROGRAM_DEPTH words of WORD_W bits) and COEFFICIENT_FILE
--   (COEF_DEPTH words of 16 bits), read by gyrofx_mem_pkg at elaboration, which
--   wants exactly that many words in each file. A read beyond a memory's depth
--   gives zero and a write there is dropped (the Verilog model reads X): a program
--   from gyrofx executes no such access, and End keeps pc on itself, so the idle
--   engine fetches within the program too.

library ieee;
use ieee.std_logic_1164.all;
use ieee.numeric_std.all;

use work.gyrofx_mem_pkg.all;

entity gyrofx_serial_engine is
    generic (
        -- gyro samples, rate output, bias outputs: widths
        IN_W : positive := 24;
        OUT_W : positive := 24;
        BIAS_W : positive := 28;
        -- bw_sel and interval index widths
        SEL_W : positive := 2;
        INTERVAL_W : positive := 2;
        -- column accumulator width (the largest column sum, signed; at least 17)
        ACC_W : positive := 32;
        -- data RAM and coefficient ROM: address widths and words
        ADDR_W : positive := 6;
        COEF_ADDR_W : positive := 5;
        RAM_DEPTH : positive := 64;
        COEF_DEPTH : positive := 32;
        -- program ROM words
        PROGRAM_DEPTH : positive := 512;
        -- run-time indexes: interval << RAM_INDEX_SHIFT, bw_sel << COEF_INDEX_SHIFT
        RAM_INDEX_SHIFT : natural := 1;
        COEF_INDEX_SHIFT : natural := 2;
        -- rounding: 0 floor, 1 ceil, 2 zero, 3 nearest, 4 round, 5 convergent
        ROUNDING : natural := 3;
        -- ROM images (hex, one word per line)
        PROGRAM_FILE : string := "serial_program.mem";
        COEFFICIENT_FILE : string := "serial_coefficients.mem";
        -- 1: y_a, y_b and the flags captured at ce. 0: y_a, y_b read from the ports while
        -- the program runs (the driver holds them from ce until out_valid)
        CAPTURE_SAMPLES : natural := 1;
        -- 1: rate_out, bias_a, bias_b, estimated load at End and hold until the next End. 0:
        -- they show the results as the program assembles them, final from End until the next
        -- sample's program writes them
        HOLD_RESULTS : natural := 1
    );
    port (
        clk         : in  std_logic;
        rst         : in  std_logic;
        ce          : in  std_logic;
        bw_sel      : in  unsigned(SEL_W - 1 downto 0);
        y_a         : in  signed(IN_W - 1 downto 0);
        y_b         : in  signed(IN_W - 1 downto 0);
        mode_a      : in  std_logic;
        mode_b      : in  std_logic;
        blank_a     : in  std_logic;
        blank_b     : in  std_logic;
        done_a      : in  std_logic;
        done_b      : in  std_logic;
        window_done : in  std_logic;
        interval_a  : in  unsigned(INTERVAL_W - 1 downto 0);
        interval_b  : in  unsigned(INTERVAL_W - 1 downto 0);
        rate_out    : out signed(OUT_W - 1 downto 0);
        out_valid   : out std_logic;
        bias_a      : out signed(BIAS_W - 1 downto 0);
        bias_b      : out signed(BIAS_W - 1 downto 0);
        estimated   : out std_logic;
        -- high while a program runs (ce is ignored)
        busy        : out std_logic
    );
end entity;

architecture rtl of gyrofx_serial_engine is

    -- ceil(log2(n)) for n >= 1, as Verilog's $clog2.
    function clog2(n : positive) return natural is
        variable bits : natural := 0;
    begin
        while 2 ** bits < n loop
            bits := bits + 1;
        end loop;
        return bits;
    end function;

    function pc_width return positive is
    begin
        if PROGRAM_DEPTH > 2 then
            return clog2(PROGRAM_DEPTH);
        end if;
        return 1;
    end function;

    constant LIMB : positive := 15;
    constant IN_LIMBS : positive := (IN_W + LIMB - 1) / LIMB;
    constant RATE_LIMBS : positive := (OUT_W + LIMB - 1) / LIMB;
    constant BIAS_LIMBS : positive := (BIAS_W + LIMB - 1) / LIMB;
    constant WORD_W : positive := 11 + ADDR_W + COEF_ADDR_W;
    constant PC_W : positive := pc_width;
    -- The product sign-extended to at least the accumulator's width.
    constant PRODUCT_W : positive := maximum(ACC_W, 32);

    -- Opcodes (gyrofx_model::serial::isa::Op).
    constant OP_ZERO : unsigned(3 downto 0) := x"0";
    constant OP_MAC : unsigned(3 downto 0) := x"1";
    constant OP_MAC_INPUT : unsigned(3 downto 0) := x"2";
    constant OP_EMIT : unsigned(3 downto 0) := x"3";
    constant OP_EMIT_TOP : unsigned(3 downto 0) := x"4";
    constant OP_DROP : unsigned(3 downto 0) := x"5";
    constant OP_DROP_HALF : unsigned(3 downto 0) := x"6";
    constant OP_SIGN : unsigned(3 downto 0) := x"7";
    constant OP_ROUND : unsigned(3 downto 0) := x"8";
    constant OP_HIGH : unsigned(3 downto 0) := x"9";
    constant OP_FITS : unsigned(3 downto 0) := x"a";
    constant OP_STORE_LOW : unsigned(3 downto 0) := x"b";
    constant OP_STORE_TOP : unsigned(3 downto 0) := x"c";
    constant OP_OUT : unsigned(3 downto 0) := x"d";
    constant OP_SET_ESTIMATED : unsigned(3 downto 0) := x"e";
    constant OP_END : unsigned(3 downto 0) := x"f";

    constant PROGRAM_ROM : word_array(0 to PROGRAM_DEPTH - 1)(WORD_W - 1 downto 0) :=
        read_mem(PROGRAM_FILE, PROGRAM_DEPTH, WORD_W);
    constant COEFFICIENT_ROM : word_array(0 to COEF_DEPTH - 1)(15 downto 0) :=
        read_mem(COEFFICIENT_FILE, COEF_DEPTH, 16);

    type ram_array is array (0 to RAM_DEPTH - 1) of std_logic_vector(15 downto 0);
    signal ram : ram_array := (others => (others => '0'));

    -- Sequencing.
    signal running : std_logic := '0';
    signal phase : unsigned(1 downto 0) := (others => '0');
    signal pc : unsigned(PC_W - 1 downto 0) := (others => '0');
    signal instruction : std_logic_vector(WORD_W - 1 downto 0) := (others => '0');

    -- The sample, captured at ce.
    signal y_a_reg : signed(LIMB * IN_LIMBS - 1 downto 0) := (others => '0');
    signal y_b_reg : signed(LIMB * IN_LIMBS - 1 downto 0) := (others => '0');
    -- The samples the program reads: captured at ce, or the ports themselves.
    signal y_a_sample : signed(LIMB * IN_LIMBS - 1 downto 0);
    signal y_b_sample : signed(LIMB * IN_LIMBS - 1 downto 0);
    signal bw_sel_reg : unsigned(SEL_W - 1 downto 0) := (others => '0');
    signal interval_a_reg : unsigned(INTERVAL_W - 1 downto 0) := (others => '0');
    signal interval_b_reg : unsigned(INTERVAL_W - 1 downto 0) := (others => '0');
    signal valid_a : std_logic := '0';
    signal valid_b : std_logic := '0';
    signal done_a_reg : std_logic := '0';
    signal done_b_reg : std_logic := '0';
    signal window_reg : std_logic := '0';
    signal mode_a_reg : std_logic := '0';
    signal mode_b_reg : std_logic := '0';

    -- Datapath.
    signal acc : signed(ACC_W - 1 downto 0) := (others => '0');
    signal a_word : signed(15 downto 0) := (others => '0');
    signal b_word : signed(15 downto 0) := (others => '0');
    signal input_word : signed(15 downto 0);
    signal product : signed(31 downto 0) := (others => '0');
    signal half : std_logic := '0';
    signal sticky : std_logic := '0';
    signal negative : std_logic := '0';
    signal high_zero : std_logic := '1';
    signal high_ones : std_logic := '1';
    signal fits : std_logic := '0';
    signal estimated_state : std_logic := '0';
    -- No sample since reset: the program clears the state first.
    signal fresh : std_logic := '1';

    -- Outputs: shifted in limb by limb, shown at End.
    signal rate_shadow : std_logic_vector(LIMB * RATE_LIMBS - 1 downto 0) := (others => '0');
    signal bias_a_shadow : std_logic_vector(LIMB * BIAS_LIMBS - 1 downto 0) := (others => '0');
    signal bias_b_shadow : std_logic_vector(LIMB * BIAS_LIMBS - 1 downto 0) := (others => '0');
    signal rate_reg : signed(OUT_W - 1 downto 0) := (others => '0');
    signal bias_a_reg : signed(BIAS_W - 1 downto 0) := (others => '0');
    signal bias_b_reg : signed(BIAS_W - 1 downto 0) := (others => '0');
    signal estimated_reg : std_logic := '0';
    signal valid_reg : std_logic := '0';

    -- Instruction fields.
    signal op : unsigned(3 downto 0);
    signal cond : unsigned(3 downto 0);
    signal ram_index : unsigned(1 downto 0);
    signal by_bw_sel : std_logic;
    signal address_field : unsigned(ADDR_W - 1 downto 0);
    signal coefficient_field : unsigned(COEF_ADDR_W - 1 downto 0);

    signal index_value : unsigned(ADDR_W - 1 downto 0);
    signal ram_address : unsigned(ADDR_W - 1 downto 0);
    signal select_value : unsigned(COEF_ADDR_W - 1 downto 0);
    signal coefficient_address : unsigned(COEF_ADDR_W - 1 downto 0);

    signal holds : std_logic;
    signal increment : std_logic;
    signal low : std_logic_vector(LIMB - 1 downto 0);
    signal shifted : signed(ACC_W - 1 downto 0);
    signal addend : signed(ACC_W - 1 downto 0);
    signal execute : std_logic;
    signal act : std_logic;
    signal a_operand : signed(15 downto 0);
    -- An output register with the RAM word's limb shifted in from the top (its lowest
    -- limb drops out): one limb wider, so that a one-limb output needs no null slice.
    signal rate_next : std_logic_vector(LIMB * (RATE_LIMBS + 1) - 1 downto 0);
    signal bias_a_next : std_logic_vector(LIMB * (BIAS_LIMBS + 1) - 1 downto 0);
    signal bias_b_next : std_logic_vector(LIMB * (BIAS_LIMBS + 1) - 1 downto 0);
    signal write_enable : std_logic;
    signal write_data : std_logic_vector(15 downto 0);

begin

    assert ACC_W >= 17 and ADDR_W > INTERVAL_W and COEF_ADDR_W > SEL_W
        report "gyrofx_serial_engine: ACC_W (" & integer'image(ACC_W) & ") must be at least 17, ADDR_W ("
            & integer'image(ADDR_W) & ") exceed INTERVAL_W (" & integer'image(INTERVAL_W)
            & "), COEF_ADDR_W (" & integer'image(COEF_ADDR_W) & ") exceed SEL_W ("
            & integer'image(SEL_W) & ")"
        severity failure;

    op <= unsigned(instruction(WORD_W - 1 downto WORD_W - 4));
    cond <= unsigned(instruction(WORD_W - 5 downto WORD_W - 8));
    ram_index <= unsigned(instruction(WORD_W - 9 downto WORD_W - 10));
    by_bw_sel <= instruction(WORD_W - 11);
    address_field <= unsigned(instruction(COEF_ADDR_W + ADDR_W - 1 downto COEF_ADDR_W));
    coefficient_field <= unsigned(instruction(COEF_ADDR_W - 1 downto 0));

    -- The run-time indexes; the sums wrap at the address width, as in the Verilog.
    index_value <= resize(interval_a_reg, ADDR_W) when ram_index = 1 else
                   resize(interval_b_reg, ADDR_W) when ram_index = 2 else
                   (others => '0');
    ram_address <= address_field + shift_left(index_value, RAM_INDEX_SHIFT);
    select_value <= resize(bw_sel_reg, COEF_ADDR_W) when by_bw_sel = '1' else (others => '0');
    coefficient_address <= coefficient_field + shift_left(select_value, COEF_INDEX_SHIFT);

    y_a_sample <= y_a_reg when CAPTURE_SAMPLES /= 0 else resize(y_a, LIMB * IN_LIMBS);
    y_b_sample <= y_b_reg when CAPTURE_SAMPLES /= 0 else resize(y_b, LIMB * IN_LIMBS);

    -- Input limbs: y_a's, then y_b's (the top ones sign-extended). A later match wins,
    -- as the Verilog's loop of assignments does.
    input_limbs : process (all)
        variable word : signed(15 downto 0);
        variable limb_a : std_logic_vector(LIMB - 1 downto 0);
        variable limb_b : std_logic_vector(LIMB - 1 downto 0);
        variable top_a : std_logic;
        variable top_b : std_logic;
    begin
        word := (others => '0');
        for j in 0 to IN_LIMBS - 1 loop
            limb_a := std_logic_vector(y_a_sample(LIMB * j + LIMB - 1 downto LIMB * j));
            limb_b := std_logic_vector(y_b_sample(LIMB * j + LIMB - 1 downto LIMB * j));
            top_a := '0';
            top_b := '0';
            if j = IN_LIMBS - 1 then
                top_a := limb_a(LIMB - 1);
                top_b := limb_b(LIMB - 1);
            end if;
            -- The Verilog compares with j[ADDR_W-1:0] and j + IN_LIMBS at ADDR_W bits.
            if address_field = resize(to_unsigned(j, 32), ADDR_W) then
                word := signed(top_a & limb_a);
            end if;
            if address_field = resize(to_unsigned(j + IN_LIMBS, 32), ADDR_W) then
                word := signed(top_b & limb_b);
            end if;
        end loop;
        input_word <= word;
    end process;

    with to_integer(cond) select holds <=
        '1' when 0,
        valid_a when 1,
        valid_b when 2,
        done_a_reg when 3,
        done_b_reg when 4,
        window_reg when 5,
        mode_a_reg when 6,
        not mode_a_reg when 7,
        mode_b_reg when 8,
        not mode_b_reg when 9,
        valid_a and valid_b when 10,
        valid_a and not valid_b when 11,
        not valid_a and valid_b when 12,
        valid_a or valid_b when 13,
        window_reg and estimated_state when 14,
        fresh when others;

    -- The rounding increment from the dropped bits, the sign and the quotient's LSB.
    rounding_increment : process (all)
    begin
        case ROUNDING is
            when 1 => increment <= half or sticky;
            when 2 => increment <= (half or sticky) and negative;
            when 3 => increment <= half;
            when 4 => increment <= half and (sticky or not negative);
            when 5 => increment <= half and (sticky or acc(0));
            when others => increment <= '0';
        end case;
    end process;

    low <= std_logic_vector(acc(LIMB - 1 downto 0));
    shifted <= shift_right(acc, LIMB);
    -- The product's low ACC_W bits (sign-extended first when ACC_W is wider): a slice,
    -- not resize, which would keep the sign bit when narrowing.
    addend <= to_signed(0, ACC_W - 1) & increment when op = OP_ROUND else
              resize(product, PRODUCT_W)(ACC_W - 1 downto 0);
    execute <= '1' when running = '1' and phase = 3 else '0';
    act <= execute and holds;
    a_operand <= input_word when op = OP_MAC_INPUT else a_word;

    rate_next <= std_logic_vector(a_word(LIMB - 1 downto 0)) & rate_shadow;
    bias_a_next <= std_logic_vector(a_word(LIMB - 1 downto 0)) & bias_a_shadow;
    bias_b_next <= std_logic_vector(a_word(LIMB - 1 downto 0)) & bias_b_shadow;

    ram_write : process (all)
    begin
        write_enable <= '0';
        write_data <= '0' & low;
        case op is
            when OP_EMIT =>
                write_enable <= act;
            when OP_EMIT_TOP =>
                write_enable <= act;
                write_data <= low(LIMB - 1) & low;
            when OP_STORE_LOW =>
                write_enable <= act;
                if fits = '0' then
                    if negative = '1' then
                        write_data <= x"0000";
                    else
                        write_data <= x"7fff";
                    end if;
                end if;
            when OP_STORE_TOP =>
                write_enable <= act;
                if fits = '1' then
                    write_data <= low(LIMB - 1) & low;
                elsif negative = '1' then
                    write_data <= not std_logic_vector(b_word);
                else
                    write_data <= std_logic_vector(b_word);
                end if;
            when others =>
                write_enable <= '0';
        end case;
    end process;

    -- Memories: registered reads on every clock (the fields are steady from phase 1 on).
    memories : process (clk)
    begin
        if rising_edge(clk) then
            if to_integer(pc) < PROGRAM_DEPTH then
                instruction <= PROGRAM_ROM(to_integer(pc));
            else
                instruction <= (others => '0');
            end if;
            if to_integer(coefficient_address) < COEF_DEPTH then
                b_word <= signed(COEFFICIENT_ROM(to_integer(coefficient_address)));
            else
                b_word <= (others => '0');
            end if;
            if to_integer(ram_address) < RAM_DEPTH then
                a_word <= signed(ram(to_integer(ram_address)));
                if write_enable = '1' then
                    ram(to_integer(ram_address)) <= write_data;
                end if;
            else
                a_word <= (others => '0');
            end if;
            -- Only the product registered in phase 2 is used (by the instruction executing in
            -- phase 3): a clock enable there keeps a simulator from computing it at the other
            -- three clocks. The Verilog registers it at every clock; the ports are the same.
            if phase = 2 then
                product <= a_operand * b_word;
            end if;
        end if;
    end process;

    -- Later assignments win, as with the Verilog's nonblocking ones: rst over everything,
    -- so a reset stops a run whatever its instruction did (the RAM write of that clock
    -- still happens, in the memories process, as in the Verilog).
    control : process (clk)
    begin
        if rising_edge(clk) then
            valid_reg <= '0';
            if running = '1' then
                phase <= phase + 1;
            end if;
            if running = '0' and ce = '1' then
                running <= '1';
                phase <= (others => '0');
                pc <= (others => '0');
                y_a_reg <= resize(y_a, LIMB * IN_LIMBS);
                y_b_reg <= resize(y_b, LIMB * IN_LIMBS);
                bw_sel_reg <= bw_sel;
                interval_a_reg <= interval_a;
                interval_b_reg <= interval_b;
                valid_a <= not blank_a;
                valid_b <= not blank_b;
                done_a_reg <= done_a;
                done_b_reg <= done_b;
                window_reg <= window_done;
                mode_a_reg <= mode_a;
                mode_b_reg <= mode_b;
            end if;
            if execute = '1' then
                -- End keeps pc on itself: the idle engine fetches no word past the program.
                if op /= OP_END then
                    pc <= pc + 1;
                end if;
                if op = OP_END then
                    running <= '0';
                    fresh <= '0';
                    -- A sample with both gyros blanked keeps the last rate.
                    if (valid_a or valid_b) = '1' then
                        rate_reg <= signed(rate_shadow(OUT_W - 1 downto 0));
                    end if;
                    bias_a_reg <= signed(bias_a_shadow(BIAS_W - 1 downto 0));
                    bias_b_reg <= signed(bias_b_shadow(BIAS_W - 1 downto 0));
                    estimated_reg <= estimated_state;
                    valid_reg <= valid_a or valid_b;
                end if;
            end if;
            if act = '1' then
                case op is
                    when OP_ZERO =>
                        acc <= (others => '0');
                        half <= '0';
                        sticky <= '0';
                        high_zero <= '1';
                        high_ones <= '1';
                    when OP_MAC | OP_MAC_INPUT | OP_ROUND =>
                        acc <= acc + addend;
                    when OP_EMIT | OP_EMIT_TOP | OP_STORE_LOW | OP_STORE_TOP =>
                        acc <= shifted;
                    when OP_DROP =>
                        sticky <= sticky or (or low);
                        acc <= shifted;
                    when OP_DROP_HALF =>
                        half <= low(LIMB - 1);
                        sticky <= sticky or (or low(LIMB - 2 downto 0));
                        acc <= shifted;
                    when OP_SIGN =>
                        negative <= a_word(15);
                    when OP_HIGH =>
                        high_zero <= high_zero and not (or low);
                        high_ones <= high_ones and (and low);
                        acc <= shifted;
                    when OP_FITS =>
                        if (acc = 0 and high_zero = '1') or (acc = -1 and high_ones = '1') then
                            fits <= '1';
                        else
                            fits <= '0';
                        end if;
                    when OP_OUT =>
                        case coefficient_field(1 downto 0) is
                            when "00" =>
                                rate_shadow <= rate_next(rate_next'high downto LIMB);
                            when "01" =>
                                bias_a_shadow <= bias_a_next(bias_a_next'high downto LIMB);
                            when others =>
                                bias_b_shadow <= bias_b_next(bias_b_next'high downto LIMB);
                        end case;
                    when OP_SET_ESTIMATED =>
                        estimated_state <= '1';
                    when others =>
                        null;
                end case;
            end if;
            if rst = '1' then
                running <= '0';
                fresh <= '1';
                rate_shadow <= (others => '0');
                bias_a_shadow <= (others => '0');
                bias_b_shadow <= (others => '0');
                rate_reg <= (others => '0');
                bias_a_reg <= (others => '0');
                bias_b_reg <= (others => '0');
                estimated_state <= '0';
                estimated_reg <= '0';
                valid_reg <= '0';
            end if;
        end if;
    end process;

    rate_out <= rate_reg when HOLD_RESULTS /= 0 else signed(rate_shadow(OUT_W - 1 downto 0));
    out_valid <= valid_reg;
    bias_a <= bias_a_reg when HOLD_RESULTS /= 0 else signed(bias_a_shadow(BIAS_W - 1 downto 0));
    bias_b <= bias_b_reg when HOLD_RESULTS /= 0 else signed(bias_b_shadow(BIAS_W - 1 downto 0));
    estimated <= estimated_reg when HOLD_RESULTS /= 0 else estimated_state;
    busy <= running;

end architecture;
