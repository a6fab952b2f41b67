//! Coefficient ROMs in every format HDL flows read, all written from one list of codes.
//!
//! A [`Rom`] is a list of words, each the concatenation of one or more fixed-point fields
//! (MSB first); [`write()`] renders it as a `$readmemh` file, a Xilinx `.coe`, an Intel `.mif`,
//! a Verilog include, a SystemVerilog package or a VHDL-2008 package, and [`parse`] reads any
//! of them back, so every format is checked against the same codes.

use gyrofx_model::estimator;
use gyrofx_model::fx::Format;
use gyrofx_model::gyro_loop;
use gyrofx_model::kf::{Plan, COEFFICIENT_NAMES};
use gyrofx_model::mean_filter;
use gyrofx_model::serial;

mod parsing;
mod writing;

pub use parsing::parse;
pub use writing::write;

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

    /// The serial engine's program (`gyrofx_serial_engine`), from address 0 to its `End`; the
    /// fields of `gyrofx_model::serial::isa::Instruction`.
    pub fn serial_program(program: &serial::Program) -> Rom {
        let unsigned = |width| Format {
            signed: false,
            width,
            frac: 0,
        };
        let layout = program.layout;
        let all = &program.sample;
        Rom {
            name: "serial_program".into(),
            description: format!(
                "serial engine program: {} instructions from 0 (4 clocks each)",
                program.sample.len()
            ),
            fields: [
                ("op", 4),
                ("cond", 4),
                ("ram_index", 2),
                ("by_bw_sel", 1),
                ("address", layout.address_bits),
                ("coefficient", layout.coefficient_bits),
            ]
            .into_iter()
            .map(|(name, width)| Field {
                name: name.into(),
                format: unsigned(width),
            })
            .collect(),
            codes: all
                .iter()
                .map(|i| {
                    vec![
                        i128::from(i.op as u8),
                        i128::from(i.cond as u8),
                        i128::from(i.ram_index as u8),
                        i128::from(i.coefficient_by_bw_sel),
                        i128::from(i.address),
                        i128::from(i.coefficient),
                    ]
                })
                .collect(),
            notes: all
                .iter()
                .map(|i| format!("{:?} if {:?}", i.op, i.cond))
                .collect(),
        }
    }

    /// The serial engine's coefficient limbs (16-bit signed words; the KF's gains from
    /// address 0, one power-of-two region per `bw_sel`, then the constants).
    pub fn serial_coefficients(program: &serial::Program) -> Rom {
        Rom {
            name: "serial_coefficients".into(),
            description:
                "serial engine coefficient limbs (s16.0: 15-bit limbs, the top one signed)".into(),
            fields: vec![Field {
                name: "limb".into(),
                format: Format {
                    signed: true,
                    width: 16,
                    frac: 0,
                },
            }],
            codes: program
                .coefficients
                .iter()
                .map(|c| vec![i128::from(*c)])
                .collect(),
            notes: program
                .coefficients
                .iter()
                .map(|c| format!("{c}"))
                .collect(),
        }
    }

    /// The gyro loop's quarter-wave sine ROM (shared by its three NCOs): address `k` holds
    /// `round(A sin(π/2 (k + ½) / 2^ADDR_W))`.
    pub fn gyro_loop_sine(plan: &gyro_loop::nco::Plan) -> Rom {
        let codes = plan.rom_codes();
        let depth = codes.len();
        Rom {
            name: "gyro_loop_nco_sine".into(),
            description: format!(
                "gyro-loop NCO quarter-wave sine ({}), address k: sin(pi/2 (k + 1/2) / {depth})",
                plan.output
            ),
            fields: vec![Field {
                name: "sine".into(),
                format: plan.output,
            }],
            codes: codes.iter().map(|c| vec![*c]).collect(),
            notes: codes
                .iter()
                .enumerate()
                .map(|(k, c)| format!("k = {k}: {}", plan.output.to_f64(*c)))
                .collect(),
        }
    }

    /// The gyro loop's CIC droop-compensator taps (shared by both CICs), `h_0` first.
    pub fn gyro_loop_cic(plan: &gyro_loop::cic::Plan) -> Rom {
        let format = plan.taps[0].format;
        Rom {
            name: "gyro_loop_cic_taps".into(),
            description: format!(
                "gyro-loop CIC droop-compensator taps ({format}), address = tap index (h_0 first, symmetric)"
            ),
            fields: vec![Field {
                name: "tap".into(),
                format,
            }],
            codes: plan.taps.iter().map(|t| vec![t.code]).collect(),
            notes: plan
                .taps
                .iter()
                .enumerate()
                .map(|(t, tap)| format!("h_{t} = {:e}", format.to_f64(tap.code)))
                .collect(),
        }
    }

    /// The folded gyro loop's schedule (`gyrofx_gyro_loop_serial`): one control word per clock
    /// after a sample's `ce`, the fields of `gyrofx_model::gyro_loop::folded::Control`.
    pub fn gyro_loop_schedule(schedule: &gyro_loop::folded::Schedule) -> Rom {
        Rom::folded_schedule(
            schedule,
            "gyro_loop_schedule",
            "clock",
            format!(
                "folded gyro-loop schedule: {} control words from 0, one a clock ({} every sample, all in a decimating one)",
                schedule.len(),
                schedule.regular
            ),
        )
    }

    /// The folded pair's schedule (`gyrofx_gyro_pair_serial`): both gyros' regular part, then
    /// each deferred segment padded to the longest sample's words.
    pub fn gyro_pair_schedule(schedule: &gyro_loop::folded::Schedule) -> Rom {
        Rom::folded_schedule(
            schedule,
            "gyro_pair_schedule",
            "word",
            format!(
                "folded two-gyro schedule: {} regular control words every sample, then {} deferred segments of {} words, one in each of the samples after a decimating one",
                schedule.regular,
                schedule.deferred.len(),
                schedule.len() - schedule.regular
            ),
        )
    }

    fn folded_schedule(
        schedule: &gyro_loop::folded::Schedule,
        name: &str,
        note: &str,
        description: String,
    ) -> Rom {
        // MSB first, as a ROM word packs its fields.
        let layout: Vec<(&str, u32)> = gyro_loop::folded::FIELDS.iter().rev().copied().collect();
        let words = schedule.rom_words();
        Rom {
            name: name.into(),
            description,
            fields: layout
                .iter()
                .map(|&(name, width)| Field {
                    name: name.into(),
                    format: Format {
                        signed: false,
                        width,
                        frac: 0,
                    },
                })
                .collect(),
            codes: words
                .iter()
                .map(|c| c.fields().iter().rev().map(|v| i128::from(*v)).collect())
                .collect(),
            notes: words
                .iter()
                .enumerate()
                .map(|(t, c)| format!("{note} {t}: {c}"))
                .collect(),
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

#[cfg(test)]
mod tests;
