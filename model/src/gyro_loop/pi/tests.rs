use super::*;
use proptest::prelude::*;

fn fmt(text: &str) -> Format {
    text.parse().unwrap()
}

/// What happens before a sample: nothing, a preset (integrator code) or a reset.
#[derive(Clone, Copy, Debug)]
enum Event {
    None,
    Preset(i64),
    Reset,
}

/// Largest `|fixed − float| − bound(n)` over the samples (≤ 0 when the bound holds), the
/// largest error in output LSB, and whether the output overflowed.
fn run(plan: &Plan, bound_plan: &Plan, samples: &[(i64, Event)]) -> (f64, f64, bool) {
    let mut fixed = FixedPi::new(plan);
    let mut float = FloatPi::new(plan);
    let lsb = plan.output.to.lsb();
    let mut since = 0u64;
    let (mut excess, mut worst) = (f64::NEG_INFINITY, 0.0f64);
    for (e, event) in samples {
        match event {
            Event::None => {}
            Event::Preset(code) => {
                fixed.preset(*code);
                float.preset(plan.integrator.to_f64(i128::from(*code)));
                since = 0;
            }
            Event::Reset => {
                fixed.reset();
                float.reset();
                since = 0;
            }
        }
        since += 1;
        let got = plan.output.to.to_f64(i128::from(fixed.step(*e)));
        let error = (got - float.step(plan.input.to_f64(i128::from(*e)))).abs() / lsb;
        worst = worst.max(error);
        excess = excess.max(error - bound_plan.error_bound_lsb(since));
    }
    (excess, worst, fixed.overflow_counts().output > 0)
}

/// `ki·e` leaves 31/32 of an integrator LSB to round every sample; `kp` = 0 so the output
/// shows the integrator.
fn drifting_spec() -> Spec {
    Spec {
        input: fmt("s16.15"),
        kp: 0.0,
        ki: 31.0 / 1048576.0,
        kp_format: CoefficientFormat::Fixed(fmt("s16.20")),
        ki_format: CoefficientFormat::Fixed(fmt("s16.20")),
        integrator: fmt("s40.30"), // ki·e has 35 fraction bits: 5 are rounded
        integrator_limits: [-100.0, 100.0],
        output: fmt("s48.30"),
        rounding: Rounding::Nearest,
        overflow: Overflow::Saturate,
    }
}

#[test]
fn an_integrator_rounded_down_breaks_the_bound() {
    let plan = Plan::new(&drifting_spec()).unwrap();
    assert!(!plan.integrator_is_exact());
    let samples = vec![(0x1001, Event::None); 100];
    let (excess, worst, overflowed) = run(&plan, &plan, &samples);
    assert!(!overflowed && excess <= 0.0, "{excess}");
    // Nearest rounds up by 1/32 LSB per sample.
    assert!((worst - 100.0 / 32.0).abs() < 1e-6, "{worst}");
    let mut mutated = plan.clone();
    mutated.integrator_point.rounding = Rounding::Floor;
    let (excess, worst, _) = run(&mutated, &plan, &samples);
    assert!(
        excess > 0.0,
        "floor integrator: {worst} LSB within the bound"
    );
}

#[test]
fn an_exact_integrator_leaves_only_the_output_rounding() {
    let mut spec = drifting_spec();
    spec.integrator = fmt("s48.35");
    spec.output = fmt("s32.30");
    spec.kp = 0.02;
    spec.integrator_limits = [-1.0, 1.0];
    let plan = Plan::new(&spec).unwrap();
    assert!(plan.integrator_is_exact());
    // Only the output rounding and the twin's own f64 rounding are left.
    assert!(plan.error_bound_lsb(20_000) < 0.51);
    let samples: Vec<(i64, Event)> = (0..20_000)
        .map(|k| (((k * 7919) % 20001 - 10000) as i64, Event::None))
        .collect();
    let (excess, worst, overflowed) = run(&plan, &plan, &samples);
    assert!(!overflowed && excess <= 0.0 && worst <= 0.5, "{worst}");
}

