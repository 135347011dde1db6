//! Conforming longest-edge bisection of a scene's mesh (Rivara 1984), the mesh side of
//! `relight precompute --refine` ([`precompute::refine`](crate::precompute::refine)
//! decides which edges to split).
//!
//! **Splitting an edge.** An edge `(a, b)` is split at its midpoint `m = (p_a + p_b) / 2`,
//! and so is *every* triangle that has it (two on a manifold edge, one on a boundary, more on
//! a non-manifold one), each into two that keep its winding: `[x, y, z]` with the edge
//! `x -> y` becomes `[x, m, z]` and `[m, y, z]`. A shared edge therefore gets one midpoint
//! and every triangle beside it uses it: no triangle ever has a vertex in the middle of one
//! of its edges (a T-junction), after every single split, so a run stopped by its budget
//! between two splits leaves a conforming mesh too.
//!
//! **Longest edge first** (Rivara's longest-edge propagation path). An edge is split only
//! when it is the longest edge of every triangle that has it; otherwise the longest edge of
//! the triangle where it is not is split first, and so on up the path. Lengths are compared
//! squared and ties are broken by the vertex indices, so "longest" names one edge and the
//! path, whose edges grow strictly, ends. Splitting longest edges only keeps the triangles'
//! angles bounded away from zero (Rivara's theorem), where splitting the edge asked for alone
//! would make slivers.
//!
//! **What a new vertex gets.** Its position is the midpoint; its normal the normalised sum of
//! the edge's endpoints' normals (the normal interpolated halfway, as shading interpolates
//! it; `(0, 0, 0)` when they are opposite); its albedo the mean of theirs (a texture is not
//! sampled again). Old vertices keep their normals: recomputing the area-weighted normals
//! after each split would tilt the normals of the split edge's endpoints toward the faces
//! that were not split (each split halves the weight of the triangles it divides), so the
//! shading would drift toward the flat facets as refinement goes on, and every such vertex
//! would need its transport again. Interpolated, refinement converges to the smooth shading
//! the normals describe, and a vertex's transport, once computed, is final.
//!
//! **Vertex order.** The scene's objects, then the ground plane (whose vertices must stay the
//! trailing block, [`Scene::ground_vertices`]); within each, the original vertices first, in
//! their order, then the new ones in the order they were made. A midpoint belongs to the
//! group of its edge (the ground plane is a separate component, so an edge is never half
//! ground).
//!
//! **What is left alone.** Triangles that name a vertex twice have no edge to split (they
//! have no area and are never hit); they are kept as they are. Edges are the pairs of vertex
//! *indices*: two vertices at one position (a crease's split normals, a texture seam) are two
//! surfaces to the splitting, and a midpoint on one side lies on the other side's edge to
//! within rounding, so no gap opens there either.

use std::collections::BTreeMap;

use ndarray::Array2;

use crate::Result;
use crate::scene::mesh::{dot, sub, unit};
use crate::{Mesh, Scene};

/// An edge: its two vertex indices, the smaller first.
pub(crate) type Edge = (u32, u32);

fn edge(a: u32, b: u32) -> Edge {
    (a.min(b), a.max(b))
}

/// A mesh being bisected, in the order vertices are made (the original ones first); see the
/// [module docs](self).
#[derive(Clone, Debug)]
pub(crate) struct Bisection {
    positions: Vec<[f64; 3]>,
    normals: Vec<[f64; 3]>,
    albedo: Vec<[f32; 3]>,
    /// Whether each vertex is the ground plane's.
    ground: Vec<bool>,
    triangles: Vec<[u32; 3]>,
    /// Every edge of a triangle with three distinct vertices, with those triangles.
    edges: BTreeMap<Edge, Vec<u32>>,
    /// Vertices before any split.
    original: usize,
}

