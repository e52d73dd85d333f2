//! Recordings of any length read as a stream of frame blocks, in bounded memory.
//!
//! [`open_stream`] opens delimited text, WAV or raw + sidecar (the same formats, options and
//! checks as [`crate::read_path`], see `docs/formats.md`) and [`FrameStream::next_block`] yields
//! [`FrameBlock`]s of at most `max_frames` frames, channel by channel. Memory is bounded by the
//! block, never by the file:
//!
//! - **raw**: the sidecar is read first; the file size must be a whole number of frames (a file
//!   cut off mid-write is refused before any sample is used, [`SignalError::PartialFrame`]);
//! - **WAV**: a 64- or 32-bit float or 16-bit integer file is read from its data chunk in
//!   blocks of bytes, other integer widths through hound's sample iterator; a file cut off mid-write (its
//!   header announces more samples than it holds) fails with a message saying so;
//! - **delimited text**: parsed by [`crate::DelimitedReader`] block by block. With a time column
//!   a first pass over the time column gives the rate `(n - 1) / (t_last - t_first)`, the jitter
//!   and the check that time increases (exactly as [`crate::read_path`] does); the blocks it
//!   parsed are kept and handed out when they hold at most [`KEEP_PARSED_MAX_VALUES`] values (a
//!   10.24 s record of 7 channels and a time column at 20 kHz holds 1.6 million), else the file
//!   is parsed again block by block as the samples are asked for; with a non-uniform time column
//!   and `allow_nonuniform` the samples are interpolated linearly onto the uniform grid as they
//!   pass.
//!
//! Every sample is checked to be finite, naming the channel and the sample's index in the file.

use crate::delimited::{check_row_index, Block, ColumnInfo, DelimitedReader};
use crate::error::{io_err, Result, SignalError, WavProblem, RAW_EXPECTED};
use crate::read::{raw_layout, reconcile_fs, sidecar_of, wav_names, Format, ReadOptions};
use std::collections::VecDeque;
use std::fs::File;
use std::io::{BufReader, Read, Seek, SeekFrom};
use std::path::Path;
use vibmode_core::{Channel, ChannelSelector, Recording, RecordingError};

/// Frames per block read by the command-line tools (65 536: 3.3 s at 20 kHz, 3.7 MB for 7
/// channels).
pub const DEFAULT_BLOCK_FRAMES: usize = 1 << 16;

/// Most values (cells of every column) of a delimited file with a time column whose blocks,
/// parsed by the first pass over the time column, are kept for the samples instead of parsing
/// the file a second time: 2^24, 128 MiB of `f64`. A longer file is read twice in bounded
/// memory.
pub const KEEP_PARSED_MAX_VALUES: usize = 1 << 24;

/// What a stream holds, known when it is opened.
#[derive(Clone, Debug, PartialEq)]
pub struct StreamInfo {
    /// The file, for messages.
    pub path: String,
    /// Its format.
    pub format: Format,
    /// Sampling rate, Hz (the given `fs_hz` when the file's rate agrees within 1 %).
    pub fs_hz: f64,
    /// Channel names (selected channels only, after [`FrameStream::select`]).
    pub names: Vec<String>,
    /// Channel units, same length as `names`.
    pub units: Vec<String>,
    /// Number of frames, when the format tells it up front (WAV, raw, text with a time column).
    pub n_frames: Option<u64>,
    /// Time of the first frame on the file's own time axis, s (the first value of a time column,
    /// else 0).
    pub start_s: f64,
    /// The absolute start time written in the sidecar (`"start_time"`, RFC 3339, e.g.
    /// `"2024-05-02T07:31:00Z"`, or seconds since 1970), as written (a number as its decimal
    /// text); `None` when there is none.
    pub start_time: Option<String>,
}

impl StreamInfo {
    /// Number of channels.
    pub fn n_channels(&self) -> usize {
        self.names.len()
    }

    /// Duration in seconds when the frame count is known.
    pub fn duration_s(&self) -> Option<f64> {
        self.n_frames.map(|n| n as f64 / self.fs_hz)
    }
}

/// Consecutive frames of a stream, stored channel by channel.
#[derive(Clone, Debug, PartialEq)]
pub struct FrameBlock {
    /// Index of the block's first frame in the file (0-based).
    pub first_frame: u64,
    /// `channels[c][k]`: channel `c`, frame `first_frame + k`.
    pub channels: Vec<Vec<f64>>,
}

impl FrameBlock {
    /// Number of frames in the block.
    pub fn n_frames(&self) -> usize {
        self.channels.first().map_or(0, |c| c.len())
    }
}

/// Linear interpolation of a non-uniform time column onto `t0 + i dt`, i = 0..n, as rows pass.
struct Interp {
    t0: f64,
    dt: f64,
    n: u64,
    emitted: u64,
    prev: Option<(f64, Vec<f64>)>,
}

