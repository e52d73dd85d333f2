//! Records cut by a GPS track, and consecutive records.

use crate::gps::{bearing_deg, distance_m, GpsTrack, GPS_TIME_ABS_MAX_S};
use crate::{
    format_rfc3339, parse_rfc3339, push_skip, GpsSummary, SegmentError, SegmentParams,
    SegmentRecord, Segmentation, SkipReason, GPS_OFFSET_S_MAX,
};
use serde::{Deserialize, Serialize};
use vibmode_core::Num;
use vibmode_core::RecordMeta;
use vibmode_signal::{FrameStream, StreamInfo};

/// How GPS times were put on the recording's time axis: `t_rec = t_gps - base + offset_s`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct GpsAlignment {
    /// The recording's start time used as `base` (from its sidecar), or `None` when `base` is the
    /// first fix.
    pub recording_start: Option<String>,
    /// Seconds added to GPS times (clock offset between the two recorders).
    pub offset_s: f64,
    /// In words.
    pub rule: String,
}

/// Unix seconds of the recording's start from its sidecar, if it has one: an RFC 3339 time or
/// seconds since 1970 (0 to [`GPS_TIME_ABS_MAX_S`]).
pub(crate) fn recording_start(info: &StreamInfo) -> Result<Option<f64>, SegmentError> {
    match &info.start_time {
        None => Ok(None),
        Some(s) => parse_rfc3339(s)
            .or_else(|| {
                s.trim()
                    .parse::<f64>()
                    .ok()
                    .filter(|v| v.is_finite() && (0.0..=GPS_TIME_ABS_MAX_S).contains(v))
            })
            .map(Some)
            .ok_or_else(|| SegmentError::StartTime {
                path: info.path.clone(),
                value: s.clone(),
            }),
    }
}

pub(crate) fn check_length(
    info: &StreamInfo,
    n_frames: u64,
    record_length_s: f64,
) -> Result<f64, SegmentError> {
    let duration_s = n_frames as f64 / info.fs_hz;
    if duration_s + 1e-9 < record_length_s {
        return Err(SegmentError::TooShort {
            path: info.path.clone(),
            duration_s,
            record_length_s,
        });
    }
    Ok(duration_s)
}

pub(crate) fn empty_segmentation(
    info: &StreamInfo,
    method: crate::SegmentMethod,
    duration_s: f64,
    record_length_s: f64,
    p: &SegmentParams,
    start_unix: Option<f64>,
) -> Segmentation {
    Segmentation {
        source: info.path.clone(),
        method,
        record_length_s,
        fs_hz: info.fs_hz,
        duration_s,
        start_time: start_unix.and_then(format_rfc3339),
        params: p.clone(),
        gps: None,
        records: Vec::new(),
        skipped: Vec::new(),
        skipped_s_by_reason: Default::default(),
    }
}

pub(crate) fn record_at(
    fs_hz: f64,
    start_s: f64,
    record_length_s: f64,
    start_unix: Option<f64>,
) -> SegmentRecord {
    let start_frame = (start_s * fs_hz).round() as u64;
    let n_frames = (record_length_s * fs_hz).round() as usize;
    SegmentRecord {
        file: None,
        start_frame,
        n_frames,
        meta: RecordMeta {
            start_s: start_frame as f64 / fs_hz,
            duration_s: n_frames as f64 / fs_hz,
            start_time: start_unix.and_then(|u| format_rfc3339(u + start_frame as f64 / fs_hz)),
            ..RecordMeta::default()
        },
        heading_deg: None,
    }
}

/// Consecutive records of `record_length_s` from the start (the remainder is skipped).
pub fn fixed_cuts(
    info: &StreamInfo,
    n_frames: u64,
    record_length_s: f64,
    p: &SegmentParams,
) -> Result<Segmentation, SegmentError> {
    p.validate(record_length_s)?;
    let duration_s = check_length(info, n_frames, record_length_s)?;
    p.check_work(record_length_s, info.fs_hz, duration_s, false)?;
    let start_unix = recording_start(info)?;
    let mut seg = empty_segmentation(
        info,
        crate::SegmentMethod::Fixed,
        duration_s,
        record_length_s,
        p,
        start_unix,
    );
    let n = (duration_s / record_length_s + 1e-9).floor() as usize;
    for k in 0..n {
        seg.records.push(record_at(
            info.fs_hz,
            k as f64 * record_length_s,
            record_length_s,
            start_unix,
        ));
    }
    push_skip(
        &mut seg.skipped,
        n as f64 * record_length_s,
        duration_s,
        SkipReason::Remainder,
    );
    seg.tally();
    Ok(seg)
}

