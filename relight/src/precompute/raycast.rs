//! Occlusion queries: does a ray from a point hit any triangle of the scene?
//!
//! Visibility needs only the *any-hit* query ("stop at the first hit"), so the interface is
//! [`Occlusion::occluded`] for one ray and [`Occlusion::occluded_from`] for many rays of one
//! origin (a vertex's rays), and the rest of the crate never sees the BVH.
//!
//! **Two tracers, one interface ([`RayTracer`]).** [`SceneBvh::new`] takes the faster one this
//! build offers ([`RayTracer::best`]):
//! * [`RayTracer::Embree`]: Intel Embree 3 (the system's `libembree3.so.3`, Debian's and
//!   Ubuntu's `libembree3-3`), loaded at run time where it is installed, its 16-wide packet
//!   query ([`embree`](super::embree)); every build can use it and none needs it. On the same
//!   rays, one thread, the whole
//!   precomputation (rays and encoding) through it is faster than Embree 4.4's single-ray
//!   `rtcOccluded1` alone on every scene `benches/rays_results.md` measures, and than our packets.
//! * [`RayTracer::Packets`]: our own, in every build. `obvhs` builds a binary BVH with PLOC,
//!   reinsertion and leaf collapsing (small dependencies: `glam`, `bytemuck`, a radix sort; dual
//!   MIT/Apache); it is laid out with both children's boxes in each node and traced by packets
//!   of up to 16 rays that share their origin (`packet`), which is every query
//!   visibility makes. Its answers are those of testing every triangle with Moller-Trumbore in
//!   f32, bit for bit. Of the pure-Rust crates `tools/bvh-compare` measured (its own workspace,
//!   so the candidates never enter this crate's build: `cd tools/bvh-compare && cargo run
//!   --release`), `obvhs`'s single-ray query was the fastest, 1.5-2x faster than `bvh` 0.12
//!   (binary SAH BVH, nalgebra, a back-face-culling triangle test) and `parry3d` 0.31 (a whole
//!   collision library); our packets are faster again on every scene measured.
//!
//! The two answer alike except on rays through a triangle's edge, whose f32 answer is decided
//! by rounding (`benches/compare_rays.py` works each such ray out in f64), and on rays that
//! start in a triangle's plane, which meet it at `t = 0` to within rounding: Embree counts
//! such a hit, and our packets count it or not as the rounding of `t` falls. No vertex's rays
//! start there: a vertex on a crease or touching another surface (a floor vertex against a
//! wall, whose lifted point lies in the wall's plane) has its origin moved into its own faces
//! first ([`origin`](super::origin), which defines these *contact vertices*: 260 of
//! `bunny_in_box.json`'s 3,284), so both tracers meet the wall at `t >= eps / 2` or so.
//!
//! **Closest hits.** [`SceneBvh::closest_hits_from`] finds, for each ray, the nearest
//! triangle it meets ([`Hit`]: the mesh's triangle, the distance, the barycentric weights of
//! its second and third corners), with either tracer. A hit names the mesh triangle the
//! BVH's triangle stands for: of repeated triangles (the same three corners in any order,
//! whatever their winding) the first in the mesh's order stands for all, so a pair of
//! opposite-facing duplicates answers as the first of the two; a triangle of zero area is
//! never hit.
//!
//! Rays are f32 (the BVH's precision). What the BVH is given is cleaned in f32, after the
//! conversion: triangles of zero area there are left out (no ray can hit one) and repeated
//! triangles (the same three corners in any order) are kept once, since they answer every
//! query alike and many copies of one box make PLOC's merging quadratic. The mesh itself is not
//! touched: cleaning feeds only the BVH. Positions reach it within
//! `MAX_COORDINATE`](super::validate::MAX_COORDINATE) (a [`Mesh` holds no other), so every
//! box it builds is finite. A scene smaller than [`SMALL_EXTENT`] is scaled up by a power of
//! two, to an extent between 1 and 2, before the build (and rays with it): PLOC ranks merges by
//! box surface areas in f32, which underflow to zero below about `1e-19`, and a scene whose
//! areas all tie builds in time quadratic in its triangles (a scene of extent `1e-23` took a
//! minute for 12,000 under the fuzzer). Scaling by `2^k` is exact in floating point: the
//! answers are those of the same scene at that size. (The traversal itself has no absolute
//! epsilon: nothing is skipped near the origin.) With our packets a ray hits a triangle when
//! the Moller-Trumbore test finds `0 <= t < t_max`
//! ([`obvhs::rt_triangle::RtTriangle::intersect`]); the caller offsets origins off surfaces.

