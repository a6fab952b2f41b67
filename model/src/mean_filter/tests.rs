use proptest::prelude::*;

use super::*;
use crate::fx::{from_f64, Format, Overflow, Rounding};

fn spec(window: u32, threshold_dps: f64) -> Spec {
    Spec {
        input: "s24.14".parse().unwrap(),
        output: "s24.14".parse().unwrap(),
        window,
        threshold_dps,
        reciprocal_width: 18,
        rounding: Rounding::Nearest,
        overflow: Overflow::Saturate,
    }
}

fn code(value: f64, format: Format) -> i64 {
    from_f64(value, format, Rounding::Nearest, Overflow::Saturate)
        .unwrap()
        .code as i64
}

#[test]
fn a_gross_error_is_dropped_and_the_rest_averaged() {
    // Paper 003's setting: L = 20, r = 0.3 °/s; nineteen samples near 0.1 °/s and one spike.
    let plan = Plan::new(&spec(20, 0.3)).unwrap();
    let mut fixed = FixedMeanFilter::new(&plan);
    let mut float = FloatMeanFilter::new(&plan);
    let values: Vec<f64> = (0..20)
        .map(|i| {
            if i == 7 {
                5.0
            } else {
                0.1 + 0.01 * f64::from(i % 3)
            }
        })
        .collect();
    let mut results = Vec::new();
    for v in &values {
        let x = code(*v, plan.input);
        results.push((fixed.step(x), float.step(plan.input.to_f64(i128::from(x)))));
    }
    assert!(results[..19]
        .iter()
        .all(|(a, b)| a.is_none() && b.is_none()));
    let (Some(fixed), Some((float, kept))) = results[19] else {
        panic!("a block ends at the 20th sample");
    };
    assert_eq!((fixed.kept, kept), (19, 19));
    let without_spike: f64 = values.iter().filter(|v| **v < 1.0).sum::<f64>() / 19.0;
    assert!(
        (float - without_spike).abs() < 1e-4,
        "{float} {without_spike}"
    );
    assert!(
        (plan.output.to_f64(i128::from(fixed.y)) - float).abs()
            <= plan.error_bound_lsb() * plan.output.lsb()
    );
}

#[test]
fn a_block_with_every_sample_rejected_outputs_the_plain_mean() {
    // Two clusters 2 °/s apart: every sample is 1 °/s from the mean, beyond r = 0.3.
    let plan = Plan::new(&spec(4, 0.3)).unwrap();
    let mut filter = FixedMeanFilter::new(&plan);
    let xs = [1.5, -0.5, 1.5, -0.5].map(|v| code(v, plan.input));
    let result = xs.iter().filter_map(|x| filter.step(*x)).next().unwrap();
    assert_eq!(result.kept, 0);
    assert_eq!(result.y, code(0.5, plan.output));
}

#[test]
fn samples_exactly_r_from_the_mean_are_kept() {
    // Mean 0, samples ±r: |x − m| = r is kept (the rejection is strictly beyond r).
    let plan = Plan::new(&spec(2, 0.25)).unwrap();
    let mut filter = FixedMeanFilter::new(&plan);
    filter.step(code(0.25, plan.input));
    let result = filter.step(code(-0.25, plan.input)).unwrap();
    assert_eq!(result.kept, 2);
    // One LSB farther and both go.
    let r = code(0.25, plan.input);
    filter.step(r + 1);
    assert_eq!(filter.step(-r - 1).unwrap().kept, 0);
}

#[test]
fn reset_drops_the_partial_block() {
    let plan = Plan::new(&spec(3, 0.3)).unwrap();
    let mut filter = FixedMeanFilter::new(&plan);
    filter.step(1000);
    filter.step(2000);
    filter.reset();
    assert_eq!(filter.phase(), 0);
    assert!(filter.step(3).is_none());
}

