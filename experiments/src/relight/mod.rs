//! The relighting experiment (`haarshift experiment relight`): every relighting method of the
//! library against the ray-cast ground truth, over the sources' axes, so that a user picks a
//! method by measured error against time and memory, and the sources' rendering claims are
//! checked.
//!
//! **Ground truth.** [`reference`](haarshift_relight::reference()) at `truth_resolution`
//! (`N x 2N` texels, the lighting brought there by solid-angle means): one ray per texel,
//! the BRDF evaluated analytically per texel in the vertex's own frame; no transform, no
//! rotation, no truncation. The rays are cast once per scene (`ReferenceVisibility`) and
//! integrated under every lighting, material and view.
//!
//! **Axes**, each its own rows (`axis` in a record):
//! * `rotation` (thesis Figs. 4.5-4.6): the BRDF brought into each vertex frame by `haar`
//!   from the sphere module's detail levels 3, 4, 5 (thesis levels 4, 5, 6) and the finest,
//!   `haar-cubic`, `spatial` (bilinear), `reference` (solid-angle integration) and `direct`
//!   (no rotation: the exact lobe), every coefficient kept; besides the error against the
//!   truth, `spatial_difference` is the thesis's own metric, the RMS of (this render - the
//!   spatially rotated render) over the truth's RMS;
//! * `coefficients` (Fig. 4.7): each rotated BRDF map cut to `C` coefficients per face,
//!   either coarse to fine (`cutoff`: the detail levels whose faces hold `C`, `GlossyOptions::brdf_levels`)
//!   or the `faces x C` largest (`largest`, the scaling coefficients among them);
//! * `resolution` (Vollick and Lessig's tables): lat-long and cube maps of several sizes times the
//!   kept ratio `r` of the lighting's and each transport's detail coefficients (and each
//!   BRDF map's), with the seconds of the precomputation and of the relighting;
//! * `depth` (Sun 2006, Fig. 3.5): the traversal depth, detail levels `0..d`;
//! * `harmonics`: spherical harmonics of `B` bands (`B^2` coefficients) against Haar with
//!   `B^2` lighting and `B^2` transport coefficients per vertex (equal counts), and Haar at
//!   larger budgets (to compare at equal time).
//!
//! Errors are per-vertex radiance differences, RMS and maximum over all vertices and channels
//! (`RelativeError`), relative to the truth's RMS radiance; `image_rms` is the same over the
//! pixels of the two renders (black background), relative to the truth image's RMS.
//! Times are wall-clock seconds on all cores: `precompute_seconds` is the transport's ray
//! casting and encoding plus the shader's preparation (truncating the transport, tables of
//! local BRDF maps), `relight_seconds` encoding the lighting and shading every vertex (BRDF
//! rotations included). `peak_mib` is the process's peak resident memory when the record was
//! made (it only grows).

use std::path::Path;

use serde::{Deserialize, Serialize};

use crate::journal::Journal;
use crate::output::write_png;
use crate::{Error, Result};
use condition::Condition;
use haarshift_relight::light::environment::Environment;
use haarshift_relight::material::orient::BrdfRotation;
use haarshift_relight::{Brdf, Scene};
use scene::SceneUnderTest;

mod axes;
mod condition;
mod picture;
pub mod report;
mod scene;

#[cfg(test)]
mod tests;

/// How far the second camera orbits the first about the vertical, degrees.
pub const SECOND_CAMERA: f64 = 120.0;

/// A scene of the experiment: its name in the records and the scene itself.
#[derive(Clone, Debug)]
pub struct Subject {
    /// The file's stem.
    pub name: String,
    /// The scene (objects, ground plane, camera).
    pub scene: Scene,
}

impl Subject {
    /// A scene file (`.json`) or a mesh (OBJ, PLY) put on its ground plane.
    pub fn load(path: &Path) -> Result<Self> {
        let mut scene = Scene::load(path)?;
        let is_mesh = !path
            .extension()
            .is_some_and(|e| e.eq_ignore_ascii_case("json"));
        if is_mesh {
            scene.add_ground_plane().map_err(|e| e.in_file(path))?;
        }
        Ok(Subject {
            name: stem(path),
            scene,
        })
    }
}