#[test]
fn the_clamp_stops_windup_and_presets_load_the_integrator() {
    let spec = Spec {
        integrator_limits: [-0.01, 0.01],
        ..Spec::default()
    };
    let plan = Plan::new(&spec).unwrap();
    let [lo, hi] = plan.limits.map(|c| c as i64);
    let mut pi = FixedPi::new(&plan);
    let full_scale = plan.input.max_code() as i64;
    for _ in 0..100_000 {
        pi.step(full_scale);
    }
    assert_eq!(pi.integrator(), hi);
    assert!(pi.overflow_counts().integrator_clamped > 90_000);
    // The first negative error moves it off the limit: nothing to unwind.
    pi.step(-full_scale);
    assert!(pi.integrator() < hi);
    for _ in 0..100_000 {
        pi.step(-full_scale);
    }
    assert_eq!(pi.integrator(), lo);

    // The PLL's mode switch: the integrator preset to a frequency, then an error of 0.
    let plan = Plan::new(&Spec::default()).unwrap();
    let mut pi = FixedPi::new(&plan);
    let nominal = 8142.0 / 200_000.0;
    pi.preset(plan.integrator_code(nominal).unwrap());
    let word = pi.step(0);
    assert!((word as f64 / 2f64.powi(32) - nominal).abs() <= 2f64.powi(-33) + 2f64.powi(-39));
    // Presets are clamped like updates.
    pi.preset(i64::MAX);
    assert_eq!(pi.integrator(), plan.limits[1] as i64);
    assert_eq!(
        plan.integrator_code(1.0).unwrap(),
        plan.limits[1] as i64,
        "a preset beyond the limits"
    );
    pi.reset();
    assert_eq!(pi.integrator(), 0);
}

#[test]
fn plan_errors_name_the_coefficient_value_and_bits() {
    let spec = Spec {
        kp: 3.0,
        kp_format: CoefficientFormat::Fixed(fmt("s18.16")),
        ..Spec::default()
    };
    let err = Plan::new(&spec).unwrap_err();
    let text = err.to_string();
    assert!(
        matches!(
            err,
            PlanError::CoefficientOverflow {
                name: "kp",
                bits_needed: 19,
                ..
            }
        ),
        "{text}"
    );
    assert!(
        text.contains("pi.kp = 3e0") && text.contains("s18.16"),
        "{text}"
    );

    let spec = Spec {
        ki: 1e-9,
        ki_format: CoefficientFormat::Fixed(fmt("s18.20")),
        ..Spec::default()
    };
    let text = Plan::new(&spec).unwrap_err().to_string();
    assert!(text.contains("pi.ki = 1e-9 quantizes to zero"), "{text}");

    let spec = Spec {
        integrator_limits: [0.05, 0.035],
        ..Spec::default()
    };
    let text = Plan::new(&spec).unwrap_err().to_string();
    assert!(
        text.contains("pi.integrator_limits = [0.05, 0.035]") && text.contains("min <= max"),
        "{text}"
    );
    let spec = Spec {
        integrator_limits: [0.0, 4.0],
        ..Spec::default()
    };
    assert!(Plan::new(&spec).unwrap_err().to_string().contains("s59.57"));
    let spec = Spec {
        output: fmt("s64.63"),
        ..Spec::default()
    };
    let text = Plan::new(&spec).unwrap_err().to_string();
    assert!(text.contains("pi.output_format = s64.63"), "{text}");
}

fn any_rounding() -> impl Strategy<Value = Rounding> {
    prop::sample::select(Rounding::ALL.to_vec())
}

#[derive(Debug, Clone)]
struct Case {
    spec: Spec,
    samples: Vec<(i64, Event)>,
}

/// `spec` with up to 2000 error codes over its input range, now and then a preset or a reset
/// before one.
fn with_samples(spec: Spec) -> impl Strategy<Value = Case> {
    let (lo, hi) = (spec.input.min_code() as i64, spec.input.max_code() as i64);
    let event = prop_oneof![
        40 => Just(Event::None),
        1 => any::<i64>().prop_map(|c| Event::Preset(c >> 20)),
        1 => Just(Event::Reset),
    ];
    let samples = prop::collection::vec((lo..=hi, event), 1..2000);
    (Just(spec), samples).prop_map(|(spec, samples)| Case { spec, samples })
}

