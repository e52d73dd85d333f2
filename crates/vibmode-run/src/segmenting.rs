//! Long recordings cut into records where the vehicle drives steadily, before the analysis
//! (behind the `segment` feature: the GPS parsers).

use std::path::{Path, PathBuf};

use vibmode_segment::{Cutting, SegmentParams, Segmentation};
use vibmode_signal::{ChannelSelector, ReadOptions};

use crate::RunError;

/// How a recording is cut into records ([`vibmode_segment::plan_file`]).
#[derive(Debug, Clone)]
#[non_exhaustive]
pub enum Segmenting {
    /// Where a GPS track (GPX, NMEA RMC/GGA or CSV) shows steady driving.
    Gps {
        /// The track file.
        track: PathBuf,
        /// Seconds added to the track's times to put them on the recording's clock.
        offset_s: f64,
        /// The tolerances.
        params: SegmentParams,
    },
    /// Where the vibration shows driving, without stops, idling or strong manoeuvres.
    Vibration {
        /// The tolerances.
        params: SegmentParams,
    },
    /// Consecutive records (the segmentation is then only the list of records).
    Consecutive {
        /// The tolerances.
        params: SegmentParams,
    },
}

/// A recording's segmentation and what the user should know about its inputs (e.g. fixes
/// dropped from the GPS track).
#[derive(Debug, Clone)]
pub struct Planned {
    /// The records to cut and the stretches skipped (`segments.json`).
    pub segmentation: Segmentation,
    /// One line each.
    pub notes: Vec<String>,
}

impl Segmenting {
    /// The segmentation of `path` (channels `channels` of it, read with `read`) into records of
    /// `record_length_s`.
    pub fn plan(
        &self,
        path: &Path,
        read: &ReadOptions,
        channels: &[ChannelSelector],
        record_length_s: f64,
    ) -> Result<Planned, RunError> {
        let mut notes = Vec::new();
        let segmentation = match self {
            Segmenting::Gps {
                track,
                offset_s,
                params,
            } => {
                let t = vibmode_segment::read_track(track)?;
                if let Some(note) = t.dropped_note() {
                    notes.push(format!("GPS track {}: {note}", track.display()));
                }
                let how = Cutting::Gps {
                    track: &t,
                    offset_s: *offset_s,
                };
                vibmode_segment::plan_file(path, read, channels, how, record_length_s, params)?
            }
            Segmenting::Vibration { params } => vibmode_segment::plan_file(
                path,
                read,
                channels,
                Cutting::Vibration,
                record_length_s,
                params,
            )?,
            Segmenting::Consecutive { params } => vibmode_segment::plan_file(
                path,
                read,
                channels,
                Cutting::Consecutive,
                record_length_s,
                params,
            )?,
        };
        Ok(Planned {
            segmentation,
            notes,
        })
    }

    /// Whether records are cut by a GPS track.
    pub fn is_gps(&self) -> bool {
        matches!(self, Segmenting::Gps { .. })
    }
}
