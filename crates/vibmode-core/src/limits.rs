//! The physical and resource bounds every input is checked against before work starts, defined
//! once. Each bound is far beyond what a measurement needs and well inside what f64 arithmetic
//! and the machine's memory can carry; `docs/formats.md` lists them.

use std::fmt;

/// Lowest sampling rate accepted, Hz (one sample every 1000 s).
pub const FS_HZ_MIN: f64 = 1e-3;
/// Highest sampling rate accepted, Hz (10 MHz).
pub const FS_HZ_MAX: f64 = 1e7;
/// Largest sample magnitude accepted. The fourth powers summed over 10^9 samples (kurtosis)
/// stay finite: (1e60)^4 x 1e9 = 1e249 < 1.8e308.
pub const SAMPLE_ABS_MAX: f64 = 1e60;
/// Smallest peak magnitude of a channel that is not all zeros. Fourth powers stay normal
/// numbers: (1e-60)^4 = 1e-240 > 2.2e-308.
pub const SAMPLE_PEAK_MIN: f64 = 1e-60;
/// Most channels in one recording.
pub const CHANNELS_MAX: usize = 1024;
/// Largest upsampling ratio (output rate / input rate). vibmode's resampling is for
/// decimation; a larger ratio is almost always a rate in the wrong unit.
pub const UPSAMPLE_RATIO_MAX: f64 = 16.0;
/// Most samples (all channels together) a resampling may produce: 2^30, 8 GiB as f64.
pub const SAMPLES_OUT_MAX: u64 = 1 << 30;
/// Largest configuration or vehicle file read, bytes (1 MiB).
pub const CONFIG_BYTES_MAX: u64 = 1 << 20;

/// Most rows of the SSI-cov block Toeplitz matrix, `block_rows x channels`: its SVD, the bulk
/// of an identification, takes about a second at this size (7 s at twice it).
pub const SSI_TOEPLITZ_ROWS_MAX: usize = 1024;
/// Highest model order (state dimension) SSI-cov identifies: at most the Toeplitz matrix's rows.
pub const SSI_ORDER_MAX: usize = SSI_TOEPLITZ_ROWS_MAX;
/// Largest first correlation lag of SSI-cov, samples (2^30: 12 days at 1 kHz, beyond any record
/// held in memory).
pub const SSI_FIRST_LAG_MAX: usize = 1 << 30;
/// Samples an SSI-cov record (or segment) needs per lag of its Toeplitz matrix beyond the lags
/// skipped: at least `first_lag - 1 + 2 (2 block_rows - 1)`, so that even the largest lag's
/// correlation averages as many products as the matrix has lags.
pub const SSI_SAMPLES_PER_LAG_MIN: usize = 2;
/// Most SVD work of one SSI-cov identification with uncertainty blocks,
/// `(2 blocks + 1) x rows^2 x columns` of the Toeplitz matrix: eight SVDs at the largest
/// matrix, thousands at the usual ones.
pub const SSI_SVD_WORK_MAX: u64 = 8 << 30;

/// A number for messages: plain below 1e9 and above 1e-4 in magnitude, otherwise in exponent
/// form, never 300 digits.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Num(pub f64);

impl fmt::Display for Num {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let v = self.0;
        let a = v.abs();
        let plain = !v.is_finite() || v == 0.0 || (1e-4..1e9).contains(&a);
        let exact = if plain {
            format!("{v}")
        } else {
            format!("{v:e}")
        };
        if exact.len() <= 12 {
            return f.write_str(&exact);
        }
        // Six significant digits, trailing zeros dropped.
        if plain {
            let decimals = (5 - a.log10().floor() as i32).max(0) as usize;
            let s = format!("{v:.decimals$}");
            let s = if s.contains('.') {
                s.trim_end_matches('0').trim_end_matches('.')
            } else {
                &s
            };
            f.write_str(s)
        } else {
            let s = format!("{v:.5e}");
            let (m, e) = s.split_once('e').unwrap_or((&s, "0"));
            let m = m.trim_end_matches('0').trim_end_matches('.');
            write!(f, "{m}e{e}")
        }
    }
}

/// `Num(*v)`, for `#[error(...)]` attributes that see fields by reference.
pub fn num(v: &f64) -> Num {
    Num(*v)
}

/// Most characters of user input quoted in a message ([`Quoted`]).
pub const QUOTE_CHARS_MAX: usize = 60;
/// Most bytes of the one-line error the command line prints (the whole line).
pub const MESSAGE_BYTES_MAX: usize = 400;

