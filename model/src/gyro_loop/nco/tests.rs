use super::*;
use proptest::prelude::*;

fn spec(p: u32, a: u32, s: u32) -> Spec {
    Spec {
        phase_bits: p,
        address_bits: a,
        sine_width: s,
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

proptest! {
    #![proptest_config(ProptestConfig::with_cases(200))]
    /// Random widths, frequency words and offsets: every sample within the derived bound.
    #[test]
    fn fixed_stays_within_the_derived_bound_of_float(
        a in 2u32..=12,
        s in 3u32..=24,
        extra in 0u32..=30,
        words in prop::collection::vec((any::<u64>(), any::<u64>()), 1..400),
    ) {
        let plan = Plan::new(&spec(a + 2 + extra, a, s)).unwrap();
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
