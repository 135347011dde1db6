//! Scenes: the ground plane, procedural generators and the JSON scene file.
//!
//! # Ground plane
//! [`add_ground_plane`]: a square at the scene's lowest `y`, centred under the bounding box's
//! centre, of side `4 x` the box's largest horizontal extent (`max(dx, dz)`), normal `+Y`,
//! subdivided into a grid of `N x N` cells (so it can receive shadows; `N` is
//! [`GROUND_CELLS`]` = 32` unless `--ground-cells` or a scene file's `"ground_cells"` says
//! otherwise, `1..=`[`MAX_GROUND_CELLS`]): `(N + 1)^2` vertices ([`ground_vertices`], 1089 by
//! default: [`GROUND_VERTICES`]) appended after the mesh's, row by row from the corner at
//! `(-x, +z)`, `x` fastest. The ground's vertices are always the last ones, and a scene and a
//! cache record how many ([`Scene::ground_vertices`], [`CacheHeader::ground_vertices`](cache::CacheHeader::ground_vertices)):
//! that count, not the default grid's formula, tells the glossy shaders which vertices stay
//! Lambertian.
//!
//! # Generators
//! Every size is fixed here, so a generator and its settings name one mesh (units are
//! arbitrary; Y up):
//!
//! | [`Generator`] | what | vertices |
//! |---|---|---|
//! | `cylinder_and_bump` | Vollick and Lessig's "Cylinder & Bump" (section 6.1.1): on a `[-4, 4]^2` ground (`cells` x `cells`, default 96) a Gaussian bump (height 1, sigma 0.6, at `(1.5, 1)`) and a cylinder (radius 0.5, height 3, 48 segments x 24 rings, capped) at `(-1.5, -1)` | 10,707 at 96 cells |
//! | `cubes` | Vollick and Lessig's "Cubes" (section 6.1.2, after Durand 2005): a wall (`z = 0`, facing `+Z`, 12.9 x 10.1, 129 x 101 cells) and in front of it, at distance `distance` (default 1.5), a `count x count` array (default 10) of cubes of side 0.6 every 1.2 across and 1.0 up, each face `cells x cells` (default 10); every cube face has its own vertices (sharp normals). The default is Vollick and Lessig's Table 2 scale | 85,860 by default: `6 count^2 (cells + 1)^2 + 13,260` |
//! | `plane_with_sphere` | a `[-3, 3]^2` ground (64 x 64 cells) with a unit sphere resting on it (a cube sphere, 16 x 16 cells a face) | 5,959 |
//! | `sphere` | a unit sphere at the origin tessellated as a cube sphere, `cells x cells` per face, normals exact (radial) | `6 (cells + 1)^2` |
//! | `table` | a table standing on `y = 0`: a top `[-1, 1] x [0.9, 1] x [-0.6, 0.6]` on four legs 0.08 thick at its corners, each box `cells x cells` a face | `30 (cells + 1)^2` |
//! | `chair` | a chair standing on `y = 0`: a seat `[-0.25, 0.25] x [0.45, 0.5] x [-0.25, 0.25]`, a back `0.5` high at `z = 0.2 .. 0.25`, four legs 0.05 thick, each box `cells x cells` a face | `36 (cells + 1)^2` |
//! | `box` | an open box standing on `y = 0`: five inward-facing squares `cells x cells` each (the floor `[-1, 1]^2` facing `+Y`, then the walls at `x = -1, 1` and `z = -1, 1`, 2 high, each facing the inside), open at the top: a concave scene for interreflections; every face has its own vertices | `5 (cells + 1)^2` |
//! | `plane_under_box` | a `[-3, 3]^2` ground (2 x 2 cells, so vertex 4 is the origin) under a box with bottom face `[-1, 1]^2` at height `height` and top at `height + 0.5` (faces 4 x 4 cells); the form-factor test | 159 |
//!
//! # Scene file
//! JSON, unknown keys refused everywhere; relative paths are relative to the scene file:
//!
//! ```json
//! {
//!   "objects": [
//!     { "mesh": "bunny.ply",
//!       "transform": { "translate": [0, 0, 0], "scale": 1, "yaw": 30, "pitch": 0, "roll": 0 },
//!       "material": { "brdf": "lambert", "albedo": [0.8, 0.8, 0.8] } },
//!     { "generator": { "cubes": { "count": 10, "cells": 10, "distance": 1.5 } } }
//!   ],
//!   "ground_plane": true,
//!   "environment": { "path": "envmaps/grace.hdr", "yaw": 0, "pitch": 0, "roll": 0 },
//!   "camera": { "position": [0, 5, 20], "look_at": [0, 4, 0], "fov": 40 }
//! }
//! ```
//!
//! * `objects` (at least one): each has exactly one of `mesh` (an OBJ, PLY, glTF or GLB path,
//!   [`MeshAsset`]; where the file carries colour, its albedo times the material's) and
//!   `generator` (one of the table's names with its settings, `{}` for the defaults);
//!   `transform` (optional: scale, then rotate by `R = Rz(roll) Ry(yaw) Rx(pitch)` in degrees,
//!   the sphere module's convention, then translate); `material` (optional, default Lambertian
//!   albedo `[0.8, 0.8, 0.8]`; `{"brdf": "phong", "exponent": 20, "albedo": [..]}` and
//!   `"blinn"` are glossy, [`Material`]). Objects are merged in order, vertices numbered as they come.
//! * `ground_plane` (default `false`): [`add_ground_plane`] after all objects, albedo
//!   [`GROUND_ALBEDO`]; `ground_cells` (optional, only with `"ground_plane": true`, default
//!   [`GROUND_CELLS`]): its cells per side.
//! * `environment` (optional): the lighting's path and its rotation `g(p) = f(R p)`.
//! * `camera` (optional): position, look-at point, vertical field of view in degrees.

