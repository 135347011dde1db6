//! The relighting experiment (`haarshift experiment relight`): every relighting method of the
//! library against the ray-cast ground truth, over the seeds' axes, so that a user picks a
//! method by measured error against time and memory, and the seeds' rendering claims are
//! checked.
//!
//! **Ground truth.** [`reference`](crate::relight::reference()) at `truth_resolution`
//! (`N x 2N` texels, the lighting brought there by solid-angle means): one ray per texel,
//! the BRDF evaluated analytically per texel in the vertex's own frame; no transform, no
//! rotation, no truncation. The rays are cast once per scene ([`ReferenceVisibility`]) and
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
//!   either coarse to fine (`cutoff`: the detail levels whose faces hold `C`, [`GlossyOptions::brdf_levels`])
//!   or the `faces x C` largest (`largest`, the scaling coefficients among them);
//! * `resolution` (seed 002's tables): lat-long and cube maps of several sizes times the
//!   kept ratio `r` of the lighting's and each transport's detail coefficients (and each
//!   BRDF map's), with the seconds of the precomputation and of the relighting;
//! * `depth` (seed 001 Fig. 3.5): the traversal depth, detail levels `0..d`;
//! * `harmonics`: spherical harmonics of `B` bands (`B^2` coefficients) against Haar with
//!   `B^2` lighting and `B^2` transport coefficients per vertex (equal counts), and Haar at
//!   larger budgets (to compare at equal time).
//!
//! Errors are per-vertex radiance differences, RMS and maximum over all vertices and channels
//! ([`RelativeError`]), relative to the truth's RMS radiance; `image_rms` is the same over the
//! pixels of the two renders (black background), relative to the truth image's RMS.
//! Times are wall-clock seconds on all cores: `precompute_seconds` is the transport's ray
//! casting and encoding plus the shader's preparation (truncating the transport, tables of
//! local BRDF maps), `relight_seconds` encoding the lighting and shading every vertex (BRDF
//! rotations included). `peak_mib` is the process's peak resident memory when the record was
//! made (it only grows).

use std::collections::HashMap;
use std::path::Path;
use std::time::Instant;

use ndarray::{Array2, Array3, Axis};
use serde::Serialize;

use crate::experiments::plot::labelled_colour_tiles;
use crate::faces::{ParamKind, Parameterization};
use crate::metrics::{RelativeError, rms};
use crate::product::Selection;
use crate::relight::light::environment::Environment;
use crate::relight::material::orient::BrdfRotation;
use crate::relight::shade::glossy::GlossyOptions;
use crate::relight::shade::reference::ReferenceVisibility;
use crate::relight::shade::{FrameSpec, Method, ShaderSpec, ShadingInput};
use crate::relight::{
    Brdf, ReferenceOptions, Scene, SceneBvh, ShadeOptions, TransportSet, VisibilityOptions,
    vertex_major,
};
use crate::render::view::ViewSpec;
use crate::render::{Background, Camera, LitMesh, render, to_srgb8};
use crate::sphere::SphereRotation;
use crate::{Error, PlanarImage, Result};

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
#[derive(Clone, Debug, PartialEq, Serialize)]
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
pub fn run(
    subjects: &[Subject],
    lights: &[Light],
    protocol: &RelightProtocol,
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
        let mut bench = Bench::new(subject, protocol)?;
        results
            .truth_seconds
            .push((subject.name.clone(), bench.truth_bits.report().seconds));
        let mut push = |r: RelightRecord, out: &mut Vec<RelightRecord>| {
            progress(&r);
            out.push(r);
        };
        // The first scene under every map; the others (larger, slower) under the first.
        let maps = if index == 0 {
            lights_used
        } else {
            &lights_used[..1]
        };
        for (k, setting) in rotation_settings(maps, protocol)?.iter().enumerate() {
            let (records, grid) = bench.rotation_axis(setting, k < protocol.reference_settings)?;
            records
                .into_iter()
                .for_each(|r| push(r, &mut results.records));
            if k == 0 {
                results.grids.push(grid);
            }
        }
        let first = Setting::new(&lights[0], [0.0; 3], &protocol.coefficient_material, 0)?;
        for r in bench.coefficient_axis(&first)? {
            push(r, &mut results.records);
        }
        for brdf in &protocol.resolution_materials {
            let setting = Setting::new(&lights[0], [0.0; 3], brdf, 0)?;
            for r in bench.resolution_axis(&setting)? {
                push(r, &mut results.records);
            }
        }
        for brdf in &protocol.depth_materials {
            let setting = Setting::new(&lights[0], [0.0; 3], brdf, 0)?;
            for r in bench.depth_axis(&setting)? {
                push(r, &mut results.records);
            }
        }
        for light in maps {
            for brdf in &protocol.harmonics_materials {
                let setting = Setting::new(light, [0.0; 3], brdf, 0)?;
                for r in bench.harmonics_axis(&setting)? {
                    push(r, &mut results.records);
                }
            }
        }
    }
    Ok(results)
}

