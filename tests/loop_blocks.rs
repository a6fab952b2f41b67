//! The gyro loop's leaf blocks (`nco`, `demodulator`, `pi`, `cic`; `hdl/gyrofx_nco`,
//! `gyrofx_demodulator`, `gyrofx_pi`, `gyrofx_cic`, each in Verilog-2001 and VHDL-2008) at plans
//! other than a package's. A generated package has each at gyro A's loop plan, and the
//! end-to-end tests run those in Icarus, Verilator and GHDL and flip a bit in each. Here each
//! block's own `push_vectors` drives it at small, wrapping and saturating formats, odd
//! gains, a 63-bit accumulator, 74-bit CIC registers; `blocks_package` writes the block's
//! folder as `generate` does, and the package's Makefile runs its generated testbenches in
//! Icarus and GHDL; so are the modules' own defaults (their RTL parameters' defaults). The Verilog also lints clean under `verilator -Wall` for several parameter
//! sets and synthesizes in yosys without latches, and the RTL's defaults are the model's.

use std::path::{Path, PathBuf};

use crate::common::run_tool;
use gyrofx_codegen::block::Block;
use gyrofx_codegen::blocks::{cic, demodulator, nco, pi};
use gyrofx_codegen::generate::blocks_package;
use gyrofx_codegen::output_folder::Replace;
use gyrofx_codegen::rom::{self, Rom, RomFormat};
use gyrofx_codegen::text::Provenance;
use gyrofx_lab::simulate::{self, Options, Simulator};
use gyrofx_model::fx::{CoefficientFormat, Format, Overflow, Rounding};
use gyrofx_model::gyro_loop::{
    cic as cic_model, demodulator as demodulator_model, nco as nco_model, pi as pi_model,
    RtlParameter,
};

fn hdl(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("hdl").join(name)
}

fn fmt(text: &str) -> Format {
    text.parse().unwrap()
}

fn provenance() -> Provenance {
    Provenance {
        version: env!("CARGO_PKG_VERSION").to_string(),
        command: "cargo test --test main loop_blocks::".to_string(),
        config_sha256: "0".repeat(64),
    }
}

/// Writes `block` as a package of its own under `dir/name` and runs its testbenches in Icarus
/// and GHDL through the package's Makefile: both must pass every sample.
fn assert_passes(dir: &Path, name: &str, block: Block) {
    let rows = block.len();
    let out = dir.join(name);
    blocks_package(&[block], &provenance())
        .write_atomically(&out, Replace::IfOwned)
        .unwrap();
    for simulator in [Simulator::Icarus, Simulator::Ghdl] {
        let outcome = simulate::run(&out, simulator, &Options::default()).unwrap();
        let log: Vec<&str> = outcome.blocks.iter().map(|b| b.log.as_str()).collect();
        assert!(
            outcome.passed(),
            "{name} in {simulator:?}:\n{}",
            log.join("\n")
        );
        assert_eq!(
            outcome.blocks[0].report,
            vec![format!("PASS n={rows}")],
            "{name} in {simulator:?}"
        );
    }
}

/// The ROM image of `rom` as a block carries it: its `.mem` file name and text.
fn rom_entry(rom: &Rom) -> (String, String) {
    (
        RomFormat::Mem.file_name(&rom.name),
        rom::write(rom, RomFormat::Mem, &provenance()),
    )
}

