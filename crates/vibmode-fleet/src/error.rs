//! Errors of the fleet store and its statistics.

/// Errors of `vibmode-fleet`; each message is one line naming the value and the fix, never a
/// command-line flag.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum FleetError {
    /// The database file cannot be opened or is not an SQLite database.
    #[error("{path} is not a vibmode fleet store ({reason}); give the path of a store made by fleet init, or a new file name")]
    NotAStore {
        /// The file.
        path: String,
        /// What SQLite or the schema check said.
        reason: String,
    },
    /// The store was written by a newer vibmode.
    #[error("{path} has fleet schema version {found}, this vibmode reads up to version {supported}; use a newer vibmode")]
    NewerSchema {
        /// The file.
        path: String,
        /// Its `user_version`.
        found: i64,
        /// The newest this build knows.
        supported: i64,
    },
    /// The store file does not exist (and was not to be created).
    #[error("no fleet store at {path}; create it with fleet init first")]
    NoStore {
        /// The path.
        path: String,
    },
    /// An SQLite operation failed.
    #[error("fleet store {path}: {operation} failed: {reason}")]
    Sql {
        /// The file.
        path: String,
        /// What was being done.
        operation: &'static str,
        /// SQLite's message.
        reason: String,
    },
    /// A vehicle identifier that the store does not know.
    #[error("vehicle '{vehicle}' is not in the store (known: {known}); ingest its nominal records first")]
    UnknownVehicle {
        /// The identifier given.
        vehicle: String,
        /// The vehicles the store has, comma-separated (or "none").
        known: String,
    },
    /// A vehicle identifier that is empty or not printable.
    #[error(
        "vehicle id '{vehicle}' must be 1 to 64 printable characters without spaces, e.g. bus-017"
    )]
    BadVehicleId {
        /// The identifier given.
        vehicle: String,
    },
    /// The body's response to the wheel motions cannot be fitted from the nominal records.
    #[error("body response to wheel motion: {reason}")]
    BodyModel {
        /// Why, with the fix.
        reason: String,
    },
    /// Too few nominal records for a baseline.
    #[error("vehicle '{vehicle}' has {found} nominal record(s) with features; a baseline needs at least {needed}: ingest more nominal runs")]
    TooFewNominal {
        /// The vehicle.
        vehicle: String,
        /// Nominal records with features.
        found: usize,
        /// Minimum.
        needed: usize,
    },
    /// A record whose channels differ from those of the baseline it is checked against.
    #[error("'{record}' has channels {found}, but the baseline of vehicle '{vehicle}' was built from {baseline}; record the same sensors with the same names, or build a new baseline for the new layout")]
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
    /// A check without a baseline.
    #[error("vehicle '{vehicle}' has no baseline yet; build one from its nominal records first (fleet baseline)")]
    NoBaseline {
        /// The vehicle.
        vehicle: String,
    },
    /// A record's features cannot be computed.
    #[error("features of '{record}' cannot be computed: {reason}")]
    Features {
        /// The record (file name).
        record: String,
        /// Why, with the fix.
        reason: String,
    },
    /// A condition label that is not nominal or test.
    #[error("condition '{value}' is not one of nominal, test")]
    BadCondition {
        /// The text given.
        value: String,
    },
    /// Stored content that does not parse (edited or foreign rows).
    #[error("fleet store {path}: {what} cannot be read ({reason}); the row was not written by this vibmode: restore the store or re-ingest the record")]
    CorruptRow {
        /// The file.
        path: String,
        /// Which row.
        what: String,
        /// The parser's message.
        reason: String,
    },
    /// Reading a record file failed.
    #[error("cannot read {path}: {reason}")]
    Io {
        /// The file.
        path: String,
        /// The operating system's message.
        reason: String,
    },
    /// A settings file that cannot be read or parsed.
    #[error("fleet config {path}: {reason}; see docs/fleet.md for the keys")]
    ConfigFile {
        /// The file.
        path: String,
        /// What is wrong (with the line).
        reason: String,
    },
    /// New settings for a store that already holds records analysed with other settings.
    #[error("{path} already holds {records} record(s) analysed with other settings; settings are fixed when the first record is stored: use a new store for new settings")]
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
