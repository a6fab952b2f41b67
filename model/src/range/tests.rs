//! The proven ranges hold for every input (proptest over random KF plans and inputs) and are
//! tight: the input with every tap's sign at full scale reaches at least 90 % of them, and the
//! node one integer bit narrower overflows on it.

use proptest::prelude::*;

use super::*;
use crate::estimator::FixedEstimator;
use crate::examples::{chain_plan, kf_spec};
use crate::fx::{Overflow, Rounding};
use crate::kf::{CoefficientFormat, FixedKf, Plan, Spec};
use crate::sequencer::Sequencer;

fn format(text: &str) -> Format {
    text.parse().unwrap()
}

#[test]
fn integer_bits_are_exact_at_powers_of_two() {
    let full = Interval::of_format(format("s24.14"));
    assert_eq!(full.signed_integer_bits(14), 10);
    // One LSB beyond the top, or the bottom one below, needs another bit.
    assert_eq!(full.widen(pow2(-14)).signed_integer_bits(14), 11);
    assert_eq!(Interval::new(-512.0, 0.0).signed_integer_bits(14), 10);
    assert_eq!(
        Interval::new(-512.0 - pow2(-14), 0.0).signed_integer_bits(14),
        11
    );
    assert_eq!(Interval::new(0.0, 512.0).signed_integer_bits(14), 11);
    assert_eq!(Interval::new(-0.25, 0.2).signed_integer_bits(20), -1);
    assert!(full.fits(format("s24.14")) && !full.fits(format("s23.14")));
}

/// The fixed KF from reset at a constant `bw_sel`, fed `z`: the extremes `[x1, x2]` reached
/// (°/s) and whether the states ever saturated.
fn extremes(plan: &Plan, bw_sel: usize, z: impl Iterator<Item = i64>) -> [Interval; 2] {
    let mut kf = FixedKf::new(plan);
    let mut seen = [Interval::new(0.0, 0.0); 2];
    for code in z {
        kf.step(code, bw_sel);
        for (range, x) in seen.iter_mut().zip(kf.state()) {
            let value = plan.state.to_f64(x);
            *range = range.union(Interval::new(value, value));
        }
    }
    seen
}

fn node<'a>(ranges: &'a KfRanges, name: &str) -> &'a NodeRange {
    find(&ranges.nodes, name).unwrap()
}

#[test]
fn the_kf_state_bound_is_reached_by_full_scale_input_and_one_bit_less_overflows() {
    let plan = Plan::new(&kf_spec()).unwrap();
    let input = Interval::of_format(plan.input);
    // Worst-case rounding drifts x1 by up to 2^-27 °/s a sample (all errors one way): the
    // default's state format is proven for records this short; longer ones need a guard bit
    // more, or round-to-nearest's statistics (kf::bound's module doc).
    let samples = 2000;
    let ranges = kf(&plan, input, samples, 0);
    let state = node(&ranges, "kf.state");
    assert!(state.fits(), "{state:?}");
    assert_eq!(state.needed_integer_bits(), state.integer_bits());
    for bw_sel in 0..plan.rom.len() {
        // Every tap of y is positive (0 < S < 1): z at full scale takes x1 to its bound.
        let high = extremes(
            &plan,
            bw_sel,
            (0..samples).map(|_| plan.input.max_code() as i64),
        );
        let low = extremes(
            &plan,
            bw_sel,
            (0..samples).map(|_| plan.input.min_code() as i64),
        );
        let reached = high[0].union(low[0]);
        assert!(reached.hi >= 0.9 * state.range.hi, "{reached:?} {state:?}");
        assert!(reached.lo <= 0.9 * state.range.lo, "{reached:?} {state:?}");
        // One integer bit fewer cannot hold what the input reached.
        let narrower = Format::signed(plan.state.width - 1, plan.state.frac).unwrap();
        assert!(!reached.fits(narrower), "{reached:?} fits {narrower}");
        assert!(reached.lo >= state.range.lo && reached.hi <= state.range.hi);
    }
}

