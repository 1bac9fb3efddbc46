//! Numbers as text, one of each: how a number reads in a program
//! ([`source`]), in SVG coordinates (a fixed number of decimals,
//! [`write_decimals`] and [`write_fixed`]), in OBJ (seven significant digits,
//! [`write_significant`]) and as an index ([`write_uint`]), and the rounding
//! of `lsyc edit` ([`round`], [`decimals`]).
//!
//! Owns: the digits. All the plain-decimal writers go through one routine,
//! [`write_scaled`] (an integer times a power of ten, trailing zeros dropped,
//! no exponent, no negative zero). The byte writers append to a buffer
//! without allocating (they run once per coordinate of large drawings).
//! Everything is deterministic: the same `f64` always gives the same text.
//! Must not know where the text goes.

use std::io::Write;

/// Prints a number as the lexer reads it back: `30`, `0.7`, `1e-7`, `1.5e20`.
/// Negative values get a leading `-` (which parses as unary minus); NaN and the
/// infinities, which no literal can spell, print as `(0 / 0)`, `(1 / 0)`, `(-1 / 0)`.
pub fn source(v: f64) -> String {
    if v.is_nan() {
        return "(0 / 0)".to_string();
    }
    if v.is_infinite() {
        return if v > 0.0 { "(1 / 0)" } else { "(-1 / 0)" }.to_string();
    }
    if v == 0.0 {
        return "0".to_string();
    }
    let a = v.abs();
    let digits = if !(1e-4..1e15).contains(&a) {
        format!("{a:e}")
    } else {
        format!("{a}")
    };
    if v < 0.0 {
        format!("-{digits}")
    } else {
        digits
    }
}

/// Appends `m` × 10^`exp` in plain decimal notation, trailing zeros of the
/// fraction dropped, with a `-` when `negative` and `m` is not zero.
pub fn write_scaled(buf: &mut Vec<u8>, negative: bool, mut m: u64, exp: i32) {
    if m == 0 {
        buf.push(b'0');
        return;
    }
    if negative {
        buf.push(b'-');
    }
    // The digits of m, lowest first.
    let mut digits = [b'0'; 20];
    let mut len = 0;
    while m > 0 {
        digits[len] = b'0' + (m % 10) as u8;
        m /= 10;
        len += 1;
    }
    if exp >= 0 {
        buf.extend(digits[..len].iter().rev());
        buf.extend(std::iter::repeat_n(b'0', exp as usize));
        return;
    }
    let k = exp.unsigned_abs() as usize;
    let digit = |i: usize| if i < len { digits[i] } else { b'0' };
    if len > k {
        buf.extend(digits[k..len].iter().rev());
    } else {
        buf.push(b'0');
    }
    let Some(first) = (0..k).find(|&i| digit(i) != b'0') else {
        return;
    };
    buf.push(b'.');
    buf.extend((first..k).rev().map(digit));
}

/// Appends the fixed-point integer `n` (units of 10^-decimals) as a decimal
/// number, trailing zeros dropped.
pub fn write_fixed(buf: &mut Vec<u8>, n: i64, decimals: usize) {
    let exp = -(decimals.min(i32::MAX as usize) as i32);
    write_scaled(buf, n < 0, n.unsigned_abs(), exp);
}

/// Appends `v` with at most `decimals` decimals, trailing zeros dropped; `0`
/// for a value that is not finite, Rust's shortest form beyond 9·10^15 units.
pub fn write_decimals(buf: &mut Vec<u8>, v: f64, decimals: usize) {
    if !v.is_finite() {
        buf.push(b'0');
        return;
    }
    let scale = 10f64.powi(decimals as i32);
    let r = (v * scale).round();
    if r.abs() >= 9.0e15 {
        buf.extend_from_slice(format!("{v}").as_bytes());
        return;
    }
    write_fixed(buf, r as i64, decimals);
}

