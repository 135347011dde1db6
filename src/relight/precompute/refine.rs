//! Vertices where the light needs them: `relight precompute --refine TOL [--max-vertices N]`.
//!
//! Per-vertex transport is only as sharp as the mesh: between two vertices a render
//! interpolates, so a shadow edge that crosses a coarse triangle is drawn across the whole of
//! it. [`precompute_refined`] precomputes the scene, then splits the edges whose endpoints'
//! transports differ by more than `TOL`, precomputes the new vertices, and repeats until no
//! edge differs by more than `TOL` or the next vertex would exceed the budget.
//!
//! **The criterion** is the relative L2 difference of the two endpoints' sparse transport
//! vectors, `|T_a - T_b| / max(|T_a|, |T_b|)` (the stored Haar coefficients; the transform is
//! orthonormal, so this is the difference of the weighted visibility x cosine over the sphere's
//! texels), in `[0, 2]`; an edge whose endpoints both see nothing is never split. Transport,
//! not the radiance under a probe lighting: a cache is relit under any map and any rotation of
//! it, and an edge that looks alike under one lighting (a shadow cast away from the probe's
//! sun, or under a dim part of the sky) is where another lighting's sun draws its shadow. The
//! transport difference bounds the radiance difference under every lighting `L`:
//! `|R_a - R_b| <= albedo / pi x |L| x |T_a - T_b|` (Cauchy-Schwarz), so an edge within `TOL`
//! is within `TOL` of its brighter end under all of them at once.
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

use crate::relight::precompute::visibility::{PrecomputeReport, vertex_range};
use crate::relight::precompute::shard::Shard;
use crate::relight::precompute::{Order, PrecomputeOptions};
use crate::relight::scene::refine::{Bisection, Edge};
use crate::relight::{RefineRecord, Scene, SceneBvh, SceneCache, TransportSet};
use crate::{Error, Result};

/// The budget of vertices when none is given: this many times the scene's.
pub const DEFAULT_GROWTH: usize = 4;

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
    /// `TOL`: split edges whose endpoints' transports differ by more (relative L2), in `(0, 2]`.
    pub tolerance: f64,
    /// `N`: the most vertices the refined mesh may have ([`DEFAULT_GROWTH`] times the
    /// scene's when `None`).
    pub max_vertices: Option<usize>,
}

impl Refinement {
    /// Refuses a tolerance outside `(0, 2]` (the relative difference of two vectors is at
    /// most 2; 0 would split forever).
    pub fn check(&self) -> Result<()> {
        if self.tolerance > 0.0 && self.tolerance <= 2.0 {
            return Ok(());
        }
        Err(Error::parameter(
            "refine",
            format!(
                "{}: the tolerance is a relative difference, in (0, 2]",
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
    /// Edges still above the tolerance: 0 unless the budget stopped the refinement.
    pub above: usize,
}

impl RefineReport {
    /// Whether the budget stopped the refinement before every edge was within the tolerance.
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
    let (mut transport, mut report) = trace(&bisection, 0..bisection.vertex_count())?;
    let (mut rounds, mut above, mut first) = (1, 0, 0u32);
    loop {
        // Edges between two older vertices were judged in an earlier round.
        let judged: Vec<Edge> = (bisection.edges())
            .filter(|&(a, b)| a >= first || b >= first)
            .collect();
        let mut marked = differences(&transport, &judged, refinement.tolerance);
        if marked.is_empty() {
            break;
        }
        let made = bisection.vertex_count();
        let stopped = split_marked(&mut bisection, &mut marked, max_vertices);
        if bisection.vertex_count() > made {
            let (set, r) = trace(&bisection, made..bisection.vertex_count())?;
            transport.append(&set)?;
            report = join(report, r)?;
            rounds += 1;
        }
        if stopped {
            let all: Vec<Edge> = bisection.edges().collect();
            above = differences(&transport, &all, refinement.tolerance).len();
            break;
        }
        first = made as u32;
    }
    let order = bisection.order();
    let refined = bisection.scene(&scene)?;
    let transport = transport.reordered(&order)?;
    report.seconds = start.elapsed().as_secs_f64();
    let mut params = options.record(scene.ground_cells, report.tracer);
    params.refine = Some(RefineRecord {
        tolerance: refinement.tolerance,
        max_vertices,
    });
    let mut cache = SceneCache::new(params, refined.mesh, refined.albedo, transport)?;
    cache.ground_vertices = refined.ground_vertices;
    cache.environment = scene.environment;
    cache.camera = scene.camera;
    let refine_report = RefineReport {
        original: scene.mesh.vertex_count(),
        vertices: cache.mesh.vertex_count(),
        ground_vertices: cache.ground_vertices,
        rounds,
        max_vertices,
        above,
    };
    Ok((cache, report, refine_report))
}

/// Splits the `marked` edges, largest difference first; returns whether the budget stopped
/// it.
fn split_marked(bisection: &mut Bisection, marked: &mut [(Edge, f64)], max_vertices: usize) -> bool {
    marked.sort_by(|(e, x), (f, y)| y.total_cmp(x).then(e.cmp(f)));
    !marked.iter().all(|&(e, _)| bisection.split(e, max_vertices))
}

/// Of `edges`, those whose endpoints' transports differ (relative L2, see the
/// [module docs](self)) by more than `tolerance`, with the difference.
fn differences(transport: &TransportSet, edges: &[Edge], tolerance: f64) -> Vec<(Edge, f64)> {
    let texels = transport.param().texels();
    edges
        .par_iter()
        .map_init(
            || vec![0.0f64; texels],
            |dense, &(a, b)| {
                let d = relative_difference(transport, a as usize, b as usize, dense);
                (d > tolerance).then_some(((a, b), d))
            },
        )
        .flatten()
        .collect()
}

/// `|T_a - T_b| / max(|T_a|, |T_b|)` in f64 (0 when both are zero), through `dense`, a zeroed
/// scratch of one vertex's texels, left zeroed.
pub(crate) fn relative_difference(
    transport: &TransportSet,
    a: usize,
    b: usize,
    dense: &mut [f64],
) -> f64 {
    let ((ia, va), (ib, vb)) = (transport.coefficients(a), transport.coefficients(b));
    let norm = |v: &[f32]| v.iter().map(|&x| f64::from(x).powi(2)).sum::<f64>();
    let largest = norm(va).max(norm(vb));
    if largest == 0.0 {
        return 0.0;
    }
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
    (squared / largest).sqrt()
}

/// Two rounds' reports as one: the rays summed, the larger working memory, the one tracer.
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
    Ok(PrecomputeReport {
        rays: sum.rays + round.rays,
        seconds: sum.seconds + round.seconds,
        working_bytes: sum.working_bytes.max(round.working_bytes),
        tracer: sum.tracer,
    })
}

#[cfg(test)]
#[path = "refine_tests.rs"]
mod tests;
