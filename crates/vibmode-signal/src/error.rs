//! The error type of this crate. Every message is one line that names the offending value and
//! says how to fix it.

/// Everything that can go wrong while reading, selecting, writing or resampling a recording.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum SignalError {
    /// A recording that breaks its invariants (NaN or infinite sample, bad rate, unequal channel
    /// lengths) or a channel that cannot be found.
    #[error(transparent)]
    Recording(#[from] vibmode_core::RecordingError),
    /// A NaN, infinite or too large sample in a file ([`vibmode_core::RecordingError::NonFinite`],
    /// [`vibmode_core::RecordingError::SampleTooLarge`]), with the file named: among many records
    /// the channel and sample alone do not tell which file to clean.
    #[error("{}: {source}", vibmode_core::quoted(.path))]
    BadSample {
        /// The file.
        path: String,
        /// The sample, its channel and index (boxed: it would make every `SignalError` larger).
        source: Box<vibmode_core::RecordingError>,
    },
    /// A file with two channels of the same name.
    #[error("{}: channels {} and {} are both named '{}'; give each channel its own name (in the file's header or its sidecar)", vibmode_core::quoted(.path), .first + 1, .second + 1, vibmode_core::quoted(.name))]
    SameChannelName {
        /// The file.
        path: String,
        /// The name.
        name: String,
        /// 0-based index of the first channel with it (the time column not counted).
        first: usize,
        /// 0-based index of the second.
        second: usize,
    },
    /// A record window (segmentation) that reaches past the end of the recording.
    #[error("record '{record}' (frames {start_frame}.. +{n_frames}) reaches past the end of the recording ({file_frames} frames); the segmentation does not fit this file")]
    WindowOutside {
        /// The record.
        record: String,
        /// Its first frame.
        start_frame: u64,
        /// Its length in frames.
        n_frames: usize,
        /// Frames in the file.
        file_frames: u64,
    },
    /// The file could not be opened, read or written.
    #[error("cannot {action} {path_q}: {message}; check the path and permissions", path_q = vibmode_core::quoted(.path))]
    Io {
        /// "read" or "write".
        action: &'static str,
        /// The file.
        path: String,
        /// The operating system's message.
        message: String,
    },
    /// A folder given as an input holds no recording.
    #[error("the folder {path_q} holds no recording (.csv, .txt, .tsv, .dat, .asc, .wav, NumPy .npy, or raw .f32, .f64, .bin, .raw with a .json sidecar); give the record files or another folder", path_q = vibmode_core::quoted(.path))]
    FolderWithoutRecordings {
        /// The folder.
        path: String,
    },
    /// A folder given as an input holds one record name in two formats (busgen's `--csv` writes
    /// `rec01.f32` and `rec01.csv`): the same record twice.
    #[error("the folder {path_q} holds {first_q} and {second_q}, the same record in two formats; give the files of one format (e.g. {path_q}/*.{ext})", path_q = vibmode_core::quoted(.path), first_q = vibmode_core::quoted(.first), second_q = vibmode_core::quoted(.second), ext = vibmode_core::quoted(.first.rsplit('.').next().unwrap_or_default()))]
    FolderRecordTwice {
        /// The folder.
        path: String,
        /// The first file name.
        first: String,
        /// The second file name, of the same stem.
        second: String,
    },
    /// The file has no content at all.
    #[error("{path_q} is empty; expected {expected}", path_q = vibmode_core::quoted(.path))]
    EmptyFile {
        /// The file.
        path: String,
        /// What the file should hold, for its format.
        expected: &'static str,
    },
    /// Bytes that are not text (NUL or other control characters) where delimited text was
    /// expected.
    #[error("{path_q} is not a text file (line {line} has control bytes); give a CSV/text export, a .wav, a .npy, or raw samples with a .json sidecar", path_q = vibmode_core::quoted(.path))]
    NotText {
        /// The file.
        path: String,
        /// 1-based line number.
        line: usize,
    },
    /// UTF-16 text (a byte-order mark `FF FE` or `FE FF`, as Excel's "Unicode Text" export).
    #[error("{path_q} is UTF-16 text (as Excel's \"Unicode Text\" export); save it as \"CSV UTF-8\" or convert it (iconv -f UTF-16 -t UTF-8 IN > OUT)", path_q = vibmode_core::quoted(.path))]
    Utf16Text {
        /// The file.
        path: String,
    },
    /// Excel's `sep=X` directive names a separator vibmode does not read.
    #[error("{path_q}: the separator directive on line {line} names '{sep_q}'; vibmode reads comma, semicolon, tab or whitespace separators", path_q = vibmode_core::quoted(.path), sep_q = vibmode_core::quoted(.sep))]
    UnsupportedSeparator {
        /// The file.
        path: String,
        /// 1-based line number.
        line: usize,
        /// The separator named.
        sep: String,
    },
    /// A header row but no data rows.
    #[error("{path_q} has a header row but no data rows; check that the file was fully exported", path_q = vibmode_core::quoted(.path))]
    NoDataRows {
        /// The file.
        path: String,
    },
    /// A data row whose number of cells differs from the header (or first row).
    #[error("line {line} of {path_q} has {found} columns but {expected} were expected (from line {reference_line}); fix or delete that row", path_q = vibmode_core::quoted(.path))]
    RaggedRow {
        /// The file.
        path: String,
        /// 1-based line number of the bad row.
        line: usize,
        /// Number of cells found on that row.
        found: usize,
        /// Number of cells expected.
        expected: usize,
        /// 1-based line the expected count comes from.
        reference_line: usize,
    },
    /// An empty cell in a data row: a missing value (pandas writes NaN as an empty cell).
    #[error("line {line}, column {column} ('{column_name_q}') of {path_q} is empty (a missing value; pandas writes NaN as an empty cell); fill or interpolate the gap, or delete the row", path_q = vibmode_core::quoted(.path), column_name_q = vibmode_core::quoted(.column_name))]
    EmptyCell {
        /// The file.
        path: String,
        /// 1-based line number.
        line: usize,
        /// 1-based column number.
        column: usize,
        /// Column name (from the header or `chN`).
        column_name: String,
    },
    /// A file in a binary format that vibmode does not read but that a user can export to one
    /// it does (recognised by its first bytes).
    #[error("{path_q} is {what}, not delimited text; {fix}", path_q = vibmode_core::quoted(.path), what = .format.description(), fix = .format.fix())]
    BinaryFormat {
        /// The file.
        path: String,
        /// The format recognised.
        format: BinaryFormat,
    },
    /// A cell that is not a number.
    #[error("line {line}, column {column} ('{column_name_q}') of {path_q}: '{text_q}' is not a number; fix the cell or delete the row", path_q = vibmode_core::quoted(.path), column_name_q = vibmode_core::quoted(.column_name), text_q = vibmode_core::quoted(.text))]
    NotNumeric {
        /// The file.
        path: String,
        /// 1-based line number.
        line: usize,
        /// 1-based column number.
        column: usize,
        /// Column name (from the header or `chN`).
        column_name: String,
        /// The offending text (truncated to 40 characters).
        text: String,
    },
    /// No time column and no `fs_hz` given.
    #[error("no time column in {path_q}; give its sampling rate (fs_hz)", path_q = vibmode_core::quoted(.path))]
    NoSampleRate {
        /// The file.
        path: String,
    },
    /// The rate given by the user and the one found in the file disagree by more than 1 %.
    #[error("{path_q}: the sampling rate from {source_name_q} is {} Hz but {} Hz was given (more than 1% apart); give no rate or fix the file", vibmode_core::num(.file_fs_hz), vibmode_core::num(.given_fs_hz), path_q = vibmode_core::quoted(.path), source_name_q = vibmode_core::quoted(.source_name))]
    SampleRateMismatch {
        /// The file.
        path: String,
        /// "the time column 'Time'", "the WAV header", "the sidecar".
        source_name: String,
        /// Rate found in the file, Hz.
        file_fs_hz: f64,
        /// Rate given in the options, Hz.
        given_fs_hz: f64,
    },
    /// The time column is not uniform enough.
    #[error("time column '{column_q}' of {path_q} is not uniform: jitter {jitter_rel:.3e} of the mean step exceeds {max_jitter_rel:.3e}; allow a non-uniform time column (allow_nonuniform) to interpolate onto a uniform grid at {mean_fs_hz:.6} Hz", path_q = vibmode_core::quoted(.path), column_q = vibmode_core::quoted(.column))]
    NonUniformTime {
        /// The file.
        path: String,
        /// Time column name.
        column: String,
        /// max |dt - mean dt| / mean dt.
        jitter_rel: f64,
        /// The allowed maximum.
        max_jitter_rel: f64,
        /// The mean rate, Hz.
        mean_fs_hz: f64,
    },
    /// The time column does not strictly increase.
    #[error("time column '{column_q}' of {path_q} does not increase at line {line} ({} then {}); sort the rows or remove duplicates", vibmode_core::num(.previous), vibmode_core::num(.value), path_q = vibmode_core::quoted(.path), column_q = vibmode_core::quoted(.column))]
    TimeNotIncreasing {
        /// The file.
        path: String,
        /// Time column name.
        column: String,
        /// 1-based line number.
        line: usize,
        /// Previous time value, s.
        previous: f64,
        /// This time value, s.
        value: f64,
    },
    /// A first column without a name that starts at 0 or 1, read as pandas' row index, does not
    /// count up by one.
    #[error("the unnamed first column of {path_q} starts like a pandas row index but holds {} at line {line}, not {}; give it a name in the header to read it as a channel, or write the file with index=False", vibmode_core::num(.value), vibmode_core::num(.expected), path_q = vibmode_core::quoted(.path))]
    NotARowIndex {
        /// The file.
        path: String,
        /// The column's name as read (`ch0` or `Unnamed: 0`).
        column: String,
        /// 1-based line number (0 when unknown).
        line: usize,
        /// The value found.
        value: f64,
        /// The row counter's value expected there.
        expected: f64,
    },
    /// The file has no data channel (e.g. only a time column).
    #[error("{path_q} has no data channels (only a time column?); check the file", path_q = vibmode_core::quoted(.path))]
    NoChannels {
        /// The file.
        path: String,
    },
    /// A missing or malformed JSON sidecar of a raw binary or WAV file.
    #[error("sidecar {path_q}: {problem}", path_q = vibmode_core::quoted(.path))]
    Sidecar {
        /// The sidecar file (or the expected names).
        path: String,
        /// What is wrong, with the values, and how to fix it.
        problem: SidecarProblem,
    },
    /// A binary (raw) file whose size does not fit the sidecar.
    #[error("{path_q} has {bytes} bytes, not a multiple of {frame_bytes} (= {channels} channels x {dtype_bytes} bytes); check dtype and channels in the sidecar", path_q = vibmode_core::quoted(.path))]
    RawSize {
        /// The file.
        path: String,
        /// File size.
        bytes: usize,
        /// Bytes per frame.
        frame_bytes: usize,
        /// Channels.
        channels: usize,
        /// Bytes per value.
        dtype_bytes: usize,
    },
    /// A raw file that ends inside a frame: cut off mid-write, or a sidecar whose `dtype` or
    /// `channels` do not fit the data (found by the stream reader before any sample is used).
    #[error("{path_q} has {bytes} bytes, not a whole number of {frame_bytes}-byte frames ({channels} channels x {dtype_bytes} bytes): it was cut off mid-write or the sidecar's dtype/channels are wrong; check the sidecar, or keep the whole frames by cutting the file to {whole_bytes} bytes (truncate -s {whole_bytes})", path_q = vibmode_core::quoted(.path))]
    PartialFrame {
        /// The file.
        path: String,
        /// File size.
        bytes: u64,
        /// Bytes per frame.
        frame_bytes: u64,
        /// Channels.
        channels: usize,
        /// Bytes per value.
        dtype_bytes: usize,
        /// The size of the whole frames it holds.
        whole_bytes: u64,
    },
    /// A WAV file that cannot be used.
    #[error("WAV {path_q}: {problem}", path_q = vibmode_core::quoted(.path))]
    Wav {
        /// The file.
        path: String,
        /// What is wrong, with the values, and how to fix it.
        problem: WavProblem,
    },
    /// A NumPy `.npy` file that cannot be used.
    #[error("{path_q}: {problem}", path_q = vibmode_core::quoted(.path))]
    Npy {
        /// The file.
        path: String,
        /// What is wrong, with the values, and how to fix it.
        problem: NpyProblem,
    },
    /// A NumPy `.npy` file (which holds no rate) read without a sampling rate.
    #[error("{path_q} is a NumPy array, which holds no sampling rate; give its sampling rate (fs_hz), or write it into the sidecar {path_q}.json as {{\"fs_hz\": 20000}}", path_q = vibmode_core::quoted(.path))]
    NpyNoSampleRate {
        /// The file.
        path: String,
    },
    /// A file extension or format name that is not known.
    #[error("unknown format '{given_q}'; valid formats: delimited (.csv/.txt/.tsv/.dat), wav (.wav), raw (.f32/.f64/.bin/.raw + .json sidecar), npy (.npy)", given_q = vibmode_core::quoted(.given))]
    UnknownFormat {
        /// The name or extension given.
        given: String,
    },
    /// An invalid parameter value (resampling, read options...).
    #[error("{name} = {value} is invalid: {fix}")]
    InvalidParam {
        /// Parameter name, e.g. "fs_out_hz".
        name: &'static str,
        /// The value as text.
        value: String,
        /// The rule and a suggested fix.
        fix: String,
    },
    /// Too few samples for the requested operation.
    #[error("{what}: {n} samples is too few; {fix}")]
    TooShort {
        /// The operation.
        what: String,
        /// Number of samples available.
        n: usize,
        /// What is needed.
        fix: String,
    },
}

