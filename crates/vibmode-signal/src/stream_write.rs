//! Writing a recording block by block, in the formats of [`crate::write_path`] (CSV with a
//! `time_s` column, 32-bit float WAV + names sidecar, raw f32/f64 + sidecar), byte for byte the
//! same as writing the whole recording at once.
//!
//! Nothing is half-written: the samples go to `<path>.partial` (and `<path>.json.partial`), which
//! [`StreamWriter::finish`] renames into place; a writer dropped without `finish` (an error on
//! the way) removes them.

use crate::error::{io_err, Result, SidecarProblem, SignalError, WavProblem};
use crate::read::{Format, Sidecar, WavSidecar};
use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};
use vibmode_core::check_fs;

enum Sink {
    Csv {
        w: BufWriter<File>,
        sep: u8,
    },
    Wav {
        w: Option<hound::WavWriter<BufWriter<File>>>,
    },
    Raw {
        w: BufWriter<File>,
        f32_out: bool,
    },
}

/// A recording written block by block; see the module documentation.
pub struct StreamWriter {
    path: PathBuf,
    tmp: PathBuf,
    sidecar: Option<(PathBuf, String)>,
    fs_hz: f64,
    start_s: f64,
    n_channels: usize,
    written: u64,
    sink: Sink,
    finished: bool,
}

impl std::fmt::Debug for StreamWriter {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("StreamWriter")
            .field("path", &self.path)
            .field("written", &self.written)
            .finish()
    }
}

fn with_suffix(path: &Path, suffix: &str) -> PathBuf {
    let mut s = path.as_os_str().to_owned();
    s.push(suffix);
    PathBuf::from(s)
}

