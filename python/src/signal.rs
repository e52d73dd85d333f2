//! Reading and writing recordings, and the ideal DFT resampling (`vibmode-signal`).

use numpy::ndarray::Array2;
use numpy::{IntoPyArray, PyArray2, PyReadonlyArray2, PyUntypedArrayMethods};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use rayon::prelude::*;
use std::path::PathBuf;
use vibmode_core::{Channel, ChannelSelector, Placement, Recording};
use vibmode_signal::{Format, ReadOptions, ResampleParams, Resampler, SignalError};

use crate::errors::{json_err, signal_err, value_err};

/// Registers the functions of this module.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(read, m)?)?;
    m.add_function(wrap_pyfunction!(info, m)?)?;
    m.add_function(wrap_pyfunction!(write, m)?)?;
    m.add_function(wrap_pyfunction!(time_column_scale, m)?)?;
    m.add_function(wrap_pyfunction!(resample_rows, m)?)?;
    Ok(())
}

/// A recording as Python sees it: data (channels, samples), rate (Hz), names, units,
/// placements (JSON list) and the first sample's Unix time (s, UTC) when the file told it.
pub type PyRecording<'py> = (
    Bound<'py, PyArray2<f64>>,
    f64,
    Vec<String>,
    Vec<String>,
    String,
    Option<f64>,
);

/// The Python form of a recording.
pub fn to_py<'py>(py: Python<'py>, rec: &Recording) -> PyResult<PyRecording<'py>> {
    let n = rec.len();
    let mut data = Vec::with_capacity(n * rec.channels.len());
    for c in &rec.channels {
        data.extend_from_slice(&c.samples);
    }
    let arr = Array2::from_shape_vec((rec.channels.len(), n), data).map_err(value_err)?;
    let placements: Vec<&Placement> = rec.channels.iter().map(|c| &c.placement).collect();
    Ok((
        arr.into_pyarray(py),
        rec.fs_hz,
        rec.channels.iter().map(|c| c.name.clone()).collect(),
        rec.channels.iter().map(|c| c.unit.clone()).collect(),
        serde_json::to_string(&placements).map_err(json_err)?,
        rec.time_axis.as_ref().and_then(|t| t.start_unix_s()),
    ))
}

/// A recording from its Python form (`placements` may be empty: unknown).
pub fn from_py(
    data: &PyReadonlyArray2<'_, f64>,
    fs: f64,
    names: &[String],
    units: &[String],
    placements: Option<&str>,
) -> PyResult<Recording> {
    let shape = data.shape();
    let (r, n) = (shape[0], shape[1]);
    if names.len() != r || units.len() != r {
        return Err(PyValueError::new_err(format!(
            "{r} channels but {} names and {} units; give one name and unit per row",
            names.len(),
            units.len()
        )));
    }
    let placements: Vec<Placement> = match placements {
        Some(p) if !p.is_empty() => serde_json::from_str(p).map_err(value_err)?,
        _ => vec![Placement::default(); r],
    };
    let view = data.as_array();
    let channels = (0..r)
        .map(|i| {
            let mut c = Channel::new(
                names[i].clone(),
                units[i].clone(),
                view.row(i).iter().copied().collect::<Vec<f64>>(),
            );
            if let Some(p) = placements.get(i) {
                c.placement = *p;
            }
            c
        })
        .collect();
    debug_assert!(n == 0 || r > 0);
    Recording::new(fs, channels).map_err(value_err)
}

/// The file-reading options every reading function takes, as the command line's shared input
/// options (`--fs --scale --unit --time-unit --resample-nonuniform`): one mapping to
/// [`ReadOptions`].
pub fn read_options(
    fs: Option<f64>,
    scale: f64,
    unit: Option<String>,
    allow_nonuniform: bool,
    time_unit: Option<&str>,
) -> PyResult<ReadOptions> {
    let time_scale_s = match time_unit {
        Some(u) => Some(vibmode_signal::time_unit_scale(u).map_err(signal_err)?),
        None => None,
    };
    Ok(ReadOptions {
        fs_hz: fs,
        scale,
        unit,
        allow_nonuniform,
        time_scale_s,
        ..ReadOptions::default()
    })
}

