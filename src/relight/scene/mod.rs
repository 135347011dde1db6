//! Scenes: the ground plane, procedural generators and the JSON scene file.
//!
//! # Ground plane
//! [`add_ground_plane`]: a square at the scene's lowest `y`, centred under the bounding box's
//! centre, of side `4 x` the box's largest horizontal extent (`max(dx, dz)`), normal `+Y`,
//! subdivided into a grid of [`GROUND_CELLS`]` x `[`GROUND_CELLS`] cells (so it can receive
//! shadows): `(GROUND_CELLS + 1)^2 = 1089` ([`GROUND_VERTICES`]) vertices appended after the
//! mesh's, row by row from
//! the corner at `(-x, +z)`, `x` fastest.
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
//! * `objects` (at least one): each has exactly one of `mesh` (an OBJ or PLY path) and
//!   `generator` (one of the table's names with its settings, `{}` for the defaults);
//!   `transform` (optional: scale, then rotate by `R = Rz(roll) Ry(yaw) Rx(pitch)` in degrees,
//!   the sphere module's convention, then translate); `material` (optional, default Lambertian
//!   albedo `[0.8, 0.8, 0.8]`; `{"brdf": "phong", "exponent": 20, "albedo": [..]}` and
//!   `"blinn"` are glossy, [`Material`]). Objects are merged in order, vertices numbered as they come.
//! * `ground_plane` (default `false`): [`add_ground_plane`] after all objects, albedo
//!   [`GROUND_ALBEDO`].
//! * `environment` (optional): the lighting's path and its rotation `g(p) = f(R p)`.
//! * `camera` (optional): position, look-at point, vertical field of view in degrees.

pub mod cache;
pub(crate) mod framed;
pub mod mesh;
pub mod validate;

use std::path::{Path, PathBuf};

use ndarray::Array2;
use serde::{Deserialize, Serialize};

use crate::relight::scene::mesh::{cross, dot};
use crate::relight::scene::validate::grid_vertices;
use crate::relight::{Brdf, Mesh, SceneError};
use crate::sphere::SphereRotation;
use crate::{Error, Result};

/// Cells per side of the ground plane's grid.
pub const GROUND_CELLS: usize = 32;

/// Vertices the ground plane adds: `(GROUND_CELLS + 1)^2`.
pub const GROUND_VERTICES: usize = (GROUND_CELLS + 1) * (GROUND_CELLS + 1);

/// Of `vertices`, those of the objects: all but the ground plane's (the last
/// [`GROUND_VERTICES`]) when there is one.
///
/// ```
/// use haarshift::relight::scene::{GROUND_VERTICES, object_vertices};
/// assert_eq!(object_vertices(GROUND_VERTICES + 54, true), 54);
/// assert_eq!(object_vertices(54, false), 54);
/// ```
pub fn object_vertices(vertices: usize, ground_plane: bool) -> usize {
    let ground = if ground_plane { GROUND_VERTICES } else { 0 };
    vertices.saturating_sub(ground)
}

/// The ground plane's albedo in a scene file.
pub const GROUND_ALBEDO: [f32; 3] = [0.8, 0.8, 0.8];

/// A grid of `nu x nv` cells on the parallelogram `origin + s u + t v`, `s, t in [0, 1]`;
/// normal `u x v` (normalised), vertices `(nu + 1)(nv + 1)`, `s` fastest.
fn grid(origin: [f64; 3], u: [f64; 3], v: [f64; 3], nu: usize, nv: usize) -> Result<Mesh> {
    let n = cross(u, v);
    let len = dot(n, n).sqrt();
    let normal = n.map(|x| x / len);
    let count = (nu + 1) * (nv + 1);
    let positions = Array2::from_shape_fn((count, 3), |(k, c)| {
        let (i, j) = (k % (nu + 1), k / (nu + 1));
        origin[c] + u[c] * i as f64 / nu as f64 + v[c] * j as f64 / nv as f64
    });
    let normals = Array2::from_shape_fn((count, 3), |(_, c)| normal[c]);
    let index = |i: usize, j: usize| (j * (nu + 1) + i) as u32;
    let mut triangles = Vec::with_capacity(2 * nu * nv);
    for j in 0..nv {
        for i in 0..nu {
            let (a, b, c, d) = (
                index(i, j),
                index(i + 1, j),
                index(i + 1, j + 1),
                index(i, j + 1),
            );
            triangles.push([a, b, c]);
            triangles.push([a, c, d]);
        }
    }
    Mesh::new(positions, triangles, Some(normals))
}

