//! Plain decimal numbers read without the general parser: Clinger's fast path.
//!
//! A decimal `[+-]digits[.digits][(e|E)[+-]digits]` whose digits form an integer `w ≤ 2^53`
//! and whose power of ten `10^e` has `|e| ≤ 22` is `w · 10^e` or `w / 10^-e` of two doubles
//! that are both exact, so one IEEE multiplication or division rounds it correctly: the same
//! double as the correctly rounded general parser (`str::parse::<f64>`). Every other text
//! (more digits, larger exponents, `inf`, spaces) is left to that parser.

/// `10^0 ..= 10^22`, every one exact in binary64.
const POWERS_OF_TEN: [f64; 23] = [
    1e0, 1e1, 1e2, 1e3, 1e4, 1e5, 1e6, 1e7, 1e8, 1e9, 1e10, 1e11, 1e12, 1e13, 1e14, 1e15, 1e16,
    1e17, 1e18, 1e19, 1e20, 1e21, 1e22,
];

/// Largest integer below which every integer is exact in binary64.
const EXACT_INTEGERS: u64 = 1 << 53;

/// The plain decimal at the start of `bytes`: its value and the number of bytes it took, or
/// `None` when the text there is not one the fast path rounds exactly (the caller then uses
/// the general parser on the whole cell). The number ends at the first byte that cannot
/// continue it; the caller checks that this is the cell's end.
pub(crate) fn parse_prefix(bytes: &[u8]) -> Option<(f64, usize)> {
    let mut i = 0;
    let negative = match bytes.first() {
        Some(b'-') => {
            i = 1;
            true
        }
        Some(b'+') => {
            i = 1;
            false
        }
        _ => false,
    };
    // Digits are accumulated with wrapping arithmetic and counted from positions: more than
    // 19 (leading zeros included) could have wrapped, and are left to the general parser.
    let mut whole: u64 = 0;
    let integer_start = i;
    while let Some(&d) = bytes.get(i) {
        let digit = d.wrapping_sub(b'0');
        if digit > 9 {
            break;
        }
        whole = whole.wrapping_mul(10).wrapping_add(u64::from(digit));
        i += 1;
    }
    let mut digits = i - integer_start;
    let mut exponent: i32 = 0;
    if bytes.get(i) == Some(&b'.') {
        i += 1;
        let fraction_start = i;
        while let Some(&d) = bytes.get(i) {
            let digit = d.wrapping_sub(b'0');
            if digit > 9 {
                break;
            }
            whole = whole.wrapping_mul(10).wrapping_add(u64::from(digit));
            i += 1;
        }
        let fraction = i - fraction_start;
        digits += fraction;
        // Any count above 19 is refused below, so the cast cannot lose a value that matters.
        exponent = -(fraction.min(64) as i32);
    }
    if digits > 19 {
        return None;
    }
    if digits == 0 {
        return None;
    }
    if matches!(bytes.get(i), Some(b'e' | b'E')) {
        i += 1;
        let negative_exponent = match bytes.get(i) {
            Some(b'-') => {
                i += 1;
                true
            }
            Some(b'+') => {
                i += 1;
                false
            }
            _ => false,
        };
        let mut written: i32 = 0;
        let mut exponent_digits = 0;
        while let Some(d) = bytes.get(i).filter(|b| b.is_ascii_digit()) {
            written = written * 10 + i32::from(d - b'0');
            exponent_digits += 1;
            i += 1;
            if exponent_digits > 4 {
                return None;
            }
        }
        if exponent_digits == 0 {
            return None;
        }
        exponent += if negative_exponent { -written } else { written };
    }
    if whole > EXACT_INTEGERS || exponent.unsigned_abs() as usize >= POWERS_OF_TEN.len() {
        return None;
    }
    // Exact: whole ≤ 2^53.
    let whole = whole as f64;
    let power = POWERS_OF_TEN[exponent.unsigned_abs() as usize];
    let magnitude = if exponent >= 0 {
        whole * power
    } else {
        whole / power
    };
    Some((if negative { -magnitude } else { magnitude }, i))
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    /// The fast path's value where it takes the whole text, else the general parser's.
    fn check(text: &str) {
        let general = text.parse::<f64>();
        match parse_prefix(text.as_bytes()) {
            Some((value, used)) if used == text.len() => {
                let general = general.unwrap_or_else(|_| panic!("{text:?}: fast path took it"));
                assert_eq!(value.to_bits(), general.to_bits(), "{text:?}");
            }
            _ => {}
        }
    }

    #[test]
    fn ordinary_numbers_take_the_fast_path_and_match() {
        for text in [
            "0",
            "-0",
            "+0",
            "12.338167",
            "-9.337146",
            "1e5",
            "1E-5",
            "5.",
            ".5",
            "-.5e+3",
            "9007199254740992",
            "0.1",
            "1234567890123456e-22",
            "3.0e22",
            "1e-22",
        ] {
            let (value, used) = parse_prefix(text.as_bytes()).expect(text);
            assert_eq!(used, text.len(), "{text}");
            assert_eq!(
                value.to_bits(),
                text.parse::<f64>().unwrap().to_bits(),
                "{text}"
            );
        }
        assert!(parse_prefix(b"-0").unwrap().0.is_sign_negative());
    }

    #[test]
    fn what_it_cannot_round_exactly_is_left_to_the_general_parser() {
        for text in [
            "9007199254740993", // 2^53 + 1
            "1e23",
            "1e-23",
            "12345678901234567890",
            "1e",
            "1e+",
            ".",
            "-",
            "",
            "inf",
            "NaN",
            " 1",
            "1e99999",
        ] {
            let taken = parse_prefix(text.as_bytes()).is_some_and(|(_, used)| used == text.len());
            assert!(!taken, "{text:?}");
        }
        // It stops where the number stops; the caller checks the cell ends there.
        assert_eq!(parse_prefix(b"1.5,2"), Some((1.5, 3)));
        assert_eq!(parse_prefix(b"2 "), Some((2.0, 1)));
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(20_000))]

        #[test]
        fn equals_the_general_parser_on_random_decimals(
            sign in prop::sample::select(vec!["", "-", "+"]),
            int in "[0-9]{0,12}",
            frac in prop::option::of("[0-9]{0,12}"),
            exp in prop::option::of((prop::sample::select(vec!["e", "E"]), prop::sample::select(vec!["", "-", "+"]), 0i32..40)),
        ) {
            let mut text = format!("{sign}{int}");
            if let Some(frac) = frac {
                text.push('.');
                text.push_str(&frac);
            }
            if let Some((e, s, v)) = exp {
                text.push_str(&format!("{e}{s}{v}"));
            }
            check(&text);
        }

        #[test]
        fn equals_the_general_parser_on_printed_doubles(bits in any::<u64>(), digits in 1usize..18) {
            let value = f64::from_bits(bits);
            prop_assume!(value.is_finite());
            check(&format!("{value:.digits$e}"));
            check(&format!("{value}"));
            check(&format!("{:.digits$}", value / 1e10_f64.powi(30)));
        }

        #[test]
        fn arbitrary_bytes_never_panic(bytes in prop::collection::vec(any::<u8>(), 0..40)) {
            if let Some((_, used)) = parse_prefix(&bytes) {
                prop_assert!(used <= bytes.len());
            }
        }
    }
}
