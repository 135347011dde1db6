//! numpy arrays in and out: which dtypes and shapes are taken, how planes are viewed and how
//! results come back.
//!
//! An image is `(H, W)` or `(H, W, C)`, of any strides (C or Fortran order, slices, negative
//! steps): it is read through a view, and copied only where a routine needs rows in memory
//! order. `float32` and `float64` images come back in their own dtype. `uint8` and `uint16`
//! images are computed in `float32`, in their code units (0..255, 0..65535), as the command line
//! reads 8- and 16-bit files; a result that is an image again (a shift, a rotation) is rounded to
//! the nearest code and clamped, as the command line writes them, and coefficients stay
//! `float32`.

use haarshift::{Sample, round_to_code};
use ndarray::{
    Array, ArrayD, ArrayView2, ArrayViewD, ArrayViewMut2, ArrayViewMutD, Axis, Ix2, IxDyn,
};
use numpy::{
    Element, PyArrayDyn, PyArrayMethods, PyReadonlyArrayDyn, PyUntypedArray, PyUntypedArrayMethods,
};
use pyo3::prelude::*;

use crate::errors::{OrRaise, bad_argument};

/// An array argument in one of the dtypes haarshift computes with or converts.
pub enum ArrayArg<'py> {
    /// `float32`, computed as it is.
    F32(PyReadonlyArrayDyn<'py, f32>),
    /// `float64`, computed as it is.
    F64(PyReadonlyArrayDyn<'py, f64>),
    /// `uint8` codes, computed in `float32`.
    U8(PyReadonlyArrayDyn<'py, u8>),
    /// `uint16` codes, computed in `float32`.
    U16(PyReadonlyArrayDyn<'py, u16>),
}

impl<'py> ArrayArg<'py> {
    /// `obj` (an ndarray, or anything `numpy.asarray` takes) as an image: 2 or 3 dimensions,
    /// none of them empty. `name` is the argument's name in error messages.
    pub fn image(obj: &Bound<'py, PyAny>, name: &str) -> PyResult<Self> {
        let array = as_ndarray(obj)?;
        let shape = array.shape();
        if !(2..=3).contains(&shape.len()) {
            return Err(bad_argument(
                name,
                format!(
                    "expected a 2D (H, W) or 3D (H, W, C) array, got {} dimensions {shape:?}",
                    shape.len()
                ),
            ));
        }
        if shape.contains(&0) {
            return Err(bad_argument(
                name,
                format!("array of shape {shape:?} is empty"),
            ));
        }
        Self::typed(&array, name)
    }

    /// The typed view of `array`, or a `ValueError` naming the dtypes taken.
    fn typed(array: &Bound<'py, PyUntypedArray>, name: &str) -> PyResult<Self> {
        if let Ok(a) = array.cast::<PyArrayDyn<f32>>() {
            return Ok(ArrayArg::F32(a.readonly()));
        }
        if let Ok(a) = array.cast::<PyArrayDyn<f64>>() {
            return Ok(ArrayArg::F64(a.readonly()));
        }
        if let Ok(a) = array.cast::<PyArrayDyn<u8>>() {
            return Ok(ArrayArg::U8(a.readonly()));
        }
        if let Ok(a) = array.cast::<PyArrayDyn<u16>>() {
            return Ok(ArrayArg::U16(a.readonly()));
        }
        Err(bad_argument(
            name,
            format!(
                "dtype {} is not supported (use float32, float64, uint8 or uint16)",
                array.dtype().str()?
            ),
        ))
    }

    /// A float copy of the array (codes as they are).
    pub fn to_float<T: Sample>(&self) -> ArrayD<T> {
        fn cast<S: Copy + Into<f64>, T: Sample>(view: ArrayViewD<'_, S>) -> ArrayD<T> {
            view.mapv(|v| T::from_f64(v.into()))
        }
        match self {
            ArrayArg::F32(a) => cast(a.as_array()),
            ArrayArg::F64(a) => cast(a.as_array()),
            ArrayArg::U8(a) => cast(a.as_array()),
            ArrayArg::U16(a) => cast(a.as_array()),
        }
    }

    /// The array's shape.
    pub fn shape(&self) -> &[usize] {
        match self {
            ArrayArg::F32(a) => a.shape(),
            ArrayArg::F64(a) => a.shape(),
            ArrayArg::U8(a) => a.shape(),
            ArrayArg::U16(a) => a.shape(),
        }
    }
}

/// `obj` itself when it is an ndarray, else `numpy.asarray(obj)`.
pub fn as_ndarray<'py>(obj: &Bound<'py, PyAny>) -> PyResult<Bound<'py, PyUntypedArray>> {
    if let Ok(array) = obj.cast::<PyUntypedArray>() {
        return Ok(array.clone());
    }
    let converted = obj
        .py()
        .import("numpy")?
        .getattr("asarray")?
        .call1((obj,))?;
    Ok(converted.cast_into::<PyUntypedArray>()?)
}

/// An operation on one image plane with a known output size, written into a given view.
pub trait PlaneOp: Sync {
    /// The output size of an input plane of `rows x cols`; checks the operation's options.
    fn shape(&self, rows: usize, cols: usize) -> haarshift::Result<(usize, usize)>;

    /// Writes the result for `plane` into `out` (of [`shape`](Self::shape), any strides).
    fn apply_into<T: Sample>(
        &self,
        plane: ArrayView2<'_, T>,
        out: ArrayViewMut2<'_, T>,
    ) -> haarshift::Result<()>;
}

/// What an integer image's result is.
#[derive(Clone, Copy, PartialEq, Eq)]
pub enum Integers {
    /// An image again: rounded to the nearest code and clamped, in the input's dtype.
    Codes,
    /// Coefficients: `float32`.
    Float,
}

/// `op` on every plane of `input` (each channel of an `(H, W, C)` array), with the GIL
/// released while it computes.
pub fn map_planes<'py>(
    py: Python<'py>,
    input: &ArrayArg<'py>,
    op: &impl PlaneOp,
    integers: Integers,
) -> PyResult<Bound<'py, PyAny>> {
    match input {
        ArrayArg::F32(a) => float_planes(py, a.as_array(), op),
        ArrayArg::F64(a) => float_planes(py, a.as_array(), op),
        ArrayArg::U8(a) => code_planes(py, a.as_array(), op, integers),
        ArrayArg::U16(a) => code_planes(py, a.as_array(), op, integers),
    }
}