enum Inner {
    /// Little-endian floats stored channel after channel (a Fortran-order `.npy`): each block
    /// read column by column from one file handle, at each column's start plus the frames
    /// already handed out.
    Columns {
        file: File,
        column_starts: Vec<u64>,
        done: u64,
        width: usize,
        remaining: u64,
        buf: Vec<u8>,
    },
    Delimited {
        reader: Box<DelimitedReader<BufReader<File>>>,
        /// Blocks parsed by the first pass over the time column, handed out before `reader`
        /// is asked for more (which is then at the end of the file).
        kept: VecDeque<Block>,
        time_col: Option<(usize, f64)>,
        /// The columns that are channels, in order.
        channel_cols: Vec<usize>,
        /// A pandas row index: its column and the value expected next (`None` before the first
        /// row).
        row_index: Option<Box<(ColumnInfo, usize, Option<f64>)>>,
        interp: Option<Interp>,
        /// Frames parsed but not yet handed out (channel-major).
        pending: Vec<VecDeque<f64>>,
        eof: bool,
    },
    Wav {
        reader: Box<hound::WavReader<BufReader<File>>>,
        float: bool,
        scale: f64,
        remaining: u64,
    },
    /// A 64- or 32-bit float or 16-bit integer WAV read from its data chunk in blocks of bytes
    /// (hound's sample iterator costs ~30 ns a sample; the same values, `v as f64 * scale`).
    WavBytes {
        data: BufReader<File>,
        /// Bytes a sample: 8 (64-bit float), 4 (32-bit float) or 2 (16-bit integer).
        width: usize,
        scale: f64,
        remaining: u64,
        buf: Vec<u8>,
    },
    Raw {
        file: BufReader<File>,
        width: usize,
        remaining: u64,
        buf: Vec<u8>,
    },
}

/// Reads into `buf` until it is full or the reader ends; the bytes read.
fn read_full(r: &mut impl Read, buf: &mut [u8]) -> std::io::Result<usize> {
    let mut got = 0;
    while got < buf.len() {
        match r.read(&mut buf[got..]) {
            Ok(0) => break,
            Ok(m) => got += m,
            Err(e) if e.kind() == std::io::ErrorKind::Interrupted => {}
            Err(e) => return Err(e),
        }
    }
    Ok(got)
}

/// Sizes `buf` for the next block of at most `max_frames` of the `remaining` frames of `nch`
/// interleaved channels of `width` bytes each; the frames in it, or `None` at the end.
fn block_bytes(
    remaining: u64,
    max_frames: usize,
    nch: usize,
    width: usize,
    buf: &mut Vec<u8>,
) -> Option<usize> {
    if remaining == 0 {
        return None;
    }
    let n = remaining.min(max_frames as u64) as usize;
    buf.resize(n * nch * width, 0);
    Some(n)
}

/// Interleaved little-endian samples of `W` bytes (`nch` a frame, decoded by `decode`) as
/// channels, each value times `scale`.
pub(crate) fn deinterleave<const W: usize>(
    buf: &[u8],
    nch: usize,
    scale: f64,
    decode: impl Fn([u8; W]) -> f64,
) -> Vec<Vec<f64>> {
    let frame = W * nch;
    if frame == 0 {
        return vec![Vec::new(); nch];
    }
    let n = buf.len() / frame;
    let mut out: Vec<Vec<f64>> = (0..nch).map(|_| vec![0.0; n]).collect();
    // Blocks of frames small enough to stay in the cache while each channel takes its values
    // out of them: one pass per channel over a block, writing that channel in order.
    const FRAMES_PER_BLOCK: usize = 1024;
    for (b, block) in buf[..n * frame]
        .chunks(FRAMES_PER_BLOCK * frame)
        .enumerate()
    {
        let start = b * FRAMES_PER_BLOCK;
        for (c, ch) in out.iter_mut().enumerate() {
            let dst = &mut ch[start..start + block.len() / frame];
            for (d, f) in dst.iter_mut().zip(block.chunks_exact(frame)) {
                let mut v = [0u8; W];
                v.copy_from_slice(&f[c * W..(c + 1) * W]);
                *d = decode(v) * scale;
            }
        }
    }
    out
}

/// Little-endian 32-bit floats as f64.
pub(crate) fn f32_le(b: [u8; 4]) -> f64 {
    f32::from_le_bytes(b) as f64
}

/// Little-endian 16-bit integers as f64.
fn i16_le(b: [u8; 2]) -> f64 {
    f64::from(i16::from_le_bytes(b))
}

/// A recording read block by block; see the module documentation.
pub struct FrameStream {
    info: StreamInfo,
    /// File channel index of each channel handed out.
    selection: Vec<usize>,
    /// Channel names as in the file (for non-finite messages).
    file_names: Vec<String>,
    next_frame: u64,
    inner: Inner,
}

impl std::fmt::Debug for FrameStream {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("FrameStream")
            .field("info", &self.info)
            .field("selection", &self.selection)
            .field("next_frame", &self.next_frame)
            .finish()
    }
}

fn open_file(path: &Path) -> Result<File> {
    File::open(path).map_err(|e| io_err("read", path, &e))
}

/// Opens `path` as a stream of frame blocks (see the module documentation). The options are
/// those of [`crate::read_path`] (`unit` fills in missing units).
pub fn open_stream(path: &Path, opts: &ReadOptions) -> Result<FrameStream> {
    open_stream_of_file(path, opts)
        .map_err(|e| crate::error::in_file(&path.display().to_string(), e))
}

fn open_stream_of_file(path: &Path, opts: &ReadOptions) -> Result<FrameStream> {
    opts.check()?;
    let format = opts.format.unwrap_or_else(|| Format::from_path(path));
    let mut s = match format {
        Format::Raw => open_raw(path, opts)?,
        Format::Npy => open_npy(path, opts)?,
        Format::Wav => open_wav(path, opts)?,
        Format::Delimited => open_delimited(path, opts)?,
    };
    crate::error::check_names_of(path, s.info.names.iter().map(String::as_str))?;
    if let Some(u) = &opts.unit {
        for unit in &mut s.info.units {
            if unit.is_empty() {
                unit.clone_from(u);
            }
        }
    }
    Ok(s)
}