/// A horizontal grid facing `+Y` over `[x0, x0 + side] x [z0 - side, z0]` at height `y`.
fn ground(x0: f64, z0: f64, y: f64, side: f64, cells: usize) -> Result<Mesh> {
    grid(
        [x0, y, z0],
        [side, 0.0, 0.0],
        [0.0, 0.0, -side],
        cells,
        cells,
    )
}

/// The six outward faces of the box `[min, max]`, `cells x cells` each, in the order +X, -X,
/// +Y, -Y, +Z, -Z.
fn cuboid(min: [f64; 3], max: [f64; 3], cells: usize) -> Result<Mesh> {
    let [x0, y0, z0] = min;
    let [x1, y1, z1] = max;
    let (dx, dy, dz) = (x1 - x0, y1 - y0, z1 - z0);
    let faces = [
        ([x1, y0, z1], [0.0, 0.0, -dz], [0.0, dy, 0.0]),
        ([x0, y0, z0], [0.0, 0.0, dz], [0.0, dy, 0.0]),
        ([x0, y1, z1], [dx, 0.0, 0.0], [0.0, 0.0, -dz]),
        ([x0, y0, z0], [dx, 0.0, 0.0], [0.0, 0.0, dz]),
        ([x0, y0, z1], [dx, 0.0, 0.0], [0.0, dy, 0.0]),
        ([x1, y0, z0], [-dx, 0.0, 0.0], [0.0, dy, 0.0]),
    ];
    let faces = faces.iter().map(|&(o, u, v)| grid(o, u, v, cells, cells));
    Ok(merge(faces.collect::<Result<Vec<_>>>()?))
}

/// A sphere of `radius` at `centre`: the faces of a cube projected onto it, normals radial.
fn cube_sphere(centre: [f64; 3], radius: f64, cells: usize) -> Result<Mesh> {
    let cube = cuboid([-1.0; 3], [1.0; 3], cells)?;
    cube.mapped(
        |p| {
            let len = dot(p, p).sqrt();
            std::array::from_fn(|k| centre[k] + radius * p[k] / len)
        },
        |_| [0.0; 3],
    )?
    .with_radial_normals(centre)
}

impl Mesh {
    /// This mesh with every normal pointing from `centre` to its vertex.
    fn with_radial_normals(self, centre: [f64; 3]) -> Result<Mesh> {
        let normals = Array2::from_shape_fn((self.vertex_count(), 3), |(v, k)| {
            self.positions()[[v, k]] - centre[k]
        });
        let triangles = self.triangles().to_vec();
        Mesh::new(self.positions().to_owned(), triangles, Some(normals))
    }
}

/// A capped cylinder standing on `base`, `segments` around and `rings` up.
fn cylinder(base: [f64; 3], radius: f64, height: f64, segments: usize, rings: usize) -> Mesh {
    let angle = |i: usize| 2.0 * std::f64::consts::PI * (i % segments) as f64 / segments as f64;
    let ring = |i: usize, y: f64| {
        let (s, c) = angle(i).sin_cos();
        [base[0] + radius * c, base[1] + y, base[2] + radius * s]
    };
    // The side: vertices ring by ring; quad (i, j) is wound so that up x around is outward.
    let side_positions = Array2::from_shape_fn((segments * (rings + 1), 3), |(k, c)| {
        ring(k % segments, height * (k / segments) as f64 / rings as f64)[c]
    });
    let side_normals = Array2::from_shape_fn((segments * (rings + 1), 3), |(k, c)| {
        let (s, co) = angle(k % segments).sin_cos();
        [co, 0.0, s][c]
    });
    let index = |i: usize, j: usize| (j * segments + i % segments) as u32;
    let mut side_triangles = Vec::new();
    for j in 0..rings {
        for i in 0..segments {
            let (a, b, c, d) = (
                index(i, j),
                index(i, j + 1),
                index(i + 1, j + 1),
                index(i + 1, j),
            );
            side_triangles.push([a, b, c]);
            side_triangles.push([a, c, d]);
        }
    }
    let mut mesh = Mesh::new(side_positions, side_triangles, Some(side_normals))
        .expect("a cylinder is a valid mesh");
    for (y, top) in [(height, true), (0.0, false)] {
        let mut positions = Array2::zeros((segments + 1, 3));
        positions
            .row_mut(0)
            .assign(&ndarray::arr1(&[base[0], base[1] + y, base[2]]));
        for i in 0..segments {
            positions.row_mut(i + 1).assign(&ndarray::arr1(&ring(i, y)));
        }
        let rim = |i: usize| (1 + i % segments) as u32;
        let triangles = (0..segments)
            .map(|i| {
                if top {
                    [0, rim(i + 1), rim(i)]
                } else {
                    [0, rim(i), rim(i + 1)]
                }
            })
            .collect();
        mesh.append(&Mesh::new(positions, triangles, None).expect("a cap is a valid mesh"));
    }
    mesh
}

