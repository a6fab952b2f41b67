//! The gyro-loop blocks' RTL (`hdl/gyrofx_nco.v`, `gyrofx_demodulator.v`, `gyrofx_pi.v`,
//! `gyrofx_cic.v`) proven bit-exact with the model: each test resolves a few plans, drives the
//! fixed model with random and directed stimulus, writes stimulus and expected outputs as hex
//! files, and runs a small self-checking testbench that compares every output bit for bit.
//! Every configuration runs in Icarus, the defaults also in Verilator; and a testbench given
//! one flipped expected bit must fail.

mod common;

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use common::run_tool;
use gyrofx_model::fx::{CoefficientFormat, Format, Overflow, Rounding};
use gyrofx_model::gyro_loop::{cic, demodulator, nco, pi, RtlParameter};

fn hdl(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("hdl").join(name)
}

fn fmt(text: &str) -> Format {
    text.parse().unwrap()
}

/// A port of the DUT carried in the vector files.
#[derive(Clone, Debug)]
struct Port {
    name: &'static str,
    format: Format,
}

impl Port {
    fn new(name: &'static str, format: Format) -> Self {
        Port { name, format }
    }

    fn flag(name: &'static str) -> Self {
        Port::new(name, Format::new(false, 1, 0).unwrap())
    }

    fn hex(&self, code: i128) -> String {
        format!(
            "{:0digits$x}",
            self.format.to_bits(code),
            digits = self.format.hex_digits()
        )
    }
}

/// One clock of stimulus: `rst`, `ce`, the input codes; and what to expect after it.
#[derive(Clone, Debug)]
struct Line {
    rst: bool,
    ce: bool,
    inputs: Vec<i128>,
    /// `None`: nothing is compared after this clock.
    expected: Option<Expected>,
}

#[derive(Clone, Debug)]
struct Expected {
    valid: bool,
    outputs: Vec<i128>,
}

/// A DUT, its parameters and ROMs, and its vectors.
struct Bench {
    module: &'static str,
    parameters: Vec<(String, String)>,
    roms: Vec<(String, String)>,
    inputs: Vec<Port>,
    outputs: Vec<Port>,
    valid: &'static str,
    lines: Vec<Line>,
    /// Values the model wrapped, saturated or clamped while computing the expected outputs:
    /// the configurations meant to exercise those paths must have some.
    overflows: u64,
}

impl Bench {
    fn stimulus_file(&self) -> String {
        let mut out = String::from("// rst:u1.0 ce:u1.0");
        for p in &self.inputs {
            let _ = write!(out, " {}:{}", p.name, p.format);
        }
        out.push('\n');
        for line in &self.lines {
            let _ = write!(out, "{} {}", u8::from(line.rst), u8::from(line.ce));
            for (p, code) in self.inputs.iter().zip(&line.inputs) {
                let _ = write!(out, " {}", p.hex(*code));
            }
            out.push('\n');
        }
        out
    }

    fn expected_file(&self) -> String {
        let mut out = format!("// check:u1.0 {}:u1.0", self.valid);
        for p in &self.outputs {
            let _ = write!(out, " {}:{}", p.name, p.format);
        }
        out.push('\n');
        for line in &self.lines {
            match &line.expected {
                None => {
                    let _ = write!(out, "0 0");
                    for p in &self.outputs {
                        let _ = write!(out, " {}", p.hex(0));
                    }
                }
                Some(e) => {
                    let _ = write!(out, "1 {}", u8::from(e.valid));
                    for (p, code) in self.outputs.iter().zip(&e.outputs) {
                        let _ = write!(out, " {}", p.hex(*code));
                    }
                }
            }
            out.push('\n');
        }
        out
    }

