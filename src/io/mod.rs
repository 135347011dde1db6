//! Reading and writing images, float arrays and coefficient files.
//!
//! Every reader returns a [`PlanarImage`]: planar channels holding the file's stored values
//! (0..=255 for 8-bit, 0..=65535 for 16-bit, the values themselves for float formats) and the
//! [`SampleDepth`] they came in. Every writer takes one back.
//!
//! | format | read | write | depths | channels |
//! |---|---|---|---|---|
//! | PNG (`.png`) | yes | yes | u8, u16 | gray, gray+alpha, RGB, RGBA |
//! | JPEG (`.jpg`, `.jpeg`) | yes | yes (8-bit, lossy) | u8 | gray, RGB |
//! | TIFF (`.tif`, `.tiff`) | yes | yes | u8, u16 (read also f32 RGB/RGBA) | gray, gray+alpha, RGB, RGBA |
//! | OpenEXR (`.exr`) | yes | yes | f16, f32 | `Y`, `Y A`, `R G B`, `R G B A` |
//! | Radiance (`.hdr`) | yes | yes (RGBE, lossy) | f32 | RGB |
//! | NumPy (`.npy`) | yes | yes | f32, f64 (read also f16) | `H x W` (gray) or `H x W x C`, C = 1..=4 |
//!
//! # Which format a file is
//!
//! Reading looks at the file's first bytes (its signature), not at its name: a PNG called
//! `photo.jpg` reads as the PNG it is. Writing picks the format from the extension.
//!
//! # Output depth, rounding and clamping
//!
//! A written file stores the image's own [`SampleDepth`] when the format can hold it, or
//! [`WriteOptions::depth`] when that is set:
//!
//! * PNG and TIFF store 8 or 16 bits. A float image must be given an integer depth explicitly;
//!   its values are then taken as code values (not rescaled).
//! * JPEG stores 8 bits only: a 16-bit image is scaled by `255/65535` (`1/257`, exact for
//!   values that came from 8-bit data). JPEG cannot store alpha.
//! * Between the two integer depths values are scaled by 257 (8 -> 16) or 1/257 (16 -> 8).
//! * Integer samples are **rounded to nearest (ties away from zero) and clamped** to
//!   `0..=255` or `0..=65535`. Float formats keep the values: EXR stores f16 for an f16 image
//!   and f32 otherwise; `.npy` stores f64 for an f64 image and f32 otherwise; `.hdr` stores
//!   RGBE (about 1% relative precision, non-negative values only).
//!
//! # Safety of files
//!
//! Outputs are written to a temporary file in the output's directory and renamed over the
//! output only when complete, so a failed write never leaves a partial file. An existing
//! output is replaced only with [`WriteOptions::force`]. Nothing here ever writes to an input;
//! [`ensure_distinct_paths`] lets a caller refuse an output that is its input.
//!
//! # Errors
//!
//! Every failure is an [`Error::Io`] or [`Error::Format`] naming the file: missing or unreadable
//! files, corrupt or truncated data, unsupported formats or channel layouts, NaN or infinity in
//! float data, zero-sized images, and images whose decoded size exceeds
//! [`ReadOptions::memory_limit`] (checked from the header, before anything large is allocated).
//!
//! ```
//! use haarshift::io::{read_image, write_image, WriteOptions};
//! use haarshift::{PlanarImage, SampleDepth};
//! use ndarray::Array2;
//! let dir = tempfile::tempdir().unwrap();
//! let path = dir.path().join("ramp.png");
//! let ramp = Array2::from_shape_fn((4, 8), |(i, j)| (i * 8 + j) as f32);
//! let image = PlanarImage::from_gray(ramp, SampleDepth::U8).unwrap();
//! write_image(&image, &path, WriteOptions::default()).unwrap();
//! assert_eq!(read_image::<f32>(&path).unwrap(), image);
//! // Existing outputs are kept unless forced.
//! let again = write_image(&image, &path, WriteOptions::default());
//! assert!(matches!(again, Err(haarshift::Error::OutputExists { .. })));
//! write_image(&image, &path, WriteOptions { force: true, ..Default::default() }).unwrap();
//! ```