/// All meshes appended in order (at least one).
pub(crate) fn merge(meshes: impl IntoIterator<Item = Mesh>) -> Mesh {
    let mut meshes = meshes.into_iter();
    let mut out = meshes.next().expect("at least one mesh");
    for m in meshes {
        out.append(&m);
    }
    out
}

impl Generator {
    /// The boxes of the furniture generators, `(min, max)` corners.
    fn boxes(&self) -> Vec<([f64; 3], [f64; 3])> {
        let legs = |x: f64, z: f64, t: f64, h: f64| {
            [(-x, -z), (x - t, -z), (-x, z - t), (x - t, z - t)]
                .map(|(a, b)| ([a, 0.0, b], [a + t, h, b + t]))
        };
        match self {
            Generator::Table { .. } => {
                let mut b = vec![([-1.0, 0.9, -0.6], [1.0, 1.0, 0.6])];
                b.extend(legs(0.95, 0.55, 0.08, 0.9));
                b
            }
            Generator::Chair { .. } => {
                let mut b = vec![
                    ([-0.25, 0.45, -0.25], [0.25, 0.5, 0.25]),
                    ([-0.25, 0.5, 0.2], [0.25, 1.0, 0.25]),
                ];
                b.extend(legs(0.25, 0.25, 0.05, 0.45));
                b
            }
            _ => Vec::new(),
        }
    }
}

/// Appends the ground plane described in the [module docs](self) to `mesh`.
///
/// ```
/// use haarshift::relight::{Generator, add_ground_plane};
/// let mut m = Generator::Sphere { cells: 4 }.mesh().unwrap();
/// let before = m.vertex_count();
/// add_ground_plane(&mut m).unwrap();
/// assert_eq!(m.vertex_count(), before + 33 * 33);
/// let b = m.bounds();
/// assert_eq!((b.min[1], b.max[0]), (-1.0, 4.0)); // at the lowest y, side 4 x 2
/// ```
///
/// Errors as [`ground_plane_under`] does.
pub fn add_ground_plane(mesh: &mut Mesh) -> Result<()> {
    mesh.append(&ground_plane_under(&mesh.bounds())?);
    Ok(())
}

/// The ground plane [`add_ground_plane`] puts under a scene of bounding box `b`, on its own.
///
/// ```
/// use haarshift::relight::{Generator, scene::ground_plane_under};
/// let ball = Generator::Sphere { cells: 4 }.mesh().unwrap();
/// let ground = ground_plane_under(&ball.bounds()).unwrap();
/// assert_eq!((ground.vertex_count(), ground.bounds().min[1]), (33 * 33, -1.0));
/// ```
///
/// Errors when the box has no horizontal extent to size the plane by
/// ([`check_ground_extent`](crate::relight::scene::validate::check_ground_extent)), or when the plane would
/// reach beyond [`MAX_COORDINATE`](crate::relight::scene::validate::MAX_COORDINATE).
pub fn ground_plane_under(b: &crate::relight::Bounds) -> Result<Mesh> {
    crate::relight::scene::validate::check_ground_extent(b)?;
    let side = 4.0 * (b.max[0] - b.min[0]).max(b.max[2] - b.min[2]);
    let c = b.centre();
    let (x0, z0) = (c[0] - 0.5 * side, c[2] + 0.5 * side);
    for corner in [[x0, b.min[1], z0], [x0 + side, b.min[1], z0 - side]] {
        validate::check_point("the ground plane's corner", corner)?;
    }
    ground(x0, z0, b.min[1], side, GROUND_CELLS)
}