/// An environment map of the experiment, with its name.
#[derive(Clone, Debug)]
pub struct Light {
    /// The file's stem.
    pub name: String,
    /// The map.
    pub environment: Environment,
}

impl Light {
    /// Reads an environment map (`.hdr`, `.exr`, `.npy`).
    pub fn load(path: &Path) -> Result<Self> {
        Ok(Light {
            name: stem(path),
            environment: Environment::load(path)?,
        })
    }
}

fn stem(path: &Path) -> String {
    path.file_stem().map_or_else(
        || path.display().to_string(),
        |s| s.to_string_lossy().into_owned(),
    )
}

/// How the BRDF is brought into each frame in the rotation axis: the method and the
/// sphere module's detail level it starts from (`None`: the finest).
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Orienting {
    /// The method.
    pub rotation: BrdfRotation,
    /// The level (`--level`).
    pub level: Option<usize>,
}

/// What to run: each axis's settings; see the [module docs](self).
#[derive(Clone, Debug, PartialEq)]
pub struct RelightProtocol {
    /// `quick` or `full`.
    pub name: String,
    /// The lat-long height `N` of the ground truth.
    pub truth_resolution: usize,
    /// How many of the given scenes every axis runs on (the first ones).
    pub scenes: usize,
    /// How many of the given lighting maps the rotation and harmonics axes run on (for the
    /// first scene; the others run under the first map).
    pub lights: usize,
    /// Rotations of the lighting (yaw, pitch, roll in degrees) the rotation axis runs under:
    /// the first with every material, the others with the first material.
    pub light_rotations: Vec<[f64; 3]>,
    /// Cameras of the rotation axis: 1 (the scene's) or 2 (also one orbited by
    /// [`SECOND_CAMERA`], with the first material).
    pub cameras: usize,
    /// Lat-long height of the rotation and coefficient axes.
    pub rotation_resolution: usize,
    /// Materials of the rotation axis.
    pub rotation_materials: Vec<Brdf>,
    /// Methods of the rotation axis.
    pub orientings: Vec<Orienting>,
    /// The first this many settings of the rotation axis (per scene) run the `reference`
    /// orienting of `orientings`; the others skip it (it takes minutes per render: every
    /// texel of every vertex's map integrated over its solid angle).
    pub reference_settings: usize,
    /// Material of the coefficient axis.
    pub coefficient_material: Brdf,
    /// Coefficients per face of the coefficient axis (powers of 4).
    pub coefficient_counts: Vec<usize>,
    /// Lat-long heights of the resolution axis.
    pub latlong_resolutions: Vec<usize>,
    /// Cube face sizes of the resolution axis.
    pub cube_resolutions: Vec<usize>,
    /// Kept ratios of the resolution axis.
    pub ratios: Vec<f64>,
    /// Materials of the resolution axis.
    pub resolution_materials: Vec<Brdf>,
    /// Lat-long height of the depth axis.
    pub depth_resolution: usize,
    /// Materials of the depth axis.
    pub depth_materials: Vec<Brdf>,
    /// Lat-long height of the harmonics axis.
    pub harmonics_resolution: usize,
    /// Spherical-harmonic bands of the harmonics axis.
    pub sh_bands: Vec<usize>,
    /// Haar budgets (coefficients of the lighting and of each transport) of the harmonics
    /// axis beyond the equal counts.
    pub haar_budgets: Vec<usize>,
    /// Materials of the harmonics axis (zonal ones: Lambert, Phong).
    pub harmonics_materials: Vec<Brdf>,
    /// Width and height of each render, pixels.
    pub image: (usize, usize),
}

fn phong(exponent: f64) -> Brdf {
    Brdf::Phong { exponent }
}

