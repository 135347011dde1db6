//! `haarshift info`: what an image, array or coefficient file holds.

use std::fmt::Write;
use std::path::PathBuf;

use haarshift::Channels;
use haarshift::io::{CoefficientFile, FileFormat, ReadOptions, StoredCoefficients, read_image};
use haarshift_relight::Result;
use ndarray::ArrayView3;

use super::print;

const EXAMPLES: &str = "\
Examples:
  haarshift info testdata/chelsea.png
  haarshift info camera.npy        (a coefficient file: shows its sidecar too)

Prints the size (width x height), channels, bit depth and, per channel, the smallest and
largest value, in the file's own units (0..255 for 8-bit, 0..65535 for 16-bit).";

/// Describe an image, a .npy array or a coefficient file.
#[derive(clap::Args, Debug)]
#[command(after_help = EXAMPLES)]
pub struct Args {
    /// Image (PNG, JPEG, TIFF, OpenEXR, .hdr), .npy array, or coefficient file with sidecar
    pub input: PathBuf,
}

pub fn run(args: Args) -> Result<()> {
    let path = &args.input;
    let format = FileFormat::of_file(path)?;
    let mut out = String::new();
    let sidecar = CoefficientFile::<f64>::sidecar_path(path);
    let stored = if format == FileFormat::Npy && sidecar.exists() {
        Some(StoredCoefficients::read(path, &ReadOptions::default())?)
    } else {
        None
    };
    match stored.as_ref().and_then(|s| s.metadata.map(|m| (s, m))) {
        Some((stored, meta)) => {
            let (c, h, w) = stored.array.dim();
            let t = meta.transform;
            let [rows, cols] = t.original_shape;
            let _ = writeln!(
                out,
                "file:      {} (haarshift coefficients)",
                path.display()
            );
            let _ = writeln!(out, "sidecar:   {}", sidecar.display());
            let _ = writeln!(
                out,
                "array:     {c} planes of {w} x {h} (width x height), float64"
            );
            let _ = writeln!(
                out,
                "transform: {} layout, {} normalisation, levels {:?} (rows, columns), {} padding",
                t.layout, t.normalization, t.levels, t.padding
            );
            let _ = writeln!(
                out,
                "original:  {cols} x {rows} (width x height), {} ({} channels), {}",
                meta.channels,
                meta.channels.count(),
                meta.depth
            );
            write_ranges(&mut out, meta.channels, stored.array.view());
        }
        None => {
            let image = read_image::<f64>(path)?;
            let _ = writeln!(out, "file:     {} ({format})", path.display());
            let _ = writeln!(
                out,
                "size:     {} x {} (width x height)",
                image.width(),
                image.height()
            );
            let _ = writeln!(
                out,
                "channels: {} ({})",
                image.channels(),
                image.channels().count()
            );
            let _ = writeln!(out, "depth:    {}", image.depth());
            write_ranges(&mut out, image.channels(), image.planes());
        }
    }
    print(&out)
}

/// One `range` line per plane: its name, smallest and largest value.
fn write_ranges(out: &mut String, channels: Channels, planes: ArrayView3<'_, f64>) {
    let names: &[&str] = match channels {
        Channels::Gray => &["gray"],
        Channels::GrayAlpha => &["gray", "alpha"],
        Channels::Rgb => &["red", "green", "blue"],
        Channels::Rgba => &["red", "green", "blue", "alpha"],
    };
    for (name, plane) in names.iter().zip(planes.outer_iter()) {
        let (lo, hi) = plane
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), &v| {
                (l.min(v), h.max(v))
            });
        let _ = writeln!(out, "range:    {name:<5} {lo} .. {hi}");
    }
}