/// A procedural mesh; see the [module docs](self) for each one's geometry and size.
///
/// ```
/// use haarshift::relight::Generator;
/// let cubes: Generator = serde_json::from_str(r#"{"cubes": {}}"#).unwrap();
/// assert_eq!(cubes.mesh().unwrap().vertex_count(), 85_860);
/// assert!(serde_json::from_str::<Generator>(r#"{"cubes": {"colour": 1}}"#).is_err());
/// ```
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case", deny_unknown_fields)]
pub enum Generator {
    /// Vollick and Lessig's "Cylinder & Bump": a cylinder beside a Gaussian bump on an 8 x 8 ground.
    CylinderAndBump {
        /// Cells per side of the ground.
        #[serde(default = "default_ground_cells")]
        cells: usize,
    },
    /// Vollick and Lessig's "Cubes": an array of cubes in front of a wall.
    Cubes {
        /// Cubes per row and per column.
        #[serde(default = "default_cube_count")]
        count: usize,
        /// Cells per side of each cube face.
        #[serde(default = "default_cube_cells")]
        cells: usize,
        /// Distance from the wall to the cubes' centres.
        #[serde(default = "default_cube_distance")]
        distance: f64,
    },
    /// A ground plane with a sphere resting on it.
    PlaneWithSphere {},
    /// A unit cube sphere at the origin.
    Sphere {
        /// Cells per side of each cube face.
        cells: usize,
    },
    /// A table: a top 2 x 0.1 x 1.2 at height 0.9 to 1 on four legs 0.08 thick, standing on
    /// `y = 0` (Sun 2006's dynamic-scene setting).
    Table {
        /// Cells per side of each box face.
        cells: usize,
    },
    /// A chair: a seat 0.5 x 0.05 x 0.5 at height 0.45, four legs 0.05 thick and a back 0.5
    /// high, standing on `y = 0`, the back towards +Z.
    Chair {
        /// Cells per side of each box face.
        cells: usize,
    },
    /// A ground plane under a floating box.
    PlaneUnderBox {
        /// Height of the box's bottom face above the plane.
        height: f64,
    },
}

fn default_cube_count() -> usize {
    10
}
fn default_ground_cells() -> usize {
    96
}
fn default_cube_cells() -> usize {
    10
}
fn default_cube_distance() -> f64 {
    1.5
}

/// The largest number of vertices a generator may make.
const MAX_GENERATED_VERTICES: usize = 50_000_000;

