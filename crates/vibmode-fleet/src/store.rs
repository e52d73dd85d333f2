//! The SQLite store: vehicles, records (content hash, file name, ingest time, condition, road
//! label, metadata), features per record, versioned model sets and checks.

use std::path::Path;

use rusqlite::{params, Connection, OpenFlags, OptionalExtension, TransactionBehavior};
use serde::de::DeserializeOwned;
use serde::{Deserialize, Serialize};

use crate::config::FleetConfig;
use crate::error::{FleetError, Result};
use crate::features::RecordFeatures;
use crate::hash::ContentHash;
use crate::model::{Assessment, Classification, ModelSet};

/// The application id kept in the `meta` table.
pub const APP_ID: &str = "vibmode-fleet";

/// Migrations in order; `user_version` is the number applied.
const MIGRATIONS: &[&str] = &[
    // 1: the first schema.
    "CREATE TABLE meta (key TEXT PRIMARY KEY, value TEXT NOT NULL);
     INSERT INTO meta (key, value) VALUES ('app', 'vibmode-fleet');
     CREATE TABLE vehicles (
        id INTEGER PRIMARY KEY,
        name TEXT NOT NULL UNIQUE,
        created TEXT NOT NULL);
     CREATE TABLE records (
        id INTEGER PRIMARY KEY,
        vehicle_id INTEGER NOT NULL REFERENCES vehicles(id),
        sha256 TEXT NOT NULL,
        file_name TEXT NOT NULL,
        ingested TEXT NOT NULL,
        condition TEXT NOT NULL CHECK (condition IN ('nominal', 'test')),
        road TEXT,
        metadata TEXT NOT NULL,
        UNIQUE (vehicle_id, sha256));
     CREATE TABLE features (
        record_id INTEGER PRIMARY KEY REFERENCES records(id) ON DELETE CASCADE,
        json TEXT NOT NULL);
     CREATE TABLE model_sets (
        id INTEGER PRIMARY KEY,
        vehicle_id INTEGER NOT NULL REFERENCES vehicles(id),
        version INTEGER NOT NULL,
        created TEXT NOT NULL,
        json TEXT NOT NULL,
        UNIQUE (vehicle_id, version));
     CREATE TABLE checks (
        id INTEGER PRIMARY KEY,
        record_id INTEGER NOT NULL REFERENCES records(id) ON DELETE CASCADE,
        model_version INTEGER NOT NULL,
        checked TEXT NOT NULL,
        classification TEXT NOT NULL,
        json TEXT NOT NULL);",
    // 2: drive verdicts (`fleet check` per drive), with the records of each.
    "CREATE TABLE drives (
        id INTEGER PRIMARY KEY,
        vehicle_id INTEGER NOT NULL REFERENCES vehicles(id),
        drive TEXT NOT NULL,
        model_version INTEGER NOT NULL,
        checked TEXT NOT NULL,
        classification TEXT NOT NULL,
        json TEXT NOT NULL);
     CREATE TABLE drive_records (
        drive_id INTEGER NOT NULL REFERENCES drives(id) ON DELETE CASCADE,
        record_id INTEGER NOT NULL REFERENCES records(id) ON DELETE CASCADE,
        PRIMARY KEY (drive_id, record_id));",
    // 3: a vehicle's full-car model file (`fleet register`), for the suspension fitted per
    // drive; the text as given and its SHA-256, which each record's stored equations name.
    "CREATE TABLE vehicle_models (
        vehicle_id INTEGER PRIMARY KEY REFERENCES vehicles(id),
        sha256 TEXT NOT NULL,
        registered TEXT NOT NULL,
        toml TEXT NOT NULL);",
    // 4: the records' content hash (crate::hash): BLAKE3 for a store without records, SHA-256
    // kept by a store that holds some (their hashes cannot be recomputed without the files).
    "ALTER TABLE records RENAME COLUMN sha256 TO content_hash;
     INSERT INTO meta (key, value) SELECT 'content_hash',
        CASE WHEN EXISTS (SELECT 1 FROM records) THEN 'sha256' ELSE 'blake3' END;",
];

/// How long a write waits for another process's transaction before giving up.
pub const BUSY_TIMEOUT: std::time::Duration = std::time::Duration::from_secs(60);

/// The schema version this build writes.
pub const SCHEMA_VERSION: i64 = MIGRATIONS.len() as i64;

/// Nominal (healthy, for the baseline) or test (to be checked).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Condition {
    /// Healthy run for the nominal model set.
    Nominal,
    /// Later measurement.
    Test,
}

impl Condition {
    /// The condition's name as the store and the commands spell it.
    pub fn as_str(self) -> &'static str {
        match self {
            Condition::Nominal => "nominal",
            Condition::Test => "test",
        }
    }
}

impl std::str::FromStr for Condition {
    type Err = FleetError;
    fn from_str(s: &str) -> Result<Self> {
        match s.trim().to_ascii_lowercase().as_str() {
            "nominal" => Ok(Condition::Nominal),
            "test" => Ok(Condition::Test),
            _ => Err(FleetError::BadCondition {
                value: s.to_string(),
            }),
        }
    }
}

/// What to store with a new record.
#[derive(Clone, Debug)]
pub struct NewRecord<'a> {
    /// Vehicle id.
    pub vehicle: &'a str,
    /// The file's content hash, hex, made with the store's [`Store::content_hash`].
    pub content_hash: &'a str,
    /// File name.
    pub file_name: &'a str,
    /// Nominal or test.
    pub condition: Condition,
    /// Road label, e.g. `B`, `cobbles`.
    pub road: Option<&'a str>,
    /// Free metadata (JSON).
    pub metadata: serde_json::Value,
}

/// A record row.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct RecordRow {
    /// Row id.
    pub id: i64,
    /// File name.
    pub file_name: String,
    /// Content hash, hex ([`Store::content_hash`]).
    pub content_hash: String,
    /// Ingest time, UTC, RFC 3339.
    pub ingested: String,
    /// Nominal or test.
    pub condition: Condition,
    /// Road label.
    pub road: Option<String>,
}

/// A vehicle's suspension line in the status when it has no registered model file.
pub const NO_MODEL_FILE_STATUS: &str = "no model file registered: springs and dampers are not fitted per drive, so a lost spring may go unseen (docs/fleet.md, \"The suspension fitted per drive\")";

/// Status of one vehicle.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct VehicleStatus {
    /// Vehicle id.
    pub vehicle: String,
    /// Nominal records.
    pub n_nominal: usize,
    /// Test records.
    pub n_test: usize,
    /// Latest model-set version, if any.
    pub baseline_version: Option<i64>,
    /// The latest checks, newest first: (file, classification, summary).
    pub last_checks: Vec<(String, Classification, String)>,
    /// The latest drive verdict, if a drive was checked (stores from before drives have none).
    #[serde(default)]
    pub latest_drive: Option<DriveStatus>,
    /// The latest drive verdicts, newest first (at most the `last` asked for).
    #[serde(default)]
    pub drives: Vec<DriveStatus>,
    /// The suspension fitted per drive: whether the vehicle has a registered model file and
    /// whether its latest model set fits it (one line; [`NO_MODEL_FILE_STATUS`] without one).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub suspension: Option<String>,
    /// The latest model set's nominal drives, each held out against the other nominal records
    /// ([`crate::model::ModelSet::held_out_drives`]); absent without one.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub held_out: Option<HeldOutCount>,
    /// When the latest drive is not flagged `vehicle` or `both`: the newest earlier drive
    /// against the same baseline that was, so that a fault found once and not on the drives
    /// after it (a fault near the limits is not found on every drive) is not hidden behind the
    /// latest `normal`; absent otherwise.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub earlier_flag: Option<EarlierFlag>,
}

/// A vehicle fault found on an earlier drive and not on the latest ([`VehicleStatus::earlier_flag`]).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct EarlierFlag {
    /// The newest flagged drive against the latest drive's baseline.
    pub drive: DriveStatus,
    /// Drives after it against the same baseline (none of them flagged `vehicle` or `both`).
    pub later_drives: usize,
    /// Drives against that baseline flagged `vehicle` or `both`, of `baseline_drives`.
    pub flagged_drives: usize,
    /// Drives checked against that baseline.
    pub baseline_drives: usize,
}

impl EarlierFlag {
    /// The newest drive flagged `vehicle` or `both` among `drives` (newest first) against the
    /// newest drive's baseline, when the newest drive itself is not.
    pub fn of(drives: &[DriveStatus]) -> Option<EarlierFlag> {
        let latest = drives.first()?;
        let faulty = |d: &DriveStatus| {
            matches!(
                d.classification,
                Classification::Vehicle | Classification::Both
            )
        };
        if faulty(latest) {
            return None;
        }
        let same: Vec<&DriveStatus> = drives
            .iter()
            .filter(|d| d.model_version == latest.model_version)
            .collect();
        let at = same.iter().position(|d| faulty(d))?;
        Some(EarlierFlag {
            drive: same[at].clone(),
            later_drives: at,
            flagged_drives: same.iter().filter(|d| faulty(d)).count(),
            baseline_drives: same.len(),
        })
    }
}

