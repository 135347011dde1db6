//! Dynamic scenes (Sun 2006 chapter 3): rigid objects that move, scale, turn about the
//! vertical and are cloned at run time, each shadowing the others through its
//! [occlusion field](crate::relight::dynamic::fields), shaded by n-function product integrals and by
//! just-in-time radiance transfer ([`JustInTimeTransfer`]).
//!
//! **What is computed.** A Lambertian vertex `v` of albedo `a` reflects
//! `B_v = a / pi x integral of T_v x L x prod_(k != own) O_k`, Sun 2006 eq. 3.1-3.3 with the
//! BRDF constant: `T_v` the vertex's own transport (its object's self-visibility, the ground
//! plane's occlusion where the scene has one, cosine and solid angle; [`TransportSet`](crate::relight::precompute::transport::TransportSet)
//! semantics), `L` the lighting, `O_k` object `k`'s occlusion looked up at the vertex
//! ([`OcclusionField::lookup`], with the options' [`Truncation`]); a vertex beyond an object's
//! outermost shell takes `O_k = 1`. Each factor is truncated as the options say (the lighting
//! by the caller's [`Lighting`]) and, with a `depth`, all factors are limited to the detail
//! levels `0..depth` (Sun 2006 Fig. 3.5's traversal depth: every factor is then constant on
//! blocks of side `S >> depth`, and so is their product).
//!
//! **Glossy materials** (a scene file's `phong` or `blinn` [`Material`](crate::relight::Material), or
//! [`DynamicScene::set_brdf`]): the BRDF in the vertex's frame, seen from the
//! [eye](DynamicScene::eye), is one more factor, `B_v = a x integral of T_v x L x prod O_k x
//! rho_v`, `rho_v` the lobe of [`Orientation::lobe`] (by [`GlossyOptions::rotation`], in the
//! vertex's exact frame) in Haar coefficients; [`reference`](DynamicScene::reference) evaluates
//! the BRDF analytically per texel. The ground plane stays Lambertian.
//!
//! **Own transport and the ground.** An object's `T_v` is precomputed at its placement in the
//! scene file, against itself and the ground plane (when the scene has one), exactly as
//! [`vertex_major`] does for a static scene. Moving the object keeps it; turning it by `k`
//! columns turns it ([`yaw_sparse`]). The ground's own transport sees the whole upper
//! hemisphere; objects shadow it through their planar fields. So one object alone at its
//! file placement, without a ground plane, is shaded exactly as the static path shades it
//! (tested); with a ground plane, moving an object keeps the ground's occlusion of it as it
//! was (exact for a plane much larger than the move; the experiment measures it).
//!
//! **Placements** ([`Placement`]): world `= Ry(turn) (s x local) + t`. An object turns about
//! the vertical by whole columns of a lat-long parameterisation (`360 / 2N` degrees; a file's
//! yaw is rounded to the nearest column and the rounded angle is the scene's, reference
//! included); a cube map cannot turn (refused). Pitch and roll are refused: an occlusion
//! field turns exactly about the vertical only (Sun 2006 cannot turn objects at all).
//!
//! **Shapes and clones.** Objects with the same mesh file or generator share one shape: one
//! set of fields (Sun 2006's instancing); [`DynamicScene::clone_object`] adds an instance of an
//! object's shape at run time, whose own transport is the original's.

use std::path::Path;
use std::sync::Arc;
use std::time::Instant;

use ndarray::Array2;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use crate::faces::integrate::layout;
use crate::faces::param::{ParamKind, Parameterization};
use crate::product::multiply::product;
use crate::product::selection::Candidate;
use crate::product::{HaarTree, IntegralOptions, Selection, Transport, product_integral};
use crate::relight::dynamic::fields::file::{FieldOrigin, FieldStore};
use crate::relight::dynamic::fields::{
    Blend, FieldOptions, OcclusionField, Truncation, select_rows, yaw_sparse,
};
use crate::relight::light::lighting::Lighting;
use crate::relight::material::brdf::Brdf;
use crate::relight::material::orient::Orientation;
use crate::relight::precompute::sparse::SparseRows;
use crate::relight::precompute::visibility::{VisibilityOptions, ray_offset, vertex_major};
use crate::relight::scene::{
    CameraSpec, EnvironmentSpec, SceneFile, Transform, ground_plane_under, merge,
};
use crate::relight::shade::glossy::GlossyOptions;
use crate::relight::shade::reference::ReferenceVisibility;
use crate::relight::shade::{select_kept, within_depth};
use crate::relight::{Mesh, ReferenceOptions, SceneBvh, SceneError};
use crate::sphere::{LatLongMap, SphereRotation};
use crate::{Error, Result, Sample};

/// How a dynamic scene is precomputed and shaded; see the [module docs](self).
///
/// ```
/// use haarshift::relight::dynamic::DynamicOptions;
/// use haarshift::faces::{ParamKind, Parameterization};
/// let o = DynamicOptions::new(Parameterization::new(ParamKind::LatLong, 32).unwrap());
/// assert_eq!(o.field.samples(), 29_720); // Sun 2006's fields
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DynamicOptions {
    /// The occlusion fields; their parameterisation is the scene's.
    pub field: FieldOptions,
    /// What each vertex's own transport keeps.
    pub keep_visibility: Selection,
    /// Truncation of looked-up occlusion maps.
    pub truncation: Truncation,
    /// What just-in-time radiance transfer keeps of each vertex's fixed product.
    pub keep_product: Selection,
    /// Detail levels taking part, `0..=log2 S` (`None`: all).
    pub depth: Option<usize>,
    /// Progress bars on standard error.
    pub progress: bool,
}

