//! Records cut from a [`FrameStream`] as it is read ([`StreamRecords`]): consecutive records of
//! a fixed length or the windows a segmentation chose, and the records of several files one
//! after the other ([`ChainedRecords`]). Only the frames of the record being cut (and one read
//! block) are held.

use std::collections::VecDeque;

use vibmode_core::{Channel, RecordInput, RecordMeta, RecordSource, RecordWindow, Recording};

use crate::stream::{FrameStream, StreamInfo, DEFAULT_BLOCK_FRAMES};
use crate::SignalError;

#[derive(Debug)]
enum Plan {
    /// Consecutive records of `n_per` frames (as [`vibmode_core::CutRecords`]).
    Cut {
        n_per: usize,
        k: u64,
        single: Option<bool>,
        done: bool,
    },
    /// Given windows, in increasing `start_frame`.
    Windows(VecDeque<RecordWindow>),
}

/// Records read from a stream one by one: consecutive records of a fixed length (the remainder
/// shorter than one record is dropped; a recording shorter than two records is one record, as
/// [`vibmode_core::CutRecords`]), or given windows (segmentation). Only the frames of the record being
/// cut (and one read block) are held.
#[derive(Debug)]
pub struct StreamRecords {
    name: String,
    stream: FrameStream,
    /// Frames from `buf_start` on, channel by channel.
    buf: Vec<Vec<f64>>,
    buf_start: u64,
    eof: bool,
    plan: Plan,
    last_meta: Option<RecordMeta>,
}

impl StreamRecords {
    /// Consecutive records of `record_length_s` seconds, named `"{name} [t0-t1 s]"`.
    pub fn cut(name: &str, stream: FrameStream, record_length_s: f64) -> Self {
        let n_per = (record_length_s * stream.info().fs_hz).round().max(1.0) as usize;
        Self::new(
            name,
            stream,
            Plan::Cut {
                n_per,
                k: 0,
                single: None,
                done: false,
            },
        )
    }

    /// The records given by `windows` (sorted by start here), named `"{name} [t0-t1 s]"`. A window
    /// reaching past the end of the file is an error when it is reached.
    pub fn windows(name: &str, stream: FrameStream, mut windows: Vec<RecordWindow>) -> Self {
        windows.sort_by_key(|w| w.start_frame);
        Self::new(name, stream, Plan::Windows(windows.into()))
    }

    fn new(name: &str, stream: FrameStream, plan: Plan) -> Self {
        let nch = stream.info().n_channels();
        StreamRecords {
            name: name.to_string(),
            stream,
            buf: vec![Vec::new(); nch],
            buf_start: 0,
            eof: false,
            plan,
            last_meta: None,
        }
    }

    /// The stream's description.
    pub fn info(&self) -> &StreamInfo {
        self.stream.info()
    }

    fn buf_end(&self) -> u64 {
        self.buf_start + self.buf.first().map_or(0, Vec::len) as u64
    }

    /// Reads blocks until the buffer reaches frame `end` (exclusive) or the file ends.
    fn fill_to(&mut self, end: u64) -> Result<(), SignalError> {
        while !self.eof && self.buf_end() < end {
            match self.stream.next_block(DEFAULT_BLOCK_FRAMES)? {
                Some(b) => {
                    for (d, c) in self.buf.iter_mut().zip(b.channels) {
                        d.extend_from_slice(&c);
                    }
                }
                None => self.eof = true,
            }
        }
        Ok(())
    }

    /// Drops buffered frames before `frame`.
    fn drop_before(&mut self, frame: u64) {
        let n = frame.saturating_sub(self.buf_start) as usize;
        let n = n.min(self.buf.first().map_or(0, Vec::len));
        if n > 0 {
            for d in &mut self.buf {
                d.drain(..n);
            }
            self.buf_start += n as u64;
        }
    }

    /// Frames `start..start + n` as a recording (they must be buffered).
    fn slice(&self, start: u64, n: usize) -> Recording {
        let info = self.stream.info();
        let a = (start - self.buf_start) as usize;
        Recording {
            fs_hz: info.fs_hz,
            channels: info
                .names
                .iter()
                .zip(&info.units)
                .zip(&self.buf)
                .map(|((name, unit), d)| {
                    Channel::new(name.clone(), unit.clone(), d[a..a + n].to_vec())
                })
                .collect(),
            time_axis: None,
        }
    }

    fn range_name(&self, start: u64, n: usize) -> String {
        let fs = self.stream.info().fs_hz;
        format!(
            "{} [{:.2}-{:.2} s]",
            self.name,
            start as f64 / fs,
            (start + n as u64) as f64 / fs
        )
    }