use std::fs::File;
use std::io::{BufRead, Read, Seek};
use std::path::Path;

use ndarray::Array3;

use crate::named::named_enum;
use crate::planar_image::depth_scale;
use crate::sample::round_to_code;
use crate::{Error, PlanarImage, Result, Sample, SampleDepth, ensure_finite};

mod atomic;
mod coefficients;
mod npy;
mod openexr;
mod raster;
mod tiff_codec;

pub use atomic::PendingFile;
pub use atomic::{ensure_distinct_paths, write_file_atomically};
pub use coefficients::{
    CoefficientFile, CoefficientMetadata, StoredCoefficients, TransformRequest,
};

/// The default [`ReadOptions::memory_limit`]: 4 GiB.
pub const DEFAULT_MEMORY_LIMIT: u64 = 4 << 30;

named_enum! {
    /// A file format haarshift reads or writes.
    pub enum FileFormat ("file format") {
        /// Portable Network Graphics.
        Png = "png",
        /// JPEG (JFIF).
        Jpeg = "jpeg",
        /// Baseline TIFF.
        Tiff = "tiff",
        /// OpenEXR.
        Exr = "exr",
        /// Radiance RGBE (`.hdr`).
        Hdr = "hdr",
        /// NumPy array file.
        Npy = "npy",
    }
}

impl FileFormat {
    /// The format a file name's extension stands for (case-insensitive), if any.
    ///
    /// ```
    /// use haarshift::io::FileFormat;
    /// assert_eq!(FileFormat::from_extension("a/b.JPG".as_ref()), Some(FileFormat::Jpeg));
    /// assert_eq!(FileFormat::from_extension("c.tif".as_ref()), Some(FileFormat::Tiff));
    /// assert_eq!(FileFormat::from_extension("d.gif".as_ref()), None);
    /// ```
    pub fn from_extension(path: &Path) -> Option<Self> {
        let ext = path.extension()?.to_str()?.to_ascii_lowercase();
        Some(match ext.as_str() {
            "png" => FileFormat::Png,
            "jpg" | "jpeg" => FileFormat::Jpeg,
            "tif" | "tiff" => FileFormat::Tiff,
            "exr" => FileFormat::Exr,
            "hdr" | "pic" => FileFormat::Hdr,
            "npy" => FileFormat::Npy,
            _ => return None,
        })
    }

    /// The format whose signature starts `bytes`, if any.
    ///
    /// ```
    /// use haarshift::io::FileFormat;
    /// assert_eq!(FileFormat::from_signature(b"\x89PNG\r\n\x1a\n...."), Some(FileFormat::Png));
    /// assert_eq!(FileFormat::from_signature(b"\x93NUMPY\x01\x00"), Some(FileFormat::Npy));
    /// assert_eq!(FileFormat::from_signature(b"hello"), None);
    /// ```
    pub fn from_signature(bytes: &[u8]) -> Option<Self> {
        const SIGNATURES: &[(&[u8], FileFormat)] = &[
            (b"\x89PNG\r\n\x1a\n", FileFormat::Png),
            (b"\xff\xd8\xff", FileFormat::Jpeg),
            (b"II*\0", FileFormat::Tiff),
            (b"MM\0*", FileFormat::Tiff),
            (b"v/1\x01", FileFormat::Exr),
            (b"#?RADIANCE", FileFormat::Hdr),
            (b"#?RGBE", FileFormat::Hdr),
            (b"\x93NUMPY", FileFormat::Npy),
        ];
        SIGNATURES
            .iter()
            .find(|(sig, _)| bytes.starts_with(sig))
            .map(|&(_, format)| format)
    }

    /// The format of the file at `path`, recognised from its first bytes; an error names the
    /// file when it cannot be read, is empty or has no known signature.
    ///
    /// ```
    /// use haarshift::io::FileFormat;
    /// let path = concat!(env!("CARGO_MANIFEST_DIR"), "/testdata/coins.png");
    /// assert_eq!(FileFormat::of_file(path.as_ref()).unwrap(), FileFormat::Png);
    /// ```
    pub fn of_file(path: &Path) -> Result<FileFormat> {
        FileFormat::of_source(&Source::File(path))
    }