impl DynamicOptions {
    /// Sun 2006's fields, everything kept, every level.
    pub fn new(param: Parameterization) -> Self {
        DynamicOptions {
            field: FieldOptions::new(param),
            keep_visibility: Selection::All,
            truncation: Truncation::Before,
            keep_product: Selection::All,
            depth: None,
            progress: false,
        }
    }

    /// The parameterisation of every map.
    pub fn param(&self) -> Parameterization {
        self.field.param
    }

    /// The options of `budgets`: the fields' sample counts and every truncation, as
    /// `relight scene` and `haarshift.relight.scene` take them.
    ///
    /// ```
    /// use haarshift::product::Selection;
    /// use haarshift::relight::dynamic::{DynamicBudgets, DynamicOptions};
    /// use haarshift::relight::dynamic::fields::Truncation;
    /// use haarshift::faces::{ParamKind, Parameterization};
    /// let param = Parameterization::new(ParamKind::LatLong, 16).unwrap();
    /// let budgets = DynamicBudgets { keep_field: Some(40), truncate_after: true, ..DynamicBudgets::new(param) };
    /// let o = DynamicOptions::from_budgets(&budgets);
    /// assert_eq!((o.field.keep, o.truncation), (Selection::Largest(40), Truncation::After(Selection::Largest(40))));
    /// assert_eq!(DynamicOptions::from_budgets(&DynamicBudgets::new(param)), DynamicOptions::new(param));
    /// ```
    pub fn from_budgets(budgets: &DynamicBudgets) -> Self {
        let largest = |k: Option<usize>| k.map_or(Selection::All, Selection::Largest);
        DynamicOptions {
            field: FieldOptions {
                keep: largest(budgets.keep_field),
                circles: budgets.circles,
                circle_points: budgets.circle_points,
                shells: budgets.shells,
                shell_grid: budgets.shell_grid,
                progress: budgets.progress,
                ..FieldOptions::new(budgets.param)
            },
            keep_visibility: largest(budgets.keep_visibility),
            truncation: if budgets.truncate_after {
                Truncation::After(largest(budgets.keep_field))
            } else {
                Truncation::Before
            },
            keep_product: largest(budgets.keep_product),
            depth: budgets.depth,
            progress: budgets.progress,
        }
    }

    fn check(&self) -> Result<usize> {
        let p = self.param();
        let details = p.texels() - p.faces();
        self.keep_visibility.limit(details)?;
        self.keep_product.limit(details)?;
        if let Truncation::After(keep) = self.truncation {
            keep.limit(details)?;
        }
        let levels = p.face_size().trailing_zeros() as usize;
        match self.depth {
            Some(d) if d > levels => Err(Error::parameter(
                "depth",
                format!(
                    "{d}: faces of side {} have detail levels 0 to {levels}",
                    p.face_size()
                ),
            )),
            Some(d) => Ok(d),
            None => Ok(levels),
        }
    }
}

/// A dynamic scene's budgets as a caller states them: the fields' parameterisation and sample
/// counts, and how many detail coefficients each factor keeps (`None`: all);
/// [`DynamicOptions::from_budgets`] makes the options.
///
/// ```
/// use haarshift::relight::dynamic::DynamicBudgets;
/// use haarshift::faces::{ParamKind, Parameterization};
/// let b = DynamicBudgets::new(Parameterization::new(ParamKind::LatLong, 32).unwrap());
/// assert_eq!((b.circles, b.circle_points, b.shells, b.shell_grid), (100, 200, 20, 9));
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DynamicBudgets {
    /// Every map's parameterisation.
    pub param: Parameterization,
    /// Detail coefficients of each vertex's own transport.
    pub keep_visibility: Option<usize>,
    /// Detail coefficients of each occlusion map.
    pub keep_field: Option<usize>,
    /// Detail coefficients of each vertex's fixed product (animations).
    pub keep_product: Option<usize>,
    /// Truncate looked-up occlusion maps after blending them (to `keep_field`), not before.
    pub truncate_after: bool,
    /// Detail levels taking part, `0..D` (`None`: all).
    pub depth: Option<usize>,
    /// Circles of the planar field.
    pub circles: usize,
    /// Points per circle.
    pub circle_points: usize,
    /// Shells of the spherical field.
    pub shells: usize,
    /// Points per face edge of each shell's cube grid.
    pub shell_grid: usize,
    /// Progress bars on standard error.
    pub progress: bool,
}

impl DynamicBudgets {
    /// Sun 2006's fields in `param`, everything kept.
    pub fn new(param: Parameterization) -> Self {
        let f = FieldOptions::new(param);
        DynamicBudgets {
            param,
            keep_visibility: None,
            keep_field: None,
            keep_product: None,
            truncate_after: false,
            depth: None,
            circles: f.circles,
            circle_points: f.circle_points,
            shells: f.shells,
            shell_grid: f.shell_grid,
            progress: false,
        }
    }
}

/// Where an object is: world `= Ry(turn) (scale x local) + translate`; see the
/// [module docs](self).
///
/// ```
/// use haarshift::relight::dynamic::Placement;
/// use haarshift::relight::Transform;
/// use haarshift::faces::{ParamKind, Parameterization};
/// let param = Parameterization::new(ParamKind::LatLong, 32).unwrap(); // 64 columns
/// let t = Transform { yaw: 92.0, translate: [1.0, 0.0, 0.0], ..Transform::default() };
/// let p = Placement::from_transform(&t, param).unwrap();
/// assert_eq!(p.turn, 16); // 92 degrees is 16.4 columns of 5.625 degrees
/// let w = p.to_world([0.0, 0.0, 1.0], param);
/// assert!((w[0] - 2.0).abs() < 1e-12 && w[2].abs() < 1e-12); // +Z turned to +X, moved
/// assert!((p.to_local(w, param)[2] - 1.0).abs() < 1e-12);
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Placement {
    /// Added last.
    pub translate: [f64; 3],
    /// Uniform scale, applied first (positive).
    pub scale: f64,
    /// Whole columns of the lat-long parameterisation turned about +Y.
    pub turn: usize,
}