/// What makes a NumPy `.npy` file unusable (the detail of [`SignalError::Npy`]).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum NpyProblem {
    /// A header that cannot be read.
    #[error("its .npy header cannot be read ({message_q}); save the array again with numpy.save", message_q = vibmode_core::quoted(.message))]
    Header {
        /// What was found.
        message: String,
    },
    /// A data type other than little-endian float32 or float64.
    #[error("data type '{descr_q}' is not supported; save little-endian float32 or float64: numpy.save(path, a.astype('<f8'))", descr_q = vibmode_core::quoted(.descr))]
    Dtype {
        /// NumPy's type string (`<i8`, `>f8`, ...).
        descr: String,
    },
    /// Neither a 1-D nor a 2-D array.
    #[error("an array of shape {shape}; save a 1-D array of samples or a 2-D array of samples by channels")]
    Dimensions {
        /// The shape, as NumPy prints it.
        shape: String,
    },
    /// A shape with no samples or no channels.
    #[error(
        "an array of shape {shape} holds no samples; save the recording's samples by channels"
    )]
    Empty {
        /// The shape, as NumPy prints it.
        shape: String,
    },
    /// More columns than rows: most likely channels by samples.
    #[error("shape ({rows}, {columns}) would be {columns} channels of {rows} samples (rows are samples, columns channels); save the transpose: numpy.save(path, a.T)")]
    Transposed {
        /// Rows (samples).
        rows: u64,
        /// Columns (channels).
        columns: u64,
    },
    /// Data of another size than the shape needs.
    #[error("its data holds {bytes} bytes, not the shape {shape}'s values of {width} bytes each; the file is cut off or was changed, save it again")]
    DataSize {
        /// Bytes after the header.
        bytes: u64,
        /// The shape.
        shape: String,
        /// Bytes per value.
        width: usize,
    },
}