    fn next_cut(&mut self) -> Result<Option<RecordInput>, SignalError> {
        let Plan::Cut {
            n_per,
            k,
            single,
            done,
        } = self.plan
        else {
            return Ok(None);
        };
        if done {
            return Ok(None);
        }
        let n_per64 = n_per as u64;
        let single = match single {
            Some(s) => s,
            None => {
                self.fill_to(2 * n_per64)?;
                self.eof && self.buf_end() < 2 * n_per64
            }
        };
        if single {
            self.plan = Plan::Cut {
                n_per,
                k,
                single: Some(true),
                done: true,
            };
            let n = self.buf.first().map_or(0, Vec::len);
            if n == 0 {
                return Ok(None);
            }
            self.last_meta = None;
            return Ok(Some(RecordInput {
                name: self.name.clone(),
                recording: self.slice(0, n),
            }));
        }
        let start = k * n_per64;
        self.fill_to(start + n_per64)?;
        if self.buf_end() < start + n_per64 {
            self.plan = Plan::Cut {
                n_per,
                k,
                single: Some(false),
                done: true,
            };
            return Ok(None);
        }
        let rec = self.slice(start, n_per);
        let name = self.range_name(start, n_per);
        self.drop_before(start + n_per64);
        self.plan = Plan::Cut {
            n_per,
            k: k + 1,
            single: Some(false),
            done: false,
        };
        let fs = self.stream.info().fs_hz;
        self.last_meta = Some(RecordMeta {
            start_s: start as f64 / fs,
            duration_s: n_per as f64 / fs,
            ..RecordMeta::default()
        });
        Ok(Some(RecordInput {
            name,
            recording: rec,
        }))
    }

    fn next_window(&mut self) -> Result<Option<RecordInput>, SignalError> {
        let w = match &mut self.plan {
            Plan::Windows(list) => match list.pop_front() {
                Some(w) => w,
                None => return Ok(None),
            },
            Plan::Cut { .. } => return Ok(None),
        };
        self.drop_before(w.start_frame);
        let end = w.start_frame + w.n_frames as u64;
        self.fill_to(end)?;
        if self.buf_end() < end || w.start_frame < self.buf_start {
            return Err(SignalError::WindowOutside {
                record: self.range_name(w.start_frame, w.n_frames),
                start_frame: w.start_frame,
                n_frames: w.n_frames,
                file_frames: self.buf_end(),
            });
        }
        let rec = self.slice(w.start_frame, w.n_frames);
        let name = self.range_name(w.start_frame, w.n_frames);
        self.last_meta = Some(w.meta);
        Ok(Some(RecordInput {
            name,
            recording: rec,
        }))
    }
}

impl RecordSource for StreamRecords {
    type Error = SignalError;

    fn next_record(&mut self) -> Option<Result<RecordInput, SignalError>> {
        let r = match self.plan {
            Plan::Cut { .. } => self.next_cut(),
            Plan::Windows(_) => self.next_window(),
        };
        r.transpose()
    }

    fn meta(&self) -> Option<RecordMeta> {
        self.last_meta.clone()
    }
}

/// The records of several files one file after the other, each file opened only when the one
/// before is used up: `open(i)` makes the source of file `i` (0..n).
pub struct ChainedRecords<F>
where
    F: FnMut(usize) -> Result<StreamRecords, SignalError>,
{
    n: usize,
    next: usize,
    open: F,
    current: Option<StreamRecords>,
}

impl<F> std::fmt::Debug for ChainedRecords<F>
where
    F: FnMut(usize) -> Result<StreamRecords, SignalError>,
{
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("ChainedRecords")
            .field("n", &self.n)
            .field("next", &self.next)
            .finish()
    }
}

impl<F> ChainedRecords<F>
where
    F: FnMut(usize) -> Result<StreamRecords, SignalError>,
{
    /// The records of `n` sources made by `open`.
    pub fn new(n: usize, open: F) -> Self {
        ChainedRecords {
            n,
            next: 0,
            open,
            current: None,
        }
    }
}

impl<F> RecordSource for ChainedRecords<F>
where
    F: FnMut(usize) -> Result<StreamRecords, SignalError>,
{
    type Error = SignalError;

    fn next_record(&mut self) -> Option<Result<RecordInput, SignalError>> {
        loop {
            if let Some(cur) = &mut self.current {
                match cur.next_record() {
                    Some(r) => return Some(r),
                    None => self.current = None,
                }
            }
            if self.next >= self.n {
                return None;
            }
            let i = self.next;
            self.next += 1;
            match (self.open)(i) {
                Ok(s) => self.current = Some(s),
                Err(e) => return Some(Err(e)),
            }
        }
    }

    fn meta(&self) -> Option<RecordMeta> {
        self.current.as_ref().and_then(|c| c.meta())
    }
}
