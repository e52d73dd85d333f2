//! Delimited text (CSV, semicolon, tab, whitespace), read as a stream of row blocks.
//!
//! [`DelimitedReader`] sniffs the layout from the first lines (separator, header, decimal comma,
//! time column) and then yields [`Block`]s of at most `max_rows` rows, so that hours-long files can
//! be processed in bounded memory. [`crate::read_path`] uses it with one block for the whole file.
//!
//! Conventions (see `docs/formats.md`):
//! - blank lines are skipped everywhere; lines starting with `#` or `%` are skipped before the first
//!   row (comments, MATLAB-style preambles);
//! - separator: tab if the first row has a tab (unless the rows are numbers aligned with a mix of
//!   spaces and tabs), else `;` if it has one, else `,` if it has one, else runs of spaces/tabs;
//! - the first row is a header if any of its cells is not a number; otherwise columns are named
//!   `ch0`, `ch1`, ...;
//! - with `;`, tab or whitespace separators, a comma inside a number is a decimal comma
//!   (`1,5;2,25`);
//! - empty cells at the end of a row are ignored (a trailing separator on every row);
//! - cells may be surrounded by spaces and double quotes;
//! - header cells `name (unit)` or `name [unit]` give a name and a unit.
//!
//! Speed: each line is first tried by a one-pass row parser for plain numeric rows (numbers,
//! separators, spaces, trailing separators, CRLF); its numbers come from a scanner that reads
//! eight digits at a time and converts mantissas below 2^53 with powers of ten up to 10^22 by
//! one exact IEEE operation, i.e. bit for bit what `str::parse::<f64>` gives (longer numbers go
//! to `str::parse::<f64>`). Any other line (quotes, words, NaN, ragged rows, odd whitespace) is
//! parsed by the general splitter below, which also produces every error message.
//! [`DelimitedReader::read_all_parallel`] runs the same line parser on newline-aligned chunks
//! in several threads.

use crate::error::{BinaryFormat, Result, SignalError};
use crate::number::{parse_slow, scan_number, Scan};
use serde::{Deserialize, Serialize};
use std::io::BufRead;
use vibmode_core::limits::CHANNELS_MAX;
use vibmode_core::RecordingError;

/// The cell separator of a delimited text file.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum Separator {
    /// `,`
    Comma,
    /// `;`
    Semicolon,
    /// A single tab.
    Tab,
    /// One or more spaces or tabs.
    Whitespace,
}

/// True if `line` has tab-separated cells that contain spaces while all its whitespace-separated
/// tokens are numbers: a numeric row aligned with a mix of spaces and tabs.
fn mixed_whitespace_numbers(line: &[u8]) -> bool {
    let mut spans = Vec::new();
    split_spans(line, Separator::Tab, &mut spans);
    let spaced = spans.iter().any(|&(a, b)| line[a..b].contains(&b' '));
    if !spaced {
        return false;
    }
    split_spans(line, Separator::Whitespace, &mut spans);
    let mut scratch = Vec::new();
    spans
        .iter()
        .all(|&(a, b)| parse_slow(&line[a..b], true, &mut scratch).is_some())
}

/// Refuses a line with NUL or other control bytes (tab, CR and form feed aside): binary data
/// read as text would otherwise be echoed into messages.
fn check_text(line: &[u8], path: &str, line_no: usize) -> Result<()> {
    if line
        .iter()
        .any(|&b| (b < 0x20 && !matches!(b, b'\t' | b'\r' | 0x0c)) || b == 0x7f)
    {
        return Err(SignalError::NotText {
            path: path.to_string(),
            line: line_no,
        });
    }
    Ok(())
}

/// Excel's separator directive `sep=X` (optionally quoted): `Some(Some(sep))` for a separator
/// vibmode reads, `Some(None)` for another one, `None` when the line is no directive.
fn sep_directive(t: &[u8]) -> Option<Option<Separator>> {
    let t = t.strip_prefix(b"\"").unwrap_or(t);
    let t = t.strip_suffix(b"\"").unwrap_or(t);
    if t.len() < 4 || !t[..4].eq_ignore_ascii_case(b"sep=") {
        return None;
    }
    Some(match &t[4..] {
        b"," => Some(Separator::Comma),
        b";" => Some(Separator::Semicolon),
        b"\t" => Some(Separator::Tab),
        b" " | b"" => Some(Separator::Whitespace),
        _ => None,
    })
}

impl Separator {
    /// The separating byte (`,`, `;`, tab; a space for whitespace runs).
    fn byte(self) -> u8 {
        match self {
            Separator::Comma => b',',
            Separator::Semicolon => b';',
            Separator::Tab => b'\t',
            Separator::Whitespace => b' ',
        }
    }

    fn sniff(line: &[u8]) -> Separator {
        if line.contains(&b'\t') && !mixed_whitespace_numbers(line) {
            Separator::Tab
        } else if line.contains(&b';') {
            Separator::Semicolon
        } else if line.contains(&b',') {
            Separator::Comma
        } else {
            Separator::Whitespace
        }
    }
}

/// One column of a delimited file, as described by its header.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ColumnInfo {
    /// Column name without the unit (`X-Axis` from `X-Axis (m/s2)`), or `chN` without header.
    pub name: String,
    /// Unit from the header (`m/s2`), empty if none.
    pub unit: String,
    /// `Some(seconds per unit)` if this is recognised as the time column (name `time`, `t`,
    /// `time_s`, `t_s`, `time_ms`, `t_ms`, `timestamp`, case-insensitive; unit s, ms, us, ns, min, h).
    pub time_scale_s: Option<f64>,
    /// True for a row counter as pandas' `DataFrame.to_csv` writes its index: the first column of
    /// a header whose cell is empty or `Unnamed: 0` (every other column named), its first value
    /// 0 or 1. It is not a channel; its values must count up by one
    /// ([`check_row_index`]).
    #[serde(default)]
    pub row_index: bool,
    /// For a time column written as text rather than numbers: how its cells are read (their
    /// values are then seconds).
    #[serde(default)]
    pub time_text: Option<TimeText>,
}

/// How a time column's text cells are read as seconds.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[non_exhaustive]
pub enum TimeText {
    /// Date-times (`2026-11-27 05:00:00.000050`, pandas' `DatetimeIndex`): seconds since the
    /// first row's instant, given as Unix seconds and nanoseconds ([`parse_datetime`]).
    DateTime {
        /// The first row's instant: Unix seconds and nanoseconds.
        base: (i64, u32),
    },
    /// A number and a time unit (`0.005 sec`, MATLAB's `writetable` of a timetable whose row
    /// times are `seconds(...)`): the number times the unit's seconds ([`parse_with_unit`]).
    WithUnit,
    /// A time of day (`05:00:00.005`, as data loggers write): seconds since midnight
    /// ([`parse_time_of_day`]); a later time earlier than the one before by more than 12 h
    /// has passed midnight, unless a [`TimeText::Date`] column gives the day.
    TimeOfDay,
    /// The date of a split date and time (`Date,Time` columns: `2026-11-27,05:00:00.005`):
    /// seconds from the first row's day to this row's (whole days, [`parse_date`]), added to the
    /// time of day beside it. Not a channel and not the time column itself.
    Date {
        /// The first row's day, days since 1970-01-01.
        base_day: i64,
        /// How the column writes its dates.
        order: DateOrder,
    },
    /// The date of a split date and time whose order of day and month cannot be told from the
    /// first row (`05/11/2026`: 5 November or May 11): not a channel, and not read; the times of
    /// day beside it pass midnight as in [`TimeText::TimeOfDay`] and the absolute start is
    /// unknown.
    UndecidedDate,
    /// A date with slashes and a time of day in one cell (`11/27/2026 08:00:00.005`,
    /// `27/11/2026 8:00:00 AM`, as spreadsheets of US or UK locale write): the time of day,
    /// passing midnight as in [`TimeText::TimeOfDay`]; the first row's day when the order of day
    /// and month can be told from it (a part above 12, or both equal), else unknown.
    SlashDateTime {
        /// The first row's day, days since 1970-01-01, when its order is known.
        first_day: Option<i64>,
    },
}

/// How a date writes its year, month and day.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[non_exhaustive]
pub enum DateOrder {
    /// `2026-11-27`, `2026/11/27` (ISO 8601).
    YearMonthDay,
    /// `27.11.2026`, `27/11/2026`.
    DayMonthYear,
    /// `11/27/2026` (US).
    MonthDayYear,
}

impl TimeText {
    /// Seconds of a cell; `None` when it is not of this kind.
    fn seconds(&self, cell: &[u8]) -> Option<f64> {
        match *self {
            TimeText::DateTime { base } => parse_datetime(cell).map(|t| seconds_since(t, base)),
            TimeText::WithUnit => parse_with_unit(cell),
            TimeText::TimeOfDay => parse_time_of_day(cell),
            TimeText::Date { base_day, order } => {
                parse_date_in(cell, order).map(|d| (d - base_day) as f64 * 86_400.0)
            }
            TimeText::UndecidedDate => slash_date_parts(cell).map(|_| 0.0),
            TimeText::SlashDateTime { .. } => parse_slash_datetime(cell).map(|(_, t)| t),
        }
    }

    /// True for a time of day that passes midnight when it steps back by more than 12 h (no
    /// date column gives its days).
    fn is_time_of_day(&self) -> bool {
        matches!(self, TimeText::TimeOfDay | TimeText::SlashDateTime { .. })
    }

    /// The kind of a time column's first cell, when it is text of a known kind.
    fn of_cell(cell: &[u8]) -> Option<TimeText> {
        if let Some(base) = parse_datetime(cell) {
            return Some(TimeText::DateTime { base });
        }
        if parse_time_of_day(cell).is_some() {
            return Some(TimeText::TimeOfDay);
        }
        if let Some(((a, b, year), _)) = parse_slash_datetime(cell) {
            let first_day = slash_order(a, b).and_then(|o| day_number(year, a, b, o));
            return Some(TimeText::SlashDateTime { first_day });
        }
        parse_with_unit(cell).map(|_| TimeText::WithUnit)
    }
}

