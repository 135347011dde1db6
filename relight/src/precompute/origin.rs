//! Where a vertex's rays start: one ray offset off its own surface, and off every other
//! surface it touches (creases and contact).
//!
//! **The rule** (the contract every ray from a vertex follows: visibility, the bounce gather,
//! `relight reference` and the path tracer's first ray). Vertex `v` has position `p`, unit
//! normal `n`, and `eps` = [`ray_offset`] (`1e-4 x` the scene's bounding-box diagonal).
//! 1. Its *lifted point* is `o = p + eps n`.
//! 2. `v` is a **contact vertex** when some triangle the tracers see (each distinct triangle
//!    of non-zero area once, in f32) that does not have `v` as a corner comes closer to `o`
//!    than `eps / 2` (the exact point-to-triangle distance, in
//!    f64, on the mesh's positions). This is a vertex on a crease of a flat-shaded mesh (a
//!    floor vertex against a wall: the floor's normal runs up the wall, so `o` lies in the
//!    wall's plane) or where two objects touch (a foot on the ground). Every other vertex is
//!    *clear*.
//! 3. A clear vertex's rays start at `o`. A contact vertex's start at `o + eps m`, where `m`
//!    is the unit direction into its own faces: the sum, over the triangles with corner `v`,
//!    of the unit vectors from `p` to their centroids, with its component along `n` removed,
//!    normalised (when that is shorter than `1e-3`, the faces stand all around the vertex, `m = 0`
//!    and the rays start at `o`).
//!
//! **Why.** From a point in another triangle's plane a ray meets that triangle at `t = 0`,
//! and whether it counts is rounding's choice: before this rule Embree counted every such hit
//! (the vertex black at every resolution) and our packets counted them at random (0.05x to
//! 4.3x the physical light, median 0.48x, at the 260 crease vertices of `bunny_in_box.json`),
//! and Mitsuba 3, which ignores hits at `t = 0`, saw through the wall. Moved into its own
//! faces, the origin is the lifted point of a point of those faces one offset away from the
//! vertex, so the vertex gets the value its faces tend to as they approach it: a floor
//! vertex against a wall sees the half of the sky the wall leaves open, as the floor beside it
//! does, and the wall is met at `t >= eps / 2` or so, where both tracers agree. A clear vertex
//! is untouched, so a mesh without creases or contact casts the rays it always has.
//!
//! The threshold `eps / 2` leaves out a vertex's neighbours across a convex edge (a box's
//! outer edge: the other face is `eps` from `o`) and a concave edge of up to 120 degrees
//! between the faces (the other face is at least `eps cos 60 = eps / 2` from `o`).
//!
//! ```
//! use haarshift_relight::Mesh;
//! use haarshift_relight::precompute::origin::RayOrigins;
//! use ndarray::array;
//! // A floor (facing +Y) with a wall (facing +Z) standing on its back edge, flat-shaded:
//! // the floor's back vertices stand on the crease.
//! let mesh = Mesh::new(
//!     array![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 0.0, 1.0], [0.0, 0.0, 1.0],
//!            [0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [0.0, 1.0, 0.0]],
//!     vec![[0, 2, 1], [0, 3, 2], [4, 5, 6], [4, 6, 7]],
//!     Some(array![[0.0, 1.0, 0.0], [0.0, 1.0, 0.0], [0.0, 1.0, 0.0], [0.0, 1.0, 0.0],
//!                 [0.0, 0.0, 1.0], [0.0, 0.0, 1.0], [0.0, 0.0, 1.0], [0.0, 0.0, 1.0]]),
//! ).unwrap();
//! let origins = RayOrigins::new(&mesh);
//! assert_eq!(origins.contact_vertices(), vec![0, 1, 4, 5]);
//! // Vertex 2 is clear: lifted by eps = 1e-4 x sqrt(3).
//! let eps = 1e-4 * 3f64.sqrt();
//! assert_eq!(origins.origin_and_normal(2).0, [1.0, eps, 1.0]);
//! // Vertex 0 moves off the wall into the floor, toward its faces' centroids.
//! let (o, _) = origins.origin_and_normal(0);
//! assert!(o[2] > 0.5 * eps && (o[1] - eps).abs() < 1e-15);
//! ```

use glam::Vec3A;
use obvhs::BvhBuildParams;
use obvhs::aabb::Aabb;
use obvhs::bvh2::Bvh2;
use obvhs::bvh2::builder::build_bvh2_from_tris;
use obvhs::triangle::Triangle;