use std::collections::HashSet;

use glam::Vec3A;
use obvhs::triangle::Triangle;

use crate::Mesh;
use crate::precompute::packet::{LANES, PacketBvh};
use crate::scene::mesh::{cross, sub};

/// Answers "does this ray hit anything before `t_max`?"; see the [module docs](self).
pub trait Occlusion: Sync {
    /// Whether the ray `origin + t direction`, `0 <= t < t_max`, hits a triangle.
    fn occluded(&self, origin: [f32; 3], direction: [f32; 3], t_max: f32) -> bool;

    /// `blocked[i] = self.occluded(origin, directions[i], t_max)` for the rays of one origin
    /// (the first `directions.len().min(blocked.len())`); an implementation may trace them
    /// together, as [`SceneBvh`] does in packets.
    ///
    /// ```
    /// use haarshift_relight::{Mesh, Occlusion, SceneBvh};
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

    /// The [`RayTracer`] answering, for reports (`None`: another implementation).
    fn tracer(&self) -> Option<RayTracer> {
        None
    }
}

haarshift::named_enum! {
    /// The ray tracers a [`SceneBvh`] traces with; [`RayTracer::best`] is what
    /// [`SceneBvh::new`] takes.
    ///
    /// ```
    /// use haarshift_relight::RayTracer;
    /// assert!(RayTracer::Packets.available()); // every build has it
    /// assert_eq!("embree".parse::<RayTracer>().unwrap(), RayTracer::Embree);
    /// ```
    pub enum RayTracer ("ray tracer") {
        /// haarshift's own binary BVH traced by packets of rays that share their origin
        /// ([`packet`](super::packet)): in every build, its answers specified to the bit.
        Packets = "packets",
        /// Intel Embree 3's 16-wide packet query ([`embree`](super::embree)): where the
        /// system's `libembree3.so.3` loads and its device starts.
        Embree = "embree",
    }
}

impl RayTracer {
    /// Whether the tracer starts on this machine.
    pub fn available(self) -> bool {
        self.unavailable().is_none()
    }

    /// Why the tracer cannot trace on this machine (for Embree: the library did not load,
    /// with what to install, or its device did not start), `None` when it can.
    ///
    /// ```
    /// use haarshift_relight::RayTracer;
    /// assert_eq!(RayTracer::Packets.unavailable(), None);
    /// if let Some(why) = RayTracer::Embree.unavailable() {
    ///     assert!(why.contains("libembree3-3"), "{why}");
    /// }
    /// ```
    pub fn unavailable(self) -> Option<&'static str> {
        match self {
            RayTracer::Packets => None,
            RayTracer::Embree => super::embree::unavailable(),
        }
    }

    /// One line on which tracer this machine would use and why: Embree's version where it
    /// loads, else why it did not.
    ///
    /// ```
    /// use haarshift_relight::RayTracer;
    /// let line = RayTracer::choice();
    /// assert!(line.starts_with(RayTracer::best().name()), "{line}");
    /// ```
    pub fn choice() -> String {
        match super::embree::version() {
            Some(version) => format!("embree (Embree {version} loaded)"),
            None => format!(
                "packets ({})",
                RayTracer::Embree
                    .unavailable()
                    .unwrap_or("Embree did not load")
            ),
        }
    }

    /// The faster tracer available: Embree where it is (`benches/rays_results.md`), else
    /// our packets.
    ///
    /// ```
    /// use haarshift_relight::RayTracer;
    /// let best = RayTracer::best();
    /// assert_eq!(best == RayTracer::Embree, RayTracer::Embree.available());
    /// ```
    pub fn best() -> RayTracer {
        if RayTracer::Embree.available() {
            RayTracer::Embree
        } else {
            RayTracer::Packets
        }
    }
}

