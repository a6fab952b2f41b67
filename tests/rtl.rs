//! The reference RTL on its own: lint-clean in Verilator and Icarus, synthesizable by yosys
//! without latches, and the requantizer checked exhaustively against the model on small
//! widths for every rounding and overflow mode.

mod common;

use std::path::{Path, PathBuf};

use common::run_tool;
use gyrofx_model::fx::{requantize, Format, Overflow, Rounding};

fn hdl(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("hdl").join(name)
}

#[test]
fn verilator_lint_is_clean_for_several_parameter_sets() {
    let dir = tempfile::tempdir().unwrap();
    let sources = [hdl("gyrofx_quantize.v"), hdl("gyrofx_kf.v")];
    let sources: Vec<&str> = sources.iter().map(|p| p.to_str().unwrap()).collect();
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
    for params in parameter_sets {
        let mut args = vec!["--lint-only", "-Wall", "--top-module", "gyrofx_kf"];
        args.extend_from_slice(params);
        args.extend_from_slice(&sources);
        let (ok, text) = run_tool("verilator", &args, dir.path());
        assert!(
            ok && text.trim().is_empty(),
            "verilator -Wall {params:?}:\n{text}"
        );
    }
}

const ALL_RTL: [&str; 6] = [
    "gyrofx_quantize.v",
    "gyrofx_kf.v",
    "gyrofx_sequencer.v",
    "gyrofx_bias_estimator.v",
    "gyrofx_calibration.v",
    "gyrofx_top.v",
];

#[test]
fn the_whole_chain_lints_clean_for_several_parameter_sets() {
    let dir = tempfile::tempdir().unwrap();
    let sources: Vec<String> = ALL_RTL
        .iter()
        .map(|n| hdl(n).to_string_lossy().into_owned())
        .collect();
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
    for params in parameter_sets {
        let mut args = vec!["--lint-only", "-Wall", "--top-module", "gyrofx_top"];
        args.extend_from_slice(params);
        args.extend(sources.iter().map(String::as_str));
        let (ok, text) = run_tool("verilator", &args, dir.path());
        assert!(
            ok && text.trim().is_empty(),
            "verilator -Wall {params:?}:\n{text}"
        );
    }
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
            hdl("gyrofx_kf.v").to_str().unwrap(),
            hdl("gyrofx_sequencer.v").to_str().unwrap(),
            hdl("gyrofx_bias_estimator.v").to_str().unwrap(),
            hdl("gyrofx_calibration.v").to_str().unwrap(),
            hdl("gyrofx_top.v").to_str().unwrap(),
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
}

/// Drives every input code of small formats through `gyrofx_quantize` in Icarus and compares
/// with `fx::requantize`, for all six rounding modes and both overflow modes.
#[test]
fn requantizer_rtl_matches_the_model_exhaustively() {
    let dir = tempfile::tempdir().unwrap();
    let cases = [
        (7u32, 3i32, 4u32, 0i32),
        (6, 4, 6, 3),
        (8, 5, 3, 1),
        (5, 2, 5, 2),
    ];
    for (in_w, in_f, out_w, out_f) in cases {
        let from = Format::signed(in_w, in_f).unwrap();
        let to = Format::signed(out_w, out_f).unwrap();
        for rounding in Rounding::ALL {
            for overflow in Overflow::ALL {
                let mut expected = String::new();
                for code in from.min_code()..=from.max_code() {
                    let q = requantize(code, in_f, to, rounding, overflow);
                    expected.push_str(&format!(
                        "{:x} {:x} {}\n",
                        from.to_bits(code),
                        to.to_bits(q.code),
                        u8::from(q.overflowed)
                    ));
                }
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
