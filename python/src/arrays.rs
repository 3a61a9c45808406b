//! Slices of the caller's NumPy arrays, and the finiteness check.

use crate::errors::value_error;
use numpy::{
    Element, PyArrayDyn, PyArrayMethods, PyReadonlyArrayDyn, PyReadwriteArrayDyn,
    PyUntypedArrayMethods,
};
use pyo3::Bound;
use pyo3::PyResult;
use so3fft::Complex64;

/// An input array borrowed for reading (an error if this call writes it too).
pub fn readonly<'py, T: Element>(
    a: &Bound<'py, PyArrayDyn<T>>,
) -> PyResult<PyReadonlyArrayDyn<'py, T>> {
    a.try_readonly()
        .map_err(|_| value_error("an input array is also being written (is it `out` too?)"))
}

/// The output array borrowed for writing (an error if it overlaps an input or is read-only).
pub fn readwrite<'py, T: Element>(
    a: &Bound<'py, PyArrayDyn<T>>,
) -> PyResult<PyReadwriteArrayDyn<'py, T>> {
    a.try_readwrite().map_err(|_| {
        value_error("out overlaps an input array, is read-only, or is in use by another call")
    })
}

/// The values of a C-contiguous input array of `len` values.
pub fn input<'a, T: Element>(
    a: &'a PyReadonlyArrayDyn<'_, T>,
    len: usize,
    what: &str,
) -> PyResult<&'a [T]> {
    let s = a
        .as_slice()
        .map_err(|_| value_error(format!("{what} must be C-contiguous and aligned")))?;
    if s.len() != len {
        return Err(value_error(format!(
            "{what} has {} values, the plan needs {len}",
            s.len()
        )));
    }
    Ok(s)
}

/// The values of a C-contiguous, writeable output array of `len` values.
pub fn output<'a, T: Element>(
    a: &'a mut PyReadwriteArrayDyn<'_, T>,
    len: usize,
    what: &str,
) -> PyResult<&'a mut [T]> {
    let got = a.len();
    let s = a
        .as_slice_mut()
        .map_err(|_| value_error(format!("{what} must be C-contiguous and aligned")))?;
    if got != len {
        return Err(value_error(format!(
            "{what} has {got} values, the plan needs {len}"
        )));
    }
    Ok(s)
}

/// Whether every value is finite (no NaN, no infinity). `x * 0` is 0 for finite `x` and NaN
/// otherwise; 32 independent sums keep the loop vectorised and off the add latency.
pub fn all_finite(values: &[Complex64]) -> bool {
    let mut acc = [0.0f64; 32];
    let chunks = values.chunks_exact(16);
    let rest = chunks.remainder();
    for c in chunks {
        for i in 0..16 {
            acc[2 * i] += c[i].re * 0.0;
            acc[2 * i + 1] += c[i].im * 0.0;
        }
    }
    for z in rest {
        acc[0] += z.re * 0.0;
        acc[1] += z.im * 0.0;
    }
    acc.iter().sum::<f64>() == 0.0
}

/// [`all_finite`] of real values.
pub fn all_finite_real(values: &[f64]) -> bool {
    let mut acc = [0.0f64; 32];
    let chunks = values.chunks_exact(32);
    let rest = chunks.remainder();
    for c in chunks {
        for i in 0..32 {
            acc[i] += c[i] * 0.0;
        }
    }
    for x in rest {
        acc[0] += x * 0.0;
    }
    acc.iter().sum::<f64>() == 0.0
}

/// The error of a transform when `all_finite` fails for `what`.
pub fn not_finite(what: &str) -> pyo3::PyErr {
    value_error(format!(
        "{what} contain NaN or infinite values (pass check_finite=False to skip this check)"
    ))
}

/// The error when `all_finite` fails for `what`, where the check is always made.
pub fn not_finite_always(what: &str) -> pyo3::PyErr {
    value_error(format!("{what} contain NaN or infinite values"))
}
