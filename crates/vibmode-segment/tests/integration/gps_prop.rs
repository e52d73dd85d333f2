//! Property tests of the GPS readers (issue 28): arbitrary and mutated GPX, NMEA and CSV text
//! never panics, and every fix returned is finite and in range, in time order.

use proptest::prelude::*;
use vibmode_segment::{parse_track, GpsTrack, TrackFormat, GPS_SPEED_KMH_MAX, GPS_TIME_ABS_MAX_S};
use vibmode_vehicle::drive::{simulate_drive, DriveParams};

fn assert_sane(t: &GpsTrack) -> Result<(), TestCaseError> {
    for f in &t.fixes {
        prop_assert!(
            f.t_s.is_finite() && f.t_s.abs() <= GPS_TIME_ABS_MAX_S,
            "{:?}",
            f
        );
        prop_assert!(f.lat_deg.is_finite() && f.lat_deg.abs() <= 90.0, "{:?}", f);
        prop_assert!(f.lon_deg.is_finite() && f.lon_deg.abs() <= 180.0, "{:?}", f);
        if let Some(v) = f.speed_kmh {
            prop_assert!(
                v.is_finite() && (0.0..=GPS_SPEED_KMH_MAX).contains(&v),
                "{:?}",
                f
            );
        }
        if let Some(c) = f.course_deg {
            prop_assert!(c.is_finite() && (0.0..=360.0).contains(&c), "{:?}", f);
        }
    }
    for w in t.fixes.windows(2) {
        prop_assert!(w[1].t_s > w[0].t_s, "{:?}", w);
    }
    prop_assert!(!t.fixes.is_empty());
    // Fixes kept and dropped never exceed those read (repeated times are merged after).
    prop_assert!(t.fixes.len() + t.dropped.values().sum::<usize>() <= t.n_read);
    Ok(())
}

/// Parses `text` in `format`; no panic, and a track returned passes [`assert_sane`]; an error
/// is one line.
fn check(text: &str, format: TrackFormat) -> Result<(), TestCaseError> {
    match parse_track(text, format, "track") {
        Ok(t) => assert_sane(&t),
        Err(e) => {
            let m = e.to_string();
            prop_assert!(!m.contains('\n'), "{}", m);
            prop_assert!(m.len() < 1000, "{} bytes", m.len());
            prop_assert!(!m.chars().any(char::is_control), "{:?}", m);
            Ok(())
        }
    }
}

const FORMATS: [TrackFormat; 3] = [TrackFormat::Gpx, TrackFormat::Nmea, TrackFormat::Csv];

fn base(format: TrackFormat) -> String {
    let d = simulate_drive(&DriveParams::new(40.0, 9));
    match format {
        TrackFormat::Gpx => d.to_gpx(),
        TrackFormat::Nmea => d.to_nmea() + &d.to_nmea_gga(),
        TrackFormat::Csv => d.to_csv(),
    }
}

/// Values that broke the readers or that lie on a bound.
const TOKENS: &[&str] = &[
    "NaN",
    "nan",
    "inf",
    "-inf",
    "1e300",
    "-1e300",
    "1e20",
    "-5",
    "0",
    "90",
    "90.0001",
    "-90",
    "180",
    "180.5",
    "-181",
    "95",
    "400",
    "9500.000",
    "1000",
    "1000.1",
    "",
    ",",
    ";",
    "<",
    ">",
    "\"",
    "$",
    "*",
    "\n",
    "\r\n",
    "\u{1b}[2J",
    "\u{0}",
    "\u{feff}",
    "é",
    "1e8",
    "1e11",
    "99999999999",
    "2024-05-02T07:31:00Z",
    "9999-12-31T23:59:59Z",
    "0000-01-01T00:00:00Z",
];

fn nmea_resign(line: &str) -> String {
    match (line.find('$'), line.rfind('*')) {
        (Some(a), Some(b)) if b > a => {
            let body = &line[a + 1..b];
            let ck = body.bytes().fold(0u8, |x, y| x ^ y);
            format!("${body}*{ck:02X}")
        }
        _ => line.to_string(),
    }
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 300, ..ProptestConfig::default() })]

    /// Arbitrary text in every format.
    #[test]
    fn arbitrary_text_never_panics(text in ".{0,400}", f in 0usize..3) {
        check(&text, FORMATS[f])?;
    }

    /// A real track with pieces replaced by nasty tokens or arbitrary text.
    #[test]
    fn mutated_tracks_never_panic_and_return_sane_fixes(
        f in 0usize..3,
        edits in prop::collection::vec((0.0f64..1.0, 0usize..12, 0usize..TOKENS.len(), ".{0,8}", any::<bool>()), 1..8),
    ) {
        let mut chars: Vec<char> = base(FORMATS[f]).chars().collect();
        for (pos, len, tok, junk, use_tok) in edits {
            let at = ((pos * chars.len() as f64) as usize).min(chars.len());
            let end = (at + len).min(chars.len());
            let with: Vec<char> = if use_tok { TOKENS[tok].chars().collect() } else { junk.chars().collect() };
            chars.splice(at..end, with);
        }
        let text: String = chars.into_iter().collect();
        check(&text, FORMATS[f])?;
    }

    /// Fields of valid sentences and rows replaced by tokens (checksums recomputed, so that
    /// the values reach the checks rather than the parsers' refusals).
    #[test]
    fn mutated_fields_reach_the_checks(
        f in 1usize..3,
        edits in prop::collection::vec((0usize..41, 0usize..12, 0usize..TOKENS.len()), 1..10),
    ) {
        let format = FORMATS[f];
        let mut lines: Vec<String> = base(format).lines().map(str::to_string).collect();
        let n = lines.len();
        for (row, field, tok) in edits {
            let row = (row * n / 41).min(n - 1);
            let line = lines[row].clone();
            let (body, tail) = match (format, line.rfind('*')) {
                (TrackFormat::Nmea, Some(b)) => (line[..b].to_string(), line[b..].to_string()),
                _ => (line.clone(), String::new()),
            };
            let mut fs: Vec<String> = body.split(',').map(str::to_string).collect();
            let k = field % fs.len();
            fs[k] = TOKENS[tok].replace(['\n', '\r', ',', '*'], "");
            let mut new = fs.join(",") + &tail;
            if format == TrackFormat::Nmea {
                new = nmea_resign(&new);
            }
            lines[row] = new;
        }
        check(&lines.join("\n"), format)?;
    }
}
