//! The gallery of diffuse renders that the repository commits (`results/relight/diffuse/`):
//! one mesh on its ground plane under each environment map of a directory, the Haar render
//! beside the spherical-harmonics render and the reference, the error of each against the
//! reference, and a turntable.
//!
//! **What is made.** The scene is precomputed once (vertex order, lat-long `N x 2N`, every
//! coefficient kept, spherical-harmonics transfer of `B` bands beside it). For each map
//! (`*.hdr`, `*.exr`, `*.npy` in the directory, in name order):
//! * the per-vertex radiance three ways, each a [`Shader`] of its [`ShaderSpec`]: Haar with the
//!   lighting truncated to `K` detail coefficients ([`Method::Haar`], in `f64`), spherical
//!   harmonics of `B` bands ([`Method::Sh`]), and the reference quadrature at the same `N`
//!   ([`Method::Reference`]);
//! * `NAME.png`: the three renders side by side, Haar | SH | reference, each `W x H`, all at one
//!   exposure: the one that brings the reference's mean vertex luminance to 0.18 x 2 (mid grey
//!   one stop up);
//! * a row of `errors.md`: the relative RMS error over all vertices and channels
//!   ([`relative_rms_error`]) of Haar with every coefficient, Haar at `K`, and SH, against the
//!   reference.
//!
//! And `turntable.gif`: the first map turning about +Y in `F` frames, Haar at `K`.
//! Every output is checked before any work and replaced only with `force`.

use std::path::{Path, PathBuf};

use ndarray::{Array2, Array3, Axis, concatenate};

use crate::Result;
use haarshift::faces::{ParamKind, Parameterization};
use haarshift::io::{WriteOptions, write_image};
use haarshift::metrics::relative_rms_error;
use haarshift::product::Selection;
use haarshift::sphere::SphereRotation;
use haarshift::{Channels, PlanarImage, SampleDepth};
use haarshift_relight::light::environment::Environment;
use haarshift_relight::precompute::{PrecomputeOptions, precompute};
use haarshift_relight::render::{Background, Camera, DEFAULT_FOV, LitMesh, render, to_srgb8};
use haarshift_relight::shade::{FrameSpec, Method, Precision, Shader, ShaderSpec, ShadingInput};
use haarshift_relight::{Mesh, Scene, SceneCache, VisibilityOptions};

/// What to make; see the [module docs](self).
///
/// ```
/// use haarshift_experiments::gallery::GalleryOptions;
/// let o = GalleryOptions::default();
/// assert_eq!((o.resolution, o.keep_light, o.sh_bands, o.frames), (64, 200, 9, 24));
/// ```
#[derive(Clone, Debug, PartialEq)]
pub struct GalleryOptions {
    /// Lat-long height `N` of the precomputation and the reference (`N x 2N` texels).
    pub resolution: usize,
    /// Detail coefficients of the lighting kept by the Haar render.
    pub keep_light: usize,
    /// Spherical-harmonic bands of the SH render (`B^2` coefficients).
    pub sh_bands: usize,
    /// Width of each render, pixels.
    pub width: usize,
    /// Height of each render, pixels.
    pub height: usize,
    /// Frames of the turntable.
    pub frames: usize,
    /// Replace existing outputs.
    pub force: bool,
    /// The command that made the gallery, written at the top of `errors.md`.
    pub command: String,
}

impl Default for GalleryOptions {
    fn default() -> Self {
        GalleryOptions {
            resolution: 64,
            keep_light: 200,
            sh_bands: 9,
            width: 320,
            height: 240,
            frames: 24,
            force: false,
            command: String::new(),
        }
    }
}

/// One map's errors against the reference, relative to the scene's RMS radiance.
#[derive(Clone, Debug, PartialEq)]
pub struct GalleryRow {
    /// The map's file name without extension.
    pub name: String,
    /// Haar with every coefficient.
    pub haar_all: f64,
    /// Haar with the lighting truncated to `keep_light`.
    pub haar_kept: f64,
    /// Spherical harmonics of `sh_bands` bands.
    pub sh: f64,
}

/// The environment maps of `dir`: `*.hdr`, `*.exr` and `*.npy` files in name order.
pub fn environment_maps(dir: &Path) -> Result<Vec<PathBuf>> {
    let entries =
        std::fs::read_dir(dir).map_err(|source| crate::Error::io(dir.to_path_buf(), source))?;
    let mut maps: Vec<PathBuf> = entries
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| {
            p.extension()
                .and_then(|e| e.to_str())
                .is_some_and(|e| ["hdr", "exr", "npy"].contains(&e.to_ascii_lowercase().as_str()))
        })
        .collect();
    maps.sort();
    if maps.is_empty() {
        return Err(crate::Error::from(haarshift::Error::Format {
            path: dir.to_path_buf(),
            reason: "no environment maps (.hdr, .exr or .npy) in this directory".into(),
        }));
    }
    Ok(maps)
}

