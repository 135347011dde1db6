//! `haarshift relight scene`: a dynamic scene (objects with occlusion fields) as one frame or
//! an animation.

use std::path::{Path, PathBuf};

use haarshift_relight::Result;
use haarshift_relight::dynamic::Change;
use haarshift_relight::dynamic::request::{FrameLine, PlayOutcome, PlayReport, PlayRequest};
use haarshift_relight::shade::dynamic_scene::DynamicMethod;

use super::flags::{CameraFlags, DynamicFlags, GlossyFlags, LightFlags, ShardFlags, brdf, bytes};
use crate::commands::{choice, names, print};

const HELP: &str = "\
Every object of the scene file gets occlusion fields (Sun 2006): from sample points on 100
circles x 200 points on its ground plane (0.05 r to 10 r) and on 20 shells of 6 x 9 x 9
points around it (0.2 R to 6 R), the visibility of the object over the sphere, one ray per
texel, Haar-transformed and truncated to --keep-field. Each vertex's own transport is
precomputed against its own object and the ground plane. A vertex's radiance is
albedo / pi x the integral of its transport x the lighting x every other object's occlusion
looked up where the vertex is (bilinear on the plane, trilinear between shells; beyond the
outermost shell an object occludes nothing): an n-function product integral on sparse Haar
coefficients. Objects move by translation, uniform scale and whole-column yaw (the scene
file's yaw is rounded to a column of the lat-long map); pitch and roll are refused.

A glossy material (\"brdf\": \"phong\" or \"blinn\" with an \"exponent\", or --brdf for every
object) adds its BRDF, rotated into each vertex's frame toward the camera (--brdf-rotation),
as one more factor: albedo x the integral of transport x lighting x occlusion x BRDF.

--animate PATH.json plays segments that each move one object, turn the lighting or turn the
eye about the camera's look-at point (\"eye_yaw\": glossy vertices are seen from elsewhere; see
the library's relight::dynamic::motion for the file): the fixed factors' product is re-formed when the
kind of change switches, and each frame is one sparse dot product per vertex with the varying
factor (just-in-time radiance transfer). Every frame's times are printed: re-forming, shading,
rasterisation. The output is a looping GIF or numbered PNGs (a pattern with %d).

--fields-dir DIR keeps each shape's fields in DIR (created if absent), one checksummed file
a shape named after its mesh file or generator (bunny.hsf, sphere-cells-3.hsf): a file built
for the same mesh with the same field flags (--param, --resolution, --keep-field, --circles,
--circle-points, --shells, --shell-grid) is loaded instead of casting its rays; an absent one
is built and written. A file that does not match (another mesh, other flags, damaged, another
format version) stops the command with the reason before anything is written; --force builds
it again and replaces it. The run prints the files' size and the time loading took.

--shard I/N (or auto, from a Slurm array or Kubernetes Indexed Job, as for precompute) with
--fields-dir DIR builds only the fields of shapes [I x S / N, (I + 1) x S / N) of the scene's
S distinct shapes (in order of first use) and renders nothing: one machine's share. Each
shape's file is independent, so nothing is merged; a render with the same DIR and field flags
loads them all.

--method reference renders the same frames with visibility ray-cast against every object in
its current placement (the ground truth; no field, no Haar transform).

Examples:
  haarshift relight scene testdata/scenes/table_and_chair.json -o table.png
  haarshift relight scene testdata/scenes/table_and_chair.json --animate testdata/scenes/chair_path.json -o chair.gif
  haarshift relight scene scene.json --resolution 64 --keep-light 200 --keep-visibility 70 --keep-field 70 -o s.png
  haarshift relight scene scene.json --method reference --vertices truth.npy -o truth.png
  haarshift relight scene testdata/scenes/table_and_chair.json --brdf phong:40 -o glossy.png
  haarshift relight scene testdata/scenes/bunny.json --param cube --resolution 64 --keep-field 120 --fields-dir fields -o bunny.png
      (the first run builds fields/bunny.hsf; the same command again loads it)
  haarshift relight scene testdata/scenes/table_and_chair.json --fields-dir fields --shard 1/2
      (builds the chair's fields only: shape 1 of the table and the chair)";

/// Render a dynamic scene of objects shadowing each other through occlusion fields.
#[derive(clap::Args, Debug)]
#[command(after_help = HELP)]
pub struct Args {
    /// The scene file (objects with names, transforms and materials; ground plane; lighting;
    /// camera)
    #[arg(value_name = "SCENE.json")]
    pub scene: PathBuf,

    /// The image (.png, .exr), or with --animate a .gif or numbered .png frames (%d); not
    /// with --shard, which only builds fields
    #[arg(
        short,
        long,
        value_name = "IMAGE",
        required_unless_present = "shard",
        conflicts_with = "shard"
    )]
    pub output: Option<PathBuf>,

    /// Play this path file (segments moving one object or turning the lighting)
    #[arg(long, value_name = "PATH.json", conflicts_with = "shard")]
    pub animate: Option<PathBuf>,

    /// Also write the per-vertex radiance, (V, 3) f32 .npy ((frames, V, 3) with --animate)
    #[arg(long, value_name = "OUT.npy", conflicts_with = "shard")]
    pub vertices: Option<PathBuf>,

    /// How the radiance is computed: `haar` (occlusion fields and Haar product integrals) or
    /// `reference` (ray-cast visibility against the placed scene, direct quadrature)
    #[arg(long, value_name = "METHOD", default_value = "haar",
          value_parser = choice::<DynamicMethod>(names!(DynamicMethod)))]
    pub method: DynamicMethod,

    /// Detail coefficients of the lighting kept [default: all]
    #[arg(long, value_name = "K")]
    pub keep_light: Option<usize>,

    #[command(flatten)]
    pub dynamic: DynamicFlags,

    /// With --fields-dir: build (or find) the fields of this shard's share of the shapes
    /// only, and render nothing
    #[command(flatten)]
    pub shard: ShardFlags,

    /// Time each GIF frame is shown, milliseconds
    #[arg(long, value_name = "MS", default_value_t = 100)]
    pub delay: u32,

    /// Every object's BRDF instead of its material's (its albedo stays; the ground plane stays
    /// Lambertian): lambert, phong:EXP, blinn:EXP, merl:FILE [default: the scene file's]
    #[arg(long, value_name = "BRDF", value_parser = brdf)]
    pub brdf: Option<String>,

    #[command(flatten)]
    pub glossy: GlossyFlags,

    #[command(flatten)]
    pub light: LightFlags,

    #[command(flatten)]
    pub camera: CameraFlags,

    /// Replace the outputs if they exist (and field files that do not match)
    #[arg(long)]
    pub force: bool,

    /// Refused: light that bounces is precomputed for static scenes (`relight precompute
    /// --bounces`); a dynamic scene's objects move, so their interreflections would change
    #[arg(long, value_name = "B", default_value_t = 0)]
    pub bounces: usize,
}

