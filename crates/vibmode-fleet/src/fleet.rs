//! The operations of `vibmode fleet`: ingest, baseline, check, over a [`Store`].

use std::path::Path;

use serde::{Deserialize, Serialize};
use vibmode_core::Recording;
use vibmode_signal::ReadOptions;

use crate::config::FleetConfig;
use crate::error::{FleetError, Result};
use crate::features::RecordFeatures;
use crate::hash::ContentHash;
use crate::model::{
    assess, assess_drive_fitted, build_model_set, Assessment, Classification, Drive, ModelSet,
    MIN_DRIVE_RECORDS,
};
use crate::store::{BatchItem, Condition, NewRecord, Store, Stored};
use crate::suspension::{corner_scores, suspension_limit, SuspensionReference, VehicleModel};

/// SHA-256 of bytes, lower-case hex (a vehicle model file's key).
pub fn sha256_hex(bytes: &[u8]) -> String {
    ContentHash::Sha256.hex(bytes)
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

/// A record read and analysed (or found in the store), not yet stored.
struct Prepared {
    file: String,
    content_hash: String,
    metadata: serde_json::Value,
    features: RecordFeatures,
    /// The vehicle already had this content when it was read.
    known: bool,
    /// Known as a nominal record: its file name in the store.
    known_nominal: Option<String>,
    /// The file given before it in the same call with the same content (whose features it
    /// shares, known or not as it is).
    same_as: Option<String>,
    /// Known, and its stored features get the body equations of the vehicle's model file,
    /// registered after the record was stored.
    refreshed: bool,
}

fn metadata_of(rec: &Recording) -> serde_json::Value {
    serde_json::json!({
        "fs_hz": rec.fs_hz,
        "n_samples": rec.len(),
        "channels": rec.names(),
    })
}

/// A nominal record must have every sensor working: it would spoil the baseline.
fn check_nominal_sensors(condition: Condition, name: &str, f: &RecordFeatures) -> Result<()> {
    if condition != Condition::Nominal || f.sensor_faults.is_empty() {
        return Ok(());
    }
    let faults: Vec<String> = f.sensor_faults.iter().map(|x| x.to_string()).collect();
    Err(FleetError::NominalSensorFault {
        record: name.to_string(),
        faults: vibmode_core::cap_message(&faults.join(", "), 160),
    })
}

/// The vehicle's registered model file, parsed (none registered: `None`).
pub fn registered_model(store: &Store, vehicle: &str) -> Result<Option<VehicleModel>> {
    match store.vehicle_model(vehicle)? {
        Some((_, text)) => Ok(Some(VehicleModel::from_toml(
            &text,
            &format!("registered for vehicle '{}'", vibmode_core::quoted(vehicle)),
        )?)),
        None => Ok(None),
    }
}

/// Registers a vehicle's full-car model file (docs/vehicle.md), the vehicle created if new:
/// records ingested or checked from now on carry their body equations, and the baseline and each
/// drive fit the suspension to them ([`crate::suspension`]). The text is parsed and a fit of it
/// made with the store's settings first; nothing is stored if either fails.
pub fn register_vehicle_model(
    store: &mut Store,
    vehicle: &str,
    text: &str,
    source: &str,
) -> Result<Registered> {
    check_vehicle_id(vehicle)?;
    let model = VehicleModel::from_toml(text, source)?;
    let cfg = store.config()?;
    model.check(&cfg.analysis, source)?;
    let before = store.vehicle_model(vehicle)?.is_some();
    Ok(
        match store.register_vehicle_model(vehicle, text, &model.sha256)? {
            false => Registered::Unchanged,
            true if before => Registered::Replaced,
            true => Registered::New,
        },
    )
}

/// What registering a model file did.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Registered {
    /// The vehicle had no model file.
    New,
    /// The same text was registered before: nothing changed.
    Unchanged,
    /// Another file was registered before and is replaced: records' equations made with it no
    /// longer count, and the model set's fitted suspension needs a new baseline.
    Replaced,
}

/// [`register_vehicle_model`] of a file (at most 1 MiB of text).
pub fn register_vehicle_model_file(
    store: &mut Store,
    vehicle: &str,
    path: &Path,
) -> Result<Registered> {
    let shown = path.display().to_string();
    let text =
        vibmode_core::files::read_text_capped(path).map_err(|e| FleetError::VehicleModel {
            source_name: shown.clone(),
            reason: vibmode_core::cap_message(&e.to_string(), 160),
        })?;
    register_vehicle_model(store, vehicle, &text, &shown)
}

/// Adds the record's body equations for the suspension fit to its features (or a note why not):
/// what `ingest` adds when the vehicle has a registered model file ([`registered_model`]); the
/// Python workers call it with the model the client read from the store.
pub fn add_body_equations(
    features: &mut RecordFeatures,
    rec: &Recording,
    model: Option<&VehicleModel>,
    cfg: &FleetConfig,
) {
    add_body_equations_spectra(features, rec, model, cfg, None);
}

/// The features of the record `rec` read from a file ([`crate::compute_features`]) with the body
/// equations of the vehicle's registered `model`, if any ([`add_body_equations`]). Where both
/// resample a channel (the analysis to its rate, the equations to
/// `vibmode_vehicle::update::EQUATION_RATE_HZ`), each channel is transformed once for both
/// (`vibmode_signal::ChannelSpectrum`): the same features and equations bit for bit as the two
/// calls.
///
/// Errors: as [`crate::compute_features`].
pub fn record_features(
    name: &str,
    rec: &Recording,
    model: Option<&VehicleModel>,
    cfg: &FleetConfig,
) -> Result<RecordFeatures> {
    // Spectra only where the equations bring the channels down too (a 2 kHz record is not),
    // with the bins they read (the analysis's lower rate lies below them); and only for a file
    // that is one record (a longer one is cut for the analysis, and its spectra would be held
    // whole for the equations alone).
    let one_record =
        vibmode_analysis::CutRecords::new(name, rec, cfg.analysis.record_length_s).len() == 1;
    let bins = vibmode_vehicle::update::spectrum_bins_read(rec.len(), rec.fs_hz);
    let spectra: Option<Vec<vibmode_signal::ChannelSpectrum>> = match (model, bins) {
        (Some(_), Some(bins)) if one_record => {
            let channels = rec.channels.iter().map(|c| &c.samples[..]);
            vibmode_signal::ChannelSpectrum::of_each(channels, bins).ok()
        }
        _ => None,
    };
    let mut features =
        crate::features::compute_features_spectra(name, rec, cfg, spectra.as_deref())?;
    add_body_equations_spectra(&mut features, rec, model, cfg, spectra.as_deref());
    Ok(features)
}

fn add_body_equations_spectra(
    features: &mut RecordFeatures,
    rec: &Recording,
    model: Option<&VehicleModel>,
    cfg: &FleetConfig,
    spectra: Option<&[vibmode_signal::ChannelSpectrum]>,
) {
    let Some(model) = model else {
        return;
    };
    if !features.sensor_faults.is_empty() {
        features
            .notes
            .push("suspension fit: no body equations from a record with a failed sensor".into());
        return;
    }
    match model.record_equations_spectra(rec, &cfg.analysis, spectra) {
        Ok(e) => features.suspension = Some(e),
        Err(why) => features.notes.push(format!(
            "suspension fit: no body equations ({})",
            vibmode_core::cap_message(&why, 200)
        )),
    }
}

