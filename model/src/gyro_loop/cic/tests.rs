use super::*;
use proptest::prelude::*;

fn fmt(text: &str) -> Format {
    text.parse().unwrap()
}

/// The `i`-th of `n` pseudo-random codes of `format` (a fixed LCG: deterministic stimulus).
fn codes(format: Format, n: usize, seed: u64) -> Vec<i64> {
    let mut state = seed;
    let (lo, hi) = (format.min_code(), format.max_code());
    (0..n)
        .map(|_| {
            state = state
                .wrapping_mul(6_364_136_223_846_793_005)
                .wrapping_add(1_442_695_040_888_963_407);
            (lo + i128::from(state >> 11) % (hi - lo + 1)) as i64
        })
        .collect()
}

/// Largest `|fixed − float|` over the outputs, in output LSB; the number of outputs; and
/// whether a quantizer overflowed.
fn worst_error(plan: &Plan, x: &[i64]) -> (f64, usize, bool) {
    let mut fixed = FixedCic::new(plan);
    let mut float = FloatCic::new(plan);
    let lsb = plan.output.to.lsb();
    let (mut worst, mut outputs) = (0.0f64, 0);
    for xi in x {
        let got = fixed.step(*xi);
        let want = float.step(plan.input.to_f64(i128::from(*xi)));
        assert_eq!(got.is_some(), want.is_some(), "the decimation phases agree");
        if let (Some(got), Some(want)) = (got, want) {
            worst = worst.max((plan.output.to.to_f64(i128::from(got)) - want).abs() / lsb);
            outputs += 1;
        }
    }
    let counts = fixed.overflow_counts();
    (worst, outputs, counts.cic > 0 || counts.output > 0)
}

fn spec(stages: u32, decimation: u32, delay: u32) -> Spec {
    Spec {
        stages,
        decimation,
        differential_delay: delay,
        passband: 0.25 / f64::from(delay),
        ..Spec::default()
    }
}

#[test]
fn register_growth_is_exact() {
    for (n, r, m, growth) in [
        (3, 1000, 1, 30), // 10^9 <= 2^30
        (3, 4000, 1, 36), // 6.4e10 <= 2^36
        (4, 1024, 1, 40), // exactly 2^40
        (4, 1025, 1, 41),
        (4, 4000, 2, 52), // 4.096e15 <= 2^52
        (1, 2, 1, 1),
    ] {
        let plan = Plan::new(&Spec {
            cic_output: fmt("s24.23"),
            ..spec(n, r, m)
        })
        .unwrap();
        assert_eq!(plan.growth_bits, growth, "N={n} R={r} M={m}");
        assert_eq!(plan.register.width, 24 + growth);
        assert_eq!(plan.shift, growth);
    }
}

#[test]
fn the_default_compensator_flattens_the_droop() {
    let plan = Plan::new(&Spec::default()).unwrap();
    let flatness = plan.flatness();
    assert!(flatness.uncompensated_edge_db < -2.7, "{flatness:?}");
    assert!(flatness.ripple_db() < 0.035, "{flatness:?}");
    assert!((flatness.dc_gain - 1.0).abs() < 1e-4, "{flatness:?}");
    let taps = plan.tap_values();
    assert_eq!(taps.len(), 5);
    for k in 0..5 {
        assert_eq!(taps[k], taps[4 - k], "symmetric");
    }
    // At the 50 Hz chain rate (R = 4000) the same holds.
    let plan = Plan::new(&spec(3, 4000, 1)).unwrap();
    assert!(plan.flatness().ripple_db() < 0.035, "{:?}", plan.flatness());
    assert_eq!(plan.register.width, 60);
    // Two more taps buy an order of magnitude.
    let plan = Plan::new(&Spec {
        taps: 7,
        ..Spec::default()
    })
    .unwrap();
    assert!(plan.flatness().ripple_db() < 0.005, "{:?}", plan.flatness());
}

