//! GPS tracks: GPX (read with the `roxmltree` XML parser), NMEA 0183 RMC/GGA (`nmea` crate) and CSV (`csv` crate).
//!
//! - **GPX**: every `<trkpt>` of every track and segment (then `<rtept>`, `<wpt>` if there are no
//!   track points) with a `<time>`; `<speed>` (m/s) when present.
//! - **NMEA**: one sentence per line. RMC sentences give date, time, position, speed (knots) and
//!   course; GGA sentences (time and position only) are used when the file has no RMC. A line
//!   that is not a valid sentence (bad checksum, malformed fields, not starting with `$`) is
//!   skipped and counted (`n_bad_sentences`); sentences of other types (GSV, VTG...) are ignored
//!   and counted (`n_other_sentences`). RMC with status `V` (no fix) is skipped. Without any date
//!   (GGA only) times are seconds of the day, rolled over at midnight.
//! - **CSV**: a header row naming a time, a latitude, a longitude and optionally a speed
//!   column; separator `,` or `;`. Columns are found by name (case-insensitive, a unit in
//!   `(...)`/`[...]` removed): first an exact name (`time`, `t`, `time_s`, `time_ms`, `t_ms`,
//!   `timestamp`, `timestamp_ms`, `datetime`, `utc`; `lat`, `latitude`; `lon`, `lng`, `long`,
//!   `longitude`), else a name with such a word among its `_`/`-`/`.`/space-separated words
//!   (`Lat_GNSS`, `gps_lat`, `Long_GNSS`, `GPS_Time`) and no motion word (`acc`, `vel`,
//!   `speed`, ...: `Long_Acc` is no longitude). Two candidates at the same level are refused,
//!   naming both. Time cells are seconds (Unix time when above 1e8), milliseconds when the
//!   name ends in `_ms` or the unit is `ms`, Unix milliseconds when a number exceeds 1e11 (no
//!   time in seconds does: [`GPS_TIME_ABS_MAX_S`]), or RFC 3339 (`2024-05-02T07:31:00Z`).
//!   Speed is m/s unless the header says km/h (`speed_kmh`, `speed (km/h)`) or knots (`kn`);
//!   without a speed column the speed comes from the positions, as for GGA-only NMEA.
//!
//! Every fix of every format passes one check ([`check_fixes`]): time finite and within
//! +-[`GPS_TIME_ABS_MAX_S`], latitude finite and within +-90 degrees, longitude finite and within
//! +-180 degrees, speed (when given) finite and within 0..=[`GPS_SPEED_KMH_MAX`] km/h. A fix that
//! fails is dropped and counted by reason ([`GpsTrack::dropped`]); when more than
//! [`DROPPED_FIXES_MAX_REL`] of the fixes fail, the file is refused
//! ([`crate::SegmentError::TooManyBadFixes`]). A course that is not finite or outside 0..=360
//! degrees is left out (the heading is then measured from the positions). Times must not go
//! backwards ([`crate::SegmentError::TimeBackwards`]); repeated times keep the first fix.

use crate::{parse_rfc3339, SegmentError, TrackProblem};
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::path::Path;
use vibmode_core::Num;

/// Highest speed accepted from a GPS track, km/h: above any ground vehicle (the maglev speed
/// record is 603 km/h); a larger value is a broken fix or a speed in the wrong unit.
pub const GPS_SPEED_KMH_MAX: f64 = 1000.0;
/// Largest magnitude of a GPS time, s (Unix time 1e11 s is the year 5138).
pub const GPS_TIME_ABS_MAX_S: f64 = 1e11;
/// Largest share of a track's fixes that may be dropped as invalid before the file is refused.
pub const DROPPED_FIXES_MAX_REL: f64 = 0.5;

/// One GPS fix.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct GpsFix {
    /// Time, s: Unix time when the track is absolute, else seconds as written (e.g. of the day).
    pub t_s: f64,
    /// Latitude, degrees.
    pub lat_deg: f64,
    /// Longitude, degrees.
    pub lon_deg: f64,
    /// Speed from the receiver, km/h.
    pub speed_kmh: Option<f64>,
    /// Course over ground from the receiver, degrees from north.
    pub course_deg: Option<f64>,
}

