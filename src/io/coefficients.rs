//! Coefficient files: the Haar coefficients of every plane of an image as one `.npy` array
//! (`C x H x W`, f64, each plane in the layout of its transform) plus a JSON sidecar
//! `<file>.json` recording how they were made, so that the image can be restored exactly.
//!
//! A sidecar looks like this:
//!
//! ```json
//! {
//!   "format": "haarshift-coefficients",
//!   "version": 1,
//!   "shape": [3, 512, 512],
//!   "transform": { "layout": "pyramid", "normalization": "average", "levels": [9, 9],
//!                  "padding": "zero", "original_shape": [512, 512] },
//!   "channels": "rgb",
//!   "depth": "u8"
//! }
//! ```

use std::io::Write;
use std::path::{Path, PathBuf};

use ndarray::{Array3, Axis};
use serde::{Deserialize, Serialize};

use super::atomic::PendingFile;
use super::{ReadOptions, format_reason, io_error, npy};
use crate::transform::{Coefficients, Layout, Levels, Normalization, TransformInfo, TransformSpec};
use crate::{BoundaryMode, Channels, Error, PlanarImage, Result, Sample, SampleDepth};

/// The `format` tag of a sidecar.
const SIDECAR_FORMAT: &str = "haarshift-coefficients";
/// The sidecar version this code writes and reads.
const SIDECAR_VERSION: u32 = 1;

/// What a coefficient file's sidecar records besides the array's shape.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct CoefficientMetadata {
    /// How every plane was transformed (all planes alike).
    pub transform: TransformInfo,
    /// The channels of the image, one coefficient plane each.
    pub channels: Channels,
    /// How the image's samples were stored, so that the inverse writes the same kind of file.
    pub depth: SampleDepth,
}

/// The sidecar as stored.
#[derive(Serialize, Deserialize)]
struct Sidecar {
    format: String,
    version: u32,
    shape: [usize; 3],
    #[serde(flatten)]
    metadata: CoefficientMetadata,
}

/// The transform of a whole image: one [`Coefficients`] per plane, with the image's channels
/// and depth.
///
/// ```
/// use haarshift::io::{CoefficientFile, WriteOptions};
/// use haarshift::transform::TransformSpec;
/// use haarshift::{PlanarImage, SampleDepth};
/// use ndarray::Array2;
/// let image = PlanarImage::from_gray(
///     Array2::from_shape_fn((5, 7), |(i, j)| (i * 7 + j) as f64),
///     SampleDepth::U8,
/// ).unwrap();
/// let coeffs = CoefficientFile::forward(&image, &TransformSpec::default()).unwrap();
/// let dir = tempfile::tempdir().unwrap();
/// let path = dir.path().join("c.npy");
/// coeffs.write(&path, WriteOptions::default()).unwrap();
/// assert!(CoefficientFile::<f64>::sidecar_path(&path).exists());
/// let back = CoefficientFile::read(&path).unwrap();
/// assert_eq!(back.inverse().unwrap(), image);
/// ```
#[derive(Clone, Debug, PartialEq)]
pub struct CoefficientFile<T> {
    planes: Vec<Coefficients<T>>,
    channels: Channels,
    depth: SampleDepth,
}

impl<T: Sample> CoefficientFile<T> {
    /// Transforms every plane of `image` with `spec`.
    pub fn forward(image: &PlanarImage<T>, spec: &TransformSpec) -> Result<Self> {
        let planes = image
            .planes()
            .outer_iter()
            .map(|plane| spec.forward(plane))
            .collect::<Result<Vec<_>>>()?;
        Self::from_parts(planes, image.channels(), image.depth())
    }

    /// Wraps per-plane coefficients; there must be one per channel, all transformed alike.
    pub fn from_parts(
        planes: Vec<Coefficients<T>>,
        channels: Channels,
        depth: SampleDepth,
    ) -> Result<Self> {
        if planes.len() != channels.count() {
            return Err(Error::parameter(
                "channels",
                format!("{} coefficient planes for {channels}", planes.len()),
            ));
        }
        if planes.windows(2).any(|p| p[0].info() != p[1].info()) {
            return Err(Error::parameter(
                "coefficients",
                "planes were transformed differently",
            ));
        }
        Ok(CoefficientFile {
            planes,
            channels,
            depth,
        })
    }