/// The scene's triangles in a BVH of the chosen [`RayTracer`].
///
/// ```
/// use haarshift_relight::{Mesh, Occlusion, RayTracer, SceneBvh};
/// use ndarray::array;
/// let roof = Mesh::new(array![[-1.0, 1.0, 1.0], [1.0, 1.0, 1.0], [0.0, 1.0, -1.0]],
///                      vec![[0, 1, 2]], None).unwrap();
/// let bvh = SceneBvh::new(&roof);
/// assert_eq!(bvh.tracer(), RayTracer::best());
/// assert!(bvh.occluded([0.0, 0.0, 0.0], [0.0, 1.0, 0.0], f32::INFINITY));
/// assert!(!bvh.occluded([0.0, 0.0, 0.0], [0.0, -1.0, 0.0], f32::INFINITY));
/// assert!(!bvh.occluded([0.0, 0.0, 0.0], [0.0, 1.0, 0.0], 0.5)); // stops short of it
/// ```
pub struct SceneBvh {
    /// `None` for a scene with no triangle of non-zero area.
    tracer: Option<Tracer>,
    /// `source[i]`: the mesh triangle the BVH's triangle `i` stands for.
    source: Vec<u32>,
    /// The tracer that answers (see [`SceneBvh::tracer`]).
    kind: RayTracer,
    /// The power of two the positions were scaled by (1 unless the scene is tiny).
    scale: f32,
}

/// A built BVH of one [`RayTracer`].
enum Tracer {
    Packets(PacketBvh),
    Embree(super::embree::EmbreeScene),
}

/// The closest triangle a ray meets ([`SceneBvh::closest_hits_from`]): the point is
/// `origin + t direction = (1 - u - v) p0 + u p1 + v p2`, `p0, p1, p2` the corners of
/// `mesh.triangles()[triangle]` in their stored order (up to f32 rounding).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Hit {
    /// The mesh's triangle, an index into [`Mesh::triangles`].
    pub triangle: usize,
    /// The distance along the ray's direction (in units of its length).
    pub t: f32,
    /// The barycentric weight of the triangle's second corner.
    pub u: f32,
    /// The barycentric weight of the triangle's third corner.
    pub v: f32,
}

impl Hit {
    /// The barycentric weights of the triangle's three corners, `(1 - u - v, u, v)`, in f64.
    ///
    /// ```
    /// use haarshift_relight::precompute::raycast::Hit;
    /// let hit = Hit { triangle: 0, t: 1.0, u: 0.25, v: 0.5 };
    /// assert_eq!(hit.weights(), [0.25, 0.25, 0.5]);
    /// ```
    pub fn weights(&self) -> [f64; 3] {
        let (u, v) = (f64::from(self.u), f64::from(self.v));
        [1.0 - u - v, u, v]
    }
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

/// What a BVH of a mesh is built from (see the [module docs](self)): its distinct triangles of
/// non-zero area, in f32, scaled by `scale` (a power of two, 1 unless the scene is smaller
/// than [`SMALL_EXTENT`]).
pub(crate) struct CleanTriangles {
    pub(crate) triangles: Vec<[[f32; 3]; 3]>,
    /// `source[i]`: the mesh triangle `triangles[i]` stands for.
    pub(crate) source: Vec<u32>,
    pub(crate) scale: f32,
}

impl CleanTriangles {
    pub(crate) fn of(mesh: &Mesh) -> Self {
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
        let (triangles, source) = mesh
            .triangles()
            .iter()
            .zip(0u32..)
            .filter_map(|(t, index)| {
                let corners = t.map(point);
                let [a, b, c] = corners.map(|v| v.map(f64::from));
                let mut key = corners.map(|v| v.map(f32::to_bits));
                key.sort_unstable();
                (cross(sub(b, a), sub(c, a)) != [0.0; 3] && seen.insert(key))
                    .then_some((corners, index))
            })
            .unzip();
        CleanTriangles {
            triangles,
            source,
            scale,
        }
    }
}

impl SceneBvh {
    /// Builds the BVH of `mesh`'s distinct triangles of non-zero area in f32 (see the
    /// [module docs](self)), a scene smaller than [`SMALL_EXTENT`] scaled up first, with
    /// [`RayTracer::best`].
    pub fn new(mesh: &Mesh) -> Self {
        Self::with_tracer(mesh, RayTracer::best())
    }

