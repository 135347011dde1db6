//! `haarshift sphere ...`: spherical environment maps (lat-long, 2:1).

use std::path::{Path, PathBuf};

use clap::Subcommand;
use haarshift::faces::ParamKind;
use haarshift::faces::integrate::{IntegralMethod, IntegrateOptions, check_size};
use haarshift::faces::map_product::{ProductOptions, map_product};
use haarshift::io::{CoefficientFile, FileFormat, WriteOptions, read_image};
use haarshift::product::Selection;
use haarshift::sphere::{LatLongMap, Method, SphereOptions, SphereRotation, rotate_map};
use haarshift::{PlanarImage, Sample, SampleDepth};
use haarshift_relight::Result;
use indicatif::ProgressBar;

use super::{Compute, ComputeFlag, ImageOutput, choice, names, print, refuse_outputs};
use crate::progress::progress_bar;

/// Operations on lat-long environment maps.
#[derive(Subcommand, Debug)]
pub enum SphereCommand {
    Rotate(RotateArgs),
    Integrate(IntegrateArgs),
    Product(ProductArgs),
}

pub fn run(command: SphereCommand) -> Result<()> {
    match command {
        SphereCommand::Rotate(args) => rotate(args),
        SphereCommand::Integrate(args) => integrate(args),
        SphereCommand::Product(args) => product(args),
    }
}

const ROTATE_HELP: &str = "\
Conventions:
  The map is a lat-long (equirectangular) map, W = 2 H, H a power of two. Row i is the
  elevation theta from +Y (up), column j the azimuth phi; pixel centres are at
  theta = (i + 0.5) pi / H, phi = (j + 0.5) 2 pi / W, and (theta, phi) is the direction
  (sin theta sin phi, cos theta, sin theta cos phi): right-handed, Y up.
  Angles are in degrees: yaw about +Y, pitch about +X, roll about +Z, combined as
  R = Rz(roll) Ry(yaw) Rx(pitch), and the rotated map is g(p) = f(R p): the output pixel
  looking along p shows what the input saw along R p. A yaw by a whole number of columns
  (a multiple of 360 / W degrees) is an exact shift for every method.

Examples:
  haarshift sphere rotate park.hdr -o park-tilted.exr --pitch 30
  haarshift sphere rotate park.exr -o park.npy --yaw 40 --pitch -25 --roll 60 --method bicubic
  haarshift sphere rotate park.npy -o coarse.exr --pitch 90 --method haar --level 5
  haarshift sphere rotate lobe.npy -o turned.npy --pitch 45 --method haar-cubic
  haarshift sphere rotate park.hdr -o truth.exr --pitch 30 --method reference --samples 16
  haarshift sphere rotate park.hdr -o park-coeffs.npy --yaw 10 --coefficients

Input and output are HDR, OpenEXR or .npy (H x W x C float); the output keeps the input's
sample precision (f32, or f64 for an f64 .npy). With --coefficients the output is the
rotated map's Haar pyramid (C x H x W float64 .npy, the 2:1 map as two square pyramids side
by side, average normalisation) with a sidecar OUT.npy.json, as `haarshift transform` writes
it: `haarshift inverse OUT.npy -o map.exr` turns it back into pixels.";

/// Rotate a lat-long environment map (g(p) = f(R p)), in pixels or in the Haar domain.
#[derive(clap::Args, Debug)]
#[command(after_help = ROTATE_HELP)]
pub struct RotateArgs {
    /// Lat-long map to rotate: Radiance .hdr, OpenEXR or .npy, twice as wide as high, the
    /// height a power of two
    pub input: PathBuf,

    /// Where to write the rotated map (.exr, .npy or .hdr), or with --coefficients its
    /// coefficients (.npy, plus the sidecar OUT.npy.json)
    #[arg(short, long, value_name = "OUTPUT")]
    pub output: PathBuf,

