//! The BVH [`SceneBvh`](super::raycast::SceneBvh) traces: a binary BVH whose nodes hold both
//! children's boxes, traversed by packets of up to [`LANES`] rays that share their origin.
//!
//! **Why packets.** Visibility casts, from every vertex, one ray per texel above its horizon,
//! in texel order: rays with one origin and neighbouring directions, as coherent as rays get.
//! A packet of them walks the tree once: a node is fetched once for all its rays, each child
//! box is tested against every active ray at once (the box's corners minus the shared origin
//! are computed once, then one multiply per slab and ray), and so is each leaf triangle (its
//! first corner minus the origin and the dot product of that with its normal are shared). A
//! ray leaves the packet at its first hit (any-hit: the order of the hits does not matter), and
//! the walk stops when every ray has. This is Wald et al. 2001's coherent packet traversal
//! ("Interactive Rendering with Coherent Ray Tracing") with Embree's any-hit termination per
//! lane (Wald et al. 2014), written for one origin; a packet of one ray is the single-ray query.
//! The lanes are plain arrays that the compiler vectorises (SSE2, four lanes at a time).
//!
//! **The tree.** [`obvhs`] builds it (PLOC, reinsertion, leaf collapsing to at most
//! [`MAX_LEAF`] triangles: `build_bvh2_from_tris` with its medium preset); it is then laid out
//! with each node holding its two children's boxes and references, one 64-byte line, so that a
//! visit reads one line and tests both children.
//!
//! **Exact answers.** A ray hits a triangle when Moller-Trumbore finds `0 <= t < t_max`, with
//! the arithmetic of [`RtTriangle::intersect`] done operation for operation (the lanes give the
//! same bits: tested). A box is never refused to a ray that meets it: the slab distances use
//! the exact reciprocal of the direction (infinite for a zero component), and the far distance
//! is raised by `1 + 2 gamma_3` (Ize 2013, "Robust BVH Ray Traversal"), which covers the three
//! roundings behind each slab distance. Nothing is skipped near the origin, so the answer is
//! that of testing every triangle (the oracle the tests use).

use glam::Vec3A;
use obvhs::BvhBuildParams;
use obvhs::bvh2::Bvh2;
use obvhs::bvh2::builder::build_bvh2_from_tris;
use obvhs::rt_triangle::RtTriangle;
use obvhs::triangle::Triangle;

/// The most rays one packet holds.
pub(crate) const LANES: usize = 16;

/// The most triangles in a leaf.
pub(crate) const MAX_LEAF: u32 = 8;

/// `1 + 2 gamma_3` rounded up, `gamma_n = n u / (1 - n u)`, `u = 2^-24` (Ize 2013).
const ROUND_UP: f32 = 1.0 + 2.0 * (3.0 * f32::EPSILON / 2.0) * 1.01;

/// A child of a node: an inner node (`count == 0`) or the leaf triangles
/// `index..index + count`.
#[derive(Clone, Copy, Debug, Default)]
struct Child {
    index: u32,
    count: u32,
}

/// Two children's boxes and references in one cache line; `lo[axis][child]`.
#[derive(Clone, Copy, Debug, Default)]
#[repr(C, align(64))]
struct Node {
    lo: [[f32; 2]; 3],
    hi: [[f32; 2]; 3],
    child: [Child; 2],
}

/// The packet-traversed BVH of a set of triangles; see the [module docs](self).
pub(crate) struct PacketBvh {
    nodes: Vec<Node>,
    /// The root's box and reference (the root may be a leaf).
    root: ([f32; 3], [f32; 3], Child),
    /// Triangles in leaf order.
    pub(crate) triangles: Vec<RtTriangle>,
    /// `order[i]`: the index, in the slice [`PacketBvh::new`] was given, of `triangles[i]`.
    order: Vec<u32>,
    /// The most entries the traversal stack holds: the tree's depth plus one.
    stack: usize,
}

/// A stack entry: a child and the lanes that met its box.
#[derive(Clone, Copy, Default)]
struct Entry {
    child: Child,
    lanes: u32,
}

