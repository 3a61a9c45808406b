//! Rotational matching: the correlation plan (double or single precision), peaks of a
//! correlation grid, refinement off the grid, rotations.

use crate::arrays::{
    all_finite, all_finite_real, build, each, input, not_finite_always, output, readonly,
    readwrite, typed, ByPrecision, Float, Precision,
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
use so3fft::{Complex, Complex32, Complex64};

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

/// A correlation plan in double or single precision (low level: exact arrays, no
/// allocation). The SO(3) coefficients and the refinement are `f64` in either.
#[pyclass(frozen, module = "so3fft._so3fft")]
pub struct Correlation {
    plan: ByPrecision<matching::Correlation<f64>, matching::Correlation<f32>>,
}

/// A shell as the caller gives it: signal, pattern, weight.
type ShellArrays<'py> = (Bound<'py, PyAny>, Bound<'py, PyAny>, f64);

/// Shells as the library takes them, from `(signal, pattern, weight)` arrays.
type Shells<'a, T> = Vec<(&'a [T], &'a [T], f64)>;

/// A library call on a signal, a pattern and an output.
type PairRun<'a, I, O, R> = &'a (dyn Fn(&[I], &[I], &mut [O]) -> so3fft::Result<R> + Sync);

/// A library call on shells and an output.
type ShellsRun<'a, I> = &'a (dyn Fn(&[(&[I], &[I], f64)], &mut [I]) -> so3fft::Result<()> + Sync);

/// A finiteness check of values of `T`.
type Finite<T> = fn(&[T]) -> bool;

/// The number of S^2 samples of the inputs of a plan of bandwidth `b_in`.
fn s2_samples(b_in: usize) -> usize {
    so3fft::s2::s2_num_samples(b_in)
}

/// Borrows `signal`, `pattern` (S^2 samples of bandwidth `b_in`) and `out` (`out_len`
/// values) as arrays of `I` and `O`, checks the inputs with `finite`, and runs `run` with the
/// GIL released.
#[allow(clippy::type_complexity)]
fn run_pair<I: Element + Sync, O: Element + Send, R: Send>(
    py: Python<'_>,
    (signal, pattern, out): (&Bound<'_, PyAny>, &Bound<'_, PyAny>, &Bound<'_, PyAny>),
    (b_in, out_len, finite): (usize, usize, Finite<I>),
    run: PairRun<'_, I, O, R>,
) -> PyResult<R> {
    let signal = readonly(typed::<I>(signal, "signal")?)?;
    let pattern = readonly(typed::<I>(pattern, "pattern")?)?;
    let mut out = readwrite(typed::<O>(out, "out")?)?;
    let n = s2_samples(b_in);
    let (s, p) = (input(&signal, n, "signal")?, input(&pattern, n, "pattern")?);
    check_inputs(py, &[s, p], finite)?;
    let o = output(&mut out, out_len, "out")?;
    py.detach(|| run(s, p, o)).map_err(to_py)
}

/// Borrows the shells' arrays (S^2 samples of bandwidth `b_in`) and `out` (`out_len` values)
/// as arrays of `I`, checks the inputs with `finite`, and runs `run` with the GIL released.
fn run_shells<I: Element + Sync + Send>(
    py: Python<'_>,
    (shells, out): (&[ShellArrays<'_>], &Bound<'_, PyAny>),
    (b_in, out_len, finite): (usize, usize, Finite<I>),
    run: ShellsRun<'_, I>,
) -> PyResult<()> {
    let borrowed = shells
        .iter()
        .map(|(s, p, w)| {
            let s = readonly(typed::<I>(s, "signal")?)?;
            Ok((s, readonly(typed::<I>(p, "pattern")?)?, *w))
        })
        .collect::<PyResult<Vec<_>>>()?;
    let mut out = readwrite(typed::<I>(out, "out")?)?;
    let n = s2_samples(b_in);
    let mut views: Shells<'_, I> = Vec::with_capacity(shells.len());
    for (s, p, w) in &borrowed {
        let (s, p) = (input(s, n, "signal")?, input(p, n, "pattern")?);
        check_inputs(py, &[s, p], finite)?;
        views.push((s, p, *w));
    }
    let g = output(&mut out, out_len, "out")?;
    py.detach(|| run(&views, g)).map_err(to_py)
}

/// Checks, with the GIL released, that the inputs are finite.
fn check_inputs<T: Sync>(
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

/// The complex and real finiteness checks of one precision, as function pointers.
fn finite<T: Float>() -> (Finite<Complex<T>>, Finite<T>) {
    (all_finite::<T>, all_finite_real::<T>)
}

#[pymethods]
impl Correlation {
    #[new]
    #[pyo3(signature = (b_in, b_out, deg_lim, real, normalized, threads, rigor, dtype = "float64"))]
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
        dtype: &str,
    ) -> PyResult<Self> {
        let o = CorrelationOptions::default()
            .with_b_out(b_out)
            .with_deg_lim(deg_lim)
            .with_real(real)
            .with_normalized(normalized)
            .with_plans(options(threads, rigor, real)?);
        let plan = build!(Precision::from_name(dtype)?, T => py
            .detach(|| matching::Correlation::<T>::new(b_in, &o))
            .map_err(to_py)?);
        Ok(Correlation { plan })
    }

    #[getter]
    fn b_in(&self) -> usize {
        each!(&self.plan, p => p.b_in())
    }

    #[getter]
    fn b_out(&self) -> usize {
        each!(&self.plan, p => p.b_out())
    }

    #[getter]
    fn deg_lim(&self) -> usize {
        each!(&self.plan, p => p.deg_lim())
    }

    #[getter]
    fn real(&self) -> bool {
        each!(&self.plan, p => p.is_real())
    }

    /// The real dtype's name of inputs and grid: `"float64"` or `"float32"`.
    #[getter]
    fn dtype(&self) -> &'static str {
        self.plan.precision().name()
    }

    #[getter]
    fn num_grid(&self) -> usize {
        each!(&self.plan, p => p.num_grid())
    }

    /// The correlation grid of complex inputs; with `argmax`, also its largest `|C|^2`.
    fn correlate(
        &self,
        py: Python<'_>,
        signal: Bound<'_, PyAny>,
        pattern: Bound<'_, PyAny>,
        out: Bound<'_, PyAny>,
        argmax: bool,
    ) -> PyResult<Option<PeakTuple>> {
        each!(&self.plan, p => {
            let sizes = (p.b_in(), p.num_grid(), finite().0);
            run_pair(py, (&signal, &pattern, &out), sizes, &|s, q, g| {
                if argmax {
                    p.correlate_argmax(s, q, g).map(|k| Some(peak_tuple(&k)))
                } else {
                    p.correlate(s, q, g).map(|_| None)
                }
            })
        })
    }

    /// The correlation grid of real inputs (a real plan); with `argmax`, also its peak.
    fn correlate_real(
        &self,
        py: Python<'_>,
        signal: Bound<'_, PyAny>,
        pattern: Bound<'_, PyAny>,
        out: Bound<'_, PyAny>,
        argmax: bool,
    ) -> PyResult<Option<PeakTuple>> {
        each!(&self.plan, p => {
            let sizes = (p.b_in(), p.num_grid(), finite().1);
            run_pair(py, (&signal, &pattern, &out), sizes, &|s, q, g| {
                if argmax {
                    p.correlate_real_argmax(s, q, g).map(|k| Some(peak_tuple(&k)))
                } else {
                    p.correlate_real(s, q, g).map(|_| None)
                }
            })
        })
    }

    /// The weighted sum of the correlations of shells `(signal, pattern, weight)`.
    fn correlate_shells(
        &self,
        py: Python<'_>,
        shells: Vec<ShellArrays<'_>>,
        out: Bound<'_, PyAny>,
    ) -> PyResult<()> {
        each!(&self.plan, p => {
            let sizes = (p.b_in(), p.num_grid(), finite().0);
            run_shells(py, (&shells, &out), sizes, &|v, g| p.correlate_shells(v, g))
        })
    }

    /// [`Correlation::correlate_shells`] of real shells.
    fn correlate_shells_real(
        &self,
        py: Python<'_>,
        shells: Vec<ShellArrays<'_>>,
        out: Bound<'_, PyAny>,
    ) -> PyResult<()> {
        each!(&self.plan, p => {
            let sizes = (p.b_in(), p.num_grid(), finite().1);
            run_shells(py, (&shells, &out), sizes, &|v, g| p.correlate_shells_real(v, g))
        })
    }

    /// The SO(3) coefficients of the correlation (bandwidth `b_out`, `complex128` in either
    /// precision), for refinement.
    fn coefficients(
        &self,
        py: Python<'_>,
        signal: Bound<'_, PyAny>,
        pattern: Bound<'_, PyAny>,
        out: Bound<'_, PyAny>,
    ) -> PyResult<()> {
        each!(&self.plan, p => {
            let sizes = (p.b_in(), so3fft::num_coeffs(p.b_out()), finite().0);
            run_pair(py, (&signal, &pattern, &out), sizes, &|s, q, c: &mut [Complex64]| {
                p.coefficients(s, q, c)
            })
        })
    }

    /// [`Correlation::coefficients`] of real inputs.
    fn coefficients_real(
        &self,
        py: Python<'_>,
        signal: Bound<'_, PyAny>,
        pattern: Bound<'_, PyAny>,
        out: Bound<'_, PyAny>,
    ) -> PyResult<()> {
        each!(&self.plan, p => {
            let sizes = (p.b_in(), so3fft::num_coeffs(p.b_out()), finite().1);
            run_pair(py, (&signal, &pattern, &out), sizes, &|s, q, c: &mut [Complex64]| {
                p.coefficients_real(s, q, c)
            })
        })
    }

    /// Refines each start rotation (rows of Euler angles) to the nearest maximum of `|C|^2`
    /// of the band-limited correlation with coefficients `coeffs` (`complex128` in either
    /// precision); the rotations (rows) and the values there, in `f64`.
    #[allow(clippy::type_complexity)]
    fn refine<'py>(
        &self,
        py: Python<'py>,
        coeffs: Bound<'_, PyArrayDyn<Complex64>>,
        starts: PyReadonlyArray2<'_, f64>,
    ) -> PyResult<(Bound<'py, PyArray2<f64>>, Bound<'py, PyArray1<f64>>)> {
        let coeffs = readonly(&coeffs)?;
        let c = input(&coeffs, so3fft::num_coeffs(self.b_out()), "coefficients")?;
        if !all_finite(c) {
            return Err(not_finite_always("coefficients"));
        }
        let gs = rotations(&starts)?;
        let found = py
            .detach(|| each!(&self.plan, p => p.refine_many(c, &gs)))
            .map_err(to_py)?;
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

/// The peaks of a grid of `X` values (`what` the library's peak search of its precision).
fn peaks<X: Element + Sync>(
    py: Python<'_>,
    grid: &Bound<'_, PyArrayDyn<X>>,
    (k, min_angle): (usize, f64),
    finite: Finite<X>,
    search: fn(usize, &[X], usize, f64) -> Vec<Peak>,
) -> PyResult<Vec<PeakTuple>> {
    let grid = readonly(grid)?;
    let g = grid
        .as_slice()
        .map_err(|_| value_error("the grid must be C-contiguous"))?;
    let b = peak_args(g.len(), min_angle)?;
    if !py.detach(|| finite(g)) {
        return Err(not_finite_always("the grid"));
    }
    let peaks = py.detach(|| search(b, g, k, min_angle));
    Ok(peaks.iter().map(peak_tuple).collect())
}

/// The `k` largest local maxima of `|C|^2` on a complex grid (`complex128` or `complex64`),
/// each at least `min_angle` radians from every larger one taken.
#[pyfunction]
fn top_peaks(
    py: Python<'_>,
    grid: Bound<'_, PyAny>,
    k: usize,
    min_angle: f64,
) -> PyResult<Vec<PeakTuple>> {
    match grid.cast::<PyArrayDyn<Complex32>>() {
        Ok(g) => peaks(
            py,
            g,
            (k, min_angle),
            all_finite,
            matching::top_peaks::<f32>,
        ),
        Err(_) => {
            let g = typed::<Complex64>(&grid, "the grid")?;
            peaks(
                py,
                g,
                (k, min_angle),
                all_finite,
                matching::top_peaks::<f64>,
            )
        }
    }
}

/// [`top_peaks`] of a real grid (`float64` or `float32`).
#[pyfunction]
fn top_peaks_real(
    py: Python<'_>,
    grid: Bound<'_, PyAny>,
    k: usize,
    min_angle: f64,
) -> PyResult<Vec<PeakTuple>> {
    match grid.cast::<PyArrayDyn<f32>>() {
        Ok(g) => peaks(
            py,
            g,
            (k, min_angle),
            all_finite_real,
            matching::top_peaks_real::<f32>,
        ),
        Err(_) => {
            let g = typed::<f64>(&grid, "the grid")?;
            peaks(
                py,
                g,
                (k, min_angle),
                all_finite_real,
                matching::top_peaks_real::<f64>,
            )
        }
    }
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
