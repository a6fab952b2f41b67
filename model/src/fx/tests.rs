use super::*;
use proptest::prelude::*;

fn fmt(text: &str) -> Format {
    text.parse().unwrap()
}

/// Independent reference: rounds the rational `code / 2^shift` with integer division written
/// differently from the implementation (truncating `/`, doubled numerators).
fn reference_round(code: i128, shift: u32, rounding: Rounding) -> i128 {
    let d = 1i128 << shift;
    let trunc = code / d; // toward zero
    let exact = trunc * d == code;
    let floor = if code < 0 && !exact { trunc - 1 } else { trunc };
    let ceil = if code > 0 && !exact { trunc + 1 } else { trunc };
    // Compare 2·|fraction| with 1 using doubled numerators.
    let twice_frac_num = 2 * (code - floor * d); // in [0, 2d)
    match rounding {
        Rounding::Floor => floor,
        Rounding::Ceil => ceil,
        Rounding::Zero => trunc,
        Rounding::Nearest => {
            if twice_frac_num >= d {
                ceil
            } else {
                floor
            }
        }
        Rounding::Round => {
            if twice_frac_num > d || (twice_frac_num == d && code > 0) {
                ceil
            } else {
                floor
            }
        }
        Rounding::Convergent => {
            if twice_frac_num > d || (twice_frac_num == d && floor.rem_euclid(2) == 1) {
                ceil
            } else {
                floor
            }
        }
    }
}

fn reference_overflow(rounded: i128, to: Format, overflow: Overflow) -> (i128, bool) {
    let (lo, hi) = (to.min_code(), to.max_code());
    if rounded >= lo && rounded <= hi {
        return (rounded, false);
    }
    match overflow {
        Overflow::Saturate => (rounded.clamp(lo, hi), true),
        Overflow::Wrap => {
            let modulus = 1i128 << to.width;
            let mut w = rounded.rem_euclid(modulus);
            if to.signed && w > hi {
                w -= modulus;
            }
            (w, true)
        }
    }
}

#[test]
fn rounding_table_of_the_docs() {
    // Rows: value, then floor, ceil, zero, nearest, round, convergent.
    let table: [(f64, [i128; 6]); 6] = [
        (2.2, [2, 3, 2, 2, 2, 2]),
        (2.7, [2, 3, 2, 3, 3, 3]),
        (-1.5, [-2, -1, -1, -1, -2, -2]),
        (-0.5, [-1, 0, 0, 0, -1, 0]),
        (0.5, [0, 1, 0, 1, 1, 0]),
        (1.5, [1, 2, 1, 2, 2, 2]),
    ];
    let to = fmt("s8.0");
    for (value, expected) in table {
        for (mode, want) in Rounding::ALL.into_iter().zip(expected) {
            let got = from_f64(value, to, mode, Overflow::Saturate).unwrap().code;
            assert_eq!(got, want, "{value} under {mode}");
        }
    }
}

#[test]
fn tie_cases_at_one_fraction_bit() {
    let to = fmt("s8.1");
    // 1.25 -> 1.5 and -1.25 -> -1.0 under nearest (ties toward +inf).
    let from_quarters = |q: i128, mode| requantize(q, 2, to, mode, Overflow::Saturate).code;
    assert_eq!(from_quarters(5, Rounding::Nearest), 3);
    assert_eq!(from_quarters(-5, Rounding::Nearest), -2);
    assert_eq!(from_quarters(5, Rounding::Round), 3);
    assert_eq!(from_quarters(-5, Rounding::Round), -3);
    assert_eq!(from_quarters(5, Rounding::Convergent), 2);
    assert_eq!(from_quarters(-5, Rounding::Convergent), -2);
    assert_eq!(from_quarters(7, Rounding::Convergent), 4);
}

#[test]
fn formats_parse_and_print() {
    for text in ["s18.16", "u12.12", "s8.-2", "u1.0", "s64.70"] {
        assert_eq!(fmt(text).to_string(), text);
    }
    assert_eq!(fmt("s24"), Format::signed(24, 0).unwrap());
    let f = fmt("s18.16");
    assert_eq!((f.min_code(), f.max_code()), (-131072, 131071));
    assert_eq!(fmt("u12.12").max_code(), 4095);
    assert_eq!(f.lsb(), 1.0 / 65536.0);
}

