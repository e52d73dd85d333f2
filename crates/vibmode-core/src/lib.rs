//! # vibmode-core: the types every vibmode stage shares
//!
//! No numerics, and no I/O but the shared file helpers of [`files`] (bounded reads, atomic
//! writes): the in-memory [`Recording`] (and a borrowed [`RecordingView`]),
//! where each sensor sits ([`Placement`]: [`Role`], [`Corner`], [`Direction`]), the pole
//! observations identification hands to clustering ([`PoleObservation`], with an optional mode
//! shape), the invariant-mode results ([`InvariantMode`], [`ModeMatch`]), fit summaries, and one
//! parameter struct per analysis stage ([`PreprocessParams`], [`SweepParams`],
//! [`PoleFilterParams`], [`StopParams`], [`SpectrumParams`], [`ClusterParams`]), each with its
//! defaults defined once. [`BandLimit`] is the one definition of "this signal has an empty band".
//!
//! ```
//! use vibmode_core::{BandLimit, Channel, Recording, SweepParams};
//! let rec = Recording::new(50.0, vec![Channel::new("z", "m/s^2", vec![0.0; 100])]).unwrap();
//! assert_eq!(rec.duration_s(), 2.0);
//! let view = rec.view(50, 100).unwrap();
//! assert_eq!(view.len(), 50);
//! assert_eq!(SweepParams::default().orders().len(), 29); // p = 2..=30
//! assert!(BandLimit::ideal_lowpass(200.0, 25.0).empty_band);
//! ```

pub mod error;
pub mod files;
pub mod identify;
pub mod limits;
pub mod modes;
pub mod params;
pub mod placement;
pub mod record_meta;
pub mod recording;
pub mod source;
pub mod ssi;
pub mod stats;

pub use error::{ParamError, RecordingError};
pub use identify::{
    Identifier, MultichannelIdentifier, PoleOut, PooledIdentification, ShapedPole, SignalFits,
};
pub use limits::{cap_message, num, printable, quoted, settings_message, Num, Quoted};
pub use modes::{
    FitSummary, InvariantMode, ModeClass, ModeMatch, ModeUncertainty, ModelCoefficients,
    PoleObservation, ReferenceMode, SupportFailure, TruthRow, UncertaintyMethod,
};
pub use params::{
    AntiRollBars, BandLimit, BodyFitParams, BodySsiParams, ClusterParams, IdentMethod,
    IdentMethods, LineParams, PoleFilterParams, PreprocessParams, Robust, SearchStarts,
    SpectrumParams, StopParams, SweepModel, SweepParams, DEFAULT_HUBER_FACTOR, EDGE_SHARE,
    EMPTY_BAND_MAX_CUTOFF_SHARE, SWEEP_MAX_ITERATIONS, SWEEP_TOLERANCE,
};
pub use placement::{Corner, Direction, Placement, Role};
pub use record_meta::RecordMeta;
pub use recording::{
    check_finite, check_fs, check_unique_names, Channel, ChannelSelector, Recording, RecordingView,
    TimeAxis,
};
pub use source::{cut_records, CutRecords, RecordInput, RecordSource, RecordWindow};
pub use ssi::{
    SsiParams, Stability, StabilityParams, ANALYSIS_BLOCK_ROWS, SINGLE_RECORD_BLOCK_ROWS,
};