/// The settings of the rotation axis under `maps`: each map under each material of the axis,
/// unrotated and seen by the first camera; then each map under the first material, rotated
/// by each further lighting rotation, and seen by the second camera.
fn rotation_settings<'a>(
    maps: &'a [Light],
    protocol: &'a RelightProtocol,
) -> Result<Vec<Setting<'a>>> {
    let mut out = Vec::new();
    let Some(first) = protocol.rotation_materials.first() else {
        return Ok(out);
    };
    for light in maps {
        for brdf in &protocol.rotation_materials {
            out.push(Setting::new(light, [0.0; 3], brdf, 0)?);
        }
        for angles in protocol.light_rotations.iter().skip(1) {
            out.push(Setting::new(light, *angles, first, 0)?);
        }
        for camera in 1..protocol.cameras.clamp(1, 2) {
            out.push(Setting::new(light, [0.0; 3], first, camera)?);
        }
    }
    Ok(out)
}

/// The lighting, its rotation, the material and the camera of a group of records.
struct Setting<'a> {
    light: &'a Light,
    angles: [f64; 3],
    rotation: SphereRotation,
    brdf: &'a Brdf,
    camera: usize,
}

impl<'a> Setting<'a> {
    fn new(light: &'a Light, angles: [f64; 3], brdf: &'a Brdf, camera: usize) -> Result<Self> {
        Ok(Setting {
            light,
            angles,
            rotation: SphereRotation::from_degrees(angles[0], angles[1], angles[2])?,
            brdf,
            camera,
        })
    }

    /// The frame of this setting seen from `eye`.
    fn frame(&self, eye: [f64; 3]) -> FrameSpec<'_> {
        FrameSpec {
            environment: &self.light.environment,
            rotation: self.rotation,
            eye: Some(eye),
        }
    }
}

/// A transport precomputed at one parameterisation, with what it cost.
struct Precomputed {
    set: TransportSet,
    seconds: f64,
}

/// What a method produced for one setting.
struct Shaded {
    radiance: Array2<f64>,
    precompute_seconds: f64,
    relight_seconds: f64,
}

/// One scene's working state: its ray-cast truth, cameras, and transports by parameterisation.
struct Bench<'a> {
    subject: &'a Subject,
    protocol: &'a RelightProtocol,
    bvh: SceneBvh,
    cameras: [Camera; 2],
    truth_bits: ReferenceVisibility,
    truths: HashMap<String, Array2<f64>>,
    truth_renders: HashMap<String, PlanarImage<f32>>,
    transports: HashMap<(ParamKind, usize, bool), Precomputed>,
}

impl<'a> Bench<'a> {
    fn new(subject: &'a Subject, protocol: &'a RelightProtocol) -> Result<Self> {
        let scene = &subject.scene;
        let bvh = SceneBvh::new(&scene.mesh);
        let first = ViewSpec::default().camera(scene.camera.as_ref(), &scene.mesh)?;
        let cameras = [first, first.orbited(SECOND_CAMERA)?];
        let truth_bits =
            ReferenceVisibility::new(&scene.mesh, &bvh, protocol.truth_resolution, true)?;
        Ok(Bench {
            subject,
            protocol,
            bvh,
            cameras,
            truth_bits,
            truths: HashMap::new(),
            truth_renders: HashMap::new(),
            transports: HashMap::new(),
        })
    }

    fn eye(&self, setting: &Setting<'_>) -> [f64; 3] {
        self.cameras[setting.camera].position()
    }

