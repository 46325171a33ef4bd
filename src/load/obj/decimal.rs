//! Decimal literals to `f64` without the standard parser's per-call overhead, for the common
//! spellings of OBJ coordinates, bit for bit what `str::parse::<f64>` gives.
//!
//! [`parse`] reads `[+-]digits[.digits][(e|E)[+-]digits]` (at least one mantissa digit, as
//! `str::parse` requires) with at most [`MAX_DIGITS`] significant digits into an integer `w`
//! and a decimal exponent `e` (value `w · 10^e`), then rounds once, exactly:
//!
//! - `w ≤ 2^53`, `|e| ≤ 22`: `w` and `10^|e|` are both exact `f64`s, so one IEEE multiplication or
//!   division is the correctly rounded result (Clinger's fast path).
//! - `0 ≤ e ≤ 19`: `w · 10^e` is an exact `u128` (below `2^64 · 10^19 < 2^128`), and the
//!   integer-to-float conversion rounds to nearest, ties to even.
//! - `-21 ≤ e < 0`, `w > 2^53`: `w` shifted left until its top bit is bit 127 is divided by
//!   `10^-e` in integers; the quotient has at least 55 bits (`2^127 / 10^21 > 2^54`), so OR-ing
//!   "remainder ≠ 0" into its lowest bit keeps every rounding decision (the bit lies below the
//!   round bit) and the conversion to `f64` rounds the true quotient correctly; scaling back by a
//!   power of two is exact (the result is a normal number).
//!
//! Anything else — more digits, larger exponents, `inf`/`nan`, a malformed token, bytes that are
//! not ASCII — returns `None`, and the caller asks `str::parse`, which then also gives the error
//! (tested against `str::parse` on millions of random and adversarial literals).

/// The most significant digits read (`10^19 < 2^64`); longer mantissas go to `str::parse`.
pub(super) const MAX_DIGITS: u32 = 19;

/// `10^i` for `i ≤ 22`: exact in `f64` (`5^22 < 2^53`).
const POW10_F64: [f64; 23] = [
    1e0, 1e1, 1e2, 1e3, 1e4, 1e5, 1e6, 1e7, 1e8, 1e9, 1e10, 1e11, 1e12, 1e13, 1e14, 1e15, 1e16, 1e17, 1e18,
    1e19, 1e20, 1e21, 1e22,
];

/// `10^i` as an integer for `i ≤ 21`.
const fn pow10_u128(i: usize) -> u128 {
    let mut v = 1u128;
    let mut k = 0;
    while k < i {
        v *= 10;
        k += 1;
    }
    v
}

const POW10_U128: [u128; 22] = {
    let mut t = [0u128; 22];
    let mut i = 0;
    while i < 22 {
        t[i] = pow10_u128(i);
        i += 1;
    }
    t
};

/// `2^53`: the largest integer below which every integer is an exact `f64`.
const EXACT_INT: u64 = 1 << 53;

/// The value of the decimal literal `t` when it has one of the spellings this reads (see the
/// module doc), exactly `str::parse::<f64>`'s; `None` otherwise (then ask `str::parse`).
#[inline]
pub(super) fn parse(t: &[u8]) -> Option<f64> {
    match prefix(t)? {
        (x, used) if used == t.len() => Some(x),
        _ => None,
    }
}

