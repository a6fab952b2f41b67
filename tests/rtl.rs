//! The reference RTL on its own: the Verilog lint-clean in Verilator and Icarus and
//! synthesizable by yosys without latches, the VHDL analysed by GHDL without warnings and
//! elaborated for several parameter sets, and the requantizer of each language checked
//! exhaustively against the model on small widths for every rounding and overflow mode.

use std::path::{Path, PathBuf};

use crate::common::run_tool;
use gyrofx_model::fx::{requantize, Format, Overflow, Rounding};

fn hdl(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("hdl").join(name)
}

/// Lints `top` from `sources` (file names in `hdl/`) with `verilator --lint-only -Wall` under
/// each parameter set; every run must pass and print nothing.
fn lint_clean(top: &str, sources: &[&str], parameter_sets: &[&[&str]]) {
    let dir = tempfile::tempdir().unwrap();
    let paths: Vec<String> = sources
        .iter()
        .map(|n| hdl(n).to_string_lossy().into_owned())
        .collect();
    for params in parameter_sets {
        let mut args = vec!["--lint-only", "-Wall", "--top-module", top];
        args.extend_from_slice(params);
        args.extend(paths.iter().map(String::as_str));
        let (ok, text) = run_tool("verilator", &args, dir.path());
        assert!(
            ok && text.trim().is_empty(),
            "verilator -Wall {top} {params:?}:\n{text}"
        );
    }
}

#[test]
fn verilator_lint_is_clean_for_several_parameter_sets() {
    let parameter_sets: [&[&str]; 3] = [
        &[],
        // No guard bits, g1 without fraction bits, floor rounding, wrapping.
        &[
            "-GSTATE_F=14",
            "-GSTATE_W=26",
            "-GG1_F=0",
            "-GROUNDING=0",
            "-GSATURATE=0",
        ],
        // Output as wide as the state, one ROM word.
        &[
            "-GOUT_W=36",
            "-GOUT_F=26",
            "-GROM_DEPTH=1",
            "-GSEL_W=1",
            "-GROUNDING=5",
        ],
    ];
    lint_clean(
        "gyrofx_kf",
        &["gyrofx_quantize.v", "gyrofx_spacing_check.v", "gyrofx_kf.v"],
        &parameter_sets,
    );
}

const ALL_RTL: [&str; 8] = [
    "gyrofx_quantize.v",
    "gyrofx_spacing_check.v",
    "gyrofx_kf.v",
    "gyrofx_sequencer.v",
    "gyrofx_bias_estimator.v",
    "gyrofx_calibration.v",
    "gyrofx_top.v",
    "gyrofx_mean_filter.v",
];

#[test]
fn the_mean_filter_lints_clean_for_several_parameter_sets() {
    let parameter_sets: [&[&str]; 3] = [
        &[],
        // The smallest window, floor rounding, wrapping.
        &[
            "-GWINDOW=2",
            "-GCOUNT_W=2",
            "-GSUM_W=25",
            "-GDEV_W=27",
            "-GSCALED_THRESHOLD=27'd100",
            "-GROUNDING=0",
            "-GSATURATE=0",
        ],
        // A window that fills its count exactly (31 of 5 bits), a narrow reciprocal.
        &[
            "-GWINDOW=31",
            "-GSUM_W=29",
            "-GRECIP_W=10",
            "-GRECIP_F=8",
            "-GOUT_W=30",
            "-GOUT_F=20",
        ],
    ];
    lint_clean(
        "gyrofx_mean_filter",
        &["gyrofx_quantize.v", "gyrofx_mean_filter.v"],
        &parameter_sets,
    );
}

#[test]
fn the_whole_chain_lints_clean_for_several_parameter_sets() {
    let parameter_sets: [&[&str]; 3] = [
        &[],
        // ABBA over 8 intervals with stagger, smoothing and convergent rounding.
        &[
            "-GINTERVALS=8",
            "-GINTERVAL_W=3",
            "-GPATTERN=8'b10011001",
            "-GSTAGGER=20",
            "-GSMOOTH=3",
            "-GROUNDING=5",
        ],
        // Two intervals, no blanking, floor rounding and wrapping.
        &[
            "-GINTERVALS=2",
            "-GINTERVAL_W=1",
            "-GPATTERN=2'b01",
            "-GBLANK=0",
            "-GROUNDING=0",
            "-GSATURATE=0",
        ],
    ];
    lint_clean("gyrofx_top", &ALL_RTL, &parameter_sets);
}

