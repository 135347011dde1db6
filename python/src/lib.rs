//! haarshift from Python: the `haarshift._native` extension module.
//!
//! A thin layer like the command line's: it converts numpy arrays and keyword arguments to the
//! library's types, calls the library with the GIL released, and turns its errors into Python
//! exceptions. The Python package `haarshift/` re-exports it with type stubs.

mod arrays;
mod errors;
mod io;
mod options;
mod relight;
mod rotate;
mod scratch;
mod shift;
mod sphere;
mod transform;

use pyo3::prelude::*;

/// haarshift: signal processing in the Haar wavelet domain, on numpy arrays.
#[pymodule]
fn _native(py: Python<'_>, m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    m.add_function(wrap_pyfunction!(transform::transform, m)?)?;
    m.add_function(wrap_pyfunction!(transform::inverse, m)?)?;
    m.add_function(wrap_pyfunction!(shift::shift, m)?)?;
    m.add_function(wrap_pyfunction!(rotate::rotate, m)?)?;
    m.add_class::<rotate::Rotator>()?;
    m.add_function(wrap_pyfunction!(io::read_image, m)?)?;
    m.add_function(wrap_pyfunction!(io::write_image, m)?)?;
    m.add_submodule(&sphere::module(py)?)?;
    m.add_submodule(&relight::module(py)?)?;
    Ok(())
}