/// What an empty raw file should hold ([`SignalError::EmptyFile`]).
pub(crate) const RAW_EXPECTED: &str =
    "the raw samples its sidecar describes (one value per channel per frame)";

/// What makes a WAV file unusable (the detail of [`SignalError::Wav`]). The WAV library's own
/// messages are kept as their text.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum WavProblem {
    /// A header with no channel.
    #[error("the header declares 0 channels; re-export the file")]
    NoChannels,
    /// Float samples of another width than 32 bits.
    #[error("{bits}-bit float samples are not supported; convert to 32-bit float or PCM")]
    FloatBits {
        /// Bits per sample.
        bits: u16,
    },
    /// Integer samples wider than 32 bits (or of 0 bits).
    #[error("{bits}-bit integer samples are not supported; use 8, 16, 24 or 32 bits")]
    IntBits {
        /// Bits per sample.
        bits: u16,
    },
    /// Not a WAV file the reader understands.
    #[error("{}; check that it is a valid WAV file", .message.trim_end_matches('.'))]
    Unreadable {
        /// The WAV reader's message.
        message: String,
    },
    /// Samples that cannot be read (whole-file reader).
    #[error("{}; the file may be truncated", .message.trim_end_matches('.'))]
    Truncated {
        /// The WAV reader's message.
        message: String,
    },
    /// No sample at all.
    #[error("it contains zero samples; check the recording")]
    NoSamples,
    /// A sample that cannot be read at a frame (streamed reader).
    #[error("{} at frame {frame} of the {announced} its header announces: the file is cut off (a recording stopped mid-write?); re-export it, or cut the header's data size to the frames present", .message.trim_end_matches('.'))]
    CutOffAt {
        /// The WAV reader's message.
        message: String,
        /// The frame.
        frame: u64,
        /// The frames the header announces.
        announced: u64,
    },
    /// Fewer frames than the header announces (streamed reader).
    #[error("it ends after frame {frame} of the {announced} its header announces: the file is cut off (a recording stopped mid-write?); re-export it")]
    EndsEarly {
        /// The last frame present.
        frame: u64,
        /// The frames the header announces.
        announced: u64,
    },
    /// Writing failed.
    #[error("{message}; check the path and free space")]
    NotWritten {
        /// The WAV writer's message.
        message: String,
    },
}

