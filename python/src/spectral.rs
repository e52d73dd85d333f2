//! Periodogram, Welch, CSD and coherence of the rows of a 2-D array (`vibmode-spectra`), one
//! planned FFT per worker thread, rows in parallel, GIL released.

use numpy::ndarray::Array2;
use numpy::{IntoPyArray, PyArray1, PyArray2, PyReadonlyArray2, PyUntypedArrayMethods};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use rayon::prelude::*;
use vibmode_spectra::{
    Average, Complex64, Detrend, PeriodogramParams, Scaling, SpectraError, WelchParams, WelchPlan,
    Window,
};

use crate::errors::value_err;

/// Registers the functions of this module.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(welch_rows, m)?)?;
    m.add_function(wrap_pyfunction!(periodogram_rows, m)?)?;
    m.add_function(wrap_pyfunction!(csd_rows, m)?)?;
    m.add_function(wrap_pyfunction!(coherence_rows, m)?)?;
    m.add_function(wrap_pyfunction!(window_values, m)?)?;
    Ok(())
}

/// The rows of a C-contiguous 2-D array as one slice, with (rows, columns).
fn rows<'a>(x: &'a PyReadonlyArray2<'_, f64>, name: &str) -> PyResult<(&'a [f64], usize, usize)> {
    let shape = x.shape();
    let (r, n) = (shape[0], shape[1]);
    let data = x.as_slice().map_err(|_| {
        PyValueError::new_err(format!(
            "vibmode: {name} must be a C-contiguous float64 array (internal)"
        ))
    })?;
    Ok((data, r, n))
}

/// Welch parameters from scipy's names.
#[allow(clippy::too_many_arguments)]
fn welch_params(
    window: &str,
    nperseg: Option<usize>,
    noverlap: Option<usize>,
    nfft: Option<usize>,
    detrend: &str,
    scaling: &str,
    average: &str,
) -> PyResult<WelchParams> {
    Ok(WelchParams {
        window: window.parse::<Window>().map_err(value_err)?,
        nperseg,
        noverlap,
        nfft,
        detrend: detrend.parse::<Detrend>().map_err(value_err)?,
        scaling: scaling.parse::<Scaling>().map_err(value_err)?,
        average: average.parse::<Average>().map_err(value_err)?,
        ..WelchParams::default()
    })
}

/// Runs `f` on every row of `x` (and `y`) with a plan of its own per worker thread, writing
/// `nfreq` values per row into `out`.
#[allow(clippy::too_many_arguments)]
fn per_row<T: Send>(
    x: &[f64],
    y: Option<&[f64]>,
    n: usize,
    fs: f64,
    p: &WelchParams,
    out: &mut [T],
    nfreq: usize,
    f: impl Fn(&mut WelchPlan, &[f64], Option<&[f64]>, &mut [T]) -> Result<(), SpectraError> + Sync,
) -> Result<(), SpectraError> {
    out.par_chunks_mut(nfreq).enumerate().try_for_each_init(
        || WelchPlan::new(n, fs, p),
        |plan, (i, o)| {
            let plan = plan.as_mut().map_err(|e| e.clone())?;
            let row = &x[i * n..(i + 1) * n];
            let yrow = y.map(|y| &y[i * n..(i + 1) * n]);
            f(plan, row, yrow, o)
        },
    )
}

/// Welch PSD of every row of `x` (rows, n): returns `(freq_hz, psd (rows, nfreq), notes)`.
#[pyfunction]
#[pyo3(signature = (x, fs, window, nperseg, noverlap, nfft, detrend, scaling, average))]
#[allow(clippy::too_many_arguments, clippy::type_complexity)]
fn welch_rows<'py>(
    py: Python<'py>,
    x: PyReadonlyArray2<'py, f64>,
    fs: f64,
    window: &str,
    nperseg: Option<usize>,
    noverlap: Option<usize>,
    nfft: Option<usize>,
    detrend: &str,
    scaling: &str,
    average: &str,
) -> PyResult<(
    Bound<'py, PyArray1<f64>>,
    Bound<'py, PyArray2<f64>>,
    Vec<String>,
)> {
    let p = welch_params(window, nperseg, noverlap, nfft, detrend, scaling, average)?;
    let (data, r, n) = rows(&x, "x")?;
    let plan = WelchPlan::new(n, fs, &p).map_err(value_err)?;
    let nfreq = plan.freq_hz().len();
    let freq = plan.freq_hz().to_vec();
    let notes = plan.notes().to_vec();
    let mut out = vec![0.0; r * nfreq];
    py.detach(|| {
        per_row(data, None, n, fs, &p, &mut out, nfreq, |plan, row, _, o| {
            let s = plan.welch(row)?;
            o.copy_from_slice(&s.psd);
            Ok(())
        })
    })
    .map_err(value_err)?;
    let psd = Array2::from_shape_vec((r, nfreq), out).map_err(value_err)?;
    Ok((freq.into_pyarray(py), psd.into_pyarray(py), notes))
}