    /// The format of a source, recognised from its first bytes.
    fn of_source(source: &Source<'_>) -> Result<FileFormat> {
        let path = source.name();
        let mut head = Vec::with_capacity(16);
        source
            .open()?
            .take(16)
            .read_to_end(&mut head)
            .map_err(|e| io_error(path, e))?;
        if head.is_empty() {
            return Err(format_reason(path, "file is empty"));
        }
        FileFormat::from_signature(&head).ok_or_else(|| {
            let reason = match FileFormat::from_extension(path) {
                Some(f) => format!(
                    "not a valid {} file (its content has no {} signature)",
                    f.display_name(),
                    f.display_name()
                ),
                None => {
                    "unsupported file format (expected PNG, JPEG, TIFF, OpenEXR, Radiance HDR or \
                         .npy content)"
                        .to_string()
                }
            };
            format_reason(path, reason)
        })
    }

    /// The format's usual name in messages.
    fn display_name(self) -> &'static str {
        match self {
            FileFormat::Png => "PNG",
            FileFormat::Jpeg => "JPEG",
            FileFormat::Tiff => "TIFF",
            FileFormat::Exr => "OpenEXR",
            FileFormat::Hdr => "Radiance HDR",
            FileFormat::Npy => ".npy",
        }
    }
}

/// How reading behaves.
///
/// ```
/// use haarshift::io::{read_image_with, ReadOptions};
/// let tiny = ReadOptions { memory_limit: 1000 };
/// let path = concat!(env!("CARGO_MANIFEST_DIR"), "/testdata/camera.png");
/// let err = read_image_with::<f32>(path.as_ref(), &tiny).unwrap_err();
/// assert!(matches!(err, haarshift::Error::Format { .. }) && err.to_string().contains("memory limit"));
/// ```
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ReadOptions {
    /// Largest number of bytes a read may allocate for the decoded image (the decoder's buffer
    /// plus the planar result). Checked from the file's header before decoding.
    pub memory_limit: u64,
}

impl Default for ReadOptions {
    fn default() -> Self {
        ReadOptions {
            memory_limit: DEFAULT_MEMORY_LIMIT,
        }
    }
}

/// How writing behaves; see the [module docs](self) for depths and rounding.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct WriteOptions {
    /// Replace an existing output (never done otherwise).
    pub force: bool,
    /// Store this depth instead of the image's own (see the module docs for what each format
    /// accepts).
    pub depth: Option<SampleDepth>,
    /// JPEG quality, 1..=100.
    pub jpeg_quality: u8,
}

impl Default for WriteOptions {
    fn default() -> Self {
        WriteOptions {
            force: false,
            depth: None,
            jpeg_quality: 95,
        }
    }
}

/// Reads an image or `.npy` array with the default [`ReadOptions`].
///
/// ```
/// let path = concat!(env!("CARGO_MANIFEST_DIR"), "/testdata/astronaut.png");
/// let img = haarshift::io::read_image::<f32>(path).unwrap();
/// assert_eq!((img.channels().count(), img.height(), img.width()), (3, 512, 512));
/// assert_eq!(img.depth(), haarshift::SampleDepth::U8);
/// ```
pub fn read_image<T: Sample>(path: impl AsRef<Path>) -> Result<PlanarImage<T>> {
    read_image_with(path.as_ref(), &ReadOptions::default())
}

/// Reads an image or `.npy` array; the format is recognised from the file's content.
pub fn read_image_with<T: Sample>(path: &Path, options: &ReadOptions) -> Result<PlanarImage<T>> {
    read_source(&Source::File(path), options)
}

