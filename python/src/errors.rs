//! so3fft's errors as Python exceptions.

use pyo3::exceptions::{PyMemoryError, PyRuntimeError, PyValueError};
use pyo3::PyErr;

/// The exception for a library error: `MemoryError` when memory ran out, `ValueError` for
/// bad arguments, `RuntimeError` for what the system refused; the library's message.
pub fn to_py(e: so3fft::Error) -> PyErr {
    let message = e.to_string();
    match e {
        so3fft::Error::OutOfMemory { .. } => PyMemoryError::new_err(message),
        so3fft::Error::InvalidBandwidth { .. }
        | so3fft::Error::LengthMismatch { .. }
        | so3fft::Error::InvalidArgument(_)
        | so3fft::Error::WrongDirection => PyValueError::new_err(message),
        _ => PyRuntimeError::new_err(message),
    }
}

/// A `ValueError` with `message`.
pub fn value_error(message: impl Into<String>) -> PyErr {
    PyValueError::new_err(message.into())
}
