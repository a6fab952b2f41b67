-- Language: VHDL-2008

-- gyrofx_mem_pkg — hex words and $readmemh-style memory images, read at elaboration.
--
-- Purpose: the VHDL RTL loads the same ROM images (.mem) as the Verilog RTL, so one
--   file serves both languages. read_mem runs at elaboration (a constant's initial
--   value), which simulators and synthesis tools (Vivado, Quartus) accept for ROMs.
--
-- Format read: one word per line as zero-padded hex (two's complement for signed
--   fields, no 0x, no underscores); lines starting with "//" and empty lines are
--   skipped; "@" address lines are not supported (gyrofx never writes them). A word
--   whose value does not fit `width` bits, a bad digit or a short file stops the
--   elaboration with a failure naming the file and the line.

library ieee;
use ieee.std_logic_1164.all;
use ieee.numeric_std.all;
use std.textio.all;

package gyrofx_mem_pkg is

    -- Words of any one width (VHDL-2008 unconstrained element).
    type word_array is array (natural range <>) of std_logic_vector;

    -- Parses `text` (hex digits only) into `word` (width word'length, value
    -- zero-extended). ok is false on an empty text, a bad digit or a value that
    -- does not fit.
    procedure parse_hex(text : in string; word : out std_logic_vector; ok : out boolean);

    -- The first `depth` words of `width` bits of the memory image `file_name`.
    impure function read_mem(file_name : string; depth : positive; width : positive)
        return word_array;

end package;

package body gyrofx_mem_pkg is

    procedure parse_hex(text : in string; word : out std_logic_vector; ok : out boolean) is
        constant WIDTH : natural := word'length;
        -- Room for every digit, so that bits above WIDTH can be checked.
        variable value : std_logic_vector(4 * text'length + WIDTH - 1 downto 0) := (others => '0');
        variable digit : natural;
        variable good : boolean := text'length > 0;
    begin
        for i in text'range loop
            case text(i) is
                when '0' to '9' => digit := character'pos(text(i)) - character'pos('0');
                when 'a' to 'f' => digit := character'pos(text(i)) - character'pos('a') + 10;
                when 'A' to 'F' => digit := character'pos(text(i)) - character'pos('A') + 10;
                when others => digit := 0; good := false;
            end case;
            value := value(value'high - 4 downto 0) & std_logic_vector(to_unsigned(digit, 4));
        end loop;
        if value(value'high downto WIDTH) /= (value'high downto WIDTH => '0') then
            good := false;
        end if;
        word := value(WIDTH - 1 downto 0);
        ok := good;
    end procedure;

    impure function read_mem(file_name : string; depth : positive; width : positive)
        return word_array is
        file image : text;
        variable status : file_open_status;
        variable text_line : line;
        variable line_number : natural := 0;
        variable count : natural := 0;
        variable word : std_logic_vector(width - 1 downto 0);
        variable ok : boolean;
        variable words : word_array(0 to depth - 1)(width - 1 downto 0) := (others => (others => '0'));
    begin
        file_open(status, image, file_name, read_mode);
        assert status = open_ok
            report "gyrofx_mem_pkg: cannot open " & file_name & " (memory image)"
            severity failure;
        while count < depth and not endfile(image) loop
            readline(image, text_line);
            line_number := line_number + 1;
            -- Drop a trailing carriage return (files edited on Windows).
            if text_line'length > 0 and text_line(text_line'right) = CR then
                text_line := new string'(text_line(text_line'left to text_line'right - 1));
            end if;
            if text_line'length = 0 then
                next;
            end if;
            if text_line'length >= 2 and text_line(text_line'left to text_line'left + 1) = "//" then
                next;
            end if;
            parse_hex(text_line.all, word, ok);
            assert ok
                report "gyrofx_mem_pkg: " & file_name & " line " & integer'image(line_number)
                    & ": '" & text_line.all & "' is not a hex word of " & integer'image(width) & " bits"
                severity failure;
            words(count) := word;
            count := count + 1;
        end loop;
        file_close(image);
        assert count = depth
            report "gyrofx_mem_pkg: " & file_name & " holds " & integer'image(count)
                & " words; " & integer'image(depth) & " are needed"
            severity failure;
        return words;
    end function;

end package body;