impl Placement {
    /// The placement of a scene file's transform, its yaw rounded to whole columns.
    pub fn from_transform(t: &Transform, param: Parameterization) -> Result<Self> {
        if t.pitch != 0.0 || t.roll != 0.0 {
            return Err(SceneError::SceneFile(format!(
                "pitch {} and roll {}: a dynamic object turns about the vertical only (yaw)",
                t.pitch, t.roll
            ))
            .into());
        }
        if !(t.scale.is_finite() && t.scale > 0.0) || t.translate.iter().any(|x| !x.is_finite()) {
            return Err(SceneError::SceneFile(format!(
                "scale {} and translate {:?}: the scale must be positive and finite, the \
                 translation finite",
                t.scale, t.translate
            ))
            .into());
        }
        Ok(Placement {
            translate: t.translate,
            scale: t.scale,
            turn: turn_columns(t.yaw, param)?,
        })
    }

    /// The turn in degrees.
    pub fn yaw_degrees(&self, param: Parameterization) -> f64 {
        self.turn as f64 * 360.0 / columns(param) as f64
    }

    fn rotation(&self, param: Parameterization) -> SphereRotation {
        SphereRotation::from_degrees(self.yaw_degrees(param), 0.0, 0.0)
            .expect("a whole number of columns is a finite angle")
    }

    /// A point of the object's own frame in the world.
    pub fn to_world(&self, p: [f64; 3], param: Parameterization) -> [f64; 3] {
        let q = self.rotation(param).apply(p.map(|x| x * self.scale));
        std::array::from_fn(|k| q[k] + self.translate[k])
    }

    /// A world point in the object's own frame.
    pub fn to_local(&self, p: [f64; 3], param: Parameterization) -> [f64; 3] {
        let d = std::array::from_fn(|k| p[k] - self.translate[k]);
        self.rotation(param)
            .inverse()
            .apply(d)
            .map(|x| x / self.scale)
    }

    /// As a scene file's transform.
    pub fn transform(&self, param: Parameterization) -> Transform {
        Transform {
            translate: self.translate,
            scale: self.scale,
            yaw: self.yaw_degrees(param),
            ..Transform::default()
        }
    }
}

/// Columns of a lat-long map of `param`'s size (`2N`).
fn columns(param: Parameterization) -> usize {
    2 * param.face_size()
}

/// A yaw in degrees as whole columns, `0..2N`; a cube map takes no turn.
fn turn_columns(yaw: f64, param: Parameterization) -> Result<usize> {
    if !yaw.is_finite() || yaw.abs() > 1e6 {
        return Err(Error::parameter(
            "yaw",
            format!("{yaw} degrees is not a finite angle of at most 1e6 degrees"),
        ));
    }
    let w = columns(param) as f64;
    let k = (yaw / 360.0 * w).round().rem_euclid(w) as usize;
    if param.kind() == ParamKind::Cube && k != 0 {
        return Err(Error::parameter(
            "yaw",
            format!("{yaw} degrees: turning an object's occlusion field needs --param latlong"),
        ));
    }
    Ok(k)
}

/// One object of a dynamic scene.
#[derive(Clone, Debug)]
struct Object {
    name: Option<String>,
    shape: usize,
    /// Where its own transport was computed.
    rest: Placement,
    placement: Placement,
    albedo: [f32; 3],
    /// Its material's BRDF, with the orientation that brings it into vertex frames (`None`:
    /// Lambertian).
    brdf: Brdf,
    orientation: Option<Arc<Orientation>>,
    transport: Arc<SparseRows<f32>>,
    /// The shape's field turned to the placement.
    field: Arc<OcclusionField>,
}

/// What building a dynamic scene did.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct BuildReport {
    /// Rays cast for the occlusion fields, all shapes.
    pub field_rays: u64,
    /// Seconds building the fields.
    pub field_seconds: f64,
    /// Bytes of the stored field maps.
    pub field_bytes: usize,
    /// Shapes whose fields were read from a field file.
    pub fields_loaded: usize,
    /// Field files written (shapes whose file was absent or replaced).
    pub fields_written: usize,
    /// Bytes of the field files read or written.
    pub field_file_bytes: u64,
    /// Seconds reading and checking field files.
    pub field_load_seconds: f64,
    /// Rays cast for the vertices' own transport.
    pub transport_rays: u64,
    /// Seconds precomputing the own transport.
    pub transport_seconds: f64,
}

