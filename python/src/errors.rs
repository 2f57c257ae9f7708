//! The libraries' errors as Python exceptions: bad input is a
//! `ValueError`, a failure while running a `RuntimeError`, a file that
//! cannot be read or written an `OSError`; the message is the library's.

use pyo3::PyErr;
use pyo3::exceptions::{PyOSError, PyRuntimeError, PyValueError};

/// Bad input: a `ValueError` with `message`.
pub fn invalid(message: impl std::fmt::Display) -> PyErr {
    PyValueError::new_err(message.to_string())
}

/// The core refuses only input: `ValueError`.
pub fn core(e: primo_core::Error) -> PyErr {
    invalid(e)
}

/// Demonstrations, DMP files and movements: `ValueError`.
pub fn skill(e: primo_skill::Error) -> PyErr {
    invalid(e)
}

/// The learning library: bad input or a refused setting is a
/// `ValueError`, I/O an `OSError`, anything else a `RuntimeError`.
pub fn learn(e: primo_learn::Error) -> PyErr {
    match e {
        primo_learn::Error::Io { .. } => PyOSError::new_err(e.to_string()),
        e if e.is_input() => invalid(e),
        e => PyRuntimeError::new_err(e.to_string()),
    }
}

/// A file that cannot be read or written: `OSError` naming it.
pub fn io(path: &std::path::Path, e: std::io::Error) -> PyErr {
    PyOSError::new_err(format!("{}: {e}", path.display()))
}