fn stream(info: StreamInfo, inner: Inner) -> FrameStream {
    let n = info.names.len();
    FrameStream {
        file_names: info.names.clone(),
        info,
        selection: (0..n).collect(),
        next_frame: 0,
        inner,
    }
}

/// `"start_time"` of a JSON sidecar, if any: a string as written, a number (seconds since 1970)
/// as its decimal text, anything else as its JSON text, so that the reader checks it and refuses
/// what it cannot use instead of it being ignored.
pub(crate) fn sidecar_start_time(sidecar: &Path) -> Option<String> {
    let text = std::fs::read_to_string(sidecar).ok()?;
    let v: serde_json::Value = serde_json::from_str(&text).ok()?;
    match v.get("start_time")? {
        serde_json::Value::Null => None,
        serde_json::Value::String(s) => Some(s.clone()),
        other => Some(other.to_string()),
    }
}

fn open_raw(path: &Path, opts: &ReadOptions) -> Result<FrameStream> {
    let p = path.display().to_string();
    let layout = raw_layout(path)?;
    let nch = layout.side.channels.len();
    let file = open_file(path)?;
    let bytes = file.metadata().map_err(|e| io_err("read", path, &e))?.len();
    let frame = (layout.width * nch) as u64;
    if bytes % frame != 0 {
        return Err(SignalError::PartialFrame {
            path: p,
            bytes,
            frame_bytes: frame,
            channels: nch,
            dtype_bytes: layout.width,
            whole_bytes: bytes - bytes % frame,
        });
    }
    let n = bytes / frame;
    if n == 0 {
        return Err(SignalError::EmptyFile {
            path: p,
            expected: RAW_EXPECTED,
        });
    }
    let fs = reconcile_fs(
        &p,
        format!("the sidecar {}", layout.sidecar_path),
        layout.side.fs_hz,
        opts.fs_hz,
    )?;
    let info = StreamInfo {
        path: p,
        format: Format::Raw,
        fs_hz: fs,
        units: layout
            .side
            .units
            .clone()
            .unwrap_or_else(|| vec![String::new(); nch]),
        names: layout.side.channels.clone(),
        n_frames: Some(n),
        start_s: 0.0,
        start_time: sidecar_start_time(Path::new(&layout.sidecar_path)),
    };
    Ok(stream(
        info,
        Inner::Raw {
            file: BufReader::with_capacity(1 << 20, file),
            width: layout.width,
            remaining: n,
            buf: Vec::new(),
        },
    ))
}

fn open_npy(path: &Path, opts: &ReadOptions) -> Result<FrameStream> {
    let p = path.display().to_string();
    let layout = crate::npy::npy_layout_of(path)?;
    let fs = crate::npy::npy_rate(path, opts.fs_hz)?;
    let nch = layout.channels;
    let (names, units) = wav_names(path, nch)?;
    let info = StreamInfo {
        path: p,
        format: Format::Npy,
        fs_hz: fs,
        units,
        names,
        n_frames: Some(layout.frames),
        start_s: 0.0,
        start_time: sidecar_start_time(&sidecar_of(path)),
    };
    let inner = if layout.fortran {
        let column_bytes = layout.frames * layout.width as u64;
        Inner::Columns {
            file: open_file(path)?,
            column_starts: (0..nch as u64)
                .map(|c| layout.data_offset + c * column_bytes)
                .collect(),
            done: 0,
            width: layout.width,
            remaining: layout.frames,
            buf: Vec::new(),
        }
    } else {
        let mut f = open_file(path)?;
        f.seek(SeekFrom::Start(layout.data_offset))
            .map_err(|e| io_err("read", path, &e))?;
        Inner::Raw {
            file: BufReader::with_capacity(1 << 20, f),
            width: layout.width,
            remaining: layout.frames,
            buf: Vec::new(),
        }
    };
    Ok(stream(info, inner))
}

fn open_wav(path: &Path, opts: &ReadOptions) -> Result<FrameStream> {
    let p = path.display().to_string();
    let wav_err = |problem: WavProblem| SignalError::Wav {
        path: p.clone(),
        problem,
    };
    let file = open_file(path)?;
    let mut reader = match hound::WavReader::new(BufReader::with_capacity(1 << 20, file)) {
        Ok(reader) => reader,
        Err(e) => {
            // hound refuses 64-bit floats; anything else keeps hound's message.
            let mut data = BufReader::with_capacity(1 << 20, open_file(path)?);
            return match crate::wav64::float64_header(&mut data) {
                Some(h) => open_float64_wav(path, opts, &h, data),
                None => Err(wav_err(WavProblem::Unreadable {
                    message: e.to_string(),
                })),
            };
        }
    };
    let spec = reader.spec();
    let (nch, float, scale) = crate::read::wav_layout(&spec, opts, &wav_err)?;
    let n = u64::from(reader.duration());
    if n == 0 {
        return Err(wav_err(WavProblem::NoSamples));
    }
    let info = wav_info(path, spec.sample_rate, nch, n, opts)?;
    let bytes = |data, width| Inner::WavBytes {
        data,
        width,
        scale,
        remaining: n,
        buf: Vec::new(),
    };
    let samples = |reader| Inner::Wav {
        reader: Box::new(reader),
        float,
        scale,
        remaining: n,
    };
    let inner = if float {
        // hound's reader stops at the start of the data chunk (wav_layout: 32 bits).
        bytes(reader.into_inner(), 4)
    } else if spec.bits_per_sample != 16 {
        samples(reader)
    } else if first_sample_reads(&mut reader) {
        // hound read a 16-bit sample of 2 bytes (it refuses any other width for 16 bits) and
        // stepped back to the start of the data chunk.
        bytes(reader.into_inner(), 2)
    } else {
        // The sample iterator from the start again: its failed read says why at the first block.
        let file = BufReader::with_capacity(1 << 20, open_file(path)?);
        samples(hound::WavReader::new(file).map_err(|e| SignalError::Wav {
            path: path.display().to_string(),
            problem: WavProblem::Unreadable {
                message: e.to_string(),
            },
        })?)
    };
    Ok(stream(info, inner))
}

