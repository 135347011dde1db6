//! `haarshift relight reference`: the ground truth, by direct quadrature over the lighting's
//! texels with ray casting, independent of every Haar path.

use std::path::PathBuf;

use haarshift::SampleDepth;
use haarshift::io::write_npy;
use haarshift::sphere::SphereRotation;
use haarshift_relight::Result;
use haarshift_relight::light::environment::Environment;
use haarshift_relight::render::Camera;
use haarshift_relight::render::view::ViewSpec;
use haarshift_relight::render::{render_format, write_render};
use haarshift_relight::shade::reference::interreflection::{self, check_bounces, check_lambertian};
use haarshift_relight::shade::reference::path_trace::{PathTraceOptions, path_trace};
use haarshift_relight::shade::{FrameSpec, Method, ShaderSpec, ShadingInput};
use haarshift_relight::{Brdf, Scene, SceneBvh};
use ndarray::ArrayView2;

use super::flags::{CameraFlags, LightFlags, MaterialFlags, SceneFlags, rotation};
use crate::commands::{print, refuse_outputs};

const HELP: &str = "\
The radiance leaving each vertex toward the camera, by direct quadrature:
  albedo x sum over texels t of L(t) V(v, t) max(0, n . w_t) rho(w_t, w_o) dOmega_t,
rho the BRDF (--brdf; lambert is 1 / pi) evaluated analytically at each texel's direction,
w_o the direction from the vertex to the camera (the one --camera, the scene or the framing
gives); with a glossy or measured BRDF the ground plane stays Lambertian. L the environment rotated by g(p) = f(R p) and downsampled to N x 2N by solid-angle-weighted
means, w_t the texel centre's direction, V one ray per texel centre from the vertex offset
along its normal by 1e-4 x the scene's bounding-box diagonal (blocked when it hits any
triangle). No Haar transform, no cache: the ground truth that `relight render` is checked
against (with --param latlong --resolution N and every coefficient kept, they agree to
rounding). Same output formats as `relight render`.

With --bounces B (Lambertian scenes), B bounces of interreflected light are gathered over
the same rays: each ray that hits the front of a triangle brings the hit point's light of
the bounce before, interpolated over the triangle's corners, times its interpolated albedo
/ pi; the output is the sum. With --path-trace N the radiance is instead estimated by N
cosine-weighted paths a vertex of depth B (seeded by --seed, repeatable), with its standard
error (--stderr FILE.npy, and its RMS printed).

Examples:
  haarshift relight reference testdata/meshes/bunny.ply --ground-plane --env park.hdr --vertices truth.npy
  haarshift relight reference bunny.ply --ground-plane --env park.hdr --resolution 64 --vertices truth.npy -o truth.png
  haarshift relight reference bunny.ply --ground-plane --env park.hdr --brdf phong:50 --resolution 128 --vertices glossy.npy
  haarshift relight reference bunny.ply --env park.hdr --brdf merl:gold-metallic-paint.binary --vertices gold.npy
  haarshift relight reference scene.json --yaw 90 --albedo 0.5,0.5,0.5 --vertices truth.npy
  haarshift relight reference testdata/scenes/bunny_in_box.json --bounces 2 --vertices gather.npy
  haarshift relight reference testdata/scenes/bunny_in_box.json --bounces 2 --path-trace 1024 --seed 3 --stderr se.npy --vertices paths.npy";

/// Per-vertex radiance by direct quadrature (the ground truth), optionally rendered.
#[derive(clap::Args, Debug)]
#[command(after_help = HELP)]
pub struct Args {
    #[command(flatten)]
    pub scene: SceneFlags,

    /// Where to write the per-vertex radiance, (V, 3) f32 .npy
    #[arg(long, value_name = "OUT.npy")]
    pub vertices: PathBuf,

    /// Also render an image: .png (8-bit sRGB) or .exr (linear f32)
    #[arg(short, long, value_name = "IMAGE")]
    pub output: Option<PathBuf>,

    /// The lighting's lat-long height N (N x 2N texels, a power of two)
    #[arg(long, value_name = "N", default_value_t = 32)]
    pub resolution: usize,

    #[command(flatten)]
    pub light: LightFlags,

    #[command(flatten)]
    pub material: MaterialFlags,

    #[command(flatten)]
    pub camera: CameraFlags,

    /// Bounces of interreflected light (0 to 8; Lambertian only): the gather's, or with
    /// --path-trace the paths' depth
    #[arg(long, value_name = "B", default_value_t = 0)]
    pub bounces: usize,

    /// Estimate the radiance by N paths a vertex instead of the gather (a second truth)
    #[arg(long, value_name = "N")]
    pub path_trace: Option<usize>,

    /// The path tracer's seed
    #[arg(long, value_name = "S", default_value_t = 0, requires = "path_trace")]
    pub seed: u64,

    /// Where to write the path tracer's standard error per vertex, (V, 3) f32 .npy
    #[arg(long, value_name = "FILE.npy", requires = "path_trace")]
    pub stderr: Option<PathBuf>,

    /// Replace the outputs if they exist
    #[arg(long)]
    pub force: bool,
}

