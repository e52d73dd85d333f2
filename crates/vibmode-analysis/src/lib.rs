//! The paper's whole analysis, from acceleration records to invariant vibration modes.
//!
//! For every record and channel: the ideal DFT anti-alias filter and resampling
//! (`vibmode-signal`), periodogram and Welch spectra (`vibmode-spectra`), an order sweep of
//! ARMA(p,p) (or AR(p)) models (`vibmode-ident`), and the modes of every fit. The poles of all
//! orders and records are then pooled per channel and per role (sprung / unsprung) and clustered
//! into invariant modes (`vibmode-modal`), optionally matched to a physical model's modes.
//!
//! The analysis is a composition of named stages, each a public module: records from a
//! [`RecordSource`] (the contract in `vibmode-core`; [`stream`] analyses them as they arrive),
//! pre-processing (`vibmode_signal::preprocess`), [`identify`] (the order sweep, an
//! [`Identifier`]), [`store`] (the pole store), [`stops`], clustering (`vibmode-modal`) and model
//! matching, composed by [`analyze`] in [`pipeline`]. Results are plain versioned serialisable
//! structs ([`AnalysisResults`], [`SCHEMA_VERSION`]); figures and reports are drawn by
//! `vibmode-report`, so this crate never depends on plotting.
//!
//! ```
//! use vibmode_analysis::{AnalysisConfig, Preset};
//! let cfg = AnalysisConfig::preset(Preset::Paper);
//! assert_eq!(cfg.preprocess.analysis_fs_hz, 200.0);
//! assert_eq!(cfg.orders().len(), 59); // p = 2..=60
//! let mine = AnalysisConfig::from_toml_str("[sweep]\norder_max = 12\n").unwrap();
//! assert_eq!(mine.sweep.order_max, 12);
//! assert!(AnalysisConfig::from_toml_str("no_such_key = 1\n").is_err());
//! ```

pub mod body;
mod config;
pub mod first_record;
pub mod identify;
pub mod lines;
pub mod multichannel;
pub mod pipeline;
pub mod results;
pub mod stops;
pub mod store;
pub mod stream;

pub use body::{BodySsi, BodySsiNotRun, RecordDelay};
pub use config::{AnalysisConfig, ChannelRole, ConfigText, Preset, ReportParams};
pub use first_record::{first_record_spectra, FirstRecord, FirstRecordSpectra, ModelPsd};
pub use identify::SweepIdentifier;
pub use lines::{LineSweep, LineTrack};
pub use multichannel::{ShapedPole, SsiAnalysis};
pub use pipeline::{
    analyze, analyze_keeping_first, analyze_prepared, analyze_with, check_channels_vary,
    check_records, preprocess_recordings, preprocess_records, RecordFacts,
};
pub use results::{
    sensor_notes, AnalysisResults, ChannelAnalysis, ClippedChannel, HeldChannel, RecordSummary,
    RoleAnalysis, Timing, HELD_MIN_S, HELD_SHARE_MIN, SCHEMA_VERSION,
};
pub use store::PoleStore;
pub use stream::analyze_source;
// The contracts of stages 1 and 3 live in vibmode-core (the streamed sources in
// vibmode-signal); re-exported here so that users of the analysis need one import path.
pub use vibmode_core::{
    cut_records, CutRecords, Identifier, PoleOut, RecordInput, RecordSource, RecordWindow,
    SignalFits,
};
pub use vibmode_core::{
    ClusterParams, Corner, FitSummary, ModelCoefficients, Placement, PoleFilterParams,
    PreprocessParams, Robust, Role, SpectrumParams, StopParams, SweepModel, SweepParams,
};
pub use vibmode_modal::{MATCH_MAC_MIN, MATCH_MAX_FREQ_DIFF_REL};
pub use vibmode_signal::{ChainedRecords, StreamRecords};

/// A number for a message: at most 9 significant digits, no trailing zeros (100.00000000000001
/// -> "100").
fn short(x: f64) -> String {
    if !x.is_finite() || x == 0.0 {
        return x.to_string();
    }
    let digits = (8 - x.abs().log10().floor() as i32).clamp(0, 17) as usize;
    let s = format!("{x:.digits$}");
    if s.contains('.') {
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        s
    }
}

