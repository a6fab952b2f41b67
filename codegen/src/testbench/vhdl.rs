//! The VHDL-2008 testbench (run by GHDL `--std=08`); the behaviour and the options are those of
//! [`crate::testbench`]. It reads the vector files with textio through `gyrofx_testbench_pkg`
//! (shipped with the RTL), instantiates the VHDL twin of the block's module with the same
//! parameters, and ends with `std.env.finish` on a pass and `std.env.stop(1)` otherwise.

use std::fmt::Write as _;

use super::{header, timeout_clocks, MAX_REPORTED};
use crate::block::{Block, Output, Signal, Timing};
use crate::text::Provenance;

/// The port type of `s` in the VHDL RTL: signed data, `std_logic` flags, unsigned indices.
fn port_type(s: &Signal) -> String {
    let top = s.format.width - 1;
    if s.format.signed {
        format!("signed({top} downto 0)")
    } else if s.flag {
        "std_logic".into()
    } else {
        format!("unsigned({top} downto 0)")
    }
}

/// `vector` (a `std_logic_vector` variable) converted to the port type of `s`.
fn from_bits(s: &Signal, vector: &str) -> String {
    if s.format.signed {
        format!("signed({vector})")
    } else if s.flag {
        format!("{vector}(0)")
    } else {
        format!("unsigned({vector})")
    }
}

/// The port `s` as a `std_logic_vector` for an exact comparison.
fn to_bits(s: &Signal) -> String {
    if s.flag {
        format!("bits({})", s.name)
    } else {
        format!("std_logic_vector({})", s.name)
    }
}

fn vector_variable(s: &Signal, prefix: &str) -> String {
    format!(
        "    variable {prefix}{} : std_logic_vector({} downto 0);",
        s.name,
        s.format.width - 1
    )
}

/// `check(...)` of output `o` at `indent`.
fn check(o: &Output, indent: &str) -> String {
    let s = &o.signal;
    format!(
        "{indent}check(\"{name}\", expected_{name}, {actual}, {frac}, {signed});",
        name = s.name,
        actual = to_bits(s),
        frac = s.format.frac,
        signed = s.format.signed,
    )
}

