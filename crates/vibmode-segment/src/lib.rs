//! # vibmode-segment
//!
//! Cuts an hours-long acceleration recording into records of `record_length_s` where the vehicle
//! drives steadily, as the paper's records were cut with a GPS track recorder
//! (`../shared/paper/METHOD.md` section 1), and says why the rest was skipped:
//!
//! - [`gps`]: GPS tracks from GPX (`roxmltree`), NMEA 0183 RMC/GGA sentences (`nmea` crate;
//!   unparseable sentences are skipped and counted) or CSV (time, latitude, longitude, speed);
//! - [`by_gps`]: records where the speed is steady and the heading nearly constant for a whole
//!   record; stops, braking, accelerating and turns are skipped;
//! - [`by_vibration`]: without GPS, stops and idling (low broadband vibration) and strong
//!   manoeuvres (low-frequency longitudinal/lateral acceleration) found from the signals;
//! - [`write_segments`]: the records as files plus `segments.json`.
//!
//! The rules and their tolerances: `docs/segment.md`.

pub mod gps;
mod plan;
mod vibration;
mod write;

pub use gps::{
    check_fixes, parse_track, read_track, GpsFix, GpsTrack, TrackFormat, DROPPED_FIXES_MAX_REL,
    GPS_SPEED_KMH_MAX, GPS_TIME_ABS_MAX_S,
};
pub use plan::{by_gps, fixed_cuts, plan_file, Cutting, GpsAlignment};
pub use vibration::{by_vibration, VibrationWindow};
pub use write::{write_segments, Written};

use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use vibmode_core::RecordWindow;
use vibmode_core::{num, quoted, Num, RecordMeta};

/// Settings of the segmentation; the defaults are the documented tolerances.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct SegmentParams {
    /// A record's mean speed must be at least this, km/h (below: a stop or creeping). Default 10.
    pub min_speed_kmh: f64,
    /// Every fix of a record must be within this fraction of the record's mean speed... Default
    /// 0.15 (15 %).
    pub speed_tolerance_rel: f64,
    /// ... or within this many km/h, whichever is larger. Default 3.
    pub speed_tolerance_kmh: f64,
    /// The heading may vary by at most this over a record, degrees. Default 20.
    pub max_heading_change_deg: f64,
    /// Largest gap between GPS fixes inside a record (and at its ends), s. Default 5.
    pub max_gps_gap_s: f64,
    /// Step by which the search moves on after a rejected stretch, s. Default 1.
    pub step_s: f64,
    /// Vibration segmentation: window length of the vibration-state features, s. Default 1.
    pub window_s: f64,
    /// Vibration segmentation: a window whose activity (RMS in about 1-8 Hz relative to the
    /// channel's median window, median over channels) is below this is a stop or idling.
    /// Default 0.4.
    pub stop_activity_ratio: f64,
    /// Vibration segmentation: a window whose mean longitudinal or lateral acceleration (x / y
    /// channels, below 0.5 Hz) departs from the recording's median by more than this, m/s^2, is a
    /// strong manoeuvre (braking, accelerating, turning). Default 1.0 (about 0.1 g).
    pub manoeuvre_mps2: f64,
    /// Vibration segmentation: windows this close to a stop or manoeuvre are skipped too
    /// (pulling away, slowing down), s. Default 2.
    pub guard_s: f64,
}

impl Default for SegmentParams {
    fn default() -> Self {
        SegmentParams {
            min_speed_kmh: 10.0,
            speed_tolerance_rel: 0.15,
            speed_tolerance_kmh: 3.0,
            max_heading_change_deg: 20.0,
            max_gps_gap_s: 5.0,
            step_s: 1.0,
            window_s: 1.0,
            stop_activity_ratio: 0.4,
            manoeuvre_mps2: 1.0,
            guard_s: 2.0,
        }
    }
}