    /// The ground truth of `setting` (cached: Lambert does not depend on the camera).
    fn truth(&mut self, setting: &Setting<'_>) -> Result<Array2<f64>> {
        let camera = if setting.brdf.is_lambert() {
            0
        } else {
            setting.camera
        };
        let key = format!(
            "{}/{:?}/{}/{camera}",
            setting.light.name, setting.angles, setting.brdf
        );
        if let Some(t) = self.truths.get(&key) {
            return Ok(t.clone());
        }
        let scene = &self.subject.scene;
        let lighting = setting
            .light
            .environment
            .lat_long(self.protocol.truth_resolution, &setting.rotation)?;
        let options = ReferenceOptions {
            progress: false,
            brdf: setting.brdf.clone(),
            eye: Some(self.cameras[camera].position()),
            object_vertices: Some(scene.object_vertices()),
        };
        let (truth, _) =
            self.truth_bits
                .reference(&scene.mesh, scene.albedo.view(), &lighting, &options)?;
        self.truths.insert(key, truth.clone());
        Ok(truth)
    }

    /// The transport at `kind` `n` (with `sh` bands of spherical harmonics beside it when
    /// asked), precomputed once.
    fn transport(&mut self, kind: ParamKind, n: usize, sh: bool) -> Result<&Precomputed> {
        let key = (kind, n, sh);
        if !self.transports.contains_key(&key) {
            let param = Parameterization::new(kind, n)?;
            let mut options = VisibilityOptions::new(param);
            options.sh_bands = sh
                .then(|| self.protocol.sh_bands.iter().copied().max())
                .flatten();
            let start = Instant::now();
            let (set, _) = vertex_major(&self.subject.scene.mesh, &self.bvh, &options)?;
            let seconds = start.elapsed().as_secs_f64();
            self.transports.insert(key, Precomputed { set, seconds });
        }
        Ok(&self.transports[&key])
    }

    /// Haar relighting of `setting` at `kind` `n`: the lighting kept by `light`, the shading
    /// options `shade`, and for a glossy material the BRDF brought into each frame by `glossy`.
    fn haar(
        &mut self,
        setting: &Setting<'_>,
        (kind, n): (ParamKind, usize),
        light: Selection,
        shade: &ShadeOptions,
        glossy: &GlossyOptions,
    ) -> Result<(Shaded, usize)> {
        let eye = self.eye(setting);
        let subject: &'a Subject = self.subject;
        let scene = &subject.scene;
        let precomputed = self.transport(kind, n, false)?;
        let set = &precomputed.set;
        let spec = ShaderSpec {
            material: glossy.for_brdf(&setting.brdf),
            shade: *shade,
            keep_light: light,
            ..ShaderSpec::default()
        };
        let input = ShadingInput::new(
            &scene.mesh,
            scene.albedo.view(),
            Some(set),
            scene.object_vertices(),
        );
        let mut shader = spec.build(&input)?;
        let shading = shader.shade(&setting.frame(eye))?;
        Ok((
            Shaded {
                radiance: shading.radiance.to_f64(),
                precompute_seconds: precomputed.seconds + shader.preparation().seconds,
                relight_seconds: shading.timing.total_seconds(),
            },
            shading.light_coefficients.unwrap_or(0),
        ))
    }