/// The two leading numbers and the year of a date `NN/NN/YYYY` (one or two digits each part);
/// `None` for anything else.
fn slash_date_parts(cell: &[u8]) -> Option<(u32, u32, i32)> {
    let text = std::str::from_utf8(trim_cell(cell)).ok()?;
    let mut parts = text.split('/');
    let (a, b, y) = (parts.next()?, parts.next()?, parts.next()?);
    let short = |p: &str| (1..=2).contains(&p.len()) && p.bytes().all(|c| c.is_ascii_digit());
    if parts.next().is_some() || !short(a) || !short(b) || y.len() != 4 {
        return None;
    }
    Some((a.parse().ok()?, b.parse().ok()?, y.parse().ok()?))
}

/// The order of a slash date's first two numbers `a/b`: day first when `a` cannot be a month,
/// month first when `b` cannot be (or when both are equal: the same day either way); `None`
/// when both could be either (`05/11`).
fn slash_order(a: u32, b: u32) -> Option<DateOrder> {
    if a > 12 && b <= 12 {
        Some(DateOrder::DayMonthYear)
    } else if b > 12 && a <= 12 || a == b {
        Some(DateOrder::MonthDayYear)
    } else {
        None
    }
}

/// Days since 1970-01-01 of the slash date `a/b/year` read in `order`; `None` for no such day.
fn day_number(year: i32, a: u32, b: u32, order: DateOrder) -> Option<i64> {
    let (month, day) = match order {
        DateOrder::MonthDayYear => (a, b),
        _ => (b, a),
    };
    let epoch = chrono::NaiveDate::from_ymd_opt(1970, 1, 1)?;
    Some((chrono::NaiveDate::from_ymd_opt(year, month, day)? - epoch).num_days())
}

/// A slash date and a time of day in one cell, `NN/NN/YYYY HH:MM:SS[.fff][ AM|PM]`: the date's
/// parts ([`slash_date_parts`]) and the seconds since midnight ([`parse_time_of_day`]).
fn parse_slash_datetime(cell: &[u8]) -> Option<((u32, u32, i32), f64)> {
    let text = trim_cell(cell);
    let gap = text.iter().position(u8::is_ascii_whitespace)?;
    let date = slash_date_parts(&text[..gap])?;
    Some((date, parse_time_of_day(&text[gap + 1..])?))
}

/// Seconds since midnight of a time of day `HH:MM:SS` or `HH:MM:SS.fff` (or `,fff`; 24-hour
/// clock, one or two digits for the hour), or the same on a 12-hour clock followed by `AM` or
/// `PM` (any case); `None` for anything else.
pub fn parse_time_of_day(cell: &[u8]) -> Option<f64> {
    let text = std::str::from_utf8(trim_cell(cell)).ok()?;
    if text.len() < 7 || text.bytes().filter(|&b| b == b':').count() != 2 {
        return None;
    }
    let mut buf = [0u8; DATETIME_BYTES_MAX];
    let text = decimal_point(text, &mut buf)?;
    // A 12-hour clock ends in AM or PM (chrono reads either case); no allocation per cell.
    let twelve_hour = matches!(
        text.as_bytes(),
        [.., b'A' | b'a' | b'P' | b'p', b'M' | b'm']
    );
    let format = if twelve_hour {
        "%I:%M:%S%.f %p"
    } else {
        "%H:%M:%S%.f"
    };
    let t = chrono::NaiveTime::parse_from_str(text, format).ok()?;
    let secs = chrono::Timelike::num_seconds_from_midnight(&t);
    let nanos = chrono::Timelike::nanosecond(&t);
    Some(f64::from(secs) + f64::from(nanos) * 1e-9)
}

/// Days since 1970-01-01 of a date `YYYY-MM-DD`, `YYYY/MM/DD` or `DD.MM.YYYY`; `None` for
/// anything else (`MM/DD/YYYY` and `DD/MM/YYYY` alone cannot be told apart: see
/// [`parse_date_in`]).
pub fn parse_date(cell: &[u8]) -> Option<i64> {
    parse_date_order(cell).map(|(d, _)| d)
}

/// [`parse_date`]'s day and the order its text follows.
fn parse_date_order(cell: &[u8]) -> Option<(i64, DateOrder)> {
    let text = std::str::from_utf8(trim_cell(cell)).ok()?;
    if text.len() < 8 || text.len() > 10 {
        return None;
    }
    let epoch = chrono::NaiveDate::from_ymd_opt(1970, 1, 1)?;
    [
        ("%Y-%m-%d", DateOrder::YearMonthDay),
        ("%Y/%m/%d", DateOrder::YearMonthDay),
        ("%d.%m.%Y", DateOrder::DayMonthYear),
    ]
    .iter()
    .find_map(|&(f, o)| {
        chrono::NaiveDate::parse_from_str(text, f)
            .ok()
            .map(|d| ((d - epoch).num_days(), o))
    })
}

/// Days since 1970-01-01 of a date written in `order`: as [`parse_date`], and `NN/NN/YYYY` read
/// as month first ([`DateOrder::MonthDayYear`]) or day first ([`DateOrder::DayMonthYear`]).
pub fn parse_date_in(cell: &[u8], order: DateOrder) -> Option<i64> {
    if let Some((a, b, year)) = slash_date_parts(cell) {
        return match order {
            DateOrder::YearMonthDay => None,
            _ => day_number(year, a, b, order),
        };
    }
    parse_date_order(cell).and_then(|(d, o)| (o == order).then_some(d))
}

/// Seconds of a number followed by a time unit (`0.005 sec`, `1.5 s`, `20 ms`, `2 min`, `1 hr`:
/// the units of [`time_unit_seconds`]); `None` for anything else.
pub fn parse_with_unit(cell: &[u8]) -> Option<f64> {
    let text = std::str::from_utf8(trim_cell(cell)).ok()?;
    let (number, unit) = text.split_once(|c: char| c.is_ascii_whitespace())?;
    let v: f64 = number.parse().ok()?;
    let scale = time_unit_seconds(unit.trim())?;
    v.is_finite().then_some(v * scale)
}

impl ColumnInfo {
    /// True for a column that holds samples of a channel (neither time, nor the date of a split
    /// date and time, nor a row counter).
    pub fn is_channel(&self) -> bool {
        self.time_scale_s.is_none()
            && !self.row_index
            && !matches!(
                self.time_text,
                Some(TimeText::Date { .. } | TimeText::UndecidedDate)
            )
    }

    /// Seconds per unit of this time column's values: `override_s` (a user's time unit) unless
    /// the column holds date-times, whose values are seconds.
    pub fn time_scale(&self, override_s: Option<f64>) -> f64 {
        if self.time_text.is_some() {
            1.0
        } else {
            override_s.or(self.time_scale_s).unwrap_or(1.0)
        }
    }
}

/// The instant of a date-time cell as Unix seconds and nanoseconds: ISO 8601 / RFC 3339 with `T`
/// or a space between date and time, optional fraction of a second, and an optional `Z` or
/// `+hh:mm` offset (without one the time is taken as UTC; only differences are used):
/// `2026-11-27 05:00:00`, `2026-11-27T05:00:00.000050`, `2026-11-27 05:00:00.25+01:00`; or a
/// European `DD.MM.YYYY HH:MM:SS[.fff]` (`27.11.2026 05:00:00`). The fraction may follow a
/// decimal comma (`05:00:00,25`, as ISO 8601 allows and European software writes).
pub fn parse_datetime(cell: &[u8]) -> Option<(i64, u32)> {
    let text = std::str::from_utf8(trim_cell(cell)).ok()?;
    // The shortest form is `YYYY-MM-DD HH:MM:SS` (`D.M.YYYY HH:MM:SS`); a plain number is never a
    // date-time.
    if text.len() < 16 {
        return None;
    }
    let mut buf = [0u8; DATETIME_BYTES_MAX];
    let text = decimal_point(text, &mut buf)?;
    let utc = |t: chrono::NaiveDateTime| {
        let t = t.and_utc();
        (t.timestamp(), t.timestamp_subsec_nanos())
    };
    if text.as_bytes().get(4) != Some(&b'-') {
        // `DD.MM.YYYY HH:MM:SS[.fff]`.
        let (date, time) = text.split_once(|c: char| c.is_ascii_whitespace())?;
        let date = chrono::NaiveDate::parse_from_str(date, "%d.%m.%Y").ok()?;
        let time = chrono::NaiveTime::parse_from_str(time.trim_start(), "%H:%M:%S%.f").ok()?;
        return Some(utc(date.and_time(time)));
    }
    if let Ok(t) = chrono::DateTime::parse_from_rfc3339(text) {
        return Some((t.timestamp(), t.timestamp_subsec_nanos()));
    }
    ["%Y-%m-%d %H:%M:%S%.f", "%Y-%m-%dT%H:%M:%S%.f"]
        .iter()
        .find_map(|f| chrono::NaiveDateTime::parse_from_str(text, f).ok())
        .map(utc)
}

/// The longest date-time or time-of-day cell read ([`parse_datetime`]): an RFC 3339 instant
/// with nanoseconds and an offset is 35 bytes.
const DATETIME_BYTES_MAX: usize = 48;

/// `text` with the decimal comma of its seconds (`05:00:00,005`) made a point, copied into `buf`;
/// `text` itself when it has no comma; `None` when it has more than one, or is longer than `buf`.
fn decimal_point<'b>(text: &'b str, buf: &'b mut [u8; DATETIME_BYTES_MAX]) -> Option<&'b str> {
    match text.bytes().filter(|&b| b == b',').count() {
        0 => Some(text),
        1 if text.len() <= buf.len() => {
            let out = &mut buf[..text.len()];
            out.copy_from_slice(text.as_bytes());
            for b in out.iter_mut().filter(|b| **b == b',') {
                *b = b'.';
            }
            std::str::from_utf8(out).ok()
        }
        _ => None,
    }
}

/// Seconds from `base` to `t` (both Unix seconds and nanoseconds), exact to the nanosecond for
/// spans of up to about 100 days.
fn seconds_since(t: (i64, u32), base: (i64, u32)) -> f64 {
    let ns = i128::from(t.0 - base.0) * 1_000_000_000 + i128::from(t.1) - i128::from(base.1);
    ns as f64 * 1e-9
}

/// Checks that a row-index column ([`ColumnInfo::row_index`]) counts up by one from `first`
/// (the value expected at `values[0]`); `lines[k]` (when given) is the file line of row `k`.
/// Returns the next value expected after `values`.
pub fn check_row_index(
    path: &str,
    column: &ColumnInfo,
    first: f64,
    values: &[f64],
    lines: &[usize],
) -> Result<f64> {
    let mut expected = first;
    for (k, &v) in values.iter().enumerate() {
        if v != expected {
            return Err(SignalError::NotARowIndex {
                path: path.to_string(),
                column: column.name.clone(),
                line: lines.get(k).copied().unwrap_or(0),
                value: v,
                expected,
            });
        }
        expected += 1.0;
    }
    Ok(expected)
}