/// The file stem of `path`, as text.
fn stem(path: &Path) -> String {
    path.file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default()
}

/// Makes the gallery of `mesh` under every map of `env_dir` in `out_dir`; see the
/// [module docs](self). Returns one row per map.
pub fn gallery(
    mesh: &Path,
    env_dir: &Path,
    out_dir: &Path,
    options: &GalleryOptions,
) -> Result<Vec<GalleryRow>> {
    let maps = environment_maps(env_dir)?;
    let mut outputs: Vec<PathBuf> = maps
        .iter()
        .map(|m| out_dir.join(format!("{}.png", stem(m))))
        .collect();
    outputs.push(out_dir.join("errors.md"));
    outputs.push(out_dir.join("turntable.gif"));
    if let Some(existing) = outputs.iter().find(|p| !options.force && p.exists()) {
        return Err(crate::Error::from(haarshift::Error::OutputExists {
            path: existing.clone(),
        }));
    }
    let environments = maps
        .iter()
        .map(|m| Environment::load(m))
        .collect::<Result<Vec<_>>>()?;
    let param = Parameterization::new(ParamKind::LatLong, options.resolution)?;
    let scene = Scene::from_mesh(Mesh::load(mesh)?, true).map_err(|e| e.in_file(mesh))?;
    let mut visibility = VisibilityOptions::new(param);
    visibility.progress = true;
    visibility.sh_bands = Some(options.sh_bands);
    let (cache, _) = precompute(scene, &PrecomputeOptions::new(visibility))?;
    let camera = {
        let b = cache.mesh.bounds();
        Camera::framing(b.min, b.max, DEFAULT_FOV)?
    };
    let input = ShadingInput::cache(&cache);
    let haar = ShaderSpec {
        precision: Precision::F64,
        ..ShaderSpec::default()
    };
    let mut full = haar.build(&input)?;
    let mut truncated = ShaderSpec {
        keep_light: Selection::Largest(options.keep_light),
        ..haar
    }
    .build(&input)?;
    let mut harmonics = ShaderSpec {
        method: Method::Sh,
        ..ShaderSpec::default()
    }
    .build(&input)?;
    let mut quadrature = ShaderSpec {
        method: Method::Reference,
        reference_resolution: Some(options.resolution),
        progress: true,
        ..ShaderSpec::default()
    }
    .build(&input)?;
    let identity = SphereRotation::identity();
    std::fs::create_dir_all(out_dir)
        .map_err(|source| crate::Error::io(out_dir.to_path_buf(), source))?;
    let mut rows = Vec::with_capacity(maps.len());
    for (path, env) in maps.iter().zip(&environments) {
        let frame = FrameSpec {
            environment: env,
            rotation: identity,
            eye: Some(camera.position()),
        };
        let shade = |shader: &mut Box<dyn Shader>| -> Result<Array2<f64>> {
            Ok(shader.shade(&frame)?.radiance.to_f64())
        };
        let haar_all = shade(&mut full)?;
        let haar_kept = shade(&mut truncated)?;
        let sh = shade(&mut harmonics)?;
        let truth = shade(&mut quadrature)?;
        rows.push(GalleryRow {
            name: stem(path),
            haar_all: relative_rms_error(haar_all.view(), truth.view())?,
            haar_kept: relative_rms_error(haar_kept.view(), truth.view())?,
            sh: relative_rms_error(sh.view(), truth.view())?,
        });
        let backdrop = env.lat_long(env.map().height().min(512), &identity)?;
        let exposure = exposure_for(&truth);
        let panels = [&haar_kept, &sh, &truth]
            .iter()
            .map(|radiance| {
                let radiance = radiance.mapv(|v| v as f32);
                let mesh = LitMesh {
                    positions: cache.mesh.positions(),
                    triangles: cache.mesh.triangles(),
                    radiance: radiance.view(),
                };
                let image = render(
                    &camera,
                    options.width,
                    options.height,
                    &mesh,
                    Background::Environment(&backdrop),
                )?;
                to_srgb8(&image, exposure)
            })
            .collect::<Result<Vec<_>>>()?;
        let views: Vec<_> = panels.iter().map(|p| p.planes()).collect();
        let side_by_side: Array3<f32> = concatenate(Axis(2), &views).expect("panels of one size");
        let image = PlanarImage::new(side_by_side, Channels::Rgb, SampleDepth::U8)?;
        write_image(
            &image,
            out_dir.join(format!("{}.png", stem(path))),
            WriteOptions {
                force: options.force,
                ..Default::default()
            },
        )?;
    }
    write_errors(&out_dir.join("errors.md"), &rows, options)?;
    turntable(
        &cache,
        &environments[0],
        &camera,
        &out_dir.join("turntable.gif"),
        options,
    )?;
    Ok(rows)
}

