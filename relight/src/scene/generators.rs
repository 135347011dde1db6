//! Procedural meshes named by a [`Generator`] and its settings; the [module docs](super) list
//! each one's geometry and size.

use serde::{Deserialize, Serialize};

use crate::Mesh;
use crate::scene::ground::ground;
use crate::scene::shapes::{cube_sphere, cuboid, cylinder, grid, merge};
use crate::scene::validate::grid_vertices;
use crate::{Error, Result};

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

/// A procedural mesh; see the [module docs](super) for each one's geometry and size.
///
/// ```
/// use haarshift_relight::Generator;
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
    /// An open box: a floor `[-1, 1]^2` at `y = 0` and four walls 2 high, all facing inward,
    /// open at the top.
    ///
    /// ```
    /// use haarshift_relight::Generator;
    /// let b: Generator = serde_json::from_str(r#"{"box": {"cells": 2}}"#).unwrap();
    /// assert_eq!(b.mesh().unwrap().vertex_count(), 5 * 9);
    /// ```
    #[serde(rename = "box")]
    OpenBox {
        /// Cells per side of each face.
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

/// The cylinder of [`Generator::CylinderAndBump`]: segments and rings.
const CYLINDER: (usize, usize) = (48, 24);
/// Its vertices ([`cylinder`]: the side's `(segments + 1) (rings + 1)` and two capped fans).
const CYLINDER_VERTICES: usize = 1298;
/// [`Generator::PlaneWithSphere`]: the ground's cells a side, the sphere's a face.
const PLANE_WITH_SPHERE_CELLS: (usize, usize) = (64, 16);
/// [`Generator::PlaneUnderBox`]: the ground's cells a side, the box's a face.
const PLANE_UNDER_BOX_CELLS: (usize, usize) = (2, 4);
/// [`Generator::Cubes`]'s wall: cells across and up.
const WALL_CELLS: (usize, usize) = (129, 101);

/// The largest number of vertices a generator may make.
const MAX_GENERATED_VERTICES: usize = 50_000_000;

impl Generator {
    /// The vertices [`mesh`](Self::mesh) makes, from the settings alone (nothing is built),
    /// or `None` when the count does not fit in a `usize`; so a scene's size is known, and
    /// checked against its [`MemoryBudget`](super::validate::MemoryBudget), before it exists.
    ///
    /// ```
    /// use haarshift_relight::Generator;
    /// let sphere = Generator::Sphere { cells: 3 };
    /// assert_eq!(sphere.vertex_count(), Some(sphere.mesh().unwrap().vertex_count()));
    /// assert_eq!(Generator::Sphere { cells: usize::MAX }.vertex_count(), None);
    /// ```
    pub fn vertex_count(&self) -> Option<usize> {
        let boxes = |cells: usize, n: usize| grid_vertices(cells)?.checked_mul(6 * n);
        match *self {
            Generator::CylinderAndBump { cells } => {
                grid_vertices(cells)?.checked_add(CYLINDER_VERTICES)
            }
            Generator::Cubes { count, cells, .. } => {
                let wall = (WALL_CELLS.0 + 1) * (WALL_CELLS.1 + 1);
                boxes(cells, 1)?
                    .checked_mul(count.checked_mul(count)?)?
                    .checked_add(wall)
            }
            Generator::PlaneWithSphere {} => {
                let (ground, sphere) = PLANE_WITH_SPHERE_CELLS;
                grid_vertices(ground)?.checked_add(boxes(sphere, 1)?)
            }
            Generator::Sphere { cells } => boxes(cells, 1),
            Generator::OpenBox { cells } => grid_vertices(cells)?.checked_mul(5),
            Generator::Table { cells } | Generator::Chair { cells } => {
                boxes(cells, self.boxes().len())
            }
            Generator::PlaneUnderBox { .. } => {
                let (ground, cuboid) = PLANE_UNDER_BOX_CELLS;
                grid_vertices(ground)?.checked_add(boxes(cuboid, 1)?)
            }
        }
    }

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
        let at_least_one = |what: &str, n: usize| {
            if n == 0 {
                Err(Error::parameter(
                    "generator",
                    format!("0 {what}: must be at least 1"),
                ))
            } else {
                Ok(())
            }
        };
        match self.vertex_count() {
            Some(v) if v <= MAX_GENERATED_VERTICES => {}
            _ => {
                return Err(Error::parameter(
                    "generator",
                    format!("{self:?} makes more than {MAX_GENERATED_VERTICES} vertices"),
                ));
            }
        }
        Ok(match *self {
            Generator::CylinderAndBump { cells } => {
                at_least_one("cells", cells)?;
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
                merge([
                    g,
                    cylinder([-1.5, 0.0, -1.0], 0.5, 3.0, CYLINDER.0, CYLINDER.1),
                ])
            }
            Generator::Cubes {
                count,
                cells,
                distance,
            } => {
                positive("distance", distance)?;
                at_least_one("cubes per row", count)?;
                at_least_one("cells", cells)?;
                let wall = grid(
                    [-6.45, 0.0, 0.0],
                    [12.9, 0.0, 0.0],
                    [0.0, 10.1, 0.0],
                    WALL_CELLS.0,
                    WALL_CELLS.1,
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
                ground(-3.0, 3.0, 0.0, 6.0, PLANE_WITH_SPHERE_CELLS.0)?,
                cube_sphere([0.0, 1.0, 0.0], 1.0, PLANE_WITH_SPHERE_CELLS.1)?,
            ]),
            Generator::Sphere { cells } => {
                at_least_one("cells", cells)?;
                cube_sphere([0.0; 3], 1.0, cells)?
            }
            Generator::Table { cells } | Generator::Chair { cells } => {
                at_least_one("cells", cells)?;
                let boxes = self
                    .boxes()
                    .into_iter()
                    .map(|(lo, hi)| cuboid(lo, hi, cells));
                merge(boxes.collect::<Result<Vec<_>>>()?)
            }
            Generator::OpenBox { cells } => {
                at_least_one("cells", cells)?;
                // (origin, u, v) with u x v pointing into the box.
                let faces = [
                    ([-1.0, 0.0, 1.0], [2.0, 0.0, 0.0], [0.0, 0.0, -2.0]),
                    ([-1.0, 0.0, 1.0], [0.0, 0.0, -2.0], [0.0, 2.0, 0.0]),
                    ([1.0, 0.0, -1.0], [0.0, 0.0, 2.0], [0.0, 2.0, 0.0]),
                    ([-1.0, 0.0, -1.0], [2.0, 0.0, 0.0], [0.0, 2.0, 0.0]),
                    ([1.0, 0.0, 1.0], [-2.0, 0.0, 0.0], [0.0, 2.0, 0.0]),
                ];
                let faces = faces.iter().map(|&(o, u, v)| grid(o, u, v, cells, cells));
                merge(faces.collect::<Result<Vec<_>>>()?)
            }
            Generator::PlaneUnderBox { height } => {
                positive("height", height)?;
                merge([
                    ground(-3.0, 3.0, 0.0, 6.0, PLANE_UNDER_BOX_CELLS.0)?,
                    cuboid(
                        [-1.0, height, -1.0],
                        [1.0, height + 0.5, 1.0],
                        PLANE_UNDER_BOX_CELLS.1,
                    )?,
                ])
            }
        })
    }
}