/// A GPS track format.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum TrackFormat {
    /// GPX 1.0/1.1.
    Gpx,
    /// NMEA 0183 sentences.
    Nmea,
    /// CSV with time, latitude, longitude, speed.
    Csv,
}

/// A GPS track, fixes in time order.
#[derive(Clone, Debug, PartialEq)]
pub struct GpsTrack {
    /// The file.
    pub path: String,
    /// Its format.
    pub format: TrackFormat,
    /// The fixes.
    pub fixes: Vec<GpsFix>,
    /// True when `t_s` is Unix time (dates known).
    pub absolute: bool,
    /// NMEA lines that could not be parsed.
    pub n_bad_sentences: usize,
    /// NMEA sentences of other types.
    pub n_other_sentences: usize,
    /// NMEA RMC/GGA sentences that parse but give no fix, by reason (e.g. "RMC without a date").
    pub incomplete_sentences: BTreeMap<String, usize>,
    /// Fixes read before the check of [`check_fixes`].
    pub n_read: usize,
    /// Fixes dropped by [`check_fixes`], by reason (e.g. "speed not finite").
    pub dropped: BTreeMap<String, usize>,
}

impl GpsTrack {
    /// Fixes dropped as invalid.
    pub fn n_dropped(&self) -> usize {
        self.dropped.values().sum()
    }

    /// `"dropped 3 of 600 fixes: 2 speed not finite, 1 latitude out of range"`, or `None` when
    /// no fix was dropped.
    pub fn dropped_note(&self) -> Option<String> {
        let n = self.n_dropped();
        (n > 0).then(|| {
            format!(
                "dropped {n} of {} fixes: {}",
                self.n_read,
                reasons(&self.dropped)
            )
        })
    }
}

/// `"2 speed not finite, 1 latitude out of range"`.
pub(crate) fn reasons(counts: &BTreeMap<String, usize>) -> String {
    counts
        .iter()
        .map(|(k, v)| format!("{v} {k}"))
        .collect::<Vec<_>>()
        .join(", ")
}

/// A library's message for ours: control characters shown as `?`, at most 160 characters
/// (it may carry pieces of the input).
fn short(msg: &str) -> String {
    let mut out: String = msg
        .chars()
        .take(160)
        .map(|c| if c.is_control() { '?' } else { c })
        .collect();
    if msg.chars().nth(160).is_some() {
        out.push_str("...");
    }
    out
}

/// Why a fix is invalid, or `None` when it passes (see the module documentation).
pub fn fix_problem(f: &GpsFix) -> Option<&'static str> {
    if !f.t_s.is_finite() {
        Some("time not finite")
    } else if f.t_s.abs() > GPS_TIME_ABS_MAX_S {
        Some("time out of range")
    } else if !f.lat_deg.is_finite() {
        Some("latitude not finite")
    } else if f.lat_deg.abs() > 90.0 {
        Some("latitude out of range")
    } else if !f.lon_deg.is_finite() {
        Some("longitude not finite")
    } else if f.lon_deg.abs() > 180.0 {
        Some("longitude out of range")
    } else {
        match f.speed_kmh {
            Some(v) if !v.is_finite() => Some("speed not finite"),
            Some(v) if v < 0.0 => Some("speed negative"),
            Some(v) if v > GPS_SPEED_KMH_MAX => Some("speed above the maximum"),
            _ => None,
        }
    }
}