/// Fixes before and after a fix between which its heading is measured when the receiver gives
/// no course.
const HEADING_BASELINE: usize = 3;

/// Window of the speed derived from positions when the receiver gives none (GGA-only NMEA, CSV
/// without a speed column), s: the distance between the first and the last fix within
/// `SPEED_WINDOW_S / 2` before and after a fix, over their time difference, i.e. the centred
/// moving average of the velocity over 8 s. Position noise of 2 m then moves the speed by about
/// 1 km/h, and a standing vehicle reads about 1 km/h, not the 10 km/h of fix-to-fix steps.
pub const SPEED_WINDOW_S: f64 = 8.0;

/// Speed from positions (see [`SPEED_WINDOW_S`]) at fix `i`, km/h.
fn derived_speed_kmh(f: &[crate::GpsFix], i: usize) -> f64 {
    let t = f[i].t_s;
    let a = f.partition_point(|q| q.t_s < t - SPEED_WINDOW_S / 2.0);
    let b = f
        .partition_point(|q| q.t_s <= t + SPEED_WINDOW_S / 2.0)
        .saturating_sub(1);
    // Fewer than two fixes in the window: the neighbours.
    let (a, b) = if b > a {
        (a, b)
    } else {
        (i.saturating_sub(1), (i + 1).min(f.len() - 1))
    };
    let dt = f[b].t_s - f[a].t_s;
    if a < b && dt > 0.0 {
        distance_m(&f[a], &f[b]) / dt * 3.6
    } else {
        0.0
    }
}

/// A fix on the recording's axis with speed and heading.
struct Point {
    t: f64,
    speed_kmh: f64,
    heading: Option<f64>,
    lat: f64,
    lon: f64,
}

fn points(track: &GpsTrack, base: f64, offset_s: f64) -> Vec<Point> {
    let f = &track.fixes;
    let n = f.len();
    (0..n)
        .map(|i| {
            let speed = f[i].speed_kmh.unwrap_or_else(|| derived_speed_kmh(f, i));
            // Bearings over a longer baseline (fixes 3 before to 3 after) so that position noise
            // (a few metres) does not pass for a turn.
            let (ha, hb) = (
                i.saturating_sub(HEADING_BASELINE),
                (i + HEADING_BASELINE).min(n - 1),
            );
            let heading = match f[i].course_deg {
                Some(c) if speed > 3.0 => Some(c),
                _ if ha != hb && distance_m(&f[ha], &f[hb]) > 10.0 => {
                    Some(bearing_deg(&f[ha], &f[hb]))
                }
                _ => None,
            };
            Point {
                t: f[i].t_s - base + offset_s,
                speed_kmh: speed,
                heading,
                lat: f[i].lat_deg,
                lon: f[i].lon_deg,
            }
        })
        .collect()
}

