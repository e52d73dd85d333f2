//! Scanning of decimal numbers in delimited text, bit-identical to `str::parse::<f64>`.
//!
//! [`scan_number`] reads one number (`[+-]digits[.digits][(e|E)[+-]digits]`, at least one digit
//! before the exponent; with `decimal_comma` a `,` may stand for the point) and returns where it
//! ends. The conversion is the `fast-float2` crate's (Eisel-Lemire with the big-number fallback,
//! correctly rounded as `str::parse::<f64>` is, the same syntax); this module only restricts
//! what it is given to plain decimal numbers and maps a decimal comma to the point. Words such as
//! `inf` or `NaN`, quotes and other text are [`Scan::Invalid`] here; the caller then uses the
//! general cell parser, which accepts everything Rust's `f64` parser does.

/// Longest number (in bytes) of a decimal-comma file converted on the stack; a longer one goes
/// to [`parse_slow`] ([`Scan::Slow`]).
const COMMA_NUMBER_BYTES_MAX: usize = 64;

/// Outcome of [`scan_number`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) enum Scan {
    /// A number, converted (infinite only where the text overflows, as `str::parse` gives it).
    Fast(f64),
    /// A syntactically valid number that needs `str::parse::<f64>` (a decimal-comma number
    /// longer than [`COMMA_NUMBER_BYTES_MAX`] bytes).
    Slow,
    /// Not a plain decimal number at this position.
    Invalid,
}

/// Whether `b` may continue a number once it has begun (digits, the point, an exponent and its
/// sign; the comma where it is the decimal mark).
#[inline(always)]
fn number_byte(b: u8, decimal_comma: bool) -> bool {
    matches!(b, b'0'..=b'9' | b'.' | b'e' | b'E' | b'+' | b'-') || (decimal_comma && b == b',')
}

/// Scans a decimal number starting at `s[i]`; returns the outcome and the index just after the
/// number (the caller checks what follows). With `decimal_comma`, `,` is accepted as the decimal
/// point as well as `.`.
#[inline(always)]
pub(crate) fn scan_number(s: &[u8], i: usize, decimal_comma: bool) -> (Scan, usize) {
    let rest = s.get(i..).unwrap_or_default();
    // A plain number starts with a digit or a point, after at most one sign: words (`inf`,
    // `NaN`, `-infinity`) are left to the general cell parser.
    let body = match rest.first() {
        Some(b'+' | b'-') => 1,
        _ => 0,
    };
    let point = |b: u8| b == b'.' || (decimal_comma && b == b',');
    match rest.get(body) {
        Some(b) if b.is_ascii_digit() || point(*b) => {}
        _ => return (Scan::Invalid, i),
    }
    let parsed = if decimal_comma {
        // The number's extent, its commas turned into points on the stack (the same length, so
        // the parsed length indexes `s` too).
        let len = rest
            .iter()
            .position(|&b| !number_byte(b, true))
            .unwrap_or(rest.len());
        if len > COMMA_NUMBER_BYTES_MAX {
            return (Scan::Slow, i + len);
        }
        let mut buf = [0u8; COMMA_NUMBER_BYTES_MAX];
        for (d, &b) in buf.iter_mut().zip(&rest[..len]) {
            *d = if b == b',' { b'.' } else { b };
        }
        fast_float2::parse_partial::<f64, _>(&buf[..len])
    } else {
        fast_float2::parse_partial::<f64, _>(rest)
    };
    match parsed {
        Ok((v, n)) => (Scan::Fast(v), i + n),
        Err(_) => (Scan::Invalid, i),
    }
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
        // (text, value by hand): every plain decimal number is converted here, none handed on.
        let cases: [(&str, f64); 19] = [
            ("0.1", 0.1),
            ("-0", -0.0),
            ("-0.000", -0.0),
            ("+0", 0.0),
            ("1e-7", 1e-7),
            (".5", 0.5),
            ("5.", 5.0),
            ("+3", 3.0),
            ("-.25", -0.25),
            ("007.50", 7.5),
            ("1E+06", 1e6),
            ("-0.012345", -0.012345),
            ("0.000000000000000000000000001", 1e-27),
            ("0.000000000000000001", 1e-18),
            ("123456789012345.0", 123456789012345.0),
            ("9007199254740992", 9007199254740992.0),
            ("9007199254740993", 9007199254740992.0),
            ("123456789012345678", 123456789012345678.0),
            ("1e300", 1e300),
        ];
        for (t, v) in cases {
            let (got, was_fast) = parse_cell(t.as_bytes(), false);
            assert_eq!(got.map(f64::to_bits), Some(v.to_bits()), "{t}");
            assert!(was_fast, "{t}: handed on");
            check(t);
        }
        // A decimal-comma number longer than the stack buffer is handed to str::parse, with the
        // same value.
        let long = format!("1,{}", "0".repeat(COMMA_NUMBER_BYTES_MAX));
        assert_eq!(parse_cell(long.as_bytes(), true), (Some(1.0), false));
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

    /// Mantissas above 2^53 with up to 19 digits divided by 10^1 ..= 10^22 (not exact in
    /// `f64`: the conversion must round) agree with `str::parse` bit for bit.
    #[test]
    fn long_mantissas_over_powers_of_ten_match_str_parse() {
        let mut rng = ChaCha8Rng::seed_from_u64(20261126);
        for _ in 0..200_000 {
            let digits = rng.gen_range(16..=19);
            let mut m: u64 = rng.gen_range(1..10);
            for _ in 1..digits {
                m = m * 10 + rng.gen_range(0..10);
            }
            if m <= 1 << 53 {
                continue;
            }
            let k = rng.gen_range(1..=22usize);
            let d = m.to_string();
            let t = if k >= d.len() {
                format!("0.{}{d}", "0".repeat(k - d.len()))
            } else {
                format!("{}.{}", &d[..d.len() - k], &d[d.len() - k..])
            };
            let t = if rng.gen_bool(0.5) {
                format!("-{t}")
            } else {
                t
            };
            assert!(check(&t), "{t}: handed on");
        }
        // Shortest round-trip output of doubles of sensor size (16-17 digits).
        for _ in 0..100_000 {
            let v: f64 = rng.gen_range(-20.0..20.0);
            assert!(check(&v.to_string()), "{v}");
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
