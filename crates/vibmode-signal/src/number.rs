//! Fast scanning of decimal numbers in delimited text, bit-identical to `str::parse::<f64>`.
//!
//! [`scan_number`] reads one number (`[+-]digits[.digits][(e|E)[+-]digits]`, at least one digit
//! before the exponent; with `decimal_comma` a `,` may stand for the point) and returns where it
//! ends. Most sensor values (`-0.012345`, `1.5e-3`) have a decimal mantissa `m < 2^53` and a
//! power of ten `10^k` with `|k| <= 22`: both are exact `f64`s, so one IEEE multiplication or
//! division gives the correctly rounded value (Clinger's fast path), which is what
//! `str::parse::<f64>` returns too. Digits are read eight at a time (SWAR). A mantissa above
//! 2^53 of at most 19 digits over `10^k`, `1 <= k <= 22` (shortest round-trip output such as
//! `0.44836338772330214` has 16-17 digits), is the floating-point quotient moved to the correctly
//! rounded neighbour by exact 128-bit comparisons with the midpoints beside it. More than 19
//! digits (leading zeros included), other large mantissas and larger exponents are handed to
//! `str::parse::<f64>` (Eisel-Lemire and big-number fallback). Words such as `inf` or `NaN`,
//! quotes and other text are [`Scan::Invalid`] here; the caller then uses the general cell
//! parser, which accepts everything Rust's `f64` parser does.

/// Exact powers of ten `10^0 ..= 10^22` (all exactly representable in `f64`).
const POW10: [f64; 23] = [
    1e0, 1e1, 1e2, 1e3, 1e4, 1e5, 1e6, 1e7, 1e8, 1e9, 1e10, 1e11, 1e12, 1e13, 1e14, 1e15, 1e16,
    1e17, 1e18, 1e19, 1e20, 1e21, 1e22,
];

/// Largest mantissa that converts to `f64` exactly on every path (2^53).
const MAX_EXACT_MANTISSA: u64 = 1 << 53;

/// Outcome of [`scan_number`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) enum Scan {
    /// A number, converted exactly by the fast path (always finite).
    Fast(f64),
    /// A syntactically valid number that needs `str::parse::<f64>` (more than 19 digits, a
    /// mantissa above 2^53 not over a power of ten 10^-1 ..= 10^-22, or a power of ten outside
    /// 10^-22 ..= 10^22).
    Slow,
    /// Not a plain decimal number at this position.
    Invalid,
}

/// `10^k` for `k = 0..=8`.
const POW10_U64: [u64; 9] = [
    1,
    10,
    100,
    1_000,
    10_000,
    100_000,
    1_000_000,
    10_000_000,
    100_000_000,
];

/// The value of 8 decimal digits given as bytes `0..=9` in a little-endian word (first digit in
/// the lowest byte), by three multiplications (the SWAR method of fast_float / simdjson).
#[inline(always)]
fn eight_digits(t: u64) -> u64 {
    const MASK: u64 = 0x0000_00FF_0000_00FF;
    const MUL1: u64 = 100 + (1_000_000 << 32);
    const MUL2: u64 = 1 + (10_000 << 32);
    let v = t.wrapping_mul(10).wrapping_add(t >> 8);
    (v & MASK)
        .wrapping_mul(MUL1)
        .wrapping_add(((v >> 16) & MASK).wrapping_mul(MUL2))
        >> 32
}

/// `5^k` for `k = 0..=22` (all below 2^52).
const POW5: [u64; 23] = {
    let mut t = [1u64; 23];
    let mut k = 1;
    while k < 23 {
        t[k] = t[k - 1] * 5;
        k += 1;
    }
    t
};

/// How `m` compares with `c 5^k 2^s` (exact, in 128-bit integers; `c < 2^55`, `5^k < 2^52`).
#[inline(always)]
fn cmp_scaled(m: u64, c: u64, p5: u64, s: i32) -> std::cmp::Ordering {
    let rhs = c as u128 * p5 as u128; // < 2^107
    if s >= 0 {
        if s as u32 > rhs.leading_zeros() {
            return std::cmp::Ordering::Less; // rhs 2^s >= 2^128 > m
        }
        (m as u128).cmp(&(rhs << s))
    } else {
        let t = (-s) as u32;
        if t > (m as u128).leading_zeros() {
            return std::cmp::Ordering::Greater; // m 2^t >= 2^128 > rhs
        }
        ((m as u128) << t).cmp(&rhs)
    }
}

