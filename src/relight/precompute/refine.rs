//! Vertices where the light needs them: `relight precompute --refine TOL [--max-vertices N]`.
//!
//! Per-vertex transport is only as sharp as the mesh: between two vertices a render
//! interpolates, so a shadow edge that crosses a coarse triangle is drawn across the whole of
//! it. [`precompute_refined`] precomputes the scene, then splits the edges whose endpoints'
//! transports differ by more than `TOL`, precomputes the new vertices, and repeats until no
//! edge differs by more than `TOL` or the next vertex would exceed the budget.
//!
//! **The criterion** is the L2 difference of the two endpoints' sparse transport vectors over
//! the most an endpoint could receive, `|T_a - T_b| / max(|U_a|, |U_b|)`, where `U_v` is the
//! transport vertex `v` would have with nothing in the way (`max(0, n_v . w) dOmega` over the
//! texels; the Haar transform is orthonormal, so the norms are the texels'). It lies in
//! `[0, 2]`, and an edge whose ends receive nothing is never split.
//!
//! *Transport, not the radiance under a probe lighting*: a cache is relit under any map and
//! any rotation of it, and an edge that looks alike under one lighting (a shadow cast away from
//! the probe's sun, or under a dim part of its sky) is where another lighting's sun draws its
//! shadow. The transport difference bounds the radiance difference under every lighting `L`:
//! `|R_a - R_b| <= albedo / pi x |L| x |T_a - T_b| <= TOL x albedo / pi x |L| x |U|`
//! (Cauchy-Schwarz), a fraction `TOL` of the most an unoccluded vertex could receive under it.
//!
//! *Over `|U|`, not over `max(|T_a|, |T_b|)`* (the first design): the image's error is judged
//! against the scene's radiance, not vertex by vertex (as `relight error` does), and a ratio of
//! the endpoints' own transports never converges where the transport goes to zero: next to
//! where an object touches the ground, the ambient occlusion grows about linearly with the
//! distance, so `T(d)` and `T(2d)` differ by about half of `T(2d)` at every scale, and every
//! round would split those edges again until the budget is spent there. Over `|U|` such edges
//! differ by as little as they receive.
//!
//! **The splits** are conforming longest-edge bisections
//! ([`scene::refine`](crate::relight::scene) in the crate's source: every triangle on a split
//! edge is split at its one midpoint, no T-junctions; new vertices get the interpolated normal
//! and albedo; the objects' vertices, then the ground plane's, originals first in each). A
//! round marks every edge above `TOL` among those touching the vertices the last round made
//! (the first round: all edges; an edge between two older vertices was judged already), and
//! splits them largest difference first, so a budget spent mid-round went to the worst edges.
//!
//! **Why the result is an unrefined precompute of the refined mesh.** A vertex's transport
//! depends on its position, its normal and the surface its rays may hit. Old vertices keep
//! their normals (they are interpolated at midpoints, not recomputed), and a split leaves the
//! surface where it was (the midpoint is on the edge to within rounding, and every triangle on
//! the edge takes it), so a vertex's transport, once traced, is what the refined mesh gives it:
//! each round traces only its new vertices, against the mesh as it then is. The exception is a
//! ray that passes within rounding of a split edge, which the refined triangles may answer
//! otherwise than the old one did; the test `refined_cache_is_a_precompute_of_the_refined_mesh`
//! compares the two bit for bit.
//!
//! **Where it stops.** An edge shorter than [`MIN_EDGE_OFFSETS`] ray offsets is not split,
//! whatever its difference: below the distance rays start off the surface the transport is
//! not resolved, and where it jumps (a vertex of a foot whose offset origin is under the
//! ground sees the sky below it, its neighbour the ground) no length would bring the edge
//! within `TOL`. The report counts the edges left above `TOL` for it
//! ([`RefineReport::short`]), and those the budget left ([`RefineReport::above`]).
//!
//! **Measured** (`results/relight/refine.md`, the bunny on its ground under Rooitou Park at
//! cube 6 x 32^2): at a quarter of the 128^2 grid's vertices the refined mesh does not reach
//! that grid's per-pixel error. The criterion is lighting-independent, and that is its limit:
//! the bunny's coarse normals differ by a large share of `|U|` from vertex to vertex, so the
//! budget goes there first, while the sun's shadow on the ground is where one texel turns dark,
//! a step of about `dOmega cos / |U|` (0.03 at cube 32), below any useful tolerance. The
//! interpolation error (the midpoint's traced transport against the mean of the ends') would
//! stop spending on smooth normal changes, and a probe lighting's radiance would see the sun.
//!
//! **What it is combined with.** The vertex order only: the direction order renders every
//! vertex into each shadow buffer at once, and a refinement traces a few vertices a round.
//! One ray per texel only: the stratified jitter is seeded by the vertex's index, which the
//! refined order renumbers. No `--shard`: which vertices exist is decided by the rounds, so
//! the vertex ranges of shards are not known before the whole precomputation has run (refine
//! once, then shard the refined mesh's precomputation). Interreflections (bounces) go after
//! refinement: refine first, then gather the bounces over the refined mesh, whose vertices
//! they need.

