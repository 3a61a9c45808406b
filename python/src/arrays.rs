//! Slices of the caller's NumPy arrays, the two precisions, and the finiteness check.

use crate::errors::value_error;
use numpy::{
    Element, PyArrayDyn, PyArrayMethods, PyReadonlyArrayDyn, PyReadwriteArrayDyn, PyUntypedArray,
    PyUntypedArrayMethods,
};
use pyo3::exceptions::PyTypeError;
use pyo3::prelude::*;
use so3fft::{Complex, Real};

/// A real element type of the plans (`f64` or `f32`): the library's [`Real`], a NumPy
/// element, and widened exactly to `f64` for the finiteness checks.
pub trait Float: Real + Element + Into<f64> {}

impl Float for f64 {}
impl Float for f32 {}

/// The precision of a plan, by the name of its real dtype.
#[derive(Clone, Copy, PartialEq, Eq)]
pub enum Precision {
    F64,
    F32,
}

impl Precision {
    /// The precision named `"float64"` or `"float32"`.
    pub fn from_name(name: &str) -> PyResult<Precision> {
        match name {
            "float64" => Ok(Precision::F64),
            "float32" => Ok(Precision::F32),
            _ => Err(PyTypeError::new_err(format!(
                "dtype must be 'float64' or 'float32', not {name:?}"
            ))),
        }
    }

    /// The name of the real dtype.
    pub fn name(self) -> &'static str {
        match self {
            Precision::F64 => "float64",
            Precision::F32 => "float32",
        }
    }
}

/// One of two values, of the library's type in double (`F64`) or single (`F32`) precision:
/// what a plan of either precision holds. [`each!`] runs the same code on either.
pub enum ByPrecision<D, S> {
    F64(D),
    F32(S),
}

impl<D, S> ByPrecision<D, S> {
    pub fn precision(&self) -> Precision {
        match self {
            ByPrecision::F64(_) => Precision::F64,
            ByPrecision::F32(_) => Precision::F32,
        }
    }
}

/// `each!(value, p => body)`: `body` with `p` bound to the value inside a [`ByPrecision`],
/// compiled once per precision (the body is generic code over the element type).
macro_rules! each {
    ($value:expr, $p:ident => $body:expr) => {
        match $value {
            $crate::arrays::ByPrecision::F64($p) => $body,
            $crate::arrays::ByPrecision::F32($p) => $body,
        }
    };
}
pub(crate) use each;

/// `build!(precision, T => value)`: a [`ByPrecision`] of `value` computed with the type
/// alias `T` standing for `f64` or `f32` as `precision` says.
macro_rules! build {
    ($precision:expr, $t:ident => $value:expr) => {
        match $precision {
            $crate::arrays::Precision::F64 => {
                #[allow(dead_code)]
                type $t = f64;
                $crate::arrays::ByPrecision::F64($value)
            }
            $crate::arrays::Precision::F32 => {
                #[allow(dead_code)]
                type $t = f32;
                $crate::arrays::ByPrecision::F32($value)
            }
        }
    };
}
pub(crate) use build;

/// `a` as a NumPy array of `T` (a `TypeError` naming `what` and both dtypes otherwise: the
/// package converts its arguments before it calls the extension).
pub fn typed<'a, 'py, T: Element>(
    a: &'a Bound<'py, PyAny>,
    what: &str,
) -> PyResult<&'a Bound<'py, PyArrayDyn<T>>> {
    a.cast::<PyArrayDyn<T>>().map_err(|_| {
        let got = match a.cast::<PyUntypedArray>() {
            Ok(u) => format!("an array of {}", u.dtype()),
            Err(_) => a
                .get_type()
                .name()
                .map(|n| n.to_string())
                .unwrap_or_default(),
        };
        PyTypeError::new_err(format!(
            "{what} must be a numpy array of {}, not {got}",
            T::get_dtype(a.py())
        ))
    })
}

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
/// otherwise (floats widened exactly); 32 independent sums keep the loop vectorised and off
/// the add latency.
pub fn all_finite<T: Float>(values: &[Complex<T>]) -> bool {
    let mut acc = [0.0f64; 32];
    let chunks = values.chunks_exact(16);
    let rest = chunks.remainder();
    for c in chunks {
        for i in 0..16 {
            acc[2 * i] += c[i].re.into() * 0.0;
            acc[2 * i + 1] += c[i].im.into() * 0.0;
        }
    }
    for z in rest {
        acc[0] += z.re.into() * 0.0;
        acc[1] += z.im.into() * 0.0;
    }
    acc.iter().sum::<f64>() == 0.0
}

/// [`all_finite`] of real values.
pub fn all_finite_real<T: Float>(values: &[T]) -> bool {
    let mut acc = [0.0f64; 32];
    let chunks = values.chunks_exact(32);
    let rest = chunks.remainder();
    for c in chunks {
        for i in 0..32 {
            acc[i] += c[i].into() * 0.0;
        }
    }
    for x in rest {
        acc[0] += (*x).into() * 0.0;
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