/// A block of consecutive data rows, stored column by column.
#[derive(Clone, Debug, PartialEq)]
pub struct Block {
    /// 1-based line number of the first row of the block.
    pub first_line: usize,
    /// `columns[c][r]` is the value of column `c` (as in [`DelimitedReader::columns`]) on row `r`
    /// of the block. Values are as written in the file (time not yet scaled to seconds).
    pub columns: Vec<Vec<f64>>,
    /// 1-based line number of each row (needed for error messages about the time column).
    pub lines: Vec<usize>,
}

/// Drops values pushed for a row that was then not accepted (columns longer than `lines`).
#[inline]
fn truncate_rows(block: &mut Block) {
    let n = block.lines.len();
    for c in &mut block.columns {
        c.truncate(n);
    }
}

impl Block {
    /// An empty block of `n_columns` columns with room for `rows` rows.
    fn with_capacity(n_columns: usize, rows: usize) -> Block {
        Block {
            first_line: 0,
            columns: (0..n_columns).map(|_| Vec::with_capacity(rows)).collect(),
            lines: Vec::with_capacity(rows),
        }
    }

    /// Number of rows in the block.
    pub fn n_rows(&self) -> usize {
        self.lines.len()
    }
}

/// Streaming reader of delimited numeric text. See the module documentation for the conventions.
pub struct DelimitedReader<R: BufRead> {
    reader: R,
    path: String,
    sep: Separator,
    decimal_comma: bool,
    columns: Vec<ColumnInfo>,
    has_header: bool,
    /// The line the column count comes from (header or first data row), 1-based.
    reference_line: usize,
    line_no: usize,
    pending: Option<(usize, Vec<u8>)>,
    buf: Vec<u8>,
    spans: Vec<(usize, usize)>,
    scratch: Vec<u8>,
    /// Times of day without a date column: whole days passed (s) and the last time read.
    day_offset_s: f64,
    last_time_of_day_s: f64,
}

impl<R: BufRead> std::fmt::Debug for DelimitedReader<R> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("DelimitedReader")
            .field("path", &self.path)
            .field("sep", &self.sep)
            .field("decimal_comma", &self.decimal_comma)
            .field("columns", &self.columns)
            .field("line_no", &self.line_no)
            .finish()
    }
}

#[inline]
fn trim_cell(mut s: &[u8]) -> &[u8] {
    let plain = |b: &u8| !b.is_ascii_whitespace() && *b != b'"';
    match (s.first(), s.last()) {
        (Some(f), Some(l)) if plain(f) && plain(l) => return s,
        (None, _) => return s,
        _ => {}
    }
    while let [first, rest @ ..] = s {
        if first.is_ascii_whitespace() || *first == b'"' {
            s = rest;
        } else {
            break;
        }
    }
    while let [rest @ .., last] = s {
        if last.is_ascii_whitespace() || *last == b'"' {
            s = rest;
        } else {
            break;
        }
    }
    s
}

/// Splits `line` into cell spans (trimmed of spaces and quotes); trailing empty cells removed.
fn split_spans(line: &[u8], sep: Separator, spans: &mut Vec<(usize, usize)>) {
    spans.clear();
    let push = |spans: &mut Vec<(usize, usize)>, a: usize, b: usize| {
        let cell = &line[a..b];
        let t = trim_cell(cell);
        let start = a + (t.as_ptr() as usize - cell.as_ptr() as usize);
        spans.push((start, start + t.len()));
    };
    match sep {
        Separator::Whitespace => {
            let mut i = 0;
            let n = line.len();
            while i < n {
                while i < n && (line[i] == b' ' || line[i] == b'\t') {
                    i += 1;
                }
                if i >= n {
                    break;
                }
                let a = i;
                while i < n && line[i] != b' ' && line[i] != b'\t' {
                    i += 1;
                }
                push(spans, a, i);
            }
        }
        _ => {
            let c = match sep {
                Separator::Comma => b',',
                Separator::Semicolon => b';',
                _ => b'\t',
            };
            let mut a = 0;
            while let Some(i) = line[a..].iter().position(|&b| b == c) {
                push(spans, a, a + i);
                a += i + 1;
            }
            push(spans, a, line.len());
        }
    }
    while let Some(&(a, b)) = spans.last() {
        if a == b {
            spans.pop();
        } else {
            break;
        }
    }
}

/// Splits `X-Axis (m/s2)` into (`X-Axis`, `m/s2`) and `Z [m/s^2]` into (`Z`, `m/s^2`).
pub fn split_name_unit(header: &str) -> (String, String) {
    let h = header.trim();
    for (open, close) in [('(', ')'), ('[', ']')] {
        if h.ends_with(close) {
            if let Some(pos) = h.rfind(open) {
                let name = h[..pos].trim();
                let unit = h[pos + 1..h.len() - 1].trim();
                if !name.is_empty() {
                    return (name.to_string(), unit.to_string());
                }
            }
        }
    }
    (h.to_string(), String::new())
}

/// Seconds per unit of the time column a header cell names (`time`, `Time (ms)`, `t_s`,
/// `timestamp_ms`: the rule of [`ColumnInfo::time_scale_s`]); `None` when it names no time column.
pub fn time_column_scale(header: &str) -> Option<f64> {
    let (name, unit) = split_name_unit(header);
    time_scale(&name, &unit)
}

/// Seconds per unit of a time unit's name (`s`, `ms`, `us`/`µs`, `ns`, `min`, `h` and their
/// spellings), case-insensitive; `None` for anything else.
pub fn time_unit_seconds(unit: &str) -> Option<f64> {
    match unit.trim().to_lowercase().as_str() {
        "s" | "sec" | "secs" | "second" | "seconds" => Some(1.0),
        "ms" | "msec" => Some(1e-3),
        "us" | "µs" | "μs" | "usec" => Some(1e-6),
        "ns" => Some(1e-9),
        "min" => Some(60.0),
        "h" | "hr" => Some(3600.0),
        _ => None,
    }
}

/// Seconds per unit if `name`/`unit` denote a time column: a base name `time`, `t`,
/// `timestamp`, `zeit`, or a Unix time's `epoch`, `epoch_time`, `unix`, `unixtime`, `unix_time`,
/// optionally with a unit suffix `_s`, `_sec`, `_ms`, `_us` or `_ns`
/// (`Time_ms`, `timestamp_ms`), case-insensitive. A unit in the header wins over the suffix; no
/// unit at all means seconds.
fn time_scale(name: &str, unit: &str) -> Option<f64> {
    let n = name.trim().to_ascii_lowercase();
    let is_base = |b: &str| {
        matches!(
            b,
            "time"
                | "t"
                | "timestamp"
                | "zeit"
                | "zeitstempel"
                | "epoch"
                | "epoch_time"
                | "unix"
                | "unixtime"
                | "unix_time"
        )
    };
    let implied = if is_base(&n) {
        None
    } else {
        let (base, suffix) = n.rsplit_once('_')?;
        if !is_base(base) {
            return None;
        }
        match suffix {
            "s" | "sec" => Some(1.0),
            "ms" => Some(1e-3),
            "us" => Some(1e-6),
            "ns" => Some(1e-9),
            _ => return None,
        }
    };
    let from_unit = if unit.trim().is_empty() {
        None
    } else {
        Some(time_unit_seconds(unit)?)
    };
    Some(from_unit.or(implied).unwrap_or(1.0))
}

fn header_columns(line: &[u8], spans: &[(usize, usize)]) -> Vec<ColumnInfo> {
    spans
        .iter()
        .enumerate()
        .map(|(i, &(a, b))| {
            let text = String::from_utf8_lossy(&line[a..b]).to_string();
            let (name, unit) = split_name_unit(&text);
            let name = if name.is_empty() {
                format!("ch{i}")
            } else {
                name
            };
            let time_scale_s = time_scale(&name, &unit);
            ColumnInfo {
                name,
                unit,
                time_scale_s,
                row_index: false,
                time_text: None,
            }
        })
        .collect()
}

/// Longest cell of a units row, in bytes.
const UNIT_CELL_MAX: usize = 24;

/// Reads `line` as a units row below the header (`s,m/s^2,m/s^2`, as data loggers export;
/// cells may be bracketed, `[s]`, `(g)`) and gives each column whose header named no unit its
/// unit, when the row has a cell per column, none of them a number or a date-time or longer than
/// [`UNIT_CELL_MAX`], and every time column's unit is a time unit (or empty); `false` (columns
/// untouched) otherwise.
fn apply_units_row(columns: &mut [ColumnInfo], line: &[u8], sep: Separator) -> bool {
    let mut spans = Vec::new();
    split_spans(line, sep, &mut spans);
    if spans.len() != columns.len() {
        return false;
    }
    let mut scratch = Vec::new();
    let mut units = Vec::with_capacity(spans.len());
    for &(a, b) in &spans {
        let cell = &line[a..b];
        if cell.len() > UNIT_CELL_MAX
            || parse_slow(cell, sep != Separator::Comma, &mut scratch).is_some()
            || parse_datetime(cell).is_some()
        {
            return false;
        }
        let Ok(text) = std::str::from_utf8(cell) else {
            return false;
        };
        let text = text.trim();
        let bare = text
            .strip_prefix('[')
            .and_then(|t| t.strip_suffix(']'))
            .or_else(|| text.strip_prefix('(').and_then(|t| t.strip_suffix(')')))
            .unwrap_or(text)
            .trim();
        units.push(bare.to_string());
    }
    if units.iter().all(String::is_empty) {
        return false;
    }
    let merged: Vec<String> = columns
        .iter()
        .zip(&units)
        .map(|(c, u)| {
            if c.unit.is_empty() {
                u.clone()
            } else {
                c.unit.clone()
            }
        })
        .collect();
    let scales: Vec<Option<f64>> = columns
        .iter()
        .zip(&merged)
        .map(|(c, u)| time_scale(&c.name, u))
        .collect();
    // A time column must stay one: its unit cell names a time unit.
    if columns
        .iter()
        .zip(&scales)
        .any(|(c, s)| c.time_scale_s.is_some() && s.is_none())
    {
        return false;
    }
    for ((c, u), s) in columns.iter_mut().zip(merged).zip(scales) {
        c.unit = u;
        c.time_scale_s = s;
    }
    true
}

