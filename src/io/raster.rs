//! PNG, JPEG and Radiance HDR through the `image` crate.

use std::io::{Seek, Write};
use std::path::Path;

use image::{DynamicImage, ExtendedColorType, ImageDecoder, ImageEncoder, ImageError, ImageFormat};

use super::{
    FileFormat, ReadOptions, Source, check_size, deinterleave, format_reason, interleave, io_error,
    planar,
};
use crate::{Channels, Error, PlanarImage, Result, Sample, SampleDepth};

/// Decodes a PNG, JPEG or Radiance file.
pub(super) fn read<T: Sample>(
    source: &Source<'_>,
    format: FileFormat,
    options: &ReadOptions,
) -> Result<PlanarImage<T>> {
    let path = source.name();
    let image_format = match format {
        FileFormat::Png => ImageFormat::Png,
        FileFormat::Jpeg => ImageFormat::Jpeg,
        _ => ImageFormat::Hdr,
    };
    let mut reader = image::ImageReader::new(source.open()?);
    reader.set_format(image_format);
    let mut limits = image::Limits::default();
    limits.max_alloc = Some(options.memory_limit);
    reader.limits(limits);
    let decoder = reader.into_decoder().map_err(|e| image_error(path, e))?;
    let (w, h) = decoder.dimensions();
    let color = decoder.color_type();
    let channels = usize::from(color.channel_count());
    let decoder_bytes = u64::from(color.bytes_per_pixel() / color.channel_count().max(1));
    let shape = [h as usize, w as usize, channels];
    check_size::<T>(path, &shape, decoder_bytes, options.memory_limit)?;
    let decoded = DynamicImage::from_decoder(decoder).map_err(|e| image_error(path, e))?;
    let shape = (channels, h as usize, w as usize);
    let (planes, depth) = if let Some(s) = decoded.as_flat_samples_u8() {
        (deinterleave(s.samples, shape, f64::from), SampleDepth::U8)
    } else if let Some(s) = decoded.as_flat_samples_u16() {
        (deinterleave(s.samples, shape, f64::from), SampleDepth::U16)
    } else if let Some(s) = decoded.as_flat_samples_f32() {
        (deinterleave(s.samples, shape, f64::from), SampleDepth::F32)
    } else {
        return Err(format_reason(
            path,
            format!("unsupported colour type {:?}", decoded.color()),
        ));
    };
    planar(path, planes, depth)
}

/// Encodes PNG, JPEG or Radiance HDR at `depth` (already checked by `stored_depth`).
pub(super) fn write<T: Sample, W: Write + Seek>(
    image: &PlanarImage<T>,
    format: FileFormat,
    depth: SampleDepth,
    jpeg_quality: u8,
    path: &Path,
    out: &mut W,
) -> Result<()> {
    let (w, h) = dimensions(image, path)?;
    let channels = image.channels();
    let unsupported = |what: &str| Error::Format {
        path: path.to_path_buf(),
        reason: what.to_string(),
    };
    match format {
        FileFormat::Png => {
            let color = color_type(channels, depth);
            let bytes = integer_bytes(image, depth);
            // fdeflate's fast mode with adaptive row filters: at 2048^2 it encodes in a small
            // fraction of zlib level 6's time for files a few per cent larger (about zlib
            // level 1's size, benches/cli_results.md).
            image::codecs::png::PngEncoder::new_with_quality(
                &mut *out,
                image::codecs::png::CompressionType::Fast,
                image::codecs::png::FilterType::Adaptive,
            )
            .write_image(&bytes, w, h, color)
            .map_err(|e| image_error(path, e))
        }
        FileFormat::Jpeg => {
            if channels.has_alpha() {
                return Err(unsupported(
                    "JPEG cannot store an alpha channel (write .png or .tif instead)",
                ));
            }
            let quality = jpeg_quality.clamp(1, 100);
            let bytes = interleave(image, SampleDepth::U8, |v| v as u8);
            image::codecs::jpeg::JpegEncoder::new_with_quality(&mut *out, quality)
                .write_image(&bytes, w, h, color_type(channels, SampleDepth::U8))
                .map_err(|e| image_error(path, e))
        }
        _ => {
            if channels != Channels::Rgb {
                return Err(unsupported(
                    "Radiance HDR stores RGB only (write .exr to keep other channels)",
                ));
            }
            let pixels: Vec<image::Rgb<f32>> = interleave(image, depth, |v| v as f32)
                .chunks_exact(3)
                .map(|p| image::Rgb([p[0], p[1], p[2]]))
                .collect();
            image::codecs::hdr::HdrEncoder::new(&mut *out)
                .encode(&pixels, w as usize, h as usize)
                .map_err(|e| image_error(path, e))
        }
    }
}

/// The image's width and height as the encoders want them.
pub(super) fn dimensions<T: Sample>(image: &PlanarImage<T>, path: &Path) -> Result<(u32, u32)> {
    match (u32::try_from(image.width()), u32::try_from(image.height())) {
        (Ok(w), Ok(h)) => Ok((w, h)),
        _ => Err(Error::Format {
            path: path.to_path_buf(),
            reason: format!(
                "{}x{} is too large to encode",
                image.height(),
                image.width()
            ),
        }),
    }
}

/// The `image` colour type of `channels` at an integer `depth`.
fn color_type(channels: Channels, depth: SampleDepth) -> ExtendedColorType {
    let wide = depth == SampleDepth::U16;
    match (channels, wide) {
        (Channels::Gray, false) => ExtendedColorType::L8,
        (Channels::GrayAlpha, false) => ExtendedColorType::La8,
        (Channels::Rgb, false) => ExtendedColorType::Rgb8,
        (Channels::Rgba, false) => ExtendedColorType::Rgba8,
        (Channels::Gray, true) => ExtendedColorType::L16,
        (Channels::GrayAlpha, true) => ExtendedColorType::La16,
        (Channels::Rgb, true) => ExtendedColorType::Rgb16,
        (Channels::Rgba, true) => ExtendedColorType::Rgba16,
    }
}

/// Interleaved samples at an integer `depth` as the bytes `image`'s encoders take (16-bit
/// samples in native byte order).
fn integer_bytes<T: Sample>(image: &PlanarImage<T>, depth: SampleDepth) -> Vec<u8> {
    if depth == SampleDepth::U8 {
        interleave(image, depth, |v| v as u8)
    } else {
        let samples = interleave(image, depth, |v| v as u16);
        let mut bytes = Vec::with_capacity(2 * samples.len());
        for v in samples {
            bytes.extend_from_slice(&v.to_ne_bytes());
        }
        bytes
    }
}

/// An `image` error as a haarshift error naming `path`.
fn image_error(path: &Path, error: ImageError) -> Error {
    match error {
        ImageError::IoError(e) if e.kind() == std::io::ErrorKind::UnexpectedEof => {
            format_reason(path, "file is truncated")
        }
        ImageError::IoError(e) => io_error(path, e),
        ImageError::Limits(e) => {
            format_reason(path, format!("image exceeds the memory limit ({e})"))
        }
        other => format_reason(path, other.to_string()),
    }
}