#[test]
fn bad_formats_are_refused_with_the_reason() {
    for text in [
        "", "x18.16", "s", "s18.", "s.3", "s18.1.2", "s-3.2", "s18.x",
    ] {
        let err = text.parse::<Format>().unwrap_err();
        assert!(
            matches!(err, FxError::Parse { .. }),
            "{text:?} gave {err:?}"
        );
        assert!(err.to_string().contains("s18.16"));
    }
    let zero = "s0.0".parse::<Format>().unwrap_err();
    assert_eq!(zero, FxError::Width { width: 0, max: 64 });
    assert!(zero.to_string().contains("1..=64"));
    assert!(matches!(
        "u65.3".parse::<Format>(),
        Err(FxError::Width { width: 65, .. })
    ));
}

#[test]
fn mode_names_round_trip_and_unknown_names_are_refused() {
    for mode in Rounding::ALL {
        assert_eq!(mode.name().parse::<Rounding>().unwrap(), mode);
    }
    for mode in Overflow::ALL {
        assert_eq!(mode.name().parse::<Overflow>().unwrap(), mode);
    }
    assert!("half_up"
        .parse::<Rounding>()
        .unwrap_err()
        .to_string()
        .contains("convergent"));
    assert!("clip"
        .parse::<Overflow>()
        .unwrap_err()
        .to_string()
        .contains("saturate"));
}

#[test]
fn non_finite_values_are_refused() {
    let to = fmt("s16.8");
    for v in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
        assert!(matches!(
            from_f64(v, to, Rounding::Nearest, Overflow::Saturate),
            Err(FxError::NotFinite { .. })
        ));
    }
}

#[test]
fn exact_arithmetic_grows_as_declared() {
    let a = Fx::new(-128, fmt("s8.4"));
    let b = Fx::new(31, fmt("s6.2"));
    let sum = a.exact_add(b).unwrap();
    assert_eq!(sum.format, fmt("s9.4").into_intermediate());
    assert_eq!(sum.to_f64(), -8.0 + 7.75);
    let diff = Fx::new(0, fmt("u4.0"))
        .exact_sub(Fx::new(15, fmt("u4.0")))
        .unwrap();
    assert_eq!((diff.code, diff.format.signed), (-15, true));
    let prod = a.exact_mul(b).unwrap();
    assert_eq!(prod.format, fmt("s14.6").into_intermediate());
    assert_eq!(prod.to_f64(), -8.0 * 7.75);
    // s64 x s64 needs all 128 bits (only for MIN x MIN), and is carried exactly.
    let s64 = fmt("s64.0");
    let min = Fx::new(i128::from(i64::MIN), s64);
    let square = min.exact_mul(min).unwrap();
    assert_eq!((square.code, square.format.width), (1i128 << 126, 128));
    let wide = Format::intermediate(true, 100, 0).unwrap();
    assert!(matches!(
        Format::product(wide, wide),
        Err(FxError::IntermediateWidth { width: 200, .. })
    ));
    assert!(Format::intermediate(false, 128, 0).is_err());
}

impl Format {
    fn into_intermediate(self) -> Format {
        Format::intermediate(self.signed, self.width, self.frac).unwrap()
    }
}

/// Every code of every tiny source format into every tiny target, in every mode: as
/// en_cl_fix does for its core, exhaustively rather than by sampling.
#[test]
fn exhaustive_tiny_formats_against_the_reference() {
    let mut checked = 0u64;
    for from_signed in [true, false] {
        for from_width in 1..=6u32 {
            for from_frac in -2..=6i32 {
                let from = Format::new(from_signed, from_width, from_frac).unwrap();
                for to_signed in [true, false] {
                    for to_width in 1..=6u32 {
                        for to_frac in -2..=6i32 {
                            let to = Format::new(to_signed, to_width, to_frac).unwrap();
                            for code in from.min_code()..=from.max_code() {
                                for rounding in Rounding::ALL {
                                    for overflow in Overflow::ALL {
                                        let got =
                                            requantize(code, from_frac, to, rounding, overflow);
                                        let shift = from_frac - to_frac;
                                        let rounded = if shift >= 0 {
                                            reference_round(code, shift as u32, rounding)
                                        } else {
                                            code * (1i128 << (-shift))
                                        };
                                        let (want, over) =
                                            reference_overflow(rounded, to, overflow);
                                        assert_eq!(
                                            (got.code, got.overflowed),
                                            (want, over),
                                            "{code} of {from} into {to}, {rounding}, {overflow}"
                                        );
                                        checked += 1;
                                    }
                                }
                            }
                        }
                    }
                }
            }
        }
    }
    assert!(checked > 1_000_000, "{checked}");
}