use std::time::Instant;

use rayon::prelude::*;

use crate::faces::Parameterization;
use crate::relight::precompute::shard::Shard;
use crate::relight::precompute::visibility::{
    PrecomputeReport, ray_offset, texel_directions, vertex_range,
};
use crate::relight::precompute::{Order, PrecomputeOptions};
use crate::relight::scene::mesh::dot;
use crate::relight::scene::refine::{Bisection, Edge};
use crate::relight::{RefineRecord, Scene, SceneBvh, SceneCache, TransportSet};
use crate::{Error, Result};

/// The budget of vertices when none is given: this many times the scene's.
pub const DEFAULT_GROWTH: usize = 4;

/// The shortest edge that is split, in [`ray_offset`]s: the transport is not resolved below
/// the distance rays start off the surface (a vertex within it of another surface, such as a
/// foot's on the ground, starts its rays beyond that surface), so shorter edges are left as
/// they are whatever their difference.
pub const MIN_EDGE_OFFSETS: f64 = 16.0;

/// How to refine (`--refine TOL [--max-vertices N]`).
///
/// ```
/// use haarshift::relight::precompute::refine::Refinement;
/// let r = Refinement { tolerance: 0.2, max_vertices: None };
/// assert_eq!(r.budget(1000).unwrap(), 4000);
/// let err = Refinement { tolerance: 0.2, max_vertices: Some(999) }.budget(1000).unwrap_err();
/// assert!(err.to_string().contains("999 vertices: the scene has 1000 already"), "{err}");
/// assert!(Refinement { tolerance: 0.0, max_vertices: None }.check().is_err());
/// assert!(Refinement { tolerance: 2.5, max_vertices: None }.check().is_err());
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Refinement {
    /// `TOL`: split edges whose endpoints' transports differ by more than `TOL` times the
    /// most an endpoint could receive (see the [module docs](self)), in `(0, 2]`.
    pub tolerance: f64,
    /// `N`: the most vertices the refined mesh may have ([`DEFAULT_GROWTH`] times the
    /// scene's when `None`).
    pub max_vertices: Option<usize>,
}

impl Refinement {
    /// Refuses a tolerance outside `(0, 2]` (the criterion is at most 2; 0 would split
    /// forever).
    pub fn check(&self) -> Result<()> {
        if self.tolerance > 0.0 && self.tolerance <= 2.0 {
            return Ok(());
        }
        Err(Error::parameter(
            "refine",
            format!(
                "{}: the tolerance is a fraction of an unoccluded vertex's transport, in (0, 2]",
                self.tolerance
            ),
        ))
    }

    /// The most vertices a scene of `vertices` may be refined to; refused below `vertices`.
    pub fn budget(&self, vertices: usize) -> Result<usize> {
        self.check()?;
        let max = match self.max_vertices {
            Some(n) => n,
            None => vertices.checked_mul(DEFAULT_GROWTH).ok_or_else(|| {
                Error::parameter("max vertices", format!("{DEFAULT_GROWTH} x {vertices}"))
            })?,
        };
        if max < vertices {
            return Err(Error::parameter(
                "max vertices",
                format!("{max} vertices: the scene has {vertices} already"),
            ));
        }
        Ok(max)
    }

