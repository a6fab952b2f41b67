use super::*;
use crate::fx::{Format, Overflow, Rounding};
use crate::stimulus::adc;
use proptest::prelude::*;

fn fmt(text: &str) -> Format {
    text.parse().unwrap()
}

fn default_spec() -> Spec {
    crate::examples::kf_spec()
}

fn default_input(samples: usize, seed: u64) -> Vec<i64> {
    adc(
        &crate::examples::gyro().simulate(samples, seed).analog,
        fmt("s24.14"),
    )
    .0
}

#[test]
fn default_plan_gives_each_coefficient_its_own_scaling() {
    let plan = Plan::new(&default_spec()).unwrap();
    assert_eq!(plan.coefficient[0], fmt("s18.17"));
    // g2 is ~1e-6 of g1: ~20 more fraction bits, and the largest entry uses the full width.
    assert!(plan.coefficient[1].frac > 35, "{}", plan.coefficient[1]);
    let largest = plan.rom.iter().map(|c| c[1].abs()).max().unwrap();
    assert!(largest > 1 << 16, "{largest}");
    assert_eq!(plan.select_width(), 2);
    assert_eq!(plan.error, Format::intermediate(true, 38, 26).unwrap());
    for (sel, g) in plan.quantized_gains().iter().enumerate() {
        let exact = plan.gains[sel];
        assert!(((g[0] - exact[0]) / exact[0]).abs() < 1e-5);
        assert!(((g[1] - exact[1]) / exact[1]).abs() < 1e-3);
        assert_eq!(plan.eigenvalues(sel)[0], 1.0);
        assert!(plan.eigenvalues(sel)[1] > 0.0 && plan.eigenvalues(sel)[1] < 1.0);
    }
}

#[test]
fn an_offset_along_the_unobservable_direction_survives_bit_for_bit() {
    let plan = Plan::new(&default_spec()).unwrap();
    let input = default_input(20_000, 3);
    let mut a = FixedKf::new(&plan);
    let mut b = FixedKf::new(&plan);
    let offset = 12_345i128;
    b.set_state([offset, -offset]);
    for (k, z) in input.iter().enumerate() {
        let sel = (k / 5000) % 3;
        a.step(*z, sel);
        b.step(*z, sel);
        let (xa, xb) = (a.state(), b.state());
        assert_eq!(
            [xb[0] - xa[0], xb[1] - xa[1]],
            [offset, -offset],
            "sample {k}"
        );
    }
}

#[test]
fn default_config_stays_within_one_output_lsb_over_a_million_samples() {
    let plan = Plan::new(&default_spec()).unwrap();
    let n = 1_000_000;
    let input = default_input(n, 11);
    let mut fixed = FixedKf::new(&plan);
    let mut float = FloatKf::new(plan.quantized_gains());
    let lsb = plan.output.lsb();
    let mut worst: f64 = 0.0;
    for (k, z) in input.iter().enumerate() {
        let sel = (k / 250_000) % 3;
        let out = fixed.step(*z, sel);
        let reference = float.step(plan.input.to_f64(i128::from(*z)), sel);
        worst = worst.max((plan.output.to_f64(i128::from(out)) - reference).abs() / lsb);
    }
    assert_eq!(fixed.overflow_counts(), OverflowCounts::default());
    assert!(worst <= 1.0, "worst |fixed - float| = {worst} LSB");
    // The statistical rule of the bound module predicts this comfortably.
    assert!(bound::random_walk_rms_lsb(&plan, n as u64) < 0.1);
}

#[test]
fn floor_rounding_drifts_as_the_bound_module_warns() {
    let mut spec = default_spec();
    spec.rounding = Rounding::Floor;
    let plan = Plan::new(&spec).unwrap();
    let input = default_input(200_000, 5);
    let mut fixed = FixedKf::new(&plan);
    let mut float = FloatKf::new(plan.quantized_gains());
    let mut last = 0.0;
    for z in &input {
        let out = fixed.step(*z, 0);
        let reference = float.step(plan.input.to_f64(i128::from(*z)), 0);
        last = (plan.output.to_f64(i128::from(out)) - reference) / plan.output.lsb();
    }
    // ~q_x/2 per sample along [1, -1]: 200000 / 2 / 4096 ≈ 24 LSB.
    assert!(last.abs() > 10.0, "{last}");
    assert!(last.abs() <= bound::rate_error_bound_lsb(&plan, 200_000, 0));
}

