//! Reading recordings from delimited text, WAV and raw binary files.

use crate::delimited::{check_row_index, Block, ColumnInfo, DelimitedReader};
use crate::error::{io_err, Result, SidecarProblem, SignalError, WavProblem, RAW_EXPECTED};
use serde::{Deserialize, Serialize};
use std::fmt;
use std::io::BufRead;
use std::path::{Path, PathBuf};
use std::str::FromStr;
use vibmode_core::{check_finite, check_fs, Channel, Recording, RecordingError, TimeAxis};

/// File format. Detected from the extension when not given (see [`Format::from_path`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum Format {
    /// Delimited text: `.csv`, `.txt`, `.tsv`, `.dat`, `.asc` (and unknown extensions).
    Delimited,
    /// WAV, PCM integer 8/16/24/32-bit or 32-bit float: `.wav`.
    Wav,
    /// Raw interleaved little-endian f32/f64 with a JSON sidecar: `.f32`, `.f64`, `.bin`, `.raw`.
    Raw,
    /// NumPy's `.npy` (`numpy.save`): a 1-D array of samples or a 2-D array of samples by
    /// channels, little-endian float32 or float64; channels named as WAV's are (`<path>.json`,
    /// else `ch0`, `ch1`, ...); the rate given, or that sidecar's `fs_hz`.
    Npy,
}

impl Format {
    /// The format implied by a file extension (case-insensitive); `None` if the extension is not
    /// one of the known ones.
    pub fn from_extension(ext: &str) -> Option<Format> {
        match ext.to_ascii_lowercase().as_str() {
            "csv" | "txt" | "tsv" | "dat" | "asc" => Some(Format::Delimited),
            "wav" | "wave" => Some(Format::Wav),
            "f32" | "f64" | "bin" | "raw" => Some(Format::Raw),
            "npy" => Some(Format::Npy),
            _ => None,
        }
    }

    /// The format of `path` from its extension; unknown extensions are read as delimited text
    /// unless the file starts with `RIFF` (WAV) or `\x93NUMPY` (npy), or a sidecar exists (raw).
    pub fn from_path(path: &Path) -> Format {
        if let Some(f) = path
            .extension()
            .and_then(|e| e.to_str())
            .and_then(Format::from_extension)
        {
            return f;
        }
        if let Ok(mut f) = std::fs::File::open(path) {
            let mut magic = [0u8; 6];
            let got = std::io::Read::read(&mut f, &mut magic).unwrap_or(0);
            if got >= 4 && &magic[..4] == b"RIFF" {
                return Format::Wav;
            }
            if got == 6 && &magic == crate::npy::NPY_MAGIC {
                return Format::Npy;
            }
        }
        if sidecar_candidates(path).iter().any(|p| p.is_file()) {
            return Format::Raw;
        }
        Format::Delimited
    }
}

/// The recordings of the folder `dir` (not its subfolders): its files with a known extension
/// ([`Format::from_extension`]), hidden files left out, sorted by name. A folder with none, or
/// with one record name in two formats (`rec01.csv` beside `rec01.f32`), is an error.
pub fn recordings_in_folder(dir: &Path) -> Result<Vec<PathBuf>> {
    let entries = std::fs::read_dir(dir).map_err(|e| io_err("read", dir, &e))?;
    let mut files: Vec<PathBuf> = Vec::new();
    for entry in entries {
        let entry = entry.map_err(|e| io_err("read", dir, &e))?;
        let path = entry.path();
        let name = entry.file_name();
        let hidden = name.to_str().map_or(true, |n| n.starts_with('.'));
        let known = path
            .extension()
            .and_then(|e| e.to_str())
            .and_then(Format::from_extension)
            .is_some();
        if !hidden && known && path.is_file() {
            files.push(path);
        }
    }
    files.sort();
    if files.is_empty() {
        return Err(SignalError::FolderWithoutRecordings {
            path: dir.display().to_string(),
        });
    }
    let name = |p: &Path| {
        p.file_name()
            .map_or(String::new(), |n| n.to_string_lossy().into_owned())
    };
    let mut stems: std::collections::HashMap<std::ffi::OsString, &Path> =
        std::collections::HashMap::new();
    for f in &files {
        let stem = f.file_stem().map(|s| s.to_os_string()).unwrap_or_default();
        if let Some(first) = stems.insert(stem, f) {
            return Err(SignalError::FolderRecordTwice {
                path: dir.display().to_string(),
                first: name(first),
                second: name(f),
            });
        }
    }
    Ok(files)
}

/// `paths` with every folder among them replaced by its recordings ([`recordings_in_folder`]),
/// in place; files are kept as given.
pub fn expand_folders(paths: &[PathBuf]) -> Result<Vec<PathBuf>> {
    let mut out = Vec::with_capacity(paths.len());
    for p in paths {
        if p.is_dir() {
            out.extend(recordings_in_folder(p)?);
        } else {
            out.push(p.clone());
        }
    }
    Ok(out)
}

impl FromStr for Format {
    type Err = SignalError;
    fn from_str(s: &str) -> Result<Format> {
        match s.trim().to_ascii_lowercase().as_str() {
            "delimited" | "csv" | "text" | "txt" => Ok(Format::Delimited),
            "wav" => Ok(Format::Wav),
            "raw" | "bin" | "binary" => Ok(Format::Raw),
            "npy" | "numpy" => Ok(Format::Npy),
            _ => Err(SignalError::UnknownFormat {
                given: s.to_string(),
            }),
        }
    }
}

