//! The loop's proven ranges are tight and hold for every input.
//!
//! Tightness: the real fixed-point blocks of the default loop (its formats widened to the
//! proven ones, so that nothing saturates), fed each node's adversarial input — the ADC's
//! extremes against the NCO's extreme codes, held; a constant error at either end until the
//! integrator clamps; the CIC cascade's impulse-response sign pattern at full scale — reach
//! at least 90 % of every proven range, and the proven format one integer bit narrower cannot
//! hold what they reach. On the default formats, the same inputs overflow exactly the nodes the
//! analysis says can. Soundness: proptests over random plans and inputs (extremes held,
//! random codes, the adversarial patterns) find no value outside its proven range, block by
//! block and for the whole loop wired as `gyro_loop::gyro` wires it.

use std::collections::{BTreeMap, VecDeque};

use proptest::prelude::*;

use super::*;
use crate::fx::{CoefficientFormat, Format, Overflow, Quantizer, Rounding};
use crate::gyro_loop::cic::{FixedCic, FloatCic};
use crate::gyro_loop::demodulator::FixedDemodulator;
use crate::gyro_loop::gyro::{FixedGyroLoop, LoopSettings, Plan, Spec};
use crate::gyro_loop::nco::{FixedNco, Reference};
use crate::gyro_loop::pi::FixedPi;
use crate::resonator::Mode;

/// The node `name` of `nodes`.
fn node<'a>(nodes: &'a [NodeRange], name: &str) -> &'a NodeRange {
    find(nodes, name).unwrap_or_else(|| panic!("{name} in {nodes:?}"))
}

fn inside(value: f64, range: Interval) -> bool {
    value >= range.lo && value <= range.hi
}

