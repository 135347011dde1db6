//! `haarshift inverse`: coefficient file -> image.

use std::path::PathBuf;

use haarshift::SampleDepth;
use haarshift::io::{CoefficientFile, ReadOptions, StoredCoefficients};
use haarshift_relight::Result;

use super::{ImageOutput, TransformFlags, choice, names};

const EXAMPLES: &str = "\
Examples:
  haarshift inverse camera.npy -o camera-restored.png
  haarshift inverse photo.npy -o photo.tif --force
  haarshift inverse pywt-coeffs.npy -o out.exr --layout separable --norm orthonormal

With the sidecar COEFFS.npy.json (written by `haarshift transform`) the transform, original
size, channels and bit depth come from it and the image is restored exactly; transform flags
given here must agree with it. Without a sidecar the flags describe the coefficients
(defaults: pyramid, average, full, zero), the output keeps the array's full padded size
because the original size is unknown, and samples are float64 (pass --depth u8 or u16 to
write PNG/TIFF/JPEG).

Integer outputs are rounded to nearest and clamped to 0..255 or 0..65535.";

/// Invert a coefficient file back to an image.
#[derive(clap::Args, Debug)]
#[command(after_help = EXAMPLES)]
pub struct Args {
    /// Coefficient file (.npy, C x H x W or H x W) written by `haarshift transform`
    pub input: PathBuf,

    #[command(flatten)]
    pub output: ImageOutput,

    #[command(flatten)]
    pub transform: TransformFlags,

    /// Store samples at this depth instead of the original's (u8/u16 for PNG, TIFF and JPEG;
    /// f16/f32 for EXR; f32/f64 for .npy) [default: the depth recorded in the sidecar]
    #[arg(long, value_parser = choice::<SampleDepth>(names!(SampleDepth)))]
    pub depth: Option<SampleDepth>,
}

pub fn run(args: Args) -> Result<()> {
    let sidecar = CoefficientFile::<f64>::sidecar_path(&args.input);
    args.output.refuse_overwriting(&[&args.input, &sidecar])?;
    let stored = StoredCoefficients::read(&args.input, &ReadOptions::default())?;
    if stored.metadata.is_none() {
        let (_, h, w) = stored.array.dim();
        eprintln!(
            "haarshift: note: {} has no sidecar {}: using the transform flags given; the \
             original size is unknown, so the output keeps the full {h}x{w}",
            args.input.display(),
            sidecar.display()
        );
    }
    let coefficients = stored.resolve(&args.transform.request())?;
    let image = coefficients.inverse().map_err(|e| e.in_file(&args.input))?;
    args.output.write(&image, args.depth, "")
}