/// Fewest samples in a record (`record_length_s * fs_hz`).
pub const RECORD_SAMPLES_MIN: f64 = 16.0;
/// Most records one segmentation may cut (`duration_s / record_length_s`).
pub const RECORDS_MAX: f64 = 100_000.0;
/// Most positions the GPS search visits (`duration_s / step_s`).
pub const SEARCH_STEPS_MAX: f64 = 1_000_000.0;
/// Most vibration windows times channels (`duration_s / window_s * channels`): 16 Mi, 256 MiB
/// of window statistics.
pub const VIBRATION_CELLS_MAX: f64 = 16_777_216.0;
/// Largest magnitude of the GPS clock offset, s (11.6 days).
pub const GPS_OFFSET_S_MAX: f64 = 1e6;

fn invalid(name: &'static str, value: f64, rule: String) -> SegmentError {
    SegmentError::Param(vibmode_core::ParamError::OutOfRangeHere {
        name,
        value: num(&value).to_string(),
        rule,
    })
}

impl SegmentParams {
    /// Checks every value (finite, in range) and the record length; the bounds against the
    /// recording are checked by [`SegmentParams::check_work`].
    pub fn validate(&self, record_length_s: f64) -> Result<(), SegmentError> {
        let checks: [(&'static str, f64, bool, &str); 11] = [
            (
                "record_length_s",
                record_length_s,
                record_length_s > 0.0,
                "a positive duration, e.g. 10.24",
            ),
            (
                "min_speed_kmh",
                self.min_speed_kmh,
                (0.0..=GPS_SPEED_KMH_MAX).contains(&self.min_speed_kmh),
                "0 to 1000, e.g. 10",
            ),
            (
                "speed_tolerance_rel",
                self.speed_tolerance_rel,
                self.speed_tolerance_rel >= 0.0,
                ">= 0, e.g. 0.15",
            ),
            (
                "speed_tolerance_kmh",
                self.speed_tolerance_kmh,
                self.speed_tolerance_kmh >= 0.0,
                ">= 0, e.g. 3",
            ),
            (
                "max_heading_change_deg",
                self.max_heading_change_deg,
                self.max_heading_change_deg >= 0.0,
                ">= 0, e.g. 20",
            ),
            (
                "max_gps_gap_s",
                self.max_gps_gap_s,
                self.max_gps_gap_s > 0.0,
                "> 0, e.g. 5",
            ),
            ("step_s", self.step_s, self.step_s > 0.0, "> 0, e.g. 1"),
            (
                "window_s",
                self.window_s,
                self.window_s > 0.0,
                "> 0, e.g. 1",
            ),
            (
                "stop_activity_ratio",
                self.stop_activity_ratio,
                self.stop_activity_ratio >= 0.0,
                ">= 0, e.g. 0.4",
            ),
            (
                "manoeuvre_mps2",
                self.manoeuvre_mps2,
                self.manoeuvre_mps2 > 0.0,
                "> 0, e.g. 1.0",
            ),
            ("guard_s", self.guard_s, self.guard_s >= 0.0, ">= 0, e.g. 2"),
        ];
        for (name, value, ok, rule) in checks {
            if !(value.is_finite() && ok) {
                return Err(invalid(name, value, rule.to_string()));
            }
        }
        Ok(())
    }

    /// Bounds the work against the recording (`fs_hz`, `duration_s`), before it starts: a
    /// record holds at least [`RECORD_SAMPLES_MIN`] samples and at most [`RECORDS_MAX`] records
    /// fit; with `gps`, the search step is at least one sample and at most [`SEARCH_STEPS_MAX`]
    /// steps fit. Errors name the setting given.
    pub fn check_work(
        &self,
        record_length_s: f64,
        fs_hz: f64,
        duration_s: f64,
        gps: bool,
    ) -> Result<(), SegmentError> {
        self.validate(record_length_s)?;
        let min_len = (RECORD_SAMPLES_MIN / fs_hz).max(duration_s / RECORDS_MAX);
        if record_length_s < min_len {
            return Err(invalid(
                "record_length_s",
                record_length_s,
                format!(
                    "at least {} s here ({} samples at {} Hz, and at most {} records in {} s), e.g. 10.24",
                    Num(min_len),
                    RECORD_SAMPLES_MIN,
                    Num(fs_hz),
                    RECORDS_MAX,
                    Num(duration_s)
                ),
            ));
        }
        let min_step = (1.0 / fs_hz).max(duration_s / SEARCH_STEPS_MAX);
        if gps && self.step_s < min_step {
            return Err(invalid(
                "step_s",
                self.step_s,
                format!(
                    "at least {} s here (one sample at {} Hz, and at most {} steps in {} s), e.g. 1",
                    Num(min_step),
                    Num(fs_hz),
                    SEARCH_STEPS_MAX,
                    Num(duration_s)
                ),
            ));
        }
        Ok(())
    }
}

/// Why a stretch of the recording holds no record.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum SkipReason {
    /// Standing or creeping (GPS speed below `min_speed_kmh`).
    Stop,
    /// Speed falling by more than the tolerance.
    Braking,
    /// Speed rising by more than the tolerance.
    Accelerating,
    /// Heading changing by more than `max_heading_change_deg`.
    Turn,
    /// No GPS fix close enough (gap above `max_gps_gap_s`, or outside the track).
    NoGps,
    /// Low broadband vibration: standing with the engine idling or off.
    StopOrIdle,
    /// Strong low-frequency longitudinal/lateral acceleration.
    Manoeuvre,
    /// Next to a stop or manoeuvre (`guard_s`).
    Transition,
    /// A steady stretch shorter than one record, or the end of the recording.
    Remainder,
}