#[test]
fn the_innovation_bound_is_reached_after_a_full_scale_step() {
    let plan = Plan::new(&kf_spec()).unwrap();
    let input = Interval::of_format(plan.input);
    let ranges = kf(&plan, input, 10_000, 0);
    let error = node(&ranges, "kf.error");
    for bw_sel in 0..plan.rom.len() {
        let mut kf = FixedKf::new(&plan);
        for _ in 0..2000 {
            kf.step(plan.input.min_code() as i64, bw_sel);
        }
        let [x1, x2] = kf.state().map(|x| plan.state.to_f64(x));
        let e = plan.input.max_value() - x1 - x2;
        assert!(
            e >= 0.9 * error.range.hi && e <= error.range.hi,
            "{e} {error:?}"
        );
    }
    assert!(
        error.fits(),
        "the plan's exact e format holds it: {error:?}"
    );
}

#[test]
fn switching_bw_sel_grows_the_state_range_and_the_analysis_says_by_how_much() {
    let plan = Plan::new(&kf_spec()).unwrap();
    let input = Interval::of_format(plan.input);
    let still = kf(&plan, input, 1000, 0);
    let switching = kf(&plan, input, 1000, 1000);
    assert!(still.per_switch > 0.0);
    let grown = node(&switching, "kf.state").range.hi - node(&still, "kf.state").range.hi;
    assert!(grown >= 1000.0 * still.per_switch, "{grown}");
}

/// A random KF plan: gains with `0 < S < 2`, formats with a few guard bits, any rounding.
fn random_plan() -> impl Strategy<Value = Plan> {
    (
        prop::collection::vec((0.01f64..1.9, 0.0001f64..0.5), 1..4),
        8u32..16,
        0i32..8,
        0i32..12,
        prop::sample::select(vec![
            Rounding::Nearest,
            Rounding::Floor,
            Rounding::Convergent,
        ]),
    )
        .prop_filter_map("plannable", |(sums, in_width, in_frac, guard, rounding)| {
            let gains: Vec<[f64; 2]> = sums
                .iter()
                .map(|(s, split)| [s * (1.0 - split), s * split])
                .collect();
            let input = Format::signed(in_width, in_frac).ok()?;
            let spec = Spec {
                input,
                // Two integer bits of headroom over the input: the range check decides.
                state: Format::signed(in_width + 2 + guard as u32, in_frac + guard).ok()?,
                output: input,
                coefficients: [CoefficientFormat::Auto { width: 18 }; 2],
                rounding,
                overflow: Overflow::Saturate,
                labels: (0..gains.len()).map(|i| i.to_string()).collect(),
                gains,
            };
            Plan::new(&spec).ok()
        })
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    /// No input inside the range, at any bw_sel sequence, takes a state outside its proven
    /// range (so a format chosen from it cannot overflow).
    #[test]
    fn no_input_leaves_the_proven_kf_ranges(
        plan in random_plan(),
        inputs in prop::collection::vec((any::<u32>(), 0u8..4, any::<bool>()), 1..600),
    ) {
        let input = Interval::of_format(plan.input);
        let switches = inputs.windows(2).filter(|w| w[0].1 != w[1].1).count() as u64;
        let ranges = kf(&plan, input, inputs.len() as u64, switches);
        let state = node(&ranges, "kf.state").range;
        let mut fixed = FixedKf::new(&plan);
        let (min, max) = (plan.input.min_code(), plan.input.max_code());
        for (raw, select, extreme) in inputs {
            // Half the samples at a full-scale extreme, the rest anywhere in the range.
            let code = if extreme {
                if raw % 2 == 0 { max } else { min }
            } else {
                min + i128::from(raw) % (max - min + 1)
            };
            fixed.step(code as i64, usize::from(select) % plan.rom.len());
            for x in fixed.state() {
                let value = plan.state.to_f64(x);
                prop_assert!(value >= state.lo && value <= state.hi, "{} outside {:?}", value, state);
            }
        }
    }
}