#[test]
fn bad_specs_name_the_field_the_value_and_what_is_allowed() {
    let cases: [(Spec, &str); 6] = [
        (
            spec(1, 0.3),
            "mean_filter.window = 1 is not allowed: 2..=1024",
        ),
        (spec(1025, 0.3), "mean_filter.window = 1025"),
        (spec(20, -0.1), "mean_filter.threshold_dps = -0.1"),
        (spec(20, f64::NAN), "mean_filter.threshold_dps = NaN"),
        (spec(20, 600.0), "from 0 to the input range's"),
        (
            Spec {
                reciprocal_width: 3,
                ..spec(20, 0.3)
            },
            "mean_filter.reciprocal_width = 3 is not allowed: 4..=64 bits",
        ),
    ];
    for (spec, message) in cases {
        let err = Plan::new(&spec).unwrap_err().to_string();
        assert!(err.contains(message), "{err}");
    }
    // 1/1024 in s4.2 rounds to 0.
    let err = Plan::new(&Spec {
        reciprocal_width: 4,
        ..spec(1024, 0.3)
    })
    .unwrap_err()
    .to_string();
    assert!(err.contains("1/1024 is not 0"), "{err}");
}

#[test]
fn the_rom_holds_one_over_n_and_the_fallback_at_address_zero() {
    let plan = Plan::new(&spec(20, 0.3)).unwrap();
    assert_eq!(plan.rom.len(), 21);
    assert_eq!(plan.rom[0], plan.rom[20]);
    for n in 1..=20u32 {
        let error = (plan.reciprocal_at(n as usize) - 1.0 / f64::from(n)).abs();
        assert!(error <= plan.reciprocal.lsb() / 2.0, "1/{n}: {error}");
    }
    assert_eq!(plan.threshold_code, (0.3f64 * 16384.0).round() as i128);
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(300))]

    /// Fixed vs float on the same codes: the same samples kept, and the means within
    /// `error_bound_lsb`, over random formats, windows, thresholds, rounding modes and inputs
    /// (with gross errors).
    #[test]
    fn fixed_matches_float_within_the_bound(
        input_width in 8u32..=32,
        input_integer in 3i32..=10,
        extra_output_frac in -3i32..=6,
        window in 2u32..=64,
        threshold_lsb_fraction in 0.0f64..0.3,
        reciprocal_width in 8u32..=32,
        rounding in proptest::sample::select(Rounding::ALL.to_vec()),
        seed in any::<u64>(),
        blocks in 1usize..=6,
    ) {
        let input_frac = input_width as i32 - input_integer;
        let input = Format::signed(input_width, input_frac).unwrap();
        // At least one integer bit more than the input: the mean of kept samples never overflows.
        let output_width = (input_width as i32 + 1 + extra_output_frac.max(0)) as u32;
        let output = Format::signed(output_width, input_frac + extra_output_frac).unwrap();
        let range = input.max_value();
        let plan = Plan::new(&Spec {
            input,
            output,
            window,
            threshold_dps: threshold_lsb_fraction * range,
            reciprocal_width,
            rounding,
            overflow: Overflow::Saturate,
        }).unwrap();
        let mut fixed = FixedMeanFilter::new(&plan);
        let mut float = FloatMeanFilter::new(&plan);
        let mut state = seed | 1;
        let half = input.max_code() / 2;
        for _ in 0..blocks * window as usize {
            // xorshift: values within half the range, every ~7th a gross error.
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            let spread = if state % 7 == 0 { half } else { half / 16 + 1 };
            let x = (state >> 8) as i128 % (2 * spread + 1) - spread;
            let a = fixed.step(x as i64);
            let b = float.step(input.to_f64(x));
            prop_assert_eq!(a.is_some(), b.is_some());
            if let (Some(a), Some((y, kept))) = (a, b) {
                prop_assert_eq!(a.kept, kept);
                prop_assert!(!a.overflowed);
                let error = (output.to_f64(i128::from(a.y)) - y).abs() / output.lsb();
                prop_assert!(error <= plan.error_bound_lsb() * (1.0 + 1e-12), "{error} > {}", plan.error_bound_lsb());
            }
        }
    }
}
