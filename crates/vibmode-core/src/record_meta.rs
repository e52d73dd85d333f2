//! Where and when a record was cut out of a long recording: its start, and the vehicle's state
//! from a GPS track when one was given.

use serde::{Deserialize, Serialize};

/// Facts about a record cut out of a longer recording (segmentation), carried into
/// `results.json` per record.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct RecordMeta {
    /// Start of the record after the start of the recording, s.
    pub start_s: f64,
    /// Duration, s.
    pub duration_s: f64,
    /// Absolute start time (RFC 3339, UTC) when the recording's start is known.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub start_time: Option<String>,
    /// Mean speed over the record from the GPS track, km/h.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub mean_speed_kmh: Option<f64>,
    /// Latitude at the middle of the record, degrees (WGS 84).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub lat_deg: Option<f64>,
    /// Longitude at the middle of the record, degrees (WGS 84).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub lon_deg: Option<f64>,
}
