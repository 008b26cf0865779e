//! Numbers in their shortest round-trip form, written fast.
//!
//! The output is the form Rust's `{}` gives (no exponent, no trailing
//! `.0`, negative zero as `0`): every number reads back as the same `f64`.
//! Three paths:
//!
//! * values that are a whole number of thousandths (most programmed
//!   coordinates, feeds, and angles) are written from that integer: if
//!   `k / 1000.0 == x`, the decimal `k/1000` is the nearest double to `x`
//!   and, below [`FAST_PATH_LIMIT`], no shorter decimal lies within half a
//!   unit in the last place of `x`, so it is the shortest form;
//! * every other value below [`TIE_FREE_LIMIT`] goes through `zmij`
//!   (Schubfach shortest digits), whose exponent form is rewritten
//!   positionally;
//! * larger values are written by Rust's own formatter. Only there can
//!   two shortest forms lie equally near the value (`558373550007.40625`
//!   is as near `…4062` as `…4063`), and `zmij` breaks such a tie the
//!   other way.

use crate::text::Text;

/// Largest magnitude for the thousandths path: below it one unit in the
/// last place is far smaller than 0.001.
const FAST_PATH_LIMIT: f64 = 1e12;
const THOUSAND: f64 = 1000.0;
/// Magnitude from which Rust's formatter writes numbers. A tie between
/// two shortest forms needs the value's exact decimal to be one digit
/// longer than them and half a unit in the last place to reach a unit of
/// their last digit, which takes more than 4.5·10^10 (a unit in the last
/// place of 10^-5); a decade of margin below that.
const TIE_FREE_LIMIT: f64 = 1e9;
/// Magnitudes `zmij` surely writes without an exponent (it does from
/// 10^-5 to below 10^16; a margin of a decade on each side).
const POSITIONAL_MIN: f64 = 1e-4;
const POSITIONAL_MAX: f64 = 1e15;

/// Appends `x` to `out`.
pub fn write_f64(out: &mut Text, x: f64) {
    let x = x + 0.0; // negative zero becomes zero
    if x.abs() < FAST_PATH_LIMIT {
        // Nearest integer to x·1000 without a call to `round`.
        let y = x * THOUSAND;
        let mut k = y as i64;
        let rest = y - k as f64;
        if rest >= 0.5 {
            k += 1;
        } else if rest <= -0.5 {
            k -= 1;
        }
        if k as f64 / THOUSAND == x {
            write_thousandths(out, k);
            return;
        }
    }
    write_shortest(out, x);
}

/// Appends `x` to `out` as [`write_f64`] does, without first trying the
/// thousandths path: for computed values (tips, tool directions), which
/// are seldom a whole number of thousandths and would only wait on that
/// path's division.
pub fn write_computed_f64(out: &mut Text, x: f64) {
    write_shortest(out, x + 0.0);
}

/// The shortest digits of `x` (not negative zero) by `zmij`, positional.
fn write_shortest(out: &mut Text, x: f64) {
    if !x.is_finite() {
        out.put_slice(if x.is_nan() {
            b"NaN"
        } else if x > 0.0 {
            b"inf"
        } else {
            b"-inf"
        });
        return;
    }
    if x.abs() >= TIE_FREE_LIMIT {
        let _ = std::fmt::Write::write_fmt(&mut TextWriter(out), format_args!("{x}"));
        return;
    }
    let mut buffer = zmij::Buffer::new();
    let text = buffer.format_finite(x).as_bytes();
    // zmij writes positionally from 1e-5 to below 1e16: no exponent to
    // look for in between.
    let positional = (POSITIONAL_MIN..POSITIONAL_MAX).contains(&x.abs());
    if (!positional && text.contains(&b'e')) || text.ends_with(b".0") {
        write_positional(out, text);
    } else {
        out.put_slice(text);
    }
}