/// Features of a recording to be stored under `labels` (from the store when the vehicle
/// already has its content).
fn prepare_recording(
    store: &Store,
    labels: &IngestLabels<'_>,
    name: &str,
    content_hash: &str,
    rec: &Recording,
    cfg: &FleetConfig,
) -> Result<Prepared> {
    if let Some(row) = store.find_record(labels.vehicle, content_hash)? {
        return Ok(Prepared {
            file: name.to_string(),
            content_hash: content_hash.to_string(),
            metadata: metadata_of(rec),
            features: store.features(row.id)?,
            known: true,
            known_nominal: nominal_name(&row),
            same_as: None,
            refreshed: false,
        });
    }
    let model = registered_model(store, labels.vehicle)?;
    let features = record_features(name, rec, model.as_ref(), cfg)?;
    check_nominal_sensors(labels.condition, name, &features)?;
    Ok(Prepared {
        file: name.to_string(),
        content_hash: content_hash.to_string(),
        metadata: metadata_of(rec),
        features,
        known: false,
        known_nominal: None,
        same_as: None,
        refreshed: false,
    })
}

/// A stored record's file name when it is a nominal one.
fn nominal_name(row: &crate::store::RecordRow) -> Option<String> {
    (row.condition == Condition::Nominal).then(|| row.file_name.clone())
}

/// Stores prepared records (with their checks) in one transaction.
fn store_prepared(
    store: &mut Store,
    labels: &IngestLabels<'_>,
    prepared: &[Prepared],
    checks: &[Option<(i64, Assessment)>],
) -> Result<Vec<Stored>> {
    store_prepared_drive(store, labels, prepared, checks, &[])
}

/// As [`store_prepared`], with a drive's verdict over the records in the same transaction.
fn store_prepared_drive(
    store: &mut Store,
    labels: &IngestLabels<'_>,
    prepared: &[Prepared],
    checks: &[Option<(i64, Assessment)>],
    drives: &[(Drive, Vec<usize>)],
) -> Result<Vec<Stored>> {
    let items: Vec<BatchItem<'_>> = prepared
        .iter()
        .zip(checks)
        .map(|(p, c)| BatchItem {
            record: NewRecord {
                vehicle: labels.vehicle,
                content_hash: &p.content_hash,
                file_name: &p.file,
                condition: labels.condition,
                road: labels.road,
                metadata: p.metadata.clone(),
            },
            features: &p.features,
            check: c.as_ref().map(|(v, a)| (*v, a)),
            refresh_features: p.refreshed,
        })
        .collect();
    store.store_batch_with_drives(&items, drives)
}

fn ingested(p: Prepared, s: Stored) -> Ingested {
    Ingested {
        file: p.file,
        record_id: s.record_id,
        already_stored: p.known || !s.inserted,
        notes: if s.inserted {
            p.features.notes
        } else if p.refreshed {
            vec![REFRESHED_NOTE.to_string()]
        } else {
            Vec::new()
        },
    }
}

/// The note of a stored record whose body equations were added.
pub const REFRESHED_NOTE: &str =
    "body equations added for the suspension fit (the record was stored before the vehicle's model file was registered)";

/// A stored record's features with the body equations of `model` added, when they lack them
/// (stored before the file was registered, or with another file) and the record can give them;
/// `None` otherwise. The file is read again for it.
fn with_equations(
    features: &RecordFeatures,
    model: Option<&VehicleModel>,
    path: &Path,
    bytes: &[u8],
    opts: &ReadOptions,
    cfg: &FleetConfig,
) -> Result<Option<RecordFeatures>> {
    let Some(model) = model else {
        return Ok(None);
    };
    if !features.lacks_equations_of(&model.sha256) {
        return Ok(None);
    }
    let rec = vibmode_signal::read_path_bytes(path, bytes, opts)?;
    Ok(model
        .record_equations(&rec, &cfg.analysis)
        .ok()
        .map(|e| RecordFeatures {
            suspension: Some(e),
            ..features.clone()
        }))
}