/// The columns named by a comment line (numpy's `savetxt(..., header="time,a,b")` writes
/// `# time,a,b`): when it splits into `n` cells with the data's separator and one of them at
/// least is not a number.
fn comment_header(
    text: &[u8],
    sep: Separator,
    n: usize,
    allow_comma: bool,
) -> Option<Vec<ColumnInfo>> {
    let mut spans = Vec::new();
    split_spans(text, sep, &mut spans);
    let mut scratch = Vec::new();
    let named = spans
        .iter()
        .any(|&(a, b)| parse_slow(&text[a..b], allow_comma, &mut scratch).is_none());
    (spans.len() == n && named).then(|| header_columns(text, &spans))
}

/// Marks the time column written as text ([`TimeText`]): a column named as a time column (or
/// `datetime`, `date_time`, `date`, `datum`), or an unnamed first column (pandas' `DatetimeIndex`), whose
/// first data cell is a date-time ([`parse_datetime`]), or, named as a time column, a number
/// and a time unit ([`parse_with_unit`]); the first such column only.
fn mark_text_time(
    columns: &mut [ColumnInfo],
    header: &[u8],
    spans: &[(usize, usize)],
    row: &[u8],
    row_spans: &[(usize, usize)],
) {
    if spans.len() != columns.len() || row_spans.len() != columns.len() {
        return;
    }
    // A split date and time: a date column just before a time column holding times of day.
    for c in 0..columns.len().saturating_sub(1) {
        let lower = columns[c].name.to_ascii_lowercase();
        let cell = |i: usize| &row[row_spans[i].0..row_spans[i].1];
        if matches!(lower.as_str(), "date" | "datum" | "day")
            && columns[c + 1].time_scale_s.is_some()
            && parse_time_of_day(cell(c + 1)).is_some()
        {
            let date = match (parse_date_order(cell(c)), slash_date_parts(cell(c))) {
                (Some((base_day, order)), _) => Some(TimeText::Date { base_day, order }),
                (None, Some((a, b, year))) => Some(
                    slash_order(a, b)
                        .and_then(|order| {
                            let base_day = day_number(year, a, b, order)?;
                            Some(TimeText::Date { base_day, order })
                        })
                        .unwrap_or(TimeText::UndecidedDate),
                ),
                (None, None) => None,
            };
            if let Some(date) = date {
                columns[c].time_text = Some(date);
                columns[c].time_scale_s = None;
                columns[c + 1].time_text = Some(TimeText::TimeOfDay);
                columns[c + 1].time_scale_s = Some(1.0);
                return;
            }
        }
    }
    for (c, col) in columns.iter_mut().enumerate() {
        let (a, b) = spans[c];
        let head = trim_cell(&header[a..b]);
        let lower = col.name.to_ascii_lowercase();
        let named = col.time_scale_s.is_some()
            || matches!(lower.as_str(), "datetime" | "date_time" | "date" | "datum")
            || (c == 0 && (head.is_empty() || head.eq_ignore_ascii_case(b"Unnamed: 0")));
        if !named {
            continue;
        }
        let (ra, rb) = row_spans[c];
        // A number and a unit only in a column named as a time column.
        let kind = TimeText::of_cell(&row[ra..rb]).filter(|k| {
            matches!(
                k,
                TimeText::DateTime { .. } | TimeText::SlashDateTime { .. }
            ) || col.time_scale_s.is_some()
        });
        if let Some(kind) = kind {
            col.time_text = Some(kind);
            col.time_scale_s = Some(1.0);
            if head.is_empty() {
                col.name = "time".to_string();
            }
            return;
        }
    }
}

/// Marks the first column as a row index when it looks like pandas' `DataFrame.to_csv` index:
/// its header cell is empty (named `ch0` here) or `Unnamed: 0`, every other column is named, it is
/// not the time column, and the first data row holds 0 or 1 there.
fn mark_row_index(
    columns: &mut [ColumnInfo],
    header: &[u8],
    spans: &[(usize, usize)],
    first_value: Option<f64>,
) {
    if columns.len() < 2 || spans.len() != columns.len() {
        return;
    }
    let cell = |i: usize| {
        let (a, b) = spans[i];
        trim_cell(&header[a..b])
    };
    let first = cell(0);
    let unnamed = first.is_empty() || first.eq_ignore_ascii_case(b"Unnamed: 0");
    let others_named = (1..columns.len()).all(|i| !cell(i).is_empty());
    if unnamed
        && others_named
        && columns[0].time_scale_s.is_none()
        && matches!(first_value, Some(v) if v == 0.0 || v == 1.0)
    {
        columns[0].row_index = true;
    }
}

impl<R: BufRead> DelimitedReader<R> {
    /// Opens a stream: reads the first row(s) to find the separator, the header and the time
    /// column. `path` is only used in error messages.
    ///
    /// Errors: empty file, header without data rows, unreadable stream.
    pub fn new(reader: R, path: &str) -> Result<Self> {
        let mut r = DelimitedReader {
            reader,
            path: path.to_string(),
            sep: Separator::Whitespace,
            decimal_comma: false,
            columns: Vec::new(),
            has_header: false,
            reference_line: 0,
            line_no: 0,
            pending: None,
            buf: Vec::new(),
            spans: Vec::new(),
            scratch: Vec::new(),
            day_offset_s: 0.0,
            last_time_of_day_s: f64::NEG_INFINITY,
        };
        // A binary format a user can export from, named by its first bytes (peeked: the
        // buffer's first fill, before any line is read).
        let head = r.reader.fill_buf().map_err(|e| SignalError::Io {
            action: "read",
            path: r.path.clone(),
            message: e.to_string(),
        })?;
        if let Some(format) = BinaryFormat::sniff(&r.path, head) {
            return Err(SignalError::BinaryFormat {
                path: r.path.clone(),
                format,
            });
        }
        // Excel's `sep=X` first line, when present.
        let mut forced_sep: Option<Separator> = None;
        // The last comment line (its number and text after the comment marks), which may be
        // numpy's `savetxt(..., header=...)` header: `# time,a,b`.
        let mut last_comment: Option<(usize, Vec<u8>)> = None;
        // First content line (skipping blanks and comment lines).
        let first = loop {
            match r.next_line()? {
                None => {
                    return Err(SignalError::EmptyFile {
                        path: r.path.clone(),
                        expected: "numeric rows (optionally after one header row)",
                    })
                }
                Some(n) => {
                    let l = &r.buf;
                    if n == 1 && (l.starts_with(&[0xFF, 0xFE]) || l.starts_with(&[0xFE, 0xFF])) {
                        return Err(SignalError::Utf16Text {
                            path: r.path.clone(),
                        });
                    }
                    let l = if n == 1 && l.starts_with(&[0xEF, 0xBB, 0xBF]) {
                        &l[3..]
                    } else {
                        &l[..]
                    };
                    check_text(l, &r.path, n)?;
                    let t = trim_cell(l);
                    if t.is_empty() {
                        continue;
                    }
                    if t[0] == b'#' || t[0] == b'%' {
                        let body = t
                            .iter()
                            .position(|&b| b != b'#' && b != b'%')
                            .unwrap_or(t.len());
                        last_comment = Some((n, t[body..].to_vec()));
                        continue;
                    }
                    if forced_sep.is_none() {
                        if let Some(sep) = sep_directive(t) {
                            forced_sep =
                                Some(sep.ok_or_else(|| SignalError::UnsupportedSeparator {
                                    path: r.path.clone(),
                                    line: n,
                                    sep: String::from_utf8_lossy(&t[4..]).into_owned(),
                                })?);
                            continue;
                        }
                    }
                    break (n, l.to_vec());
                }
            }
        };
        r.sep = forced_sep.unwrap_or_else(|| Separator::sniff(&first.1));
        let mut spans = Vec::new();
        split_spans(&first.1, r.sep, &mut spans);
        if spans.len() > CHANNELS_MAX + 1 {
            return Err(RecordingError::TooManyChannels {
                what: r.path.clone(),
                count: spans.len(),
                max: CHANNELS_MAX,
            }
            .into());
        }
        let allow_comma = r.sep != Separator::Comma;
        let mut scratch = Vec::new();
        let is_header = spans
            .iter()
            .any(|&(a, b)| parse_slow(&first.1[a..b], allow_comma, &mut scratch).is_none());
        if is_header {
            r.has_header = true;
            r.reference_line = first.0;
            r.columns = header_columns(&first.1, &spans);
            // A units row may follow the header (data loggers' exports: `s,m/s^2,m/s^2`).
            let mut units_checked = false;
            // Peek the first data row for decimal commas.
            loop {
                match r.next_line()? {
                    None => {
                        return Err(SignalError::NoDataRows {
                            path: r.path.clone(),
                        })
                    }
                    Some(n) => {
                        check_text(&r.buf, &r.path, n)?;
                        if trim_cell(&r.buf).is_empty() {
                            continue;
                        }
                        if !units_checked {
                            units_checked = true;
                            if apply_units_row(&mut r.columns, &r.buf, r.sep) {
                                continue;
                            }
                        }
                        if forced_sep.is_none()
                            && r.sep == Separator::Tab
                            && mixed_whitespace_numbers(&r.buf)
                        {
                            // Data aligned with spaces and tabs: split header and rows on runs.
                            r.sep = Separator::Whitespace;
                            split_spans(&first.1, r.sep, &mut spans);
                            r.columns = header_columns(&first.1, &spans);
                        }
                        let mut row_spans = Vec::new();
                        split_spans(&r.buf, r.sep, &mut row_spans);
                        let first_value = row_spans.first().and_then(|&(a, b)| {
                            parse_slow(&r.buf[a..b], r.sep != Separator::Comma, &mut scratch)
                        });
                        mark_text_time(&mut r.columns, &first.1, &spans, &r.buf, &row_spans);
                        mark_row_index(&mut r.columns, &first.1, &spans, first_value);
                        r.pending = Some((n, r.buf.clone()));
                        break;
                    }
                }
            }
        } else if let Some(columns) = last_comment
            .filter(|(n, _)| *n + 1 == first.0)
            .and_then(|(_, text)| comment_header(&text, r.sep, spans.len(), allow_comma))
        {
            // numpy's `savetxt` header: the comment line just above the first row names its
            // columns.
            r.has_header = true;
            r.reference_line = first.0;
            r.columns = columns;
            r.pending = Some(first);
        } else {
            r.reference_line = first.0;
            r.columns = (0..spans.len())
                .map(|i| ColumnInfo {
                    name: format!("ch{i}"),
                    unit: String::new(),
                    time_scale_s: None,
                    row_index: false,
                    time_text: None,
                })
                .collect();
            r.pending = Some(first);
        }
        r.decimal_comma = allow_comma;
        r.spans = spans;
        Ok(r)
    }