/// The extremes each node reached, reals.
#[derive(Default)]
struct Reached(BTreeMap<&'static str, Interval>);

impl Reached {
    fn see(&mut self, name: &'static str, value: f64) {
        let point = Interval::new(value, value);
        self.0
            .entry(name)
            .and_modify(|r| *r = r.union(point))
            .or_insert(point);
    }

    fn get(&self, name: &str) -> Interval {
        *self.0.get(name).unwrap_or_else(|| panic!("{name} reached"))
    }

    /// The least and greatest codes of `format` reached at `name`.
    fn codes(&self, name: &str, format: Format) -> [i64; 2] {
        let r = self.get(name);
        [r.lo, r.hi].map(|v| (v / format.lsb()).round() as i64)
    }
}

/// The NCO's least and greatest output codes, over every phase bin (the real NCO swept one bin
/// a sample).
fn nco_extremes(plan: &nco::Plan) -> [i64; 2] {
    let mut nco = FixedNco::new(plan);
    let bin = 1u64 << (plan.phase.width - plan.address_bits - 2);
    (0..4u64 << plan.address_bits).fold([i64::MAX, i64::MIN], |[lo, hi], _| {
        let r = nco.step(bin, 0);
        [lo.min(r.sin).min(r.cos), hi.max(r.sin).max(r.cos)]
    })
}

/// The cascade's impulse response from the CIC's input to the compensator's output, lag 0 the
/// input sample of the output itself, measured on the float twin (a different structure: the
/// CIC as one direct-form FIR): an impulse `d` samples before an output gives lags `mR + d`.
fn cascade_response(plan: &cic::Plan) -> Vec<f64> {
    let r = plan.decimation as usize;
    let outputs = plan.taps.len() + plan.stages as usize * plan.differential_delay as usize + 1;
    let mut response = vec![0.0; outputs * r];
    for d in 0..r {
        let mut twin = FloatCic::new(plan);
        let mut m = 0;
        for i in 0..outputs * r {
            let x = if i + d == r - 1 { 1.0 } else { 0.0 };
            if let Some(y) = twin.step(x) {
                response[m * r + d] = y;
                m += 1;
            }
        }
    }
    response
}

/// Full-scale codes with the sign pattern of `response` (`sign` +1 for the top, −1 for the
/// bottom), oldest first, ending with an output's own sample.
fn sign_pattern(response: &[f64], input: Format, sign: f64) -> Vec<i64> {
    response
        .iter()
        .rev()
        .map(|h| {
            if h * sign >= 0.0 {
                input.max_code() as i64
            } else {
                input.min_code() as i64
            }
        })
        .collect()
}

/// Runs `pattern` into `cic` from reset, its last sample aligned with an output; returns that
/// output (output format code).
fn run_pattern(cic: &mut FixedCic, decimation: u32, pattern: &[i64]) -> i64 {
    cic.reset();
    let r = decimation as usize;
    let lead = (r - pattern.len() % r) % r;
    let mut last = None;
    for &x in std::iter::repeat_n(&0, lead).chain(pattern) {
        last = cic.step(x).or(last);
    }
    last.expect("the pattern ends with an output")
}

/// The extremes a loop's real blocks reach on each node's adversarial input, and which of the
/// block's quantizers overflowed. The DAC node is also rounded into a wider word (the DAC's own
/// rounding, no saturation) to see where its exact value goes.
fn adversary(plan: &Plan) -> (Reached, BTreeMap<&'static str, bool>) {
    let mut reached = Reached::default();
    let mut overflowed = BTreeMap::new();
    let d = &plan.demodulator;
    let [r_lo, r_hi] = nco_extremes(&plan.nco);
    let (x_min, x_max) = (plan.adc.min_code() as i64, plan.adc.max_code() as i64);

    // The product at the ADC's extremes against the ROM's; the demodulator held there (a
    // frequency word of 0 holds a reference), I at the top and Q at the bottom, then reversed.
    let mut product = d.product.quantizer();
    for x in [x_min, x_max] {
        for r in [r_lo, r_hi] {
            let code = product.apply(i128::from(x) * i128::from(r));
            reached.see("loop.demod_product", d.product.to.to_f64(code));
        }
    }
    overflowed.insert("loop.demod_product", product.overflow_count > 0);
    let mut demod = FixedDemodulator::new(d);
    for (sin, cos) in [(r_lo, r_hi), (r_hi, r_lo)] {
        demod.reset();
        for _ in 0..40u32 << d.lowpass_shift {
            let iq = demod.step(x_min, Reference { sin, cos });
            for y in demod.state() {
                reached.see("loop.demod_state", d.state.to.to_f64(i128::from(y)));
            }
            for v in [iq.i, iq.q] {
                reached.see("loop.demod_output", d.output.to.to_f64(i128::from(v)));
            }
        }
    }
    let counts = demod.overflow_counts();
    overflowed.insert("loop.demod_output", counts.output != [0, 0]);
    let [i_lo, i_hi] = reached.codes("loop.demod_output", d.output.to);

    // e_A at both modes' setpoints against I's extremes.
    let mut agc_error = plan.agc_error.quantizer();
    for m in &plan.modes {
        for i in [i_lo, i_hi] {
            let code = agc_error.apply(i128::from(m.setpoint_code) - i128::from(i));
            reached.see("loop.agc_error", plan.agc_error.to.to_f64(code));
        }
    }
    overflowed.insert("loop.agc_error", agc_error.overflow_count > 0);

    // Each PI at a constant error at either end until its integrator clamps.
    let controllers = [
        (
            &plan.pll,
            [i_lo, i_hi],
            "loop.pll_integrator",
            "loop.pll_output",
        ),
        (
            &plan.agc,
            reached.codes("loop.agc_error", plan.agc_error.to),
            "loop.agc_integrator",
            "loop.agc_output",
        ),
    ];
    for (pi_plan, [e_lo, e_hi], integrator, output) in controllers {
        let mut pi = FixedPi::new(pi_plan);
        reached.see(
            integrator,
            pi_plan.integrator.to_f64(i128::from(pi.integrator())),
        );
        for e in [e_hi, e_lo] {
            loop {
                let before = pi.integrator();
                let u = pi.step(e);
                let v = pi.integrator();
                reached.see(integrator, pi_plan.integrator.to_f64(i128::from(v)));
                reached.see(output, pi_plan.output.to.to_f64(i128::from(u)));
                if v == before {
                    break;
                }
            }
        }
        overflowed.insert(output, pi.overflow_counts().output > 0);
    }

    // The DAC at the AGC output's extremes against the ROM's.
    let mut dac = plan.dac.quantizer();
    let unsaturated = Format::intermediate(true, 128, plan.dac.to.frac).unwrap();
    let mut dac_wide = Quantizer::new(
        plan.dac.from.frac,
        unsaturated,
        plan.dac.rounding,
        Overflow::Saturate,
    );
    for u in reached.codes("loop.agc_output", plan.agc.output.to) {
        for r in [r_lo, r_hi] {
            let exact = i128::from(u) * i128::from(r);
            dac.apply(exact);
            reached.see("loop.dac", unsaturated.to_f64(dac_wide.apply(exact)));
        }
    }
    overflowed.insert("loop.dac", dac.overflow_count > 0);

    // The CIC at I's extremes held (c at its ends), then with the cascade's sign pattern.
    let c = &plan.cic;
    let mut cic = FixedCic::new(c);
    let run = |cic: &mut FixedCic, x: i64, reached: &mut Reached| {
        if let Some(y) = cic.step(x) {
            let newest = cic.compensator_line()[0];
            reached.see("loop.cic_internal", c.cic.to.to_f64(i128::from(newest)));
            reached.see("loop.cic_output", c.output.to.to_f64(i128::from(y)));
        }
    };
    let settle = (c.taps.len() + c.stages as usize + 1) * c.decimation as usize;
    for x in [i_hi, i_lo] {
        for _ in 0..settle {
            run(&mut cic, x, &mut reached);
        }
    }
    let response = cascade_response(c);
    for sign in [1.0, -1.0] {
        // The CIC's input here is I: its extremes are the demodulator's, not the format's.
        let pattern: Vec<i64> = sign_pattern(&response, c.input, sign)
            .into_iter()
            .map(|x| if x > 0 { i_hi } else { i_lo })
            .collect();
        let y = run_pattern(&mut cic, c.decimation, &pattern);
        reached.see("loop.cic_output", c.output.to.to_f64(i128::from(y)));
    }
    // A reset keeps the counts.
    let counts = cic.overflow_counts();
    overflowed.insert("loop.cic_internal", counts.cic > 0);
    overflowed.insert("loop.cic_output", counts.output > 0);

    // The output at the CIC's extremes times every 1/SF coefficient.
    let mut output = plan.output.quantizer();
    for y in reached.codes("loop.cic_output", c.output.to) {
        for m in &plan.modes {
            for coefficient in [m.rate_coefficient.code, m.quadrature_coefficient.code] {
                let code = output.apply(coefficient * i128::from(y));
                reached.see("loop.output", plan.output.to.to_f64(code));
            }
        }
    }
    overflowed.insert("loop.output", output.overflow_count > 0);
    (reached, overflowed)
}

/// The format with `node`'s fraction bits and one integer bit fewer than its range needs.
fn one_bit_narrower(node: &NodeRange) -> Format {
    let frac = node.format.frac;
    Format::signed((node.needed_integer_bits() - 1 + frac) as u32, frac).unwrap()
}

/// `reached` lies inside `node`'s range, within 10 % of each end (of the range's magnitude or
/// width, whichever is less), and does not fit one integer bit less.
fn assert_tight(node: &NodeRange, reached: Interval) {
    let range = node.range;
    assert!(
        reached.lo >= range.lo && reached.hi <= range.hi,
        "{}: reached {reached:?} outside {range:?}",
        node.name
    );
    let slack = 0.1 * range.magnitude().min(range.hi - range.lo);
    assert!(
        reached.hi >= range.hi - slack && reached.lo <= range.lo + slack,
        "{}: reached only {reached:?} of {range:?}",
        node.name
    );
    let narrower = one_bit_narrower(node);
    assert!(
        !reached.fits(narrower),
        "{}: {reached:?} fits {narrower}",
        node.name
    );
}

/// `spec` with every configured format of the loop at its proven one (same fraction bits),
/// the AGC output's too (the default keeps it narrow on purpose), the DAC's aside: its full
/// scale is the AGC integrator's limit.
fn with_proven_formats(spec: &Spec) -> Spec {
    let nodes = gyro(&Plan::new(spec).unwrap());
    let proven = |name: &str| {
        let n = node(&nodes, name);
        Format::signed(
            (n.needed_integer_bits() + n.format.frac) as u32,
            n.format.frac,
        )
        .unwrap()
    };
    let widest = |a: Format, b: Format| if a.width >= b.width { a } else { b };
    let mut proven_spec = spec.clone();
    let s = &mut proven_spec.settings;
    s.demod_product_format = proven("loop.demod_product").to_string();
    s.demod_state_format = proven("loop.demod_state").to_string();
    s.demod_output_format =
        widest(proven("loop.demod_output"), proven("loop.agc_error")).to_string();
    s.pll_integrator_format = proven("loop.pll_integrator").to_string();
    s.agc_integrator_format = proven("loop.agc_integrator").to_string();
    s.agc_output_format = proven("loop.agc_output").to_string();
    s.cic_internal_format = proven("loop.cic_internal").to_string();
    s.cic_output_format = proven("loop.cic_output").to_string();
    s.output_format = proven("loop.output").to_string();
    proven_spec
}

#[test]
fn every_loop_bound_is_reached_by_its_adversarial_input_and_one_bit_less_overflows() {
    // Unequal pick-off gains give the modes different setpoints and 1/SF: the bounds must
    // take both.
    let mut unequal = Spec::paper_004();
    unequal.front_end.pickoff_gain_v_per_m = [0.9e5, 1e5];
    let spec = with_proven_formats(&unequal);
    let plan = Plan::new(&spec).unwrap();
    let nodes = gyro(&plan);
    let (reached, overflowed) = adversary(&plan);
    for n in &nodes {
        // The DAC's full scale is the AGC's limit: the AGC's proportional path passes it.
        assert_eq!(n.fits(), n.name != "loop.dac", "{n:?}");
        // The comb's register is not a port of the block; c is its rounding.
        if n.name != "loop.cic_comb" {
            assert_tight(n, reached.get(n.name));
        }
    }
    for (name, overflow) in overflowed {
        assert_eq!(overflow, name == "loop.dac", "{name}");
    }
}

/// The default's formats: the adversarial inputs overflow the real blocks exactly where the
/// analysis says a format cannot hold its node.
#[test]
fn the_default_overflows_exactly_where_the_analysis_says() {
    let plan = Plan::new(&Spec::paper_004()).unwrap();
    let nodes = gyro(&plan);
    let (_, overflowed) = adversary(&plan);
    for (name, overflow) in overflowed {
        assert_eq!(overflow, !node(&nodes, name).fits(), "{name}");
    }
    // Every node that cannot overflow by construction fits.
    for name in [
        "loop.demod_state",
        "loop.pll_integrator",
        "loop.agc_integrator",
        "loop.cic_comb",
    ] {
        assert!(node(&nodes, name).fits(), "{name}");
    }
}

fn any_rounding() -> impl Strategy<Value = Rounding> {
    prop::sample::select(Rounding::ALL.to_vec())
}

fn any_overflow() -> impl Strategy<Value = Overflow> {
    prop::sample::select(vec![Overflow::Saturate, Overflow::Wrap])
}

/// A code of `format`: an extreme or anywhere.
fn pick(format: Format, choice: u8, raw: u64) -> i64 {
    let (lo, hi) = (format.min_code(), format.max_code());
    (match choice % 3 {
        0 => lo,
        1 => hi,
        _ => lo + i128::from(raw) % (hi - lo + 1),
    }) as i64
}

/// A signed format of `int` integer bits and `frac` fraction bits.
fn signed(int: i32, frac: i32) -> Option<Format> {
    Format::signed(u32::try_from(int + frac).ok()?, frac).ok()
}

/// A demodulator with its NCO: random widths, fraction bits, integer bits (too few, now and
/// then), shift and modes.
fn any_demodulator() -> impl Strategy<Value = (nco::Plan, demodulator::Plan)> {
    (
        (2u32..=8, 3u32..=20, 0u32..=8),
        (4u32..=24, 0i32..=4, 0i32..=12),
        (0i32..=2, 0i32..=8, 0i32..=2, 0i32..=8),
        (1u32..=6, any_rounding(), any_overflow()),
    )
        .prop_filter_map(
            "plannable",
            |(
                (a, s, p),
                (w, product_int, product_drop),
                (state_int, state_guard, out_int, out_drop),
                (k, rounding, overflow),
            )| {
                let nco = nco::Plan::new(&nco::Spec {
                    phase_bits: a + 2 + p,
                    address_bits: a,
                    sine_width: s,
                    error_feedback: false,
                })
                .ok()?;
                let input = signed(1, w as i32 - 1)?;
                let product_frac = input.frac + nco.output.frac - 1 - product_drop;
                let product = signed(product_int, product_frac)?;
                let state_frac = product_frac + state_guard;
                let state = signed(product_int + state_int, state_frac)?;
                let output = signed(out_int, state_frac - out_drop)?;
                let plan = demodulator::Plan::new(&demodulator::Spec {
                    input,
                    reference: nco.output,
                    product,
                    state,
                    output,
                    lowpass_shift: k,
                    rounding,
                    overflow,
                })
                .ok()?;
                Some((nco, plan))
            },
        )
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    /// Segments of held or turning references and extreme or random ADC codes keep the
    /// product, state and outputs within their proven ranges (held extremes drive the state to
    /// its bound: scaling it by 0.9 fails this).
    #[test]
    fn no_input_leaves_the_proven_demodulator_ranges(
        (nco_plan, plan) in any_demodulator(),
        segments in prop::collection::vec((0u8..3, any::<u64>(), any::<u64>(), any::<bool>(), 1usize..400), 1..12),
    ) {
        let nodes = demodulator(&plan, Interval::of_format(plan.input), reference(&nco_plan));
        let product = output_of(node(&nodes, "loop.demod_product").range, &plan.product);
        let state = node(&nodes, "loop.demod_state").range;
        let output = output_of(node(&nodes, "loop.demod_output").range, &plan.output);
        let mut nco = FixedNco::new(&nco_plan);
        let mut demod = FixedDemodulator::new(&plan);
        let mut quantizer = plan.product.quantizer();
        for (choice, raw, word, held, length) in segments {
            let x = pick(plan.input, choice, raw);
            let freq = if held { 0 } else { word };
            for _ in 0..length {
                let r = nco.step(freq, 0);
                for reference in [r.sin, r.cos] {
                    let p = plan.product.to.to_f64(quantizer.apply(i128::from(x) * i128::from(reference)));
                    prop_assert!(inside(p, product), "product {} outside {:?}", p, product);
                }
                let iq = demod.step(x, r);
                for y in demod.state() {
                    let value = plan.state.to.to_f64(i128::from(y));
                    prop_assert!(inside(value, state), "state {} outside {:?}", value, state);
                }
                for v in [iq.i, iq.q] {
                    let value = plan.output.to.to_f64(i128::from(v));
                    prop_assert!(inside(value, output), "output {} outside {:?}", value, output);
                }
            }
        }
    }
}

/// A PI controller: random gains of either sign, limits, formats (outputs too narrow, now and
/// then) and modes.
fn any_pi() -> impl Strategy<Value = pi::Plan> {
    (
        (4u32..=24, 0i32..=24),
        (-12.0f64..4.0, -16.0f64..0.0, any::<bool>(), any::<bool>()),
        (1i32..=8, -4i32..=16, -1.0f64..1.0, 0.0f64..1.0),
        (-4i32..=12, -2i32..=6),
        (any_rounding(), any_overflow()),
    )
        .prop_filter_map(
            "plannable",
            |(
                (w, f),
                (log_kp, log_ki, negative_kp, negative_ki),
                (v_int, v_guard, centre, half),
                (o_drop, o_int),
                (rounding, overflow),
            )| {
                let input = Format::signed(w, f.min(w as i32)).ok()?;
                let integrator = signed(v_int, input.frac + v_guard)?;
                let span = integrator.max_value();
                let sign = |negative: bool| if negative { -1.0 } else { 1.0 };
                pi::Plan::new(&pi::Spec {
                    input,
                    kp: sign(negative_kp) * 2f64.powf(log_kp),
                    ki: sign(negative_ki) * 2f64.powf(log_ki),
                    kp_format: CoefficientFormat::Auto { width: 18 },
                    ki_format: CoefficientFormat::Auto { width: 18 },
                    integrator,
                    integrator_limits: [
                        span * (centre - half).max(-1.0) * 0.9,
                        span * (centre + half).min(1.0) * 0.9,
                    ],
                    output: signed(v_int + o_int, integrator.frac - o_drop)?,
                    rounding,
                    overflow,
                })
                .ok()
            },
        )
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(128))]

    /// Segments of constant extreme or random errors, now and then after a preset or reset,
    /// keep the integrator within its limits and the output within its proven range (held
    /// extremes clamp the integrator: the output then sits at its bound).
    #[test]
    fn no_error_leaves_the_proven_pi_ranges(
        plan in any_pi(),
        segments in prop::collection::vec((0u8..3, any::<u64>(), 0u8..8, any::<i64>(), 1usize..3000), 1..8),
    ) {
        let nodes = pi(&plan, Interval::of_format(plan.input), Controller::Agc);
        let integrator = node(&nodes, "loop.agc_integrator").range;
        let output = output_of(node(&nodes, "loop.agc_output").range, &plan.output);
        let mut fixed = FixedPi::new(&plan);
        for (choice, raw, event, preset, length) in segments {
            match event {
                0 => fixed.preset(preset >> 8),
                1 => fixed.reset(),
                _ => {}
            }
            let e = pick(plan.input, choice, raw);
            for _ in 0..length {
                let u = plan.output.to.to_f64(i128::from(fixed.step(e)));
                let v = plan.integrator.to_f64(i128::from(fixed.integrator()));
                prop_assert!(inside(v, integrator), "integrator {} outside {:?}", v, integrator);
                prop_assert!(inside(u, output), "output {} outside {:?}", u, output);
            }
        }
    }
}

