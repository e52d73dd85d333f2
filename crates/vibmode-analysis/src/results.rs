//! The results of an analysis: plain versioned structs, serialised as `results.json`. Nothing
//! in here exists only for the report (spectra of single records and model spectra on a grid
//! are computed by the report from the records and the kept model coefficients).

use serde::{Deserialize, Serialize};
use vibmode_core::{
    BandLimit, FitSummary, InvariantMode, ModeMatch, ModelCoefficients, Placement, ReferenceMode,
    Role,
};

use crate::config::AnalysisConfig;
use crate::lines::LineTrack;
use crate::multichannel::SsiAnalysis;
use vibmode_core::PoleOut;

/// Version of the layout of [`AnalysisResults`] (`schema_version` in `results.json`). 2: stage
/// sections in `config`, per-record bands, fit errors kept, model coefficients instead of model
/// spectra, timing apart. 3: periodic line tracks (`lines`) per channel and pool, each mode's
/// `line_kurtosis`, the `[lines]` config section, `method`, `[ssi]` and the multichannel
/// results `ssi` (poles with shapes, clusters with mean shapes, matches with MAC).
pub const SCHEMA_VERSION: u32 = 3;

/// Facts about one analysed record.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct RecordSummary {
    /// Display name.
    pub name: String,
    /// Original sampling rate, Hz.
    pub fs_hz: f64,
    /// Original number of samples.
    pub n_samples: usize,
    /// Duration, s.
    pub duration_s: f64,
    /// The band of the record after pre-processing: the analysis rate actually reached (with a
    /// non-integer rate ratio it can differ from `analysis_fs_hz` by a hair), the cutoff applied
    /// and whether an empty band lies above it. This record's poles were computed at this rate.
    pub band: BandLimit,
    /// Activity per channel: RMS of the acceleration in `activity_min_hz..cutoff_hz`, from the
    /// record's Welch PSD at the analysis rate (square root of its integral over the band), in
    /// the channel's unit.
    pub activity_rms: Vec<f64>,
    /// Activity relative to the other records: per channel `activity_rms` divided by its median
    /// over all records, then the median over channels (1 = a typical record).
    pub activity_ratio: f64,
    /// True when `activity_ratio < stop_rms_ratio`: the vehicle was (mostly) at rest, the record
    /// is left out of the invariant-mode statistics (its poles are still in `poles`).
    pub stationary: bool,
    /// Why the record is left out of the mode statistics (None = used).
    pub excluded_reason: Option<String>,
    /// Where the record was cut from a long recording: start, and with a GPS track the mean
    /// speed and position (absent for record files analysed whole).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub segment: Option<vibmode_core::RecordMeta>,
    /// The record's channels held at an extreme (a saturated sensor or amplifier,
    /// [`vibmode_core::stats::clipped`]), as read: still analysed, but their spectra and modes
    /// hold the clipping's harmonics. Empty when none is.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub clipped: Vec<ClippedChannel>,
    /// The record's channels that hold one value over stretches of [`HELD_MIN_S`] or more for
    /// [`HELD_SHARE_MIN`] of their samples or more (a data logger's dropouts filled with the last
    /// value or with 0, [`vibmode_core::stats::ChannelHealth::held`]), as read: still analysed. Empty when
    /// none does.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub held: Vec<HeldChannel>,
}

pub use vibmode_core::stats::{HELD_MIN_S, HELD_SHARE_MIN};

/// A channel of a record that holds one value over stretches (dropouts).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct HeldChannel {
    /// The channel.
    pub channel: String,
    /// Share of the record's samples in held stretches (0-1).
    pub share: f64,
    /// How many stretches.
    pub stretches: usize,
    /// The longest, s.
    pub longest_s: f64,
}

/// A channel of a record held at one of its extremes.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ClippedChannel {
    /// The channel.
    pub channel: String,
    /// Share of the record's samples at the extreme (0-1).
    pub share: f64,
    /// The extreme, in the channel's unit.
    pub value: f64,
}

/// The clipped channels of `rec` and those that hold one value for [`HELD_SHARE_MIN`] of the
/// samples or more in stretches of [`HELD_MIN_S`] (at least
/// [`vibmode_core::stats::HELD_MIN_SAMPLES`]), each in channel order, from one look at each
/// channel ([`vibmode_core::stats::channel_health`]); a clipped channel's stretches at its
/// extremes are clipping, not counted as held.
pub fn sensor_notes(rec: &vibmode_core::Recording) -> (Vec<ClippedChannel>, Vec<HeldChannel>) {
    let min_run = vibmode_core::stats::held_min_run(rec.fs_hz);
    let health: Vec<vibmode_core::stats::ChannelHealth> = rec
        .channels
        .iter()
        .map(|ch| vibmode_core::stats::channel_health(&ch.samples, min_run))
        .collect();
    sensor_notes_of(rec, &health)
}

