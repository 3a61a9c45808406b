//! Rotational matching: the correlation plan, peaks of a correlation grid, refinement off the
//! grid, rotations.

use crate::arrays::{
    all_finite, all_finite_real, input, not_finite_always, output, readonly, readwrite,
};
use crate::errors::{to_py, value_error};
use crate::layout::checked;
use crate::transforms::options;
use numpy::{
    Element, PyArray1, PyArray2, PyArrayDyn, PyArrayMethods, PyReadonlyArray2, PyReadonlyArrayDyn,
    PyUntypedArrayMethods,
};
use pyo3::prelude::*;
use so3fft::matching::{self, CorrelationOptions, Peak, Rotation};
use so3fft::Complex64;

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<Correlation>()?;
    m.add_function(wrap_pyfunction!(top_peaks, m)?)?;
    m.add_function(wrap_pyfunction!(top_peaks_real, m)?)?;
    m.add_function(wrap_pyfunction!(euler_to_quaternion, m)?)?;
    m.add_function(wrap_pyfunction!(euler_to_matrix, m)?)?;
    m.add_function(wrap_pyfunction!(rotate_s2_coeffs, m)?)?;
    m.add_function(wrap_pyfunction!(refine_series, m)?)?;
    m.add_function(wrap_pyfunction!(evaluate_series, m)?)?;
    Ok(())
}

/// A peak as `(index, alpha, beta, gamma, value)`.
type PeakTuple = (usize, f64, f64, f64, f64);

fn peak_tuple(p: &Peak) -> PeakTuple {
    (p.index, p.alpha, p.beta, p.gamma, p.value)
}

/// A correlation plan (low level: exact arrays, no allocation).
#[pyclass(frozen, module = "so3fft._so3fft")]
pub struct Correlation {
    plan: matching::Correlation,
}

/// A shell as the caller gives it: signal, pattern, weight.
type ShellArrays<'py, T> = (Bound<'py, PyArrayDyn<T>>, Bound<'py, PyArrayDyn<T>>, f64);

/// Shells as the library takes them, from `(signal, pattern, weight)` arrays.
type Shells<'a, T> = Vec<(&'a [T], &'a [T], f64)>;

impl Correlation {
    fn s2_samples(&self) -> usize {
        so3fft::s2::s2_num_samples(self.plan.b_in())
    }

    /// Borrows `signal`, `pattern` (S^2 samples) and `out` (`out_len` values), checks the
    /// inputs with `finite`, and runs `run` with the GIL released.
    #[allow(clippy::type_complexity)]
    fn run_pair<I: Element + Sync, O: Element + Send, R: Send>(
        &self,
        py: Python<'_>,
        (signal, pattern, out): (
            &Bound<'_, PyArrayDyn<I>>,
            &Bound<'_, PyArrayDyn<I>>,
            &Bound<'_, PyArrayDyn<O>>,
        ),
        (out_len, finite): (usize, fn(&[I]) -> bool),
        run: &(dyn Fn(&[I], &[I], &mut [O]) -> so3fft::Result<R> + Sync),
    ) -> PyResult<R> {
        let signal = readonly(signal)?;
        let pattern = readonly(pattern)?;
        let mut out = readwrite(out)?;
        let n = self.s2_samples();
        let (s, p) = (input(&signal, n, "signal")?, input(&pattern, n, "pattern")?);
        self.check_inputs(py, &[s, p], finite)?;
        let o = output(&mut out, out_len, "out")?;
        py.detach(|| run(s, p, o)).map_err(to_py)
    }

    /// Checks, with the GIL released, that the inputs are finite.
    fn check_inputs<T: Sync>(
        &self,
        py: Python<'_>,
        values: &[&[T]],
        finite: impl Fn(&[T]) -> bool + Send + Sync,
    ) -> PyResult<()> {
        if py.detach(|| values.iter().all(|v| finite(v))) {
            Ok(())
        } else {
            Err(not_finite_always("signal or pattern samples"))
        }
    }
}