/// A CIC decimator: random stages, decimation, delay, taps, passband, formats (too narrow, now
/// and then) and modes.
fn any_cic() -> impl Strategy<Value = cic::Plan> {
    (
        (1u32..=4, 2u32..=24, 1u32..=2, 0u32..=4, 0.1f64..0.9),
        (4u32..=20, 0i32..=3, 0i32..=10, 0i32..=3, 0i32..=10),
        (any_rounding(), any_overflow()),
    )
        .prop_filter_map(
            "plannable",
            |(
                (stages, decimation, delay, half_taps, passband),
                (w, c_int, c_drop, y_int, y_drop),
                (rounding, overflow),
            )| {
                let input = signed(1, w as i32 - 1)?;
                let gain = (decimation * delay).checked_pow(stages)?;
                let shift = 32 - (gain - 1).leading_zeros();
                let cic_output = signed(c_int, input.frac + shift as i32 - c_drop)?;
                cic::Plan::new(&cic::Spec {
                    input,
                    stages,
                    decimation,
                    differential_delay: delay,
                    shift: None,
                    cic_output,
                    taps: 2 * half_taps + 1,
                    passband: passband * 0.5 / f64::from(delay),
                    coefficients: CoefficientFormat::Auto { width: 18 },
                    output: signed(y_int, cic_output.frac + 16 - y_drop)?,
                    rounding,
                    overflow,
                })
                .ok()
            },
        )
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    /// Segments of held extremes, random codes and the cascade's sign pattern (either sign)
    /// keep c and the compensator's output within their proven ranges; where neither can
    /// overflow, the sign pattern alone takes the output within 10 % of its bound (up to c's
    /// roundings through the taps, both ways, and the output's own).
    #[test]
    fn no_input_leaves_the_proven_cic_ranges(
        plan in any_cic(),
        segments in prop::collection::vec((0u8..5, any::<u64>(), 1usize..200), 1..10),
    ) {
        let input = Interval::of_format(plan.input);
        let nodes = cic(&plan, input);
        let c = output_of(node(&nodes, "loop.cic_internal").range, &plan.cic);
        let y = output_of(node(&nodes, "loop.cic_output").range, &plan.output);
        let response = cascade_response(&plan);
        let mut fixed = FixedCic::new(&plan);
        for (choice, raw, length) in segments {
            let codes: Vec<i64> = match choice {
                3 => sign_pattern(&response, plan.input, 1.0),
                4 => sign_pattern(&response, plan.input, -1.0),
                _ => (0..length as u64).map(|k| pick(plan.input, choice, raw.rotate_left(k as u32))).collect(),
            };
            for x in codes {
                if let Some(out) = fixed.step(x) {
                    let newest = plan.cic.to.to_f64(i128::from(fixed.compensator_line()[0]));
                    let out = plan.output.to.to_f64(i128::from(out));
                    prop_assert!(inside(newest, c), "c {} outside {:?}", newest, c);
                    prop_assert!(inside(out, y), "y {} outside {:?}", out, y);
                }
            }
        }
        let output = node(&nodes, "loop.cic_output");
        if node(&nodes, "loop.cic_internal").fits() && output.fits() {
            // The bound adds c's worst rounding outward, the pattern may meet it inward.
            let taps: f64 = plan.tap_values().iter().map(|h| h.abs()).sum();
            let allowance = 0.1 * output.range.magnitude()
                + 2.0 * taps * plan.cic.max_error()
                + plan.output.to.lsb();
            for sign in [1.0, -1.0] {
                let pattern = sign_pattern(&response, plan.input, sign);
                let reached = plan.output.to.to_f64(i128::from(run_pattern(&mut fixed, plan.decimation, &pattern)));
                let end = if sign > 0.0 { output.range.hi } else { output.range.lo };
                prop_assert!((end - reached).abs() <= allowance, "{} reached of {:?}", reached, output.range);
            }
        }
    }
}