    /// The coefficients of each plane.
    pub fn planes(&self) -> &[Coefficients<T>] {
        &self.planes
    }

    /// What the sidecar records.
    pub fn metadata(&self) -> CoefficientMetadata {
        CoefficientMetadata {
            transform: *self.planes[0].info(),
            channels: self.channels,
            depth: self.depth,
        }
    }

    /// The image the coefficients came from (cropped to its original size).
    pub fn inverse(&self) -> Result<PlanarImage<T>> {
        let planes = self
            .planes
            .iter()
            .map(Coefficients::inverse)
            .collect::<Result<Vec<_>>>()?;
        let views: Vec<_> = planes.iter().map(|p| p.view()).collect();
        let stacked = ndarray::stack(Axis(0), &views)
            .map_err(|e| Error::shape(&[planes.len()], e.to_string()))?;
        PlanarImage::new(stacked, self.channels, self.depth)
    }

    /// Where the sidecar of the coefficient file `path` is: `path` with `.json` appended.
    ///
    /// ```
    /// use haarshift::io::CoefficientFile;
    /// let s = CoefficientFile::<f64>::sidecar_path("out/c.npy".as_ref());
    /// assert_eq!(s, std::path::Path::new("out/c.npy.json"));
    /// ```
    pub fn sidecar_path(path: &Path) -> PathBuf {
        let mut name = path.as_os_str().to_owned();
        name.push(".json");
        PathBuf::from(name)
    }

    /// Writes the coefficients to `path` (`.npy`, f64, `C x H x W`) and the sidecar beside it.
    /// Both are written atomically; with `options.force` off, neither may exist yet.
    /// (`options.depth` and `jpeg_quality` do not apply.) The name must end in `.npy`.
    pub fn write(&self, path: &Path, options: super::WriteOptions) -> Result<()> {
        if super::FileFormat::from_extension(path) != Some(super::FileFormat::Npy) {
            return Err(format_reason(
                path,
                "coefficients are stored as .npy arrays: give the output a .npy name",
            ));
        }
        let sidecar_path = Self::sidecar_path(path);
        let (h, w) = self.planes[0].as_array().dim();
        let shape = [self.planes.len(), h, w];
        let data = self
            .planes
            .iter()
            .flat_map(|p| p.as_array().into_iter().map(|v| v.as_f64()));
        let sidecar = Sidecar {
            format: SIDECAR_FORMAT.into(),
            version: SIDECAR_VERSION,
            shape,
            metadata: self.metadata(),
        };
        let mut array_file = PendingFile::create(path, options.force)?;
        let mut sidecar_file = PendingFile::create(&sidecar_path, options.force)?;
        npy::write_samples(data, &shape, path, array_file.writer())?;
        serde_json::to_writer_pretty(&mut *sidecar_file.writer(), &sidecar)
            .map_err(|e| format_reason(&sidecar_path, e.to_string()))?;
        writeln!(sidecar_file.writer()).map_err(|e| io_error(&sidecar_path, e))?;
        array_file.commit()?;
        sidecar_file.commit()
    }
}

impl CoefficientFile<f64> {
    /// Reads a coefficient file and its sidecar (which must exist); see [`StoredCoefficients`]
    /// to read one without.
    pub fn read(path: &Path) -> Result<Self> {
        let stored = StoredCoefficients::read(path, &ReadOptions::default())?;
        if stored.metadata.is_none() {
            return Err(format_reason(
                &Self::sidecar_path(path),
                "sidecar is missing, so the transform that made the coefficients is unknown",
            ));
        }
        stored.resolve(&TransformRequest::default())
    }
}