/// What a WAV stream of `n` frames of `nch` channels at the header's `sample_rate` (Hz) is: the
/// rate checked against `opts.fs_hz`, names and units and the start time from its sidecar.
fn wav_info(
    path: &Path,
    sample_rate: u32,
    nch: usize,
    n: u64,
    opts: &ReadOptions,
) -> Result<StreamInfo> {
    let p = path.display().to_string();
    let fs = reconcile_fs(
        &p,
        "the WAV header".into(),
        f64::from(sample_rate),
        opts.fs_hz,
    )?;
    let (names, units) = wav_names(path, nch)?;
    Ok(StreamInfo {
        path: p,
        format: Format::Wav,
        fs_hz: fs,
        names,
        units,
        n_frames: Some(n),
        start_s: 0.0,
        start_time: sidecar_start_time(&sidecar_of(path)),
    })
}

/// The stream of a 64-bit float WAV (`h`: its header, [`crate::wav64`]), read from its data
/// chunk in blocks of bytes.
fn open_float64_wav(
    path: &Path,
    opts: &ReadOptions,
    h: &crate::wav64::Float64Wav,
    mut data: BufReader<File>,
) -> Result<FrameStream> {
    crate::read::check_wav_scale(opts)?;
    let n = h.frames();
    if n == 0 {
        return Err(SignalError::Wav {
            path: path.display().to_string(),
            problem: WavProblem::NoSamples,
        });
    }
    data.seek(std::io::SeekFrom::Start(h.data_offset))
        .map_err(|e| io_err("read", path, &e))?;
    let info = wav_info(path, h.sample_rate, usize::from(h.channels), n, opts)?;
    Ok(stream(
        info,
        Inner::WavBytes {
            data,
            width: 8,
            scale: opts.scale,
            remaining: n,
            buf: Vec::new(),
        },
    ))
}

/// Whether hound reads the first sample of an integer WAV; it then seeks back to the start of
/// the data chunk.
fn first_sample_reads(reader: &mut hound::WavReader<BufReader<File>>) -> bool {
    matches!(reader.samples::<i32>().next(), Some(Ok(_))) && reader.seek(0).is_ok()
}

fn delimited_reader(path: &Path) -> Result<DelimitedReader<BufReader<File>>> {
    let file = open_file(path)?;
    DelimitedReader::new(
        BufReader::with_capacity(1 << 20, file),
        &path.display().to_string(),
    )
}

/// First pass over a time column: count, first and last value, strictly increasing, jitter.
struct TimeScan {
    n: u64,
    t0: f64,
    t_last: f64,
    max_dt: f64,
    min_dt: f64,
}

/// The first pass over a time column with `r` (just past the header); the blocks parsed, when
/// they hold at most `keep_max` values ([`KEEP_PARSED_MAX_VALUES`]).
fn scan_time(
    r: &mut DelimitedReader<BufReader<File>>,
    path: &Path,
    col: usize,
    scale: f64,
    name: &str,
    keep_max: usize,
) -> Result<(TimeScan, Option<VecDeque<Block>>)> {
    let p = path.display().to_string();
    let mut scan = TimeScan {
        n: 0,
        t0: 0.0,
        t_last: 0.0,
        max_dt: f64::NEG_INFINITY,
        min_dt: f64::INFINITY,
    };
    let mut kept = Some(VecDeque::new());
    let mut n_values = 0usize;
    while let Some(block) = r.next_block(DEFAULT_BLOCK_FRAMES)? {
        for (k, &raw) in block.columns[col].iter().enumerate() {
            let t = raw * scale;
            if !t.is_finite() {
                return Err(RecordingError::NonFinite {
                    channel: name.to_string(),
                    index: scan.n as usize,
                    value: t,
                }
                .into());
            }
            if scan.n == 0 {
                scan.t0 = t;
            } else {
                if t <= scan.t_last {
                    return Err(SignalError::TimeNotIncreasing {
                        path: p,
                        column: name.to_string(),
                        line: block.lines[k],
                        previous: scan.t_last,
                        value: t,
                    });
                }
                let dt = t - scan.t_last;
                scan.max_dt = scan.max_dt.max(dt);
                scan.min_dt = scan.min_dt.min(dt);
            }
            scan.t_last = t;
            scan.n += 1;
        }
        n_values += block.columns.iter().map(Vec::len).sum::<usize>();
        if n_values > keep_max {
            kept = None;
        }
        if let Some(k) = kept.as_mut() {
            k.push_back(block);
        }
    }
    Ok((scan, kept))
}

fn open_delimited(path: &Path, opts: &ReadOptions) -> Result<FrameStream> {
    open_delimited_keeping(path, opts, KEEP_PARSED_MAX_VALUES)
}