/// Ingests a recording with a known content hash (made with [`Store::content_hash`], e.g.
/// [`ContentHash::of_recording`]): a no-op if the vehicle already has it.
pub fn ingest_recording(
    store: &mut Store,
    labels: &IngestLabels<'_>,
    name: &str,
    content_hash: &str,
    rec: &Recording,
    cfg: &FleetConfig,
) -> Result<Ingested> {
    check_vehicle_id(labels.vehicle)?;
    let p = prepare_recording(store, labels, name, content_hash, rec, cfg)?;
    let others = store.other_vehicles_with(labels.vehicle, content_hash)?;
    let stored = store_prepared(store, labels, std::slice::from_ref(&p), &[None])?;
    let s = stored
        .first()
        .copied()
        .ok_or_else(|| FleetError::NotStorable {
            what: format!("'{}'", vibmode_core::quoted(name)),
            reason: "the store returned no row".into(),
        })?;
    Ok(with_other_vehicles(ingested(p, s), &others))
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

/// Reads and analyses every file (a file whose bytes the vehicle already has is not analysed
/// again; the same bytes twice in `paths` are analysed once). `layout` checks each read
/// recording first. `progress(n)` is called as the first `n` files are done.
///
/// The files go in chunks of as many as rayon's pool has threads: each chunk's files are read
/// and hashed in parallel, looked up in the store in order, then parsed from the bytes read
/// and analysed in parallel (so at most one recording per thread is in memory, and each file
/// is read from disk once). The results keep the order of `paths`; the first error in that
/// order is returned.
fn prepare_files(
    store: &Store,
    labels: &IngestLabels<'_>,
    paths: &[&Path],
    opts: &ReadOptions,
    cfg: &FleetConfig,
    layout: &(dyn Fn(&str, &Recording) -> Result<()> + Sync),
    progress: &dyn Fn(usize),
) -> Result<Vec<Prepared>> {
    use rayon::prelude::*;
    /// What a path needs.
    enum Plan {
        /// Stored before for the vehicle: its features (the equations added if they lack them),
        /// and its file name if it is a nominal record.
        Known(Box<RecordFeatures>, Option<String>),
        /// The same bytes as the path at this index, read before in this call.
        Same(usize),
        /// To be read and analysed.
        New,
    }
    let model = registered_model(store, labels.vehicle)?;
    let model = model.as_ref();
    let hash = store.content_hash()?;
    // A path's prepared record, or `None` for a repeat (taken from the first).
    let work = |path: &Path,
                bytes: Vec<u8>,
                name: &str,
                sha: &str,
                plan: &Plan|
     -> Result<Option<Prepared>> {
        match plan {
            Plan::Same(_) => Ok(None),
            Plan::Known(stored, nominal) => {
                let fresh = with_equations(stored, model, path, &bytes, opts, cfg)?;
                Ok(Some(Prepared {
                    file: name.to_string(),
                    content_hash: sha.to_string(),
                    metadata: serde_json::json!({}),
                    refreshed: fresh.is_some(),
                    features: fresh.unwrap_or_else(|| (**stored).clone()),
                    known: true,
                    known_nominal: nominal.clone(),
                    same_as: None,
                }))
            }
            Plan::New => {
                let rec = vibmode_signal::read_path_bytes(path, &bytes, opts)?;
                drop(bytes);
                layout(name, &rec)?;
                let features = record_features(name, &rec, model, cfg)?;
                check_nominal_sensors(labels.condition, name, &features)?;
                Ok(Some(Prepared {
                    file: name.to_string(),
                    content_hash: sha.to_string(),
                    metadata: metadata_of(&rec),
                    features,
                    known: false,
                    known_nominal: None,
                    same_as: None,
                    refreshed: false,
                }))
            }
        }
    };
    let mut first_of: std::collections::HashMap<String, usize> = std::collections::HashMap::new();
    let mut out: Vec<Prepared> = Vec::with_capacity(paths.len());
    for chunk in paths.chunks(rayon::current_num_threads().max(1)) {
        // Each file is read once: hashed here (in parallel), parsed from the same bytes below.
        let read: Vec<Result<(Vec<u8>, String)>> =
            chunk.par_iter().map(|p| hash.read_file(p)).collect();
        let mut plans: Vec<(String, String, Plan)> = Vec::with_capacity(chunk.len());
        let mut contents: Vec<Vec<u8>> = Vec::with_capacity(chunk.len());
        for (path, r) in chunk.iter().zip(read) {
            let name = file_name(path);
            let (bytes, sha) = r?;
            let plan = if let Some(&k) = first_of.get(&sha) {
                Plan::Same(k)
            } else {
                first_of.insert(sha.clone(), out.len() + plans.len());
                match store.find_record(labels.vehicle, &sha)? {
                    Some(row) => Plan::Known(Box::new(store.features(row.id)?), nominal_name(&row)),
                    None => Plan::New,
                }
            };
            contents.push(match plan {
                Plan::Same(_) => Vec::new(),
                _ => bytes,
            });
            plans.push((name, sha, plan));
        }
        let results: Vec<Result<Option<Prepared>>> = chunk
            .par_iter()
            .zip(contents.into_par_iter())
            .zip(plans.par_iter())
            .map(|((path, bytes), (name, sha, plan))| work(path, bytes, name, sha, plan))
            .collect();
        for (r, (name, sha, plan)) in results.into_iter().zip(plans) {
            if let Some(p) = r? {
                out.push(p);
            } else if let Plan::Same(k) = plan {
                let first = &out[k];
                out.push(Prepared {
                    file: name,
                    content_hash: sha,
                    metadata: serde_json::json!({}),
                    features: first.features.clone(),
                    known: first.known,
                    known_nominal: first.known_nominal.clone(),
                    same_as: Some(first.file.clone()),
                    refreshed: false,
                });
            }
        }
        progress(out.len());
    }
    Ok(out)
}

/// Ingests files, all or nothing: every file is read and analysed first, then all are stored
/// in one transaction; any error (an unreadable file, a record too short, a nominal record
/// with a failed sensor) leaves the store unchanged. A file whose bytes the vehicle already
/// has (stored earlier, by another process meanwhile, or given twice) is a no-op
/// (`already_stored`).
pub fn ingest_files(
    store: &mut Store,
    labels: &IngestLabels<'_>,
    paths: &[&Path],
    opts: &ReadOptions,
    cfg: &FleetConfig,
) -> Result<Vec<Ingested>> {
    ingest_files_progress(store, labels, paths, opts, cfg, &|_| ())
}

/// As [`ingest_files`], calling `progress(n)` after the first `n` files are read and analysed
/// (before anything is stored).
pub fn ingest_files_progress(
    store: &mut Store,
    labels: &IngestLabels<'_>,
    paths: &[&Path],
    opts: &ReadOptions,
    cfg: &FleetConfig,
    progress: &dyn Fn(usize),
) -> Result<Vec<Ingested>> {
    check_vehicle_id(labels.vehicle)?;
    let prepared = prepare_files(store, labels, paths, opts, cfg, &|_, _| Ok(()), progress)?;
    let others = other_vehicles(store, labels.vehicle, &prepared)?;
    let checks = vec![None; prepared.len()];
    let stored = store_prepared(store, labels, &prepared, &checks)?;
    Ok(prepared
        .into_iter()
        .zip(stored)
        .zip(others)
        .map(|((p, s), o)| with_other_vehicles(ingested(p, s), &o))
        .collect())
}

/// Per prepared record, the other vehicles that have a record of its content.
fn other_vehicles(store: &Store, vehicle: &str, prepared: &[Prepared]) -> Result<Vec<Vec<String>>> {
    prepared
        .iter()
        .map(|p| store.other_vehicles_with(vehicle, &p.content_hash))
        .collect()
}

/// A newly stored record whose content another vehicle has too gets a note naming it: a
/// record is of one vehicle, and a nominal record of another would enter this one's baseline.
/// `others`: [`Store::other_vehicles_with`] of its content, looked up before it was stored.
pub fn with_other_vehicles(mut done: Ingested, others: &[String]) -> Ingested {
    if !done.already_stored && !others.is_empty() {
        let names: Vec<String> = others
            .iter()
            .map(|o| format!("'{}'", vibmode_core::quoted(o)))
            .collect();
        done.notes.push(format!(
            "its content is stored for vehicle {} too: a record is of one vehicle; if it is that vehicle's, it does not belong to this one",
            names.join(", ")
        ));
    }
    done
}

/// Ingests a file (read with `opts`): a no-op when its bytes are already stored for the vehicle.
pub fn ingest_file(
    store: &mut Store,
    labels: &IngestLabels<'_>,
    path: &Path,
    opts: &ReadOptions,
    cfg: &FleetConfig,
) -> Result<Ingested> {
    let mut out = ingest_files(store, labels, &[path], opts, cfg)?;
    out.pop().ok_or_else(|| FleetError::NotStorable {
        what: format!("'{}'", vibmode_core::quoted(&file_name(path))),
        reason: "the store returned no row".into(),
    })
}

/// Builds and stores the next model-set version of a vehicle from its nominal records.
/// Nominal records with a failed sensor (stored by an older vibmode, or through the Python
/// workers) are left out, with a note.
pub fn build_baseline(store: &mut Store, vehicle: &str, cfg: &FleetConfig) -> Result<ModelSet> {
    let nominal = store.nominal_records(vehicle)?;
    let mut notes = Vec::new();
    let mut names = Vec::new();
    let mut feats = Vec::new();
    for (r, f) in nominal {
        if f.sensor_faults.is_empty() {
            names.push(r.file_name);
            feats.push(f);
        } else {
            let faults: Vec<String> = f.sensor_faults.iter().map(|x| x.to_string()).collect();
            notes.push(format!(
                "nominal record {} left out: {}",
                vibmode_core::quoted(&r.file_name),
                faults.join(", ")
            ));
        }
    }
    // Records stored before the line-free features: left out (kept in the store) when enough
    // newer ones remain, else the baseline is refused (a model set of the older features would
    // score the transmissibility with the periodic lines in).
    let old = feats.iter().filter(|f| f.line_free.is_none()).count();
    if old > 0 {
        let current = feats.len() - old;
        if current < cfg.min_nominal {
            return Err(FleetError::NominalBeforeLineFree {
                vehicle: vehicle.to_string(),
                old,
                current,
                needed: cfg.min_nominal,
            });
        }
        let keep: Vec<bool> = feats.iter().map(|f| f.line_free.is_some()).collect();
        let mut k = keep.iter();
        names.retain(|_| k.next().copied().unwrap_or(false));
        feats.retain(|f| f.line_free.is_some());
        notes.push(format!(
            "{old} nominal record(s) stored before the transmissibility left out the periodic lines are left out of the baseline (they stay stored)"
        ));
    }
    let mut set = build_model_set(vehicle, &names, &feats, cfg)?;
    set.notes.extend(notes);
    let model = registered_model(store, vehicle)?;
    if let Some(model) = &model {
        let eqs: Vec<&vibmode_vehicle::update::RecordEquations> = feats
            .iter()
            .filter_map(|f| f.suspension.as_ref())
            .filter(|e| e.model_sha256 == model.sha256)
            .map(|e| &e.equations)
            .collect();
        match model.fit_corners(&cfg.analysis, &eqs) {
            Ok(fit) => {
                set.suspension = Some(SuspensionReference {
                    model_sha256: model.sha256.clone(),
                    fit,
                    limit: suspension_limit(cfg.false_alarm_rate),
                })
            }
            Err(why) => set.notes.push(format!(
                "no suspension fit per drive: the nominal records' fit failed: {} (ingest nominal records after registering the vehicle model file)",
                vibmode_core::cap_message(&why, 200)
            )),
        }
    }
    let fitted = set.suspension.as_ref().and(model.as_ref());
    let (held_out, why_not) = held_out_drives(vehicle, &names, &feats, cfg, fitted);
    set.held_out_drives = held_out;
    set.notes.extend(why_not);
    store.save_model_set(&mut set)?;
    Ok(set)
}

/// The drives of a vehicle's nominal records, as (id, indices of the records), sorted by id:
/// one per UTC day where every record's start is known, else one per folder the records were
/// given in ([`DEFAULT_DRIVE_ID`] for those given without one). Unlike a check's drives
/// ([`drives_of_records`]) records of several folders are several drives: a baseline is
/// commonly ingested a drive's folder at a time, or all of them at once.
pub fn nominal_drives<S: AsRef<str>>(
    starts: &[Option<f64>],
    files: &[S],
) -> Vec<(String, Vec<usize>)> {
    let days: Option<Vec<String>> = starts.iter().map(|s| s.and_then(drive_of_day)).collect();
    let ids: Vec<String> = match days {
        Some(days) => days,
        None => files
            .iter()
            .map(|f| drive_of_folder(std::slice::from_ref(f)))
            .collect(),
    };
    let mut out: Vec<(String, Vec<usize>)> = Vec::new();
    for (i, id) in ids.into_iter().enumerate() {
        match out.iter_mut().find(|(d, _)| *d == id) {
            Some((_, members)) => members.push(i),
            None => out.push((id, vec![i])),
        }
    }
    out.sort_by(|a, b| a.0.cmp(&b.0));
    out
}

/// Leave one drive out: each drive of the nominal records ([`nominal_drives`]) with at least
/// [`MIN_DRIVE_RECORDS`] records, checked as a drive ([`assess_drive_fitted`]) against a model
/// set built from the other nominal records (and, with `model`, the suspension fitted to them),
/// where those are at least `cfg.min_nominal`. Every such drive was driven healthy, so a
/// verdict other than `normal` is a false alarm of the drive rule on this vehicle's own
/// records. The second value says why no drive could be held out (fewer than two drives, or
/// too few records besides each).
pub fn held_out_drives(
    vehicle: &str,
    names: &[String],
    feats: &[RecordFeatures],
    cfg: &FleetConfig,
    model: Option<&VehicleModel>,
) -> (Vec<crate::model::HeldOutDrive>, Option<String>) {
    let starts: Vec<Option<f64>> = feats.iter().map(|f| f.start_unix_s).collect();
    let drives = nominal_drives(&starts, names);
    let mut out = Vec::new();
    let mut skipped = Vec::new();
    for (id, members) in &drives {
        let rest: Vec<usize> = (0..feats.len()).filter(|i| !members.contains(i)).collect();
        if members.len() < MIN_DRIVE_RECORDS || rest.len() < cfg.min_nominal {
            skipped.push(format!(
                "{} ({} records)",
                vibmode_core::quoted(id),
                members.len()
            ));
            continue;
        }
        let rest_names: Vec<String> = rest.iter().map(|&i| names[i].clone()).collect();
        let rest_feats: Vec<RecordFeatures> = rest.iter().map(|&i| feats[i].clone()).collect();
        let mut held = match build_model_set(vehicle, &rest_names, &rest_feats, cfg) {
            Ok(set) => set,
            Err(_) => {
                skipped.push(format!(
                    "{} (the other records gave no model set)",
                    vibmode_core::quoted(id)
                ));
                continue;
            }
        };
        let drive: Vec<&RecordFeatures> = members.iter().map(|&i| &feats[i]).collect();
        let mut scores = Vec::new();
        if let Some(model) = model {
            let equations = |idx: &[usize]| -> Vec<&vibmode_vehicle::update::RecordEquations> {
                idx.iter()
                    .map(|&i| &feats[i])
                    .filter(|f| f.sensor_faults.is_empty())
                    .filter_map(|f| f.suspension.as_ref())
                    .filter(|e| e.model_sha256 == model.sha256)
                    .map(|e| &e.equations)
                    .collect()
            };
            if let (Ok(reference), Ok(fit)) = (
                model.fit_corners(&cfg.analysis, &equations(&rest)),
                model.fit_corners(&cfg.analysis, &equations(members)),
            ) {
                scores = corner_scores(&[&reference], &fit);
                held.suspension = Some(SuspensionReference {
                    model_sha256: model.sha256.clone(),
                    fit: reference,
                    limit: suspension_limit(cfg.false_alarm_rate),
                });
            }
        }
        let a = assess_drive_fitted(&held, &drive, &scores, None);
        out.push(crate::model::HeldOutDrive {
            drive: id.clone(),
            records: members.iter().map(|&i| names[i].clone()).collect(),
            reference_records: rest.len(),
            classification: a.classification,
            component: a.component,
            summary: a.summary,
        });
    }
    let why_not = match (out.is_empty(), drives.len()) {
        (false, _) => None,
        (true, 1) => Some(format!(
            "leave-one-drive-out: not made: the {} nominal records form one drive ({}), so no healthy drive of this vehicle was checked against the others; a drive's stated false-alarm rate is then a bound, not measured on it (ingest nominal records of another day or folder)",
            feats.len(),
            vibmode_core::quoted(&drives[0].0)
        )),
        (true, _) => Some(format!(
            "leave-one-drive-out: not made: no nominal drive has {MIN_DRIVE_RECORDS} records with {} others beside it: {}",
            cfg.min_nominal,
            skipped.join(", ")
        )),
    };
    (out, why_not)
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
    /// The model set's record (its file name) with this record's content, when the model set
    /// was built from it: the check is not independent of the baseline. Absent otherwise.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub in_baseline: Option<String>,
    /// The file given before it in the same check with the same content: scored alike, and
    /// counted once in a drive. Absent otherwise.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub same_as: Option<String>,
}

/// What `fleet check` reports (its text and JSON, for the CLI and Python alike): the records'
/// verdicts, the drives', and a fault found on an earlier drive against the same baseline when
/// the vehicle's latest drive does not show it ([`crate::store::EarlierFlag`]).
#[derive(Clone, Debug, Serialize)]
pub struct CheckReport {
    /// The vehicle.
    pub vehicle: String,
    /// The model-set version the records were scored against.
    pub model_version: i64,
    /// Each record's verdict.
    pub records: Vec<Checked>,
    /// Each drive's verdict.
    pub drives: Vec<crate::model::Drive>,
    /// An earlier drive flagged `vehicle` or `both` against the latest drive's baseline, when the
    /// latest drive is not (only where this check made a drive); absent otherwise.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub earlier_flag: Option<crate::store::EarlierFlag>,
}

impl CheckReport {
    /// The report of a check of `vehicle` just stored in `store`.
    pub fn new(
        store: &Store,
        vehicle: &str,
        model_version: i64,
        records: Vec<Checked>,
        drives: Vec<crate::model::Drive>,
    ) -> Result<Self> {
        let earlier_flag = if drives.is_empty() {
            None
        } else {
            store.earlier_flag(vehicle)?
        };
        Ok(CheckReport {
            vehicle: vehicle.to_string(),
            model_version,
            records,
            drives,
            earlier_flag,
        })
    }

    /// The text `fleet check` prints: the records' and drives' table
    /// ([`crate::text::check_text`]) and the earlier flag's note.
    pub fn text(&self) -> String {
        crate::text::check_text(
            &self.vehicle,
            self.model_version,
            &self.records,
            &self.drives,
        ) + &crate::text::earlier_flag_note(self.earlier_flag.as_ref())
    }
}

/// The file name of a model set's record with the content of `p`, if the set holds it.
fn in_baseline(set: &ModelSet, p: &Prepared) -> Option<String> {
    p.known_nominal
        .as_ref()
        .filter(|n| set.records.contains(n))
        .cloned()
}

/// The vehicle's latest model set; errors name the fix when there is none.
/// A model set built before the line-free features is refused ([`FleetError::StaleBaseline`]).
pub fn require_baseline(store: &Store, vehicle: &str) -> Result<ModelSet> {
    let set = store
        .latest_model_set(vehicle)?
        .ok_or_else(|| FleetError::NoBaseline {
            vehicle: vehicle.to_string(),
        })?;
    require_line_free(&set)?;
    Ok(set)
}

/// Refuses a model set built before the line-free features ([`ModelSet::line_free`]).
fn require_line_free(set: &ModelSet) -> Result<()> {
    if set.line_free {
        Ok(())
    } else {
        Err(FleetError::StaleBaseline {
            vehicle: set.vehicle.clone(),
            version: set.version,
        })
    }
}

fn test_labels(set: &ModelSet) -> IngestLabels<'_> {
    IngestLabels {
        vehicle: &set.vehicle,
        condition: Condition::Test,
        road: None,
    }
}