pub fn run(args: Args) -> Result<()> {
    let mut outputs = vec![args.vertices.as_path()];
    outputs.extend(args.output.as_deref());
    outputs.extend(args.stderr.as_deref());
    let mut inputs = vec![args.scene.input.as_path()];
    inputs.extend(args.light.env.as_deref());
    inputs.extend(args.material.brdf_file());
    refuse_outputs(&inputs, &outputs, args.force)?;
    if let Some(image) = &args.output {
        render_format(image)?;
    }
    let view = args.camera.view()?;
    let brdf = args.material.brdf()?;
    let mut scene = args.scene.load()?;
    args.material.apply(&mut scene.albedo)?;
    let (env, angles) = args.light.load(scene.environment.as_ref())?;
    let rotation = rotation(angles)?;
    let camera = view.camera(scene.camera.as_ref(), &scene.mesh)?;
    if args.bounces > 0 || args.path_trace.is_some() {
        return interreflected(&args, &brdf, &scene, &env, &rotation, &view, &camera);
    }
    let mut spec = ShaderSpec {
        method: Method::Reference,
        reference_resolution: Some(args.resolution),
        light_rotation: args.light.light_rotation,
        progress: true,
        ..ShaderSpec::default()
    };
    spec.material.brdf = brdf;
    let shading = spec
        .build(&ShadingInput::scene(&scene))?
        .shade(&FrameSpec {
            environment: &env,
            rotation,
            eye: Some(camera.position()),
        })?;
    let radiance = shading.radiance.to_f32();
    haarshift::io::write_npy(
        radiance.view(),
        SampleDepth::F32,
        &args.vertices,
        args.force,
    )?;
    let text = format!(
        "{}: ({}, 3) {} (lighting downsampled in {:.1} ms)\n",
        args.vertices.display(),
        scene.mesh.vertex_count(),
        shading.description,
        shading.timing.encode_seconds * 1e3,
    );
    finish(
        &args,
        &scene,
        radiance.view(),
        &env,
        &rotation,
        &view,
        &camera,
        text,
    )
}

/// `--bounces B` by the gather, or `--path-trace N`: Lambertian only.
fn interreflected(
    args: &Args,
    brdf: &Brdf,
    scene: &Scene,
    env: &Environment,
    rotation: &SphereRotation,
    view: &ViewSpec,
    camera: &Camera,
) -> Result<()> {
    check_bounces(args.bounces)?;
    check_lambertian(brdf)?;
    let lighting = env.lat_long(args.resolution, rotation)?;
    let bvh = SceneBvh::new(&scene.mesh);
    let (radiance, mut text) = match args.path_trace {
        None => {
            let r = interreflection::interreflected(
                &scene.mesh,
                &bvh,
                scene.albedo.view(),
                &lighting,
                args.bounces,
                true,
            )?;
            let about = format!(
                "radiance (lambert) with {} bounces gathered over {} x {} texels: rays {}, {:.3} s",
                args.bounces,
                args.resolution,
                2 * args.resolution,
                r.report.rays,
                r.report.seconds
            );
            (r.radiance(args.bounces), about)
        }
        Some(paths) => {
            let options = PathTraceOptions {
                paths,
                bounces: args.bounces,
                seed: args.seed,
                progress: true,
            };
            let t = path_trace(&scene.mesh, &bvh, scene.albedo.view(), &lighting, &options)?;
            if let Some(path) = &args.stderr {
                write_npy(
                    t.standard_error.mapv(|x| x as f32).view(),
                    SampleDepth::F32,
                    path,
                    args.force,
                )?;
            }
            let about = format!(
                "radiance (lambert) by {paths} paths of depth {} (seed {}) under {} x {} texels: \
                 RMS standard error {:.6e}, rays {}, {:.3} s",
                args.bounces,
                args.seed,
                args.resolution,
                2 * args.resolution,
                t.rms_standard_error(),
                t.report.rays,
                t.report.seconds
            );
            (t.radiance, about)
        }
    };
    let radiance = radiance.mapv(|x| x as f32);
    write_npy(
        radiance.view(),
        SampleDepth::F32,
        &args.vertices,
        args.force,
    )?;
    text = format!(
        "{}: ({}, 3) {text}\n",
        args.vertices.display(),
        scene.mesh.vertex_count()
    );
    if let Some(path) = &args.stderr {
        text += &format!(
            "{}: ({}, 3) standard errors\n",
            path.display(),
            scene.mesh.vertex_count()
        );
    }
    finish(
        args,
        scene,
        radiance.view(),
        env,
        rotation,
        view,
        camera,
        text,
    )
}

/// Draws the image `--output` asks for (the same for every way the radiance was computed) and
/// prints what was written.
#[allow(clippy::too_many_arguments)]
fn finish(
    args: &Args,
    scene: &Scene,
    radiance: ArrayView2<'_, f32>,
    env: &Environment,
    rotation: &SphereRotation,
    view: &ViewSpec,
    camera: &Camera,
    mut text: String,
) -> Result<()> {
    if let Some(path) = &args.output {
        let image = view.draw(camera, &scene.mesh, radiance, env, rotation)?;
        write_render(&image, path, args.camera.exposure, args.force)?;
        text += &format!(
            "{}: {} x {} image\n",
            path.display(),
            args.camera.width,
            args.camera.height
        );
    }
    print(&text)
}