/// What is wrong with a JSON sidecar (the detail of [`SignalError::Sidecar`]). The JSON
/// parser's own messages are kept as their text.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum SidecarProblem {
    /// A WAV file's sidecar that is not the expected JSON.
    #[error("{message}; expected {{\"channels\": [\"FL\", ...]}} (or delete it to name the channels ch0, ch1, ...)")]
    WavJson {
        /// The JSON parser's message.
        message: String,
    },
    /// A WAV file's sidecar naming another number of channels.
    #[error("names {names} channels but the file has {channels}; fix the channel list or delete the file")]
    WavChannels {
        /// Names in the sidecar.
        names: usize,
        /// Channels in the WAV.
        channels: usize,
    },
    /// A WAV file's sidecar with another number of units.
    #[error("has {units} units for {channels} channels; give one unit per channel")]
    WavUnits {
        /// Units in the sidecar.
        units: usize,
        /// Channels in the WAV.
        channels: usize,
    },
    /// A sidecar's `"start_time"` that is no time.
    #[error("has start_time {value}, neither an ISO 8601 time such as \"2026-11-27T07:31:00Z\" nor seconds since 1970 (0 to 1e11); fix or delete it")]
    StartTime {
        /// The value as written (JSON text).
        value: String,
    },
    /// A raw file without its sidecar.
    #[error("not found; a raw file needs a JSON sidecar like {{\"fs_hz\": 20000, \"dtype\": \"f32\", \"channels\": [\"FL\"]}}")]
    NotFound,
    /// A raw file's sidecar that is not the expected JSON.
    #[error("{message}; expected {{\"fs_hz\": 20000, \"dtype\": \"f32\"|\"f64\", \"channels\": [\"FL\", ...], \"units\": [\"m/s^2\", ...]}}")]
    RawJson {
        /// The JSON parser's message.
        message: String,
    },
    /// A sample type other than f32 and f64.
    #[error("dtype '{}' is not supported; use \"f32\" or \"f64\"", vibmode_core::quoted(.dtype))]
    Dtype {
        /// The type given.
        dtype: String,
    },
    /// No channel name.
    #[error("\"channels\" is empty; list one name per interleaved channel")]
    NoChannels,
    /// Another number of units than channels.
    #[error("\"units\" has {units} entries but \"channels\" has {channels}; give one unit per channel or omit \"units\"")]
    Units {
        /// Units given.
        units: usize,
        /// Channels named.
        channels: usize,
    },
    /// A rate that is not a positive finite number.
    #[error("fs_hz {fs_hz} must be a positive finite number, e.g. 20000")]
    Rate {
        /// The rate given.
        fs_hz: f64,
    },
    /// A sidecar that cannot be written.
    #[error("cannot serialise: {message}")]
    NotSerialised {
        /// The JSON writer's message.
        message: String,
    },
}