/// A stretch of the recording without records.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct SkippedSpan {
    /// Start, s after the recording's start.
    pub start_s: f64,
    /// End, s.
    pub end_s: f64,
    /// Why.
    pub reason: SkipReason,
}

/// One record of the segmentation.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct SegmentRecord {
    /// File written for it (by [`write_segments`]), relative to the output folder.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub file: Option<String>,
    /// First frame in the recording.
    pub start_frame: u64,
    /// Frames.
    pub n_frames: usize,
    /// Start, duration, absolute time, mean speed, position.
    #[serde(flatten)]
    pub meta: RecordMeta,
    /// Mean heading from the GPS track, degrees from north (clockwise).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub heading_deg: Option<f64>,
}

/// What the GPS track contributed.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct GpsSummary {
    /// The track file.
    pub path: String,
    /// Its format.
    pub format: TrackFormat,
    /// Fixes read.
    pub n_fixes: usize,
    /// NMEA sentences that could not be parsed (bad checksum, malformed), skipped.
    pub n_bad_sentences: usize,
    /// NMEA sentences of other types (GSV, VTG...), ignored.
    pub n_other_sentences: usize,
    /// NMEA RMC/GGA sentences without a fix, by reason (e.g. "RMC without a date"), skipped.
    #[serde(default, skip_serializing_if = "BTreeMap::is_empty")]
    pub incomplete_sentences: BTreeMap<String, usize>,
    /// Fixes dropped as invalid (time, latitude, longitude or speed not finite or out of
    /// range), by reason; `n_fixes` counts the fixes kept.
    #[serde(default)]
    pub dropped_fixes: BTreeMap<String, usize>,
    /// How GPS times were mapped onto the recording.
    pub alignment: GpsAlignment,
    /// The part of the recording the track covers, s.
    pub covered_s: [f64; 2],
    /// The track's speed over the recording: `[time in the recording s, speed km/h]` of the
    /// fixes inside it (at most [`SPEED_TRACE_MAX_POINTS`], evenly thinned), for the report's
    /// speed-over-time figure.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub speed_trace: Vec<[f64; 2]>,
}

/// Most points of [`GpsSummary::speed_trace`] (a day at 1 Hz thinned to a drawable line).
pub const SPEED_TRACE_MAX_POINTS: usize = 4000;

