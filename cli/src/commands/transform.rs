//! `haarshift transform`: image -> coefficient file.

use std::path::PathBuf;

use haarshift::Sample;
use haarshift::io::{CoefficientFile, WriteOptions, read_image};
use haarshift_relight::Result;

use super::{Compute, TransformFlags, print, refuse_outputs};

const EXAMPLES: &str = "\
Examples:
  haarshift transform testdata/camera.png -o camera.npy
  haarshift transform photo.jpg -o photo.npy --layout separable --norm orthonormal --levels 3
  haarshift transform scan.tif -o scan.npy --pad reflect --force

The output holds one plane of coefficients per channel (C x H x W, float64), H and W being the
image's sides rounded up to powers of two. In the pyramid layout the coarsest averages sit at
the top left and level l's details a (horizontal), b (vertical), c (diagonal) to its right,
below and diagonally. The sidecar OUT.npy.json records the transform, the original size, the
channels and the bit depth, so `haarshift inverse` restores the image exactly.";

/// Haar-transform an image and save the coefficients (.npy plus a .json sidecar).
#[derive(clap::Args, Debug)]
#[command(after_help = EXAMPLES)]
pub struct Args {
    /// Image to transform: PNG, JPEG, TIFF (8/16-bit), OpenEXR, Radiance .hdr, or a .npy float
    /// array (H x W or H x W x C)
    pub input: PathBuf,

    /// Coefficient file to write (.npy); its sidecar is written to OUT.npy.json
    #[arg(short, long, value_name = "OUT.npy")]
    pub output: PathBuf,

    #[command(flatten)]
    pub transform: TransformFlags,

    /// Replace the output and its sidecar if they exist
    #[arg(long)]
    pub force: bool,

    /// Float type to compute in: `f64` or `f32` (faster; its rounding then shows in the
    /// float64 coefficients) [default: f64, the coefficient file's type]
    #[arg(long, value_enum, value_name = "TYPE")]
    pub compute: Option<Compute>,
}

pub fn run(args: Args) -> Result<()> {
    let sidecar = CoefficientFile::<f64>::sidecar_path(&args.output);
    refuse_outputs(&[&args.input], &[&args.output, &sidecar], args.force)?;
    match args.compute.unwrap_or(Compute::F64) {
        Compute::F32 => transform::<f32>(&args),
        Compute::F64 => transform::<f64>(&args),
    }
}

/// Reads, transforms and writes in `T`.
fn transform<T: Sample>(args: &Args) -> Result<()> {
    let sidecar = CoefficientFile::<T>::sidecar_path(&args.output);
    let image = read_image::<T>(&args.input)?;
    let spec = args.transform.request().spec();
    let coefficients =
        CoefficientFile::forward(&image, &spec).map_err(|e| e.in_file(&args.input))?;
    let options = WriteOptions {
        force: args.force,
        ..Default::default()
    };
    coefficients.write(&args.output, options)?;
    let meta = coefficients.metadata();
    let (h, w) = coefficients.planes()[0].as_array().dim();
    print(&format!(
        "{}: {} x {} x {} coefficients ({} layout, {} normalisation, levels {:?}, {} padding), \
         sidecar {}\n",
        args.output.display(),
        meta.channels.count(),
        h,
        w,
        meta.transform.layout,
        meta.transform.normalization,
        meta.transform.levels,
        meta.transform.padding,
        sidecar.display()
    ))
}
