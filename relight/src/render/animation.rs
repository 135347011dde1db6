//! Animations: a sequence of rendered frames as one animated GIF, written atomically.
//!
//! GIF holds at most 256 colours per frame. Each frame gets its own palette, chosen by the
//! NeuQuant neural-net quantiser (the `color_quant` crate, through the `image` crate's GIF
//! encoder) at sampling speed [`QUANTIZER_SPEED`] (1 is the slowest and best, 30 the fastest),
//! and every pixel takes its nearest palette colour, without dithering. The animation loops
//! forever; frame delays are stored in hundredths of a second, so `delay_ms` is rounded to
//! 10 ms. [`numbered_path`] names the files of an animation written as numbered images.

use std::path::{Path, PathBuf};

use image::codecs::gif::{GifEncoder, Repeat};
use image::{Delay, Frame, RgbaImage};

use crate::{Error, Result};
use haarshift::io::write_file_atomically;
use haarshift::{PlanarImage, SampleDepth};

/// The NeuQuant sampling speed used for every frame's palette.
pub const QUANTIZER_SPEED: i32 = 10;

/// Writes `frames` (8-bit sRGB codes, as [`to_srgb8`](crate::render::to_srgb8) gives them:
/// RGB or gray of depth [`SampleDepth::U8`], all the same size) to `path` as a looping
/// animated GIF, `delay_ms` per frame (10 ms to 655 s); atomically, replacing an existing file
/// only with `force`. See the [module docs](self) for the palette.
///
/// ```
/// use haarshift_relight::render::animation::write_gif;
/// use haarshift::{PlanarImage, SampleDepth};
/// use ndarray::Array2;
/// let frames: Vec<_> = (0..3)
///     .map(|k| PlanarImage::from_gray(Array2::from_elem((4, 6), 100.0 * k as f32), SampleDepth::U8).unwrap())
///     .collect();
/// let dir = tempfile::tempdir().unwrap();
/// write_gif(&frames, &dir.path().join("turn.gif"), 100, false).unwrap();
/// assert!(write_gif(&frames, &dir.path().join("turn.gif"), 100, false).is_err()); // exists
/// ```
pub fn write_gif(
    frames: &[PlanarImage<f32>],
    path: &Path,
    delay_ms: u32,
    force: bool,
) -> Result<()> {
    let first = frames
        .first()
        .ok_or_else(|| Error::parameter("frames", "an animation needs at least one frame"))?;
    let (h, w) = (first.height(), first.width());
    if h > u16::MAX as usize || w > u16::MAX as usize {
        return Err(Error::shape(
            &[h, w],
            "a GIF frame is at most 65535 pixels a side",
        ));
    }
    if !(10..=655_350).contains(&delay_ms) {
        return Err(Error::parameter(
            "delay",
            format!("{delay_ms} ms (expected 10 ms to 655 s)"),
        ));
    }
    let mut images = Vec::with_capacity(frames.len());
    for (k, frame) in frames.iter().enumerate() {
        if (frame.height(), frame.width()) != (h, w) || frame.depth() != SampleDepth::U8 {
            return Err(Error::parameter(
                "frames",
                format!(
                    "frame {k} is {} x {} of depth {}; every frame must be {w} x {h} of depth u8",
                    frame.width(),
                    frame.height(),
                    frame.depth()
                ),
            ));
        }
        images.push(rgba(frame));
    }
    let centis = (delay_ms + 5) / 10;
    Ok(write_file_atomically(path, force, |out| {
        let mut encoder = GifEncoder::new_with_speed(out, QUANTIZER_SPEED);
        encoder
            .set_repeat(Repeat::Infinite)
            .map_err(std::io::Error::other)?;
        for image in images {
            let delay = Delay::from_numer_denom_ms(10 * centis, 1);
            encoder
                .encode_frame(Frame::from_parts(image, 0, 0, delay))
                .map_err(std::io::Error::other)?;
        }
        Ok(())
    })?)
}

/// An opaque RGBA image from 8-bit codes (gray repeated into R, G and B).
fn rgba(frame: &PlanarImage<f32>) -> RgbaImage {
    let colour = frame.color_planes();
    let (c, h, w) = colour.dim();
    RgbaImage::from_fn(w as u32, h as u32, |x, y| {
        let at = |k: usize| {
            colour[[k.min(c - 1), y as usize, x as usize]]
                .clamp(0.0, 255.0)
                .round() as u8
        };
        image::Rgba([at(0), at(1), at(2), 255])
    })
}

/// Frame `index`'s file for a numbered-image pattern: the one `%d` or `%0Nd` (`N` from 1 to 9)
/// in `pattern`'s file name replaced by `index`, zero-padded to `N` digits. A pattern without
/// exactly one such field is refused.
///
/// ```
/// use haarshift_relight::render::animation::numbered_path;
/// use std::path::Path;
/// assert_eq!(numbered_path(Path::new("out/frame_%03d.png"), 7).unwrap(), Path::new("out/frame_007.png"));
/// assert_eq!(numbered_path(Path::new("f%d.png"), 12).unwrap(), Path::new("f12.png"));
/// assert!(numbered_path(Path::new("frame.png"), 0).is_err());
/// assert!(numbered_path(Path::new("%d_%d.png"), 0).is_err());
/// ```
pub fn numbered_path(pattern: &Path, index: usize) -> Result<PathBuf> {
    let refuse = || {
        crate::Error::from(haarshift::Error::Format {
            path: pattern.to_path_buf(),
            reason: "numbered frames need one %d or %0Nd (N from 1 to 9) in the file name".into(),
        })
    };
    let name = pattern
        .file_name()
        .and_then(|n| n.to_str())
        .ok_or_else(refuse)?;
    let start = name.find('%').ok_or_else(refuse)?;
    let rest = &name[start + 1..];
    let (width, after) = match rest.strip_prefix('0') {
        Some(r) => {
            let digit = r
                .chars()
                .next()
                .and_then(|c| c.to_digit(10))
                .filter(|&d| d >= 1);
            (digit.ok_or_else(refuse)? as usize, &r[1..])
        }
        None => (0, rest),
    };
    let tail = after.strip_prefix('d').ok_or_else(refuse)?;
    if tail.contains('%') {
        return Err(refuse());
    }
    let file = format!("{}{index:0width$}{tail}", &name[..start]);
    Ok(pattern.with_file_name(file))
}

#[cfg(test)]
#[path = "animation_tests.rs"]
mod tests;
