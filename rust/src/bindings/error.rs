//! Engine errors to Python exceptions, in one place, and the last guard against a panic.
//!
//! `ParameterError` and `InternalError` are Python classes (`thermojitter.errors`), so that the
//! Python layer raises the very same types with the same attributes; they are looked up once.

use crate::Error;
use pyo3::create_exception;
use pyo3::exceptions::{PyKeyboardInterrupt, PyRuntimeError};
use pyo3::prelude::*;
use pyo3::sync::PyOnceLock;
use pyo3::types::PyType;
use std::panic::{catch_unwind, AssertUnwindSafe};

create_exception!(
    _core,
    IntegrationError,
    PyRuntimeError,
    "The integrator could not finish the run."
);
create_exception!(
    _core,
    ConvergenceError,
    PyRuntimeError,
    "A non-linear solve did not converge."
);

static PARAMETER_ERROR: PyOnceLock<Py<PyType>> = PyOnceLock::new();
static INTERNAL_ERROR: PyOnceLock<Py<PyType>> = PyOnceLock::new();

/// A `thermojitter.errors` class built with `args`; if the import itself fails, that error.
fn python_error<A>(cell: &'static PyOnceLock<Py<PyType>>, name: &str, args: A) -> PyErr
where
    A: for<'py> IntoPyObject<'py> + Send + Sync + 'static,
{
    Python::attach(|py| match cell.import(py, "thermojitter.errors", name) {
        Ok(ty) => PyErr::from_type(ty.clone(), args),
        Err(e) => e,
    })
}

/// `thermojitter.ParameterError(parameter, value, allowed, message)`; a value that reads as a
/// number is passed as a float.
fn parameter_error(name: String, value: String, reason: String, message: String) -> PyErr {
    match value.parse::<f64>() {
        Ok(x) => python_error(
            &PARAMETER_ERROR,
            "ParameterError",
            (name, x, reason, message),
        ),
        Err(_) => python_error(
            &PARAMETER_ERROR,
            "ParameterError",
            (name, value, reason, message),
        ),
    }
}

impl From<Error> for PyErr {
    fn from(err: Error) -> PyErr {
        let message = err.to_string();
        match err {
            Error::InvalidParameter {
                name,
                value,
                reason,
            } => parameter_error(name, value, reason, message),
            Error::Integration { .. } => IntegrationError::new_err(message),
            Error::NoConvergence { .. } => ConvergenceError::new_err(message),
            Error::Cancelled => PyKeyboardInterrupt::new_err(message),
        }
    }
}

/// A `ParameterError` for a value the binding layer refuses itself.
pub fn invalid(name: &str, value: impl std::fmt::Display, reason: &str) -> PyErr {
    Error::invalid(name, value, reason).into()
}

/// Runs `f`, turning a panic into `thermojitter.InternalError` instead of pyo3's
/// `PanicException` (a BaseException that `except Exception` does not catch). The engine returns
/// errors for bad input; this is only the last line of defence.
pub fn shield<T>(f: impl FnOnce() -> PyResult<T>) -> PyResult<T> {
    match catch_unwind(AssertUnwindSafe(f)) {
        Ok(result) => result,
        Err(payload) => {
            let what = payload
                .downcast_ref::<String>()
                .cloned()
                .or_else(|| payload.downcast_ref::<&str>().map(|s| s.to_string()))
                .unwrap_or_else(|| "unknown panic".to_string());
            Err(python_error(
                &INTERNAL_ERROR,
                "InternalError",
                (format!("internal error in the engine: {what}"),),
            ))
        }
    }
}
