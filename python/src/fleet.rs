//! Fleet monitoring on the SQLite store (`vibmode-fleet`): init, ingest, baseline, check,
//! status. Every call opens the store, does its work and closes it (SQLite: one writer at a
//! time; see docs/scaling.md).

use crate::signal::read_options;
use pyo3::prelude::*;
use serde::Serialize;
use std::path::PathBuf;
use vibmode_fleet::store::{BatchItem, NewRecord};
use vibmode_fleet::{
    build_baseline, check_drive_files_progress, ingest_files, require_baseline, Condition,
    FleetConfig, IngestLabels, Store,
};
use vibmode_fleet::{ContentHash, FleetError, Ingested, RecordFeatures};

use crate::errors::{fleet_err, json_err};

/// Registers the functions of this module.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(fleet_init, m)?)?;
    m.add_function(wrap_pyfunction!(fleet_settings, m)?)?;
    m.add_function(wrap_pyfunction!(fleet_ingest, m)?)?;
    m.add_function(wrap_pyfunction!(fleet_register, m)?)?;
    m.add_function(wrap_pyfunction!(fleet_model, m)?)?;
    m.add_function(wrap_pyfunction!(fleet_content_hash, m)?)?;
    m.add_function(wrap_pyfunction!(fleet_baseline, m)?)?;
    m.add_function(wrap_pyfunction!(fleet_check, m)?)?;
    m.add_function(wrap_pyfunction!(fleet_status, m)?)?;
    m.add_function(wrap_pyfunction!(fleet_features, m)?)?;
    m.add_function(wrap_pyfunction!(fleet_store_features, m)?)?;
    Ok(())
}

/// Creates the store if needed, with the settings `config_toml` (TOML text of a
/// `FleetConfig`, as `vibmode fleet init --config`; checked before the store is created);
/// returns whether it was created.
#[pyfunction]
#[pyo3(signature = (db, config_toml=None))]
fn fleet_init(db: PathBuf, config_toml: Option<&str>) -> PyResult<bool> {
    let cfg = config_toml
        .map(|t| FleetConfig::from_toml_str(t, "config"))
        .transpose()
        .map_err(fleet_err)?;
    let (mut store, created) = Store::init(&db).map_err(fleet_err)?;
    if let Some(cfg) = &cfg {
        store.set_config(cfg).map_err(fleet_err)?;
    }
    Ok(created)
}

/// The settings new records of the store are analysed with (`Store::config`: those given at
/// init, or the defaults), as JSON.
#[pyfunction]
fn fleet_settings(py: Python<'_>, db: PathBuf) -> PyResult<String> {
    let cfg = py
        .detach(|| Store::open(&db)?.config())
        .map_err(fleet_err)?;
    serde_json::to_string(&cfg).map_err(json_err)
}

/// Settings from JSON (from [`fleet_settings`]), checked; `None`: the defaults.
fn settings_from_json(json: Option<&str>) -> PyResult<FleetConfig> {
    let Some(json) = json else {
        return Ok(FleetConfig::default());
    };
    let cfg: FleetConfig = serde_json::from_str(json).map_err(|e| {
        crate::errors::value_err(format!(
            "settings are not fleet settings ({e}); pass what vibmode.fleet.settings(db) returns"
        ))
    })?;
    cfg.validate().map_err(fleet_err)?;
    Ok(cfg)
}

/// Ingests files for a vehicle; JSON list of `Ingested`.
#[pyfunction]
#[pyo3(signature = (db, vehicle, files, condition="nominal", road=None, fs=None, scale=1.0, unit=None, allow_nonuniform=false, time_unit=None))]
#[allow(clippy::too_many_arguments)]
fn fleet_ingest(
    py: Python<'_>,
    db: PathBuf,
    vehicle: &str,
    files: Vec<PathBuf>,
    condition: &str,
    road: Option<&str>,
    fs: Option<f64>,
    scale: f64,
    unit: Option<String>,
    allow_nonuniform: bool,
    time_unit: Option<&str>,
) -> PyResult<(String, String)> {
    let condition: Condition = condition.parse().map_err(fleet_err)?;
    let opts = read_options(fs, scale, unit, allow_nonuniform, time_unit)?;
    let out = py
        .detach(|| {
            let mut store = Store::open(&db)?;
            let labels = IngestLabels {
                vehicle,
                condition,
                road,
            };
            // The settings the store was initialised with (`fleet init --config`).
            let cfg = store.config()?;
            // All or nothing, as `vibmode fleet ingest`; a folder stands for its recordings.
            let files = vibmode_signal::expand_folders(&files)?;
            let paths: Vec<&std::path::Path> = files.iter().map(|f| f.as_path()).collect();
            ingest_files(&mut store, &labels, &paths, &opts, &cfg)
        })
        .map_err(fleet_err)?;
    let text = vibmode_fleet::text::ingest_text(&out, vehicle, condition);
    Ok((serde_json::to_string(&out).map_err(json_err)?, text))
}