impl fmt::Display for Format {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Format::Delimited => "delimited",
            Format::Wav => "wav",
            Format::Raw => "raw",
            Format::Npy => "npy",
        })
    }
}

/// Options for [`read_path`].
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ReadOptions {
    /// Sampling rate, Hz. Required for text files without a time column; when the file also has
    /// a rate (time column, WAV header, sidecar) they must agree within 1 % and this value wins.
    /// Default `None`.
    pub fs_hz: Option<f64>,
    /// Format; default `None` = from the extension ([`Format::from_path`]).
    pub format: Option<Format>,
    /// Multiplier for WAV integer samples after scaling them to [-1, 1) full scale, e.g. the
    /// sensor's full-scale range in m/s^2. Default 1.0 (full scale = 1.0).
    pub scale: f64,
    /// Accept a non-uniform time column by linear interpolation onto a uniform grid at the mean
    /// rate (CLI `--resample-nonuniform`). Default false.
    pub allow_nonuniform: bool,
    /// Largest accepted time-step jitter, max |dt - mean dt| / mean dt. Default 0.01.
    pub max_jitter_rel: f64,
    /// Unit given to channels whose file does not state one (e.g. `m/s^2`). Default `None`.
    pub unit: Option<String>,
    /// Seconds per unit of a text file's time column, overriding what its name and header say
    /// (`Some(1e-3)` for a `Timestamp` column in milliseconds; see [`time_unit_scale`]).
    /// Default `None`: from the name and header.
    pub time_scale_s: Option<f64>,
}

/// Seconds per unit of a time unit (`s`, `ms`, `us`, `ns`, `min`, `h`, case-insensitive), for
/// [`ReadOptions::time_scale_s`].
pub fn time_unit_scale(unit: &str) -> Result<f64> {
    crate::delimited::time_unit_seconds(unit).ok_or_else(|| SignalError::InvalidParam {
        name: "time_unit",
        value: format!("'{}'", vibmode_core::quoted(unit)),
        fix: "use s, ms, us, ns, min or h".into(),
    })
}

impl Default for ReadOptions {
    fn default() -> Self {
        ReadOptions {
            fs_hz: None,
            format: None,
            scale: 1.0,
            allow_nonuniform: false,
            max_jitter_rel: 0.01,
            unit: None,
            time_scale_s: None,
        }
    }
}

impl ReadOptions {
    /// Checks the options themselves (a given rate, the jitter tolerance) before any file is
    /// opened.
    pub fn check(&self) -> Result<()> {
        if let Some(fs) = self.fs_hz {
            check_fs(fs, "the given fs_hz")?;
        }
        if let Some(t) = self.time_scale_s {
            if !(t.is_finite() && t > 0.0) {
                return Err(SignalError::InvalidParam {
                    name: "time_scale_s",
                    value: t.to_string(),
                    fix: "must be a finite number > 0, e.g. 0.001 for milliseconds".into(),
                });
            }
        }
        if !(self.max_jitter_rel.is_finite() && self.max_jitter_rel >= 0.0) {
            return Err(SignalError::InvalidParam {
                name: "max_jitter_rel",
                value: self.max_jitter_rel.to_string(),
                fix: "must be a finite number >= 0, e.g. 0.01".into(),
            });
        }
        Ok(())
    }
}

/// Reads a recording from `path` (delimited text, WAV or raw + sidecar; see `docs/formats.md`).
///
/// All samples are checked to be finite; channel order is file order (time column removed).
pub fn read_path(path: &Path, opts: &ReadOptions) -> Result<Recording> {
    read_path_or_bytes(path, None, opts)
        .map_err(|e| crate::error::in_file(&path.display().to_string(), e))
}

/// Reads a recording from the bytes of the file at `path`, already read (for example to hash
/// them): the same result as [`read_path`] without reading the file again. `path` gives the
/// format (unless `opts.format` does), names the file in messages and finds a WAV's sidecar;
/// a raw file is read from `path` with its sidecar as by [`read_path`].
pub fn read_path_bytes(path: &Path, bytes: &[u8], opts: &ReadOptions) -> Result<Recording> {
    read_path_or_bytes(path, Some(bytes), opts)
        .map_err(|e| crate::error::in_file(&path.display().to_string(), e))
}

fn read_path_or_bytes(path: &Path, bytes: Option<&[u8]>, opts: &ReadOptions) -> Result<Recording> {
    opts.check()?;
    let format = opts.format.unwrap_or_else(|| Format::from_path(path));
    let mut rec = match (format, bytes) {
        (Format::Delimited, Some(bytes)) => {
            read_delimited_bytes(bytes, &path.display().to_string(), opts)?
        }
        (Format::Delimited, None) => {
            let bytes = std::fs::read(path).map_err(|e| io_err("read", path, &e))?;
            read_delimited_bytes(&bytes, &path.display().to_string(), opts)?
        }
        (Format::Wav, Some(bytes)) => read_wav(path, Some(bytes), opts)?,
        (Format::Wav, None) => {
            // A file that is there is read whole (its bytes take half the memory of the
            // samples they become); a missing one keeps the WAV reader's own message.
            match std::fs::read(path) {
                Ok(bytes) => read_wav(path, Some(&bytes), opts)?,
                Err(_) => read_wav(path, None, opts)?,
            }
        }
        (Format::Raw, _) => read_raw(path, opts)?,
        (Format::Npy, bytes) => read_npy(path, bytes, opts)?,
    };
    crate::error::check_names_of(path, rec.channels.iter().map(|c| c.name.as_str()))?;
    if let Some(u) = &opts.unit {
        for c in &mut rec.channels {
            if c.unit.is_empty() {
                c.unit = u.clone();
            }
        }
    }
    Ok(rec)
}