/// How many of a baseline's nominal drives, held out against its other nominal records, were
/// flagged (a verdict other than `normal`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct HeldOutCount {
    /// Drives held out.
    pub drives: usize,
    /// Of them, flagged.
    pub flagged: usize,
}

/// One drive verdict as the status shows it.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct DriveStatus {
    /// The drive id.
    pub drive: String,
    /// When it was checked (UTC, RFC 3339).
    pub checked: String,
    /// normal, road, vehicle, both or sensor.
    pub classification: Classification,
    /// The corner named first, if any.
    pub corner: Option<String>,
    /// The component of that corner (damper, spring, tyre or suspension), if named; absent in
    /// drives stored before it existed.
    #[serde(default)]
    pub component: Option<crate::model::Component>,
    /// One line: the flagged features per corner.
    pub summary: String,
    /// The largest |z| of the flagged vehicle features, each over its own limit (how sure: 1 at
    /// the limit); absent without one.
    pub vehicle_z_over_limit: Option<f64>,
    /// The false-alarm rate per drive and feature group.
    pub false_alarm_rate: f64,
    /// Records in the drive.
    pub n_records: usize,
    /// When the drive was driven (UTC, RFC 3339 to the second): its earliest record's start,
    /// where every record's start is known; else `None`.
    #[serde(default)]
    pub driven: Option<String>,
    /// Since when the vehicle has had this verdict: the first drive of the latest run of
    /// drives with this classification, by when it was driven (`driven`), or by when it was
    /// checked where that is unknown.
    pub since: String,
    /// The version of the vehicle's model set (baseline) it was checked against.
    #[serde(default)]
    pub model_version: i64,
}

/// A Unix time (s) as UTC RFC 3339 to the second, as [`now_utc`] writes it; `None` outside
/// the years chrono can represent.
pub fn utc_of_unix(unix_s: f64) -> Option<String> {
    if !unix_s.is_finite() || unix_s.abs() > 1e14 {
        return None;
    }
    let t = chrono::DateTime::from_timestamp(unix_s.floor() as i64, 0)?;
    Some(t.format("%Y-%m-%dT%H:%M:%SZ").to_string())
}

impl DriveStatus {
    /// When the drive was driven, or `checked <time>` where that is unknown: the time the
    /// drives are ordered by.
    pub fn when(&self) -> String {
        match &self.driven {
            Some(t) => t.clone(),
            None => format!("checked {}", self.checked),
        }
    }

    /// The corner and its component as tables show them: `RL damper`, `RL` (no component
    /// named), `-` (no corner).
    pub fn place(&self) -> String {
        match (&self.corner, self.component) {
            (Some(c), Some(k)) => format!("{c} {k}"),
            (Some(c), None) => c.clone(),
            (None, _) => "-".into(),
        }
    }
}

/// An open fleet store.
#[derive(Debug)]
pub struct Store {
    conn: Connection,
    path: String,
}

/// `map_err`'s conversion of an SQLite error met while doing `operation` on the store at `path`.
fn sql_error<'a>(
    path: &'a str,
    operation: &'static str,
) -> impl Fn(rusqlite::Error) -> FleetError + Copy + 'a {
    move |e| FleetError::Sql {
        path: path.to_string(),
        operation,
        reason: e.to_string(),
    }
}

/// Now as UTC RFC 3339 (seconds).
pub fn now_utc() -> String {
    let secs = std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map_or(0, |d| d.as_secs()) as i64;
    let days = secs.div_euclid(86_400);
    let rem = secs.rem_euclid(86_400);
    // Howard Hinnant's civil_from_days.
    let z = days + 719_468;
    let era = z.div_euclid(146_097);
    let doe = z.rem_euclid(146_097);
    let yoe = (doe - doe / 1460 + doe / 36_524 - doe / 146_096) / 365;
    let doy = doe - (365 * yoe + yoe / 4 - yoe / 100);
    let mp = (5 * doy + 2) / 153;
    let d = doy - (153 * mp + 2) / 5 + 1;
    let m = if mp < 10 { mp + 3 } else { mp - 9 };
    let y = yoe + era * 400 + i64::from(m <= 2);
    format!(
        "{y:04}-{m:02}-{d:02}T{:02}:{:02}:{:02}Z",
        rem / 3600,
        (rem / 60) % 60,
        rem % 60
    )
}

