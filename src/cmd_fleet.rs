//! `vibmode fleet`: fleet monitoring on an SQLite store (init, ingest, baseline, check, status).

use anyhow::{bail, Result};
use clap::{Args, Subcommand};
use serde::Serialize;
use std::path::PathBuf;
use vibmode_fleet::{
    build_baseline, check_drive_files_progress, ingest_files_progress, require_baseline, Checked,
    Condition, Drive, FleetConfig, IngestLabels, Store,
};

/// Arguments of `vibmode fleet`.
#[derive(Args, Debug)]
pub struct FleetArgs {
    #[command(subcommand)]
    pub command: FleetCommand,
}

/// The fleet subcommands.
#[derive(Subcommand, Debug)]
pub enum FleetCommand {
    /// Create a fleet store (or confirm an existing one).
    Init {
        /// The store file (SQLite).
        #[arg(long)]
        db: PathBuf,
        /// Settings (TOML; docs/fleet.md): feature bands, false-alarm rate, spread floors and
        /// the per-record analysis under `[analysis]`. Fixed once the first record is stored.
        #[arg(long)]
        config: Option<PathBuf>,
    },
    /// Analyse records and store their features (the same file twice is a no-op).
    #[command(allow_negative_numbers = true)]
    Ingest(IngestArgs),
    /// Register a vehicle's full-car model file (docs/vehicle.md): records ingested or checked
    /// afterwards keep their body equations, and the baseline and each checked drive fit the
    /// suspension (springs and dampers per corner) to them (docs/fleet.md).
    Register {
        /// The store file.
        #[arg(long)]
        db: PathBuf,
        /// Vehicle id (created if new).
        #[arg(long)]
        vehicle: String,
        /// The vehicle's model file (TOML: geometry, masses, tyres, suspension, sensors).
        model: PathBuf,
    },
    /// Build a new nominal model-set version from a vehicle's nominal records.
    Baseline {
        /// The store file.
        #[arg(long)]
        db: PathBuf,
        /// Vehicle id.
        #[arg(long)]
        vehicle: String,
    },
    /// Classify records against the vehicle's latest model set: normal, road, vehicle, both,
    /// or sensor (a dead, stuck, clipped or held channel). All files or none are stored.
    #[command(allow_negative_numbers = true)]
    Check(CheckArgs),
    /// Per vehicle: records, baseline version, last classifications.
    Status {
        /// The store file.
        #[arg(long)]
        db: PathBuf,
    },
    /// HTML report: every vehicle's status, feature trends with the nominal band, flagged
    /// records with their evidence.
    Report {
        /// The store file.
        #[arg(long)]
        db: PathBuf,
        /// Output folder (index.html is written there).
        #[arg(short = 'o', long = "output", default_value = "vibmode-fleet-report")]
        output: PathBuf,
    },
}

/// Arguments of `vibmode fleet ingest`.
#[derive(Args, Debug)]
pub struct IngestArgs {
    /// The store file.
    #[arg(long)]
    pub db: PathBuf,
    /// Vehicle id (created on first ingest).
    #[arg(long)]
    pub vehicle: String,
    /// nominal (healthy runs for the baseline) or test.
    #[arg(long, default_value = "nominal")]
    pub condition: String,
    /// Road label kept with the records (e.g. B, cobbles).
    #[arg(long)]
    pub road: Option<String>,
    #[command(flatten)]
    pub read: crate::input::ReadArgs,
    /// Record files, or folders of them (each folder's recordings, sorted by name).
    #[arg(required = true)]
    pub files: Vec<PathBuf>,
}

/// Arguments of `vibmode fleet check`.
#[derive(Args, Debug)]
pub struct CheckArgs {
    /// The store file.
    #[arg(long)]
    pub db: PathBuf,
    /// Vehicle id.
    #[arg(long)]
    pub vehicle: String,
    /// Write the results as JSON to this file, or `-` for standard output.
    #[arg(long)]
    pub json: Option<String>,
    /// The given records are one drive with this id (at least 3 records), classified from the
    /// medians of their features; without it, records whose time column holds date-times form
    /// one drive per UTC day (named `YYYY-MM-DD`, 3 records or more), and other records, 3 or
    /// more, the drive `all given records` (docs/fleet.md, "Drives").
    #[arg(long)]
    pub drive: Option<String>,
    #[command(flatten)]
    pub read: crate::input::ReadArgs,
    /// Record files, or folders of them (each folder's recordings, sorted by name).
    #[arg(required = true)]
    pub files: Vec<PathBuf>,
}