#[test]
fn the_nco_passes_at_other_widths() {
    let dir = tempfile::tempdir().unwrap();
    for (name, spec, seed) in [
        ("default", nco_model::Spec::default(), 1),
        // A small ROM and a short accumulator.
        (
            "small",
            nco_model::Spec {
                phase_bits: 12,
                address_bits: 4,
                sine_width: 8,
                error_feedback: false,
            },
            2,
        ),
        // Error feedback: one bit carried (P = A + 3) and many.
        (
            "feedback_one_bit",
            nco_model::Spec {
                phase_bits: 9,
                address_bits: 6,
                sine_width: 12,
                error_feedback: true,
            },
            5,
        ),
        (
            "feedback",
            nco_model::Spec {
                error_feedback: true,
                ..nco_model::Spec::default()
            },
            6,
        ),
        // No truncation (P = A + 2), a wide sine.
        (
            "untruncated",
            nco_model::Spec {
                phase_bits: 8,
                address_bits: 6,
                sine_width: 24,
                error_feedback: false,
            },
            3,
        ),
        // A 63-bit accumulator.
        (
            "wide_phase",
            nco_model::Spec {
                phase_bits: 63,
                address_bits: 12,
                sine_width: 16,
                error_feedback: true,
            },
            4,
        ),
    ] {
        let plan = nco_model::Plan::new(&spec).unwrap();
        let mut block = nco::block(&plan, rom_entry(&Rom::gyro_loop_sine(&plan)));
        nco::push_vectors(&mut block, &plan, seed);
        assert_passes(dir.path(), name, block);
    }
}

#[test]
fn the_demodulator_passes_where_it_wraps_and_saturates() {
    let dir = tempfile::tempdir().unwrap();
    let small = |rounding, overflow, product: &str, output: &str, k| demodulator_model::Spec {
        input: fmt("s12.11"),
        reference: fmt("s9.8"),
        product: fmt(product),
        state: fmt("s20.15"),
        output: fmt(output),
        lowpass_shift: k,
        rounding,
        overflow,
    };
    for (name, spec, seed) in [
        // Products that wrap, floor everywhere, the shortest low-pass.
        (
            "floor_wrap",
            small(Rounding::Floor, Overflow::Wrap, "s8.7", "s10.9", 1),
            6,
        ),
        // Products that saturate, convergent, outputs narrower than the state.
        (
            "convergent_saturate",
            small(Rounding::Convergent, Overflow::Saturate, "s9.7", "s6.5", 5),
            7,
        ),
        (
            "round_wrap",
            small(Rounding::Round, Overflow::Wrap, "s10.8", "s8.6", 3),
            8,
        ),
        (
            "zero_saturate",
            small(Rounding::Zero, Overflow::Saturate, "s12.10", "s12.12", 2),
            9,
        ),
        (
            "ceil_wrap",
            small(Rounding::Ceil, Overflow::Wrap, "s14.12", "s9.7", 4),
            10,
        ),
    ] {
        let plan = demodulator_model::Plan::new(&spec).unwrap();
        let mut block = demodulator::block(&plan);
        let overflows = demodulator::push_vectors(&mut block, &plan, seed);
        assert!(overflows > 0, "{name} exercises no overflow");
        assert_passes(dir.path(), name, block);
    }
    // The module's own defaults (the RTL's parameter defaults), which no loop plan has.
    let plan = demodulator_model::Plan::new(&demodulator_model::Spec::default()).unwrap();
    let mut block = demodulator::block(&plan);
    demodulator::push_vectors(&mut block, &plan, 5);
    assert_passes(dir.path(), "default", block);
}

#[test]
fn the_pi_passes_with_other_gains_limits_and_formats() {
    let dir = tempfile::tempdir().unwrap();
    let small = |rounding, overflow, kp, ki, integrator: &str, output: &str| pi_model::Spec {
        input: fmt("s10.9"),
        kp,
        ki,
        kp_format: CoefficientFormat::Auto { width: 8 },
        ki_format: CoefficientFormat::Auto { width: 6 },
        integrator: fmt(integrator),
        integrator_limits: [-0.7, 0.45],
        output: fmt(output),
        rounding,
        overflow,
    };
    for (name, spec, seed) in [
        // Rounded integrator, a wrapping output, negative gains.
        (
            "negative_gains",
            small(
                Rounding::Floor,
                Overflow::Wrap,
                -0.75,
                -0.01,
                "s12.10",
                "s6.4",
            ),
            12,
        ),
        // An exact integrator (24 fraction bits >= ki·e's 13 + 9) and a saturating output.
        (
            "exact_integrator",
            small(
                Rounding::Convergent,
                Overflow::Saturate,
                1.5,
                0.003,
                "s26.24",
                "s5.3",
            ),
            13,
        ),
        (
            "round_saturate",
            small(
                Rounding::Round,
                Overflow::Saturate,
                0.3,
                0.2,
                "s8.6",
                "s12.10",
            ),
            14,
        ),
        (
            "zero_wrap",
            small(Rounding::Zero, Overflow::Wrap, 3.0, -0.05, "s14.11", "s7.5"),
            15,
        ),
        (
            "ceil_saturate",
            small(
                Rounding::Ceil,
                Overflow::Saturate,
                -0.1,
                0.9,
                "s9.7",
                "s9.7",
            ),
            16,
        ),
    ] {
        let plan = pi_model::Plan::new(&spec).unwrap();
        let mut block = pi::block(&plan);
        let overflows = pi::push_vectors(&mut block, &plan, seed);
        assert!(overflows > 0, "{name} exercises no clamp or overflow");
        assert_passes(dir.path(), name, block);
    }
    // The module's own defaults (the RTL's parameter defaults), which no loop plan has.
    let plan = pi_model::Plan::new(&pi_model::Spec::default()).unwrap();
    let mut block = pi::block(&plan);
    pi::push_vectors(&mut block, &plan, 11);
    assert_passes(dir.path(), "default", block);
}