#[test]
fn reset_returns_to_the_initial_state_and_bw_sel_switches_mid_stream() {
    let plan = Plan::new(&default_spec()).unwrap();
    let input = default_input(3000, 1);
    let mut kf = FixedKf::new(&plan);
    let first: Vec<i64> = input[..100].iter().map(|z| kf.step(*z, 2)).collect();
    for z in &input[100..] {
        kf.step(*z, 1);
    }
    kf.reset();
    let again: Vec<i64> = input[..100].iter().map(|z| kf.step(*z, 2)).collect();
    assert_eq!(first, again);
    // Different ROM entries filter differently.
    let mut narrow = FixedKf::new(&plan);
    let mut wide = FixedKf::new(&plan);
    let a: Vec<i64> = input.iter().map(|z| narrow.step(*z, 0)).collect();
    let b: Vec<i64> = input.iter().map(|z| wide.step(*z, 2)).collect();
    assert_ne!(a, b);
}

#[test]
fn saturation_is_counted() {
    let mut spec = default_spec();
    spec.state = fmt("s28.26"); // only ±2 °/s of state range
    let plan = Plan::new(&spec).unwrap();
    let mut kf = FixedKf::new(&plan);
    let full_scale = plan.input.max_code() as i64;
    for _ in 0..100 {
        kf.step(full_scale, 0);
    }
    let counts = kf.overflow_counts();
    assert!(counts.x1 > 0, "{counts:?}");
    assert_eq!(kf.state()[0], plan.state.max_code());
}

#[test]
fn plan_errors_name_the_coefficient_and_format() {
    let mut spec = default_spec();
    spec.coefficients[0] = CoefficientFormat::Fixed(fmt("s18.18"));
    spec.gains[2][0] = 0.6;
    let err = Plan::new(&spec).unwrap_err();
    let text = err.to_string();
    assert!(
        matches!(
            err,
            PlanError::CoefficientOverflow {
                name: "g1",
                bits_needed: 19,
                ..
            }
        ),
        "{text}"
    );
    assert!(
        text.contains("g1") && text.contains("30 Hz") && text.contains("s18.18"),
        "{text}"
    );

    let mut spec = default_spec();
    spec.coefficients[1] = CoefficientFormat::Fixed(fmt("s18.17"));
    let err = Plan::new(&spec).unwrap_err();
    assert!(
        matches!(err, PlanError::CoefficientZero { name: "g2", .. }),
        "{err}"
    );
    assert!(err.to_string().contains("quantizes to zero"));

    let mut spec = default_spec();
    spec.gains[1] = [2.5, 0.0];
    spec.coefficients[0] = CoefficientFormat::Auto { width: 18 };
    let err = Plan::new(&spec).unwrap_err();
    assert!(matches!(err, PlanError::Unstable { .. }), "{err}");
    assert!(err.to_string().contains("-1.5"), "{err}");

    let mut spec = default_spec();
    spec.state = fmt("s30.10");
    assert!(Plan::new(&spec)
        .unwrap_err()
        .to_string()
        .contains("state_format = s30.10"));
    let mut spec = default_spec();
    spec.output = fmt("u24.14");
    assert!(Plan::new(&spec)
        .unwrap_err()
        .to_string()
        .contains("output_format = u24.14"));
    let mut spec = default_spec();
    spec.input = fmt("s64.20");
    spec.state = fmt("s64.60");
    spec.coefficients = [CoefficientFormat::Auto { width: 32 }; 2];
    let err = Plan::new(&spec).unwrap_err();
    assert!(
        matches!(err, PlanError::Intermediate { node: "g1 * e", .. }),
        "{err}"
    );
}

fn any_rounding() -> impl Strategy<Value = Rounding> {
    prop::sample::select(Rounding::ALL.to_vec())
}

/// Random formats, gains, modes and inputs (with `bw_sel` switches and resets): the fixed model
/// stays within the derived worst-case bound of the float model fed the same quantized gains.
#[derive(Debug, Clone)]
struct Case {
    spec: Spec,
    inputs: Vec<(i64, usize, bool)>,
}