    /// A record of `shaded` against the truth of `setting`, with the render's image error.
    fn record(
        &mut self,
        axis: &str,
        setting: &Setting<'_>,
        shaded: &Shaded,
        param: Parameterization,
    ) -> Result<RelightRecord> {
        let truth = self.truth(setting)?;
        let error = RelativeError::between(shaded.radiance.view(), truth.view())?;
        let camera = &self.cameras[setting.camera];
        let (w, h) = self.protocol.image;
        let black = Background::Colour([0.0; 3]);
        let got = draw(&self.subject.scene, camera, (w, h), &shaded.radiance, black)?;
        // The truth's render, once per setting and camera.
        let key = format!(
            "{}/{:?}/{}/{}",
            setting.light.name, setting.angles, setting.brdf, setting.camera
        );
        if !self.truth_renders.contains_key(&key) {
            let image = draw(&self.subject.scene, camera, (w, h), &truth, black)?;
            self.truth_renders.insert(key.clone(), image);
        }
        let want = &self.truth_renders[&key];
        let image_rms = RelativeError::between(
            got.planes()
                .view()
                .into_shape_with_order((3 * h, w))
                .expect("contiguous"),
            want.planes()
                .view()
                .into_shape_with_order((3 * h, w))
                .expect("contiguous"),
        )?
        .rms_relative;
        Ok(RelightRecord {
            axis: axis.into(),
            scene: self.subject.name.clone(),
            vertices: self.subject.scene.mesh.vertex_count(),
            envmap: setting.light.name.clone(),
            light_rotation: format!(
                "{}/{}/{}",
                setting.angles[0], setting.angles[1], setting.angles[2]
            ),
            material: setting.brdf.to_string(),
            camera: setting.camera,
            method: "haar".into(),
            parameters: String::new(),
            param: param.kind().to_string(),
            resolution: param.face_size(),
            level: None,
            kept_ratio: None,
            light_coefficients: param.texels(),
            brdf_coefficients: None,
            depth: param.face_size().trailing_zeros() as usize,
            sh_bands: None,
            rms_relative: error.rms_relative,
            max_relative: error.max_relative,
            rms: error.rms,
            max: error.max,
            image_rms,
            spatial_difference: None,
            precompute_seconds: shaded.precompute_seconds,
            relight_seconds: shaded.relight_seconds,
            peak_mib: crate::memory::peak_resident_bytes().unwrap_or(0) as f64
                / (1u64 << 20) as f64,
        })
    }

    /// Thesis Figs. 4.5-4.6: every orienting method (`reference` only `with_reference`),
    /// every coefficient kept; and the picture grid of this setting.
    fn rotation_axis(
        &mut self,
        setting: &Setting<'_>,
        with_reference: bool,
    ) -> Result<(Vec<RelightRecord>, PictureGrid)> {
        let n = self.protocol.rotation_resolution;
        let param = Parameterization::new(ParamKind::LatLong, n)?;
        let mut shaded = Vec::new();
        for o in &self.protocol.orientings.clone() {
            if o.rotation == BrdfRotation::Reference && !with_reference {
                continue;
            }
            let glossy = GlossyOptions {
                rotation: o.rotation,
                level: o.level,
                ..GlossyOptions::default()
            };
            let (s, kept) = self.haar(
                setting,
                (ParamKind::LatLong, n),
                Selection::All,
                &ShadeOptions::default(),
                &glossy,
            )?;
            let mut r = self.record("rotation", setting, &s, param)?;
            r.method = o.rotation.to_string();
            r.level = o.level;
            r.light_coefficients = kept;
            r.parameters = match o.level {
                Some(l) => format!("level {l} (thesis {})", l + 1),
                None => "finest level".into(),
            };
            shaded.push((r, s));
        }
        let spatial = shaded
            .iter()
            .find(|(r, _)| r.method == BrdfRotation::Spatial.to_string())
            .map(|(_, s)| s.radiance.clone());
        let truth = self.truth(setting)?;
        if let Some(spatial) = &spatial {
            // Relative to the truth's RMS, as every other figure.
            let scale = rms(truth.view());
            for (r, s) in &mut shaded {
                r.spatial_difference = Some(rms((&s.radiance - spatial).view()) / scale);
            }
        }
        let grid = self.grid(setting, &shaded, &truth)?;
        Ok((shaded.into_iter().map(|(r, _)| r).collect(), grid))
    }

    /// Thesis Fig. 4.7: the rotated BRDF cut coarse to fine or to its largest coefficients.
    fn coefficient_axis(&mut self, setting: &Setting<'_>) -> Result<Vec<RelightRecord>> {
        let n = self.protocol.rotation_resolution;
        let param = Parameterization::new(ParamKind::LatLong, n)?;
        let levels = n.trailing_zeros() as usize;
        let mut out = Vec::new();
        let mut cuts: Vec<(String, Option<usize>, GlossyOptions)> = Vec::new();
        for &c in &self.protocol.coefficient_counts {
            let l = (c.trailing_zeros() / 2) as usize;
            if 4usize.pow(l as u32) != c || l > levels {
                return Err(Error::parameter(
                    "coefficient counts",
                    format!("{c}: expected a power of 4 up to {}", n * n),
                ));
            }
            cuts.push((
                format!("cutoff {c}/face"),
                Some(c),
                GlossyOptions {
                    brdf_levels: Some(l),
                    ..GlossyOptions::default()
                },
            ));
            cuts.push((
                format!("largest {c}/face"),
                Some(c),
                GlossyOptions {
                    keep_brdf: Some((c - 1) * param.faces()),
                    ..GlossyOptions::default()
                },
            ));
        }
        cuts.push(("every coefficient".into(), None, GlossyOptions::default()));
        for (label, count, glossy) in cuts {
            let (s, kept) = self.haar(
                setting,
                (ParamKind::LatLong, n),
                Selection::All,
                &ShadeOptions::default(),
                &glossy,
            )?;
            let mut r = self.record("coefficients", setting, &s, param)?;
            r.parameters = label;
            r.brdf_coefficients = count;
            r.light_coefficients = kept;
            out.push(r);
        }
        Ok(out)
    }

