use super::*;
use proptest::prelude::*;

fn fmt(text: &str) -> Format {
    text.parse().unwrap()
}

fn reference(sin: i64, cos: i64) -> Reference {
    Reference { sin, cos }
}

/// Largest `|fixed − float|` over the samples, in output LSB, and whether a product or an
/// output overflowed (where the bound does not apply).
fn worst_error(plan: &Plan, samples: &[(i64, i64, i64)]) -> (f64, bool) {
    let mut fixed = FixedDemodulator::new(plan);
    let mut float = FloatDemodulator::new(plan);
    let lsb = plan.output.to.lsb();
    let mut worst: f64 = 0.0;
    for (x, s, c) in samples {
        let out = fixed.step(*x, reference(*s, *c));
        let want = float.step(
            plan.input.to_f64(i128::from(*x)),
            plan.reference.to_f64(i128::from(*s)),
            plan.reference.to_f64(i128::from(*c)),
        );
        for (got, want) in [out.i, out.q].iter().zip(want) {
            worst = worst.max((plan.output.to.to_f64(i128::from(*got)) - want).abs() / lsb);
        }
    }
    let counts = fixed.overflow_counts();
    let overflowed = counts.product != [0, 0] || counts.output != [0, 0];
    (worst, overflowed)
}

/// A constant input whose exact product `x·r` leaves 255/256 of a product LSB to round.
fn constant_tie_case() -> (Spec, Vec<(i64, i64, i64)>) {
    let spec = Spec {
        input: fmt("s16.15"),
        reference: fmt("s12.11"),
        product: fmt("s20.17"), // the exact s28.25 loses 8 bits
        state: fmt("s40.37"),
        output: fmt("s40.37"),
        lowpass_shift: 4,
        rounding: Rounding::Nearest,
        overflow: Overflow::Saturate,
    };
    (spec, vec![(0x12ff, 0x101, 0x101); 800])
}

#[test]
fn default_plan_formats() {
    let plan = Plan::new(&Spec::default()).unwrap();
    assert_eq!(
        plan.product.from,
        Format::intermediate(true, 42, 39).unwrap()
    );
    assert_eq!(plan.state.from, Format::intermediate(true, 49, 46).unwrap());
    // The guard bits keep the products' and the state's rounding (2^8 accumulated) under
    // 0.01 output LSB: the output's own rounding dominates.
    let bound = plan.error_bound_lsb();
    assert!(bound > 0.5 && bound < 0.51, "{bound}");
    let names: Vec<&str> = plan.rtl_parameters().iter().map(|p| p.0).collect();
    assert_eq!(names[..3], ["ADC_W", "ADC_F", "REF_W"]);
}

#[test]
fn a_product_rounded_down_breaks_the_bound() {
    let (spec, samples) = constant_tie_case();
    let plan = Plan::new(&spec).unwrap();
    let (worst, overflowed) = worst_error(&plan, &samples);
    assert!(!overflowed);
    assert!(worst <= plan.error_bound_lsb());
    let mut mutated = plan.clone();
    mutated.product.rounding = Rounding::Floor;
    let (worst, _) = worst_error(&mutated, &samples);
    assert!(
        worst > plan.error_bound_lsb(),
        "floor product: {worst} <= {}",
        plan.error_bound_lsb()
    );
}

#[test]
fn the_low_pass_settles_to_the_product_with_unit_dc_gain() {
    let (spec, samples) = constant_tie_case();
    let plan = Plan::new(&spec).unwrap();
    let mut demodulator = FixedDemodulator::new(&plan);
    let mut last = Iq::default();
    for (x, s, c) in &samples {
        last = demodulator.step(*x, reference(*s, *c));
    }
    // 2·x·r in the product's LSB (2^-17), rounded to nearest, then aligned to 2^-37.
    let product = ((2 * 0x12ff * 0x101) as f64 / 2f64.powi(9)).round() as i64;
    // Rising from 0, the update (p − y)·2^-4 rounds to 0 once p − y < 8 state LSB: the
    // rounding's dead band, 2^(k−1) LSB, which the bound's 2^k·u·q_y covers.
    let short = (product << 20) - last.i;
    assert!((0..8).contains(&short), "{short}");
    assert_eq!(last.q, last.i);
    demodulator.reset();
    assert_eq!(demodulator.state(), [0, 0]);
}

#[test]
fn plan_errors_name_the_field() {
    let spec = Spec {
        state: fmt("s35.22"),
        ..Spec::default()
    };
    let text = Plan::new(&spec).unwrap_err().to_string();
    assert!(text.contains("demodulator.state_format = s35.22"), "{text}");
    assert!(text.contains("product_format s32.30"), "{text}");
    let spec = Spec {
        product: fmt("s25.40"),
        state: fmt("s60.50"),
        ..Spec::default()
    };
    let text = Plan::new(&spec).unwrap_err().to_string();
    assert!(
        text.contains("demodulator.product_format = s25.40") && text.contains("s42.39"),
        "{text}"
    );
    let spec = Spec {
        lowpass_shift: 0,
        ..Spec::default()
    };
    let text = Plan::new(&spec).unwrap_err().to_string();
    assert!(
        text.contains("lowpass_shift = 0") && text.contains("1..=24"),
        "{text}"
    );
    let spec = Spec {
        input: fmt("u24.24"),
        ..Spec::default()
    };
    assert!(Plan::new(&spec)
        .unwrap_err()
        .to_string()
        .contains("input_format = u24.24"));
}