/// `fast.step` against `reference.step_reference` over `samples` (presets and resets applied
/// to both): the same outputs, integrators and counts.
fn paths_agree(
    fast: &mut FixedPi,
    reference: &mut FixedPi,
    samples: &[(i64, Event)],
) -> Result<(), TestCaseError> {
    for (k, (e, event)) in samples.iter().enumerate() {
        match event {
            Event::Preset(code) => {
                fast.preset(*code);
                reference.preset(*code);
            }
            Event::Reset => {
                fast.reset();
                reference.reset();
            }
            Event::None => {}
        }
        prop_assert_eq!(fast.step(*e), reference.step_reference(*e), "sample {}", k);
        prop_assert_eq!(fast.integrator(), reference.integrator());
    }
    prop_assert_eq!(fast.overflow_counts(), reference.overflow_counts());
    Ok(())
}

fn any_case() -> impl Strategy<Value = Case> {
    (
        (6u32..=28, 0i32..=28),         // input width, frac
        (-12.0f64..2.0, -16.0f64..0.0), // log2 |kp|, |ki|
        (any::<bool>(), any::<bool>()), // their signs
        (4u32..=24, 4u32..=24),         // their widths
        (2u32..=6, -8i32..=24),         // integrator integer bits, frac offset from the input's
        (-1.0f64..1.0, 0.0f64..1.0),    // limits: centre and half-width, fractions of range
        (-4i32..=12, 0u32..=8),         // output frac offset from the integrator, extra int bits
        any_rounding(),
    )
        .prop_flat_map(
            |(
                (ew, ef),
                (lkp, lki),
                (skp, ski),
                (wkp, wki),
                (vi, voff),
                (centre, half),
                (ooff, oextra),
                rounding,
            )| {
                let input = Format::signed(ew, ef.min(ew as i32)).unwrap();
                let vfrac = input.frac + voff;
                let integrator =
                    Format::signed((vi as i32 + vfrac).clamp(2, 64) as u32, vfrac).unwrap();
                let range = integrator.max_value();
                let low = range * (centre - half).max(-1.0) * 0.9;
                let high = range * (centre + half).min(1.0) * 0.9;
                let ofrac = vfrac - ooff;
                let output = Format::signed(
                    (integrator.int_bits() + 2 + oextra as i32 + ofrac).clamp(2, 64) as u32,
                    ofrac,
                )
                .unwrap();
                let sign = |negative: bool| if negative { -1.0 } else { 1.0 };
                let spec = Spec {
                    input,
                    kp: sign(skp) * 2f64.powf(lkp),
                    ki: sign(ski) * 2f64.powf(lki),
                    kp_format: CoefficientFormat::Auto { width: wkp },
                    ki_format: CoefficientFormat::Auto { width: wki },
                    integrator,
                    integrator_limits: [low, high],
                    output,
                    rounding,
                    overflow: Overflow::Saturate,
                };
                with_samples(spec)
            },
        )
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(400))]
    /// Random formats, gains, limits, modes, errors, presets and resets: every output within
    /// the bound for the samples since the last preset or reset.
    #[test]
    fn fixed_stays_within_the_derived_bound_of_float(case in any_case()) {
        let plan = match Plan::new(&case.spec) {
            Ok(plan) => plan,
            // Tiny widths can push a gain to zero, and narrow outputs can need more fraction
            // bits than kp·e + v has: refused designs.
            Err(PlanError::CoefficientZero { .. }) | Err(PlanError::Field { field: "output_format", .. }) => return Ok(()),
            Err(other) => return Err(TestCaseError::fail(other.to_string())),
        };
        let samples: Vec<(i64, Event)> = case.samples.iter().map(|(e, ev)| match ev {
            Event::Preset(code) => {
                let (lo, hi) = (plan.integrator.min_code() as i64, plan.integrator.max_code() as i64);
                (*e, Event::Preset((*code).clamp(lo, hi)))
            }
            other => (*e, *other),
        }).collect();
        let (excess, worst, overflowed) = run(&plan, &plan, &samples);
        prop_assume!(!overflowed);
        prop_assert!(excess <= 0.0, "{} LSB beyond the bound (worst {}) for {:?}", excess, worst, plan);
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(300))]
    /// The monomorphized 64-bit path, the literal i128 reference and `process` give the same
    /// bits and counts, for every mode, wrap and saturate, with presets and overflowing
    /// outputs.
    #[test]
    fn fast_path_equals_the_reference(case in any_case(), wrap in any::<bool>(), narrow_out in any::<bool>()) {
        let mut spec = case.spec;
        if wrap {
            spec.overflow = Overflow::Wrap;
        }
        if narrow_out {
            spec.output = Format::signed(spec.output.width.saturating_sub(6).max(2), spec.output.frac).unwrap();
        }
        let Ok(plan) = Plan::new(&spec) else { return Ok(()) };
        let mut fast = FixedPi::new(&plan);
        paths_agree(&mut fast, &mut FixedPi::new(&plan), &case.samples)?;
        let e: Vec<i64> = case.samples.iter().map(|s| s.0).collect();
        let mut block = vec![0; e.len()];
        FixedPi::new(&plan).process(&e, &mut block);
        let mut pi = FixedPi::new(&plan);
        let stepped: Vec<i64> = e.iter().map(|x| pi.step_reference(*x)).collect();
        prop_assert_eq!(block, stepped);
    }
}

