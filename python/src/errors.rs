//! The libraries' errors as Python exceptions, with their one-line messages.
//!
//! Files that cannot be opened, read or written raise `OSError` (`FileNotFoundError` when the
//! operating system says the file does not exist); everything else raises `ValueError`.

use pyo3::exceptions::{PyFileNotFoundError, PyOSError, PyValueError};
use pyo3::PyErr;
use std::fmt::Display;

/// `ValueError` with the error's message.
pub fn value_err(e: impl Display) -> PyErr {
    PyValueError::new_err(e.to_string())
}

/// `OSError` (or `FileNotFoundError`) with the error's message.
pub fn os_err(e: impl Display) -> PyErr {
    let text = e.to_string();
    if text.contains("No such file") || text.contains("cannot find the") {
        PyFileNotFoundError::new_err(text)
    } else {
        PyOSError::new_err(text)
    }
}

/// A signal error: `OSError` for I/O, `ValueError` otherwise.
pub fn signal_err(e: vibmode_signal::SignalError) -> PyErr {
    match e {
        vibmode_signal::SignalError::Io { .. } => os_err(e),
        other => value_err(other),
    }
}

/// A vehicle-model error: `OSError` for an unreadable file, `ValueError` otherwise.
pub fn vehicle_err(e: vibmode_vehicle::VehicleError) -> PyErr {
    match e {
        vibmode_vehicle::VehicleError::Io { .. } => os_err(e),
        other => value_err(other),
    }
}

/// An analysis error: `OSError` for an unreadable config file, `ValueError` otherwise.
pub fn analysis_err(e: vibmode_analysis::AnalysisError) -> PyErr {
    if let vibmode_analysis::AnalysisError::Signal(s) = e {
        return signal_err(s);
    }
    match &e {
        vibmode_analysis::AnalysisError::ConfigFile { message, .. }
            if message.contains("os error") =>
        {
            os_err(e)
        }
        _ => value_err(e),
    }
}

/// A fleet error: `OSError` for files and the store's file, `ValueError` otherwise.
pub fn fleet_err(e: vibmode_fleet::FleetError) -> PyErr {
    use vibmode_fleet::FleetError as F;
    match e {
        F::Signal(s) => signal_err(s),
        F::Io { .. }
        | F::Write { .. }
        | F::NoStore { .. }
        | F::NotAStore { .. }
        | F::NotAFile { .. }
        | F::NoFolder { .. }
        | F::Sql { .. } => os_err(e),
        other => value_err(other),
    }
}

/// A JSON (de)serialisation failure of the binding itself.
pub fn json_err(e: serde_json::Error) -> PyErr {
    PyValueError::new_err(format!("vibmode: internal JSON conversion failed: {e}"))
}