    /// Rotation about +Y (the vertical axis), degrees; yaw 90: the output's +Z (phi = 0)
    /// shows the input's +X (phi = 90 degrees)
    #[arg(
        long,
        value_name = "DEG",
        default_value_t = 0.0,
        allow_negative_numbers = true
    )]
    pub yaw: f64,

    /// Rotation about +X, degrees; pitch 90: the output's top (+Y) shows the input's +Z
    #[arg(
        long,
        value_name = "DEG",
        default_value_t = 0.0,
        allow_negative_numbers = true
    )]
    pub pitch: f64,

    /// Rotation about +Z, degrees; roll 90: the output's top (+Y) shows the input's -X
    #[arg(
        long,
        value_name = "DEG",
        default_value_t = 0.0,
        allow_negative_numbers = true
    )]
    pub roll: f64,

    /// `haar`: the chain rule on the Haar detail coefficients, coarser levels by recursive
    /// filters (no pixel lookups). `haar-cubic`: the same with four-point differences and
    /// Catmull-Rom derivatives (bicubic's accuracy, in the Haar domain). `bilinear`,
    /// `bicubic`: one lookup per output pixel.
    /// `reference`: ground truth, the solid-angle mean of SAMPLES x SAMPLES bilinear lookups
    /// per output pixel (slow)
    #[arg(long, default_value = "haar", value_parser = choice::<Method>(names!(Method)))]
    pub method: Method,

    /// Compute only detail levels 0..=L (0 the coarsest; a map of H rows has levels
    /// 0..=log2(H)-1): the work is on the 2^(L+1) x 2^(L+2) approximation, 4x less per level
    /// dropped, and the output has blocks of equal pixels [default: the finest level]
    #[arg(long, value_name = "L")]
    pub level: Option<usize>,

    /// Samples per axis and pixel for --method reference (1 to 64)
    #[arg(long, value_name = "N", default_value_t = 8)]
    pub samples: usize,

    /// Write the rotated Haar coefficients (.npy + .npy.json sidecar) instead of pixels
    #[arg(long)]
    pub coefficients: bool,

    /// Replace the output (and its sidecar) if it exists
    #[arg(long)]
    pub force: bool,
}

fn rotate(args: RotateArgs) -> Result<()> {
    let sidecar = CoefficientFile::<f64>::sidecar_path(&args.output);
    let outputs: &[&Path] = if args.coefficients {
        &[&args.output, &sidecar]
    } else {
        &[&args.output]
    };
    refuse_outputs(&[&args.input], outputs, args.force)?;
    let rotation = SphereRotation::from_degrees(args.yaw, args.pitch, args.roll)?;
    let options = SphereOptions {
        method: args.method,
        level: args.level,
        reference_samples: args.samples,
    };
    // Work in the input's own precision: f64 only for f64 data.
    let image = read_image::<f64>(&args.input)?;
    let (h, w) = (image.height(), image.width());
    if image.depth() == SampleDepth::F64 {
        rotate_image(&args, image, &rotation, &options)?;
    } else {
        let (planes, channels, depth) = image.into_parts();
        let single = PlanarImage::new(planes.mapv(|v| v as f32), channels, depth)?;
        rotate_image(&args, single, &rotation, &options)?;
    }
    let what = if args.coefficients {
        format!("coefficients, sidecar {}", sidecar.display())
    } else {
        "pixels".into()
    };
    print(&format!(
        "{}: {w} x {h} map rotated by yaw {} pitch {} roll {} ({} method, {what})\n",
        args.output.display(),
        args.yaw,
        args.pitch,
        args.roll,
        args.method,
    ))
}

/// Rotates `image` and writes the pixels or coefficients `args` ask for.
fn rotate_image<T: Sample>(
    args: &RotateArgs,
    image: PlanarImage<T>,
    rotation: &SphereRotation,
    options: &SphereOptions,
) -> Result<()> {
    let in_input = |e: haarshift::Error| e.in_file(&args.input);
    let map = LatLongMap::from_image(&image).map_err(in_input)?;
    let rotated = rotate_map(&map, rotation, options).map_err(in_input)?;
    let write = WriteOptions {
        force: args.force,
        ..Default::default()
    };
    if args.coefficients {
        let file = rotated.coefficients.to_coefficient_file(image.depth())?;
        Ok(file.write(&args.output, write)?)
    } else {
        let out = rotated.map.to_image(image.depth())?;
        Ok(haarshift::io::write_image(&out, &args.output, write)?)
    }
}

