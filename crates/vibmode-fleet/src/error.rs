//! Errors of the fleet store and its statistics.

/// Errors of `vibmode-fleet`; each message is one line naming the value and the fix, never a
/// command-line flag.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum FleetError {
    /// The database file cannot be opened or is not an SQLite database.
    #[error("{} is not a vibmode fleet store ({}); give the path of a store made by fleet init, or a new file name", vibmode_core::quoted(path), vibmode_core::cap_message(reason, 120))]
    NotAStore {
        /// The file.
        path: String,
        /// What SQLite or the schema check said.
        reason: String,
    },
    /// The store was written by a newer vibmode.
    #[error("{} has fleet schema version {found}, this vibmode reads up to version {supported}; use a newer vibmode", vibmode_core::quoted(path))]
    NewerSchema {
        /// The file.
        path: String,
        /// Its `user_version`.
        found: i64,
        /// The newest this build knows.
        supported: i64,
    },
    /// The store file does not exist (and was not to be created).
    #[error(
        "no fleet store at {}; create it with fleet init first",
        vibmode_core::quoted(path)
    )]
    NoStore {
        /// The path.
        path: String,
    },
    /// A store schema version that no vibmode writes (below 1; 0 is an empty file).
    #[error("{}: store schema version {found} is not one vibmode knows (1..{supported}); the file was changed by another program: restore it from a backup or start a new store", vibmode_core::quoted(path))]
    UnknownSchema {
        /// The file.
        path: String,
        /// Its `user_version`.
        found: i64,
        /// The newest this build knows.
        supported: i64,
    },
    /// The store path is a folder or a device, not a regular file.
    #[error(
        "{} is {what}, not a store file; give the path of a store file (e.g. fleet.db)",
        vibmode_core::quoted(path)
    )]
    NotAFile {
        /// The path.
        path: String,
        /// "a folder" or "not a regular file".
        what: &'static str,
    },
    /// The folder the store would be in does not exist.
    #[error("the folder {} (where the store {} would be) does not exist; create it first or give another path", vibmode_core::quoted(folder), vibmode_core::quoted(path))]
    NoFolder {
        /// The store path.
        path: String,
        /// Its folder.
        folder: String,
    },
    /// Something to be stored that could not be read back (a number that is not finite).
    #[error("{what} was not stored: it holds a value that is not a finite number ({}); nothing was written", vibmode_core::cap_message(reason, 120))]
    NotStorable {
        /// What.
        what: String,
        /// The check's message.
        reason: String,
    },
    /// A record sampled too slowly for the highest feature band.
    #[error(
        "'{}' cannot be scored: it is sampled at {} Hz, but the feature bands reach {} Hz, which needs at least {} Hz; record at a higher rate",
        vibmode_core::quoted(record),
        vibmode_core::Num(*fs_hz),
        vibmode_core::Num(*min_fs_hz / 2.0),
        vibmode_core::Num(*min_fs_hz)
    )]
    RecordUnderSampled {
        /// The record (file name).
        record: String,
        /// Its sampling rate, Hz.
        fs_hz: f64,
        /// The lowest rate the feature bands need (twice their highest edge), Hz.
        min_fs_hz: f64,
    },
    /// A record too short for the lowest feature band.
    #[error(
        "'{}' cannot be scored: it lasts {} s, but the features need at least {} s ({periods} periods of the lowest band edge, {} Hz, and one Welch segment); give longer records",
        vibmode_core::quoted(record),
        vibmode_core::Num(*duration_s),
        vibmode_core::Num(*min_duration_s),
        vibmode_core::Num(*lowest_band_edge_hz)
    )]
    RecordTooShort {
        /// The record (file name).
        record: String,
        /// Its duration, s.
        duration_s: f64,
        /// The shortest duration the features need, s.
        min_duration_s: f64,
        /// Periods of the lowest band edge asked for.
        periods: f64,
        /// The lowest band edge, Hz.
        lowest_band_edge_hz: f64,
    },
    /// A nominal record with a faulty sensor (it would spoil the baseline).
    #[error("'{}' is to be nominal but {faults}; a nominal record needs every sensor working: fix the logger or leave the file out", vibmode_core::quoted(record))]
    NominalSensorFault {
        /// The record (file name).
        record: String,
        /// The faults, e.g. `channel FL_sprung is dead (every sample 0)`.
        faults: String,
    },
    /// An SQLite operation failed.
    #[error(
        "fleet store {}: {operation} failed: {}",
        vibmode_core::quoted(path),
        vibmode_core::cap_message(reason, 160)
    )]
    Sql {
        /// The file.
        path: String,
        /// What was being done.
        operation: &'static str,
        /// SQLite's message.
        reason: String,
    },
    /// A vehicle identifier that the store does not know.
    #[error(
        "vehicle '{}' is not in the store (known: {}); ingest its nominal records first",
        vibmode_core::quoted(vehicle),
        vibmode_core::cap_message(known, 120)
    )]
    UnknownVehicle {
        /// The identifier given.
        vehicle: String,
        /// The vehicles the store has, comma-separated (or "none").
        known: String,
    },
    /// A vehicle identifier that is empty or not printable.
    #[error(
        "vehicle id '{}' must be 1 to 64 printable characters without spaces, e.g. bus-017",
        vibmode_core::quoted(vehicle)
    )]
    BadVehicleId {
        /// The identifier given.
        vehicle: String,
    },
    /// The body's response to the wheel motions: no nominal record has body spectra.
    #[error("body response to wheel motion: no nominal record has body spectra; ingest records with sprung and unsprung channels")]
    NoBodySpectra,
    /// The body's response to the wheel motions: nominal records of different layouts.
    #[error(
        "body response to wheel motion: the nominal records' body spectra differ (channels [{}] / [{}] and {bins} bins, against [{}] / [{}] and {first_bins} bins); build the baseline from records of one layout and one analysis rate",
        sprung.join(", "),
        unsprung.join(", "),
        first_sprung.join(", "),
        first_unsprung.join(", ")
    )]
    BodySpectraDiffer {
        /// The differing record's sprung channels.
        sprung: Vec<String>,
        /// Its unsprung channels.
        unsprung: Vec<String>,
        /// Its frequency bins.
        bins: usize,
        /// The first record's sprung channels.
        first_sprung: Vec<String>,
        /// Its unsprung channels.
        first_unsprung: Vec<String>,
        /// Its frequency bins.
        first_bins: usize,
    },
    /// The body's response to the wheel motions: the pooled wheel cross-spectra are singular.
    #[error(
        "body response to wheel motion: the pooled wheel cross-spectra of the nominal records are singular in every body bin (best condition number {best_condition:.3e}, at most {max_condition:e} needed); baseline records at several speeds tell the wheels apart"
    )]
    BodySpectraSingular {
        /// The smallest condition number over the bins.
        best_condition: f64,
        /// The largest accepted.
        max_condition: f64,
    },
    /// Too few nominal records for a baseline.
    #[error("vehicle '{}' has {found} nominal record(s) with features; a baseline needs at least {needed}: ingest more nominal runs", vibmode_core::quoted(vehicle))]
    TooFewNominal {
        /// The vehicle.
        vehicle: String,
        /// Nominal records with features.
        found: usize,
        /// Minimum.
        needed: usize,
    },
    /// A record whose channels differ from those of the baseline it is checked against.
    #[error("'{}' has channels {}, but the baseline of vehicle '{}' was built from {}; record the same sensors with the same names, or build a new baseline for the new layout", vibmode_core::quoted(record), vibmode_core::cap_message(found, 100), vibmode_core::quoted(vehicle), vibmode_core::cap_message(baseline, 100))]
    LayoutDiffers {
        /// The record (file) name.
        record: String,
        /// The vehicle.
        vehicle: String,
        /// The record's channels, comma-separated.
        found: String,
        /// The baseline's channels, comma-separated.
        baseline: String,
    },
    /// A vehicle model file that cannot be read or fitted.
    #[error("vehicle model {}: {reason}; give a full-car model file as docs/vehicle.md describes (e.g. examples/city_bus.toml)", vibmode_core::quoted(source_name))]
    VehicleModel {
        /// The file (or where the text came from).
        source_name: String,
        /// What the parser or the fit said.
        reason: String,
    },
    /// A drive with too few records for its statistic.
    #[error("drive '{}' has {found} record(s) of distinct content; a drive's statistic (the median over its records) needs at least {needed}: give more records of the drive, or check these records one by one, without a drive id", vibmode_core::quoted(drive))]
    DriveTooShort {
        /// The drive id.
        drive: String,
        /// Records given, each content counted once.
        found: usize,
        /// Records needed.
        needed: usize,
    },
    /// A drive given with a record stored for another vehicle.
    #[error("drive '{}' of vehicle '{}' holds '{}', a record of vehicle '{}'; a drive holds the records of one vehicle: check it as a record of vehicle '{}' or leave it out", vibmode_core::quoted(drive), vibmode_core::quoted(vehicle), vibmode_core::quoted(record), vibmode_core::quoted(other), vibmode_core::quoted(other))]
    DriveMixesVehicles {
        /// The drive id.
        drive: String,
        /// The vehicle checked.
        vehicle: String,
        /// The record.
        record: String,
        /// The vehicle that has the record.
        other: String,
    },
    /// A check against a model set built before the features left the periodic lines out.
    #[error("the baseline of vehicle '{}' (model set version {version}) was built before the transmissibility left out the engine and driveline lines; build it again (fleet baseline), after ingesting healthy records again if its nominal records are that old", vibmode_core::quoted(vehicle))]
    StaleBaseline {
        /// The vehicle.
        vehicle: String,
        /// The model set's version in the store.
        version: i64,
    },
    /// A baseline whose nominal records are too few once those stored before the line-free
    /// features are left out.
    #[error("vehicle '{}' has {old} nominal record(s) stored before the transmissibility left out the engine and driveline lines and {current} stored since; a baseline needs at least {needed} of the latter: ingest healthy records again (the older ones stay stored)", vibmode_core::quoted(vehicle))]
    NominalBeforeLineFree {
        /// The vehicle.
        vehicle: String,
        /// Nominal records without line-free features.
        old: usize,
        /// Nominal records with them.
        current: usize,
        /// Minimum.
        needed: usize,
    },
    /// A check without a baseline.
    #[error("vehicle '{}' has no baseline yet; build one from its nominal records first (fleet baseline)", vibmode_core::quoted(vehicle))]
    NoBaseline {
        /// The vehicle.
        vehicle: String,
    },
    /// A record's features cannot be computed: the analysis refused it or its settings.
    #[error(
        "features of '{}' cannot be computed: {source}",
        vibmode_core::quoted(record)
    )]
    FeaturesAnalysis {
        /// The record (file name).
        record: String,
        /// The analysis' error.
        #[source]
        source: vibmode_analysis::AnalysisError,
    },
    /// A record's features cannot be computed: a spectrum of it failed.
    #[error(
        "features of '{}' cannot be computed: {source}",
        vibmode_core::quoted(record)
    )]
    FeaturesSpectra {
        /// The record (file name).
        record: String,
        /// The spectrum's error.
        #[source]
        source: vibmode_spectra::SpectraError,
    },
    /// A record whose pieces give spectra of different lengths.
    #[error("features of '{}' cannot be computed: its segments give spectra of {first_bins} and {other_bins} bins; give records of one length", vibmode_core::quoted(record))]
    SpectraBinsDiffer {
        /// The record (file name).
        record: String,
        /// Bins of the first piece's spectrum.
        first_bins: usize,
        /// Bins of the piece that differs.
        other_bins: usize,
    },
    /// A record that gives no feature at all.
    #[error(
        "features of '{}' cannot be computed: no corner has both a sprung and an unsprung channel and no structural mode was found in channels [{}]; name channels by role and corner (e.g. FL_unsprung, FL_sprung) or give longer records",
        vibmode_core::quoted(record),
        vibmode_core::cap_message(&channels.join(", "), 200)
    )]
    NoRecordFeature {
        /// The record (file name).
        record: String,
        /// Its channels.
        channels: Vec<String>,
    },
    /// A baseline without any vehicle feature.
    #[error("the nominal records of vehicle '{}' give no vehicle feature (transmissibility or mode) in enough of them; name channels by role and corner (e.g. RL_unsprung, RL_sprung)", vibmode_core::quoted(vehicle))]
    NoVehicleFeature {
        /// The vehicle.
        vehicle: String,
    },
    /// A condition label that is not nominal or test.
    #[error(
        "condition '{}' is not one of nominal, test",
        vibmode_core::quoted(value)
    )]
    BadCondition {
        /// The text given.
        value: String,
    },
    /// A content-hash name that is not `sha256` or `blake3`.
    #[error(
        "content hash '{}' is not one of sha256, blake3; use the store's own (vibmode.fleet.content_hash(db))",
        vibmode_core::quoted(value)
    )]
    BadContentHash {
        /// The text given.
        value: String,
    },
    /// Features hashed with another function than the store keys its records by.
    #[error("fleet store {}: record {} was hashed with {given}, the store keys records by {store}; compute its features with content_hash = '{store}'", vibmode_core::quoted(path), vibmode_core::quoted(file))]
    ContentHashMismatch {
        /// Store path.
        path: String,
        /// The record's file name.
        file: String,
        /// The hash the features carry.
        given: crate::hash::ContentHash,
        /// The store's.
        store: crate::hash::ContentHash,
    },
    /// Stored content that does not parse (edited or foreign rows).
    #[error("fleet store {}: {} cannot be read ({}); the row was not written by this vibmode: restore the store or re-ingest the record", vibmode_core::quoted(path), vibmode_core::cap_message(what, 80), vibmode_core::cap_message(reason, 100))]
    CorruptRow {
        /// The file.
        path: String,
        /// Which row.
        what: String,
        /// The parser's message.
        reason: String,
    },
    /// Reading a record file failed.
    #[error(
        "cannot read {}: {reason}; check the path and its permissions",
        vibmode_core::quoted(path)
    )]
    Io {
        /// The file.
        path: String,
        /// The operating system's message.
        reason: String,
    },
    /// Writing the fleet report (a folder, the page, or a figure in it) failed.
    #[error(
        "cannot write {}: {reason}; write the report to a folder you can write to",
        vibmode_core::quoted(what)
    )]
    Write {
        /// The file or folder, or the figure.
        what: String,
        /// The operating system's or the renderer's message.
        reason: String,
    },
    /// A settings file that cannot be read or parsed.
    #[error(
        "fleet config {}: {reason}; see docs/fleet.md for the keys",
        vibmode_core::quoted(path)
    )]
    ConfigFile {
        /// The file.
        path: String,
        /// What is wrong (with the line).
        reason: String,
    },
    /// New settings for a store that already holds records analysed with other settings.
    #[error("{} already holds {records} record(s) analysed with other settings; settings are fixed when the first record is stored: use a new store for new settings", vibmode_core::quoted(path))]
    ConfigAfterRecords {
        /// The store.
        path: String,
        /// Records stored.
        records: i64,
    },
    /// A fleet setting is out of range.
    #[error("fleet config: {key} = {value} {fix}")]
    Config {
        /// The key.
        key: &'static str,
        /// Its value.
        value: String,
        /// The valid range or an example.
        fix: String,
    },
    /// Reading the record failed.
    #[error(transparent)]
    Signal(#[from] vibmode_signal::SignalError),
    /// The per-record analysis failed.
    #[error(transparent)]
    Analysis(#[from] vibmode_analysis::AnalysisError),
    /// A spectrum failed.
    #[error(transparent)]
    Spectra(#[from] vibmode_spectra::SpectraError),
}

/// Result of this crate.
pub type Result<T, E = FleetError> = std::result::Result<T, E>;

#[cfg(test)]
mod tests {
    use super::*;

    /// The typed feature errors carry their values into one line each, a long channel list
    /// capped, and keep the underlying error as their source.
    #[test]
    fn feature_errors_name_their_values_in_one_line() {
        let many: Vec<String> = (0..100).map(|k| format!("channel_{k}")).collect();
        let e = FleetError::NoRecordFeature {
            record: "a.csv".into(),
            channels: many,
        };
        let m = e.to_string();
        assert!(m.contains("'a.csv'") && m.contains("channel_0, channel_1") && m.len() < 600);
        assert!(!m.contains("channel_99") && !m.contains('\n'), "{m}");
        let e = FleetError::SpectraBinsDiffer {
            record: "b.csv".into(),
            first_bins: 129,
            other_bins: 65,
        };
        assert!(e.to_string().contains("129 and 65 bins"), "{e}");
        let source = vibmode_spectra::SpectraError::LengthMismatch { len_x: 3, len_y: 8 };
        let e = FleetError::FeaturesSpectra {
            record: "c.csv".into(),
            source,
        };
        let src = std::error::Error::source(&e).map(|s| s.to_string());
        assert!(src.is_some() && e.to_string().ends_with(&src.unwrap_or_default()));
    }
}
