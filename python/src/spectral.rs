//! Periodogram, Welch, CSD and coherence of the rows of a 2-D array (`vibmode-spectra`), one
//! planned FFT per worker thread, rows in parallel, GIL released. The segment arguments
//! (window name or coefficients, nperseg, noverlap, nfft, detrend, scaling, average) arrive as
//! one dict, read in one place ([`SegmentArgs`]).

use numpy::ndarray::Array2;
use numpy::{
    Element, IntoPyArray, PyArray1, PyArray2, PyReadonlyArray1, PyReadonlyArray2,
    PyUntypedArrayMethods,
};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use rayon::prelude::*;
use vibmode_spectra::{
    periodogram_with_window, Average, Complex64, Detrend, PeriodogramParams, Scaling, SpectraError,
    WelchParams, WelchPlan, Window, WindowSpec,
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

/// scipy's `window`: a window name of the crate (`hann`, `tukey:0.25`; the Python wrappers
/// translate scipy's names and tuples) or the coefficients themselves (1-D float64).
#[derive(FromPyObject)]
enum WindowArg<'py> {
    Name(String),
    Values(PyReadonlyArray1<'py, f64>),
}

/// scipy's segment arguments, given by the Python wrappers as one dict (`_segment_args`): the
/// one place where all four spectra read them.
#[derive(FromPyObject)]
#[pyo3(from_item_all)]
struct SegmentArgs<'py> {
    window: WindowArg<'py>,
    nperseg: Option<usize>,
    noverlap: Option<usize>,
    nfft: Option<usize>,
    detrend: String,
    scaling: String,
    average: String,
}

impl SegmentArgs<'_> {
    /// The crate's taper (named, or checked coefficients).
    fn window(&self) -> PyResult<WindowSpec> {
        match &self.window {
            WindowArg::Name(name) => Ok(WindowSpec::Named(
                name.parse::<Window>().map_err(value_err)?,
            )),
            WindowArg::Values(v) => {
                let coefficients: Vec<f64> = v.as_array().iter().copied().collect();
                WindowSpec::custom(coefficients).map_err(value_err)
            }
        }
    }

    /// Welch parameters and taper (the taper replaces `WelchParams::window`).
    fn welch(&self) -> PyResult<(WelchParams, WindowSpec)> {
        let p = WelchParams {
            nperseg: self.nperseg,
            noverlap: self.noverlap,
            nfft: self.nfft,
            detrend: self.detrend.parse::<Detrend>().map_err(value_err)?,
            scaling: self.scaling.parse::<Scaling>().map_err(value_err)?,
            average: self.average.parse::<Average>().map_err(value_err)?,
            ..WelchParams::default()
        };
        Ok((p, self.window()?))
    }
}

/// What a spectral call returns to Python: frequencies (Hz), one spectrum per row, notes.
type RowsOut<'py, T> = (
    Bound<'py, PyArray1<f64>>,
    Bound<'py, PyArray2<T>>,
    Vec<String>,
);

/// The shared path of [`welch_rows`], [`csd_rows`] and [`coherence_rows`]: plans the segments
/// once (errors before any work), then runs `f` on every row of `x` (and of `y`) with a plan of
/// its own per worker thread, rows in parallel with the GIL released; `f` writes one value per
/// bin.
fn welch_like<'py, T: Element + Copy + Send>(
    py: Python<'py>,
    x: &PyReadonlyArray2<'py, f64>,
    y: Option<&PyReadonlyArray2<'py, f64>>,
    fs: f64,
    args: &SegmentArgs<'_>,
    zero: T,
    f: impl Fn(&mut WelchPlan, &[f64], &[f64], &mut [T]) -> Result<(), SpectraError> + Sync,
) -> PyResult<RowsOut<'py, T>> {
    let (p, window) = args.welch()?;
    let (xd, r, n) = rows(x, "x")?;
    let yd = match y {
        None => xd,
        Some(y) => {
            let (yd, ry, ny) = rows(y, "y")?;
            if (r, n) != (ry, ny) {
                return Err(PyValueError::new_err(format!(
                    "x and y have different shapes ({r}, {n}) and ({ry}, {ny}) after broadcasting (internal)"
                )));
            }
            yd
        }
    };
    let plan = WelchPlan::with_window(n, fs, &p, &window).map_err(value_err)?;
    let nfreq = plan.freq_hz().len();
    let freq = plan.freq_hz().to_vec();
    let notes = plan.notes().to_vec();
    let mut out = vec![zero; r * nfreq];
    py.detach(|| {
        out.par_chunks_mut(nfreq).enumerate().try_for_each_init(
            || WelchPlan::with_window(n, fs, &p, &window),
            |plan, (i, o)| {
                let plan = plan.as_mut().map_err(|e| e.clone())?;
                f(plan, &xd[i * n..(i + 1) * n], &yd[i * n..(i + 1) * n], o)
            },
        )
    })
    .map_err(value_err)?;
    let out = Array2::from_shape_vec((r, nfreq), out).map_err(value_err)?;
    Ok((freq.into_pyarray(py), out.into_pyarray(py), notes))
}