/// Convenient alias.
pub type Result<T> = std::result::Result<T, SignalError>;

pub(crate) fn io_err(
    action: &'static str,
    path: &std::path::Path,
    e: &std::io::Error,
) -> SignalError {
    SignalError::Io {
        action,
        path: path.display().to_string(),
        message: e.to_string(),
    }
}

/// `e` with the file `path` named where it is a bad sample ([`SignalError::BadSample`]).
pub(crate) fn in_file(path: &str, e: SignalError) -> SignalError {
    use vibmode_core::RecordingError as R;
    match e {
        SignalError::Recording(r @ (R::NonFinite { .. } | R::SampleTooLarge { .. })) => {
            SignalError::BadSample {
                path: path.to_string(),
                source: Box::new(r),
            }
        }
        e => e,
    }
}

/// [`vibmode_core::check_unique_names`] for the channels of the file `path`.
pub(crate) fn check_names_of<'a>(
    path: &std::path::Path,
    names: impl IntoIterator<Item = &'a str>,
) -> Result<()> {
    vibmode_core::check_unique_names(names).map_err(|e| match e {
        vibmode_core::RecordingError::SameName {
            name,
            first,
            second,
        } => SignalError::SameChannelName {
            path: path.display().to_string(),
            name,
            first,
            second,
        },
        other => SignalError::Recording(other),
    })
}

