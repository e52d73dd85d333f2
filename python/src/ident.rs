//! AR / ARMA fits, model spectra and order sweeps (`vibmode-ident`).

use numpy::{IntoPyArray, PyArray1, PyReadonlyArray1};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use serde::Serialize;
use vibmode_core::{BandLimit, PoleFilterParams, SweepModel, SweepParams};
use vibmode_ident::{ArMethod, ArmaModel, ArmaParams, IdentError, ModeSet, Robust};

use crate::errors::{json_err, value_err};

/// Registers the functions of this module.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(fit_arma, m)?)?;
    m.add_function(wrap_pyfunction!(fit_ar, m)?)?;
    m.add_function(wrap_pyfunction!(arma_psd, m)?)?;
    m.add_function(wrap_pyfunction!(sweep, m)?)?;
    m.add_function(wrap_pyfunction!(ident_defaults, m)?)?;
    Ok(())
}

/// The Huber factor of a criterion, `None` for the quadratic one (Python's `robust`).
fn huber_factor(robust: Robust) -> Option<f64> {
    match robust {
        Robust::Huber { factor } => Some(factor),
        Robust::Off => None,
    }
}

/// The defaults of `fit_arma` (a single fit: `ArmaParams::default()`) and `sweep` (the analysis
/// sweep: `SweepParams::default()`), as JSON `{"fit_arma": ..., "sweep": ...}`, so that Python
/// copies no number.
#[pyfunction]
fn ident_defaults() -> PyResult<String> {
    let fit = ArmaParams::default();
    let sweep = SweepParams::default();
    serde_json::to_string(&serde_json::json!({
        "fit_arma": {
            "robust": huber_factor(fit.robust),
            "max_iterations": fit.max_iterations,
            "tolerance": fit.tolerance,
            "demean": fit.demean,
        },
        "sweep": {
            "order_min": sweep.order_min,
            "order_max": sweep.order_max,
            "robust": huber_factor(sweep.robust),
            "max_iterations": sweep.max_iterations,
            "tolerance": sweep.tolerance,
            "starts": sweep.starts,
        },
    }))
    .map_err(json_err)
}

/// Checks a sampling rate.
pub fn check_fs(fs: f64) -> PyResult<()> {
    if fs.is_finite() && fs > 0.0 {
        Ok(())
    } else {
        Err(PyValueError::new_err(format!(
            "fs = {fs} Hz is invalid: the sampling rate must be positive and finite"
        )))
    }
}

/// The samples of a 1-D array (copied if not contiguous).
fn samples(y: &PyReadonlyArray1<'_, f64>) -> Vec<f64> {
    match y.as_slice() {
        Ok(s) => s.to_vec(),
        Err(_) => y.as_array().iter().copied().collect(),
    }
}

/// A fitted model with its modes at `fs_hz`.
#[derive(Serialize)]
struct FitOut<'a> {
    fs_hz: f64,
    model: &'a ArmaModel,
    modes: ModeSet,
}

fn fit_json(model: &ArmaModel, fs: f64) -> PyResult<String> {
    let out = FitOut {
        fs_hz: fs,
        model,
        modes: model.modes(fs),
    };
    serde_json::to_string(&out).map_err(json_err)
}

/// The criterion: a Huber factor or `None` for the quadratic one.
fn robust_of(robust: Option<f64>) -> Robust {
    match robust {
        Some(factor) => Robust::Huber { factor },
        None => Robust::Off,
    }
}

/// ARMA(p, q) by prediction-error minimisation; returns the model and its modes as JSON.
#[pyfunction]
#[pyo3(signature = (y, fs, p, q, robust, max_iterations, tolerance, demean))]
#[allow(clippy::too_many_arguments)]
fn fit_arma(
    py: Python<'_>,
    y: PyReadonlyArray1<'_, f64>,
    fs: f64,
    p: usize,
    q: usize,
    robust: Option<f64>,
    max_iterations: usize,
    tolerance: f64,
    demean: bool,
) -> PyResult<String> {
    check_fs(fs)?;
    let y = samples(&y);
    let params = ArmaParams {
        robust: robust_of(robust),
        max_iterations,
        tolerance,
        demean,
        ..ArmaParams::default()
    };
    let model = py
        .detach(|| vibmode_ident::fit_arma(&y, p, q, &params))
        .map_err(value_err)?;
    fit_json(&model, fs)
}

/// AR(p) by Burg, Yule-Walker or forward-backward least squares; JSON as [`fit_arma`].
#[pyfunction]
fn fit_ar(
    py: Python<'_>,
    y: PyReadonlyArray1<'_, f64>,
    fs: f64,
    p: usize,
    method: &str,
) -> PyResult<String> {
    check_fs(fs)?;
    let method: ArMethod = method.parse().map_err(value_err)?;
    let y = samples(&y);
    let model = py
        .detach(|| vibmode_ident::fit_ar(&y, p, method))
        .map_err(value_err)?;
    fit_json(&model, fs)
}

