//! Rust errors as Python exceptions, and the slot that carries an exception raised by a Python
//! callable out of a solve.

use std::sync::Mutex;

use pyo3::create_exception;
use pyo3::exceptions::PyException;
use pyo3::prelude::*;

create_exception!(
    synovia,
    SynoviaError,
    PyException,
    "An error of the synovia library (invalid model, failed solve, unreadable scenario); \
     the message is the Rust error's."
);

/// A Rust error as a `SynoviaError` with its message (and its chain of sources).
pub fn err(e: impl std::fmt::Display) -> PyErr {
    SynoviaError::new_err(e.to_string())
}

/// A `SynoviaError` with a message.
pub fn msg(m: impl Into<String>) -> PyErr {
    SynoviaError::new_err(m.into())
}

/// The first exception raised by a Python callable (load history, displacement field, part
/// selector) since the last [`take_callback_error`]: the callables are called from inside the
/// Rust solves, which cannot carry a Python exception, so the value becomes `NaN` there and the
/// exception is raised when the solve returns.
static CALLBACK_ERROR: Mutex<Option<PyErr>> = Mutex::new(None);

/// Records an exception of a callable (the first one is kept).
pub fn set_callback_error(e: PyErr) {
    let mut slot = CALLBACK_ERROR.lock().unwrap_or_else(|p| p.into_inner());
    if slot.is_none() {
        *slot = Some(e);
    }
}

/// Takes the recorded exception of a callable, if any.
pub fn take_callback_error() -> Option<PyErr> {
    CALLBACK_ERROR.lock().unwrap_or_else(|p| p.into_inner()).take()
}

/// The result of a solve: a callable's exception first (it is the cause of whatever the solve
/// did with the `NaN`), else the solve's own error as a `SynoviaError`.
pub fn solved<T, E: std::fmt::Display>(r: Result<T, E>) -> PyResult<T> {
    if let Some(e) = take_callback_error() {
        return Err(e);
    }
    r.map_err(err)
}