/// Reads an image or `.npy` array from bytes in memory (the content of a file, e.g. one
/// embedded in a program with `include_bytes!`); `name` stands for the file in messages. The
/// same formats, checks and errors as [`read_image_with`].
///
/// ```
/// use haarshift::io::{read_image_from_memory, ReadOptions};
/// let bytes = include_bytes!(concat!(env!("CARGO_MANIFEST_DIR"), "/testdata/coins.png"));
/// let img = read_image_from_memory::<f32>(bytes, "coins.png".as_ref(), &ReadOptions::default()).unwrap();
/// assert_eq!((img.height(), img.width()), (303, 384));
/// let err = read_image_from_memory::<f32>(&bytes[..100], "cut.png".as_ref(), &ReadOptions::default());
/// assert_eq!(err.unwrap_err().to_string(), "cut.png: file is truncated");
/// ```
pub fn read_image_from_memory<T: Sample>(
    bytes: &[u8],
    name: &Path,
    options: &ReadOptions,
) -> Result<PlanarImage<T>> {
    read_source(&Source::Memory { name, bytes }, options)
}

fn read_source<T: Sample>(source: &Source<'_>, options: &ReadOptions) -> Result<PlanarImage<T>> {
    let format = FileFormat::of_source(source)?;
    let image = match format {
        FileFormat::Npy => npy::read(source, options)?,
        FileFormat::Exr => openexr::read(source, options)?,
        FileFormat::Tiff => tiff_codec::read(source, options)?,
        FileFormat::Png | FileFormat::Jpeg | FileFormat::Hdr => {
            raster::read(source, format, options)?
        }
    };
    // Integer samples are finite by construction.
    if image.depth().integer_max().is_none() {
        ensure_finite(&image.planes()).map_err(|e| e.in_file(source.name()))?;
    }
    Ok(image)
}

/// Where a reader's bytes come from: a file, or a buffer in memory named for messages.
#[derive(Clone, Copy, Debug)]
pub(crate) enum Source<'a> {
    /// A file on disk.
    File(&'a Path),
    /// The bytes of a file, held in memory.
    Memory {
        /// What messages call it.
        name: &'a Path,
        /// Its content.
        bytes: &'a [u8],
    },
}

/// A buffered, seekable reader of a [`Source`].
pub(crate) trait SourceReader: BufRead + Seek {}
impl<R: BufRead + Seek> SourceReader for R {}

impl<'a> Source<'a> {
    /// The path that messages name.
    pub(crate) fn name(&self) -> &'a Path {
        match *self {
            Source::File(path) | Source::Memory { name: path, .. } => path,
        }
    }

    /// A reader positioned at the start.
    pub(crate) fn open(&self) -> Result<Box<dyn SourceReader + 'a>> {
        match *self {
            Source::File(path) => {
                let file = File::open(path).map_err(|e| io_error(path, e))?;
                Ok(Box::new(std::io::BufReader::new(file)))
            }
            Source::Memory { bytes, .. } => Ok(Box::new(std::io::Cursor::new(bytes))),
        }
    }

    /// The length in bytes.
    pub(crate) fn len(&self) -> Result<u64> {
        match *self {
            Source::File(path) => std::fs::metadata(path)
                .map(|m| m.len())
                .map_err(|e| io_error(path, e)),
            Source::Memory { bytes, .. } => Ok(bytes.len() as u64),
        }
    }
}

/// Whether the file at `path` holds float64 samples (a float64 `.npy` array), which reading as
/// f32 would round; every other file reads exactly as f32 (8- and 16-bit integers, f16 and
/// f32 floats). Only the file's signature and header are read.
///
/// ```
/// use haarshift::io::{holds_f64, write_image, WriteOptions};
/// use haarshift::{PlanarImage, SampleDepth};
/// use ndarray::Array2;
/// let dir = tempfile::tempdir().unwrap();
/// let path = dir.path().join("a.npy");
/// let image = PlanarImage::from_gray(Array2::<f64>::ones((2, 3)), SampleDepth::F64).unwrap();
/// write_image(&image, &path, WriteOptions::default()).unwrap();
/// assert!(holds_f64(&path).unwrap());
/// let png = concat!(env!("CARGO_MANIFEST_DIR"), "/testdata/camera.png");
/// assert!(!holds_f64(png.as_ref()).unwrap());
/// ```
pub fn holds_f64(path: &Path) -> Result<bool> {
    Ok(match FileFormat::of_file(path)? {
        FileFormat::Npy => npy::stored_depth(path)? == SampleDepth::F64,
        _ => false,
    })
}