/// The rays of one packet, lane by lane (structure of arrays).
struct Rays<const N: usize> {
    d: [[f32; N]; 3],
    inv: [[f32; N]; 3],
    t_max: [f32; N],
    /// The axis along which the first ray moves fastest, and whether it moves up it.
    axis: usize,
    up: bool,
    /// Per axis, the least and greatest reciprocal over the packet's rays, when all of them
    /// have the same sign (`None` when they do not: the packet is not tested as a whole).
    span: Option<[[f32; 2]; 3]>,
    /// Whether a ray has a zero component (the slab test then guards against NaN).
    parallel: bool,
}

impl PacketBvh {
    /// Builds the tree of `triangles` (not empty).
    pub(crate) fn new(triangles: &[Triangle]) -> Self {
        let mut params = BvhBuildParams::medium_build();
        params.max_prims_per_leaf = MAX_LEAF;
        let bvh2 = build_bvh2_from_tris(triangles, params, &mut std::time::Duration::default());
        let ordered = bvh2
            .primitive_indices
            .iter()
            .map(|&i| RtTriangle::from(&triangles[i as usize]))
            .collect();
        let order = bvh2.primitive_indices.clone();
        let mut nodes = Vec::with_capacity(bvh2.nodes.len() / 2);
        // (obvhs node, our node, its depth): inner nodes still to lay out.
        let mut pending = Vec::new();
        // The reference to obvhs node `id`, an inner node given its place in `nodes`.
        let refer = |id: usize, depth: usize, nodes: &mut Vec<Node>, pending: &mut Vec<_>| {
            let n = &bvh2.nodes[id];
            if n.is_leaf() {
                return Child {
                    index: n.first_index,
                    count: n.prim_count,
                };
            }
            nodes.push(Node::default());
            pending.push((id, nodes.len() - 1, depth));
            Child {
                index: (nodes.len() - 1) as u32,
                count: 0,
            }
        };
        let root = refer(0, 1, &mut nodes, &mut pending);
        let mut deepest = 1;
        while let Some((id, at, depth)) = pending.pop() {
            deepest = deepest.max(depth + 1);
            let first = bvh2.nodes[id].first_index as usize;
            let mut node = Node::default();
            for c in 0..2 {
                let (lo, hi) = corners(&bvh2, first + c);
                for k in 0..3 {
                    (node.lo[k][c], node.hi[k][c]) = (lo[k], hi[k]);
                }
                node.child[c] = refer(first + c, depth + 1, &mut nodes, &mut pending);
            }
            nodes[at] = node;
        }
        let (lo, hi) = corners(&bvh2, 0);
        PacketBvh {
            nodes,
            root: (lo, hi, root),
            triangles: ordered,
            order,
            stack: deepest + 1,
        }
    }

    /// Sets `blocked[i]` to whether ray `origin + t directions[i]`, `0 <= t < t_max`, hits a
    /// triangle, for at most [`LANES`] rays.
    pub(crate) fn occluded_packet<const N: usize>(
        &self,
        origin: [f32; 3],
        directions: &[[f32; 3]],
        t_max: f32,
        blocked: &mut [bool],
    ) {
        debug_assert!(directions.len() <= N && N <= 32 && blocked.len() == directions.len());
        // Unused lanes get a zero direction; their answers are masked off.
        let lead = directions.first().copied().unwrap_or_default();
        let axis = (0..3)
            .max_by(|&i, &j| lead[i].abs().total_cmp(&lead[j].abs()))
            .unwrap_or(0);
        let mut rays = Rays::<N> {
            d: [[0.0; N]; 3],
            inv: [[f32::INFINITY; N]; 3],
            t_max: [t_max; N],
            axis,
            up: lead[axis] > 0.0,
            span: None,
            parallel: directions.iter().flatten().any(|&x| x == 0.0),
        };
        let mut span = [[f32::INFINITY, f32::NEG_INFINITY]; 3];
        for (i, d) in directions.iter().enumerate() {
            for k in 0..3 {
                rays.d[k][i] = d[k];
                rays.inv[k][i] = 1.0 / d[k];
                span[k] = [
                    span[k][0].min(rays.inv[k][i]),
                    span[k][1].max(rays.inv[k][i]),
                ];
            }
        }
        let one_sign =
            |[lo, hi]: [f32; 2]| lo.is_finite() && hi.is_finite() && (lo > 0.0) == (hi > 0.0);
        rays.span = (N > 1 && span.iter().all(|&k| one_sign(k))).then_some(span);
        let all = if directions.len() == 32 {
            u32::MAX
        } else {
            (1u32 << directions.len()) - 1
        };
        let hit = if self.stack <= SMALL_STACK {
            self.traverse(origin, &rays, all, &mut [Entry::default(); SMALL_STACK])
        } else {
            self.traverse(origin, &rays, all, &mut vec![Entry::default(); self.stack])
        };
        for (i, b) in blocked.iter_mut().enumerate() {
            *b = hit >> i & 1 == 1;
        }
    }