/// The loop's settings with random formats (integer bits too few, now and then), shift,
/// decimation, CIC and modes.
fn any_loop() -> impl Strategy<Value = Plan> {
    (
        (
            0i32..=4,
            1i32..=3,
            0i32..=6,
            1i32..=3,
            26i32..=34,
            4u32..=10,
        ),
        (-3i32..=1, 16i32..=24, 17i32..=20, 2i32..=8),
        (
            1i32..=3,
            0i32..=8,
            1i32..=3,
            -4i32..=8,
            6i32..=22,
            8i32..=14,
        ),
        (4u32..=48, 1u32..=4, 0u32..=3),
        (any_rounding(), any_overflow()),
    )
        .prop_filter_map(
            "plannable",
            |(
                (product_drop, product_int, state_guard, out_int, out_frac, k),
                (pll_int, agc_v_frac, agc_int, agc_frac),
                (c_int, c_drop, y_int, y_offset, output_int, output_frac),
                (decimation, stages, half_taps),
                (rounding, overflow),
            )| {
                let text = |int: i32, frac: i32| signed(int, frac).map(|f| f.to_string());
                let product_frac = 39 - product_drop;
                let out_frac = out_frac.min(product_frac + state_guard);
                // c's fraction bits from the comb's (the output's plus the growth) downward.
                let growth = 32 - (decimation.checked_pow(stages)? - 1).leading_zeros() as i32;
                let c_frac = out_frac + growth - c_drop;
                let settings = LoopSettings {
                    demod_product_format: text(product_int, product_frac)?,
                    demod_state_format: text(product_int, product_frac + state_guard)?,
                    demod_output_format: text(out_int, out_frac)?,
                    demod_lowpass_shift: k,
                    pll_integrator_format: text(pll_int, 38)?,
                    agc_integrator_format: text(19, agc_v_frac)?,
                    agc_output_format: text(agc_int, agc_frac)?,
                    cic_internal_format: text(c_int, c_frac)?,
                    cic_output_format: text(y_int, c_frac + y_offset)?,
                    output_format: text(output_int, output_frac)?,
                    decimation,
                    cic_stages: stages,
                    cic_taps: 2 * half_taps + 1,
                    rounding: rounding.name().to_string(),
                    overflow: overflow.name().to_string(),
                    ..LoopSettings::default()
                };
                Plan::new(&Spec {
                    settings,
                    ..Spec::paper_004()
                })
                .ok()
            },
        )
}

