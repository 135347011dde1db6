//! Renders out to files.
//!
//! [`render`](super::render) returns linear radiance as an f32 RGB [`PlanarImage`]. [`write_render`] writes
//! `.exr` as it is (linear f32) and `.png` as 8-bit sRGB after an exposure of `2^stops`
//! ([`to_srgb8`], [`srgb_encode`]), atomically, through [`haarshift::io`].

use std::path::Path;

use crate::{Error, Result};
use haarshift::io::{FileFormat, WriteOptions, write_image};
use haarshift::{PlanarImage, SampleDepth};

/// The sRGB encoding (IEC 61966-2-1) of a linear value, clamped to `[0, 1]` first:
/// `12.92 v` up to `0.0031308`, `1.055 v^(1/2.4) - 0.055` above.
///
/// ```
/// use haarshift_relight::render::output::srgb_encode;
/// assert_eq!(srgb_encode(0.0), 0.0);
/// assert!((srgb_encode(1.0) - 1.0).abs() < 1e-15);
/// assert_eq!(srgb_encode(-1.0), 0.0);
/// ```
pub fn srgb_encode(linear: f64) -> f64 {
    let v = linear.clamp(0.0, 1.0);
    if v <= 0.003_130_8 {
        12.92 * v
    } else {
        1.055 * v.powf(1.0 / 2.4) - 0.055
    }
}

/// `image` (linear) times `2^exposure` (stops), sRGB-encoded, as 8-bit codes (depth
/// [`SampleDepth::U8`], values `0..=255`, rounded to nearest).
///
/// ```
/// use haarshift_relight::render::output::to_srgb8;
/// use haarshift::{PlanarImage, SampleDepth};
/// use ndarray::Array2;
/// let half = PlanarImage::from_gray(Array2::from_elem((1, 1), 0.5f32), SampleDepth::F32).unwrap();
/// assert_eq!(to_srgb8(&half, 1.0).unwrap().plane(0)[[0, 0]], 255.0); // 0.5 x 2 = 1
/// assert_eq!(to_srgb8(&half, 0.0).unwrap().plane(0)[[0, 0]], 188.0); // 0.7354 x 255
/// ```
pub fn to_srgb8(image: &PlanarImage<f32>, exposure: f64) -> Result<PlanarImage<f32>> {
    if !exposure.is_finite() || exposure.abs() > 64.0 {
        return Err(Error::parameter(
            "exposure",
            format!("{exposure} stops (expected a finite number from -64 to 64)"),
        ));
    }
    let scale = exposure.exp2();
    let planes = image
        .planes()
        .mapv(|v| (srgb_encode(v as f64 * scale) * 255.0).round() as f32);
    Ok(PlanarImage::new(planes, image.channels(), SampleDepth::U8)?)
}

/// Writes a linear render: `.exr` as linear f32, `.png` as 8-bit sRGB after `exposure` stops
/// ([`to_srgb8`]); atomically, replacing an existing file only with `force`. Other extensions
/// are refused.
///
/// ```
/// use haarshift_relight::render::output::write_render;
/// use haarshift::{PlanarImage, SampleDepth};
/// use ndarray::Array3;
/// let dir = tempfile::tempdir().unwrap();
/// let image = PlanarImage::new(Array3::from_elem((3, 2, 2), 0.25f32), haarshift::Channels::Rgb, SampleDepth::F32).unwrap();
/// write_render(&image, &dir.path().join("a.exr"), 0.0, false).unwrap();
/// let back = haarshift::io::read_image::<f32>(dir.path().join("a.exr")).unwrap();
/// assert_eq!(back.planes(), image.planes());
/// assert!(write_render(&image, &dir.path().join("a.jpg"), 0.0, false).is_err());
/// ```
pub fn write_render(
    image: &PlanarImage<f32>,
    path: &Path,
    exposure: f64,
    force: bool,
) -> Result<()> {
    let options = WriteOptions {
        force,
        ..Default::default()
    };
    match render_format(path)? {
        FileFormat::Exr => {
            let linear = PlanarImage::new(
                image.planes().to_owned(),
                image.channels(),
                SampleDepth::F32,
            )?;
            Ok(write_image(&linear, path, options)?)
        }
        _ => Ok(write_image(&to_srgb8(image, exposure)?, path, options)?),
    }
}

/// The format [`write_render`] writes to `path`: PNG or OpenEXR by the extension, anything else
/// refused (so a caller can check an output before rendering).
///
/// ```
/// use haarshift::io::FileFormat;
/// use haarshift_relight::render::output::render_format;
/// assert_eq!(render_format("a.PNG".as_ref()).unwrap(), FileFormat::Png);
/// assert!(render_format("a.tif".as_ref()).unwrap_err().to_string().contains("a.tif"));
/// ```
pub fn render_format(path: &Path) -> Result<FileFormat> {
    match FileFormat::from_extension(path) {
        Some(format @ (FileFormat::Exr | FileFormat::Png)) => Ok(format),
        _ => Err(crate::Error::from(haarshift::Error::Format {
            path: path.to_path_buf(),
            reason: "a render is written as .png (8-bit sRGB) or .exr (linear f32)".into(),
        })),
    }
}