/// The one check of every format's fixes: drops invalid fixes (counted by reason in the
/// returned map) and clears an invalid course; `keep` gets the indices kept.
pub fn check_fixes(fixes: Vec<GpsFix>) -> (Vec<GpsFix>, Vec<usize>, BTreeMap<String, usize>) {
    let mut dropped: BTreeMap<String, usize> = BTreeMap::new();
    let mut kept = Vec::with_capacity(fixes.len());
    let mut idx = Vec::with_capacity(fixes.len());
    for (i, mut f) in fixes.into_iter().enumerate() {
        if let Some(why) = fix_problem(&f) {
            *dropped.entry(why.to_string()).or_insert(0) += 1;
            continue;
        }
        if f.course_deg
            .is_some_and(|c| !(c.is_finite() && (0.0..=360.0).contains(&c)))
        {
            f.course_deg = None;
        }
        kept.push(f);
        idx.push(i);
    }
    (kept, idx, dropped)
}

fn track_err(path: &str, problem: TrackProblem) -> SegmentError {
    SegmentError::Track {
        path: path.to_string(),
        problem,
    }
}

/// Reads a track; the format from the extension (`.gpx`, `.nmea`/`.nma`/`.log`, `.csv`/`.txt`)
/// or, failing that, from the first character (`<` GPX, `$` NMEA, else CSV).
pub fn read_track(path: &Path) -> Result<GpsTrack, SegmentError> {
    let p = path.display().to_string();
    let text = std::fs::read_to_string(path).map_err(|e| SegmentError::Io {
        path: p.clone(),
        message: e.to_string(),
    })?;
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .unwrap_or("")
        .to_ascii_lowercase();
    let first = text
        .trim_start_matches('\u{feff}')
        .trim_start()
        .chars()
        .next();
    let format = match ext.as_str() {
        "gpx" => TrackFormat::Gpx,
        "nmea" | "nma" => TrackFormat::Nmea,
        "csv" | "tsv" => TrackFormat::Csv,
        _ => match first {
            Some('<') => TrackFormat::Gpx,
            Some('$') => TrackFormat::Nmea,
            _ => TrackFormat::Csv,
        },
    };
    let (raw, places) = match format {
        TrackFormat::Gpx => read_gpx(&text, &p)?,
        TrackFormat::Nmea => read_nmea(&text, &p)?,
        TrackFormat::Csv => read_csv(&text, &p)?,
    };
    finish(raw, places, &p)
}

/// Reads a track from its text in a known format (as [`read_track`]; `path` names it in
/// messages).
pub fn parse_track(text: &str, format: TrackFormat, path: &str) -> Result<GpsTrack, SegmentError> {
    let (raw, places) = match format {
        TrackFormat::Gpx => read_gpx(text, path)?,
        TrackFormat::Nmea => read_nmea(text, path)?,
        TrackFormat::Csv => read_csv(text, path)?,
    };
    finish(raw, places, path)
}

/// Checks the fixes as read (`places` names each: line or point), their order and their count.
fn finish(mut track: GpsTrack, places: Vec<String>, p: &str) -> Result<GpsTrack, SegmentError> {
    let n_read = track.fixes.len();
    let (fixes, idx, dropped) = check_fixes(std::mem::take(&mut track.fixes));
    track.fixes = fixes;
    track.n_read = n_read;
    track.dropped = dropped;
    let n_dropped = track.n_dropped();
    if track.fixes.is_empty() {
        let mut detail = Vec::new();
        if track.format == TrackFormat::Nmea {
            detail.push(format!(
                "{} unparseable and {} other sentences",
                track.n_bad_sentences, track.n_other_sentences
            ));
            if !track.incomplete_sentences.is_empty() {
                detail.push(reasons(&track.incomplete_sentences));
            }
        }
        if n_dropped > 0 {
            detail.push(format!(
                "{n_dropped} fixes dropped: {}",
                reasons(&track.dropped)
            ));
        }
        return Err(SegmentError::NoFixes {
            path: p.to_string(),
            detail: if detail.is_empty() {
                String::new()
            } else {
                format!(" ({})", detail.join("; "))
            },
        });
    }
    if n_dropped as f64 > DROPPED_FIXES_MAX_REL * n_read as f64 {
        return Err(SegmentError::TooManyBadFixes {
            path: p.to_string(),
            n_dropped,
            n_read,
            reasons: reasons(&track.dropped),
        });
    }
    let absolute = track.absolute;
    check_order(
        p,
        &track.fixes,
        |i| {
            idx.get(i)
                .and_then(|&k| places.get(k))
                .cloned()
                .unwrap_or_default()
        },
        show_time(absolute),
    )?;
    track.fixes.dedup_by(|b, a| b.t_s == a.t_s);
    Ok(track)
}