    /// Refuses what refinement cannot be combined with (see the [module docs](self)): a
    /// shard, the direction order and stratified rays, besides [`check`](Self::check)'s
    /// tolerance; and `options` that [`PrecomputeOptions::check`] refuses.
    ///
    /// ```
    /// use haarshift::relight::precompute::{Order, PrecomputeOptions};
    /// use haarshift::relight::precompute::refine::Refinement;
    /// use haarshift::relight::precompute::shard::Shard;
    /// use haarshift::relight::VisibilityOptions;
    /// use haarshift::faces::{ParamKind, Parameterization};
    /// let mut o = PrecomputeOptions::new(VisibilityOptions::new(Parameterization::new(ParamKind::Cube, 4).unwrap()));
    /// let r = Refinement { tolerance: 0.1, max_vertices: None };
    /// assert!(r.check_with(&o, None).is_ok());
    /// let err = r.check_with(&o, Some(Shard::new(0, 2).unwrap())).unwrap_err().to_string();
    /// assert!(err.contains("with --shard"), "{err}");
    /// o.order = Order::Direction;
    /// assert!(r.check_with(&o, None).is_err());
    /// ```
    pub fn check_with(&self, options: &PrecomputeOptions, shard: Option<Shard>) -> Result<()> {
        self.check()?;
        if shard.is_some() {
            return Err(Error::parameter(
                "refine",
                "with --shard: the rounds decide which vertices exist, so no shard's range is \
                 known before the whole refinement has run; refine unsharded",
            ));
        }
        if options.order != Order::Vertex {
            return Err(Error::parameter(
                "refine",
                "with --order direction: every shadow buffer serves all vertices at once, and \
                 a refinement traces a few a round; refine with --order vertex",
            ));
        }
        if options.visibility.samples != 1 {
            return Err(Error::parameter(
                "refine",
                "with --visibility-samples above 1: the jitter is seeded by vertex index, \
                 which refinement renumbers",
            ));
        }
        options.check()
    }
}

/// What a refinement did.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RefineReport {
    /// Vertices before refinement.
    pub original: usize,
    /// Vertices after.
    pub vertices: usize,
    /// Of them, the ground plane's (the trailing block).
    pub ground_vertices: usize,
    /// Rounds of splitting and tracing.
    pub rounds: usize,
    /// The budget of vertices ([`Refinement::budget`]).
    pub max_vertices: usize,
    /// Edges still above the tolerance and long enough to split: 0 unless the budget stopped
    /// the refinement.
    pub above: usize,
    /// Edges above the tolerance left because they are shorter than [`MIN_EDGE_OFFSETS`]
    /// ray offsets.
    pub short: usize,
}

impl RefineReport {
    /// Whether the budget stopped the refinement before every edge was within the tolerance.
    ///
    /// ```
    /// use haarshift::relight::precompute::refine::RefineReport;
    /// let mut r = RefineReport { original: 63, vertices: 80, ground_vertices: 12, rounds: 3,
    ///     max_vertices: 80, above: 5, short: 0 };
    /// assert!(r.stopped_by_budget());
    /// r.above = 0;
    /// assert!(!r.stopped_by_budget());
    /// ```
    pub fn stopped_by_budget(&self) -> bool {
        self.above > 0
    }
}

