//! `haarshift relight reference`: the ground truth, by direct quadrature over the lighting's
//! texels with ray casting, independent of every Haar path.

use std::path::PathBuf;

use haarshift::relight::shade::{FrameSpec, Method, ShaderSpec, ShadingInput};
use haarshift::render::{render_format, write_render};
use haarshift::{Result, SampleDepth};

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

Examples:
  haarshift relight reference testdata/meshes/bunny.ply --ground-plane --env park.hdr --vertices truth.npy
  haarshift relight reference bunny.ply --ground-plane --env park.hdr --resolution 64 --vertices truth.npy -o truth.png
  haarshift relight reference bunny.ply --ground-plane --env park.hdr --brdf phong:50 --resolution 128 --vertices glossy.npy
  haarshift relight reference bunny.ply --env park.hdr --brdf merl:gold-metallic-paint.binary --vertices gold.npy
  haarshift relight reference scene.json --yaw 90 --albedo 0.5,0.5,0.5 --vertices truth.npy";

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

    /// Replace the outputs if they exist
    #[arg(long)]
    pub force: bool,
}

pub fn run(args: Args) -> Result<()> {
    let mut outputs = vec![args.vertices.as_path()];
    outputs.extend(args.output.as_deref());
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
    let mut text = format!(
        "{}: ({}, 3) {} (lighting downsampled in {:.1} ms)\n",
        args.vertices.display(),
        scene.mesh.vertex_count(),
        shading.description,
        shading.timing.encode_seconds * 1e3,
    );
    if let Some(path) = &args.output {
        let image = view.draw(&camera, &scene.mesh, radiance.view(), &env, &rotation)?;
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