/// How a recording was cut into records.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
#[non_exhaustive]
pub enum SegmentMethod {
    /// Where a GPS track says the speed is steady and the heading nearly constant.
    Gps,
    /// Where the vibration itself shows no stop, idling or strong manoeuvre.
    Vibration,
    /// Consecutive records from the start, stops and idling included.
    Fixed,
}

impl std::fmt::Display for SegmentMethod {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            SegmentMethod::Gps => "by GPS (steady speed and heading)",
            SegmentMethod::Vibration => "by the vibration (stops, idling and strong manoeuvres skipped)",
            SegmentMethod::Fixed => {
                "into consecutive windows (no GPS track and no vibration test: stops and idling are kept)"
            }
        })
    }
}

/// The result: records to cut and the skipped stretches, written as `segments.json`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Segmentation {
    /// The recording.
    pub source: String,
    /// How the records were cut (`"gps"`, `"vibration"` or `"fixed"` in the JSON).
    pub method: SegmentMethod,
    /// Record length, s.
    pub record_length_s: f64,
    /// Sampling rate, Hz.
    pub fs_hz: f64,
    /// Recording duration, s.
    pub duration_s: f64,
    /// Absolute start of the recording, when known (RFC 3339).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub start_time: Option<String>,
    /// Settings used.
    pub params: SegmentParams,
    /// The GPS track, when one was used.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub gps: Option<GpsSummary>,
    /// The records, in time order.
    pub records: Vec<SegmentRecord>,
    /// The stretches without records, in time order, with the reason.
    pub skipped: Vec<SkippedSpan>,
    /// Seconds skipped per reason.
    pub skipped_s_by_reason: std::collections::BTreeMap<String, f64>,
}

impl Segmentation {
    /// The records as windows for [`vibmode_signal::StreamRecords::windows`].
    pub fn windows(&self) -> Vec<RecordWindow> {
        self.records
            .iter()
            .map(|r| RecordWindow {
                start_frame: r.start_frame,
                n_frames: r.n_frames,
                meta: r.meta.clone(),
            })
            .collect()
    }

    /// One line: the recording, its length, the records cut and by what, the seconds skipped
    /// per reason, and what was dropped from the GPS track (printed by `vibmode segment` and
    /// `vibmode analyze`).
    pub fn summary(&self) -> String {
        let skipped: Vec<String> = self
            .skipped_s_by_reason
            .iter()
            .map(|(k, v)| format!("{k} {v:.1} s"))
            .collect();
        let gps = self
            .gps
            .as_ref()
            .map(|g| {
                let dropped: usize = g.dropped_fixes.values().sum();
                let incomplete: usize = g.incomplete_sentences.values().sum();
                let mut t = format!(
                    "; GPS: {} fixes, {} unparseable sentences skipped",
                    g.n_fixes, g.n_bad_sentences
                );
                if incomplete > 0 {
                    t += &format!(", {incomplete} sentences without a fix skipped");
                }
                if dropped > 0 {
                    t += &format!(", {dropped} invalid fixes dropped");
                }
                t
            })
            .unwrap_or_default();
        format!(
            "{}: {:.1} s, {} records of {} s cut {}; skipped: {}{}",
            self.source,
            self.duration_s,
            self.records.len(),
            self.record_length_s,
            self.method,
            if skipped.is_empty() {
                "nothing".to_string()
            } else {
                skipped.join(", ")
            },
            gps
        )
    }

    pub(crate) fn tally(&mut self) {
        // A record rounded past the last frame is dropped.
        let total = (self.duration_s * self.fs_hz).round() as u64;
        self.records
            .retain(|r| r.start_frame + r.n_frames as u64 <= total);
        self.skipped_s_by_reason.clear();
        for s in &self.skipped {
            let key = serde_json::to_value(s.reason)
                .ok()
                .and_then(|v| v.as_str().map(str::to_string))
                .unwrap_or_default();
            *self.skipped_s_by_reason.entry(key).or_insert(0.0) += s.end_s - s.start_s;
        }
    }
}

