//! OpenEXR through the `exr` crate: f16 or f32 channels named `Y`, `Y A`, `R G B` or
//! `R G B A` (a layer prefix such as `diffuse.R` is ignored).

use std::io::{Seek, Write};
use std::path::Path;

use exr::prelude::{
    AnyChannel, AnyChannels, Encoding, FlatSamples, Image, Layer, LayerAttributes, MetaData,
    ReadChannels, ReadLayers, SampleType, SmallVec, WritableImage, f16,
};
use ndarray::{Array3, Axis};

use super::{ReadOptions, Source, check_size, format_reason, io_error, planar};
use crate::{Channels, PlanarImage, Result, Sample, SampleDepth};

/// The channel names of each layout, in plane order.
fn channel_names(channels: Channels) -> &'static [&'static str] {
    match channels {
        Channels::Gray => &["Y"],
        Channels::GrayAlpha => &["Y", "A"],
        Channels::Rgb => &["R", "G", "B"],
        Channels::Rgba => &["R", "G", "B", "A"],
    }
}

/// The name of a channel without its layer prefix.
fn base_name(name: &exr::prelude::Text) -> String {
    let name = name.to_string();
    match name.rsplit_once('.') {
        Some((_, base)) => base.to_string(),
        None => name,
    }
}

/// Reads the first layer of an OpenEXR file.
pub(super) fn read<T: Sample>(
    source: &Source<'_>,
    options: &ReadOptions,
) -> Result<PlanarImage<T>> {
    let path = source.name();
    let exr_error = |e: exr::error::Error| match e {
        exr::error::Error::Io(e) if e.kind() == std::io::ErrorKind::UnexpectedEof => {
            format_reason(path, "file is truncated")
        }
        // A seek the system refuses (EINVAL) comes from an offset in the file, not the disk.
        exr::error::Error::Io(e) if e.kind() == std::io::ErrorKind::InvalidInput => format_reason(
            path,
            "invalid OpenEXR file: a chunk offset lies outside the file",
        ),
        exr::error::Error::Io(e) => io_error(path, e),
        other => format_reason(path, format!("invalid OpenEXR file: {other}")),
    };
    // The header alone first: the sizes it promises are checked before any pixel buffer exists.
    let meta = MetaData::read_from_buffered(source.open()?, false).map_err(exr_error)?;
    let header = meta
        .headers
        .iter()
        .find(|h| !h.deep)
        .ok_or_else(|| format_reason(path, "OpenEXR file has no flat (non-deep) layer"))?;
    let names: Vec<String> = header
        .channels
        .list
        .iter()
        .map(|c| base_name(&c.name))
        .collect();
    let channels = [
        Channels::Rgba,
        Channels::Rgb,
        Channels::GrayAlpha,
        Channels::Gray,
    ]
    .into_iter()
    .find(|&ch| {
        let wanted = channel_names(ch);
        wanted.len() == names.len() && wanted.iter().all(|w| names.iter().any(|n| n == w))
    })
    .ok_or_else(|| {
        format_reason(
            path,
            format!("unsupported OpenEXR channels {names:?} (expected Y, Y A, R G B or R G B A)"),
        )
    })?;
    let mut depth = SampleDepth::F16;
    for c in &header.channels.list {
        match c.sample_type {
            SampleType::F16 => {}
            SampleType::F32 => depth = SampleDepth::F32,
            SampleType::U32 => {
                return Err(format_reason(
                    path,
                    "OpenEXR u32 channels are not supported (expected f16 or f32)",
                ));
            }
        }
    }
    let size = header.layer_size;
    let shape = [size.height(), size.width(), names.len()];
    check_size::<T>(path, &shape, 4, options.memory_limit)?;

    let image = exr::prelude::read()
        .no_deep_data()
        .largest_resolution_level()
        .all_channels()
        .first_valid_layer()
        .all_attributes()
        .from_buffered(source.open()?)
        .map_err(exr_error)?;
    let layer = &image.layer_data;
    let (h, w) = (layer.size.height(), layer.size.width());
    let mut planes = Array3::<T>::zeros((channels.count(), h, w));
    for (name, mut plane) in channel_names(channels)
        .iter()
        .zip(planes.axis_iter_mut(Axis(0)))
    {
        let channel = layer
            .channel_data
            .list
            .iter()
            .find(|c| base_name(&c.name) == *name)
            .ok_or_else(|| format_reason(path, format!("OpenEXR channel {name} is missing")))?;
        let samples = &channel.sample_data;
        if samples.len() != h * w {
            return Err(format_reason(
                path,
                format!("OpenEXR channel {name} is subsampled, which is not supported"),
            ));
        }
        for (dst, v) in plane.iter_mut().zip(samples.values_as_f32()) {
            *dst = T::from_f64(f64::from(v));
        }
    }
    planar(path, planes, depth)
}

/// Writes one layer with f16 channels at depth `F16` and f32 otherwise (lossless ZIP
/// compression).
pub(super) fn write<T: Sample, W: Write + Seek>(
    image: &PlanarImage<T>,
    depth: SampleDepth,
    path: &Path,
    out: &mut W,
) -> Result<()> {
    let (h, w) = (image.height(), image.width());
    let mut list: SmallVec<[AnyChannel<FlatSamples>; 4]> = SmallVec::new();
    for (c, name) in channel_names(image.channels()).iter().enumerate() {
        let values = image.plane(c);
        let samples = if depth == SampleDepth::F16 {
            let half: Vec<f16> = values.iter().map(|v| f16::from_f64(v.as_f64())).collect();
            if let Some(bad) = half.iter().position(|v| !v.is_finite()) {
                return Err(format_reason(
                    path,
                    format!(
                        "value {} in channel {name} does not fit in a half float",
                        values.iter().nth(bad).map_or(0.0, |v| v.as_f64())
                    ),
                ));
            }
            FlatSamples::F16(half)
        } else {
            FlatSamples::F32(values.iter().map(|v| v.as_f64() as f32).collect())
        };
        list.push(AnyChannel::new(*name, samples));
    }
    let layer = Layer::new(
        (w, h),
        LayerAttributes::default(),
        Encoding::SMALL_LOSSLESS,
        AnyChannels::sort(list),
    );
    Image::from_layer(layer)
        .write()
        .to_buffered(out)
        .map_err(|e| match e {
            exr::error::Error::Io(e) => io_error(path, e),
            other => format_reason(path, format!("cannot encode OpenEXR: {other}")),
        })
}