/// Runs `vibmode fleet ...`.
pub fn run(a: &FleetArgs) -> Result<()> {
    match &a.command {
        FleetCommand::Init { db, config } => {
            // The settings are read and checked before the store is created.
            let cfg = config.as_deref().map(FleetConfig::from_path).transpose()?;
            let (mut store, created) = Store::init(db)?;
            if let Some(cfg) = &cfg {
                store.set_config(cfg)?;
            }
            eprintln!(
                "{} fleet store {} (schema version {})",
                if created { "created" } else { "already a" },
                db.display(),
                store.schema_version()?
            );
            Ok(())
        }
        FleetCommand::Ingest(i) => ingest(i),
        FleetCommand::Register { db, vehicle, model } => register(db, vehicle, model),
        FleetCommand::Baseline { db, vehicle } => baseline(db, vehicle),
        FleetCommand::Check(c) => check(c),
        FleetCommand::Status { db } => status(db),
        FleetCommand::Report { db, output } => {
            let store = Store::open(db)?;
            let out = crate::output::StagedDir::begin(output, std::slice::from_ref(db))?;
            let path = vibmode_fleet::write_fleet_report(&store, out.path())?;
            out.commit()?;
            let name = path
                .file_name()
                .map(|n| n.to_os_string())
                .unwrap_or_default();
            eprintln!("report: {}", output.join(name).display());
            Ok(())
        }
    }
}

fn ingest(a: &IngestArgs) -> Result<()> {
    let mut store = Store::open(&a.db)?;
    let condition: Condition = a.condition.parse()?;
    let labels = IngestLabels {
        vehicle: &a.vehicle,
        condition,
        road: a.road.as_deref(),
    };
    let cfg = store.config()?;
    // All or nothing: every file is read and analysed before any is stored, so nothing is
    // reported as stored unless all were.
    let expanded = vibmode_signal::expand_folders(&a.files)?;
    let files: Vec<&std::path::Path> = expanded.iter().map(|f| f.as_path()).collect();
    let pb = crate::progress::records_bar(Some(files.len() as u64), "files analysed", "files");
    let done = ingest_files_progress(
        &mut store,
        &labels,
        &files,
        &a.read.options()?,
        &cfg,
        &|n| pb.set_position(n as u64),
    );
    pb.finish_and_clear();
    let done = done?;
    // A note every newly stored record has (a sensor layout without a partner channel, say)
    // is printed once, after the list, not under each record.
    let new: Vec<&Vec<String>> = done
        .iter()
        .filter(|r| !r.already_stored)
        .map(|r| &r.notes)
        .collect();
    let common: Vec<&String> = match new.split_first() {
        Some((first, rest)) if !rest.is_empty() => first
            .iter()
            .filter(|n| rest.iter().all(|o| o.contains(n)))
            .collect(),
        _ => Vec::new(),
    };
    let n_new = new.len();
    let own = |r: &'_ vibmode_fleet::Ingested| -> Vec<String> {
        r.notes
            .iter()
            .filter(|n| r.already_stored || !common.contains(n))
            .cloned()
            .collect()
    };
    for r in &done {
        let notes = own(r);
        if r.already_stored && !r.notes.is_empty() {
            eprintln!(
                "{}: already stored for vehicle {} (record {})",
                r.file, a.vehicle, r.record_id
            );
            for n in &notes {
                eprintln!("  note: {n}");
            }
        } else if r.already_stored {
            eprintln!(
                "{}: already stored for vehicle {} (record {}), nothing to do",
                r.file, a.vehicle, r.record_id
            );
        } else {
            eprintln!(
                "{}: stored as {} record {} of vehicle {}",
                r.file, a.condition, r.record_id, a.vehicle
            );
            for n in &notes {
                eprintln!("  note: {n}");
            }
        }
    }
    for n in common {
        eprintln!("note (every one of the {n_new} records stored): {n}");
    }
    Ok(())
}

