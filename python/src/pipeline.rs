//! The whole analysis (`vibmode-analysis`), the full-car model and the simulator
//! (`vibmode-vehicle`).

use numpy::PyReadonlyArray2;
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::{PyList, PyTuple};
use std::path::PathBuf;
use vibmode_analysis::{cut_records, AnalysisConfig, ConfigText, Preset, RecordInput};
use vibmode_vehicle::{FullCar, RoadClass, SimParams, VehicleParams};

use crate::errors::{analysis_err, json_err, signal_err, value_err, vehicle_err};
use crate::signal::{from_py, select, to_py, PyRecording};

/// Registers the functions of this module.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(analysis_config, m)?)?;
    m.add_function(wrap_pyfunction!(analyze, m)?)?;
    m.add_function(wrap_pyfunction!(fullcar_modes, m)?)?;
    m.add_function(wrap_pyfunction!(simulate, m)?)?;
    m.add_function(wrap_pyfunction!(simulate_defaults, m)?)?;
    m.add_function(wrap_pyfunction!(json_to_toml, m)?)?;
    Ok(())
}

/// The defaults of `simulate` (`SimParams::default()`, as `vibmode simulate`'s), as JSON with
/// Python's argument names, so that Python copies no number.
#[pyfunction]
fn simulate_defaults() -> PyResult<String> {
    let d = SimParams::default();
    serde_json::to_string(&serde_json::json!({
        "road": d.road.to_string(),
        "speed_kmh": d.speed_kmh,
        "duration_s": d.duration_s,
        "records": d.records,
        "fs": d.fs_hz,
        "seed": d.seed,
    }))
    .map_err(json_err)
}

/// TOML text from JSON text (a Python dict given as settings); nulls are dropped.
#[pyfunction]
fn json_to_toml(json: &str) -> PyResult<String> {
    let mut v: serde_json::Value = serde_json::from_str(json).map_err(value_err)?;
    drop_nulls(&mut v);
    let t: toml::Value = serde_json::from_value(v)
        .map_err(|e| PyValueError::new_err(format!("settings cannot be written as TOML: {e}")))?;
    toml::to_string(&t)
        .map_err(|e| PyValueError::new_err(format!("settings cannot be written as TOML: {e}")))
}

/// Removes `null` values (TOML has none; a missing key takes the default).
fn drop_nulls(v: &mut serde_json::Value) {
    match v {
        serde_json::Value::Object(m) => {
            m.retain(|_, x| !x.is_null());
            m.values_mut().for_each(drop_nulls);
        }
        serde_json::Value::Array(a) => a.iter_mut().for_each(drop_nulls),
        _ => {}
    }
}

/// The analysis settings from TOML text (merged over its preset) or a preset name; as JSON.
#[pyfunction]
#[pyo3(signature = (toml_text=None, preset=None))]
fn analysis_config(toml_text: Option<&str>, preset: Option<&str>) -> PyResult<String> {
    let cfg = config_of(toml_text, preset)?;
    serde_json::to_string(&cfg).map_err(json_err)
}

fn config_of(toml_text: Option<&str>, preset: Option<&str>) -> PyResult<AnalysisConfig> {
    let preset = preset
        .map(str::parse::<Preset>)
        .transpose()
        .map_err(analysis_err)?;
    AnalysisConfig::load(toml_text.map(ConfigText::Text), preset).map_err(analysis_err)
}

/// Vehicle parameters from a file path, TOML text, or a shipped model's name.
fn vehicle_of(kind: &str, value: &str) -> PyResult<VehicleParams> {
    match kind {
        "path" => VehicleParams::from_path(value).map_err(vehicle_err),
        "toml" => VehicleParams::from_toml_str(value).map_err(vehicle_err),
        "builtin" => match value {
            "city_bus" => Ok(VehicleParams::city_bus()),
            "city_bus_flexible" => Ok(VehicleParams::city_bus_flexible()),
            "passenger_car" => Ok(VehicleParams::passenger_car()),
            other => Err(PyValueError::new_err(format!(
                "unknown vehicle '{other}'; shipped models: city_bus, city_bus_flexible, passenger_car (or give a TOML file, TOML text or a dict)"
            ))),
        },
        other => Err(PyValueError::new_err(format!(
            "vehicle kind '{other}' (internal)"
        ))),
    }
}

/// Modes of the full-car model, as JSON (a list of `ModeInfo`).
#[pyfunction]
fn fullcar_modes(py: Python<'_>, kind: &str, value: &str) -> PyResult<String> {
    let params = vehicle_of(kind, value)?;
    let modes = py
        .detach(|| FullCar::new(&params).and_then(|car| car.modes()))
        .map_err(vehicle_err)?;
    serde_json::to_string(&modes).map_err(json_err)
}