/// Periodogram of every row of `x` (rows, n): returns `(freq_hz, psd (rows, nfreq), notes)`.
#[pyfunction]
#[pyo3(signature = (x, fs, window, nfft, detrend, scaling))]
#[allow(clippy::type_complexity)]
fn periodogram_rows<'py>(
    py: Python<'py>,
    x: PyReadonlyArray2<'py, f64>,
    fs: f64,
    window: &str,
    nfft: Option<usize>,
    detrend: &str,
    scaling: &str,
) -> PyResult<(
    Bound<'py, PyArray1<f64>>,
    Bound<'py, PyArray2<f64>>,
    Vec<String>,
)> {
    let p = PeriodogramParams {
        window: window.parse::<Window>().map_err(value_err)?,
        nfft,
        detrend: detrend.parse::<Detrend>().map_err(value_err)?,
        scaling: scaling.parse::<Scaling>().map_err(value_err)?,
    };
    let (data, r, n) = rows(&x, "x")?;
    if r == 0 || n == 0 {
        return Err(PyValueError::new_err(
            "x has no samples; give a non-empty array",
        ));
    }
    // The first row gives the frequencies and notes (and the first error, if any).
    let first = vibmode_spectra::periodogram(&data[..n], fs, &p).map_err(value_err)?;
    let nfreq = first.freq_hz.len();
    let mut out = vec![0.0; r * nfreq];
    py.detach(|| {
        out.par_chunks_mut(nfreq)
            .enumerate()
            .try_for_each(|(i, o)| {
                let s = vibmode_spectra::periodogram(&data[i * n..(i + 1) * n], fs, &p)?;
                o.copy_from_slice(&s.psd);
                Ok::<(), SpectraError>(())
            })
    })
    .map_err(value_err)?;
    let psd = Array2::from_shape_vec((r, nfreq), out).map_err(value_err)?;
    Ok((
        first.freq_hz.into_pyarray(py),
        psd.into_pyarray(py),
        first.notes,
    ))
}

/// The checked pair (x, y) of one shape, with (rows, n).
fn pair<'a>(
    x: &'a PyReadonlyArray2<'_, f64>,
    y: &'a PyReadonlyArray2<'_, f64>,
) -> PyResult<(&'a [f64], &'a [f64], usize, usize)> {
    let (xd, r, n) = rows(x, "x")?;
    let (yd, ry, ny) = rows(y, "y")?;
    if (r, n) != (ry, ny) {
        return Err(PyValueError::new_err(format!(
            "x and y have different shapes ({r}, {n}) and ({ry}, {ny}) after broadcasting (internal)"
        )));
    }
    Ok((xd, yd, r, n))
}

