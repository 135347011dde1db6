//! The primitive meshes the generators and the ground plane are made of: grids, boxes, cube
//! spheres and capped cylinders.

use ndarray::Array2;

use crate::Mesh;
use crate::Result;
use crate::scene::mesh::{cross, dot};

/// A grid of `nu x nv` cells on the parallelogram `origin + s u + t v`, `s, t in [0, 1]`;
/// normal `u x v` (normalised), vertices `(nu + 1)(nv + 1)`, `s` fastest.
pub(crate) fn grid(
    origin: [f64; 3],
    u: [f64; 3],
    v: [f64; 3],
    nu: usize,
    nv: usize,
) -> Result<Mesh> {
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

/// The six outward faces of the box `[min, max]`, `cells x cells` each, in the order +X, -X,
/// +Y, -Y, +Z, -Z.
pub(crate) fn cuboid(min: [f64; 3], max: [f64; 3], cells: usize) -> Result<Mesh> {
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
pub(crate) fn cube_sphere(centre: [f64; 3], radius: f64, cells: usize) -> Result<Mesh> {
    let cube = cuboid([-1.0; 3], [1.0; 3], cells)?;
    let projected = cube.mapped(
        |p| {
            let len = dot(p, p).sqrt();
            std::array::from_fn(|k| centre[k] + radius * p[k] / len)
        },
        |_| [0.0; 3],
    )?;
    with_radial_normals(projected, centre)
}

/// `mesh` with every normal pointing from `centre` to its vertex.
fn with_radial_normals(mesh: Mesh, centre: [f64; 3]) -> Result<Mesh> {
    let normals = Array2::from_shape_fn((mesh.vertex_count(), 3), |(v, k)| {
        mesh.positions()[[v, k]] - centre[k]
    });
    let triangles = mesh.triangles().to_vec();
    Mesh::new(mesh.positions().to_owned(), triangles, Some(normals))
}

/// A capped cylinder standing on `base`, `segments` around and `rings` up.
pub(crate) fn cylinder(
    base: [f64; 3],
    radius: f64,
    height: f64,
    segments: usize,
    rings: usize,
) -> Mesh {
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
