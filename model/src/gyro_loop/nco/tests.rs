use super::*;
use proptest::prelude::*;

fn spec(p: u32, a: u32, s: u32) -> Spec {
    Spec {
        phase_bits: p,
        address_bits: a,
        sine_width: s,
        error_feedback: false,
    }
}

/// Largest `|fixed − float|` over `(freq, offset)` samples, in output LSB, for sin and cos.
fn worst_error(plan: &Plan, inputs: &[(u64, u64)]) -> f64 {
    let mut fixed = FixedNco::new(plan);
    let mut float = FloatNco::new(plan);
    let lsb = plan.output.lsb();
    let mut worst: f64 = 0.0;
    for (freq, offset) in inputs {
        let r = fixed.step(*freq, *offset);
        let [s, c] = float.step(*freq, *offset);
        worst = worst
            .max((plan.output.to_f64(i128::from(r.sin)) - s).abs() / lsb)
            .max((plan.output.to_f64(i128::from(r.cos)) - c).abs() / lsb);
    }
    worst
}

/// One sample per phase bin, starting on the bins' lower edges: the truncation's worst case.
fn bin_sweep(plan: &Plan) -> Vec<(u64, u64)> {
    let bins = 1u64 << (plan.address_bits + 2);
    let bin = 1u64 << (plan.phase.width - plan.address_bits - 2);
    (0..bins).map(|_| (bin, 0)).collect()
}

#[test]
fn one_bin_per_sample_walks_the_sine_at_the_bin_centres() {
    let plan = Plan::new(&spec(16, 4, 12)).unwrap();
    let mut nco = FixedNco::new(&plan);
    let amplitude = 2047.0;
    for (t, (freq, offset)) in bin_sweep(&plan).into_iter().enumerate() {
        let r = nco.step(freq, offset);
        // Independent of the model: the platform's sine at the bin centre, rounded.
        let angle = 2.0 * std::f64::consts::PI * (t as f64 + 0.5) / 64.0;
        assert_eq!(r.sin, (amplitude * angle.sin()).round() as i64, "sin t={t}");
        assert_eq!(r.cos, (amplitude * angle.cos()).round() as i64, "cos t={t}");
    }
    assert_eq!(plan.rom_codes().len(), 16);
    assert_eq!(plan.rtl_parameters()[1], ("ADDR_W", 4));
}

#[test]
fn the_offset_shifts_the_phase_and_reset_restarts_it() {
    let plan = Plan::new(&Spec::default()).unwrap();
    let freq = plan.frequency_word(8195.0, 200_000.0).unwrap();
    let quarter = plan.offset_word(90.0).unwrap();
    assert_eq!(quarter, 1 << 30);
    let mut a = FixedNco::new(&plan);
    let mut b = FixedNco::new(&plan);
    for _ in 0..1000 {
        let ra = a.step(freq, quarter);
        let rb = b.step(freq, 0);
        // sin(θ + 90°) = cos θ: exactly, since a quarter cycle is a whole number of bins.
        assert_eq!(ra.sin, rb.cos);
    }
    let first = {
        let mut n = FixedNco::new(&plan);
        (0..10).map(|_| n.step(freq, 7)).collect::<Vec<_>>()
    };
    a.reset();
    let again: Vec<_> = (0..10).map(|_| a.step(freq, 7)).collect();
    assert_eq!(first, again);
}

#[test]
fn frequency_words_round_to_nearest_and_wrap() {
    let plan = Plan::new(&Spec::default()).unwrap();
    // 8195 / 200000 · 2^32 = 175_995_014.1… in exact integers.
    let exact_numerator = 8195u128 << 32;
    let nearest = (exact_numerator + 100_000) / 200_000;
    assert_eq!(
        plan.frequency_word(8195.0, 200_000.0).unwrap() as u128,
        nearest
    );
    // −1 kHz is fs − 1 kHz.
    let negative = plan.frequency_word(-1000.0, 200_000.0).unwrap();
    let positive = plan.frequency_word(199_000.0, 200_000.0).unwrap();
    assert_eq!(negative, positive);
    assert_eq!(plan.offset_word(-90.0).unwrap(), 3 << 30);
    assert!(plan.frequency_word(f64::NAN, 1.0).is_err());
}

