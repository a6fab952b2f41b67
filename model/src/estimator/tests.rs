use super::*;
use crate::fx::{from_f64, CoefficientFormat, Format, Overflow, Rounding};
use crate::sequencer::{Pattern, Schedule, Sequencer, Slot};
use proptest::prelude::*;

fn fmt(text: &str) -> Format {
    text.parse().unwrap()
}

fn spec(schedule: Schedule, rate_order: usize) -> Spec {
    Spec {
        schedule,
        rate_order,
        input: fmt("s24.14"),
        mean: fmt("s28.18"),
        bias: fmt("s28.18"),
        calibrated: fmt("s24.14"),
        gain: CoefficientFormat::Auto { width: 18 },
        reciprocal: CoefficientFormat::Auto { width: 18 },
        smoothing_shift: 0,
        rounding: Rounding::Nearest,
        overflow: Overflow::Saturate,
    }
}

fn schedule(l: usize, w: usize, pattern: Pattern, m: usize, s: usize) -> Schedule {
    Schedule {
        interval_length: l,
        intervals: w,
        pattern,
        blank: m,
        stagger: s,
    }
}

/// Runs the fixed estimator over `samples` samples of `y_g = rate(k) + p_g b_g` (quantized);
/// `corrupt` replaces blanked samples. Returns the slots, samples and final estimates (°/s).
fn run(
    plan: &Plan,
    samples: usize,
    biases: [f64; 2],
    rate: impl Fn(usize) -> f64,
    corrupt: Option<f64>,
) -> (Vec<Slot>, Vec<Sample>, [f64; 2]) {
    let mut seq = Sequencer::new(&plan.schedule);
    let mut est = FixedEstimator::new(plan);
    let (mut slots, mut out) = (Vec::new(), Vec::new());
    for k in 0..samples {
        let slot = seq.advance();
        let modes = [f64::from(slot.mode_a), f64::from(slot.mode_b)];
        let blank = [slot.blank_a, slot.blank_b];
        let y = [0, 1].map(|g| {
            let v = match corrupt {
                Some(bad) if blank[g] => bad,
                _ => rate(k) + modes[g] * biases[g],
            };
            from_f64(v, plan.input, Rounding::Nearest, Overflow::Saturate)
                .unwrap()
                .code as i64
        });
        out.push(est.step(&slot, y));
        slots.push(slot);
    }
    let b = est.bias();
    (slots, out, [plan.bias.to_f64(b[0]), plan.bias.to_f64(b[1])])
}

#[test]
fn constant_rate_biases_are_recovered_to_quantization() {
    for (sched, r) in [
        (schedule(150, 4, Pattern::Alternating, 10, 0), 0),
        (schedule(150, 4, Pattern::Abba, 10, 0), 1),
        (schedule(150, 2, Pattern::Alternating, 10, 0), 0),
    ] {
        let plan = Plan::new(&spec(sched, r)).unwrap();
        let (_, _, b) = run(&plan, 3000, [0.0066, -0.0055], |_| 12.5, None);
        // The input LSB (6e-5 °/s) limits what the means can say.
        assert!(
            (b[0] - 0.0066).abs() < 1e-4 && (b[1] + 0.0055).abs() < 1e-4,
            "{b:?}"
        );
    }
}

#[test]
fn abba_with_rate_order_one_cancels_a_linear_rate() {
    let plan = Plan::new(&spec(schedule(100, 4, Pattern::Abba, 0, 0), 1)).unwrap();
    assert!(plan.gains_are_shifts(), "ABBA, r = 1: all ±1/4");
    // A ramp of 0.01 °/s per sample: 400 samples per window sweep 4 °/s.
    let (_, _, b) = run(&plan, 1600, [0.25, 0.125], |k| 0.01 * k as f64, None);
    assert!(
        (b[0] - 0.25).abs() < 1e-4 && (b[1] - 0.125).abs() < 1e-4,
        "{b:?}"
    );
}