/// Transform parameters as a user gives them, each optional: checked against a sidecar when
/// there is one, completed with the defaults of [`TransformSpec`] when there is not.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct TransformRequest {
    /// Pyramid or separable.
    pub layout: Option<Layout>,
    /// Coefficient scaling.
    pub normalization: Option<Normalization>,
    /// How many steps.
    pub levels: Option<Levels>,
    /// How the input was padded.
    pub padding: Option<BoundaryMode>,
}

impl TransformRequest {
    /// The spec with unset parameters at their defaults.
    ///
    /// ```
    /// use haarshift::io::TransformRequest;
    /// use haarshift::transform::{Layout, TransformSpec};
    /// let r = TransformRequest { layout: Some(Layout::Separable), ..Default::default() };
    /// assert_eq!(r.spec(), TransformSpec { layout: Layout::Separable, ..Default::default() });
    /// ```
    pub fn spec(&self) -> TransformSpec {
        let d = TransformSpec::default();
        TransformSpec {
            layout: self.layout.unwrap_or(d.layout),
            normalization: self.normalization.unwrap_or(d.normalization),
            levels: self.levels.unwrap_or(d.levels),
            padding: self.padding.unwrap_or(d.padding),
        }
    }

    /// The first parameter that differs from `info`, as a sentence, if any; `h x w` is the
    /// padded size of the coefficient array.
    fn contradiction(&self, info: &TransformInfo, h: usize, w: usize) -> Option<String> {
        let differs = |what: &str, asked: String, made: String| {
            Some(format!(
                "{what} {asked} was requested but the coefficients were made with {what} {made}"
            ))
        };
        if let Some(l) = self.layout.filter(|&l| l != info.layout) {
            return differs("layout", l.to_string(), info.layout.to_string());
        }
        if let Some(n) = self.normalization.filter(|&n| n != info.normalization) {
            return differs(
                "normalisation",
                n.to_string(),
                info.normalization.to_string(),
            );
        }
        if let Some(p) = self.padding.filter(|&p| p != info.padding) {
            return differs("padding", p.to_string(), info.padding.to_string());
        }
        if let Some(levels) = self.levels {
            let spec = TransformSpec {
                layout: info.layout,
                levels,
                ..Default::default()
            };
            if spec.resolve_levels(h, w).ok() != Some(info.levels) {
                return differs("levels", levels.to_string(), format!("{:?}", info.levels));
            }
        }
        None
    }
}

/// The content of a coefficient file as read: the array and, when the sidecar exists, its
/// metadata. [`resolve`](Self::resolve) turns it into a [`CoefficientFile`].
#[derive(Clone, Debug, PartialEq)]
pub struct StoredCoefficients {
    /// The coefficient file.
    pub path: PathBuf,
    /// Planes of coefficients, `C x H x W` (a 2D array reads as one plane).
    pub array: Array3<f64>,
    /// The sidecar's record, `None` when there is no sidecar.
    pub metadata: Option<CoefficientMetadata>,
}

impl StoredCoefficients {
    /// Reads the `.npy` array (f32 or f64; `H x W` or `C x H x W` with `C` = 1 to 4) and the
    /// sidecar if it exists.
    pub fn read(path: &Path, options: &ReadOptions) -> Result<Self> {
        let (array, _) = npy::read_array::<f64>(&super::Source::File(path), options, |shape| {
            match shape {
                [_, _] => Ok(()),
                [c, _, _] if (1..=4).contains(c) => Ok(()),
                _ => Err(format!(
                    "array of shape {shape:?} is not a coefficient file (expected H x W or C x H x W \
                 with C = 1 to 4)"
                )),
            }
        })?;
        let array = if array.ndim() == 2 {
            array.insert_axis(Axis(0))
        } else {
            array
        };
        let array = array
            .into_dimensionality::<ndarray::Ix3>()
            .map_err(|e| format_reason(path, e.to_string()))?;
        let sidecar_path = CoefficientFile::<f64>::sidecar_path(path);
        let metadata = match read_sidecar(&sidecar_path) {
            Ok(bytes) => Some(parse_sidecar(&sidecar_path, &bytes, array.dim())?),
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => None,
            Err(e) if e.kind() == std::io::ErrorKind::FileTooLarge => {
                return Err(format_reason(
                    &sidecar_path,
                    format!("a sidecar is at most {SIDECAR_MAX_BYTES} bytes; this one is longer"),
                ));
            }
            Err(e) => return Err(io_error(&sidecar_path, e)),
        };
        Ok(StoredCoefficients {
            path: path.to_path_buf(),
            array,
            metadata,
        })
    }