/// As [`sensor_notes`], from each channel's health (`health[i]` of `rec.channels[i]`).
pub(crate) fn sensor_notes_of(
    rec: &vibmode_core::Recording,
    health: &[vibmode_core::stats::ChannelHealth],
) -> (Vec<ClippedChannel>, Vec<HeldChannel>) {
    let (mut clipped, mut held) = (Vec::new(), Vec::new());
    for (ch, h) in rec.channels.iter().zip(health) {
        if let Some((n, value)) = h.clipped {
            clipped.push(ClippedChannel {
                channel: ch.name.clone(),
                share: n as f64 / ch.samples.len() as f64,
                value,
            });
        }
        if h.is_held() {
            held.push(HeldChannel {
                channel: ch.name.clone(),
                share: h.held_share(),
                stretches: h.held.1,
                longest_s: h.held.2 as f64 / rec.fs_hz,
            });
        }
    }
    (clipped, held)
}

/// Everything found for one channel.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct ChannelAnalysis {
    /// Channel name.
    pub name: String,
    /// Unit of the samples.
    pub unit: String,
    /// Role on the vehicle.
    pub role: Role,
    /// Role, corner and direction.
    pub placement: Placement,
    /// Welch frequencies, Hz.
    pub welch_freq_hz: Vec<f64>,
    /// Welch PSD averaged over the records used for the modes (stops left out), (unit)^2/Hz.
    pub welch_psd: Vec<f64>,
    /// Every pole pair of every fit that passed the pole filters.
    pub poles: Vec<PoleOut>,
    /// Every fit's summary.
    pub fits: Vec<FitSummary>,
    /// Coefficients of the first record's models at the report's `model_psd_orders`.
    pub first_record_models: Vec<ModelCoefficients>,
    /// Invariant modes of this channel alone.
    pub invariant_modes: Vec<InvariantMode>,
    /// Periodic lines of this channel, tracked over the records.
    #[serde(default)]
    pub lines: Vec<LineTrack>,
}

/// Modes pooled over all channels of one role.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct RoleAnalysis {
    /// The role.
    pub role: Role,
    /// Channels pooled.
    pub channels: Vec<String>,
    /// Invariant modes of the pool.
    pub invariant_modes: Vec<InvariantMode>,
    /// Periodic lines of the pool's channels, tracked over the records.
    #[serde(default)]
    pub lines: Vec<LineTrack>,
    /// Reference (physical model) modes matched to the invariant structural modes.
    pub matches: Vec<ModeMatch>,
}

/// How long the analysis took (kept apart from the results: it differs run to run).
#[derive(Clone, Debug, Default, Serialize, Deserialize)]
pub struct Timing {
    /// Wall-clock time of the analysis, s.
    pub elapsed_s: f64,
}

/// The whole analysis.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct AnalysisResults {
    /// Layout version ([`SCHEMA_VERSION`]).
    pub schema_version: u32,
    /// The vehicle's speed over the recording from its GPS track, `[time in the recording s,
    /// speed km/h]`, when records were cut by GPS (one recording); empty otherwise.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub drive_speed_trace: Vec<[f64; 2]>,
    /// Settings used.
    pub config: AnalysisConfig,
    /// Records analysed.
    pub records: Vec<RecordSummary>,
    /// Per channel results.
    pub channels: Vec<ChannelAnalysis>,
    /// Per role results.
    pub roles: Vec<RoleAnalysis>,
    /// Multichannel (SSI-cov) results, when that method ran.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub ssi: Option<SsiAnalysis>,
    /// Body modes by SSI-cov at a low rate, each record beyond its own wheelbase delay, when
    /// that ran (`[body_ssi]`, docs/ssi.md).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub body_ssi: Option<crate::BodySsi>,
    /// Why the body-band SSI-cov did not run, when SSI-cov ran but it did not.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub body_ssi_not_run: Option<String>,
    /// Physical model modes used for matching (empty without a vehicle model).
    pub reference_modes: Vec<ReferenceMode>,
    /// Number of records marked `stationary` (stops), left out of the mode statistics; the
    /// invariant modes' `record_share` and `order_share` are relative to the other records.
    pub n_stationary: usize,
    /// Number of model fits run.
    pub n_fits: usize,
    /// Number of fits that did not converge (failed fits included).
    pub n_not_converged: usize,
    /// Number of fits that failed outright (their `error` says why).
    pub n_failed: usize,
    /// Wall-clock time.
    pub timing: Timing,
}