/// The blocks of one gyro's loop in normal mode, wired as `FixedGyroLoop` wires them, each
/// node's value open to the test.
struct Harness {
    nco: [FixedNco; 3],
    demod: [FixedDemodulator; 2],
    product: Quantizer,
    pll: FixedPi,
    agc: FixedPi,
    agc_error: Quantizer,
    dac: Quantizer,
    cic: [FixedCic; 2],
    output: Quantizer,
    freq: u64,
    mask: u64,
    delay: VecDeque<i64>,
}

impl Harness {
    fn new(plan: &Plan) -> Self {
        let m = plan.mode(Mode::Normal);
        let mut pll = FixedPi::new(&plan.pll);
        pll.preset(m.pll_preset);
        Harness {
            nco: [(); 3].map(|_| FixedNco::new(&plan.nco)),
            demod: [(); 2].map(|_| FixedDemodulator::new(&plan.demodulator)),
            product: plan.demodulator.product.quantizer(),
            pll,
            agc: FixedPi::new(&plan.agc),
            agc_error: plan.agc_error.quantizer(),
            dac: plan.dac.quantizer(),
            cic: [(); 2].map(|_| FixedCic::new(&plan.cic)),
            output: plan.output.quantizer(),
            freq: m.frequency_word,
            mask: u64::MAX >> (64 - plan.nco.phase.width),
            delay: std::iter::repeat_n(0, plan.latency as usize).collect(),
        }
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(24))]

    /// The whole loop of random plans, fed ADC codes at the extremes, anywhere, or with the
    /// signs of the references (an adversary of I and Q inside the loop), keeps every node
    /// within its proven range; the blocks wired here give the real loop's DAC codes and
    /// outputs bit for bit, so the nodes seen are the loop's.
    #[test]
    fn no_adc_sequence_leaves_the_proven_loop_ranges(
        plan in any_loop(),
        segments in prop::collection::vec((0u8..5, 0u8..5, any::<u64>(), 1usize..300), 1..12),
    ) {
        let nodes = gyro(&plan);
        let bound = |name: &str, point: &Point| output_of(node(&nodes, name).range, point);
        let d = &plan.demodulator;
        let product = bound("loop.demod_product", &d.product);
        let state = node(&nodes, "loop.demod_state").range;
        let iq = bound("loop.demod_output", &d.output);
        let agc_error = bound("loop.agc_error", &plan.agc_error);
        let pll_integrator = node(&nodes, "loop.pll_integrator").range;
        let pll_output = bound("loop.pll_output", &plan.pll.output);
        let agc_integrator = node(&nodes, "loop.agc_integrator").range;
        let agc_output = bound("loop.agc_output", &plan.agc.output);
        let dac = bound("loop.dac", &plan.dac);
        let c = bound("loop.cic_internal", &plan.cic.cic);
        let y = bound("loop.cic_output", &plan.cic.output);
        let output = bound("loop.output", &plan.output);
        let check = |name: &str, value: f64, range: Interval| -> Result<(), TestCaseError> {
            prop_assert!(inside(value, range), "{} = {} outside {:?}", name, value, range);
            Ok(())
        };

        let m = *plan.mode(Mode::Normal);
        let mut real = FixedGyroLoop::new(&plan);
        let mut h = Harness::new(&plan);
        for (drive_choice, sense_choice, raw, length) in segments {
            for k in 0..length as u64 {
                let freq = h.freq;
                let reference = h.nco[0].step(freq, 0);
                let transmit = h.nco[1].step(freq, m.dac_offset_word);
                let sense_reference = h.nco[2].step(freq, m.sense_offset_word);
                let adversary = |choice: u8, r: Reference, salt: u32| match choice {
                    3 => if r.sin >= 0 { plan.adc.max_code() as i64 } else { plan.adc.min_code() as i64 },
                    4 => if r.cos >= 0 { plan.adc.max_code() as i64 } else { plan.adc.min_code() as i64 },
                    _ => pick(plan.adc, choice, raw.rotate_left(salt).wrapping_add(k)),
                };
                let adc = [adversary(drive_choice, reference, 0), adversary(sense_choice, sense_reference, 17)];

                for (x, r) in [(adc[0], reference), (adc[1], sense_reference)] {
                    for r in [r.sin, r.cos] {
                        let p = d.product.to.to_f64(h.product.apply(i128::from(x) * i128::from(r)));
                        check("product", p, product)?;
                    }
                }
                let drive = h.demod[0].step(adc[0], reference);
                let sense = h.demod[1].step(adc[1], sense_reference);
                for demod in &h.demod {
                    for s in demod.state() {
                        check("state", d.state.to.to_f64(i128::from(s)), state)?;
                    }
                }
                for v in [drive.i, drive.q, sense.i, sense.q] {
                    check("I/Q", d.output.to.to_f64(i128::from(v)), iq)?;
                }

                let u_pll = h.pll.step(drive.q);
                check("PLL output", plan.pll.output.to.to_f64(i128::from(u_pll)), pll_output)?;
                check("PLL integrator", plan.pll.integrator.to_f64(i128::from(h.pll.integrator())), pll_integrator)?;
                h.freq = (u_pll as u64) & h.mask;
                let error = h.agc_error.apply(i128::from(m.setpoint_code) - i128::from(drive.i)) as i64;
                check("e_A", plan.agc_error.to.to_f64(i128::from(error)), agc_error)?;
                let amplitude = h.agc.step(error);
                check("AGC output", plan.agc.output.to.to_f64(i128::from(amplitude)), agc_output)?;
                check("AGC integrator", plan.agc.integrator.to_f64(i128::from(h.agc.integrator())), agc_integrator)?;
                let code = h.dac.apply(i128::from(amplitude) * i128::from(transmit.cos)) as i64;
                check("DAC", plan.dac.to.to_f64(i128::from(code)), dac)?;
                h.delay.push_back(code);
                let dac_out = h.delay.pop_front().unwrap();

                let mut chain = [None, None];
                for ((cic, x), slot) in h.cic.iter_mut().zip([sense.i, sense.q]).zip(&mut chain) {
                    if let Some(out) = cic.step(x) {
                        check("c", plan.cic.cic.to.to_f64(i128::from(cic.compensator_line()[0])), c)?;
                        check("y", plan.cic.output.to.to_f64(i128::from(out)), y)?;
                        *slot = Some(out);
                    }
                }
                let outputs = match chain {
                    [Some(yi), Some(yq)] => {
                        let rate = h.output.apply(m.rate_coefficient.code * i128::from(yi)) as i64;
                        let quadrature = h.output.apply(m.quadrature_coefficient.code * i128::from(yq)) as i64;
                        for v in [rate, quadrature] {
                            check("output", plan.output.to.to_f64(i128::from(v)), output)?;
                        }
                        Some((rate, quadrature))
                    }
                    _ => None,
                };

                let step = real.step(adc, Mode::Normal);
                prop_assert_eq!(step.dac, [dac_out, 0]);
                prop_assert_eq!(step.chain.map(|s| (s.rate, s.quadrature)), outputs);
            }
        }
    }
}
