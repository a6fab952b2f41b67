//! The package's `roms/` folder: every ROM in every format holds the words the blocks'
//! `$readmemh` files hold, and the HDL formats compile in Icarus, Verilator and GHDL and
//! read back those words there.

mod common;

use std::path::Path;

use common::*;
use gyrofx_codegen::rom::{parse, RomFormat, ROM_FOLDER};

const ROMS: [(&str, &str); 2] = [("kf_coefficients", "kf"), ("estimator_gains", "estimator")];

fn read(path: &Path) -> String {
    std::fs::read_to_string(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

/// The words the block's own ROM (read by its testbench) holds.
fn block_words(package: &Path, name: &str, block: &str) -> Vec<u128> {
    let text = read(&package.join(block).join(format!("{name}.mem")));
    parse(&text, RomFormat::Mem).unwrap()
}

/// A SystemVerilog bench comparing both packages and both includes with the `.mem` files.
const SV_BENCH: &str = r#"`default_nettype none
module rom_bench;
`include "kf_coefficients.vh"
`include "estimator_gains.vh"
    reg [gyrofx_kf_coefficients_pkg::WIDTH-1:0] kf_mem [0:gyrofx_kf_coefficients_pkg::DEPTH-1];
    reg [gyrofx_estimator_gains_pkg::WIDTH-1:0] est_mem [0:gyrofx_estimator_gains_pkg::DEPTH-1];
    integer a;
    integer errors;
    initial begin
        errors = 0;
        $readmemh("kf_coefficients.mem", kf_mem);
        $readmemh("estimator_gains.mem", est_mem);
        for (a = 0; a < gyrofx_kf_coefficients_pkg::DEPTH; a = a + 1) begin
            if (gyrofx_kf_coefficients_pkg::word(a) !== kf_mem[a]) errors = errors + 1;
            if (KF_COEFFICIENTS_ROM[a*KF_COEFFICIENTS_WIDTH +: KF_COEFFICIENTS_WIDTH] !== kf_mem[a])
                errors = errors + 1;
        end
        for (a = 0; a < gyrofx_estimator_gains_pkg::DEPTH; a = a + 1) begin
            if (gyrofx_estimator_gains_pkg::word(a) !== est_mem[a]) errors = errors + 1;
            if (ESTIMATOR_GAINS_ROM[a*ESTIMATOR_GAINS_WIDTH +: ESTIMATOR_GAINS_WIDTH] !== est_mem[a])
                errors = errors + 1;
        end
        if (errors == 0) $display("ROMS MATCH");
        else $display("ROM MISMATCHES: %0d", errors);
        $finish;
    end
endmodule
"#;

/// A VHDL bench asserting every word of both packages against binary literals of `words`.
fn vhdl_bench(words: &[Vec<u128>; 2], widths: [u32; 2]) -> String {
    let mut checks = String::new();
    for ((name, _), (rom, width)) in ROMS.iter().zip(words.iter().zip(widths)) {
        for (address, word) in rom.iter().enumerate() {
            checks.push_str(&format!(
                "        assert work.gyrofx_{name}_pkg.ROM({address}) = \"{word:0w$b}\"\n            \
                 report \"ROM MISMATCH {name} @{address}\" severity failure;\n",
                w = width as usize
            ));
        }
    }
    format!(
        "library ieee;\nuse ieee.std_logic_1164.all;\n\nentity rom_bench is\nend entity;\n\n\
         architecture sim of rom_bench is\nbegin\n    process\n    begin\n{checks}        \
         report \"ROMS MATCH\";\n        wait;\n    end process;\nend architecture;\n"
    )
}

fn ghdl(dir: &Path) -> (bool, String) {
    let (ok_analyse, log) = run_tool(
        "ghdl",
        &[
            "-a",
            "--std=08",
            "gyrofx_kf_coefficients_pkg.vhd",
            "gyrofx_estimator_gains_pkg.vhd",
            "rom_bench.vhd",
        ],
        dir,
    );
    assert!(ok_analyse, "ghdl analysis: {log}");
    assert!(!log.contains("warning"), "ghdl warns: {log}");
    let (ok_elaborate, log) = run_tool("ghdl", &["-e", "--std=08", "rom_bench"], dir);
    assert!(ok_elaborate, "ghdl elaboration: {log}");
    run_tool("ghdl", &["-r", "--std=08", "rom_bench"], dir)
}

#[test]
fn every_rom_format_holds_the_blocks_words_in_every_simulator() {
    let dir = tempfile::tempdir().unwrap();
    let package = generate_default(dir.path(), "2000");
    let roms = package.join(ROM_FOLDER);

    // Every format parses back to the words the block testbenches read.
    let mut words: [Vec<u128>; 2] = Default::default();
    let mut widths = [0u32; 2];
    for (i, (name, block)) in ROMS.iter().enumerate() {
        words[i] = block_words(&package, name, block);
        assert!(!words[i].is_empty());
        let mif = read(&roms.join(format!("{name}.mif")));
        widths[i] = mif
            .lines()
            .find_map(|l| l.strip_prefix("WIDTH="))
            .and_then(|w| w.trim_end_matches(';').parse().ok())
            .expect("a WIDTH line");
        for format in RomFormat::ALL {
            let file = match format {
                RomFormat::Mem => format!("{name}.mem"),
                RomFormat::Coe => format!("{name}.coe"),
                RomFormat::Mif => format!("{name}.mif"),
                RomFormat::VerilogInclude => format!("{name}.vh"),
                RomFormat::SystemVerilogPackage => format!("gyrofx_{name}_pkg.sv"),
                RomFormat::VhdlPackage => format!("gyrofx_{name}_pkg.vhd"),
            };
            let text = read(&roms.join(&file));
            let header: String = text.lines().take(2).collect::<Vec<_>>().join("\n");
            assert!(header.contains("generated by gyrofx"), "{file}: {header}");
            assert!(header.contains("config sha256"), "{file}: {header}");
            assert!(header.contains(format.title()), "{file}: {header}");
            assert_eq!(parse(&text, format).unwrap(), words[i], "{file}");
        }
    }

    // Icarus: the packages and the includes read back the .mem words.
    std::fs::write(roms.join("rom_bench.sv"), SV_BENCH).unwrap();
    let sources = [
        "-g2012",
        "-Wall",
        "-o",
        "rom_bench.vvp",
        "gyrofx_kf_coefficients_pkg.sv",
        "gyrofx_estimator_gains_pkg.sv",
        "rom_bench.sv",
    ];
    let (compiled, log) = run_tool("iverilog", &sources, &roms);
    assert!(compiled && log.trim().is_empty(), "iverilog: {log}");
    let (_, log) = run_tool("vvp", &["-n", "rom_bench.vvp"], &roms);
    assert!(log.contains("ROMS MATCH"), "vvp: {log}");

    // Verilator: the packages lint clean (the bench's unused include parameters aside).
    let (linted, log) = run_tool(
        "verilator",
        &[
            "--lint-only",
            "-Wall",
            "-Wno-UNUSEDPARAM",
            "--top-module",
            "rom_bench",
            "gyrofx_kf_coefficients_pkg.sv",
            "gyrofx_estimator_gains_pkg.sv",
            "rom_bench.sv",
        ],
        &roms,
    );
    assert!(linted && log.trim().is_empty(), "verilator: {log}");

    // GHDL: the VHDL-2008 packages hold the same words.
    std::fs::write(roms.join("rom_bench.vhd"), vhdl_bench(&words, widths)).unwrap();
    let (ran, log) = ghdl(&roms);
    assert!(ran && log.contains("ROMS MATCH"), "ghdl: {log}");

    // The benches can fail: one flipped bit in a .mem word, one in a VHDL expectation.
    let mem = roms.join("kf_coefficients.mem");
    let original = read(&mem);
    let mut flipped = words[0].clone();
    flipped[0] ^= 1;
    let width = widths[0].div_ceil(4) as usize;
    let first = format!("{:0width$x}", words[0][0]);
    let changed = format!("{:0width$x}", flipped[0]);
    std::fs::write(
        &mem,
        original.replacen(&format!("\n{first}\n"), &format!("\n{changed}\n"), 1),
    )
    .unwrap();
    let (_, log) = run_tool("vvp", &["-n", "rom_bench.vvp"], &roms);
    assert!(log.contains("ROM MISMATCHES: 2"), "vvp after a flip: {log}");

    std::fs::write(
        roms.join("rom_bench.vhd"),
        vhdl_bench(&[flipped, words[1].clone()], widths),
    )
    .unwrap();
    let (ran, log) = ghdl(&roms);
    assert!(
        !ran && log.contains("ROM MISMATCH kf_coefficients @0"),
        "ghdl after a flip: {log}"
    );
}