/// Judges the window `a..b`: `Ok((mean speed, middle point index, mean heading))` or the reason
/// to skip it.
fn judge(
    pts: &[Point],
    a: f64,
    b: f64,
    p: &SegmentParams,
) -> Result<(f64, usize, Option<f64>), SkipReason> {
    let lo = pts.partition_point(|q| q.t < a);
    let hi = pts.partition_point(|q| q.t <= b);
    if hi <= lo {
        return Err(SkipReason::NoGps);
    }
    let w = &pts[lo..hi];
    if w[0].t - a > p.max_gps_gap_s
        || b - w[w.len() - 1].t > p.max_gps_gap_s
        || w.windows(2).any(|x| x[1].t - x[0].t > p.max_gps_gap_s)
    {
        return Err(SkipReason::NoGps);
    }
    let mean = w.iter().map(|q| q.speed_kmh).sum::<f64>() / w.len() as f64;
    if mean < p.min_speed_kmh {
        return Err(SkipReason::Stop);
    }
    let tol = (p.speed_tolerance_rel * mean).max(p.speed_tolerance_kmh);
    if w.iter().any(|q| (q.speed_kmh - mean).abs() > tol) {
        return Err(if w[w.len() - 1].speed_kmh < w[0].speed_kmh {
            SkipReason::Braking
        } else {
            SkipReason::Accelerating
        });
    }
    // Heading unwrapped from the first known one.
    let mut first: Option<f64> = None;
    let (mut hmin, mut hmax, mut hsum, mut hn) = (0.0f64, 0.0f64, 0.0, 0usize);
    for h in w.iter().filter_map(|q| q.heading) {
        let f = *first.get_or_insert(h);
        let d = ((h - f + 540.0) % 360.0) - 180.0;
        hmin = hmin.min(d);
        hmax = hmax.max(d);
        hsum += d;
        hn += 1;
    }
    if hmax - hmin > p.max_heading_change_deg {
        return Err(SkipReason::Turn);
    }
    let heading = first.map(|f| (f + hsum / hn.max(1) as f64 + 360.0) % 360.0);
    let mid = (a + b) / 2.0;
    let k = lo
        + w.iter()
            .enumerate()
            .min_by(|x, y| (x.1.t - mid).abs().total_cmp(&(y.1.t - mid).abs()))
            .map_or(0, |(i, _)| i);
    Ok((mean, k, heading))
}

/// Records where the GPS track shows steady driving (see [`SegmentParams`]): the search starts at
/// 0 s; a window of one record length that passes becomes a record and the search goes on after
/// it; one that fails is skipped by `step_s` with its reason. `offset_s` is added to GPS times
/// after the recording's start (sidecar `start_time`, when both it and the track have dates) or
/// else the first fix has been subtracted.
pub fn by_gps(
    info: &StreamInfo,
    n_frames: u64,
    track: &GpsTrack,
    offset_s: f64,
    record_length_s: f64,
    p: &SegmentParams,
) -> Result<Segmentation, SegmentError> {
    p.validate(record_length_s)?;
    if !(offset_s.is_finite() && offset_s.abs() <= GPS_OFFSET_S_MAX) {
        return Err(crate::invalid(
            "gps_offset_s",
            offset_s,
            format!(
                "a number of seconds within +-{} (11.6 days), e.g. 3600",
                Num(GPS_OFFSET_S_MAX)
            ),
        ));
    }
    let duration_s = check_length(info, n_frames, record_length_s)?;
    p.check_work(record_length_s, info.fs_hz, duration_s, true)?;
    let start = recording_start(info)?;
    let first_t = track.fixes.first().map_or(0.0, |f| f.t_s);
    let (base, alignment) = match (start, track.absolute) {
        (Some(s), true) => (
            s,
            GpsAlignment {
                recording_start: format_rfc3339(s),
                offset_s,
                rule: format!(
                    "GPS time minus the recording's start time from its sidecar, plus {} s",
                    Num(offset_s)
                ),
            },
        ),
        _ => (
            first_t,
            GpsAlignment {
                recording_start: None,
                offset_s,
                rule: format!(
                    "the recording starts at the track's first fix; GPS times shifted by {} s",
                    Num(offset_s)
                ),
            },
        ),
    };
    // Absolute time of recording time t, when known.
    let unix_base = match (start, track.absolute) {
        (Some(s), _) => Some(s),
        (None, true) => Some(first_t - offset_s),
        (None, false) => None,
    };
    let pts = points(track, base, offset_s);
    let t0 = pts.first().map_or(0.0, |q| q.t);
    let t1 = pts.last().map_or(0.0, |q| q.t);
    if t1 < 0.0
        || t0 > duration_s
        || pts
            .iter()
            .filter(|q| q.t >= 0.0 && q.t <= duration_s)
            .count()
            < 2
    {
        return Err(SegmentError::NoOverlap {
            path: track.path.clone(),
            track_start_s: t0,
            track_end_s: t1,
            duration_s,
            alignment: alignment.rule.clone(),
        });
    }
    let mut seg = empty_segmentation(
        info,
        crate::SegmentMethod::Gps,
        duration_s,
        record_length_s,
        p,
        unix_base,
    );
    seg.gps = Some(GpsSummary {
        path: track.path.clone(),
        format: track.format,
        n_fixes: track.fixes.len(),
        n_bad_sentences: track.n_bad_sentences,
        n_other_sentences: track.n_other_sentences,
        incomplete_sentences: track.incomplete_sentences.clone(),
        dropped_fixes: track.dropped.clone(),
        alignment,
        covered_s: [t0.max(0.0), t1.min(duration_s)],
        speed_trace: {
            let inside: Vec<[f64; 2]> = pts
                .iter()
                .filter(|q| q.t >= 0.0 && q.t <= duration_s)
                .map(|q| [q.t, q.speed_kmh])
                .collect();
            let step = inside.len().div_ceil(crate::SPEED_TRACE_MAX_POINTS).max(1);
            inside.into_iter().step_by(step).collect()
        },
    });
    let mut t = 0.0;
    while t + record_length_s <= duration_s + 1e-9 {
        match judge(&pts, t, t + record_length_s, p) {
            Ok((speed, k, heading)) => {
                let mut r = record_at(info.fs_hz, t, record_length_s, unix_base);
                r.meta.mean_speed_kmh = Some(speed);
                r.meta.lat_deg = Some(pts[k].lat);
                r.meta.lon_deg = Some(pts[k].lon);
                r.heading_deg = heading;
                seg.records.push(r);
                t += record_length_s;
            }
            Err(reason) => {
                push_skip(&mut seg.skipped, t, (t + p.step_s).min(duration_s), reason);
                t += p.step_s;
            }
        }
    }
    push_skip(
        &mut seg.skipped,
        t.min(duration_s),
        duration_s,
        SkipReason::Remainder,
    );
    seg.tally();
    Ok(seg)
}