impl Store {
    fn sql(&self, operation: &'static str) -> impl Fn(rusqlite::Error) -> FleetError + '_ {
        sql_error(&self.path, operation)
    }

    fn not_a_store(path: &str, reason: impl ToString) -> FleetError {
        FleetError::NotAStore {
            path: path.to_string(),
            reason: reason.to_string(),
        }
    }

    /// The store path must be a regular file (or, with `may_be_new`, a new name in an existing
    /// folder): a folder, a device or a missing folder is named as such.
    fn check_path(path: &Path, may_be_new: bool) -> Result<()> {
        let p = path.display().to_string();
        match std::fs::metadata(path) {
            Ok(m) if m.is_dir() => Err(FleetError::NotAFile {
                path: p,
                what: "a folder",
            }),
            Ok(m) if !m.is_file() => Err(FleetError::NotAFile {
                path: p,
                what: "a special file (a device or a pipe)",
            }),
            Ok(_) => Ok(()),
            Err(_) => {
                let folder = vibmode_core::files::parent_dir(path);
                if !folder.is_dir() {
                    Err(FleetError::NoFolder {
                        path: p,
                        folder: folder.display().to_string(),
                    })
                } else if may_be_new {
                    Ok(())
                } else {
                    Err(FleetError::NoStore { path: p })
                }
            }
        }
    }

    /// Creates a new store at `path`, or opens the store already there. Returns the store and
    /// whether it was created. A file that is not a fleet store is an error (it is not touched).
    ///
    /// Safe to run by several processes at once: the schema is created in an immediate
    /// transaction that re-reads the schema version, so exactly one of them creates it and the
    /// others find it.
    pub fn init(path: &Path) -> Result<(Store, bool)> {
        Store::check_path(path, true)?;
        let p = path.display().to_string();
        let conn = Connection::open_with_flags(
            path,
            OpenFlags::SQLITE_OPEN_READ_WRITE
                | OpenFlags::SQLITE_OPEN_CREATE
                | OpenFlags::SQLITE_OPEN_NO_MUTEX,
        )
        .map_err(|e| Store::not_a_store(&p, e))?;
        conn.busy_timeout(BUSY_TIMEOUT)
            .map_err(|e| Store::not_a_store(&p, e))?;
        let mut store = Store { conn, path: p };
        // A foreign database is refused before anything (the journal mode) is changed in it.
        store.refuse_foreign()?;
        // WAL before the schema: a store is in WAL from its first transaction, so the
        // processes that meet here wait for each other's writes instead of deadlocking.
        store.configure()?;
        let created = store.create_schema()?;
        store.check_schema()?;
        store.migrate()?;
        Ok((store, created))
    }

    /// An SQLite file with tables but no fleet schema, or with another application's meta
    /// table, is not one `init` may write to.
    fn refuse_foreign(&self) -> Result<()> {
        let p = &self.path;
        let err = |e: rusqlite::Error| Store::not_a_store(p, e);
        let version: i64 = self
            .conn
            .query_row("PRAGMA user_version", [], |r| r.get(0))
            .map_err(err)?;
        let objects: i64 = self
            .conn
            .query_row("SELECT COUNT(*) FROM sqlite_master", [], |r| r.get(0))
            .map_err(err)?;
        if version == 0 && objects == 0 {
            return Ok(());
        }
        self.check_schema()
    }

    /// In one immediate transaction: an empty database (no table, `user_version` 0) gets the
    /// first schema; anything else is left alone. Returns whether the schema was created.
    fn create_schema(&mut self) -> Result<bool> {
        let p = self.path.clone();
        let err = |e: rusqlite::Error| Store::not_a_store(&p, e);
        let tx = self
            .conn
            .transaction_with_behavior(TransactionBehavior::Immediate)
            .map_err(err)?;
        let version: i64 = tx
            .query_row("PRAGMA user_version", [], |r| r.get(0))
            .map_err(err)?;
        let objects: i64 = tx
            .query_row("SELECT COUNT(*) FROM sqlite_master", [], |r| r.get(0))
            .map_err(err)?;
        if version != 0 || objects != 0 {
            return Ok(false);
        }
        Store::apply_migration(&tx, 0).map_err(|e| FleetError::Sql {
            path: p.clone(),
            operation: "creating the schema",
            reason: e.to_string(),
        })?;
        tx.commit().map_err(err)?;
        Ok(true)
    }

    /// Migration `i` (0-based) and its `user_version`, inside `tx`.
    fn apply_migration(tx: &rusqlite::Transaction<'_>, i: usize) -> rusqlite::Result<()> {
        if let Some(sql) = MIGRATIONS.get(i) {
            tx.execute_batch(sql)?;
            tx.execute_batch(&format!("PRAGMA user_version = {}", i + 1))?;
        }
        Ok(())
    }

    /// Opens an existing store, migrating an older schema. Errors: no file, a file that is not
    /// a fleet store (corrupt, foreign SQLite), a newer or unknown schema.
    pub fn open(path: &Path) -> Result<Store> {
        Store::check_path(path, false)?;
        let p = path.display().to_string();
        let conn = Connection::open_with_flags(
            path,
            OpenFlags::SQLITE_OPEN_READ_WRITE | OpenFlags::SQLITE_OPEN_NO_MUTEX,
        )
        .map_err(|e| Store::not_a_store(&p, e))?;
        conn.busy_timeout(BUSY_TIMEOUT)
            .map_err(|e| Store::not_a_store(&p, e))?;
        let mut store = Store { conn, path: p };
        store.check_schema()?;
        store.configure()?;
        store.migrate()?;
        Ok(store)
    }

    /// The schema version must be one this build reads, and the file a fleet store.
    fn check_schema(&self) -> Result<()> {
        let p = &self.path;
        let version: i64 = self
            .conn
            .query_row("PRAGMA user_version", [], |r| r.get(0))
            .map_err(|e| Store::not_a_store(p, e))?;
        if version > SCHEMA_VERSION {
            return Err(FleetError::NewerSchema {
                path: p.clone(),
                found: version,
                supported: SCHEMA_VERSION,
            });
        }
        if version < 0 {
            return Err(FleetError::UnknownSchema {
                path: p.clone(),
                found: version,
                supported: SCHEMA_VERSION,
            });
        }
        if version == 0 {
            return Err(Store::not_a_store(p, "no fleet schema (user_version 0)"));
        }
        let app: Option<String> = self
            .conn
            .query_row("SELECT value FROM meta WHERE key = 'app'", [], |r| r.get(0))
            .optional()
            .map_err(|e| Store::not_a_store(p, e))?;
        if app.as_deref() != Some(APP_ID) {
            return Err(Store::not_a_store(
                p,
                format!(
                    "meta app is '{}', not {APP_ID}",
                    vibmode_core::quoted(app.as_deref().unwrap_or("none"))
                ),
            ));
        }
        Ok(())
    }

    fn configure(&mut self) -> Result<()> {
        let p = self.path.clone();
        // Another process writing: wait for it (up to BUSY_TIMEOUT) instead of failing.
        self.conn
            .busy_timeout(BUSY_TIMEOUT)
            .map_err(|e| Store::not_a_store(&p, e))?;
        // Switching to WAL takes an exclusive lock. Two processes switching at once both hold
        // a shared lock and want the exclusive one; SQLite answers one of them SQLITE_BUSY at
        // once, without the busy handler (it would deadlock). That one tries again.
        let deadline = std::time::Instant::now() + BUSY_TIMEOUT;
        let mut attempt = 0u32;
        loop {
            match self
                .conn
                .query_row("PRAGMA journal_mode=WAL", [], |r| r.get::<_, String>(0))
            {
                Ok(_) => break,
                Err(rusqlite::Error::SqliteFailure(e, _))
                    if e.code == rusqlite::ErrorCode::DatabaseBusy
                        && std::time::Instant::now() < deadline =>
                {
                    attempt += 1;
                    // 5..40 ms, varied by process and attempt so that the two part.
                    let ms = 5 + (u64::from(std::process::id()) + u64::from(attempt) * 7) % 36;
                    std::thread::sleep(std::time::Duration::from_millis(ms));
                }
                Err(e) => return Err(Store::not_a_store(&p, e)),
            }
        }
        self.conn
            .execute_batch("PRAGMA foreign_keys=ON;")
            .map_err(|e| Store::not_a_store(&p, e))?;
        Ok(())
    }

    /// Applies the missing migrations, each in an immediate transaction that re-reads
    /// `user_version` (another process may have applied it meanwhile).
    fn migrate(&mut self) -> Result<()> {
        let path = self.path.clone();
        let err = sql_error(&path, "schema migration");
        let current: i64 = self
            .conn
            .query_row("PRAGMA user_version", [], |r| r.get(0))
            .map_err(err)?;
        if current >= SCHEMA_VERSION {
            return Ok(());
        }
        loop {
            let tx = self
                .conn
                .transaction_with_behavior(TransactionBehavior::Immediate)
                .map_err(err)?;
            let version: i64 = tx
                .query_row("PRAGMA user_version", [], |r| r.get(0))
                .map_err(err)?;
            if !(1..SCHEMA_VERSION).contains(&version) {
                return Ok(());
            }
            Store::apply_migration(&tx, version as usize).map_err(err)?;
            tx.commit().map_err(err)?;
        }
    }

    /// The hash function this store keys its records by (`meta.content_hash`, set by
    /// migration 4): every record hash given to [`Store::find_record`], [`NewRecord`] and
    /// [`Store::other_vehicles_with`] must be made with it.
    pub fn content_hash(&self) -> Result<ContentHash> {
        let name = self
            .meta_value("content_hash", "reading the content hash")?
            .ok_or_else(|| self.corrupt("meta content_hash", "missing"))?;
        name.parse().map_err(|_| {
            self.corrupt(
                "meta content_hash",
                format!("'{}' is not sha256 or blake3", vibmode_core::quoted(&name)),
            )
        })
    }

    /// The `meta` table's value of `key`, if any.
    fn meta_value(&self, key: &str, operation: &'static str) -> Result<Option<String>> {
        self.conn
            .query_row("SELECT value FROM meta WHERE key = ?1", [key], |r| r.get(0))
            .optional()
            .map_err(self.sql(operation))
    }

    /// The schema version (`user_version`).
    pub fn schema_version(&self) -> Result<i64> {
        self.conn
            .query_row("PRAGMA user_version", [], |r| r.get(0))
            .map_err(self.sql("reading user_version"))
    }

    /// The path of the file.
    pub fn path(&self) -> &str {
        &self.path
    }

    /// The vehicles, sorted.
    pub fn vehicles(&self) -> Result<Vec<String>> {
        let mut st = self
            .conn
            .prepare("SELECT name FROM vehicles ORDER BY name")
            .map_err(self.sql("listing vehicles"))?;
        let rows = st
            .query_map([], |r| r.get::<_, String>(0))
            .map_err(self.sql("listing vehicles"))?;
        rows.collect::<rusqlite::Result<Vec<_>>>()
            .map_err(self.sql("listing vehicles"))
    }

    fn vehicle_id(&self, vehicle: &str) -> Result<Option<i64>> {
        self.conn
            .query_row("SELECT id FROM vehicles WHERE name = ?1", [vehicle], |r| {
                r.get(0)
            })
            .optional()
            .map_err(self.sql("looking up a vehicle"))
    }

    /// The id of a known vehicle; an unknown one is an error listing the known ones.
    pub fn require_vehicle(&self, vehicle: &str) -> Result<i64> {
        match self.vehicle_id(vehicle)? {
            Some(id) => Ok(id),
            None => {
                let known = self.vehicles()?;
                let mut shown: Vec<String> = known
                    .iter()
                    .take(5)
                    .map(|v| vibmode_core::quoted(v).to_string())
                    .collect();
                if known.len() > 5 {
                    shown.push(format!("and {} more", known.len() - 5));
                }
                Err(FleetError::UnknownVehicle {
                    vehicle: vehicle.to_string(),
                    known: if known.is_empty() {
                        "none".into()
                    } else {
                        shown.join(", ")
                    },
                })
            }
        }
    }

    /// Registers (or replaces) the full-car model file of a vehicle, created if new: its text
    /// and SHA-256. Returns true when it differs from the one registered before (or there was
    /// none).
    pub fn register_vehicle_model(
        &mut self,
        vehicle: &str,
        toml: &str,
        sha256: &str,
    ) -> Result<bool> {
        let now = now_utc();
        let path = self.path.clone();
        let err = sql_error(&path, "registering a vehicle model");
        let tx = self
            .conn
            .transaction_with_behavior(TransactionBehavior::Immediate)
            .map_err(err)?;
        tx.execute(
            "INSERT OR IGNORE INTO vehicles (name, created) VALUES (?1, ?2)",
            params![vehicle, now],
        )
        .map_err(err)?;
        let vid: i64 = tx
            .query_row("SELECT id FROM vehicles WHERE name = ?1", [vehicle], |r| {
                r.get(0)
            })
            .map_err(err)?;
        let before: Option<String> = tx
            .query_row(
                "SELECT sha256 FROM vehicle_models WHERE vehicle_id = ?1",
                [vid],
                |r| r.get(0),
            )
            .optional()
            .map_err(err)?;
        let changed = before.as_deref() != Some(sha256);
        if changed {
            tx.execute(
                "INSERT INTO vehicle_models (vehicle_id, sha256, registered, toml)
                 VALUES (?1, ?2, ?3, ?4)
                 ON CONFLICT (vehicle_id) DO UPDATE SET
                    sha256 = excluded.sha256, registered = excluded.registered,
                    toml = excluded.toml",
                params![vid, sha256, now, toml],
            )
            .map_err(err)?;
        }
        tx.commit().map_err(err)?;
        Ok(changed)
    }

    /// The registered full-car model file of a vehicle: (SHA-256, TOML text), if any.
    pub fn vehicle_model(&self, vehicle: &str) -> Result<Option<(String, String)>> {
        self.conn
            .query_row(
                "SELECT m.sha256, m.toml FROM vehicle_models m
                 JOIN vehicles v ON v.id = m.vehicle_id WHERE v.name = ?1",
                [vehicle],
                |r| Ok((r.get(0)?, r.get(1)?)),
            )
            .optional()
            .map_err(self.sql("reading a vehicle model"))
    }

    /// The vehicles other than `vehicle` that have a record with this content hash.
    pub fn other_vehicles_with(&self, vehicle: &str, content_hash: &str) -> Result<Vec<String>> {
        let mut st = self
            .conn
            .prepare(
                "SELECT DISTINCT v.name FROM records r JOIN vehicles v ON v.id = r.vehicle_id
                 WHERE r.content_hash = ?1 AND v.name <> ?2 ORDER BY v.name",
            )
            .map_err(self.sql("looking up a record's vehicles"))?;
        let rows = st
            .query_map(params![content_hash, vehicle], |r| r.get::<_, String>(0))
            .map_err(self.sql("looking up a record's vehicles"))?;
        rows.collect::<std::result::Result<Vec<_>, _>>()
            .map_err(self.sql("looking up a record's vehicles"))
    }

    /// The record of `vehicle` with this content hash, if stored.
    pub fn find_record(&self, vehicle: &str, content_hash: &str) -> Result<Option<RecordRow>> {
        let Some(vid) = self.vehicle_id(vehicle)? else {
            return Ok(None);
        };
        self.conn
            .query_row(
                "SELECT id, file_name, content_hash, ingested, condition, road FROM records
                 WHERE vehicle_id = ?1 AND content_hash = ?2",
                params![vid, content_hash],
                row_to_record,
            )
            .optional()
            .map_err(self.sql("looking up a record"))?
            .transpose()
            .map_err(|e| self.corrupt("a record row", e))
    }

    fn corrupt(&self, what: &str, reason: impl ToString) -> FleetError {
        FleetError::CorruptRow {
            path: self.path.clone(),
            what: what.to_string(),
            reason: reason.to_string(),
        }
    }

    /// Stores a record and its features in one transaction (creating the vehicle if new).
    /// Returns the record id; a record whose content the vehicle already has (stored by another
    /// process meanwhile, too) is left alone and its id returned.
    pub fn insert_record(&mut self, rec: &NewRecord<'_>, features: &RecordFeatures) -> Result<i64> {
        let out = self.store_batch(&[BatchItem {
            record: rec.clone(),
            features,
            check: None,
            refresh_features: false,
        }])?;
        Ok(out.first().map_or(0, |o| o.record_id))
    }

    /// Stores records, their features and checks all in one immediate transaction: all of them
    /// or (on any error) none. A record whose content the vehicle already has (stored earlier,
    /// by another process meanwhile, or twice in `items`) is not stored again (`inserted`
    /// false); its check is stored against the existing row. Everything is serialised and read
    /// back before the transaction starts: a value that could not be read later (a non-finite
    /// number) is an error and nothing is written.
    pub fn store_batch(&mut self, items: &[BatchItem<'_>]) -> Result<Vec<Stored>> {
        self.store_batch_with_drives(items, &[])
    }

    /// As [`Store::store_batch`], and in the same transaction the verdict of each drive over
    /// some of these records (table `drives`, its records, given by their indices in `items`, in
    /// `drive_records`).
    pub fn store_batch_with_drives(
        &mut self,
        items: &[BatchItem<'_>],
        drives: &[(crate::model::Drive, Vec<usize>)],
    ) -> Result<Vec<Stored>> {
        let mut drive_json = Vec::with_capacity(drives.len());
        for (d, members) in drives {
            if let Some(&bad) = members.iter().find(|&&i| i >= items.len()) {
                return Err(FleetError::NotStorable {
                    what: format!("the verdict of drive '{}'", vibmode_core::quoted(&d.drive)),
                    reason: format!("record index {bad} of {} records", items.len()),
                });
            }
            drive_json.push(to_json_checked(
                d,
                &format!("the verdict of drive '{}'", vibmode_core::quoted(&d.drive)),
            )?);
        }
        let mut prepared = Vec::with_capacity(items.len());
        for it in items {
            let features = to_json_checked(
                it.features,
                &format!(
                    "the features of '{}'",
                    vibmode_core::quoted(it.record.file_name)
                ),
            )?;
            let check = match it.check {
                Some((version, a)) => Some((
                    version,
                    a.classification.to_string(),
                    to_json_checked(
                        a,
                        &format!(
                            "the check of '{}'",
                            vibmode_core::quoted(it.record.file_name)
                        ),
                    )?,
                )),
                None => None,
            };
            prepared.push((features, check));
        }
        let now = now_utc();
        let path = self.path.clone();
        let err = sql_error(&path, "storing records");
        let tx = self
            .conn
            .transaction_with_behavior(TransactionBehavior::Immediate)
            .map_err(err)?;
        let mut out = Vec::with_capacity(items.len());
        for (it, (features, check)) in items.iter().zip(prepared) {
            let rec = &it.record;
            tx.execute(
                "INSERT OR IGNORE INTO vehicles (name, created) VALUES (?1, ?2)",
                params![rec.vehicle, now],
            )
            .map_err(err)?;
            let vid: i64 = tx
                .query_row(
                    "SELECT id FROM vehicles WHERE name = ?1",
                    [rec.vehicle],
                    |r| r.get(0),
                )
                .map_err(err)?;
            let changed = tx
                .execute(
                    "INSERT INTO records
                        (vehicle_id, content_hash, file_name, ingested, condition, road, metadata)
                     VALUES (?1, ?2, ?3, ?4, ?5, ?6, ?7)
                     ON CONFLICT (vehicle_id, content_hash) DO NOTHING",
                    params![
                        vid,
                        rec.content_hash,
                        rec.file_name,
                        now,
                        rec.condition.as_str(),
                        rec.road,
                        rec.metadata.to_string()
                    ],
                )
                .map_err(err)?;
            let inserted = changed == 1;
            let id: i64 = if inserted {
                let id = tx.last_insert_rowid();
                tx.execute(
                    "INSERT INTO features (record_id, json) VALUES (?1, ?2)",
                    params![id, features],
                )
                .map_err(err)?;
                id
            } else {
                let id: i64 = tx
                    .query_row(
                        "SELECT id FROM records WHERE vehicle_id = ?1 AND content_hash = ?2",
                        params![vid, rec.content_hash],
                        |r| r.get(0),
                    )
                    .map_err(err)?;
                if it.refresh_features {
                    tx.execute(
                        "UPDATE features SET json = ?1 WHERE record_id = ?2",
                        params![features, id],
                    )
                    .map_err(err)?;
                }
                id
            };
            if let Some((version, class, json)) = check {
                tx.execute(
                    "INSERT INTO checks (record_id, model_version, checked, classification, json)
                     VALUES (?1, ?2, ?3, ?4, ?5)",
                    params![id, version, now, class, json],
                )
                .map_err(err)?;
            }
            out.push(Stored {
                record_id: id,
                inserted,
            });
        }
        for ((d, members), json) in drives.iter().zip(drive_json) {
            let Some(first) = members.first().map(|&i| &items[i]) else {
                continue;
            };
            let vid: i64 = tx
                .query_row(
                    "SELECT id FROM vehicles WHERE name = ?1",
                    [first.record.vehicle],
                    |r| r.get(0),
                )
                .map_err(err)?;
            // The same drive checked again (its name, its records and the baseline version):
            // its stored verdict is replaced by this one, checked now, so the timeline holds it
            // once (as the latest check where its records' times are unknown).
            let ids: Vec<i64> = members.iter().map(|&i| out[i].record_id).collect();
            if let Some(old) = same_drive(&tx, vid, &d.drive, d.model_version, &ids).map_err(err)? {
                tx.execute("DELETE FROM drive_records WHERE drive_id = ?1", [old])
                    .map_err(err)?;
                tx.execute("DELETE FROM drives WHERE id = ?1", [old])
                    .map_err(err)?;
            }
            tx.execute(
                "INSERT INTO drives (vehicle_id, drive, model_version, checked, classification, json)
                 VALUES (?1, ?2, ?3, ?4, ?5, ?6)",
                params![
                    vid,
                    d.drive,
                    d.model_version,
                    now,
                    d.assessment.classification.to_string(),
                    json
                ],
            )
            .map_err(err)?;
            let did = tx.last_insert_rowid();
            for &i in members {
                tx.execute(
                    "INSERT OR IGNORE INTO drive_records (drive_id, record_id) VALUES (?1, ?2)",
                    params![did, out[i].record_id],
                )
                .map_err(err)?;
            }
        }
        tx.commit().map_err(err)?;
        Ok(out)
    }

    /// The last `last` drive verdicts of `vehicle` stored with model set `model_version`, in the
    /// order they were stored, each with its records' content hashes (for the spring trend over
    /// a vehicle's drives, [`crate::suspension::spring_trend`]).
    pub fn drives_of_model_set(
        &self,
        vehicle: &str,
        model_version: i64,
        last: usize,
    ) -> Result<Vec<(crate::model::Drive, Vec<String>)>> {
        let Some(vid) = self.vehicle_id(vehicle)? else {
            return Ok(Vec::new());
        };
        let mut st = self
            .conn
            .prepare(
                "SELECT d.drive, d.json,
                        (SELECT group_concat(r.content_hash, ' ') FROM drive_records x
                         JOIN records r ON r.id = x.record_id WHERE x.drive_id = d.id)
                 FROM drives d WHERE d.vehicle_id = ?1 AND d.model_version = ?2
                 ORDER BY d.id DESC LIMIT ?3",
            )
            .map_err(self.sql("reading drives"))?;
        let last = i64::try_from(last).unwrap_or(i64::MAX);
        let mut rows = st
            .query_map(params![vid, model_version, last], |r| {
                Ok((
                    r.get::<_, String>(0)?,
                    r.get::<_, String>(1)?,
                    r.get::<_, Option<String>>(2)?,
                ))
            })
            .map_err(self.sql("reading drives"))?
            .collect::<rusqlite::Result<Vec<_>>>()
            .map_err(self.sql("reading drives"))?;
        rows.reverse();
        let mut out = Vec::with_capacity(rows.len());
        for (drive, json, hashes) in rows {
            let d: crate::model::Drive = serde_json::from_str(&json)
                .map_err(|e| self.corrupt(&format!("drive {drive} of {vehicle}"), e))?;
            let hashes = hashes
                .unwrap_or_default()
                .split_whitespace()
                .map(str::to_string)
                .collect();
            out.push((d, hashes));
        }
        Ok(out)
    }

    /// The drive verdicts of `vehicle`, oldest first: (drive, classification, records).
    pub fn drives(&self, vehicle: &str) -> Result<Vec<(String, String, usize)>> {
        let Some(vid) = self.vehicle_id(vehicle)? else {
            return Ok(Vec::new());
        };
        Ok(self
            .drive_statuses(vid, vehicle)?
            .into_iter()
            .rev()
            .map(|d| (d.drive, d.classification.to_string(), d.n_records))
            .collect())
    }

    /// The features of a record.
    pub fn features(&self, record_id: i64) -> Result<RecordFeatures> {
        let json: String = self
            .conn
            .query_row(
                "SELECT json FROM features WHERE record_id = ?1",
                [record_id],
                |r| r.get(0),
            )
            .map_err(self.sql("reading features"))?;
        serde_json::from_str(&json)
            .map_err(|e| self.corrupt(&format!("features of record {record_id}"), e))
    }

    /// The nominal records of a vehicle with their features, oldest first.
    pub fn nominal_records(&self, vehicle: &str) -> Result<Vec<(RecordRow, RecordFeatures)>> {
        let vid = self.require_vehicle(vehicle)?;
        let mut st = self
            .conn
            .prepare(
                "SELECT r.id, r.file_name, r.content_hash, r.ingested, r.condition, r.road, f.json
                 FROM records r JOIN features f ON f.record_id = r.id
                 WHERE r.vehicle_id = ?1 AND r.condition = 'nominal' ORDER BY r.id",
            )
            .map_err(self.sql("reading nominal records"))?;
        let rows = st
            .query_map([vid], |r| Ok((row_to_record(r)?, r.get::<_, String>(6)?)))
            .map_err(self.sql("reading nominal records"))?
            .collect::<rusqlite::Result<Vec<_>>>()
            .map_err(self.sql("reading nominal records"))?;
        rows.into_iter()
            .map(|(row, json)| {
                let row = row.map_err(|e| self.corrupt("a record row", e))?;
                let f = serde_json::from_str(&json).map_err(|e| {
                    self.corrupt(&format!("features of record {}", row.file_name), e)
                })?;
                Ok((row, f))
            })
            .collect()
    }

    /// Every record of a vehicle, oldest first, with its features and its latest check (none for
    /// records never checked).
    pub fn records_with_checks(
        &self,
        vehicle: &str,
    ) -> Result<Vec<(RecordRow, RecordFeatures, Option<Assessment>)>> {
        let vid = self.require_vehicle(vehicle)?;
        let mut st = self
            .conn
            .prepare(
                "SELECT r.id, r.file_name, r.content_hash, r.ingested, r.condition, r.road, f.json,
                        (SELECT c.json FROM checks c WHERE c.record_id = r.id
                         ORDER BY c.id DESC LIMIT 1)
                 FROM records r JOIN features f ON f.record_id = r.id
                 WHERE r.vehicle_id = ?1 ORDER BY r.id",
            )
            .map_err(self.sql("reading records"))?;
        let rows = st
            .query_map([vid], |r| {
                Ok((
                    row_to_record(r)?,
                    r.get::<_, String>(6)?,
                    r.get::<_, Option<String>>(7)?,
                ))
            })
            .map_err(self.sql("reading records"))?
            .collect::<rusqlite::Result<Vec<_>>>()
            .map_err(self.sql("reading records"))?;
        rows.into_iter()
            .map(|(row, json, check)| {
                let row = row.map_err(|e| self.corrupt("a record row", e))?;
                let f = serde_json::from_str(&json).map_err(|e| {
                    self.corrupt(&format!("features of record {}", row.file_name), e)
                })?;
                let a = match check {
                    Some(c) => Some(serde_json::from_str(&c).map_err(|e| {
                        self.corrupt(&format!("the check of {}", row.file_name), e)
                    })?),
                    None => None,
                };
                Ok((row, f, a))
            })
            .collect()
    }

    /// Stores a model set as the vehicle's next version (set in `set.version`).
    pub fn save_model_set(&mut self, set: &mut ModelSet) -> Result<i64> {
        let vid = self.require_vehicle(&set.vehicle)?;
        let path = self.path.clone();
        let err = sql_error(&path, "storing a model set");
        let tx = self
            .conn
            .transaction_with_behavior(rusqlite::TransactionBehavior::Immediate)
            .map_err(err)?;
        let last: Option<i64> = tx
            .query_row(
                "SELECT MAX(version) FROM model_sets WHERE vehicle_id = ?1",
                [vid],
                |r| r.get(0),
            )
            .map_err(err)?;
        set.version = last.unwrap_or(0) + 1;
        let json = to_json_checked(
            &*set,
            &format!("the model set of '{}'", vibmode_core::quoted(&set.vehicle)),
        )?;
        tx.execute(
            "INSERT INTO model_sets (vehicle_id, version, created, json) VALUES (?1, ?2, ?3, ?4)",
            params![vid, set.version, now_utc(), json],
        )
        .map_err(err)?;
        tx.commit().map_err(err)?;
        Ok(set.version)
    }

    /// The settings new records are analysed with: those given to `fleet init --config`, or
    /// the defaults.
    pub fn config(&self) -> Result<FleetConfig> {
        let json = self.meta_value("fleet_config", "reading the settings")?;
        match json {
            None => Ok(FleetConfig::default()),
            Some(j) => {
                let cfg: FleetConfig =
                    serde_json::from_str(&j).map_err(|e| self.corrupt("the settings", e))?;
                cfg.validate()?;
                Ok(cfg)
            }
        }
    }

    /// Stores the settings. Refused when the store already holds records and the settings
    /// differ (their features were computed with the old ones); the same settings again are
    /// a no-op.
    ///
    /// Settings stored by an older vibmode that can no longer be read are replaced while the
    /// store holds no record.
    pub fn set_config(&mut self, cfg: &FleetConfig) -> Result<()> {
        cfg.validate()?;
        // Read back as a later command will: a setting that would not read is never stored.
        let json = to_json_checked(cfg, "the settings")?;
        let back: FleetConfig =
            serde_json::from_str(&json).map_err(|e| FleetError::NotStorable {
                what: "the settings".into(),
                reason: e.to_string(),
            })?;
        back.validate()?;
        // Compared as stored: serde_json may parse a float one unit in the last place off, so
        // the same file again must compare what it reads back as.
        if self.config().ok().as_ref() == Some(&back) {
            return Ok(());
        }
        let path = self.path.clone();
        let err = sql_error(&path, "storing the settings");
        let tx = self
            .conn
            .transaction_with_behavior(rusqlite::TransactionBehavior::Immediate)
            .map_err(err)?;
        let records: i64 = tx
            .query_row("SELECT COUNT(*) FROM records", [], |r| r.get(0))
            .map_err(err)?;
        if records > 0 {
            return Err(FleetError::ConfigAfterRecords {
                path: path.clone(),
                records,
            });
        }
        tx.execute(
            "INSERT INTO meta (key, value) VALUES ('fleet_config', ?1)
             ON CONFLICT(key) DO UPDATE SET value = excluded.value",
            [json],
        )
        .map_err(err)?;
        tx.commit().map_err(err)
    }

    /// The newest model set of a vehicle, if any.
    pub fn latest_model_set(&self, vehicle: &str) -> Result<Option<ModelSet>> {
        let vid = self.require_vehicle(vehicle)?;
        let json: Option<String> = self
            .conn
            .query_row(
                "SELECT json FROM model_sets WHERE vehicle_id = ?1 ORDER BY version DESC LIMIT 1",
                [vid],
                |r| r.get(0),
            )
            .optional()
            .map_err(self.sql("reading a model set"))?;
        json.map(|j| {
            serde_json::from_str(&j)
                .map_err(|e| self.corrupt(&format!("the model set of '{vehicle}'"), e))
        })
        .transpose()
    }

    /// Stores the outcome of a check.
    pub fn save_check(&mut self, record_id: i64, version: i64, a: &Assessment) -> Result<()> {
        let json = to_json_checked(a, "the check")?;
        let path = self.path.clone();
        let err = sql_error(&path, "storing a check");
        let tx = self
            .conn
            .transaction_with_behavior(rusqlite::TransactionBehavior::Immediate)
            .map_err(err)?;
        tx.execute(
            "INSERT INTO checks (record_id, model_version, checked, classification, json)
             VALUES (?1, ?2, ?3, ?4, ?5)",
            params![
                record_id,
                version,
                now_utc(),
                a.classification.to_string(),
                json
            ],
        )
        .map_err(err)?;
        tx.commit().map_err(err)?;
        Ok(())
    }

    /// Status of every vehicle, with its `last` latest checks.
    pub fn status(&self, last: usize) -> Result<Vec<VehicleStatus>> {
        let mut out = Vec::new();
        for v in self.vehicles()? {
            let vid = self.require_vehicle(&v)?;
            let count = |cond: &str| -> Result<usize> {
                self.conn
                    .query_row(
                        "SELECT COUNT(*) FROM records WHERE vehicle_id = ?1 AND condition = ?2",
                        params![vid, cond],
                        |r| r.get::<_, i64>(0),
                    )
                    .map(|n| n.max(0) as usize)
                    .map_err(self.sql("counting records"))
            };
            let baseline_version: Option<i64> = self
                .conn
                .query_row(
                    "SELECT MAX(version) FROM model_sets WHERE vehicle_id = ?1",
                    [vid],
                    |r| r.get(0),
                )
                .map_err(self.sql("reading model sets"))?;
            let mut st = self
                .conn
                .prepare(
                    "SELECT r.file_name, c.json FROM checks c JOIN records r ON r.id = c.record_id
                     WHERE r.vehicle_id = ?1 ORDER BY c.id DESC LIMIT ?2",
                )
                .map_err(self.sql("reading checks"))?;
            let rows = st
                .query_map(params![vid, last as i64], |r| {
                    Ok((r.get::<_, String>(0)?, r.get::<_, String>(1)?))
                })
                .map_err(self.sql("reading checks"))?
                .collect::<rusqlite::Result<Vec<_>>>()
                .map_err(self.sql("reading checks"))?;
            let mut last_checks = Vec::new();
            for (file, json) in rows {
                let a: Assessment = serde_json::from_str(&json)
                    .map_err(|e| self.corrupt(&format!("the check of {file}"), e))?;
                last_checks.push((file, a.classification, a.summary));
            }
            let drives = self.drive_statuses(vid, &v)?;
            let latest = self.latest_model_set(&v)?;
            let held_out = latest
                .as_ref()
                .filter(|set| !set.held_out_drives.is_empty())
                .map(|set| HeldOutCount {
                    drives: set.held_out_drives.len(),
                    flagged: set
                        .held_out_drives
                        .iter()
                        .filter(|d| d.classification != Classification::Normal)
                        .count(),
                });
            let suspension = match self.vehicle_model(&v)? {
                // Said, not left out: without the fit a lost spring may pass unseen.
                None => Some(NO_MODEL_FILE_STATUS.to_string()),
                Some((sha, _)) => Some(match latest {
                    None => "model file registered; no baseline yet".to_string(),
                    Some(set) => match &set.suspension {
                        Some(r) if r.model_sha256 == sha => format!(
                            "model file registered; baseline version {} fits the suspension ({} nominal records): springs and dampers scored per drive, springs also over the last {} drives",
                            set.version,
                            r.fit.records,
                            crate::suspension::TREND_DRIVES
                        ),
                        _ => format!(
                            "model file registered, but baseline version {} has no fit of it: drives are checked without the suspension fit until nominal records ingested since and a new baseline",
                            set.version
                        ),
                    },
                }),
            };
            out.push(VehicleStatus {
                vehicle: v,
                n_nominal: count("nominal")?,
                n_test: count("test")?,
                baseline_version,
                last_checks,
                latest_drive: drives.first().cloned(),
                earlier_flag: EarlierFlag::of(&drives),
                drives: drives.into_iter().take(last).collect(),
                suspension,
                held_out,
            });
        }
        Ok(out)
    }
}

/// The stored drive of vehicle `vid` named `drive` against model set `model_version` whose
/// records are exactly `record_ids` (in any order, repeats counted once), if any.
fn same_drive(
    tx: &rusqlite::Transaction<'_>,
    vid: i64,
    drive: &str,
    model_version: i64,
    record_ids: &[i64],
) -> rusqlite::Result<Option<i64>> {
    let mut want = record_ids.to_vec();
    want.sort_unstable();
    want.dedup();
    let mut st = tx.prepare(
        "SELECT x.drive_id, x.record_id FROM drive_records x JOIN drives d ON d.id = x.drive_id
         WHERE d.vehicle_id = ?1 AND d.drive = ?2 AND d.model_version = ?3
         ORDER BY x.drive_id, x.record_id",
    )?;
    let rows = st
        .query_map(params![vid, drive, model_version], |r| {
            Ok((r.get::<_, i64>(0)?, r.get::<_, i64>(1)?))
        })?
        .collect::<rusqlite::Result<Vec<_>>>()?;
    Ok(rows
        .chunk_by(|a, b| a.0 == b.0)
        .find(|g| g.iter().map(|r| r.1).eq(want.iter().copied()))
        .map(|g| g[0].0))
}

impl Store {
    /// The vehicle's [`EarlierFlag`]: a drive flagged `vehicle` or `both` against the baseline
    /// of its latest drive, when the latest is not (what `status` shows beneath its row).
    pub fn earlier_flag(&self, vehicle: &str) -> Result<Option<EarlierFlag>> {
        let vid = self.require_vehicle(vehicle)?;
        Ok(EarlierFlag::of(&self.drive_statuses(vid, vehicle)?))
    }

    /// Every drive verdict of the vehicle `vid`, newest first, each with the start of its run
    /// of equal verdicts. A drive's time is when it was driven where its records' starts are
    /// known, else when it was checked (checked in the order stored where times are equal), so
    /// a drive of last week checked today takes its place in last week.
    fn drive_statuses(&self, vid: i64, vehicle: &str) -> Result<Vec<DriveStatus>> {
        let mut st = self
            .conn
            .prepare(
                "SELECT d.drive, d.checked, d.json,
                        (SELECT COUNT(*) FROM drive_records r WHERE r.drive_id = d.id),
                        d.model_version
                 FROM drives d WHERE d.vehicle_id = ?1 ORDER BY d.id",
            )
            .map_err(self.sql("reading drives"))?;
        let rows = st
            .query_map([vid], |r| {
                Ok((
                    r.get::<_, String>(0)?,
                    r.get::<_, String>(1)?,
                    r.get::<_, String>(2)?,
                    r.get::<_, i64>(3)?,
                    r.get::<_, i64>(4)?,
                ))
            })
            .map_err(self.sql("reading drives"))?
            .collect::<rusqlite::Result<Vec<_>>>()
            .map_err(self.sql("reading drives"))?;
        let mut parsed = Vec::with_capacity(rows.len());
        for (drive, checked, json, n, version) in rows {
            let d: crate::model::Drive = serde_json::from_str(&json)
                .map_err(|e| self.corrupt(&format!("drive {drive} of {vehicle}"), e))?;
            let driven = d.start_unix_s.and_then(utc_of_unix);
            parsed.push((drive, checked, d, n, driven, version));
        }
        // Stable: drives of equal time stay in the order they were stored.
        parsed.sort_by(|a, b| {
            let at = a.4.as_deref().unwrap_or(&a.1);
            let bt = b.4.as_deref().unwrap_or(&b.1);
            at.cmp(bt)
        });
        let mut out: Vec<DriveStatus> = Vec::with_capacity(parsed.len());
        for (drive, checked, d, n, driven, model_version) in parsed {
            let class = d.assessment.classification;
            let since = match out.last() {
                Some(prev) if prev.classification == class => prev.since.clone(),
                _ => driven.clone().unwrap_or_else(|| checked.clone()),
            };
            // Each flagged vehicle feature against its own limit (a drive's fit and the spring
            // trend have limits of their own): the largest ratio.
            let z_over_limit = d
                .assessment
                .evidence
                .iter()
                .filter(|e| e.meta.group == crate::model::Group::Vehicle && e.limit > 0.0)
                .map(|e| e.z.abs() / e.limit)
                .reduce(f64::max);
            out.push(DriveStatus {
                drive,
                checked,
                classification: class,
                corner: d.corner.map(|c| c.to_string()),
                component: d.assessment.component,
                summary: d.assessment.summary.clone(),
                vehicle_z_over_limit: z_over_limit,
                false_alarm_rate: d.false_alarm_rate,
                n_records: n.max(0) as usize,
                driven,
                since,
                model_version,
            });
        }
        out.reverse();
        Ok(out)
    }
}

/// One record of [`Store::store_batch`].
#[derive(Clone, Debug)]
pub struct BatchItem<'a> {
    /// The record.
    pub record: NewRecord<'a>,
    /// Its features (stored when the record is new).
    pub features: &'a RecordFeatures,
    /// A check to store with it: the model-set version and the verdict.
    pub check: Option<(i64, &'a Assessment)>,
    /// When the vehicle already has the record: replace its stored features with `features`
    /// (its body equations added after the model file was registered).
    pub refresh_features: bool,
}

/// Where [`Store::store_batch`] put a record.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Stored {
    /// Its row id.
    pub record_id: i64,
    /// False when the vehicle already had the content (nothing was stored but the check).
    pub inserted: bool,
}

/// JSON of `value`, read back as a later command will read it: a value that does not read back
/// (a NaN or infinity, written as null) is refused before anything is stored.
fn to_json_checked<T: Serialize + DeserializeOwned>(value: &T, what: &str) -> Result<String> {
    let fail = |e: serde_json::Error| FleetError::NotStorable {
        what: what.to_string(),
        reason: e.to_string(),
    };
    let json = serde_json::to_string(value).map_err(fail)?;
    serde_json::from_str::<T>(&json).map_err(fail)?;
    Ok(json)
}

type RowResult = std::result::Result<RecordRow, String>;

fn row_to_record(r: &rusqlite::Row<'_>) -> rusqlite::Result<RowResult> {
    let cond: String = r.get(4)?;
    let condition = match cond.parse::<Condition>() {
        Ok(c) => c,
        Err(e) => return Ok(Err(e.to_string())),
    };
    Ok(Ok(RecordRow {
        id: r.get(0)?,
        file_name: r.get(1)?,
        content_hash: r.get(2)?,
        ingested: r.get(3)?,
        condition,
        road: r.get(5)?,
    }))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::features::{ChannelFeatures, RecordFeatures};
    use vibmode_analysis::{Corner, Role};

    fn features() -> RecordFeatures {
        RecordFeatures {
            analysis_fs_hz: 50.0,
            duration_s: 10.24,
            n_segments: 1,
            bands_hz: vec![[2.0, 5.0]],
            channels: vec![ChannelFeatures {
                name: "RL_unsprung".into(),
                role: Role::Unsprung,
                corner: Some(Corner::RL),
                band_rms: vec![Some(0.5)],
                modes: Vec::new(),
                ratio_band_rms: None,
            }],
            transmissibility: Vec::new(),
            notes: Vec::new(),
            body_spectra: None,
            sensor_faults: Vec::new(),
            line_free: None,
            suspension: None,
            start_unix_s: None,
        }
    }

    /// A store of schema 1 (before drives) opens, is migrated to the current schema, keeps its
    /// records and stores drives.
    #[test]
    fn a_schema_1_store_is_migrated_and_keeps_its_records() {
        let d = tempfile::tempdir().expect("tmp");
        let path = d.path().join("old.db");
        {
            let c = Connection::open(&path).expect("create");
            c.execute_batch(MIGRATIONS[0]).expect("schema 1");
            c.execute_batch(
                "PRAGMA user_version = 1;
                 INSERT INTO vehicles (name, created) VALUES ('bus-1', 'then');",
            )
            .expect("v1");
        }
        let s = Store::open(&path).expect("open");
        assert_eq!(s.schema_version().expect("version"), SCHEMA_VERSION);
        assert_eq!(s.vehicles().expect("vehicles"), vec!["bus-1".to_string()]);
        assert!(s.drives("bus-1").expect("drives").is_empty());
        // Migration 3: the vehicle model table exists, empty.
        assert!(s.vehicle_model("bus-1").expect("model").is_none());
    }

    /// Migration 4: a store that held records keeps SHA-256 as its records' key (their hashes
    /// cannot be recomputed), and its records are still found by it; a store made now, or one
    /// migrated without records, keys by BLAKE3.
    #[test]
    fn the_content_hash_is_kept_by_a_store_with_records_and_blake3_otherwise() {
        let d = tempfile::tempdir().expect("tmp");
        let bytes = b"time,z\n0,1\n";
        let sha = ContentHash::Sha256.hex(bytes);
        for (name, with_record) in [("old.db", true), ("empty.db", false)] {
            let path = d.path().join(name);
            {
                let c = Connection::open(&path).expect("create");
                for m in &MIGRATIONS[..3] {
                    c.execute_batch(m).expect("schema 3");
                }
                c.execute_batch(
                    "PRAGMA user_version = 3;
                     INSERT INTO vehicles (name, created) VALUES ('bus-1', 'then');",
                )
                .expect("v3");
                if with_record {
                    c.execute(
                        "INSERT INTO records (vehicle_id, sha256, file_name, ingested, condition,
                         metadata) VALUES (1, ?1, 'r.csv', 'then', 'nominal', '{}')",
                        params![sha],
                    )
                    .expect("record");
                }
            }
            let s = Store::open(&path).expect("open");
            assert_eq!(s.schema_version().expect("version"), SCHEMA_VERSION);
            let kind = s.content_hash().expect("hash");
            if with_record {
                assert_eq!(kind, ContentHash::Sha256);
                let row = s.find_record("bus-1", &kind.hex(bytes)).expect("find");
                assert_eq!(row.map(|r| r.file_name), Some("r.csv".to_string()));
            } else {
                assert_eq!(kind, ContentHash::Blake3);
            }
        }
        let (s, _) = Store::init(&d.path().join("new.db")).expect("init");
        assert_eq!(s.content_hash().expect("hash"), ContentHash::Blake3);
    }

    #[test]
    fn fresh_store_reopens_with_its_schema_version() {
        let d = tempfile::tempdir().expect("tempdir");
        let p = d.path().join("f.db");
        let (s, created) = Store::init(&p).expect("init");
        assert!(created);
        assert_eq!(s.schema_version().expect("version"), SCHEMA_VERSION);
        drop(s);
        let (s, created) = Store::init(&p).expect("init again");
        assert!(!created);
        assert_eq!(s.schema_version().expect("version"), SCHEMA_VERSION);
        let s = Store::open(&p).expect("open");
        assert!(s.vehicles().expect("vehicles").is_empty());
    }

    #[test]
    fn foreign_corrupt_newer_and_missing_files_are_clear_errors() {
        let d = tempfile::tempdir().expect("tempdir");
        // Random bytes (a fixed pseudo-random sequence, not a chosen pattern).
        let junk: Vec<u8> = (0u32..8192)
            .map(|i| (i.wrapping_mul(2_654_435_761) >> 13) as u8)
            .collect();
        let p = d.path().join("junk.db");
        std::fs::write(&p, &junk).expect("write");
        let e = Store::open(&p).expect_err("junk opens");
        assert!(matches!(e, FleetError::NotAStore { .. }), "{e}");
        let e = Store::init(&p).expect_err("junk inits");
        assert!(e.to_string().contains("not a vibmode fleet store"), "{e}");
        // A foreign SQLite database.
        let q = d.path().join("other.db");
        let c = Connection::open(&q).expect("sqlite");
        c.execute_batch("CREATE TABLE t (x); PRAGMA user_version = 1;")
            .expect("foreign");
        drop(c);
        assert!(matches!(Store::open(&q), Err(FleetError::NotAStore { .. })));
        // init refuses it too and leaves it byte for byte (its journal mode not switched).
        let before = std::fs::read(&q).expect("read");
        assert!(matches!(Store::init(&q), Err(FleetError::NotAStore { .. })));
        assert_eq!(std::fs::read(&q).expect("read"), before);
        assert!(!d.path().join("other.db-wal").exists());
        // A newer schema.
        let r = d.path().join("newer.db");
        drop(Store::init(&r).expect("init"));
        let c = Connection::open(&r).expect("sqlite");
        c.execute_batch("PRAGMA user_version = 99;").expect("bump");
        drop(c);
        match Store::open(&r) {
            Err(FleetError::NewerSchema { found: 99, .. }) => {}
            other => panic!("{other:?}"),
        }
        assert!(matches!(
            Store::open(&d.path().join("none.db")),
            Err(FleetError::NoStore { .. })
        ));
    }

    /// Features of one RL corner whose transmissibility is `t` (with and without lines alike),
    /// with the line-free values when `line_free`.
    fn corner_features(t: f64, line_free: bool) -> RecordFeatures {
        let mut f = features();
        f.transmissibility = vec![crate::features::CornerTransmissibility {
            corner: Corner::RL,
            sprung: "RL_sprung".into(),
            unsprung: "RL_unsprung".into(),
            values: vec![Some(t)],
            h1: vec![Some(t)],
        }];
        f.line_free = line_free.then(|| crate::features::LineFree {
            line_bins_hz: Vec::new(),
            h1: vec![vec![Some(t)]],
            ratio_band_rms: vec![None],
            noise_density: Vec::new(),
            bins: None,
        });
        f
    }

    /// Nominal records stored before the line-free features: with fewer than `min_nominal`
    /// newer ones the baseline is refused naming both counts and nothing is stored; a model set
    /// built from them (stored by an older version) is refused by a check with the fix; with
    /// enough newer records the baseline is built from those alone, says so, and is accepted.
    #[test]
    fn records_and_baselines_before_the_line_free_features_are_named_not_mixed() {
        let d = tempfile::tempdir().expect("tempdir");
        let (mut s, _) = Store::init(&d.path().join("f.db")).expect("init");
        let cfg = FleetConfig::default();
        let insert = |s: &mut Store, i: usize, line_free: bool| {
            let sha = format!("sha{i}");
            let name = format!("r{i}.csv");
            let rec = NewRecord {
                vehicle: "bus-1",
                content_hash: &sha,
                file_name: &name,
                condition: Condition::Nominal,
                road: Some("B"),
                metadata: serde_json::json!({}),
            };
            let t = 0.5 + 0.01 * i as f64;
            s.insert_record(&rec, &corner_features(t, line_free))
                .expect("insert");
        };
        for i in 0..6 {
            insert(&mut s, i, false);
        }
        let e = crate::fleet::build_baseline(&mut s, "bus-1", &cfg).expect_err("all old");
        assert!(
            matches!(
                e,
                FleetError::NominalBeforeLineFree {
                    old: 6,
                    current: 0,
                    needed: 5,
                    ..
                }
            ),
            "{e}"
        );
        assert_eq!(s.latest_model_set("bus-1").expect("none"), None);
        // A model set of the older features, as an older version stored it.
        let old: Vec<RecordFeatures> = (0..6)
            .map(|i| corner_features(0.5 + 0.01 * i as f64, false))
            .collect();
        let names: Vec<String> = (0..6).map(|i| format!("r{i}.csv")).collect();
        let mut set = crate::model::build_model_set("bus-1", &names, &old, &cfg).expect("old set");
        assert!(!set.line_free);
        s.save_model_set(&mut set).expect("save");
        let e = crate::fleet::require_baseline(&s, "bus-1").expect_err("stale");
        assert!(
            matches!(e, FleetError::StaleBaseline { version: 1, .. }),
            "{e}"
        );
        assert!(e.to_string().contains("build it again"), "{e}");
        for i in 6..11 {
            insert(&mut s, i, true);
        }
        let set = crate::fleet::build_baseline(&mut s, "bus-1", &cfg).expect("line-free");
        assert!(set.line_free);
        assert_eq!(
            set.records,
            (6..11).map(|i| format!("r{i}.csv")).collect::<Vec<_>>()
        );
        assert!(set
            .features
            .iter()
            .any(|f| f.meta.key.starts_with("transh1lf:")));
        assert!(set
            .notes
            .iter()
            .any(|n| n.starts_with("6 nominal record(s) stored before")));
        assert!(crate::fleet::require_baseline(&s, "bus-1").is_ok());
    }

    #[test]
    fn the_same_content_twice_is_one_record() {
        let d = tempfile::tempdir().expect("tempdir");
        let (mut s, _) = Store::init(&d.path().join("f.db")).expect("init");
        let rec = NewRecord {
            vehicle: "bus-1",
            content_hash: "abc",
            file_name: "a.csv",
            condition: Condition::Nominal,
            road: Some("B"),
            metadata: serde_json::json!({}),
        };
        let id = s.insert_record(&rec, &features()).expect("insert");
        let found = s.find_record("bus-1", "abc").expect("find");
        assert_eq!(found.map(|r| r.id), Some(id));
        // The same content again (another process, a second file) is the same row.
        assert_eq!(s.insert_record(&rec, &features()).expect("again"), id);
        assert_eq!(s.nominal_records("bus-1").expect("nominal").len(), 1);
        assert_eq!(s.features(id).expect("features"), features());
        assert!(matches!(
            s.latest_model_set("bus-9"),
            Err(FleetError::UnknownVehicle { .. })
        ));
        assert_eq!(s.latest_model_set("bus-1").expect("none"), None);
    }

    #[test]
    fn nothing_a_later_command_cannot_read_is_stored() {
        let d = tempfile::tempdir().expect("tempdir");
        let (mut s, _) = Store::init(&d.path().join("f.db")).expect("init");
        // Settings with a NaN (as an older vibmode stored them: null) make the store unreadable;
        // while it holds no record, good settings replace them.
        s.conn
            .execute(
                "INSERT INTO meta (key, value) VALUES ('fleet_config', '{\"transmissibility_min_hz\": null}')",
                [],
            )
            .expect("bad settings");
        assert!(s.config().is_err());
        let good = FleetConfig {
            false_alarm_rate: 0.02,
            ..FleetConfig::default()
        };
        s.set_config(&good).expect("repaired");
        assert_eq!(s.config().expect("readable"), good);
        // Settings that fail validation are refused before anything is written.
        let bad = FleetConfig {
            transmissibility_min_hz: f64::NAN,
            ..FleetConfig::default()
        };
        assert!(s.set_config(&bad).is_err());
        assert_eq!(s.config().expect("unchanged"), good);
        // A check with a NaN score is refused (it would be stored as null and never read).
        let rec = NewRecord {
            vehicle: "bus-1",
            content_hash: "abc",
            file_name: "a.csv",
            condition: Condition::Test,
            road: None,
            metadata: serde_json::json!({}),
        };
        let mut a = Assessment::normal_for_tests();
        a.scores.vehicle_max_abs_z = f64::NAN;
        let f = features();
        let e = s
            .store_batch(&[BatchItem {
                record: rec,
                features: &f,
                check: Some((1, &a)),
                refresh_features: false,
            }])
            .expect_err("NaN score");
        assert!(matches!(e, FleetError::NotStorable { .. }), "{e}");
        // All or nothing: the record was not stored either.
        assert_eq!(s.find_record("bus-1", "abc").expect("find"), None);
    }
}