    /// As [`SceneBvh::new`], traced by `tracer` when it is
    /// [available](RayTracer::available) and builds the scene, else by our packets (see
    /// [`SceneBvh::tracer`]).
    ///
    /// ```
    /// use haarshift_relight::{Mesh, Occlusion, RayTracer, SceneBvh};
    /// use ndarray::array;
    /// let roof = Mesh::new(array![[-1.0, 1.0, 1.0], [1.0, 1.0, 1.0], [0.0, 1.0, -1.0]],
    ///                      vec![[0, 1, 2]], None).unwrap();
    /// let ours = SceneBvh::with_tracer(&roof, RayTracer::Packets);
    /// assert_eq!(ours.tracer(), RayTracer::Packets);
    /// let best = SceneBvh::with_tracer(&roof, RayTracer::best());
    /// for d in [[0.0, 1.0, 0.0], [0.0, -1.0, 0.0], [0.3, 0.9, 0.3]] {
    ///     assert_eq!(ours.occluded([0.0; 3], d, 9.0), best.occluded([0.0; 3], d, 9.0));
    /// }
    /// ```
    pub fn with_tracer(mesh: &Mesh, tracer: RayTracer) -> Self {
        let CleanTriangles {
            triangles,
            source,
            scale,
        } = CleanTriangles::of(mesh);
        let built = (!triangles.is_empty()).then(|| build(&triangles, tracer));
        let kind = match &built {
            None if tracer.available() => tracer,
            Some(Tracer::Embree(_)) => RayTracer::Embree,
            _ => RayTracer::Packets,
        };
        SceneBvh {
            tracer: built,
            source,
            kind,
            scale,
        }
    }

    /// The tracer that answers this scene's queries: the one asked for, or
    /// [`RayTracer::Packets`] when that one was not available or could not build the scene.
    ///
    /// ```
    /// use haarshift_relight::{Generator, RayTracer, SceneBvh};
    /// let mesh = Generator::Sphere { cells: 2 }.mesh().unwrap();
    /// let asked = SceneBvh::with_tracer(&mesh, RayTracer::Embree);
    /// let expected = if RayTracer::Embree.available() { RayTracer::Embree } else { RayTracer::Packets };
    /// assert_eq!(asked.tracer(), expected);
    /// ```
    pub fn tracer(&self) -> RayTracer {
        self.kind
    }