/// Checks that `t` does not go backwards; `at(i)` names fix i.
fn check_order(
    path: &str,
    fixes: &[GpsFix],
    at: impl Fn(usize) -> String,
    show: impl Fn(f64) -> String,
) -> Result<(), SegmentError> {
    for i in 1..fixes.len() {
        if fixes[i].t_s < fixes[i - 1].t_s {
            return Err(SegmentError::TimeBackwards {
                path: path.to_string(),
                at: at(i),
                previous: show(fixes[i - 1].t_s),
                value: show(fixes[i].t_s),
            });
        }
    }
    Ok(())
}

fn show_time(absolute: bool) -> impl Fn(f64) -> String {
    move |t| {
        if absolute {
            crate::format_rfc3339(t).unwrap_or_else(|| format!("{} s", Num(t)))
        } else {
            format!("{} s", Num(t))
        }
    }
}

/// A track as read, before [`finish`] checks it, with a place name per fix.
type Raw = (GpsTrack, Vec<String>);

fn raw_track(p: &str, format: TrackFormat, fixes: Vec<GpsFix>, absolute: bool) -> GpsTrack {
    GpsTrack {
        path: p.to_string(),
        format,
        fixes,
        absolute,
        n_bad_sentences: 0,
        n_other_sentences: 0,
        incomplete_sentences: BTreeMap::new(),
        n_read: 0,
        dropped: BTreeMap::new(),
    }
}

fn read_gpx(text: &str, p: &str) -> Result<Raw, SegmentError> {
    let doc = roxmltree::Document::parse(text).map_err(|e| {
        track_err(
            p,
            TrackProblem::NotXml {
                message: short(&e.to_string()),
            },
        )
    })?;
    let root = doc.root_element();
    if root.tag_name().name() != "gpx" {
        return Err(track_err(
            p,
            TrackProblem::NotGpx {
                root: root.tag_name().name().to_string(),
            },
        ));
    }
    // Track points of every track and segment; else route points; else waypoints.
    let mut points: Vec<roxmltree::Node<'_, '_>> = children(root, "trk")
        .flat_map(|t| children(t, "trkseg"))
        .flat_map(|s| children(s, "trkpt"))
        .collect();
    if points.is_empty() {
        points = children(root, "rte")
            .flat_map(|r| children(r, "rtept"))
            .collect();
    }
    if points.is_empty() {
        points = children(root, "wpt").collect();
    }
    let mut fixes = Vec::with_capacity(points.len());
    let mut places = Vec::with_capacity(points.len());
    for (k, w) in points.into_iter().enumerate() {
        let point = k + 1;
        let place = format!("point {point}");
        // A coordinate out of range, or not a number, makes the file invalid GPX: refused as a
        // whole, the value named, short.
        let coord = |name: &'static str, limit: f64| -> Result<f64, SegmentError> {
            let Some(cell) = w.attribute(name) else {
                return Err(track_err(
                    p,
                    TrackProblem::MissingCoordinate { point, name },
                ));
            };
            match cell.trim().parse::<f64>() {
                Ok(v) if (-limit..=limit).contains(&v) => Ok(v),
                Ok(value) => Err(track_err(
                    p,
                    TrackProblem::CoordinateOutOfRange {
                        point,
                        name,
                        value,
                        limit_deg: limit,
                    },
                )),
                Err(_) => Err(track_err(
                    p,
                    TrackProblem::PointNotANumber {
                        point,
                        name,
                        text: cell.to_string(),
                    },
                )),
            }
        };
        let lat_deg = coord("lat", 90.0)?;
        let lon_deg = coord("lon", 180.0)?;
        let child_text =
            |name: &str| children_named(w, name).map(|c| c.text().unwrap_or("").trim().to_string());
        // A point without a time cannot be placed on the recording: skipped.
        let Some(time_text) = child_text("time") else {
            continue;
        };
        let Some(t_s) = parse_rfc3339(&time_text) else {
            return Err(track_err(
                p,
                TrackProblem::PointTime {
                    point,
                    text: time_text,
                },
            ));
        };
        // GPX 1.0's `<speed>`, m/s; a speed that is not finite is dropped by the common check.
        let speed_kmh = match child_text("speed") {
            None => None,
            Some(v) => match v.parse::<f64>() {
                Ok(v) => Some(v * 3.6),
                Err(_) => {
                    return Err(track_err(
                        p,
                        TrackProblem::PointNotANumber {
                            point,
                            name: "speed",
                            text: v,
                        },
                    ))
                }
            },
        };
        fixes.push(GpsFix {
            t_s,
            lat_deg,
            lon_deg,
            speed_kmh,
            course_deg: None,
        });
        places.push(place);
    }
    Ok((raw_track(p, TrackFormat::Gpx, fixes, true), places))
}