/// How [`plan_file`] cuts a recording into records.
#[derive(Debug, Clone, Copy)]
#[non_exhaustive]
pub enum Cutting<'a> {
    /// Where the GPS track shows steady driving ([`by_gps`]); `offset_s` is added to the
    /// track's times to put them on the recording's clock.
    Gps {
        /// The track.
        track: &'a GpsTrack,
        /// Seconds added to the GPS times.
        offset_s: f64,
    },
    /// Where the vibration shows driving, without stops, idling or strong manoeuvres
    /// ([`by_vibration`](crate::by_vibration)).
    Vibration,
    /// Consecutive records ([`fixed_cuts`]).
    Consecutive,
}

/// The segmentation of the file `path` (channels `sel` of it, read with `opts`) into records of
/// `record_length_s`: by GPS, by vibration or consecutive. The file is read once for the
/// vibration, and to its end for its length when the format does not state it.
pub fn plan_file(
    path: &std::path::Path,
    opts: &vibmode_signal::ReadOptions,
    sel: &[vibmode_signal::ChannelSelector],
    how: Cutting<'_>,
    record_length_s: f64,
    p: &SegmentParams,
) -> Result<Segmentation, SegmentError> {
    let open = || -> Result<FrameStream, SegmentError> {
        let mut s = vibmode_signal::open_stream(path, opts)?;
        s.select(sel)?;
        Ok(s)
    };
    let mut s = open()?;
    match how {
        Cutting::Gps { track, offset_s } => {
            let n = frames(&mut s)?;
            let s = open()?;
            by_gps(s.info(), n, track, offset_s, record_length_s, p)
        }
        Cutting::Vibration => Ok(crate::by_vibration(&mut s, record_length_s, p)?.0),
        Cutting::Consecutive => {
            let n = frames(&mut s)?;
            fixed_cuts(s.info(), n, record_length_s, p)
        }
    }
}

/// The number of frames of a stream (reading it to the end when its format does not say).
fn frames(s: &mut FrameStream) -> Result<u64, SegmentError> {
    if let Some(n) = s.info().n_frames {
        return Ok(n);
    }
    while s
        .next_block(vibmode_signal::DEFAULT_BLOCK_FRAMES)?
        .is_some()
    {}
    Ok(s.position())
}
