//! `read_image` and `write_image`: the image files the command line reads and writes.

use std::path::PathBuf;

use haarshift::io::{WriteOptions, read_image as read, write_image as write};
use haarshift::{Channels, PlanarImage, Sample, SampleDepth};
use ndarray::{Array2, Array3, Axis};
use numpy::{Element, IntoPyArray};
use pyo3::prelude::*;

use crate::arrays::{ArrayArg, Code};
use crate::errors::{OrRaise, bad_argument};
use crate::options::parse;

/// read_image(path)
///
/// An image file as an array: PNG, JPEG, TIFF, OpenEXR, Radiance .hdr or .npy, recognised by
/// content. (H, W) for one channel, else (H, W, C) (C = 2, 3, 4: gray-alpha, RGB, RGBA).
/// 8- and 16-bit files give uint8 and uint16, half and single floats float32, a float64 .npy
/// float64. Raises FileNotFoundError, or OSError naming the file and what is wrong with it.
///
/// >>> import numpy as np, haarshift, os, tempfile
/// >>> path = os.path.join(tempfile.mkdtemp(), "gray.png")
/// >>> haarshift.write_image(path, np.full((2, 3), 200, dtype=np.uint8))
/// >>> haarshift.read_image(path)
/// array([[200, 200, 200],
///        [200, 200, 200]], dtype=uint8)
#[pyfunction]
pub fn read_image<'py>(py: Python<'py>, path: PathBuf) -> PyResult<Bound<'py, PyAny>> {
    let image = py.detach(|| read::<f64>(&path)).or_raise()?;
    Ok(match image.depth() {
        SampleDepth::U8 => interleaved(py, image.planes().mapv(|v| u8::from_rounded(v as f32))),
        SampleDepth::U16 => interleaved(py, image.planes().mapv(|v| u16::from_rounded(v as f32))),
        SampleDepth::F16 | SampleDepth::F32 => interleaved(py, image.planes().mapv(|v| v as f32)),
        SampleDepth::F64 => interleaved(py, image.into_parts().0),
    })
}

/// `(C, H, W)` planes as Python's `(H, W)` or `(H, W, C)`.
fn interleaved<'py, T: Element + Clone>(py: Python<'py>, planes: Array3<T>) -> Bound<'py, PyAny> {
    if planes.dim().0 == 1 {
        let plane: Array2<T> = planes.index_axis_move(Axis(0), 0);
        return plane.into_pyarray(py).into_any();
    }
    let mut hwc = planes.permuted_axes([1, 2, 0]);
    hwc = hwc.as_standard_layout().into_owned();
    hwc.into_pyarray(py).into_any()
}

/// write_image(path, image, *, force=False, depth=None)
///
/// Writes `image` ((H, W) or (H, W, C), C = 1 to 4) to `path`, in the format its extension
/// names (.png, .jpg, .tif, .exr, .hdr, .npy), atomically (a temporary file renamed into
/// place). The depth is the dtype's (uint8 "u8", uint16 "u16", float32 "f32", float64 "f64")
/// unless `depth` names another; float samples written at an integer depth are code values
/// (0..255), rounded and clamped. An existing file is replaced only with force=True
/// (FileExistsError otherwise).
///
/// >>> import numpy as np, haarshift, os, tempfile
/// >>> path = os.path.join(tempfile.mkdtemp(), "ramp.exr")
/// >>> haarshift.write_image(path, np.linspace(0, 1, 6, dtype=np.float32).reshape(2, 3))
/// >>> haarshift.read_image(path)[1]
/// array([0.6, 0.8, 1. ], dtype=float32)
#[pyfunction]
#[pyo3(signature = (path, image, *, force = false, depth = None))]
pub fn write_image(
    py: Python<'_>,
    path: PathBuf,
    image: &Bound<'_, PyAny>,
    force: bool,
    depth: Option<&str>,
) -> PyResult<()> {
    let image = ArrayArg::image(image, "image")?;
    let options = WriteOptions {
        force,
        depth: depth.map(parse::<SampleDepth>).transpose()?,
        ..Default::default()
    };
    match &image {
        ArrayArg::F64(a) => {
            let planar = planar(a.as_array().to_owned(), SampleDepth::F64)?;
            py.detach(|| write(&planar, &path, options)).or_raise()
        }
        _ => {
            let own = match &image {
                ArrayArg::U8(_) => SampleDepth::U8,
                ArrayArg::U16(_) => SampleDepth::U16,
                _ => SampleDepth::F32,
            };
            let planar = planar(image.to_float::<f32>(), own)?;
            py.detach(|| write(&planar, &path, options)).or_raise()
        }
    }
}

/// Python's `(H, W)` or `(H, W, C)` as planes.
fn planar<T: Sample>(data: ndarray::ArrayD<T>, depth: SampleDepth) -> PyResult<PlanarImage<T>> {
    let planes: Array3<T> = match data.ndim() {
        2 => data
            .into_dimensionality::<ndarray::Ix2>()
            .expect("two axes")
            .insert_axis(Axis(0)),
        _ => data
            .into_dimensionality::<ndarray::Ix3>()
            .expect("three axes")
            .permuted_axes([2, 0, 1])
            .as_standard_layout()
            .into_owned(),
    };
    let channels = Channels::from_count(planes.dim().0).map_err(|e| bad_argument("image", e))?;
    PlanarImage::new(planes, channels, depth).or_raise()
}