/// User input (a cell, a name, an id, a path) for messages: at most [`QUOTE_CHARS_MAX`]
/// characters (a longer one: its first and last halves, so a path keeps its file name), every
/// control character, escape sequence or replacement character shown as `?`, and `...` where it
/// was cut. A 2 MB cell or a terminal escape sequence never reaches the
/// terminal through an error.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Quoted<'a>(pub &'a str);

impl fmt::Display for Quoted<'_> {
    /// Longer than [`QUOTE_CHARS_MAX`]: its first and last characters (half each) around
    /// `...`, so a long path keeps its file name.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let shown = printable;
        let n = self.0.chars().count();
        if n <= QUOTE_CHARS_MAX {
            return self.0.chars().try_for_each(|c| write!(f, "{}", shown(c)));
        }
        let head = QUOTE_CHARS_MAX / 2;
        let tail = QUOTE_CHARS_MAX - head;
        self.0
            .chars()
            .take(head)
            .try_for_each(|c| write!(f, "{}", shown(c)))?;
        f.write_str("...")?;
        self.0
            .chars()
            .skip(n - tail)
            .try_for_each(|c| write!(f, "{}", shown(c)))
    }
}

/// A character of user input as messages show it: a control character (escape sequences
/// included) or the replacement character as `?`, any other as it is ([`Quoted`]).
pub fn printable(c: char) -> char {
    if c.is_control() || c == char::REPLACEMENT_CHARACTER {
        '?'
    } else {
        c
    }
}

/// `Quoted(s)`, for `#[error(...)]` attributes that see fields by reference.
pub fn quoted(s: &str) -> Quoted<'_> {
    Quoted(s)
}

/// A message cut to at most `max_bytes` bytes on a character boundary, `...` marking the cut.
pub fn cap_message(msg: &str, max_bytes: usize) -> String {
    if msg.len() <= max_bytes {
        return msg.to_string();
    }
    let mut end = max_bytes.saturating_sub(3);
    while end > 0 && !msg.is_char_boundary(end) {
        end -= 1;
    }
    format!("{}...", &msg[..end])
}

/// A settings file's deserialisation message in words a user acts on. The TOML reader reports a
/// number, boolean or table given where a name (an enum of settings such as `model = "arma"`)
/// belongs as "invalid type: unit variant, expected string only"; that phrase is replaced by
/// what the key takes. Other messages are returned as they are.
pub fn settings_message(msg: &str) -> String {
    msg.replace(
        "invalid type: unit variant, expected string only",
        "expected a name in quotes (key = \"name\")",
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn settings_messages_say_what_a_key_takes() {
        assert_eq!(
            settings_message("invalid type: unit variant, expected string only in `sweep.model`"),
            "expected a name in quotes (key = \"name\") in `sweep.model`"
        );
        assert_eq!(settings_message("unknown field `x`"), "unknown field `x`");
    }

    #[test]
    fn num_is_short() {
        assert_eq!(Num(1.5).to_string(), "1.5");
        assert_eq!(Num(200.0).to_string(), "200");
        assert_eq!(Num(1e300).to_string(), "1e300");
        assert_eq!(Num(-1.25e-200).to_string(), "-1.25e-200");
        assert_eq!(Num(0.0).to_string(), "0");
        assert_eq!(Num(f64::NAN).to_string(), "NaN");
        assert_eq!(Num(1.2881847531554629e154).to_string(), "1.28818e154");
        assert_eq!(Num(14999.999999999998).to_string(), "15000");
        assert_eq!(Num(0.0033333333333333335).to_string(), "0.00333333");
        assert_eq!(Num(3.2837746232756027e-200).to_string(), "3.28377e-200");
        assert_eq!(Num(-1.0000001).to_string(), "-1.0000001");
    }

    #[test]
    fn quoted_is_short_and_printable() {
        assert_eq!(Quoted("bus-017").to_string(), "bus-017");
        assert_eq!(Quoted("a\u{1b}[31mb\n").to_string(), "a?[31mb?");
        let long = "x".repeat(10_000);
        assert_eq!(
            Quoted(&long).to_string(),
            format!("{}...{}", "x".repeat(30), "x".repeat(30))
        );
        // A long path keeps its file name: 30 characters, `...`, the last 30.
        let path = format!("/tmp/{}/record_01.wav", "d".repeat(80));
        assert_eq!(
            Quoted(&path).to_string(),
            format!("/tmp/{}...{}/record_01.wav", "d".repeat(25), "d".repeat(16))
        );
        assert_eq!(Quoted("\u{fffd}\u{fffd}").to_string(), "??");
    }

    #[test]
    fn cap_message_keeps_char_boundaries() {
        assert_eq!(cap_message("short", 400), "short");
        let m = "é".repeat(300); // 600 bytes
        let c = cap_message(&m, 400);
        assert!(c.len() <= 400 && c.ends_with("..."));
    }
}
