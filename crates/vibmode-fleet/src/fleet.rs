//! The operations of `vibmode fleet`: ingest, baseline, check, over a [`Store`].

use std::path::Path;

use serde::{Deserialize, Serialize};
use sha2::{Digest, Sha256};
use vibmode_core::Recording;
use vibmode_signal::ReadOptions;

use crate::config::FleetConfig;
use crate::error::{FleetError, Result};
use crate::features::compute_features;
use crate::model::{assess, build_model_set, Assessment, ModelSet};
use crate::store::{Condition, NewRecord, Store};

/// SHA-256 of bytes, lower-case hex.
pub fn sha256_hex(bytes: &[u8]) -> String {
    let digest = Sha256::digest(bytes);
    digest.iter().map(|b| format!("{b:02x}")).collect()
}

/// SHA-256 of a recording's content (rate, channel names and samples), for records that are
/// not files.
pub fn recording_hash(rec: &Recording) -> String {
    let mut h = Sha256::new();
    h.update(rec.fs_hz.to_le_bytes());
    for c in &rec.channels {
        h.update(c.name.as_bytes());
        h.update([0u8]);
        for s in &c.samples {
            h.update(s.to_le_bytes());
        }
    }
    h.finalize().iter().map(|b| format!("{b:02x}")).collect()
}

/// Checks a vehicle id: 1 to 64 printable characters without spaces.
pub fn check_vehicle_id(vehicle: &str) -> Result<()> {
    let ok = !vehicle.is_empty()
        && vehicle.chars().count() <= 64
        && vehicle
            .chars()
            .all(|c| !c.is_whitespace() && !c.is_control());
    if ok {
        Ok(())
    } else {
        Err(FleetError::BadVehicleId {
            vehicle: vehicle.to_string(),
        })
    }
}

/// Outcome of ingesting one record.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Ingested {
    /// File (or record) name.
    pub file: String,
    /// Record id in the store.
    pub record_id: i64,
    /// True when the same content was already stored for this vehicle (nothing was done).
    pub already_stored: bool,
    /// Notes on features that could not be computed.
    pub notes: Vec<String>,
}

/// How a record is labelled when ingested.
#[derive(Clone, Debug)]
pub struct IngestLabels<'a> {
    /// Vehicle id.
    pub vehicle: &'a str,
    /// Nominal or test.
    pub condition: Condition,
    /// Road label.
    pub road: Option<&'a str>,
}

/// Ingests a recording with a known content hash: a no-op if the vehicle already has it.
pub fn ingest_recording(
    store: &mut Store,
    labels: &IngestLabels<'_>,
    name: &str,
    sha256: &str,
    rec: &Recording,
    cfg: &FleetConfig,
) -> Result<Ingested> {
    check_vehicle_id(labels.vehicle)?;
    if let Some(row) = store.find_record(labels.vehicle, sha256)? {
        return Ok(Ingested {
            file: name.to_string(),
            record_id: row.id,
            already_stored: true,
            notes: Vec::new(),
        });
    }
    let features = compute_features(name, rec, cfg)?;
    let metadata = serde_json::json!({
        "fs_hz": rec.fs_hz,
        "n_samples": rec.len(),
        "channels": rec.names(),
    });
    let id = store.insert_record(
        &NewRecord {
            vehicle: labels.vehicle,
            sha256,
            file_name: name,
            condition: labels.condition,
            road: labels.road,
            metadata,
        },
        &features,
    )?;
    Ok(Ingested {
        file: name.to_string(),
        record_id: id,
        already_stored: false,
        notes: features.notes,
    })
}

/// The name a record file is stored and reported under: the path as the user gave it, not
/// its base name, so that `run1/record_01.wav` and `run2/record_01.wav` stay apart in the
/// tables and the JSON. The CLI and the Python workers (`vibmode.fleet.features`) both use it.
pub fn record_file_name(path: &Path) -> String {
    path.display().to_string()
}

fn file_name(path: &Path) -> String {
    record_file_name(path)
}

fn hash_file(path: &Path) -> Result<String> {
    let bytes = std::fs::read(path).map_err(|e| FleetError::Io {
        path: path.display().to_string(),
        reason: e.to_string(),
    })?;
    Ok(sha256_hex(&bytes))
}

