//! One module per command; flags shared by several commands are defined here.

use std::io::Write;
use std::path::{Path, PathBuf};

use clap::builder::{PossibleValuesParser, TypedValueParser};
use haarshift::BoundaryMode;
use haarshift::io::TransformRequest;
use haarshift::transform::{Layout, Levels, Normalization};
use haarshift_relight::Result;

pub mod experiment;
pub mod info;
pub mod inverse;
mod method;
pub mod relight;
pub mod rotate;
pub mod shift;
pub mod sphere;
pub mod transform;

/// A clap parser accepting exactly `names` and parsing them with the library's `FromStr`, so
/// that `--help` lists the choices and the library stays the one place that defines them.
fn choice<T>(names: impl Iterator<Item = &'static str>) -> impl TypedValueParser<Value = T>
where
    T: std::str::FromStr<Err = haarshift::Error> + Clone + Send + Sync + 'static,
{
    PossibleValuesParser::new(names.collect::<Vec<_>>()).try_map(|s| s.parse::<T>())
}

/// The names of a `named_enum!` type, in declaration order.
macro_rules! names {
    ($t:ty) => {
        <$t>::ALL.iter().map(|v| v.name())
    };
}
pub(crate) use names;

/// The transform parameters, shared by `transform` and `inverse`.
#[derive(clap::Args, Debug)]
pub struct TransformFlags {
    /// Transform steps: a whole number K (a partial transform leaving (H >> K) x (W >> K)
    /// scaling coefficients) or `full` (as many as the padded size allows) [default: full]
    #[arg(long, value_name = "K|full", value_parser = clap::value_parser!(Levels))]
    pub levels: Option<Levels>,

    /// `pyramid`: non-separable 2D Haar (each level splits 2x2 blocks into the average A and
    /// details a, b, c; Mallat layout). `separable`: a full 1D transform along rows, then
    /// along columns [default: pyramid]
    #[arg(long, value_parser = choice::<Layout>(names!(Layout)))]
    pub layout: Option<Layout>,

    /// `average`: parent = mean of children, detail = (first - second) / 2 per axis (the
    /// sources' convention). `orthonormal`: 1/sqrt(2) per axis step, energy preserving
    /// [default: average]
    #[arg(long, value_parser = choice::<Normalization>(names!(Normalization)))]
    pub norm: Option<Normalization>,

    /// How an image whose sides are not powers of two is extended (at the bottom and right)
    /// before the transform; the inverse crops it off again. `zero`: zeros; `edge`: the last
    /// row/column repeated; `reflect`: mirrored (d c b a | a b c d | d c b a); `wrap`:
    /// periodic [default: zero]
    #[arg(long, value_parser = choice::<BoundaryMode>(names!(BoundaryMode)))]
    pub pad: Option<BoundaryMode>,
}

impl TransformFlags {
    /// The parameters as given (unset ones left open).
    pub fn request(&self) -> TransformRequest {
        TransformRequest {
            layout: self.layout,
            normalization: self.norm,
            levels: self.levels,
            padding: self.pad,
        }
    }
}

/// The float type a command computes in.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum Compute {
    /// Single precision: exact for 8- and 16-bit, f16 and f32 data, and twice as light.
    F32,
    /// Double precision.
    F64,
}

/// `--compute`, shared by the commands that read an image and compute on it.
#[derive(clap::Args, Debug)]
pub struct ComputeFlag {
    /// Float type to compute in: `f32` or `f64` [default: f64 for a float64 .npy input, f32
    /// otherwise (8- and 16-bit, f16 and f32 data, which f32 holds exactly)]
    #[arg(long, value_enum, value_name = "TYPE")]
    pub compute: Option<Compute>,
}

impl ComputeFlag {
    /// The float type given, or the one `input`'s samples need (read from its header).
    pub fn resolve(&self, input: &Path) -> Result<Compute> {
        match self.compute {
            Some(compute) => Ok(compute),
            None if haarshift::io::holds_f64(input)? => Ok(Compute::F64),
            None => Ok(Compute::F32),
        }
    }
}

/// Where a command that makes one image writes it.
#[derive(clap::Args, Debug)]
pub struct ImageOutput {
    /// Image to write; the format follows the extension: .png, .jpg, .tif, .exr, .hdr, .npy
    #[arg(short, long, value_name = "OUTPUT")]
    pub output: PathBuf,

    /// Replace the output if it exists
    #[arg(long)]
    pub force: bool,
}

impl ImageOutput {
    /// Refuses, before any work, an output that is the file `input` (or any of `inputs`),
    /// and an existing output without `--force`.
    pub fn refuse_overwriting(&self, inputs: &[&Path]) -> Result<()> {
        refuse_outputs(inputs, &[&self.output], self.force)
    }

    /// Writes `image` (atomically; replaced only with `--force`; stored at `depth` when given)
    /// and prints `OUTPUT: W x H CHANNELS image` followed by `what` (", rotated by ...").
    pub fn write<T: haarshift::Sample>(
        &self,
        image: &haarshift::PlanarImage<T>,
        depth: Option<haarshift::SampleDepth>,
        what: &str,
    ) -> Result<()> {
        let options = haarshift::io::WriteOptions {
            force: self.force,
            depth,
            ..Default::default()
        };
        haarshift::io::write_image(image, &self.output, options)?;
        print(&format!(
            "{}: {} x {} {} image{what}\n",
            self.output.display(),
            image.width(),
            image.height(),
            image.channels()
        ))
    }
}

/// A number as people read it, for echoing parameters: at most six significant digits, plain
/// from 1e-4 up to 1e6 and in scientific notation outside (`30`, `-12.5`, `0.333333`,
/// `1e308`, `2.5e-7`).
pub fn number(x: f64) -> String {
    if x == 0.0 || !x.is_finite() {
        // -0 is the same angle or shift as 0.
        return format!("{}", x + 0.0);
    }
    let trim = |s: &str| {
        if s.contains('.') {
            s.trim_end_matches('0').trim_end_matches('.').to_string()
        } else {
            s.to_string()
        }
    };
    let exponent = x.abs().log10().floor() as i32;
    if (-4..6).contains(&exponent) {
        let decimals = (5 - exponent).max(0) as usize;
        trim(&format!("{x:.decimals$}"))
    } else {
        let scientific = format!("{x:.5e}");
        let (mantissa, exponent) = scientific.split_once('e').expect("{:e} has an exponent");
        format!("{}e{exponent}", trim(mantissa))
    }
}

/// Writes `text` to standard output; a closed pipe (`haarshift info x | head -1`) is not an
/// error.
pub fn print(text: &str) -> Result<()> {
    match std::io::stdout().lock().write_all(text.as_bytes()) {
        Err(e) if e.kind() != std::io::ErrorKind::BrokenPipe => {
            Err(haarshift_relight::Error::from(haarshift::Error::Io {
                path: PathBuf::from("<stdout>"),
                source: e,
            }))
        }
        _ => Ok(()),
    }
}

/// Refuses, before any work, an output that is one of `inputs` (the same file by any path),
/// and the first of `outputs` that exists unless `force`: the write itself would refuse it
/// too, but only after the computation. Every command checks its outputs here.
pub fn refuse_outputs(inputs: &[&Path], outputs: &[&Path], force: bool) -> Result<()> {
    for input in inputs {
        for output in outputs {
            haarshift::io::ensure_distinct_paths(input, output)?;
        }
    }
    match outputs.iter().find(|p| !force && p.exists()) {
        Some(path) => Err(haarshift_relight::Error::from(
            haarshift::Error::OutputExists {
                path: path.to_path_buf(),
            },
        )),
        None => Ok(()),
    }
}
