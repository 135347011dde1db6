//! NumPy `.npy` float arrays: images as `H x W` or `H x W x C`, and the raw arrays of
//! coefficient files.

use std::io::{Seek, Write};
use std::path::Path;

use ndarray::{Array, ArrayD, IxDyn};
use ndarray_npy::npy::header::Header;
use ndarray_npy::{ReadNpyExt, WriteNpyExt};

use super::{ReadOptions, Source, check_size, format_reason, interleave, io_error, planar};
use crate::{Error, PlanarImage, Result, Sample, SampleDepth};

/// Reads an image stored as `H x W` (gray) or `H x W x C` (C = 1..=4) floats.
pub(super) fn read<T: Sample>(
    source: &Source<'_>,
    options: &ReadOptions,
) -> Result<PlanarImage<T>> {
    let path = source.name();
    let (array, depth) = read_array::<T>(source, options, |shape| match shape {
        [_, _] => Ok(()),
        [_, _, c] if (1..=4).contains(c) => Ok(()),
        _ => Err(format!(
            "array of shape {shape:?} is not an image (expected H x W, or H x W x C with C = 1 \
             to 4)"
        )),
    })?;
    let array = if array.ndim() == 2 {
        array.insert_axis(ndarray::Axis(2))
    } else {
        array
    };
    let planes = array
        .into_dimensionality::<ndarray::Ix3>()
        .map_err(|e| format_reason(path, e.to_string()))?
        .permuted_axes([2, 0, 1]);
    planar(path, planes.as_standard_layout().into_owned(), depth)
}

/// Reads a float32 or float64 array whose shape `accept` allows, after checking its size
/// against the file's length and the memory limit; returns it with the depth it was stored in.
pub(super) fn read_array<T: Sample>(
    source: &Source<'_>,
    options: &ReadOptions,
    accept: impl Fn(&[usize]) -> std::result::Result<(), String>,
) -> Result<(ArrayD<T>, SampleDepth)> {
    let path = source.name();
    let file_len = source.len()?;
    let mut reader = source.open()?;
    let header = Header::from_reader(&mut reader)
        .map_err(|e| format_reason(path, format!("invalid .npy header: {e}")))?;
    let data_start = reader.stream_position().map_err(|e| io_error(path, e))?;
    let descriptor = header.type_descriptor.to_string();
    let descriptor = descriptor.trim_matches(|c| c == '\'' || c == '"');
    let (depth, element_size) = match descriptor {
        "<f4" | ">f4" | "=f4" => (SampleDepth::F32, 4),
        "<f8" | ">f8" | "=f8" => (SampleDepth::F64, 8),
        other => {
            return Err(format_reason(
                path,
                format!("unsupported .npy element type {other} (expected float32 or float64)"),
            ));
        }
    };
    let shape = header.shape.clone();
    accept(&shape).map_err(|reason| format_reason(path, reason))?;
    check_size::<T>(path, &shape, element_size, options.memory_limit)?;
    let needed = shape
        .iter()
        .fold(element_size as u128, |n, &d| n.saturating_mul(d as u128));
    let available = u128::from(file_len.saturating_sub(data_start));
    if available < needed {
        return Err(format_reason(
            path,
            format!(
                "file is truncated: the header promises {needed} bytes of data, {available} are present"
            ),
        ));
    }
    reader.rewind().map_err(|e| io_error(path, e))?;
    let npy_error =
        |e: ndarray_npy::ReadNpyError| format_reason(path, format!("invalid .npy data: {e}"));
    let array: ArrayD<T> = match depth {
        SampleDepth::F32 => ArrayD::<f32>::read_npy(reader)
            .map_err(npy_error)?
            .mapv(|v| T::from_f64(f64::from(v))),
        _ => ArrayD::<f64>::read_npy(reader)
            .map_err(npy_error)?
            .mapv(T::from_f64),
    };
    Ok((array, depth))
}

/// Writes an image as `H x W` (gray) or `H x W x C`, f64 at depth `F64` and f32 otherwise.
pub(super) fn write<T: Sample, W: Write>(
    image: &PlanarImage<T>,
    depth: SampleDepth,
    path: &Path,
    out: &mut W,
) -> Result<()> {
    let (c, h, w) = image.planes().dim();
    let shape = if c == 1 { vec![h, w] } else { vec![h, w, c] };
    match depth {
        SampleDepth::F64 => write_array(interleave(image, depth, |v| v), &shape, path, out),
        _ => write_array(interleave(image, depth, |v| v as f32), &shape, path, out),
    }
}

/// Writes row-major `data` of `shape` as a `.npy` array.
pub(super) fn write_array<E, W>(
    data: Vec<E>,
    shape: &[usize],
    path: &Path,
    out: &mut W,
) -> Result<()>
where
    E: ndarray_npy::WritableElement,
    W: Write,
{
    let array = Array::from_shape_vec(IxDyn(shape), data)
        .map_err(|e| format_reason(path, e.to_string()))?;
    array.write_npy(out).map_err(|e| match e {
        ndarray_npy::WriteNpyError::Io(e) => io_error(path, e),
        other => Error::Format {
            path: path.to_path_buf(),
            reason: format!("cannot write .npy: {other}"),
        },
    })
}
