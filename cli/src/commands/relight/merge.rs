//! `haarshift relight merge`: the shards of a precomputation joined into its cache.

use std::path::PathBuf;
use std::time::Instant;

use haarshift_relight::Result;
use haarshift_relight::merge_shards;

use super::flags::bytes;
use crate::commands::{print, refuse_outputs};

const HELP: &str = "\
The shards must come from the same scene and options (mesh, albedo, the scene file's
environment and camera, every precomputation option) and cover every vertex exactly once,
in any order and from any number of shards each; a missing or doubly covered vertex range,
a shard of another scene or options, and a damaged or truncated shard are refused, naming
the file. The cache written is the one an unsharded `relight precompute` writes, byte for
byte.

Examples:
  haarshift relight merge part-*.hsr -o scene.hsr
  haarshift relight merge part-0.hsr part-1.hsr part-2.hsr -o scene.hsr --force";

/// Merge the shards of `relight precompute --shard` into one scene cache.
#[derive(clap::Args, Debug)]
#[command(after_help = HELP)]
pub struct Args {
    /// The shards (.hsr), in any order
    #[arg(value_name = "PART.hsr", required = true)]
    pub shards: Vec<PathBuf>,

    /// The cache to write (.hsr)
    #[arg(short, long, value_name = "SCENE.hsr")]
    pub output: PathBuf,

    /// Replace the output if it exists
    #[arg(long)]
    pub force: bool,
}

pub fn run(args: Args) -> Result<()> {
    let inputs: Vec<_> = args.shards.iter().map(PathBuf::as_path).collect();
    refuse_outputs(&inputs, &[&args.output], args.force)?;
    let start = Instant::now();
    let cache = merge_shards(&args.shards)?;
    let file_bytes = cache.write(&args.output, args.force)?;
    print(&format!(
        "{}: {} shards merged, {} vertices, {} coefficients, file {}, {:.3} s\n",
        args.output.display(),
        args.shards.len(),
        cache.mesh.vertex_count(),
        cache.transport.coefficient_count(),
        bytes(file_bytes),
        start.elapsed().as_secs_f64(),
    ))
}
