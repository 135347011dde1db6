//! One module per command; flags shared by several commands are defined here.

use std::io::Write;
use std::path::{Path, PathBuf};

use clap::builder::{PossibleValuesParser, TypedValueParser};
use haarshift::io::TransformRequest;
use haarshift::transform::{Layout, Levels, Normalization};
use haarshift::{BoundaryMode, Error, Result};

pub mod experiment;
pub mod info;
pub mod inverse;
mod method;
pub mod rotate;
pub mod shift;
pub mod sphere;
pub mod transform;

/// A clap parser accepting exactly `names` and parsing them with the library's `FromStr`, so
/// that `--help` lists the choices and the library stays the one place that defines them.
fn choice<T>(names: impl Iterator<Item = &'static str>) -> impl TypedValueParser<Value = T>
where
    T: std::str::FromStr<Err = Error> + Clone + Send + Sync + 'static,
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
    /// seeds' convention). `orthonormal`: 1/sqrt(2) per axis step, energy preserving
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
        inputs
            .iter()
            .try_for_each(|input| refuse_overwriting_input(input, &[&self.output]))?;
        refuse_existing(&[&self.output], self.force)
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

/// Writes `text` to standard output; a closed pipe (`haarshift info x | head -1`) is not an
/// error.
pub fn print(text: &str) -> Result<()> {
    match std::io::stdout().lock().write_all(text.as_bytes()) {
        Err(e) if e.kind() != std::io::ErrorKind::BrokenPipe => Err(Error::Io {
            path: PathBuf::from("<stdout>"),
            source: e,
        }),
        _ => Ok(()),
    }
}

/// Refuses, before any work, the first of `outputs` that exists unless `force`: the write
/// itself would refuse it too, but only after the computation.
pub fn refuse_existing(outputs: &[&Path], force: bool) -> Result<()> {
    match outputs.iter().find(|p| !force && p.exists()) {
        Some(path) => Err(Error::OutputExists {
            path: path.to_path_buf(),
        }),
        None => Ok(()),
    }
}

/// Refuses `output` (and each of `others`, e.g. a sidecar) when it is the file `input`.
pub fn refuse_overwriting_input(input: &Path, outputs: &[&Path]) -> Result<()> {
    outputs
        .iter()
        .try_for_each(|out| haarshift::io::ensure_distinct_paths(input, out))
}