/// Appends a skipped span, merging it with the previous one when they touch and agree.
pub(crate) fn push_skip(
    spans: &mut Vec<SkippedSpan>,
    start_s: f64,
    end_s: f64,
    reason: SkipReason,
) {
    if end_s <= start_s {
        return;
    }
    if let Some(last) = spans.last_mut() {
        if last.reason == reason && (start_s - last.end_s).abs() < 1e-9 {
            last.end_s = end_s;
            return;
        }
    }
    spans.push(SkippedSpan {
        start_s,
        end_s,
        reason,
    });
}

/// Errors of segmentation; one line each, naming the value and the fix (never a command-line
/// flag).
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum SegmentError {
    /// A GPS track that cannot be read.
    #[error("cannot read GPS track {path}: {message}; check the path and permissions")]
    Io {
        /// The file.
        path: String,
        /// The system's message.
        message: String,
    },
    /// A GPS track in a format that cannot be parsed.
    #[error("GPS track {path}: {problem}")]
    Track {
        /// The file.
        path: String,
        /// What is wrong, with the values, and how to fix it.
        problem: TrackProblem,
    },
    /// A track without usable fixes.
    #[error("GPS track {path} has no usable fix (with time, latitude and longitude){detail}; check the file and its format")]
    NoFixes {
        /// The file.
        path: String,
        /// Counts of what was found.
        detail: String,
    },
    /// More than [`DROPPED_FIXES_MAX_REL`] of the fixes invalid.
    #[error("GPS track {path}: {n_dropped} of {n_read} fixes are invalid ({reasons}); fix the track (a speed in m/s, km/h or knots as the header says; latitude within +-90, longitude within +-180 degrees)")]
    TooManyBadFixes {
        /// The file.
        path: String,
        /// Fixes dropped.
        n_dropped: usize,
        /// Fixes read.
        n_read: usize,
        /// Counts by reason, in words.
        reasons: String,
    },
    /// Time going backwards in the track.
    #[error("GPS track {path}: time goes backwards at {at} ({previous} then {value}); sort the fixes by time or remove the repeated stretch")]
    TimeBackwards {
        /// The file.
        path: String,
        /// Where (line or point number).
        at: String,
        /// The time before, as written.
        previous: String,
        /// The time after, as written.
        value: String,
    },
    /// A track that does not overlap the recording.
    #[error("GPS track {path} covers {} to {} s of the recording's time axis but the recording runs from 0 to {} s ({alignment}); they do not overlap: check the recording's start time, or give the offset between the two clocks (gps_offset_s)", num(track_start_s), num(track_end_s), num(duration_s))]
    NoOverlap {
        /// The track.
        path: String,
        /// First fix, s on the recording's axis.
        track_start_s: f64,
        /// Last fix, s.
        track_end_s: f64,
        /// Recording duration, s.
        duration_s: f64,
        /// How the times were aligned.
        alignment: String,
    },
    /// A start time that cannot be parsed.
    #[error("start time '{}' of {path} is neither an RFC 3339 time such as 2024-05-02T07:31:00Z nor seconds since 1970 (0 to 1e11); fix \"start_time\" in the sidecar", quoted(value))]
    StartTime {
        /// The file.
        path: String,
        /// The text.
        value: String,
    },
    /// A recording shorter than one record.
    #[error("{path} lasts {duration_s:.2} s, shorter than one record ({} s); give a longer recording or a shorter record length", num(record_length_s))]
    TooShort {
        /// The file.
        path: String,
        /// Its duration, s.
        duration_s: f64,
        /// The record length, s.
        record_length_s: f64,
    },
    /// A setting out of range: core's one shape of a parameter error.
    #[error("segmentation setting {0}")]
    Param(#[from] vibmode_core::ParamError),
    /// Writing the records or segments.json failed.
    #[error("cannot write {path}: {message}; check the folder and free space")]
    Write {
        /// The file.
        path: String,
        /// What failed.
        message: String,
    },
    /// Reading the recording or cutting its records failed.
    #[error(transparent)]
    Signal(#[from] vibmode_signal::SignalError),
}

/// What makes a GPS track file unreadable (the detail of [`SegmentError::Track`]); points
/// and lines are 1-based. The XML and CSV parsers' own messages are kept as their text, shortened.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum TrackProblem {
    /// Not well-formed XML.
    #[error("{message}; check that it is a valid GPX file")]
    NotXml {
        /// The XML parser's message.
        message: String,
    },
    /// XML whose root is not `<gpx>`.
    #[error("the root element is <{}>, not <gpx>; check that it is a valid GPX file", quoted(.root))]
    NotGpx {
        /// The root element's name.
        root: String,
    },
    /// A GPX point without `lat` or `lon`.
    #[error("point {point} has no {name} attribute, which makes the file invalid GPX; fix or delete that point")]
    MissingCoordinate {
        /// The point.
        point: usize,
        /// `lat` or `lon`.
        name: &'static str,
    },
    /// A GPX coordinate outside its range.
    #[error("point {point}: {name} {} is outside -{limit_deg}..{limit_deg} degrees, which makes the file invalid GPX; fix or delete that point", Num(*.value))]
    CoordinateOutOfRange {
        /// The point.
        point: usize,
        /// `lat` or `lon`.
        name: &'static str,
        /// The value, degrees.
        value: f64,
        /// The range's bound, degrees.
        limit_deg: f64,
    },
    /// A GPX coordinate or speed that is not a number.
    #[error("point {point}: {name} {} is not a number, which makes the file invalid GPX; fix or delete that point", quoted(.text))]
    PointNotANumber {
        /// The point.
        point: usize,
        /// `lat`, `lon` or `speed`.
        name: &'static str,
        /// The text.
        text: String,
    },
    /// A GPX time that is not RFC 3339.
    #[error("point {point}: time {} is not an RFC 3339 time (2024-05-02T07:31:00Z), which makes the file invalid GPX; fix or delete that point", quoted(.text))]
    PointTime {
        /// The point.
        point: usize,
        /// The text.
        text: String,
    },
    /// Two CSV columns that both read as one quantity.
    #[error("two {what} columns, '{}' and '{}'; keep one, or rename the other so that it does not read as {what}", quoted(.first), quoted(.second))]
    TwoColumns {
        /// time, latitude, longitude or speed.
        what: &'static str,
        /// The first column's name.
        first: String,
        /// The second's.
        second: String,
    },
    /// A CSV header that cannot be read.
    #[error("{message}; expected a header row like time,lat,lon,speed")]
    CsvHeader {
        /// The CSV parser's message.
        message: String,
    },
    /// A CSV header without a column the track needs.
    #[error("no {what} column in the header [{}]; name the columns time, lat, lon and (optionally) speed", quoted(&.header.join(", ")))]
    NoColumn {
        /// time, latitude or longitude.
        what: &'static str,
        /// The header's names.
        header: Vec<String>,
    },
    /// A CSV row that cannot be read.
    #[error("line {line}: {message}; check the CSV quoting")]
    CsvRow {
        /// The line.
        line: usize,
        /// The CSV parser's message.
        message: String,
    },
    /// A CSV cell that is not a number.
    #[error("line {line}: {what} '{}' is not a number; fix the cell or delete the row", quoted(.text))]
    CellNotANumber {
        /// The line.
        line: usize,
        /// latitude, longitude or speed.
        what: &'static str,
        /// The cell.
        text: String,
    },
    /// A CSV time cell that is neither seconds nor a date-time.
    #[error("line {line}: time '{}' is neither seconds nor a date-time such as 2024-05-02T07:31:00Z or 2024-05-02 07:31:00", quoted(.text))]
    CellTime {
        /// The line.
        line: usize,
        /// The cell.
        text: String,
    },
}

/// Unix seconds of an RFC 3339 time (`2024-05-02T07:31:00Z`, `2024-05-02T09:31:00.25+02:00`).
pub fn parse_rfc3339(text: &str) -> Option<f64> {
    let t = chrono::DateTime::parse_from_rfc3339(text.trim()).ok()?;
    Some(t.timestamp() as f64 + f64::from(t.timestamp_subsec_nanos()) / 1e9)
}

/// RFC 3339 (UTC, `Z`) of Unix seconds rounded to the millisecond, the fraction written only
/// when it is not zero and without trailing zeros (`07:31:00Z`, `07:31:00.5Z`, `07:31:00.125Z`);
/// `None` outside the years 0000-9999.
pub fn format_rfc3339(unix_s: f64) -> Option<String> {
    use chrono::Datelike;
    let ms = (unix_s * 1e3).round();
    if !ms.is_finite() || ms.abs() > 1e15 {
        return None;
    }
    let t = chrono::DateTime::from_timestamp_millis(ms as i64)?;
    if !(0..=9999).contains(&t.year()) {
        return None;
    }
    let mut out = t.format("%Y-%m-%dT%H:%M:%S").to_string();
    let frac = t.timestamp_subsec_millis();
    if frac != 0 {
        let digits = format!("{frac:03}");
        out.push('.');
        out.push_str(digits.trim_end_matches('0'));
    }
    out.push('Z');
    Some(out)
}

#[cfg(test)]
mod rfc3339_tests {
    use super::*;

    /// By hand: 2024-05-02T07:31:00Z is 19845 days after 1970-01-01, plus 7 h 31 min.
    #[test]
    fn rfc3339_by_hand() {
        let t0 = 19845.0 * 86400.0 + 7.0 * 3600.0 + 31.0 * 60.0;
        assert_eq!(t0, 1714635060.0);
        assert_eq!(parse_rfc3339("2024-05-02T07:31:00Z"), Some(t0));
        assert_eq!(
            parse_rfc3339(" 2024-05-02T09:31:00.5+02:00 "),
            Some(t0 + 0.5)
        );
        assert_eq!(parse_rfc3339("2024-05-02 07:31"), None);
        assert_eq!(format_rfc3339(t0).as_deref(), Some("2024-05-02T07:31:00Z"));
        assert_eq!(
            format_rfc3339(t0 + 0.5).as_deref(),
            Some("2024-05-02T07:31:00.5Z")
        );
        assert_eq!(
            format_rfc3339(t0 + 0.125).as_deref(),
            Some("2024-05-02T07:31:00.125Z")
        );
        assert_eq!(
            format_rfc3339(t0 + 0.0004).as_deref(),
            Some("2024-05-02T07:31:00Z")
        );
        assert_eq!(
            format_rfc3339(-0.5).as_deref(),
            Some("1969-12-31T23:59:59.5Z")
        );
        assert_eq!(format_rfc3339(1e12), None);
        assert_eq!(format_rfc3339(f64::NAN), None);
    }

    /// Formatting then parsing gives the time back to the millisecond, over seeded random times
    /// from 1900 to 2200.
    #[test]
    fn rfc3339_round_trips_to_the_millisecond() {
        let mut x = 0x2545_f491_4f6c_dd1d_u64;
        for _ in 0..2000 {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            let u = (x >> 11) as f64 / (1u64 << 53) as f64;
            let t = -2.2e9 + u * 9.5e9;
            let s = format_rfc3339(t).unwrap();
            let back = parse_rfc3339(&s).unwrap();
            assert!(
                (back - (t * 1e3).round() / 1e3).abs() < 1e-6,
                "{t} {s} {back}"
            );
        }
    }
}

#[cfg(test)]
mod method_tests {
    use super::SegmentMethod;

    #[test]
    fn the_method_is_written_as_before_and_said_in_words() {
        for (m, json) in [
            (SegmentMethod::Gps, "\"gps\""),
            (SegmentMethod::Vibration, "\"vibration\""),
            (SegmentMethod::Fixed, "\"fixed\""),
        ] {
            assert_eq!(serde_json::to_string(&m).unwrap(), json);
            assert_eq!(serde_json::from_str::<SegmentMethod>(json).unwrap(), m);
        }
        assert!(SegmentMethod::Fixed
            .to_string()
            .contains("stops and idling are kept"));
    }
}