    /// Seed 002's tables: map resolution times kept ratio, time per stage.
    fn resolution_axis(&mut self, setting: &Setting<'_>) -> Result<Vec<RelightRecord>> {
        let sizes: Vec<(ParamKind, usize)> = (self.protocol.latlong_resolutions.iter())
            .map(|&n| (ParamKind::LatLong, n))
            .chain(
                self.protocol
                    .cube_resolutions
                    .iter()
                    .map(|&n| (ParamKind::Cube, n)),
            )
            .collect();
        let mut out = Vec::new();
        for (kind, n) in sizes {
            let param = Parameterization::new(kind, n)?;
            if kind == ParamKind::LatLong {
                out.push(self.quadrature_floor(setting, param)?);
            }
            // The thesis's rotation is lat-long only: cube maps take the exact lobe.
            let rotation = match kind {
                ParamKind::LatLong => BrdfRotation::Haar,
                ParamKind::Cube => BrdfRotation::Direct,
            };
            for &ratio in &self.protocol.ratios.clone() {
                let keep = kept_details(param, ratio);
                let select = keep.map_or(Selection::All, Selection::Largest);
                let shade = ShadeOptions {
                    keep_visibility: keep.map(Selection::Largest),
                    depth: None,
                };
                let glossy = GlossyOptions {
                    rotation,
                    keep_brdf: keep,
                    ..GlossyOptions::default()
                };
                let (s, kept) = self.haar(setting, (kind, n), select, &shade, &glossy)?;
                let mut r = self.record("resolution", setting, &s, param)?;
                r.kept_ratio = Some(ratio);
                r.light_coefficients = kept;
                r.brdf_coefficients = (!setting.brdf.is_lambert())
                    .then(|| keep.map(|k| k + param.faces()))
                    .flatten();
                r.method = if setting.brdf.is_lambert() {
                    "haar".into()
                } else {
                    rotation.to_string()
                };
                r.parameters = format!("ratio {ratio}");
                out.push(r);
            }
        }
        Ok(out)
    }

    /// The floor a resolution sets: the reference quadrature itself at lat-long `param`
    /// (rays cast at that resolution, no transform, no truncation). At the truth's
    /// resolution it is the truth.
    fn quadrature_floor(
        &mut self,
        setting: &Setting<'_>,
        param: Parameterization,
    ) -> Result<RelightRecord> {
        let scene = &self.subject.scene;
        let n = param.face_size();
        let start = Instant::now();
        let bits = ReferenceVisibility::new(&scene.mesh, &self.bvh, n, false)?;
        let precompute_seconds = start.elapsed().as_secs_f64();
        let start = Instant::now();
        let lighting = setting.light.environment.lat_long(n, &setting.rotation)?;
        let options = ReferenceOptions {
            progress: false,
            brdf: setting.brdf.clone(),
            eye: Some(self.eye(setting)),
            object_vertices: Some(scene.object_vertices()),
        };
        let (radiance, _) =
            bits.reference(&scene.mesh, scene.albedo.view(), &lighting, &options)?;
        let shaded = Shaded {
            radiance,
            precompute_seconds,
            relight_seconds: start.elapsed().as_secs_f64(),
        };
        let mut r = self.record("resolution", setting, &shaded, param)?;
        r.method = "reference".into();
        r.parameters = "quadrature".into();
        Ok(r)
    }

