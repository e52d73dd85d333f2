//! The paper's whole analysis, from acceleration records to invariant vibration modes.
//!
//! For every record and channel: the ideal DFT anti-alias filter and resampling
//! (`vibmode-signal`), periodogram and Welch spectra (`vibmode-spectra`), an order sweep of
//! ARMA(p,p) (or AR(p)) models (`vibmode-ident`), and the modes of every fit. The poles of all
//! orders and records are then pooled per channel and per role (sprung / unsprung) and clustered
//! into invariant modes (`vibmode-modal`), optionally matched to a physical model's modes.
//!
//! Results are plain serialisable structs ([`AnalysisResults`]); figures and reports are drawn
//! elsewhere (the `vibmode` binary), so this crate never depends on plotting.
//!
//! ```
//! use vibmode_analysis::{AnalysisConfig, Preset};
//! let cfg = AnalysisConfig::preset(Preset::Paper);
//! assert_eq!(cfg.analysis_fs_hz, 200.0);
//! assert_eq!(cfg.orders().len(), 59); // p = 2..=60
//! let mine = AnalysisConfig::from_toml_str("order_max = 12\n").unwrap();
//! assert_eq!(mine.order_max, 12);
//! assert!(AnalysisConfig::from_toml_str("no_such_key = 1\n").is_err());
//! ```

mod config;
mod pipeline;

pub use config::{AnalysisConfig, ChannelRole, ClusterConfig, Preset, Role, SweepModel};
pub use pipeline::{
    analyze, cut_records, AnalysisResults, ChannelAnalysis, FitSummary, ModelPsd, PoleOut,
    RecordInput, RecordSummary, RoleAnalysis,
};

/// Errors of the analysis; each message is one line naming the value and the fix.
#[derive(Debug, thiserror::Error)]
pub enum AnalysisError {
    /// A setting is invalid.
    #[error("analysis config: {0}")]
    Config(String),
    /// The records do not fit together (rates, channels, lengths).
    #[error("{0}")]
    Records(String),
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