/// Appends a decimal integer.
pub fn write_uint(buf: &mut Vec<u8>, mut n: u64) {
    const PAIRS: &[u8; 200] = b"0001020304050607080910111213141516171819\
        2021222324252627282930313233343536373839\
        4041424344454647484950515253545556575859\
        6061626364656667686970717273747576777879\
        8081828384858687888990919293949596979899";
    let mut digits = [0u8; 20];
    let mut i = digits.len();
    while n >= 100 {
        let r = (n % 100) as usize * 2;
        n /= 100;
        i -= 2;
        digits[i..i + 2].copy_from_slice(&PAIRS[r..r + 2]);
    }
    if n >= 10 {
        let r = n as usize * 2;
        i -= 2;
        digits[i..i + 2].copy_from_slice(&PAIRS[r..r + 2]);
    } else {
        i -= 1;
        digits[i] = b'0' + n as u8;
    }
    buf.extend_from_slice(&digits[i..]);
}

/// Powers of ten exactly representable as `f64`.
const POW10: [f64; 23] = [
    1e0, 1e1, 1e2, 1e3, 1e4, 1e5, 1e6, 1e7, 1e8, 1e9, 1e10, 1e11, 1e12, 1e13, 1e14, 1e15, 1e16,
    1e17, 1e18, 1e19, 1e20, 1e21, 1e22,
];

/// `a / 10^(e − 6)` rounded (a > 0): the 7 significant digits of `a` when its
/// decimal exponent is `e`.
fn mantissa(a: f64, e: i32) -> u64 {
    let k = 6 - e;
    let p = POW10
        .get(k.unsigned_abs() as usize)
        .copied()
        .unwrap_or_else(|| 10f64.powi(k.abs()));
    (if k >= 0 { a * p } else { a / p } + 0.5) as u64
}

/// Appends a number with 7 significant digits (about single precision), in
/// plain decimal notation without exponent, trailing zeros or negative zero.
pub fn write_significant(buf: &mut Vec<u8>, x: f64) {
    let a = x.abs();
    if !(1e-15..1e22).contains(&a) {
        // Zero (and rounding noise around it), non-finite (never written), or
        // beyond the usual range.
        if a < 1e-15 || !a.is_finite() {
            buf.push(b'0');
        } else {
            let _ = write!(buf, "{}", x as f32);
        }
        return;
    }
    // The decimal exponent from the binary one (78913 / 2^18 ≈ log10 2), then
    // corrected: the estimate may be one off, and rounding may carry to 10^7.
    let e2 = ((a.to_bits() >> 52) & 0x7ff) as i32 - 1023;
    let mut e = (e2 * 78913) >> 18;
    let mut m = mantissa(a, e);
    for _ in 0..3 {
        if m >= 10_000_000 {
            e += 1;
        } else if m < 1_000_000 {
            e -= 1;
        } else {
            break;
        }
        m = mantissa(a, e);
    }
    write_scaled(buf, x < 0.0, m.clamp(1_000_000, 9_999_999), e - 6);
}

/// The fewest decimals (up to 12) that write `v` exactly.
pub fn decimals(v: f64) -> usize {
    (0..=12)
        .find(|&d| format!("{v:.d$}").parse::<f64>() == Ok(v))
        .unwrap_or(12)
}