impl RelightProtocol {
    /// The default run: a few minutes on two cores. One scene, one map, Phong 50 for the
    /// glossy axes, the ground truth at 256 x 512.
    pub fn quick() -> Self {
        let haar = |level| Orienting {
            rotation: BrdfRotation::Haar,
            level,
        };
        let other = |rotation| Orienting {
            rotation,
            level: None,
        };
        RelightProtocol {
            name: "quick".into(),
            truth_resolution: 256,
            scenes: 1,
            lights: 1,
            light_rotations: vec![[0.0; 3]],
            cameras: 1,
            rotation_resolution: 128,
            rotation_materials: vec![phong(50.0)],
            orientings: vec![
                haar(Some(3)),
                haar(Some(4)),
                haar(Some(5)),
                haar(None),
                other(BrdfRotation::HaarCubic),
                other(BrdfRotation::Spatial),
                other(BrdfRotation::Direct),
            ],
            reference_settings: 0,
            coefficient_material: phong(50.0),
            coefficient_counts: vec![4, 16, 64, 256],
            latlong_resolutions: vec![32, 64, 128],
            cube_resolutions: vec![16, 32],
            ratios: vec![1.0, 0.1, 0.05, 0.01],
            resolution_materials: vec![Brdf::Lambert],
            depth_resolution: 128,
            depth_materials: vec![Brdf::Lambert],
            harmonics_resolution: 64,
            sh_bands: (2..=8).collect(),
            haar_budgets: vec![128, 256, 512, 1024],
            harmonics_materials: vec![Brdf::Lambert, phong(10.0)],
            image: (320, 240),
        }
    }

    /// The full run: every scene and map given, the lighting also rotated, both cameras,
    /// Phong 10, 50, 200 and Blinn-Phong 50, the `reference` rotation, maps up to 256 x 512
    /// and cube 6 x 128^2, glossy resolution and depth rows, the ground truth at 512 x 1024.
    pub fn full() -> Self {
        let quick = Self::quick();
        let mut orientings = quick.orientings.clone();
        orientings.insert(
            orientings.len() - 1,
            Orienting {
                rotation: BrdfRotation::Reference,
                level: None,
            },
        );
        RelightProtocol {
            name: "full".into(),
            truth_resolution: 512,
            scenes: usize::MAX,
            lights: usize::MAX,
            light_rotations: vec![[0.0; 3], [90.0, 30.0, 0.0]],
            cameras: 2,
            rotation_materials: vec![
                phong(10.0),
                phong(50.0),
                phong(200.0),
                Brdf::BlinnPhong { exponent: 50.0 },
            ],
            orientings,
            reference_settings: 1,
            latlong_resolutions: vec![32, 64, 128, 256],
            cube_resolutions: vec![16, 32, 64, 128],
            resolution_materials: vec![Brdf::Lambert, phong(50.0)],
            depth_materials: vec![Brdf::Lambert, phong(50.0)],
            harmonics_resolution: 128,
            ..quick
        }
    }
}

/// One measured setting; see the [module docs](self).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct RelightRecord {
    /// `rotation`, `coefficients`, `resolution`, `depth` or `harmonics`.
    pub axis: String,
    /// Scene name.
    pub scene: String,
    /// Vertices of the scene.
    pub vertices: usize,
    /// Environment map name.
    pub envmap: String,
    /// The lighting's rotation, `yaw/pitch/roll` in degrees.
    pub light_rotation: String,
    /// The objects' material (the ground plane stays Lambertian).
    pub material: String,
    /// The camera: 0 the scene's, 1 orbited by [`SECOND_CAMERA`].
    pub camera: usize,
    /// `haar`, `haar-cubic`, `spatial`, `reference`, `direct` (Haar triple products with the
    /// BRDF so brought into each frame; `haar` alone for Lambert) or `sh`.
    pub method: String,
    /// The method's parameters, as a label.
    pub parameters: String,
    /// `latlong` or `cube`.
    pub param: String,
    /// Face side of the maps (lat-long `N x 2N`, cube `6 x N^2`).
    pub resolution: usize,
    /// The rotation's starting detail level (empty: the finest); the thesis's level is one
    /// more.
    pub level: Option<usize>,
    /// The kept ratio of the resolution axis.
    pub kept_ratio: Option<f64>,
    /// Coefficients of the lighting kept (scaling coefficients included).
    pub light_coefficients: usize,
    /// Coefficients per rotated BRDF map kept (empty: all).
    pub brdf_coefficients: Option<usize>,
    /// Traversal depth (detail levels `0..depth`).
    pub depth: usize,
    /// Spherical-harmonic bands (`sh` only).
    pub sh_bands: Option<usize>,
    /// RMS error over vertices and channels, relative to the truth's RMS radiance.
    pub rms_relative: f64,
    /// Largest error, relative to the truth's RMS radiance.
    pub max_relative: f64,
    /// RMS error, radiance units.
    pub rms: f64,
    /// Largest error, radiance units.
    pub max: f64,
    /// RMS of the render's pixels minus the truth render's, relative to the truth render's
    /// RMS.
    pub image_rms: f64,
    /// Thesis metric (rotation axis): RMS of (this - the spatially rotated result) over the
    /// truth's RMS.
    pub spatial_difference: Option<f64>,
    /// Seconds of the precomputation and the shader's preparation.
    pub precompute_seconds: f64,
    /// Seconds of encoding the lighting and shading every vertex.
    pub relight_seconds: f64,
    /// Peak resident memory of the process so far, MiB.
    pub peak_mib: f64,
}

