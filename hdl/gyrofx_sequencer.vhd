-- Language: VHDL-2008

-- gyrofx_sequencer — state-machine sequencer of mode reversal (paper 004, Fig. 5).
--
-- Purpose: the VHDL twin of gyrofx_sequencer.v (same generics, ports and timing).
--   Cuts time into intervals of INTERVAL_LENGTH samples, W = INTERVALS intervals
--   per cycle (the bias estimator's window); gyro A runs in mode PATTERN(i) in
--   interval i, gyro B in the opposite mode, with B's whole schedule STAGGER
--   samples behind A's. Bit-exact with gyrofx_model::sequencer.
--
-- Algorithm: per gyro a phase counter (0..L-1) and an interval counter
--   (0..W-1), advanced on ce. After reset A is at (0, 0); B at position
--   W*L - STAGGER (the tail of a virtual previous cycle). For the current sample:
--     mode    = PATTERN(interval) (A), not PATTERN(interval) (B); '1' = normal
--     blank   = phase < BLANK
--     done    = phase = L - 1
--     window_done = done_b and interval_b = W - 1 and B has started a full cycle
--
-- PATTERN: INTERVALS bits, bit i (counting from the right, as in Verilog's
--   4'b0101) for interval i: pass x"5" or "0101" for A normal in intervals 0 and 2.
--
-- Latency: outputs describe the current sample (combinational from the
--   counters, 0 clocks); the counters advance on ce. rst is synchronous.

library ieee;
use ieee.std_logic_1164.all;
use ieee.numeric_std.all;

entity gyrofx_sequencer is
    generic (
        -- L: samples per measurement interval
        INTERVAL_LENGTH : positive := 150;
        -- W: intervals per cycle
        INTERVALS : positive := 4;
        -- A's mode per interval, rightmost bit = interval 0: '1' normal, '0' reversed
        PATTERN : std_logic_vector := "0101";
        -- M: blanked samples at the start of every interval
        BLANK : natural := 10;
        -- S: samples by which B runs behind A
        STAGGER : natural := 0;
        -- width of the phase counter; width of an interval index, ceil(log2(INTERVALS))
        PHASE_W : positive := 8;
        INTERVAL_W : positive := 2
    );
    port (
        clk         : in  std_logic;
        rst         : in  std_logic;
        ce          : in  std_logic;
        mode_a      : out std_logic;
        mode_b      : out std_logic;
        blank_a     : out std_logic;
        blank_b     : out std_logic;
        interval_a  : out unsigned(INTERVAL_W - 1 downto 0);
        interval_b  : out unsigned(INTERVAL_W - 1 downto 0);
        done_a      : out std_logic;
        done_b      : out std_logic;
        window_done : out std_logic
    );
end entity;

architecture rtl of gyrofx_sequencer is

    -- PATTERN renumbered INTERVALS-1 downto 0, whatever range the actual had; a
    -- PATTERN of another length stops the elaboration with a message (not a bound error).
    function modes_of(bits : std_logic_vector) return std_logic_vector is
        variable result : std_logic_vector(INTERVALS - 1 downto 0) := (others => '0');
    begin
        assert bits'length = INTERVALS
            report "gyrofx_sequencer: PATTERN has " & integer'image(bits'length)
                & " bits; INTERVALS = " & integer'image(INTERVALS)
            severity failure;
        if bits'length = INTERVALS then
            result := bits;
        end if;
        return result;
    end function;

    constant MODES : std_logic_vector(INTERVALS - 1 downto 0) := modes_of(PATTERN);

    function b_start_interval return natural is
    begin
        if STAGGER = 0 then
            return 0;
        end if;
        return INTERVALS - 1;
    end function;

    function b_started_at_reset return std_logic is
    begin
        if STAGGER = 0 then
            return '1';
        end if;
        return '0';
    end function;

    function b_start_phase return natural is
    begin
        if STAGGER = 0 then
            return 0;
        end if;
        return INTERVAL_LENGTH - STAGGER;
    end function;

    constant LAST_PHASE : unsigned(PHASE_W - 1 downto 0) := to_unsigned(INTERVAL_LENGTH - 1, PHASE_W);
    constant LAST_INTERVAL : unsigned(INTERVAL_W - 1 downto 0) := to_unsigned(INTERVALS - 1, INTERVAL_W);
    constant B_PHASE_RESET : unsigned(PHASE_W - 1 downto 0) := to_unsigned(b_start_phase, PHASE_W);
    constant B_INTERVAL_RESET : unsigned(INTERVAL_W - 1 downto 0) := to_unsigned(b_start_interval, INTERVAL_W);
    -- Without a stagger B starts a full cycle at once.
    constant B_STARTED_RESET : std_logic := b_started_at_reset;

    signal phase_a_reg : unsigned(PHASE_W - 1 downto 0) := (others => '0');
    signal interval_a_reg : unsigned(INTERVAL_W - 1 downto 0) := (others => '0');
    signal phase_b_reg : unsigned(PHASE_W - 1 downto 0) := B_PHASE_RESET;
    signal interval_b_reg : unsigned(INTERVAL_W - 1 downto 0) := B_INTERVAL_RESET;
    signal b_started_reg : std_logic := B_STARTED_RESET;

    signal done_a_now : std_logic;
    signal done_b_now : std_logic;

begin

    assert INTERVALS >= 2 and INTERVALS <= 256
        report "gyrofx_sequencer: INTERVALS (" & integer'image(INTERVALS) & ") must be 2..256"
        severity failure;
    assert BLANK < INTERVAL_LENGTH and STAGGER < INTERVAL_LENGTH
        report "gyrofx_sequencer: BLANK (" & integer'image(BLANK) & ") and STAGGER ("
            & integer'image(STAGGER) & ") must be < INTERVAL_LENGTH ("
            & integer'image(INTERVAL_LENGTH) & ")"
        severity failure;
    assert 2 ** PHASE_W >= INTERVAL_LENGTH and 2 ** INTERVAL_W >= INTERVALS
        report "gyrofx_sequencer: PHASE_W (" & integer'image(PHASE_W) & ") or INTERVAL_W ("
            & integer'image(INTERVAL_W) & ") too narrow"
        severity failure;

    done_a_now <= '1' when phase_a_reg = LAST_PHASE else '0';
    done_b_now <= '1' when phase_b_reg = LAST_PHASE else '0';

    interval_a <= interval_a_reg;
    interval_b <= interval_b_reg;
    mode_a <= MODES(to_integer(interval_a_reg));
    mode_b <= not MODES(to_integer(interval_b_reg));
    blank_a <= '1' when phase_a_reg < BLANK else '0';
    blank_b <= '1' when phase_b_reg < BLANK else '0';
    done_a <= done_a_now;
    done_b <= done_b_now;
    window_done <= done_b_now and b_started_reg when interval_b_reg = LAST_INTERVAL else '0';

    counters : process (clk)
    begin
        if rising_edge(clk) then
            if ce = '1' then
                if done_a_now = '1' then
                    phase_a_reg <= (others => '0');
                    if interval_a_reg = LAST_INTERVAL then
                        interval_a_reg <= (others => '0');
                    else
                        interval_a_reg <= interval_a_reg + 1;
                    end if;
                else
                    phase_a_reg <= phase_a_reg + 1;
                end if;
                if done_b_now = '1' then
                    phase_b_reg <= (others => '0');
                    if interval_b_reg = LAST_INTERVAL then
                        interval_b_reg <= (others => '0');
                    else
                        interval_b_reg <= interval_b_reg + 1;
                    end if;
                else
                    phase_b_reg <= phase_b_reg + 1;
                end if;
                if phase_b_reg = 0 and interval_b_reg = 0 then
                    b_started_reg <= '1';
                end if;
            end if;

            if rst = '1' then
                phase_a_reg <= (others => '0');
                interval_a_reg <= (others => '0');
                phase_b_reg <= B_PHASE_RESET;
                interval_b_reg <= B_INTERVAL_RESET;
                b_started_reg <= B_STARTED_RESET;
            end if;
        end if;
    end process;

end architecture;