/// The literal at the start of `t`, read as far as its spelling goes: its value and length,
/// when that much is a spelling [`parse`] reads. The caller checks what follows: when it ends
/// the token, the value is [`parse`]'s (and so `str::parse`'s) for the token.
#[inline]
pub(super) fn prefix(t: &[u8]) -> Option<(f64, usize)> {
    let (negative, rest, sign) = match t {
        [b'-', rest @ ..] => (true, rest, 1),
        [b'+', rest @ ..] => (false, rest, 1),
        _ => (false, t, 0),
    };
    let mut i = 0;
    let mut w: u64 = 0;
    let mut significant: u32 = 0;
    // Integer part.
    digits(rest, &mut i, &mut w, &mut significant);
    let mut mantissa_digits = i;
    let mut exponent: i64 = 0;
    if rest.get(i) == Some(&b'.') {
        i += 1;
        let start = i;
        digits(rest, &mut i, &mut w, &mut significant);
        mantissa_digits += i - start;
        exponent = -((i - start) as i64);
    }
    if mantissa_digits == 0 || significant > MAX_DIGITS {
        return None;
    }
    if let Some(b'e' | b'E') = rest.get(i) {
        i += 1;
        let negative_exp = match rest.get(i) {
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
        let start = i;
        let mut x: i64 = 0;
        while let Some(&c) = rest.get(i) {
            let d = c.wrapping_sub(b'0');
            if d > 9 {
                break;
            }
            // Saturate: any exponent this large is out of the fast range anyway.
            x = (x * 10 + d as i64).min(1 << 40);
            i += 1;
        }
        if i == start {
            return None;
        }
        exponent += if negative_exp { -x } else { x };
    }
    let magnitude = if w == 0 { 0.0 } else { scale(w, exponent)? };
    Some((if negative { -magnitude } else { magnitude }, sign + i))
}

/// Reads the run of ASCII digits of `t` from `*i` into `w` (`w · 10 + d` per digit; wrapping,
/// so only meaningful while `significant` ≤ [`MAX_DIGITS`]), counting the digits from the first
/// non-zero one on in `significant`. Eight digits at a time where eight are there.
#[inline(always)]
fn digits(t: &[u8], i: &mut usize, w: &mut u64, significant: &mut u32) {
    while let Some(eight) = t.get(*i..*i + 8) {
        let Some(v) = eight_digits(u64::from_le_bytes(eight.try_into().expect("8 bytes"))) else {
            break;
        };
        if *w != 0 {
            *significant += 8;
        } else if v != 0 {
            // Digits of `v` (its leading zeros are leading zeros of the number).
            *significant += v.ilog10() + 1;
        }
        *w = w.wrapping_mul(100_000_000).wrapping_add(v as u64);
        *i += 8;
    }
    while let Some(&c) = t.get(*i) {
        let d = c.wrapping_sub(b'0');
        if d > 9 {
            break;
        }
        if *w != 0 || d != 0 {
            *significant += 1;
            *w = w.wrapping_mul(10).wrapping_add(d as u64);
        }
        *i += 1;
    }
}

/// The value of eight ASCII digits (the first in the lowest byte), or `None` if one of the
/// bytes is not a digit.
#[inline(always)]
fn eight_digits(chunk: u64) -> Option<u32> {
    let low = chunk.wrapping_sub(0x3030_3030_3030_3030); // byte - '0'
    let high = chunk.wrapping_add(0x4646_4646_4646_4646); // byte + ('\x7f' - '9')
                                                          // A byte below '0' borrows or wraps into its top bit; one above '9' carries into it; so
                                                          // does any byte with its own top bit set.
    if (low | high | chunk) & 0x8080_8080_8080_8080 != 0 {
        return None;
    }
    // Pairs, then quadruples, then the eight: each step joins neighbouring fields (the first
    // digit is the most significant).
    let pairs = (low * 10 + (low >> 8)) & 0x00ff_00ff_00ff_00ff;
    let quads = (pairs * 100 + (pairs >> 16)) & 0x0000_ffff_0000_ffff;
    Some(((quads * 10_000 + (quads >> 32)) & 0xffff_ffff) as u32)
}

/// `w · 10^e` correctly rounded (`w > 0`), when one of the exact routes of the module doc
/// applies.
#[inline]
fn scale(w: u64, e: i64) -> Option<f64> {
    if w <= EXACT_INT && (-22..=22).contains(&e) {
        let v = w as f64;
        return Some(if e >= 0 { v * POW10_F64[e as usize] } else { v / POW10_F64[(-e) as usize] });
    }
    if (0..=19).contains(&e) {
        return Some((w as u128 * POW10_U128[e as usize]) as f64);
    }
    if (-21..0).contains(&e) {
        let shift = (w as u128).leading_zeros();
        let n = (w as u128) << shift;
        let d = POW10_U128[(-e) as usize];
        let (q, r) = (n / d, n % d);
        debug_assert!(q >= 1 << 54);
        let rounded = (q | (r != 0) as u128) as f64;
        // 2^-shift, shift in 64..=127: a normal f64.
        let unscale = f64::from_bits((1023 - shift as u64) << 52);
        return Some(rounded * unscale);
    }
    None
}

#[cfg(test)]
mod tests {
    use super::parse;

    /// `parse` either declines or gives `str::parse`'s bits; returns whether it answered.
    fn agrees(s: &str) -> bool {
        let want = s.parse::<f64>().ok();
        // The prefix reader on the token followed by a blank and more: it reads exactly the
        // token when `parse` reads it, with the same bits, and stops short of the blank otherwise.
        let line = format!("{s} 7 x");
        let read = super::prefix(line.as_bytes());
        match (parse(s.as_bytes()), read) {
            (Some(x), Some((y, used))) => {
                assert_eq!((x.to_bits(), used), (y.to_bits(), s.len()), "'{s}' as a prefix");
            }
            (Some(_), None) => panic!("'{s}': read as a token, not as a prefix"),
            (None, Some((_, used))) => assert!(used < s.len() || s.is_empty(), "'{s}' read as a prefix only"),
            (None, None) => {}
        }
        match parse(s.as_bytes()) {
            Some(got) => {
                let want = want.unwrap_or_else(|| panic!("'{s}': read {got:e}, str::parse refuses it"));
                assert_eq!(got.to_bits(), want.to_bits(), "'{s}': {got:e} vs {want:e}");
                true
            }
            None => false,
        }
    }

    /// A small xorshift generator (deterministic).
    struct Rng(u64);
    impl Rng {
        fn next(&mut self) -> u64 {
            self.0 ^= self.0 << 13;
            self.0 ^= self.0 >> 7;
            self.0 ^= self.0 << 17;
            self.0
        }
        fn below(&mut self, n: u64) -> u64 {
            self.next() % n
        }
    }

    #[test]
    fn eight_digits_reads_digits_and_refuses_everything_else() {
        let mut rng = Rng(0x8888_1234_5678_9abc);
        for _ in 0..200_000 {
            let mut b = [0u8; 8];
            for x in &mut b {
                *x = if rng.below(4) == 0 { rng.next() as u8 } else { b'0' + rng.below(10) as u8 };
            }
            let want = std::str::from_utf8(&b)
                .ok()
                .filter(|s| s.bytes().all(|c| c.is_ascii_digit()))
                .map(|s| s.parse::<u32>().unwrap());
            assert_eq!(super::eight_digits(u64::from_le_bytes(b)), want, "{b:?}");
        }
        for s in [b"00000000", b"99999999", b"12345678", b"0000000/", b":0000000", b"1234567\xff"] {
            let want = std::str::from_utf8(s).ok().and_then(|s| s.parse::<u32>().ok());
            assert_eq!(super::eight_digits(u64::from_le_bytes(*s)), want);
        }
    }

    #[test]
    fn hand_picked_spellings() {
        let taken = [
            "0",
            "-0",
            "+0",
            "0.0",
            "-0.0",
            "00000",
            "0e999999999999",
            "-0e-5",
            ".5",
            "5.",
            "-.5",
            "+5.",
            "1e5",
            "1E5",
            "1e+5",
            "1e-5",
            "1.5e22",
            "9007199254740992",
            "9007199254740993",
            "9007199254740993e-5",
            "18446744073709551615e-21",
            "9999999999999999999",
            "1e19",
            "9999999999999999999e19",
            "0.1",
            "0.30000000000000004",
            "0.8506507873535156",
            "-0.525731086730957",
            "123456789.123456789",
            "000000000000000000000000001.5",
            "0.000000000000000000000000000123",
            "2.2250738585072014e-5",
            "4.9406564584124654e-5",
            "1.7976931348623157",
            "17976931348623157e292",
        ];
        for s in taken {
            let _ = agrees(s);
        }
        for s in ["0.1", "1e5", "-2.5", ".5", "5.", "0.8506507873535156", "9999999999999999999e19"] {
            assert!(agrees(s), "{s} should take the fast path");
        }
        let declined = [
            "",
            "+",
            "-",
            ".",
            "e5",
            "1e",
            "1e+",
            "1e-",
            "--1",
            "+-1",
            "1.2.3",
            "1e5.0",
            "0x10",
            "1_0",
            "inf",
            "-inf",
            "infinity",
            "NaN",
            "nan",
            "1,5",
            " 1",
            "1 ",
            "1e5e5",
            "١",
            "12345678901234567890",
            "1e400",
            "1e-400",
            "2.4e-320",
            "1.e",
            "1..",
            "+.",
            "-.e1",
        ];
        for s in declined {
            assert!(!agrees(s), "{s} should go to str::parse");
        }
    }

    #[test]
    fn halfway_cases_round_to_even() {
        // 2^53 + 1 and 2^53 + 3 are exactly halfway between f64s; shifted by powers of ten.
        for base in [9007199254740993u64, 9007199254740995, 18014398509481987, 18014398509481985] {
            for k in 0..=21 {
                let digits = base.to_string();
                let (int, frac) = digits.split_at(digits.len().saturating_sub(k));
                let s = if k >= digits.len() {
                    format!("0.{}{}", "0".repeat(k - digits.len()), digits)
                } else {
                    format!("{int}.{frac}")
                };
                let _ = agrees(&s);
                let _ = agrees(&format!("{digits}e-{k}"));
                let _ = agrees(&format!("{digits}e{k}"));
            }
        }
        // Exact decimal spellings of points halfway between neighbouring f64s, and their
        // neighbours one unit in the last digit away: m odd with 54 bits, m / 2^j = m·5^j / 10^j.
        let mut rng = Rng(0x5eed_1234_abcd_ef01);
        let mut taken = 0usize;
        for _ in 0..200_000 {
            let m = (rng.next() >> 10) | (1 << 53) | 1;
            let j = rng.below(4) as u32;
            let w = m * 5u64.pow(j);
            for t in 0..3u32 {
                let Some(wt) = w.checked_mul(10u64.pow(t)) else { continue };
                for x in [wt - 1, wt, wt + 1] {
                    let digits = x.to_string();
                    let k = (j + t) as usize;
                    let (int, frac) = digits.split_at(digits.len() - k);
                    taken += agrees(&format!("{int}.{frac}")) as usize;
                    taken += agrees(&format!("{digits}e-{k}")) as usize;
                    // Halfway integers above 2^54 (m·2^j), with positive exponents.
                    let _ = agrees(&format!("{}e{t}", m << j));
                }
            }
        }
        assert!(taken > 1_000_000, "{taken}");
    }

    #[test]
    fn random_literals_agree_with_str_parse() {
        let mut rng = Rng(0x0123_4567_89ab_cdef);
        let mut taken = 0usize;
        let total = 2_000_000;
        for _ in 0..total {
            let mut s = String::new();
            match rng.below(4) {
                0 => s.push('-'),
                1 if rng.below(4) == 0 => s.push('+'),
                _ => {}
            }
            for _ in 0..rng.below(4) {
                s.push('0');
            }
            for _ in 0..rng.below(22) {
                s.push((b'0' + rng.below(10) as u8) as char);
            }
            if rng.below(3) != 0 {
                s.push('.');
                for _ in 0..rng.below(4) {
                    s.push('0');
                }
                for _ in 0..rng.below(22) {
                    s.push((b'0' + rng.below(10) as u8) as char);
                }
            }
            if rng.below(3) == 0 {
                s.push(if rng.below(2) == 0 { 'e' } else { 'E' });
                match rng.below(3) {
                    0 => s.push('-'),
                    1 => s.push('+'),
                    _ => {}
                }
                let big = rng.below(8) == 0;
                let e = if big { rng.below(400) } else { rng.below(30) };
                if rng.below(20) != 0 {
                    s.push_str(&e.to_string());
                }
            }
            if rng.below(50) == 0 {
                // A stray byte somewhere.
                let at = rng.below(s.len() as u64 + 1) as usize;
                let junk = [b'x', b'.', b'e', b'-', b'+', b' ', b'#'][rng.below(7) as usize] as char;
                s.insert(at, junk);
            }
            taken += agrees(&s) as usize;
        }
        assert!(taken > total / 3, "the fast path answered only {taken} of {total}");
    }

    #[test]
    fn shortest_spellings_of_random_doubles_round_trip() {
        let mut rng = Rng(0xfeed_face_cafe_beef);
        let mut taken = 0usize;
        let total = 1_000_000;
        for i in 0..total {
            let x = match i % 3 {
                // Any finite double.
                0 => f64::from_bits(rng.next() & !(0x7ffu64 << 52) | (rng.below(2046) << 52)),
                // Coordinates of everyday size, and f32 values printed as f64 (as OBJ writers do).
                1 => (rng.next() as i64 as f64) / 2f64.powi(rng.below(80) as i32),
                _ => ((rng.next() as i64 as f64) / 2f64.powi(62) * 50.0) as f32 as f64,
            };
            let s = x.to_string();
            taken += agrees(&s) as usize;
            let _ = agrees(&format!("{x:e}"));
        }
        assert!(taken > total / 2, "the fast path answered only {taken} of {total}");
    }
}
