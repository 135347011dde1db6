//! `rotate` and `Rotator`: an image turned by any angle with three shears.

use std::sync::Mutex;

use haarshift::Sample;
use haarshift::kernels::{KernelOptions, Outside, ShiftMethod};
use haarshift::rotate::{Canvas, RotateOptions, RotationWorkspace, rotated_size};
use ndarray::{ArrayView2, ArrayViewMut2};
use numpy::{Element, PyArrayDyn, PyArrayMethods, PyUntypedArrayMethods};
use pyo3::prelude::*;

use crate::arrays::{ArrayArg, Integers, PlaneOp, apply_all, map_planes};
use crate::errors::{OrRaise, bad_argument};
use crate::options::{kernel, outside, parse};
use crate::scratch::{Kind, Scratch, lock};

/// How to rotate, apart from the angle.
#[derive(Clone, Copy, Debug)]
struct Rotation {
    method: ShiftMethod,
    kernel: KernelOptions,
    options: RotateOptions,
}

impl Rotation {
    #[allow(clippy::too_many_arguments)] // the keyword arguments of `rotate` and `Rotator`
    fn new(
        method: &str,
        precision: Option<u32>,
        retain: bool,
        keys_a: Option<f64>,
        canvas: &str,
        fill: Option<f64>,
        boundary: Option<&str>,
        supersample: u32,
    ) -> PyResult<Self> {
        let (method, kernel) = kernel(method, precision, retain, keys_a)?;
        let options = RotateOptions {
            canvas: parse::<Canvas>(canvas)?,
            outside: outside(fill, boundary)?,
            supersample,
            ..Default::default()
        };
        options.validate().or_raise()?;
        Ok(Rotation {
            method,
            kernel,
            options,
        })
    }
}

/// The intermediate images of rotations.
struct Intermediates;

impl Kind for Intermediates {
    type Of<T: Sample> = RotationWorkspace<T>;
}

thread_local! {
    /// `rotate`'s workspaces, one set per calling thread: a one-off call reuses the memory of
    /// the thread's previous rotation instead of faulting in fresh pages every time.
    static SCRATCH: Mutex<Scratch<Intermediates>> = Mutex::default();
}

/// One rotation of every plane through `scratch`.
struct Rotate<'a> {
    rotation: &'a Rotation,
    angle: f64,
    scratch: &'a Mutex<Scratch<Intermediates>>,
}

impl PlaneOp for Rotate<'_> {
    fn shape(&self, rows: usize, cols: usize) -> haarshift::Result<(usize, usize)> {
        rotated_size(rows, cols, self.angle, &self.rotation.options)
    }

    fn apply_into<T: Sample>(
        &self,
        plane: ArrayView2<'_, T>,
        out: ArrayViewMut2<'_, T>,
    ) -> haarshift::Result<()> {
        let kernel = self
            .rotation
            .method
            .kernel_with::<T>(&self.rotation.kernel)?;
        lock(self.scratch).get::<T>().rotate_plane_into(
            plane,
            self.angle,
            kernel.as_ref(),
            &self.rotation.options,
            out,
        )
    }
}

/// The image turned by `angle` degrees, as `haarshift rotate` turns it.
///
/// A positive angle turns counter-clockwise as displayed (row 0 at the top), like
/// scipy.ndimage.rotate, about the centre ((W-1)/2, (H-1)/2). The angle is split into exact
/// quarter turns (bit-exact for every method) and a residual in [-45, 45] degrees done by
/// three shears, each shifting every row or column with `method`: "bspline3" (the default),
/// "keys" (cubic convolution, `keys_a` default -0.5), "bspline5", "lanczos3", "lanczos4",
/// "fft", "nearest", "linear", or "haar" (`precision` H: shifts rounded to 1/2^H, default 3;
/// `retain=True` keeps the finer levels across the shears).
///
/// `canvas` "same" keeps the size, "expand" holds the whole rotated image. Samples from
/// outside are `fill` (default 0) or continue the image by `boundary` ("edge", "reflect",
/// "wrap", "zero"). `supersample` S rotates on a 2^S-finer grid and box-averages back (at
/// most 8).
///
/// `image` is (H, W) or (H, W, C), each channel rotated alone; float32 or float64 (kept),
/// uint8 or uint16 (computed in float32, rounded to the nearest code and clamped). A call
/// keeps its intermediate images for the calling thread's next call; `Rotator` keeps its own.
/// Raises ValueError for NaN or infinity, a non-finite angle or fill, an unknown name, a
/// parameter the method does not take, or too large a supersample or precision.
///
/// >>> import numpy as np, haarshift
/// >>> haarshift.rotate(np.array([[1.0, 2.0], [3.0, 4.0]]), 90)
/// array([[2., 4.],
///        [1., 3.]])
#[pyfunction]
#[pyo3(signature = (image, angle, *, method = "bspline3", precision = None, retain = false, keys_a = None, canvas = "same", fill = None, boundary = None, supersample = 0))]
#[allow(clippy::too_many_arguments)] // the keyword arguments of one Python function
pub fn rotate<'py>(
    py: Python<'py>,
    image: &Bound<'py, PyAny>,
    angle: f64,
    method: &str,
    precision: Option<u32>,
    retain: bool,
    keys_a: Option<f64>,
    canvas: &str,
    fill: Option<f64>,
    boundary: Option<&str>,
    supersample: u32,
) -> PyResult<Bound<'py, PyAny>> {
    let rotation = Rotation::new(
        method,
        precision,
        retain,
        keys_a,
        canvas,
        fill,
        boundary,
        supersample,
    )?;
    let image = ArrayArg::image(image, "image")?;
    SCRATCH.with(|scratch| {
        let op = Rotate {
            rotation: &rotation,
            angle,
            scratch,
        };
        map_planes(py, &image, &op, Integers::Codes)
    })
}