impl Generator {
    /// The mesh.
    pub fn mesh(&self) -> Result<Mesh> {
        let positive = |name: &'static str, x: f64| {
            if x.is_finite() && x > 0.0 && x < 1e6 {
                Ok(())
            } else {
                Err(Error::parameter(
                    name,
                    format!("{x}: must be positive and finite"),
                ))
            }
        };
        let cells_ok = |what: &str, n: usize, vertices: usize| {
            if n == 0 || vertices > MAX_GENERATED_VERTICES {
                Err(Error::parameter(
                    "generator",
                    format!(
                        "{n} {what}: must be at least 1 and make at most {MAX_GENERATED_VERTICES} vertices"
                    ),
                ))
            } else {
                Ok(())
            }
        };
        Ok(match *self {
            Generator::CylinderAndBump { cells } => {
                cells_ok("cells", cells, grid_vertices(cells).unwrap_or(usize::MAX))?;
                let mut g = ground(-4.0, 4.0, 0.0, 8.0, cells)?;
                g = g.mapped(
                    |[x, y, z]| {
                        let r2 = (x - 1.5).powi(2) + (z - 1.0).powi(2);
                        [x, y + (-r2 / (2.0 * 0.6 * 0.6)).exp(), z]
                    },
                    |n| n,
                )?;
                let triangles = g.triangles().to_vec();
                let g = Mesh::new(g.positions().to_owned(), triangles, None)?;
                merge([g, cylinder([-1.5, 0.0, -1.0], 0.5, 3.0, 48, 24)])
            }
            Generator::Cubes {
                count,
                cells,
                distance,
            } => {
                positive("distance", distance)?;
                let vertices = 6usize
                    .saturating_mul(count.saturating_mul(count))
                    .saturating_mul(grid_vertices(cells).unwrap_or(usize::MAX));
                cells_ok("cubes per row", count, vertices)?;
                cells_ok("cells", cells, vertices)?;
                let wall = grid(
                    [-6.45, 0.0, 0.0],
                    [12.9, 0.0, 0.0],
                    [0.0, 10.1, 0.0],
                    129,
                    101,
                )?;
                let (h, c) = (0.3, count as f64);
                let cubes = (0..count * count).map(|k| {
                    let x = 1.2 * ((k % count) as f64 - 0.5 * (c - 1.0));
                    let y = 0.6 + 1.0 * (k / count) as f64;
                    cuboid(
                        [x - h, y - h, distance - h],
                        [x + h, y + h, distance + h],
                        cells,
                    )
                });
                merge(
                    std::iter::once(Ok(wall))
                        .chain(cubes)
                        .collect::<Result<Vec<_>>>()?,
                )
            }
            Generator::PlaneWithSphere {} => merge([
                ground(-3.0, 3.0, 0.0, 6.0, 64)?,
                cube_sphere([0.0, 1.0, 0.0], 1.0, 16)?,
            ]),
            Generator::Sphere { cells } => {
                cells_ok(
                    "cells",
                    cells,
                    6usize.saturating_mul(grid_vertices(cells).unwrap_or(usize::MAX)),
                )?;
                cube_sphere([0.0; 3], 1.0, cells)?
            }
            Generator::Table { cells } | Generator::Chair { cells } => {
                let boxes = self.boxes();
                let per_box = 6usize.saturating_mul(grid_vertices(cells).unwrap_or(usize::MAX));
                cells_ok("cells", cells, per_box.saturating_mul(boxes.len()))?;
                let boxes = boxes.into_iter().map(|(lo, hi)| cuboid(lo, hi, cells));
                merge(boxes.collect::<Result<Vec<_>>>()?)
            }
            Generator::PlaneUnderBox { height } => {
                positive("height", height)?;
                merge([
                    ground(-3.0, 3.0, 0.0, 6.0, 2)?,
                    cuboid([-1.0, height, -1.0], [1.0, height + 0.5, 1.0], 4)?,
                ])
            }
        })
    }
}

/// Scale, rotation and translation of an object; see the [module docs](self).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Transform {
    /// Added last.
    #[serde(default)]
    pub translate: [f64; 3],
    /// Uniform scale, applied first.
    #[serde(default = "unit_scale")]
    pub scale: f64,
    /// Degrees about Y.
    #[serde(default)]
    pub yaw: f64,
    /// Degrees about X.
    #[serde(default)]
    pub pitch: f64,
    /// Degrees about Z.
    #[serde(default)]
    pub roll: f64,
}

/// A transform's default scale.
fn unit_scale() -> f64 {
    1.0
}

impl Default for Transform {
    fn default() -> Self {
        Transform {
            translate: [0.0; 3],
            scale: 1.0,
            yaw: 0.0,
            pitch: 0.0,
            roll: 0.0,
        }
    }
}

impl Transform {
    /// `mesh` transformed: positions `R (s p) + t`, normals `R n` (a uniform scale keeps them).
    pub fn apply(&self, mesh: &Mesh) -> Result<Mesh> {
        if !(self.scale.is_finite() && self.scale > 0.0)
            || self.translate.iter().any(|t| !t.is_finite())
        {
            return Err(Error::parameter(
                "transform",
                "scale must be positive and finite, translate finite",
            ));
        }
        let r = SphereRotation::from_degrees(self.yaw, self.pitch, self.roll)?;
        mesh.mapped(
            |p| {
                let q = r.apply(p.map(|x| x * self.scale));
                std::array::from_fn(|k| q[k] + self.translate[k])
            },
            |n| r.apply(n),
        )
    }
}

/// The albedo of the default material.
const DEFAULT_ALBEDO: [f32; 3] = [0.8, 0.8, 0.8];

