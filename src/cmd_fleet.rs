//! `vibmode fleet`: fleet monitoring on an SQLite store (init, ingest, baseline, check, status).

use anyhow::Result;
use clap::{Args, Subcommand};
use std::path::PathBuf;
use vibmode_fleet::{
    build_baseline, check_drive_files_progress, ingest_files_progress, require_baseline, Condition,
    FleetConfig, IngestLabels, Store,
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
    /// more, one drive named by the folder they lie in (`all given records` when they lie in
    /// several or none; docs/fleet.md, "Drives").
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
    eprint!(
        "{}",
        vibmode_fleet::text::ingest_text(&done, &a.vehicle, condition)
    );
    Ok(())
}

fn register(db: &std::path::Path, vehicle: &str, model: &std::path::Path) -> Result<()> {
    let mut store = Store::open(db)?;
    let done = vibmode_fleet::register_vehicle_model_file(&mut store, vehicle, model)?;
    crate::output::print_stdout(&vibmode_fleet::text::register_text(vehicle, model, done))
}

fn baseline(db: &std::path::Path, vehicle: &str) -> Result<()> {
    let mut store = Store::open(db)?;
    let cfg = store.config()?;
    let set = build_baseline(&mut store, vehicle, &cfg)?;
    crate::output::print_stdout(&vibmode_fleet::text::baseline_text(&set))
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
    let report = vibmode_fleet::CheckReport::new(&store, &a.vehicle, set.version, out, drives)?;
    let text = report.text();
    match a.json.as_deref() {
        Some("-") => {
            eprint!("{text}");
        }
        _ => crate::output::print_stdout(&text)?,
    }
    if let Some(dest) = &a.json {
        crate::output::write_json(dest, &report)?;
    }
    Ok(())
}

fn status(db: &std::path::Path) -> Result<()> {
    let store = Store::open(db)?;
    let st = store.status(5)?;
    crate::output::print_stdout(&vibmode_fleet::text::status_text(&st))
}
