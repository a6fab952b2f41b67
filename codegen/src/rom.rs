//! Coefficient ROMs in every format HDL flows read, all written from one list of codes.
//!
//! A [`Rom`] is a list of words, each the concatenation of one or more fixed-point fields
//! (MSB first); [`write`] renders it as a `$readmemh` file, a Xilinx `.coe`, an Intel `.mif`,
//! a Verilog include, a SystemVerilog package or a VHDL-2008 package, and [`parse`] reads any
//! of them back, so every format is checked against the same codes.

use std::fmt::Write as _;

use gyrofx_model::estimator;
use gyrofx_model::fx::Format;
use gyrofx_model::kf::{Plan, COEFFICIENT_NAMES};
use gyrofx_model::mean_filter;

use crate::writers::Provenance;

/// Folder of the package holding every ROM in every format.
pub const ROM_FOLDER: &str = "roms";

/// One field of a ROM word.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Field {
    /// Identifier of the field (`g1`).
    pub name: String,
    /// Its fixed-point format.
    pub format: Format,
}

/// A coefficient ROM: `codes[address][field]`, fields packed MSB first into one word.
#[derive(Clone, Debug, PartialEq)]
pub struct Rom {
    /// Identifier: file stem and package name (`kf_coefficients`).
    pub name: String,
    /// One line saying what the ROM holds and how it is addressed.
    pub description: String,
    /// The fields of a word, most significant first.
    pub fields: Vec<Field>,
    /// The codes, one array of fields per address.
    pub codes: Vec<Vec<i128>>,
    /// A comment per address (its label and real values).
    pub notes: Vec<String>,
}

impl Rom {
    /// The KF gain ROM: one word `{g1, g2}` per `bw_sel` address.
    pub fn kf(plan: &Plan) -> Rom {
        let quantized = plan.quantized_gains();
        Rom {
            name: "kf_coefficients".into(),
            description: format!(
                "KF coefficient ROM: word = {{g1 {}, g2 {}}}, address = bw_sel",
                plan.coefficient[0], plan.coefficient[1]
            ),
            fields: COEFFICIENT_NAMES
                .iter()
                .zip(plan.coefficient)
                .map(|(name, format)| Field {
                    name: (*name).into(),
                    format,
                })
                .collect(),
            codes: plan.rom.iter().map(|w| w.to_vec()).collect(),
            notes: plan
                .labels
                .iter()
                .zip(&quantized)
                .map(|(label, g)| {
                    format!(
                        "{label}: {} = {:e}, {} = {:e}",
                        COEFFICIENT_NAMES[0], g[0], COEFFICIENT_NAMES[1], g[1]
                    )
                })
                .collect(),
        }
    }

    /// The bias estimator's gain ROM: A's row over `[mA0, mB0, mA1, …]`, then B's.
    pub fn estimator(plan: &estimator::Plan) -> Rom {
        let quantized = plan.quantized_gains();
        let mut codes = Vec::new();
        let mut notes = Vec::new();
        for (row, name) in ["bias_a", "bias_b"].iter().enumerate() {
            for (j, code) in plan.rom[row].iter().enumerate() {
                let mean = if j % 2 == 0 { "mA" } else { "mB" };
                codes.push(vec![*code]);
                notes.push(format!("{name} <- {mean}{}: {}", j / 2, quantized[row][j]));
            }
        }
        Rom {
            name: "estimator_gains".into(),
            description: format!(
                "bias-estimator gains G ({}): A's row over [mA0, mB0, mA1, ...] then B's",
                plan.gain
            ),
            fields: vec![Field {
                name: "gain".into(),
                format: plan.gain,
            }],
            codes,
            notes,
        }
    }

    /// The mean filter's reciprocal ROM: `1/n` at address `n` (the kept count), and at
    /// address 0 `1/L` (every sample rejected: the plain mean).
    pub fn mean_filter(plan: &mean_filter::Plan) -> Rom {
        let notes = (0..=plan.window as usize)
            .map(|n| {
                let divisor = if n == 0 { plan.window as usize } else { n };
                let what = if n == 0 { "none kept: 1/L" } else { "1/n" };
                format!("{what} = 1/{divisor}: {}", plan.reciprocal_at(n))
            })
            .collect();
        Rom {
            name: "mean_filter_reciprocals".into(),
            description: format!(
                "mean-filter reciprocals 1/n ({}), address = samples kept (0: 1/L)",
                plan.reciprocal
            ),
            fields: vec![Field {
                name: "recip".into(),
                format: plan.reciprocal,
            }],
            codes: plan.rom.iter().map(|c| vec![*c]).collect(),
            notes,
        }
    }

    /// Bits in a word.
    pub fn width(&self) -> u32 {
        self.fields.iter().map(|f| f.format.width).sum()
    }

    /// Number of words.
    pub fn depth(&self) -> usize {
        self.codes.len()
    }