pub(crate) fn reconcile_fs(
    path: &str,
    source_name: String,
    file_fs: f64,
    given: Option<f64>,
) -> Result<f64> {
    check_fs(file_fs, &source_name)?;
    match given {
        None => Ok(file_fs),
        Some(g) => {
            if (g - file_fs).abs() > 0.01 * file_fs {
                Err(SignalError::SampleRateMismatch {
                    path: path.to_string(),
                    source_name,
                    file_fs_hz: file_fs,
                    given_fs_hz: g,
                })
            } else {
                Ok(g)
            }
        }
    }
}

/// Checks a WAV header and the scale option (the whole-file and the streamed readers share
/// it): `(channels, float samples, factor from a raw sample to the output unit)`. Integer
/// samples are scaled to [-1, 1) first, then by `opts.scale`.
pub(crate) fn wav_layout(
    spec: &hound::WavSpec,
    opts: &ReadOptions,
    wav_err: &dyn Fn(WavProblem) -> SignalError,
) -> Result<(usize, bool, f64)> {
    let nch = spec.channels as usize;
    if nch == 0 {
        return Err(wav_err(WavProblem::NoChannels));
    }
    check_wav_scale(opts)?;
    match spec.sample_format {
        hound::SampleFormat::Float => {
            if spec.bits_per_sample != 32 {
                return Err(wav_err(WavProblem::FloatBits {
                    bits: spec.bits_per_sample,
                }));
            }
            Ok((nch, true, opts.scale))
        }
        hound::SampleFormat::Int => {
            let bits = spec.bits_per_sample;
            if !(1..=32).contains(&bits) {
                return Err(wav_err(WavProblem::IntBits { bits }));
            }
            Ok((nch, false, opts.scale / f64::powi(2.0, bits as i32 - 1)))
        }
    }
}

/// The scale option of a WAV: a finite non-zero number.
pub(crate) fn check_wav_scale(opts: &ReadOptions) -> Result<()> {
    if !(opts.scale.is_finite() && opts.scale != 0.0) {
        return Err(SignalError::InvalidParam {
            name: "scale",
            value: opts.scale.to_string(),
            fix:
                "the WAV scale must be a finite non-zero number, e.g. 19.62 (m/s^2 per full scale)"
                    .into(),
        });
    }
    Ok(())
}

/// Reads delimited text from any buffered reader (the whole stream). `path` is used in messages.
/// Same rules as [`read_path`] for time columns, rates and units (except `opts.unit`, which
/// [`read_path`] applies afterwards).
pub fn read_delimited<R: BufRead>(reader: R, path: &str, opts: &ReadOptions) -> Result<Recording> {
    let mut r = DelimitedReader::new(reader, path)?;
    let mut data: Vec<Vec<f64>> = vec![Vec::new(); r.columns().len()];
    let mut lines: Vec<usize> = Vec::new();
    let keep_lines = r.needs_lines();
    while let Some(block) = r.next_block(1 << 16)? {
        append_block(&mut data, &mut lines, block, keep_lines);
    }
    let cols = r.columns().to_vec();
    finish_delimited(path, opts, &cols, data, lines)
}

/// Reads delimited text held in memory, parsing with several threads for large files (one
/// when called on a thread of rayon's pool: a parallel loop over files keeps the cores busy
/// already, and a file cut into parts costs a copy of its columns).
pub fn read_delimited_bytes(bytes: &[u8], path: &str, opts: &ReadOptions) -> Result<Recording> {
    let mut r = DelimitedReader::new(bytes, path)?;
    let mut data: Vec<Vec<f64>> = vec![Vec::new(); r.columns().len()];
    let mut lines: Vec<usize> = Vec::new();
    let keep_lines = r.needs_lines();
    let threads = if rayon::current_thread_index().is_some() {
        1
    } else {
        std::thread::available_parallelism().map_or(1, |n| n.get().min(8))
    };
    if let Some(block) = r.read_all_parallel(threads)? {
        append_block(&mut data, &mut lines, block, keep_lines);
    }
    let cols = r.columns().to_vec();
    finish_delimited(path, opts, &cols, data, lines)
}

fn append_block(data: &mut [Vec<f64>], lines: &mut Vec<usize>, block: Block, keep_lines: bool) {
    for (d, b) in data.iter_mut().zip(block.columns) {
        if d.is_empty() {
            *d = b;
        } else {
            d.extend_from_slice(&b);
        }
    }
    if keep_lines {
        lines.extend_from_slice(&block.lines);
    }
}

/// The first value (s) of a numeric time column read as Unix time: 1e9 s (2001-09-09) to
/// 4102444800 s (2100-01-01).
pub const UNIX_TIME_RANGE_S: std::ops::Range<f64> = 1e9..4_102_444_800.0;

