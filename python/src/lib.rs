//! `vibmode._native`: the Rust side of the `vibmode` Python package.
//!
//! Thin wrappers over the vibmode crates. Arrays come in as C-contiguous float64 numpy arrays
//! (the Python layer moves the `axis` last and reshapes to 2-D rows); structured results go
//! out as JSON text that the Python layer turns into dicts, model objects and DataFrames, so
//! that every field name is the one of `results.json` and the CLI's JSON.
//!
//! Errors are Python exceptions carrying the library's one-line messages: `OSError` for files
//! (`FileNotFoundError` when the file does not exist), `ValueError` for everything else. Long
//! computations release the GIL. No `unwrap()` on input data.

mod errors;
mod fleet;
mod ident;
mod pipeline;
mod signal;
mod spectral;
mod ssi;

use pyo3::prelude::*;

/// The native module.
#[pymodule]
fn _native(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    spectral::register(m)?;
    ident::register(m)?;
    signal::register(m)?;
    pipeline::register(m)?;
    fleet::register(m)?;
    ssi::register(m)?;
    Ok(())
}