/// The request these flags make: the library checks and runs it.
fn request(args: &Args) -> Result<PlayRequest> {
    Ok(PlayRequest {
        output: args.output.clone(),
        animate: args.animate.clone(),
        vertices: args.vertices.clone(),
        method: args.method,
        keep_light: args.keep_light,
        fields_dir: args.dynamic.fields_dir.clone(),
        shard: args.shard.shard,
        shards: args.shard.shards,
        delay: args.delay,
        brdf: args.brdf.clone(),
        // The BRDF is the scene's first glossy material, set by the run.
        glossy: args.glossy.options(&Default::default()),
        fill_cache: args.glossy.fill_cache,
        light: args.light.spec(),
        light_rotation: args.light.light_rotation,
        view: args.camera.view()?,
        exposure: args.camera.exposure,
        force: args.force,
        bounces: args.bounces,
        ..PlayRequest::new(args.scene.clone(), args.dynamic.options()?)
    })
}

pub fn run(args: Args) -> Result<()> {
    match request(&args)?.run()? {
        PlayOutcome::Fields {
            shard,
            dir,
            report: r,
            seconds,
        } => print(&format!(
            "{}: shard {shard}: fields of {} shapes in {}: {} built ({} rays, {:.1} s), {} loaded \
             ({:.2} s), {} on disk; {:.1} s in all\n",
            args.scene.display(),
            r.fields_written + r.fields_loaded,
            dir.display(),
            r.fields_written,
            r.field_rays,
            r.field_seconds,
            r.fields_loaded,
            r.field_load_seconds,
            bytes(r.field_file_bytes),
            seconds,
        )),
        PlayOutcome::Frames(report) => {
            let output = args.output.as_deref().unwrap_or(Path::new(""));
            print(&frames_text(&args, output, &report))
        }
    }
}

/// What `relight scene` prints of a rendering: the build, a line a frame, and the images.
fn frames_text(args: &Args, output: &Path, report: &PlayReport) -> String {
    let r = &report.build;
    let files = report.fields_dir.as_ref().map_or(String::new(), |dir| {
        format!(
            "; field files in {}: {} loaded in {:.2} s, {} written, {} on disk",
            dir.display(),
            r.fields_loaded,
            r.field_load_seconds,
            r.fields_written,
            bytes(r.field_file_bytes)
        )
    });
    let mut text = format!(
        "{}: {} objects ({} shapes), {} vertices, {} {}; fields: {} samples a shape, {} rays, \
         {:.1} s, {} stored{files}; own transport: {} rays, {:.1} s; built in {:.1} s\n",
        args.scene.display(),
        report.objects,
        report.shapes,
        report.vertices,
        report.param.kind(),
        report.param.face_size(),
        report.field_samples,
        r.field_rays,
        r.field_seconds,
        bytes(r.field_bytes as u64),
        r.transport_rays,
        r.transport_seconds,
        report.build_seconds,
    );
    for frame in &report.frames {
        text += &format!(
            "{}, rasterisation {:.1} ms\n",
            frame_line(output, report, frame),
            frame.raster_seconds * 1e3
        );
    }
    text + &format!(
        "{}: {} frame(s) of {} x {}\n",
        output.display(),
        report.frames.len(),
        args.camera.width,
        args.camera.height
    )
}

/// One frame's line, before its rasterisation time.
fn frame_line(output: &Path, report: &PlayReport, frame: &FrameLine) -> String {
    let shade = format!("{} {:.1} ms", frame.description, frame.shade_seconds * 1e3);
    let Some(played) = &frame.played else {
        return format!("{}: {shade}", output.display());
    };
    let r = &played.report;
    let vertices = report.vertices.max(1) as f64;
    let reformed = r.reformed.map_or(String::new(), |t| {
        format!(
            "re-formed in {:.1} ms ({:.0} coefficients a vertex, {}), ",
            t.seconds * 1e3,
            t.coefficients as f64 / vertices,
            bytes(t.bytes as u64)
        )
    });
    let state = match r.state.placement {
        Some(p) => format!(
            "{:?} at {:.3?} scale {:.3} yaw {:.2}",
            r.state.change,
            p.translate,
            p.scale,
            p.yaw_degrees(report.param)
        ),
        None if r.state.change == Change::View => format!("eye at {:.3?}", played.eye),
        None => format!("lighting yaw {:+.2}", r.state.light_yaw),
    };
    format!("frame {}: {state}: {reformed}{shade}", r.index)
}