    /// Seed 001 Fig. 3.5: the traversal depth.
    fn depth_axis(&mut self, setting: &Setting<'_>) -> Result<Vec<RelightRecord>> {
        let n = self.protocol.depth_resolution;
        let param = Parameterization::new(ParamKind::LatLong, n)?;
        let mut out = Vec::new();
        for depth in 1..=n.trailing_zeros() as usize {
            let shade = ShadeOptions {
                keep_visibility: None,
                depth: Some(depth),
            };
            let (s, kept) = self.haar(
                setting,
                (ParamKind::LatLong, n),
                Selection::All,
                &shade,
                &GlossyOptions::default(),
            )?;
            let mut r = self.record("depth", setting, &s, param)?;
            r.depth = depth;
            r.light_coefficients = kept;
            r.parameters = format!("depth {depth}");
            out.push(r);
        }
        Ok(out)
    }

    /// Haar against spherical harmonics at equal coefficient counts, and Haar at larger
    /// budgets.
    fn harmonics_axis(&mut self, setting: &Setting<'_>) -> Result<Vec<RelightRecord>> {
        let n = self.protocol.harmonics_resolution;
        let param = Parameterization::new(ParamKind::LatLong, n)?;
        let mut out = Vec::new();
        let eye = self.eye(setting);
        let subject: &'a Subject = self.subject;
        for &bands in &self.protocol.sh_bands.clone() {
            let precomputed = self.transport(ParamKind::LatLong, n, true)?;
            let seconds = precomputed.seconds;
            let scene = &subject.scene;
            let spec = ShaderSpec {
                method: Method::Sh,
                material: GlossyOptions {
                    brdf: setting.brdf.clone(),
                    ..GlossyOptions::default()
                },
                sh_bands: Some(bands),
                ..ShaderSpec::default()
            };
            let input = ShadingInput::new(
                &scene.mesh,
                scene.albedo.view(),
                Some(&precomputed.set),
                scene.object_vertices(),
            );
            let shading = spec.build(&input)?.shade(&setting.frame(eye))?;
            let shaded = Shaded {
                radiance: shading.radiance.to_f64(),
                precompute_seconds: seconds,
                relight_seconds: shading.timing.total_seconds(),
            };
            let mut r = self.record("harmonics", setting, &shaded, param)?;
            r.method = "sh".into();
            r.sh_bands = Some(bands);
            r.light_coefficients = bands * bands;
            r.parameters = format!("{bands} bands");
            out.push(r);
        }
        let mut budgets: Vec<usize> = self.protocol.sh_bands.iter().map(|b| b * b).collect();
        budgets.extend(&self.protocol.haar_budgets);
        for count in budgets {
            if count < param.faces() || count > param.texels() {
                continue;
            }
            let keep = Selection::Largest(count - param.faces());
            let shade = ShadeOptions {
                keep_visibility: Some(keep),
                depth: None,
            };
            let glossy = GlossyOptions {
                keep_brdf: Some(count - param.faces()),
                ..GlossyOptions::default()
            };
            let (s, kept) = self.haar(setting, (ParamKind::LatLong, n), keep, &shade, &glossy)?;
            let mut r = self.record("harmonics", setting, &s, param)?;
            r.light_coefficients = kept;
            r.brdf_coefficients = (!setting.brdf.is_lambert()).then_some(count);
            r.parameters = format!("{count} coefficients");
            out.push(r);
        }
        Ok(out)
    }