#[test]
fn the_cic_passes_at_other_orders_rates_and_formats() {
    let dir = tempfile::tempdir().unwrap();
    let small = |stages, decimation, delay, taps, rounding, overflow, mid: &str, out: &str| {
        cic_model::Spec {
            input: fmt("s10.9"),
            stages,
            decimation,
            differential_delay: delay,
            shift: None,
            cic_output: fmt(mid),
            taps,
            passband: 0.2 / f64::from(delay),
            coefficients: CoefficientFormat::Auto { width: 12 },
            output: fmt(out),
            rounding,
            overflow,
        }
    };
    for (name, spec, samples, seed) in [
        // 74-bit registers (N = 5, R·M = 1024): the model's i128 path.
        (
            "wide_registers",
            cic_model::Spec {
                stages: 5,
                decimation: 512,
                differential_delay: 2,
                passband: 0.1,
                taps: 7,
                ..cic_model::Spec::default()
            },
            10_000,
            18,
        ),
        // The smallest: one stage, R = 2, no compensation, floor, wrapping outputs.
        (
            "smallest",
            small(1, 2, 1, 1, Rounding::Floor, Overflow::Wrap, "s10.9", "s7.7"),
            400,
            19,
        ),
        (
            "convergent_saturate",
            small(
                4,
                7,
                2,
                3,
                Rounding::Convergent,
                Overflow::Saturate,
                "s12.11",
                "s9.8",
            ),
            2000,
            20,
        ),
        (
            "round_wrap",
            small(
                2,
                33,
                1,
                9,
                Rounding::Round,
                Overflow::Wrap,
                "s14.13",
                "s11.10",
            ),
            3000,
            21,
        ),
        (
            "ceil_saturate",
            small(
                3,
                16,
                1,
                5,
                Rounding::Ceil,
                Overflow::Saturate,
                "s11.12",
                "s16.14",
            ),
            2000,
            22,
        ),
        // Saturating CIC outputs: an explicit shift that leaves the gain at 8.
        (
            "explicit_shift",
            cic_model::Spec {
                shift: Some(3),
                ..small(
                    2,
                    8,
                    1,
                    3,
                    Rounding::Zero,
                    Overflow::Saturate,
                    "s10.9",
                    "s12.9",
                )
            },
            1000,
            23,
        ),
    ] {
        let plan = cic_model::Plan::new(&spec).unwrap();
        let mut block = cic::block(&plan, rom_entry(&Rom::gyro_loop_cic(&plan)));
        let overflows = cic::push_vectors(&mut block, &plan, samples, seed);
        assert!(overflows > 0, "{name} exercises no overflow");
        assert_passes(dir.path(), name, block);
    }
    // The module's own defaults (the RTL's parameter defaults).
    let plan = cic_model::Plan::new(&cic_model::Spec::default()).unwrap();
    let mut block = cic::block(&plan, rom_entry(&Rom::gyro_loop_cic(&plan)));
    cic::push_vectors(&mut block, &plan, 12_000, 17);
    assert_passes(dir.path(), "default", block);
}