fn any_case() -> impl Strategy<Value = Case> {
    (
        8u32..=32,  // input width
        -4i32..=20, // input frac
        0i32..=16,  // guard bits
        2u32..=4,   // extra state integer bits
        6u32..=24,  // coefficient width
        prop::collection::vec((0.002f64..1.9, -9.0f64..0.0), 1..=4),
        any_rounding(),
    )
        .prop_flat_map(|(in_w, in_f, guard, extra_int, coef_w, gains, rounding)| {
            let entries = gains.len();
            let amplitude = 1i64 << (in_w - 4);
            let inputs = prop::collection::vec(
                (
                    -amplitude..amplitude,
                    0..entries,
                    prop::bool::weighted(0.002),
                ),
                50..1500,
            );
            let spec = Spec {
                input: Format::signed(in_w, in_f).unwrap(),
                state: Format::signed(in_w + guard as u32 + extra_int, in_f + guard).unwrap(),
                output: Format::signed(in_w, in_f).unwrap(),
                coefficients: [CoefficientFormat::Auto { width: coef_w }; 2],
                rounding,
                overflow: Overflow::Saturate,
                gains: gains
                    .iter()
                    .map(|(s, log_ratio)| {
                        let ratio = 10f64.powf(*log_ratio);
                        [s / (1.0 + ratio), s * ratio / (1.0 + ratio)]
                    })
                    .collect(),
                labels: (0..entries).map(|i| format!("entry {i}")).collect(),
            };
            (Just(spec), inputs).prop_map(|(spec, inputs)| Case { spec, inputs })
        })
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(400))]
    #[test]
    fn fixed_stays_within_the_derived_bound_of_float(case in any_case()) {
        let plan = match Plan::new(&case.spec) {
            Ok(plan) => plan,
            // Tiny coefficient widths can round a small g2 to zero: a refused design.
            Err(PlanError::CoefficientZero { .. }) | Err(PlanError::Unstable { .. }) => return Ok(()),
            Err(other) => return Err(TestCaseError::fail(other.to_string())),
        };
        let mut fixed = FixedKf::new(&plan);
        let mut float = FloatKf::new(plan.quantized_gains());
        let mut switches = 0u64;
        let mut previous_sel = case.inputs[0].1;
        let mut worst: f64 = 0.0;
        for (z, sel, reset) in &case.inputs {
            if *reset {
                fixed.reset();
                float.reset();
            }
            if *sel != previous_sel {
                switches += 1;
                previous_sel = *sel;
            }
            let out = fixed.step(*z, *sel);
            let reference = float.step(plan.input.to_f64(i128::from(*z)), *sel);
            worst = worst.max((plan.output.to_f64(i128::from(out)) - reference).abs() / plan.output.lsb());
        }
        prop_assume!(fixed.overflow_counts() == OverflowCounts::default());
        let bound = bound::rate_error_bound_lsb(&plan, case.inputs.len() as u64, switches);
        prop_assert!(worst <= bound, "worst {} LSB > bound {} LSB for {}", worst, bound, plan);
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(300))]
    /// The monomorphized 64-bit fast path and the literal i128 reference give the same bits,
    /// overflow counts included, for every mode, wrap and saturate, narrow and wide plans.
    #[test]
    fn fast_path_equals_the_reference(
        case in any_case(),
        wrap in any::<bool>(),
        wide in any::<bool>(),
        boost in 0u32..6,
    ) {
        let mut spec = case.spec.clone();
        if wrap {
            spec.overflow = Overflow::Wrap;
        }
        if wide {
            // Push the error format past 64 bits: the reference path everywhere.
            spec.state = Format::signed(62, spec.state.frac + 40).unwrap_or(spec.state);
        }
        let plan = match Plan::new(&spec) {
            Ok(plan) => plan,
            Err(_) => return Ok(()),
        };
        let mut fast = FixedKf::new(&plan);
        let mut reference = FixedKf::new(&plan);
        for (k, (z, sel, reset)) in case.inputs.iter().enumerate() {
            if *reset {
                fast.reset();
                reference.reset();
            }
            // Larger inputs so that narrow states overflow now and then.
            let z = z.saturating_mul(1 << boost).clamp(plan.input.min_code() as i64, plan.input.max_code() as i64);
            let a = fast.step(z, *sel);
            let b = reference.step_reference(z, *sel);
            prop_assert_eq!(a, b, "sample {}", k);
            prop_assert_eq!(fast.state(), reference.state(), "sample {}", k);
        }
        prop_assert_eq!(fast.overflow_counts(), reference.overflow_counts());
        let mut block = vec![0i64; case.inputs.len()];
        let zs: Vec<i64> = case.inputs.iter().map(|c| c.0).collect();
        let mut by_block = FixedKf::new(&plan);
        by_block.process(&zs, 0, &mut block);
        let mut by_step = FixedKf::new(&plan);
        let stepped: Vec<i64> = zs.iter().map(|z| by_step.step_reference(*z, 0)).collect();
        prop_assert_eq!(block, stepped);
    }
}
