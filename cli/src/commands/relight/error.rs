//! `haarshift relight error`: how far renders are from a reference, in the relighting error
//! measure (`metrics::RelativeError`).

use std::path::{Path, PathBuf};

use haarshift::io::read_image;
use haarshift::metrics::RelativeError;
use haarshift_relight::Result;
use ndarray::Array2;

use crate::commands::print;

const HELP: &str = "\
For each RENDER, one line: the RMS over every vertex and channel of (render - reference)
divided by the RMS of the reference, then the largest absolute difference over the same
RMS. Relative to the scene's RMS radiance, never per vertex (a shadowed vertex's radiance is
near 0). The files are the (V, 3) .npy arrays that --vertices writes (or images of one size,
compared over every sample).

Examples:
  haarshift relight reference bunny.ply --ground-plane --env park.hdr --vertices truth.npy
  haarshift relight render bunny.hsr --env park.hdr --vertices haar.npy --keep 64
  haarshift relight error truth.npy haar.npy";

/// The error of renders against a reference, relative to the reference's RMS.
#[derive(clap::Args, Debug)]
#[command(after_help = HELP)]
pub struct Args {
    /// The reference: per-vertex radiance (.npy) or an image
    #[arg(value_name = "REFERENCE")]
    pub reference: PathBuf,

    /// The renders to compare with it, each of the reference's shape
    #[arg(value_name = "RENDER", required = true)]
    pub renders: Vec<PathBuf>,
}

pub fn run(args: Args) -> Result<()> {
    let reference = samples(&args.reference)?;
    for path in &args.renders {
        let render = samples(path)?;
        if render.dim() != reference.dim() {
            return Err(haarshift_relight::Error::from(haarshift::Error::Format {
                path: path.clone(),
                reason: format!(
                    "{:?} samples, the reference {} has {:?}",
                    render.dim(),
                    args.reference.display(),
                    reference.dim()
                ),
            }));
        }
        let e = RelativeError::between(render.view(), reference.view())
            .map_err(|e| e.in_file(&args.reference))?;
        print(&format!(
            "{}: relative RMS {}, largest {}\n",
            path.display(),
            scientific(e.rms_relative),
            scientific(e.max_relative)
        ))?;
    }
    Ok(())
}

/// Every sample of a file as rows of one plane's width: (planes x height, width).
fn samples(path: &Path) -> Result<Array2<f64>> {
    let (planes, _, _) = read_image::<f64>(path)?.into_parts();
    let (c, h, w) = planes.dim();
    Ok(Array2::from_shape_fn((c * h, w), |(row, x)| {
        planes[[row / h, row % h, x]]
    }))
}

/// `x` as C's and numpy's `%.2e` write it (`8.98e-04`): the form the tables in `results/` use.
fn scientific(x: f64) -> String {
    let text = format!("{x:.2e}");
    match text.split_once('e') {
        Some((mantissa, exponent)) => match exponent.strip_prefix('-') {
            Some(digits) => format!("{mantissa}e-{digits:0>2}"),
            None => format!("{mantissa}e+{exponent:0>2}"),
        },
        None => text,
    }
}