/// `m / 10^k` correctly rounded (to nearest, ties to even) for `m < 2^64` and `1 <= k <= 22`:
/// the floating-point quotient (within two units in the last place of it) moved to the right
/// neighbour by comparing the exact value `m / (5^k 2^k)` with the midpoints beside it. `None`
/// if that takes more than a few steps (never expected; the caller then uses `str::parse`).
#[inline]
fn quotient_pow10(m: u64, k: usize) -> Option<f64> {
    use std::cmp::Ordering::{Equal, Greater, Less};
    const HIDDEN: u64 = 1 << 52;
    let q = m as f64 / POW10[k];
    // A normal double: m / 10^k lies between 2^53 / 10^22 and 2^64 / 10.
    let bits = q.to_bits();
    let mut mant = (bits & (HIDDEN - 1)) | HIDDEN;
    let mut e = ((bits >> 52) & 0x7ff) as i32 - 1075; // q = mant 2^e
    let p5 = POW5[k];
    let k = k as i32;
    for _ in 0..4 {
        // Upper midpoint (2 mant + 1) 2^(e-1); lower one (2 mant - 1) 2^(e-1), or
        // (4 mant - 1) 2^(e-2) at the bottom of the binade. v = m / (5^k 2^k).
        let upper = cmp_scaled(m, 2 * mant + 1, p5, e - 1 + k);
        let lower = if mant == HIDDEN {
            cmp_scaled(m, 4 * mant - 1, p5, e - 2 + k)
        } else {
            cmp_scaled(m, 2 * mant - 1, p5, e - 1 + k)
        };
        match (upper, lower) {
            (Greater, _) => {
                mant += 1;
                if mant == 2 * HIDDEN {
                    mant = HIDDEN;
                    e += 1;
                }
            }
            (Less, Less) => {
                mant -= 1;
                if mant < HIDDEN {
                    mant = 2 * HIDDEN - 1;
                    e -= 1;
                }
            }
            (Equal, _) => {
                if mant & 1 == 1 {
                    mant += 1;
                    if mant == 2 * HIDDEN {
                        mant = HIDDEN;
                        e += 1;
                    }
                }
                return Some(f64::from_bits(((e + 1075) as u64) << 52 | (mant - HIDDEN)));
            }
            (Less, Equal) => {
                if mant & 1 == 1 {
                    mant -= 1;
                    if mant < HIDDEN {
                        mant = 2 * HIDDEN - 1;
                        e -= 1;
                    }
                }
                return Some(f64::from_bits(((e + 1075) as u64) << 52 | (mant - HIDDEN)));
            }
            (Less, Greater) => {
                return Some(f64::from_bits(((e + 1075) as u64) << 52 | (mant - HIDDEN)));
            }
        }
    }
    None
}

/// Reads the run of ASCII digits at `s[i..]` into `m` (`m = m * 10^count + digits`, wrapping:
/// only meaningful while the total count stays <= 19) and adds their number to `n`; returns the
/// index after the run. Eight bytes at a time where the slice is long enough.
#[inline(always)]
fn eat_digits(s: &[u8], mut i: usize, m: &mut u64, n: &mut u32) -> usize {
    while let Some(word) = s.get(i..i + 8).and_then(|w| <[u8; 8]>::try_from(w).ok()) {
        let t = u64::from_le_bytes(word) ^ 0x3030_3030_3030_3030;
        // A byte is a digit iff its high nibble was 3 (now 0) and its low nibble is <= 9.
        let not_digit = (t & 0xF0F0_F0F0_F0F0_F0F0)
            | ((t & 0x0F0F_0F0F_0F0F_0F0F).wrapping_add(0x0606_0606_0606_0606)
                & 0xF0F0_F0F0_F0F0_F0F0);
        let k = (not_digit.trailing_zeros() / 8) as usize;
        if k == 0 {
            return i;
        }
        // Keep the k digits, as the last k of 8 (leading zeros in front).
        let digits = t << (8 * (8 - k) as u32);
        *m = m
            .wrapping_mul(POW10_U64[k])
            .wrapping_add(eight_digits(digits));
        *n += k as u32;
        i += k;
        if k < 8 {
            return i;
        }
    }
    while let Some(&b) = s.get(i) {
        let d = b.wrapping_sub(b'0');
        if d > 9 {
            break;
        }
        *m = m.wrapping_mul(10).wrapping_add(d as u64);
        *n += 1;
        i += 1;
    }
    i
}