/// A PLL-like family whose integrator update is wider than 64 bits (`v` aligned to `ki·e`'s
/// many fraction bits), so that [`FixedPi::step`] takes the split path.
fn wide_update_case() -> impl Strategy<Value = Case> {
    (
        (16u32..=32, 0.0f64..1.0),    // input width, frac as a fraction of it
        (8u32..=24, 28i32..=44),      // ki width, frac
        (30u32..=62, 16i32..=40),     // integrator width, frac
        (-0.9f64..0.9, 0.05f64..0.9), // limits: centre and half-width, fractions of range
        (any::<bool>(), 0.0f64..1.0), // ki sign, magnitude as a fraction of its format's range
        any_rounding(),
        any::<bool>(), // wrap
    )
        .prop_flat_map(
            |((ew, ef), (wk, fk), (wv, fv), (centre, half), (ski, mki), rounding, wrap)| {
                let input = Format::signed(ew, (ef * f64::from(ew)) as i32).unwrap();
                let ki_format = Format::signed(wk, fk).unwrap();
                let integrator = Format::signed(wv, fv.min(wv as i32 - 2)).unwrap();
                let range = integrator.max_value();
                let ki = if ski { -1.0 } else { 1.0 } * ki_format.max_value() * (0.02 + 0.9 * mki);
                let spec = Spec {
                    input,
                    kp: 0.25,
                    ki,
                    kp_format: CoefficientFormat::Fixed(fmt("s12.8")),
                    ki_format: CoefficientFormat::Fixed(ki_format),
                    integrator,
                    integrator_limits: [
                        range * (centre - half).max(-0.95),
                        range * (centre + half).min(0.95),
                    ],
                    output: Format::signed(
                        (integrator.int_bits() + 4 + integrator.frac).clamp(2, 64) as u32,
                        integrator.frac,
                    )
                    .unwrap(),
                    rounding,
                    overflow: if wrap {
                        Overflow::Wrap
                    } else {
                        Overflow::Saturate
                    },
                };
                with_samples(spec)
            },
        )
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(300))]
    /// The split 64-bit path against the literal i128 reference, for every mode, wrap and
    /// saturate, presets and resets: the same bits, integrator and counts.
    #[test]
    fn split_update_path_equals_the_reference(case in wide_update_case()) {
        let Ok(plan) = Plan::new(&case.spec) else { return Ok(()) };
        let mut fast = FixedPi::new(&plan);
        prop_assume!(matches!(fast.fast, Some((_, Path::SplitUpdate))));
        paths_agree(&mut fast, &mut FixedPi::new(&plan), &case.samples)?;
    }
}

/// The default PLL (and the resonator loop's) update is wider than 64 bits: it takes the split
/// path, the AGC the narrow one.
#[test]
fn the_default_pll_takes_the_split_path_and_the_agc_the_narrow_one() {
    let plan =
        crate::gyro_loop::gyro::Plan::new(&crate::gyro_loop::gyro::Spec::paper_004()).unwrap();
    assert!(matches!(
        FixedPi::new(&plan.pll).fast,
        Some((_, Path::SplitUpdate))
    ));
    assert!(matches!(
        FixedPi::new(&plan.agc).fast,
        Some((_, Path::Narrow))
    ));
    assert!(matches!(
        FixedPi::new(&Plan::new(&Spec::default()).unwrap()).fast,
        Some((_, Path::SplitUpdate)) | Some((_, Path::Narrow))
    ));
}