fn finish_delimited(
    path: &str,
    opts: &ReadOptions,
    cols: &[ColumnInfo],
    data: Vec<Vec<f64>>,
    lines: Vec<usize>,
) -> Result<Recording> {
    let tcol = cols.iter().position(|c| c.time_scale_s.is_some());
    if data.first().map_or(true, |d| d.is_empty()) {
        return Err(SignalError::NoDataRows {
            path: path.to_string(),
        });
    }
    let mut time: Option<Vec<f64>> = None;
    let mut channels = Vec::with_capacity(cols.len());
    for (i, (c, d)) in cols.iter().zip(data).enumerate() {
        if Some(i) == tcol {
            let scale = c.time_scale(opts.time_scale_s);
            time = Some(d.into_iter().map(|v| v * scale).collect());
        } else if c.row_index {
            check_row_index(path, c, d.first().copied().unwrap_or(0.0), &d, &lines)?;
        } else if !c.is_channel() {
            // The date of a split date and time: added to the time column by the reader.
        } else {
            channels.push(Channel::new(c.name.clone(), c.unit.clone(), d));
        }
    }
    if channels.is_empty() {
        return Err(SignalError::NoChannels {
            path: path.to_string(),
        });
    }
    check_finite(&channels)?;
    let (fs_hz, time_axis) = match (time, tcol) {
        (Some(t), Some(ti)) => {
            let name = cols[ti].name.clone();
            let n = t.len();
            if let Some(k) = t.iter().position(|v| !v.is_finite()) {
                return Err(RecordingError::NonFinite {
                    channel: name,
                    index: k,
                    value: t[k],
                }
                .into());
            }
            if n < 2 {
                return Err(SignalError::TooShort {
                    what: format!("time column '{name}' of {path}"),
                    n,
                    fix: "need at least 2 rows to derive the sampling rate; or drop the time column and give the sampling rate (fs_hz)".into(),
                });
            }
            for k in 1..n {
                if t[k] <= t[k - 1] {
                    return Err(SignalError::TimeNotIncreasing {
                        path: path.to_string(),
                        column: name,
                        line: lines.get(k).copied().unwrap_or(0),
                        previous: t[k - 1],
                        value: t[k],
                    });
                }
            }
            let mean_dt = (t[n - 1] - t[0]) / (n - 1) as f64;
            let jitter = t
                .windows(2)
                .map(|w| ((w[1] - w[0]) - mean_dt).abs())
                .fold(0.0f64, f64::max)
                / mean_dt;
            let mean_fs = 1.0 / mean_dt;
            if jitter > opts.max_jitter_rel {
                if !opts.allow_nonuniform {
                    return Err(SignalError::NonUniformTime {
                        path: path.to_string(),
                        column: name,
                        jitter_rel: jitter,
                        max_jitter_rel: opts.max_jitter_rel,
                        mean_fs_hz: mean_fs,
                    });
                }
                for c in &mut channels {
                    c.samples = interp_uniform(&t, &c.samples, t[0], mean_dt);
                }
            }
            let fs = reconcile_fs(
                path,
                format!("the time column '{name}'"),
                mean_fs,
                opts.fs_hz,
            )?;
            (
                fs,
                Some(TimeAxis {
                    column: name,
                    fs_hz: mean_fs,
                    jitter_rel: jitter,
                    start_s: t[0],
                    origin_unix_s: match cols[ti].time_text {
                        Some(crate::delimited::TimeText::DateTime { base }) => {
                            Some(base.0 as f64 + f64::from(base.1) * 1e-9)
                        }
                        // Times of day beside a date column: from the first row's midnight.
                        Some(crate::delimited::TimeText::TimeOfDay) => {
                            cols.iter().find_map(|c| match c.time_text {
                                Some(crate::delimited::TimeText::Date { base_day, .. }) => {
                                    Some(base_day as f64 * 86_400.0)
                                }
                                _ => None,
                            })
                        }
                        // A slash date and a time of day: from the first row's midnight when
                        // the order of its day and month is known.
                        Some(crate::delimited::TimeText::SlashDateTime { first_day }) => {
                            first_day.map(|d| d as f64 * 86_400.0)
                        }
                        // A number of seconds since 1970 (a logger's Unix timestamp, `timestamp`
                        // or `timestamp_ms`): its first value is 2001-09-09 to 2100 as such, and no
                        // recording's relative time is 31 years long.
                        None if UNIX_TIME_RANGE_S.contains(&t[0]) => Some(0.0),
                        _ => None,
                    },
                }),
            )
        }
        _ => match opts.fs_hz {
            Some(fs) => (fs, None),
            None => {
                return Err(SignalError::NoSampleRate {
                    path: path.to_string(),
                })
            }
        },
    };
    Ok(Recording {
        fs_hz,
        channels,
        time_axis,
    })
}

/// Linear interpolation of (t, y) (t strictly increasing) at `t0 + i * dt`, i = 0..t.len().
pub(crate) fn interp_uniform(t: &[f64], y: &[f64], t0: f64, dt: f64) -> Vec<f64> {
    let n = t.len();
    let mut out = Vec::with_capacity(n);
    let mut k = 0usize;
    for i in 0..n {
        let ti = t0 + i as f64 * dt;
        while k + 2 < n && t[k + 1] < ti {
            k += 1;
        }
        let (ta, tb) = (t[k], t[k + 1]);
        let w = ((ti - ta) / (tb - ta)).clamp(0.0, 1.0);
        out.push(y[k] + w * (y[k + 1] - y[k]));
    }
    out
}