/// Registers the vehicle's full-car model file (`vibmode fleet register`): "new", "unchanged"
/// or "replaced".
#[pyfunction]
fn fleet_register(py: Python<'_>, db: PathBuf, vehicle: &str, model: PathBuf) -> PyResult<String> {
    let done = py
        .detach(|| {
            let mut store = Store::open(&db)?;
            vibmode_fleet::register_vehicle_model_file(&mut store, vehicle, &model)
        })
        .map_err(fleet_err)?;
    Ok(match done {
        vibmode_fleet::Registered::New => "new",
        vibmode_fleet::Registered::Unchanged => "unchanged",
        _ => "replaced",
    }
    .to_string())
}

/// The hash function the store keys its records by (`sha256` or `blake3`), for the workers'
/// [`fleet_features`].
#[pyfunction]
fn fleet_content_hash(py: Python<'_>, db: PathBuf) -> PyResult<String> {
    py.detach(|| Ok::<_, FleetError>(Store::open(&db)?.content_hash()?.as_str().to_string()))
        .map_err(fleet_err)
}

/// The vehicle's registered model file's text, if any (for the workers' [`fleet_features`]).
#[pyfunction]
fn fleet_model(py: Python<'_>, db: PathBuf, vehicle: &str) -> PyResult<Option<String>> {
    py.detach(|| {
        let store = Store::open(&db)?;
        Ok::<_, FleetError>(store.vehicle_model(vehicle)?.map(|(_, text)| text))
    })
    .map_err(fleet_err)
}

/// Builds the vehicle's nominal model set; JSON of the `ModelSet`.
#[pyfunction]
fn fleet_baseline(py: Python<'_>, db: PathBuf, vehicle: &str) -> PyResult<(String, String)> {
    let set = py
        .detach(|| {
            let mut store = Store::open(&db)?;
            let cfg = store.config()?;
            build_baseline(&mut store, vehicle, &cfg)
        })
        .map_err(fleet_err)?;
    let text = vibmode_fleet::text::baseline_text(&set);
    Ok((serde_json::to_string(&set).map_err(json_err)?, text))
}

/// Checks files against the vehicle's latest model set; JSON as `vibmode fleet check --json`,
/// and the table `vibmode fleet check` prints.
#[pyfunction]
#[pyo3(signature = (db, vehicle, files, fs=None, scale=1.0, unit=None, allow_nonuniform=false, time_unit=None, drive=None))]
#[allow(clippy::too_many_arguments)]
fn fleet_check(
    py: Python<'_>,
    db: PathBuf,
    vehicle: &str,
    files: Vec<PathBuf>,
    fs: Option<f64>,
    scale: f64,
    unit: Option<String>,
    allow_nonuniform: bool,
    time_unit: Option<&str>,
    drive: Option<&str>,
) -> PyResult<(String, String)> {
    let opts = read_options(fs, scale, unit, allow_nonuniform, time_unit)?;
    let out = py
        .detach(|| {
            let mut store = Store::open(&db)?;
            store.require_vehicle(vehicle)?;
            let set = require_baseline(&store, vehicle)?;
            // All or nothing, as `vibmode fleet check`; a folder stands for its recordings.
            let files = vibmode_signal::expand_folders(&files)?;
            let paths: Vec<&std::path::Path> = files.iter().map(|f| f.as_path()).collect();
            let (records, drives) =
                check_drive_files_progress(&mut store, &set, &paths, &opts, drive, &|_| ())?;
            vibmode_fleet::CheckReport::new(&store, vehicle, set.version, records, drives)
        })
        .map_err(fleet_err)?;
    let text = out.text();
    Ok((serde_json::to_string(&out).map_err(json_err)?, text))
}

/// Status of every vehicle (its last `last` records); JSON list of `VehicleStatus` and the
/// text `vibmode fleet status` prints.
#[pyfunction]
#[pyo3(signature = (db, last=10))]
fn fleet_status(py: Python<'_>, db: PathBuf, last: usize) -> PyResult<(String, String)> {
    let out = py
        .detach(|| Store::open(&db)?.status(last))
        .map_err(fleet_err)?;
    let text = vibmode_fleet::text::status_text(&out);
    Ok((serde_json::to_string(&out).map_err(json_err)?, text))
}

/// A record's fleet features, computed away from the store (e.g. on a Dask worker).
#[derive(Serialize, serde::Deserialize)]
struct FeaturesOut {
    file: String,
    /// The file's content hash (hex) and the function that made it (the store's).
    content_hash: String,
    content_hash_kind: ContentHash,
    metadata: serde_json::Value,
    features: RecordFeatures,
}