/// `Text` as a `fmt::Write` (a number of at most 330 bytes, within the
/// room kept free past the cursor).
struct TextWriter<'a>(&'a mut Text);

impl std::fmt::Write for TextWriter<'_> {
    fn write_str(&mut self, piece: &str) -> std::fmt::Result {
        self.0.put_slice(piece.as_bytes());
        Ok(())
    }
}

/// The most decimals `--digits` takes: beyond 15 a double has no digits
/// left to round at for numbers of machine size.
pub const MAX_DIGITS: u8 = 15;

/// Powers of ten up to `10^MAX_DIGITS`, each exact.
const POWERS: [f64; MAX_DIGITS as usize + 1] = [
    1e0, 1e1, 1e2, 1e3, 1e4, 1e5, 1e6, 1e7, 1e8, 1e9, 1e10, 1e11, 1e12, 1e13, 1e14, 1e15,
];

/// Largest scaled magnitude written from an integer, 2^53: below it every
/// whole number is a double, so `x · 10^n` rounds to the integer nearest
/// the decimal (within the one rounding of the product).
const SCALED_LIMIT: f64 = 9_007_199_254_740_992.0;

/// Appends `x` rounded to at most `digits` decimals (at most
/// [`MAX_DIGITS`]; half away from zero), trailing zeros and a bare point
/// left out, never `-0`: `-25.000000000000004` is `-25`, `3.06e-17` is `0`
/// at 6 digits. A number too large for that many decimals keeps as many
/// as its magnitude leaves (a double has about 17 significant digits).
pub fn write_rounded(out: &mut Text, x: f64, digits: u8) {
    if !x.is_finite() {
        write_f64(out, x);
        return;
    }
    let mut n = usize::from(digits.min(MAX_DIGITS));
    loop {
        let scaled = (x * POWERS[n]).round();
        if scaled.abs() < SCALED_LIMIT {
            write_scaled(out, scaled as i64, n);
            return;
        }
        if n == 0 {
            // Beyond 2^53 every double is a whole number: nothing to round.
            write_f64(out, x);
            return;
        }
        n -= 1;
    }
}

/// Writes `k / 10^decimals` without trailing zeros (and `0` for zero).
fn write_scaled(out: &mut Text, k: i64, decimals: usize) {
    let magnitude = k.unsigned_abs();
    let unit = 10u64.pow(decimals as u32);
    let (whole, mut frac) = (magnitude / unit, magnitude % unit);
    let mut decimals = decimals;
    while frac != 0 && frac.is_multiple_of(10) {
        frac /= 10;
        decimals -= 1;
    }
    if k < 0 {
        out.push(b'-');
    }
    out.put_decimal(whole);
    if frac != 0 {
        out.push(b'.');
        out.put_digits(frac, decimals);
    }
}

/// Writes `k / 1000` without trailing zeros ([`write_scaled`] with three
/// decimals, by constant divisors and the table of digit pairs).
fn write_thousandths(out: &mut Text, k: i64) {
    let magnitude = k.unsigned_abs();
    let (whole, frac) = (magnitude / 1000, (magnitude % 1000) as usize);
    if k < 0 {
        out.push(b'-');
    }
    out.put_decimal(whole);
    if frac != 0 {
        out.push(b'.');
        let (tenths, rest) = (frac / 100, frac % 100);
        out.push(b'0' + tenths as u8);
        if rest % 10 == 0 {
            if rest != 0 {
                out.push(b'0' + (rest / 10) as u8);
            }
        } else {
            out.put_pair(rest);
        }
    }
}

/// Appends the decimal digits of `n`.
pub fn write_u64(out: &mut Text, n: u64) {
    out.put_decimal(n);
}