/// A scene of rigid objects with occlusion fields; see the [module docs](self).
///
/// ```
/// use haarshift::relight::dynamic::{DynamicOptions, DynamicScene};
/// use haarshift::relight::SceneFile;
/// use haarshift::faces::{ParamKind, Parameterization};
/// let file: SceneFile = serde_json::from_str(r#"{"objects": [
///     {"name": "a", "generator": {"sphere": {"cells": 2}}},
///     {"name": "b", "generator": {"sphere": {"cells": 2}}, "transform": {"translate": [3, 0, 0]}}
///   ], "ground_plane": true}"#).unwrap();
/// let mut options = DynamicOptions::new(Parameterization::new(ParamKind::LatLong, 8).unwrap());
/// (options.field.circles, options.field.circle_points) = (8, 16);
/// (options.field.shells, options.field.shell_grid) = (4, 3);
/// let scene = DynamicScene::build(&file, std::path::Path::new("."), &options).unwrap();
/// assert_eq!((scene.object_count(), scene.shape_count()), (2, 1)); // one shape, two instances
/// assert_eq!(scene.vertex_count(), 2 * 54 + 33 * 33);
/// assert_eq!(scene.object_index("b"), Some(1));
/// ```
#[derive(Clone, Debug)]
pub struct DynamicScene {
    options: DynamicOptions,
    shapes: Vec<Mesh>,
    fields: Vec<Arc<OcclusionField>>,
    objects: Vec<Object>,
    ground: Option<(Mesh, Arc<SparseRows<f32>>)>,
    /// How far lookups are lifted off their surface: the ray offset of the scene as built.
    lift: f64,
    /// The lighting of the scene file, path resolved.
    pub environment: Option<EnvironmentSpec>,
    /// The camera of the scene file.
    pub camera: Option<CameraSpec>,
    /// Where glossy vertices are seen from (the file's camera position unless set).
    eye: Option<[f64; 3]>,
    /// How glossy BRDFs are brought into vertex frames and truncated.
    glossy: GlossyOptions,
    report: BuildReport,
}

impl DynamicScene {
    /// Reads a JSON scene file ([`SceneFile`]) and builds it.
    pub fn load(path: &Path, options: &DynamicOptions) -> Result<Self> {
        Self::load_with(path, options, None)
    }

    /// [`load`](Self::load), with the fields of [`build_with`](Self::build_with).
    ///
    /// ```
    /// use haarshift::relight::dynamic::{DynamicOptions, DynamicScene};
    /// use haarshift::relight::dynamic::fields::file::FieldStore;
    /// use haarshift::faces::{ParamKind, Parameterization};
    /// let dir = tempfile::tempdir().unwrap();
    /// let scene = dir.path().join("ball.json");
    /// std::fs::write(&scene, r#"{"objects": [{"generator": {"sphere": {"cells": 2}}}]}"#).unwrap();
    /// let mut options = DynamicOptions::new(Parameterization::new(ParamKind::LatLong, 4).unwrap());
    /// (options.field.circles, options.field.circle_points) = (3, 6);
    /// (options.field.shells, options.field.shell_grid) = (2, 2);
    /// let mut store = FieldStore::new(dir.path(), false);
    /// DynamicScene::load_with(&scene, &options, Some(&mut store)).unwrap();
    /// assert!(dir.path().join("sphere-cells-2.hsf").exists());
    /// ```
    pub fn load_with(
        path: &Path,
        options: &DynamicOptions,
        store: Option<&mut FieldStore>,
    ) -> Result<Self> {
        let (file, dir) = SceneFile::read(path)?;
        Self::build_with(&file, dir, options, store).map_err(|e| e.in_file(path))
    }

    /// Builds the scene of `file` (paths relative to `dir`): every shape's fields and every
    /// vertex's own transport.
    pub fn build(file: &SceneFile, dir: &Path, options: &DynamicOptions) -> Result<Self> {
        Self::build_with(file, dir, options, None)
    }

