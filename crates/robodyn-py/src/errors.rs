//! Core errors as the Python exceptions the API promises: `ValueError` for bad values,
//! `FileNotFoundError` for a missing file, `SimulationError` for a simulation that stopped.

use pyo3::exceptions::{PyFileNotFoundError, PyValueError};
use pyo3::prelude::*;
use robodyn::Error;

pyo3::create_exception!(
    robodyn,
    SimulationError,
    PyValueError,
    "A simulation stopped: it diverged (the message says when, which quantity and joint, and \
     a step that keeps it stable), or its controller or wrenches gave something unusable."
);

/// A core error as the Python exception the API promises.
pub(crate) fn to_py_err(error: Error) -> PyErr {
    match error {
        Error::FileNotFound { .. } => PyFileNotFoundError::new_err(error.to_string()),
        Error::Simulation { .. } | Error::Diverged { .. } => {
            SimulationError::new_err(error.to_string())
        }
        _ => PyValueError::new_err(error.to_string()),
    }
}

/// The error of element `k` of a numeric batch, the element named in the message.
pub(crate) fn batch_element_error(k: usize, error: Error) -> PyErr {
    let message = format!("batch element {k}: {error}");
    match error {
        Error::FileNotFound { .. } => PyFileNotFoundError::new_err(message),
        _ => PyValueError::new_err(message),
    }
}