#[test]
fn full_scale_inputs_wrap_the_integrators_and_the_combs_undo_it() {
    // B = 24 + 48 = 72 bits: the i128 registers.
    let plan = Plan::new(&spec(4, 4000, 1)).unwrap();
    assert!(plan.register.width > 64);
    // 7/8 of full scale: the compensator's DC gain, a hair over 1, must not saturate.
    let mut x = vec![(plan.input.max_code() * 7 / 8) as i64; 30_000];
    x.extend(codes(plan.input, 30_000, 7));
    let mut fixed = FixedCic::new(&plan);
    let mut wrapped = false;
    for xi in &x {
        fixed.step(*xi);
        wrapped |= fixed
            .integrators()
            .iter()
            .any(|v| *v < 0 && fixed.phase() > 0);
    }
    assert!(
        wrapped,
        "a positive input drove an integrator negative: it wrapped"
    );
    let (worst, outputs, overflowed) = worst_error(&plan, &x);
    assert_eq!(outputs, 15);
    assert!(!overflowed);
    assert!(
        worst <= plan.error_bound_lsb(),
        "{worst} > {}",
        plan.error_bound_lsb()
    );
}

#[test]
fn a_cic_output_rounded_down_breaks_the_bound() {
    let plan = Plan::new(&Spec {
        input: fmt("s16.15"),
        cic_output: fmt("s20.17"), // the scaled comb output has 22 fraction bits
        output: fmt("s24.21"),
        taps: 3,
        ..spec(2, 9, 1)
    })
    .unwrap();
    // 81·x ≡ 31 (mod 32): 31/32 of a CIC-output LSB to round at every output.
    let x = vec![15 + 32 * 100; 50 * 9];
    let (worst, _, overflowed) = worst_error(&plan, &x);
    assert!(!overflowed && worst <= plan.error_bound_lsb());
    let mut mutated = plan.clone();
    mutated.cic.rounding = Rounding::Floor;
    let (worst, _, _) = worst_error(&mutated, &x);
    assert!(
        worst > plan.error_bound_lsb(),
        "floor: {worst} <= {}",
        plan.error_bound_lsb()
    );
}

#[test]
fn reset_restarts_the_decimation_phase() {
    let plan = Plan::new(&spec(2, 5, 2)).unwrap();
    let x = codes(plan.input, 200, 3);
    let mut cic = FixedCic::new(&plan);
    let first: Vec<Option<i64>> = x.iter().map(|v| cic.step(*v)).collect();
    assert_eq!(first.iter().filter(|y| y.is_some()).count(), 40);
    assert!(first[4].is_some() && first[3].is_none());
    cic.step(1);
    cic.reset();
    let again: Vec<Option<i64>> = x.iter().map(|v| cic.step(*v)).collect();
    assert_eq!(first, again);
    let mut block = vec![0; 40];
    assert_eq!(FixedCic::new(&plan).process(&x, &mut block), 40);
    let outputs: Vec<i64> = first.into_iter().flatten().collect();
    assert_eq!(block, outputs);
}

#[test]
fn plan_errors_name_the_field() {
    let cases: [(Spec, &str); 6] = [
        (
            Spec {
                taps: 4,
                ..Spec::default()
            },
            "cic.taps = 4 is not allowed: an odd number 1..=15",
        ),
        (
            Spec {
                passband: 0.3,
                ..spec(3, 1000, 2)
            },
            "cic.passband = 0.3 is not allowed: (0, 0.25)",
        ),
        (
            spec(3, 1, 1),
            "cic.decimation = 1 is not allowed: 2..=65536",
        ),
        (spec(0, 100, 1), "cic.stages = 0"),
        (
            spec(8, 65536, 2),
            "cic.stages = 8 is not allowed: a CIC gain",
        ),
        (
            Spec {
                cic_output: fmt("s28.60"),
                ..Spec::default()
            },
            "cic.cic_output_format = s28.60 is not allowed: fraction bits from",
        ),
    ];
    for (spec, want) in cases {
        let text = Plan::new(&spec).unwrap_err().to_string();
        assert!(text.contains(want), "{text}");
    }
    let text = Plan::new(&Spec {
        coefficients: CoefficientFormat::Fixed(fmt("s18.17")),
        ..Spec::default()
    })
    .unwrap_err()
    .to_string();
    assert!(
        text.contains("cic.taps = ") && text.contains("does not fit s18.17"),
        "{text}"
    );
    let text = Plan::new(&Spec {
        input: fmt("s60.40"),
        ..spec(6, 4000, 1)
    })
    .unwrap_err()
    .to_string();
    assert!(text.contains("cic integrator registers"), "{text}");
}