/// Writes `image` in the format of `path`'s extension; see the [module docs](self).
pub fn write_image<T: Sample>(
    image: &PlanarImage<T>,
    path: impl AsRef<Path>,
    options: WriteOptions,
) -> Result<()> {
    let path = path.as_ref();
    let format = FileFormat::from_extension(path).ok_or_else(|| Error::Format {
        path: path.to_path_buf(),
        reason: "cannot tell the output format from the name (use .png, .jpg, .tif, .exr, .hdr \
                 or .npy)"
            .into(),
    })?;
    ensure_finite(&image.planes()).map_err(|e| e.in_file(path))?;
    let depth =
        stored_depth(format, image.depth(), options.depth).map_err(|reason| Error::Format {
            path: path.to_path_buf(),
            reason,
        })?;
    let mut out = atomic::PendingFile::create(path, options.force)?;
    match format {
        FileFormat::Npy => npy::write(image, depth, path, out.writer())?,
        FileFormat::Exr => openexr::write(image, depth, path, out.writer())?,
        FileFormat::Tiff => tiff_codec::write(image, depth, path, out.writer())?,
        FileFormat::Png | FileFormat::Jpeg | FileFormat::Hdr => raster::write(
            image,
            format,
            depth,
            options.jpeg_quality,
            path,
            out.writer(),
        )?,
    }
    out.commit()
}

/// Writes `array` (any shape, row-major) as a `.npy` array, atomically: float64 at depth
/// [`SampleDepth::F64`], float32 otherwise. An existing `path` is replaced only with `force`.
///
/// ```
/// use haarshift::{SampleDepth, io::write_npy};
/// let dir = tempfile::tempdir().unwrap();
/// let path = dir.path().join("c.npy");
/// let a = ndarray::Array4::<f64>::from_elem((6, 2, 2, 3), 0.5);
/// write_npy(a.view(), SampleDepth::F32, &path, false).unwrap();
/// let back: ndarray::Array4<f32> = ndarray_npy::read_npy(&path).unwrap();
/// assert_eq!(back.dim(), (6, 2, 2, 3));
/// assert!(write_npy(a.view(), SampleDepth::F32, &path, false).is_err());
/// ```
pub fn write_npy<T: Sample, D: ndarray::Dimension>(
    array: ndarray::ArrayView<'_, T, D>,
    depth: SampleDepth,
    path: &Path,
    force: bool,
) -> Result<()> {
    ensure_finite(&array).map_err(|e| e.in_file(path))?;
    let mut out = atomic::PendingFile::create(path, force)?;
    let shape = array.shape().to_vec();
    match depth {
        SampleDepth::F64 => {
            npy::write_samples(array.iter().map(|v| v.as_f64()), &shape, path, out.writer())?
        }
        _ => npy::write_samples(
            array.iter().map(|v| v.as_f64() as f32),
            &shape,
            path,
            out.writer(),
        )?,
    }
    out.commit()
}

/// The depth `format` stores for an image of `depth` when `requested` (or else `depth`) is
/// asked for, or why it cannot.
fn stored_depth(
    format: FileFormat,
    depth: SampleDepth,
    requested: Option<SampleDepth>,
) -> std::result::Result<SampleDepth, String> {
    use SampleDepth::*;
    let wanted = requested.unwrap_or(depth);
    let integer_only = |stores: &str| {
        format!(
            "{} stores {stores} integers but the image holds {wanted} samples (ask for depth \
             u8 or u16, or write .exr or .npy to keep float values)",
            format.display_name()
        )
    };
    match format {
        FileFormat::Png | FileFormat::Tiff => match wanted {
            U8 | U16 => Ok(wanted),
            _ => Err(integer_only("8- or 16-bit")),
        },
        FileFormat::Jpeg => match wanted {
            U8 | U16 => Ok(U8),
            _ => Err(integer_only("8-bit")),
        },
        FileFormat::Exr => Ok(if wanted == F16 { F16 } else { F32 }),
        FileFormat::Npy => Ok(if wanted == F64 { F64 } else { F32 }),
        FileFormat::Hdr => Ok(F32),
    }
}