/// The maps of `sphere integrate` and `sphere product` and how each is represented.
#[derive(clap::Args, Debug)]
pub struct MapFlags {
    /// Two or more lat-long maps (HDR, OpenEXR or .npy; H x 2H, H a power of two, all of one
    /// size; a 1-channel map multiplies every channel of the others)
    #[arg(required = true, num_args = 2..)]
    pub maps: Vec<PathBuf>,

    /// Detail coefficients kept per map: one count for every map, or one per map (K1,K2,...)
    #[arg(
        long,
        value_name = "K",
        value_delimiter = ',',
        conflicts_with = "threshold"
    )]
    pub keep: Vec<usize>,

    /// Keep every detail coefficient of magnitude above T (orthonormal normalisation)
    #[arg(long, value_name = "T")]
    pub threshold: Option<f64>,

    /// With --keep: K largest of each face rather than over the whole map
    #[arg(long, requires = "keep")]
    pub per_face: bool,

    /// `latlong`: two H x H faces, the halves of the map. `cube`: six faces, each map
    /// converted by solid-angle integration over each cube texel
    #[arg(long, default_value = "latlong", value_parser = choice::<ParamKind>(names!(ParamKind)))]
    pub param: ParamKind,

    /// Working face side: lat-long N x 2N or cube 6 x N x N, a power of two [default: the
    /// maps' height H for latlong, H / 2 for cube]
    #[arg(long, value_name = "N")]
    pub resolution: Option<usize>,

    #[command(flatten)]
    pub compute: ComputeFlag,
}

impl MapFlags {
    /// The selection of each map (one for all when one is given).
    fn selections(&self) -> Result<Vec<Selection>> {
        Ok(Selection::from_counts(
            &self.keep,
            self.threshold,
            self.per_face,
        )?)
    }

    /// The float type given, or f64 when any map holds f64 samples and f32 otherwise.
    fn compute(&self) -> Result<Compute> {
        for path in &self.maps {
            if self.compute.resolve(path)? == Compute::F64 {
                return Ok(Compute::F64);
            }
        }
        Ok(Compute::F32)
    }

    /// Reads the maps as lat-long maps of `T`, checking each one's size against the first's
    /// so that an error names its file; one bar step each.
    fn read<T: Sample>(&self, bar: &ProgressBar) -> Result<Vec<LatLongMap<T>>> {
        let mut maps: Vec<LatLongMap<T>> = Vec::with_capacity(self.maps.len());
        for path in &self.maps {
            bar.set_message(format!("reading {}", path.display()));
            let image = read_image::<T>(path)?;
            let map = LatLongMap::from_image(&image).map_err(|e| e.in_file(path))?;
            let height = maps.first().unwrap_or(&map).height();
            check_size(height, &map).map_err(|e| e.in_file(path))?;
            maps.push(map);
            bar.inc(1);
        }
        Ok(maps)
    }
}

/// A bar over reading `maps` maps and one computation, its elapsed time kept ticking (hidden
/// when stderr is not a terminal).
fn map_progress(maps: usize) -> ProgressBar {
    let bar = progress_bar(maps + 1);
    bar.enable_steady_tick(std::time::Duration::from_millis(200));
    bar
}

const INTEGRATE_HELP: &str = "\
The integral over the sphere of the product of the maps, computed on their Haar trees:
  sum over texels of f_1(p) x f_2(p) x ... x solid_angle(p),
the solid angle folded into the first map. Maps are lat-long (H x 2H, H a power of two; HDR,
OpenEXR or .npy), all of one size; a 1-channel map multiplies every channel of the others.
With --param latlong, no --keep and no --depth the result is exactly that pixel sum (to
rounding); with --keep K each map keeps its K largest detail coefficients (orthonormal
magnitudes, RGB by the root of the sum of squares, ties by index in the H x 2H Mallat array)
plus its face scaling coefficients, and the result is the same sum over the pruned maps.
The sums are accumulated in f64 whatever --compute says.

Examples:
  haarshift sphere integrate light.hdr visibility.npy brdf.exr
  haarshift sphere integrate light.hdr visibility.npy --keep 200,70
  haarshift sphere integrate light.hdr visibility.npy brdf.exr --param cube --resolution 64 --keep 1200 --per-face
  haarshift sphere integrate a.npy b.npy --depth 4 --json result.json --compute f64
  haarshift sphere integrate a.npy b.npy c.npy --method triple --threshold 0.01";