/// `v` rounded to `places` decimals, as the nearest double to the decimal
/// (never negative zero).
pub fn round(v: f64, places: usize) -> f64 {
    let r = format!("{v:.places$}").parse::<f64>().unwrap_or(v);
    if r == 0.0 { 0.0 } else { r }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn text(f: impl FnOnce(&mut Vec<u8>)) -> String {
        let mut b = Vec::new();
        f(&mut b);
        String::from_utf8(b).unwrap_or_default()
    }

    #[test]
    fn source_numbers_read_back() {
        assert_eq!(source(30.0), "30");
        assert_eq!(source(0.7), "0.7");
        assert_eq!(source(1e-7), "1e-7");
        assert_eq!(source(-0.0), "0");
        assert_eq!(source(f64::NAN), "(0 / 0)");
        assert_eq!(source(f64::NEG_INFINITY), "(-1 / 0)");
    }

    #[test]
    fn fixed_point_numbers() {
        let f = |n: i64, d: usize| text(|b| write_fixed(b, n, d));
        for (n, d, want) in [
            (0, 3, "0"),
            (1500, 3, "1.5"),
            (-1250, 3, "-1.25"),
            (41, 3, "0.041"),
            (-1, 3, "-0.001"),
            (12, 0, "12"),
            (120, 1, "12"),
            (i64::MIN, 0, "-9223372036854775808"),
        ] {
            assert_eq!(f(n, d), want, "{n} {d}");
        }
        assert_eq!(f(i64::MIN + 1, 2).len(), 21);
        assert_eq!(f(5, 30), format!("0.{}5", "0".repeat(29)));
    }

    #[test]
    fn decimal_numbers_are_short_and_exact_enough() {
        let n = |v: f64, d: usize| text(|b| write_decimals(b, v, d));
        for (v, d, want) in [
            (0.0, 3, "0"),
            (1.5, 3, "1.5"),
            (-1.25, 3, "-1.25"),
            (0.0004, 3, "0"),
            (-0.0004, 3, "0"),
            (0.0405, 3, "0.041"),
            (12.0, 0, "12"),
            (-0.001, 3, "-0.001"),
            (1.23456, 2, "1.23"),
            (f64::NAN, 2, "0"),
        ] {
            assert_eq!(n(v, d), want, "{v} {d}");
        }
        assert_eq!(n(1e300, 2), format!("{}", 1e300));
    }

    #[test]
    fn integers() {
        for n in [0, 7, 10, 99, 100, 12345, u64::MAX] {
            assert_eq!(text(|b| write_uint(b, n)), n.to_string());
        }
    }

    #[test]
    fn numbers_have_seven_significant_digits() {
        let text = |x: f64| {
            let mut b = Vec::new();
            write_significant(&mut b, x);
            String::from_utf8(b).expect("ascii")
        };
        for (x, t) in [
            (0.0, "0"),
            (-0.0, "0"),
            (1.0, "1"),
            (-2.5, "-2.5"),
            (0.1, "0.1"),
            (0.1 + 0.2, "0.3"),
            (100.0, "100"),
            (1e-3, "0.001"),
            (6.123233995736766e-17, "0"),
            (1234567.8, "1234568"),
            (123456789.0, "123456800"),
            (9999999.6, "10000000"),
            (0.99999996, "1"),
            (std::f64::consts::PI, "3.141593"),
            (-0.000123456789, "-0.0001234568"),
        ] {
            assert_eq!(text(x), t, "{x}");
        }
        assert_eq!(text(f64::NAN), "0");
        let mut s = 12345u64;
        for _ in 0..100_000 {
            s = s
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            let x = f64::from_bits((s >> 2) & !(0x7ff << 52) | (((s >> 54) % 60 + 1000) << 52));
            let x = if s & 1 == 0 { x } else { -x };
            let t = text(x);
            let back: f64 = t.parse().expect("a number");
            assert!((back - x).abs() <= 5.0000001e-7 * x.abs(), "{x} as {t}");
            assert!(!t.contains('e') && !t.ends_with('.'), "{t}");
            if t.contains('.') {
                assert!(!t.ends_with('0'), "{t}");
            }
        }
    }

    #[test]
    fn edit_rounding() {
        assert_eq!(decimals(12.345), 3);
        assert_eq!(decimals(40.0), 0);
        assert_eq!(round(0.1 + 0.2, 3), 0.3);
        assert_eq!(round(-0.0001, 2).to_bits(), 0.0f64.to_bits());
    }
}