/// Precomputes `scene` refined to `refinement` (see the [module docs](self)) into a
/// [`SceneCache`] whose mesh is the refined one ([`CacheParams::refine`](crate::relight::CacheParams::refine)
/// recording how), with what the precomputation and the refinement did. The precomputation's
/// report sums every round's rays; its seconds are the whole run's (splits and criterion
/// included).
///
/// ```
/// use haarshift::relight::precompute::PrecomputeOptions;
/// use haarshift::relight::precompute::refine::{Refinement, precompute_refined};
/// use haarshift::relight::{Generator, Scene, VisibilityOptions};
/// use haarshift::faces::{ParamKind, Parameterization};
/// let mut scene = Scene::from_mesh(Generator::Sphere { cells: 1 }.mesh().unwrap(), false).unwrap();
/// scene.add_ground_plane_of(2).unwrap();
/// let options = PrecomputeOptions::new(VisibilityOptions::new(Parameterization::new(ParamKind::LatLong, 8).unwrap()));
/// let refinement = Refinement { tolerance: 0.5, max_vertices: Some(200) };
/// let (cache, _, report) = precompute_refined(scene, &options, &refinement).unwrap();
/// assert!(report.vertices > 24 + 9 && report.vertices <= 200);
/// assert_eq!(cache.mesh.vertex_count(), report.vertices);
/// assert_eq!(cache.ground_vertices, report.ground_vertices);
/// assert_eq!(cache.params.refine.unwrap().tolerance, 0.5);
/// ```
pub fn precompute_refined(
    scene: Scene,
    options: &PrecomputeOptions,
    refinement: &Refinement,
) -> Result<(SceneCache, PrecomputeReport, RefineReport)> {
    refinement.check_with(options, None)?;
    let max_vertices = refinement.budget(scene.mesh.vertex_count())?;
    (options.budget(None)).check("the refined scene", max_vertices as u128)?;
    let start = Instant::now();
    let mut bisection = Bisection::new(&scene);
    let trace = |bisection: &Bisection, vertices: std::ops::Range<usize>| {
        let mesh = bisection.working_mesh()?;
        let bvh = SceneBvh::with_tracer(&mesh, options.ray_tracer);
        vertex_range(&mesh, &bvh, &options.visibility, vertices)
    };
    let unoccluded = Unoccluded::new(options.visibility.param);
    let scales = |bisection: &Bisection, vertices: std::ops::Range<usize>| {
        (vertices.into_par_iter())
            .map(|v| unoccluded.norm(bisection.normal(v)))
            .collect::<Vec<f64>>()
    };
    let (mut transport, mut report) = trace(&bisection, 0..bisection.vertex_count())?;
    let mut scale = scales(&bisection, 0..bisection.vertex_count());
    let shortest = (MIN_EDGE_OFFSETS * ray_offset(&scene.mesh)).powi(2);
    let (mut rounds, mut first) = (1, 0u32);
    loop {
        // Edges between two older vertices were judged in an earlier round.
        let judged: Vec<Edge> = (bisection.edges())
            .filter(|&(a, b)| a >= first || b >= first)
            .filter(|&e| bisection.squared_length(e) >= shortest)
            .collect();
        let mut marked = differences(&transport, &scale, &judged, refinement.tolerance);
        if marked.is_empty() {
            break;
        }
        let made = bisection.vertex_count();
        let stopped = split_marked(&mut bisection, &mut marked, max_vertices);
        if bisection.vertex_count() > made {
            let (set, r) = trace(&bisection, made..bisection.vertex_count())?;
            transport.append(&set)?;
            scale.extend(scales(&bisection, made..bisection.vertex_count()));
            report = join(report, r)?;
            rounds += 1;
        }
        if stopped {
            break;
        }
        first = made as u32;
    }
    let all: Vec<Edge> = bisection.edges().collect();
    let left = differences(&transport, &scale, &all, refinement.tolerance);
    let short = (left.iter())
        .filter(|&&(e, _)| bisection.squared_length(e) < shortest)
        .count();
    let order = bisection.order();
    let refined = bisection.scene(&scene)?;
    let transport = transport.reordered(&order)?;
    let mut params = options.record(scene.ground_cells, report.tracer);
    params.refine = Some(RefineRecord {
        tolerance: refinement.tolerance,
        max_vertices,
    });
    let mut cache = SceneCache::new(params, refined.mesh, refined.albedo, transport)?;
    cache.ground_vertices = refined.ground_vertices;
    // Refine first, then bounce: the gather runs once, over the refined mesh.
    report = super::add_bounces(&mut cache, options, report)?;
    report.seconds = start.elapsed().as_secs_f64();
    cache.environment = scene.environment;
    cache.camera = scene.camera;
    let refine_report = RefineReport {
        original: scene.mesh.vertex_count(),
        vertices: cache.mesh.vertex_count(),
        ground_vertices: cache.ground_vertices,
        rounds,
        max_vertices,
        above: left.len() - short,
        short,
    };
    Ok((cache, report, refine_report))
}

