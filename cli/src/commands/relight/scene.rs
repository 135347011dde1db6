//! `haarshift relight scene`: a dynamic scene (objects with occlusion fields) as one frame or
//! an animation.

use std::path::{Path, PathBuf};
use std::time::Instant;

use haarshift::SampleDepth;
use haarshift::product::Selection;
use haarshift_relight::Result;
use haarshift_relight::dynamic::fields::file::FieldStore;
use haarshift_relight::dynamic::motion::{MotionPath, play};
use haarshift_relight::dynamic::{Change, DynamicScene};
use haarshift_relight::light::environment::LightRotation;
use haarshift_relight::precompute::shard::Shard;
use haarshift_relight::render::animation::{numbered_path, write_gif};
use haarshift_relight::render::view::Frames;
use haarshift_relight::render::{Camera, render_format, to_srgb8, write_render};
use haarshift_relight::shade::dynamic_scene::{DynamicMethod, DynamicShader, glossy_material};
use haarshift_relight::shade::{FrameSpec, Shader, ShaderSpec};
use haarshift_relight::{Brdf, CameraSpec};
use ndarray::{Array2, Array3};

use super::flags::{
    CameraFlags, DynamicFlags, GlossyFlags, LightFlags, ShardFlags, brdf, bytes, ms, rotation,
};
use crate::commands::{choice, names, print, refuse_outputs};

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

/// `--shard`: this machine's share of the shapes' fields, built (or found) in --fields-dir.
fn build_fields(args: &Args, shard: Shard) -> Result<()> {
    let dir = args.dynamic.fields_dir.as_ref().ok_or_else(|| {
        haarshift_relight::Error::from(haarshift::Error::InvalidParameter {
            name: "shard",
            reason: "--shard builds fields into a directory: add --fields-dir DIR".into(),
        })
    })?;
    let options = args.dynamic.options()?;
    let mut store = FieldStore::new(dir, args.force);
    store.prepare()?;
    let start = Instant::now();
    let r = DynamicScene::build_fields(&args.scene, &options, &mut store, shard)?;
    print(&format!(
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
        ms(start) / 1e3,
    ))
}

