//! `haarshift relight precompute`: a scene's visibility and transport, into a cache file.

use std::path::PathBuf;

use haarshift::faces::ParamKind;
use haarshift::memory::peak_resident_bytes;
use haarshift_relight::RayTracer;
use haarshift_relight::Result;
use haarshift_relight::precompute::refine::{MIN_EDGE_OFFSETS, RefineReport};
use haarshift_relight::precompute::request::{
    DEFAULT_RESOLUTION, Outcome, PrecomputeRequest, SceneInput,
};
use haarshift_relight::precompute::{DEFAULT_MAP_SIZE, Order};

use super::flags::{SceneFlags, ShardFlags, bytes};
use crate::commands::{choice, names, print};

const HELP: &str = "\
For every vertex, the visibility over the sphere at the texel centres of the chosen
parameterisation (lat-long N x 2N, or cube 6 x N x N), times max(0, n . w) and the texel's
solid angle, Haar-transformed (orthonormal, face by face) and truncated to the K largest
detail coefficients (plus each face's scaling coefficient); rays start 1e-4 x the scene's
bounding-box diagonal off the surface along the normal, and a ray that hits any triangle is
blocked. Rays are traced by Intel Embree 3 where the system's libembree3.so.3 loads (Debian
and Ubuntu: apt-get install libembree3-3; $HAARSHIFT_EMBREE names another file), else by
haarshift's own packet tracer (--ray-tracer chooses; the output and the cache name the one
that cast, and `relight merge` joins only shards cast by one). The cache (.hsr) holds the
mesh, the albedo, the transport, the parameters, and the scene file's environment and
camera; `relight render` reads it.