fn register(db: &std::path::Path, vehicle: &str, model: &std::path::Path) -> Result<()> {
    let mut store = Store::open(db)?;
    let done = vibmode_fleet::register_vehicle_model_file(&mut store, vehicle, model)?;
    let file = model.display();
    let text = match done {
        vibmode_fleet::Registered::New => format!(
            "vehicle {vehicle}: model file {file} registered; records ingested or checked from now on keep their body equations for the suspension fitted per drive (ingest nominal records, then build the baseline)\n"
        ),
        vibmode_fleet::Registered::Unchanged => {
            format!("vehicle {vehicle}: model file {file} already registered (unchanged)\n")
        }
        vibmode_fleet::Registered::Replaced => format!(
            "vehicle {vehicle}: model file {file} registered in place of the one before; records' body equations made with the old file no longer count: ingest nominal records and build a new baseline for the suspension fitted per drive\n"
        ),
    };
    crate::output::print_stdout(&text)
}

fn baseline(db: &std::path::Path, vehicle: &str) -> Result<()> {
    let mut store = Store::open(db)?;
    let cfg = store.config()?;
    let set = build_baseline(&mut store, vehicle, &cfg)?;
    let mut text = format!(
        "vehicle {}: model set version {} from {} nominal records, {} features, {} modes\n",
        set.vehicle,
        set.version,
        set.records.len(),
        set.features.len(),
        set.slots.len()
    );
    text.push_str("kind               features  Bonferroni  LOO max |z|  limit\n");
    for l in &set.limits {
        text.push_str(&format!(
            "{:<18} {:>8}  {:>10.2}  {:>11.2}  {:>5.2}\n",
            format!("{:?}", l.kind),
            l.n_features,
            l.bonferroni,
            l.loo_max_abs_z,
            l.limit
        ));
    }
    if let Some(s) = &set.suspension {
        text.push_str(&format!(
            "suspension fitted to {} nominal records: springs and dampers per corner scored per drive, one-sided limit {:.2}{}\n",
            s.fit.records,
            s.limit,
            if s.fit.supported {
                ""
            } else {
                " (the fit's standard deviations exceed the model update's support limits: the scores use them as they are)"
            }
        ));
        for (i, c) in vibmode_fleet::suspension::CORNERS.iter().enumerate() {
            text.push_str(&format!(
                "  {c}: spring {:.1} kN/m (sd {:.1} %), damper {:.2} kN s/m (sd {:.1} %)\n",
                s.fit.spring_n_per_m[i] / 1e3,
                100.0 * s.fit.spring_rel_sd[i],
                s.fit.damper_n_s_per_m[i] / 1e3,
                100.0 * s.fit.damper_rel_sd[i]
            ));
        }
    }
    for n in &set.notes {
        text.push_str(&format!("note: {n}\n"));
    }
    crate::output::print_stdout(&text)
}

#[derive(Serialize)]
struct CheckJson<'a> {
    vehicle: &'a str,
    model_version: i64,
    records: &'a [Checked],
    drives: Vec<&'a Drive>,
}