    /// The renders of the rotation axis over their false-colour error images, and the truth
    /// over a blank.
    fn grid(
        &self,
        setting: &Setting<'_>,
        shaded: &[(RelightRecord, Shaded)],
        truth: &Array2<f64>,
    ) -> Result<PictureGrid> {
        let scene = &self.subject.scene;
        let camera = &self.cameras[setting.camera];
        let size = self.protocol.image;
        let backdrop = setting.light.environment.lat_long(
            setting.light.environment.map().height().min(512),
            &setting.rotation,
        )?;
        let background = Background::Environment(&backdrop);
        let exposure = crate::relight::gallery::exposure_for(truth);
        let black = Background::Colour([0.0; 3]);
        let want = luminance(&draw(scene, camera, size, truth, black)?);
        let mut errors = Vec::new();
        for (_, s) in shaded {
            let got = luminance(&draw(scene, camera, size, &s.radiance, black)?);
            errors.push(&got - &want);
        }
        // One scale for the whole grid: the 99th percentile of |error| over every tile, so
        // that the colours compare across methods.
        let mut all: Vec<f64> = errors.iter().flatten().map(|e| e.abs()).collect();
        all.sort_by(f64::total_cmp);
        let scale = all
            .get(all.len() * 99 / 100)
            .copied()
            .filter(|&v| v > 0.0)
            .unwrap_or(1.0);
        let mut tiles: Vec<(String, Array3<f64>)> = Vec::new();
        for (r, s) in shaded {
            let image = to_srgb8(
                &draw(scene, camera, size, &s.radiance, background)?,
                exposure,
            )?;
            tiles.push((
                format!("{} {}: {:.1e}", r.method, r.parameters, r.rms_relative),
                image.planes().mapv(f64::from),
            ));
        }
        let image = to_srgb8(&draw(scene, camera, size, truth, background)?, exposure)?;
        tiles.push(("truth".into(), image.planes().mapv(f64::from)));
        for (e, (r, _)) in errors.iter().zip(shaded) {
            tiles.push((
                format!("error of {} {}", r.method, r.parameters),
                false_colour(e, scale),
            ));
        }
        let (h, w) = want.dim();
        let bar = Array2::from_shape_fn((h, w), |(_, j)| scale * (2.0 * j as f64 / w as f64 - 1.0));
        tiles.push((
            format!("scale: -{scale:.1e} to +{scale:.1e}"),
            false_colour(&bar, scale),
        ));
        let views: Vec<(String, ndarray::ArrayView3<'_, f64>)> =
            tiles.iter().map(|(l, t)| (l.clone(), t.view())).collect();
        let image = labelled_colour_tiles(&views, shaded.len() + 1, 1)?;
        Ok(PictureGrid {
            name: format!(
                "{}-{}-{}",
                self.subject.name, setting.light.name, setting.brdf
            )
            .replace(':', ""),
            caption: format!(
                "{} under {} ({}), {}, camera {}: top, each rotation method's render and the \
                 truth; below each, the luminance error (blue: too dark, red: too bright, \
                 white: none; saturated at +-{scale:.2e}, the 99th percentile of every tile)",
                self.subject.name,
                setting.light.name,
                format_angles(setting.angles),
                setting.brdf,
                setting.camera
            ),
            image,
        })
    }
}

fn format_angles(a: [f64; 3]) -> String {
    format!("yaw {} pitch {} roll {}", a[0], a[1], a[2])
}

/// The detail coefficients a kept ratio leaves of `param`'s (`None`: ratio 1, all).
fn kept_details(param: Parameterization, ratio: f64) -> Option<usize> {
    let details = param.texels() - param.faces();
    (ratio < 1.0).then(|| ((ratio * details as f64).round() as usize).clamp(1, details))
}

/// `radiance` (`(V, 3)`) drawn by `camera`, linear.
fn draw(
    scene: &Scene,
    camera: &Camera,
    (width, height): (usize, usize),
    radiance: &Array2<f64>,
    background: Background<'_>,
) -> Result<PlanarImage<f32>> {
    let radiance = radiance.mapv(|v| v as f32);
    let mesh = LitMesh {
        positions: scene.mesh.positions(),
        triangles: scene.mesh.triangles(),
        radiance: radiance.view(),
    };
    render(camera, width, height, &mesh, background)
}

/// Rec. 709 luminance of a linear RGB image.
fn luminance(image: &PlanarImage<f32>) -> Array2<f64> {
    let p = image.planes();
    let lum = |c: usize| p.index_axis(Axis(0), c).mapv(f64::from);
    lum(0) * 0.2126 + lum(1) * 0.7152 + lum(2) * 0.0722
}

/// A diverging false colour, `(3, H, W)` in 0..=255: blue for `-scale`, white for 0, red for
/// `+scale`, saturated beyond.
fn false_colour(error: &Array2<f64>, scale: f64) -> Array3<f64> {
    let (h, w) = error.dim();
    Array3::from_shape_fn((3, h, w), |(c, i, j)| {
        let t = (error[[i, j]] / scale).clamp(-1.0, 1.0);
        let v = match (c, t >= 0.0) {
            (0, true) | (2, false) => 1.0,
            _ => 1.0 - t.abs(),
        };
        255.0 * v
    })
}

pub mod report;

#[cfg(test)]
mod tests;