/// A picture grid: renders side by side, the false-colour error image under each.
#[derive(Clone, Debug)]
pub struct PictureGrid {
    /// `SCENE-ENVMAP-MATERIAL`.
    pub name: String,
    /// What it shows and the error scale.
    pub caption: String,
    /// The grid, 8-bit sRGB RGB.
    pub image: image::RgbImage,
}

/// What a run made.
#[derive(Clone, Debug)]
pub struct RelightResults {
    /// Every record, axis by axis.
    pub records: Vec<RelightRecord>,
    /// One grid per scene: the rotation axis's first setting.
    pub grids: Vec<PictureGrid>,
    /// Seconds of casting the ground truth's rays, per scene.
    pub truth_seconds: Vec<(String, f64)>,
}

/// Runs `protocol` over `subjects` under `lights`; `progress` is called with each record.
///
/// Each unit of work (a scene's truth, a condition of the rotation axis, an axis under one
/// material) goes through `journal` ([`Journal::in_memory`] for none): a resumed journal's
/// units are taken from it, and a scene whose units are all journaled casts no rays. A shard's
/// journal ([`Journal::create_shard`]) measures its share of the units only, and the results
/// hold those.
pub fn run(
    subjects: &[Subject],
    lights: &[Light],
    protocol: &RelightProtocol,
    journal: &mut Journal,
    mut progress: impl FnMut(&RelightRecord),
) -> Result<RelightResults> {
    if subjects.is_empty() || lights.is_empty() {
        return Err(Error::parameter(
            "relight experiment",
            "needs at least one scene and one environment map",
        ));
    }
    let mut results = RelightResults {
        records: Vec::new(),
        grids: Vec::new(),
        truth_seconds: Vec::new(),
    };
    let lights_used = &lights[..protocol.lights.min(lights.len())];
    let scenes = &subjects[..protocol.scenes.min(subjects.len())];
    for (index, subject) in scenes.iter().enumerate() {
        // Built (its truth cast) only when a unit of it is not journaled.
        let mut slot = None;
        let unit = |name: String| format!("{index} {}/{name}", subject.name);
        let truth = journal.assigned_unit(&unit("truth".into()), || {
            Ok(under_test(&mut slot, subject, protocol)?
                .truth_bits
                .report()
                .seconds)
        })?;
        if let Some(seconds) = truth {
            results.truth_seconds.push((subject.name.clone(), seconds));
        }
        // A unit's records; `None` for another shard's unit.
        let mut push = |records: Option<Vec<RelightRecord>>| {
            let records = records.unwrap_or_default();
            records.iter().for_each(&mut progress);
            results.records.extend(records);
        };
        // The first scene under every map; the others (larger, slower) under the first.
        let maps = if index == 0 {
            lights_used
        } else {
            &lights_used[..1]
        };
        for (k, condition) in rotation_conditions(maps, protocol)?.iter().enumerate() {
            // The first condition's picture grid is kept, beside the journal when it has a file.
            let keep_grid = k == 0;
            let grid_file = keep_grid
                .then(|| journal.sidecar(&format!("grid-{index}.png")))
                .flatten();
            let mut grid = None;
            let measured: Option<(_, Option<(String, String)>)> =
                journal.assigned_unit(&unit(format!("rotation {k}")), || {
                    let (records, picture) = under_test(&mut slot, subject, protocol)?
                        .rotation_axis(condition, k < protocol.reference_settings)?;
                    if !keep_grid {
                        return Ok((records, None));
                    }
                    if let Some(file) = &grid_file {
                        write_png(file, &picture.image, true)?;
                    }
                    let label = (picture.name.clone(), picture.caption.clone());
                    grid = Some(picture);
                    Ok((records, Some(label)))
                })?;
            // Another shard's unit.
            let Some((records, label)) = measured else {
                continue;
            };
            push(Some(records));
            // Taken from the journal: the grid is read back from its sidecar.
            if let (None, Some(file), Some((name, caption))) = (&grid, &grid_file, label) {
                grid = Some(PictureGrid {
                    name,
                    caption,
                    image: read_png(file)?,
                });
            }
            results.grids.extend(grid);
        }
        let first = Condition::new(&lights[0], [0.0; 3], &protocol.coefficient_material, 0)?;
        push(journal.assigned_unit(&unit("coefficients".into()), || {
            under_test(&mut slot, subject, protocol)?.coefficient_axis(&first)
        })?);
        for (m, brdf) in protocol.resolution_materials.iter().enumerate() {
            let condition = Condition::new(&lights[0], [0.0; 3], brdf, 0)?;
            push(journal.assigned_unit(&unit(format!("resolution {m}")), || {
                under_test(&mut slot, subject, protocol)?.resolution_axis(&condition)
            })?);
        }
        for (m, brdf) in protocol.depth_materials.iter().enumerate() {
            let condition = Condition::new(&lights[0], [0.0; 3], brdf, 0)?;
            push(journal.assigned_unit(&unit(format!("depth {m}")), || {
                under_test(&mut slot, subject, protocol)?.depth_axis(&condition)
            })?);
        }
        for (l, light) in maps.iter().enumerate() {
            for (m, brdf) in protocol.harmonics_materials.iter().enumerate() {
                let condition = Condition::new(light, [0.0; 3], brdf, 0)?;
                push(
                    journal.assigned_unit(&unit(format!("harmonics {l} {m}")), || {
                        under_test(&mut slot, subject, protocol)?.harmonics_axis(&condition)
                    })?,
                );
            }
        }
    }
    Ok(results)
}