fn check(a: &CheckArgs) -> Result<()> {
    let files = vibmode_signal::expand_folders(&a.files)?;
    // The store is an input too: JSON written over it would destroy it.
    let inputs: Vec<&std::path::Path> = std::iter::once(a.db.as_path())
        .chain(files.iter().map(|f| f.as_path()))
        .collect();
    crate::output::check_json_dest(a.json.as_deref(), &inputs)?;
    let mut store = Store::open(&a.db)?;
    store.require_vehicle(&a.vehicle)?;
    let set = require_baseline(&store, &a.vehicle)?;
    // All or nothing: every file is read and scored before any record or check is stored.
    let pb = crate::progress::records_bar(Some(files.len() as u64), "files analysed", "files");
    let out = check_drive_files_progress(
        &mut store,
        &set,
        &files.iter().map(|f| f.as_path()).collect::<Vec<_>>(),
        &a.read.options()?,
        a.drive.as_deref(),
        &|n| pb.set_position(n as u64),
    );
    pb.finish_and_clear();
    let (out, drives) = out?;
    let mut text = format!(
        "vehicle {} against model set version {}\nfile                            class     vehicle |z|  road score  evidence\n",
        a.vehicle, set.version
    );
    for c in &out {
        text.push_str(&format!(
            "{:<31} {:<9} {:>11.1}  {:>10.1}  {}\n",
            c.file,
            c.assessment.classification.to_string(),
            c.assessment.scores.vehicle_max_abs_z,
            c.assessment.scores.excitation_max_abs_z,
            if c.assessment.summary.is_empty() {
                "-"
            } else {
                &c.assessment.summary
            }
        ));
    }
    // A record of the baseline checked against it is scored by a yardstick made from itself.
    for c in &out {
        if let Some(first) = &c.same_as {
            text.push_str(&format!(
                "note: {} has the content of {}, given before it: counted once in a drive\n",
                c.file, first
            ));
        }
        if let Some(twin) = &c.in_baseline {
            text.push_str(&format!(
                "note: {} has the content of {}, a record model set version {} was built from: not an independent check\n",
                c.file, twin, c.model_version
            ));
        }
    }
    for d in &drives {
        text.push_str(&format!(
            "drive {} ({} records, median of each feature; false alarms per drive at most {} %): {}{}  {}\n",
            d.drive,
            d.records.len(),
            100.0 * d.false_alarm_rate,
            d.assessment.classification,
            match (d.corner, d.assessment.component) {
                (Some(c), Some(k)) => format!(" ({c} {k})"),
                (Some(c), None) => format!(" ({c})"),
                _ => String::new(),
            },
            if d.assessment.summary.is_empty() {
                "-"
            } else {
                &d.assessment.summary
            }
        ));
        // Why the suspension was not fitted to the drive, when the vehicle has a model file or
        // the model set a fitted suspension: not a silent absence.
        for m in d
            .assessment
            .missing
            .iter()
            .filter(|m| m.starts_with("suspension fit:"))
        {
            text.push_str(&format!("  note: {m}\n"));
        }
        if !d.in_baseline.is_empty() {
            text.push_str(&format!(
                "  note: {} of the drive's {} records are records of the baseline ({}): its verdict leans toward normal; check records the baseline was not built from\n",
                d.in_baseline.len(),
                d.records.len(),
                vibmode_core::cap_message(&d.in_baseline.join(", "), 120)
            ));
        }
    }
    match a.json.as_deref() {
        Some("-") => {
            eprint!("{text}");
        }
        _ => crate::output::print_stdout(&text)?,
    }
    if let Some(dest) = &a.json {
        crate::output::write_json(
            dest,
            &CheckJson {
                vehicle: &a.vehicle,
                model_version: set.version,
                records: &out,
                drives: drives.iter().collect(),
            },
        )?;
    }
    Ok(())
}

fn status(db: &std::path::Path) -> Result<()> {
    let store = Store::open(db)?;
    let st = store.status(5)?;
    if st.is_empty() {
        bail!(
            "the store {} has no vehicle yet; ingest nominal records first (vibmode fleet ingest --vehicle ID)",
            db.display()
        );
    }
    // One row per vehicle first: its latest drive verdict, the corner, since when, how sure.
    let mut text = String::from(
        "vehicle          latest drive verdict  corner, component  since                 |z|/limit  drive\n",
    );
    for v in &st {
        match &v.latest_drive {
            Some(d) => text.push_str(&format!(
                "{:<16} {:<21} {:<18} {:<21} {:>9}  {} ({} records, false alarms <= {} per drive)\n",
                v.vehicle,
                d.classification.to_string(),
                d.place(),
                d.since,
                d.vehicle_z_over_limit
                    .map_or("-".to_string(), |z| format!("{z:.2}")),
                d.drive,
                d.n_records,
                d.false_alarm_rate
            )),
            None => text.push_str(&format!("{:<16} no drive checked yet\n", v.vehicle)),
        }
    }
    text.push('\n');
    for v in &st {
        text.push_str(&format!(
            "vehicle {}: {} nominal, {} test records, baseline {}\n",
            v.vehicle,
            v.n_nominal,
            v.n_test,
            v.baseline_version
                .map_or("none".to_string(), |n| format!("version {n}"))
        ));
        if let Some(s) = &v.suspension {
            text.push_str(&format!("  {s}\n"));
        }
        if !v.drives.is_empty() {
            text.push_str("  drives, newest first (when driven; when checked where the records' times are unknown):\n");
            for d in &v.drives {
                text.push_str(&format!(
                    "    {:<28} {:<8} {:<15} {} {}\n",
                    d.when(),
                    d.classification.to_string(),
                    d.place(),
                    d.drive,
                    d.summary
                ));
            }
            text.push_str("  records, newest first:\n");
        }
        for (file, class, summary) in &v.last_checks {
            text.push_str(&format!(
                "  {file:<31} {:<8} {summary}\n",
                class.to_string()
            ));
        }
    }
    crate::output::print_stdout(&text)
}