/// The branch-free per-mode fast path of [`Quantizer`] against [`requantize`], exhaustively on
/// small values, every shift, every mode, both overflow modes (including overflowing targets).
#[test]
fn quantizer_fast_path_equals_requantize() {
    for rounding in Rounding::ALL {
        for overflow in Overflow::ALL {
            for shift in 1..=9i32 {
                for to in [fmt("s4.0"), fmt("s9.2"), fmt("u3.1"), fmt("s16.0")] {
                    let from_frac = to.frac + shift;
                    let mut q = Quantizer::new(from_frac, to, rounding, overflow);
                    let mut overflows = 0;
                    for code in -3000i128..=3000 {
                        let want = requantize(code, from_frac, to, rounding, overflow);
                        overflows += u64::from(want.overflowed);
                        assert_eq!(
                            q.apply(code),
                            want.code,
                            "{code} >> {shift} into {to} {rounding} {overflow}"
                        );
                    }
                    assert_eq!(q.overflow_count, overflows);
                }
            }
        }
    }
    // Wide values and the largest shifts.
    for rounding in Rounding::ALL {
        let to = Format::intermediate(true, 100, 0).unwrap();
        for shift in [100i32, 126, 127] {
            let mut q = Quantizer::new(shift, to, rounding, Overflow::Saturate);
            for code in [
                i128::MIN,
                i128::MIN + 1,
                -(1 << 126),
                -(1 << 100) - 1,
                -1,
                0,
                1,
                1 << 99,
                (1 << 126) + 5,
                i128::MAX,
            ] {
                let want = requantize(code, shift, to, rounding, Overflow::Saturate).code;
                assert_eq!(q.apply(code), want, "{code} >> {shift} {rounding}");
            }
        }
    }
}

/// Calls `$check::<MODE>(rounding)` for every rounding mode.
macro_rules! every_mode {
    ($check:ident) => {
        $check::<{ mode::FLOOR }>(Rounding::Floor);
        $check::<{ mode::CEIL }>(Rounding::Ceil);
        $check::<{ mode::ZERO }>(Rounding::Zero);
        $check::<{ mode::NEAREST }>(Rounding::Nearest);
        $check::<{ mode::ROUND }>(Rounding::Round);
        $check::<{ mode::CONVERGENT }>(Rounding::Convergent);
    };
}

/// The 64-bit kernel against [`requantize`]: exhaustively on small values, and on the extremes.
#[test]
fn quantizer_i64_path_equals_requantize() {
    fn check<const M: u8>(rounding: Rounding) {
        for overflow in Overflow::ALL {
            for shift in 1..=12i32 {
                for to in [
                    fmt("s4.0"),
                    fmt("s9.2"),
                    fmt("u3.1"),
                    fmt("s40.3"),
                    fmt("s64.0"),
                ] {
                    let from_frac = to.frac + shift;
                    let mut q = Quantizer::new(from_frac, to, rounding, overflow);
                    let mut dispatched = q.clone();
                    let mut overflows = 0;
                    let extremes = [
                        i64::MIN,
                        i64::MIN + 1,
                        i64::MAX,
                        i64::MAX - 1,
                        -(1 << 62),
                        1 << 62,
                    ];
                    for code in (-5000i64..=5000).chain(extremes) {
                        let want = requantize(i128::from(code), from_frac, to, rounding, overflow);
                        overflows += u64::from(want.overflowed);
                        assert_eq!(
                            i128::from(q.apply_mode_i64::<M>(code)),
                            want.code,
                            "{code} >> {shift} into {to} {rounding} {overflow}"
                        );
                        assert_eq!(i128::from(dispatched.apply_i64(code)), want.code);
                    }
                    assert_eq!(q.overflow_count, overflows);
                    assert_eq!(dispatched.overflow_count, overflows);
                }
            }
        }
    }
    every_mode!(check);
}

