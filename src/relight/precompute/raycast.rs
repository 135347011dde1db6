//! Occlusion queries: does a ray from a point hit any triangle of the scene?
//!
//! Visibility needs only the *any-hit* query ("stop at the first hit"), so the interface is
//! [`Occlusion::occluded`] for one ray and [`Occlusion::occluded_from`] for many rays of one
//! origin (a vertex's rays), and the rest of the crate never sees the BVH.
//!
//! **The BVH: [`obvhs`] builds, our packets trace ([`packet`](super::packet)).** `obvhs`
//! builds a binary BVH with PLOC, reinsertion and leaf collapsing (small dependencies: `glam`,
//! `bytemuck`, a radix sort; dual MIT/Apache); it is laid out with both children's boxes in each
//! node and traced by packets of up to 16 rays that share their origin, which is every query
//! visibility makes. Before, the rays went one by one through `obvhs`'s own compressed 8-wide
//! BVH (CWBVH, Ylitie et al. 2017; its any-hit `ray_traverse_miss`). On the same rays, one
//! thread, the whole precomputation (rays and encoding) is faster than through that path on
//! every scene measured, and than Intel Embree 4.4's single-ray `rtcOccluded1` (rays only) on
//! the bunny but not on the two larger scenes: the figures are `benches/rays_results.md`
//! (`python3 benches/compare_rays.py`; `cargo bench --bench rays`). Embree is not bound (yet):
//! on large scenes it is the faster tracer. Of the crates `tools/bvh-compare`
//! measured (its own workspace, so the candidates never enter this crate's build: `cd
//! tools/bvh-compare && cargo run --release`), `obvhs`'s single-ray query was the fastest, 1.5-2x
//! faster than `bvh` 0.12 (binary SAH BVH, nalgebra, a back-face-culling triangle test) and
//! `parry3d` 0.31 (a whole collision library).
//!
//! Rays are f32 (the BVH's precision). What the BVH is given is cleaned in f32, after the
//! conversion: triangles of zero area there are left out (no ray can hit one) and repeated
//! triangles (the same three corners in any order) are kept once, since they answer every
//! query alike and many copies of one box make PLOC's merging quadratic. The mesh itself is not
//! touched: cleaning feeds only the BVH. Positions reach it within
//! [`MAX_COORDINATE`](super::validate::MAX_COORDINATE) (a [`Mesh`] holds no other), so every
//! box it builds is finite. A scene smaller than [`SMALL_EXTENT`] is scaled up by a power of
//! two, to an extent between 1 and 2, before the build (and rays with it): PLOC ranks merges by
//! box surface areas in f32, which underflow to zero below about `1e-19`, and a scene whose
//! areas all tie builds in time quadratic in its triangles (a scene of extent `1e-23` took a
//! minute for 12,000 under the fuzzer). Scaling by `2^k` is exact in floating point: the
//! answers are those of the same scene at that size. (The traversal itself has no absolute
//! epsilon: `obvhs`'s CWBVH skipped a box the ray left before `t = 1e-4`, so an occluder that
//! near the origin was missed; none is now. On the bunny every visibility bit is the old
//! path's; on the cubes scene some rays differ from it, see `benches/rays_results.md`.) A ray
//! hits a triangle
//! when the Moller-Trumbore test finds `0 <= t < t_max`
//! ([`obvhs::rt_triangle::RtTriangle::intersect`]); the caller offsets origins off surfaces.

use std::collections::HashSet;

use glam::Vec3A;
use obvhs::triangle::Triangle;

use crate::relight::Mesh;
use crate::relight::precompute::packet::{LANES, PacketBvh};
use crate::relight::scene::mesh::{cross, sub};

/// Answers "does this ray hit anything before `t_max`?"; see the [module docs](self).
pub trait Occlusion: Sync {
    /// Whether the ray `origin + t direction`, `0 <= t < t_max`, hits a triangle.
    fn occluded(&self, origin: [f32; 3], direction: [f32; 3], t_max: f32) -> bool;

    /// `blocked[i] = self.occluded(origin, directions[i], t_max)` for the rays of one origin
    /// (the first `directions.len().min(blocked.len())`); an implementation may trace them
    /// together, as [`SceneBvh`] does in packets.
    ///
    /// ```
    /// use haarshift::relight::{Mesh, Occlusion, SceneBvh};
    /// use ndarray::array;
    /// let roof = Mesh::new(array![[-1.0, 1.0, 1.0], [1.0, 1.0, 1.0], [0.0, 1.0, -1.0]],
    ///                      vec![[0, 1, 2]], None).unwrap();
    /// let mut blocked = [false; 3];
    /// let up = [[0.0, 1.0, 0.0], [0.0, -1.0, 0.0], [0.0, 0.8, 0.6]];
    /// SceneBvh::new(&roof).occluded_from([0.0; 3], &up, f32::INFINITY, &mut blocked);
    /// assert_eq!(blocked, [true, false, true]);
    /// ```
    fn occluded_from(
        &self,
        origin: [f32; 3],
        directions: &[[f32; 3]],
        t_max: f32,
        blocked: &mut [bool],
    ) {
        for (b, &d) in blocked.iter_mut().zip(directions) {
            *b = self.occluded(origin, d, t_max);
        }
    }
}