/// Splits the `marked` edges, largest difference first; returns whether the budget stopped
/// it.
fn split_marked(
    bisection: &mut Bisection,
    marked: &mut [(Edge, f64)],
    max_vertices: usize,
) -> bool {
    marked.sort_by(|(e, x), (f, y)| y.total_cmp(x).then(e.cmp(f)));
    !marked
        .iter()
        .all(|&(e, _)| bisection.split(e, max_vertices))
}

/// Of `edges`, those whose endpoints' transports differ by more than `tolerance` times the
/// larger of their unoccluded norms `scale` (see the [module docs](self)), with the ratio.
fn differences(
    transport: &TransportSet,
    scale: &[f64],
    edges: &[Edge],
    tolerance: f64,
) -> Vec<(Edge, f64)> {
    let texels = transport.param().texels();
    edges
        .par_iter()
        .map_init(
            || vec![0.0f64; texels],
            |dense, &(a, b)| {
                let most = scale[a as usize].max(scale[b as usize]);
                let d = difference(transport, a as usize, b as usize, dense) / most;
                // 0 / 0: neither end receives anything, and NaN is never above.
                (d > tolerance).then_some(((a, b), d))
            },
        )
        .flatten()
        .collect()
}

/// `|T_a - T_b|` in f64, through `dense`, a zeroed scratch of one vertex's texels, left zeroed.
pub(crate) fn difference(transport: &TransportSet, a: usize, b: usize, dense: &mut [f64]) -> f64 {
    let ((ia, va), (ib, vb)) = (transport.coefficients(a), transport.coefficients(b));
    for (&i, &x) in ia.iter().zip(va) {
        dense[i as usize] = f64::from(x);
    }
    let mut squared = 0.0;
    for (&i, &y) in ib.iter().zip(vb) {
        squared += (dense[i as usize] - f64::from(y)).powi(2);
        dense[i as usize] = 0.0;
    }
    for &i in ia {
        squared += dense[i as usize].powi(2);
        dense[i as usize] = 0.0;
    }
    squared.sqrt()
}

/// The norm of the transport with nothing in the way, `|U_n|`, for any normal `n`: the
/// parameterisation's texel directions and solid angles, made once.
pub(crate) struct Unoccluded {
    directions: Vec<[f64; 3]>,
    solid_angles: Vec<f64>,
}

impl Unoccluded {
    pub(crate) fn new(param: Parameterization) -> Self {
        Unoccluded {
            directions: texel_directions(param),
            solid_angles: param.solid_angles().iter().copied().collect(),
        }
    }

    /// `sqrt(sum_t (max(0, n . w_t) dOmega_t)^2)`.
    pub(crate) fn norm(&self, n: [f64; 3]) -> f64 {
        (self.directions.iter().zip(&self.solid_angles))
            .map(|(&w, &o)| (dot(n, w).max(0.0) * o).powi(2))
            .sum::<f64>()
            .sqrt()
    }
}

/// Two rounds' reports as one ([`PrecomputeReport::followed_by`]), refused unless one tracer
/// cast both.
fn join(sum: PrecomputeReport, round: PrecomputeReport) -> Result<PrecomputeReport> {
    if sum.tracer != round.tracer {
        return Err(Error::parameter(
            "ray tracer",
            format!(
                "the refinement's rounds were traced by {:?} and {:?}: one cache is cast by one",
                sum.tracer, round.tracer
            ),
        ));
    }
    Ok(sum.followed_by(&round))
}

#[cfg(test)]
#[path = "refine_tests.rs"]
mod tests;
