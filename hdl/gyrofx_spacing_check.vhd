-- Language: VHDL-2008

-- gyrofx_spacing_check — simulation only: stops the simulation when a sample (a clock with ce
-- high) comes sooner than MIN_CLOCKS_PER_SAMPLE clocks after the previous one. The VHDL twin of
-- gyrofx_spacing_check.v: each pipelined block instantiates it between
-- "-- pragma translate_off" and "-- pragma translate_on", so synthesis never sees it.
--
-- Behaviour: counts the clocks since the last ce (rst clears the count's history); on a ce
-- sooner than the minimum, an assertion of severity failure naming the instance: "<path>: a
-- sample <n> clocks after the previous one; <BLOCK_NAME> takes one at most every <m> clocks".

library ieee;
use ieee.std_logic_1164.all;

entity gyrofx_spacing_check is
    generic (
        -- the fewest clocks from one sample's ce to the next one's
        MIN_CLOCKS_PER_SAMPLE : positive := 2;
        -- the checked block's entity name, for the message
        BLOCK_NAME : string := "block"
    );
    port (
        clk : in std_logic;
        rst : in std_logic;
        ce : in std_logic
    );
end entity;

architecture simulation of gyrofx_spacing_check is
begin
    check : process (clk)
        variable clocks_since_sample : natural := MIN_CLOCKS_PER_SAMPLE;
    begin
        if rising_edge(clk) then
            if rst = '1' then
                clocks_since_sample := MIN_CLOCKS_PER_SAMPLE;
            elsif ce = '1' then
                assert clocks_since_sample >= MIN_CLOCKS_PER_SAMPLE
                    report check'path_name & ": a sample " & integer'image(clocks_since_sample)
                        & " clocks after the previous one; " & BLOCK_NAME & " takes one at most every "
                        & integer'image(MIN_CLOCKS_PER_SAMPLE) & " clocks"
                    severity failure;
                clocks_since_sample := 1;
            elsif clocks_since_sample < MIN_CLOCKS_PER_SAMPLE then
                clocks_since_sample := clocks_since_sample + 1;
            end if;
        end if;
    end process;
end architecture;