    /// The self-checking testbench: one sample per clock with `ce`, an idle clock after
    /// every third; after each clock whose line is checked, compares the valid flag and (when
    /// valid) every output; prints the first mismatches, then PASS or FAIL, and exits
    /// non-zero on a mismatch.
    fn testbench(&self) -> String {
        let decl = |kind: &str, prefix: &str, p: &Port| {
            format!("{kind} [{}:0] {prefix}{};\n", p.format.width - 1, p.name)
        };
        let mut tb = String::from(
            "`timescale 1ns / 1ps\nmodule tb;\nreg clk = 1'b0;\nalways #5 clk = ~clk;\nreg rst = 1'b1;\nreg ce = 1'b0;\n",
        );
        for p in &self.inputs {
            tb += &decl("reg", "", p);
            tb += &decl("reg", "v_", p);
        }
        for p in &self.outputs {
            tb += &decl("wire", "", p);
            tb += &decl("reg", "e_", p);
        }
        let _ = writeln!(tb, "wire {};", self.valid);
        let params: Vec<String> = self
            .parameters
            .iter()
            .map(|(n, v)| format!(".{n}({v})"))
            .collect();
        let mut ports = vec![
            ".clk(clk)".to_string(),
            ".rst(rst)".into(),
            ".ce(ce)".into(),
        ];
        ports.extend(
            self.inputs
                .iter()
                .chain(&self.outputs)
                .map(|p| format!(".{0}({0})", p.name)),
        );
        ports.push(format!(".{0}({0})", self.valid));
        let _ = writeln!(
            tb,
            "{} #({}) dut ({});",
            self.module,
            params.join(", "),
            ports.join(", ")
        );
        let stimulus_fields = 2 + self.inputs.len();
        let expected_fields = 2 + self.outputs.len();
        let scan = |n: usize| vec!["%h"; n].join(" ");
        let stimulus_vars: Vec<String> = ["v_rst", "v_ce"]
            .iter()
            .map(|s| s.to_string())
            .chain(self.inputs.iter().map(|p| format!("v_{}", p.name)))
            .collect();
        let expected_vars: Vec<String> = ["e_check", "e_valid"]
            .iter()
            .map(|s| s.to_string())
            .chain(self.outputs.iter().map(|p| format!("e_{}", p.name)))
            .collect();
        let assign_inputs: String = self
            .inputs
            .iter()
            .map(|p| format!("        {0} = v_{0};\n", p.name))
            .collect();
        // Strobes such as `preset` act without `ce`: every input is low between samples.
        let clear_inputs: String = self
            .inputs
            .iter()
            .map(|p| format!("        {} = 0;\n", p.name))
            .collect();
        let compare: Vec<String> = self
            .outputs
            .iter()
            .map(|p| format!("{0} !== e_{0}", p.name))
            .collect();
        let show: String = self
            .outputs
            .iter()
            .map(|p| {
                format!(
                    "            $display(\"  {0} expected %h actual %h\", e_{0}, {0});\n",
                    p.name
                )
            })
            .collect();
        let _ = write!(
            tb,
            "integer sfd, efd, n, index, errors, checked;
reg [8*1024-1:0] header;
reg v_rst, v_ce, e_check, e_valid;
initial begin
    sfd = $fopen(\"stimulus.hex\", \"r\");
    efd = $fopen(\"expected.hex\", \"r\");
    if (sfd == 0 || efd == 0) $fatal(1, \"cannot open the vectors\");
    n = $fgets(header, sfd);
    n = $fgets(header, efd);
    errors = 0;
    checked = 0;
    index = 0;
    @(posedge clk);
    @(posedge clk);
    #1 rst = 1'b0;
    n = $fscanf(sfd, \"{stimulus_scan}\\n\", {stimulus_vars});
    while (n == {stimulus_fields}) begin
        if ($fscanf(efd, \"{expected_scan}\\n\", {expected_vars}) != {expected_fields})
            $fatal(1, \"expected.hex ends early at sample %0d\", index);
        rst = v_rst;
        ce = v_ce;
{assign_inputs}        @(posedge clk);
        #1;
        rst = 1'b0;
        ce = 1'b0;
{clear_inputs}        if (e_check) begin
            checked = checked + 1;
            if ({valid} !== e_valid || (e_valid && ({compare}))) begin
                errors = errors + 1;
                if (errors <= 10) begin
                    $display(\"MISMATCH sample %0d {valid} expected %b actual %b\", index, e_valid, {valid});
{show}                end
            end
        end
        if (index % 3 == 2) begin
            @(posedge clk);
            #1;
        end
        index = index + 1;
        n = $fscanf(sfd, \"{stimulus_scan}\\n\", {stimulus_vars});
    end
    if (errors != 0) begin
        $display(\"FAIL mismatches=%0d n=%0d\", errors, index);
        $fatal(1, \"FAIL\");
    end
    $display(\"PASS n=%0d checked=%0d\", index, checked);
    $finish;
end
endmodule
",
            stimulus_scan = scan(stimulus_fields),
            stimulus_vars = stimulus_vars.join(", "),
            expected_scan = scan(expected_fields),
            expected_vars = expected_vars.join(", "),
            valid = self.valid,
            compare = compare.join(" || "),
        );
        tb
    }

    fn write(&self, dir: &Path) {
        std::fs::write(dir.join("stimulus.hex"), self.stimulus_file()).unwrap();
        std::fs::write(dir.join("expected.hex"), self.expected_file()).unwrap();
        std::fs::write(dir.join("tb.v"), self.testbench()).unwrap();
        for (name, contents) in &self.roms {
            std::fs::write(dir.join(name), contents).unwrap();
        }
    }

    fn sources(&self) -> Vec<String> {
        vec![
            hdl("gyrofx_quantize.v").to_string_lossy().into_owned(),
            hdl(&format!("{}.v", self.module))
                .to_string_lossy()
                .into_owned(),
            "tb.v".into(),
        ]
    }

    /// Runs the testbench in Icarus; returns whether it passed and its output.
    fn icarus(&self, dir: &Path) -> (bool, String) {
        let mut args = vec!["-g2005", "-o", "tb.vvp"];
        let sources = self.sources();
        args.extend(sources.iter().map(String::as_str));
        let (ok, text) = run_tool("iverilog", &args, dir);
        assert!(ok, "iverilog {}:\n{text}", self.module);
        run_tool("vvp", &["-n", "tb.vvp"], dir)
    }

    /// Builds and runs the testbench with Verilator.
    fn verilator(&self, dir: &Path) -> (bool, String) {
        let mut args = vec![
            "--binary",
            "--timing",
            "-Wno-fatal",
            "-Wno-lint",
            "-Wno-style",
            "-O0",
            "--top-module",
            "tb",
            "-Mdir",
            "obj",
        ];
        let sources = self.sources();
        args.extend(sources.iter().map(String::as_str));
        let (ok, text) = run_tool("verilator", &args, dir);
        assert!(ok, "verilator {}:\n{text}", self.module);
        run_tool("./obj/Vtb", &[], dir)
    }

    /// Runs in Icarus (and Verilator when asked) and asserts PASS with every checked line.
    fn assert_passes(&self, verilator: bool) {
        let dir = tempfile::tempdir().unwrap();
        self.write(dir.path());
        let checked = self.lines.iter().filter(|l| l.expected.is_some()).count();
        let want = format!("PASS n={} checked={checked}", self.lines.len());
        let (ok, text) = self.icarus(dir.path());
        assert!(
            ok && text.contains(&want),
            "Icarus {}:\n{text}",
            self.module
        );
        if verilator {
            let (ok, text) = self.verilator(dir.path());
            assert!(
                ok && text.contains(&want),
                "Verilator {}:\n{text}",
                self.module
            );
        }
    }

    /// Flips the lowest bit of the last output of a checked, valid line near the middle and
    /// asserts that the testbench fails, naming that sample.
    fn assert_a_flipped_bit_fails(&self) {
        let mut flipped = Bench {
            module: self.module,
            parameters: self.parameters.clone(),
            roms: self.roms.clone(),
            inputs: self.inputs.clone(),
            outputs: self.outputs.clone(),
            valid: self.valid,
            lines: self.lines.clone(),
            overflows: self.overflows,
        };
        let index = (self.lines.len() / 2..self.lines.len())
            .chain(0..self.lines.len())
            .find(|k| matches!(&self.lines[*k].expected, Some(e) if e.valid))
            .expect("a checked, valid line");
        let last = self.outputs.len() - 1;
        let expected = flipped.lines[index].expected.as_mut().unwrap();
        let format = self.outputs[last].format;
        expected.outputs[last] = format.from_bits(format.to_bits(expected.outputs[last]) ^ 1);
        let dir = tempfile::tempdir().unwrap();
        flipped.write(dir.path());
        let (ok, text) = flipped.icarus(dir.path());
        assert!(
            !ok && text.contains(&format!("MISMATCH sample {index} ")) && text.contains("FAIL"),
            "a flipped bit at sample {index} passed {}:\n{text}",
            self.module
        );
    }
}

/// A Verilog literal for parameter `name` of a plan: sized signed hex for the codes the RTL
/// declares with a width, plain decimal otherwise.
fn parameter_literal(name: &str, value: i128, all: &[RtlParameter]) -> String {
    let width_of = |w: &str| all.iter().find(|p| p.0 == w).unwrap().1 as u32;
    let width = match name {
        "KP" => Some(width_of("KP_W")),
        "KI" => Some(width_of("KI_W")),
        "INT_MIN" | "INT_MAX" => Some(width_of("INT_W")),
        _ => None,
    };
    match width {
        Some(w) => format!("{w}'sh{:x}", Format::signed(w, 0).unwrap().to_bits(value)),
        None => value.to_string(),
    }
}

fn parameters(all: &[RtlParameter]) -> Vec<(String, String)> {
    all.iter()
        .map(|(n, v)| (n.to_string(), parameter_literal(n, *v, all)))
        .collect()
}

fn rom_image(format: Format, codes: &[i128]) -> String {
    let port = Port::new("rom", format);
    let mut out = format!("// {format}\n");
    for c in codes {
        out += &port.hex(*c);
        out.push('\n');
    }
    out
}

/// A deterministic stream of pseudo-random words.
struct Lcg(u64);

impl Lcg {
    fn next(&mut self) -> u64 {
        self.0 = self
            .0
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        self.0 ^ (self.0 >> 29)
    }

    /// A code of `format`, uniform over its range.
    fn code(&mut self, format: Format) -> i128 {
        format.from_bits(u128::from(self.next()))
    }
}

// ---------------------------------------------------------------- NCO

fn nco_bench(spec: nco::Spec, seed: u64) -> Bench {
    let plan = nco::Plan::new(&spec).unwrap();
    let mut model = nco::FixedNco::new(&plan);
    let phase = plan.phase;
    let mut rng = Lcg(seed);
    let bin = 1u64 << (phase.width - plan.address_bits - 2);
    let mut stimulus: Vec<(bool, bool, u64, u64)> = Vec::new();
    // Every bin, in both quadrant orders, then with a quarter-cycle offset.
    let bins = 1usize << (plan.address_bits + 2);
    stimulus.extend((0..bins.min(4096)).map(|_| (false, true, bin, 0)));
    stimulus.extend((0..64).map(|_| {
        (
            false,
            true,
            bin.wrapping_neg() & (u64::MAX >> (64 - phase.width)),
            1 << (phase.width - 2),
        )
    }));
    // A reset with ce high (rst wins), the largest frequency word, random words.
    stimulus.push((true, true, 5, 5));
    stimulus.extend((0..32).map(|_| (false, true, u64::MAX >> (64 - phase.width), 0)));
    for k in 0..2000 {
        let reset = k % 700 == 699;
        stimulus.push((reset, !reset, rng.next(), rng.next()));
    }
    let mask = u64::MAX >> (64 - phase.width);
    let lines = stimulus
        .into_iter()
        .map(|(rst, ce, freq, offset)| {
            let (freq, offset) = (freq & mask, offset & mask);
            let expected = if rst {
                model.reset();
                None
            } else {
                let r = model.step(freq, offset);
                Some(Expected {
                    valid: true,
                    outputs: vec![i128::from(r.sin), i128::from(r.cos)],
                })
            };
            Line {
                rst,
                ce,
                inputs: vec![i128::from(freq), i128::from(offset)],
                expected,
            }
        })
        .collect();
    let mut parameters = parameters(&plan.rtl_parameters());
    parameters.push(("ROM_FILE".into(), "\"nco_sine.mem\"".into()));
    Bench {
        module: "gyrofx_nco",
        parameters,
        roms: vec![(
            "nco_sine.mem".into(),
            rom_image(plan.output, plan.rom_codes()),
        )],
        inputs: vec![Port::new("freq", phase), Port::new("offset", phase)],
        outputs: vec![
            Port::new("sin_out", plan.output),
            Port::new("cos_out", plan.output),
        ],
        valid: "out_valid",
        lines,
        overflows: 0,
    }
}

#[test]
fn the_nco_rtl_is_bit_exact() {
    let default = nco_bench(nco::Spec::default(), 1);
    default.assert_passes(true);
    default.assert_a_flipped_bit_fails();
    for (spec, seed) in [
        // A small ROM and a short accumulator.
        (
            nco::Spec {
                phase_bits: 12,
                address_bits: 4,
                sine_width: 8,
            },
            2,
        ),
        // No truncation (P = A + 2), a wide sine.
        (
            nco::Spec {
                phase_bits: 8,
                address_bits: 6,
                sine_width: 24,
            },
            3,
        ),
        // A 63-bit accumulator.
        (
            nco::Spec {
                phase_bits: 63,
                address_bits: 12,
                sine_width: 16,
            },
            4,
        ),
    ] {
        nco_bench(spec, seed).assert_passes(false);
    }
}

// ---------------------------------------------------------------- demodulator

fn demodulator_bench(spec: demodulator::Spec, seed: u64) -> Bench {
    let plan = demodulator::Plan::new(&spec).unwrap();
    let mut model = demodulator::FixedDemodulator::new(&plan);
    let mut rng = Lcg(seed);
    let (x_format, r_format) = (plan.input, plan.reference);
    let mut stimulus: Vec<(bool, bool, [i128; 3])> = Vec::new();
    // The extremes: the largest products (min × min) and their neighbours.
    let corners = [x_format.min_code(), x_format.max_code(), 0, -1];
    let r_corners = [r_format.min_code(), r_format.max_code(), 1, -1];
    for (k, x) in corners.iter().enumerate() {
        for r in r_corners {
            stimulus.extend((0..5).map(|_| (false, true, [*x, r, r_corners[k]])));
        }
    }
    // A sine through an NCO-like reference, long enough for the low-pass to settle.
    let nco_plan = nco::Plan::new(&nco::Spec {
        phase_bits: 32,
        address_bits: 8,
        sine_width: r_format.width,
    })
    .unwrap();
    let mut nco = nco::FixedNco::new(&nco_plan);
    let freq = nco_plan.frequency_word(8195.0, 200_000.0).unwrap();
    let amplitude = (x_format.max_code() / 2) as f64;
    for n in 0..1500 {
        let r = nco.step(freq, 0);
        let x = (amplitude * (0.2578 * n as f64 + 0.7).sin()).round() as i128;
        stimulus.push((false, true, [x, i128::from(r.sin), i128::from(r.cos)]));
    }
    stimulus.push((true, true, [1, 1, 1]));
    for k in 0..1500 {
        let reset = k == 900;
        stimulus.push((
            reset,
            !reset,
            [rng.code(x_format), rng.code(r_format), rng.code(r_format)],
        ));
    }
    let lines = stimulus
        .into_iter()
        .map(|(rst, ce, [x, s, c])| {
            let expected = if rst {
                model.reset();
                None
            } else {
                let out = model.step(
                    x as i64,
                    nco::Reference {
                        sin: s as i64,
                        cos: c as i64,
                    },
                );
                Some(Expected {
                    valid: true,
                    outputs: vec![i128::from(out.i), i128::from(out.q)],
                })
            };
            Line {
                rst,
                ce,
                inputs: vec![x, s, c],
                expected,
            }
        })
        .collect();
    Bench {
        module: "gyrofx_demodulator",
        parameters: parameters(&plan.rtl_parameters()),
        roms: vec![],
        inputs: vec![
            Port::new("adc", x_format),
            Port::new("ref_sin", r_format),
            Port::new("ref_cos", r_format),
        ],
        outputs: vec![
            Port::new("i_out", plan.output.to),
            Port::new("q_out", plan.output.to),
        ],
        valid: "out_valid",
        lines,
        overflows: {
            let c = model.overflow_counts();
            c.product.iter().chain(&c.state).chain(&c.output).sum()
        },
    }
}

#[test]
fn the_demodulator_rtl_is_bit_exact() {
    let default = demodulator_bench(demodulator::Spec::default(), 5);
    default.assert_passes(true);
    default.assert_a_flipped_bit_fails();
    let small = |rounding, overflow, product: &str, output: &str, k| demodulator::Spec {
        input: fmt("s12.11"),
        reference: fmt("s9.8"),
        product: fmt(product),
        state: fmt("s20.15"),
        output: fmt(output),
        lowpass_shift: k,
        rounding,
        overflow,
    };
    for (spec, seed) in [
        // Products that wrap, floor everywhere, the shortest low-pass.
        (
            small(Rounding::Floor, Overflow::Wrap, "s8.7", "s10.9", 1),
            6,
        ),
        // Products that saturate, convergent, outputs narrower than the state.
        (
            small(Rounding::Convergent, Overflow::Saturate, "s9.7", "s6.5", 5),
            7,
        ),
        (
            small(Rounding::Round, Overflow::Wrap, "s10.8", "s8.6", 3),
            8,
        ),
        (
            small(Rounding::Zero, Overflow::Saturate, "s12.10", "s12.12", 2),
            9,
        ),
        (
            small(Rounding::Ceil, Overflow::Wrap, "s14.12", "s9.7", 4),
            10,
        ),
    ] {
        let bench = demodulator_bench(spec, seed);
        assert!(
            bench.overflows > 0,
            "{} exercises no overflow",
            bench.module
        );
        bench.assert_passes(false);
    }
}

// ---------------------------------------------------------------- PI

fn pi_bench(spec: pi::Spec, seed: u64) -> Bench {
    let plan = pi::Plan::new(&spec).unwrap();
    let mut model = pi::FixedPi::new(&plan);
    let mut rng = Lcg(seed);
    let e_format = plan.input;
    let v_format = plan.integrator;
    // (rst, ce, err, preset, preset_value)
    let mut stimulus: Vec<(bool, bool, i128, bool, i128)> = Vec::new();
    // Wind up against both limits and back.
    stimulus.extend((0..600).map(|_| (false, true, e_format.max_code(), false, 0)));
    stimulus.extend((0..600).map(|_| (false, true, e_format.min_code(), false, 0)));
    // Presets with ce (loaded before the update), without ce (only loaded), beyond the
    // limits, and a reset that wins over both.
    let mid = (plan.limits[0] + plan.limits[1]) / 2;
    let above = (plan.limits[1] + 1).min(v_format.max_code());
    for value in [mid, above, v_format.min_code(), v_format.max_code()] {
        stimulus.push((false, true, 3, true, value));
        stimulus.extend((0..4).map(|_| (false, true, -7, false, 0)));
        stimulus.push((false, false, 0, true, value));
        stimulus.extend((0..4).map(|_| (false, true, 11, false, 0)));
    }
    stimulus.push((true, true, 5, true, mid));
    for _ in 0..2500 {
        let r = rng.next();
        let (rst, preset) = (r.is_multiple_of(600), r.is_multiple_of(97));
        let ce = !rst && !r.is_multiple_of(101);
        stimulus.push((rst, ce, rng.code(e_format), preset, rng.code(v_format)));
    }
    let lines = stimulus
        .into_iter()
        .map(|(rst, ce, e, preset, value)| {
            let expected = if rst {
                model.reset();
                None
            } else {
                if preset {
                    model.preset(value as i64);
                }
                ce.then(|| Expected {
                    valid: true,
                    outputs: vec![i128::from(model.step(e as i64))],
                })
            };
            Line {
                rst,
                ce,
                inputs: vec![e, i128::from(preset), value],
                expected,
            }
        })
        .collect();
    Bench {
        module: "gyrofx_pi",
        parameters: parameters(&plan.rtl_parameters()),
        roms: vec![],
        inputs: vec![
            Port::new("err", e_format),
            Port::flag("preset"),
            Port::new("preset_value", v_format),
        ],
        outputs: vec![Port::new("u_out", plan.output.to)],
        valid: "out_valid",
        lines,
        overflows: {
            let c = model.overflow_counts();
            c.integrator_clamped + c.output
        },
    }
}

#[test]
fn the_pi_rtl_is_bit_exact() {
    let default = pi_bench(pi::Spec::default(), 11);
    default.assert_passes(true);
    default.assert_a_flipped_bit_fails();
    let small = |rounding, overflow, kp, ki, integrator: &str, output: &str| pi::Spec {
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
    for (spec, seed) in [
        // Rounded integrator, a wrapping output, negative gains.
        (
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
            small(Rounding::Zero, Overflow::Wrap, 3.0, -0.05, "s14.11", "s7.5"),
            15,
        ),
        (
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
        let bench = pi_bench(spec, seed);
        assert!(
            bench.overflows > 0,
            "{} exercises no overflow",
            bench.module
        );
        bench.assert_passes(false);
    }
}

// ---------------------------------------------------------------- CIC

fn cic_bench(spec: cic::Spec, samples: usize, seed: u64) -> Bench {
    let plan = cic::Plan::new(&spec).unwrap();
    let mut model = cic::FixedCic::new(&plan);
    let mut rng = Lcg(seed);
    let x_format = plan.input;
    let r = plan.decimation as usize;
    let mut stimulus: Vec<(bool, bool, i128)> = Vec::new();
    // Full scale for a while (the integrators wrap), then the most negative code, then
    // random codes with a reset in the middle of a decimation period.
    stimulus.extend((0..samples / 4).map(|_| (false, true, x_format.max_code())));
    stimulus.extend((0..samples / 4).map(|_| (false, true, x_format.min_code())));
    for k in 0..samples / 2 {
        let reset = k == samples / 4 + r / 3;
        stimulus.push((reset, !reset, rng.code(x_format)));
    }
    stimulus.push((true, true, 3));
    stimulus.extend((0..3 * r).map(|_| (false, true, rng.code(x_format))));
    let lines = stimulus
        .into_iter()
        .map(|(rst, ce, x)| {
            let expected = if rst {
                model.reset();
                None
            } else {
                let y = model.step(x as i64);
                Some(Expected {
                    valid: y.is_some(),
                    outputs: vec![i128::from(y.unwrap_or(0))],
                })
            };
            Line {
                rst,
                ce,
                inputs: vec![x],
                expected,
            }
        })
        .collect();
    let mut parameters = parameters(&plan.rtl_parameters());
    parameters.push(("ROM_FILE".into(), "\"cic_taps.mem\"".into()));
    Bench {
        module: "gyrofx_cic",
        parameters,
        roms: vec![(
            "cic_taps.mem".into(),
            rom_image(plan.taps[0].format, &plan.tap_codes()),
        )],
        inputs: vec![Port::new("x", x_format)],
        outputs: vec![Port::new("y", plan.output.to)],
        valid: "y_valid",
        lines,
        overflows: {
            let c = model.overflow_counts();
            c.cic + c.output
        },
    }
}

#[test]
fn the_cic_rtl_is_bit_exact() {
    let default = cic_bench(cic::Spec::default(), 24_000, 17);
    default.assert_passes(true);
    default.assert_a_flipped_bit_fails();
    let small =
        |stages, decimation, delay, taps, rounding, overflow, mid: &str, out: &str| cic::Spec {
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
        };
    for (spec, samples, seed) in [
        // 74-bit registers (N = 5, R·M = 1024): the model's i128 path.
        (
            cic::Spec {
                stages: 5,
                decimation: 512,
                differential_delay: 2,
                passband: 0.1,
                taps: 7,
                ..cic::Spec::default()
            },
            20_000,
            18,
        ),
        // The smallest: one stage, R = 2, no compensation, floor, wrapping outputs.
        (
            small(1, 2, 1, 1, Rounding::Floor, Overflow::Wrap, "s10.9", "s7.7"),
            400,
            19,
        ),
        (
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
            cic::Spec {
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
        let bench = cic_bench(spec, samples, seed);
        assert!(
            bench.overflows > 0,
            "{} exercises no overflow",
            bench.module
        );
        bench.assert_passes(false);
    }
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
    let nco = nco::Plan::new(&nco::Spec::default()).unwrap();
    std::fs::write(
        dir.path().join("nco_sine.mem"),
        rom_image(nco.output, nco.rom_codes()),
    )
    .unwrap();
    let cic = cic::Plan::new(&cic::Spec::default()).unwrap();
    std::fs::write(
        dir.path().join("cic_taps.mem"),
        rom_image(cic.taps[0].format, &cic.tap_codes()),
    )
    .unwrap();
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