fn any_rounding() -> impl Strategy<Value = Rounding> {
    prop::sample::select(Rounding::ALL.to_vec())
}

#[derive(Debug, Clone)]
struct Case {
    spec: Spec,
    seed: u64,
    outputs: usize,
}

fn any_case() -> impl Strategy<Value = Case> {
    (
        (4u32..=28, -4i32..=28),                // input width, frac
        (1u32..=5, 2u32..=40, 1u32..=2),        // N, R, M
        prop::option::weighted(0.2, 0u32..=12), // an explicit shift
        (0u32..=16, 1u32..=3), // CIC output: extra fraction bits, extra integer bits
        (0u32..=3, 0.02f64..0.45), // taps (2t+1), passband (fraction of 0.5/M)
        4u32..=24,             // tap width
        (0u32..=12, 1u32..=3), // output: fraction bits dropped, extra integer bits
        any_rounding(),
        (any::<u64>(), 1usize..40),
    )
        .prop_map(
            |(
                (iw, f),
                (n, r, m),
                shift,
                (cfrac, cint),
                (t, pass),
                tw,
                (odrop, oint),
                rounding,
                (seed, outputs),
            )| {
                let input = Format::signed(iw, f).unwrap();
                // The CIC output can have at most `shift` more fraction bits than the input.
                let growth = 128 - (u128::from(r * m).pow(n) - 1).leading_zeros();
                let cfrac = cfrac.min(shift.unwrap_or(growth));
                let cic_output = Format::signed(
                    (input.int_bits() + cint as i32 + f + cfrac as i32).clamp(2, 64) as u32,
                    f + cfrac as i32,
                )
                .unwrap();
                let ofrac = cic_output.frac - odrop as i32;
                let output = Format::signed(
                    (cic_output.int_bits() + oint as i32 + ofrac).clamp(2, 64) as u32,
                    ofrac,
                )
                .unwrap();
                Case {
                    spec: Spec {
                        input,
                        stages: n,
                        decimation: r,
                        differential_delay: m,
                        shift,
                        cic_output,
                        taps: 2 * t + 1,
                        passband: pass / f64::from(m),
                        coefficients: CoefficientFormat::Auto { width: tw },
                        output,
                        rounding,
                        overflow: Overflow::Saturate,
                    },
                    seed,
                    outputs,
                }
            },
        )
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(300))]
    /// Random formats, stages, decimations, delays, compensators, modes and full-range
    /// inputs: every output within the derived bound of the direct-form float twin.
    #[test]
    fn fixed_stays_within_the_derived_bound_of_float(case in any_case()) {
        let plan = match Plan::new(&case.spec) {
            Ok(plan) => plan,
            // An explicit shift can leave the CIC output's fraction out of reach, and tiny
            // tap widths can round a tap to zero: refused designs.
            Err(PlanError::Field { field: "cic_output_format", .. })
            | Err(PlanError::Field { field: "output_format", .. })
            | Err(PlanError::CoefficientZero { .. }) => return Ok(()),
            Err(other) => return Err(TestCaseError::fail(other.to_string())),
        };
        let x = codes(plan.input, case.outputs * plan.decimation as usize, case.seed);
        let (worst, outputs, overflowed) = worst_error(&plan, &x);
        prop_assert_eq!(outputs, case.outputs);
        prop_assume!(!overflowed);
        prop_assert!(worst <= plan.error_bound_lsb(), "{} > {} for {:?}", worst, plan.error_bound_lsb(), plan);
    }

    /// The i64 registers (B ≤ 64) and the i128 ones give the same bits.
    #[test]
    fn narrow_and_wide_registers_agree(case in any_case(), wrap in any::<bool>()) {
        let mut spec = case.spec;
        if wrap {
            spec.overflow = Overflow::Wrap;
        }
        let Ok(plan) = Plan::new(&spec) else { return Ok(()) };
        prop_assume!(plan.register.width <= 64);
        let x = codes(plan.input, case.outputs * plan.decimation as usize, case.seed);
        let mut narrow = FixedCic::new(&plan);
        let mut wide = FixedCic::new(&plan);
        wide.engine = Engine::Wide(Registers::default());
        for xi in &x {
            prop_assert_eq!(narrow.step(*xi), wide.step(*xi));
            prop_assert_eq!(narrow.integrators(), wide.integrators());
        }
    }
}