/// The child elements of `n` called `name` (any namespace).
fn children<'a, 'i: 'a>(
    n: roxmltree::Node<'a, 'i>,
    name: &'static str,
) -> impl Iterator<Item = roxmltree::Node<'a, 'i>> {
    n.children()
        .filter(move |c| c.is_element() && c.tag_name().name() == name)
}

/// The first child element of `n` called `name` (any namespace).
fn children_named<'a, 'i>(
    n: roxmltree::Node<'a, 'i>,
    name: &str,
) -> Option<roxmltree::Node<'a, 'i>> {
    n.children()
        .find(|c| c.is_element() && c.tag_name().name() == name)
}

fn read_nmea(text: &str, p: &str) -> Result<Raw, SegmentError> {
    use chrono::Timelike;
    let mut rmc: Vec<(GpsFix, usize)> = Vec::new();
    let mut gga: Vec<(f64, f64, f64, usize)> = Vec::new();
    let (mut bad, mut other) = (0usize, 0usize);
    let mut incomplete: BTreeMap<String, usize> = BTreeMap::new();
    let mut count = |why: &str| *incomplete.entry(why.to_string()).or_insert(0) += 1;
    for (k, line) in text.lines().enumerate() {
        let line = line.trim().trim_start_matches('\u{feff}');
        if line.is_empty() {
            continue;
        }
        if !line.starts_with('$') {
            bad += 1;
            continue;
        }
        match nmea::parse_str(line) {
            Ok(nmea::ParseResult::RMC(r)) => {
                let valid = !matches!(
                    r.status_of_fix,
                    nmea::sentences::rmc::RmcStatusOfFix::Invalid
                );
                if !valid {
                    count("RMC without a fix (status V)");
                } else if r.fix_time.is_none() {
                    count("RMC without a time");
                } else if r.fix_date.is_none() {
                    count("RMC without a date");
                } else if r.lat.is_none() || r.lon.is_none() {
                    count("RMC without a position");
                }
                if let (true, Some(tm), Some(date), Some(lat), Some(lon)) =
                    (valid, r.fix_time, r.fix_date, r.lat, r.lon)
                {
                    let dt = date.and_time(tm).and_utc();
                    let t = dt.timestamp() as f64 + dt.timestamp_subsec_nanos() as f64 / 1e9;
                    rmc.push((
                        GpsFix {
                            t_s: t,
                            lat_deg: lat,
                            lon_deg: lon,
                            speed_kmh: r.speed_over_ground.map(|v| v as f64 * 1.852),
                            course_deg: r.true_course.map(|v| v as f64),
                        },
                        k + 1,
                    ));
                }
            }
            Ok(nmea::ParseResult::GGA(g)) => {
                if let (Some(tm), Some(lat), Some(lon)) = (g.fix_time, g.latitude, g.longitude) {
                    let t = tm.num_seconds_from_midnight() as f64 + tm.nanosecond() as f64 / 1e9;
                    gga.push((t, lat, lon, k + 1));
                } else {
                    count("GGA without a time or position");
                }
            }
            Ok(_) => other += 1,
            Err(
                nmea::Error::DisabledSentence
                | nmea::Error::Unsupported(_)
                | nmea::Error::Unknown(_),
            ) => other += 1,
            Err(_) => bad += 1,
        }
    }
    let (fixes, lines, absolute) = if !rmc.is_empty() {
        incomplete.remove("GGA without a time or position");
        other += gga.len();
        let lines: Vec<usize> = rmc.iter().map(|f| f.1).collect();
        (
            rmc.into_iter().map(|f| f.0).collect::<Vec<_>>(),
            lines,
            true,
        )
    } else {
        // Seconds of the day; a step back of more than 12 h is midnight.
        let mut day = 0.0;
        let mut prev = f64::NEG_INFINITY;
        let mut fixes = Vec::with_capacity(gga.len());
        let mut lines = Vec::with_capacity(gga.len());
        for (t, lat, lon, line) in gga {
            if t + day < prev - 43_200.0 {
                day += 86_400.0;
            }
            prev = t + day;
            fixes.push(GpsFix {
                t_s: t + day,
                lat_deg: lat,
                lon_deg: lon,
                speed_kmh: None,
                course_deg: None,
            });
            lines.push(line);
        }
        (fixes, lines, false)
    };
    let mut track = raw_track(p, TrackFormat::Nmea, fixes, absolute);
    track.n_bad_sentences = bad;
    track.n_other_sentences = other;
    track.incomplete_sentences = incomplete;
    Ok((track, lines.iter().map(|l| format!("line {l}")).collect()))
}

