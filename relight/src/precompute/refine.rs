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
//! **Under a probe lighting** (`--refine-light ENV`, [`Refinement::probe`]) the criterion is
//! the RGB difference of the ends' radiances under that lighting over the most an end could
//! receive from it, `|<T_a, L> - <T_b, L>| / max(|<U_a, L>|, |<U_b, L>|)` (the albedo left
//! out, `<., L_c>` per channel and `|.|` over the channels; also in `[0, 2]` for a lighting of
//! no negative texel). It sees what the transport's norm cannot: a sun of one texel is one
//! texel of the transport, a step of about `dOmega cos / |U|` (0.03 at cube 32) where its
//! shadow falls, but most of the radiance under a sunny map. It refines for that lighting
//! unrotated, though: a rotated map's sun casts its shadow where the probe's did not.
//!
//! *By default transport, not the radiance under a probe lighting*: a cache is relit under any map and
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
//! ([`scene::bisect`](crate::scene) in the crate's source: every triangle on a split
//! edge is split at its one midpoint, no T-junctions; new vertices get the interpolated normal
//! and albedo; the objects' vertices, then the ground plane's, originals first in each). A
//! round marks every edge above `TOL` among those touching the vertices the last round made
//! and those the last round left marked (the first round: all edges; another edge between two
//! older vertices was judged already), and splits them in order of their difference times
//! their length, making at most a quarter of the vertices the budget has left (at least 64).
//! *Times the length*: the picture's error an edge leaves spans an area that grows with it, so
//! a long ground edge across a shadow goes before a short one on the bunny with the same
//! difference. *A quarter a round*: the halves of a split edge are judged in the next round
//! and compete for the rest of the budget with the edges left, so a shadow's edge is refined
//! again before the whole budget is spent at the first level.
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
//! cube 6 x 32^2, per pixel against `relight reference` of a dense mesh): the 128^2 grid
//! (18,480 vertices) is at 4.85e-2; at a quarter of its vertices (4,620) the transport
//! criterion reaches 5.77e-2 at best, and the probe criterion under the same map 4.57e-2 and
//! 4.53e-2 (`TOL` 0.2 and 0.1). The transport criterion is lighting-independent, and that is
//! its limit: the sun's shadow on the ground is where one texel turns dark, a step of about
//! `dOmega cos / |U|` (0.03 at cube 32), below any useful tolerance. The probe sees it, for
//! its own lighting: with the map turned 120 degrees the probe's meshes are at 5.18e-2 and
//! the transport's at 4.73e-2 and 4.68e-2, below the 128^2 grid's 4.86e-2.
//!
//! **What it is combined with.** The vertex order only: the direction order renders every
//! vertex into each shadow buffer at once, and a refinement traces a few vertices a round.
//! One ray per texel only: the stratified jitter is seeded by the vertex's index, which the
//! refined order renumbers. No `--shard`: which vertices exist is decided by the rounds, so
//! the vertex ranges of shards are not known before the whole precomputation has run (refine
//! once, then shard the refined mesh's precomputation). Interreflections (bounces) go after
//! refinement: refine first, then gather the bounces over the refined mesh, whose vertices
//! they need.

use std::collections::BTreeSet;
use std::ops::Range;
use std::time::Instant;

use rayon::prelude::*;