/// Integrate the product of lat-long maps over the sphere, on their Haar coefficients.
#[derive(clap::Args, Debug)]
#[command(after_help = INTEGRATE_HELP)]
pub struct IntegrateArgs {
    #[command(flatten)]
    pub maps: MapFlags,

    /// Visit detail levels 0..=D only (0 the coarsest; faces of side S have levels
    /// 0..=log2(S)-1), as the sphere commands' --level [default: all]
    #[arg(long, value_name = "D")]
    pub depth: Option<usize>,

    /// `tree`: the N-function tree traversal. `triple`: the three-function fast path (3 maps).
    /// `pixel`: inverse transforms, then the pixel sum. `pairwise`: products of two
    /// functions at a time ("recursive Haar")
    #[arg(long, default_value = "tree", value_parser = choice::<IntegralMethod>(names!(IntegralMethod)))]
    pub method: IntegralMethod,

    /// Also write the results as JSON records (channel, integral, kept, visited, seconds,
    /// method)
    #[arg(long, value_name = "FILE")]
    pub json: Option<PathBuf>,

    /// Replace the JSON file if it exists
    #[arg(long)]
    pub force: bool,
}

/// One line of `--json`.
#[derive(serde::Serialize)]
struct IntegralRecord {
    channel: usize,
    integral: f64,
    kept: Vec<usize>,
    visited: usize,
    seconds: f64,
    method: IntegralMethod,
    param: ParamKind,
    compute: &'static str,
}

fn integrate(args: IntegrateArgs) -> Result<()> {
    if let Some(json) = &args.json {
        let maps: Vec<&Path> = args.maps.maps.iter().map(PathBuf::as_path).collect();
        refuse_outputs(&maps, &[json], args.force)?;
    }
    match args.maps.compute()? {
        Compute::F32 => integrate_as::<f32>(&args),
        Compute::F64 => integrate_as::<f64>(&args),
    }
}

fn integrate_as<T: Sample>(args: &IntegrateArgs) -> Result<()> {
    let flags = &args.maps;
    let bar = map_progress(flags.maps.len());
    let maps = flags.read::<T>(&bar)?;
    let options = IntegrateOptions {
        param: flags.param,
        resolution: flags.resolution,
        selections: flags.selections()?,
        depth: args.depth,
        method: args.method,
    };
    bar.set_message("integrating");
    let result = haarshift::faces::integrate::integrate(&maps, &options);
    bar.finish_and_clear();
    let result = result?;
    let kept: Vec<String> = result.kept.iter().map(|k| k.to_string()).collect();
    let mut text = String::new();
    for (channel, value) in result.value.iter().enumerate() {
        text += &format!("channel {channel}: integral {value:.17e}\n");
    }
    text += &format!(
        "kept {} detail coefficients per map, visited {}, {:.6} s ({} method, {} param, {})\n",
        kept.join(","),
        result.visited,
        result.seconds,
        args.method,
        flags.param,
        T::NAME
    );
    if let Some(json) = &args.json {
        let records: Vec<IntegralRecord> = result
            .value
            .iter()
            .enumerate()
            .map(|(channel, &integral)| IntegralRecord {
                channel,
                integral,
                kept: result.kept.clone(),
                visited: result.visited,
                seconds: result.seconds,
                method: args.method,
                param: flags.param,
                compute: T::NAME,
            })
            .collect();
        haarshift_experiments::output::write_json(json, &records, args.force)?;
    }
    print(&text)
}

const PRODUCT_HELP: &str = "\
The product of the maps, f_1(p) x f_2(p) x ..., computed on their Haar trees (the tree
product, not pixel by pixel): with everything kept it equals the pixelwise product to
rounding; with --keep K each map keeps its K largest detail coefficients (the rule of
`sphere integrate`, no solid angle: a product is a map, not an integral) and the result is
the product of the pruned maps. Maps are lat-long (H x 2H, H a power of two; HDR, OpenEXR or
.npy), all of one size; a 1-channel map multiplies every channel of the others.