fn read_wav(path: &Path, bytes: Option<&[u8]>, opts: &ReadOptions) -> Result<Recording> {
    let wav_err = wav_error(path);
    let unreadable = |e: hound::Error| {
        wav_err(WavProblem::Unreadable {
            message: e.to_string(),
        })
    };
    match bytes {
        Some(b) => match hound::WavReader::new(std::io::Cursor::new(b)) {
            Ok(reader) => {
                let spec = reader.spec();
                if spec.sample_format == hound::SampleFormat::Float && spec.bits_per_sample == 32 {
                    float_wav_from_bytes(path, reader, opts)
                } else {
                    read_wav_from(path, reader, opts)
                }
            }
            // hound refuses 64-bit floats; anything else keeps hound's message.
            Err(e) => match crate::wav64::float64_header(&mut std::io::Cursor::new(b)) {
                Some(h) => float64_wav_from_bytes(path, &h, b, opts),
                None => Err(unreadable(e)),
            },
        },
        None => {
            if !path.exists() {
                return Err(io_err(
                    "read",
                    path,
                    &std::io::Error::from(std::io::ErrorKind::NotFound),
                ));
            }
            match hound::WavReader::open(path) {
                Ok(reader) => read_wav_from(path, reader, opts),
                Err(e) => {
                    let float64 = std::fs::File::open(path).ok().and_then(|f| {
                        crate::wav64::float64_header(&mut std::io::BufReader::new(f))
                    });
                    match float64 {
                        Some(h) => {
                            let b = std::fs::read(path).map_err(|e| io_err("read", path, &e))?;
                            float64_wav_from_bytes(path, &h, &b, opts)
                        }
                        None => Err(unreadable(e)),
                    }
                }
            }
        }
    }
}

/// A 64-bit float WAV in memory (`h`: its header, [`crate::wav64`]): its data chunk decoded
/// into the channels, `f64` values times `opts.scale`.
fn float64_wav_from_bytes(
    path: &Path,
    h: &crate::wav64::Float64Wav,
    bytes: &[u8],
    opts: &ReadOptions,
) -> Result<Recording> {
    check_wav_scale(opts)?;
    let nch = usize::from(h.channels);
    let data = bytes.get(h.data_offset as usize..).unwrap_or(&[]);
    let declared = h.frames() as usize;
    if data.len() / (8 * nch) < declared {
        return Err(wav_error(path)(WavProblem::Truncated {
            message: format!(
                "the data chunk declares {} samples, the file holds {}",
                declared * nch,
                data.len() / 8
            ),
        }));
    }
    let samples = crate::stream::deinterleave(
        &data[..8 * nch * declared],
        nch,
        opts.scale,
        f64::from_le_bytes,
    );
    wav_recording(path, h.sample_rate, opts, samples)
}

/// The error of a WAV file at `path`.
fn wav_error(path: &Path) -> impl Fn(WavProblem) -> SignalError + '_ {
    move |problem| SignalError::Wav {
        path: path.display().to_string(),
        problem,
    }
}

/// A 32-bit float WAV in memory: its data chunk decoded straight into the channels (the same
/// values as hound's sample iterator, `f32 as f64 * scale`, without an interleaved copy).
fn float_wav_from_bytes(
    path: &Path,
    reader: hound::WavReader<std::io::Cursor<&[u8]>>,
    opts: &ReadOptions,
) -> Result<Recording> {
    let wav_err = wav_error(path);
    let spec = reader.spec();
    let (nch, _, k) = wav_layout(&spec, opts, &wav_err)?;
    let declared = reader.len() as usize;
    let cursor = reader.into_inner();
    let start = (cursor.position() as usize).min(cursor.get_ref().len());
    let data = &cursor.get_ref()[start..];
    if data.len() / 4 < declared {
        return Err(wav_err(WavProblem::Truncated {
            message: format!(
                "the data chunk declares {declared} samples, the file holds {}",
                data.len() / 4
            ),
        }));
    }
    let n = declared / nch;
    let samples = crate::stream::deinterleave(&data[..4 * nch * n], nch, k, crate::stream::f32_le);
    wav_recording(path, spec.sample_rate, opts, samples)
}

fn read_wav_from<R: std::io::Read>(
    path: &Path,
    reader: hound::WavReader<R>,
    opts: &ReadOptions,
) -> Result<Recording> {
    let wav_err = wav_error(path);
    let spec = reader.spec();
    let (nch, float, k) = wav_layout(&spec, opts, &wav_err)?;
    let truncated = |e: hound::Error| {
        wav_err(WavProblem::Truncated {
            message: e.to_string(),
        })
    };
    let interleaved: Vec<f64> = if float {
        reader
            .into_samples::<f32>()
            .map(|s| s.map(|v| v as f64 * k))
            .collect::<std::result::Result<_, _>>()
            .map_err(truncated)?
    } else {
        reader
            .into_samples::<i32>()
            .map(|s| s.map(|v| v as f64 * k))
            .collect::<std::result::Result<_, _>>()
            .map_err(truncated)?
    };
    let n = interleaved.len() / nch;
    let samples = (0..nch)
        .map(|c| {
            interleaved
                .iter()
                .skip(c)
                .step_by(nch)
                .take(n)
                .copied()
                .collect()
        })
        .collect();
    wav_recording(path, spec.sample_rate, opts, samples)
}

