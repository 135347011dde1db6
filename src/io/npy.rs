//! NumPy `.npy` float arrays: images as `H x W` or `H x W x C`, and the raw arrays of
//! coefficient files.
//!
//! Data is converted element by element as it streams through a small buffer, so reading
//! and writing hold no copy of the whole array beyond the image itself.

use std::io::{BufReader, Read, Seek, Write};
use std::path::Path;

use ndarray::{ArrayD, IxDyn, ShapeBuilder};
use ndarray_npy::WritableElement;
use ndarray_npy::npy::header::{Header, Layout};

use super::{ReadOptions, Source, check_size, format_reason, io_error, planar};
use crate::{Error, PlanarImage, Result, Sample, SampleDepth};

/// Elements converted per buffer while streaming.
const CHUNK: usize = 1 << 14;

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
    // One channel in C order is already planar: no copy.
    let planes = if planes.is_standard_layout() {
        planes
    } else {
        planes.as_standard_layout().into_owned()
    };
    planar(path, planes, depth)
}

/// The stored element type of a `.npy` descriptor: depth, size in bytes, little-endian.
fn element_type(descriptor: &str) -> Option<(SampleDepth, usize, bool)> {
    let little = match descriptor.as_bytes().first()? {
        b'<' => true,
        b'>' => false,
        b'=' => cfg!(target_endian = "little"),
        _ => return None,
    };
    let (depth, size) = match &descriptor[1..] {
        "f2" => (SampleDepth::F16, 2),
        "f4" => (SampleDepth::F32, 4),
        "f8" => (SampleDepth::F64, 8),
        _ => return None,
    };
    Some((depth, size, little))
}

/// The depth of the samples in the `.npy` file at `path`, from its header.
pub(super) fn stored_depth(path: &Path) -> Result<SampleDepth> {
    let file = std::fs::File::open(path).map_err(|e| io_error(path, e))?;
    let file_len = file.metadata().map_err(|e| io_error(path, e))?.len();
    Ok(read_header(path, &mut BufReader::new(file), file_len)?.1)
}

/// The longest `.npy` header read (numpy writes a few hundred bytes and by default refuses
/// to read more than 10,000).
const HEADER_MAX_BYTES: u64 = 1 << 20;

/// The header of the `.npy` file of `file_len` bytes that `reader` reads, and its element
/// type. The header's length is checked against the file and [`HEADER_MAX_BYTES`] first:
/// the parser allocates what the length field says before reading.
fn read_header(
    path: &Path,
    reader: &mut impl Read,
    file_len: u64,
) -> Result<(Header, SampleDepth, usize, bool)> {
    // Magic (6 bytes), version (2), then the header's length: 2 bytes in version 1, 4 after.
    let mut preamble = Vec::with_capacity(12);
    reader
        .by_ref()
        .take(12)
        .read_to_end(&mut preamble)
        .map_err(|e| io_error(path, e))?;
    let length_bytes = if preamble.get(6) == Some(&1) { 2 } else { 4 };
    if preamble.len() >= 8 + length_bytes && preamble[..6] == *b"\x93NUMPY" {
        let mut length = [0u8; 4];
        length[..length_bytes].copy_from_slice(&preamble[8..8 + length_bytes]);
        let length = u64::from(u32::from_le_bytes(length));
        let room = file_len.saturating_sub((8 + length_bytes) as u64);
        if length > room.min(HEADER_MAX_BYTES) {
            return Err(format_reason(
                path,
                format!(
                    "invalid .npy header: {length} bytes long, more than the file's {room} \
                     after the preamble or the limit of {HEADER_MAX_BYTES}"
                ),
            ));
        }
    }
    let mut reader = std::io::Cursor::new(preamble).chain(reader);
    let header = Header::from_reader(&mut reader).map_err(|e| {
        format_reason(
            path,
            format!("invalid .npy header: {}", one_line(&e.to_string())),
        )
    })?;
    let descriptor = header.type_descriptor.to_string();
    let descriptor = one_line(descriptor.trim_matches(|c| c == '\'' || c == '"'));
    let (depth, size, little) = element_type(&descriptor).ok_or_else(|| {
        format_reason(
            path,
            format!(
                "unsupported .npy element type {descriptor} (expected float16, float32 or \
                 float64)"
            ),
        )
    })?;
    Ok((header, depth, size, little))
}

/// A parser's message as one short line: the header parser's diagnostic spans several lines
/// and echoes the whole header (which a hostile file makes megabytes long), so only its first
/// line and its `= expected ...` note are kept, cut to 160 characters.
fn one_line(message: &str) -> String {
    const MAX: usize = 160;
    let mut lines = message.lines();
    let first = lines.next().unwrap_or("").trim();
    let notes = lines.filter_map(|l| l.trim().strip_prefix("= "));
    let line = std::iter::once(first)
        .chain(notes)
        .filter(|l| !l.is_empty())
        .collect::<Vec<_>>()
        .join("; ");
    match line.char_indices().nth(MAX) {
        Some((cut, _)) => format!("{}...", &line[..cut]),
        None => line,
    }
}

