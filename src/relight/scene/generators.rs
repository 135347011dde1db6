//! Procedural meshes named by a [`Generator`] and its settings; the [module docs](super) list
//! each one's geometry and size.

use serde::{Deserialize, Serialize};

use crate::relight::Mesh;
use crate::relight::scene::ground::ground;
use crate::relight::scene::shapes::{cube_sphere, cuboid, cylinder, grid, merge};
use crate::relight::scene::validate::grid_vertices;
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