/// Scores prepared records against `set` and stores them with their checks in one
/// transaction.
fn check_prepared(
    store: &mut Store,
    set: &ModelSet,
    prepared: Vec<Prepared>,
) -> Result<Vec<Checked>> {
    check_prepared_drive(store, set, prepared, &[])
}

/// As [`check_prepared`], storing a drive's verdict in the same transaction.
fn check_prepared_drive(
    store: &mut Store,
    set: &ModelSet,
    prepared: Vec<Prepared>,
    drives: &[(Drive, Vec<usize>)],
) -> Result<Vec<Checked>> {
    require_line_free(set)?;
    let checks: Vec<Option<(i64, Assessment)>> = prepared
        .iter()
        .map(|p| Some((set.version, assess(set, &p.features))))
        .collect();
    let stored = store_prepared_drive(store, &test_labels(set), &prepared, &checks, drives)?;
    Ok(prepared
        .into_iter()
        .zip(checks)
        .zip(stored)
        .filter_map(|((p, c), s)| {
            c.map(|(v, assessment)| Checked {
                in_baseline: in_baseline(set, &p),
                same_as: p.same_as,
                file: p.file,
                record_id: s.record_id,
                model_version: v,
                assessment,
            })
        })
        .collect())
}

/// Checks a recording (stored as a test record unless already stored) against `set`.
pub fn check_recording(
    store: &mut Store,
    set: &ModelSet,
    name: &str,
    content_hash: &str,
    rec: &Recording,
) -> Result<Checked> {
    check_vehicle_id(&set.vehicle)?;
    check_layout(set, name, rec)?;
    let p = prepare_recording(
        store,
        &test_labels(set),
        name,
        content_hash,
        rec,
        &set.config,
    )?;
    let mut out = check_prepared(store, set, vec![p])?;
    out.pop().ok_or_else(|| FleetError::NotStorable {
        what: format!("the check of '{}'", vibmode_core::quoted(name)),
        reason: "the store returned no row".into(),
    })
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

/// Checks files against `set`, all or nothing: every file is read, analysed and scored first,
/// then all (test records and checks) are stored in one transaction; any error leaves the
/// store unchanged. A file the vehicle already has is scored from its stored features.
pub fn check_files(
    store: &mut Store,
    set: &ModelSet,
    paths: &[&Path],
    opts: &ReadOptions,
) -> Result<Vec<Checked>> {
    check_files_progress(store, set, paths, opts, &|_| ())
}

/// As [`check_files`], calling `progress(n)` after the first `n` files are read and analysed
/// (they are scored and stored after the last).
pub fn check_files_progress(
    store: &mut Store,
    set: &ModelSet,
    paths: &[&Path],
    opts: &ReadOptions,
    progress: &dyn Fn(usize),
) -> Result<Vec<Checked>> {
    check_vehicle_id(&set.vehicle)?;
    let prepared = prepare_test_files(store, set, paths, opts, progress)?;
    check_prepared(store, set, prepared)
}

/// Reads and analyses files to be checked against `set` (its layout and settings), as test
/// records of its vehicle; `progress(n)` after the first `n`.
fn prepare_test_files(
    store: &Store,
    set: &ModelSet,
    paths: &[&Path],
    opts: &ReadOptions,
    progress: &dyn Fn(usize),
) -> Result<Vec<Prepared>> {
    let layout = |name: &str, rec: &Recording| check_layout(set, name, rec);
    prepare_files(
        store,
        &test_labels(set),
        paths,
        opts,
        &set.config,
        &layout,
        progress,
    )
}

/// The id of a drive when none is given, the records' starts are not known and the records
/// lie in different folders (or in the current one): see [`drive_of_folder`].
pub const DEFAULT_DRIVE_ID: &str = "all given records";

/// The id of a drive of records whose starts are not known: the folder all of them lie in, as
/// given (`bus17/2026-11-26` for `bus17/2026-11-26/rec01.csv ...`: a day's records are
/// commonly kept in a folder of their own), else [`DEFAULT_DRIVE_ID`] (records of several
/// folders, or given without one or as `./rec01.csv`).
pub fn drive_of_folder<S: AsRef<str>>(files: &[S]) -> String {
    let folder = |f: &S| {
        Path::new(f.as_ref())
            .parent()
            .map(|p| p.display().to_string())
    };
    let first = files.first().and_then(folder);
    match first {
        Some(dir)
            if !dir.is_empty()
                && dir != "."
                && files.iter().all(|f| folder(f).as_ref() == Some(&dir)) =>
        {
            dir
        }
        _ => DEFAULT_DRIVE_ID.to_string(),
    }
}

/// The drive (its id, `YYYY-MM-DD`) of a record that started at this Unix time (s): its day
/// in UTC. `None` outside the years chrono can represent.
pub fn drive_of_day(start_unix_s: f64) -> Option<String> {
    // `YYYY-MM-DDTHH:MM:SSZ`: its date.
    crate::store::utc_of_unix(start_unix_s).map(|t| t[..10].to_string())
}

/// The drives of records checked without a drive id, as (id, indices of the records): where
/// every record's start is known (a time column of date-times), one drive per UTC day with at
/// least [`MIN_DRIVE_RECORDS`] records (the records of a day with fewer are checked one by one
/// only); else all the records as one drive, named by [`drive_of_folder`] of `files`, when
/// there are that many.
fn drives_of_records(starts: &[Option<f64>], files: &[&str]) -> Vec<(String, Vec<usize>)> {
    let days: Option<Vec<String>> = starts.iter().map(|s| s.and_then(drive_of_day)).collect();
    match days {
        Some(days) if !days.is_empty() => {
            let mut out: Vec<(String, Vec<usize>)> = Vec::new();
            for (i, day) in days.into_iter().enumerate() {
                match out.iter_mut().find(|(d, _)| *d == day) {
                    Some((_, members)) => members.push(i),
                    None => out.push((day, vec![i])),
                }
            }
            out.retain(|(_, members)| members.len() >= MIN_DRIVE_RECORDS);
            out.sort_by(|a, b| a.0.cmp(&b.0));
            out
        }
        _ if starts.len() >= MIN_DRIVE_RECORDS => {
            vec![(drive_of_folder(files), (0..starts.len()).collect())]
        }
        _ => Vec::new(),
    }
}

/// As [`check_files_progress`], and the given files as drives of the vehicle: with `drive`
/// given, all of them are that one drive, and at least [`MIN_DRIVE_RECORDS`] files are needed
/// (else an error before anything is read or stored; files of the same content count once, a
/// repeat is left out of every drive); without it, one drive per day where
/// every record's start is known, else one drive named by their folder ([`drive_of_folder`];
/// [`drives_of_records`]). Every record must have the baseline's channels (one layout per
/// drive), and no record of a drive may be one stored for another vehicle (one vehicle per
/// drive); else an error, and nothing is stored. The drives come sorted by id.
pub fn check_drive_files_progress(
    store: &mut Store,
    set: &ModelSet,
    paths: &[&Path],
    opts: &ReadOptions,
    drive: Option<&str>,
    progress: &dyn Fn(usize),
) -> Result<(Vec<Checked>, Vec<Drive>)> {
    check_vehicle_id(&set.vehicle)?;
    if let Some(id) = drive {
        if paths.len() < MIN_DRIVE_RECORDS {
            return Err(FleetError::DriveTooShort {
                drive: id.to_string(),
                found: paths.len(),
                needed: MIN_DRIVE_RECORDS,
            });
        }
    }
    let prepared = prepare_test_files(store, set, paths, opts, progress)?;
    // Each content once: a file given twice (or a copy) would weigh twice in the median.
    let distinct: Vec<usize> = (0..prepared.len())
        .filter(|&i| prepared[i].same_as.is_none())
        .collect();
    let groups = match drive {
        Some(id) if distinct.len() < MIN_DRIVE_RECORDS => {
            return Err(FleetError::DriveTooShort {
                drive: id.to_string(),
                found: distinct.len(),
                needed: MIN_DRIVE_RECORDS,
            });
        }
        Some(id) => vec![(id.to_string(), distinct)],
        None => {
            let starts: Vec<Option<f64>> = distinct
                .iter()
                .map(|&i| prepared[i].features.start_unix_s)
                .collect();
            let files: Vec<&str> = distinct
                .iter()
                .map(|&i| prepared[i].file.as_str())
                .collect();
            drives_of_records(&starts, &files)
                .into_iter()
                .map(|(id, members)| (id, members.into_iter().map(|k| distinct[k]).collect()))
                .collect()
        }
    };
    // One vehicle per drive: a record stored for another vehicle is refused in any drive (named
    // or by day or of all given records); a record checked alone may be one.
    for (id, members) in &groups {
        for p in members.iter().map(|&i| &prepared[i]).filter(|p| !p.known) {
            if let Some(other) = store
                .other_vehicles_with(&set.vehicle, &p.content_hash)?
                .into_iter()
                .next()
            {
                return Err(FleetError::DriveMixesVehicles {
                    drive: id.clone(),
                    vehicle: set.vehicle.clone(),
                    record: p.file.clone(),
                    other,
                });
            }
        }
    }
    // The vehicle's stored drives against this baseline, read once for every drive's spring
    // trend (only where the model set fits the suspension).
    let stored = if set.suspension.is_some() {
        store.drives_of_model_set(&set.vehicle, set.version, TREND_CANDIDATES)?
    } else {
        Vec::new()
    };
    let mut drives: Vec<(Drive, Vec<usize>)> = Vec::with_capacity(groups.len());
    for (id, members) in groups {
        let group: Vec<&Prepared> = members.iter().map(|&i| &prepared[i]).collect();
        // The drives of this check before it count as earlier drives of the spring trend.
        let earlier: Vec<(Drive, Vec<String>)> = drives
            .iter()
            .map(|(d, m)| {
                let hashes = m
                    .iter()
                    .map(|&i| prepared[i].content_hash.clone())
                    .collect();
                (d.clone(), hashes)
            })
            .collect();
        drives.push((
            drive_verdict(store, set, &id, &group, &stored, &earlier)?,
            members,
        ));
    }
    let checked = check_prepared_drive(store, set, prepared, &drives)?;
    Ok((checked, drives.into_iter().map(|(d, _)| d).collect()))
}

/// A drive's note when its vehicle has no registered model file (and its model set no fitted
/// suspension): what the verdict could not look at.
pub const NO_MODEL_FILE: &str = "suspension fit: not made: the vehicle has no registered full-car model file, so its springs and dampers are not fitted per drive and a lost spring may go unseen (docs/fleet.md, \"The suspension fitted per drive\")";

/// The verdict of one drive of `records`; `stored` are the vehicle's stored drives against the
/// model set ([`Store::drives_of_model_set`]) and `earlier` the drives checked before it in the
/// same call, each with their records' content hashes.
fn drive_verdict(
    store: &Store,
    set: &ModelSet,
    id: &str,
    records: &[&Prepared],
    stored: &[(Drive, Vec<String>)],
    earlier: &[(Drive, Vec<String>)],
) -> Result<Drive> {
    let start_unix_s = records
        .iter()
        .map(|p| p.features.start_unix_s)
        .collect::<Option<Vec<f64>>>()
        .and_then(|s| s.into_iter().reduce(f64::min));
    let hashes: Vec<&str> = records.iter().map(|p| p.content_hash.as_str()).collect();
    let before = earlier_fits(stored.iter().chain(earlier), &hashes, start_unix_s);
    let window = crate::suspension::TREND_DRIVES - 1;
    let reference_drives = reference_drives(&before, window, set.config.reference_drives);
    let extra: Vec<&crate::suspension::CornerFit> =
        reference_drives.iter().map(|(_, f)| *f).collect();
    let mut suspension = drive_suspension(store, set, records, &extra)?;
    let mut trend_missing = None;
    if let (Some(d), Some(reference)) = (suspension.0.as_mut(), set.suspension.as_ref()) {
        d.reference_drives = reference_drives
            .iter()
            .map(|(id, _)| id.to_string())
            .collect();
        if before.len() >= window {
            let mut fits = vec![&d.fit];
            let mut ids = vec![id.to_string()];
            for (drive, fit, _) in before.iter().take(window) {
                fits.push(fit);
                ids.push(drive.to_string());
            }
            let mut refs = vec![&reference.fit];
            refs.extend(&extra);
            d.trend = Some(crate::suspension::SpringTrend {
                drives: ids,
                scores: crate::suspension::spring_trend(&refs, &fits),
                limit: crate::suspension::trend_limit(set.config.false_alarm_rate),
            });
        } else {
            trend_missing = Some(format!(
                "suspension fit: no spring trend over the last {} drives yet: {} of the {} earlier drives it needs fitted against baseline version {} (a spring's slow loss is judged on this drive alone)",
                crate::suspension::TREND_DRIVES,
                before.len(),
                window,
                set.version,
            ));
        }
    }
    let feats: Vec<&RecordFeatures> = records.iter().map(|p| &p.features).collect();
    let scores = suspension.0.as_ref().map_or(&[][..], |d| &d.scores[..]);
    let trend = suspension.0.as_ref().and_then(|d| d.trend.as_ref());
    let mut assessment = assess_drive_fitted(set, &feats, scores, trend);
    if let Some(why) = &suspension.1 {
        assessment.missing.push(why.clone());
    }
    assessment.missing.extend(trend_missing);
    Ok(Drive {
        drive: id.to_string(),
        model_version: set.version,
        records: records.iter().map(|p| p.file.clone()).collect(),
        start_unix_s,
        corner: assessment
            .evidence
            .iter()
            .find(|e| e.meta.group == crate::model::Group::Vehicle)
            .and_then(|e| e.meta.corner),
        false_alarm_rate: if suspension.0.is_some() {
            2.0 * set.config.false_alarm_rate
        } else {
            set.config.false_alarm_rate
        },
        assessment,
        suspension: suspension.0,
        in_baseline: records
            .iter()
            .filter(|p| in_baseline(set, p).is_some())
            .map(|p| p.file.clone())
            .collect(),
    })
}

/// The drives checked last against a baseline among which [`earlier_fits`] looks for a drive's
/// earlier drives: enough for a week of drives checked out of order, and a bound on what each
/// check reads back from the store.
const TREND_CANDIDATES: usize = 64;

/// The fitted drives before a drive of records with `hashes` and start `start_unix_s`, newest
/// first, from `candidates` (the vehicle's drives against the same baseline, in the order they
/// were checked, with their records' content hashes): those with a fit that share no record
/// with it, one of each set of records (a drive checked twice counts once). They are ordered by
/// when they were driven where this drive's start and all theirs are known (and only those
/// driven before it count), else by when they were checked.
fn earlier_fits<'a>(
    candidates: impl IntoIterator<Item = &'a (Drive, Vec<String>)>,
    hashes: &[&str],
    start_unix_s: Option<f64>,
) -> Vec<(&'a str, &'a crate::suspension::CornerFit, Classification)> {
    let fitted: Vec<&(Drive, Vec<String>)> = candidates
        .into_iter()
        .filter(|(d, h)| d.suspension.is_some() && !h.iter().any(|x| hashes.contains(&x.as_str())))
        .collect();
    let timed = start_unix_s.is_some() && fitted.iter().all(|(d, _)| d.start_unix_s.is_some());
    let mut ordered: Vec<&(Drive, Vec<String>)> = match start_unix_s {
        Some(t) if timed => {
            let mut v: Vec<_> = fitted
                .into_iter()
                .filter(|(d, _)| d.start_unix_s.is_some_and(|s| s < t))
                .collect();
            v.sort_by(|a, b| {
                b.0.start_unix_s
                    .unwrap_or(0.0)
                    .total_cmp(&a.0.start_unix_s.unwrap_or(0.0))
            });
            v
        }
        _ => fitted.into_iter().rev().collect(),
    };
    let mut seen: Vec<Vec<&str>> = Vec::new();
    ordered.retain(|(_, h)| {
        let mut set: Vec<&str> = h.iter().map(String::as_str).collect();
        set.sort_unstable();
        if seen.contains(&set) {
            false
        } else {
            seen.push(set);
            true
        }
    });
    ordered
        .into_iter()
        .filter_map(|(d, _)| {
            d.suspension
                .as_ref()
                .map(|s| (d.drive.as_str(), &s.fit, d.assessment.classification))
        })
        .collect()
}