    /// The closest hit of the ray `origin + t direction`, `0 <= t < t_max`: the index of its
    /// triangle in the slice [`PacketBvh::new`] was given, `t`, and the barycentric weights
    /// `(u, v)` of that triangle's second and third corners. Of hits at the same `t`, the
    /// first met in the traversal is kept.
    pub(crate) fn closest_hit(
        &self,
        origin: [f32; 3],
        direction: [f32; 3],
        t_max: f32,
    ) -> Option<(u32, f32, f32, f32)> {
        let rays = Rays::<1> {
            d: direction.map(|x| [x]),
            inv: direction.map(|x| [1.0 / x]),
            t_max: [t_max],
            axis: 0,
            up: false,
            span: None,
            parallel: direction.contains(&0.0),
        };
        if self.stack <= SMALL_STACK {
            self.closest(
                origin,
                direction,
                rays,
                &mut [Child::default(); SMALL_STACK],
            )
        } else {
            self.closest(
                origin,
                direction,
                rays,
                &mut vec![Child::default(); self.stack],
            )
        }
    }

    /// [`closest_hit`](Self::closest_hit)'s traversal, `stack` (at least the tree's depth
    /// plus one entries) its scratch.
    #[inline(always)]
    fn closest(
        &self,
        origin: [f32; 3],
        direction: [f32; 3],
        mut rays: Rays<1>,
        stack: &mut [Child],
    ) -> Option<(u32, f32, f32, f32)> {
        let mut best = None;
        let (lo, hi, root) = self.root;
        if box_lanes(lo, hi, origin, &rays) == 0 {
            return None;
        }
        stack[0] = root;
        let mut top = 1;
        // Depth first; a box is opened only while it may hold a hit nearer than the best.
        while top > 0 {
            top -= 1;
            let child = stack[top];
            if child.count > 0 {
                let first = child.index as usize;
                for (i, tri) in self.triangles[first..first + child.count as usize]
                    .iter()
                    .enumerate()
                {
                    let (hit, t, u, v) = moller_trumbore(tri, origin, direction, rays.t_max[0]);
                    if hit {
                        rays.t_max[0] = t;
                        best = Some((self.order[first + i], t, u, v));
                    }
                }
                continue;
            }
            let node = &self.nodes[child.index as usize];
            for c in 0..2 {
                let lo = [node.lo[0][c], node.lo[1][c], node.lo[2][c]];
                let hi = [node.hi[0][c], node.hi[1][c], node.hi[2][c]];
                if box_lanes(lo, hi, origin, &rays) != 0 {
                    stack[top] = node.child[c];
                    top += 1;
                }
            }
        }
        best
    }