    /// [`build`](Self::build), with every shape's fields read from `store` when its file
    /// there matches, else built and written to it ([`FieldStore::field`]).
    ///
    /// ```
    /// use haarshift::relight::dynamic::{DynamicOptions, DynamicScene};
    /// use haarshift::relight::dynamic::fields::file::FieldStore;
    /// use haarshift::relight::SceneFile;
    /// use haarshift::faces::{ParamKind, Parameterization};
    /// let file: SceneFile = serde_json::from_str(
    ///     r#"{"objects": [{"generator": {"sphere": {"cells": 2}}}]}"#).unwrap();
    /// let mut options = DynamicOptions::new(Parameterization::new(ParamKind::LatLong, 4).unwrap());
    /// (options.field.circles, options.field.circle_points) = (3, 6);
    /// (options.field.shells, options.field.shell_grid) = (2, 2);
    /// let dir = tempfile::tempdir().unwrap();
    /// let mut store = FieldStore::new(dir.path(), false);
    /// let here = std::path::Path::new(".");
    /// let first = DynamicScene::build_with(&file, here, &options, Some(&mut store)).unwrap();
    /// assert_eq!((first.report().fields_written, first.report().fields_loaded), (1, 0));
    /// let second = DynamicScene::build_with(&file, here, &options, Some(&mut store)).unwrap();
    /// assert_eq!((second.report().fields_loaded, second.report().field_rays), (1, 0));
    /// assert_eq!(second.field(0), first.field(0));
    /// ```
    pub fn build_with(
        file: &SceneFile,
        dir: &Path,
        options: &DynamicOptions,
        mut store: Option<&mut FieldStore>,
    ) -> Result<Self> {
        options.check()?;
        if file.objects.is_empty() {
            return Err(SceneError::SceneFile("a scene needs at least one object".into()).into());
        }
        let param = options.param();
        let mut report = BuildReport::default();
        let mut sources = Vec::new();
        let mut shapes: Vec<Mesh> = Vec::new();
        let mut placed = Vec::new();
        let mut names: Vec<Option<String>> = Vec::new();
        for (k, object) in file.objects.iter().enumerate() {
            if let Some(name) = &object.name
                && names.iter().flatten().any(|n| n == name)
            {
                return Err(
                    SceneError::SceneFile(format!("two objects are named {name:?}")).into(),
                );
            }
            names.push(object.name.clone());
            let source = (object.mesh.clone(), object.generator.clone());
            let shape = match sources.iter().position(|s| *s == source) {
                Some(i) => i,
                None => {
                    shapes.push(object.shape(dir, k)?);
                    sources.push(source);
                    shapes.len() - 1
                }
            };
            let placement =
                Placement::from_transform(&object.transform, param).map_err(|e| match e {
                    Error::Scene { source, .. } => {
                        SceneError::SceneFile(format!("object {k}: {source}")).into()
                    }
                    other => other,
                })?;
            let brdf = object.material.brdf().map_err(|e| match e {
                Error::Scene { source, .. } => {
                    SceneError::SceneFile(format!("object {k}: {source}")).into()
                }
                other => other,
            })?;
            placed.push((shape, placement, object.material.albedo()?, brdf));
        }
        // Validated before any field is built (relight::validate).
        if let Some(camera) = &file.camera {
            camera.check()?;
        }
        let meshes = placed
            .iter()
            .map(|(shape, p, _, _)| place_mesh(&shapes[*shape], p, param))
            .collect::<Result<Vec<Mesh>>>()?;
        let objects_mesh = merge(meshes.iter().cloned());
        let ground = file
            .ground_plane
            .then(|| ground_plane_under(&objects_mesh.bounds()))
            .transpose()?;
        let mut fields = Vec::with_capacity(shapes.len());
        for (mesh, (path, generator)) in shapes.iter().zip(&sources) {
            let (field, origin) = match store.as_deref_mut() {
                Some(store) => {
                    store.field(mesh, path.as_deref(), generator.as_ref(), &options.field)?
                }
                None => {
                    let (field, r) = OcclusionField::build(mesh, &options.field)?;
                    (
                        field,
                        FieldOrigin::Built {
                            report: r,
                            bytes: 0,
                        },
                    )
                }
            };
            match origin {
                FieldOrigin::Built { report: r, bytes } => {
                    report.field_rays += r.rays;
                    report.field_seconds += r.seconds;
                    // Nothing is written without a store.
                    report.fields_written += usize::from(store.is_some());
                    report.field_file_bytes += bytes;
                }
                FieldOrigin::Loaded { bytes, seconds } => {
                    report.fields_loaded += 1;
                    report.field_file_bytes += bytes;
                    report.field_load_seconds += seconds;
                }
            }
            report.field_bytes += field.stored_bytes();
            fields.push(Arc::new(field));
        }
        let visibility = VisibilityOptions {
            keep: options.keep_visibility,
            progress: options.progress,
            ..VisibilityOptions::new(param)
        };
        let own = |mesh: &Mesh, vertices: usize, report: &mut BuildReport| -> Result<_> {
            let (set, r) = vertex_major(mesh, &SceneBvh::new(mesh), &visibility)?;
            report.transport_rays += r.rays;
            report.transport_seconds += r.seconds;
            let rows: SparseRows<f32> = (0..vertices).map(|v| set.coefficients(v)).collect();
            Ok(Arc::new(rows))
        };
        let mut objects = Vec::with_capacity(placed.len());
        for (k, ((shape, placement, albedo, brdf), mesh)) in
            placed.into_iter().zip(&meshes).enumerate()
        {
            let mut with_ground = mesh.clone();
            if let Some(g) = &ground {
                with_ground.append(g);
            }
            let transport = own(&with_ground, mesh.vertex_count(), &mut report)?;
            objects.push(Object {
                name: names[k].clone(),
                shape,
                rest: placement,
                placement,
                albedo,
                brdf,
                orientation: None,
                transport,
                field: turned(&fields[shape], placement.turn)?,
            });
        }
        let ground = match ground {
            Some(g) => {
                let rows = own(&g, g.vertex_count(), &mut report)?;
                Some((g, rows))
            }
            None => None,
        };
        let all = merge(std::iter::once(objects_mesh).chain(ground.iter().map(|g| g.0.clone())));
        let mut scene = DynamicScene {
            options: *options,
            lift: ray_offset(&all),
            shapes,
            fields,
            objects,
            ground,
            environment: file.environment.clone().map(|mut e| {
                e.path = dir.join(&e.path);
                e
            }),
            eye: file.camera.as_ref().map(|c| c.position),
            camera: file.camera.clone(),
            glossy: GlossyOptions::default(),
            report,
        };
        scene.orient()?;
        Ok(scene)
    }

    /// The options it was built with.
    pub fn options(&self) -> &DynamicOptions {
        &self.options
    }

    /// What building it did.
    pub fn report(&self) -> &BuildReport {
        &self.report
    }

    /// The parameterisation of every map.
    pub fn param(&self) -> Parameterization {
        self.options.param()
    }

    /// The scene with every vertex's own transport re-truncated to `keep_visibility` and
    /// every field map to `keep_field` (each can only keep fewer than the build kept): a
    /// budget without a new build.
    pub fn truncated(&self, keep_visibility: Selection, keep_field: Selection) -> Result<Self> {
        let param = self.param();
        keep_visibility.limit(param.texels() - param.faces())?;
        let fields = self
            .fields
            .iter()
            .map(|f| Ok(Arc::new(f.truncated(keep_field)?)))
            .collect::<Result<Vec<_>>>()?;
        let select = |rows: &SparseRows<f32>| Arc::new(select_rows(param, keep_visibility, rows));
        let objects = self
            .objects
            .iter()
            .map(|o| {
                Ok(Object {
                    transport: select(&o.transport),
                    field: turned(&fields[o.shape], o.placement.turn)?,
                    ..o.clone()
                })
            })
            .collect::<Result<Vec<_>>>()?;
        let mut options = self.options;
        options.keep_visibility = keep_visibility;
        options.field.keep = keep_field;
        Ok(DynamicScene {
            options,
            fields,
            objects,
            ground: self
                .ground
                .as_ref()
                .map(|(g, rows)| (g.clone(), select(rows))),
            ..self.clone()
        })
    }