/// The split 64-bit kernel (an aligned part plus a term) against [`requantize`] on the sum in
/// `i128`: exhaustively on small aligned parts and terms, every shift up to 12, every mode,
/// both overflow modes, overflowing targets; then at wide values and the largest shifts.
#[test]
fn quantizer_split_path_equals_requantize_of_the_sum() {
    fn check<const M: u8>(rounding: Rounding) {
        for overflow in Overflow::ALL {
            for shift in 1..=12i32 {
                for to in [fmt("s4.0"), fmt("s9.2"), fmt("u3.1"), fmt("s40.3")] {
                    let from_frac = to.frac + shift;
                    let mut q = Quantizer::new(from_frac, to, rounding, overflow);
                    let mut overflows = 0;
                    for aligned in -40i64..=40 {
                        for term in -300i64..=300 {
                            let sum = (i128::from(aligned) << shift) + i128::from(term);
                            let want = requantize(sum, from_frac, to, rounding, overflow);
                            overflows += u64::from(want.overflowed);
                            assert_eq!(
                                i128::from(q.apply_mode_split_i64::<M>(aligned, term)),
                                want.code,
                                "({aligned} << {shift}) + {term} into {to} {rounding} {overflow}"
                            );
                        }
                    }
                    assert_eq!(q.overflow_count, overflows);
                }
            }
        }
        // Wide parts: the sum exceeds 64 bits.
        for shift in [1u32, 30, 62, 63] {
            for aligned in [
                -(1i64 << 61),
                -(1 << 40) - 1,
                -1,
                0,
                1,
                (1 << 40) + 3,
                1 << 61,
            ] {
                for term in [
                    i64::MIN >> 1,
                    -(1i64 << 50) - 7,
                    -(1 << (shift - 1)),
                    -1,
                    0,
                    1 << (shift - 1),
                    (1 << 50) + 9,
                    i64::MAX >> 1,
                ] {
                    let sum = (i128::from(aligned) << shift) + i128::from(term);
                    let want = round_right::<M>(sum, shift);
                    assert_eq!(
                        i128::from(round_right_split_i64::<M>(aligned, term, shift)),
                        want,
                        "({aligned} << {shift}) + {term} {rounding}"
                    );
                }
            }
        }
    }
    every_mode!(check);
}

#[test]
fn extreme_shifts_round_correctly() {
    let to = fmt("s8.0");
    for rounding in Rounding::ALL {
        for code in [i128::MIN, -(1 << 126), -1, 0, 1, 1 << 126, i128::MAX] {
            for shift in [126u32, 127, 128, 130, 200] {
                let got = requantize(code, shift as i32, to, rounding, Overflow::Saturate).code;
                // The value lies in [-1, 1]; round it with exact rational reasoning.
                let want = if shift == 127 {
                    // code / 2^127 in [-1, 1): worked out by hand per code.
                    let row = match code {
                        i128::MIN => [-1, -1, -1, -1, -1, -1],
                        c if c == -(1 << 126) => [-1, 0, 0, 0, -1, 0],
                        -1 => [-1, 0, 0, 0, 0, 0],
                        0 => [0; 6],
                        1 => [0, 1, 0, 0, 0, 0],
                        c if c == 1 << 126 => [0, 1, 0, 1, 1, 0],
                        _ => [0, 1, 0, 1, 1, 1], // i128::MAX: just below 1
                    };
                    row[Rounding::ALL.iter().position(|r| *r == rounding).unwrap()]
                } else if shift >= 128 {
                    let negative_half = shift == 128 && code == i128::MIN;
                    match rounding {
                        Rounding::Floor => -i128::from(code < 0),
                        Rounding::Ceil => i128::from(code > 0),
                        Rounding::Round => -i128::from(negative_half),
                        _ => 0,
                    }
                } else {
                    reference_round(code, shift, rounding)
                };
                assert_eq!(got, want, "{code} >> {shift} {rounding}");
            }
        }
    }
}

