//! TIFF through the `tiff` crate directly: unlike the `image` crate's TIFF support it reads and
//! writes gray+alpha.

use std::io::{Seek, Write};
use std::path::Path;

use tiff::ColorType;
use tiff::decoder::{Decoder, DecodingResult};

use super::raster::dimensions;
use super::{
    ReadOptions, Source, check_size, deinterleave, format_reason, interleave, io_error, planar,
};
use crate::{Channels, Error, PlanarImage, Result, Sample, SampleDepth};

/// Decodes the first image of a TIFF file: 8- or 16-bit integer or 32-bit float samples, with
/// 1 to 4 channels.
pub(super) fn read<T: Sample>(
    source: &Source<'_>,
    options: &ReadOptions,
) -> Result<PlanarImage<T>> {
    let path = source.name();
    let tiff_error = |e: tiff::TiffError| match e {
        tiff::TiffError::IoError(e) if e.kind() == std::io::ErrorKind::UnexpectedEof => {
            format_reason(path, "file is truncated")
        }
        tiff::TiffError::IoError(e) => io_error(path, e),
        tiff::TiffError::LimitsExceeded => format_reason(path, "image exceeds the memory limit"),
        other => format_reason(path, format!("invalid TIFF file: {other}")),
    };
    let mut limits = tiff::decoder::Limits::default();
    limits.decoding_buffer_size = usize::try_from(options.memory_limit).unwrap_or(usize::MAX);
    let mut decoder = Decoder::new(source.open()?)
        .map_err(tiff_error)?
        .with_limits(limits);
    let (w, h) = decoder.dimensions().map_err(tiff_error)?;
    let color = decoder.colortype().map_err(tiff_error)?;
    let (channels, bits) = match color {
        ColorType::Gray(b) => (1, b),
        ColorType::GrayA(b) => (2, b),
        // Gray with an extra (alpha) sample: how the `tiff` crate reports gray+alpha.
        ColorType::Multiband {
            bit_depth,
            num_samples: 2,
        } => (2, bit_depth),
        ColorType::RGB(b) => (3, b),
        ColorType::RGBA(b) => (4, b),
        other => {
            return Err(format_reason(
                path,
                format!("unsupported TIFF colour type {other:?}"),
            ));
        }
    };
    let shape = [h as usize, w as usize, channels];
    check_size::<T>(
        path,
        &shape,
        u64::from(bits.div_ceil(8)),
        options.memory_limit,
    )?;
    let planar_shape = (channels, h as usize, w as usize);
    let unsupported = || {
        format_reason(
            path,
            format!("unsupported TIFF sample format ({bits}-bit {color:?})"),
        )
    };
    let expected = channels * shape[0] * shape[1];
    let (planes, depth) = match decoder.read_image().map_err(tiff_error)? {
        DecodingResult::U8(v) if bits == 8 && v.len() == expected => {
            (deinterleave(&v, planar_shape, f64::from), SampleDepth::U8)
        }
        DecodingResult::U16(v) if v.len() == expected => {
            (deinterleave(&v, planar_shape, f64::from), SampleDepth::U16)
        }
        DecodingResult::F32(v) if v.len() == expected => {
            (deinterleave(&v, planar_shape, f64::from), SampleDepth::F32)
        }
        _ => return Err(unsupported()),
    };
    planar(path, planes, depth)
}

/// Encodes a baseline TIFF (deflate-compressed) at `depth`, `U8` or `U16`.
pub(super) fn write<T: Sample, W: Write + Seek>(
    image: &PlanarImage<T>,
    depth: SampleDepth,
    path: &Path,
    out: &mut W,
) -> Result<()> {
    use tiff::encoder::{Compression, DeflateLevel, TiffEncoder, colortype};
    let (w, h) = dimensions(image, path)?;
    let result = (|| -> tiff::TiffResult<()> {
        let mut encoder = TiffEncoder::new(&mut *out)?
            .with_compression(Compression::Deflate(DeflateLevel::Balanced));
        let alpha = [tiff::tags::ExtraSamples::UnassociatedAlpha];
        macro_rules! encode {
            ($color:ty, $data:expr, $extra:expr) => {{
                let mut tiff_image = encoder.new_image::<$color>(w, h)?;
                if $extra {
                    tiff_image.extra_samples(&alpha)?;
                }
                tiff_image.write_data(&$data)
            }};
        }
        let u8s = || interleave(image, SampleDepth::U8, |v| v as u8);
        let u16s = || interleave(image, SampleDepth::U16, |v| v as u16);
        match (image.channels(), depth) {
            (Channels::Gray, SampleDepth::U8) => encode!(colortype::Gray8, u8s(), false),
            (Channels::GrayAlpha, SampleDepth::U8) => encode!(colortype::Gray8, u8s(), true),
            (Channels::Rgb, SampleDepth::U8) => encode!(colortype::RGB8, u8s(), false),
            (Channels::Rgba, SampleDepth::U8) => encode!(colortype::RGBA8, u8s(), false),
            (Channels::Gray, _) => encode!(colortype::Gray16, u16s(), false),
            (Channels::GrayAlpha, _) => encode!(colortype::Gray16, u16s(), true),
            (Channels::Rgb, _) => encode!(colortype::RGB16, u16s(), false),
            (Channels::Rgba, _) => encode!(colortype::RGBA16, u16s(), false),
        }
    })();
    result.map_err(|e| Error::Format {
        path: path.to_path_buf(),
        reason: format!("cannot encode TIFF: {e}"),
    })
}