/// Scans a decimal number starting at `s[i]`; returns the outcome and the index just after the
/// number (the caller checks what follows). With `decimal_comma`, `,` is accepted as the decimal
/// point as well as `.`.
#[inline(always)]
pub(crate) fn scan_number(s: &[u8], mut i: usize, decimal_comma: bool) -> (Scan, usize) {
    // Signs are random in sensor data: no branches on them (mispredictions cost more than the
    // rest of the number).
    let first = s.get(i).copied().unwrap_or(0);
    let neg = first == b'-';
    i += (neg | (first == b'+')) as usize;
    let sign_bit = (neg as u64) << 63;
    // Mantissa: all digits (leading zeros included) while there are at most 19 of them.
    let mut m: u64 = 0;
    let mut n_digits = 0u32;
    i = eat_digits(s, i, &mut m, &mut n_digits);
    let mut exp10: i64 = 0;
    if let Some(&b) = s.get(i) {
        if b == b'.' || (decimal_comma && b == b',') {
            let n_int = n_digits;
            i = eat_digits(s, i + 1, &mut m, &mut n_digits);
            exp10 = -((n_digits - n_int) as i64);
        }
    }
    if n_digits == 0 {
        return (Scan::Invalid, i);
    }
    if let Some(b'e' | b'E') = s.get(i) {
        i += 1;
        let mut eneg = false;
        match s.get(i) {
            Some(b'-') => {
                eneg = true;
                i += 1;
            }
            Some(b'+') => i += 1,
            _ => {}
        }
        let mut e: i64 = 0;
        let mut e_digits = 0u32;
        while let Some(&b) = s.get(i) {
            let d = b.wrapping_sub(b'0');
            if d > 9 {
                break;
            }
            if e < 1_000_000 {
                e = e * 10 + d as i64;
            }
            e_digits += 1;
            i += 1;
        }
        if e_digits == 0 {
            return (Scan::Invalid, i);
        }
        exp10 += if eneg { -e } else { e };
    }
    if n_digits > 19 {
        return (Scan::Slow, i);
    }
    if m == 0 {
        return (Scan::Fast(f64::from_bits(sign_bit)), i);
    }
    if m > MAX_EXACT_MANTISSA {
        // Up to 19 digits (the simulator's and most loggers' shortest round-trip output has
        // 16-17) and a decimal fraction: the quotient by a power of ten, checked exactly.
        if (-22..=-1).contains(&exp10) {
            if let Some(v) = quotient_pow10(m, (-exp10) as usize) {
                return (Scan::Fast(f64::from_bits(v.to_bits() | sign_bit)), i);
            }
        }
        return (Scan::Slow, i);
    }
    if !(-22..=22).contains(&exp10) {
        return (Scan::Slow, i);
    }
    // Both m and 10^|exp10| are exact doubles: one correctly rounded operation. (m <= 2^53, so
    // the conversion through i64 is exact and a single instruction.)
    let mf = m as i64 as f64;
    let v = if exp10 >= 0 {
        mf * POW10[exp10 as usize]
    } else {
        mf / POW10[(-exp10) as usize]
    };
    (Scan::Fast(f64::from_bits(v.to_bits() | sign_bit)), i)
}

/// `str::parse::<f64>` of an ASCII cell already accepted by [`scan_number`] (with a decimal
/// comma turned into a point); `None` if the standard parser refuses it.
pub(crate) fn parse_slow(cell: &[u8], decimal_comma: bool, scratch: &mut Vec<u8>) -> Option<f64> {
    let bytes: &[u8] = if decimal_comma && cell.contains(&b',') {
        scratch.clear();
        scratch.extend(cell.iter().map(|&b| if b == b',' { b'.' } else { b }));
        scratch
    } else {
        cell
    };
    std::str::from_utf8(bytes).ok()?.parse::<f64>().ok()
}