/// The scene's triangles in a BVH traced by packets of rays that share their origin
/// ([`packet`](super::packet)).
///
/// ```
/// use haarshift::relight::{Mesh, Occlusion, SceneBvh};
/// use ndarray::array;
/// let roof = Mesh::new(array![[-1.0, 1.0, 1.0], [1.0, 1.0, 1.0], [0.0, 1.0, -1.0]],
///                      vec![[0, 1, 2]], None).unwrap();
/// let bvh = SceneBvh::new(&roof);
/// assert!(bvh.occluded([0.0, 0.0, 0.0], [0.0, 1.0, 0.0], f32::INFINITY));
/// assert!(!bvh.occluded([0.0, 0.0, 0.0], [0.0, -1.0, 0.0], f32::INFINITY));
/// assert!(!bvh.occluded([0.0, 0.0, 0.0], [0.0, 1.0, 0.0], 0.5)); // stops short of it
/// ```
pub struct SceneBvh {
    bvh: Option<PacketBvh>,
    /// The power of two the positions were scaled by (1 unless the scene is tiny).
    scale: f32,
}

/// The extent (largest side of the bounding box, in f32) below which [`SceneBvh`] scales a
/// scene up: `2^-20`, far above where PLOC's surface areas underflow.
pub const SMALL_EXTENT: f32 = 1.0 / (1 << 20) as f32;

/// The power of two that brings a scene of f32 bounding box `lo..hi` smaller than
/// [`SMALL_EXTENT`] to an extent in `[1, 2)` (1 for any other scene, and one of no extent),
/// keeping every coordinate within `2^50` (about 1e15).
fn scale_for(lo: [f32; 3], hi: [f32; 3]) -> f32 {
    let extent = (0..3).map(|k| hi[k] - lo[k]).fold(0.0f32, f32::max);
    let largest = lo.iter().chain(&hi).fold(0.0f32, |m, v| m.max(v.abs()));
    if !(extent > 0.0 && extent < SMALL_EXTENT) {
        return 1.0;
    }
    // Whole powers of two: 1 <= extent * 2^up < 2, largest * 2^up <= 2^50.
    let up = -(extent.log2().floor() as i32);
    let room = (2f32.powi(50) / largest).log2().floor() as i32;
    2f32.powi(up.min(room).clamp(0, 126))
}

impl SceneBvh {
    /// Builds the BVH of `mesh`'s distinct triangles of non-zero area in f32 (see the
    /// [module docs](self)), a scene smaller than [`SMALL_EXTENT`] scaled up first.
    pub fn new(mesh: &Mesh) -> Self {
        let p = mesh.positions();
        let f32_row = |i: usize| {
            let r = p.row(i);
            [r[0] as f32, r[1] as f32, r[2] as f32]
        };
        let (mut lo, mut hi) = ([f32::INFINITY; 3], [f32::NEG_INFINITY; 3]);
        for i in 0..mesh.vertex_count() {
            let v = f32_row(i);
            for k in 0..3 {
                (lo[k], hi[k]) = (lo[k].min(v[k]), hi[k].max(v[k]));
            }
        }
        let scale = scale_for(lo, hi);
        let point = |i: u32| f32_row(i as usize).map(|x| x * scale);
        let mut seen = HashSet::with_capacity(mesh.triangles().len());
        let triangles: Vec<Triangle> = mesh
            .triangles()
            .iter()
            .filter_map(|t| {
                let corners = t.map(point);
                let [a, b, c] = corners.map(|v| v.map(f64::from));
                let mut key = corners.map(|v| v.map(f32::to_bits));
                key.sort_unstable();
                (cross(sub(b, a), sub(c, a)) != [0.0; 3] && seen.insert(key)).then(|| {
                    let [v0, v1, v2] = corners.map(Vec3A::from_array);
                    Triangle { v0, v1, v2 }
                })
            })
            .collect();
        drop(seen);
        SceneBvh {
            bvh: (!triangles.is_empty()).then(|| PacketBvh::new(&triangles)),
            scale,
        }
    }
}

impl Occlusion for SceneBvh {
    fn occluded(&self, origin: [f32; 3], direction: [f32; 3], t_max: f32) -> bool {
        let mut blocked = [false];
        if let Some(bvh) = &self.bvh {
            // In the BVH's scaled space: origin + t d becomes s origin + (s t) d.
            let o = origin.map(|x| x * self.scale);
            bvh.occluded_packet::<1>(o, &[direction], t_max * self.scale, &mut blocked);
        }
        blocked[0]
    }

    fn occluded_from(
        &self,
        origin: [f32; 3],
        directions: &[[f32; 3]],
        t_max: f32,
        blocked: &mut [bool],
    ) {
        let n = directions.len().min(blocked.len());
        let Some(bvh) = &self.bvh else {
            blocked[..n].fill(false);
            return;
        };
        let o = origin.map(|x| x * self.scale);
        for (d, b) in directions[..n]
            .chunks(LANES)
            .zip(blocked[..n].chunks_mut(LANES))
        {
            bvh.occluded_packet::<LANES>(o, d, t_max * self.scale, b);
        }
    }
}

#[cfg(test)]
#[path = "raycast_tests.rs"]
mod tests;