/// A header cell's name: without a unit in `(...)` or `[...]`, trimmed, lower case.
fn base_name(h: &str) -> String {
    h.split(['(', '['])
        .next()
        .unwrap_or("")
        .trim()
        .to_ascii_lowercase()
}

/// A header cell's unit in `(...)` or `[...]`, lower case (empty when none).
fn header_unit(h: &str) -> String {
    match h.find(['(', '[']) {
        Some(i) => h[i + 1..]
            .trim_end()
            .trim_end_matches([')', ']'])
            .trim()
            .to_ascii_lowercase(),
        None => String::new(),
    }
}

/// The words of a name: split at `_`, `-`, `.` and spaces (`Lat_GNSS` -> `lat`, `gnss`).
fn words(name: &str) -> Vec<&str> {
    name.split(['_', '-', '.', ' '])
        .filter(|w| !w.is_empty())
        .collect()
}

fn find_col(header: &[String], names: &[&str]) -> Option<usize> {
    header
        .iter()
        .position(|h| names.contains(&base_name(h).as_str()))
}

/// Words that make a column a motion quantity rather than a position (`Long_Acc`, `lat_vel`).
const NOT_POSITION: [&str; 8] = [
    "acc",
    "accel",
    "acceleration",
    "g",
    "vel",
    "velocity",
    "speed",
    "rate",
];

/// A CSV track's column for one quantity: the one whose name is exactly one of `exact`
/// (`lat`); failing that, the one that has a word of `words_any` and none of [`NOT_POSITION`]
/// (`Lat_GNSS`, `gps_lat`, `latitude_deg`). `Ok(None)` when no column matches; two candidates
/// at the same level are refused, naming both (but of several exact time names the first is
/// taken, as the reader always did).
fn find_pattern_col(
    header: &[String],
    exact: &[&str],
    words_any: &[&str],
    what: &'static str,
    p: &str,
) -> Result<Option<usize>, SegmentError> {
    let pick = |cands: Vec<usize>| -> Result<Option<usize>, SegmentError> {
        match cands.as_slice() {
            [] => Ok(None),
            [i] => Ok(Some(*i)),
            [a, b, ..] => Err(track_err(
                p,
                TrackProblem::TwoColumns {
                    what,
                    first: header[*a].clone(),
                    second: header[*b].clone(),
                },
            )),
        }
    };
    let exact_cands: Vec<usize> = (0..header.len())
        .filter(|&i| exact.contains(&base_name(&header[i]).as_str()))
        .collect();
    // Several exact time names (`time_s` and `utc`) take the first, as before patterns.
    if what == "time" {
        if let Some(&first) = exact_cands.first() {
            return Ok(Some(first));
        }
    }
    if !exact_cands.is_empty() {
        return pick(exact_cands);
    }
    let pattern_cands: Vec<usize> = (0..header.len())
        .filter(|&i| {
            let b = base_name(&header[i]);
            let w = words(&b);
            w.iter().any(|x| words_any.contains(x)) && !w.iter().any(|x| NOT_POSITION.contains(x))
        })
        .collect();
    pick(pattern_cands)
}