#[test]
fn alternating_with_rate_order_zero_leaks_a_linear_rate_as_predicted() {
    let sched = schedule(100, 4, Pattern::Alternating, 0, 0);
    let plan = Plan::new(&spec(sched.clone(), 0)).unwrap();
    let slope = 0.01; // °/s per sample = 1 °/s per interval
    let window = sched.cycle_length();
    // Run to the end of the second window; its means see the rate at absolute sample times.
    let (_, _, b) = run(&plan, 2 * window, [0.0, 0.0], |k| slope * k as f64, None);
    // Predicted leak: bA = Σ G_j m_j with m_j the mean rate of interval j of window 1.
    let mean_rate = |interval: usize| {
        let start = window + interval * 100;
        (start..start + 100).map(|k| slope * k as f64).sum::<f64>() / 100.0
    };
    let m: Vec<f64> = (0..4).flat_map(|i| [mean_rate(i), mean_rate(i)]).collect();
    for (g, estimate) in b.iter().enumerate() {
        let predicted: f64 = plan.gains[g].iter().zip(&m).map(|(c, v)| c * v).sum();
        assert!(predicted.abs() > 0.1, "the leak is visible: {predicted}");
        assert!(
            (estimate - predicted).abs() < 1e-4,
            "gyro {g}: {estimate} vs {predicted}"
        );
    }
}

#[test]
fn blanked_samples_never_reach_the_means() {
    let plan = Plan::new(&spec(schedule(50, 4, Pattern::Alternating, 7, 0), 0)).unwrap();
    let (_, clean, bc) = run(&plan, 1000, [0.5, -0.25], |_| 3.0, None);
    let (slots, dirty, bd) = run(&plan, 1000, [0.5, -0.25], |_| 3.0, Some(400.0));
    assert_eq!(bc, bd);
    // The blanked samples' outputs are flagged invalid, the others identical.
    for (k, ((c, d), s)) in clean.iter().zip(&dirty).zip(&slots).enumerate() {
        assert_eq!(d.valid, [!s.blank_a, !s.blank_b], "sample {k}");
        if d.combined_valid {
            assert_eq!(c.combined, d.combined, "sample {k}");
        }
    }
}

#[test]
fn stagger_keeps_the_combined_output_uninterrupted() {
    let with = Plan::new(&spec(schedule(50, 4, Pattern::Alternating, 7, 10), 0)).unwrap();
    let (_, out, _) = run(&with, 2000, [0.5, -0.25], |_| 3.0, None);
    assert!(out.iter().all(|s| s.combined_valid));
    let without = Plan::new(&spec(schedule(50, 4, Pattern::Alternating, 7, 0), 0)).unwrap();
    let (_, out, _) = run(&without, 2000, [0.5, -0.25], |_| 3.0, None);
    assert_eq!(
        out.iter().filter(|s| !s.combined_valid).count(),
        2000 / 50 * 7
    );
}

#[test]
fn estimates_apply_from_the_sample_after_the_window() {
    let plan = Plan::new(&spec(schedule(10, 2, Pattern::Alternating, 0, 0), 0)).unwrap();
    let (slots, out, _) = run(&plan, 45, [1.0, 0.0], |_| 0.0, None);
    let first = slots.iter().position(|s| s.window_done).unwrap();
    assert_eq!(first, 19);
    assert!(!out[first].estimated || out[first].bias == [0, 0]);
    assert_eq!(out[first].bias, [0, 0]);
    assert_ne!(out[first + 1].bias, [0, 0]);
}

#[test]
fn smoothing_converges_geometrically() {
    let mut s = spec(schedule(20, 2, Pattern::Alternating, 0, 0), 0);
    s.smoothing_shift = 2;
    let plan = Plan::new(&s).unwrap();
    // The first window sees bias 0 (a step later): 1, then 1 - 3/4, ...
    let (_, _, b) = run(&plan, 40 * 12, [0.5, 0.5], |_| 0.0, None);
    assert!((b[0] - 0.5).abs() < 0.5 * 0.75f64.powi(10), "{b:?}");
}