#[test]
fn the_truncation_bound_is_reached_at_the_bin_edges() {
    // A coarse ROM: the phase truncation dominates the bound.
    let plan = Plan::new(&spec(24, 5, 16)).unwrap();
    let worst = worst_error(&plan, &bin_sweep(&plan));
    let bound = plan.error_bound_lsb();
    assert!(worst <= bound, "{worst} > {bound}");
    assert!(
        worst > 0.95 * bound,
        "the bound is loose: {worst} of {bound}"
    );
}

#[test]
fn a_rom_rounded_down_breaks_the_bound() {
    // A fine ROM of a narrow sine: the ROM's rounding dominates.
    let s = spec(30, 12, 8);
    let bound = Plan::new(&s).unwrap().error_bound_lsb();
    let sweep = bin_sweep(&Plan::new(&s).unwrap());
    let correct = worst_error(&Plan::new(&s).unwrap(), &sweep);
    assert!(correct <= bound);
    let mutated = Plan::with_rom_rounding(&s, Rounding::Floor).unwrap();
    let worst = worst_error(&mutated, &sweep);
    assert!(worst > bound, "floor ROM: {worst} <= bound {bound}");
}

#[test]
fn plan_errors_name_the_field() {
    let text = Plan::new(&spec(32, 1, 18)).unwrap_err().to_string();
    assert!(
        text.contains("nco.address_bits = 1") && text.contains("2..=20"),
        "{text}"
    );
    let text = Plan::new(&spec(11, 10, 18)).unwrap_err().to_string();
    assert!(
        text.contains("nco.phase_bits = 11") && text.contains("12..=63"),
        "{text}"
    );
    let text = Plan::new(&spec(32, 10, 40)).unwrap_err().to_string();
    assert!(text.contains("nco.sine_width = 40"), "{text}");
}

/// The mean phase error (in bins) of the sine over `n` samples at frequency word `freq`, read
/// as `(sin_fixed cos θ − cos_fixed sin θ)/A_nco ≈ sin e` against the exact phase `θ`.
fn mean_phase_error_bins(plan: &Plan, freq: u64, n: usize) -> f64 {
    let mut nco = FixedNco::new(plan);
    let cycle = crate::fx::pow2(plan.phase.width as i32);
    let amplitude = plan.amplitude();
    let bin_rad = 2.0 * std::f64::consts::PI / crate::fx::pow2(plan.address_bits as i32 + 2);
    let mut sum = 0.0;
    for _ in 0..n {
        let theta = 2.0 * std::f64::consts::PI * (nco.accumulator() as f64 / cycle);
        let r = nco.step(freq, 0);
        let (sin, cos) = (
            plan.output.to_f64(i128::from(r.sin)),
            plan.output.to_f64(i128::from(r.cos)),
        );
        sum += (sin * libm::cos(theta) - cos * libm::sin(theta)) / amplitude;
    }
    sum / n as f64 / bin_rad
}

/// Where `2^(A+2) f/fs` sits half-way between integers the bin positions alternate between
/// two values and the truncation errors stop averaging out: a static error of a quarter bin
/// (issue 32's gyro loop, `2^12 f_L/fs` = 0.49997 mod 1). Error feedback takes it to the
/// bound of one bin over the run.
#[test]
fn error_feedback_takes_the_static_error_of_a_near_fraction_away() {
    let (p, a) = (32, 10);
    let bin = 1u64 << (p - a - 2);
    // Half a bin a sample, plus a whole number of bins and a drift of one LSB.
    let freq = 167 * bin + bin / 2 + 1;
    let n = 20_000;
    let plain = Plan::new(&spec(p, a, 18)).unwrap();
    let fed_back = Plan::new(&Spec {
        error_feedback: true,
        ..spec(p, a, 18)
    })
    .unwrap();
    let static_error = mean_phase_error_bins(&plain, freq, n);
    assert!(static_error.abs() > 0.2, "{static_error}");
    let shaped = mean_phase_error_bins(&fed_back, freq, n);
    // One bin over the run, and the ROM's rounding.
    assert!(shaped.abs() < 2.0 / n as f64 + 1e-4, "{shaped}");
}