/// The recording of a WAV's decoded channels: refused without samples; its rate checked
/// against `opts.fs_hz`, names and units from its sidecar, every sample finite.
fn wav_recording(
    path: &Path,
    sample_rate: u32,
    opts: &ReadOptions,
    samples: Vec<Vec<f64>>,
) -> Result<Recording> {
    if samples.first().map_or(true, |s| s.is_empty()) {
        return Err(wav_error(path)(WavProblem::NoSamples));
    }
    let fs = reconcile_fs(
        &path.display().to_string(),
        "the WAV header".into(),
        f64::from(sample_rate),
        opts.fs_hz,
    )?;
    named_recording(path, fs, samples)
}

/// The recording of a WAV's or `.npy` file's channels at `fs_hz`: names, units and start time
/// from its sidecar `<path>.json` ([`wav_names`]), every sample finite.
fn named_recording(path: &Path, fs_hz: f64, samples: Vec<Vec<f64>>) -> Result<Recording> {
    let (names, units) = wav_names(path, samples.len())?;
    let channels: Vec<Channel> = samples
        .into_iter()
        .zip(names.into_iter().zip(units))
        .map(|(samples, (name, unit))| Channel {
            placement: Default::default(),
            name,
            unit,
            samples,
        })
        .collect();
    check_finite(&channels)?;
    Ok(Recording {
        fs_hz,
        channels,
        time_axis: sidecar_time_axis(&sidecar_of(path), fs_hz)?,
    })
}

/// The time axis of a WAV or raw recording whose sidecar gives its `"start_time"` (ISO 8601 /
/// RFC 3339 text, or a number of seconds since 1970, 0 to 1e11; as `vibmode segment` reads
/// it): column `start_time`, the header's rate, origin that time. `None` without a sidecar or
/// without the key; an error naming the value when it is no time.
fn sidecar_time_axis(sidecar: &Path, fs_hz: f64) -> Result<Option<TimeAxis>> {
    // A missing or malformed sidecar gives none here; the sidecar's own reader reports it.
    let Some(text) = crate::stream::sidecar_start_time(sidecar) else {
        return Ok(None);
    };
    let origin = crate::delimited::parse_datetime(text.as_bytes())
        .map(|(s, ns)| s as f64 + f64::from(ns) * 1e-9)
        .or_else(|| text.trim().parse::<f64>().ok())
        .filter(|u| u.is_finite() && (0.0..=1e11).contains(u));
    match origin {
        Some(u) => Ok(Some(TimeAxis {
            column: "start_time".into(),
            fs_hz,
            jitter_rel: 0.0,
            start_s: 0.0,
            origin_unix_s: Some(u),
        })),
        None => Err(SignalError::Sidecar {
            path: sidecar.display().to_string(),
            problem: SidecarProblem::StartTime {
                value: vibmode_core::cap_message(&format!("{text:?}"), 60),
            },
        }),
    }
}

/// The optional JSON sidecar of a WAV file (`<path>.json`): channel names and units, which WAV
/// cannot hold. vibmode writes one beside every WAV it writes; other keys are ignored.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct WavSidecar {
    /// Channel names, in the WAV's channel order (none given: `ch0`, `ch1`, ..., as without a
    /// sidecar; a sidecar may hold only a `start_time`, or an `.npy` file's `fs_hz`).
    #[serde(default)]
    pub channels: Vec<String>,
    /// Units per channel (optional; same length as `channels`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub units: Option<Vec<String>>,
}

/// Channel names and units of a WAV or `.npy` file: from `<path>.json` when it exists, else
/// `ch0`, `ch1`, ...
pub(crate) fn wav_names(path: &Path, nch: usize) -> Result<(Vec<String>, Vec<String>)> {
    let side = sidecar_of(path);
    if !side.is_file() {
        return Ok((
            (0..nch).map(|c| format!("ch{c}")).collect(),
            vec![String::new(); nch],
        ));
    }
    let sp = side.display().to_string();
    let text =
        vibmode_core::files::read_text_capped(&side).map_err(|e| io_err("read", &side, &e))?;
    let bad = |problem: SidecarProblem| SignalError::Sidecar {
        path: sp.clone(),
        problem,
    };
    let w: WavSidecar = serde_json::from_str(&text).map_err(|e| {
        bad(SidecarProblem::WavJson {
            message: e.to_string(),
        })
    })?;
    let names = if w.channels.is_empty() {
        (0..nch).map(|c| format!("ch{c}")).collect()
    } else {
        w.channels
    };
    if names.len() != nch {
        return Err(bad(SidecarProblem::WavChannels {
            names: names.len(),
            channels: nch,
        }));
    }
    let units = match w.units {
        Some(u) if u.len() == nch => u,
        Some(u) => {
            return Err(bad(SidecarProblem::WavUnits {
                units: u.len(),
                channels: nch,
            }))
        }
        None => vec![String::new(); nch],
    };
    Ok((names, units))
}

/// The JSON sidecar of a raw binary file.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Sidecar {
    /// Sampling rate, Hz.
    pub fs_hz: f64,
    /// `"f32"` or `"f64"` (little-endian).
    pub dtype: String,
    /// Channel names, in interleaving order; their count is the channel count.
    pub channels: Vec<String>,
    /// Units per channel (optional; same length as `channels`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub units: Option<Vec<String>>,
}