impl Bisection {
    /// The scene's mesh, before any split.
    pub(crate) fn new(scene: &Scene) -> Self {
        let mesh = &scene.mesh;
        let row = |a: ndarray::ArrayView2<'_, f64>, v: usize| [a[[v, 0]], a[[v, 1]], a[[v, 2]]];
        let v = mesh.vertex_count();
        let objects = scene.object_vertices();
        let mut b = Bisection {
            positions: (0..v).map(|k| row(mesh.positions(), k)).collect(),
            normals: (0..v).map(|k| row(mesh.normals(), k)).collect(),
            albedo: (0..v)
                .map(|k| std::array::from_fn(|c| scene.albedo[[k, c]]))
                .collect(),
            ground: (0..v).map(|k| k >= objects).collect(),
            triangles: mesh.triangles().to_vec(),
            edges: BTreeMap::new(),
            original: v,
        };
        for t in 0..b.triangles.len() as u32 {
            b.link(t);
        }
        b
    }

    /// Vertices, original and new.
    pub(crate) fn vertex_count(&self) -> usize {
        self.positions.len()
    }

    /// Vertex `v`'s normal.
    pub(crate) fn normal(&self, v: usize) -> [f64; 3] {
        self.normals[v]
    }

    /// Every edge, in index order (each with its triangles).
    pub(crate) fn edges(&self) -> impl Iterator<Item = Edge> + '_ {
        self.edges.keys().copied()
    }

    /// Whether `e` is an edge of the mesh as it now is (not split, nor never made).
    pub(crate) fn has_edge(&self, e: Edge) -> bool {
        self.edges.contains_key(&e)
    }

    /// The squared length of `e`.
    pub(crate) fn squared_length(&self, (a, b): Edge) -> f64 {
        let d = sub(self.positions[a as usize], self.positions[b as usize]);
        dot(d, d)
    }

    /// The triangles of `e` (none once it has been split).
    #[cfg(test)]
    pub(crate) fn triangles_of(&self, e: Edge) -> &[u32] {
        self.edges.get(&e).map_or(&[], Vec::as_slice)
    }

    /// The triangles, each `[x, y, z]` counter-clockwise as the original was.
    #[cfg(test)]
    pub(crate) fn triangles(&self) -> &[[u32; 3]] {
        &self.triangles
    }

    /// Splits `e` and whatever its longest-edge path needs split first, one vertex at a
    /// time, while the mesh has fewer than `max_vertices` vertices. Returns whether `e` is
    /// gone (split now or before); `false` when the budget stopped it, the mesh conforming
    /// still.
    pub(crate) fn split(&mut self, e: Edge, max_vertices: usize) -> bool {
        let mut path = vec![e];
        while let Some(&top) = path.last() {
            let Some(triangles) = self.edges.get(&top) else {
                path.pop();
                continue;
            };
            let longer = triangles
                .iter()
                .map(|&t| self.longest(t))
                .find(|&l| l != top);
            if let Some(longer) = longer {
                path.push(longer);
                continue;
            }
            if self.vertex_count() >= max_vertices {
                return false;
            }
            self.split_edge(top);
            path.pop();
        }
        true
    }

    /// The mesh in the order vertices were made (for tracing: the order does not change a
    /// vertex's rays).
    pub(crate) fn working_mesh(&self) -> Result<Mesh> {
        let identity: Vec<u32> = (0..self.vertex_count() as u32).collect();
        self.mesh_in(&identity, &identity)
    }

    /// The vertex order of the refined scene (see the [module docs](self)): for each of its
    /// vertices, which one of this bisection it is.
    pub(crate) fn order(&self) -> Vec<u32> {
        let original = self.original;
        let (old, new) = (
            0..original as u32,
            original as u32..self.vertex_count() as u32,
        );
        let on = |ground: bool| move |&v: &u32| self.ground[v as usize] == ground;
        (old.clone().filter(on(false)))
            .chain(new.clone().filter(on(false)))
            .chain(old.filter(on(true)))
            .chain(new.filter(on(true)))
            .collect()
    }

    /// The refined scene in [`order`](Self::order): the mesh, its albedo and its ground
    /// plane's vertex count; the environment, camera and ground cells are `scene`'s.
    pub(crate) fn scene(&self, scene: &Scene) -> Result<Scene> {
        let order = self.order();
        let mut place = vec![0u32; order.len()];
        for (to, &from) in order.iter().enumerate() {
            place[from as usize] = to as u32;
        }
        let albedo =
            Array2::from_shape_fn((order.len(), 3), |(v, c)| self.albedo[order[v] as usize][c]);
        Ok(Scene {
            mesh: self.mesh_in(&order, &place)?,
            albedo,
            ground_vertices: self.ground.iter().filter(|&&g| g).count(),
            warnings: Vec::new(),
            ..scene.clone()
        })
    }

    /// The mesh with vertex `order[k]` of this bisection as its `k`-th (`place` the inverse).
    fn mesh_in(&self, order: &[u32], place: &[u32]) -> Result<Mesh> {
        let take = |a: &[[f64; 3]]| {
            Array2::from_shape_fn((order.len(), 3), |(v, c)| a[order[v] as usize][c])
        };
        let triangles = (self.triangles.iter())
            .map(|t| t.map(|v| place[v as usize]))
            .collect();
        // Every normal is a mesh's (unit or zero) or `unit` of a sum: kept bit for bit.
        Mesh::stored(take(&self.positions), triangles, take(&self.normals))
    }

    /// Triangle `t`'s longest edge: the largest squared length, ties to the larger pair of
    /// indices.
    fn longest(&self, t: u32) -> Edge {
        let [a, b, c] = self.triangles[t as usize];
        let key = |e: Edge| (self.squared_length(e), e.1, e.0);
        [edge(a, b), edge(b, c), edge(c, a)]
            .into_iter()
            .max_by(|&p, &q| key(p).partial_cmp(&key(q)).expect("finite positions"))
            .expect("three edges")
    }

    /// Records triangle `t` on its edges (unless it names a vertex twice).
    fn link(&mut self, t: u32) {
        let [a, b, c] = self.triangles[t as usize];
        if a == b || b == c || c == a {
            return;
        }
        for e in [edge(a, b), edge(b, c), edge(c, a)] {
            self.edges.entry(e).or_default().push(t);
        }
    }

    /// Removes triangle `t` from its edges.
    fn unlink(&mut self, t: u32) {
        let [a, b, c] = self.triangles[t as usize];
        for e in [edge(a, b), edge(b, c), edge(c, a)] {
            if let Some(list) = self.edges.get_mut(&e) {
                list.retain(|&x| x != t);
                if list.is_empty() {
                    self.edges.remove(&e);
                }
            }
        }
    }

    /// Splits `e` and every triangle on it at one new vertex, its midpoint.
    fn split_edge(&mut self, e: Edge) {
        let (a, b) = (e.0 as usize, e.1 as usize);
        let m = self.positions.len() as u32;
        let (pa, pb) = (self.positions[a], self.positions[b]);
        self.positions
            .push(std::array::from_fn(|k| 0.5 * (pa[k] + pb[k])));
        let n = std::array::from_fn(|k| self.normals[a][k] + self.normals[b][k]);
        self.normals.push(unit(n).unwrap_or([0.0; 3]));
        let (ca, cb) = (self.albedo[a], self.albedo[b]);
        self.albedo
            .push(std::array::from_fn(|k| 0.5 * (ca[k] + cb[k])));
        self.ground.push(self.ground[a]);
        for t in self.edges.get(&e).cloned().unwrap_or_default() {
            let tri = self.triangles[t as usize];
            let i = (0..3)
                .find(|&i| edge(tri[i], tri[(i + 1) % 3]) == e)
                .expect("the triangle has the edge");
            let (x, y, z) = (tri[i], tri[(i + 1) % 3], tri[(i + 2) % 3]);
            self.unlink(t);
            self.triangles[t as usize] = [x, m, z];
            self.link(t);
            self.triangles.push([m, y, z]);
            self.link(self.triangles.len() as u32 - 1);
        }
    }
}

#[cfg(test)]
#[path = "bisect_tests.rs"]
mod tests;