/// The VHDL testbench of `block`.
pub fn testbench(block: &Block, provenance: &Provenance) -> String {
    let tb = format!("tb_{}", block.module);
    let mut out = String::new();
    let _ = writeln!(out, "-- Language: VHDL-2008");
    let _ = writeln!(out, "{}", provenance.line("--"));
    let _ = writeln!(
        out,
        "
-- {tb} — self-checking testbench of {module} ({title}).
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

entity {tb} is
    generic (
        STIMULUS_FILE : string := \"{stimulus}\";
        EXPECTED_FILE : string := \"{expected}\";
        MASK_SAMPLES : natural := 0;
        MAX_REPORTED : natural := {max};
        MAX_MISMATCHES : natural := 0
    );
end entity;

architecture sim of {tb} is
",
        module = block.module,
        title = block.title,
        stimulus = block.file("stimulus.hex"),
        expected = block.file("expected.hex"),
        max = MAX_REPORTED,
    );
    for p in &block.params {
        let _ = writeln!(
            out,
            "    constant P_{} : {} := {}; -- {}",
            p.name, p.vhdl_type, p.vhdl_value, p.comment
        );
    }
    let _ = writeln!(
        out,
        "    constant VECTOR_COUNT : natural := {count};
    constant CLOCK_PERIOD : time := 10 ns;
    constant TIMEOUT : time := {timeout} * CLOCK_PERIOD;

    signal clk : std_logic := '0';
    signal rst : std_logic := '1';
    signal ce : std_logic := '0';",
        count = block.len(),
        timeout = timeout_clocks(block.len(), block.settle_clocks),
    );
    for s in &block.inputs {
        let zero = if s.flag { "'0'" } else { "(others => '0')" };
        let _ = writeln!(out, "    signal {} : {} := {zero};", s.name, port_type(s));
    }
    for o in &block.outputs {
        let _ = writeln!(
            out,
            "    signal {} : {};",
            o.signal.name,
            port_type(&o.signal)
        );
    }
    // Set by the main process, read by the timeout process.
    let _ = writeln!(
        out,
        "    signal samples_done : natural := 0;

begin

    clk <= not clk after CLOCK_PERIOD / 2;

    dut : entity work.{module}
        generic map (",
        module = block.module
    );
    let generics: Vec<String> = block
        .params
        .iter()
        .map(|p| format!("            {0} => P_{0}", p.name))
        .collect();
    let _ = writeln!(
        out,
        "{}\n        )\n        port map (",
        generics.join(",\n")
    );
    let mut ports = vec![
        "            clk => clk".to_string(),
        "            rst => rst".into(),
        "            ce => ce".into(),
    ];
    ports.extend(
        block
            .inputs
            .iter()
            .chain(block.outputs.iter().map(|o| &o.signal))
            .map(|s| format!("            {0} => {0}", s.name)),
    );
    let _ = writeln!(out, "{}\n        );", ports.join(",\n"));

    let _ = writeln!(
        out,
        "
    timeout_watch : process
    begin
        wait for TIMEOUT;
        fail(\"timeout after \" & time'image(TIMEOUT) & \" (\" & integer'image(samples_done)
            & \" of \" & integer'image(VECTOR_COUNT) & \" samples)\");
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
        variable vector_rst : std_logic_vector(0 downto 0);"
    );
    for s in &block.inputs {
        let _ = writeln!(out, "    {}", vector_variable(s, "vector_"));
    }
    for o in &block.outputs {
        let _ = writeln!(out, "    {}", vector_variable(&o.signal, "expected_"));
    }
    let _ = writeln!(
        out,
        "
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
                say(\"MISMATCH sample \" & integer'image(index) & \" signal \" & name
                    & \" expected \" & hex_of(expected) & \" (\" & real_of(expected, fraction, is_signed)
                    & \") actual \" & hex_of(actual) & \" (\" & real_of(actual, fraction, is_signed) & \")\");
            end if;
        end procedure;

    begin
        open_vectors(stimulus_vectors, STIMULUS_FILE, \"{stimulus_header}\");
        open_vectors(expected_vectors, EXPECTED_FILE, \"{expected_header}\");
        if MASK_SAMPLES > 0 then
            say(\"mask: \" & integer'image(MASK_SAMPLES) & \" samples after each reset\");
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
                read_field(text_line, vector_rst, ok);",
        stimulus_header = header(&block.inputs.iter().collect::<Vec<_>>(), true)
            .trim_start_matches("// "),
        expected_header = header(
            &block.outputs.iter().map(|o| &o.signal).collect::<Vec<_>>(),
            false
        )
        .trim_start_matches("// "),
    );
    for s in &block.inputs {
        let _ = writeln!(
            out,
            "                read_field(text_line, vector_{}, ok);",
            s.name
        );
    }
    let _ = writeln!(
        out,
        "            end if;
            if not ok then
                fail(STIMULUS_FILE & \": line for sample \" & integer'image(index) & \" is missing or malformed\");
            end if;
            ok := not endfile(expected_vectors);
            if ok then
                readline(expected_vectors, text_line);"
    );
    for o in &block.outputs {
        let _ = writeln!(
            out,
            "                read_field(text_line, expected_{}, ok);",
            o.signal.name
        );
    }
    let _ = writeln!(
        out,
        "            end if;
            if not ok then
                fail(EXPECTED_FILE & \": line for sample \" & integer'image(index) & \" is missing or malformed\");
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
            ce <= '1';"
    );
    for s in &block.inputs {
        let _ = writeln!(
            out,
            "            {} <= {};",
            s.name,
            from_bits(s, &format!("vector_{}", s.name))
        );
    }
    let combinational: Vec<&Output> = block
        .outputs
        .iter()
        .filter(|o| o.timing == Timing::Combinational)
        .collect();
    if !combinational.is_empty() {
        let _ = writeln!(
            out,
            "            wait for 1 ns;\n            if vector_rst(0) = '0' and not masked then"
        );
        for o in &combinational {
            let _ = writeln!(out, "{}", check(o, "                "));
        }
        let _ = writeln!(out, "            end if;");
    }
    let _ = writeln!(
        out,
        "            wait until falling_edge(clk);
            rst <= '0';
            ce <= '0';"
    );
    if block.settle_clocks > 0 {
        let _ = writeln!(
            out,
            "            -- The pipeline's latency: registered outputs settle these clocks later.
            for settle in 1 to {} loop
                wait until falling_edge(clk);
            end loop;",
            block.settle_clocks
        );
    }
    let _ = writeln!(out, "            if not masked then");
    for o in block
        .outputs
        .iter()
        .filter(|o| o.timing == Timing::Registered)
    {
        match o.gate {
            Some(gate) => {
                let _ = writeln!(
                    out,
                    "                if expected_{gate} = \"1\" then\n{}\n                end if;",
                    check(o, "                    ")
                );
            }
            None => {
                let _ = writeln!(out, "{}", check(o, "                "));
            }
        }
    }
    // Idle clock: pulses low, other ungated registered outputs held.
    let _ = writeln!(
        out,
        "            end if;
            if index mod 4 = 3 then
                wait until falling_edge(clk);"
    );
    let held: Vec<&Output> = block
        .outputs
        .iter()
        .filter(|o| o.timing == Timing::Registered && o.gate.is_none())
        .collect();
    for o in &held {
        if o.pulse {
            let _ = writeln!(
                out,
                "                expected_{} := (others => '0');",
                o.signal.name
            );
        }
    }
    if !held.is_empty() {
        let _ = writeln!(out, "                if not masked then");
        for o in &held {
            let _ = writeln!(out, "{}", check(o, "                    "));
        }
        let _ = writeln!(out, "                end if;");
    }
    let _ = writeln!(
        out,
        "            end if;
            if stop_at_cap then
                fail(\"mismatches=\" & integer'image(mismatches) & \" n=\" & integer'image(index + 1)
                    & \" first=\" & integer'image(first_mismatch) & \" (stopped at MAX_MISMATCHES)\");
            end if;
            index := index + 1;
            samples_done <= index;
        end loop;

        if mismatches = 0 then
            if masked_count > 0 then
                say(\"PASS n=\" & integer'image(VECTOR_COUNT) & \" masked=\" & integer'image(masked_count));
            else
                say(\"PASS n=\" & integer'image(VECTOR_COUNT));
            end if;
            std.env.finish;
        else
            fail(\"mismatches=\" & integer'image(mismatches) & \" n=\" & integer'image(VECTOR_COUNT)
                & \" first=\" & integer'image(first_mismatch));
        end if;
        wait;
    end process;

end architecture;"
    );
    out
}