#[test]
fn the_loop_rtl_lints_clean_for_several_parameter_sets() {
    let dir = tempfile::tempdir().unwrap();
    let cases: [(&str, &[&[&str]]); 4] = [
        (
            "gyrofx_nco",
            &[
                &[],
                &["-GPHASE_W=8", "-GADDR_W=6", "-GSIN_W=24"],
                &["-GPHASE_W=63", "-GADDR_W=2"],
            ],
        ),
        (
            "gyrofx_demodulator",
            &[
                &[],
                &[
                    "-GSHIFT=1",
                    "-GPROD_W=8",
                    "-GPROD_F=7",
                    "-GSTATE_W=8",
                    "-GSTATE_F=7",
                    "-GOUT_F=7",
                    "-GOUT_W=8",
                ],
                &[
                    "-GROUNDING=0",
                    "-GSATURATE=0",
                    "-GSHIFT=24",
                    "-GOUT_W=40",
                    "-GOUT_F=38",
                ],
            ],
        ),
        (
            "gyrofx_pi",
            &[
                &[],
                &[
                    "-GINT_W=64",
                    "-GINT_F=57",
                    "-GINT_MIN=64'sd0",
                    "-GINT_MAX=64'sd1000",
                    "-GROUNDING=5",
                    "-GSATURATE=0",
                ],
                &[
                    "-GKP_W=4",
                    "-GKP_F=0",
                    "-GKP=4'sd3",
                    "-GOUT_W=8",
                    "-GOUT_F=0",
                ],
            ],
        ),
        (
            "gyrofx_cic",
            &[
                &[],
                &[
                    "-GSTAGES=1",
                    "-GDECIMATION=2",
                    "-GSHIFT=1",
                    "-GMID_F=23",
                    "-GMID_W=24",
                    "-GTAPS=1",
                    "-GDELAY=2",
                ],
                &[
                    "-GSTAGES=6",
                    "-GDECIMATION=4000",
                    "-GSHIFT=72",
                    "-GTAPS=15",
                    "-GROUNDING=0",
                    "-GSATURATE=0",
                ],
            ],
        ),
    ];
    for (top, sets) in cases {
        for params in sets {
            let mut args = vec!["--lint-only", "-Wall", "--top-module", top];
            args.extend_from_slice(params);
            let sources = [
                hdl("gyrofx_quantize.v").to_string_lossy().into_owned(),
                hdl(&format!("{top}.v")).to_string_lossy().into_owned(),
            ];
            args.extend(sources.iter().map(String::as_str));
            let (ok, text) = run_tool("verilator", &args, dir.path());
            assert!(
                ok && text.trim().is_empty(),
                "verilator -Wall {top} {params:?}:\n{text}"
            );
        }
    }
    // Icarus with every warning: silent.
    let mut args = vec!["-g2005", "-Wall", "-o", "loop.vvp"];
    let sources: Vec<String> = [
        "gyrofx_quantize.v",
        "gyrofx_nco.v",
        "gyrofx_demodulator.v",
        "gyrofx_pi.v",
        "gyrofx_cic.v",
    ]
    .iter()
    .map(|n| hdl(n).to_string_lossy().into_owned())
    .collect();
    args.extend(sources.iter().map(String::as_str));
    let (ok, text) = run_tool("iverilog", &args, dir.path());
    assert!(ok && text.trim().is_empty(), "{text}");
}

