//! `Plan` (the SO(3) transform) and `S2Plan` (the S^2 transform) over NumPy arrays, in
//! double or single precision (one class each: the library's plan of either precision in a
//! [`ByPrecision`]). Each transform returns the seconds it took inside the library (for
//! measuring the bindings' overhead).

use crate::arrays::{
    all_finite, build, each, input, not_finite, output, readonly, readwrite, typed, ByPrecision,
    Float, Precision,
};
use crate::errors::{to_py, value_error};
use numpy::{Element, PyArrayDyn};
use pyo3::prelude::*;
use so3fft::s2::S2Plan as RustS2Plan;
use so3fft::{Complex, Options, Rigor, StageTimes};

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<Plan>()?;
    m.add_class::<S2Plan>()?;
    Ok(())
}

/// Values of `howmany` fields of `per_field` values each.
fn fields(howmany: usize, per_field: usize) -> PyResult<usize> {
    howmany
        .checked_mul(per_field)
        .ok_or_else(|| value_error(format!("{howmany} fields are too many")))
}

/// FFTW's planning rigour by name.
pub fn rigor(name: &str) -> PyResult<Rigor> {
    match name.to_ascii_lowercase().as_str() {
        "estimate" => Ok(Rigor::Estimate),
        "measure" => Ok(Rigor::Measure),
        "patient" => Ok(Rigor::Patient),
        "exhaustive" => Ok(Rigor::Exhaustive),
        _ => Err(value_error(format!(
            "rigor must be 'estimate', 'measure', 'patient' or 'exhaustive', not {name:?}"
        ))),
    }
}

/// The plans' options: `threads` workers (0: all cores), FFTW's `rigor`, real data or not.
pub fn options(threads: usize, rigor_name: &str, real: bool) -> PyResult<Options> {
    Ok(Options::default()
        .with_threads(threads)
        .with_rigor(rigor(rigor_name)?)
        .with_real(real))
}

/// A library transform from `In` values to `Out` values.
type Run<'a, In, Out> = &'a (dyn Fn(&[In], &mut [Out]) -> so3fft::Result<StageTimes> + Sync);

/// Runs a forward transform `run` from `samples` into `coeffs` (sizes `(samples, coeffs)`)
/// with the GIL released; with `check_finite`, non-finite samples (seen in the coefficients)
/// are an error. The library's seconds.
fn run_forward<X: Element + Sync, T: Float>(
    py: Python<'_>,
    (samples, coeffs): (
        &Bound<'_, PyArrayDyn<X>>,
        &Bound<'_, PyArrayDyn<Complex<T>>>,
    ),
    (ns, nc): (usize, usize),
    check_finite: bool,
    run: Run<'_, X, Complex<T>>,
) -> PyResult<f64>
where
    Complex<T>: Element,
{
    let samples = readonly(samples)?;
    let mut coeffs = readwrite(coeffs)?;
    let x = input(&samples, ns, "samples")?;
    let c = output(&mut coeffs, nc, "out")?;
    let (t, finite) = py
        .detach(|| run(x, c).map(|t| (t.total, !check_finite || all_finite(c))))
        .map_err(to_py)?;
    if finite {
        Ok(t)
    } else {
        Err(not_finite("samples"))
    }
}

/// Runs an inverse transform `run` from `coeffs` into `samples` (sizes `(coeffs, samples)`)
/// with the GIL released, after checking with `check_finite` that the coefficients are
/// finite. The library's seconds.
fn run_inverse<X: Element + Send, T: Float>(
    py: Python<'_>,
    (coeffs, samples): (
        &Bound<'_, PyArrayDyn<Complex<T>>>,
        &Bound<'_, PyArrayDyn<X>>,
    ),
    (nc, ns): (usize, usize),
    check_finite: bool,
    run: Run<'_, Complex<T>, X>,
) -> PyResult<f64>
where
    Complex<T>: Element,
{
    let coeffs = readonly(coeffs)?;
    let mut samples = readwrite(samples)?;
    let c = input(&coeffs, nc, "coefficients")?;
    let x = output(&mut samples, ns, "out")?;
    py.detach(|| {
        if check_finite && !all_finite(c) {
            return Ok(None);
        }
        run(c, x).map(|t| Some(t.total))
    })
    .map_err(to_py)?
    .ok_or_else(|| not_finite("coefficients"))
}