    /// Changes how the scene is shaded (none of these needs a new build): the truncation of
    /// looked-up maps, of just-in-time transfer's fixed products, and the depth.
    pub fn set_shading(
        &mut self,
        truncation: Truncation,
        keep_product: Selection,
        depth: Option<usize>,
    ) -> Result<()> {
        let mut options = self.options;
        (options.truncation, options.keep_product, options.depth) =
            (truncation, keep_product, depth);
        options.check()?;
        self.options = options;
        Ok(())
    }

    /// Objects (instances).
    pub fn object_count(&self) -> usize {
        self.objects.len()
    }

    /// Distinct shapes (each with one set of fields).
    pub fn shape_count(&self) -> usize {
        self.shapes.len()
    }

    /// The fields of object `k`'s shape, turned to its placement.
    pub fn field(&self, k: usize) -> &OcclusionField {
        &self.objects[k].field
    }

    /// The object named `name`.
    pub fn object_index(&self, name: &str) -> Option<usize> {
        self.objects
            .iter()
            .position(|o| o.name.as_deref() == Some(name))
    }

    /// Object `k`'s placement.
    pub fn placement(&self, k: usize) -> Placement {
        self.objects[k].placement
    }

    /// Moves object `k`; a new turn turns its field (every map: the cost of a re-formation,
    /// not of a frame).
    pub fn place(&mut self, k: usize, placement: Placement) -> Result<()> {
        self.check_object(k)?;
        if !(placement.scale.is_finite() && placement.scale > 0.0)
            || placement.translate.iter().any(|x| !x.is_finite())
            || placement.turn >= columns(self.param())
            || (self.param().kind() == ParamKind::Cube && placement.turn != 0)
        {
            return Err(Error::parameter(
                "placement",
                format!(
                    "{placement:?}: the scale must be positive, the translation finite, the \
                     turn below {} columns (0 for a cube map)",
                    columns(self.param())
                ),
            ));
        }
        // Every placed vertex stays in range, as a scene file's are: a rotation keeps lengths,
        // so `|R(s q) + t|_k <= s |q| + |t_k|`.
        let b = self.shapes[self.objects[k].shape].bounds();
        let radius = (0..3)
            .map(|c| b.min[c].abs().max(b.max[c].abs()).powi(2))
            .sum::<f64>()
            .sqrt();
        let reach = placement
            .translate
            .map(|t| t.abs() + placement.scale * radius);
        crate::relight::scene::validate::check_point("the placed object", reach)?;
        let o = &mut self.objects[k];
        if placement.turn != o.placement.turn {
            o.field = turned(&self.fields[o.shape], placement.turn)?;
        }
        o.placement = placement;
        Ok(())
    }

    /// Adds an instance of object `k`'s shape at `placement` (its own transport is `k`'s);
    /// returns its index. Its vertices come after every object's, before the ground's.
    pub fn clone_object(&mut self, k: usize, placement: Placement) -> Result<usize> {
        self.check_object(k)?;
        let mut copy = self.objects[k].clone();
        copy.name = None;
        copy.placement = copy.rest;
        self.objects.push(copy);
        let new = self.objects.len() - 1;
        self.place(new, placement)?;
        Ok(new)
    }

    fn check_object(&self, k: usize) -> Result<()> {
        if k >= self.objects.len() {
            return Err(Error::parameter(
                "object",
                format!("{k}: the scene has {} objects", self.objects.len()),
            ));
        }
        Ok(())
    }

    /// Vertices of all objects and the ground plane.
    pub fn vertex_count(&self) -> usize {
        self.objects
            .iter()
            .map(|o| self.shapes[o.shape].vertex_count())
            .sum::<usize>()
            + self.ground.as_ref().map_or(0, |g| g.0.vertex_count())
    }

    /// The vertices of object `k`: a range of the merged mesh's.
    pub fn object_vertices(&self, k: usize) -> std::ops::Range<usize> {
        let start: usize = self.objects[..k]
            .iter()
            .map(|o| self.shapes[o.shape].vertex_count())
            .sum();
        start..start + self.shapes[self.objects[k].shape].vertex_count()
    }

    /// Every object at its placement, then the ground plane, as one mesh (for the reference
    /// and the rasteriser).
    pub fn mesh(&self) -> Mesh {
        let param = self.param();
        merge(
            self.objects
                .iter()
                .map(|o| {
                    place_mesh(&self.shapes[o.shape], &o.placement, param)
                        .expect("placements are checked in range when made")
                })
                .chain(self.ground.iter().map(|g| g.0.clone())),
        )
    }

    /// The albedo of every vertex of [`mesh`](Self::mesh), `(V, 3)`.
    pub fn albedo(&self) -> Array2<f32> {
        let mut rows = Vec::with_capacity(self.vertex_count());
        for o in &self.objects {
            rows.extend(std::iter::repeat_n(
                o.albedo,
                self.shapes[o.shape].vertex_count(),
            ));
        }
        if let Some((g, _)) = &self.ground {
            rows.extend(std::iter::repeat_n(
                crate::relight::scene::GROUND_ALBEDO,
                g.vertex_count(),
            ));
        }
        Array2::from_shape_fn((rows.len(), 3), |(v, c)| rows[v][c])
    }