    /// The lanes of `all` whose rays hit a triangle.
    #[inline(always)]
    fn traverse<const N: usize>(
        &self,
        origin: [f32; 3],
        rays: &Rays<N>,
        all: u32,
        stack: &mut [Entry],
    ) -> u32 {
        let (lo, hi, root) = self.root;
        let lanes = box_lanes(lo, hi, origin, rays) & all;
        if lanes == 0 {
            return 0;
        }
        let mut open = all; // lanes not yet blocked
        stack[0] = Entry { child: root, lanes };
        let mut top = 1;
        while top > 0 {
            top -= 1;
            let Entry { child, lanes } = stack[top];
            let lanes = lanes & open;
            if lanes == 0 {
                continue;
            }
            if child.count > 0 {
                let first = child.index as usize;
                for tri in &self.triangles[first..first + child.count as usize] {
                    open &= !(triangle_lanes(tri, origin, rays) & lanes);
                    if open & lanes == 0 {
                        break;
                    }
                }
                if open == 0 {
                    break;
                }
                continue;
            }
            let node = &self.nodes[child.index as usize];
            let side = |c: usize| {
                let lo = [node.lo[0][c], node.lo[1][c], node.lo[2][c]];
                let hi = [node.hi[0][c], node.hi[1][c], node.hi[2][c]];
                box_lanes(lo, hi, origin, rays) & lanes
            };
            let (a, b) = (side(0), side(1));
            // The child nearer along the packet's first ray is visited first: a hit there
            // ends its rays before the farther child is opened.
            let k = rays.axis;
            let second_first = (node.lo[k][1] < node.lo[k][0]) == rays.up;
            let order = if second_first {
                [(0, a), (1, b)]
            } else {
                [(1, b), (0, a)]
            };
            for (c, lanes) in order {
                if lanes != 0 {
                    stack[top] = Entry {
                        child: node.child[c],
                        lanes,
                    };
                    top += 1;
                }
            }
        }
        all & !open
    }
}

/// Trees no deeper than this trace with a stack on the call's frame (others allocate one per
/// packet or closest-hit ray, which only a degenerate tree needs).
const SMALL_STACK: usize = 128;

/// The corners of node `id` of `bvh2`.
fn corners(bvh2: &Bvh2, id: usize) -> ([f32; 3], [f32; 3]) {
    let a = bvh2.nodes[id].aabb();
    (a.min.to_array(), a.max.to_array())
}

/// The lanes whose rays meet the box `lo..hi` at some `0 <= t <= t_max` (a conservative slab
/// test: see the [module docs](self)).
#[inline(always)]
fn box_lanes<const N: usize>(lo: [f32; 3], hi: [f32; 3], o: [f32; 3], rays: &Rays<N>) -> u32 {
    let a = [lo[0] - o[0], lo[1] - o[1], lo[2] - o[2]];
    let b = [hi[0] - o[0], hi[1] - o[1], hi[2] - o[2]];
    if let Some(span) = &rays.span {
        // The whole packet first, by interval arithmetic on the reciprocals (Boulos et al.
        // 2007): with one sign per axis, each ray's entry distance along an axis is its
        // reciprocal times the near slab, so it lies between the products with the least
        // and the greatest reciprocal (rounding is monotonic: these bound the lanes' own
        // products exactly), and likewise its exit. No ray meets a box that the bounds miss.
        let mut near = 0.0f32;
        let mut far = rays.t_max[0];
        for k in 0..3 {
            let [p, q] = span[k];
            let (n, f) = if p > 0.0 { (a[k], b[k]) } else { (b[k], a[k]) };
            near = near.max((n * p).min(n * q));
            far = far.min((f * p).max(f * q));
        }
        if near > far * ROUND_UP {
            return 0;
        }
    }
    let mut near = [0.0f32; N];
    let mut far = rays.t_max;
    for k in 0..3 {
        for i in 0..N {
            let (mut t0, mut t1) = (a[k] * rays.inv[k][i], b[k] * rays.inv[k][i]);
            if rays.parallel {
                // A zero component and an origin on the slab's plane give `0 x inf = NaN`:
                // the ray runs in that plane, inside the slab for every t. With the other
                // distance (then infinite) negated, the slab is (-inf, inf); both NaN (a flat
                // slab) stay NaN, which the comparisons below pass over.
                (t0, t1) = (
                    if t0.is_nan() { -t1 } else { t0 },
                    if t1.is_nan() { -t0 } else { t1 },
                );
            }
            let (t_near, t_far) = if t0 < t1 { (t0, t1) } else { (t1, t0) };
            near[i] = if t_near > near[i] { t_near } else { near[i] };
            far[i] = if t_far < far[i] { t_far } else { far[i] };
        }
    }
    mask::<N>(std::array::from_fn(|i| near[i] <= far[i] * ROUND_UP))
}