mod asset;
pub(crate) mod asset_path;
pub(crate) mod bisect;
pub mod cache;
pub mod cache_shard;
mod file;
pub(crate) mod framed;
mod generators;
pub(crate) mod gltf_file;
mod ground;
pub mod mesh;
mod mtl;
mod obj;
pub(crate) mod shapes;
pub mod texture;
pub mod validate;

pub use asset::MeshAsset;

pub(crate) use file::read_json;
pub use file::{CameraSpec, EnvironmentSpec, Material, SceneFile, SceneObject, Transform};
pub use generators::Generator;
pub use ground::{
    GROUND_ALBEDO, GROUND_CELLS, GROUND_VERTICES, MAX_GROUND_CELLS, add_ground_plane,
    check_ground_cells, ground_plane_under, ground_vertices, object_vertices,
};

use std::path::Path;

use ndarray::Array2;

use crate::Mesh;
use crate::Result;
use crate::scene::file::DEFAULT_ALBEDO;
use crate::scene::validate::MemoryBudget;

/// A scene ready to precompute: one merged mesh, an albedo per vertex, and the scene file's
/// lighting and camera with their paths resolved.
///
/// ```
/// use haarshift_relight::Scene;
/// let dir = tempfile::tempdir().unwrap();
/// let path = dir.path().join("s.json");
/// std::fs::write(&path, r#"{"objects": [{"generator": {"sphere": {"cells": 2}},
///     "material": {"brdf": "lambert", "albedo": [0.5, 0.6, 0.7]}}],
///     "ground_plane": true, "environment": {"path": "sky.hdr"}}"#).unwrap();
/// let scene = Scene::load(&path).unwrap();
/// assert_eq!(scene.mesh.vertex_count(), 54 + 1089);
/// assert_eq!(scene.albedo.row(0).to_vec(), vec![0.5, 0.6, 0.7]);
/// assert_eq!(scene.environment.unwrap().path, dir.path().join("sky.hdr"));
/// ```
#[derive(Clone, Debug, PartialEq)]
pub struct Scene {
    /// All objects (and the ground plane) merged.
    pub mesh: Mesh,
    /// RGB albedo per vertex, `(V, 3)`.
    pub albedo: Array2<f32>,
    /// The lighting, path resolved.
    pub environment: Option<EnvironmentSpec>,
    /// The camera.
    pub camera: Option<CameraSpec>,
    /// Whether the ground plane has been added (its vertices are the last ones).
    pub ground_plane: bool,
    /// The ground plane's cells per side, when it has been added.
    pub ground_cells: Option<usize>,
    /// How many of the last vertices are the ground plane's (0 without one): `(N + 1)^2` for
    /// a grid of `N` cells.
    pub ground_vertices: usize,
    /// What reading its mesh files approximated, one line each ([`MeshAsset::warnings`];
    /// a scene file's prefixed by the object): the CLI prints them.
    pub warnings: Vec<String>,
}