/// Errors of the analysis; each message is one line naming the value and the fix, never a
/// command-line flag.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum AnalysisError {
    /// A setting of the config is invalid or cannot be parsed.
    #[error("analysis config: {message}")]
    Config {
        /// The key at fault, when known.
        key: Option<&'static str>,
        /// What is wrong and how to fix it.
        message: String,
    },
    /// A preset in the config file other than the one given beside it.
    #[error("analysis config: the config sets preset = \"{in_file}\" but preset {given} was given; give one of them")]
    PresetConflict {
        /// The config file's preset.
        in_file: &'static str,
        /// The preset given.
        given: &'static str,
    },
    /// A config file cannot be read or parsed.
    #[error("config {path}: {message}")]
    ConfigFile {
        /// The file.
        path: String,
        /// What is wrong.
        message: String,
    },
    /// A stage's parameter is out of range.
    #[error("analysis config: {0}")]
    Param(#[from] vibmode_core::ParamError),
    /// No records were given.
    #[error("no records to analyse; give at least one record")]
    NoRecords,
    /// Records with different channels.
    #[error("record '{record}' has channels [{channels}] but '{first}' has [{first_channels}]; give records with the same channels or select the same channels in each")]
    ChannelsDiffer {
        /// The record at fault.
        record: String,
        /// Its channels.
        channels: String,
        /// The first record.
        first: String,
        /// The first record's channels.
        first_channels: String,
    },
    /// A channel of a record that carries no vibration: every sample 0 (a dead sensor) or one
    /// other value (a stuck one), [`vibmode_core::stats::constant_value`]. Its "modes" would be
    /// those of the rounding noise of the pre-processing.
    #[error("record '{record}': channel '{channel}' is constant (every sample is {}): a dead or stuck sensor has no vibration to identify; check the sensor, or analyse the record without this channel", vibmode_core::num(.value))]
    ChannelConstant {
        /// The record.
        record: String,
        /// The channel.
        channel: String,
        /// Its one value.
        value: f64,
    },
    /// A channel of a record that repeats a value over most of its samples
    /// ([`vibmode_core::stats::REPEATED_SHARE_MAX`] or more, at a clipped extreme or in held
    /// stretches, [`vibmode_core::stats::ChannelHealth::is_mostly_repeated`]): a dead or stuck
    /// sensor with glitches, whose "modes" would be those of its glitches.
    #[error("record '{record}': channel '{channel}' repeats a value over {:.1} % of its samples (at an extreme or in held stretches): a dead or stuck sensor with glitches has no vibration to identify; check the sensor, or analyse the record without this channel", (1000.0 * .share).floor() / 10.0)]
    ChannelMostlyRepeated {
        /// The record.
        record: String,
        /// The channel.
        channel: String,
        /// Share of its samples that repeat a value (0-1).
        share: f64,
    },
    /// Records at different sampling rates.
    #[error("record '{record}' is sampled at {} Hz but '{first}' at {} Hz; resample them to one rate first", short(*fs_hz), short(*first_fs_hz))]
    RatesDiffer {
        /// The record at fault.
        record: String,
        /// Its rate, Hz.
        fs_hz: f64,
        /// The first record.
        first: String,
        /// The first record's rate, Hz.
        first_fs_hz: f64,
    },
    /// A record too short for the analysis at the analysis rate.
    #[error("record '{record}' has {n_samples} samples at the analysis rate {} Hz ({duration_s:.3} s); the lowest model order p = {order_min} needs at least {needed} samples ({needed_s:.3} s): give a longer record", short(*fs_hz))]
    RecordTooShort {
        /// The record.
        record: String,
        /// Its samples after pre-processing.
        n_samples: usize,
        /// The analysis rate reached, Hz.
        fs_hz: f64,
        /// Its duration, s.
        duration_s: f64,
        /// The lowest order of the sweep.
        order_min: usize,
        /// Samples needed.
        needed: usize,
        /// Duration needed, s.
        needed_s: f64,
    },
    /// The sweep's highest order needs more samples than the longest record has.
    #[error("sweep order_max = {order_max} needs at least {needed} samples per record at the analysis rate {} Hz ({needed_s:.3} s), the longest record '{record}' has {n_samples} ({duration_s:.3} s): lower order_max to {highest} or less, or give longer records", short(*fs_hz))]
    OrderMaxTooHigh {
        /// The sweep's highest order.
        order_max: usize,
        /// Samples it needs.
        needed: usize,
        /// Duration it needs, s.
        needed_s: f64,
        /// The longest record.
        record: String,
        /// Its samples after pre-processing.
        n_samples: usize,
        /// The analysis rate reached, Hz.
        fs_hz: f64,
        /// Its duration, s.
        duration_s: f64,
        /// The highest order its samples support.
        highest: usize,
    },
    /// A recording breaks its invariants.
    #[error(transparent)]
    Recording(#[from] vibmode_core::RecordingError),
    /// Reading or resampling failed.
    #[error(transparent)]
    Signal(#[from] vibmode_signal::SignalError),
    /// A spectrum failed.
    #[error(transparent)]
    Spectra(#[from] vibmode_spectra::SpectraError),
    /// Clustering failed.
    #[error(transparent)]
    Modal(#[from] vibmode_modal::ModalError),
}