fn any_rounding() -> impl Strategy<Value = Rounding> {
    prop::sample::select(Rounding::ALL.to_vec())
}
fn any_overflow() -> impl Strategy<Value = Overflow> {
    prop::sample::select(Overflow::ALL.to_vec())
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(4000))]

    #[test]
    fn requantize_matches_exact_reference(
        code in any::<i64>(),
        extra in 0i32..40,
        to_signed in any::<bool>(),
        to_width in 1u32..=64,
        to_frac in -8i32..70,
        rounding in any_rounding(),
        overflow in any_overflow(),
    ) {
        let code = i128::from(code) << 20;
        let from_frac = to_frac + extra - 10;
        let to = Format::new(to_signed, to_width, to_frac).unwrap();
        let got = requantize(code, from_frac, to, rounding, overflow);
        let shift = from_frac - to_frac;
        let rounded = if shift >= 0 {
            reference_round(code, shift as u32, rounding)
        } else {
            code * (1i128 << (-shift))
        };
        let (want, over) = reference_overflow(rounded, to, overflow);
        prop_assert_eq!((got.code, got.overflowed), (want, over));
    }

    #[test]
    fn from_f64_matches_reference_on_dyadic_values(
        mantissa in -(1i64 << 40)..(1i64 << 40),
        exp in -30i32..10,
        to_width in 2u32..=48,
        to_frac in -4i32..40,
        rounding in any_rounding(),
        overflow in any_overflow(),
    ) {
        // mantissa · 2^exp is exact in f64; as a code with frac -exp it is exact in i128.
        let value = mantissa as f64 * pow2(exp);
        let to = Format::signed(to_width, to_frac).unwrap();
        let got = from_f64(value, to, rounding, overflow).unwrap();
        let want = requantize(i128::from(mantissa), -exp, to, rounding, overflow);
        prop_assert_eq!(got, want);
    }

    /// The inline ADC rounding equals `floor` plus the half-LSB test done with std's `floor`,
    /// on arbitrary finite f64 bit patterns and on dyadic values near ties.
    #[test]
    fn round_half_up_equals_floor_based_rounding(
        bits in any::<u64>(),
        mantissa in -(1i64 << 53)..(1i64 << 53),
        exp in -4i32..14,
    ) {
        let reference = |x: f64| {
            let floor = x.floor();
            (floor as i64).saturating_add(i64::from(x - floor >= 0.5))
        };
        let dyadic = mantissa as f64 * pow2(exp);
        for x in [f64::from_bits(bits), dyadic, -dyadic, dyadic + 0.5, dyadic - 0.5] {
            if x.is_finite() {
                prop_assert_eq!(round_half_up(x), reference(x), "x = {:e}", x);
            }
        }
    }

    #[test]
    fn bits_round_trip(code in any::<i64>(), width in 1u32..=64, signed in any::<bool>()) {
        let f = Format::new(signed, width, 0).unwrap();
        let code = f.wrap(i128::from(code));
        prop_assert!(f.contains(code));
        prop_assert_eq!(f.from_bits(f.to_bits(code)), code);
    }
}

/// The `fixed` crate as an independent oracle on the formats it has.
mod against_fixed_crate {
    use super::*;
    use fixed::types::{I16F16, I32F32, I8F24};