/// An SO(3) transform plan of one bandwidth, in double or single precision (low level:
/// exact arrays, no allocation).
#[pyclass(frozen, module = "so3fft._so3fft")]
pub struct Plan {
    plan: ByPrecision<so3fft::Plan<f64>, so3fft::Plan<f32>>,
    real: bool,
}

#[pymethods]
impl Plan {
    #[new]
    #[pyo3(signature = (bandwidth, real, threads, rigor, dtype = "float64"))]
    fn new(
        py: Python<'_>,
        bandwidth: usize,
        real: bool,
        threads: usize,
        rigor: &str,
        dtype: &str,
    ) -> PyResult<Self> {
        let o = options(threads, rigor, real)?;
        let plan = build!(Precision::from_name(dtype)?, T => py
            .detach(|| so3fft::Plan::<T>::new(bandwidth, &o))
            .map_err(to_py)?);
        Ok(Plan { plan, real })
    }

    #[getter]
    fn bandwidth(&self) -> usize {
        each!(&self.plan, p => p.bandwidth())
    }

    #[getter]
    fn real(&self) -> bool {
        self.real
    }

    /// The real dtype's name: `"float64"` or `"float32"`.
    #[getter]
    fn dtype(&self) -> &'static str {
        self.plan.precision().name()
    }

    #[getter]
    fn threads(&self) -> usize {
        each!(&self.plan, p => p.threads())
    }

    #[getter]
    fn num_samples(&self) -> usize {
        each!(&self.plan, p => p.num_samples())
    }

    #[getter]
    fn num_coeffs(&self) -> usize {
        each!(&self.plan, p => p.num_coeffs())
    }

    #[getter]
    fn memory_bytes(&self) -> usize {
        each!(&self.plan, p => p.memory_bytes())
    }

    #[getter]
    fn isa(&self) -> String {
        format!("{:?}", each!(&self.plan, p => p.isa())).to_lowercase()
    }

    /// Complex samples to coefficients.
    fn forward(
        &self,
        py: Python<'_>,
        samples: Bound<'_, PyAny>,
        coeffs: Bound<'_, PyAny>,
        check_finite: bool,
    ) -> PyResult<f64> {
        each!(&self.plan, p => {
            let arrays = (typed(&samples, "samples")?, typed(&coeffs, "out")?);
            let sizes = (p.num_samples(), p.num_coeffs());
            run_forward(py, arrays, sizes, check_finite, &|x, c| p.forward(x, c))
        })
    }

    /// Real samples to coefficients.
    fn forward_real(
        &self,
        py: Python<'_>,
        samples: Bound<'_, PyAny>,
        coeffs: Bound<'_, PyAny>,
        check_finite: bool,
    ) -> PyResult<f64> {
        each!(&self.plan, p => {
            let arrays = (typed(&samples, "samples")?, typed(&coeffs, "out")?);
            let sizes = (p.num_samples(), p.num_coeffs());
            run_forward(py, arrays, sizes, check_finite, &|x, c| p.forward_real(x, c))
        })
    }

    /// Coefficients to complex samples.
    fn inverse(
        &self,
        py: Python<'_>,
        coeffs: Bound<'_, PyAny>,
        samples: Bound<'_, PyAny>,
        check_finite: bool,
    ) -> PyResult<f64> {
        each!(&self.plan, p => {
            let arrays = (typed(&coeffs, "coefficients")?, typed(&samples, "out")?);
            let sizes = (p.num_coeffs(), p.num_samples());
            run_inverse(py, arrays, sizes, check_finite, &|c, x| p.inverse(c, x))
        })
    }

    /// Coefficients (of a real function) to real samples.
    fn inverse_real(
        &self,
        py: Python<'_>,
        coeffs: Bound<'_, PyAny>,
        samples: Bound<'_, PyAny>,
        check_finite: bool,
    ) -> PyResult<f64> {
        each!(&self.plan, p => {
            let arrays = (typed(&coeffs, "coefficients")?, typed(&samples, "out")?);
            let sizes = (p.num_coeffs(), p.num_samples());
            run_inverse(py, arrays, sizes, check_finite, &|c, x| p.inverse_real(c, x))
        })
    }
}

