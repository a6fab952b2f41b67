-- Language: VHDL-2008

-- gyrofx_top_serial — the mode-reversal chain, time-multiplexed: the sequencer and
--   gyrofx_serial_engine (one shared multiplier) in place of the parallel
--   estimator, calibration and KF of gyrofx_top.
--
-- Purpose: the VHDL twin of gyrofx_top_serial.v (same generics, ports, ROM images
--   and timing). The same chain as gyrofx_top, bit-exact with
--   gyrofx_model::chain::FixedChain, on a small FPGA: the sample rate (hundreds of
--   samples/s) leaves thousands of clocks per sample, so one multiplier does the
--   work of forty.
--
-- Ports: those of gyrofx_top; mode_a/mode_b describe the sample to be taken at the
--   next ce (0 clocks), as there.
--
-- Latency: rate_out/out_valid, bias_a/bias_b/estimated show SETTLE = 4 * (sample
--   program length) clocks after the ce clock (out_valid high for one clock, low
--   when both gyros were blanked). ce at most every SETTLE + 1 clocks: a ce while
--   the engine is busy is ignored by the sequencer too, so that its counters stay
--   with the samples the engine took. gyrofx writes the program for the config and
--   states SETTLE (manifest.json, the block's README).
--   rst (synchronous) clears the outputs and the sequencer at once; the next
--   sample's program clears the engine's state before it reads it.

library ieee;
use ieee.std_logic_1164.all;
use ieee.numeric_std.all;

entity gyrofx_top_serial is
    generic (
        -- sequencer (PATTERN: rightmost bit = interval 0)
        INTERVAL_LENGTH : positive := 150;
        INTERVALS : positive := 4;
        PATTERN : std_logic_vector := "0101";
        BLANK : natural := 10;
        STAGGER : natural := 0;
        PHASE_W : positive := 8;
        INTERVAL_W : positive := 2;
        -- gyro samples, rate output, bias outputs: widths
        IN_W : positive := 24;
        OUT_W : positive := 24;
        BIAS_W : positive := 28;
        SEL_W : positive := 2;
        -- KF gain words: bw_sel must be below ROM_DEPTH
        ROM_DEPTH : positive := 3;
        -- the engine (gyrofx_serial_engine): written by gyrofx for the config
        ACC_W : positive := 32;
        ADDR_W : positive := 6;
        COEF_ADDR_W : positive := 5;
        RAM_DEPTH : positive := 64;
        COEF_DEPTH : positive := 32;
        PROGRAM_DEPTH : positive := 512;
        RAM_INDEX_SHIFT : natural := 1;
        COEF_INDEX_SHIFT : natural := 2;
        -- rounding: 0 floor, 1 ceil, 2 zero, 3 nearest, 4 round, 5 convergent
        ROUNDING : natural := 3;
        PROGRAM_FILE : string := "serial_program.mem";
        COEFFICIENT_FILE : string := "serial_coefficients.mem"
    );
    port (
        clk       : in  std_logic;
        rst       : in  std_logic;
        ce        : in  std_logic;
        bw_sel    : in  unsigned(SEL_W - 1 downto 0);
        y_a       : in  signed(IN_W - 1 downto 0);
        y_b       : in  signed(IN_W - 1 downto 0);
        mode_a    : out std_logic;
        mode_b    : out std_logic;
        rate_out  : out signed(OUT_W - 1 downto 0);
        out_valid : out std_logic;
        bias_a    : out signed(BIAS_W - 1 downto 0);
        bias_b    : out signed(BIAS_W - 1 downto 0);
        estimated : out std_logic
    );
end entity;

architecture rtl of gyrofx_top_serial is

    signal busy : std_logic;
    signal take : std_logic;
    signal mode_a_now : std_logic;
    signal mode_b_now : std_logic;
    signal blank_a : std_logic;
    signal blank_b : std_logic;
    signal interval_a : unsigned(INTERVAL_W - 1 downto 0);
    signal interval_b : unsigned(INTERVAL_W - 1 downto 0);
    signal done_a : std_logic;
    signal done_b : std_logic;
    signal window_done : std_logic;

begin

    assert ROM_DEPTH <= 2 ** SEL_W
        report "gyrofx_top_serial: ROM_DEPTH (" & integer'image(ROM_DEPTH) & ") must be 1..2^SEL_W"
        severity failure;

    -- One ce for both: the sequencer advances only on the samples the engine takes.
    take <= ce and not busy;

    sequencer : entity work.gyrofx_sequencer
        generic map (
            INTERVAL_LENGTH => INTERVAL_LENGTH, INTERVALS => INTERVALS, PATTERN => PATTERN,
            BLANK => BLANK, STAGGER => STAGGER, PHASE_W => PHASE_W, INTERVAL_W => INTERVAL_W
        )
        port map (
            clk => clk, rst => rst, ce => take,
            mode_a => mode_a_now, mode_b => mode_b_now, blank_a => blank_a, blank_b => blank_b,
            interval_a => interval_a, interval_b => interval_b, done_a => done_a, done_b => done_b,
            window_done => window_done
        );

    engine : entity work.gyrofx_serial_engine
        generic map (
            IN_W => IN_W, OUT_W => OUT_W, BIAS_W => BIAS_W, SEL_W => SEL_W, INTERVAL_W => INTERVAL_W,
            ACC_W => ACC_W, ADDR_W => ADDR_W, COEF_ADDR_W => COEF_ADDR_W, RAM_DEPTH => RAM_DEPTH,
            COEF_DEPTH => COEF_DEPTH, PROGRAM_DEPTH => PROGRAM_DEPTH,
            RAM_INDEX_SHIFT => RAM_INDEX_SHIFT, COEF_INDEX_SHIFT => COEF_INDEX_SHIFT,
            ROUNDING => ROUNDING, PROGRAM_FILE => PROGRAM_FILE, COEFFICIENT_FILE => COEFFICIENT_FILE
        )
        port map (
            clk => clk, rst => rst, ce => take, bw_sel => bw_sel, y_a => y_a, y_b => y_b,
            mode_a => mode_a_now, mode_b => mode_b_now, blank_a => blank_a, blank_b => blank_b,
            done_a => done_a, done_b => done_b, window_done => window_done,
            interval_a => interval_a, interval_b => interval_b,
            rate_out => rate_out, out_valid => out_valid, bias_a => bias_a, bias_b => bias_b,
            estimated => estimated, busy => busy
        );

    mode_a <= mode_a_now;
    mode_b <= mode_b_now;

    -- pragma translate_off
    -- Simulation only: a ce while the engine still runs the previous sample's program would
    -- be dropped (take is low); stop the simulation instead, naming this instance
    -- (gyrofx_job::pipeline gives the spacing, the manifest's min_clocks_per_sample).
    spacing_check : process (clk)
    begin
        if rising_edge(clk) then
            assert not (rst = '0' and ce = '1' and busy = '1')
                report spacing_check'path_name & ": a sample while the engine still runs the previous one; "
                    & "gyrofx_top_serial takes one at most every min_clocks_per_sample clocks (manifest.json)"
                severity failure;
        end if;
    end process;
    -- pragma translate_on

end architecture;
