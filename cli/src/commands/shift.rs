//! `haarshift shift`: an image moved by a whole or fractional number of pixels, in the Haar
//! domain or with a pixel-domain kernel.

use std::path::PathBuf;

use haarshift::io::read_image;
use haarshift::kernels::ShiftMethod;
use haarshift::shift::PlaneShift;
use haarshift::{BoundaryMode, Sample};
use haarshift_relight::Result;

use super::method::MethodFlags;
use super::{Compute, ComputeFlag, ImageOutput, choice, names, number};

const EXAMPLES: &str = "\
Examples:
  haarshift shift testdata/camera.png -o moved.png --dx 3 --dy -5
  haarshift shift camera.png -o half.png --dx 0.5 --precision 1
  haarshift shift camera.png -o fine.npy --dx 0.3 --dy 0.7 --precision 2 --retain
  haarshift shift photo.png -o moved.png --dx 2.25 --method bspline3 --boundary reflect

Sign convention (scipy.ndimage.shift): out[r][c] = in[r - dy][c - dx], so a positive dx
moves content right and a positive dy moves it down.

Haar (the default): each plane is transformed (pyramid, average normalisation, full depth),
shifted directly on its coefficients and transformed back. The shift is periodic over the
transform's size, the image's sides rounded up to powers of two: content leaving one side
comes back on the other. A non-power-of-two image is first padded periodically at the bottom
and right, and that padding (copies of the top and left) can wrap into view. Shifts are
rounded to 1/2^H pixel (ties upwards); an integer shift is exact. The compact result equals
periodic bilinear interpolation at the rounded shift. With --retain the output is the
2^H-finer image the retained N+H levels describe, 2^H times the input's width and height:
each pixel becomes a 2^H x 2^H block moved by a whole number of fine samples; its 2^H x 2^H
box average is the compact result.

Other methods shift rows, then columns, in the pixel domain, with samples from outside the
image given by --boundary (wrap by default, matching the Haar shift on power-of-two images).

Every plane, alpha included, is shifted as it is (no premultiplication): integer shifts move
pixels exactly; fractional ones mix the colour of neighbouring pixels whatever their alpha.";

/// Shift an image by (dx, dy) pixels, in the Haar domain or the pixel domain.
#[derive(clap::Args, Debug)]
#[command(after_help = EXAMPLES)]
pub struct Args {
    /// Image to shift: PNG, JPEG, TIFF, OpenEXR, .hdr or a .npy array
    pub input: PathBuf,

    #[command(flatten)]
    pub output: ImageOutput,

    /// Columns to move by (positive: right)
    #[arg(long, value_name = "F", allow_negative_numbers = true)]
    pub dx: f64,

    /// Rows to move by (positive: down)
    #[arg(
        long,
        value_name = "F",
        allow_negative_numbers = true,
        default_value_t = 0.0
    )]
    pub dy: f64,

    #[command(flatten)]
    pub method: MethodFlags,

    /// Samples from outside the image, for pixel-domain methods: `wrap` (periodic), `zero`,
    /// `edge` (last pixel), `reflect` (mirrored). The Haar shift is always `wrap`
    /// [default: wrap]
    #[arg(long, value_parser = choice::<BoundaryMode>(names!(BoundaryMode)))]
    pub boundary: Option<BoundaryMode>,

    #[command(flatten)]
    pub compute: ComputeFlag,
}

pub fn run(args: Args) -> Result<()> {
    args.output.refuse_overwriting(&[&args.input])?;
    match args.compute.resolve(&args.input)? {
        Compute::F32 => shift::<f32>(&args),
        Compute::F64 => shift::<f64>(&args),
    }
}

/// Reads, shifts and writes in `T`.
fn shift<T: Sample>(args: &Args) -> Result<()> {
    let (method, options) = args.method.resolve(ShiftMethod::Haar)?;
    let shift = PlaneShift::new(method, options, args.boundary.unwrap_or(BoundaryMode::Wrap))?;
    let (dx, dy) = (args.dx, args.dy);
    let image = read_image::<T>(&args.input)?;
    let shifted = image.map_planes(|p| shift.apply(p, dx, dy))?;
    drop(image);
    let what = format!(
        ", shifted by ({}, {}) with {method} in {}",
        number(dx),
        number(dy),
        T::NAME
    );
    args.output.write(&shifted, None, &what)
}