/// The scene under test in `slot`, built on first use.
fn under_test<'s, 'a>(
    slot: &'s mut Option<SceneUnderTest<'a>>,
    subject: &'a Subject,
    protocol: &'a RelightProtocol,
) -> Result<&'s mut SceneUnderTest<'a>> {
    let scene = match slot.take() {
        Some(scene) => scene,
        None => SceneUnderTest::new(subject, protocol)?,
    };
    Ok(slot.insert(scene))
}

/// A picture grid kept beside a journal.
fn read_png(path: &Path) -> Result<image::RgbImage> {
    let image = image::open(path).map_err(|e| {
        crate::Error::from(haarshift::Error::Format {
            path: path.to_owned(),
            reason: e.to_string(),
        })
    })?;
    Ok(image.into_rgb8())
}

/// The conditions of the rotation axis under `maps`: each map under each material of the axis,
/// unrotated and seen by the first camera; then each map under the first material, rotated
/// by each further lighting rotation, and seen by the second camera.
fn rotation_conditions<'a>(
    maps: &'a [Light],
    protocol: &'a RelightProtocol,
) -> Result<Vec<Condition<'a>>> {
    let mut out = Vec::new();
    let Some(first) = protocol.rotation_materials.first() else {
        return Ok(out);
    };
    for light in maps {
        for brdf in &protocol.rotation_materials {
            out.push(Condition::new(light, [0.0; 3], brdf, 0)?);
        }
        for angles in protocol.light_rotations.iter().skip(1) {
            out.push(Condition::new(light, *angles, first, 0)?);
        }
        for camera in 1..protocol.cameras.clamp(1, 2) {
            out.push(Condition::new(light, [0.0; 3], first, camera)?);
        }
    }
    Ok(out)
}