/// Reads a float16, float32 or float64 array whose shape `accept` allows, after checking its
/// size against the file's length and the memory limit; returns it with the depth it was
/// stored in.
pub(super) fn read_array<T: Sample>(
    source: &Source<'_>,
    options: &ReadOptions,
    accept: impl Fn(&[usize]) -> std::result::Result<(), String>,
) -> Result<(ArrayD<T>, SampleDepth)> {
    let path = source.name();
    let file_len = source.len()?;
    let mut reader = source.open()?;
    let (header, depth, size, little) = read_header(path, &mut reader, file_len)?;
    let data_start = reader.stream_position().map_err(|e| io_error(path, e))?;
    let shape = header.shape.clone();
    accept(&shape).map_err(|reason| format_reason(path, reason))?;
    check_size::<T>(path, &shape, size as u64, options.memory_limit)?;
    let needed = shape
        .iter()
        .fold(size as u128, |n, &d| n.saturating_mul(d as u128));
    let available = u128::from(file_len.saturating_sub(data_start));
    if available < needed {
        return Err(format_reason(
            path,
            format!(
                "file is truncated: the header promises {needed} bytes of data, {available} are present"
            ),
        ));
    }
    let count = shape.iter().product();
    let data = match (depth, little) {
        (SampleDepth::F16, true) => {
            decode(&mut reader, count, |b| half::f16::from_le_bytes(b).to_f64())
        }
        (SampleDepth::F16, false) => {
            decode(&mut reader, count, |b| half::f16::from_be_bytes(b).to_f64())
        }
        (SampleDepth::F32, true) => {
            decode(&mut reader, count, |b| f64::from(f32::from_le_bytes(b)))
        }
        (SampleDepth::F32, false) => {
            decode(&mut reader, count, |b| f64::from(f32::from_be_bytes(b)))
        }
        (_, true) => decode(&mut reader, count, f64::from_le_bytes),
        (_, false) => decode(&mut reader, count, f64::from_be_bytes),
    }
    .map_err(|e| io_error(path, e))?;
    let dim = IxDyn(&shape);
    let array = if header.layout == Layout::Fortran {
        ArrayD::from_shape_vec(dim.f(), data)
    } else {
        ArrayD::from_shape_vec(dim, data)
    }
    .map_err(|e| format_reason(path, e.to_string()))?;
    Ok((array, depth))
}

/// `count` elements of `N` bytes each from `reader`, each converted by `value` (exact for
/// every stored type) and then to `T`.
fn decode<T: Sample, const N: usize>(
    reader: &mut impl Read,
    count: usize,
    value: impl Fn([u8; N]) -> f64,
) -> std::io::Result<Vec<T>> {
    let mut data = Vec::with_capacity(count);
    let mut bytes = vec![0u8; CHUNK * N];
    while data.len() < count {
        let n = (count - data.len()).min(CHUNK);
        reader.read_exact(&mut bytes[..n * N])?;
        data.extend(
            bytes[..n * N]
                .chunks_exact(N)
                .map(|b| T::from_f64(value(b.try_into().expect("N bytes")))),
        );
    }
    Ok(data)
}

/// Writes an image as `H x W` (gray) or `H x W x C`, f64 at depth `F64` and f32 otherwise.
pub(super) fn write<T: Sample, W: Write>(
    image: &PlanarImage<T>,
    depth: SampleDepth,
    path: &Path,
    out: &mut W,
) -> Result<()> {
    let planes = image.planes();
    let (c, h, w) = planes.dim();
    let shape = if c == 1 { vec![h, w] } else { vec![h, w, c] };
    // Pixel by pixel, channel last: the planes' axes (c, h, w) visited in the order h, w, c.
    let samples = planes.permuted_axes([1, 2, 0]);
    match depth {
        SampleDepth::F64 => write_samples(samples.iter().map(|v| v.as_f64()), &shape, path, out),
        _ => write_samples(samples.iter().map(|v| v.as_f64() as f32), &shape, path, out),
    }
}

/// Writes `samples` (row-major) as a `.npy` array of `shape`, streaming them through a small
/// buffer.
pub(super) fn write_samples<E, W>(
    samples: impl Iterator<Item = E>,
    shape: &[usize],
    path: &Path,
    out: &mut W,
) -> Result<()>
where
    E: WritableElement,
    W: Write,
{
    let header = Header {
        type_descriptor: E::type_descriptor(),
        layout: Layout::Standard,
        shape: shape.to_vec(),
    };
    let npy_error = |e: String| Error::Format {
        path: path.to_path_buf(),
        reason: format!("cannot write .npy: {e}"),
    };
    header.write(&mut *out).map_err(|e| match e {
        ndarray_npy::npy::header::WriteHeaderError::Io(e) => io_error(path, e),
        other => npy_error(other.to_string()),
    })?;
    let mut chunk = Vec::with_capacity(CHUNK);
    let mut samples = samples.peekable();
    while samples.peek().is_some() {
        chunk.clear();
        chunk.extend(samples.by_ref().take(CHUNK));
        E::write_slice(&chunk, &mut *out).map_err(|e| match e {
            ndarray_npy::WriteDataError::Io(e) => io_error(path, e),
            other => npy_error(other.to_string()),
        })?;
    }
    Ok(())
}