/// The lanes whose rays hit `tri` at `0 <= t < t_max`: [`RtTriangle::intersect`] lane by
/// lane, the same operations in the same order (so the same bits), with what depends only on
/// the origin done once.
#[inline(always)]
fn triangle_lanes<const N: usize>(tri: &RtTriangle, o: [f32; 3], rays: &Rays<N>) -> u32 {
    let (c, ng_c) = shared(tri, o);
    let mut hit = [false; N];
    for (i, hit) in hit.iter_mut().enumerate() {
        let d = [rays.d[0][i], rays.d[1][i], rays.d[2][i]];
        *hit = lane(tri, c, ng_c, d, rays.t_max[i]).0;
    }
    mask(hit)
}

/// What [`RtTriangle::intersect`] computes once per origin: the first corner minus the origin,
/// and its dot product with the triangle's normal.
#[inline(always)]
fn shared(tri: &RtTriangle, o: [f32; 3]) -> ([f32; 3], f32) {
    let c = tri.v0 - Vec3A::from_array(o);
    (c.to_array(), tri.ng.dot(c))
}

/// [`RtTriangle::intersect`] for one direction `d`, the operations in its order (so its
/// bits): whether the ray hits at `0 <= t < t_max`, `t`, and the weights `(u, v)` of the
/// second and third corners (`e1 = v0 - v1`, `e2 = v2 - v0`: `u` multiplies `e2`'s
/// cofactor, Moller and Trumbore 1997 as Embree writes it).
#[inline(always)]
fn lane(
    tri: &RtTriangle,
    c: [f32; 3],
    ng_c: f32,
    d: [f32; 3],
    t_max: f32,
) -> (bool, f32, f32, f32) {
    let (e1, e2, ng) = (tri.e1.to_array(), tri.e2.to_array(), tri.ng.to_array());
    // r = d x c, glam's component order.
    let r = [
        d[1] * c[2] - d[2] * c[1],
        d[2] * c[0] - d[0] * c[2],
        d[0] * c[1] - d[1] * c[0],
    ];
    let inv_det = 1.0 / (ng[0] * d[0] + ng[1] * d[1] + ng[2] * d[2]);
    let u = (r[0] * e2[0] + r[1] * e2[1] + r[2] * e2[2]) * inv_det;
    let v = (r[0] * e1[0] + r[1] * e1[1] + r[2] * e1[2]) * inv_det;
    let w = 1.0 - u - v;
    let signs = u.to_bits() | v.to_bits() | w.to_bits();
    let t = ng_c * inv_det;
    let hit = inv_det != 0.0 && signs & 0x8000_0000 == 0 && t >= 0.0 && t < t_max;
    (hit, t, u, v)
}

/// [`lane`] for one ray from `o`.
fn moller_trumbore(
    tri: &RtTriangle,
    o: [f32; 3],
    d: [f32; 3],
    t_max: f32,
) -> (bool, f32, f32, f32) {
    let (c, ng_c) = shared(tri, o);
    lane(tri, c, ng_c, d, t_max)
}

/// The bits `i` for which `lanes[i]` holds.
#[inline(always)]
fn mask<const N: usize>(lanes: [bool; N]) -> u32 {
    (0..N).fold(0, |m, i| m | u32::from(lanes[i]) << i)
}

#[cfg(test)]
#[path = "packet_tests.rs"]
mod tests;