/// A surface's material: its BRDF (the `brdf` tag, [`Brdf`]'s `--brdf` names) and its RGB
/// albedo, the diffuse colour of a Lambertian surface and the specular colour of a glossy one.
/// Glossy materials are shaded in dynamic scenes ([`DynamicScene`](crate::relight::dynamic::DynamicScene));
/// a static scene ([`Scene`]) takes its BRDF from `--brdf` and refuses them.
///
/// ```
/// use haarshift::relight::{Brdf, Material};
/// let m: Material = serde_json::from_str(
///     r#"{"brdf": "phong", "exponent": 20, "albedo": [0.9, 0.9, 0.9]}"#).unwrap();
/// assert_eq!(m.brdf().unwrap(), Brdf::Phong { exponent: 20.0 });
/// let bad = Material::Phong { albedo: [1.0; 3], exponent: -1.0 };
/// assert!(bad.brdf().unwrap_err().to_string().contains("from 0"));
/// ```
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "brdf", rename_all = "snake_case", deny_unknown_fields)]
pub enum Material {
    /// Lambertian: reflects `albedo / pi` of the irradiance, per channel.
    Lambert {
        /// RGB albedo, each in `[0, 1]`.
        albedo: [f32; 3],
    },
    /// Energy-normalised Phong ([`Brdf::Phong`]).
    Phong {
        /// RGB specular albedo, each in `[0, 1]`.
        albedo: [f32; 3],
        /// Shininess, `0..=`[`MAX_EXPONENT`](crate::relight::material::brdf::MAX_EXPONENT).
        exponent: f64,
    },
    /// Energy-normalised Blinn-Phong ([`Brdf::BlinnPhong`]).
    Blinn {
        /// RGB specular albedo, each in `[0, 1]`.
        albedo: [f32; 3],
        /// Shininess, `0..=`[`MAX_EXPONENT`](crate::relight::material::brdf::MAX_EXPONENT).
        exponent: f64,
    },
}

impl Default for Material {
    fn default() -> Self {
        Material::Lambert {
            albedo: DEFAULT_ALBEDO,
        }
    }
}

impl Material {
    /// The RGB albedo, checked to be in `[0, 1]`.
    ///
    /// ```
    /// use haarshift::relight::Material;
    /// assert_eq!(Material::default().albedo().unwrap(), [0.8; 3]);
    /// assert!(Material::Lambert { albedo: [2.0, 0.0, 0.0] }.albedo().is_err());
    /// ```
    pub fn albedo(&self) -> Result<[f32; 3]> {
        let (Material::Lambert { albedo }
        | Material::Phong { albedo, .. }
        | Material::Blinn { albedo, .. }) = self;
        if albedo.iter().any(|a| !(0.0..=1.0).contains(a)) {
            return Err(SceneError::SceneFile(format!(
                "albedo {albedo:?}: every channel must be in [0, 1]"
            ))
            .into());
        }
        Ok(*albedo)
    }

    /// The BRDF, its exponent checked as `--brdf` checks it (the same grammar: `phong:EXP`).
    ///
    /// ```
    /// use haarshift::relight::{Brdf, Material};
    /// let m = Material::Blinn { albedo: [0.5; 3], exponent: 12.0 };
    /// assert_eq!(m.brdf().unwrap(), Brdf::BlinnPhong { exponent: 12.0 });
    /// assert!(Material::Phong { albedo: [0.5; 3], exponent: f64::NAN }.brdf().is_err());
    /// ```
    pub fn brdf(&self) -> Result<Brdf> {
        let spec = match self {
            Material::Lambert { .. } => return Ok(Brdf::Lambert),
            Material::Phong { exponent, .. } => format!("phong:{exponent}"),
            Material::Blinn { exponent, .. } => format!("blinn:{exponent}"),
        };
        spec.parse::<Brdf>()
            .map_err(|e| SceneError::SceneFile(format!("material: {e}")).into())
    }
}

/// One object of a scene file.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SceneObject {
    /// A name an animation path can refer to (dynamic scenes).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub name: Option<String>,
    /// A mesh file (OBJ or PLY), relative to the scene file.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub mesh: Option<PathBuf>,
    /// A procedural mesh.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub generator: Option<Generator>,
    /// Placement.
    #[serde(default)]
    pub transform: Transform,
    /// Material.
    #[serde(default)]
    pub material: Material,
}