    /// Reads the next raw line into `self.buf` (without the line ending); returns its number.
    fn next_line(&mut self) -> Result<Option<usize>> {
        self.buf.clear();
        let n = self
            .reader
            .read_until(b'\n', &mut self.buf)
            .map_err(|e| SignalError::Io {
                action: "read",
                path: self.path.clone(),
                message: e.to_string(),
            })?;
        if n == 0 {
            return Ok(None);
        }
        if self.buf.last() == Some(&b'\n') {
            self.buf.pop();
        }
        if self.buf.last() == Some(&b'\r') {
            self.buf.pop();
        }
        self.line_no += 1;
        Ok(Some(self.line_no))
    }

    /// The columns (including the time column, if any), in file order.
    pub fn columns(&self) -> &[ColumnInfo] {
        &self.columns
    }

    /// The detected separator.
    pub fn separator(&self) -> Separator {
        self.sep
    }

    /// True if numbers may use a decimal comma (`1,5`): the separator is not a comma.
    pub fn decimal_comma(&self) -> bool {
        self.decimal_comma
    }

    /// True if the first row was a header.
    pub fn has_header(&self) -> bool {
        self.has_header
    }

    /// The file name used in error messages.
    pub fn path(&self) -> &str {
        &self.path
    }

    /// True when the rows' line numbers are needed to name a row in an error: a time column or a
    /// row index is checked row by row after the read.
    pub fn needs_lines(&self) -> bool {
        self.time_column().is_some() || self.columns.iter().any(|c| c.row_index)
    }

    /// Index of the first column recognised as time, if any.
    pub fn time_column(&self) -> Option<usize> {
        self.columns.iter().position(|c| c.time_scale_s.is_some())
    }

    /// Reads at most `max_rows` data rows (blank lines skipped). Returns `Ok(None)` at the end of
    /// the stream. Errors on ragged rows and non-numeric cells, naming line and column.
    /// Values are not checked for NaN/Inf here. Errors if `max_rows` is 0.
    pub fn next_block(&mut self, max_rows: usize) -> Result<Option<Block>> {
        if max_rows == 0 {
            return Err(SignalError::InvalidParam {
                name: "max_rows",
                value: "0".into(),
                fix: "ask for at least 1 row per block".into(),
            });
        }
        self.next_block_reserved(max_rows, 0)
    }

    /// [`Self::next_block`] with room for `rows` rows reserved in the block's vectors (a
    /// reader that knows how many rows are coming grows them once, not by doubling).
    fn next_block_reserved(&mut self, max_rows: usize, rows: usize) -> Result<Option<Block>> {
        let nc = self.columns.len();
        let mut block = Block::with_capacity(nc, rows.min(max_rows));
        let mut ctx = RowCtx {
            path: &self.path,
            sep: self.sep,
            decimal_comma: self.decimal_comma,
            columns: &self.columns,
            reference_line: self.reference_line,
            spans: &mut self.spans,
            scratch: &mut self.scratch,
        };
        if let Some((n, line)) = self.pending.take() {
            ctx.parse_row(&line, n, &mut block)?;
        }
        while block.lines.len() < max_rows {
            // Parse the complete lines of the reader's buffer in place (for an in-memory slice
            // that is the whole rest of the file).
            let avail = self.reader.fill_buf().map_err(|e| SignalError::Io {
                action: "read",
                path: ctx.path.to_string(),
                message: e.to_string(),
            })?;
            if avail.is_empty() {
                break;
            }
            let consumed =
                ctx.parse_lines(avail, &mut self.line_no, &mut block, max_rows, false)?;
            if consumed > 0 {
                self.reader.consume(consumed);
            } else {
                // A line longer than the buffer, or the last line without a newline.
                self.buf.clear();
                let n =
                    self.reader
                        .read_until(b'\n', &mut self.buf)
                        .map_err(|e| SignalError::Io {
                            action: "read",
                            path: ctx.path.to_string(),
                            message: e.to_string(),
                        })?;
                if n == 0 {
                    break;
                }
                if self.buf.last() == Some(&b'\n') {
                    self.buf.pop();
                }
                if self.buf.is_empty() {
                    self.line_no += 1; // a blank line (parse_lines sees no line in "")
                } else {
                    ctx.parse_lines(&self.buf, &mut self.line_no, &mut block, max_rows, true)?;
                }
            }
        }
        if block.lines.is_empty() {
            Ok(None)
        } else {
            self.finish_times(&mut block);
            Ok(Some(block))
        }
    }

    /// Completes a block's times of day: the date column's days added where there is one, else
    /// the days passed at each midnight (a time more than 12 h earlier than the one before).
    fn finish_times(&mut self, block: &mut Block) {
        let Some(t) = self
            .columns
            .iter()
            .position(|c| c.time_text.is_some_and(|k| k.is_time_of_day()))
        else {
            return;
        };
        let date = self
            .columns
            .iter()
            .position(|c| matches!(c.time_text, Some(TimeText::Date { .. })));
        match date {
            Some(d) => {
                let days = std::mem::take(&mut block.columns[d]);
                for (v, day) in block.columns[t].iter_mut().zip(&days) {
                    *v += day;
                }
                block.columns[d] = days;
            }
            None => {
                for v in block.columns[t].iter_mut() {
                    if *v + self.day_offset_s < self.last_time_of_day_s - 43_200.0 {
                        self.day_offset_s += 86_400.0;
                    }
                    *v += self.day_offset_s;
                    self.last_time_of_day_s = *v;
                }
            }
        }
    }
}

impl<'s> DelimitedReader<&'s [u8]> {
    /// Reads all remaining rows of an in-memory file, splitting the work across up to `threads`
    /// threads (chunks cut at line boundaries; line numbers in errors stay exact). Gives the same
    /// result as one [`DelimitedReader::next_block`] call with `usize::MAX` rows, or `Ok(None)`
    /// if there are no rows.
    pub fn read_all_parallel(&mut self, threads: usize) -> Result<Option<Block>> {
        let rest: &'s [u8] = self.reader;
        let threads = threads.clamp(1, 64);
        if threads == 1 || rest.len() < (1 << 20) {
            return self.next_block_reserved(usize::MAX, estimate_rows(rest) + 1);
        }
        // Cut points just after a newline.
        let mut cuts = vec![0usize];
        for k in 1..threads {
            let target = rest.len() * k / threads;
            let prev = *cuts.last().unwrap_or(&0);
            if target <= prev {
                continue;
            }
            if let Some(i) = rest[target..].iter().position(|&b| b == b'\n') {
                cuts.push(target + i + 1);
            }
        }
        cuts.push(rest.len());
        cuts.dedup();
        let chunks: Vec<&[u8]> = cuts.windows(2).map(|w| &rest[w[0]..w[1]]).collect();
        let (path, sep, dc, cols, refl) = (
            self.path.as_str(),
            self.sep,
            self.decimal_comma,
            self.columns.as_slice(),
            self.reference_line,
        );
        let pending = self.pending.take();
        let line0 = self.line_no;
        // Chunk 0 (after the pending row, if any) is numbered from the real line; the other
        // chunks count their lines from 0 and are shifted once the earlier chunks' line counts
        // are known. `parse_chunk` parses one chunk whose first line is `first_line` (after the
        // pending row, if any) and returns its block and the number of lines it went through.
        let parse_chunk = |chunk: &[u8],
                           first_line: usize,
                           pending: Option<&(usize, Vec<u8>)>|
         -> Result<(Block, usize)> {
            let mut spans = Vec::new();
            let mut scratch = Vec::new();
            let mut ctx = RowCtx {
                path,
                sep,
                decimal_comma: dc,
                columns: cols,
                reference_line: refl,
                spans: &mut spans,
                scratch: &mut scratch,
            };
            let mut b = Block::with_capacity(cols.len(), estimate_rows(chunk) + 1);
            if let Some((n, l)) = pending {
                ctx.parse_row(l, *n, &mut b)?;
            }
            let mut ln = first_line;
            ctx.parse_lines(chunk, &mut ln, &mut b, usize::MAX, true)?;
            Ok((b, ln - first_line))
        };
        let parse_chunk = &parse_chunk;
        let results: Vec<Result<(Block, usize)>> = std::thread::scope(|sc| {
            let handles: Vec<_> = chunks
                .iter()
                .enumerate()
                .map(|(k, &chunk)| {
                    let pending = if k == 0 { pending.as_ref() } else { None };
                    let first_line = if k == 0 { line0 } else { 0 };
                    sc.spawn(move || parse_chunk(chunk, first_line, pending))
                })
                .collect();
            handles
                .into_iter()
                .map(|h| {
                    h.join().unwrap_or_else(|_| {
                        Err(SignalError::InvalidParam {
                            name: "parser thread",
                            value: "panicked".into(),
                            fix: "internal error; please report this as a bug".into(),
                        })
                    })
                })
                .collect()
        });
        let mut offset = line0;
        let mut blocks = Vec::with_capacity(results.len());
        for (k, r) in results.into_iter().enumerate() {
            match r {
                Ok((mut b, n_lines)) => {
                    if k > 0 {
                        b.first_line += offset;
                        for l in &mut b.lines {
                            *l += offset;
                        }
                    }
                    offset += n_lines;
                    blocks.push(b);
                }
                Err(e) if k == 0 => return Err(e),
                Err(e) => {
                    // Parse the chunk again from its real first line, for the exact line number
                    // in the message (all earlier chunks were read, so `offset` is known).
                    parse_chunk(chunks[k], offset, None)?;
                    return Err(e);
                }
            }
        }
        self.reader = &rest[rest.len()..];
        self.line_no = offset;
        let total: usize = blocks.iter().map(Block::n_rows).sum();
        let mut blocks = blocks.into_iter();
        let Some(mut all) = blocks.next() else {
            return Ok(None);
        };
        // Growing the first block's vectors in place (realloc of large blocks moves pages, not
        // bytes), then one copy of the other chunks.
        for c in &mut all.columns {
            c.reserve_exact(total - c.len());
        }
        all.lines.reserve_exact(total - all.lines.len());
        for b in blocks {
            if all.lines.is_empty() {
                all.first_line = b.first_line;
            }
            for (d, c) in all.columns.iter_mut().zip(&b.columns) {
                d.extend_from_slice(c);
            }
            all.lines.extend_from_slice(&b.lines);
        }
        if all.lines.is_empty() {
            Ok(None)
        } else {
            self.finish_times(&mut all);
            Ok(Some(all))
        }
    }
}