/// Reads a recording (delimited text, WAV, raw + JSON sidecar).
#[pyfunction]
#[pyo3(signature = (path, fs=None, scale=1.0, unit=None, allow_nonuniform=false, format=None, channels=None, time_unit=None))]
#[allow(clippy::too_many_arguments)]
fn read<'py>(
    py: Python<'py>,
    path: PathBuf,
    fs: Option<f64>,
    scale: f64,
    unit: Option<String>,
    allow_nonuniform: bool,
    format: Option<&str>,
    channels: Option<Vec<String>>,
    time_unit: Option<&str>,
) -> PyResult<PyRecording<'py>> {
    let format = match format {
        Some(f) => Some(f.parse::<Format>().map_err(signal_err)?),
        None => None,
    };
    let opts = ReadOptions {
        format,
        ..read_options(fs, scale, unit, allow_nonuniform, time_unit)?
    };
    let rec = py
        .detach(|| {
            let rec = vibmode_signal::read_path(&path, &opts)?;
            select(rec, channels.as_deref())
        })
        .map_err(signal_err)?;
    to_py(py, &rec)
}

/// What each file holds (`vibmode_signal::summarize`, folders expanded), as the JSON array
/// `vibmode info --json` prints.
#[pyfunction]
#[pyo3(signature = (paths, fs=None, scale=1.0, unit=None, allow_nonuniform=false, time_unit=None))]
fn info(
    py: Python<'_>,
    paths: Vec<PathBuf>,
    fs: Option<f64>,
    scale: f64,
    unit: Option<String>,
    allow_nonuniform: bool,
    time_unit: Option<&str>,
) -> PyResult<String> {
    let opts = read_options(fs, scale, unit, allow_nonuniform, time_unit)?;
    let all = py
        .detach(|| {
            vibmode_signal::expand_folders(&paths)?
                .iter()
                .map(|p| vibmode_signal::summarize(p, &opts))
                .collect::<Result<Vec<_>, _>>()
        })
        .map_err(signal_err)?;
    serde_json::to_string(&all).map_err(json_err)
}

/// The channels `sel` (names or 0-based indices) of `rec`; all when `None` or empty.
pub fn select(rec: Recording, sel: Option<&[String]>) -> Result<Recording, SignalError> {
    match sel {
        Some(s) if !s.is_empty() => {
            let sel = s
                .iter()
                .map(|t| t.parse::<ChannelSelector>())
                .collect::<Result<Vec<_>, _>>()?;
            Ok(rec.select(&sel)?)
        }
        _ => Ok(rec),
    }
}

/// Seconds per unit of the time column a column name names (the file reader's rule), or None.
#[pyfunction]
fn time_column_scale(name: &str) -> Option<f64> {
    vibmode_signal::delimited::time_column_scale(name)
}

/// Writes a recording; the format follows the extension (.csv, .wav, .f32/.f64 + sidecar).
#[pyfunction]
#[pyo3(signature = (path, data, fs, names, units, placements=None))]
fn write(
    py: Python<'_>,
    path: PathBuf,
    data: PyReadonlyArray2<'_, f64>,
    fs: f64,
    names: Vec<String>,
    units: Vec<String>,
    placements: Option<&str>,
) -> PyResult<()> {
    let rec = from_py(&data, fs, &names, &units, placements)?;
    py.detach(|| vibmode_signal::write_path(&path, &rec))
        .map_err(signal_err)
}

/// Ideal DFT low-pass and resampling of every row: `(y (rows, n_out), fs_out_hz)`.
#[pyfunction]
#[pyo3(signature = (x, fs, fs_out, cutoff_hz, filter))]
fn resample_rows<'py>(
    py: Python<'py>,
    x: PyReadonlyArray2<'py, f64>,
    fs: f64,
    fs_out: f64,
    cutoff_hz: Option<f64>,
    filter: bool,
) -> PyResult<(Bound<'py, PyArray2<f64>>, f64)> {
    let shape = x.shape();
    let (r, n) = (shape[0], shape[1]);
    let data = x
        .as_slice()
        .map_err(|_| PyValueError::new_err("x must be C-contiguous (internal)"))?;
    let p = ResampleParams {
        fs_out_hz: fs_out,
        cutoff_hz,
        filter,
    };
    let plan = Resampler::new(n, fs, &p).map_err(signal_err)?;
    let n_out = plan.n_out();
    let fs_real = plan.fs_out_hz();
    let mut out = vec![0.0; r * n_out];
    if n_out > 0 && r > 0 {
        py.detach(|| {
            out.par_chunks_mut(n_out).enumerate().try_for_each_init(
                || Resampler::new(n, fs, &p),
                |plan, (i, o)| {
                    let plan = plan.as_mut().map_err(|e| SignalError::InvalidParam {
                        name: "resampler",
                        value: e.to_string(),
                        fix: "internal".to_string(),
                    })?;
                    plan.process(&data[i * n..(i + 1) * n], o)
                },
            )
        })
        .map_err(signal_err)?;
    }
    let y = Array2::from_shape_vec((r, n_out), out).map_err(value_err)?;
    Ok((y.into_pyarray(py), fs_real))
}