/// The exposure (stops) that brings the mean luminance of `radiance` (`(V, 3)`) to 0.36.
pub(crate) fn exposure_for(radiance: &Array2<f64>) -> f64 {
    let luminance = radiance
        .rows()
        .into_iter()
        .map(|r| 0.2126 * r[0] + 0.7152 * r[1] + 0.0722 * r[2])
        .sum::<f64>()
        / radiance.nrows().max(1) as f64;
    if luminance > 0.0 && luminance.is_finite() {
        (0.36 / luminance).log2().clamp(-64.0, 64.0)
    } else {
        0.0
    }
}

/// `errors.md`: the command, what was compared, one row per map.
fn write_errors(path: &Path, rows: &[GalleryRow], options: &GalleryOptions) -> Result<()> {
    let mut text = format!(
        "# Diffuse relighting: Haar and spherical harmonics against the reference\n\n\
         Made by:\n\n```\n{}\n```\n\n\
         The mesh on its ground plane, Lambertian, precomputed at lat-long {n} x {}: one ray per \
         texel centre, every transport coefficient kept. Each image is three renders at one \
         exposure: Haar with the lighting's {k} largest detail coefficients | spherical \
         harmonics of {b} bands ({} coefficients) | the reference (direct quadrature over the \
         {n} x {} texels with ray casting, no Haar transform). Errors: the RMS over all vertices \
         and channels of (method - reference), divided by the reference's RMS.\n\n\
         | environment | image | Haar, every coefficient | Haar, {k} lighting coefficients | SH, {b} bands |\n\
         |---|---|---|---|---|\n",
        options.command,
        2 * options.resolution,
        options.sh_bands * options.sh_bands,
        2 * options.resolution,
        n = options.resolution,
        k = options.keep_light,
        b = options.sh_bands,
    );
    for row in rows {
        text += &format!(
            "| {} | [{}.png]({}.png) | {:.2e} | {:.2e} | {:.2e} |\n",
            row.name, row.name, row.name, row.haar_all, row.haar_kept, row.sh
        );
    }
    Ok(haarshift::io::write_file_atomically(
        path,
        options.force,
        |w| w.write_all(text.as_bytes()),
    )?)
}

/// `turntable.gif`: `env` turning about +Y, Haar at `keep_light`.
fn turntable(
    cache: &SceneCache,
    env: &Environment,
    camera: &Camera,
    path: &Path,
    options: &GalleryOptions,
) -> Result<()> {
    let input = ShadingInput::cache(cache);
    let first = ShaderSpec::default().build(&input)?.shade(&FrameSpec {
        environment: env,
        rotation: SphereRotation::identity(),
        eye: None,
    })?;
    let exposure = exposure_for(&first.radiance.to_f64());
    let mut shader = ShaderSpec {
        keep_light: Selection::Largest(options.keep_light),
        ..ShaderSpec::default()
    }
    .build(&input)?;
    let frames = (0..options.frames)
        .map(|k| {
            let turn =
                SphereRotation::from_degrees(360.0 * k as f64 / options.frames as f64, 0.0, 0.0)?;
            let radiance = shader
                .shade(&FrameSpec {
                    environment: env,
                    rotation: turn,
                    eye: None,
                })?
                .radiance
                .to_f32();
            let backdrop = env.lat_long(env.map().height().min(512), &turn)?;
            let mesh = LitMesh {
                positions: cache.mesh.positions(),
                triangles: cache.mesh.triangles(),
                radiance: radiance.view(),
            };
            to_srgb8(
                &render(
                    camera,
                    options.width,
                    options.height,
                    &mesh,
                    Background::Environment(&backdrop),
                )?,
                exposure,
            )
        })
        .collect::<Result<Vec<_>>>()?;
    haarshift_relight::render::animation::write_gif(&frames, path, 100, options.force)
}