/// The drives pooled with the baseline's fit into the reference: of `before` (a drive's earlier
/// fitted drives, newest first: [`earlier_fits`]), those older than its trend's `window` drives
/// and classed `normal`, the oldest `most` of them, oldest first.
fn reference_drives<'a>(
    before: &[(&'a str, &'a crate::suspension::CornerFit, Classification)],
    window: usize,
    most: usize,
) -> Vec<(&'a str, &'a crate::suspension::CornerFit)> {
    let mut out: Vec<(&str, &crate::suspension::CornerFit)> = before
        .iter()
        .skip(window)
        .filter(|(_, _, class)| *class == Classification::Normal)
        .map(|(d, f, _)| (*d, *f))
        .collect();
    out.reverse();
    out.truncate(most);
    out
}

/// The suspension fitted to a drive's records and scored against the model set's, or why not
/// (`None` and no scores when the vehicle has no registered model file and the model set no
/// fitted suspension: nothing to say).
fn drive_suspension(
    store: &Store,
    set: &ModelSet,
    prepared: &[&Prepared],
    reference_drives: &[&crate::suspension::CornerFit],
) -> Result<(Option<crate::suspension::DriveSuspension>, Option<String>)> {
    let model = registered_model(store, &set.vehicle)?;
    let (model, reference) = match (model, &set.suspension) {
        // Not silent: without the fit a spring's loss may pass unseen (docs/fleet.md: 0 of 50
        // springs at 80 % found on busgen drives without it).
        (None, None) => {
            return Ok((
                None,
                Some(NO_MODEL_FILE.into()),
            ))
        }
        (None, Some(_)) => {
            return Ok((
                None,
                Some("suspension fit: the vehicle has no registered model file".into()),
            ))
        }
        (Some(_), None) => {
            return Ok((
                None,
                Some(format!(
                    "suspension fit: model set version {} has no fitted suspension (build a baseline from nominal records ingested after registering the model file)",
                    set.version
                )),
            ))
        }
        (Some(m), Some(r)) => (m, r),
    };
    if model.sha256 != reference.model_sha256 {
        return Ok((
            None,
            Some(format!(
                "suspension fit: the vehicle's model file changed after model set version {} was built (build a new baseline)",
                set.version
            )),
        ));
    }
    let eqs: Vec<&vibmode_vehicle::update::RecordEquations> = prepared
        .iter()
        .filter(|p| p.features.sensor_faults.is_empty())
        .filter_map(|p| p.features.suspension.as_ref())
        .filter(|e| e.model_sha256 == model.sha256)
        .map(|e| &e.equations)
        .collect();
    match model.fit_corners(&set.config.analysis, &eqs) {
        Ok(fit) => Ok((
            Some(crate::suspension::DriveSuspension {
                scores: corner_scores(
                    &std::iter::once(&reference.fit)
                        .chain(reference_drives.iter().copied())
                        .collect::<Vec<_>>(),
                    &fit,
                ),
                fit,
                limit: reference.limit,
                trend: None,
                reference_drives: Vec::new(),
            }),
            None,
        )),
        Err(why) => Ok((
            None,
            Some(format!(
                "suspension fit: {}",
                vibmode_core::cap_message(&why, 200)
            )),
        )),
    }
}