/// `<path>.json`: the sidecar of a WAV or `.npy` file, and the first one tried for a raw file.
pub(crate) fn sidecar_of(path: &Path) -> PathBuf {
    let mut side = path.as_os_str().to_owned();
    side.push(".json");
    side.into()
}

/// The sidecar paths tried for a raw file, in order: `<path>.json`, then `<stem>.json`.
pub fn sidecar_candidates(path: &Path) -> Vec<PathBuf> {
    let mut v = vec![sidecar_of(path)];
    if path.extension().is_some() {
        v.push(path.with_extension("json"));
    }
    v
}

/// A raw file's sidecar, checked: where it is, what it says and the bytes per value.
pub(crate) struct RawLayout {
    /// The sidecar's path, for messages.
    pub sidecar_path: String,
    /// Its content.
    pub side: Sidecar,
    /// Bytes per value (4 or 8).
    pub width: usize,
}

/// Finds, reads and checks the sidecar of the raw file `path`.
pub(crate) fn raw_layout(path: &Path) -> Result<RawLayout> {
    let cands = sidecar_candidates(path);
    let side_path = cands
        .iter()
        .find(|c| c.is_file())
        .ok_or_else(|| SignalError::Sidecar {
            path: cands
                .iter()
                .map(|c| c.display().to_string())
                .collect::<Vec<_>>()
                .join(" or "),
            problem: SidecarProblem::NotFound,
        })?;
    let sp = side_path.display().to_string();
    let text = vibmode_core::files::read_text_capped(side_path)
        .map_err(|e| io_err("read", side_path, &e))?;
    let side: Sidecar = serde_json::from_str(&text).map_err(|e| SignalError::Sidecar {
        path: sp.clone(),
        problem: SidecarProblem::RawJson {
            message: e.to_string(),
        },
    })?;
    let side_err = |problem: SidecarProblem| SignalError::Sidecar {
        path: sp.clone(),
        problem,
    };
    let width = match side.dtype.as_str() {
        "f32" | "float32" => 4,
        "f64" | "float64" => 8,
        other => {
            return Err(side_err(SidecarProblem::Dtype {
                dtype: other.to_string(),
            }))
        }
    };
    let nch = side.channels.len();
    if nch == 0 {
        return Err(side_err(SidecarProblem::NoChannels));
    }
    if let Some(u) = &side.units {
        if u.len() != nch {
            return Err(side_err(SidecarProblem::Units {
                units: u.len(),
                channels: nch,
            }));
        }
    }
    if !(side.fs_hz.is_finite() && side.fs_hz > 0.0) {
        return Err(side_err(SidecarProblem::Rate { fs_hz: side.fs_hz }));
    }
    Ok(RawLayout {
        sidecar_path: sp,
        side,
        width,
    })
}

fn read_npy(path: &Path, bytes: Option<&[u8]>, opts: &ReadOptions) -> Result<Recording> {
    let owned;
    let bytes = match bytes {
        Some(b) => b,
        None => {
            owned = std::fs::read(path).map_err(|e| io_err("read", path, &e))?;
            &owned
        }
    };
    let layout =
        crate::npy::npy_layout(path, &mut std::io::Cursor::new(bytes), bytes.len() as u64)?;
    let fs = crate::npy::npy_rate(path, opts.fs_hz)?;
    named_recording(
        path,
        fs,
        crate::npy::npy_channels(&bytes[layout.data_offset as usize..], &layout),
    )
}