Output: with --param latlong the H x 2H product map; with --param cube its six S x S faces
stacked from the top in the order +X, -X, +Y, -Y, +Z, -Z (S wide, 6 S high), as .exr, .hdr or
.npy. With --coefficients, a .npy array (faces, S, S, C) of the product's Haar coefficients:
per face the full-depth orthonormal Mallat pyramid ([f, 0, 0, c] the pixel sum over S; the
H, V, D details of level l at (r, 2^l + c), (2^l + r, c), (2^l + r, 2^l + c)); faces are the
map's halves (phi in [0, pi), then [pi, 2 pi)) or the cube's faces in the order above.

Examples:
  haarshift sphere product light.hdr visibility.npy -o lit.exr
  haarshift sphere product light.hdr brdf.exr --keep 200 -o approx.npy
  haarshift sphere product light.hdr visibility.npy --param cube --resolution 64 -o cube.exr
  haarshift sphere product light.hdr visibility.npy --coefficients -o product-coeffs.npy";

/// Multiply lat-long maps through their Haar trees; write the product map or its coefficients.
#[derive(clap::Args, Debug)]
#[command(after_help = PRODUCT_HELP)]
pub struct ProductArgs {
    #[command(flatten)]
    pub maps: MapFlags,

    /// Where to write the product (.exr, .hdr or .npy), or with --coefficients its Haar
    /// coefficients (.npy)
    #[arg(short, long, value_name = "OUTPUT")]
    pub output: PathBuf,

    /// Write the product's Haar coefficients (.npy, (faces, S, S, C), orthonormal) instead of
    /// its pixels
    #[arg(long)]
    pub coefficients: bool,

    /// Replace the output if it exists
    #[arg(long)]
    pub force: bool,
}

fn product(args: ProductArgs) -> Result<()> {
    let output = ImageOutput {
        output: args.output.clone(),
        force: args.force,
    };
    let inputs: Vec<&Path> = args.maps.maps.iter().map(|p| p.as_path()).collect();
    output.refuse_overwriting(&inputs)?;
    let format = FileFormat::from_extension(&args.output);
    let allowed: &[FileFormat] = if args.coefficients {
        &[FileFormat::Npy]
    } else {
        &[FileFormat::Exr, FileFormat::Hdr, FileFormat::Npy]
    };
    if !format.is_some_and(|f| allowed.contains(&f)) {
        return Err(haarshift_relight::Error::from(haarshift::Error::Format {
            path: args.output.clone(),
            reason: if args.coefficients {
                "coefficients are written as .npy".into()
            } else {
                "a product map is written as .exr, .hdr or .npy".into()
            },
        }));
    }
    match args.maps.compute()? {
        Compute::F32 => product_as::<f32>(&args, &output, SampleDepth::F32),
        Compute::F64 => product_as::<f64>(&args, &output, SampleDepth::F64),
    }
}

/// The product in `T`, written at `depth`.
fn product_as<T: Sample>(
    args: &ProductArgs,
    output: &ImageOutput,
    depth: SampleDepth,
) -> Result<()> {
    let flags = &args.maps;
    let bar = map_progress(flags.maps.len());
    let maps = flags.read::<T>(&bar)?;
    let options = ProductOptions {
        param: flags.param,
        resolution: flags.resolution,
        selections: flags.selections()?,
    };
    bar.set_message("multiplying");
    let result = map_product(&maps, &options);
    bar.finish_and_clear();
    let result = result?;
    let kept: Vec<String> = result.kept.iter().map(|k| k.to_string()).collect();
    let what = format!(
        ", the product of {} maps ({} param, kept {} detail coefficients per map, {} tree nodes, \
         {:.6} s, {})",
        flags.maps.len(),
        flags.param,
        kept.join(","),
        result.nodes,
        result.seconds,
        T::NAME
    );
    if args.coefficients {
        let c = &result.coefficients;
        haarshift::io::write_npy(c.view(), depth, &args.output, args.force)?;
        let (f, s, _, ch) = c.dim();
        print(&format!(
            "{}: ({f}, {s}, {s}, {ch}) {} Haar coefficients{what}\n",
            args.output.display(),
            T::NAME
        ))
    } else {
        output.write(&result.map.to_image(depth)?, Some(depth), &what)
    }
}
