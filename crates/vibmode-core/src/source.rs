//! Stage 1's contract, the record source: where records come from. A recording held in memory
//! cut into records of `record_length_s` ([`CutRecords`]); streamed files
//! (`vibmode_signal::StreamRecords`) and a database implement [`RecordSource`] too.

use crate::error::RecordingError;
use crate::record_meta::RecordMeta;
use crate::recording::Recording;

/// One record to analyse, with a name for tables (usually the file name and segment).
#[derive(Clone, Debug)]
pub struct RecordInput {
    /// Display name, e.g. `record_03.csv` or `drive.wav [20.48-30.72 s]`.
    pub name: String,
    /// The samples, at their original rate.
    pub recording: Recording,
}

/// One record to cut from a stream: `n_frames` frames from `start_frame`, with what is known of
/// it (e.g. from a GPS track).
#[derive(Clone, Debug, PartialEq)]
pub struct RecordWindow {
    /// First frame (0-based, in the file).
    pub start_frame: u64,
    /// Number of frames.
    pub n_frames: usize,
    /// Start, speed, position.
    pub meta: RecordMeta,
}

/// Anything that yields records one by one.
pub trait RecordSource {
    /// Why a record could not be made (a read error of a file, say).
    type Error;

    /// The next record, `None` when the source is exhausted.
    fn next_record(&mut self) -> Option<Result<RecordInput, Self::Error>>;

    /// Where the record last returned by [`RecordSource::next_record`] was cut from (start,
    /// speed and position), for sources that know it; `None` by default.
    fn meta(&self) -> Option<RecordMeta> {
        None
    }

    /// Every remaining record.
    fn collect_records(&mut self) -> Result<Vec<RecordInput>, Self::Error> {
        let mut out = Vec::new();
        while let Some(r) = self.next_record() {
            out.push(r?);
        }
        Ok(out)
    }
}

/// A recording cut into consecutive records of a fixed length (the remainder shorter than one
/// record is dropped; a recording shorter than two records is one record). Each record is copied
/// out of the recording when it is yielded, never the whole recording.
#[derive(Debug)]
pub struct CutRecords<'a> {
    name: String,
    rec: &'a Recording,
    n_per: usize,
    n_records: usize,
    next: usize,
    record_length_s: f64,
}

impl<'a> CutRecords<'a> {
    /// Records of `record_length_s` seconds of `rec`, named `"{name} [t0-t1 s]"`.
    pub fn new(name: &str, rec: &'a Recording, record_length_s: f64) -> Self {
        let n_per = (record_length_s * rec.fs_hz).round() as usize;
        let n = rec.len();
        let n_records = if n_per == 0 || n < 2 * n_per {
            1
        } else {
            n / n_per
        };
        CutRecords {
            name: name.to_string(),
            rec,
            n_per,
            n_records,
            next: 0,
            record_length_s,
        }
    }

    /// Number of records the source yields in all.
    pub fn len(&self) -> usize {
        self.n_records
    }

    /// True if the source yields no record (never: a short recording is one record).
    pub fn is_empty(&self) -> bool {
        self.n_records == 0
    }
}

impl RecordSource for CutRecords<'_> {
    type Error = RecordingError;

    fn next_record(&mut self) -> Option<Result<RecordInput, RecordingError>> {
        if self.next >= self.n_records {
            return None;
        }
        let k = self.next;
        self.next += 1;
        if self.n_records == 1 {
            return Some(Ok(RecordInput {
                name: self.name.clone(),
                recording: self.rec.clone(),
            }));
        }
        let view = match self.rec.view(k * self.n_per, (k + 1) * self.n_per) {
            Ok(v) => v,
            Err(e) => return Some(Err(e)),
        };
        let mut recording = view.to_recording();
        recording.time_axis = None;
        Some(Ok(RecordInput {
            name: format!(
                "{} [{:.2}-{:.2} s]",
                self.name,
                k as f64 * self.record_length_s,
                (k + 1) as f64 * self.record_length_s
            ),
            recording,
        }))
    }
}

/// Cuts a long recording into consecutive records of `record_length_s` seconds (see
/// [`CutRecords`]).
pub fn cut_records(name: &str, rec: &Recording, record_length_s: f64) -> Vec<RecordInput> {
    let mut src = CutRecords::new(name, rec, record_length_s);
    // Views inside the recording cannot fail: the ranges are built from its length.
    src.collect_records().unwrap_or_default()
}
