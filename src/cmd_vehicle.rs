//! `vibmode fullcar` and `vibmode simulate`: the physical model and the measurement simulator.

use crate::output::write_json;
use anyhow::{bail, Context, Result};
use clap::{Args, ValueEnum};
use serde::Serialize;
use std::path::{Path, PathBuf};
use vibmode_vehicle::{FullCar, ModeInfo, RoadClass, SimParams, Simulation, VehicleParams};

/// Arguments of `vibmode fullcar`.
#[derive(Args, Debug)]
pub struct FullcarArgs {
    /// Vehicle parameter file (TOML, see docs/vehicle.md and examples/city_bus.toml).
    pub params: PathBuf,
    /// Write the modes as JSON to this path (`-` for standard output).
    #[arg(long)]
    pub json: Option<String>,
}

#[derive(Serialize)]
struct FullcarOutput {
    source: String,
    modes: Vec<ModeInfo>,
}

/// Runs `vibmode fullcar`.
pub fn run_fullcar(a: &FullcarArgs) -> Result<()> {
    crate::output::check_json_dest(a.json.as_deref(), &[a.params.as_path()])?;
    let params = VehicleParams::from_path(&a.params)?;
    let car = FullCar::new(&params)?;
    let modes = car.modes()?;
    let out = FullcarOutput {
        source: a.params.display().to_string(),
        modes,
    };
    match &a.json {
        Some(dest) => write_json(dest, &out)?,
        None => {
            let mut text = format!(
                "Modes of {}:\n  {:>10} {:>14} {:>12}  label\n",
                out.source, "freq_hz", "damping_ratio", "damped_hz"
            );
            for m in &out.modes {
                text += &format!(
                    "  {:>10.3} {:>14.4} {:>12.3}  {}\n",
                    m.frequency_hz, m.damping_ratio, m.damped_frequency_hz, m.label
                );
            }
            crate::output::print_stdout(&text)?;
        }
    }
    Ok(())
}

/// Non-road effects of the simulation.
#[derive(ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum Effects {
    /// Pure road response: no engine lines, noise, bias, tones or manoeuvres.
    None,
    /// A bus in service: engine/gear lines (7, 11, 12 Hz), sensor noise and bias, tones at
    /// 150 Hz, 1.3 kHz and 6 kHz, braking, acceleration and a turn.
    InService,
}

/// File format of simulated records.
#[derive(ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum RecordFormat {
    /// 32-bit float WAV (compact; every channel; rate in the header).
    Wav,
    /// CSV with a time_s column (large at 20 kHz).
    Csv,
    /// Raw little-endian f32 with a JSON sidecar.
    F32,
}

/// Arguments of `vibmode simulate`.
#[derive(Args, Debug)]
pub struct SimulateArgs {
    /// Vehicle parameter file (TOML).
    pub params: PathBuf,
    /// ISO 8608 road class, A (very good) to H (very poor).
    #[arg(long, default_value_t = SimParams::default().road.to_string())]
    pub road: String,
    /// Vehicle speed, km/h (1 to 500; also the cruising speed of --gps-track).
    #[arg(long = "speed-kmh", default_value_t = SimParams::default().speed_kmh)]
    pub speed_kmh: f64,
    /// Length of each record, s.
    #[arg(long = "duration-s", default_value_t = SimParams::default().duration_s)]
    pub duration_s: f64,
    /// Number of records (successive segments of one drive).
    #[arg(long, default_value_t = SimParams::default().records)]
    pub records: usize,
    /// Sampling rate, Hz (a whole number for --format wav).
    #[arg(long = "fs", default_value_t = SimParams::default().fs_hz)]
    pub fs_hz: f64,
    /// Random seed: the same seed gives the same bytes.
    #[arg(long, default_value_t = SimParams::default().seed)]
    pub seed: u64,
    /// Non-road effects.
    #[arg(long, value_enum, default_value_t = Effects::InService)]
    pub effects: Effects,
    /// File format of the records.
    #[arg(long, value_enum, default_value_t = RecordFormat::Wav)]
    pub format: RecordFormat,
    /// Output folder: record_01.wav ... and truth.json.
    #[arg(short = 'o', long = "output")]
    pub output: PathBuf,
    /// Also write a GPS track of a city drive (stops, turns, speed changes; cruising at about
    /// --speed-kmh) as long as all the records together, starting at 2024-05-02T07:31:00Z:
    /// track.gpx, track.nmea, track.csv and the true phases in drive_truth.json.
    #[arg(long = "gps-track")]
    pub gps_track: bool,
}