    /// The packed bit pattern of the word at `address`.
    pub fn word(&self, address: usize) -> u128 {
        self.fields
            .iter()
            .zip(&self.codes[address])
            .fold(0u128, |word, (field, code)| {
                // A word is at most two 64-bit fields, so the shift never drops a set bit.
                (word << field.format.width) | field.format.to_bits(*code)
            })
    }

    /// Every packed word, by address.
    pub fn words(&self) -> Vec<u128> {
        (0..self.depth()).map(|a| self.word(a)).collect()
    }

    fn hex(&self, word: u128) -> String {
        format!(
            "{word:0digits$x}",
            digits = self.width().div_ceil(4) as usize
        )
    }

    fn summary(&self) -> String {
        format!(
            "{}: {} words of {} bits",
            self.description,
            self.depth(),
            self.width()
        )
    }
}

/// The file formats a ROM is written in.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum RomFormat {
    /// `$readmemh`: one zero-padded two's-complement hex word per line, `//` comments.
    Mem,
    /// Xilinx coefficient file: `memory_initialization_radix=16;` and a comma-separated vector.
    Coe,
    /// Intel memory initialization file: one `address : data;` line per address.
    Mif,
    /// Verilog-2001 include: localparams for the formats and the flattened ROM
    /// (address 0 in the least significant word).
    VerilogInclude,
    /// SystemVerilog package: the formats, the flattened ROM (as in the include) and a
    /// `word(address)` function.
    SystemVerilogPackage,
    /// VHDL-2008 package: the formats and a `std_logic_vector` array ROM.
    VhdlPackage,
}

impl RomFormat {
    /// Every format, in the order they are written.
    pub const ALL: [RomFormat; 6] = [
        RomFormat::Mem,
        RomFormat::Coe,
        RomFormat::Mif,
        RomFormat::VerilogInclude,
        RomFormat::SystemVerilogPackage,
        RomFormat::VhdlPackage,
    ];

    /// The file name of the ROM called `rom` (a [`Rom::name`]) in this format.
    pub fn file_name(self, rom: &str) -> String {
        match self {
            RomFormat::Mem => format!("{rom}.mem"),
            RomFormat::Coe => format!("{rom}.coe"),
            RomFormat::Mif => format!("{rom}.mif"),
            RomFormat::VerilogInclude => format!("{rom}.vh"),
            RomFormat::SystemVerilogPackage => format!("gyrofx_{rom}_pkg.sv"),
            RomFormat::VhdlPackage => format!("gyrofx_{rom}_pkg.vhd"),
        }
    }

    /// What the format is, for the file header.
    pub fn title(self) -> &'static str {
        match self {
            RomFormat::Mem => "Verilog $readmemh memory file",
            RomFormat::Coe => "Xilinx coefficient (.coe) file",
            RomFormat::Mif => "Intel memory initialization (.mif) file",
            RomFormat::VerilogInclude => "Verilog-2001 include",
            RomFormat::SystemVerilogPackage => "SystemVerilog package",
            RomFormat::VhdlPackage => "VHDL-2008 package",
        }
    }

    fn comment(self) -> &'static str {
        match self {
            RomFormat::Mem | RomFormat::VerilogInclude | RomFormat::SystemVerilogPackage => "//",
            RomFormat::Coe => ";",
            RomFormat::Mif | RomFormat::VhdlPackage => "--",
        }
    }
}

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