    /// Every vertex: its owner (`None`: the ground), its index in its owner, its world
    /// position lifted off the surface along its normal by the scene's ray offset (where
    /// field lookups are made; fixed at build, so that a move changes no other lookup).
    fn receivers(&self) -> Vec<Receiver> {
        let param = self.param();
        let eps = self.lift;
        let mut out = Vec::with_capacity(self.vertex_count());
        let lift = |p: [f64; 3], n: [f64; 3]| std::array::from_fn(|k| p[k] + eps * n[k]);
        for (k, o) in self.objects.iter().enumerate() {
            let mesh = &self.shapes[o.shape];
            let rot = o.placement.rotation(param);
            let (p, n) = (mesh.positions(), mesh.normals());
            for v in 0..mesh.vertex_count() {
                let world = o
                    .placement
                    .to_world([p[[v, 0]], p[[v, 1]], p[[v, 2]]], param);
                let normal = rot.apply([n[[v, 0]], n[[v, 1]], n[[v, 2]]]);
                out.push(Receiver {
                    owner: Some(k),
                    vertex: v,
                    point: lift(world, normal),
                    position: world,
                    normal,
                });
            }
        }
        if let Some((g, _)) = &self.ground {
            let (p, n) = (g.positions(), g.normals());
            for v in 0..g.vertex_count() {
                let (position, normal) = (
                    [p[[v, 0]], p[[v, 1]], p[[v, 2]]],
                    [n[[v, 0]], n[[v, 1]], n[[v, 2]]],
                );
                out.push(Receiver {
                    owner: None,
                    vertex: v,
                    point: lift(position, normal),
                    position,
                    normal,
                });
            }
        }
        out
    }

    /// The receiver's own transport at its owner's turn, depth-limited.
    fn own_transport(&self, r: &Receiver, depth: usize) -> Result<(Vec<u32>, Vec<f32>)> {
        let param = self.param();
        let (indices, values, turn) = match r.owner {
            Some(k) => {
                let o = &self.objects[k];
                let (i, v) = o.transport.row(r.vertex);
                let w = columns(param);
                (i, v, (o.placement.turn + w - o.rest.turn) % w)
            }
            None => {
                let (i, v) = self
                    .ground
                    .as_ref()
                    .expect("a ground receiver")
                    .1
                    .row(r.vertex);
                (i, v, 0)
            }
        };
        let (i, v) = if turn == 0 {
            (indices.to_vec(), values.to_vec())
        } else {
            yaw_sparse(param, indices, values, turn, Selection::Threshold(0.0))?
        };
        Ok(limit_depth(param, depth, i, v))
    }

    /// Object `k`'s occlusion map at the world point `x`, depth-limited, in `scratch.map`
    /// (`None`: beyond its fields).
    fn occlusion<'s>(
        &self,
        k: usize,
        x: [f64; 3],
        depth: usize,
        scratch: &'s mut Scratch,
    ) -> Option<(&'s [u32], &'s [f64])> {
        let o = &self.objects[k];
        let local = o.placement.to_local(x, self.param());
        o.field.blended(
            local,
            self.options.truncation,
            &mut scratch.blend,
            &mut scratch.map,
        )?;
        let s = self.param().face_size();
        if depth < s.trailing_zeros() as usize {
            let (i, v) = &mut scratch.map;
            let mut at = 0;
            for slot in 0..i.len() {
                if within_depth(s, depth, i[slot] as usize) {
                    (i[at], v[at]) = (i[slot], v[slot]);
                    at += 1;
                }
            }
            i.truncate(at);
            v.truncate(at);
        }
        Some((&scratch.map.0, &scratch.map.1))
    }

    /// Every vertex's outgoing radiance `(V, 3)` by the n-function product integral of its
    /// own transport, the lighting and every other object's occlusion (issue 7's traversal),
    /// with no reuse between frames: the oracle of [`JustInTimeTransfer`] and the cost it saves.
    pub fn shade<T: Sample>(&self, lighting: &Lighting) -> Result<Array2<T>> {
        let depth = self.check_lighting(lighting)?;
        let param = self.param();
        let light = light_tree::<T>(lighting, depth)?;
        let receivers = self.receivers();
        let reflectance = self.reflectance();
        let rows: Vec<[T; 3]> = receivers
            .par_iter()
            .map_init(
                || Scratch::new(param),
                |scratch, r| -> Result<[T; 3]> {
                    let (i, v) = self.own_transport(r, depth)?;
                    let own = Transport::from_weighted_tree(tree(
                        param,
                        &i,
                        v.iter().map(|&x| f64::from(x)),
                    )?);
                    let mut factors = Vec::new();
                    for k in (0..self.objects.len()).filter(|&k| Some(k) != r.owner) {
                        if let Some((i, v)) = self.occlusion(k, r.point, depth, scratch) {
                            factors.push(tree(param, i, v.iter().copied())?);
                        }
                    }
                    factors.extend(self.brdf_tree(r, depth)?);
                    let mut refs: Vec<&HaarTree<T, 3>> = vec![&light];
                    refs.extend(factors.iter());
                    let value = product_integral(&own, &refs, IntegralOptions::default())?.value;
                    Ok(value.map(T::from_f64))
                },
            )
            .collect::<Result<_>>()?;
        Ok(radiance(&rows, &reflectance))
    }

    /// The ground truth of the scene as placed now: [`reference`](crate::relight::reference()) with
    /// visibility ray-cast against every object and the ground plane, over `lighting` (a
    /// lat-long map, rotated), no field, no Haar transform; a glossy object's BRDF evaluated
    /// analytically per texel toward the [eye](Self::eye), as `relight reference --brdf` does.
    pub fn reference(&self, lighting: &LatLongMap<f64>) -> Result<Array2<f64>> {
        let mesh = self.mesh();
        let bvh = SceneBvh::new(&mesh);
        let albedo = self.albedo();
        let lambert = ReferenceOptions {
            progress: self.options.progress,
            ..ReferenceOptions::default()
        };
        let mut glossy: Vec<&Brdf> = Vec::new();
        for o in self.objects.iter().filter(|o| !o.brdf.is_lambert()) {
            if !glossy.contains(&&o.brdf) {
                glossy.push(&o.brdf);
            }
        }
        if glossy.is_empty() {
            return Ok(
                crate::relight::reference(&mesh, &bvh, albedo.view(), lighting, &lambert)?.0,
            );
        }
        // The rays once; then one quadrature per material, each vertex taking its own's.
        let eye = self.glossy_eye()?;
        let bits = ReferenceVisibility::new(&mesh, &bvh, lighting.height(), lambert.progress)?;
        let mut out = bits.reference(&mesh, albedo.view(), lighting, &lambert)?.0;
        for brdf in glossy {
            let options = ReferenceOptions {
                brdf: brdf.clone(),
                eye: Some(eye),
                ..ReferenceOptions::default()
            };
            let (shaded, _) = bits.reference(&mesh, albedo.view(), lighting, &options)?;
            for k in (0..self.objects.len()).filter(|&k| self.objects[k].brdf == *brdf) {
                let rows = ndarray::s![self.object_vertices(k), ..];
                out.slice_mut(rows).assign(&shaded.slice(rows));
            }
        }
        Ok(out)
    }

    /// The depth the options name, after checking `lighting` against the scene.
    fn check_lighting(&self, lighting: &Lighting) -> Result<usize> {
        if lighting.param() != self.param() {
            return Err(Error::parameter(
                "lighting",
                format!(
                    "{} {}: the scene's maps are {} {}",
                    lighting.param().kind(),
                    lighting.param().face_size(),
                    self.param().kind(),
                    self.param().face_size()
                ),
            ));
        }
        self.options.check()
    }
}