/// Seconds per unit of a CSV track's time column, when its name (`time_ms`) or header unit
/// (`time (ms)`) says; `None` for seconds or RFC 3339 text as the cells say.
fn time_col_scale(h: &str) -> Option<f64> {
    let unit = header_unit(h);
    let b = base_name(h);
    let suffix = words(&b).last().map(|w| w.to_string()).unwrap_or_default();
    let by = |u: &str| match u {
        "ms" | "msec" => Some(1e-3),
        "us" | "µs" => Some(1e-6),
        "ns" => Some(1e-9),
        _ => None,
    };
    if unit.is_empty() {
        by(&suffix)
    } else {
        by(&unit)
    }
}

fn read_csv(text: &str, p: &str) -> Result<Raw, SegmentError> {
    let text = text.trim_start_matches('\u{feff}');
    let first_line = text.lines().next().unwrap_or("");
    let delim = if first_line.contains(';') { b';' } else { b',' };
    let mut rdr = csv::ReaderBuilder::new()
        .delimiter(delim)
        .flexible(true)
        .trim(csv::Trim::All)
        .from_reader(text.as_bytes());
    let header: Vec<String> = rdr
        .headers()
        .map_err(|e| {
            track_err(
                p,
                TrackProblem::CsvHeader {
                    message: short(&e.to_string()),
                },
            )
        })?
        .iter()
        .map(str::to_string)
        .collect();
    let need = |names: &[&str], what: &'static str| {
        find_col(&header, names).ok_or_else(|| {
            track_err(
                p,
                TrackProblem::NoColumn {
                    what,
                    header: header.clone(),
                },
            )
        })
    };
    let tc = find_pattern_col(
        &header,
        &[
            "time",
            "t",
            "time_s",
            "time_ms",
            "t_s",
            "t_ms",
            "timestamp",
            "timestamp_s",
            "timestamp_ms",
            "datetime",
            "utc",
            "date_time",
        ],
        &["time", "timestamp", "datetime", "utc"],
        "time",
        p,
    )?;
    let tc = tc.map_or_else(|| need(&[], "time"), Ok)?;
    let la = find_pattern_col(
        &header,
        &["lat", "latitude"],
        &["lat", "latitude"],
        "latitude",
        p,
    )?;
    let la = la.map_or_else(|| need(&[], "latitude"), Ok)?;
    let lo = find_pattern_col(
        &header,
        &["lon", "lng", "long", "longitude"],
        &["lon", "lng", "long", "longitude"],
        "longitude",
        p,
    )?;
    let lo = lo.map_or_else(|| need(&[], "longitude"), Ok)?;
    let time_scale = time_col_scale(&header[tc]);
    let sc = find_col(
        &header,
        &[
            "speed",
            "speed_kmh",
            "speed_mps",
            "speed_ms",
            "velocity",
            "v",
        ],
    );
    let speed_factor = sc.map_or(3.6, |i| {
        let h = header[i].to_ascii_lowercase();
        if h.contains("km") {
            1.0
        } else if h.contains("kn") {
            1.852
        } else {
            3.6
        }
    });
    let mut fixes = Vec::new();
    let mut lines = Vec::new();
    let mut absolute = None;
    for (k, rec) in rdr.records().enumerate() {
        let line = k + 2;
        let rec = rec.map_err(|e| {
            track_err(
                p,
                TrackProblem::CsvRow {
                    line,
                    message: short(&e.to_string()),
                },
            )
        })?;
        let cell = |i: usize| rec.get(i).unwrap_or("");
        if rec.iter().all(str::is_empty) {
            continue;
        }
        // A number that is not finite (nan, inf) or out of range is checked with the other
        // formats' fixes (dropped and counted); text that is no number at all is refused.
        let num = |i: usize, what: &'static str| -> Result<f64, SegmentError> {
            cell(i).parse::<f64>().map_err(|_| {
                track_err(
                    p,
                    TrackProblem::CellNotANumber {
                        line,
                        what,
                        text: cell(i).to_string(),
                    },
                )
            })
        };
        let (t, abs) = match cell(tc).parse::<f64>() {
            // Milliseconds by the column's name or unit; a number above 1e11 (no Unix time in
            // seconds, GPS_TIME_ABS_MAX_S) is Unix time in milliseconds.
            Ok(v) => match time_scale {
                Some(k) => (v * k, v * k > 1e8),
                None if v.abs() > GPS_TIME_ABS_MAX_S => (v * 1e-3, true),
                None => (v, v > 1e8),
            },
            _ => match parse_rfc3339(cell(tc)).or_else(|| csv_datetime(cell(tc))) {
                Some(v) => (v, true),
                None => {
                    return Err(track_err(
                        p,
                        TrackProblem::CellTime {
                            line,
                            text: cell(tc).to_string(),
                        },
                    ))
                }
            },
        };
        if t.is_finite() {
            absolute.get_or_insert(abs);
        }
        let speed_kmh = match sc {
            Some(i) if !cell(i).is_empty() => Some(num(i, "speed")? * speed_factor),
            _ => None,
        };
        fixes.push(GpsFix {
            t_s: t,
            lat_deg: num(la, "latitude")?,
            lon_deg: num(lo, "longitude")?,
            speed_kmh,
            course_deg: None,
        });
        lines.push(line);
    }
    let absolute = absolute.unwrap_or(false);
    Ok((
        raw_track(p, TrackFormat::Csv, fixes, absolute),
        lines.iter().map(|l| format!("line {l}")).collect(),
    ))
}