pub fn run(args: Args) -> Result<()> {
    if args.bounces > 0 {
        return Err(haarshift_relight::Error::from(
            haarshift::Error::InvalidParameter {
                name: "bounces",
                reason: "a dynamic scene's objects move, so their interreflections are not \
                     precomputed: --bounces is for static scenes (relight precompute --bounces)"
                    .into(),
            },
        ));
    }
    if let Some(shard) = args.shard.resolve()? {
        return build_fields(&args, shard);
    }
    let output = args.output.as_deref().ok_or_else(|| {
        haarshift_relight::Error::from(haarshift::Error::InvalidParameter {
            name: "output",
            reason: "-o IMAGE is needed to render (only --shard renders nothing)".into(),
        })
    })?;
    let gif = output
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("gif"));
    let path = args.animate.as_deref().map(MotionPath::load).transpose()?;
    let frame_count = path.as_ref().map_or(1, MotionPath::frame_count);
    if path.is_none() && gif {
        return Err(haarshift_relight::Error::from(
            haarshift::Error::InvalidParameter {
                name: "output",
                reason: "a .gif needs --animate PATH.json; one frame is .png or .exr".into(),
            },
        ));
    }
    let frame_paths: Vec<PathBuf> = match (&path, gif) {
        (Some(_), false) => (0..frame_count)
            .map(|k| numbered_path(output, k))
            .collect::<Result<_>>()?,
        _ => Vec::new(),
    };
    match frame_paths.first() {
        Some(first) => render_format(first).map(|_| ())?,
        None if !gif => render_format(output).map(|_| ())?,
        None => {}
    }
    let mut outputs: Vec<&Path> = if frame_paths.is_empty() {
        vec![output]
    } else {
        frame_paths.iter().map(PathBuf::as_path).collect()
    };
    outputs.extend(args.vertices.as_deref());
    let mut inputs = vec![args.scene.as_path()];
    inputs.extend(args.animate.as_deref());
    inputs.extend(args.light.env.as_deref());
    inputs.extend(
        args.brdf
            .as_deref()
            .and_then(|b| b.strip_prefix("merl:"))
            .map(Path::new),
    );
    refuse_outputs(&inputs, &outputs, args.force)?;
    if args.light.light_rotation != LightRotation::Source && args.animate.is_some() {
        return Err(haarshift_relight::Error::from(
            haarshift::Error::InvalidParameter {
                name: "light-rotation",
                reason:
                    "--light-rotation prefiltered applies to one frame; an animation's lighting \
                     is rotated at the source's resolution"
                        .into(),
            },
        ));
    }
    let view = args.camera.view()?;
    let options = args.dynamic.options()?;
    let mut store = args.dynamic.field_store(args.force)?;

    let start = Instant::now();
    let mut scene = DynamicScene::load_with(&args.scene, &options, store.as_mut())?;
    let build_ms = ms(start);
    let (env, angles) = args.light.load(scene.environment.as_ref())?;
    let camera = view.camera(scene.camera.as_ref(), &scene.mesh())?;
    if let Some(spec) = &args.brdf {
        let brdf: Brdf = spec.parse()?;
        for k in 0..scene.object_count() {
            scene.set_brdf(k, brdf.clone())?;
        }
    }
    // The glossy flags apply to the first glossy material (any other is rotated alike).
    let glossy = args.glossy.options(&glossy_material(&scene)?);
    ShaderSpec {
        material: glossy.clone(),
        fill_cache: args.glossy.fill_cache,
        ..ShaderSpec::default()
    }
    .check()?;
    scene.set_glossy(&glossy)?;
    scene.set_eye(camera.position())?;
    // The camera as resolved from the flags and the file: eye segments orbit its look-at point.
    scene.camera = Some(CameraSpec {
        position: camera.position(),
        look_at: camera.look_at(),
        fov: camera.fov(),
    });
    let param = scene.param();
    let r = *scene.report();
    let files = store.as_ref().map_or(String::new(), |s| {
        format!(
            "; field files in {}: {} loaded in {:.2} s, {} written, {} on disk",
            s.dir().display(),
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
        scene.object_count(),
        scene.shape_count(),
        scene.vertex_count(),
        param.kind(),
        param.face_size(),
        options.field.samples(),
        r.field_rays,
        r.field_seconds,
        bytes(r.field_bytes as u64),
        r.transport_rays,
        r.transport_seconds,
        build_ms / 1e3,
    );
    let keep_light = args.keep_light.map_or(Selection::All, Selection::Largest);
    let mut all_radiance: Vec<Array2<f32>> = Vec::new();
    let mut gif_frames = Vec::new();
    // Each pixel's place in the environment, prepared with the first frame and kept while
    // the camera stays.
    let mut frames = Frames::new(view);
    let mut draw = |scene: &DynamicScene,
                    camera: &Camera,
                    radiance: &Array2<f32>,
                    turn: &haarshift::sphere::SphereRotation,
                    index: usize,
                    text: &mut String,
                    what: String|
     -> Result<()> {
        let start = Instant::now();
        let image = frames.draw(camera, &scene.mesh(), radiance.view(), &env, turn)?;
        let raster_ms = ms(start);
        match (frame_paths.get(index), gif) {
            (Some(p), _) => write_render(&image, p, args.camera.exposure, args.force)?,
            (None, true) => gif_frames.push(to_srgb8(&image, args.camera.exposure)?),
            (None, false) => write_render(&image, output, args.camera.exposure, args.force)?,
        }
        *text += &format!("{what}, rasterisation {raster_ms:.1} ms\n");
        if args.vertices.is_some() {
            all_radiance.push(radiance.clone());
        }
        Ok(())
    };
    match &path {
        None => {
            let turn = rotation(angles)?;
            let shading = DynamicShader::new(&scene, args.method, keep_light)
                .with_light_rotation(args.light.light_rotation)
                .shade(&FrameSpec {
                    environment: &env,
                    rotation: turn,
                    eye: None,
                })?;
            let radiance = shading.radiance.to_f32();
            let what = format!(
                "{}: {} {:.1} ms",
                output.display(),
                shading.description,
                shading.timing.total_seconds() * 1e3
            );
            draw(&scene, &camera, &radiance, &turn, 0, &mut text, what)?;
        }
        Some(path) => {
            play(
                &mut scene,
                &env,
                angles,
                keep_light,
                path,
                |scene, radiance, turn, report| {
                    let shading =
                        args.method
                            .played(scene, radiance, report.shade_seconds, &env, turn)?;
                    let shade = format!(
                        "{} {:.1} ms",
                        shading.description,
                        shading.timing.total_seconds() * 1e3
                    );
                    let radiance = shading.radiance.to_f32();
                    let vertices = scene.vertex_count().max(1) as f64;
                    let reformed = report.reformed.map_or(String::new(), |r| {
                        format!(
                            "re-formed in {:.1} ms ({:.0} coefficients a vertex, {}), ",
                            r.seconds * 1e3,
                            r.coefficients as f64 / vertices,
                            bytes(r.bytes as u64)
                        )
                    });
                    let state = match report.state.placement {
                        Some(p) => format!(
                            "{:?} at {:.3?} scale {:.3} yaw {:.2}",
                            report.state.change,
                            p.translate,
                            p.scale,
                            p.yaw_degrees(param)
                        ),
                        None if report.state.change == Change::View => {
                            format!("eye at {:.3?}", scene.eye().unwrap_or(camera.position()))
                        }
                        None => format!("lighting yaw {:+.2}", report.state.light_yaw),
                    };
                    let what = format!("frame {}: {state}: {reformed}{shade}", report.index);
                    let seen_from = match scene.eye() {
                        Some(eye) if eye != camera.position() => {
                            Camera::new(eye, camera.look_at(), camera.fov())?
                        }
                        _ => camera,
                    };
                    draw(
                        scene,
                        &seen_from,
                        &radiance,
                        turn,
                        report.index,
                        &mut text,
                        what,
                    )
                },
            )?;
        }
    }
    if gif {
        write_gif(&gif_frames, output, args.delay, args.force)?;
    }
    if let Some(out) = &args.vertices {
        match &path {
            None => {
                haarshift::io::write_npy(all_radiance[0].view(), SampleDepth::F32, out, args.force)?
            }
            Some(_) => {
                let (v, _) = all_radiance[0].dim();
                let mut stack = Array3::<f32>::zeros((all_radiance.len(), v, 3));
                for (k, r) in all_radiance.iter().enumerate() {
                    stack.index_axis_mut(ndarray::Axis(0), k).assign(r);
                }
                haarshift::io::write_npy(stack.view(), SampleDepth::F32, out, args.force)?;
            }
        }
    }
    text += &format!(
        "{}: {frame_count} frame(s) of {} x {}\n",
        output.display(),
        args.camera.width,
        args.camera.height
    );
    print(&text)
}