/// The output shape of `op` for an input of `shape` (channels kept).
fn out_shape(op: &impl PlaneOp, shape: &[usize]) -> PyResult<Vec<usize>> {
    let (h, w) = op.shape(shape[0], shape[1]).or_raise()?;
    let mut out = vec![h, w];
    out.extend_from_slice(&shape[2..]);
    Ok(out)
}

/// A new C-ordered numpy array of `shape`, filled by `fill` with the GIL released.
pub fn new_array<'py, T: Element + Send>(
    py: Python<'py>,
    shape: Vec<usize>,
    fill: impl FnOnce(ArrayViewMutD<'_, T>) -> haarshift::Result<()> + Send,
) -> PyResult<Bound<'py, PyAny>> {
    // SAFETY: every element is written by `fill` before the array is returned; on an error
    // the array is dropped unread.
    let out = unsafe { PyArrayDyn::<T>::new(py, shape, false) };
    {
        let mut guard = out.readwrite();
        let view = guard.as_array_mut();
        py.detach(|| fill(view)).or_raise()?;
    }
    Ok(out.into_any())
}

fn float_planes<'py, T: Sample + Element>(
    py: Python<'py>,
    input: ArrayViewD<'_, T>,
    op: &impl PlaneOp,
) -> PyResult<Bound<'py, PyAny>> {
    let shape = out_shape(op, input.shape())?;
    new_array(py, shape, |out| apply_all(input, op, out))
}

/// `op` on each plane of `input` into the matching plane of `out`.
pub fn apply_all<T: Sample>(
    input: ArrayViewD<'_, T>,
    op: &impl PlaneOp,
    mut out: ArrayViewMutD<'_, T>,
) -> haarshift::Result<()> {
    if input.ndim() == 2 {
        let plane = input.into_dimensionality::<Ix2>().expect("two axes");
        let out = out.into_dimensionality::<Ix2>().expect("two axes");
        return op.apply_into(plane, out);
    }
    for (plane, out) in input.axis_iter(Axis(2)).zip(out.axis_iter_mut(Axis(2))) {
        let plane = plane.into_dimensionality::<Ix2>().expect("two axes");
        let out = out.into_dimensionality::<Ix2>().expect("two axes");
        op.apply_into(plane, out)?;
    }
    Ok(())
}

/// An integer sample type of images: its largest code and conversions.
pub trait Code: Element + Copy + Send + Sync {
    /// The largest code (255, 65535).
    const MAX: f64;
    /// The code as a float sample.
    fn to_f32(self) -> f32;
    /// A rounded, clamped float sample as a code.
    fn from_rounded(v: f32) -> Self;
}

impl Code for u8 {
    const MAX: f64 = 255.0;
    fn to_f32(self) -> f32 {
        f32::from(self)
    }
    fn from_rounded(v: f32) -> Self {
        v as u8
    }
}

impl Code for u16 {
    const MAX: f64 = 65535.0;
    fn to_f32(self) -> f32 {
        f32::from(self)
    }
    fn from_rounded(v: f32) -> Self {
        v as u16
    }
}

fn code_planes<'py, C: Code>(
    py: Python<'py>,
    input: ArrayViewD<'_, C>,
    op: &impl PlaneOp,
    integers: Integers,
) -> PyResult<Bound<'py, PyAny>> {
    let shape = out_shape(op, input.shape())?;
    let floats = || input.mapv(Code::to_f32);
    match integers {
        Integers::Float => new_array(py, shape, |out| apply_all(floats().view(), op, out)),
        Integers::Codes => new_array(py, shape.clone(), |mut out: ArrayViewMutD<'_, C>| {
            let mut result = Array::<f32, IxDyn>::zeros(IxDyn(&shape));
            apply_all(floats().view(), op, result.view_mut())?;
            out.zip_mut_with(&result, |o, &v| {
                *o = C::from_rounded(round_to_code(v, C::MAX));
            });
            Ok(())
        }),
    }
}