/// A rotation kept for repeated calls: its method, canvas and outside are fixed, and it keeps
/// its intermediate images between calls, so that rotating many images of one size costs no
/// allocation. `out=` writes into an existing array. Safe to share between threads (calls
/// take turns).
///
/// >>> import numpy as np, haarshift
/// >>> rotator = haarshift.Rotator(method="keys", canvas="expand")
/// >>> rotator(np.ones((20, 30), dtype=np.float32), 30).shape
/// (32, 36)
#[pyclass(module = "haarshift", frozen)]
pub struct Rotator {
    rotation: Rotation,
    scratch: Mutex<Scratch<Intermediates>>,
}

#[pymethods]
impl Rotator {
    #[new]
    #[pyo3(signature = (*, method = "bspline3", precision = None, retain = false, keys_a = None, canvas = "same", fill = None, boundary = None, supersample = 0))]
    #[allow(clippy::too_many_arguments)] // the keyword arguments of `rotate`
    fn new(
        method: &str,
        precision: Option<u32>,
        retain: bool,
        keys_a: Option<f64>,
        canvas: &str,
        fill: Option<f64>,
        boundary: Option<&str>,
        supersample: u32,
    ) -> PyResult<Self> {
        Ok(Rotator {
            rotation: Rotation::new(
                method,
                precision,
                retain,
                keys_a,
                canvas,
                fill,
                boundary,
                supersample,
            )?,
            scratch: Mutex::default(),
        })
    }

    /// rotate(image, angle, *, out=None): `image` turned by `angle` degrees (see
    /// `haarshift.rotate`). With `out` (a writeable array of the result's shape and the
    /// image's float dtype) the result is written there and `out` is returned.
    #[pyo3(signature = (image, angle, *, out = None))]
    fn rotate<'py>(
        &self,
        py: Python<'py>,
        image: &Bound<'py, PyAny>,
        angle: f64,
        out: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let image = ArrayArg::image(image, "image")?;
        let op = Rotate {
            rotation: &self.rotation,
            angle,
            scratch: &self.scratch,
        };
        let Some(out) = out else {
            return map_planes(py, &image, &op, Integers::Codes);
        };
        match &image {
            ArrayArg::F32(a) => write_into(py, a.as_array(), &op, out),
            ArrayArg::F64(a) => write_into(py, a.as_array(), &op, out),
            ArrayArg::U8(_) | ArrayArg::U16(_) => Err(bad_argument(
                "out",
                "out= takes float32 and float64 images (an integer image's result is rounded into a new array)",
            )),
        }?;
        Ok(out.clone())
    }

    /// Same as `rotate`.
    #[pyo3(signature = (image, angle, *, out = None))]
    fn __call__<'py>(
        &self,
        py: Python<'py>,
        image: &Bound<'py, PyAny>,
        angle: f64,
        out: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<Bound<'py, PyAny>> {
        self.rotate(py, image, angle, out)
    }

    fn __repr__(&self) -> String {
        let Rotation {
            method,
            kernel,
            options,
        } = self.rotation;
        let outside = match options.outside {
            Outside::Fill(v) => format!("fill={v}"),
            Outside::Boundary(mode) => format!("boundary='{mode}'"),
        };
        let parameters = match method {
            ShiftMethod::Haar => {
                format!(", precision={}, retain={}", kernel.precision, kernel.retain)
            }
            ShiftMethod::Keys => format!(", keys_a={}", kernel.keys_a),
            _ => String::new(),
        };
        format!(
            "Rotator(method='{method}'{parameters}, canvas='{}', {outside}, supersample={})",
            options.canvas, options.supersample
        )
    }
}

/// `op` on `input` into the caller's array `out`, checked for dtype, shape and writeability.
fn write_into<'py, T: Sample + Element>(
    py: Python<'py>,
    input: ndarray::ArrayViewD<'_, T>,
    op: &Rotate<'_>,
    out: &Bound<'py, PyAny>,
) -> PyResult<()> {
    let Ok(out) = out.cast::<PyArrayDyn<T>>() else {
        return Err(bad_argument(
            "out",
            format!("expected a {} array, like the image", T::NAME),
        ));
    };
    let (h, w) = op.shape(input.shape()[0], input.shape()[1]).or_raise()?;
    let mut expected = vec![h, w];
    expected.extend_from_slice(&input.shape()[2..]);
    if out.shape() != expected.as_slice() {
        return Err(bad_argument(
            "out",
            format!("shape {:?}, the result is {expected:?}", out.shape()),
        ));
    }
    let mut guard = out.try_readwrite().map_err(|e| bad_argument("out", e))?;
    let view = guard.as_array_mut();
    py.detach(|| apply_all(input, op, view)).or_raise()
}
