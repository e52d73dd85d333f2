//! Writing recordings: CSV, 32-bit float WAV, raw binary + JSON sidecar.

use crate::error::{Result, SignalError};
use crate::stream_write::StreamWriter;
use std::path::Path;
use vibmode_core::Recording;

/// Writes `rec` to `path`, choosing the format by extension (case-insensitive):
/// - `.csv`, `.txt`, `.tsv`, `.dat`: comma-separated text (tab for `.tsv`), header
///   `time_s,<name> (<unit>),...` (just `<name>` when the unit is empty), then one row per sample
///   with the time in seconds (`start_s + i / fs_hz`) and the shortest decimal that reads back to
///   the same f64 (lossless);
/// - `.wav`: 32-bit float WAV, rate rounded to whole Hz (error if `fs_hz` is not an integer),
///   plus a sidecar `<path>.json` with the channel names and units (which WAV cannot hold; the
///   reader uses it);
/// - `.f32`, `.f64`, `.bin`, `.raw`: interleaved little-endian samples (`f32` for `.f32`,
///   otherwise `f64`) plus a sidecar `<path>.json` (`fs_hz`, `dtype`, `channels`, `units`).
///
/// Errors: unknown extension, empty recording, I/O errors.
pub fn write_path(path: &Path, rec: &Recording) -> Result<()> {
    // Never write what vibmode itself would refuse to read (resampling extreme values once
    // wrote +-inf).
    vibmode_core::check_finite(&rec.channels)?;
    if rec.channels.is_empty() || rec.is_empty() {
        return Err(SignalError::TooShort {
            what: format!("writing {}", path.display()),
            n: rec.len(),
            fix: "the recording has no channels or no samples; nothing to write".into(),
        });
    }
    // One writer for both: the whole recording is one block of the streamed writer, which
    // writes under `<path>.partial` and renames when complete.
    let names: Vec<String> = rec.channels.iter().map(|c| c.name.clone()).collect();
    let units: Vec<String> = rec.channels.iter().map(|c| c.unit.clone()).collect();
    let mut w = StreamWriter::create(path, &names, &units, rec.fs_hz, rec.time_s(0))?;
    let block: Vec<&[f64]> = rec.channels.iter().map(|c| c.samples.as_slice()).collect();
    w.write_block(&block)?;
    w.finish()
}