#[test]
fn icarus_compiles_without_warnings() {
    let dir = tempfile::tempdir().unwrap();
    let (ok, text) = run_tool(
        "iverilog",
        &[
            "-g2005",
            "-Wall",
            "-o",
            "kf.vvp",
            hdl("gyrofx_quantize.v").to_str().unwrap(),
            hdl("gyrofx_spacing_check.v").to_str().unwrap(),
            hdl("gyrofx_kf.v").to_str().unwrap(),
            hdl("gyrofx_sequencer.v").to_str().unwrap(),
            hdl("gyrofx_bias_estimator.v").to_str().unwrap(),
            hdl("gyrofx_calibration.v").to_str().unwrap(),
            hdl("gyrofx_top.v").to_str().unwrap(),
            hdl("gyrofx_mean_filter.v").to_str().unwrap(),
        ],
        dir.path(),
    );
    assert!(ok && text.trim().is_empty(), "{text}");
}

#[test]
fn yosys_synthesizes_without_latches() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(
        dir.path().join("kf_coefficients.mem"),
        "2245157f7\n3a5a25c01\n4ae2f4c60\n",
    )
    .unwrap();
    let script = format!(
        "read_verilog {} {}; synth -top gyrofx_kf; select -assert-none t:$dlatch t:$_DLATCH_*; check -assert; stat",
        hdl("gyrofx_quantize.v").display(),
        hdl("gyrofx_kf.v").display()
    );
    let (ok, text) = run_tool("yosys", &["-q", "-p", &script], dir.path());
    assert!(ok, "yosys:\n{text}");
    assert!(!text.to_lowercase().contains("latch inferred"), "{text}");

    // The mean filter, with a ROM image of its 21 reciprocals.
    let rom: String = (0..=20u32)
        .map(|n| format!("{:05x}\n", (1u32 << 16) / n.max(1)))
        .collect();
    std::fs::write(dir.path().join("mean_filter_reciprocals.mem"), rom).unwrap();
    let script = format!(
        "read_verilog {} {}; synth -top gyrofx_mean_filter -run :coarse; proc; select -assert-none t:$dlatch t:$adlatch t:$dlatchsr; synth -top gyrofx_mean_filter; check -assert; stat",
        hdl("gyrofx_quantize.v").display(),
        hdl("gyrofx_mean_filter.v").display()
    );
    let (ok, text) = run_tool("yosys", &["-q", "-p", &script], dir.path());
    assert!(ok, "yosys (mean filter):\n{text}");
}

/// Small requantizations (input width, fraction, output width, fraction) checked exhaustively:
/// fewer, more and equal fraction bits, wrapping into fewer integer bits.
const QUANTIZER_CASES: [(u32, i32, u32, i32); 4] =
    [(7, 3, 4, 0), (6, 4, 6, 3), (8, 5, 3, 1), (5, 2, 5, 2)];

/// Every code of `from` with `fx::requantize`'s result in `to`: one line per code, input and
/// output as zero-padded hex and the overflow flag.
fn requantizer_vectors(from: Format, to: Format, rounding: Rounding, overflow: Overflow) -> String {
    (from.min_code()..=from.max_code())
        .map(|code| {
            let q = requantize(code, from.frac, to, rounding, overflow);
            format!(
                "{:0iw$x} {:0ow$x} {}\n",
                from.to_bits(code),
                to.to_bits(q.code),
                u8::from(q.overflowed),
                iw = from.hex_digits(),
                ow = to.hex_digits(),
            )
        })
        .collect()
}