/// Checks a file against `set` (stored as a test record unless already stored).
pub fn check_file(
    store: &mut Store,
    set: &ModelSet,
    path: &Path,
    opts: &ReadOptions,
) -> Result<Checked> {
    let mut out = check_files(store, set, &[path], opts)?;
    out.pop().ok_or_else(|| FleetError::NotStorable {
        what: format!("the check of '{}'", vibmode_core::quoted(&file_name(path))),
        reason: "the store returned no row".into(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A stored drive for [`earlier_fits`]: fitted or not, its start, its records' hashes.
    fn stored(id: &str, start: Option<f64>, fitted: bool, hashes: &[&str]) -> (Drive, Vec<String>) {
        let fit = crate::suspension::CornerFit::even_for_tests();
        let drive = Drive {
            drive: id.to_string(),
            model_version: 1,
            records: Vec::new(),
            start_unix_s: start,
            corner: None,
            false_alarm_rate: 0.02,
            assessment: Assessment::normal_for_tests(),
            suspension: fitted.then(|| crate::suspension::DriveSuspension {
                fit,
                scores: Vec::new(),
                limit: 3.0,
                trend: None,
                reference_drives: Vec::new(),
            }),
            in_baseline: Vec::new(),
        };
        (drive, hashes.iter().map(|h| h.to_string()).collect())
    }

    fn ids(v: &[(&str, &crate::suspension::CornerFit, Classification)]) -> Vec<String> {
        v.iter().map(|(d, _, _)| d.to_string()).collect()
    }

    /// By hand: of 9 earlier drives (newest first), the 2 of the trend are skipped, the ones
    /// not `normal` are left out, and the oldest `most` of the rest are the reference, oldest
    /// first; none when the drive has no more than its trend's drives before it.
    #[test]
    fn the_reference_drives_by_hand() {
        let fit = crate::suspension::CornerFit::even_for_tests();
        use Classification::{Normal, Road, Vehicle};
        let classes = [
            Normal, Normal, Vehicle, Normal, Road, Normal, Normal, Normal, Normal,
        ];
        let names = ["d9", "d8", "d7", "d6", "d5", "d4", "d3", "d2", "d1"];
        let before: Vec<(&str, &crate::suspension::CornerFit, Classification)> = names
            .iter()
            .zip(classes)
            .map(|(n, c)| (*n, &fit, c))
            .collect();
        let got = |most| -> Vec<&str> {
            reference_drives(&before, 2, most)
                .iter()
                .map(|(d, _)| *d)
                .collect()
        };
        assert_eq!(got(6), ["d1", "d2", "d3", "d4", "d6"]);
        assert_eq!(got(3), ["d1", "d2", "d3"]);
        assert!(got(0).is_empty());
        assert!(reference_drives(&before[..2], 2, 6).is_empty());
    }

    /// By hand: the drives before a drive, newest first; without times in the order checked,
    /// with times by when driven and only those driven before; a drive without a fit, one
    /// sharing a record with the drive checked, and a second drive of the same records are left
    /// out.
    #[test]
    fn the_earlier_drives_of_a_spring_trend_by_hand() {
        let c = vec![
            stored("mon", None, true, &["a", "b"]),
            stored("tue", None, false, &["c", "d"]),
            stored("wed", None, true, &["e", "f"]),
            stored("wed again", None, true, &["f", "e"]),
            stored("thu", None, true, &["g", "h"]),
            stored("today, checked before", None, true, &["x", "h2"]),
        ];
        // The drive checked holds record "x": the drive that shares it is not earlier.
        let got = earlier_fits(&c, &["x", "y"], None);
        assert_eq!(ids(&got), ["thu", "wed again", "mon"]);
        // With times: by when driven, and only those before the drive's start.
        let t = vec![
            stored("late", Some(500.0), true, &["a"]),
            stored("first", Some(100.0), true, &["b"]),
            stored("second", Some(200.0), true, &["c"]),
            stored("after", Some(900.0), true, &["d"]),
        ];
        assert_eq!(
            ids(&earlier_fits(&t, &["z"], Some(600.0))),
            ["late", "second", "first"]
        );
        assert_eq!(ids(&earlier_fits(&t, &["z"], Some(150.0))), ["first"]);
        // One drive without a time: all in the order checked.
        let mut u = t.clone();
        u.push(stored("untimed", None, true, &["e"]));
        assert_eq!(
            ids(&earlier_fits(&u, &["z"], Some(150.0))),
            ["untimed", "after", "second", "first", "late"]
        );
        assert!(earlier_fits(&[], &["z"], None).is_empty());
    }

    /// By hand: 2026-11-27 is day 20784 after 1970-01-01.
    #[test]
    fn the_day_of_a_start_by_hand() {
        let midnight = 20784.0 * 86400.0;
        assert_eq!(drive_of_day(midnight).as_deref(), Some("2026-11-27"));
        assert_eq!(drive_of_day(midnight - 0.25).as_deref(), Some("2026-11-26"));
        assert_eq!(
            drive_of_day(midnight + 86399.9).as_deref(),
            Some("2026-11-27")
        );
        assert_eq!(drive_of_day(0.0).as_deref(), Some("1970-01-01"));
        assert_eq!(drive_of_day(f64::NAN), None);
        assert_eq!(drive_of_day(1e300), None);
    }

    #[test]
    fn records_are_grouped_by_day_where_every_start_is_known() {
        let day = |d: f64, h: f64| Some((20784.0 + d) * 86400.0 + h * 3600.0);
        let id = |s: &str| s.to_string();
        // Two days of 3, one of 1 (left out), in the order of the dates.
        let starts = [
            day(1.0, 8.0),
            day(0.0, 8.0),
            day(1.0, 9.0),
            day(2.0, 1.0),
            day(0.0, 23.9),
            day(1.0, 0.1),
            day(0.0, 0.0),
        ];
        let files = ["d/r1.csv"; 7];
        assert_eq!(
            drives_of_records(&starts, &files),
            vec![
                (id("2026-11-27"), vec![1, 4, 6]),
                (id("2026-11-28"), vec![0, 2, 5])
            ]
        );
        // One unknown start: all together, as without dates.
        let mut some = starts.to_vec();
        some[3] = None;
        assert_eq!(
            drives_of_records(&some, &files),
            vec![(id("d"), (0..7).collect())]
        );
        assert_eq!(drives_of_records(&[None, None], &files[..2]), vec![]);
        assert_eq!(
            drives_of_records(&[day(0.0, 1.0), day(0.0, 2.0)], &files[..2]),
            vec![]
        );
        assert_eq!(drives_of_records(&[], &[]), vec![]);
    }

    /// The baseline's drives: by day where every start is known (small days kept: they stay in
    /// every held-out model set), else one per folder as given, sorted by id.
    #[test]
    fn nominal_records_are_grouped_by_day_else_by_folder() {
        let day = |d: f64, h: f64| Some((20784.0 + d) * 86400.0 + h * 3600.0);
        let id = |s: &str| s.to_string();
        let files = [
            "tue/r1.csv",
            "mon/r1.csv",
            "tue/r2.csv",
            "r3.csv",
            "./r4.csv",
            "mon/r2.csv",
        ];
        let dated = [
            day(1.0, 8.0),
            day(0.0, 8.0),
            day(1.0, 9.0),
            day(2.0, 1.0),
            day(0.0, 9.0),
            day(0.0, 10.0),
        ];
        assert_eq!(
            nominal_drives(&dated, &files),
            vec![
                (id("2026-11-27"), vec![1, 4, 5]),
                (id("2026-11-28"), vec![0, 2]),
                (id("2026-11-29"), vec![3]),
            ]
        );
        let mut undated = dated.to_vec();
        undated[2] = None;
        assert_eq!(
            nominal_drives(&undated, &files),
            vec![
                (id(DEFAULT_DRIVE_ID), vec![3, 4]),
                (id("mon"), vec![1, 5]),
                (id("tue"), vec![0, 2]),
            ]
        );
        assert_eq!(nominal_drives::<&str>(&[], &[]), vec![]);
    }

    /// A drive of records of unknown start is named by the one folder they lie in, as given.
    #[test]
    fn a_drive_without_dates_is_named_by_its_folder() {
        assert_eq!(drive_of_folder(&["a/b/r1.csv", "a/b/r2.csv"]), "a/b");
        assert_eq!(
            drive_of_folder(&["/data/2026-11-26/r.wav"]),
            "/data/2026-11-26"
        );
        for other in [
            &["a/r1.csv", "b/r2.csv"][..],
            &["r1.csv", "r2.csv"],
            &["./r1.csv", "./r2.csv"],
            &["a/r1.csv", "r2.csv"],
            &[],
        ] {
            assert_eq!(drive_of_folder(other), DEFAULT_DRIVE_ID, "{other:?}");
        }
    }
}
