//! # vibmode-signal
//!
//! Reading and writing multichannel acceleration records, and the paper's ideal anti-alias
//! resampling (METHOD.md section 2).
//!
//! - [`read_path`] reads delimited text (separator, header, units, decimal commas and a time
//!   column detected automatically), WAV (PCM integer or 32-bit float) and raw little-endian
//!   f32/f64 with a JSON sidecar into a [`Recording`]. The conventions are documented in
//!   `docs/formats.md`. [`DelimitedReader`] streams text files as blocks of rows.
//! - [`summarize`] reads a file block by block into a [`FileSummary`]: format, rate,
//!   channels, length, start time and each channel's range, mean, std and RMS (`vibmode info`).
//! - [`write_path`] writes CSV (with a `time_s` column), 32-bit float WAV or raw + sidecar.
//! - [`resample()`], [`Resampler`] and [`ResampleRecording::resample`] implement the ideal DFT low-pass
//!   followed by decimation (integer ratios) or Fourier resampling (other ratios, equal to
//!   `scipy.signal.resample`); see the [`resample`](mod@resample) module.
//!
//! Errors are [`SignalError`]; every message is one line naming the offending value and the fix.
//! No function panics on input data.
//!
//! ```
//! use vibmode_signal::{read_delimited, ReadOptions, ResampleParams, ResampleRecording};
//! // A semicolon file with decimal commas, a time column in ms and a trailing separator.
//! let mut text = String::from("Time (ms);Z-Axis [m/s^2];\n");
//! for i in 0..1000 {
//!     // 10 Hz tone at 1000 Hz sampling, written with decimal commas.
//!     let z = (2.0 * std::f64::consts::PI * 10.0 * i as f64 / 1000.0).sin();
//!     text.push_str(&format!("{};{};\n", i, z).replace('.', ","));
//! }
//! let rec = read_delimited(text.as_bytes(), "example.csv", &ReadOptions::default()).unwrap();
//! assert!((rec.fs_hz - 1000.0).abs() < 1e-9);
//! assert_eq!(rec.channels[0].name, "Z-Axis");
//! assert_eq!(rec.channels[0].unit, "m/s^2");
//!
//! // Ideal anti-alias filter at 25 Hz, then keep every 10th sample (1000 Hz -> 100 Hz):
//! // the 10 Hz tone passes unchanged.
//! let p = ResampleParams { fs_out_hz: 100.0, cutoff_hz: Some(25.0), filter: true };
//! let low = rec.resample(&p).unwrap();
//! assert_eq!(low.len(), 100);
//! let expected = (2.0 * std::f64::consts::PI * 10.0 * 7.0 / 100.0).sin();
//! assert!((low.channels[0].samples[7] - expected).abs() < 1e-9);
//! ```

pub mod delimited;
pub mod error;
mod npy;
mod number;
mod preprocess;
pub mod read;
pub mod records;
pub mod resample;
pub mod stream;
pub mod stream_resample;
pub mod stream_write;
pub mod summary;
mod wav64;
pub mod write;

pub use delimited::{Block, ColumnInfo, DateOrder, DelimitedReader, Separator, TimeText};
pub use error::{BinaryFormat, NpyProblem, SidecarProblem, SignalError, WavProblem};
pub use npy::NPY_MAGIC;
pub use preprocess::{preprocess, preprocess_with_spectra, Preprocessed};
pub use read::{
    expand_folders, read_delimited, read_delimited_bytes, read_path, read_path_bytes,
    recordings_in_folder, sidecar_candidates, time_unit_scale, Format, ReadOptions, Sidecar,
    WavSidecar,
};
pub use records::{ChainedRecords, StreamRecords};
pub use resample::ResampleRecording;
pub use resample::{
    planned_fs_out_hz, resample, resample_recording, ChannelSpectrum, ResampleMethod,
    ResampleParams, Resampler,
};
pub use stream::{
    open_stream, FrameBlock, FrameStream, StreamInfo, DEFAULT_BLOCK_FRAMES, KEEP_PARSED_MAX_VALUES,
};
pub use stream_resample::{
    resample_stream, FirDecimator, FirDesign, ResamplerKind, StreamResampleParams,
    StreamResampleSummary,
};
pub use stream_write::StreamWriter;
pub use summary::{summarize, ChannelSummary, FileSummary};
pub use vibmode_core::{
    Channel, ChannelSelector, Recording, RecordingError, RecordingView, TimeAxis,
};
pub use write::write_path;