/// Drives every input code of small formats through `gyrofx_quantize` in Icarus and compares
/// with `fx::requantize`, for all six rounding modes and both overflow modes.
#[test]
fn requantizer_rtl_matches_the_model_exhaustively() {
    let dir = tempfile::tempdir().unwrap();
    for (in_w, in_f, out_w, out_f) in QUANTIZER_CASES {
        let from = Format::signed(in_w, in_f).unwrap();
        let to = Format::signed(out_w, out_f).unwrap();
        for rounding in Rounding::ALL {
            for overflow in Overflow::ALL {
                let expected = requantizer_vectors(from, to, rounding, overflow);
                std::fs::write(dir.path().join("expected.txt"), &expected).unwrap();
                let tb = format!(
                    "`timescale 1ns/1ps
module tb;
reg signed [{iw}:0] in; wire signed [{ow}:0] out; wire overflow;
integer fd, n, errors = 0; reg [{iw}:0] i_bits; reg [{ow}:0] o_bits; reg o_flag;
gyrofx_quantize #(.IN_W({in_w}), .IN_F({in_f}), .OUT_W({out_w}), .OUT_F({out_f}), .ROUNDING({r}), .SATURATE({s})) dut (.in(in), .out(out), .overflow(overflow));
initial begin
  fd = $fopen(\"expected.txt\", \"r\");
  if (fd == 0) $fatal(1, \"no vectors\");
  n = $fscanf(fd, \"%h %h %h\\n\", i_bits, o_bits, o_flag);
  while (n == 3) begin
    in = i_bits; #1;
    if (out !== o_bits || overflow !== o_flag) begin errors = errors + 1; $display(\"MISMATCH in=%h out=%h want %h flag %b want %b\", in, out, o_bits, overflow, o_flag); end
    n = $fscanf(fd, \"%h %h %h\\n\", i_bits, o_bits, o_flag);
  end
  if (errors != 0) $fatal(1, \"%0d errors\", errors);
  $display(\"PASS\");
  $finish;
end
endmodule
",
                    iw = in_w - 1,
                    ow = out_w - 1,
                    r = rounding.rtl_code(),
                    s = overflow.rtl_code()
                );
                std::fs::write(dir.path().join("tb.v"), tb).unwrap();
                let (ok, text) = run_tool(
                    "iverilog",
                    &[
                        "-g2005",
                        "-o",
                        "tb.vvp",
                        hdl("gyrofx_quantize.v").to_str().unwrap(),
                        "tb.v",
                    ],
                    dir.path(),
                );
                assert!(ok, "{text}");
                let (ok, text) = run_tool("vvp", &["-n", "tb.vvp"], dir.path());
                assert!(
                    ok && text.contains("PASS"),
                    "{from} -> {to} {rounding} {overflow}:\n{text}"
                );
            }
        }
    }
}

/// The VHDL RTL in compile order (packages first).
const VHDL_RTL: [&str; 9] = [
    "gyrofx_mem_pkg.vhd",
    "gyrofx_quantize.vhd",
    "gyrofx_spacing_check.vhd",
    "gyrofx_kf.vhd",
    "gyrofx_sequencer.vhd",
    "gyrofx_bias_estimator.vhd",
    "gyrofx_calibration.vhd",
    "gyrofx_top.vhd",
    "gyrofx_mean_filter.vhd",
];

/// GHDL's warnings that apply to this code, all as errors.
const GHDL_WARNINGS: [&str; 5] = ["-Werror", "-Wunused", "-Wbinding", "-Wbody", "-Wspecs"];

/// Analyses `files` (paths) into `dir/work`; asserts success and silence.
fn ghdl_analyse(dir: &Path, files: &[String]) {
    std::fs::create_dir_all(dir.join("work")).unwrap();
    let mut args = vec!["-a", "--std=08", "--workdir=work"];
    args.extend_from_slice(&GHDL_WARNINGS);
    args.extend(files.iter().map(String::as_str));
    let (ok, text) = run_tool("ghdl", &args, dir);
    assert!(ok && text.trim().is_empty(), "ghdl -a:\n{text}");
}

/// `words` lines of `width`-bit zero words: a ROM image of the right shape.
fn zero_rom(words: usize, width: u32) -> String {
    let digits = width.div_ceil(4) as usize;
    (0..words).map(|_| format!("{:0digits$x}\n", 0)).collect()
}

#[test]
fn ghdl_analyses_the_vhdl_without_warnings_and_elaborates_several_parameter_sets() {
    let dir = tempfile::tempdir().unwrap();
    let mut files: Vec<String> = VHDL_RTL
        .iter()
        .map(|n| hdl(n).to_string_lossy().into_owned())
        .collect();
    files.push(
        hdl("gyrofx_testbench_pkg.vhd")
            .to_string_lossy()
            .into_owned(),
    );
    ghdl_analyse(dir.path(), &files);
    // ROM images for the default 4 intervals (16 gains) and for 8 and 2 intervals.
    std::fs::write(dir.path().join("kf.mem"), zero_rom(3, 36)).unwrap();
    std::fs::write(dir.path().join("kf_wide.mem"), zero_rom(1, 50)).unwrap();
    for intervals in [2usize, 4, 8] {
        std::fs::write(
            dir.path().join(format!("gains_{intervals}.mem")),
            zero_rom(4 * intervals, 18),
        )
        .unwrap();
    }
    let parameter_sets: [&[&str]; 3] = [
        &["-gGAIN_ROM_FILE=gains_4.mem", "-gKF_ROM_FILE=kf.mem"],
        // ABBA over 8 intervals with stagger, smoothing and convergent rounding.
        &[
            "-gINTERVALS=8",
            "-gINTERVAL_W=3",
            "-gPATTERN=10011001",
            "-gSTAGGER=20",
            "-gSMOOTH=3",
            "-gROUNDING=5",
            "-gGAIN_ROM_FILE=gains_8.mem",
            "-gKF_ROM_FILE=kf.mem",
        ],
        // Two intervals, no blanking, floor rounding, wrapping, one wide KF word, no guard
        // bits and g1 without fraction bits.
        &[
            "-gINTERVALS=2",
            "-gINTERVAL_W=1",
            "-gPATTERN=01",
            "-gBLANK=0",
            "-gROUNDING=0",
            "-gSATURATE=0",
            "-gSTATE_W=24",
            "-gSTATE_F=14",
            "-gG1_W=20",
            "-gG1_F=0",
            "-gG2_W=30",
            "-gROM_DEPTH=1",
            "-gSEL_W=1",
            "-gGAIN_ROM_FILE=gains_2.mem",
            "-gKF_ROM_FILE=kf_wide.mem",
        ],
    ];
    for params in parameter_sets {
        let mut args = vec!["--elab-run", "--std=08", "--workdir=work", "gyrofx_top"];
        args.extend_from_slice(params);
        args.push("--no-run");
        let (ok, text) = run_tool("ghdl", &args, dir.path());
        assert!(ok && text.trim().is_empty(), "ghdl {params:?}:\n{text}");
    }
    // A ROM image of the wrong shape stops the elaboration with a message naming the file.
    let (ok, text) = run_tool(
        "ghdl",
        &[
            "--elab-run",
            "--std=08",
            "--workdir=work",
            "gyrofx_top",
            "-gGAIN_ROM_FILE=gains_2.mem",
            "-gKF_ROM_FILE=kf.mem",
            "--no-run",
        ],
        dir.path(),
    );
    assert!(
        !ok && text.contains("gains_2.mem holds 8 words; 16 are needed"),
        "{text}"
    );

    // The mean filter: the default and the smallest window.
    std::fs::write(dir.path().join("recip_20.mem"), zero_rom(21, 18)).unwrap();
    std::fs::write(dir.path().join("recip_2.mem"), zero_rom(3, 12)).unwrap();
    let mean_filter_sets: [&[&str]; 2] = [
        &["-gROM_FILE=recip_20.mem"],
        &[
            "-gWINDOW=2",
            "-gCOUNT_W=2",
            "-gSUM_W=25",
            "-gDEV_W=27",
            "-gSCALED_THRESHOLD=000000000000000000001100100",
            "-gRECIP_W=12",
            "-gRECIP_F=10",
            "-gROM_FILE=recip_2.mem",
        ],
    ];
    for params in mean_filter_sets {
        let mut args = vec![
            "--elab-run",
            "--std=08",
            "--workdir=work",
            "gyrofx_mean_filter",
        ];
        args.extend_from_slice(params);
        args.push("--no-run");
        let (ok, text) = run_tool("ghdl", &args, dir.path());
        assert!(ok && text.trim().is_empty(), "ghdl {params:?}:\n{text}");
    }
}

/// Drives every input code of small formats through the VHDL `gyrofx_quantize` in GHDL and
/// compares with `fx::requantize`, for all six rounding modes and both overflow modes.
#[test]
fn vhdl_requantizer_matches_the_model_exhaustively() {
    let dir = tempfile::tempdir().unwrap();
    let tb = r#"library ieee;
use ieee.std_logic_1164.all;
use ieee.numeric_std.all;
use std.textio.all;
use work.gyrofx_mem_pkg.all;

entity tb_quantize is
    generic (IN_W : positive; IN_F : integer; OUT_W : positive; OUT_F : integer;
             ROUNDING : natural; SATURATE : natural; VECTORS : string);
end entity;

architecture sim of tb_quantize is
    signal value_in : signed(IN_W - 1 downto 0) := (others => '0');
    signal value_out : signed(OUT_W - 1 downto 0);
    signal overflow : std_logic;
begin
    dut : entity work.gyrofx_quantize
        generic map (IN_W => IN_W, IN_F => IN_F, OUT_W => OUT_W, OUT_F => OUT_F,
                     ROUNDING => ROUNDING, SATURATE => SATURATE)
        port map (value_in => value_in, value_out => value_out, overflow => overflow);

    process
        file vector_file : text;
        variable text_line : line;
        variable field : string(1 to 8);
        variable width : natural;
        variable in_bits : std_logic_vector(IN_W - 1 downto 0);
        variable out_bits : std_logic_vector(OUT_W - 1 downto 0);
        variable flag : std_logic_vector(0 downto 0);
        variable ok : boolean;
        variable errors : natural := 0;
        variable count : natural := 0;
    begin
        file_open(vector_file, VECTORS, read_mode);
        while not endfile(vector_file) loop
            readline(vector_file, text_line);
            width := (IN_W + 3) / 4;
            read(text_line, field(1 to width));
            parse_hex(field(1 to width), in_bits, ok);
            assert ok report "bad input field" severity failure;
            read(text_line, field(1));
            width := (OUT_W + 3) / 4;
            read(text_line, field(1 to width));
            parse_hex(field(1 to width), out_bits, ok);
            assert ok report "bad output field" severity failure;
            read(text_line, field(1));
            read(text_line, field(1 to 1));
            parse_hex(field(1 to 1), flag, ok);
            value_in <= signed(in_bits);
            wait for 1 ns;
            if std_logic_vector(value_out) /= out_bits or overflow /= flag(0) then
                errors := errors + 1;
                report "MISMATCH in=" & to_hstring(in_bits) & " out=" & to_hstring(value_out)
                    & " want " & to_hstring(out_bits);
            end if;
            count := count + 1;
        end loop;
        assert errors = 0 report integer'image(errors) & " errors" severity failure;
        report "PASS " & integer'image(count);
        wait;
    end process;
end architecture;
"#;
    std::fs::write(dir.path().join("tb_quantize.vhd"), tb).unwrap();
    ghdl_analyse(
        dir.path(),
        &[
            hdl("gyrofx_mem_pkg.vhd").to_string_lossy().into_owned(),
            hdl("gyrofx_quantize.vhd").to_string_lossy().into_owned(),
            "tb_quantize.vhd".into(),
        ],
    );
    for (in_w, in_f, out_w, out_f) in QUANTIZER_CASES {
        let from = Format::signed(in_w, in_f).unwrap();
        let to = Format::signed(out_w, out_f).unwrap();
        for rounding in Rounding::ALL {
            for overflow in Overflow::ALL {
                let expected = requantizer_vectors(from, to, rounding, overflow);
                std::fs::write(dir.path().join("expected.txt"), &expected).unwrap();
                let generics = [
                    format!("-gIN_W={in_w}"),
                    format!("-gIN_F={in_f}"),
                    format!("-gOUT_W={out_w}"),
                    format!("-gOUT_F={out_f}"),
                    format!("-gROUNDING={}", rounding.rtl_code()),
                    format!("-gSATURATE={}", overflow.rtl_code()),
                    "-gVECTORS=expected.txt".to_string(),
                ];
                let mut args = vec!["--elab-run", "--std=08", "--workdir=work", "tb_quantize"];
                args.extend(generics.iter().map(String::as_str));
                let (ok, text) = run_tool("ghdl", &args, dir.path());
                let want = format!("PASS {}", from.max_code() - from.min_code() + 1);
                assert!(
                    ok && text.contains(&want),
                    "{from} -> {to} {rounding} {overflow}:\n{text}"
                );
            }
        }
    }
}

/// Every numeric parameter and every width localparam is `integer`-typed: an untyped one
/// takes the signedness of the values given it, and a tool that sets them unsigned (yosys 0.23's
/// `chparam`) then wraps a negative intermediate such as the KF's `P2_I = P2_W − P2_F`.
#[test]
fn numeric_parameters_and_localparams_are_integer_typed() {
    let untyped = untyped_declaration();
    let mut found = Vec::new();
    for (name, source) in gyrofx_codegen::hdl::RTL_SOURCES {
        if !name.ends_with(".v") {
            continue;
        }
        for (number, line) in source.lines().enumerate() {
            if untyped(line) {
                found.push(format!("{name}:{}: {}", number + 1, line.trim()));
            }
        }
    }
    assert!(found.is_empty(), "untyped:\n{}", found.join("\n"));
}

/// Whether a line declares a `parameter`/`localparam` with no type or range before its name,
/// given a number or an expression (string parameters name files and stay untyped).
fn untyped_declaration() -> impl Fn(&str) -> bool {
    |line: &str| {
        let line = line.trim_start();
        let rest = match line
            .strip_prefix("localparam ")
            .or_else(|| line.strip_prefix("parameter "))
        {
            Some(rest) => rest.trim_start(),
            None => return false,
        };
        let typed = ["integer ", "signed ", "[", "real "]
            .iter()
            .any(|t| rest.starts_with(t));
        let value = rest.split_once('=').map(|(_, v)| v.trim_start());
        !typed && value.is_some_and(|v| !v.starts_with('"'))
    }
}