impl SceneObject {
    /// The object's mesh in its own frame (before its transform): its mesh file, relative to
    /// `dir`, or its generator's; `k` is its place in the scene file, for the message.
    pub fn shape(&self, dir: &Path, k: usize) -> Result<Mesh> {
        match (&self.mesh, &self.generator) {
            (Some(path), None) => Mesh::load(&dir.join(path)),
            (None, Some(generator)) => generator.mesh(),
            _ => Err(SceneError::SceneFile(format!(
                "object {k} must have exactly one of \"mesh\" and \"generator\""
            ))
            .into()),
        }
    }
}

/// The environment lighting of a scene file.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct EnvironmentSpec {
    /// The lat-long map (HDR, EXR or `.npy`), relative to the scene file.
    pub path: PathBuf,
    /// Degrees.
    #[serde(default)]
    pub yaw: f64,
    /// Degrees.
    #[serde(default)]
    pub pitch: f64,
    /// Degrees.
    #[serde(default)]
    pub roll: f64,
}

/// The camera of a scene file.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CameraSpec {
    /// Eye position.
    pub position: [f64; 3],
    /// The point the camera looks at.
    pub look_at: [f64; 3],
    /// Vertical field of view, degrees.
    #[serde(default = "default_fov")]
    pub fov: f64,
}

impl CameraSpec {
    /// Checks the position and the point looked at against
    /// [`MAX_COORDINATE`](super::validate::MAX_COORDINATE), as a scene file is read.
    ///
    /// ```
    /// use haarshift::relight::CameraSpec;
    /// let far = CameraSpec { position: [0.0, 2.0, 5.0], look_at: [0.0, 1e308, 0.0], fov: 40.0 };
    /// assert!(matches!(far.check(), Err(haarshift::Error::Scene { .. })));
    /// ```
    pub fn check(&self) -> Result<()> {
        validate::check_point("the camera's position", self.position)?;
        validate::check_point("the camera's look_at", self.look_at)
    }
}

fn default_fov() -> f64 {
    45.0
}

/// A scene file's content; see the [module docs](self) for the schema.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SceneFile {
    /// The objects, merged in order.
    pub objects: Vec<SceneObject>,
    /// Whether to add the ground plane.
    #[serde(default)]
    pub ground_plane: bool,
    /// The lighting.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub environment: Option<EnvironmentSpec>,
    /// The camera.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub camera: Option<CameraSpec>,
}

/// A scene ready to precompute: one merged mesh, an albedo per vertex, and the scene file's
/// lighting and camera with their paths resolved.
///
/// ```
/// use haarshift::relight::Scene;
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
}

impl Scene {
    /// A scene of one mesh with the default material (and, if asked, the ground plane:
    /// errors as [`add_ground_plane`] does).
    pub fn from_mesh(mesh: Mesh, ground_plane: bool) -> Result<Scene> {
        let mut scene = Scene {
            albedo: Array2::zeros((0, 3)),
            mesh,
            environment: None,
            camera: None,
            ground_plane: false,
        };
        scene.albedo =
            Array2::from_shape_fn((scene.mesh.vertex_count(), 3), |(_, c)| DEFAULT_ALBEDO[c]);
        if ground_plane {
            scene.add_ground_plane()?;
        }
        Ok(scene)
    }

    /// Appends the ground plane ([`add_ground_plane`]) with albedo [`GROUND_ALBEDO`], unless the
    /// scene has it already.
    ///
    /// ```
    /// use haarshift::relight::{Generator, Scene};
    /// let mut scene = Scene::from_mesh(Generator::Sphere { cells: 2 }.mesh().unwrap(), true).unwrap();
    /// let v = scene.mesh.vertex_count();
    /// scene.add_ground_plane().unwrap();
    /// assert_eq!((scene.mesh.vertex_count(), scene.ground_plane), (v, true));
    /// ```
    ///
    /// Errors (leaving the scene as it was) as [`add_ground_plane`] does.
    pub fn add_ground_plane(&mut self) -> Result<()> {
        if self.ground_plane {
            return Ok(());
        }
        let before = self.mesh.vertex_count();
        add_ground_plane(&mut self.mesh)?;
        self.ground_plane = true;
        let added = Array2::from_shape_fn((self.mesh.vertex_count() - before, 3), |(_, c)| {
            GROUND_ALBEDO[c]
        });
        self.albedo
            .append(ndarray::Axis(0), added.view())
            .expect("both are (V, 3)");
        Ok(())
    }