/// The carried error is what is left below the truncation less half a bin, and the reset
/// clears it: the first sample after a reset is the plain NCO's.
#[test]
fn error_feedback_carries_the_remainder_and_the_reset_clears_it() {
    let plain = Plan::new(&spec(16, 4, 12)).unwrap();
    let fed_back = Plan::new(&Spec {
        error_feedback: true,
        ..spec(16, 4, 12)
    })
    .unwrap();
    // A bin is 2^10 phase LSB; a step of 1.25 bins. By hand, in bins: the exact phase 1.25 k
    // plus the carried r, floored to t, and r = what is left less ½:
    //   k      0     1     2     3     4     5     6     7
    //   u      0     0.75  2.75  4     4.5   6.25  7.25  8.5
    //   t      0     0     2     4     4     6     7     8
    //   r     −½    ¼     ¼    −½     0    −¼    −¼     0
    // (errors of the bin centres t + ½ against 1.25 k: +½ −¾ 0 +¾ −½ +¼ 0 −¼, summing to 0).
    // The plain NCO takes t = floor(1.25 k): 0 1 2 3 5 6 7 8.
    let freq = 1280;
    let sine = |t: &[u32]| -> Vec<i64> {
        // The platform's sine at the bin centres of a 64-bin cycle, as in the sweep test.
        t.iter()
            .map(|&t| {
                let angle = 2.0 * std::f64::consts::PI * (f64::from(t) + 0.5) / 64.0;
                (2047.0 * angle.sin()).round() as i64
            })
            .collect()
    };
    let (mut a, mut b) = (FixedNco::new(&plain), FixedNco::new(&fed_back));
    let walk = |nco: &mut FixedNco| -> Vec<i64> { (0..8).map(|_| nco.step(freq, 0).sin).collect() };
    assert_eq!(walk(&mut a), sine(&[0, 1, 2, 3, 5, 6, 7, 8]));
    let shaped = walk(&mut b);
    assert_eq!(shaped, sine(&[0, 0, 2, 4, 4, 6, 7, 8]));
    b.reset();
    assert_eq!(walk(&mut b), shaped);
    let text = Plan::new(&Spec {
        error_feedback: true,
        ..spec(12, 10, 18)
    })
    .unwrap_err()
    .to_string();
    assert!(
        text.contains("nco.error_feedback = true")
            && text.contains("phase_bits = address_bits + 2"),
        "{text}"
    );
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(200))]
    /// Random widths, frequency words and offsets, with or without error feedback: every
    /// sample within the derived bound.
    #[test]
    fn fixed_stays_within_the_derived_bound_of_float(
        a in 2u32..=12,
        s in 3u32..=24,
        extra in 0u32..=30,
        error_feedback in any::<bool>(),
        words in prop::collection::vec((any::<u64>(), any::<u64>()), 1..400),
    ) {
        let error_feedback = error_feedback && extra > 0;
        let plan = Plan::new(&Spec { error_feedback, ..spec(a + 2 + extra, a, s) }).unwrap();
        let worst = worst_error(&plan, &words);
        prop_assert!(worst <= plan.error_bound_lsb(), "{} > {}", worst, plan.error_bound_lsb());
    }

    /// `step` and `process` agree, and the phase wraps mod 2^P like the RTL's P-bit adder.
    #[test]
    fn process_equals_step_and_the_phase_wraps(
        p in 6u32..=63,
        words in prop::collection::vec((any::<u64>(), any::<u64>()), 1..200),
    ) {
        let plan = Plan::new(&spec(p, 4, 10)).unwrap();
        let (freq, offset): (Vec<u64>, Vec<u64>) = words.iter().copied().unzip();
        let mut by_block = vec![Reference::default(); words.len()];
        FixedNco::new(&plan).process(&freq, &offset, &mut by_block);
        let mut nco = FixedNco::new(&plan);
        let mask = u64::MAX >> (64 - p);
        let mut acc = 0u64;
        for (k, (f, o)) in words.iter().enumerate() {
            prop_assert_eq!(nco.accumulator(), acc);
            prop_assert_eq!(nco.step(*f, *o), by_block[k]);
            acc = (acc + (f & mask)) & mask;
        }
    }
}
