//! The extension module `so3fft._so3fft`: so3fft's plans over NumPy arrays, for the Python
//! package `so3fft` (python/so3fft), which checks and converts the arguments, allocates the
//! outputs and documents the API. Everything here takes exactly-typed C-contiguous arrays,
//! releases the GIL while a transform runs, and turns every error into a Python exception.

use pyo3::prelude::*;

mod arrays;
mod errors;
mod layout;
mod matching;
mod transforms;

/// so3fft's extension module (see the package `so3fft` for the documented API). It keeps the
/// GIL on free-threaded interpreters: the module has not been checked for running without it.
#[pymodule(gil_used = true)]
fn _so3fft(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    transforms::register(m)?;
    layout::register(m)?;
    matching::register(m)?;
    Ok(())
}