#[test]
fn plan_errors() {
    let err = Plan::new(&spec(schedule(150, 2, Pattern::Alternating, 10, 0), 1)).unwrap_err();
    assert!(err.to_string().contains("rank-deficient"), "{err}");
    let err = Plan::new(&spec(schedule(150, 4, Pattern::Alternating, 150, 0), 0)).unwrap_err();
    assert!(err.to_string().contains("blank = 150"), "{err}");
    let mut s = spec(schedule(150, 4, Pattern::Alternating, 10, 0), 0);
    s.gain = CoefficientFormat::Fixed(fmt("s8.9"));
    let err = Plan::new(&s).unwrap_err();
    assert!(err.to_string().contains("does not fit s8.9"), "{err}");
    s.gain = CoefficientFormat::Auto { width: 18 };
    s.reciprocal = CoefficientFormat::Fixed(fmt("s8.4"));
    let err = Plan::new(&s).unwrap_err();
    assert!(
        err.to_string().contains("quantizes to zero in s8.4"),
        "{err}"
    );
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(120))]
    /// Fixed vs float (same quantized gains and reciprocal) over random schedules, formats,
    /// modes and noisy inputs: the estimates stay within `Plan::bias_error_bound`, the
    /// calibrated and combined outputs within that plus their own rounding.
    #[test]
    fn fixed_stays_within_the_derived_bound_of_float(
        l in 8usize..60, w_quarters in 1usize..3, abba in any::<bool>(), m_frac in 0.0f64..0.5,
        s_frac in 0.0f64..0.9, r in 0usize..2, guard in 0i32..8, smoothing in 0u32..4,
        rounding in prop::sample::select(Rounding::ALL.to_vec()),
        noise in prop::collection::vec(-1.0f64..1.0, 600),
        biases in (-2.0f64..2.0, -2.0f64..2.0), rate in -50.0f64..50.0,
    ) {
        let w = 4 * w_quarters;
        let sched = schedule(l, w, if abba { Pattern::Abba } else { Pattern::Alternating },
            (l as f64 * m_frac) as usize, (l as f64 * s_frac) as usize);
        let mut s = spec(sched, r);
        s.mean = Format::signed(24 + guard as u32, 14 + guard).unwrap();
        s.bias = Format::signed(24 + guard as u32, 14 + guard).unwrap();
        s.smoothing_shift = smoothing;
        s.rounding = rounding;
        let plan = Plan::new(&s).unwrap();
        let mut seq = Sequencer::new(&plan.schedule);
        let mut fixed = FixedEstimator::new(&plan);
        let mut float = FloatEstimator::quantized(&plan);
        let bound = plan.bias_error_bound();
        let u = rounding.max_error_lsb();
        let cal_lsb = plan.calibrated.lsb();
        for k in 0..(4 * plan.schedule.cycle_length()).max(600) {
            let slot = seq.advance();
            let modes = [f64::from(slot.mode_a), f64::from(slot.mode_b)];
            let y = [0, 1].map(|g| {
                let v = rate + modes[g] * [biases.0, biases.1][g] + noise[(k * 7 + g) % 600];
                from_f64(v, plan.input, Rounding::Nearest, Overflow::Saturate).unwrap().code as i64
            });
            let a = fixed.step(&slot, y);
            let b = float.step(&slot, [plan.input.to_f64(i128::from(y[0])), plan.input.to_f64(i128::from(y[1]))]);
            for g in 0..2 {
                let bias_error = (plan.bias.to_f64(i128::from(a.bias[g])) - b.bias[g]).abs();
                prop_assert!(bias_error <= bound, "bias {}: {} > {} at {}", g, bias_error, bound, k);
                let out_error = (plan.calibrated.to_f64(i128::from(a.out[g])) - b.out[g]).abs();
                prop_assert!(out_error <= bound + u * cal_lsb, "out {}: {} at {}", g, out_error, k);
            }
            if a.combined_valid {
                let err = (plan.calibrated.to_f64(i128::from(a.combined)) - b.combined).abs();
                prop_assert!(err <= bound + 2.0 * u * cal_lsb, "combined: {} at {}", err, k);
            }
        }
        prop_assert_eq!(fixed.overflow_counts(), OverflowCounts::default());
    }
}