/// Rough number of lines in `chunk` (from the newline density of its first 64 KiB), to reserve
/// the column vectors once instead of growing them by doubling.
fn estimate_rows(chunk: &[u8]) -> usize {
    let head = &chunk[..chunk.len().min(1 << 16)];
    let n = head.iter().filter(|&&b| b == b'\n').count().max(1);
    let per_line = head.len() / n;
    let est = chunk.len() / per_line.max(1);
    est + est / 32 + 16
}

/// Outcome of [`RowCtx::fast_row`].
enum FastRow {
    /// A row of numbers, pushed onto the block's columns (but not yet onto `lines`); the line
    /// ends at this index (its `\n`, or the end of the slice).
    Row(usize),
    /// A line with nothing but spaces, ending at this index.
    Blank(usize),
    /// Anything else (quotes, words, wrong cell count, ...): nothing was pushed, the caller
    /// parses the line with [`RowCtx::parse_row`].
    Fallback,
}

/// If a line ends at `s[i]` (`\n`, `\r\n`, a final `\r` or the end of `s`), the index of its
/// end (the `\n`, or `s.len()`).
#[inline(always)]
fn line_end(s: &[u8], i: usize) -> Option<usize> {
    match s.get(i) {
        None => Some(s.len()),
        Some(b'\n') => Some(i),
        Some(b'\r') => match s.get(i + 1) {
            None | Some(b'\n') => Some(i + 1),
            _ => None,
        },
        _ => None,
    }
}

/// What parsing one row needs (borrowed from the reader, so that rows can be parsed directly
/// from the reader's buffer).
struct RowCtx<'a> {
    path: &'a str,
    sep: Separator,
    decimal_comma: bool,
    columns: &'a [ColumnInfo],
    reference_line: usize,
    spans: &'a mut Vec<(usize, usize)>,
    scratch: &'a mut Vec<u8>,
}