/// Welch PSD of every row of `x` (rows, n): returns `(freq_hz, psd (rows, nfreq), notes)`.
#[pyfunction]
fn welch_rows<'py>(
    py: Python<'py>,
    x: PyReadonlyArray2<'py, f64>,
    fs: f64,
    args: SegmentArgs<'py>,
) -> PyResult<RowsOut<'py, f64>> {
    welch_like(py, &x, None, fs, &args, 0.0, |plan, row, _, o| {
        o.copy_from_slice(&plan.welch(row)?.psd);
        Ok(())
    })
}

/// Cross-spectral density of the rows of `x` and `y`: `(freq_hz, Pxy (rows, nfreq), notes)`.
#[pyfunction]
fn csd_rows<'py>(
    py: Python<'py>,
    x: PyReadonlyArray2<'py, f64>,
    y: PyReadonlyArray2<'py, f64>,
    fs: f64,
    args: SegmentArgs<'py>,
) -> PyResult<RowsOut<'py, Complex64>> {
    let zero = Complex64::new(0.0, 0.0);
    welch_like(py, &x, Some(&y), fs, &args, zero, |plan, row, yrow, o| {
        o.copy_from_slice(&plan.csd(row, yrow)?.csd);
        Ok(())
    })
}

/// Magnitude-squared coherence of the rows of `x` and `y` (scaling and average are not used:
/// density, mean): `(freq_hz, Cxy (rows, nfreq), notes)`.
#[pyfunction]
fn coherence_rows<'py>(
    py: Python<'py>,
    x: PyReadonlyArray2<'py, f64>,
    y: PyReadonlyArray2<'py, f64>,
    fs: f64,
    args: SegmentArgs<'py>,
) -> PyResult<RowsOut<'py, f64>> {
    welch_like(py, &x, Some(&y), fs, &args, 0.0, |plan, row, yrow, o| {
        let c = plan.coherence(row, yrow)?;
        o.copy_from_slice(&c.coherence);
        // Bins where Pxx * Pyy == 0: scipy gives NaN there (0 / 0); the crate gives 0 and a
        // note. Only an exact 0 can be such a bin: look at the auto-spectra then.
        if c.coherence.contains(&0.0) {
            let w = plan.welch(row)?;
            let v = plan.welch(yrow)?;
            for (k, slot) in o.iter_mut().enumerate() {
                if w.psd[k] * v.psd[k] == 0.0 {
                    *slot = f64::NAN;
                }
            }
        }
        Ok(())
    })
}

/// Periodogram of every row of `x` (rows, n) (`nperseg`, `noverlap` and `average` are not
/// used): returns `(freq_hz, psd (rows, nfreq), notes)`.
#[pyfunction]
fn periodogram_rows<'py>(
    py: Python<'py>,
    x: PyReadonlyArray2<'py, f64>,
    fs: f64,
    args: SegmentArgs<'py>,
) -> PyResult<RowsOut<'py, f64>> {
    let window = args.window()?;
    let p = PeriodogramParams {
        nfft: args.nfft,
        detrend: args.detrend.parse::<Detrend>().map_err(value_err)?,
        scaling: args.scaling.parse::<Scaling>().map_err(value_err)?,
        ..PeriodogramParams::default()
    };
    let (data, r, n) = rows(&x, "x")?;
    if r == 0 || n == 0 {
        return Err(PyValueError::new_err(
            "x has no samples; give a non-empty array",
        ));
    }
    // The first row gives the frequencies and notes (and the first error, if any).
    let first = periodogram_with_window(&data[..n], fs, &p, &window).map_err(value_err)?;
    let nfreq = first.freq_hz.len();
    let mut out = vec![0.0; r * nfreq];
    py.detach(|| {
        out.par_chunks_mut(nfreq)
            .enumerate()
            .try_for_each(|(i, o)| {
                let s = periodogram_with_window(&data[i * n..(i + 1) * n], fs, &p, &window)?;
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