impl StreamWriter {
    /// Starts writing `path` (format from the extension, as [`crate::write_path`]) for channels
    /// `names` with `units` at `fs_hz`; CSV times start at `start_s`.
    pub fn create(
        path: &Path,
        names: &[String],
        units: &[String],
        fs_hz: f64,
        start_s: f64,
    ) -> Result<StreamWriter> {
        check_fs(fs_hz, "fs_hz of the recording to write")?;
        vibmode_core::files::check_output_file(path).map_err(|e| io_err("write", path, &e))?;
        if names.is_empty() {
            return Err(SignalError::TooShort {
                what: format!("writing {}", path.display()),
                n: 0,
                fix: "the recording has no channels; nothing to write".into(),
            });
        }
        let ext = path
            .extension()
            .and_then(|e| e.to_str())
            .unwrap_or("")
            .to_ascii_lowercase();
        let tmp = with_suffix(path, ".partial");
        let open = || -> Result<BufWriter<File>> {
            let f = File::create(&tmp).map_err(|e| io_err("write", path, &e))?;
            Ok(BufWriter::with_capacity(1 << 16, f))
        };
        let (sink, sidecar) = match Format::from_extension(&ext) {
            Some(Format::Delimited) => {
                let sep = if ext == "tsv" { b'\t' } else { b',' };
                let mut w = open()?;
                let mut header = vec!["time_s".to_string()];
                for (name, unit) in names.iter().zip(units) {
                    let name = name.replace([',', '\t', '"'], "_");
                    header.push(if unit.is_empty() {
                        name
                    } else {
                        format!("{name} ({unit})")
                    });
                }
                writeln!(w, "{}", header.join(&(sep as char).to_string()))
                    .map_err(|e| io_err("write", path, &e))?;
                (Sink::Csv { w, sep }, None)
            }
            Some(Format::Wav) => {
                let rate = fs_hz.round();
                if (rate - fs_hz).abs() > 1e-6 * fs_hz || rate > u32::MAX as f64 {
                    return Err(SignalError::InvalidParam {
                        name: "fs_hz",
                        value: fs_hz.to_string(),
                        fix: "WAV stores a whole number of Hz; write .csv or .f64 instead, or resample to an integer rate".into(),
                    });
                }
                if names.len() > u16::MAX as usize {
                    return Err(SignalError::InvalidParam {
                        name: "channels",
                        value: names.len().to_string(),
                        fix: "WAV holds at most 65535 channels; select fewer".into(),
                    });
                }
                let spec = hound::WavSpec {
                    channels: names.len() as u16,
                    sample_rate: rate as u32,
                    bits_per_sample: 32,
                    sample_format: hound::SampleFormat::Float,
                };
                let w = hound::WavWriter::new(open()?, spec).map_err(|e| SignalError::Wav {
                    path: path.display().to_string(),
                    problem: WavProblem::NotWritten {
                        message: e.to_string(),
                    },
                })?;
                let side = WavSidecar {
                    channels: names.to_vec(),
                    units: Some(units.to_vec()),
                };
                let text =
                    serde_json::to_string_pretty(&side).map_err(|e| SignalError::Sidecar {
                        path: with_suffix(path, ".json").display().to_string(),
                        problem: SidecarProblem::NotSerialised {
                            message: e.to_string(),
                        },
                    })?;
                (
                    Sink::Wav { w: Some(w) },
                    Some((with_suffix(path, ".json"), text + "\n")),
                )
            }
            Some(Format::Raw) => {
                let f32_out = ext == "f32";
                let side = Sidecar {
                    fs_hz,
                    dtype: if f32_out { "f32" } else { "f64" }.into(),
                    channels: names.to_vec(),
                    units: Some(units.to_vec()),
                };
                let text =
                    serde_json::to_string_pretty(&side).map_err(|e| SignalError::Sidecar {
                        path: with_suffix(path, ".json").display().to_string(),
                        problem: SidecarProblem::NotSerialised {
                            message: e.to_string(),
                        },
                    })?;
                (
                    Sink::Raw {
                        w: open()?,
                        f32_out,
                    },
                    Some((with_suffix(path, ".json"), text + "\n")),
                )
            }
            Some(Format::Npy) => {
                return Err(SignalError::InvalidParam {
                    name: "output format",
                    value: path.display().to_string(),
                    fix: ".npy is read, not written; write .f64 (raw samples with a .json sidecar, numpy.fromfile reads them), .csv or .wav".into(),
                });
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
        Ok(StreamWriter {
            path: path.to_path_buf(),
            tmp,
            sidecar,
            fs_hz,
            start_s,
            n_channels: names.len(),
            written: 0,
            sink,
            finished: false,
        })
    }

    /// Writes `start_time` (the absolute time of the first frame, RFC 3339 text as `vibmode
    /// segment` gives it) into the sidecar of a WAV or raw file, where the readers find the
    /// record's start (docs/formats.md); a CSV keeps its relative `time_s`. `None` leaves the
    /// sidecar as it is.
    pub fn set_start_time(&mut self, start_time: Option<&str>) -> Result<()> {
        let (Some(t), Some((sp, text))) = (start_time, self.sidecar.as_mut()) else {
            return Ok(());
        };
        let not_serialised = |e: serde_json::Error| SignalError::Sidecar {
            path: sp.display().to_string(),
            problem: SidecarProblem::NotSerialised {
                message: e.to_string(),
            },
        };
        let mut v: serde_json::Value = serde_json::from_str(text).map_err(not_serialised)?;
        if let Some(map) = v.as_object_mut() {
            map.insert(
                "start_time".into(),
                serde_json::Value::String(t.to_string()),
            );
        }
        *text = serde_json::to_string_pretty(&v).map_err(not_serialised)? + "\n";
        Ok(())
    }

    /// Frames written so far.
    pub fn frames_written(&self) -> u64 {
        self.written
    }

    /// Appends a block (`block[c]` = channel c, all the same length).
    pub fn write_block<C: AsRef<[f64]>>(&mut self, block: &[C]) -> Result<()> {
        let block: Vec<&[f64]> = block.iter().map(AsRef::as_ref).collect();
        let block = block.as_slice();
        let n = block.first().map_or(0, |c| c.len());
        if block.len() != self.n_channels || block.iter().any(|c| c.len() != n) {
            return Err(SignalError::InvalidParam {
                name: "block",
                value: format!("{} channels", block.len()),
                fix: format!(
                    "give {} channels of equal length, as the writer was created with",
                    self.n_channels
                ),
            });
        }
        let path = self.path.clone();
        let we = |e: std::io::Error| io_err("write", &path, &e);
        match &mut self.sink {
            Sink::Csv { w, sep } => {
                use std::fmt::Write as _;
                let mut line = String::with_capacity(32 * (block.len() + 1));
                for i in 0..n {
                    line.clear();
                    let t = self.start_s + (self.written + i as u64) as f64 / self.fs_hz;
                    let _ = write!(line, "{t}");
                    for c in block {
                        line.push(*sep as char);
                        let _ = write!(line, "{}", c[i]);
                    }
                    line.push('\n');
                    w.write_all(line.as_bytes()).map_err(we)?;
                }
            }
            Sink::Wav { w } => {
                if let Some(w) = w {
                    for i in 0..n {
                        for c in block {
                            w.write_sample(c[i] as f32).map_err(|e| SignalError::Wav {
                                path: path.display().to_string(),
                                problem: WavProblem::NotWritten {
                                    message: e.to_string(),
                                },
                            })?;
                        }
                    }
                }
            }
            Sink::Raw { w, f32_out } => {
                let mut bytes = Vec::with_capacity(n * block.len() * 8);
                for i in 0..n {
                    for c in block {
                        if *f32_out {
                            bytes.extend_from_slice(&(c[i] as f32).to_le_bytes());
                        } else {
                            bytes.extend_from_slice(&c[i].to_le_bytes());
                        }
                    }
                }
                w.write_all(&bytes).map_err(we)?;
            }
        }
        self.written += n as u64;
        Ok(())
    }

    /// Flushes, writes the sidecar and renames everything into place.
    pub fn finish(mut self) -> Result<()> {
        if self.written == 0 {
            return Err(SignalError::TooShort {
                what: format!("writing {}", self.path.display()),
                n: 0,
                fix: "the recording has no samples; nothing to write".into(),
            });
        }
        let path = self.path.clone();
        let we = |e: std::io::Error| io_err("write", &path, &e);
        match &mut self.sink {
            Sink::Csv { w, .. } | Sink::Raw { w, .. } => {
                w.flush().map_err(we)?;
                w.get_ref().sync_all().map_err(we)?;
            }
            Sink::Wav { w } => {
                if let Some(w) = w.take() {
                    w.finalize().map_err(|e| SignalError::Wav {
                        path: path.display().to_string(),
                        problem: WavProblem::NotWritten {
                            message: e.to_string(),
                        },
                    })?;
                }
            }
        }
        if let Some((sp, text)) = &self.sidecar {
            let stmp = with_suffix(sp, ".partial");
            std::fs::write(&stmp, text).map_err(|e| io_err("write", sp, &e))?;
            std::fs::rename(&stmp, sp).map_err(|e| io_err("write", sp, &e))?;
        }
        std::fs::rename(&self.tmp, &self.path).map_err(we)?;
        self.finished = true;
        Ok(())
    }
}

impl Drop for StreamWriter {
    fn drop(&mut self) {
        if !self.finished {
            let _ = std::fs::remove_file(&self.tmp);
            if let Some((sp, _)) = &self.sidecar {
                let _ = std::fs::remove_file(with_suffix(sp, ".partial"));
            }
        }
    }
}
