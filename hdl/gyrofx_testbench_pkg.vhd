-- Language: VHDL-2008

-- gyrofx_testbench_pkg — what the generated VHDL testbenches share (simulation only).
--
-- Purpose: reading gyrofx vector files with textio and printing mismatches in the
--   same words as the Verilog testbenches (lowercase hex, real values), so that a
--   log reads the same whatever the simulator. Not for synthesis.
--
-- Vector files: line 1 a generated-by comment, line 2 "// " and the fields with
--   their formats (compared verbatim with what the testbench expects), then one
--   line per clock-enable with one zero-padded hex field per signal.

library ieee;
use ieee.std_logic_1164.all;
use std.textio.all;

use work.gyrofx_mem_pkg.all;

package gyrofx_testbench_pkg is

    -- Prints `text` as one line on standard output.
    procedure say(text : string);

    -- Prints "FAIL <text>" and stops the simulation with exit status 1.
    procedure fail(text : string);

    -- A port value as bits, for exact comparison (like Verilog's !==).
    function bits(value : std_logic) return std_logic_vector;
    function bits(value : std_logic_vector) return std_logic_vector;

    -- Lowercase hex of `value`, ceil(length / 4) digits; x for a digit with a metavalue.
    function hex_of(value : std_logic_vector) return string;

    -- The real value of `value` read as a signed code with `fraction` fraction bits
    -- (signed = false: unsigned, no fraction), as a string; "x" when not 0/1.
    function real_of(value : std_logic_vector; fraction : natural; is_signed : boolean)
        return string;

    -- Opens `name` as `vectors` and checks its field line (line 2) is "// " & `fields`.
    procedure open_vectors(file vectors : text; name : string; fields : string);

    -- Reads the next hex field of `text_line` into `word` (ceil(length / 4) digits,
    -- after any spaces); ok becomes false (and stays so) on a missing or bad field.
    procedure read_field(text_line : inout line; word : out std_logic_vector; ok : inout boolean);

end package;

package body gyrofx_testbench_pkg is

    procedure say(text : string) is
        variable text_line : line;
    begin
        write(text_line, text);
        writeline(output, text_line);
    end procedure;

    procedure fail(text : string) is
    begin
        say("FAIL " & text);
        std.env.stop(1);
        -- Simulators that let a process run on after stop end here.
        report "FAIL " & text severity failure;
    end procedure;

    function bits(value : std_logic) return std_logic_vector is
        variable result : std_logic_vector(0 downto 0);
    begin
        result(0) := value;
        return result;
    end function;

    function bits(value : std_logic_vector) return std_logic_vector is
    begin
        return value;
    end function;

    function hex_of(value : std_logic_vector) return string is
        constant DIGITS : string(1 to 16) := "0123456789abcdef";
        constant COUNT : positive := (value'length + 3) / 4;
        variable padded : std_logic_vector(4 * COUNT - 1 downto 0) := (others => '0');
        variable nibble : std_logic_vector(3 downto 0);
        variable result : string(1 to COUNT);
        variable digit : natural;
    begin
        padded(value'length - 1 downto 0) := value;
        for i in 0 to COUNT - 1 loop
            nibble := padded(4 * (COUNT - i) - 1 downto 4 * (COUNT - i - 1));
            if is_x(nibble) then
                result(i + 1) := 'x';
            else
                digit := 0;
                for b in 3 downto 0 loop
                    digit := 2 * digit + std_logic'pos(to_x01(nibble(b))) - std_logic'pos('0');
                end loop;
                result(i + 1) := DIGITS(digit + 1);
            end if;
        end loop;
        return result;
    end function;

    function real_of(value : std_logic_vector; fraction : natural; is_signed : boolean)
        return string is
        constant NORMAL : std_logic_vector(value'length - 1 downto 0) := value;
        variable result : real := 0.0;
    begin
        if is_x(NORMAL) then
            return "x";
        end if;
        for i in NORMAL'range loop
            result := 2.0 * result;
            if NORMAL(i) = '1' then
                if is_signed and i = NORMAL'high then
                    result := result - 1.0;
                else
                    result := result + 1.0;
                end if;
            end if;
        end loop;
        return real'image(result / 2.0 ** fraction);
    end function;

    procedure open_vectors(file vectors : text; name : string; fields : string) is
        variable status : file_open_status;
        variable text_line : line;
    begin
        file_open(status, vectors, name, read_mode);
        if status /= open_ok then
            fail("cannot open " & name);
        end if;
        for line_number in 1 to 2 loop
            if endfile(vectors) then
                fail(name & " ends before its field line");
            end if;
            readline(vectors, text_line);
        end loop;
        if text_line.all /= "// " & fields then
            if text_line'length > 3 and text_line(1 to 3) = "// " then
                fail(name & " declares " & text_line(4 to text_line'length)
                    & "; the testbench expects " & fields);
            end if;
            fail(name & " declares " & text_line.all & "; the testbench expects " & fields);
        end if;
    end procedure;

    procedure read_field(text_line : inout line; word : out std_logic_vector; ok : inout boolean) is
        variable digits : string(1 to (word'length + 3) / 4);
        variable space : character;
        variable good : boolean;
    begin
        while text_line /= null and text_line'length > 0 and text_line(text_line'left) = ' ' loop
            read(text_line, space);
        end loop;
        if text_line = null or text_line'length < digits'length then
            ok := false;
            return;
        end if;
        read(text_line, digits);
        parse_hex(digits, word, good);
        ok := ok and good;
    end procedure;

end package body;
