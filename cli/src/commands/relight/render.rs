//! `haarshift relight render`: a precomputed scene under a lighting, as an image and per-vertex
//! radiance.

use std::path::PathBuf;
use std::time::Instant;

use haarshift::relight::harmonics::{PhongSh, non_zonal_material};
use haarshift::relight::material::orient::mirror_directions;
use haarshift::relight::{Brdf, Lighting, SceneCache, shade_sh};
use haarshift::render::{render_format, write_render};
use haarshift::sphere::harmonics::SphericalHarmonics;
use haarshift::{Error, Result, SampleDepth};
use ndarray::Array2;

use super::flags::{
    CameraFlags, GlossyFlags, LightFlags, MaterialFlags, ShadingFlags, filled_note, ms,
    object_vertices, refuse_inputs, rotation,
};
use crate::commands::{print, refuse_existing};

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

Examples:
  haarshift relight render bunny.hsr --env testdata/envmaps/rooitou_park_256x128.npy -o bunny.png
  haarshift relight render bunny.hsr --env park.hdr --yaw 120 --keep-light 200 -o bunny.exr
  haarshift relight render cubes.hsr --env park.hdr --keep-light 194 --keep-visibility 414 -o cubes.png
  haarshift relight render bunny.hsr --env park.hdr --camera 0,1,4 --look-at 0,0.5,0 --fov 35 -o near.png
  haarshift relight render bunny.hsr --env park.hdr --vertices radiance.npy --background 0,0,0 -o b.png
  haarshift relight render bunny.hsr --env park.hdr --basis sh -o bunny-sh.png   (after --sh-bands)";

/// The basis the radiance is computed in.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum Basis {
    /// Haar wavelets: all-frequency.
    Haar,
    /// Spherical harmonics: low-frequency PRT.
    Sh,
}

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
    /// stored by `precompute --sh-bands B` and the lighting projected onto the same bands
    #[arg(long, value_enum, default_value = "haar")]
    pub basis: Basis,

    #[command(flatten)]
    pub camera: CameraFlags,

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
    refuse_inputs(&inputs, &outputs)?;
    refuse_existing(&outputs, args.force)?;
    render_format(&args.output)?;
    let background = args.camera.background()?;
    let mut cache = SceneCache::read(&args.cache)?;
    args.material.apply(&mut cache.albedo)?;
    let (env, angles) = args.light.load(cache.environment.as_ref())?;
    let rotation = rotation(angles)?;
    let camera = args.camera.camera(cache.camera.as_ref(), &cache.mesh)?;

    let brdf = args.material.brdf()?;
    args.glossy.check(&brdf)?;
    let param = cache.transport.param();
    let shaded = match args.basis {
        Basis::Haar if brdf.is_lambert() => {
            let start = Instant::now();
            let prepared = args.shading.prepare(&cache)?;
            let prepare_ms = ms(start);
            let start = Instant::now();
            let lighting = Lighting::new(&env, param, &rotation, args.shading.light_selection())?;
            let encode_ms = ms(start);
            let start = Instant::now();
            let radiance = prepared.shade(&lighting)?;
            Shaded {
                radiance,
                encode_ms,
                shade_ms: ms(start),
                what: format!(
                    "Haar, lighting kept {} detail coefficients, transport {} coefficients; \
                     transport prepared once in {prepare_ms:.1} ms",
                    lighting.kept(),
                    prepared.coefficient_count()
                ),
            }
        }
        Basis::Haar => {
            let start = Instant::now();
            let shader = args.shading.prepare_glossy(&cache, &brdf, &args.glossy)?;
            let prepare_ms = ms(start);
            let filled = filled_note(args.glossy.fill(&shader)?);
            let start = Instant::now();
            let lighting = Lighting::new(&env, param, &rotation, args.shading.light_selection())?;
            let encode_ms = ms(start);
            let start = Instant::now();
            let (radiance, report) = shader.shade(&lighting, camera.position())?;
            let cache_note = match args.glossy.rotation_cache {
                Some(n) => format!(
                    "rotation cache {n} x {}: {filled}{} maps rotated in {:.1} ms, {} from the \
                     cache",
                    2 * n,
                    report.rotated,
                    report.rotate_seconds * 1e3,
                    report.maps - report.rotated
                ),
                None => format!("no rotation cache: {} maps rotated", report.rotated),
            };
            Shaded {
                radiance,
                encode_ms,
                shade_ms: ms(start),
                what: format!(
                    "Haar triple product, {} rotated by {}{}, lighting kept {} detail \
                     coefficients, transport {} coefficients; {cache_note}; transport prepared \
                     once in {prepare_ms:.1} ms",
                    brdf,
                    args.glossy.brdf_rotation,
                    args.glossy.level.map_or(String::new(), |l| format!(
                        " from level {l} (thesis level {})",
                        l + 1
                    )),
                    lighting.kept(),
                    shader.transport().coefficient_count()
                ),
            }
        }
        Basis::Sh => {
            if args.shading.is_set() {
                return Err(Error::InvalidParameter {
                    name: "basis",
                    reason: "--keep-light, --keep-visibility and --depth truncate the Haar \
                             basis; --basis sh uses every band stored"
                        .into(),
                });
            }
            let transfer = cache.transport.sh().ok_or_else(|| Error::Format {
                path: args.cache.clone(),
                reason: "the cache holds no spherical-harmonic transfer: precompute it with \
                         --sh-bands B"
                    .into(),
            })?;
            let start = Instant::now();
            let map = env.sphere_map(param, &rotation)?;
            let lighting = SphericalHarmonics::new(transfer.bands())?.project(&map);
            let encode_ms = ms(start);
            let start = Instant::now();
            let radiance = match brdf {
                Brdf::Lambert => shade_sh(transfer, cache.albedo.view(), lighting.view())?,
                Brdf::Phong { exponent } => {
                    let mirror = mirror_directions(&cache.mesh, camera.position());
                    PhongSh::new(transfer.bands(), exponent)?
                        .shade(
                            transfer,
                            cache.albedo.view(),
                            lighting.view(),
                            mirror.view(),
                            object_vertices(&cache),
                        )?
                        .mapv(|x| x as f32)
                }
                other => return Err(non_zonal_material(&other.to_string())),
            };
            Shaded {
                radiance,
                encode_ms,
                shade_ms: ms(start),
                what: format!(
                    "spherical harmonics, {} bands ({} coefficients)",
                    transfer.bands(),
                    transfer.bands() * transfer.bands()
                ),
            }
        }
    };
    let Shaded {
        radiance,
        encode_ms,
        shade_ms,
        what,
    } = shaded;

    let start = Instant::now();
    let image = args.camera.draw(
        &camera,
        &cache.mesh,
        radiance.view(),
        &background,
        &env,
        &rotation,
    )?;
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

/// The per-vertex radiance of one basis, with its timings.
struct Shaded {
    radiance: Array2<f32>,
    encode_ms: f64,
    shade_ms: f64,
    what: String,
}