/// Runs the analysis of `inputs`: each a file path (str) or a tuple
/// `(name, data (channels, samples), fs_hz, names, units, placements_json)`.
/// Files are cut into records of `record_length_s`. Returns results.json's text.
#[pyfunction]
#[pyo3(signature = (inputs, config_toml=None, preset=None, fs=None, scale=1.0, unit=None, channels=None, vehicle_kind=None, vehicle=None, allow_nonuniform=false, time_unit=None))]
#[allow(clippy::too_many_arguments)]
fn analyze(
    py: Python<'_>,
    inputs: &Bound<'_, PyList>,
    config_toml: Option<&str>,
    preset: Option<&str>,
    fs: Option<f64>,
    scale: f64,
    unit: Option<String>,
    channels: Option<Vec<String>>,
    vehicle_kind: Option<&str>,
    vehicle: Option<&str>,
    allow_nonuniform: bool,
    time_unit: Option<&str>,
) -> PyResult<String> {
    let cfg = config_of(config_toml, preset)?;
    let opts = crate::signal::read_options(fs, scale, unit, allow_nonuniform, time_unit)?;
    let all_paths: Option<Vec<PathBuf>> = inputs
        .iter()
        .map(|item| item.extract::<PathBuf>().ok())
        .collect();
    let selectors: Vec<vibmode_signal::ChannelSelector> = channels
        .iter()
        .flatten()
        .map(|c| c.parse::<vibmode_signal::ChannelSelector>())
        .collect::<Result<_, _>>()
        .map_err(|e| signal_err(e.into()))?;
    // A folder stands for its recordings, sorted by name (as `vibmode analyze DIR`).
    let paths = all_paths
        .filter(|p| !p.is_empty())
        .map(|p| vibmode_signal::expand_folders(&p))
        .transpose()
        .map_err(signal_err)?;
    let mut records: Vec<RecordInput> = Vec::new();
    for item in inputs.iter().filter(|_| paths.is_none()) {
        if let Ok(t) = item.cast::<PyTuple>() {
            let name: String = t.get_item(0)?.extract()?;
            let data: PyReadonlyArray2<'_, f64> = t.get_item(1)?.extract()?;
            let rate: f64 = t.get_item(2)?.extract()?;
            let names: Vec<String> = t.get_item(3)?.extract()?;
            let units: Vec<String> = t.get_item(4)?.extract()?;
            let placements: Option<String> = t.get_item(5)?.extract()?;
            let rec = from_py(&data, rate, &names, &units, placements.as_deref())?;
            let rec = select(rec, channels.as_deref()).map_err(signal_err)?;
            records.extend(cut_records(&name, &rec, cfg.record_length_s));
        } else {
            let given: PathBuf = item.extract()?;
            let files =
                vibmode_signal::expand_folders(std::slice::from_ref(&given)).map_err(signal_err)?;
            for path in files {
                let rec = py
                    .detach(|| {
                        let rec = vibmode_signal::read_path(&path, &opts)?;
                        select(rec, channels.as_deref())
                    })
                    .map_err(signal_err)?;
                // The path as given (as the CLI and vibmode.fleet name records), not its base
                // name.
                let name = vibmode_fleet::record_file_name(&path);
                records.extend(cut_records(&name, &rec, cfg.record_length_s));
            }
        }
    }
    if records.is_empty() && paths.is_none() {
        return Err(PyValueError::new_err(
            "no records to analyse; give at least one file or array",
        ));
    }
    let mut run = vibmode_run::Run::new(cfg);
    if let (Some(k), Some(v)) = (vehicle_kind, vehicle) {
        run = run.vehicle(vehicle_of(k, v)?).map_err(run_err)?;
    }
    // Files only: read as streams, as `vibmode analyze` reads them (the same results.json);
    // arrays (or a mix): the records in memory.
    let output = match paths {
        Some(paths) => py.detach(|| {
            run.run(
                vibmode_run::RunInput::files(&paths, &opts, &selectors),
                &vibmode_run::Progress::none(),
            )
        }),
        None => py.detach(|| {
            run.run(
                vibmode_run::RunInput::Records(records),
                &vibmode_run::Progress::none(),
            )
        }),
    }
    .map_err(run_err)?;
    let value = output.to_json().map_err(run_err)?;
    serde_json::to_string(&value).map_err(json_err)
}

/// A run's error as Python's: a file that cannot be read is an OSError, the rest ValueError.
fn run_err(e: vibmode_run::RunError) -> PyErr {
    match e {
        vibmode_run::RunError::Analysis(a) => analysis_err(a),
        vibmode_run::RunError::Signal(s) => signal_err(s),
        vibmode_run::RunError::Vehicle(v) => vehicle_err(v),
        other => PyValueError::new_err(other.to_string()),
    }
}

/// Simulates in-service records of a vehicle: `(records, truth_json)`, each record in the
/// Python form of [`to_py`] plus its start time (s) and mean speed (km/h).
#[pyfunction]
#[pyo3(signature = (kind, value, road, speed_kmh, duration_s, records, fs, seed, effects))]
#[allow(clippy::too_many_arguments, clippy::type_complexity)]
fn simulate<'py>(
    py: Python<'py>,
    kind: &str,
    value: &str,
    road: &str,
    speed_kmh: f64,
    duration_s: f64,
    records: usize,
    fs: f64,
    seed: u64,
    effects: &str,
) -> PyResult<(Vec<(PyRecording<'py>, f64, f64)>, String)> {
    let vehicle = vehicle_of(kind, value)?;
    if records == 0 {
        return Err(PyValueError::new_err(
            "records = 0: give at least one record",
        ));
    }
    let road: RoadClass = road.parse().map_err(vehicle_err)?;
    let base = match effects {
        "none" => SimParams::default(),
        "in-service" | "in_service" => SimParams::in_service(),
        "demo" => SimParams::demo(records, seed),
        other => {
            return Err(PyValueError::new_err(format!(
                "effects = '{other}' is unknown; use 'none', 'in-service' or 'demo'"
            )))
        }
    };
    let p = SimParams {
        road,
        speed_kmh,
        duration_s,
        records,
        fs_hz: fs,
        seed,
        ..base
    };
    p.validate().map_err(vehicle_err)?;
    let sim = py
        .detach(|| vibmode_vehicle::simulate(&vehicle, &p))
        .map_err(vehicle_err)?;
    let truth = serde_json::to_string(&sim.truth).map_err(json_err)?;
    let mut out = Vec::with_capacity(sim.records.len());
    for r in &sim.records {
        out.push((to_py(py, &r.recording)?, r.start_time_s, r.mean_speed_kmh));
    }
    Ok((out, truth))
}