fn any_rounding() -> impl Strategy<Value = Rounding> {
    prop::sample::select(Rounding::ALL.to_vec())
}

#[derive(Debug, Clone)]
struct Case {
    spec: Spec,
    samples: Vec<(i64, i64, i64)>,
}

/// Random formats and modes; full-range input and reference codes.
fn any_case() -> impl Strategy<Value = Case> {
    (
        (4u32..=32, -4i32..=30), // input width, frac
        (3u32..=24, 0i32..=4),   // reference width, frac below width - 1
        0u32..=20,               // product bits dropped
        (0u32..=3, 0u32..=16),   // extra state integer bits, guard bits
        0u32..=6,                // output bits dropped below the product's fraction
        1u32..=12,               // k
        any_rounding(),
    )
        .prop_flat_map(
            |((xw, xf), (rw, r_below), drop, (extra, guard), out_drop, k, rounding)| {
                let reference = Format::signed(rw, rw as i32 - 1 - r_below).unwrap();
                let input = Format::signed(xw, xf).unwrap();
                let exact_width = xw + rw;
                let drop = drop.min(exact_width - 2);
                let product =
                    Format::signed(exact_width - drop, xf + reference.frac - 1 - drop as i32)
                        .unwrap();
                let state = Format::signed(
                    (product.width + extra + guard).min(64),
                    product.frac + guard as i32,
                )
                .unwrap();
                let out_drop = out_drop.min(product.width - 2);
                let output =
                    Format::signed(product.width - out_drop, product.frac - out_drop as i32)
                        .unwrap();
                let spec = Spec {
                    input,
                    reference,
                    product,
                    state,
                    output,
                    lowpass_shift: k,
                    rounding,
                    overflow: Overflow::Saturate,
                };
                let (x_lo, x_hi) = (input.min_code() as i64, input.max_code() as i64);
                let (r_lo, r_hi) = (reference.min_code() as i64, reference.max_code() as i64);
                let samples =
                    prop::collection::vec((x_lo..=x_hi, r_lo..=r_hi, r_lo..=r_hi), 1..1500);
                (Just(spec), samples).prop_map(|(spec, samples)| Case { spec, samples })
            },
        )
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(300))]
    #[test]
    fn fixed_stays_within_the_derived_bound_of_float(case in any_case()) {
        let plan = match Plan::new(&case.spec) {
            Ok(plan) => plan,
            // A state clipped to 64 bits can lose the product's integer bits: refused.
            Err(PlanError::Field { field: "state_format", .. }) => return Ok(()),
            Err(other) => return Err(TestCaseError::fail(other.to_string())),
        };
        let (worst, overflowed) = worst_error(&plan, &case.samples);
        prop_assume!(!overflowed);
        prop_assert!(worst <= plan.error_bound_lsb(), "{} > {} for {:?}", worst, plan.error_bound_lsb(), plan);
    }

    /// Full-scale inputs in every mode, wrap included: the state never overflows when it
    /// holds the product's integer bits, and `process` equals `step`.
    #[test]
    fn the_state_never_overflows(case in any_case(), wrap in any::<bool>()) {
        let mut spec = case.spec;
        if wrap {
            spec.overflow = Overflow::Wrap;
        }
        let Ok(state) = Format::signed((spec.product.int_bits() + spec.state.frac) as u32, spec.state.frac) else {
            return Ok(());
        };
        spec.state = state;
        let Ok(plan) = Plan::new(&spec) else { return Ok(()) };
        let extremes = [plan.input.min_code() as i64, plan.input.max_code() as i64];
        let rextremes = [plan.reference.min_code() as i64, plan.reference.max_code() as i64];
        let samples: Vec<(i64, Reference)> = case.samples.iter().enumerate().map(|(k, (x, s, c))| {
            if k % 3 == 0 { (extremes[k % 2], reference(rextremes[k / 2 % 2], rextremes[k / 4 % 2])) }
            else { (*x, reference(*s, *c)) }
        }).collect();
        let mut demodulator = FixedDemodulator::new(&plan);
        let stepped: Vec<Iq> = samples.iter().map(|(x, r)| demodulator.step(*x, *r)).collect();
        prop_assert_eq!(demodulator.overflow_counts().state, [0, 0]);
        let (x, r): (Vec<i64>, Vec<Reference>) = samples.into_iter().unzip();
        let mut block = vec![Iq::default(); x.len()];
        FixedDemodulator::new(&plan).process(&x, &r, &mut block);
        prop_assert_eq!(block, stepped);
    }
}
