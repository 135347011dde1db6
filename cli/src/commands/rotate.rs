//! `haarshift rotate`: an image turned by any angle with three shears.

use std::path::PathBuf;

use haarshift::io::read_image;
use haarshift::kernels::{Outside, ShiftMethod};
use haarshift::rotate::{Canvas, RotateOptions, rotate_image};
use haarshift::{BoundaryMode, Sample, SampleDepth};
use haarshift_relight::Result;

use super::method::MethodFlags;
use super::{Compute, ComputeFlag, ImageOutput, choice, names, number};

const EXAMPLES: &str = "\
Examples:
  haarshift rotate testdata/camera.png -o turned.png --angle 30
  haarshift rotate photo.jpg -o photo-90.jpg --angle -90            (clockwise, exact)
  haarshift rotate scan.tif -o scan.tif.png --angle 12.5 --canvas expand --fill 255
  haarshift rotate camera.png -o haar.png --angle 30 --method haar --precision 3 --retain
  haarshift rotate camera.png -o ss.png --angle 30 --method keys --supersample 2

Conventions: a positive angle turns the image counter-clockwise as displayed (row 0 at the
top), like scipy.ndimage.rotate, about the centre ((w-1)/2, (h-1)/2). The angle is split
into exact quarter turns (copies, bit-exact for every method) and a residual in [-45, 45]
degrees done by three shears (x by -tan(t/2), y by sin(t), x by -tan(t/2)), each shifting
every row or column by its own fractional amount with the chosen method.

The default method, bspline3, is accurate (an interpolating cubic spline with the exact
prefilter) and fast (4 taps plus a recursive filter); keys is a little faster and blurrier,
bspline5, lanczos4 and fft sharper and slower.

Haar: every shift is rounded to 1/2^H pixel. Compact (the default) projects back to the
original levels after each shear: that equals linear interpolation with each shear's shifts
rounded to 1/2^H. With --retain the H extra levels are kept across the three shears: that
equals nearest neighbour on a 2^H-finer grid, box-averaged back to pixels at the end. Memory
grows as 4^(H+S) with --supersample S (rotate on a 2^S-finer grid, box-average back; any
method), within a 4 GiB budget.

Images with alpha are rotated premultiplied, so colour does not bleed from transparent
pixels; outside the image is transparent. All work is in float with no rounding between the
shears; 8- and 16-bit outputs are rounded to nearest and clamped.";

/// Rotate an image by any angle (three shears; quarter turns exact).
#[derive(clap::Args, Debug)]
#[command(after_help = EXAMPLES)]
pub struct Args {
    /// Image to rotate: PNG, JPEG, TIFF, OpenEXR, .hdr or a .npy array
    pub input: PathBuf,

    #[command(flatten)]
    pub output: ImageOutput,

    /// Angle in degrees, counter-clockwise as displayed (negative: clockwise)
    #[arg(long, value_name = "DEG", allow_negative_numbers = true)]
    pub angle: f64,

    #[command(flatten)]
    pub method: MethodFlags,

    /// Rotate on a 2^S-finer grid and box-average back (at most 8) [default: 0]
    #[arg(long, value_name = "S", default_value_t = 0, hide_default_value = true)]
    pub supersample: u32,

    /// `same`: the input's size (corners are cut off); `expand`: large enough for the whole
    /// rotated image [default: same]
    #[arg(long, value_parser = choice::<Canvas>(names!(Canvas)))]
    pub canvas: Option<Canvas>,

    /// Value of the pixels from outside the image (in the file's units, e.g. 0..255) [default:
    /// 0, transparent when the image has alpha]
    #[arg(
        long,
        value_name = "V",
        allow_negative_numbers = true,
        conflicts_with = "boundary"
    )]
    pub fill: Option<f64>,

    /// Continue the image outside its border instead of filling: `edge` (last pixel),
    /// `reflect` (mirrored), `wrap` (periodic), `zero`
    #[arg(long, value_parser = choice::<BoundaryMode>(names!(BoundaryMode)))]
    pub boundary: Option<BoundaryMode>,

    /// Store samples at this depth instead of the input's (u8/u16 for PNG, TIFF and JPEG;
    /// f16/f32 for EXR; f32/f64 for .npy)
    #[arg(long, value_parser = choice::<SampleDepth>(names!(SampleDepth)))]
    pub depth: Option<SampleDepth>,

    #[command(flatten)]
    pub compute: ComputeFlag,
}

pub fn run(args: Args) -> Result<()> {
    args.output.refuse_overwriting(&[&args.input])?;
    match args.compute.resolve(&args.input)? {
        Compute::F32 => rotate::<f32>(&args),
        Compute::F64 => rotate::<f64>(&args),
    }
}

/// Reads, rotates and writes in `T`.
fn rotate<T: Sample>(args: &Args) -> Result<()> {
    let (method, kernel_options) = args.method.resolve(ShiftMethod::BSpline3)?;
    let kernel = method.kernel_with::<T>(&kernel_options)?;
    let options = RotateOptions {
        canvas: args.canvas.unwrap_or_default(),
        outside: match args.boundary {
            Some(mode) => Outside::Boundary(mode),
            None => Outside::Fill(args.fill.unwrap_or(0.0)),
        },
        supersample: args.supersample,
        ..Default::default()
    };
    let mut image = read_image::<T>(&args.input)?;
    if let Some(depth) = args.depth {
        // Rotation rounds integer depths to their codes: round once, at the output's depth
        // (an 8-bit input written as 16 bits keeps the rotation's finer values).
        image = image.with_depth(depth);
    }
    let rotated = rotate_image(&image, args.angle, kernel.as_ref(), &options)?;
    drop(image);
    let what = format!(
        ", rotated by {} degrees with {} in {}",
        number(args.angle),
        kernel.name(),
        T::NAME
    );
    args.output.write(&rotated, args.depth, &what)
}