/// Ingests a file (read with `opts`): a no-op when its bytes are already stored for the vehicle.
pub fn ingest_file(
    store: &mut Store,
    labels: &IngestLabels<'_>,
    path: &Path,
    opts: &ReadOptions,
    cfg: &FleetConfig,
) -> Result<Ingested> {
    check_vehicle_id(labels.vehicle)?;
    let sha = hash_file(path)?;
    if let Some(row) = store.find_record(labels.vehicle, &sha)? {
        return Ok(Ingested {
            file: file_name(path),
            record_id: row.id,
            already_stored: true,
            notes: Vec::new(),
        });
    }
    let rec = vibmode_signal::read_path(path, opts)?;
    ingest_recording(store, labels, &file_name(path), &sha, &rec, cfg)
}

/// Builds and stores the next model-set version of a vehicle from its nominal records.
pub fn build_baseline(store: &mut Store, vehicle: &str, cfg: &FleetConfig) -> Result<ModelSet> {
    let nominal = store.nominal_records(vehicle)?;
    let names: Vec<String> = nominal.iter().map(|(r, _)| r.file_name.clone()).collect();
    let feats: Vec<_> = nominal.into_iter().map(|(_, f)| f).collect();
    let mut set = build_model_set(vehicle, &names, &feats, cfg)?;
    store.save_model_set(&mut set)?;
    Ok(set)
}

/// One checked record.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Checked {
    /// File (or record) name.
    pub file: String,
    /// Record id in the store.
    pub record_id: i64,
    /// The model-set version it was scored against.
    pub model_version: i64,
    /// The verdict.
    #[serde(flatten)]
    pub assessment: Assessment,
}

/// The vehicle's latest model set; errors name the fix when there is none.
pub fn require_baseline(store: &Store, vehicle: &str) -> Result<ModelSet> {
    store
        .latest_model_set(vehicle)?
        .ok_or_else(|| FleetError::NoBaseline {
            vehicle: vehicle.to_string(),
        })
}

/// Checks a recording (stored as a test record unless already stored) against `set`.
pub fn check_recording(
    store: &mut Store,
    set: &ModelSet,
    name: &str,
    sha256: &str,
    rec: &Recording,
) -> Result<Checked> {
    let labels = IngestLabels {
        vehicle: &set.vehicle,
        condition: Condition::Test,
        road: None,
    };
    check_layout(set, name, rec)?;
    let ing = ingest_recording(store, &labels, name, sha256, rec, &set.config)?;
    finish_check(store, set, ing)
}

/// A record must have the channels the baseline was built from (same names, any order); else
/// an error, before anything is stored.
fn check_layout(set: &ModelSet, name: &str, rec: &Recording) -> Result<()> {
    if set.channels.is_empty() {
        return Ok(());
    }
    let mut found: Vec<&str> = rec.channels.iter().map(|c| c.name.as_str()).collect();
    let mut base: Vec<&str> = set.channels.iter().map(String::as_str).collect();
    found.sort_unstable();
    base.sort_unstable();
    if found == base {
        return Ok(());
    }
    Err(FleetError::LayoutDiffers {
        record: name.to_string(),
        vehicle: set.vehicle.clone(),
        found: found.join(", "),
        baseline: base.join(", "),
    })
}

/// Checks a file against `set` (stored as a test record unless already stored).
pub fn check_file(
    store: &mut Store,
    set: &ModelSet,
    path: &Path,
    opts: &ReadOptions,
) -> Result<Checked> {
    let labels = IngestLabels {
        vehicle: &set.vehicle,
        condition: Condition::Test,
        road: None,
    };
    check_vehicle_id(labels.vehicle)?;
    let sha = hash_file(path)?;
    let ing = match store.find_record(labels.vehicle, &sha)? {
        Some(row) => Ingested {
            file: file_name(path),
            record_id: row.id,
            already_stored: true,
            notes: Vec::new(),
        },
        None => {
            let rec = vibmode_signal::read_path(path, opts)?;
            check_layout(set, &file_name(path), &rec)?;
            ingest_recording(store, &labels, &file_name(path), &sha, &rec, &set.config)?
        }
    };
    finish_check(store, set, ing)
}

fn finish_check(store: &mut Store, set: &ModelSet, ing: Ingested) -> Result<Checked> {
    let features = store.features(ing.record_id)?;
    let assessment = assess(set, &features);
    store.save_check(ing.record_id, set.version, &assessment)?;
    Ok(Checked {
        file: ing.file,
        record_id: ing.record_id,
        model_version: set.version,
        assessment,
    })
}
