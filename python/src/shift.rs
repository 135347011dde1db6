//! `shift`: an image moved by whole or fractional pixels, in the Haar domain or with a pixel
//! kernel.

use haarshift::shift::PlaneShift;
use haarshift::{BoundaryMode, Sample};
use ndarray::{ArrayView2, ArrayViewMut2};
use pyo3::prelude::*;

use crate::arrays::{ArrayArg, Integers, PlaneOp, map_planes};
use crate::errors::OrRaise;
use crate::options::{kernel, parse};

/// One shift of every plane.
struct Shift {
    shift: PlaneShift,
    dx: f64,
    dy: f64,
}

impl PlaneOp for Shift {
    fn shape(&self, rows: usize, cols: usize) -> haarshift::Result<(usize, usize)> {
        self.shift.shape(rows, cols)
    }

    fn apply_into<T: Sample>(
        &self,
        plane: ArrayView2<'_, T>,
        mut out: ArrayViewMut2<'_, T>,
    ) -> haarshift::Result<()> {
        out.assign(&self.shift.apply(plane, self.dx, self.dy)?);
        Ok(())
    }
}

/// The image moved by `dx` columns and `dy` rows, as `haarshift shift` moves it.
///
/// The sign convention is scipy.ndimage.shift's: `out[r, c] = image[r - dy, c - dx]`, so a
/// positive dx moves content right and a positive dy moves it down.
///
/// `method` "haar" (the default) shifts directly on the Haar coefficients (pyramid, average
/// normalisation, full depth): periodic over the sides rounded up to powers of two, each
/// shift rounded to 1/2^precision pixel (default precision 3); an integer shift is exact and a
/// fractional one equals periodic linear interpolation at the rounded shift. With
/// `retain=True` the result is the 2^precision-finer image the retained levels describe
/// (2^precision times the height and width). The pixel kernels ("nearest", "linear",
/// "keys" with `keys_a`, "bspline3", "bspline5", "lanczos3", "lanczos4", "fft") shift rows,
/// then columns, with samples from outside given by `boundary` ("wrap", "zero", "edge",
/// "reflect"); the Haar shift is always "wrap".
///
/// `image` is (H, W) or (H, W, C), float32 or float64 (kept), uint8 or uint16 (computed in
/// float32, rounded back to codes). Raises ValueError for NaN or infinity in the image or the
/// shift, an unknown method or boundary, a parameter the method does not take, or a
/// precision above the largest the library allows.
///
/// >>> import numpy as np, haarshift
/// >>> haarshift.shift(np.array([[1.0, 2.0, 3.0, 4.0]]), 1)
/// array([[4., 1., 2., 3.]])
/// >>> haarshift.shift(np.array([[0.0, 2.0, 4.0, 6.0]]), 0.5, precision=1)
/// array([[3., 1., 3., 5.]])
#[pyfunction]
#[pyo3(signature = (image, dx, dy = 0.0, *, method = "haar", precision = None, retain = false, keys_a = None, boundary = "wrap"))]
#[allow(clippy::too_many_arguments)] // the keyword arguments of one Python function
pub fn shift<'py>(
    py: Python<'py>,
    image: &Bound<'py, PyAny>,
    dx: f64,
    dy: f64,
    method: &str,
    precision: Option<u32>,
    retain: bool,
    keys_a: Option<f64>,
    boundary: &str,
) -> PyResult<Bound<'py, PyAny>> {
    let (method, options) = kernel(method, precision, retain, keys_a)?;
    let boundary = parse::<BoundaryMode>(boundary)?;
    let shift = PlaneShift::new(method, options, boundary).or_raise()?;
    let image = ArrayArg::image(image, "image")?;
    map_planes(py, &image, &Shift { shift, dx, dy }, Integers::Codes)
}
