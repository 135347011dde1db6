//! `transform` and `inverse`: the 2D Haar transform of an image and back.

use std::sync::Mutex;

use haarshift::transform::{Layout, Normalization, TransformSpec, inverse_into};
use haarshift::{BoundaryMode, Sample};
use ndarray::{ArrayView2, ArrayViewMut2};
use pyo3::prelude::*;

use crate::arrays::{ArrayArg, Integers, PlaneOp, map_planes};
use crate::options::{levels, parse};
use crate::scratch::{Kind, Scratch, lock};

/// The pyramid's scratch approximations.
struct Approximations;

impl Kind for Approximations {
    type Of<T: Sample> = Vec<T>;
}

thread_local! {
    /// `transform`'s scratch, one per calling thread (a quarter and a sixteenth of the largest
    /// image transformed), so that a call allocates only its result.
    static SCRATCH: Mutex<Scratch<Approximations>> = Mutex::default();
}

/// The forward transform of one plane.
struct Forward<'a> {
    spec: TransformSpec,
    scratch: &'a Mutex<Scratch<Approximations>>,
}

impl PlaneOp for Forward<'_> {
    fn shape(&self, rows: usize, cols: usize) -> haarshift::Result<(usize, usize)> {
        self.spec.padded_shape(rows, cols)
    }

    fn apply_into<T: Sample>(
        &self,
        plane: ArrayView2<'_, T>,
        out: ArrayViewMut2<'_, T>,
    ) -> haarshift::Result<()> {
        let mut scratch = lock(self.scratch);
        self.spec
            .forward_into(plane, out, scratch.get::<T>())
            .map(drop)
    }
}

/// The inverse transform of one plane of coefficients, cropped to `shape` if given.
struct Inverse {
    spec: TransformSpec,
    shape: Option<(usize, usize)>,
}

impl PlaneOp for Inverse {
    fn shape(&self, rows: usize, cols: usize) -> haarshift::Result<(usize, usize)> {
        let original = self.shape.unwrap_or((rows, cols));
        self.spec.info_for((rows, cols), original)?;
        Ok(original)
    }

    fn apply_into<T: Sample>(
        &self,
        plane: ArrayView2<'_, T>,
        out: ArrayViewMut2<'_, T>,
    ) -> haarshift::Result<()> {
        let info = self.spec.info_for(plane.dim(), out.dim())?;
        inverse_into(plane, &info, out)
    }
}

/// The 2D Haar transform of an image, as `haarshift transform` computes it.
///
/// `image` is (H, W) or (H, W, C) (each channel transformed alone), float32 or float64
/// (kept), uint8 or uint16 (transformed in float32). A side that is not a power of two is
/// padded up to one with `padding` ("zero", "edge", "reflect", "wrap"); the result has the
/// padded size. `layout` "pyramid" is the non-separable standard pyramid (Mallat layout: the
/// scaling block top left, each level's a (horizontal) detail to the right of its
/// approximation, b (vertical) below it, c (diagonal) diagonally); "separable" transforms
/// the rows fully, then the columns. `normalization` "average" (a parent is the mean of its
/// children) or "orthonormal". `levels` is "full" (or None) or a number of steps.
///
/// With normalization="orthonormal" a pyramid equals PyWavelets'
/// `wavedec2(x, "haar", mode="periodization")` placed by `pywt.coeffs_to_array`: cA top left,
/// pywt's cH (vertical detail) in haarshift's b band, cV in a, cD in c.
///
/// Raises ValueError for NaN or infinity, an empty array, a bad dimension count or dtype, an
/// unknown name or too many levels.
///
/// >>> import numpy as np, haarshift
/// >>> haarshift.transform(np.array([[1.0, 3.0], [5.0, 7.0]]))
/// array([[ 4., -1.],
///        [-2.,  0.]])
#[pyfunction]
#[pyo3(signature = (image, *, layout = "pyramid", normalization = "average", levels = None, padding = "zero"))]
pub fn transform<'py>(
    py: Python<'py>,
    image: &Bound<'py, PyAny>,
    layout: &str,
    normalization: &str,
    levels: Option<&Bound<'py, PyAny>>,
    padding: &str,
) -> PyResult<Bound<'py, PyAny>> {
    let spec = spec(layout, normalization, levels, padding)?;
    let image = ArrayArg::image(image, "image")?;
    SCRATCH.with(|scratch| map_planes(py, &image, &Forward { spec, scratch }, Integers::Float))
}

/// The image whose transform `coefficients` are (the inverse of `transform`, bit for bit
/// where the arithmetic is exact and to rounding otherwise).
///
/// `coefficients` is (H, W) or (H, W, C) with H and W powers of two, float32 or float64;
/// `layout`, `normalization` and `levels` must be those of the forward transform. `shape`
/// (rows, cols) crops the result to the image's size before padding (default: the
/// coefficients' size).
///
/// >>> import numpy as np, haarshift
/// >>> x = np.arange(12.0).reshape(3, 4)
/// >>> bool((haarshift.inverse(haarshift.transform(x), shape=x.shape) == x).all())
/// True
#[pyfunction]
#[pyo3(signature = (coefficients, *, layout = "pyramid", normalization = "average", levels = None, shape = None))]
pub fn inverse<'py>(
    py: Python<'py>,
    coefficients: &Bound<'py, PyAny>,
    layout: &str,
    normalization: &str,
    levels: Option<&Bound<'py, PyAny>>,
    shape: Option<(usize, usize)>,
) -> PyResult<Bound<'py, PyAny>> {
    let spec = spec(layout, normalization, levels, "zero")?;
    let coefficients = ArrayArg::image(coefficients, "coefficients")?;
    map_planes(py, &coefficients, &Inverse { spec, shape }, Integers::Float)
}

/// The transform the keyword arguments name.
fn spec(
    layout: &str,
    normalization: &str,
    levels_arg: Option<&Bound<'_, PyAny>>,
    padding: &str,
) -> PyResult<TransformSpec> {
    Ok(TransformSpec {
        layout: parse::<Layout>(layout)?,
        normalization: parse::<Normalization>(normalization)?,
        levels: levels(levels_arg)?,
        padding: parse::<BoundaryMode>(padding)?,
    })
}