The input is a mesh (.obj or .ply; degenerate triangles and open or non-manifold meshes
work) or a scene file (.json, see the library's relight::scene docs).

Memory: the mesh, its BVH and the transport at the most coefficients --keep-visibility lets a
vertex keep (every texel's without it) are counted before anything is built, a scene file's
generators from their settings; a run that would need more than --memory-limit is refused.

Examples:
  haarshift relight precompute testdata/meshes/bunny.ply --ground-plane -o bunny.hsr
  haarshift relight precompute bunny.ply --ground-plane --param cube --resolution 32 -o bunny.hsr
  haarshift relight precompute bunny.ply --ground-plane --resolution 64 --sh-bands 9 -o bunny.hsr
  haarshift relight precompute testdata/scenes/cubes.json --param cube --resolution 64 -o cubes.hsr
  haarshift relight precompute scene.json --order direction --map-size 2048 -o scene.hsr
  haarshift relight precompute bunny.ply --ray-tracer packets -o bunny.hsr   # not Embree
  haarshift relight precompute testdata/scenes/bunny_in_box.json --bounces 2 -o box.hsr

With --bounces B, B bounces of interreflected light (Lambertian) are gathered over the same
rays: each ray that hits the front of a triangle brings the bounce-before transport of the
hit point (interpolated over the triangle's corners) times its albedo / pi; the sum of the B
bounces is stored beside the direct transport (one set when every albedo is grey, else R, G,
B), and `relight render` shows it unless given --direct-only. The albedo is baked in, so a
render of such a cache refuses --albedo and glossy BRDFs.

Refined where the light needs it (--refine TOL): after the precomputation, every edge whose
endpoints' transports differ (L2) by more than TOL times the most an endpoint could receive
(its transport with nothing in the way; TOL in (0, 2]) is split, with its
neighbours across longer edges (conforming longest-edge bisection: no T-junctions), the new
vertices precomputed, and so on until every edge is within TOL or the next vertex would pass
--max-vertices (default 4 x the scene's; then one line says how many edges are left); edges
shorter than 16 ray offsets are left as they are. New
vertices come after the objects' and after the ground's own, so the ground stays the last
block; the cache equals a precomputation of the refined mesh. Vertex order only, one ray per
texel, not with --shard; refine first, then bounce. With --refine-light ENV the edges are
judged by their radiance under that map instead (the same ratio, of <T, L> over <U, L>): the
sun's shadow, one texel of the transport, is most of the radiance. results/relight/refine.md
measures both:
  haarshift relight precompute bunny.ply --ground-plane --param cube --refine 0.2 --max-vertices 5000 -o bunny.hsr
  haarshift relight precompute bunny.ply --ground-plane --param cube --refine 0.2 --refine-light sky.hdr -o bunny.hsr

Sharded across machines (vertex order only): shard I of N computes the vertices
[I x V / N, (I + 1) x V / N) against the whole scene, with the bits an unsharded run gives
them; `relight merge` joins the shards into the cache an unsharded run writes, byte for byte.
A shard whose output exists and is complete (same scene, options and shard) is skipped, so a
rerun after a preemption does only what is missing. `--shard auto` reads the shard from a
Slurm array job (SLURM_ARRAY_TASK_ID, _MIN, _STEP, _COUNT; arrays with gaps are refused) or a
Kubernetes Indexed Job (JOB_COMPLETION_INDEX, with the Job's completions as --shards N):
  haarshift relight precompute scene.json --shard 2/8 -o part-2.hsr
  haarshift relight precompute scene.json --shard auto -o part-$SLURM_ARRAY_TASK_ID.hsr
  haarshift relight precompute scene.json --shard auto --shards 8 -o part-$JOB_COMPLETION_INDEX.hsr

Bounces, sharded: bounce b + 1 of a vertex needs bounce b of every vertex, so shards go bounce
by bounce with a merge between (in Slurm, one array job per bounce, each after the last's
merge). The last merge is the cache an unsharded --bounces run writes, byte for byte:
  haarshift relight precompute scene.json --shard 2/8 -o d-2.hsr            # then merge: b0.hsr
  haarshift relight precompute scene.json --shard 2/8 --bounces 1 --bounce-from b0.hsr -o b1-2.hsr
  haarshift relight merge b1-*.hsr -o b1.hsr                                # and so on to B";

/// Precompute a scene's per-vertex visibility and transport into a cache file.
#[derive(clap::Args, Debug)]
#[command(after_help = HELP)]
pub struct Args {
    #[command(flatten)]
    pub scene: SceneFlags,

    /// The cache to write (.hsr)
    #[arg(short, long, value_name = "SCENE.hsr")]
    pub output: PathBuf,

    /// `latlong`: N x 2N texels (two N x N faces). `cube`: six N x N faces
    #[arg(long, default_value = "latlong", value_parser = choice::<ParamKind>(names!(ParamKind)))]
    pub param: ParamKind,

    /// Face side N, a power of two
    #[arg(long, value_name = "N", default_value_t = DEFAULT_RESOLUTION)]
    pub resolution: usize,

    /// Detail coefficients kept per vertex (the largest, orthonormal) [default: all]
    #[arg(long, value_name = "K")]
    pub keep_visibility: Option<usize>,

    /// S x S stratified rays per texel (1: one ray through the texel centre)
    #[arg(long, value_name = "S", default_value_t = 1)]
    pub visibility_samples: usize,

    /// Seed of the stratified jitter (with --visibility-samples above 1)
    #[arg(long, default_value_t = 0)]
    pub seed: u64,

    /// `vertex`: vertices outer, rays through a BVH. `direction`: directions outer, a shadow
    /// buffer per direction (Microsoft 2003), texel centres only
    #[arg(long, default_value = "vertex", value_parser = choice::<Order>(names!(Order)))]
    pub order: Order,

    /// The ray tracer of --order vertex: `embree` (Intel Embree 3's packets, where the
    /// system's libembree3.so.3 loads: the default there) or `packets` (haarshift's own,
    /// always available; its answers specified to the bit). Both answer alike except on rays
    /// through a triangle's edge. This machine's default is printed below the flags
    #[arg(long, value_parser = choice::<RayTracer>(names!(RayTracer)))]
    pub ray_tracer: Option<RayTracer>,

    /// Shadow-buffer side for --order direction
    #[arg(long, value_name = "M", default_value_t = DEFAULT_MAP_SIZE)]
    pub map_size: usize,

    /// Also store each vertex's transport projected onto B bands of real spherical harmonics
    /// (degrees 0 to B - 1, B^2 coefficients), for `relight render --basis sh`
    #[arg(long, value_name = "B")]
    pub sh_bands: Option<usize>,

    /// Also gather B bounces of interreflected light (0 to 8; Lambertian scenes, --order
    /// vertex) over the same rays, stored beside the direct transport
    #[arg(long, value_name = "B", default_value_t = 0)]
    pub bounces: usize,

    /// With --shard: add one bounce (--bounces B, B - 1 the merged cache's) to the shard's
    /// vertices, gathered from the merged cache of every vertex's B - 1 bounces
    #[arg(long, value_name = "MERGED.hsr", requires = "shard")]
    pub bounce_from: Option<PathBuf>,

    /// Split edges whose endpoints' transports differ by more than TOL (in (0, 2]) times the
    /// most an endpoint could receive, precompute the new vertices, and repeat until none does
    #[arg(long, value_name = "TOL")]
    pub refine: Option<f64>,

    /// With --refine: the most vertices the refined mesh may have [default: 4 x the scene's]
    #[arg(long, value_name = "N", requires = "refine")]
    pub max_vertices: Option<usize>,

    /// With --refine: judge edges by their radiance under this environment map (unrotated)
    /// instead of by their transport
    #[arg(long, value_name = "ENV", requires = "refine")]
    pub refine_light: Option<PathBuf>,

    #[command(flatten)]
    pub shard: ShardFlags,

    /// Replace the output if it exists (a shard: even a complete one)
    #[arg(long)]
    pub force: bool,
}

/// `relight precompute --help`'s line on the tracer this machine would use and why. Finding
/// out loads Embree, so it is asked only when help is shown.
pub fn tracer_help() -> String {
    format!("Ray tracer on this machine: {}", RayTracer::choice())
}

/// The request these flags make: the library checks and runs it.
fn request(args: Args) -> PrecomputeRequest {
    PrecomputeRequest {
        ground_plane: args.scene.ground_plane,
        ground_cells: args.scene.ground_cells,
        memory_limit: args.scene.memory_limit,
        output: Some(args.output),
        param: args.param,
        resolution: args.resolution,
        keep_visibility: args.keep_visibility,
        visibility_samples: args.visibility_samples,
        seed: args.seed,
        order: args.order,
        ray_tracer: args.ray_tracer,
        map_size: args.map_size,
        sh_bands: args.sh_bands,
        bounces: args.bounces,
        bounce_from: args.bounce_from,
        refine: args.refine,
        max_vertices: args.max_vertices,
        refine_light: args.refine_light,
        shard: args.shard.shard,
        shards: args.shard.shards,
        force: args.force,
        progress: true,
        ..PrecomputeRequest::new(SceneInput::File(args.scene.input))
    }
}

pub fn run(args: Args) -> Result<()> {
    let (output, tolerance) = (args.output.clone(), args.refine);
    let run = request(args).run()?;
    for warning in &run.warnings {
        eprintln!("haarshift: warning: {warning}");
    }
    let (vertices, triangles, what, transport, file_bytes, report) = match &run.outcome {
        Outcome::Skipped { shard, vertices } => {
            return print(&format!(
                "{}: shard {shard} (vertices {}..{}) is complete: skipped\n",
                output.display(),
                vertices.start,
                vertices.end
            ));
        }
        Outcome::Whole {
            cache,
            report,
            refined,
            file_bytes,
        } => {
            if let (Some(r), Some(tolerance)) = (refined, tolerance) {
                print(&refine_line(r, tolerance))?;
            }
            let what = cache.bounced.as_ref().map_or(String::new(), |b| {
                format!(
                    " (and {} bounces: {} sets, {} coefficients, {:.3} s)",
                    b.bounces(),
                    b.channels().len(),
                    b.coefficient_count(),
                    report.bounce_seconds
                )
            });
            let mesh = &cache.mesh;
            (
                mesh.vertex_count(),
                mesh.triangles().len(),
                what,
                &cache.transport,
                file_bytes.unwrap_or(0),
                report,
            )
        }
        Outcome::Shard {
            shard,
            vertices,
            part,
            report,
            file_bytes,
        } => {
            let what = format!(
                " (shard {shard}: vertices {}..{})",
                vertices.start, vertices.end
            );
            let mesh = &part.mesh;
            (
                mesh.vertex_count(),
                mesh.triangles().len(),
                what,
                &part.transport,
                *file_bytes,
                report,
            )
        }
    };
    let param = run.param;
    let rate = if report.seconds > 0.0 {
        report.rays as f64 / report.seconds
    } else {
        0.0
    };
    print(&format!(
        "{}: {vertices} vertices{what}, {triangles} triangles, {} {} ({} texels), {} order\n\
         rays {}{}, {:.3} s, {:.3} M rays/s, working memory {}\n\
         transport {} ({} coefficients), file {}, peak memory {}\n",
        output.display(),
        param.kind(),
        param.face_size(),
        param.texels(),
        run.order,
        report.rays,
        report.tracer.map_or(String::new(), |t| format!(" ({t})")),
        report.seconds,
        rate / 1e6,
        bytes(report.working_bytes as u64),
        bytes(transport.stored_bytes() as u64),
        transport.coefficient_count(),
        bytes(file_bytes),
        peak_resident_bytes().map_or("unknown".into(), bytes),
    ))
}

/// The one line on what a refinement to `tolerance` did.
fn refine_line(r: &RefineReport, tolerance: f64) -> String {
    let mut end = if r.stopped_by_budget() {
        format!(
            "stopped by --max-vertices {} with {} edges above {tolerance}",
            r.max_vertices, r.above
        )
    } else {
        format!("every edge within {tolerance}")
    };
    if r.short > 0 {
        end += &format!(
            " ({} shorter edges above it left: below {MIN_EDGE_OFFSETS} ray offsets)",
            r.short
        );
    }
    format!(
        "refined {} -> {} vertices ({} of them the ground's) in {} rounds: {end}\n",
        r.original, r.vertices, r.ground_vertices, r.rounds
    )
}