fn read_raw(path: &Path, opts: &ReadOptions) -> Result<Recording> {
    let p = path.display().to_string();
    let RawLayout {
        sidecar_path: sp,
        side,
        width,
    } = raw_layout(path)?;
    let nch = side.channels.len();
    let bytes = std::fs::read(path).map_err(|e| io_err("read", path, &e))?;
    let frame = width * nch;
    if bytes.len() % frame != 0 {
        return Err(SignalError::RawSize {
            path: p,
            bytes: bytes.len(),
            frame_bytes: frame,
            channels: nch,
            dtype_bytes: width,
        });
    }
    let n = bytes.len() / frame;
    if n == 0 {
        return Err(SignalError::EmptyFile {
            path: p,
            expected: RAW_EXPECTED,
        });
    }
    let fs = reconcile_fs(&p, format!("the sidecar {sp}"), side.fs_hz, opts.fs_hz)?;
    let mut channels: Vec<Channel> = side
        .channels
        .iter()
        .enumerate()
        .map(|(i, name)| Channel {
            placement: Default::default(),
            name: name.clone(),
            unit: side
                .units
                .as_ref()
                .and_then(|u| u.get(i).cloned())
                .unwrap_or_default(),
            samples: Vec::with_capacity(n),
        })
        .collect();
    for (k, chunk) in bytes.chunks_exact(width).enumerate() {
        let v = if width == 4 {
            f32::from_le_bytes([chunk[0], chunk[1], chunk[2], chunk[3]]) as f64
        } else {
            f64::from_le_bytes([
                chunk[0], chunk[1], chunk[2], chunk[3], chunk[4], chunk[5], chunk[6], chunk[7],
            ])
        };
        channels[k % nch].samples.push(v);
    }
    check_finite(&channels)?;
    Ok(Recording {
        fs_hz: fs,
        channels,
        time_axis: sidecar_time_axis(Path::new(&sp), fs)?,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};

    /// The direct decoding of a 32-bit float WAV gives hound's sample iterator's values bit for
    /// bit (`f32 as f64 * scale`, channels de-interleaved), on seeded random frames of 1 to 9
    /// channels (NaN-free, with subnormals and extremes), at scales 1 and 19.62.
    #[test]
    fn float_wav_decoded_directly_equals_hounds_samples() {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(11);
        for case in 0..40 {
            let nch = 1 + case % 9;
            let frames = rng.gen_range(1..300);
            let spec = hound::WavSpec {
                channels: nch as u16,
                sample_rate: 1000,
                bits_per_sample: 32,
                sample_format: hound::SampleFormat::Float,
            };
            let mut buf = std::io::Cursor::new(Vec::new());
            {
                let mut w = hound::WavWriter::new(&mut buf, spec).unwrap();
                for _ in 0..frames * nch {
                    let v: f32 = match rng.gen_range(0..10) {
                        0 => f32::MIN_POSITIVE / 3.0,
                        1 => f32::MAX,
                        2 => -0.0,
                        _ => rng.gen_range(-100.0..100.0),
                    };
                    w.write_sample(v).unwrap();
                }
                w.finalize().unwrap();
            }
            let bytes = buf.into_inner();
            let path = Path::new("case.wav");
            for scale in [1.0, 19.62] {
                let opts = ReadOptions {
                    scale,
                    ..ReadOptions::default()
                };
                let reader = || hound::WavReader::new(std::io::Cursor::new(&bytes[..])).unwrap();
                let a = read_wav_from(path, reader(), &opts).unwrap();
                let b = float_wav_from_bytes(path, reader(), &opts).unwrap();
                assert_eq!(a.fs_hz, b.fs_hz);
                assert_eq!(a.channels.len(), nch);
                for (x, y) in a.channels.iter().zip(&b.channels) {
                    assert_eq!(x.samples.len(), frames);
                    let bits = |v: &[f64]| v.iter().map(|s| s.to_bits()).collect::<Vec<_>>();
                    assert_eq!(
                        bits(&x.samples),
                        bits(&y.samples),
                        "case {case} scale {scale}"
                    );
                }
            }
        }
    }

    /// A 64-bit float WAV (which hound refuses) is read whole, from its bytes and from its path,
    /// and streamed block by block, to the values written times the scale; one cut off in its
    /// data chunk, a NaN sample and an absurd scale are one-line errors.
    #[test]
    fn a_64_bit_float_wav_is_read_and_streamed_as_written() {
        use crate::wav64::tests::{fmt_chunk, wav_bytes};
        let dir = tempfile::tempdir().unwrap();
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(64);
        let (nch, frames) = (3usize, 1000usize);
        let values: Vec<f64> = (0..nch * frames)
            .map(|_| rng.gen_range(-50.0..50.0))
            .collect();
        let bytes = wav_bytes(&fmt_chunk(3, nch as u16, 2000, 64), &values, true);
        let path = dir.path().join("f64.wav");
        std::fs::write(&path, &bytes).unwrap();
        let opts = ReadOptions {
            scale: 2.0,
            ..ReadOptions::default()
        };
        let expect = |c: usize, k: usize| 2.0 * values[k * nch + c];
        for rec in [
            read_path(&path, &opts).unwrap(),
            read_path_bytes(&path, &bytes, &opts).unwrap(),
        ] {
            assert_eq!((rec.fs_hz, rec.n_channels()), (2000.0, nch));
            for (c, ch) in rec.channels.iter().enumerate() {
                assert_eq!(ch.samples.len(), frames);
                assert!((0..frames).all(|k| ch.samples[k] == expect(c, k)));
            }
        }
        for max_frames in [1, 7, 300, 100_000] {
            let mut stream = crate::open_stream(&path, &opts).unwrap();
            assert_eq!(stream.info().n_frames, Some(frames as u64));
            assert_eq!(stream.info().fs_hz, 2000.0);
            let mut got = vec![Vec::new(); nch];
            while let Some(block) = stream.next_block(max_frames).unwrap() {
                for (g, ch) in got.iter_mut().zip(block.channels) {
                    g.extend(ch);
                }
            }
            for (c, g) in got.iter().enumerate() {
                assert!(g.len() == frames && (0..frames).all(|k| g[k] == expect(c, k)));
            }
        }

        // Cut off in the data chunk: the whole reader and the stream say so.
        let cut = dir.path().join("cut.wav");
        std::fs::write(&cut, &bytes[..bytes.len() - 100]).unwrap();
        let e = read_path(&cut, &opts).unwrap_err().to_string();
        assert!(
            e.contains("declares 3000 samples, the file holds 2987"),
            "{e}"
        );
        let e = crate::stream::tests::stream_error(&cut, &opts, 300);
        assert!(e.contains("995") && e.contains("1000"), "{e}");

        let mut bad = values.clone();
        bad[5] = f64::NAN;
        let nan = dir.path().join("nan.wav");
        std::fs::write(&nan, wav_bytes(&fmt_chunk(3, 3, 2000, 64), &bad, false)).unwrap();
        let e = read_path(&nan, &opts).unwrap_err().to_string();
        assert!(e.contains("NaN") || e.contains("not finite"), "{e}");
        let zero = ReadOptions {
            scale: 0.0,
            ..ReadOptions::default()
        };
        let e = read_path(&path, &zero).unwrap_err().to_string();
        assert!(e.contains("scale"), "{e}");
        assert!(crate::open_stream(&path, &zero).is_err());
    }
}