use crate::Mesh;
use crate::precompute::raycast::CleanTriangles;
use crate::precompute::visibility::ray_offset;
use crate::scene::mesh::{dot, sub, unit};

/// The shortest sum of unit vectors (rule 3) that gives a direction `m`: shorter, the faces
/// stand all around the vertex and the direction is rounding's.
const MIN_TANGENT: f64 = 1e-3;

/// The ray origins of a mesh's vertices; see the [module docs](self).
pub struct RayOrigins<'a> {
    mesh: &'a Mesh,
    eps: f64,
    /// The triangles the tree holds, indices into `mesh.triangles()`.
    kept: Vec<u32>,
    /// The power of two the tree's positions were scaled by.
    scale: f64,
    /// A tree over `kept` (f32 boxes, widened so that no triangle within `eps / 2` of a point
    /// is missed), `None` for a mesh without a triangle of non-zero area.
    bvh: Option<Bvh2>,
    /// `faces[first[v]..first[v + 1]]`: the triangles with corner `v`.
    first: Vec<u32>,
    faces: Vec<u32>,
}

impl<'a> RayOrigins<'a> {
    /// Indexes `mesh`'s triangles for the contact test: those the tracers see (each distinct
    /// triangle of non-zero area once, in f32, as [`SceneBvh`](super::raycast::SceneBvh)
    /// keeps them, a tiny scene scaled up by a power of two), in a tree built for speed.
    pub fn new(mesh: &'a Mesh) -> Self {
        let eps = ray_offset(mesh);
        let clean = CleanTriangles::of(mesh);
        let boxes: Vec<Triangle> = clean
            .triangles
            .iter()
            .map(|t| {
                let [v0, v1, v2] = t.map(Vec3A::from_array);
                Triangle { v0, v1, v2 }
            })
            .collect();
        let bvh = (!boxes.is_empty()).then(|| {
            let params = BvhBuildParams::fastest_build();
            build_bvh2_from_tris(&boxes, params, &mut std::time::Duration::default())
        });
        let (first, faces) = faces_of_vertices(mesh);
        RayOrigins {
            mesh,
            eps,
            kept: clean.source,
            scale: f64::from(clean.scale),
            bvh,
            first,
            faces,
        }
    }

    /// The ray offset `eps` ([`ray_offset`]).
    pub fn eps(&self) -> f64 {
        self.eps
    }

    /// Vertex `v`'s lifted point `p + eps n` and its normal.
    fn lifted(&self, v: usize) -> ([f64; 3], [f64; 3]) {
        let (p, n) = (self.mesh.positions(), self.mesh.normals());
        let n = [n[[v, 0]], n[[v, 1]], n[[v, 2]]];
        (std::array::from_fn(|k| p[[v, k]] + self.eps * n[k]), n)
    }

    /// Whether `v` is a contact vertex (rule 2 of the [module docs](self)).
    pub fn is_contact(&self, v: usize) -> bool {
        let Some(bvh) = &self.bvh else { return false };
        let (o, _) = self.lifted(v);
        let reach = 0.5 * self.eps;
        // The f32 query box is widened by a relative margin, so that rounding the triangles'
        // boxes to f32 never drops one within reach.
        let pad = |x: f64, s: f64| {
            let y = (x + s * reach) * self.scale;
            (y + s * (y.abs() * 1e-6 + f64::from(f32::MIN_POSITIVE))) as f32
        };
        let query = Aabb::new(
            Vec3A::new(pad(o[0], -1.0), pad(o[1], -1.0), pad(o[2], -1.0)),
            Vec3A::new(pad(o[0], 1.0), pad(o[1], 1.0), pad(o[2], 1.0)),
        );
        let own = self.own_faces(v);
        let (p, triangles) = (self.mesh.positions(), self.mesh.triangles());
        let corner = |i: u32| [0, 1, 2].map(|k| p[[i as usize, k]]);
        let mut contact = false;
        bvh.aabb_traverse(query, |bvh, node| {
            let node = &bvh.nodes[node as usize];
            let leaf = node.first_index..node.first_index + node.prim_count;
            contact = leaf.into_iter().any(|i| {
                let t = self.kept[bvh.primitive_indices[i as usize] as usize];
                !own.contains(&t)
                    && distance_squared(o, triangles[t as usize].map(corner)) < reach * reach
            });
            !contact
        });
        contact
    }