    /// `hits[i]`: the closest triangle the ray `origin + t directions[i]` meets at
    /// `0 <= t < t_max` (with Embree `t <= t_max`), or `None`, for the first
    /// `directions.len().min(hits.len())` rays; see [`Hit`] and the [module docs](self).
    ///
    /// ```
    /// use haarshift_relight::{Mesh, SceneBvh};
    /// use ndarray::array;
    /// // Two roofs, at heights 1 and 2, the lower one the second triangle.
    /// let roofs = Mesh::new(array![[-1.0, 2.0, 1.0], [1.0, 2.0, 1.0], [0.0, 2.0, -1.0],
    ///                              [-1.0, 1.0, 1.0], [1.0, 1.0, 1.0], [0.0, 1.0, -1.0]],
    ///                       vec![[0, 1, 2], [3, 4, 5]], None).unwrap();
    /// let mut hits = [None; 2];
    /// SceneBvh::new(&roofs).closest_hits_from([0.0; 3], &[[0.0, 1.0, 0.0], [0.0, -1.0, 0.0]],
    ///                                         f32::INFINITY, &mut hits);
    /// let hit = hits[0].unwrap();
    /// // Embree's t is within an ulp or so of 1, depending on the CPU's instruction set.
    /// assert!(hit.triangle == 1 && (hit.t - 1.0).abs() < 1e-6);
    /// assert!((hit.u - 0.25).abs() < 1e-6 && (hit.v - 0.5).abs() < 1e-6);
    /// assert_eq!(hits[1], None);
    /// ```
    pub fn closest_hits_from(
        &self,
        origin: [f32; 3],
        directions: &[[f32; 3]],
        t_max: f32,
        hits: &mut [Option<Hit>],
    ) {
        let n = directions.len().min(hits.len());
        let (directions, hits) = (&directions[..n], &mut hits[..n]);
        let (o, t_max_scaled) = (origin.map(|x| x * self.scale), t_max * self.scale);
        let mut raw = [None; super::embree::EMBREE_LANES];
        for (d, h) in directions
            .chunks(super::embree::EMBREE_LANES)
            .zip(hits.chunks_mut(super::embree::EMBREE_LANES))
        {
            let raw = &mut raw[..d.len()];
            match &self.tracer {
                None => raw.fill(None),
                Some(Tracer::Packets(bvh)) => {
                    for (r, &d) in raw.iter_mut().zip(d) {
                        *r = bvh.closest_hit(o, d, t_max_scaled);
                    }
                }
                Some(Tracer::Embree(scene)) => scene.closest_packet(o, d, t_max_scaled, raw),
            }
            for (h, r) in h.iter_mut().zip(raw.iter()) {
                *h = r.map(|(index, t, u, v)| Hit {
                    triangle: self.source[index as usize] as usize,
                    t: t / self.scale,
                    u,
                    v,
                });
            }
        }
    }
}

/// The BVH of `triangles` (not empty) for `tracer`, our packets' when that one is not
/// available or fails to build.
fn build(triangles: &[[[f32; 3]; 3]], tracer: RayTracer) -> Tracer {
    if tracer == RayTracer::Embree
        && let Some(scene) = super::embree::EmbreeScene::new(triangles)
    {
        return Tracer::Embree(scene);
    }
    let triangles: Vec<Triangle> = triangles
        .iter()
        .map(|t| {
            let [v0, v1, v2] = t.map(Vec3A::from_array);
            Triangle { v0, v1, v2 }
        })
        .collect();
    Tracer::Packets(PacketBvh::new(&triangles))
}

impl Occlusion for SceneBvh {
    fn occluded(&self, origin: [f32; 3], direction: [f32; 3], t_max: f32) -> bool {
        // In the BVH's scaled space: origin + t d becomes s origin + (s t) d.
        let (o, t_max) = (origin.map(|x| x * self.scale), t_max * self.scale);
        match &self.tracer {
            None => false,
            Some(Tracer::Packets(bvh)) => {
                let mut blocked = [false];
                bvh.occluded_packet::<1>(o, &[direction], t_max, &mut blocked);
                blocked[0]
            }
            Some(Tracer::Embree(scene)) => scene.occluded(o, direction, t_max),
        }
    }

    fn occluded_from(
        &self,
        origin: [f32; 3],
        directions: &[[f32; 3]],
        t_max: f32,
        blocked: &mut [bool],
    ) {
        let n = directions.len().min(blocked.len());
        let (directions, blocked) = (&directions[..n], &mut blocked[..n]);
        let (o, t_max) = (origin.map(|x| x * self.scale), t_max * self.scale);
        match &self.tracer {
            None => blocked.fill(false),
            Some(Tracer::Packets(bvh)) => {
                for (d, b) in directions.chunks(LANES).zip(blocked.chunks_mut(LANES)) {
                    bvh.occluded_packet::<LANES>(o, d, t_max, b);
                }
            }
            Some(Tracer::Embree(scene)) => {
                use super::embree::EMBREE_LANES;
                let packets = directions.chunks(EMBREE_LANES);
                for (d, b) in packets.zip(blocked.chunks_mut(EMBREE_LANES)) {
                    scene.occluded_packet(o, d, t_max, b);
                }
            }
        }
    }

    fn tracer(&self) -> Option<RayTracer> {
        Some(self.kind)
    }
}

#[cfg(test)]
#[path = "raycast_tests.rs"]
pub(crate) mod tests;