#[test]
fn the_bias_bound_is_reached_by_means_with_the_gains_signs() {
    let plan = chain_plan(20, 2, 0, 0, Rounding::Nearest).estimator;
    let input = Interval::of_format(plan.input);
    let nodes = estimator(&plan, input);
    let bias = find(&nodes, "estimator.bias").unwrap();
    let calibrated = nodes
        .iter()
        .find(|n| n.name == "estimator.calibrated")
        .unwrap();
    assert!(bias.fits(), "{bias:?}");
    // The calibrated sample can reach about twice full scale: the KF's input format cannot
    // hold it, and the analysis says so (the calibration saturates).
    assert!(
        !calibrated.fits() && calibrated.needed_integer_bits() == calibrated.integer_bits() + 1
    );
    // Gyro A's samples at full scale with the sign of A's gain for each interval's mean.
    let mut sequencer = Sequencer::new(&plan.schedule);
    let mut fixed = FixedEstimator::new(&plan);
    let (max, min) = (plan.input.max_code() as i64, plan.input.min_code() as i64);
    for _ in 0..plan.schedule.cycle_length() {
        let slot = sequencer.advance();
        // m = [mA0, mB0, mA1, mB1, ...]: A's gain for interval i is entry 2i of row A.
        let gain = plan.rom[0][2 * slot.interval_a];
        let y_a = if gain >= 0 { max } else { min };
        fixed.step(&slot, [y_a, 0]);
    }
    assert!(fixed.estimated());
    let reached = plan.bias.to_f64(fixed.bias()[0]);
    assert!(
        reached >= 0.9 * bias.range.hi && reached <= bias.range.hi,
        "{reached} {bias:?}"
    );
    let narrower = Format::signed(plan.bias.width - 1, plan.bias.frac).unwrap();
    assert!(reached > narrower.max_value(), "one bit fewer overflows");
}

#[test]
fn quantizing_an_interval_rounds_its_endpoints_by_the_mode() {
    let q = |lo: f64, hi: f64, rounding| {
        let i = Interval::new(lo, hi).quantized(1, rounding);
        (i.lo, i.hi)
    };
    assert_eq!(q(-0.3, 0.3, Rounding::Floor), (-0.5, 0.0));
    assert_eq!(q(-0.3, 0.3, Rounding::Ceil), (0.0, 0.5));
    assert_eq!(q(-0.3, 0.3, Rounding::Zero), (0.0, 0.0));
    assert_eq!(q(-0.25, 0.75, Rounding::Nearest), (0.0, 1.0));
    assert_eq!(q(-0.25, 0.75, Rounding::Round), (-0.5, 1.0));
    assert_eq!(q(0.25, 0.75, Rounding::Convergent), (0.0, 1.0));
    // The output of the default KF rounds back onto the format's last code.
    let near = Interval::new(-512.000_002, 511.999_941).quantized(14, Rounding::Nearest);
    assert!(near.fits("s24.14".parse().unwrap()));
}