fn open_delimited_keeping(path: &Path, opts: &ReadOptions, keep_max: usize) -> Result<FrameStream> {
    let p = path.display().to_string();
    let mut reader = delimited_reader(path)?;
    let cols = reader.columns().to_vec();
    let tcol = cols.iter().position(|c| c.time_scale_s.is_some());
    let channel_cols: Vec<usize> = (0..cols.len()).filter(|&i| cols[i].is_channel()).collect();
    let names: Vec<String> = channel_cols.iter().map(|&i| cols[i].name.clone()).collect();
    let units: Vec<String> = channel_cols.iter().map(|&i| cols[i].unit.clone()).collect();
    let row_index = cols
        .iter()
        .position(|c| c.row_index)
        .map(|i| Box::new((cols[i].clone(), i, None)));
    if names.is_empty() {
        return Err(SignalError::NoChannels { path: p });
    }
    let mut kept = VecDeque::new();
    let (fs_hz, n_frames, start_s, time_col, interp) = match tcol {
        Some(ti) => {
            let name = cols[ti].name.clone();
            let scale = cols[ti].time_scale(opts.time_scale_s);
            let (scan, blocks) = scan_time(&mut reader, path, ti, scale, &name, keep_max)?;
            match blocks {
                Some(b) => kept = b,
                // Too long to keep: parsed again as the samples are asked for.
                None => reader = delimited_reader(path)?,
            }
            if scan.n == 0 {
                return Err(SignalError::NoDataRows { path: p });
            }
            if scan.n < 2 {
                return Err(SignalError::TooShort {
                    what: format!("time column '{name}' of {p}"),
                    n: scan.n as usize,
                    fix: "need at least 2 rows to derive the sampling rate; or drop the time column and give the sampling rate (fs_hz)".into(),
                });
            }
            let mean_dt = (scan.t_last - scan.t0) / (scan.n - 1) as f64;
            let jitter = (scan.max_dt - mean_dt)
                .abs()
                .max((scan.min_dt - mean_dt).abs())
                / mean_dt;
            let mean_fs = 1.0 / mean_dt;
            let interp = if jitter > opts.max_jitter_rel {
                if !opts.allow_nonuniform {
                    return Err(SignalError::NonUniformTime {
                        path: p,
                        column: name,
                        jitter_rel: jitter,
                        max_jitter_rel: opts.max_jitter_rel,
                        mean_fs_hz: mean_fs,
                    });
                }
                Some(Interp {
                    t0: scan.t0,
                    dt: mean_dt,
                    n: scan.n,
                    emitted: 0,
                    prev: None,
                })
            } else {
                None
            };
            let fs = reconcile_fs(&p, format!("the time column '{name}'"), mean_fs, opts.fs_hz)?;
            (fs, Some(scan.n), scan.t0, Some((ti, scale)), interp)
        }
        None => match opts.fs_hz {
            Some(fs) => (fs, None, 0.0, None, None),
            None => return Err(SignalError::NoSampleRate { path: p }),
        },
    };
    let nch = names.len();
    let info = StreamInfo {
        path: p,
        format: Format::Delimited,
        fs_hz,
        names,
        units,
        n_frames,
        start_s,
        start_time: None,
    };
    Ok(stream(
        info,
        Inner::Delimited {
            reader: Box::new(reader),
            kept,
            time_col,
            channel_cols,
            row_index,
            interp,
            pending: vec![VecDeque::new(); nch],
            eof: false,
        },
    ))
}

/// Appends a parsed block's channel columns to `pending`.
fn push_rows(block: &Block, channel_cols: &[usize], pending: &mut [VecDeque<f64>]) {
    for (p, &c) in pending.iter_mut().zip(channel_cols) {
        p.extend(&block.columns[c]);
    }
}

impl Interp {
    /// Feeds one row (time `t`, values `y`) and emits every grid point at or before `t`.
    fn feed(&mut self, t: f64, y: &[f64], pending: &mut [VecDeque<f64>]) {
        while self.emitted < self.n {
            let ti = self.t0 + self.emitted as f64 * self.dt;
            if ti > t {
                break;
            }
            match &self.prev {
                Some((ta, ya)) if ti > *ta => {
                    let w = ((ti - ta) / (t - ta)).clamp(0.0, 1.0);
                    for ((p, a), b) in pending.iter_mut().zip(ya).zip(y) {
                        p.push_back(a + w * (b - a));
                    }
                }
                Some((_, ya)) => {
                    for (p, a) in pending.iter_mut().zip(ya) {
                        p.push_back(*a);
                    }
                }
                None => {
                    for (p, b) in pending.iter_mut().zip(y) {
                        p.push_back(*b);
                    }
                }
            }
            self.emitted += 1;
        }
        self.prev = Some((t, y.to_vec()));
    }

    /// At the end of the file: the grid points left (rounding past the last time) take the last
    /// row's values.
    fn finish(&mut self, pending: &mut [VecDeque<f64>]) {
        if let Some((_, y)) = &self.prev {
            while self.emitted < self.n {
                for (p, v) in pending.iter_mut().zip(y) {
                    p.push_back(*v);
                }
                self.emitted += 1;
            }
        }
    }
}

impl FrameStream {
    /// What the stream holds.
    pub fn info(&self) -> &StreamInfo {
        &self.info
    }

    /// Index of the next frame [`FrameStream::next_block`] returns.
    pub fn position(&self) -> u64 {
        self.next_frame
    }