/// One-sided model PSD `2 lambda Ts |C / A|^2` at `freq_hz` (units^2/Hz).
#[pyfunction]
fn arma_psd<'py>(
    py: Python<'py>,
    a: Vec<f64>,
    c: Vec<f64>,
    noise_variance: f64,
    freq_hz: PyReadonlyArray1<'py, f64>,
    fs: f64,
) -> PyResult<Bound<'py, PyArray1<f64>>> {
    check_fs(fs)?;
    let f = samples(&freq_hz);
    Ok(vibmode_ident::arma_psd(&a, &c, noise_variance, &f, fs).into_pyarray(py))
}

/// One fit of the sweep.
#[derive(Serialize)]
struct SweepFit {
    order: usize,
    loss: Option<f64>,
    noise_variance: Option<f64>,
    aic: Option<f64>,
    converged: bool,
    iterations: usize,
    error: Option<String>,
}

#[derive(Serialize)]
struct SweepOut {
    fs_hz: f64,
    n_samples: usize,
    model: String,
    fits: Vec<SweepFit>,
    modes: Vec<vibmode_run::sweep::SweepMode>,
    filtered_out: Vec<vibmode_run::sweep::FilteredMode>,
    clusters: Vec<vibmode_core::InvariantMode>,
}

/// Order sweep of one signal (`vibmode sweep`): every order's fit and modes, split by the
/// analysis' pole filters. Returns JSON.
#[pyfunction]
#[pyo3(signature = (y, fs, orders, model, method, robust, max_iterations, tolerance, starts))]
#[allow(clippy::too_many_arguments)]
fn sweep(
    py: Python<'_>,
    y: PyReadonlyArray1<'_, f64>,
    fs: f64,
    orders: Vec<usize>,
    model: &str,
    method: &str,
    robust: Option<f64>,
    max_iterations: usize,
    tolerance: f64,
    starts: &str,
) -> PyResult<String> {
    check_fs(fs)?;
    if orders.is_empty() || orders.contains(&0) {
        return Err(PyValueError::new_err(format!(
            "orders {orders:?} must list orders >= 1, e.g. range(2, 31)"
        )));
    }
    let y = samples(&y);
    // One spelling with the analysis config's `[sweep] starts` (serde's).
    let starts: vibmode_core::SearchStarts =
        serde_json::from_value(serde_json::Value::String(starts.to_string())).map_err(|_| {
            PyValueError::new_err(format!(
                "starts = '{starts}' is unknown; use 'multi' (every starting candidate for small models) or 'single'"
            ))
        })?;
    let params = ArmaParams {
        robust: robust_of(robust),
        max_iterations,
        tolerance,
        starts,
        ..ArmaParams::default()
    };
    let (kind, ar_method) = match model {
        "arma" => (SweepModel::Arma, ArMethod::Burg),
        "ar" => (SweepModel::Ar, method.parse().map_err(value_err)?),
        other => {
            return Err(PyValueError::new_err(format!(
                "model = '{other}' is unknown; use 'arma' (ARMA(p, p)) or 'ar'"
            )))
        }
    };
    let fits: Vec<Result<ArmaModel, IdentError>> =
        py.detach(|| vibmode_ident::sweep_fits(&y, kind, ar_method, &orders, &params));
    if let Some(Err(e)) = fits
        .iter()
        .find(|f| f.is_err())
        .filter(|_| fits.iter().all(|f| f.is_err()))
    {
        return Err(value_err(e));
    }
    // The modes split by the pole filters: the sweep's one collection (`vibmode sweep`'s).
    let band = BandLimit::full(fs);
    let mut ch = vibmode_run::sweep::SweepChannel::new("", "", &orders);
    ch.add_fits(&fits, &band, &PoleFilterParams::default());
    ch.cluster(&band, &vibmode_core::ClusterParams::default())
        .map_err(value_err)?;
    let out = SweepOut {
        fs_hz: fs,
        n_samples: y.len(),
        model: model.to_string(),
        fits: orders
            .iter()
            .zip(&fits)
            .map(|(&order, f)| match f {
                Ok(m) => SweepFit {
                    order,
                    loss: Some(m.loss),
                    noise_variance: Some(m.noise_variance),
                    aic: Some(m.aic),
                    converged: m.converged,
                    iterations: m.iterations,
                    error: None,
                },
                Err(e) => SweepFit {
                    order,
                    loss: None,
                    noise_variance: None,
                    aic: None,
                    converged: false,
                    iterations: 0,
                    error: Some(e.to_string()),
                },
            })
            .collect(),
        modes: ch.modes,
        filtered_out: ch.filtered_out,
        clusters: ch.clusters,
    };
    serde_json::to_string(&out).map_err(json_err)
}