impl Scene {
    /// A scene of one mesh with the default material (and, if asked, the ground plane:
    /// errors as [`add_ground_plane`] does).
    pub fn from_mesh(mesh: Mesh, ground_plane: bool) -> Result<Scene> {
        Self::from_asset(MeshAsset::plain(mesh), ground_plane)
    }

    /// A scene of one mesh file's asset: its own albedo where it carries colour, else the
    /// default material's (and the ground plane, as [`from_mesh`](Self::from_mesh)).
    ///
    /// ```
    /// use haarshift_relight::{Generator, Scene};
    /// use haarshift_relight::scene::MeshAsset;
    /// let mut asset = MeshAsset::plain(Generator::Sphere { cells: 1 }.mesh().unwrap());
    /// asset.albedo = Some(ndarray::Array2::from_elem((24, 3), 0.25));
    /// let scene = Scene::from_asset(asset, true).unwrap();
    /// assert_eq!(scene.albedo.row(0).to_vec(), vec![0.25; 3]);
    /// assert_eq!(scene.albedo.row(24).to_vec(), haarshift_relight::scene::GROUND_ALBEDO.to_vec());
    /// ```
    pub fn from_asset(asset: MeshAsset, ground_plane: bool) -> Result<Scene> {
        let v = asset.mesh.vertex_count();
        let mut scene = Scene {
            albedo: asset
                .albedo
                .unwrap_or_else(|| Array2::from_shape_fn((v, 3), |(_, c)| DEFAULT_ALBEDO[c])),
            mesh: asset.mesh,
            environment: None,
            camera: None,
            ground_plane: false,
            ground_cells: None,
            ground_vertices: 0,
            warnings: asset.warnings,
        };
        if ground_plane {
            scene.add_ground_plane()?;
        }
        Ok(scene)
    }

    /// Appends the default ground plane ([`add_ground_plane`], [`GROUND_CELLS`] cells per
    /// side) with albedo [`GROUND_ALBEDO`], unless the scene has one already (of any cells).
    ///
    /// ```
    /// use haarshift_relight::{Generator, Scene};
    /// let mut scene = Scene::from_mesh(Generator::Sphere { cells: 2 }.mesh().unwrap(), true).unwrap();
    /// let v = scene.mesh.vertex_count();
    /// scene.add_ground_plane().unwrap();
    /// assert_eq!((scene.mesh.vertex_count(), scene.ground_plane), (v, true));
    /// assert_eq!((scene.ground_cells, scene.ground_vertices), (Some(32), 33 * 33));
    /// ```
    ///
    /// Errors (leaving the scene as it was) as [`add_ground_plane`] does.
    pub fn add_ground_plane(&mut self) -> Result<()> {
        if self.ground_plane {
            return Ok(());
        }
        self.add_ground_plane_of(GROUND_CELLS)
    }

