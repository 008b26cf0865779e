//! Numbers in their shortest round-trip form, written fast.
//!
//! The output is the form Rust's `{}` gives (no exponent, no trailing
//! `.0`, negative zero as `0`): every number reads back as the same `f64`.
//! Two paths:
//!
//! * values that are a whole number of thousandths (most programmed
//!   coordinates, feeds, and angles) are written from that integer: if
//!   `k / 1000.0 == x`, the decimal `k/1000` is the nearest double to `x`
//!   and, below [`FAST_PATH_LIMIT`], no shorter decimal lies within half a
//!   unit in the last place of `x`, so it is the shortest form;
//! * every other value goes through `zmij` (Schubfach shortest digits),
//!   whose exponent form is rewritten positionally.

use crate::text::Text;

/// Largest magnitude for the thousandths path: below it one unit in the
/// last place is far smaller than 0.001.
const FAST_PATH_LIMIT: f64 = 1e12;
const THOUSAND: f64 = 1000.0;

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
    let mut buffer = zmij::Buffer::new();
    let text = buffer.format_finite(x).as_bytes();
    if text.contains(&b'e') || text.ends_with(b".0") {
        write_positional(out, text);
    } else {
        for &byte in text {
            out.push(byte);
        }
    }
}

/// Writes `k / 1000` without trailing zeros.
fn write_thousandths(out: &mut Text, k: i64) {
    let magnitude = k.unsigned_abs();
    let (whole, mut frac) = (magnitude / 1000, magnitude % 1000);
    let mut decimals = 3;
    while frac != 0 && frac.is_multiple_of(10) {
        frac /= 10;
        decimals -= 1;
    }
    if k < 0 {
        out.push(b'-');
    }
    out.put_digits(whole, decimal_digits(whole));
    if frac != 0 {
        out.push(b'.');
        out.put_digits(frac, decimals);
    }
}

/// How many decimal digits `n` has (1 for 0).
fn decimal_digits(n: u64) -> usize {
    let mut digits = 1;
    let mut bound = 10;
    while n >= bound && digits < 20 {
        digits += 1;
        bound = bound.saturating_mul(10);
    }
    digits
}

/// Appends the decimal digits of `n`.
pub fn write_u64(out: &mut Text, n: u64) {
    out.put_digits(n, decimal_digits(n));
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
            f64::MAX,
            f64::MIN_POSITIVE,
        ] {
            assert_eq!(text(x), format!("{}", x + 0.0), "for {x:?}");
        }
    }

    proptest! {
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

        #[test]
        fn equals_rust_display_for_short_decimals(k in -1_000_000_000i64..1_000_000_000) {
            let x = k as f64 / 1000.0;
            prop_assert_eq!(text(x), format!("{}", x + 0.0));
        }
    }
}