/// Reads a file and computes what the store keeps of it (the expensive part of an ingest),
/// without touching a store, with the settings `settings_json` (from [`fleet_settings`]; `None`:
/// the defaults); JSON for [`fleet_store_features`].
#[pyfunction]
#[pyo3(signature = (path, fs=None, scale=1.0, unit=None, settings_json=None, allow_nonuniform=false, time_unit=None, model_toml=None, content_hash=None))]
#[allow(clippy::too_many_arguments)]
fn fleet_features(
    py: Python<'_>,
    path: PathBuf,
    fs: Option<f64>,
    scale: f64,
    unit: Option<String>,
    settings_json: Option<&str>,
    allow_nonuniform: bool,
    time_unit: Option<&str>,
    model_toml: Option<&str>,
    content_hash: Option<&str>,
) -> PyResult<String> {
    // `None`: the hash of a store made now (`ContentHash::default`).
    let kind: ContentHash = content_hash
        .map(str::parse)
        .transpose()
        .map_err(fleet_err)?
        .unwrap_or_default();
    let cfg = settings_from_json(settings_json)?;
    let model = model_toml
        .map(|t| vibmode_fleet::suspension::VehicleModel::from_toml(t, "model"))
        .transpose()
        .map_err(fleet_err)?;
    let opts = read_options(fs, scale, unit, allow_nonuniform, time_unit)?;
    let out = py
        .detach(|| {
            let (bytes, key) = kind.read_file(&path)?;
            let rec = vibmode_signal::read_path_bytes(&path, &bytes, &opts)?;
            drop(bytes);
            let file = vibmode_fleet::record_file_name(&path);
            let features = vibmode_fleet::record_features(&file, &rec, model.as_ref(), &cfg)?;
            Ok::<_, FleetError>(FeaturesOut {
                file,
                content_hash: key,
                content_hash_kind: kind,
                metadata: serde_json::json!({
                    "fs_hz": rec.fs_hz,
                    "n_samples": rec.len(),
                    "channels": rec.names(),
                }),
                features,
            })
        })
        .map_err(fleet_err)?;
    serde_json::to_string(&out).map_err(json_err)
}

/// Stores features from [`fleet_features`] (a JSON list) for a vehicle, as `fleet ingest` does
/// (a record whose bytes are already stored is left alone); JSON list of `Ingested`.
#[pyfunction]
#[pyo3(signature = (db, vehicle, items_json, condition="nominal", road=None))]
fn fleet_store_features(
    py: Python<'_>,
    db: PathBuf,
    vehicle: &str,
    items_json: &str,
    condition: &str,
    road: Option<&str>,
) -> PyResult<String> {
    let condition: Condition = condition.parse().map_err(fleet_err)?;
    let items: Vec<FeaturesOut> =
        serde_json::from_str(items_json).map_err(crate::errors::value_err)?;
    let out = py
        .detach(|| {
            vibmode_fleet::check_vehicle_id(vehicle)?;
            let mut store = Store::open(&db)?;
            let kind = store.content_hash()?;
            if let Some(it) = items.iter().find(|it| it.content_hash_kind != kind) {
                return Err(FleetError::ContentHashMismatch {
                    path: db.display().to_string(),
                    file: it.file.clone(),
                    given: it.content_hash_kind,
                    store: kind,
                });
            }
            // A record the vehicle already has, stored without the body equations the worker
            // made (before the model file was registered): its stored features get them, as
            // `fleet ingest` of the same file does.
            let mut refreshed: Vec<Option<RecordFeatures>> = Vec::with_capacity(items.len());
            for it in &items {
                let fresh = match (
                    &it.features.suspension,
                    store.find_record(vehicle, &it.content_hash)?,
                ) {
                    (Some(e), Some(row)) => {
                        let stored = store.features(row.id)?;
                        stored
                            .lacks_equations_of(&e.model_sha256)
                            .then(|| RecordFeatures {
                                suspension: Some(e.clone()),
                                ..stored
                            })
                    }
                    _ => None,
                };
                refreshed.push(fresh);
            }
            // All or nothing, in one transaction; content the vehicle already has (stored by
            // another process meanwhile, too) is left alone (but for the equations above).
            let batch: Vec<BatchItem<'_>> = items
                .iter()
                .zip(&refreshed)
                .map(|(it, fresh)| BatchItem {
                    record: NewRecord {
                        vehicle,
                        content_hash: &it.content_hash,
                        file_name: &it.file,
                        condition,
                        road,
                        metadata: it.metadata.clone(),
                    },
                    features: fresh.as_ref().unwrap_or(&it.features),
                    check: None,
                    refresh_features: fresh.is_some(),
                })
                .collect();
            let others = items
                .iter()
                .map(|it| store.other_vehicles_with(vehicle, &it.content_hash))
                .collect::<Result<Vec<_>, _>>()?;
            let stored = store.store_batch(&batch)?;
            let out: Vec<Ingested> = items
                .iter()
                .zip(stored)
                .zip(&refreshed)
                .zip(&others)
                .map(|(((it, s), fresh), o)| {
                    vibmode_fleet::fleet::with_other_vehicles(
                        Ingested {
                            file: it.file.clone(),
                            record_id: s.record_id,
                            already_stored: !s.inserted,
                            notes: if s.inserted {
                                it.features.notes.clone()
                            } else if fresh.is_some() {
                                vec![vibmode_fleet::fleet::REFRESHED_NOTE.to_string()]
                            } else {
                                Vec::new()
                            },
                        },
                        o,
                    )
                })
                .collect();
            Ok::<_, FleetError>(out)
        })
        .map_err(fleet_err)?;
    serde_json::to_string(&out).map_err(json_err)
}