    /// Keeps only the selected channels, in the order given (as [`Recording::select`], with the
    /// same errors). An empty selection keeps every channel.
    pub fn select(&mut self, sel: &[ChannelSelector]) -> Result<()> {
        if sel.is_empty() {
            return Ok(());
        }
        // Resolve through Recording::select (same matching and messages): channel i holds the
        // single sample i.
        let probe = Recording {
            fs_hz: self.info.fs_hz,
            channels: self
                .info
                .names
                .iter()
                .zip(&self.info.units)
                .enumerate()
                .map(|(i, (n, u))| Channel::new(n.clone(), u.clone(), vec![i as f64]))
                .collect(),
            time_axis: None,
        };
        let picked = probe.select(sel)?;
        let idx: Vec<usize> = picked
            .channels
            .iter()
            .map(|c| c.samples.first().map_or(0, |&v| v as usize))
            .collect();
        self.selection = idx.iter().map(|&i| self.selection[i]).collect();
        self.info.names = picked.channels.iter().map(|c| c.name.clone()).collect();
        self.info.units = picked.channels.iter().map(|c| c.unit.clone()).collect();
        Ok(())
    }

    /// The next block of at most `max_frames` frames (at least one), `Ok(None)` at the end.
    ///
    /// Errors: read errors (a WAV cut off mid-write), parse errors of text files (naming line and
    /// column), non-finite samples (naming channel and frame), `max_frames` = 0.
    pub fn next_block(&mut self, max_frames: usize) -> Result<Option<FrameBlock>> {
        self.next_block_of_file(max_frames)
            .map_err(|e| crate::error::in_file(&self.info.path, e))
    }

    fn next_block_of_file(&mut self, max_frames: usize) -> Result<Option<FrameBlock>> {
        if max_frames == 0 {
            return Err(SignalError::InvalidParam {
                name: "max_frames",
                value: "0".into(),
                fix: "ask for at least 1 frame per block".into(),
            });
        }
        let all = match &mut self.inner {
            Inner::Columns {
                file,
                column_starts,
                done,
                width,
                remaining,
                buf,
            } => {
                let Some(n) = block_bytes(*remaining, max_frames, 1, *width, buf) else {
                    return Ok(None);
                };
                let mut out = Vec::with_capacity(column_starts.len());
                for &start in column_starts.iter() {
                    file.seek(SeekFrom::Start(start + *done * *width as u64))
                        .and_then(|_| file.read_exact(buf))
                        .map_err(|e| SignalError::Io {
                            action: "read",
                            path: self.info.path.clone(),
                            message: format!(
                                "{e} (was the file cut off or changed while being read?)"
                            ),
                        })?;
                    out.push(if *width == 4 {
                        deinterleave(buf, 1, 1.0, f32_le).remove(0)
                    } else {
                        deinterleave(buf, 1, 1.0, f64::from_le_bytes).remove(0)
                    });
                }
                *remaining -= n as u64;
                *done += n as u64;
                out
            }
            Inner::Raw {
                file,
                width,
                remaining,
                buf,
            } => {
                let nch = self.file_names.len();
                let Some(n) = block_bytes(*remaining, max_frames, nch, *width, buf) else {
                    return Ok(None);
                };
                file.read_exact(buf).map_err(|e| SignalError::Io {
                    action: "read",
                    path: self.info.path.clone(),
                    message: format!("{e} (was the file cut off or changed while being read?)"),
                })?;
                *remaining -= n as u64;
                if *width == 4 {
                    deinterleave(buf, nch, 1.0, f32_le)
                } else {
                    deinterleave(buf, nch, 1.0, f64::from_le_bytes)
                }
            }
            Inner::WavBytes {
                data,
                width,
                scale,
                remaining,
                buf,
            } => {
                let nch = self.file_names.len();
                let Some(n) = block_bytes(*remaining, max_frames, nch, *width, buf) else {
                    return Ok(None);
                };
                let got = read_full(data, buf).map_err(|e| SignalError::Wav {
                    path: self.info.path.clone(),
                    problem: WavProblem::CutOffAt {
                        message: e.to_string(),
                        frame: self.next_frame,
                        announced: self.next_frame + *remaining,
                    },
                })?;
                if got < buf.len() {
                    return Err(SignalError::Wav {
                        path: self.info.path.clone(),
                        problem: WavProblem::EndsEarly {
                            frame: self.next_frame + (got / (*width * nch)) as u64,
                            announced: self.next_frame + *remaining,
                        },
                    });
                }
                *remaining -= n as u64;
                match *width {
                    8 => deinterleave(buf, nch, *scale, f64::from_le_bytes),
                    4 => deinterleave(buf, nch, *scale, f32_le),
                    _ => deinterleave(buf, nch, *scale, i16_le),
                }
            }
            Inner::Wav {
                reader,
                float,
                scale,
                remaining,
            } => {
                if *remaining == 0 {
                    return Ok(None);
                }
                let nch = self.file_names.len();
                let n = (*remaining).min(max_frames as u64) as usize;
                let mut out = vec![Vec::with_capacity(n); nch];
                let truncated = |e: hound::Error, frame: u64| SignalError::Wav {
                    path: self.info.path.clone(),
                    problem: WavProblem::CutOffAt {
                        message: e.to_string(),
                        frame,
                        announced: self.next_frame + *remaining,
                    },
                };
                let mut k = 0usize;
                if *float {
                    for s in reader.samples::<f32>().take(n * nch) {
                        let v = s.map_err(|e| truncated(e, self.next_frame + (k / nch) as u64))?;
                        out[k % nch].push(v as f64 * *scale);
                        k += 1;
                    }
                } else {
                    for s in reader.samples::<i32>().take(n * nch) {
                        let v = s.map_err(|e| truncated(e, self.next_frame + (k / nch) as u64))?;
                        out[k % nch].push(v as f64 * *scale);
                        k += 1;
                    }
                }
                if k < n * nch {
                    return Err(SignalError::Wav {
                        path: self.info.path.clone(),
                        problem: WavProblem::EndsEarly {
                            frame: self.next_frame + (k / nch) as u64,
                            announced: self.next_frame + *remaining,
                        },
                    });
                }
                *remaining -= n as u64;
                out
            }
            Inner::Delimited {
                reader,
                kept,
                time_col,
                channel_cols,
                row_index,
                interp,
                pending,
                eof,
            } => {
                while !*eof && pending.first().map_or(0, |p| p.len()) < max_frames {
                    let next = match kept.pop_front() {
                        Some(block) => Some(block),
                        None => reader.next_block(max_frames)?,
                    };
                    match next {
                        Some(block) => {
                            if let Some((info, col, next)) = row_index.as_deref_mut() {
                                let values = &block.columns[*col];
                                let first = next.or(values.first().copied()).unwrap_or(0.0);
                                *next = Some(check_row_index(
                                    reader.path(),
                                    info,
                                    first,
                                    values,
                                    &block.lines,
                                )?);
                            }
                            match interp.as_mut() {
                                Some(ip) => {
                                    let (ti, scale) = time_col.unwrap_or((0, 1.0));
                                    let mut row = Vec::with_capacity(channel_cols.len());
                                    for r in 0..block.n_rows() {
                                        row.clear();
                                        row.extend(
                                            channel_cols.iter().map(|&c| block.columns[c][r]),
                                        );
                                        ip.feed(block.columns[ti][r] * scale, &row, pending);
                                    }
                                }
                                None => push_rows(&block, channel_cols, pending),
                            }
                        }
                        None => {
                            *eof = true;
                            if let Some(ip) = interp.as_mut() {
                                ip.finish(pending);
                            }
                        }
                    }
                }
                let have = pending.first().map_or(0, |p| p.len());
                if have == 0 {
                    if self.next_frame == 0 {
                        return Err(SignalError::NoDataRows {
                            path: self.info.path.clone(),
                        });
                    }
                    return Ok(None);
                }
                let n = have.min(max_frames);
                // From the front of a queue: O(n) however much stays pending (a kept block of
                // 65 536 rows handed out a few frames at a time).
                pending.iter_mut().map(|p| p.drain(..n).collect()).collect()
            }
        };
        for (c, d) in all.iter().enumerate() {
            if let Some(k) = d.iter().position(|v| !v.is_finite()) {
                return Err(RecordingError::NonFinite {
                    channel: self.file_names[c].clone(),
                    index: (self.next_frame as usize) + k,
                    value: d[k],
                }
                .into());
            }
            if let Some(k) = d
                .iter()
                .position(|v| v.abs() > vibmode_core::limits::SAMPLE_ABS_MAX)
            {
                return Err(RecordingError::SampleTooLarge {
                    channel: self.file_names[c].clone(),
                    index: (self.next_frame as usize) + k,
                    value: d[k],
                }
                .into());
            }
        }
        let first_frame = self.next_frame;
        let n = all.first().map_or(0, |d| d.len());
        self.next_frame += n as u64;
        let identity = self.selection.len() == all.len()
            && self.selection.iter().enumerate().all(|(k, &i)| k == i);
        let channels = if identity {
            all
        } else {
            self.selection.iter().map(|&i| all[i].clone()).collect()
        };
        Ok(Some(FrameBlock {
            first_frame,
            channels,
        }))
    }