#[test]
fn yosys_synthesizes_the_loop_rtl_without_latches() {
    let dir = tempfile::tempdir().unwrap();
    // The RTL's default ROM_FILEs, from the default plans.
    let nco = nco_model::Plan::new(&nco_model::Spec::default()).unwrap();
    let cic = cic_model::Plan::new(&cic_model::Spec::default()).unwrap();
    for (file, rom) in [
        ("nco_sine.mem", Rom::gyro_loop_sine(&nco)),
        ("cic_taps.mem", Rom::gyro_loop_cic(&cic)),
    ] {
        std::fs::write(dir.path().join(file), rom_entry(&rom).1).unwrap();
    }
    for top in [
        "gyrofx_nco",
        "gyrofx_demodulator",
        "gyrofx_pi",
        "gyrofx_cic",
    ] {
        let script = format!(
            "read_verilog {} {}; synth -top {top}; select -assert-none t:$dlatch t:$_DLATCH_*; check -assert",
            hdl("gyrofx_quantize.v").display(),
            hdl(&format!("{top}.v")).display()
        );
        let (ok, text) = run_tool("yosys", &["-q", "-p", &script], dir.path());
        assert!(ok, "yosys {top}:\n{text}");
    }
}

/// The default parameter values of `file` (Verilog `parameter NAME = value` or VHDL
/// `NAME : type := value`), as integers; strings are skipped.
fn rtl_defaults(file: &str) -> Vec<(String, i128)> {
    let text = std::fs::read_to_string(hdl(file)).unwrap();
    let mut out = Vec::new();
    for line in text.lines().map(str::trim) {
        let (name, value) = if let Some(rest) = line.strip_prefix("parameter ") {
            let Some((left, right)) = rest.split_once('=') else {
                continue;
            };
            (left.split_whitespace().last().unwrap(), right)
        } else if let Some((left, right)) = line.split_once(":=") {
            let Some((name, _)) = left.split_once(':') else {
                continue;
            };
            if name.trim().contains(' ') {
                continue;
            }
            (name.trim(), right)
        } else {
            continue;
        };
        let value = value.trim().trim_end_matches([',', ';']).trim();
        // A negative Verilog literal is a minus and a sized one (`-24'sd6641270`).
        let (sign, value) = match value.strip_prefix('-') {
            Some(magnitude) if magnitude.contains("'sd") => (-1, magnitude),
            _ => (1, value),
        };
        let parsed = if let Some((width, digits)) = value.split_once("'sd") {
            let _: u32 = width.parse().unwrap();
            digits.parse::<i128>().ok().map(|v| sign * v)
        } else if let Some((width, digits)) = value.split_once("x\"") {
            let width: u32 = width.parse().unwrap();
            let bits = u128::from_str_radix(digits.trim_end_matches('"'), 16).unwrap();
            Some(Format::signed(width, 0).unwrap().from_bits(bits))
        } else {
            value.parse::<i128>().ok()
        };
        if let Some(v) = parsed {
            out.push((name.to_string(), v));
        }
    }
    out
}

/// The RTL's default parameters (both languages) are the model's default plans, so the
/// documented defaults describe one design.
#[test]
fn the_rtl_defaults_are_the_model_defaults() {
    let plans: [(&str, Vec<RtlParameter>); 4] = [
        (
            "gyrofx_nco",
            nco_model::Plan::new(&nco_model::Spec::default())
                .unwrap()
                .rtl_parameters(),
        ),
        (
            "gyrofx_demodulator",
            demodulator_model::Plan::new(&demodulator_model::Spec::default())
                .unwrap()
                .rtl_parameters(),
        ),
        (
            "gyrofx_pi",
            pi_model::Plan::new(&pi_model::Spec::default())
                .unwrap()
                .rtl_parameters(),
        ),
        (
            "gyrofx_cic",
            cic_model::Plan::new(&cic_model::Spec::default())
                .unwrap()
                .rtl_parameters(),
        ),
    ];
    for (module, parameters) in plans {
        for language in ["v", "vhd"] {
            let file = format!("{module}.{language}");
            let defaults = rtl_defaults(&file);
            for (name, value) in &parameters {
                let found = defaults.iter().find(|(n, _)| n == name);
                assert_eq!(
                    found.map(|f| f.1),
                    Some(*value),
                    "{file}: default of {name}"
                );
            }
        }
    }
}

