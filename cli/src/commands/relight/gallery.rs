//! `haarshift relight gallery`: the committed diffuse renders, regenerated.

use std::path::PathBuf;

use haarshift_experiments::gallery::{GalleryOptions, gallery};
use haarshift_relight::Result;

use crate::commands::print;

const HELP: &str = "\
The mesh on its ground plane under every environment map of --env-dir (*.hdr, *.exr, *.npy,
in name order), precomputed once at lat-long N x 2N (every coefficient kept, spherical
harmonics of B bands beside it). For each map, NAME.png holds three renders at one exposure:
Haar with the lighting's K largest detail coefficients | spherical harmonics | the reference
(direct quadrature, no Haar transform); errors.md has each method's error against the
reference relative to the scene's RMS radiance, with this command at its top; turntable.gif
turns the first map about +Y. Every output is checked before any work.

Examples:
  haarshift relight gallery testdata/meshes/bunny.ply --env-dir ../shared/envmaps --out-dir results/relight/diffuse --force
  haarshift relight gallery bunny.ply --env-dir maps --out-dir out --resolution 32 --keep-light 100 --frames 12";

/// Regenerate the gallery of diffuse renders (Haar | SH | reference per environment map).
#[derive(clap::Args, Debug)]
#[command(after_help = HELP)]
pub struct Args {
    /// The mesh (.obj or .ply); the ground plane is added
    #[arg(value_name = "MESH")]
    pub mesh: PathBuf,

    /// Directory of lat-long environment maps
    #[arg(long, value_name = "DIR")]
    pub env_dir: PathBuf,

    /// Where to write the images, errors.md and turntable.gif
    #[arg(long, value_name = "DIR")]
    pub out_dir: PathBuf,

    /// Lat-long height N of the precomputation and the reference (N x 2N texels)
    #[arg(long, value_name = "N", default_value_t = 64)]
    pub resolution: usize,

    /// Detail coefficients of the lighting the Haar renders keep
    #[arg(long, value_name = "K", default_value_t = 200)]
    pub keep_light: usize,

    /// Bands of the spherical-harmonic renders (B^2 coefficients)
    #[arg(long, value_name = "B", default_value_t = 9)]
    pub sh_bands: usize,

    /// Frames of the turntable
    #[arg(long, value_name = "F", default_value_t = 24)]
    pub frames: usize,

    /// Replace the outputs if they exist
    #[arg(long)]
    pub force: bool,
}

pub fn run(args: Args) -> Result<()> {
    let command = std::iter::once("haarshift".to_string())
        .chain(std::env::args().skip(1))
        .collect::<Vec<_>>()
        .join(" ");
    let options = GalleryOptions {
        resolution: args.resolution,
        keep_light: args.keep_light,
        sh_bands: args.sh_bands,
        frames: args.frames,
        force: args.force,
        command,
        ..GalleryOptions::default()
    };
    let rows = gallery(&args.mesh, &args.env_dir, &args.out_dir, &options)?;
    let mut text = format!(
        "{}: {} maps; errors relative to the scene's RMS radiance (Haar all, Haar {}, SH {} bands):\n",
        args.out_dir.display(),
        rows.len(),
        args.keep_light,
        args.sh_bands
    );
    for row in rows {
        text += &format!(
            "  {}: {:.2e} {:.2e} {:.2e}\n",
            row.name, row.haar_all, row.haar_kept, row.sh
        );
    }
    print(&text)
}