#[pymethods]
impl Correlation {
    #[new]
    #[pyo3(signature = (b_in, b_out, deg_lim, real, normalized, threads, rigor))]
    #[allow(clippy::too_many_arguments)]
    fn new(
        py: Python<'_>,
        b_in: usize,
        b_out: Option<usize>,
        deg_lim: Option<usize>,
        real: bool,
        normalized: bool,
        threads: usize,
        rigor: &str,
    ) -> PyResult<Self> {
        let o = CorrelationOptions::default()
            .with_b_out(b_out)
            .with_deg_lim(deg_lim)
            .with_real(real)
            .with_normalized(normalized)
            .with_plans(options(threads, rigor, real)?);
        let plan = py
            .detach(|| matching::Correlation::new(b_in, &o))
            .map_err(to_py)?;
        Ok(Correlation { plan })
    }

    #[getter]
    fn b_in(&self) -> usize {
        self.plan.b_in()
    }

    #[getter]
    fn b_out(&self) -> usize {
        self.plan.b_out()
    }

    #[getter]
    fn deg_lim(&self) -> usize {
        self.plan.deg_lim()
    }

    #[getter]
    fn real(&self) -> bool {
        self.plan.is_real()
    }

    #[getter]
    fn num_grid(&self) -> usize {
        self.plan.num_grid()
    }

    /// The correlation grid of complex inputs; with `argmax`, also its largest `|C|^2`.
    fn correlate(
        &self,
        py: Python<'_>,
        signal: Bound<'_, PyArrayDyn<Complex64>>,
        pattern: Bound<'_, PyArrayDyn<Complex64>>,
        out: Bound<'_, PyArrayDyn<Complex64>>,
        argmax: bool,
    ) -> PyResult<Option<PeakTuple>> {
        let grid = (self.plan.num_grid(), all_finite as fn(&[_]) -> bool);
        self.run_pair(py, (&signal, &pattern, &out), grid, &|s, p, g| {
            if argmax {
                self.plan
                    .correlate_argmax(s, p, g)
                    .map(|k| Some(peak_tuple(&k)))
            } else {
                self.plan.correlate(s, p, g).map(|_| None)
            }
        })
    }

    /// The correlation grid of real inputs (a real plan); with `argmax`, also its peak.
    fn correlate_real(
        &self,
        py: Python<'_>,
        signal: Bound<'_, PyArrayDyn<f64>>,
        pattern: Bound<'_, PyArrayDyn<f64>>,
        out: Bound<'_, PyArrayDyn<f64>>,
        argmax: bool,
    ) -> PyResult<Option<PeakTuple>> {
        let grid = (self.plan.num_grid(), all_finite_real as fn(&[_]) -> bool);
        self.run_pair(py, (&signal, &pattern, &out), grid, &|s, p, g| {
            if argmax {
                self.plan
                    .correlate_real_argmax(s, p, g)
                    .map(|k| Some(peak_tuple(&k)))
            } else {
                self.plan.correlate_real(s, p, g).map(|_| None)
            }
        })
    }

    /// The weighted sum of the correlations of shells `(signal, pattern, weight)`.
    fn correlate_shells(
        &self,
        py: Python<'_>,
        shells: Vec<ShellArrays<'_, Complex64>>,
        out: Bound<'_, PyArrayDyn<Complex64>>,
    ) -> PyResult<()> {
        let borrowed = shells
            .iter()
            .map(|(s, p, w)| Ok((readonly(s)?, readonly(p)?, *w)))
            .collect::<PyResult<Vec<_>>>()?;
        let mut out = readwrite(&out)?;
        let n = self.s2_samples();
        let mut views: Shells<'_, Complex64> = Vec::with_capacity(shells.len());
        for (s, p, w) in &borrowed {
            let (s, p) = (input(s, n, "signal")?, input(p, n, "pattern")?);
            self.check_inputs(py, &[s, p], all_finite)?;
            views.push((s, p, *w));
        }
        let g = output(&mut out, self.plan.num_grid(), "out")?;
        py.detach(|| self.plan.correlate_shells(&views, g))
            .map_err(to_py)
    }