/// An S^2 transform plan of one bandwidth, in double or single precision; every call takes
/// `howmany` fields stored one after another.
#[pyclass(frozen, module = "so3fft._so3fft")]
pub struct S2Plan {
    plan: ByPrecision<RustS2Plan<f64>, RustS2Plan<f32>>,
}

impl S2Plan {
    /// The values of `howmany` fields: `(samples, coefficients)`.
    fn sizes(&self, howmany: usize) -> PyResult<(usize, usize)> {
        let (ns, nc) = each!(&self.plan, p => (p.num_samples(), p.num_coeffs()));
        Ok((fields(howmany, ns)?, fields(howmany, nc)?))
    }
}

#[pymethods]
impl S2Plan {
    #[new]
    #[pyo3(signature = (bandwidth, threads, rigor, dtype = "float64"))]
    fn new(
        py: Python<'_>,
        bandwidth: usize,
        threads: usize,
        rigor: &str,
        dtype: &str,
    ) -> PyResult<Self> {
        let o = options(threads, rigor, false)?;
        let plan = build!(Precision::from_name(dtype)?, T => py
            .detach(|| RustS2Plan::<T>::new(bandwidth, &o))
            .map_err(to_py)?);
        Ok(S2Plan { plan })
    }

    #[getter]
    fn bandwidth(&self) -> usize {
        each!(&self.plan, p => p.bandwidth())
    }

    /// The real dtype's name: `"float64"` or `"float32"`.
    #[getter]
    fn dtype(&self) -> &'static str {
        self.plan.precision().name()
    }

    #[getter]
    fn threads(&self) -> usize {
        each!(&self.plan, p => p.threads())
    }

    #[getter]
    fn num_samples(&self) -> usize {
        each!(&self.plan, p => p.num_samples())
    }

    #[getter]
    fn num_coeffs(&self) -> usize {
        each!(&self.plan, p => p.num_coeffs())
    }

    fn forward(
        &self,
        py: Python<'_>,
        samples: Bound<'_, PyAny>,
        coeffs: Bound<'_, PyAny>,
        howmany: usize,
        check_finite: bool,
    ) -> PyResult<f64> {
        let sizes = self.sizes(howmany)?;
        each!(&self.plan, p => {
            let arrays = (typed(&samples, "samples")?, typed(&coeffs, "out")?);
            run_forward(py, arrays, sizes, check_finite, &|x, c| {
                p.forward_many(x, c, howmany)
            })
        })
    }

    fn forward_real(
        &self,
        py: Python<'_>,
        samples: Bound<'_, PyAny>,
        coeffs: Bound<'_, PyAny>,
        howmany: usize,
        check_finite: bool,
    ) -> PyResult<f64> {
        let sizes = self.sizes(howmany)?;
        each!(&self.plan, p => {
            let arrays = (typed(&samples, "samples")?, typed(&coeffs, "out")?);
            run_forward(py, arrays, sizes, check_finite, &|x, c| {
                p.forward_real_many(x, c, howmany)
            })
        })
    }

    fn inverse(
        &self,
        py: Python<'_>,
        coeffs: Bound<'_, PyAny>,
        samples: Bound<'_, PyAny>,
        howmany: usize,
        check_finite: bool,
    ) -> PyResult<f64> {
        let (ns, nc) = self.sizes(howmany)?;
        each!(&self.plan, p => {
            let arrays = (typed(&coeffs, "coefficients")?, typed(&samples, "out")?);
            run_inverse(py, arrays, (nc, ns), check_finite, &|c, x| {
                p.inverse_many(c, x, howmany)
            })
        })
    }

    fn inverse_real(
        &self,
        py: Python<'_>,
        coeffs: Bound<'_, PyAny>,
        samples: Bound<'_, PyAny>,
        howmany: usize,
        check_finite: bool,
    ) -> PyResult<f64> {
        let (ns, nc) = self.sizes(howmany)?;
        each!(&self.plan, p => {
            let arrays = (typed(&coeffs, "coefficients")?, typed(&samples, "out")?);
            run_inverse(py, arrays, (nc, ns), check_finite, &|c, x| {
                p.inverse_real_many(c, x, howmany)
            })
        })
    }
}
