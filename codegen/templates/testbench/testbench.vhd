-- Language: VHDL-2008
@provenance@

-- @tb@ — self-checking testbench of @module@ (@title@).
--
-- Reads STIMULUS_FILE and EXPECTED_FILE (one line per clock-enable, hex fields,
-- formats declared on line 2 and checked here), drives one sample per ce with an
-- idle clock after every fourth, and compares combinational outputs before the
-- clock edge and registered outputs 1 clock after it. Prints the first
-- MAX_REPORTED mismatches, then PASS n=<N> [masked=<M>] or
-- FAIL mismatches=<M> n=<N> first=<index>, and stops with exit status 1
-- (std.env.stop(1)) on a mismatch, a timeout or a bad vector file.
-- Generics (GHDL: -g<NAME>=<value>): MASK_SAMPLES does not compare the first n
-- samples of the run and from every reset sample on (latency mask); MAX_REPORTED
-- mismatches printed; MAX_MISMATCHES > 0 stops at that many. Waveforms: GHDL's
-- --vcd=<file> or --wave=<file>.

library ieee;
use ieee.std_logic_1164.all;
use ieee.numeric_std.all;
use std.textio.all;

use work.gyrofx_testbench_pkg.all;

entity @tb@ is
    generic (
        STIMULUS_FILE : string := "@stimulus@";
        EXPECTED_FILE : string := "@expected@";
        MASK_SAMPLES : natural := 0;
        MAX_REPORTED : natural := @max@;
        MAX_MISMATCHES : natural := 0
    );
end entity;

architecture sim of @tb@ is

@constants@    constant VECTOR_COUNT : natural := @count@;
    constant CLOCK_PERIOD : time := 10 ns;
    constant TIMEOUT : time := @timeout@ * CLOCK_PERIOD;

    signal clk : std_logic := '0';
    signal rst : std_logic := '1';
    signal ce : std_logic := '0';
@signals@    signal samples_done : natural := 0;

begin

    clk <= not clk after CLOCK_PERIOD / 2;

    dut : entity work.@module@
        generic map (
@generics@
        )
        port map (
@ports@
        );

    timeout_watch : process
    begin
        wait for TIMEOUT;
        fail("timeout after " & time'image(TIMEOUT) & " (" & integer'image(samples_done)
            & " of " & integer'image(VECTOR_COUNT) & " samples)");
        wait;
    end process;

    main : process
        file stimulus_vectors : text;
        file expected_vectors : text;
        variable text_line : line;
        variable ok : boolean;
        variable index : natural := 0;
        variable mismatches : natural := 0;
        variable first_mismatch : integer := -1;
        variable since_reset : natural := 0;
        variable masked_count : natural := 0;
        variable masked : boolean := false;
        variable stop_at_cap : boolean := false;
        variable vector_rst : std_logic_vector(0 downto 0);
@variables@
        -- Counts and prints a mismatch of `name` at the current sample.
        procedure check(name : string; expected, actual : std_logic_vector;
                        fraction : natural; is_signed : boolean) is
        begin
            if actual = expected then
                return;
            end if;
            mismatches := mismatches + 1;
            if first_mismatch < 0 then
                first_mismatch := index;
            end if;
            if MAX_MISMATCHES > 0 and mismatches >= MAX_MISMATCHES then
                stop_at_cap := true;
            end if;
            if mismatches <= MAX_REPORTED then
                say("MISMATCH sample " & integer'image(index) & " signal " & name
                    & " expected " & hex_of(expected) & " (" & real_of(expected, fraction, is_signed)
                    & ") actual " & hex_of(actual) & " (" & real_of(actual, fraction, is_signed) & ")");
            end if;
        end procedure;

    begin
        open_vectors(stimulus_vectors, STIMULUS_FILE, "@stimulus_header@");
        open_vectors(expected_vectors, EXPECTED_FILE, "@expected_header@");
        if MASK_SAMPLES > 0 then
            say("mask: " & integer'image(MASK_SAMPLES) & " samples after each reset");
        end if;

        -- Power-on reset.
        rst <= '1';
        wait until rising_edge(clk);
        wait until rising_edge(clk);
        wait until falling_edge(clk);
        rst <= '0';

        while index < VECTOR_COUNT loop
            ok := not endfile(stimulus_vectors);
            if ok then
                readline(stimulus_vectors, text_line);
                read_field(text_line, vector_rst, ok);
@read_inputs@            end if;
            if not ok then
                fail(STIMULUS_FILE & ": line for sample " & integer'image(index) & " is missing or malformed");
            end if;
            ok := not endfile(expected_vectors);
            if ok then
                readline(expected_vectors, text_line);
@read_outputs@            end if;
            if not ok then
                fail(EXPECTED_FILE & ": line for sample " & integer'image(index) & " is missing or malformed");
            end if;
            if vector_rst(0) = '1' then
                since_reset := 0;
            end if;
            masked := since_reset < MASK_SAMPLES;
            if masked then
                masked_count := masked_count + 1;
            end if;
            since_reset := since_reset + 1;
            rst <= vector_rst(0);
            ce <= '1';
@sample_checks@            if stop_at_cap then
                fail("mismatches=" & integer'image(mismatches) & " n=" & integer'image(index + 1)
                    & " first=" & integer'image(first_mismatch) & " (stopped at MAX_MISMATCHES)");
            end if;
            index := index + 1;
            samples_done <= index;
        end loop;

        if mismatches = 0 then
            if masked_count > 0 then
                say("PASS n=" & integer'image(VECTOR_COUNT) & " masked=" & integer'image(masked_count));
            else
                say("PASS n=" & integer'image(VECTOR_COUNT));
            end if;
            std.env.finish;
        else
            fail("mismatches=" & integer'image(mismatches) & " n=" & integer'image(VECTOR_COUNT)
                & " first=" & integer'image(first_mismatch));
        end if;
        wait;
    end process;

end architecture;