    /// [`Correlation::correlate_shells`] of real shells.
    fn correlate_shells_real(
        &self,
        py: Python<'_>,
        shells: Vec<ShellArrays<'_, f64>>,
        out: Bound<'_, PyArrayDyn<f64>>,
    ) -> PyResult<()> {
        let borrowed = shells
            .iter()
            .map(|(s, p, w)| Ok((readonly(s)?, readonly(p)?, *w)))
            .collect::<PyResult<Vec<_>>>()?;
        let mut out = readwrite(&out)?;
        let n = self.s2_samples();
        let mut views: Shells<'_, f64> = Vec::with_capacity(shells.len());
        for (s, p, w) in &borrowed {
            let (s, p) = (input(s, n, "signal")?, input(p, n, "pattern")?);
            self.check_inputs(py, &[s, p], all_finite_real)?;
            views.push((s, p, *w));
        }
        let g = output(&mut out, self.plan.num_grid(), "out")?;
        py.detach(|| self.plan.correlate_shells_real(&views, g))
            .map_err(to_py)
    }

    /// The SO(3) coefficients of the correlation (bandwidth `b_out`), for refinement.
    fn coefficients(
        &self,
        py: Python<'_>,
        signal: Bound<'_, PyArrayDyn<Complex64>>,
        pattern: Bound<'_, PyArrayDyn<Complex64>>,
        out: Bound<'_, PyArrayDyn<Complex64>>,
    ) -> PyResult<()> {
        let coeffs = (
            so3fft::num_coeffs(self.plan.b_out()),
            all_finite as fn(&[_]) -> bool,
        );
        self.run_pair(py, (&signal, &pattern, &out), coeffs, &|s, p, c| {
            self.plan.coefficients(s, p, c)
        })
    }

    /// [`Correlation::coefficients`] of real inputs.
    fn coefficients_real(
        &self,
        py: Python<'_>,
        signal: Bound<'_, PyArrayDyn<f64>>,
        pattern: Bound<'_, PyArrayDyn<f64>>,
        out: Bound<'_, PyArrayDyn<Complex64>>,
    ) -> PyResult<()> {
        let coeffs = (
            so3fft::num_coeffs(self.plan.b_out()),
            all_finite_real as fn(&[_]) -> bool,
        );
        self.run_pair(py, (&signal, &pattern, &out), coeffs, &|s, p, c| {
            self.plan.coefficients_real(s, p, c)
        })
    }

    /// Refines each start rotation (rows of Euler angles) to the nearest maximum of `|C|^2`
    /// of the band-limited correlation with coefficients `coeffs`; the rotations (rows) and
    /// the values there.
    #[allow(clippy::type_complexity)]
    fn refine<'py>(
        &self,
        py: Python<'py>,
        coeffs: Bound<'_, PyArrayDyn<Complex64>>,
        starts: PyReadonlyArray2<'_, f64>,
    ) -> PyResult<(Bound<'py, PyArray2<f64>>, Bound<'py, PyArray1<f64>>)> {
        let coeffs = readonly(&coeffs)?;
        let c = input(
            &coeffs,
            so3fft::num_coeffs(self.plan.b_out()),
            "coefficients",
        )?;
        if !all_finite(c) {
            return Err(not_finite_always("coefficients"));
        }
        let gs = rotations(&starts)?;
        let found = py.detach(|| self.plan.refine_many(c, &gs)).map_err(to_py)?;
        found_arrays(py, &found)
    }
}