impl RowCtx<'_> {
    /// Parses the lines of `buf` into `block` until it holds `max_rows` rows; blank lines are
    /// skipped. `line_no` is the number of the line before the first line of `buf` and is
    /// advanced per line. With `complete` false, a last line without `\n` is left alone (the
    /// rest of it may not be in `buf` yet). Returns the number of bytes consumed.
    fn parse_lines(
        &mut self,
        buf: &[u8],
        line_no: &mut usize,
        block: &mut Block,
        max_rows: usize,
        complete: bool,
    ) -> Result<usize> {
        let mut pos = 0;
        while pos < buf.len() && block.lines.len() < max_rows {
            let rest = &buf[pos..];
            let end = match self.fast_row(rest, block) {
                FastRow::Row(end) => {
                    if !complete && end == rest.len() {
                        truncate_rows(block);
                        break;
                    }
                    *line_no += 1;
                    if block.lines.is_empty() {
                        block.first_line = *line_no;
                    }
                    block.lines.push(*line_no);
                    end
                }
                FastRow::Blank(end) => {
                    if !complete && end == rest.len() {
                        break;
                    }
                    *line_no += 1;
                    end
                }
                FastRow::Fallback => {
                    let end = match rest.iter().position(|&b| b == b'\n') {
                        Some(i) => i,
                        None if complete => rest.len(),
                        None => break,
                    };
                    let line = match &rest[..end] {
                        [head @ .., b'\r'] => head,
                        l => l,
                    };
                    *line_no += 1;
                    self.parse_row(line, *line_no, block)?;
                    end
                }
            };
            pos += end + 1;
        }
        Ok(pos.min(buf.len()))
    }

    /// Parses the line at the start of `s` if it is plain: numbers separated by the separator,
    /// padded with spaces (and tabs unless they separate), trailing empty cells, ended by
    /// `\n`, `\r\n` or the end of `s`. Gives exactly what [`RowCtx::parse_row`] gives on such a
    /// line; everything else is [`FastRow::Fallback`] (with nothing pushed).
    #[inline]
    fn fast_row(&mut self, s: &[u8], block: &mut Block) -> FastRow {
        let ws = self.sep == Separator::Whitespace;
        let sep = match self.sep {
            Separator::Comma => b',',
            Separator::Semicolon => b';',
            Separator::Tab | Separator::Whitespace => b'\t',
        };
        // Padding that trimming removes and that does not separate cells.
        let tab_pads = self.sep != Separator::Tab;
        let is_pad = |b: u8| b == b' ' || (tab_pads && b == b'\t');
        let skip_pad = |mut i: usize| {
            while let Some(&b) = s.get(i) {
                if !is_pad(b) {
                    break;
                }
                i += 1;
            }
            i
        };
        let dc = self.decimal_comma;
        let nc = self.columns.len();
        let mut i = skip_pad(0);
        if let Some(end) = line_end(s, i) {
            return FastRow::Blank(end);
        }
        for c in 0..nc {
            // Between cells: the separator and padding (with whitespace separators the padding
            // after the previous number is the separator, checked below).
            if c > 0 && !ws {
                if s.get(i) != Some(&sep) {
                    truncate_rows(block);
                    return FastRow::Fallback;
                }
                i = skip_pad(i + 1);
            }
            let (scan, j) = scan_number(s, i, dc);
            let v = match scan {
                Scan::Fast(v) => v,
                Scan::Slow => match parse_slow(&s[i..j], dc, self.scratch) {
                    Some(v) => v,
                    None => {
                        truncate_rows(block);
                        return FastRow::Fallback;
                    }
                },
                Scan::Invalid => {
                    truncate_rows(block);
                    return FastRow::Fallback;
                }
            };
            i = skip_pad(j);
            if ws && i == j && c + 1 < nc {
                // Two cells must be separated by spaces or tabs.
                truncate_rows(block);
                return FastRow::Fallback;
            }
            block.columns[c].push(v);
        }
        loop {
            if let Some(end) = line_end(s, i) {
                return FastRow::Row(end);
            }
            if !ws && s.get(i) == Some(&sep) {
                i = skip_pad(i + 1);
            } else {
                truncate_rows(block);
                return FastRow::Fallback;
            }
        }
    }

    /// Parses one line into `block` (blank lines are skipped).
    fn parse_row(&mut self, line: &[u8], line_no: usize, block: &mut Block) -> Result<()> {
        check_text(line, self.path, line_no)?;
        let nc = self.columns.len();
        split_spans(line, self.sep, self.spans);
        if self.spans.is_empty() {
            return Ok(());
        }
        // A row cut short by empty cells at its end (`1.5,2.0,` for three columns: a missing
        // value, as pandas writes NaN) is a missing value, not a short row.
        let cells_written = match self.sep {
            Separator::Whitespace => self.spans.len(),
            sep => line.iter().filter(|&&b| b == sep.byte()).count() + 1,
        };
        if self.spans.len() < nc && cells_written >= nc {
            return Err(SignalError::EmptyCell {
                path: self.path.to_string(),
                line: line_no,
                column: self.spans.len() + 1,
                column_name: self.columns[self.spans.len()].name.clone(),
            });
        }
        if self.spans.len() != nc {
            return Err(SignalError::RaggedRow {
                path: self.path.to_string(),
                line: line_no,
                found: self.spans.len(),
                expected: nc,
                reference_line: self.reference_line,
            });
        }
        // One UTF-8 check per line (not per cell); cells are then cut at ASCII separators.
        let text = std::str::from_utf8(line).ok();
        for (c, &(a, b)) in self.spans.iter().enumerate() {
            let cell = &line[a..b];
            let parsed = match (self.columns[c].time_text, text.and_then(|t| t.get(a..b))) {
                (Some(kind), _) => kind.seconds(cell),
                (None, Some(t)) if !self.decimal_comma => t.parse::<f64>().ok(),
                _ => parse_slow(cell, self.decimal_comma, self.scratch),
            };
            match parsed {
                Some(v) => block.columns[c].push(v),
                None if cell.is_empty() => {
                    return Err(SignalError::EmptyCell {
                        path: self.path.to_string(),
                        line: line_no,
                        column: c + 1,
                        column_name: self.columns[c].name.clone(),
                    });
                }
                None => {
                    let text: String = String::from_utf8_lossy(cell).chars().take(40).collect();
                    return Err(SignalError::NotNumeric {
                        path: self.path.to_string(),
                        line: line_no,
                        column: c + 1,
                        column_name: self.columns[c].name.clone(),
                        text,
                    });
                }
            }
        }
        if block.lines.is_empty() {
            block.first_line = line_no;
        }
        block.lines.push(line_no);
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn spans_of(line: &str, sep: Separator) -> Vec<String> {
        let mut s = Vec::new();
        split_spans(line.as_bytes(), sep, &mut s);
        s.iter().map(|&(a, b)| line[a..b].to_string()).collect()
    }

    #[test]
    fn splitting_by_hand() {
        assert_eq!(spans_of("1,2,3,", Separator::Comma), ["1", "2", "3"]);
        assert_eq!(spans_of("1, 2 ,,", Separator::Comma), ["1", "2"]);
        assert_eq!(spans_of("1,,3", Separator::Comma), ["1", "", "3"]);
        assert_eq!(
            spans_of("  1   2\t 3  ", Separator::Whitespace),
            ["1", "2", "3"]
        );
        assert_eq!(spans_of("\"a\";\"b\"", Separator::Semicolon), ["a", "b"]);
        assert_eq!(spans_of("1\t2\t", Separator::Tab), ["1", "2"]);
        assert!(spans_of("   ", Separator::Whitespace).is_empty());
    }

    /// By hand: 2026-11-27 is day 20784 after 1970-01-01, so 04:00:00.25 UTC is
    /// 20784 * 86400 + 4 * 3600 + 0.25 = 1795752000.25 s.
    #[test]
    fn date_times_by_hand() {
        let t = (1_795_752_000, 250_000_000);
        assert_eq!(20784 * 86400 + 4 * 3600, t.0);
        for cell in [
            "2026-11-27 04:00:00.25",
            "2026-11-27T04:00:00.250000",
            "2026-11-27T05:00:00.25+01:00",
            " 2026-11-27 04:00:00.250Z ",
            "\"2026-11-27 04:00:00.25\"",
            "27.11.2026 04:00:00.25",
            "27.11.2026 04:00:00,25",
        ] {
            assert_eq!(parse_datetime(cell.as_bytes()), Some(t), "{cell}");
        }
        for cell in [
            "1795752000.25",
            "2026-11-27",
            "31.11.2026 04:00:00",
            "2026-11-31 04:00:00",
        ] {
            assert_eq!(parse_datetime(cell.as_bytes()), None, "{cell}");
        }
        for (cell, seconds) in [
            ("0 sec", 0.0),
            ("0.005 sec", 0.005),
            ("1.5 s", 1.5),
            ("20 ms", 0.02),
            ("2 min", 120.0),
            ("1 hr", 3600.0),
        ] {
            assert_eq!(parse_with_unit(cell.as_bytes()), Some(seconds), "{cell}");
        }
        for cell in ["0.005", "sec", "0.005 parsecs", "NaN sec", "1e400 s"] {
            assert_eq!(parse_with_unit(cell.as_bytes()), None, "{cell}");
        }
        // 10 s + 100 ns after 9 s + 999 999 900 ns: 200 ns.
        assert!((seconds_since((10, 100), (9, 999_999_900)) - 200e-9).abs() < 1e-22);
    }

    /// Times of day and dates worked out by hand: 23:59:59.5 is 23 h 59 min 59.5 s =
    /// 86 399.5 s; 2026-11-27 is 20 784 days after 1970-01-01 (56 years of 365 days, 14 leap
    /// days from 1972 to 2024, and 330 days from January 1 to November 27 of 2026).
    #[test]
    fn times_of_day_and_dates_by_hand() {
        assert_eq!(56 * 365 + 14 + 330, 20784);
        for (cell, seconds) in [
            ("00:00:00", 0.0),
            ("05:00:00.005", 18_000.005),
            ("23:59:59.5", 86_399.5),
            (" 7:30:00.25 ", 27_000.25),
        ] {
            let got = parse_time_of_day(cell.as_bytes()).unwrap_or(f64::NAN);
            assert!((got - seconds).abs() < 1e-9, "{cell}: {got}");
        }
        for cell in [
            "0.005",
            "05:00",
            "25:00:00",
            "05:61:00",
            "2026-11-27",
            "13:00:00 PM",
            "5:00 PM",
        ] {
            assert_eq!(parse_time_of_day(cell.as_bytes()), None, "{cell}");
        }
        // A 12-hour clock: 12 AM is midnight, 12 PM noon.
        for (cell, seconds) in [
            ("12:00:00.25 AM", 0.25),
            ("5:00:00 am", 18_000.0),
            ("12:30:00 PM", 45_000.0),
            ("11:59:59.5 pm", 86_399.5),
        ] {
            let got = parse_time_of_day(cell.as_bytes()).unwrap_or(f64::NAN);
            assert!((got - seconds).abs() < 1e-9, "{cell}: {got}");
        }
        // Slash dates: the order from a part above 12 (or both equal); 05/11 is undecided.
        assert_eq!(slash_order(27, 11), Some(DateOrder::DayMonthYear));
        assert_eq!(slash_order(11, 27), Some(DateOrder::MonthDayYear));
        assert_eq!(slash_order(11, 11), Some(DateOrder::MonthDayYear));
        assert_eq!(slash_order(5, 11), None);
        assert_eq!(slash_order(13, 14), None);
        for (cell, order) in [
            ("11/27/2026", DateOrder::MonthDayYear),
            ("27/11/2026", DateOrder::DayMonthYear),
            ("2026-11-27", DateOrder::YearMonthDay),
            ("27.11.2026", DateOrder::DayMonthYear),
        ] {
            assert_eq!(parse_date_in(cell.as_bytes(), order), Some(20784), "{cell}");
        }
        // 1 February 2026: 56 x 365 + 14 + 31 days.
        assert_eq!(56 * 365 + 14 + 31, 20485);
        assert_eq!(
            parse_date_in(b"1/2/2026", DateOrder::DayMonthYear),
            Some(20485)
        );
        assert_eq!(
            parse_date_in(b"2/1/2026", DateOrder::MonthDayYear),
            Some(20485)
        );
        assert_eq!(parse_date_in(b"11/27/2026", DateOrder::DayMonthYear), None);
        assert_eq!(parse_date_in(b"27.11.2026", DateOrder::MonthDayYear), None);
        // European date-times and decimal commas: 2026-11-27 05:00:00.25 UTC.
        let at = (20784 * 86_400 + 18_000, 250_000_000);
        for cell in [
            "27.11.2026 05:00:00,25",
            "27.11.2026 05:00:00.25",
            "2026-11-27 05:00:00,25",
            "2026-11-27T05:00:00,25Z",
        ] {
            assert_eq!(parse_datetime(cell.as_bytes()), Some(at), "{cell}");
        }
        assert_eq!(
            parse_datetime(b"1.2.2026 00:00:00"),
            Some((20485 * 86_400, 0))
        );
        for cell in [
            "27.13.2026 05:00:00",
            "27.11.2026 05:00:00,25,1",
            "27.11.2026",
            "1234567890123456",
        ] {
            assert_eq!(parse_datetime(cell.as_bytes()), None, "{cell}");
        }
        let got = parse_time_of_day(b"05:00:00,005").unwrap_or(f64::NAN);
        assert!((got - 18_000.005).abs() < 1e-9, "{got}");
        let t = parse_slash_datetime(b"11/27/2026 11:59:55.5 PM").unwrap();
        assert_eq!(t, ((11, 27, 2026), 86_395.5));
        assert_eq!(parse_slash_datetime(b"11/27/26 08:00:00"), None);
        assert_eq!(parse_slash_datetime(b"2026/11/27 08:00:00"), None);
        for cell in ["2026-11-27", "2026/11/27", "27.11.2026", "\"2026-11-27\""] {
            assert_eq!(parse_date(cell.as_bytes()), Some(20784), "{cell}");
        }
        assert_eq!(parse_date(b"1970-01-01"), Some(0));
        for cell in [
            "11/27/2026",
            "27/11/2026",
            "2026-11-31",
            "20261127",
            "05:00:00",
        ] {
            assert_eq!(parse_date(cell.as_bytes()), None, "{cell}");
        }
    }

    #[test]
    fn name_unit_and_time() {
        assert_eq!(
            split_name_unit("X-Axis (m/s2)"),
            ("X-Axis".into(), "m/s2".into())
        );
        assert_eq!(split_name_unit("Z [m/s^2]"), ("Z".into(), "m/s^2".into()));
        assert_eq!(split_name_unit("plain"), ("plain".into(), "".into()));
        assert_eq!(split_name_unit("(odd)"), ("(odd)".into(), "".into()));
        assert_eq!(time_scale("Time", "s"), Some(1.0));
        assert_eq!(time_scale("TIME", "ms"), Some(1e-3));
        assert_eq!(time_scale("time_ms", ""), Some(1e-3));
        assert_eq!(time_scale("t", ""), Some(1.0));
        assert_eq!(time_scale("timestamp", ""), Some(1.0));
        assert_eq!(time_scale("epoch_ms", ""), Some(1e-3));
        assert_eq!(time_scale("unix_time", ""), Some(1.0));
        assert_eq!(time_scale("Unix_Time_ms", ""), Some(1e-3));
        assert_eq!(time_scale("epoch", "ms"), Some(1e-3));
        assert_eq!(time_scale("Zeitstempel", "ms"), Some(1e-3));
        assert_eq!(time_scale("Time", "furlongs"), None);
        assert_eq!(time_scale("x", "s"), None);
        assert_eq!(time_scale("Time_ms", ""), Some(1e-3));
        assert_eq!(time_scale("Timestamp_ms", ""), Some(1e-3));
        assert_eq!(time_scale("time_ns", ""), Some(1e-9));
        assert_eq!(time_scale("t_ms", "s"), Some(1.0));
        assert_eq!(time_scale("speed_ms", ""), None);
        assert_eq!(time_scale("time_xyz", ""), None);
        assert_eq!(time_unit_seconds("MS"), Some(1e-3));
        assert_eq!(time_unit_seconds("fortnight"), None);
    }

    #[test]
    fn blocks_stream_in_bounded_pieces() {
        let text = "a;b\n1,5;2,25\n\n3;4\n5;6\n";
        let mut r = DelimitedReader::new(text.as_bytes(), "mem").unwrap();
        assert_eq!(r.separator(), Separator::Semicolon);
        assert!(r.decimal_comma());
        let b1 = r.next_block(2).unwrap().unwrap();
        assert_eq!(b1.columns, vec![vec![1.5, 3.0], vec![2.25, 4.0]]);
        assert_eq!(b1.lines, vec![2, 4]);
        let b2 = r.next_block(2).unwrap().unwrap();
        assert_eq!(b2.columns, vec![vec![5.0], vec![6.0]]);
        assert_eq!(b2.first_line, 5);
        assert!(r.next_block(2).unwrap().is_none());
    }

    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    fn random_number(rng: &mut ChaCha8Rng, decimal_comma: bool) -> String {
        let mut t = String::new();
        match rng.gen_range(0..5) {
            0 | 1 => t.push('-'),
            2 if rng.gen_bool(0.2) => t.push('+'),
            _ => {}
        }
        let long = rng.gen_bool(0.1);
        let int_digits = rng.gen_range(0..if long { 22 } else { 4 });
        let frac_digits = rng.gen_range(0..if long { 22 } else { 10 });
        for _ in 0..int_digits {
            t.push(char::from(b'0' + rng.gen_range(0..10u8)));
        }
        if frac_digits > 0 || int_digits == 0 || rng.gen_bool(0.2) {
            t.push(if decimal_comma && rng.gen_bool(0.5) {
                ','
            } else {
                '.'
            });
        }
        for _ in 0..frac_digits {
            t.push(char::from(b'0' + rng.gen_range(0..10u8)));
        }
        if int_digits + frac_digits == 0 {
            t.push('5');
        }
        if rng.gen_bool(0.15) {
            t.push_str(["e", "E", "e-", "e+"][rng.gen_range(0..4)]);
            t.push_str(&rng.gen_range(0..400).to_string());
        }
        t
    }

    fn random_cell(rng: &mut ChaCha8Rng, decimal_comma: bool) -> String {
        match rng.gen_range(0..40) {
            0 => String::new(),
            1 => "abc".into(),
            2 => [
                "inf", "-inf", "NaN", "nan", "1e", "1.2.3", "--1", "+", ".", "1,2,3",
            ][rng.gen_range(0..10)]
            .into(),
            3 => format!("\"{}\"", random_number(rng, decimal_comma)),
            4 => random_number(rng, decimal_comma) + "x",
            5 => "\u{b5}1".into(),
            _ => random_number(rng, decimal_comma),
        }
    }

    fn random_pad(rng: &mut ChaCha8Rng) -> &'static str {
        match rng.gen_range(0..40) {
            0 => "\x0c",
            1 => " ",
            2 => "  ",
            3 => "\t",
            4 => " \t",
            _ => "",
        }
    }

    /// A random line: mostly `nc` numbers, sometimes blank, ragged, padded, quoted or wrong.
    fn random_line(rng: &mut ChaCha8Rng, sep: Separator, nc: usize, dc: bool) -> String {
        if rng.gen_bool(0.03) {
            return random_pad(rng).to_string();
        }
        let sep_text = |rng: &mut ChaCha8Rng| -> String {
            match sep {
                Separator::Comma => ",".into(),
                Separator::Semicolon => ";".into(),
                Separator::Tab => "\t".into(),
                Separator::Whitespace => [" ", "  ", "\t", " \t "][rng.gen_range(0..4)].into(),
            }
        };
        let n = match rng.gen_range(0..30) {
            0 => nc.saturating_sub(1),
            1 => nc + 1,
            _ => nc,
        };
        let mut line = String::new();
        for c in 0..n {
            if c > 0 {
                line.push_str(&sep_text(rng));
            }
            line.push_str(random_pad(rng));
            line.push_str(&random_cell(rng, dc));
            line.push_str(random_pad(rng));
        }
        for _ in 0..[0, 0, 0, 1, 2][rng.gen_range(0..5)] {
            line.push_str(&sep_text(rng));
            line.push_str(random_pad(rng));
        }
        if rng.gen_bool(0.1) {
            line.push('\r');
        }
        line
    }

    fn ctx_parts(nc: usize) -> Vec<ColumnInfo> {
        (0..nc)
            .map(|i| ColumnInfo {
                name: ["a", "b", "c", "d"][i % 4].to_string(),
                unit: String::new(),
                time_scale_s: None,
                row_index: false,
                time_text: None,
            })
            .collect()
    }

    /// A block with its values as bits (NaN == NaN), to compare blocks exactly.
    fn block_bits(b: &Block) -> (usize, Vec<usize>, Vec<Vec<u64>>) {
        let bits = b
            .columns
            .iter()
            .map(|c| c.iter().map(|v| v.to_bits()).collect())
            .collect();
        (b.first_line, b.lines.clone(), bits)
    }

    /// Every line the fast row parser accepts gives exactly what the general parser gives; the
    /// lines it refuses go to the general parser (same values, same errors).
    #[test]
    fn fast_rows_equal_general_rows() {
        let mut rng = ChaCha8Rng::seed_from_u64(7);
        let mut n_fast = 0;
        let mut n_lines = 0;
        for sep in [
            Separator::Comma,
            Separator::Semicolon,
            Separator::Tab,
            Separator::Whitespace,
        ] {
            let dc = sep != Separator::Comma;
            for nc in 1..=4 {
                let columns = ctx_parts(nc);
                let (mut spans, mut scratch) = (Vec::new(), Vec::new());
                let mut ctx = RowCtx {
                    path: "t.csv",
                    sep,
                    decimal_comma: dc,
                    columns: &columns,
                    reference_line: 1,
                    spans: &mut spans,
                    scratch: &mut scratch,
                };
                for _ in 0..5000 {
                    let line = random_line(&mut rng, sep, nc, dc);
                    let bytes = line.as_bytes();
                    n_lines += 1;
                    // Fast path (with fallback), as the readers use it: the line with its
                    // newline, and (if not empty) without it, as the last line of a file.
                    let with_nl = format!("{line}\n");
                    let mut fast = Block::with_capacity(nc, 1);
                    let mut ln = 6;
                    let got =
                        ctx.parse_lines(with_nl.as_bytes(), &mut ln, &mut fast, usize::MAX, true);
                    assert_eq!(ln, 7);
                    if !line.is_empty() {
                        let mut last = Block::with_capacity(nc, 1);
                        let mut ln = 6;
                        let got_last = ctx.parse_lines(bytes, &mut ln, &mut last, usize::MAX, true);
                        assert_eq!(ln, 7);
                        match (&got, &got_last) {
                            (Ok(_), Ok(_)) => {
                                assert_eq!(block_bits(&fast), block_bits(&last), "{line:?}")
                            }
                            (Err(a), Err(b)) => assert_eq!(a.to_string(), b.to_string()),
                            _ => panic!("{line:?}: {got:?} with newline, {got_last:?} without"),
                        }
                    }
                    // General path alone, on the line without its final '\r'.
                    let mut general = Block::with_capacity(nc, 1);
                    let plain = bytes.strip_suffix(b"\r").unwrap_or(bytes);
                    let want = ctx.parse_row(plain, 7, &mut general);
                    match (&got, &want) {
                        (Ok(_), Ok(())) => assert_eq!(
                            block_bits(&fast),
                            block_bits(&general),
                            "{line:?} ({sep:?})"
                        ),
                        (Err(a), Err(b)) => assert_eq!(a.to_string(), b.to_string()),
                        _ => panic!("{line:?} ({sep:?}): fast {got:?}, general {want:?}"),
                    }
                    let mut probe = Block::with_capacity(nc, 1);
                    if let FastRow::Row(_) = ctx.fast_row(bytes, &mut probe) {
                        n_fast += 1;
                    }
                }
            }
        }
        // Most random lines are plain numbers: the fast path must really be taken.
        assert!(
            n_fast * 2 > n_lines,
            "fast path on {n_fast} of {n_lines} lines"
        );
    }

    /// The streaming reader with a tiny buffer (lines cut across buffer refills), the parallel
    /// reader and the general parser line by line give the same block; with a bad line, the
    /// same error (same line number).
    #[test]
    fn streaming_parallel_and_general_agree() {
        let mut rng = ChaCha8Rng::seed_from_u64(8);
        for (sep, head) in [
            (Separator::Semicolon, "a;b;c"),
            (Separator::Comma, "a,b,c"),
            (Separator::Whitespace, "a b c"),
        ] {
            let dc = sep != Separator::Comma;
            let s = match sep {
                Separator::Comma => ",",
                Separator::Semicolon => ";",
                _ => "  ",
            };
            let mut text = format!("{head}\n");
            let mut n = 0;
            while text.len() < (1 << 20) + 5000 {
                match rng.gen_range(0..50) {
                    0 => text.push('\n'),
                    1 => text.push_str("  \r\n"),
                    _ => {
                        let cells: Vec<String> =
                            (0..3).map(|_| random_number(&mut rng, dc)).collect();
                        text.push_str(&cells.join(s));
                        text.push_str(if rng.gen_bool(0.2) { "\r\n" } else { "\n" });
                        n += 1;
                    }
                }
            }
            text.push_str(&["1", "2", "3"].join(s)); // last line without newline
            n += 1;
            let bad_at = text.len() * 3 / 4;
            let cut = bad_at + text[bad_at..].find('\n').unwrap_or(0) + 1;
            let bad = format!("{}1{s}x2{s}3\n{}", &text[..cut], &text[cut..]);
            for (t, ok) in [(&text, true), (&bad, false)] {
                let reference: std::result::Result<Block, String> = (|| {
                    let columns = ctx_parts(3);
                    let (mut spans, mut scratch) = (Vec::new(), Vec::new());
                    let mut ctx = RowCtx {
                        path: "t.csv",
                        sep,
                        decimal_comma: dc,
                        columns: &columns,
                        reference_line: 1,
                        spans: &mut spans,
                        scratch: &mut scratch,
                    };
                    let mut b = Block::with_capacity(3, 0);
                    for (i, l) in t.split('\n').enumerate().skip(1) {
                        let l = l.strip_suffix('\r').unwrap_or(l);
                        ctx.parse_row(l.as_bytes(), i + 1, &mut b)
                            .map_err(|e| e.to_string())?;
                    }
                    Ok(b)
                })();
                let small = std::io::BufReader::with_capacity(16, t.as_bytes());
                let streamed: std::result::Result<Block, String> = (|| {
                    let mut r = DelimitedReader::new(small, "t.csv").map_err(|e| e.to_string())?;
                    let mut all = Block::with_capacity(3, 0);
                    while let Some(b) = r.next_block(1000).map_err(|e| e.to_string())? {
                        assert!(b.n_rows() <= 1000);
                        for (d, c) in all.columns.iter_mut().zip(b.columns) {
                            d.extend(c);
                        }
                        if all.lines.is_empty() {
                            all.first_line = b.first_line;
                        }
                        all.lines.extend(b.lines);
                    }
                    Ok(all)
                })();
                let parallel: std::result::Result<Block, String> = (|| {
                    let mut r =
                        DelimitedReader::new(t.as_bytes(), "t.csv").map_err(|e| e.to_string())?;
                    assert_eq!(r.separator(), sep);
                    Ok(r.read_all_parallel(3)
                        .map_err(|e| e.to_string())?
                        .unwrap_or(Block::with_capacity(3, 0)))
                })();
                let bits =
                    |r: &std::result::Result<Block, String>| r.clone().map(|b| block_bits(&b));
                let summary = |r: &std::result::Result<Block, String>| match r {
                    Ok(b) => format!("{} rows from line {}", b.n_rows(), b.first_line),
                    Err(e) => e.clone(),
                };
                for (name, got) in [("streamed", &streamed), ("parallel", &parallel)] {
                    assert!(
                        bits(got) == bits(&reference),
                        "{sep:?} {name}: {} but line by line {}",
                        summary(got),
                        summary(&reference)
                    );
                }
                if ok {
                    assert_eq!(reference.as_ref().map(Block::n_rows), Ok(n));
                } else {
                    let e = reference.err().unwrap_or_default();
                    let line = t[..cut].matches('\n').count() + 1;
                    assert!(
                        e.contains(&format!("line {line}, column 2")) && e.contains("'x2'"),
                        "{e}"
                    );
                }
            }
        }
    }
}