/// One vertex as the shading sees it.
struct Receiver {
    owner: Option<usize>,
    vertex: usize,
    point: [f64; 3],
    /// On the surface, and the unit normal: a glossy vertex's frame.
    position: [f64; 3],
    normal: [f64; 3],
}

/// Per-thread working memory: a dense blend buffer and a sparse map.
struct Scratch {
    blend: Vec<f64>,
    map: (Vec<u32>, Vec<f64>),
}

impl Scratch {
    fn new(param: Parameterization) -> Self {
        Scratch {
            blend: vec![0.0; param.texels()],
            map: (Vec::new(), Vec::new()),
        }
    }
}

fn turned(field: &Arc<OcclusionField>, turn: usize) -> Result<Arc<OcclusionField>> {
    Ok(if turn == 0 {
        field.clone()
    } else {
        Arc::new(field.turned(turn)?)
    })
}

fn place_mesh(mesh: &Mesh, p: &Placement, param: Parameterization) -> Result<Mesh> {
    let rot = p.rotation(param);
    mesh.mapped(|q| p.to_world(q, param), |n| rot.apply(n))
}

/// The entries within the detail levels `0..depth`.
fn limit_depth<V>(
    param: Parameterization,
    depth: usize,
    indices: Vec<u32>,
    values: Vec<V>,
) -> (Vec<u32>, Vec<V>) {
    let s = param.face_size();
    if depth == s.trailing_zeros() as usize {
        return (indices, values);
    }
    indices
        .into_iter()
        .zip(values)
        .filter(|(i, _)| within_depth(s, depth, *i as usize))
        .unzip()
}

/// A one-channel sparse function as a three-channel tree (every channel the same).
fn tree<T: Sample>(
    param: Parameterization,
    indices: &[u32],
    values: impl Iterator<Item = f64>,
) -> Result<HaarTree<T, 3>> {
    let values: Vec<[T; 3]> = values.map(|v| [T::from_f64(v); 3]).collect();
    HaarTree::from_sparse(
        param.faces(),
        param.face_size(),
        layout(param),
        indices,
        &values,
    )
}

/// The lighting's kept coefficients, depth-limited, sparse and ascending.
fn light_sparse<T: Sample>(lighting: &Lighting, depth: usize) -> (Vec<u32>, Vec<[T; 3]>) {
    let param = lighting.param();
    lighting
        .coefficients_f64()
        .rows()
        .into_iter()
        .enumerate()
        .filter(|(i, row)| {
            row.iter().any(|&x| x != 0.0) && within_depth(param.face_size(), depth, *i)
        })
        .map(|(i, row)| (i as u32, [row[0], row[1], row[2]].map(T::from_f64)))
        .unzip()
}

/// The lighting's kept coefficients as a tree, depth-limited.
fn light_tree<T: Sample>(lighting: &Lighting, depth: usize) -> Result<HaarTree<T, 3>> {
    let param = lighting.param();
    let (indices, values) = light_sparse::<T>(lighting, depth);
    HaarTree::from_sparse(
        param.faces(),
        param.face_size(),
        layout(param),
        &indices,
        &values,
    )
}

/// `reflectance x integral`, per vertex and channel ([`DynamicScene::reflectance`]).
fn radiance<T: Sample>(integrals: &[[T; 3]], reflectance: &Array2<f64>) -> Array2<T> {
    Array2::from_shape_fn((integrals.len(), 3), |(v, c)| {
        T::from_f64(integrals[v][c].as_f64() * reflectance[[v, c]])
    })
}

pub mod fields;
mod glossy;
mod jrt;
pub mod motion;
mod products;
pub use jrt::{Change, JustInTimeTransfer, TransferReport};

/// The old name of [`JustInTimeTransfer`], kept for one release.
#[deprecated(note = "renamed `haarshift::relight::dynamic::JustInTimeTransfer`")]
pub type Jrt<T> = JustInTimeTransfer<T>;

/// The old name of [`TransferReport`], kept for one release.
#[deprecated(note = "renamed `haarshift::relight::dynamic::TransferReport`")]
pub type JrtReport = TransferReport;

#[cfg(test)]
mod tests;