/// Rows of Euler angles as rotations (all finite).
fn rotations(rows: &PyReadonlyArray2<'_, f64>) -> PyResult<Vec<Rotation>> {
    let values = rows
        .as_slice()
        .map_err(|_| value_error("the rotations must be a C-contiguous, aligned array"))?;
    if rows.shape()[1] != 3 {
        return Err(value_error(
            "rotations must be rows of three Euler angles (alpha, beta, gamma)",
        ));
    }
    let gs: Vec<Rotation> = values
        .chunks_exact(3)
        .map(|r| Rotation::new(r[0], r[1], r[2]))
        .collect();
    if gs.iter().any(|g| !g.is_finite()) {
        return Err(value_error("the rotations' angles must be finite"));
    }
    Ok(gs)
}

/// Refined rotations and values as arrays `(k, 3)` and `(k,)`.
#[allow(clippy::type_complexity)]
fn found_arrays<'py>(
    py: Python<'py>,
    found: &[(Rotation, f64)],
) -> PyResult<(Bound<'py, PyArray2<f64>>, Bound<'py, PyArray1<f64>>)> {
    let angles: Vec<f64> = found
        .iter()
        .flat_map(|(g, _)| [g.alpha, g.beta, g.gamma])
        .collect();
    let values: Vec<f64> = found.iter().map(|(_, v)| *v).collect();
    Ok((
        PyArray1::from_vec(py, angles).reshape([found.len(), 3])?,
        PyArray1::from_vec(py, values),
    ))
}

/// The series of SO(3) coefficients of bandwidth `bandwidth`, degrees `<= deg_lim`.
fn series(bandwidth: usize, deg_lim: usize, c: &[Complex64]) -> PyResult<matching::So3Series> {
    checked(bandwidth, so3fft::MAX_BANDWIDTH)?;
    if deg_lim >= bandwidth {
        return Err(value_error(format!(
            "deg_lim = {deg_lim} must be below the bandwidth {bandwidth}"
        )));
    }
    if c.len() != so3fft::num_coeffs(bandwidth) {
        return Err(value_error(format!(
            "coefficients: {} values, bandwidth {bandwidth} has {}",
            c.len(),
            so3fft::num_coeffs(bandwidth)
        )));
    }
    if !all_finite(c) {
        return Err(not_finite_always("coefficients"));
    }
    Ok(matching::So3Series::new(bandwidth, deg_lim, c))
}

/// Refines each start rotation to the nearest maximum of `|C|^2` of the series of `coeffs`
/// (degrees `<= deg_lim`); the rotations (rows) and the values there.
#[pyfunction]
#[allow(clippy::type_complexity)]
fn refine_series<'py>(
    py: Python<'py>,
    bandwidth: usize,
    deg_lim: usize,
    coeffs: PyReadonlyArrayDyn<'_, Complex64>,
    starts: PyReadonlyArray2<'_, f64>,
) -> PyResult<(Bound<'py, PyArray2<f64>>, Bound<'py, PyArray1<f64>>)> {
    let c = coeffs
        .as_slice()
        .map_err(|_| value_error("the coefficients must be C-contiguous"))?;
    let gs = rotations(&starts)?;
    let found = py.detach(|| series(bandwidth, deg_lim, c).map(|s| s.maximise_many(&gs)))?;
    found_arrays(py, &found)
}

/// The band-limited function of SO(3) coefficients `coeffs` (degrees `<= deg_lim`) at each
/// rotation (rows of Euler angles).
#[pyfunction]
fn evaluate_series<'py>(
    py: Python<'py>,
    bandwidth: usize,
    deg_lim: usize,
    coeffs: PyReadonlyArrayDyn<'_, Complex64>,
    at: PyReadonlyArray2<'_, f64>,
) -> PyResult<Bound<'py, PyArray1<Complex64>>> {
    let c = coeffs
        .as_slice()
        .map_err(|_| value_error("the coefficients must be C-contiguous"))?;
    let gs = rotations(&at)?;
    let values = py.detach(|| series(bandwidth, deg_lim, c).map(|s| s.values(&gs)))?;
    Ok(PyArray1::from_vec(py, values))
}

