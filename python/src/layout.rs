//! Sizes, indices, grid angles and quadrature weights.

use crate::errors::{to_py, value_error};
use numpy::{PyArray1, PyArray2, PyArrayMethods};
use pyo3::prelude::*;

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("MAX_BANDWIDTH", so3fft::MAX_BANDWIDTH)?;
    m.add("S2_MAX_BANDWIDTH", so3fft::s2::S2_MAX_BANDWIDTH)?;
    m.add_function(wrap_pyfunction!(num_coeffs, m)?)?;
    m.add_function(wrap_pyfunction!(num_samples, m)?)?;
    m.add_function(wrap_pyfunction!(coef_index, m)?)?;
    m.add_function(wrap_pyfunction!(coef_degrees_orders, m)?)?;
    m.add_function(wrap_pyfunction!(s2_num_coeffs, m)?)?;
    m.add_function(wrap_pyfunction!(s2_num_samples, m)?)?;
    m.add_function(wrap_pyfunction!(s2_coef_index, m)?)?;
    m.add_function(wrap_pyfunction!(s2_coef_degrees_orders, m)?)?;
    m.add_function(wrap_pyfunction!(grid_angles, m)?)?;
    m.add_function(wrap_pyfunction!(weights, m)?)?;
    Ok(())
}

/// `bandwidth` if it is in `1 ..= max`.
pub fn checked(bandwidth: usize, max: usize) -> PyResult<usize> {
    if bandwidth == 0 || bandwidth > max {
        return Err(to_py(so3fft::Error::InvalidBandwidth { bandwidth, max }));
    }
    Ok(bandwidth)
}

#[pyfunction]
fn num_coeffs(bandwidth: usize) -> PyResult<usize> {
    Ok(so3fft::num_coeffs(checked(
        bandwidth,
        so3fft::MAX_BANDWIDTH,
    )?))
}

#[pyfunction]
fn num_samples(bandwidth: usize) -> PyResult<usize> {
    Ok(so3fft::num_samples(checked(
        bandwidth,
        so3fft::MAX_BANDWIDTH,
    )?))
}

#[pyfunction]
fn coef_index(bandwidth: usize, l: isize, m: isize, mp: isize) -> PyResult<usize> {
    let b = checked(bandwidth, so3fft::MAX_BANDWIDTH)?;
    let l = usize::try_from(l).map_err(|_| value_error(format!("degree l = {l} is negative")))?;
    so3fft::try_coef_index(b, l, m, mp).map_err(to_py)
}

/// `(l, m, mp)` of every coefficient, in the flat layout's order: shape `(num_coeffs, 3)`.
#[pyfunction]
fn coef_degrees_orders(py: Python<'_>, bandwidth: usize) -> PyResult<Bound<'_, PyArray2<i64>>> {
    let b = checked(bandwidth, so3fft::MAX_BANDWIDTH)?;
    let n = so3fft::num_coeffs(b);
    let mut lmm: Vec<i64> = Vec::new();
    lmm.try_reserve_exact(3 * n)
        .map_err(|_| to_py(so3fft::Error::OutOfMemory { bytes: 24 * n }))?;
    lmm.resize(3 * n, 0);
    let bi = b as isize;
    for m in 1 - bi..bi {
        for mp in 1 - bi..bi {
            for l in m.unsigned_abs().max(mp.unsigned_abs())..b {
                let at = 3 * so3fft::coef_index(b, l, m, mp);
                lmm[at..at + 3].copy_from_slice(&[l as i64, m as i64, mp as i64]);
            }
        }
    }
    PyArray1::from_vec(py, lmm).reshape([n, 3])
}

#[pyfunction]
fn s2_num_coeffs(bandwidth: usize) -> PyResult<usize> {
    Ok(so3fft::s2::s2_num_coeffs(checked(
        bandwidth,
        so3fft::s2::S2_MAX_BANDWIDTH,
    )?))
}

#[pyfunction]
fn s2_num_samples(bandwidth: usize) -> PyResult<usize> {
    Ok(so3fft::s2::s2_num_samples(checked(
        bandwidth,
        so3fft::s2::S2_MAX_BANDWIDTH,
    )?))
}

#[pyfunction]
fn s2_coef_index(bandwidth: usize, l: isize, m: isize) -> PyResult<usize> {
    let b = checked(bandwidth, so3fft::s2::S2_MAX_BANDWIDTH)?;
    let l = usize::try_from(l).map_err(|_| value_error(format!("degree l = {l} is negative")))?;
    so3fft::s2::s2_try_coef_index(b, l, m).map_err(to_py)
}

/// `(l, m)` of every S^2 coefficient, in the flat layout's order: shape `(B^2, 2)`.
#[pyfunction]
fn s2_coef_degrees_orders(py: Python<'_>, bandwidth: usize) -> PyResult<Bound<'_, PyArray2<i64>>> {
    let b = checked(bandwidth, so3fft::s2::S2_MAX_BANDWIDTH)?;
    let mut lm: Vec<i64> = Vec::new();
    lm.try_reserve_exact(2 * b * b)
        .map_err(|_| to_py(so3fft::Error::OutOfMemory { bytes: 16 * b * b }))?;
    lm.resize(2 * b * b, 0);
    for l in 0..b {
        let li = l as isize;
        for m in -li..=li {
            let at = 2 * so3fft::s2::s2_coef_index(b, l, m);
            lm[at..at + 2].copy_from_slice(&[l as i64, m as i64]);
        }
    }
    PyArray1::from_vec(py, lm).reshape([b * b, 2])
}

/// The grid's angles: `alpha_j = pi j / B`, `beta_k = pi (2k + 1) / (4B)`,
/// `gamma_j = pi j / B` (each `2B` values), up to the S^2 transforms' largest bandwidth.
#[pyfunction]
#[allow(clippy::type_complexity)]
fn grid_angles(
    py: Python<'_>,
    bandwidth: usize,
) -> PyResult<(
    Bound<'_, PyArray1<f64>>,
    Bound<'_, PyArray1<f64>>,
    Bound<'_, PyArray1<f64>>,
)> {
    let b = checked(bandwidth, so3fft::s2::S2_MAX_BANDWIDTH)?;
    let n = 2 * b;
    let a: Vec<f64> = (0..n).map(|j| so3fft::alpha(b, j)).collect();
    let be: Vec<f64> = (0..n).map(|k| so3fft::beta(b, k)).collect();
    let g: Vec<f64> = (0..n).map(|j| so3fft::gamma(b, j)).collect();
    Ok((
        PyArray1::from_vec(py, a),
        PyArray1::from_vec(py, be),
        PyArray1::from_vec(py, g),
    ))
}

/// The quadrature weights of the beta grid (`2B` values).
#[pyfunction]
fn weights(py: Python<'_>, bandwidth: usize) -> PyResult<Bound<'_, PyArray1<f64>>> {
    let b = checked(bandwidth, so3fft::s2::S2_MAX_BANDWIDTH)?;
    Ok(PyArray1::from_vec(py, so3fft::weights(b)))
}