/// The folded loop's RTL (both languages) has the parallel loop's parameters with the same
/// defaults, and its schedule's defaults are the default config's schedule.
#[test]
fn the_folded_loops_rtl_defaults_are_the_parallel_loops_and_the_default_schedule() {
    use gyrofx_model::gyro_loop::folded::Schedule;
    use gyrofx_model::gyro_loop::gyro::{Plan as LoopPlan, Spec as LoopSpec};

    let schedule = Schedule::new(&LoopPlan::new(&LoopSpec::paper_004()).unwrap()).unwrap();
    for language in ["v", "vhd"] {
        let parallel = rtl_defaults(&format!("gyrofx_gyro_loop.{language}"));
        let folded = rtl_defaults(&format!("gyrofx_gyro_loop_serial.{language}"));
        assert!(
            parallel.len() > 60,
            "{language}: {} defaults parsed",
            parallel.len()
        );
        for (name, value) in &parallel {
            let found = folded.iter().find(|(n, _)| n == name).map(|f| f.1);
            assert_eq!(
                found,
                Some(*value),
                "gyrofx_gyro_loop_serial.{language}: {name}"
            );
        }
        for (name, value) in [
            ("SCHEDULE_LEN", schedule.len()),
            ("SCHEDULE_REGULAR", schedule.regular),
            ("RAM_WORDS", schedule.words.count()),
        ] {
            let found = folded.iter().find(|(n, _)| n == name).map(|f| f.1);
            assert_eq!(
                found,
                Some(value as i128),
                "gyrofx_gyro_loop_serial.{language}: {name}"
            );
        }
    }
}

/// Each `<field>_field` the folded loop's RTL (both languages) slices out of the control word is
/// the field of the model's layout (`folded::FIELDS`: name, width, offset from bit 0), and every
/// field the layout has is sliced, so a moved or resized field fails here. The one-gyro loop
/// leaves out the pair's fields (which gyro each unit serves, the decimating-only write), and
/// its schedule leaves them 0.
#[test]
fn the_folded_loops_rtl_slices_the_models_control_word_fields() {
    use gyrofx_model::gyro_loop::folded::{Schedule, FIELDS};
    use gyrofx_model::gyro_loop::gyro::{Plan as LoopPlan, Spec as LoopSpec};

    let pair_only = |name: &str| name.ends_with("_gyro") || name == "decimating_write";
    let mut offset = 0;
    let mut pair_bits = 0u64;
    let layout: Vec<(String, u32, u32)> = FIELDS
        .iter()
        .map(|&(name, width)| {
            offset += width;
            if pair_only(name) {
                pair_bits |= ((1u64 << width) - 1) << (offset - width);
            }
            (name.to_string(), offset - 1, offset - width)
        })
        .filter(|(name, ..)| !pair_only(name))
        .collect();
    let schedule = Schedule::new(&LoopPlan::new(&LoopSpec::paper_004()).unwrap()).unwrap();
    assert!(schedule.encoded().iter().all(|w| w & pair_bits == 0));
    for language in ["v", "vhd"] {
        let text =
            std::fs::read_to_string(hdl(&format!("gyrofx_gyro_loop_serial.{language}"))).unwrap();
        let mut sliced = Vec::new();
        for line in text.lines() {
            // Most fields act from the word executing (control_reg); x and y are decoded a
            // clock earlier from the word fetched (fetched_reg).
            let Some((left, right)) = line
                .split_once("control_reg")
                .or_else(|| line.split_once("fetched_reg"))
            else {
                continue;
            };
            let Some(name) = left
                .split_whitespace()
                .find_map(|word| word.strip_suffix("_field"))
            else {
                continue;
            };
            let bounds: String = right
                .chars()
                .skip(1)
                .take_while(|c| *c != ']' && *c != ')')
                .collect();
            let numbers: Vec<u32> = bounds
                .split(|c: char| !c.is_ascii_digit())
                .filter(|s| !s.is_empty())
                .map(|s| s.parse().unwrap())
                .collect();
            let (high, low) = match numbers[..] {
                [bit] => (bit, bit),
                [high, low] => (high, low),
                _ => panic!("{language}: {line}"),
            };
            sliced.push((name.to_string(), high, low));
        }
        sliced.sort_by_key(|(_, _, low)| *low);
        assert_eq!(sliced, layout, "gyrofx_gyro_loop_serial.{language}");
    }
}