    /// Reads the rest of the stream into one recording (for short files and tests).
    pub fn read_to_recording(&mut self) -> Result<Recording> {
        let mut data: Vec<Vec<f64>> = vec![Vec::new(); self.info.n_channels()];
        while let Some(b) = self.next_block(DEFAULT_BLOCK_FRAMES)? {
            for (d, c) in data.iter_mut().zip(b.channels) {
                d.extend_from_slice(&c);
            }
        }
        Ok(Recording {
            fs_hz: self.info.fs_hz,
            channels: self
                .info
                .names
                .iter()
                .zip(&self.info.units)
                .zip(data)
                .map(|((n, u), d)| Channel::new(n.clone(), u.clone(), d))
                .collect(),
            time_axis: None,
        })
    }
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;

    /// Frames taken apart in blocks give each channel its values in order, as one frame at a
    /// time does: 1-7 channels of 16-, 32- and 64-bit samples, lengths around and across the
    /// block size, with a scale and with trailing bytes of a partial frame.
    #[test]
    fn blocks_of_frames_give_the_frames_values_in_order() {
        use rand::{Rng, SeedableRng};
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(13);
        let mut byte = move || rng.gen::<u8>();
        for nch in 1..=7 {
            for frames in [0usize, 1, 1023, 1024, 1025, 2500] {
                let bytes: Vec<u8> = (0..frames * 8 * nch + 3).map(|_| byte()).collect();
                let one_by_one = |w: usize, decode: &dyn Fn(&[u8]) -> f64| -> Vec<Vec<f64>> {
                    let mut out = vec![Vec::new(); nch];
                    for f in bytes.chunks_exact(w * nch) {
                        for (c, ch) in out.iter_mut().enumerate() {
                            ch.push(decode(&f[c * w..(c + 1) * w]) * 0.5);
                        }
                    }
                    out
                };
                let bits = |v: Vec<Vec<f64>>| -> Vec<Vec<u64>> {
                    v.into_iter()
                        .map(|c| c.into_iter().map(f64::to_bits).collect())
                        .collect()
                };
                let cut2 = |b: &[u8]| [b[0], b[1]];
                let cut4 = |b: &[u8]| [b[0], b[1], b[2], b[3]];
                let cut8 = |b: &[u8]| [b[0], b[1], b[2], b[3], b[4], b[5], b[6], b[7]];
                assert_eq!(
                    bits(deinterleave(&bytes, nch, 0.5, i16_le)),
                    bits(one_by_one(2, &|b| i16_le(cut2(b)))),
                    "i16 {nch} x {frames}"
                );
                assert_eq!(
                    bits(deinterleave(&bytes, nch, 0.5, f32_le)),
                    bits(one_by_one(4, &|b| f32_le(cut4(b)))),
                    "f32 {nch} x {frames}"
                );
                assert_eq!(
                    bits(deinterleave(&bytes, nch, 0.5, f64::from_le_bytes)),
                    bits(one_by_one(8, &|b| f64::from_le_bytes(cut8(b)))),
                    "f64 {nch} x {frames}"
                );
            }
        }
    }