/// The value of a whole cell by [`scan_number`] (+ [`parse_slow`]) and whether the fast path
/// gave it; `None` if the cell is not entirely one plain decimal number. The cell is scanned
/// alone and followed by other text (so that both the 8-byte and the byte-wise digit loops
/// run); the two must agree. Used by tests to compare with `str::parse::<f64>`.
#[cfg(test)]
pub(crate) fn parse_cell(cell: &[u8], decimal_comma: bool) -> (Option<f64>, bool) {
    let scan_alone = |s: &[u8]| -> (Option<f64>, bool, usize) {
        let (scan, end) = scan_number(s, 0, decimal_comma);
        let v = match scan {
            Scan::Fast(v) => (Some(v), true),
            Scan::Slow => (parse_slow(&s[..end], decimal_comma, &mut Vec::new()), false),
            Scan::Invalid => (None, false),
        };
        (v.0, v.1, end)
    };
    let (v, fast, end) = scan_alone(cell);
    for tail in [&b";12345678901234567890"[..], b"\n", b" 9", b"x"] {
        let mut long = cell.to_vec();
        long.extend_from_slice(tail);
        let (v2, fast2, end2) = scan_alone(&long);
        if end == cell.len() || end2 < cell.len() {
            assert_eq!(
                (v.map(f64::to_bits), fast, end),
                (v2.map(f64::to_bits), fast2, end2),
                "{:?} followed by {:?}",
                String::from_utf8_lossy(cell),
                String::from_utf8_lossy(tail)
            );
        }
    }
    if end != cell.len() {
        return (None, false);
    }
    (v, fast)
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    /// Compares with `str::parse::<f64>` bit for bit (NaN never occurs here); returns whether
    /// the fast path was taken.
    fn check(text: &str) -> bool {
        let reference = text.parse::<f64>().ok();
        let (got, fast) = parse_cell(text.as_bytes(), false);
        assert_eq!(
            got.map(f64::to_bits),
            reference.map(f64::to_bits),
            "{text:?}: scanner {got:?}, str::parse {reference:?}"
        );
        // The same text with a decimal comma, read with decimal_comma = true.
        let comma = text.replace('.', ",");
        let (got_c, _) = parse_cell(comma.as_bytes(), true);
        assert_eq!(
            got_c.map(f64::to_bits),
            reference.map(f64::to_bits),
            "{comma:?} (decimal comma)"
        );
        fast
    }

    #[test]
    fn hand_cases() {
        // (text, value by hand, fast path expected)
        let cases: [(&str, f64, bool); 19] = [
            ("0.1", 0.1, true),
            ("-0", -0.0, true),
            ("-0.000", -0.0, true),
            ("+0", 0.0, true),
            ("1e-7", 1e-7, true),
            (".5", 0.5, true),
            ("5.", 5.0, true),
            ("+3", 3.0, true),
            ("-.25", -0.25, true),
            ("007.50", 7.5, true),
            ("1E+06", 1e6, true),
            ("-0.012345", -0.012345, true),
            ("0.000000000000000000000000001", 1e-27, false),
            ("0.000000000000000001", 1e-18, true),
            ("123456789012345.0", 123456789012345.0, true),
            ("9007199254740992", 9007199254740992.0, true),
            ("9007199254740993", 9007199254740992.0, false),
            ("123456789012345678", 123456789012345678.0, false),
            ("1e300", 1e300, false),
        ];
        for (t, v, fast) in cases {
            let (got, was_fast) = parse_cell(t.as_bytes(), false);
            assert_eq!(got.map(f64::to_bits), Some(v.to_bits()), "{t}");
            assert_eq!(was_fast, fast, "{t}: fast path taken?");
            check(t);
        }
        assert_eq!(parse_cell(b"1,5", true).0, Some(1.5));
        assert_eq!(parse_cell(b"1,5", false).0, None);
        for bad in [
            "", ".", "-", "+", "e5", "1e", "1e+", "1.2.3", "1,2,3", "--1", "1-", "inf", "NaN",
            "0x10", " 1", "1 ", "1_000", "1.5f",
        ] {
            assert_eq!(parse_cell(bad.as_bytes(), true).0, None, "{bad:?}");
            // Everything refused here is refused by str::parse too (or is a word/space that the
            // general cell parser handles).
            if !matches!(bad, "inf" | "NaN") {
                assert!(bad.replace(',', ".").parse::<f64>().is_err(), "{bad:?}");
            }
        }
        // Huge exponents and many digits go to str::parse and still agree with it.
        for t in [
            "1e400",
            "-1e-400",
            "0e999999999999",
            "2.2250738585072011e-308",
            "4.9e-324",
            "1.7976931348623157e308",
            "0.1000000000000000055511151231257827",
            "00000000000000000000000000000001.5",
        ] {
            check(t);
        }
    }

    #[test]
    fn seeded_random_decimals_match_str_parse() {
        let mut rng = ChaCha8Rng::seed_from_u64(20261122);
        let mut n_fast = 0usize;
        let n = 200_000;
        for _ in 0..n {
            let mut t = String::new();
            match rng.gen_range(0..4) {
                0 => t.push('-'),
                1 if rng.gen_bool(0.3) => t.push('+'),
                _ => {}
            }
            let int_digits = rng.gen_range(0..=12);
            let frac_digits = rng.gen_range(0..=14);
            let lead_zeros = if rng.gen_bool(0.2) {
                rng.gen_range(1..5)
            } else {
                0
            };
            for _ in 0..lead_zeros {
                t.push('0');
            }
            for _ in 0..int_digits {
                t.push(char::from(b'0' + rng.gen_range(0..10u8)));
            }
            if frac_digits > 0 || rng.gen_bool(0.5) {
                t.push('.');
                for _ in 0..frac_digits {
                    t.push(char::from(b'0' + rng.gen_range(0..10u8)));
                }
            }
            if int_digits + frac_digits + lead_zeros == 0 {
                t.push('0');
            }
            if rng.gen_bool(0.25) {
                t.push(if rng.gen_bool(0.5) { 'e' } else { 'E' });
                match rng.gen_range(0..3) {
                    0 => t.push('-'),
                    1 => t.push('+'),
                    _ => {}
                }
                t.push_str(&rng.gen_range(0..40).to_string());
            }
            if check(&t) {
                n_fast += 1;
            }
        }
        // Numbers as sensors write them: printf-style with 1..=17 significant digits.
        for _ in 0..n {
            let v: f64 = rng.gen_range(-50.0..50.0) * 10f64.powi(rng.gen_range(-8..4));
            let digits = rng.gen_range(0..=17);
            let t = if rng.gen_bool(0.5) {
                format!("{v:.digits$}")
            } else {
                format!("{v:.digits$e}")
            };
            if check(&t) {
                n_fast += 1;
            }
        }
        // Shortest round-trip representation (Rust's Display): up to 17 digits.
        for _ in 0..n {
            let v: f64 = rng.gen_range(-1.0..1.0) * 10f64.powi(rng.gen_range(-30..30));
            check(&v.to_string());
            assert_eq!(parse_cell(v.to_string().as_bytes(), false).0, Some(v));
        }
        // The fast path is really exercised (most numbers above have <= 15 digits).
        assert!(n_fast > n, "fast path taken for only {n_fast} of {}", 2 * n);
    }

    /// Mantissas above 2^53 with up to 19 digits divided by 10^1 ..= 10^22 (the quotient
    /// checked against its midpoints) agree with `str::parse` bit for bit, and take that path.
    #[test]
    fn long_mantissas_over_powers_of_ten_match_str_parse() {
        let mut rng = ChaCha8Rng::seed_from_u64(20261126);
        for _ in 0..200_000 {
            let digits = rng.gen_range(16..=19);
            let mut m: u64 = rng.gen_range(1..10);
            for _ in 1..digits {
                m = m * 10 + rng.gen_range(0..10);
            }
            if m <= MAX_EXACT_MANTISSA {
                continue;
            }
            let k = rng.gen_range(1..=22usize);
            let d = m.to_string();
            let t = if k >= d.len() {
                format!("0.{}{d}", "0".repeat(k - d.len()))
            } else {
                format!("{}.{}", &d[..d.len() - k], &d[d.len() - k..])
            };
            // Leading zeros count towards the 19 digits of the fast paths.
            let n_digits = t.bytes().filter(u8::is_ascii_digit).count();
            let t = if rng.gen_bool(0.5) {
                format!("-{t}")
            } else {
                t
            };
            assert!(check(&t) || n_digits > 19, "{t}: not the fast path");
        }
        // Shortest round-trip output of doubles of sensor size (16-17 digits).
        for _ in 0..100_000 {
            let v: f64 = rng.gen_range(-20.0..20.0);
            // Below 1 the leading zeros may make more than 19 digits (str::parse then).
            assert!(check(&v.to_string()) || v.abs() < 1.0, "{v}");
        }
    }

    /// Exact ties between two doubles round to the even one, also at the bottom and the top of
    /// a binade: `M + 1/2` for M in [2^52, 2^53) (written `M.5`: `m / 10`, `m = 5 (2 M + 1)`);
    /// `M + 0.25` and `M + 0.75` (not ties) agree with `str::parse` too.
    #[test]
    fn exact_ties_round_to_even() {
        let lo = 1u64 << 52;
        for mm in [
            lo,
            lo + 1,
            lo + 2,
            lo + 12345,
            (1u64 << 53) - 2,
            (1u64 << 53) - 1,
        ] {
            let half = format!("{mm}.5");
            let want = if mm % 2 == 0 { mm } else { mm + 1 } as f64;
            let (got, fast) = parse_cell(half.as_bytes(), false);
            assert_eq!(got.map(f64::to_bits), Some(want.to_bits()), "{half}");
            assert!(fast, "{half}");
            check(&half);
            for q in ["25", "75"] {
                assert!(check(&format!("{mm}.{q}")), "{mm}.{q}");
            }
        }
    }
}