    /// The vertices of the scene's objects, `0..object_vertices()`: all but the ground plane's
    /// (the last [`GROUND_VERTICES`] when the scene has it), which stays Lambertian under a
    /// glossy BRDF.
    ///
    /// ```
    /// use haarshift::relight::{Generator, Scene};
    /// let sphere = Generator::Sphere { cells: 2 }.mesh().unwrap();
    /// assert_eq!(Scene::from_mesh(sphere.clone(), true).unwrap().object_vertices(), 54);
    /// assert_eq!(Scene::from_mesh(sphere, false).unwrap().object_vertices(), 54);
    /// ```
    pub fn object_vertices(&self) -> usize {
        object_vertices(self.mesh.vertex_count(), self.ground_plane)
    }

    /// Reads a scene: a JSON scene file (`.json`), or a mesh file (OBJ or PLY) as a scene of
    /// one object with the default material.
    pub fn load(path: &Path) -> Result<Scene> {
        let is_json = path
            .extension()
            .is_some_and(|e| e.eq_ignore_ascii_case("json"));
        if !is_json {
            return Scene::from_mesh(Mesh::load(path)?, false);
        }
        let (file, dir) = SceneFile::read(path)?;
        file.build(dir).map_err(|e| e.in_file(path))
    }
}

/// Reads a JSON file of the scene family (scene files, motion paths) into `T`; a bad file is
/// a [`SceneError::SceneFile`] naming it.
pub(crate) fn read_json<T: serde::de::DeserializeOwned>(path: &Path) -> Result<T> {
    let text = std::fs::read_to_string(path).map_err(|source| Error::Io {
        path: path.to_path_buf(),
        source,
    })?;
    serde_json::from_str(&text)
        .map_err(|e| Error::from(SceneError::SceneFile(e.to_string())).in_file(path))
}

impl SceneFile {
    /// Reads a JSON scene file; returns it with the directory its relative paths start from.
    pub fn read(path: &Path) -> Result<(SceneFile, &Path)> {
        Ok((read_json(path)?, path.parent().unwrap_or(Path::new(""))))
    }

    /// The scene, relative paths resolved against `dir`.
    pub fn build(&self, dir: &Path) -> Result<Scene> {
        if self.objects.is_empty() {
            return Err(SceneError::SceneFile("a scene needs at least one object".into()).into());
        }
        if let Some(camera) = &self.camera {
            camera.check()?;
        }
        let mut mesh: Option<Mesh> = None;
        let mut albedo = Array2::<f32>::zeros((0, 3));
        for (k, object) in self.objects.iter().enumerate() {
            let shape = object.shape(dir, k)?;
            let shape = object.transform.apply(&shape)?;
            let a = object.material.albedo()?;
            if !object.material.brdf()?.is_lambert() {
                return Err(SceneError::SceneFile(format!(
                    "object {k}: a glossy material is shaded in dynamic scenes (relight scene); \
                     a static scene takes its BRDF from --brdf"
                ))
                .into());
            }
            let rows = Array2::from_shape_fn((shape.vertex_count(), 3), |(_, c)| a[c]);
            albedo
                .append(ndarray::Axis(0), rows.view())
                .expect("(V, 3)");
            match &mut mesh {
                None => mesh = Some(shape),
                Some(m) => m.append(&shape),
            }
        }
        let mut scene = Scene {
            mesh: mesh.expect("at least one object"),
            albedo,
            environment: self.environment.clone().map(|mut e| {
                e.path = dir.join(&e.path);
                e
            }),
            camera: self.camera.clone(),
            ground_plane: false,
        };
        if self.ground_plane {
            scene.add_ground_plane()?;
        }
        Ok(scene)
    }
}

#[cfg(test)]
mod tests;