    fn own_faces(&self, v: usize) -> &[u32] {
        &self.faces[self.first[v] as usize..self.first[v + 1] as usize]
    }

    /// Where vertex `v`'s rays start, and its normal (rule 3 of the [module docs](self)).
    pub fn origin_and_normal(&self, v: usize) -> ([f64; 3], [f64; 3]) {
        let (o, n) = self.lifted(v);
        if !self.is_contact(v) {
            return (o, n);
        }
        let p = self.mesh.positions();
        let p = [p[[v, 0]], p[[v, 1]], p[[v, 2]]];
        let mut sum = [0.0; 3];
        let corner = |i: u32| [0, 1, 2].map(|k| self.mesh.positions()[[i as usize, k]]);
        for &t in self.own_faces(v) {
            let [a, b, c] = self.mesh.triangles()[t as usize].map(corner);
            let centroid = std::array::from_fn(|k| (a[k] + b[k] + c[k]) / 3.0);
            if let Some(u) = unit(sub(centroid, p)) {
                sum = std::array::from_fn(|k| sum[k] + u[k]);
            }
        }
        let along = dot(sum, n);
        let tangent: [f64; 3] = std::array::from_fn(|k| sum[k] - along * n[k]);
        if dot(tangent, tangent) < MIN_TANGENT * MIN_TANGENT {
            return (o, n);
        }
        let Some(m) = unit(tangent) else {
            return (o, n);
        };
        (std::array::from_fn(|k| o[k] + self.eps * m[k]), n)
    }

    /// The contact vertices, in increasing order.
    pub fn contact_vertices(&self) -> Vec<usize> {
        (0..self.mesh.vertex_count())
            .filter(|&v| self.is_contact(v))
            .collect()
    }
}

/// For each vertex the triangles with that corner, as offsets `first` (`V + 1`) into `faces`
/// (a triangle that lists a corner twice is listed twice for it).
fn faces_of_vertices(mesh: &Mesh) -> (Vec<u32>, Vec<u32>) {
    let mut first = vec![0u32; mesh.vertex_count() + 1];
    for &c in mesh.triangles().iter().flatten() {
        first[c as usize + 1] += 1;
    }
    for v in 0..mesh.vertex_count() {
        first[v + 1] += first[v];
    }
    let mut next = first.clone();
    let mut faces = vec![0u32; first[mesh.vertex_count()] as usize];
    for (t, corners) in (0u32..).zip(mesh.triangles()) {
        for &c in corners {
            faces[next[c as usize] as usize] = t;
            next[c as usize] += 1;
        }
    }
    (first, faces)
}

/// The squared distance from `q` to the closest point of the triangle `[a, b, c]` (of
/// non-zero area): Ericson 2005, "Real-Time Collision Detection", section 5.1.5, by the
/// Voronoi regions of the corners and edges.
pub(crate) fn distance_squared(q: [f64; 3], [a, b, c]: [[f64; 3]; 3]) -> f64 {
    let closest = closest_point(q, a, b, c);
    let d = sub(q, closest);
    dot(d, d)
}

fn closest_point(p: [f64; 3], a: [f64; 3], b: [f64; 3], c: [f64; 3]) -> [f64; 3] {
    let along = |x: [f64; 3], d: [f64; 3], s: f64| std::array::from_fn(|k| x[k] + s * d[k]);
    let (ab, ac, ap) = (sub(b, a), sub(c, a), sub(p, a));
    let (d1, d2) = (dot(ab, ap), dot(ac, ap));
    if d1 <= 0.0 && d2 <= 0.0 {
        return a;
    }
    let bp = sub(p, b);
    let (d3, d4) = (dot(ab, bp), dot(ac, bp));
    if d3 >= 0.0 && d4 <= d3 {
        return b;
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        return along(a, ab, d1 / (d1 - d3));
    }
    let cp = sub(p, c);
    let (d5, d6) = (dot(ab, cp), dot(ac, cp));
    if d6 >= 0.0 && d5 <= d6 {
        return c;
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        return along(a, ac, d2 / (d2 - d6));
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0 {
        return along(b, sub(c, b), (d4 - d3) / ((d4 - d3) + (d5 - d6)));
    }
    let denom = 1.0 / (va + vb + vc);
    let (v, w) = (vb * denom, vc * denom);
    std::array::from_fn(|k| a[k] + ab[k] * v + ac[k] * w)
}

#[cfg(test)]
#[path = "origin_tests.rs"]
mod tests;
