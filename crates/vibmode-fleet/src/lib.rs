//! Fleet monitoring: per vehicle, a nominal model set from repeated healthy runs, kept in an
//! embedded SQLite store; every later record is classified `normal`, `road` (excitation out of
//! the nominal range), `vehicle` (transmissibility or modes of a corner moved) or `both`.
//!
//! The stages: [`compute_features`] (band levels, transmissibility, modes and the body
//! cross-spectra of one file; [`body`]: the body's response to the wheel motions),
//! [`build_model_set`] (median and MAD of every feature over the nominal records, control
//! limits from a false-alarm rate), [`assess`] (robust z-scores and the classification), and
//! [`Store`] (the SQLite file: vehicles, records, features, model sets). See docs/fleet.md.

pub mod body;
pub mod config;
pub mod error;
pub mod features;
pub mod fleet;
pub mod hash;
pub mod model;
#[cfg(feature = "report")]
pub mod report;
pub mod stats;
pub mod store;
pub mod suspension;
pub mod text;

pub use body::{fit_body_model, BodyModel, BodySpectra};
pub use config::{fleet_analysis, FleetConfig, SUSPENSION_BAND_HZ};
pub use error::{FleetError, Result};
pub use features::{
    check_sampling, compute_features, sensor_faults, ChannelFeatures, CornerTransmissibility,
    FaultKind, LineFree, ModeEstimate, RecordFeatures, SensorFault, LINE_HALF_WIDTH_BINS,
};
pub use fleet::{
    add_body_equations, build_baseline, check_drive_files_progress, check_file, check_files,
    check_files_progress, check_recording, check_vehicle_id, drive_of_day, drive_of_folder,
    ingest_file, ingest_files, ingest_files_progress, ingest_recording, record_features,
    record_file_name, register_vehicle_model, register_vehicle_model_file, registered_model,
    require_baseline, sha256_hex, CheckReport, Checked, IngestLabels, Ingested, Registered,
    DEFAULT_DRIVE_ID,
};
pub use hash::ContentHash;
pub use model::{
    assess, assess_drive, assess_drive_fitted, build_model_set, Assessment, Classification,
    Component, Drive, Evidence, FeatureMeta, FeatureStat, Group, Kind, KindLimit, ModeSlot,
    ModelSet, NotJudged, Scores, LOO_MARGIN, MIN_DRIVE_RECORDS,
};
#[cfg(feature = "report")]
pub use report::write_fleet_report;
pub use store::{
    BatchItem, Condition, DriveStatus, RecordRow, Store, Stored, VehicleStatus, SCHEMA_VERSION,
};