    /// The coefficients with their transform: the sidecar's, which every parameter set in
    /// `request` must agree with, or without a sidecar the requested one (defaults for unset
    /// parameters), with the original size taken to be the array's (no cropping) and the depth
    /// `F64`.
    pub fn resolve(self, request: &TransformRequest) -> Result<CoefficientFile<f64>> {
        let (c, h, w) = self.array.dim();
        let path = self.path;
        let metadata = match self.metadata {
            Some(m) => {
                if let Some(reason) = request.contradiction(&m.transform, h, w) {
                    return Err(format_reason(&path, reason));
                }
                m
            }
            None => {
                let spec = request.spec();
                let levels = spec.resolve_levels(h, w).map_err(|e| e.in_file(&path))?;
                CoefficientMetadata {
                    transform: TransformInfo {
                        layout: spec.layout,
                        normalization: spec.normalization,
                        levels,
                        padding: spec.padding,
                        original_shape: [h, w],
                    },
                    channels: Channels::from_count(c).map_err(|e| e.in_file(&path))?,
                    depth: SampleDepth::F64,
                }
            }
        };
        let planes = self
            .array
            .outer_iter()
            .map(|p| Coefficients::from_parts(p.to_owned(), metadata.transform))
            .collect::<Result<Vec<_>>>()
            .map_err(|e| e.in_file(&path))?;
        CoefficientFile::from_parts(planes, metadata.channels, metadata.depth)
            .map_err(|e| e.in_file(&path))
    }
}

/// The longest sidecar read: one is a few hundred bytes, and the limit keeps a sidecar that
/// is a link to a device (`/dev/zero`) or a huge file from being read into memory.
const SIDECAR_MAX_BYTES: u64 = 1 << 20;

/// The bytes of the sidecar at `path`; an error of kind `FileTooLarge` beyond
/// [`SIDECAR_MAX_BYTES`].
fn read_sidecar(path: &Path) -> std::io::Result<Vec<u8>> {
    use std::io::Read;
    let mut bytes = Vec::new();
    std::fs::File::open(path)?
        .take(SIDECAR_MAX_BYTES + 1)
        .read_to_end(&mut bytes)?;
    if bytes.len() as u64 > SIDECAR_MAX_BYTES {
        return Err(std::io::ErrorKind::FileTooLarge.into());
    }
    Ok(bytes)
}

/// Parses and checks a sidecar against the array's shape `(c, h, w)`.
fn parse_sidecar(
    path: &Path,
    bytes: &[u8],
    (c, h, w): (usize, usize, usize),
) -> Result<CoefficientMetadata> {
    let sidecar: Sidecar = serde_json::from_slice(bytes)
        .map_err(|e| format_reason(path, format!("invalid sidecar: {e}")))?;
    if sidecar.format != SIDECAR_FORMAT || sidecar.version != SIDECAR_VERSION {
        return Err(format_reason(
            path,
            format!(
                "not a {SIDECAR_FORMAT} version {SIDECAR_VERSION} sidecar (found {} version {})",
                sidecar.format, sidecar.version
            ),
        ));
    }
    if sidecar.shape != [c, h, w] {
        return Err(format_reason(
            path,
            format!(
                "sidecar describes a {:?} array but the coefficient file holds [{c}, {h}, {w}]",
                sidecar.shape
            ),
        ));
    }
    Ok(sidecar.metadata)
}