use crate::Lighting;
use crate::light::environment::{Environment, SphereMapping};
use crate::precompute::shard::Shard;
use crate::precompute::visibility::{PrecomputeReport, ray_offset, texel_directions, vertex_range};
use crate::precompute::{Order, PrecomputeOptions};
use crate::scene::bisect::{Bisection, Edge};
use crate::scene::mesh::dot;
use crate::{Error, Result};
use crate::{RefineRecord, Scene, SceneBvh, SceneCache, TransportSet};
use haarshift::faces::Parameterization;
use haarshift::product::Selection;
use haarshift::sphere::SphereRotation;

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
/// use haarshift_relight::precompute::refine::Refinement;
/// let r = Refinement { tolerance: 0.2, max_vertices: None, probe: None };
/// assert_eq!(r.budget(1000).unwrap(), 4000);
/// let err = Refinement { tolerance: 0.2, max_vertices: Some(999), probe: None }.budget(1000).unwrap_err();
/// assert!(err.to_string().contains("999 vertices: the scene has 1000 already"), "{err}");
/// assert!(Refinement { tolerance: 0.0, max_vertices: None, probe: None }.check().is_err());
/// assert!(Refinement { tolerance: 2.5, max_vertices: None, probe: None }.check().is_err());
/// ```
#[derive(Clone, Debug, PartialEq)]
pub struct Refinement {
    /// `TOL`: split edges whose endpoints' transports (or radiances under the
    /// [`probe`](Self::probe)) differ by more than `TOL` times the most an endpoint could
    /// receive (see the [module docs](self)), in `(0, 2]`.
    pub tolerance: f64,
    /// `N`: the most vertices the refined mesh may have ([`DEFAULT_GROWTH`] times the
    /// scene's when `None`).
    pub max_vertices: Option<usize>,
    /// `--refine-light ENV`: judge edges by their radiance under this lighting instead of by
    /// their transport.
    pub probe: Option<Probe>,
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
    /// use haarshift_relight::precompute::{Order, PrecomputeOptions};
    /// use haarshift_relight::precompute::refine::Refinement;
    /// use haarshift_relight::precompute::shard::Shard;
    /// use haarshift_relight::VisibilityOptions;
    /// use haarshift::faces::{ParamKind, Parameterization};
    /// let mut o = PrecomputeOptions::new(VisibilityOptions::new(Parameterization::new(ParamKind::Cube, 4).unwrap()));
    /// let r = Refinement { tolerance: 0.1, max_vertices: None, probe: None };
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
        if let Some(probe) = &self.probe
            && probe.lighting.param() != options.visibility.param
        {
            return Err(Error::parameter(
                "refine light",
                "the probe lighting was made at another parameterisation than the transport's",
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
    /// use haarshift_relight::precompute::refine::RefineReport;
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
/// [`SceneCache`] whose mesh is the refined one ([`CacheParams::refine`](crate::CacheParams::refine)
/// recording how), with what the precomputation and the refinement did. The precomputation's
/// report sums every round's rays; its seconds are the whole run's (splits and criterion
/// included).
///
/// ```
/// use haarshift_relight::precompute::PrecomputeOptions;
/// use haarshift_relight::precompute::refine::{Refinement, precompute_refined};
/// use haarshift_relight::{Generator, Scene, VisibilityOptions};
/// use haarshift::faces::{ParamKind, Parameterization};
/// let mut scene = Scene::from_mesh(Generator::Sphere { cells: 1 }.mesh().unwrap(), false).unwrap();
/// scene.add_ground_plane_of(2).unwrap();
/// let options = PrecomputeOptions::new(VisibilityOptions::new(Parameterization::new(ParamKind::LatLong, 8).unwrap()));
/// let refinement = Refinement { tolerance: 0.5, max_vertices: Some(200), probe: None };
/// let (cache, _, report) = precompute_refined(scene, &options, &refinement).unwrap();
/// assert!(report.vertices > 24 + 9 && report.vertices <= 200);
/// assert_eq!(cache.mesh.vertex_count(), report.vertices);
/// assert_eq!(cache.ground_vertices, report.ground_vertices);
/// assert_eq!(cache.params.refine.as_ref().unwrap().tolerance, 0.5);
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
    let trace = |bisection: &Bisection, vertices: Range<usize>| {
        let mesh = bisection.working_mesh()?;
        let bvh = SceneBvh::with_tracer(&mesh, options.ray_tracer);
        vertex_range(&mesh, &bvh, &options.visibility, vertices)
    };
    let mut judge = Judge::new(options.visibility.param, refinement.probe.as_ref());
    let (mut transport, mut report) = trace(&bisection, 0..bisection.vertex_count())?;
    judge.extend(&bisection, &transport, 0..bisection.vertex_count());
    let shortest = (MIN_EDGE_OFFSETS * ray_offset(&scene.mesh)).powi(2);
    let (mut rounds, mut first) = (1, 0u32);
    // Marked edges a round's quota left unsplit, judged again with the next round's.
    let mut pending: BTreeSet<Edge> = BTreeSet::new();
    loop {
        // Edges between two older vertices were judged in an earlier round.
        let judged: Vec<Edge> = (bisection.edges())
            .filter(|&(a, b)| a >= first || b >= first || pending.contains(&(a, b)))
            .filter(|&e| bisection.squared_length(e) >= shortest)
            .collect();
        let marked = judge.above(&transport, &judged, refinement.tolerance);
        if marked.is_empty() {
            break;
        }
        let made = bisection.vertex_count();
        let cap = made + round_quota(max_vertices - made);
        split_marked(&mut bisection, &marked, cap.min(max_vertices));
        pending = (marked.iter())
            .map(|&(e, _)| e)
            .filter(|&e| bisection.has_edge(e))
            .collect();
        if bisection.vertex_count() > made {
            let (set, r) = trace(&bisection, made..bisection.vertex_count())?;
            transport.append(&set)?;
            judge.extend(&bisection, &transport, made..bisection.vertex_count());
            report = join(report, r)?;
            rounds += 1;
        }
        if bisection.vertex_count() >= max_vertices || bisection.vertex_count() == made {
            break;
        }
        first = made as u32;
    }
    let all: Vec<Edge> = bisection.edges().collect();
    let left = judge.above(&transport, &all, refinement.tolerance);
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
        probe: refinement.probe.as_ref().map(|p| p.name.clone()),
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

/// The most vertices one round may make of the `left` the budget still allows: a quarter
/// (at least [`MIN_ROUND`]), so that the shorter edges a round makes compete for the rest of
/// the budget with the longer ones it left.
fn round_quota(left: usize) -> usize {
    (left / 4).max(MIN_ROUND)
}

/// The fewest vertices a round may make (unless the budget has fewer left).
const MIN_ROUND: usize = 64;

/// Splits the `marked` edges in order of their difference times their length (the area of
/// the picture an edge's error spans grows with it), until the next would pass `cap` vertices.
fn split_marked(bisection: &mut Bisection, marked: &[(Edge, f64)], cap: usize) {
    let rank = |&(e, d): &(Edge, f64)| d * bisection.squared_length(e).sqrt();
    let mut ranked: Vec<(f64, Edge)> = marked.iter().map(|m| (rank(m), m.0)).collect();
    ranked.sort_by(|(x, e), (y, f)| y.total_cmp(x).then(e.cmp(f)));
    for (_, e) in ranked {
        if !bisection.split(e, cap) {
            return;
        }
    }
}

/// A probe lighting for the criterion (`--refine-light ENV`, see the [module docs](self)): the
/// environment at the transport's parameterisation, as Haar coefficients (for `<T_v, L>`) and
/// as texels (for the unoccluded `<U_v, L>`), unrotated and untruncated.
///
/// ```
/// use haarshift_relight::precompute::refine::Probe;
/// use haarshift_relight::light::environment::Environment;
/// use haarshift::faces::{ParamKind, Parameterization};
/// use haarshift::sphere::LatLongMap;
/// let sky = Environment::new(LatLongMap::<f64>::from_fn(16, 3, |d, o| o.fill(1.0 + d[1])).unwrap());
/// let probe = Probe::new("sky", &sky, Parameterization::new(ParamKind::Cube, 4).unwrap()).unwrap();
/// assert_eq!(probe.name(), "sky");
/// ```
#[derive(Clone, Debug, PartialEq)]
pub struct Probe {
    name: String,
    lighting: Lighting,
    texels: Vec<[f64; 3]>,
}

impl Probe {
    /// `env` brought to `param` ([`SphereMapping`]), recorded in the cache as `name`.
    pub fn new(
        name: impl Into<String>,
        env: &Environment,
        param: Parameterization,
    ) -> Result<Probe> {
        let map = SphereMapping::new(env.map().height(), param)?
            .apply(env, &SphereRotation::identity())?;
        let lighting = Lighting::from_map(&map, Selection::All)?;
        let rows = lighting.coefficients_f64();
        let a = map.as_array();
        let last = map.channels() - 1; // a grey map (1) broadcast, as the lighting's
        let texels = (a.rows().into_iter())
            .map(|t| [t[0], t[1.min(last)], t[2.min(last)]])
            .collect::<Vec<_>>();
        debug_assert_eq!(
            (texels.len(), rows.nrows()),
            (param.texels(), param.texels())
        );
        Ok(Probe {
            name: name.into(),
            lighting,
            texels,
        })
    }

    /// The name the cache records.
    pub fn name(&self) -> &str {
        &self.name
    }

    /// `<T_v, L_c>` per channel: the sparse transport against the lighting's coefficients.
    fn radiance(&self, transport: &TransportSet, v: usize) -> [f64; 3] {
        let rows = self.lighting.coefficients_f64();
        let (indices, values) = transport.coefficients(v);
        let mut sum = [0.0; 3];
        for (&i, &x) in indices.iter().zip(values) {
            for (s, &l) in sum.iter_mut().zip(rows.row(i as usize)) {
                *s += f64::from(x) * l;
            }
        }
        sum
    }
}

/// The criterion's per-vertex state, extended as rounds make vertices: the scale `|U_v|` (or
/// `|<U_v, L>|` under a probe) and, under a probe, each vertex's `<T_v, L>`.
struct Judge<'a> {
    unoccluded: Unoccluded,
    probe: Option<&'a Probe>,
    scale: Vec<f64>,
    radiance: Vec<[f64; 3]>,
}

impl<'a> Judge<'a> {
    fn new(param: Parameterization, probe: Option<&'a Probe>) -> Self {
        Judge {
            unoccluded: Unoccluded::new(param),
            probe,
            scale: Vec::new(),
            radiance: Vec::new(),
        }
    }

    /// The state of `vertices`, the next of the bisection's, traced into `transport`.
    fn extend(&mut self, bisection: &Bisection, transport: &TransportSet, vertices: Range<usize>) {
        let (unoccluded, probe) = (&self.unoccluded, self.probe);
        let scale: Vec<f64> = (vertices.clone().into_par_iter())
            .map(|v| match probe {
                None => unoccluded.norm(bisection.normal(v)),
                Some(p) => norm(unoccluded.radiance(bisection.normal(v), &p.texels)),
            })
            .collect();
        self.scale.extend(scale);
        if let Some(p) = probe {
            let radiance: Vec<[f64; 3]> = (vertices.into_par_iter())
                .map(|v| p.radiance(transport, v))
                .collect();
            self.radiance.extend(radiance);
        }
    }

    /// Of `edges`, those whose endpoints differ by more than `tolerance` times the larger of
    /// their scales (see the [module docs](self)), with the ratio.
    fn above(&self, transport: &TransportSet, edges: &[Edge], tolerance: f64) -> Vec<(Edge, f64)> {
        // The transport's difference needs a dense scratch of a vertex's texels; a probe's none.
        let texels = match self.probe {
            None => transport.param().texels(),
            Some(_) => 0,
        };
        edges
            .par_iter()
            .map_init(
                || vec![0.0f64; texels],
                |dense, &(a, b)| {
                    let (a, b) = (a as usize, b as usize);
                    let most = self.scale[a].max(self.scale[b]);
                    let d = match self.probe {
                        None => difference(transport, a, b, dense),
                        Some(_) => {
                            let (x, y) = (self.radiance[a], self.radiance[b]);
                            norm([0, 1, 2].map(|c| x[c] - y[c]))
                        }
                    } / most;
                    // 0 / 0: neither end receives anything, and NaN is never above.
                    (d > tolerance).then_some(((a as u32, b as u32), d))
                },
            )
            .flatten()
            .collect()
    }
}

fn norm(x: [f64; 3]) -> f64 {
    x.iter().map(|v| v * v).sum::<f64>().sqrt()
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

    /// `<U_n, L_c>` per channel, `sum_t max(0, n . w_t) dOmega_t L_c(w_t)`, for the
    /// lighting's `texels`.
    pub(crate) fn radiance(&self, n: [f64; 3], texels: &[[f64; 3]]) -> [f64; 3] {
        let mut sum = [0.0; 3];
        for ((&w, &o), l) in self.directions.iter().zip(&self.solid_angles).zip(texels) {
            let weight = dot(n, w).max(0.0) * o;
            for (s, &x) in sum.iter_mut().zip(l) {
                *s += weight * x;
            }
        }
        sum
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
