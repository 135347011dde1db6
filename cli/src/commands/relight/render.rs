//! `haarshift relight render`: a precomputed scene under a lighting, as an image and per-vertex
//! radiance.

use std::path::PathBuf;
use std::time::Instant;

use haarshift::SampleDepth;
use haarshift_relight::Result;
use haarshift_relight::SceneCache;
use haarshift_relight::render::{render_format, write_render};
use haarshift_relight::shade::{FrameSpec, Method, ShadingInput};

use super::flags::{
    CameraFlags, GlossyFlags, LightFlags, MaterialFlags, ShadingFlags, ms, rotation,
};
use crate::commands::{choice, names, print, refuse_outputs};

const HELP: &str = "\
The radiance leaving each vertex (Lambertian) is albedo / pi x the integral over the sphere of
lighting x visibility x max(0, n . w), computed as one sparse dot product of the vertex's Haar
transport (from the cache) with the lighting's Haar coefficients: the lighting is the
environment map rotated by g(p) = f(R p), brought to the cache's parameterisation by
solid-angle-weighted means, transformed and truncated to --keep-light. The image is the mesh
rasterised with that radiance interpolated across triangles (z-buffer), the rotated
environment (or a colour) behind; .png is 8-bit sRGB after --exposure, .exr linear f32.
--vertices writes the radiance as a (V, 3) f32 .npy in the mesh file's vertex order (ground
plane vertices after). The lighting's encoding, the shading and the rasterisation are timed
separately (preparing the transport, once per scene, apart).

A cache precomputed with --bounces B renders albedo / pi x <T0 + S_c, L_c> per channel c:
the direct transport T0 and the stored sum S of B bounces (up to four sparse dot products a
vertex; --basis haar or sh, Lambertian, the cache's albedo); --direct-only renders T0 alone,
with any material.

Examples:
  haarshift relight render bunny.hsr --env testdata/envmaps/rooitou_park_256x128.npy -o bunny.png
  haarshift relight render bunny.hsr --env park.hdr --yaw 120 --keep-light 200 -o bunny.exr
  haarshift relight render cubes.hsr --env park.hdr --keep-light 194 --keep-visibility 414 -o cubes.png
  haarshift relight render bunny.hsr --env park.hdr --camera 0,1,4 --look-at 0,0.5,0 --fov 35 -o near.png
  haarshift relight render bunny.hsr --env park.hdr --vertices radiance.npy --background 0,0,0 -o b.png
  haarshift relight render bunny.hsr --env park.hdr --basis sh -o bunny-sh.png   (after --sh-bands)
  haarshift relight render box.hsr --env park.hdr --direct-only -o direct.png   (after --bounces)";

/// Render a precomputed scene under an environment map.
#[derive(clap::Args, Debug)]
#[command(after_help = HELP)]
pub struct Args {
    /// The scene cache (`relight precompute ... -o SCENE.hsr`)
    #[arg(value_name = "SCENE.hsr")]
    pub cache: PathBuf,

    /// The image to write: .png (8-bit sRGB) or .exr (linear f32)
    #[arg(short, long, value_name = "IMAGE")]
    pub output: PathBuf,

    /// Also write the per-vertex radiance, (V, 3) f32 .npy
    #[arg(long, value_name = "OUT.npy")]
    pub vertices: Option<PathBuf>,

    #[command(flatten)]
    pub light: LightFlags,

    #[command(flatten)]
    pub material: MaterialFlags,

    #[command(flatten)]
    pub shading: ShadingFlags,

    #[command(flatten)]
    pub glossy: GlossyFlags,

    /// `haar`: the sparse Haar transport and lighting. `sh`: the spherical-harmonic transfer
    /// stored by `precompute --sh-bands B` and the lighting projected onto the same bands.
    /// `reference`: direct quadrature with ray casting at the cache's resolution (the ground
    /// truth). `ambient`: ambient occlusion, albedo / pi x the transport's integral
    #[arg(long, value_name = "BASIS", default_value = "haar",
          value_parser = choice::<Method>(names!(Method)))]
    pub basis: Method,

    #[command(flatten)]
    pub camera: CameraFlags,

    /// On a cache precomputed with --bounces, render the direct light alone (the bounced
    /// sum is shown by default)
    #[arg(long)]
    pub direct_only: bool,

    /// Replace the outputs if they exist
    #[arg(long)]
    pub force: bool,
}

pub fn run(args: Args) -> Result<()> {
    let mut outputs = vec![args.output.as_path()];
    outputs.extend(args.vertices.as_deref());
    let mut inputs = vec![args.cache.as_path()];
    inputs.extend(args.light.env.as_deref());
    inputs.extend(args.material.brdf_file());
    refuse_outputs(&inputs, &outputs, args.force)?;
    render_format(&args.output)?;
    let view = args.camera.view()?;
    let mut cache = SceneCache::read(&args.cache)?;
    if args.direct_only {
        cache.bounced = None;
    }
    args.material.apply_to_cache(&mut cache, &args.cache)?;
    let (env, angles) = args.light.load(cache.environment.as_ref())?;
    let rotation = rotation(angles)?;
    let camera = view.camera(cache.camera.as_ref(), &cache.mesh)?;
    let brdf = args.material.brdf()?;
    let spec = args
        .shading
        .spec(args.basis, &brdf, &args.glossy, &args.light);
    spec.check()?;
    let param = cache.transport.param();
    let mut shader = spec.build(&ShadingInput::cache(&cache).from_file(&args.cache))?;
    let shading = shader.shade(&FrameSpec {
        environment: &env,
        rotation,
        eye: Some(camera.position()),
    })?;
    let radiance = shading.radiance.to_f32();
    let encode_ms = shading.timing.encode_seconds * 1e3;
    let shade_ms = shading.timing.shade_seconds * 1e3;
    let what = shading.description;

    let start = Instant::now();
    let image = view.draw(&camera, &cache.mesh, radiance.view(), &env, &rotation)?;
    let raster_ms = ms(start);
    write_render(&image, &args.output, args.camera.exposure, args.force)?;
    if let Some(path) = &args.vertices {
        haarshift::io::write_npy(radiance.view(), SampleDepth::F32, path, args.force)?;
    }
    print(&format!(
        "{}: {} x {} image of {} vertices ({} {}, {what})\n\
         lighting encoding {encode_ms:.1} ms, shading {shade_ms:.1} ms, together {:.1} ms; \
         rasterisation {raster_ms:.1} ms\n",
        args.output.display(),
        args.camera.width,
        args.camera.height,
        cache.mesh.vertex_count(),
        param.kind(),
        param.face_size(),
        encode_ms + shade_ms,
    ))
}