/// Cross-spectral density of the rows of `x` and `y`: `(freq_hz, Pxy (rows, nfreq), notes)`.
#[pyfunction]
#[pyo3(signature = (x, y, fs, window, nperseg, noverlap, nfft, detrend, scaling, average))]
#[allow(clippy::too_many_arguments, clippy::type_complexity)]
fn csd_rows<'py>(
    py: Python<'py>,
    x: PyReadonlyArray2<'py, f64>,
    y: PyReadonlyArray2<'py, f64>,
    fs: f64,
    window: &str,
    nperseg: Option<usize>,
    noverlap: Option<usize>,
    nfft: Option<usize>,
    detrend: &str,
    scaling: &str,
    average: &str,
) -> PyResult<(
    Bound<'py, PyArray1<f64>>,
    Bound<'py, PyArray2<Complex64>>,
    Vec<String>,
)> {
    let p = welch_params(window, nperseg, noverlap, nfft, detrend, scaling, average)?;
    let (xd, yd, r, n) = pair(&x, &y)?;
    let plan = WelchPlan::new(n, fs, &p).map_err(value_err)?;
    let nfreq = plan.freq_hz().len();
    let freq = plan.freq_hz().to_vec();
    let notes = plan.notes().to_vec();
    let mut out = vec![Complex64::new(0.0, 0.0); r * nfreq];
    py.detach(|| {
        per_row(
            xd,
            Some(yd),
            n,
            fs,
            &p,
            &mut out,
            nfreq,
            |plan, row, yrow, o| {
                let s = plan.csd(row, yrow.unwrap_or(row))?;
                o.copy_from_slice(&s.csd);
                Ok(())
            },
        )
    })
    .map_err(value_err)?;
    let pxy = Array2::from_shape_vec((r, nfreq), out).map_err(value_err)?;
    Ok((freq.into_pyarray(py), pxy.into_pyarray(py), notes))
}

/// Magnitude-squared coherence of the rows of `x` and `y`: `(freq_hz, Cxy (rows, nfreq), notes)`.
#[pyfunction]
#[pyo3(signature = (x, y, fs, window, nperseg, noverlap, nfft, detrend))]
#[allow(clippy::too_many_arguments, clippy::type_complexity)]
fn coherence_rows<'py>(
    py: Python<'py>,
    x: PyReadonlyArray2<'py, f64>,
    y: PyReadonlyArray2<'py, f64>,
    fs: f64,
    window: &str,
    nperseg: Option<usize>,
    noverlap: Option<usize>,
    nfft: Option<usize>,
    detrend: &str,
) -> PyResult<(
    Bound<'py, PyArray1<f64>>,
    Bound<'py, PyArray2<f64>>,
    Vec<String>,
)> {
    let p = welch_params(window, nperseg, noverlap, nfft, detrend, "density", "mean")?;
    let (xd, yd, r, n) = pair(&x, &y)?;
    let plan = WelchPlan::new(n, fs, &p).map_err(value_err)?;
    let nfreq = plan.freq_hz().len();
    let freq = plan.freq_hz().to_vec();
    let notes = plan.notes().to_vec();
    let mut out = vec![0.0; r * nfreq];
    // Bins where Pxx * Pyy == 0: scipy gives NaN there (0 / 0); the crate gives 0 and a note.
    let mut zero_bins = vec![false; r * nfreq];
    py.detach(|| {
        let mut both: Vec<(f64, bool)> = vec![(0.0, false); r * nfreq];
        let res = per_row(
            xd,
            Some(yd),
            n,
            fs,
            &p,
            &mut both,
            nfreq,
            |plan, row, yrow, o| {
                let y = yrow.unwrap_or(row);
                let c = plan.coherence(row, y)?;
                for (slot, &v) in o.iter_mut().zip(&c.coherence) {
                    *slot = (v, false);
                }
                // Only an exact 0 can be a 0 / 0 bin: look at the auto-spectra then.
                if c.coherence.contains(&0.0) {
                    let w = plan.welch(row)?;
                    let v = plan.welch(y)?;
                    for (k, slot) in o.iter_mut().enumerate() {
                        slot.1 = w.psd[k] * v.psd[k] == 0.0;
                    }
                }
                Ok(())
            },
        );
        for (i, (c, z)) in both.into_iter().enumerate() {
            out[i] = c;
            zero_bins[i] = z;
        }
        res
    })
    .map_err(value_err)?;
    for (o, z) in out.iter_mut().zip(&zero_bins) {
        if *z {
            *o = f64::NAN;
        }
    }
    let cxy = Array2::from_shape_vec((r, nfreq), out).map_err(value_err)?;
    Ok((freq.into_pyarray(py), cxy.into_pyarray(py), notes))
}

/// The periodic window `name` of length `n` (scipy `get_window(name, n)`), dimensionless.
#[pyfunction]
fn window_values<'py>(
    py: Python<'py>,
    name: &str,
    n: usize,
) -> PyResult<Bound<'py, PyArray1<f64>>> {
    let w = name.parse::<Window>().map_err(value_err)?;
    Ok(vibmode_spectra::window_values(&w, n).into_pyarray(py))
}
