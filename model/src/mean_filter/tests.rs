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

#[test]
fn the_serial_division_floors_and_flags_a_remainder_at_every_edge() {
    // Every sum of an s9 register, windows that divide it and windows that do not.
    for window in [2u32, 3, 7, 20, 255] {
        for sum in -256i128..256 {
            let (floor, inexact) = serial::floor_divide(sum, 9, window);
            let divisor = i128::from(window);
            assert_eq!(floor, sum.div_euclid(divisor), "{sum}/{window}");
            assert_eq!(inexact, sum.rem_euclid(divisor) != 0, "{sum}/{window}");
        }
    }
}

#[test]
fn the_serial_bounds_keep_exactly_the_samples_the_deviation_test_keeps() {
    let plan = Plan::new(&spec(20, 0.3)).unwrap();
    let r = plan.threshold_code;
    // A sum that 20 does not divide (mean 1000.35) and one it does (mean −1000).
    for sum in [20_007i128, -20_000] {
        let (low, high) = serial::kept_range(&plan, sum);
        for x in low - 3..=high + 3 {
            let kept = (20 * x - sum).abs() <= 20 * r;
            assert_eq!(kept, (low..=high).contains(&x), "sum {sum}, x {x}");
        }
        assert!((20 * low - sum).abs() <= 20 * r && (20 * (low - 1) - sum).abs() > 20 * r);
    }
}

#[test]
fn the_serial_shift_and_add_product_is_the_product() {
    for operand in [0i128, 1, -1, 5, -7, (1 << 28) - 1, -(1 << 28)] {
        for reciprocal in [0i128, 1, 3, 0x0a_aaab, (1 << 24) - 1, 1 << 23] {
            assert_eq!(
                serial::shift_add_product(operand, reciprocal, 25),
                operand * reciprocal,
                "{operand} * {reciprocal}"
            );
        }
    }
}

#[test]
fn the_serial_latency_counts_every_phase() {
    // s24.14 input, L = 20: SUM_W = 29, RECIP_W = 18 (the spec's).
    let plan = Plan::new(&spec(20, 0.3)).unwrap();
    assert_eq!(plan.sum.width, 29);
    assert_eq!(
        serial::latency_clocks(&plan),
        1 + (29 - 1) + 1 + 20 + 1 + 1 + (18 - 1) + 1
    );
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(300))]

    /// The serial schedule (one division, bounds, shift-and-add product) gives the parallel
    /// filter's block means bit for bit: random formats, windows up to 1024, thresholds from 0
    /// to the whole range, every rounding and overflow mode, full-scale and clustered blocks.
    #[test]
    fn the_serial_schedule_matches_the_parallel_filter_bit_for_bit(
        input_width in 4u32..=40,
        output_width in 4u32..=40,
        output_frac_shift in -4i32..=4,
        window in 2u32..=1024,
        threshold_fraction in 0.0f64..=1.0,
        reciprocal_width in 12u32..=64,
        rounding in proptest::sample::select(Rounding::ALL.to_vec()),
        saturate in any::<bool>(),
        seed in any::<u64>(),
        spread_shift in 0u32..=40,
    ) {
        let input = Format::signed(input_width, input_width as i32 / 2).unwrap();
        let output = Format::signed(output_width, input.frac + output_frac_shift).unwrap();
        let plan = Plan::new(&Spec {
            input,
            output,
            window,
            threshold_dps: threshold_fraction * input.max_value(),
            reciprocal_width,
            rounding,
            overflow: if saturate { Overflow::Saturate } else { Overflow::Wrap },
        });
        // Narrow reciprocals for long windows are refused (1/L rounds to 0): nothing to test.
        let Ok(plan) = plan else { return Ok(()); };
        let (low, high) = (input.min_code(), input.max_code());
        let spread = (high >> spread_shift.min(input_width - 1)).max(1);
        let center = (seed as i128 % (high + 1)).clamp(low + spread, high - spread);
        let mut state = seed | 1;
        let block: Vec<i64> = (0..window)
            .map(|i| {
                state ^= state << 13;
                state ^= state >> 7;
                state ^= state << 17;
                let x = match (seed >> 3) % 4 {
                    0 if i % 2 == 0 => high,
                    0 => low,
                    1 => [high, low][(state % 2) as usize],
                    _ => center + (state >> 4) as i128 % (2 * spread + 1) - spread,
                };
                x.clamp(low, high) as i64
            })
            .collect();
        prop_assert_eq!(serial::block_mean(&plan, &block), block_mean(&plan, &block));
    }
}
