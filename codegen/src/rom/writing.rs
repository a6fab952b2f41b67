//! Rendering a [`Rom`] in each [`RomFormat`]: the plain data formats inline, the Verilog
//! (include and SystemVerilog package) and VHDL packages in a function each.

use std::fmt::Write as _;

use super::{Rom, RomFormat};
use crate::text::Provenance;

/// `rom` rendered in `format`, headed by the provenance line, the format's name and the ROM's
/// shape.
pub fn write(rom: &Rom, format: RomFormat, provenance: &Provenance) -> String {
    let c = format.comment();
    let mut out = provenance.line(c);
    let _ = writeln!(out, "\n{c} {}: {}", format.title(), rom.summary());
    if format != RomFormat::Mem {
        for (i, field) in rom.fields.iter().enumerate() {
            let low: u32 = rom.fields[i + 1..].iter().map(|f| f.format.width).sum();
            let _ = writeln!(
                out,
                "{c} field {} {}: bits {}..{}",
                field.name,
                field.format,
                low + field.format.width - 1,
                low
            );
        }
    }
    let words = rom.words();
    match format {
        RomFormat::Mem => {
            for (address, word) in words.iter().enumerate() {
                let _ = writeln!(
                    out,
                    "// @{address} {}\n{}",
                    rom.notes[address],
                    rom.hex(*word)
                );
            }
        }
        RomFormat::Coe => {
            out.push_str("memory_initialization_radix=16;\nmemory_initialization_vector=\n");
            for (address, word) in words.iter().enumerate() {
                let end = if address + 1 == words.len() { ';' } else { ',' };
                let _ = writeln!(out, "{}{end}", rom.hex(*word));
            }
        }
        RomFormat::Mif => {
            let _ = writeln!(
                out,
                "WIDTH={};\nDEPTH={};\nADDRESS_RADIX=UNS;\nDATA_RADIX=HEX;\nCONTENT BEGIN",
                rom.width(),
                rom.depth()
            );
            for (address, word) in words.iter().enumerate() {
                let _ = writeln!(
                    out,
                    "    {address} : {}; -- {}",
                    rom.hex(*word),
                    rom.notes[address]
                );
            }
            out.push_str("END;\n");
        }
        RomFormat::VerilogInclude | RomFormat::SystemVerilogPackage => write_verilog(
            &mut out,
            rom,
            &words,
            format == RomFormat::SystemVerilogPackage,
        ),
        RomFormat::VhdlPackage => write_vhdl(&mut out, rom, &words),
    }
    out
}

fn write_verilog(out: &mut String, rom: &Rom, words: &[u128], package: bool) {
    let (prefix, int, indent) = if package {
        let _ = writeln!(out, "package gyrofx_{}_pkg;", rom.name);
        (String::new(), "int", "    ")
    } else {
        (format!("{}_", rom.name.to_uppercase()), "integer", "")
    };
    let _ = writeln!(
        out,
        "{indent}localparam {int} {prefix}DEPTH = {};\n{indent}localparam {int} {prefix}WIDTH = {};",
        rom.depth(),
        rom.width()
    );
    for field in &rom.fields {
        let name = field.name.to_uppercase();
        let _ = writeln!(
            out,
            "{indent}localparam {int} {prefix}{name}_WIDTH = {};\n\
             {indent}localparam {int} {prefix}{name}_FRACTION = {};\n\
             {indent}localparam {int} {prefix}{name}_SIGNED = {};",
            field.format.width,
            field.format.frac,
            u8::from(field.format.signed)
        );
    }
    let width = rom.width();
    // A flat vector rather than a packed 2-D array: Icarus cannot hold a 2-D localparam.
    let logic = if package { "logic " } else { "" };
    let _ = writeln!(
        out,
        "{indent}localparam {logic}[{prefix}DEPTH*{prefix}WIDTH-1:0] {prefix}ROM = {{"
    );
    // Concatenation runs MSB first, so the highest address comes first and address 0 lands
    // in the least significant word: word a is ROM[a*WIDTH +: WIDTH].
    for address in (0..words.len()).rev() {
        let end = if address == 0 { "" } else { "," };
        let _ = writeln!(
            out,
            "{indent}    {width}'h{}{end} // @{address} {}",
            rom.hex(words[address]),
            rom.notes[address]
        );
    }
    let _ = writeln!(out, "{indent}}};");
    if package {
        let _ = writeln!(
            out,
            "    // The word at `address`.\n    \
             function automatic logic [WIDTH-1:0] word(input int address);\n        \
             return ROM[address*WIDTH +: WIDTH];\n    \
             endfunction\n\
             endpackage"
        );
    }
}

fn write_vhdl(out: &mut String, rom: &Rom, words: &[u128]) {
    let _ = writeln!(
        out,
        "library ieee;\nuse ieee.std_logic_1164.all;\n\npackage gyrofx_{}_pkg is",
        rom.name
    );
    let _ = writeln!(
        out,
        "    constant DEPTH : natural := {};\n    constant WIDTH : natural := {};",
        rom.depth(),
        rom.width()
    );
    for field in &rom.fields {
        let name = field.name.to_uppercase();
        let _ = writeln!(
            out,
            "    constant {name}_WIDTH : natural := {};\n    \
             constant {name}_FRACTION : integer := {};\n    \
             constant {name}_SIGNED : boolean := {};",
            field.format.width, field.format.frac, field.format.signed
        );
    }
    let _ = writeln!(
        out,
        "    type rom_type is array (0 to DEPTH - 1) of std_logic_vector(WIDTH - 1 downto 0);\n    \
         constant ROM : rom_type := ("
    );
    let width = rom.width();
    for (address, word) in words.iter().enumerate() {
        let end = if address + 1 == words.len() { "" } else { "," };
        let _ = writeln!(
            out,
            "        {address} => {width}x\"{}\"{end} -- {}",
            rom.hex(*word),
            rom.notes[address]
        );
    }
    let _ = writeln!(out, "    );\nend package;");
}