/// Checks a grid and the peak-selection arguments; the grid's bandwidth.
fn peak_args(len: usize, min_angle: f64) -> PyResult<usize> {
    let b = ((len as f64 / 8.0).cbrt().round() as usize).max(1);
    if 8 * (b as u128).pow(3) != len as u128 {
        return Err(value_error(format!(
            "a grid holds (2B)^3 values, not {len}"
        )));
    }
    if min_angle.is_nan() || min_angle < 0.0 {
        return Err(value_error(format!(
            "min_angle must be a non-negative number of radians, not {min_angle}"
        )));
    }
    Ok(b)
}

/// The `k` largest local maxima of `|C|^2` on a complex grid, each at least `min_angle`
/// radians from every larger one taken.
#[pyfunction]
fn top_peaks(
    py: Python<'_>,
    grid: PyReadonlyArrayDyn<'_, Complex64>,
    k: usize,
    min_angle: f64,
) -> PyResult<Vec<PeakTuple>> {
    let g = grid
        .as_slice()
        .map_err(|_| value_error("the grid must be C-contiguous"))?;
    let b = peak_args(g.len(), min_angle)?;
    if !py.detach(|| all_finite(g)) {
        return Err(not_finite_always("the grid"));
    }
    let peaks = py.detach(|| matching::top_peaks(b, g, k, min_angle));
    Ok(peaks.iter().map(peak_tuple).collect())
}

/// [`top_peaks`] of a real grid.
#[pyfunction]
fn top_peaks_real(
    py: Python<'_>,
    grid: PyReadonlyArrayDyn<'_, f64>,
    k: usize,
    min_angle: f64,
) -> PyResult<Vec<PeakTuple>> {
    let g = grid
        .as_slice()
        .map_err(|_| value_error("the grid must be C-contiguous"))?;
    let b = peak_args(g.len(), min_angle)?;
    if !py.detach(|| all_finite_real(g)) {
        return Err(not_finite_always("the grid"));
    }
    let peaks = py.detach(|| matching::top_peaks_real(b, g, k, min_angle));
    Ok(peaks.iter().map(peak_tuple).collect())
}

/// The unit quaternion `(w, x, y, z)` (`w >= 0`) of `Rz(alpha) Ry(beta) Rz(gamma)`.
#[pyfunction]
fn euler_to_quaternion(alpha: f64, beta: f64, gamma: f64) -> [f64; 4] {
    Rotation::new(alpha, beta, gamma).quaternion()
}

/// The matrix (rows) of `Rz(alpha) Ry(beta) Rz(gamma)`, acting on column vectors.
#[pyfunction]
fn euler_to_matrix(alpha: f64, beta: f64, gamma: f64) -> [[f64; 3]; 3] {
    Rotation::new(alpha, beta, gamma).matrix()
}

/// The S^2 coefficients of the function rotated by `Rz(alpha) Ry(beta) Rz(gamma)`.
#[pyfunction]
fn rotate_s2_coeffs<'py>(
    py: Python<'py>,
    bandwidth: usize,
    coeffs: PyReadonlyArrayDyn<'_, Complex64>,
    angles: (f64, f64, f64),
) -> PyResult<Bound<'py, PyArray1<Complex64>>> {
    let b = checked(bandwidth, so3fft::s2::S2_MAX_BANDWIDTH)?;
    let c = coeffs
        .as_slice()
        .map_err(|_| value_error("the coefficients must be C-contiguous"))?;
    if !all_finite(c) {
        return Err(not_finite_always("coefficients"));
    }
    let g = Rotation::new(angles.0, angles.1, angles.2);
    if !g.is_finite() {
        return Err(value_error("the rotation's angles must be finite"));
    }
    let out = py
        .detach(|| matching::rotate_s2_coeffs(b, c, &g))
        .map_err(to_py)?;
    Ok(PyArray1::from_vec(py, out))
}