/// Simulation settings from the command-line values.
pub fn sim_params(
    road: &str,
    speed_kmh: f64,
    duration_s: f64,
    records: usize,
    fs_hz: f64,
    seed: u64,
    effects: Effects,
) -> Result<SimParams> {
    let road: RoadClass = road.parse()?;
    let base = match effects {
        Effects::None => SimParams::default(),
        Effects::InService => SimParams::in_service(),
    };
    let p = SimParams {
        road,
        speed_kmh,
        duration_s,
        records,
        fs_hz,
        seed,
        ..base
    };
    p.validate()?;
    // At low speeds the in-service braking is softened so the vehicle keeps moving (from 11 km/h
    // up it is unchanged).
    let p = p.manoeuvres_fitted_to_speed();
    Ok(p)
}

/// Writes the records and truth.json of a simulation into `dir`, which must exist.
pub fn write_simulation(
    dir: &Path,
    sim: &Simulation,
    format: RecordFormat,
) -> Result<Vec<PathBuf>> {
    let ext = match format {
        RecordFormat::Wav => "wav",
        RecordFormat::Csv => "csv",
        RecordFormat::F32 => "f32",
    };
    let mut paths = Vec::new();
    for (i, r) in sim.records.iter().enumerate() {
        let name = format!("record_{:02}.{ext}", i + 1);
        let path = dir.join(&name);
        // Named without the hidden staging folder it is written in.
        vibmode_signal::write_path(&path, &r.recording)
            .with_context(|| format!("writing {name}"))?;
        paths.push(path);
    }
    write_json(&dir.join("truth.json").to_string_lossy(), &sim.truth)?;
    Ok(paths)
}

/// Runs `vibmode simulate`.
pub fn run_simulate(a: &SimulateArgs) -> Result<()> {
    if a.records == 0 {
        bail!("--records 0: give at least one record");
    }
    if a.format == RecordFormat::Wav && a.fs_hz.is_finite() && a.fs_hz.fract() != 0.0 {
        bail!(
            "--fs {}: WAV stores a whole number of Hz; give a whole rate such as --fs {} or write --format csv or f32",
            vibmode_core::Num(a.fs_hz),
            vibmode_core::Num(a.fs_hz.round().max(1.0))
        );
    }
    let vehicle = VehicleParams::from_path(&a.params)?;
    let p = sim_params(
        &a.road,
        a.speed_kmh,
        a.duration_s,
        a.records,
        a.fs_hz,
        a.seed,
        a.effects,
    )?;
    let out = crate::output::StagedDir::begin(&a.output, std::slice::from_ref(&a.params))?;
    let sim = vibmode_vehicle::simulate(&vehicle, &p)?;
    let paths = write_simulation(out.path(), &sim, a.format)?;
    if a.gps_track {
        let drive = vibmode_vehicle::drive::simulate_drive(&vibmode_vehicle::drive::DriveParams {
            cruise_kmh: a.speed_kmh,
            ..vibmode_vehicle::drive::DriveParams::new(a.duration_s * a.records as f64, a.seed)
        });
        for (name, text) in [
            ("track.gpx", drive.to_gpx()),
            ("track.nmea", drive.to_nmea()),
            ("track.csv", drive.to_csv()),
            (
                "drive_truth.json",
                serde_json::to_string_pretty(&drive)? + "\n",
            ),
        ] {
            let path = out.path().join(name);
            std::fs::write(&path, text).with_context(|| format!("writing {name}"))?;
        }
        eprintln!(
            "wrote a {:.0} s GPS track (track.gpx, track.nmea, track.csv) and its true phases (drive_truth.json)",
            a.duration_s * a.records as f64
        );
    }
    out.commit()?;
    eprintln!(
        "wrote {} record(s) of {} s at {} Hz and truth.json to {}",
        paths.len(),
        a.duration_s,
        a.fs_hz,
        a.output.display()
    );
    Ok(())
}