    /// The message of the error that streaming `path` in blocks of `max_frames` ends with
    /// (a file cut off mid-write); panics when it streams to its end.
    pub(crate) fn stream_error(path: &Path, opts: &ReadOptions, max_frames: usize) -> String {
        let mut st = open_stream(path, opts).unwrap();
        loop {
            match st.next_block(max_frames) {
                Ok(Some(_)) => {}
                Ok(None) => panic!("{} streamed to its end", path.display()),
                Err(e) => break e.to_string(),
            }
        }
    }

    /// The samples of a delimited file with a time column are the same whether the first
    /// pass's blocks are kept or the file is parsed again (a bound below the file's values).
    #[test]
    fn kept_blocks_and_a_second_pass_give_the_same_samples() {
        let dir = std::env::temp_dir().join(format!("vibmode-keep-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("t.csv");
        let mut text = String::from("time_s,a,b\n");
        for i in 0..5000 {
            // Jittered times: interpolated onto the grid as they pass.
            let t = i as f64 * 0.01 + if i % 7 == 3 { 0.002 } else { 0.0 };
            text += &format!(
                "{t},{},{}\n",
                (i as f64 * 0.37).sin(),
                (i % 13) as f64 - 6.0
            );
        }
        std::fs::write(&path, text).unwrap();
        let opts = ReadOptions {
            allow_nonuniform: true,
            ..Default::default()
        };
        let read_all = |keep_max: usize, block: usize| {
            let mut s = open_delimited_keeping(&path, &opts, keep_max).unwrap();
            let mut out = vec![Vec::new(); 2];
            while let Some(b) = s.next_block(block).unwrap() {
                for (o, c) in out.iter_mut().zip(b.channels) {
                    o.extend(c);
                }
            }
            (s.info().fs_hz, out)
        };
        let whole = crate::read_path(&path, &opts).unwrap();
        for (keep_max, block) in [(usize::MAX, 1000), (100, 1000), (0, 777), (usize::MAX, 1)] {
            let (fs, got) = read_all(keep_max, block);
            assert_eq!(fs, whole.fs_hz);
            for (g, c) in got.iter().zip(&whole.channels) {
                assert_eq!(g, &c.samples, "keep_max {keep_max}, block {block}");
            }
        }
        std::fs::remove_dir_all(&dir).ok();
    }

    /// A 16-bit integer WAV streamed from its bytes gives hound's values (scaled), block by
    /// block; cut off, it says so.
    #[test]
    fn a_16_bit_wav_streams_as_the_whole_file_reader_reads_it() {
        let dir = std::env::temp_dir().join(format!("vibmode-i16-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let write = |name: &str, n: usize| {
            let path = dir.join(name);
            let spec = hound::WavSpec {
                channels: 3,
                sample_rate: 1000,
                bits_per_sample: 16,
                sample_format: hound::SampleFormat::Int,
            };
            let mut w = hound::WavWriter::create(&path, spec).unwrap();
            for k in 0..n * 3 {
                w.write_sample(((k * 7919) % 65536) as i32 as i16).unwrap();
            }
            w.finalize().unwrap();
            path
        };
        let path = write("a.wav", 4000);
        let opts = ReadOptions {
            scale: 9.81,
            ..Default::default()
        };
        let whole = crate::read_path(&path, &opts).unwrap();
        assert_eq!(whole.channels[0].samples.len(), 4000);
        for block in [1, 999, 4000, 65536] {
            let mut st = open_stream(&path, &opts).unwrap();
            let mut got = vec![Vec::new(); 3];
            while let Some(b) = st.next_block(block).unwrap() {
                for (g, c) in got.iter_mut().zip(b.channels) {
                    g.extend(c);
                }
            }
            for (g, c) in got.iter().zip(&whole.channels) {
                assert_eq!(g, &c.samples, "block {block}");
            }
        }
        // Cut off mid-write.
        let bytes = std::fs::read(&path).unwrap();
        let cut = dir.join("cut.wav");
        std::fs::write(&cut, &bytes[..bytes.len() - 1001]).unwrap();
        let e = stream_error(&cut, &opts, 1000);
        assert!(e.contains("cut off") && e.contains("of the 4000"), "{e}");
        std::fs::remove_dir_all(&dir).ok();
    }
}