    fn i16f16() -> Format {
        fmt("s32.16")
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(4000))]

        #[test]
        fn add_wrapping_and_saturating(a in any::<i32>(), b in any::<i32>()) {
            let f = i16f16();
            let sum = Fx::new(a.into(), f).exact_add(Fx::new(b.into(), f)).unwrap();
            let wrap = sum.quantize(f, Rounding::Floor, Overflow::Wrap).code;
            let sat = sum.quantize(f, Rounding::Floor, Overflow::Saturate).code;
            let (fa, fb) = (I16F16::from_bits(a), I16F16::from_bits(b));
            prop_assert_eq!(wrap, i128::from(fa.wrapping_add(fb).to_bits()));
            prop_assert_eq!(sat, i128::from(fa.saturating_add(fb).to_bits()));
        }

        #[test]
        fn mul_wrapping_and_saturating_i16f16(a in any::<i32>(), b in any::<i32>()) {
            // `fixed` truncates the product's extra fraction bits (toward -inf).
            let f = i16f16();
            let prod = Fx::new(a.into(), f).exact_mul(Fx::new(b.into(), f)).unwrap();
            let (fa, fb) = (I16F16::from_bits(a), I16F16::from_bits(b));
            prop_assert_eq!(
                prod.quantize(f, Rounding::Floor, Overflow::Wrap).code,
                i128::from(fa.wrapping_mul(fb).to_bits())
            );
            prop_assert_eq!(
                prod.quantize(f, Rounding::Floor, Overflow::Saturate).code,
                i128::from(fa.saturating_mul(fb).to_bits())
            );
        }

        #[test]
        fn mul_i32f32_and_i8f24(a in any::<i64>(), b in any::<i64>(), c in any::<i32>(), d in any::<i32>()) {
            let f = fmt("s64.32");
            let prod = Fx::new(a.into(), f).exact_mul(Fx::new(b.into(), f)).unwrap();
            let (fa, fb) = (I32F32::from_bits(a), I32F32::from_bits(b));
            prop_assert_eq!(
                prod.quantize(f, Rounding::Floor, Overflow::Saturate).code,
                i128::from(fa.saturating_mul(fb).to_bits())
            );
            let g = fmt("s32.24");
            let prod = Fx::new(c.into(), g).exact_mul(Fx::new(d.into(), g)).unwrap();
            let (fc, fd) = (I8F24::from_bits(c), I8F24::from_bits(d));
            prop_assert_eq!(
                prod.quantize(g, Rounding::Floor, Overflow::Wrap).code,
                i128::from(fc.wrapping_mul(fd).to_bits())
            );
        }

        #[test]
        fn conversion_from_f64_is_convergent(x in -40000.0f64..40000.0) {
            // `fixed` converts floats to nearest with ties to even.
            let got = from_f64(x, i16f16(), Rounding::Convergent, Overflow::Saturate).unwrap().code;
            prop_assert_eq!(got, i128::from(I16F16::saturating_from_num(x).to_bits()));
            let got = from_f64(x / 1000.0, fmt("s32.24"), Rounding::Convergent, Overflow::Wrap).unwrap().code;
            prop_assert_eq!(got, i128::from(I8F24::wrapping_from_num(x / 1000.0).to_bits()));
        }

        #[test]
        fn conversion_to_f64(a in any::<i32>()) {
            prop_assert_eq!(i16f16().to_f64(a.into()), I16F16::from_bits(a).to_num::<f64>());
        }
    }
}

#[test]
fn round_half_up_at_the_edges_of_exactness_and_of_i64() {
    let reference = |x: f64| {
        let floor = x.floor();
        (floor as i64).saturating_add(i64::from(x - floor >= 0.5))
    };
    let p52 = pow2(52);
    let p63 = pow2(63);
    for x in [
        0.0,
        -0.0,
        0.5,
        -0.5,
        0.49999999999999994,
        -0.49999999999999994,
        1.5,
        -1.5,
        2.5,
        -2.5,
        f64::MIN_POSITIVE,
        -f64::MIN_POSITIVE,
        p52 - 0.5,
        -p52 + 0.5,
        p52,
        -p52,
        p52 + 1.0,
        p63,
        -p63,
        p63 * 2.0,
        -p63 * 2.0,
        f64::from_bits((-p63).to_bits() + 1), // the next f64 below −2^63
        f64::MAX,
        f64::MIN,
    ] {
        assert_eq!(round_half_up(x), reference(x), "x = {x:e}");
    }
    assert_eq!(round_half_up(-0.5), 0);
    assert_eq!(round_half_up(-1.5), -1);
    assert_eq!(round_half_up(p63), i64::MAX);
    assert_eq!(round_half_up(-p63 * 2.0), i64::MIN);
}