/// Rewrites `zmij`'s output (`1.5e-7`, `1e+22`, `100.0`) the way Rust's
/// `{}` prints the same digits (`0.00000015`, `10000000000000000000000`,
/// `100`).
fn write_positional(out: &mut Text, text: &[u8]) {
    let (negative, text) = match text.split_first() {
        Some((b'-', rest)) => (true, rest),
        _ => (false, text),
    };
    let (mantissa, exponent) = match text.iter().position(|&b| b == b'e') {
        Some(e) => (&text[..e], parse_exponent(&text[e + 1..])),
        None => (text, 0),
    };
    let point = mantissa
        .iter()
        .position(|&b| b == b'.')
        .unwrap_or(mantissa.len());
    let mut digits = [0u8; 32];
    let mut len = 0;
    for &b in mantissa.iter().filter(|b| b.is_ascii_digit()) {
        if len < digits.len() {
            digits[len] = b;
            len += 1;
        }
    }
    // Drop trailing zeros of the fraction ("100.0" → digits "1000", point 3).
    let mut digits = &digits[..len];
    let point = point as i64 + exponent;
    while digits.len() as i64 > point.max(1) && digits.last() == Some(&b'0') {
        digits = &digits[..digits.len() - 1];
    }
    // Drop leading zeros that stand before the point ("0.001").
    let mut point = point;
    while digits.len() > 1 && digits[0] == b'0' && point > 1 {
        digits = &digits[1..];
        point -= 1;
    }
    if negative {
        out.push(b'-');
    }
    let n = digits.len() as i64;
    let zeros = |out: &mut Text, count: i64| (0..count).for_each(|_| out.push(b'0'));
    if point <= 0 {
        out.put_slice(b"0.");
        zeros(out, -point);
        out.put_slice(digits);
    } else if point >= n {
        out.put_slice(digits);
        zeros(out, point - n);
    } else {
        let p = point as usize;
        out.put_slice(&digits[..p]);
        out.push(b'.');
        out.put_slice(&digits[p..]);
    }
}

