//! SSI-cov of one multichannel record (`vibmode-ssi`): the order sweep, stabilisation labels and
//! the modes that stay over the orders, as `vibmode ssi` computes them.

use numpy::PyReadonlyArray2;
use pyo3::prelude::*;
use vibmode_core::{SsiParams, StabilityParams};
use vibmode_ssi::RecordSsiOptions;

use crate::errors::{json_err, value_err};
use crate::ident::check_fs;

/// Registers the functions of this module.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(ssi_cov, m)?)?;
    m.add_function(wrap_pyfunction!(ssi_defaults, m)?)?;
    Ok(())
}

/// The SSI and stabilisation parameters' defaults (JSON `{"ssi": ..., "stability": ...}`): the
/// structs the CLI and the analysis' TOML read.
#[pyfunction]
fn ssi_defaults() -> PyResult<String> {
    serde_json::to_string(&serde_json::json!({
        "ssi": SsiParams::default(),
        "stability": StabilityParams::default(),
    }))
    .map_err(json_err)
}

/// SSI-cov of `data` (`n_channels x n_samples`, C-contiguous) sampled at `fs` Hz. `ssi` and
/// `stability` are JSON objects of the keys to change from the defaults (unknown keys are an
/// error). `uncertainty_blocks`: first-order standard deviations from that many blocks.
/// Returns the JSON of `vibmode_ssi::RecordSsi`.
#[pyfunction]
#[pyo3(signature = (data, fs, ssi, stability, normalise, valid_max_hz, uncertainty_blocks=None))]
#[allow(clippy::too_many_arguments)]
fn ssi_cov(
    py: Python<'_>,
    data: PyReadonlyArray2<'_, f64>,
    fs: f64,
    ssi: &str,
    stability: &str,
    normalise: bool,
    valid_max_hz: Option<f64>,
    uncertainty_blocks: Option<usize>,
) -> PyResult<String> {
    check_fs(fs)?;
    let params: SsiParams = serde_json::from_str(ssi).map_err(value_err)?;
    params.validate().map_err(value_err)?;
    let stability: StabilityParams = serde_json::from_str(stability).map_err(value_err)?;
    stability.validate().map_err(value_err)?;
    let a = data.as_array();
    let rows: Vec<Vec<f64>> = a.rows().into_iter().map(|r| r.to_vec()).collect();
    let options = RecordSsiOptions {
        normalise,
        valid_max_hz,
        stability,
        uncertainty_blocks,
        ..RecordSsiOptions::default()
    };
    let found = py
        .detach(|| {
            let chans: Vec<&[f64]> = rows.iter().map(Vec::as_slice).collect();
            vibmode_ssi::identify_record(&chans, fs, &params, &options)
        })
        .map_err(value_err)?;
    serde_json::to_string(&found).map_err(json_err)
}