/// The words of a ROM file in `format`, by address, as written by [`write`].
///
/// # Errors
/// A message naming the line that does not parse, or a missing or out-of-order address.
pub fn parse(text: &str, format: RomFormat) -> Result<Vec<u128>, String> {
    let comment = format.comment();
    let lines = text.lines().enumerate().filter_map(|(n, line)| {
        // In a .coe, `;` also ends a statement, so only a whole line can be a comment.
        let code = if format == RomFormat::Coe {
            if line.trim_start().starts_with(comment) {
                ""
            } else {
                line.trim()
            }
        } else {
            line.split(comment).next().unwrap_or("").trim()
        };
        (!code.is_empty()).then_some((n + 1, code))
    });
    let number = |n: usize, digits: &str| {
        u128::from_str_radix(digits.trim(), 16)
            .map_err(|e| format!("line {n}: `{digits}` is not a hex word: {e}"))
    };
    let mut words = Vec::new();
    match format {
        RomFormat::Mem => {
            for (n, code) in lines {
                words.push(number(n, code)?);
            }
        }
        RomFormat::Coe => {
            let mut in_vector = false;
            for (n, code) in lines {
                if code == "memory_initialization_radix=16;" {
                    continue;
                }
                if let Some(rest) = code.strip_prefix("memory_initialization_vector=") {
                    in_vector = true;
                    if rest.is_empty() {
                        continue;
                    }
                }
                if !in_vector {
                    return Err(format!("line {n}: `{code}` before the vector"));
                }
                let value = code.trim_end_matches([',', ';']);
                words.push(number(n, value)?);
            }
        }
        RomFormat::Mif => {
            let mut depth = None;
            for (n, code) in lines {
                if let Some(d) = code.strip_prefix("DEPTH=") {
                    depth = d.trim_end_matches(';').parse::<usize>().ok();
                } else if let Some((address, data)) = code.split_once(':') {
                    let address: usize = address
                        .trim()
                        .parse()
                        .map_err(|e| format!("line {n}: bad address: {e}"))?;
                    if address != words.len() {
                        return Err(format!("line {n}: address {address} out of order"));
                    }
                    words.push(number(n, data.trim().trim_end_matches(';'))?);
                }
            }
            if depth != Some(words.len()) {
                return Err(format!("DEPTH {depth:?} but {} addresses", words.len()));
            }
        }
        RomFormat::VerilogInclude | RomFormat::SystemVerilogPackage => {
            for (n, code) in lines {
                if let Some((_, digits)) = code.split_once("'h") {
                    words.push(number(n, digits.trim_end_matches(','))?);
                }
            }
            words.reverse();
        }
        RomFormat::VhdlPackage => {
            for (n, code) in lines {
                if let Some((address, literal)) = code.split_once("=>") {
                    let address: usize = address
                        .trim()
                        .parse()
                        .map_err(|e| format!("line {n}: bad address: {e}"))?;
                    if address != words.len() {
                        return Err(format!("line {n}: address {address} out of order"));
                    }
                    let digits = literal
                        .split_once("x\"")
                        .and_then(|(_, rest)| rest.split_once('"'))
                        .map(|(digits, _)| digits)
                        .ok_or_else(|| format!("line {n}: no x\"...\" literal"))?;
                    words.push(number(n, digits)?);
                }
            }
        }
    }
    Ok(words)
}

#[cfg(test)]
mod tests {
    use super::*;
    use gyrofx_model::examples;

    fn provenance() -> Provenance {
        Provenance {
            version: "0.0.0".into(),
            command: "test".into(),
            config_sha256: "0123456789abcdef0123456789abcdef".into(),
        }
    }

    fn wide_rom() -> Rom {
        // Two 64-bit fields: the widest word, with both signs at the top of their fields.
        let format = Format::signed(64, 62).unwrap();
        Rom {
            name: "wide".into(),
            description: "test".into(),
            fields: vec![
                Field {
                    name: "a".into(),
                    format,
                },
                Field {
                    name: "b".into(),
                    format,
                },
            ],
            codes: vec![
                vec![-1, 1],
                vec![i64::MIN.into(), i64::MAX.into()],
                vec![0, -2],
            ],
            notes: vec!["x".into(), "y".into(), "z".into()],
        }
    }

    #[test]
    fn every_format_reads_back_the_packed_codes() {
        let chain = examples::chain_plan(40, 5, 0, 1, gyrofx_model::fx::Rounding::Convergent);
        let roms = [
            Rom::kf(&chain.kf),
            Rom::estimator(&chain.estimator),
            wide_rom(),
        ];
        for rom in &roms {
            // Unpack independently of `Rom::word`: field by field from the bottom.
            let expected: Vec<Vec<i128>> = rom.codes.clone();
            for format in RomFormat::ALL {
                let text = write(rom, format, &provenance());
                assert!(text.contains(format.title()), "{format:?} header");
                assert!(text.contains("gyrofx 0.0.0") && text.contains("0123456789abcdef"));
                let words = parse(&text, format).unwrap_or_else(|e| panic!("{format:?}: {e}"));
                assert_eq!(words.len(), rom.depth(), "{format:?}");
                for (address, word) in words.iter().enumerate() {
                    let mut rest = *word;
                    let mut fields = Vec::new();
                    for field in rom.fields.iter().rev() {
                        fields.push(field.format.from_bits(rest));
                        rest = rest.checked_shr(field.format.width).unwrap_or(0);
                    }
                    fields.reverse();
                    assert_eq!(rest, 0, "{format:?} @{address}: bits above the word");
                    assert_eq!(fields, expected[address], "{format:?} @{address}");
                }
            }
        }
    }

    #[test]
    fn a_corrupted_file_does_not_parse_as_the_rom() {
        let rom =
            Rom::kf(&examples::chain_plan(40, 5, 0, 1, gyrofx_model::fx::Rounding::Convergent).kf);
        for format in RomFormat::ALL {
            let text = write(&rom, format, &provenance());
            let good = parse(&text, format).unwrap();
            // Flip the last hex digit of the first data word.
            let first = rom.hex(
                good[if matches!(
                    format,
                    RomFormat::VerilogInclude | RomFormat::SystemVerilogPackage
                ) {
                    good.len() - 1
                } else {
                    0
                }],
            );
            let flipped = format!(
                "{}{}",
                &first[..first.len() - 1],
                if first.ends_with('0') { '1' } else { '0' }
            );
            let bad = text.replacen(&first, &flipped, 1);
            assert_ne!(parse(&bad, format).ok(), Some(good), "{format:?}");
        }
    }
}