/// Great-circle distance between two fixes, m (haversine, mean Earth radius 6 371 008.8 m).
pub fn distance_m(a: &GpsFix, b: &GpsFix) -> f64 {
    let r = 6_371_008.8;
    let (p1, p2) = (a.lat_deg.to_radians(), b.lat_deg.to_radians());
    let dp = p2 - p1;
    let dl = (b.lon_deg - a.lon_deg).to_radians();
    let h = (dp / 2.0).sin().powi(2) + p1.cos() * p2.cos() * (dl / 2.0).sin().powi(2);
    2.0 * r * h.sqrt().min(1.0).asin()
}

/// Initial bearing from `a` to `b`, degrees from north in 0..360.
pub fn bearing_deg(a: &GpsFix, b: &GpsFix) -> f64 {
    let (p1, p2) = (a.lat_deg.to_radians(), b.lat_deg.to_radians());
    let dl = (b.lon_deg - a.lon_deg).to_radians();
    let y = dl.sin() * p2.cos();
    let x = p1.cos() * p2.sin() - p1.sin() * p2.cos() * dl.cos();
    (y.atan2(x).to_degrees() + 360.0) % 360.0
}

/// Unix seconds of a CSV time cell written as a date-time the recordings' reader takes
/// ([`vibmode_signal::delimited::parse_datetime`]): `2024-05-02 07:31:00.25` (no offset: UTC),
/// `02.05.2024 07:31:00,25`, an ISO 8601 time with a decimal comma.
fn csv_datetime(text: &str) -> Option<f64> {
    let (s, ns) = vibmode_signal::delimited::parse_datetime(text.as_bytes())?;
    Some(s as f64 + f64::from(ns) * 1e-9)
}
