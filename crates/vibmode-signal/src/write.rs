//! Writing recordings: CSV, 32-bit float WAV, raw binary + JSON sidecar.

use crate::error::{io_err, Result, SignalError};
use crate::read::{Format, Sidecar, WavSidecar};
use std::io::Write;
use std::path::{Path, PathBuf};
use vibmode_core::files::write_atomic;
use vibmode_core::{check_fs, Recording};

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
    check_fs(rec.fs_hz, "fs_hz of the recording to write")?;
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
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .unwrap_or("")
        .to_ascii_lowercase();
    let on_io = |e: std::io::Error| io_err("write", path, &e);
    let format = Format::from_extension(&ext);
    // Each file (data, then its sidecar) is written under a temporary name and renamed when
    // complete: an interrupted run leaves the old file or the new one, never part of one.
    let sidecar = match format {
        Some(Format::Delimited) => {
            let sep = if ext == "tsv" { b'\t' } else { b',' };
            return write_atomic(path, on_io, |tmp| write_csv(tmp, rec, sep));
        }
        Some(Format::Wav) => {
            write_atomic(path, on_io, |tmp| write_wav(tmp, rec))?;
            serde_json::to_string_pretty(&WavSidecar {
                channels: rec.channels.iter().map(|c| c.name.clone()).collect(),
                units: Some(rec.channels.iter().map(|c| c.unit.clone()).collect()),
            })
        }
        Some(Format::Raw) => {
            let f32_out = ext == "f32";
            write_atomic(path, on_io, |tmp| write_raw(tmp, rec, f32_out))?;
            serde_json::to_string_pretty(&Sidecar {
                fs_hz: rec.fs_hz,
                dtype: if f32_out { "f32" } else { "f64" }.into(),
                channels: rec.channels.iter().map(|c| c.name.clone()).collect(),
                units: Some(rec.channels.iter().map(|c| c.unit.clone()).collect()),
            })
        }
        None => {
            return Err(SignalError::UnknownFormat {
                given: if ext.is_empty() {
                    format!("(no extension) {}", path.display())
                } else {
                    format!(".{ext}")
                },
            })
        }
    };
    let mut sp = path.as_os_str().to_owned();
    sp.push(".json");
    let sp = PathBuf::from(sp);
    let text = sidecar.map_err(|e| SignalError::Sidecar {
        path: sp.display().to_string(),
        reason: format!("cannot serialise: {e}"),
    })?;
    let on_io = |e: std::io::Error| io_err("write", &sp, &e);
    write_atomic(&sp, on_io, |tmp| {
        std::fs::write(tmp, text + "\n").map_err(|e| io_err("write", &sp, &e))
    })
}

fn create(path: &Path) -> Result<std::io::BufWriter<std::fs::File>> {
    let f = std::fs::File::create(path).map_err(|e| io_err("write", path, &e))?;
    Ok(std::io::BufWriter::with_capacity(1 << 16, f))
}

fn write_csv(path: &Path, rec: &Recording, sep: u8) -> Result<()> {
    let mut w = create(path)?;
    let we = |e: std::io::Error| io_err("write", path, &e);
    let sep_s = (sep as char).to_string();
    let mut header = vec!["time_s".to_string()];
    for c in &rec.channels {
        let name = c.name.replace([',', '\t', '"'], "_");
        header.push(if c.unit.is_empty() {
            name
        } else {
            format!("{name} ({})", c.unit)
        });
    }
    writeln!(w, "{}", header.join(&sep_s)).map_err(we)?;
    let mut line = String::with_capacity(32 * (rec.channels.len() + 1));
    use std::fmt::Write as _;
    for i in 0..rec.len() {
        line.clear();
        let _ = write!(line, "{}", rec.time_s(i));
        for c in &rec.channels {
            line.push(sep as char);
            let _ = write!(line, "{}", c.samples[i]);
        }
        line.push('\n');
        w.write_all(line.as_bytes()).map_err(we)?;
    }
    w.flush().map_err(we)
}

fn write_wav(path: &Path, rec: &Recording) -> Result<()> {
    let rate = rec.fs_hz.round();
    if (rate - rec.fs_hz).abs() > 1e-6 * rec.fs_hz || rate > u32::MAX as f64 {
        return Err(SignalError::InvalidParam {
            name: "fs_hz",
            value: rec.fs_hz.to_string(),
            fix: "WAV stores a whole number of Hz; write .csv or .f64 instead, or resample to an integer rate".into(),
        });
    }
    if rec.channels.len() > u16::MAX as usize {
        return Err(SignalError::InvalidParam {
            name: "channels",
            value: rec.channels.len().to_string(),
            fix: "WAV holds at most 65535 channels; select fewer".into(),
        });
    }
    let spec = hound::WavSpec {
        channels: rec.channels.len() as u16,
        sample_rate: rate as u32,
        bits_per_sample: 32,
        sample_format: hound::SampleFormat::Float,
    };
    let werr = |e: hound::Error| SignalError::Wav {
        path: path.display().to_string(),
        reason: format!("{e}; check the path and free space"),
    };
    let mut w = hound::WavWriter::create(path, spec).map_err(werr)?;
    for i in 0..rec.len() {
        for c in &rec.channels {
            w.write_sample(c.samples[i] as f32).map_err(werr)?;
        }
    }
    w.finalize().map_err(werr)
}

fn write_raw(path: &Path, rec: &Recording, f32_out: bool) -> Result<()> {
    let mut w = create(path)?;
    let we = |e: std::io::Error| io_err("write", path, &e);
    for i in 0..rec.len() {
        for c in &rec.channels {
            let v = c.samples[i];
            if f32_out {
                w.write_all(&(v as f32).to_le_bytes()).map_err(we)?;
            } else {
                w.write_all(&v.to_le_bytes()).map_err(we)?;
            }
        }
    }
    w.flush().map_err(we)
}