    /// [`add_ground_plane`](Self::add_ground_plane) with `cells` cells per side
    /// ([`ground_plane_under`]); a scene that has a ground plane already keeps it, and is
    /// refused when its plane has other cells than `cells`.
    ///
    /// ```
    /// use haarshift_relight::{Generator, Scene};
    /// let mut scene = Scene::from_mesh(Generator::Sphere { cells: 2 }.mesh().unwrap(), false).unwrap();
    /// scene.add_ground_plane_of(64).unwrap();
    /// assert_eq!((scene.mesh.vertex_count(), scene.object_vertices()), (54 + 65 * 65, 54));
    /// assert!(scene.add_ground_plane_of(64).is_ok());
    /// let err = scene.add_ground_plane_of(16).unwrap_err().to_string();
    /// assert!(err.contains("has a ground plane of 64 cells per side, not 16"), "{err}");
    /// ```
    ///
    /// Errors (leaving the scene as it was) as [`ground_plane_under`] does.
    pub fn add_ground_plane_of(&mut self, cells: usize) -> Result<()> {
        if self.ground_plane {
            return match self.ground_cells {
                Some(had) if had != cells => Err(crate::Error::parameter(
                    "ground cells",
                    format!("the scene has a ground plane of {had} cells per side, not {cells}"),
                )),
                _ => Ok(()),
            };
        }
        let ground = ground_plane_under(&self.mesh.bounds(), cells)?;
        self.mesh.append(&ground);
        self.ground_plane = true;
        self.ground_cells = Some(cells);
        self.ground_vertices = ground.vertex_count();
        let added = Array2::from_shape_fn((ground.vertex_count(), 3), |(_, c)| GROUND_ALBEDO[c]);
        self.albedo
            .append(ndarray::Axis(0), added.view())
            .expect("both are (V, 3)");
        Ok(())
    }

    /// The vertices of the scene's objects, `0..object_vertices()`: all but the ground plane's
    /// (the last [`ground_vertices`](Self::ground_vertices)), which stays Lambertian under a
    /// glossy BRDF.
    ///
    /// ```
    /// use haarshift_relight::{Generator, Scene};
    /// let sphere = Generator::Sphere { cells: 2 }.mesh().unwrap();
    /// assert_eq!(Scene::from_mesh(sphere.clone(), true).unwrap().object_vertices(), 54);
    /// assert_eq!(Scene::from_mesh(sphere, false).unwrap().object_vertices(), 54);
    /// ```
    pub fn object_vertices(&self) -> usize {
        object_vertices(self.mesh.vertex_count(), self.ground_vertices)
    }

    /// Reads a scene: a JSON scene file (`.json`), or a mesh file (OBJ, PLY, glTF or GLB,
    /// [`MeshAsset`]) as a scene of one object with the default material (the file's own
    /// colour, where it carries colour, replacing the default albedo); within the default
    /// [`MemoryBudget`].
    pub fn load(path: &Path) -> Result<Scene> {
        Self::load_within(path, &MemoryBudget::default())
    }

    /// [`load`](Self::load) within `budget`: a scene file is refused before anything is built
    /// when its generators do not fit ([`SceneFile::check_memory`]), and any scene once read
    /// when its vertices do not.
    ///
    /// ```
    /// use haarshift_relight::Scene;
    /// use haarshift_relight::scene::validate::MemoryBudget;
    /// let dir = tempfile::tempdir().unwrap();
    /// let path = dir.path().join("s.json");
    /// std::fs::write(&path, r#"{"objects": [{"generator": {"sphere": {"cells": 20}}}]}"#).unwrap();
    /// let small = MemoryBudget { limit: 1 << 20, ..MemoryBudget::default() };
    /// let err = Scene::load_within(&path, &small).unwrap_err().to_string();
    /// assert!(err.starts_with(&format!("{}: object 0", path.display())));
    /// assert!(err.contains("(2646 vertices) needs 1693440 bytes"));
    /// assert!(Scene::load(&path).is_ok());
    /// ```
    pub fn load_within(path: &Path, budget: &MemoryBudget) -> Result<Scene> {
        let is_json = path
            .extension()
            .is_some_and(|e| e.eq_ignore_ascii_case("json"));
        let scene = if is_json {
            let (file, dir) = SceneFile::read(path)?;
            file.build_within(dir, budget)
        } else {
            Scene::from_asset(MeshAsset::load_within(path, budget)?, false)
        };
        let scene = scene.map_err(|e| e.in_file(path))?;
        // A mesh file's size bounds its reader, not what the caller will store per vertex.
        budget
            .check("the scene", scene.mesh.vertex_count() as u128)
            .map_err(|e| e.in_file(path))?;
        Ok(scene)
    }
}

#[cfg(test)]
mod tests;