/// Binary formats recognised by their first bytes where delimited text was expected, each with
/// the way to export it to a format vibmode reads.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[non_exhaustive]
pub enum BinaryFormat {
    /// A spreadsheet workbook: Excel's `.xlsx`/`.xlsm` or LibreOffice's `.ods` (ZIP archives).
    ExcelWorkbook,
    /// A legacy Excel workbook (`.xls`: an OLE compound file).
    ExcelLegacy,
    /// A MATLAB MAT-file of version 5 to 7 (`MATLAB 5.0 MAT-file` header).
    MatFile,
    /// HDF5, as MATLAB's `-v7.3` MAT-files and `.h5` files.
    Hdf5,
    /// Apache Parquet (pandas' `to_parquet`).
    Parquet,
    /// National Instruments TDMS.
    Tdms,
    /// A gzip-compressed file.
    Gzip,
    /// Another ZIP archive.
    Zip,
}

impl BinaryFormat {
    /// The format recognised from the first bytes of the file at `path` (its extension tells a
    /// workbook from another ZIP archive when the first entry does not), if any.
    pub fn sniff(path: &str, head: &[u8]) -> Option<BinaryFormat> {
        if head.starts_with(b"PK\x03\x04") {
            // The first entry's name follows the 30-byte local header.
            let name = head.get(30..head.len().min(30 + 64)).unwrap_or(&[]);
            let ext = std::path::Path::new(path)
                .extension()
                .and_then(|e| e.to_str())
                .map(str::to_ascii_lowercase);
            let excel = name.starts_with(b"[Content_Types].xml")
                || name.starts_with(b"xl/")
                || name.starts_with(b"docProps/")
                || name.starts_with(b"_rels/")
                || name.starts_with(b"mimetype")
                || matches!(ext.as_deref(), Some("xlsx" | "xlsm" | "ods"));
            return Some(if excel {
                BinaryFormat::ExcelWorkbook
            } else {
                BinaryFormat::Zip
            });
        }
        let magic: [(&[u8], BinaryFormat); 6] = [
            (
                b"\xD0\xCF\x11\xE0\xA1\xB1\x1A\xE1",
                BinaryFormat::ExcelLegacy,
            ),
            (b"MATLAB 5.0 MAT-file", BinaryFormat::MatFile),
            (b"\x89HDF\r\n\x1a\n", BinaryFormat::Hdf5),
            (b"PAR1", BinaryFormat::Parquet),
            (b"TDSm", BinaryFormat::Tdms),
            (b"\x1f\x8b", BinaryFormat::Gzip),
        ];
        magic
            .iter()
            .find(|(m, _)| head.starts_with(m))
            .map(|&(_, f)| f)
    }

    /// What the file is, for messages (`an Excel workbook`).
    pub fn description(self) -> &'static str {
        match self {
            BinaryFormat::ExcelWorkbook => "a spreadsheet workbook (.xlsx, .ods)",
            BinaryFormat::ExcelLegacy => "an Excel 97-2003 workbook (.xls)",
            BinaryFormat::MatFile => "a MATLAB MAT-file",
            BinaryFormat::Hdf5 => "an HDF5 file (a MATLAB -v7.3 MAT-file or .h5)",
            BinaryFormat::Parquet => "an Apache Parquet file",
            BinaryFormat::Tdms => "an NI TDMS file",
            BinaryFormat::Gzip => "gzip-compressed",
            BinaryFormat::Zip => "a ZIP archive",
        }
    }

    /// How to export it to a format vibmode reads.
    pub fn fix(self) -> &'static str {
        match self {
            BinaryFormat::ExcelWorkbook | BinaryFormat::ExcelLegacy => {
                "save the sheet as \"CSV UTF-8\" (Excel) or \"Text CSV\" (LibreOffice), or in Python: pandas.read_excel(IN).to_csv(OUT, index=False)"
            }
            BinaryFormat::MatFile | BinaryFormat::Hdf5 => {
                "export the channels in MATLAB with writetable(T, 'OUT.csv') or writematrix(A, 'OUT.csv'), or write them as a WAV (audiowrite)"
            }
            BinaryFormat::Parquet => {
                "convert it in Python: pandas.read_parquet(IN).to_csv(OUT, index=False)"
            }
            BinaryFormat::Tdms => {
                "export it to CSV (NI DIAdem or LabVIEW, or in Python: nptdms.TdmsFile.read(IN).as_dataframe().to_csv(OUT, index=False))"
            }
            BinaryFormat::Gzip => "decompress it first (gunzip)",
            BinaryFormat::Zip => "extract the recordings from it first (unzip)",
        }
    }
}