/// Converts a sample to an integer code of `max` (255 or 65535): scale, round to nearest
/// (ties away from zero), clamp.
fn to_code(value: f64, scale: f64, max: f64) -> f64 {
    round_to_code(value * scale, max)
}

/// The planes of `image` as stored at `depth`, interleaved pixel by pixel (row-major, then
/// channel), converted by `convert` from the f64 value (already rescaled and, for integer
/// depths, rounded and clamped).
fn interleave<T: Sample, P: Copy + Default>(
    image: &PlanarImage<T>,
    depth: SampleDepth,
    convert: impl Fn(f64) -> P,
) -> Vec<P> {
    let scale = depth_scale(image.depth(), depth);
    let code = |v: T| match depth.integer_max() {
        Some(max) => to_code(v.as_f64(), scale, max),
        None => v.as_f64(),
    };
    let planes = image.planes();
    let planes = planes.as_standard_layout();
    let (c, h, w) = planes.dim();
    let n = h * w;
    let samples = planes.as_slice().expect("standard layout");
    // Plane by plane: reads in order, writes every c-th sample.
    let mut out = vec![P::default(); c * n];
    for (k, plane) in samples.chunks_exact(n).enumerate() {
        for (o, &v) in out[k..].iter_mut().step_by(c).zip(plane) {
            *o = convert(code(v));
        }
    }
    out
}

/// Planes `(c, h, w)` from interleaved samples, each converted to f64 by `to_f64`.
fn deinterleave<T: Sample, P: Copy>(
    data: &[P],
    (c, h, w): (usize, usize, usize),
    to_f64: impl Fn(P) -> f64,
) -> Array3<T> {
    let mut planes = Array3::zeros((c, h, w));
    let pixels = ndarray::ArrayView3::from_shape((h, w, c), data)
        .expect("the decoder's buffer holds h x w x c samples")
        .permuted_axes([2, 0, 1]);
    ndarray::Zip::from(&mut planes)
        .and(pixels)
        .for_each(|p, &v| *p = T::from_f64(to_f64(v)));
    planes
}

/// Checks that decoding data of `shape` stays within `limit` when the decoder needs
/// `decoder_bytes_per_sample` per sample and the planar result `size_of::<T>()` more; zero
/// sizes are refused here too.
fn check_size<T: Sample>(
    path: &Path,
    shape: &[usize],
    decoder_bytes_per_sample: u64,
    limit: u64,
) -> Result<()> {
    let dims = shape
        .iter()
        .map(|d| d.to_string())
        .collect::<Vec<_>>()
        .join("x");
    if shape.contains(&0) {
        return Err(format_reason(path, format!("image has zero size ({dims})")));
    }
    let per_sample = decoder_bytes_per_sample as u128 + std::mem::size_of::<T>() as u128;
    let needed = shape
        .iter()
        .fold(per_sample, |n, &d| n.saturating_mul(d as u128));
    if needed > limit as u128 {
        return Err(format_reason(
            path,
            format!(
                "data of size {dims} needs {needed} bytes to decode, more than the memory limit \
                 of {limit} bytes"
            ),
        ));
    }
    Ok(())
}

/// An [`Error::Io`] for `path`.
fn io_error(path: &Path, source: std::io::Error) -> Error {
    Error::Io {
        path: path.to_path_buf(),
        source,
    }
}

/// An [`Error::Format`] for `path`.
fn format_reason(path: &Path, reason: impl Into<String>) -> Error {
    Error::Format {
        path: path.to_path_buf(),
        reason: reason.into(),
    }
}

/// A planar image from `(c, h, w)` planes, with `path` attached to any error.
fn planar<T: Sample>(path: &Path, planes: Array3<T>, depth: SampleDepth) -> Result<PlanarImage<T>> {
    let channels = crate::Channels::from_count(planes.dim().0).map_err(|e| e.in_file(path))?;
    PlanarImage::new(planes, channels, depth).map_err(|e| e.in_file(path))
}

#[cfg(test)]
mod foreign_tests;
#[cfg(test)]
mod tests;
