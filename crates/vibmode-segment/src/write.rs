//! The records of a segmentation written as files, and `segments.json`.

use crate::{SegmentError, Segmentation};
use std::path::{Path, PathBuf};
use vibmode_core::RecordSource;
use vibmode_signal::{FrameStream, StreamRecords, StreamWriter};

/// What [`write_segments`] wrote.
#[derive(Clone, Debug, PartialEq)]
pub struct Written {
    /// The record files, in order.
    pub records: Vec<PathBuf>,
    /// `segments.json`.
    pub segments_json: PathBuf,
}

fn write_err(path: &Path, e: impl std::fmt::Display) -> SegmentError {
    SegmentError::Write {
        path: path.display().to_string(),
        message: e.to_string(),
    }
}

/// Writes every record of `seg` read from `stream` into `dir` as `record_0001.<ext>`, ... (`ext`:
/// `csv`, `wav`, `f32`, `f64`; CSV times are the record's times in the recording), fills in
/// `file` of each record and writes `dir/segments.json` last. If anything fails, the files this
/// call wrote are removed: nothing is left half-written.
pub fn write_segments(
    stream: FrameStream,
    seg: &mut Segmentation,
    dir: &Path,
    ext: &str,
) -> Result<Written, SegmentError> {
    std::fs::create_dir_all(dir).map_err(|e| write_err(dir, e))?;
    let mut written: Vec<PathBuf> = Vec::new();
    let result = write_all(stream, seg, dir, ext, &mut written);
    match result {
        Ok(json) => Ok(Written {
            records: written,
            segments_json: json,
        }),
        Err(e) => {
            for f in &written {
                let _ = std::fs::remove_file(f);
                let mut side = f.as_os_str().to_owned();
                side.push(".json");
                let _ = std::fs::remove_file(PathBuf::from(side));
            }
            Err(e)
        }
    }
}

fn write_all(
    stream: FrameStream,
    seg: &mut Segmentation,
    dir: &Path,
    ext: &str,
    written: &mut Vec<PathBuf>,
) -> Result<PathBuf, SegmentError> {
    // The records are named by the source as given (as `vibmode analyze` names them).
    let mut src = StreamRecords::windows(&seg.source, stream, seg.windows());
    let mut k = 0;
    while let Some(r) = src.next_record() {
        let r = r?;
        let file = format!("record_{:04}.{ext}", k + 1);
        let path = dir.join(&file);
        let names: Vec<String> = r
            .recording
            .channels
            .iter()
            .map(|c| c.name.clone())
            .collect();
        let units: Vec<String> = r
            .recording
            .channels
            .iter()
            .map(|c| c.unit.clone())
            .collect();
        let start_s = seg.records.get(k).map_or(0.0, |s| s.meta.start_s);
        let mut w = StreamWriter::create(&path, &names, &units, r.recording.fs_hz, start_s)?;
        // A WAV or raw record's sidecar carries its absolute start, when the recording's is
        // known: `fleet check` groups records into drives by their day.
        w.set_start_time(
            seg.records
                .get(k)
                .and_then(|s| s.meta.start_time.as_deref()),
        )?;
        let block: Vec<Vec<f64>> = r
            .recording
            .channels
            .into_iter()
            .map(|c| c.samples)
            .collect();
        w.write_block(&block)?;
        w.finish()?;
        written.push(path);
        if let Some(s) = seg.records.get_mut(k) {
            s.file = Some(file);
        }
        k += 1;
    }
    let json_path = dir.join("segments.json");
    let text = serde_json::to_string_pretty(&*seg).map_err(|e| write_err(&json_path, e))?;
    let tmp = dir.join("segments.json.partial");
    std::fs::write(&tmp, text + "\n").map_err(|e| write_err(&json_path, e))?;
    std::fs::rename(&tmp, &json_path).map_err(|e| write_err(&json_path, e))?;
    Ok(json_path)
}