/// The mean filter's output bound: the fixed filter on blocks built to reach each count's
/// extreme never leaves it and reaches it; the format one integer bit narrower cannot hold
/// that.
#[test]
fn the_mean_filter_output_bound_holds_and_is_reached() {
    use crate::mean_filter::{block_mean, Plan as FilterPlan, Spec as FilterSpec};
    let plan = FilterPlan::new(&FilterSpec {
        input: format("s24.14"),
        output: format("s24.14"),
        window: 20,
        threshold_dps: 0.3,
        reciprocal_width: 25,
        rounding: Rounding::Nearest,
        overflow: Overflow::Saturate,
    })
    .unwrap();
    let nodes = mean_filter(&plan);
    let output = nodes
        .iter()
        .find(|n| n.name == "mean_filter.output")
        .unwrap();
    let (min, max) = (plan.input.min_code() as i64, plan.input.max_code() as i64);
    let l = plan.window as usize;
    let mut reached = Interval::new(0.0, 0.0);
    let mut overflowed = false;
    // n kept at full scale and the rest rejected just below the mean (n > L/2), every count.
    for n in (l / 2 + 1)..=l {
        for (edge, sign) in [(max, -1i64), (min, 1)] {
            let mut block = vec![edge; n];
            // The kept stay within L·r of the block sum ((L − n)·step ≤ L·r), the rejected
            // leave it (n·step > L·r): possible exactly when n > L/2.
            let step = (plan.scaled_threshold as i64) / (l - n).max(1) as i64;
            block.extend(std::iter::repeat_n(edge + sign * step, l - n));
            let result = block_mean(&plan, &block);
            assert_eq!(
                result.kept as usize, n,
                "the block keeps what it was built to"
            );
            overflowed |= result.overflowed;
            let value = plan.output.to_f64(i128::from(result.y));
            reached = reached.union(Interval::new(value, value));
            assert!(
                value >= output.range.lo && value <= output.range.hi,
                "n = {n}: {value} outside {:?} (kept {})",
                output.range,
                result.kept
            );
        }
    }
    assert!(reached.hi >= 0.9 * output.range.hi && reached.lo <= 0.9 * output.range.lo);
    let narrower = Format::signed(plan.output.width - 1, plan.output.frac).unwrap();
    assert!(!reached.fits(narrower));
    // 1/n rounds up in the ROM for some n > L/2: those blocks' means pass full scale by a few
    // LSB. The analysis says the output can overflow, and such a block does (it saturates).
    assert!(!output.fits() && overflowed, "{output:?}");
    for node in nodes.iter().filter(|n| n.exact) {
        assert!(node.fits(), "{node:?}");
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(200))]

    /// Random blocks (clusters and outliers anywhere in the range) stay within the proven
    /// output range.
    #[test]
    fn no_block_leaves_the_proven_mean_filter_range(
        center in any::<i32>(),
        spread in 0u32..20_000,
        outliers in prop::collection::vec((0usize..20, any::<i32>()), 0..12),
        threshold in 0.01f64..5.0,
    ) {
        use crate::mean_filter::{block_mean, Plan as FilterPlan, Spec as FilterSpec};
        let plan = FilterPlan::new(&FilterSpec {
            input: format("s24.14"),
            output: format("s24.14"),
            window: 20,
            threshold_dps: threshold,
            reciprocal_width: 25,
            rounding: Rounding::Nearest,
            overflow: Overflow::Saturate,
        })
        .unwrap();
        let output = mean_filter(&plan).into_iter().find(|n| n.name == "mean_filter.output").unwrap();
        let (min, max) = (plan.input.min_code() as i64, plan.input.max_code() as i64);
        let center = i64::from(center) >> 8;
        let mut block: Vec<i64> = (0..20)
            .map(|i| (center + (i as i64 * 7919 % (2 * i64::from(spread) + 1)) - i64::from(spread)).clamp(min, max))
            .collect();
        for (i, value) in outliers {
            block[i] = (i64::from(value) >> 8).clamp(min, max);
        }
        let value = plan.output.to_f64(i128::from(block_mean(&plan, &block).y));
        prop_assert!(value >= output.range.lo && value <= output.range.hi);
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(48))]

    /// Random samples over whole windows of random schedules and smoothing keep the bias
    /// estimates within their proven range. Each interval's samples are all at full scale
    /// (either sign) or anywhere in the range, so some windows take the gains' sign pattern
    /// and reach the bound (cutting the bound by a tenth fails this).
    #[test]
    fn no_input_leaves_the_proven_bias_range(
        interval_length in 3usize..12,
        blank in 0usize..2,
        smoothing in 0u32..3,
        choices in prop::collection::vec(0u8..3, 64),
        noise in prop::collection::vec(any::<u32>(), 64),
    ) {
        let plan = chain_plan(interval_length, blank, 0, smoothing, Rounding::Nearest).estimator;
        let nodes = estimator(&plan, Interval::of_format(plan.input));
        let bias = find(&nodes, "estimator.bias").unwrap().range;
        let mut sequencer = Sequencer::new(&plan.schedule);
        let mut fixed = FixedEstimator::new(&plan);
        let (min, max) = (plan.input.min_code(), plan.input.max_code());
        for k in 0..64 * interval_length {
            let interval = k / interval_length;
            let code = |salt: u32| match choices[interval] {
                0 => min,
                1 => max,
                _ => min + i128::from(noise[interval].rotate_left(salt)) % (max - min + 1),
            } as i64;
            fixed.step(&sequencer.advance(), [code(0), code(7)]);
            for b in fixed.bias() {
                let value = plan.bias.to_f64(b);
                prop_assert!(value >= bias.lo && value <= bias.hi, "{} outside {:?}", value, bias);
            }
        }
    }
}