fn parse_exponent(text: &[u8]) -> i64 {
    let (sign, digits) = match text.split_first() {
        Some((b'-', rest)) => (-1, rest),
        Some((b'+', rest)) => (1, rest),
        _ => (1, text),
    };
    sign * digits
        .iter()
        .fold(0i64, |n, &b| n * 10 + i64::from(b.wrapping_sub(b'0')))
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    fn text(x: f64) -> String {
        let mut out = Text::default();
        write_f64(&mut out, x);
        String::from_utf8(out.as_bytes().to_vec()).unwrap_or_default()
    }

    #[test]
    fn matches_rust_display_on_known_values() {
        for x in [
            0.0,
            -0.0,
            1.0,
            -1.0,
            100.0,
            0.1,
            0.5,
            -0.5,
            123.456,
            -123.456,
            0.001,
            0.0001,
            1e-5,
            1e-7,
            1.1102230246251565e-16,
            12.000000000000007,
            1e15,
            1e16,
            1e22,
            1.5e20,
            5e-324,
            250.367,
            359.99999999999994,
            1e12,
            999999999999.999,
            // Two shortest forms equally near: Rust's is the contract's.
            558_373_550_007.406_3,
            f64::MAX,
            f64::MIN_POSITIVE,
        ] {
            assert_eq!(text(x), format!("{}", x + 0.0), "for {x:?}");
        }
    }

    fn rounded(x: f64, digits: u8) -> String {
        let mut out = Text::default();
        write_rounded(&mut out, x, digits);
        String::from_utf8(out.as_bytes().to_vec()).unwrap_or_default()
    }

    #[test]
    fn rounded_numbers_lose_their_noise_and_trailing_zeros() {
        assert_eq!(rounded(-25.000000000000004, 6), "-25");
        assert_eq!(rounded(3.061616997868383e-17, 6), "0");
        assert_eq!(rounded(-3.061616997868383e-17, 6), "0");
        assert_eq!(rounded(-0.0, 3), "0");
        assert_eq!(rounded(-0.0004, 3), "0");
        assert_eq!(rounded(-0.0005, 3), "-0.001");
        assert_eq!(rounded(std::f64::consts::FRAC_1_SQRT_2, 4), "0.7071");
        assert_eq!(rounded(0.70715, 0), "1");
        assert_eq!(rounded(123.450, 2), "123.45");
        assert_eq!(rounded(123.4, 6), "123.4");
        assert_eq!(rounded(1000.0, 3), "1000");
        assert_eq!(rounded(359.99999999999994, 6), "360");
        assert_eq!(rounded(1e300, 6), format!("{}", 1e300));
        assert_eq!(rounded(123_456_789.123_456_79, 15), "123456789.1234568");
        assert_eq!(rounded(f64::NAN, 3), "NaN");
        assert_eq!(rounded(0.1, 99), "0.1");
    }

    proptest! {
        #[test]
        fn rounded_numbers_are_within_half_a_unit_and_never_minus_zero(
            x in -1e7..1e7f64, scale in 0i32..12, digits in 0u8..=15
        ) {
            let x = x / 10f64.powi(scale);
            let t = rounded(x, digits);
            let back: f64 = t.parse().unwrap_or(f64::NAN);
            let decimals = t.split_once('.').map_or(0, |(_, f)| f.len());
            prop_assert!(decimals <= usize::from(digits), "{} has more than {} decimals", t, digits);
            prop_assert!(!t.ends_with('0') || !t.contains('.'), "{}", t);
            prop_assert!(t != "-0", "{}", t);
            let half = 0.5 * 10f64.powi(-i32::from(digits));
            prop_assert!((back - x).abs() <= half * (1.0 + 1e-9) + x.abs() * 1e-15, "{} from {}", t, x);
        }

        #[test]
        fn reads_back_exactly(bits in any::<u64>()) {
            let x = f64::from_bits(bits);
            prop_assume!(x.is_finite());
            let t = text(x);
            prop_assert_eq!(t.parse::<f64>().ok().map(f64::to_bits), Some((x + 0.0).to_bits()), "{}", t);
        }

        #[test]
        fn equals_rust_display_for_machine_sized_values(x in -1e9..1e9f64, scale in 0i32..12) {
            let x = x / 10f64.powi(scale);
            prop_assert_eq!(text(x), format!("{}", x + 0.0));
        }

        /// Around both ends of the range where no exponent is looked for
        /// and across the limit where Rust's formatter takes over: never
        /// an exponent, the same double read back, Rust's form.
        #[test]
        fn positional_around_the_range_without_exponent_search(m in 1.0..10.0f64, e in -7i32..=17, negative in any::<bool>()) {
            let x = m * 10f64.powi(e);
            let x = if negative { -x } else { x };
            let t = text(x);
            prop_assert!(!t.contains('e'), "{}", t);
            prop_assert_eq!(t.parse::<f64>().ok().map(f64::to_bits), Some(x.to_bits()), "{}", t);
            prop_assert_eq!(t, format!("{}", x + 0.0));
        }

        #[test]
        fn equals_rust_display_for_short_decimals(k in -1_000_000_000i64..1_000_000_000) {
            let x = k as f64 / 1000.0;
            prop_assert_eq!(text(x), format!("{}", x + 0.0));
        }

        /// Computed values take the other road to the same text.
        #[test]
        fn computed_values_are_written_alike(k in -1_000_000_000i64..1_000_000_000, noise in 0u64..4, bits in any::<u64>()) {
            let short = k as f64 / 1000.0;
            let near = f64::from_bits(short.to_bits().wrapping_add(noise));
            for x in [short, near, -short, f64::from_bits(bits), 0.0, -0.0, 1.0] {
                let mut out = Text::default();
                write_computed_f64(&mut out, x);
                let computed = String::from_utf8(out.as_bytes().to_vec()).unwrap_or_default();
                prop_assert_eq!(computed, text(x));
            }
        }
    }
}
