//! The whole precomputation of a scene, as `haarshift relight precompute` runs it: the
//! visibility in the chosen loop order ([`vertex_major`](visibility::vertex_major) through a
//! [`SceneBvh`], or [`direction_major`] with shadow buffers), the transport of every vertex, and
//! the [`SceneCache`] that records how it was made; or one [`shard`] of the vertices of a
//! precomputation split across machines ([`precompute_shard`], a [`CacheShard`]). With
//! [`PrecomputeOptions::bounces`] `B > 0` the direct transport is followed by the bounced sum
//! of `B` bounces of interreflected light ([`bounce`]), gathered over the same rays.
//!
//! **The contract of a ray**, which every caster here, `relight reference` and the path
//! tracer share: a vertex's rays start at the origin [`origin`] defines (one ray offset off
//! its surface, and off any other surface it touches: creases and contact); a ray is blocked
//! by the closest triangle it meets at `0 <= t`, whichever tracer casts it
//! ([`raycast`]); and a hit sends light back only on its shading normal's side ([`bounce`]).
//!
//! **Limits.** A precomputation holds one `(faces, S, S)` array of f32 per thread and, in the
//! direction order, one bit per (vertex, direction); a transport of more than [`MAX_TEXELS`]
//! texels (lat-long `2048 x 4096`, cube `6 x 1024^2` are inside) is refused before any work,
//! so an absurd `--resolution` is a clear error rather than an exhausted machine. A scene
//! whose vertices would not fit in [`PrecomputeOptions::budget`] is refused from its count,
//! before the BVH or any transport is built.

pub mod bounce;
pub(crate) mod cast;
pub(crate) mod combine;
pub mod embree;
pub mod origin;
mod packet;
pub mod raycast;
pub mod refine;
pub mod request;
pub mod shadowmap;
pub mod shard;
pub mod sparse;
pub mod transport_set;
pub mod visibility;

use haarshift::named_enum;
use std::path::Path;

use crate::precompute::bounce::BouncedTransport;
use crate::precompute::shard::Shard;
use crate::precompute::visibility::{
    PrecomputeReport, VisibilityOptions, direction_major, vertex_range,
};
use crate::scene::cache_shard::Provenance;
use crate::scene::validate::{DEFAULT_MEMORY_LIMIT, MemoryBudget};
use crate::{
    CacheParams, CacheShard, RayTracer, Scene, SceneBvh, SceneCache, SceneError, TransportSet,
};
use crate::{Error, Result};
use haarshift::product::Selection;

named_enum! {
    /// The loop order of the visibility precomputation (`--order`).
    #[derive(Default)]
    pub enum Order ("order") {
        #[default]
        /// Vertices outer, directions inner, rays through a BVH.
        Vertex = "vertex",
        /// Microsoft 2003's order: directions outer, a shadow buffer per direction.
        Direction = "direction",
    }
}

/// The most texels a transport may have (`2^24`).
pub const MAX_TEXELS: usize = 1 << 24;

/// The default shadow-buffer side of the direction order (the issue's agreement bound holds
/// from 2048 up).
pub const DEFAULT_MAP_SIZE: usize = 2048;

/// How to precompute a scene.
///
/// ```
/// use haarshift_relight::precompute::{Order, PrecomputeOptions};
/// use haarshift_relight::VisibilityOptions;
/// use haarshift::faces::{ParamKind, Parameterization};
/// let o = PrecomputeOptions::new(VisibilityOptions::new(Parameterization::new(ParamKind::Cube, 8).unwrap()));
/// assert_eq!((o.order, o.map_size, o.memory_limit), (Order::Vertex, 2048, 4 << 30));
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PrecomputeOptions {
    /// Directions, samples, truncation, seed, progress reporting.
    pub visibility: VisibilityOptions,
    /// The loop order.
    pub order: Order,
    /// Shadow-buffer side for [`Order::Direction`].
    pub map_size: usize,
    /// The most bytes the scene and its transport may take ([`budget`](Self::budget)).
    pub memory_limit: u64,
    /// The ray tracer of [`Order::Vertex`] ([`RayTracer::best`] unless changed).
    pub ray_tracer: RayTracer,
    /// Bounces of interreflected light, 0 to [`MAX_BOUNCES`](bounce::MAX_BOUNCES) (0: direct
    /// light alone); the vertex order only.
    pub bounces: usize,
}

impl PrecomputeOptions {
    /// The vertex order with `visibility` (shadow buffers of [`DEFAULT_MAP_SIZE`] if the order
    /// is changed).
    pub fn new(visibility: VisibilityOptions) -> Self {
        PrecomputeOptions {
            visibility,
            order: Order::Vertex,
            map_size: DEFAULT_MAP_SIZE,
            memory_limit: DEFAULT_MEMORY_LIMIT,
            ray_tracer: RayTracer::best(),
            bounces: 0,
        }
    }

    /// Refuses a transport of more than [`MAX_TEXELS`] texels, and bounces beyond
    /// [`MAX_BOUNCES`](bounce::MAX_BOUNCES) or in the direction order (a shadow buffer says
    /// whether a ray is blocked, not what it hits), before any scene is read.
    ///
    /// ```
    /// use haarshift_relight::precompute::PrecomputeOptions;
    /// use haarshift_relight::VisibilityOptions;
    /// use haarshift::faces::{ParamKind, Parameterization};
    /// let huge = Parameterization::new(ParamKind::LatLong, 4096).unwrap();
    /// let err = PrecomputeOptions::new(VisibilityOptions::new(huge)).check().unwrap_err();
    /// assert!(err.to_string().contains("resolution"));
    /// let mut bounced = PrecomputeOptions::new(VisibilityOptions::new(Parameterization::new(ParamKind::Cube, 8).unwrap()));
    /// bounced.bounces = 9;
    /// assert!(bounced.check().unwrap_err().to_string().contains("0 to 8"));
    /// bounced.bounces = 2;
    /// bounced.order = haarshift_relight::precompute::Order::Direction;
    /// assert!(bounced.check().unwrap_err().to_string().contains("shadow buffers"));
    /// ```
    pub fn check(&self) -> Result<()> {
        if self.bounces > 0 {
            bounce::check_bounces(self.bounces)?;
            if self.order == Order::Direction {
                return Err(Error::parameter(
                    "bounces",
                    "the direction order's shadow buffers say whether a ray is blocked, not \
                     what it hits, so they gather no bounces: use --order vertex",
                ));
            }
        }
        if let Some(why) = self.ray_tracer.unavailable() {
            return Err(Error::parameter(
                "ray tracer",
                format!("{} is not available: {why}", self.ray_tracer),
            ));
        }
        let param = self.visibility.param;
        if param.texels() <= MAX_TEXELS {
            return Ok(());
        }
        Err(Error::parameter(
            "resolution",
            format!(
                "{} {}: {} texels per vertex, more than the {MAX_TEXELS} a precomputation takes",
                param.kind(),
                param.face_size(),
                param.texels()
            ),
        ))
    }

    /// Refuses what a shard cannot do, before any scene is read: the direction order (every
    /// shadow buffer serves all vertices at once) and bounces without `bounce_from` (bounce
    /// `b + 1` of a shard's vertices needs bounce `b` of every vertex: the merged cache of the
    /// last bounce, [`precompute_bounce_shard`]).
    ///
    /// ```
    /// use haarshift_relight::precompute::{Order, PrecomputeOptions};
    /// use haarshift_relight::VisibilityOptions;
    /// use haarshift::faces::{ParamKind, Parameterization};
    /// let mut o = PrecomputeOptions::new(VisibilityOptions::new(Parameterization::new(ParamKind::Cube, 4).unwrap()));
    /// assert!(o.check_shard(false).is_ok());
    /// o.bounces = 1;
    /// let err = o.check_shard(false).unwrap_err().to_string();
    /// assert!(err.contains("--bounce-from MERGED.hsr"), "{err}");
    /// assert!(o.check_shard(true).is_ok());
    /// o.order = Order::Direction;
    /// assert!(o.check_shard(true).unwrap_err().to_string().contains("cannot be sharded"));
    /// ```
    pub fn check_shard(&self, bounce_from: bool) -> Result<()> {
        if self.order == Order::Direction {
            return Err(Error::parameter(
                "order",
                "direction: every shadow buffer serves all vertices at once, so it cannot be \
                 sharded; shard with --order vertex",
            ));
        }
        if self.bounces > 0 && !bounce_from {
            return Err(Error::parameter(
                "bounces",
                "bounce b + 1 of a shard's vertices needs bounce b of every vertex: shard \
                 without --bounces, merge, then add one bounce at a time with --bounce-from \
                 MERGED.hsr",
            ));
        }
        Ok(())
    }

    /// The [`MemoryBudget`] of this precomputation: per vertex, beyond the mesh, the most
    /// coefficients its selection can keep (every texel's unless it keeps a count), 8 bytes
    /// each (`u32` index, `f32` value) held twice (the vertices' rows, then the gathered set
    /// and the file's bytes), its row's 80 bytes of bookkeeping, the spherical-harmonic
    /// transfer, with bounces as much again for each of three channels of the bounced sum,
    /// and in the direction order one bit per texel. The direction order's shadow
    /// buffers (one per thread, `4 M^2` bytes) are not per vertex and not counted. With a
    /// `shard` of `N`, each vertex's mesh is held but the transport of only the largest
    /// `N`-th of them.
    ///
    /// ```
    /// use haarshift_relight::precompute::PrecomputeOptions;
    /// use haarshift_relight::VisibilityOptions;
    /// use haarshift::faces::{ParamKind, Parameterization};
    /// use haarshift::product::Selection;
    /// let mut o = PrecomputeOptions::new(VisibilityOptions::new(Parameterization::new(ParamKind::LatLong, 8).unwrap()));
    /// assert_eq!(o.budget(None).per_vertex, 2 * 8 * 128 + 80); // every one of 8 x 16 texels
    /// o.visibility.keep = Selection::Largest(30);
    /// assert_eq!(o.budget(None).per_vertex, 2 * 8 * 32 + 80); // 30 details and 2 face scalings
    /// let third = haarshift_relight::precompute::shard::Shard::new(2, 3).unwrap();
    /// assert_eq!((o.budget(None).shards, o.budget(Some(third)).shards), (1, 3));
    /// ```
    pub fn budget(&self, shard: Option<Shard>) -> MemoryBudget {
        let param = self.visibility.param;
        let (texels, faces) = (param.texels() as u64, param.faces() as u64);
        let kept = match self.visibility.keep {
            Selection::All | Selection::Threshold(_) => texels,
            Selection::Largest(k) => (k as u64).saturating_add(faces).min(texels),
            Selection::LargestPerFace(k) => (k as u64)
                .saturating_add(1)
                .saturating_mul(faces)
                .min(texels),
        };
        let sh = (self.visibility.sh_bands)
            .map_or(0, |b| (b as u64).saturating_pow(2).saturating_mul(4));
        let bits = match self.order {
            Order::Vertex => 0,
            Order::Direction => texels.div_ceil(8),
        };
        let sets = if self.bounces > 0 { 4 } else { 1 };
        MemoryBudget {
            limit: self.memory_limit,
            shards: shard.map_or(1, |s| s.count() as u64),
            per_vertex: kept
                .saturating_mul(2 * 8)
                .saturating_add(80)
                .saturating_add(sh.saturating_mul(2))
                .saturating_mul(sets)
                .saturating_add(bits),
        }
    }

    /// What the cache records of these options.
    pub(crate) fn record(
        &self,
        ground_cells: Option<usize>,
        tracer: Option<RayTracer>,
    ) -> CacheParams {
        let v = &self.visibility;
        CacheParams {
            param: v.param.kind().to_string(),
            resolution: v.param.face_size(),
            keep: v.keep.into(),
            samples: v.samples,
            seed: v.seed,
            order: self.order.to_string(),
            map_size: (self.order == Order::Direction).then_some(self.map_size),
            ground_plane: ground_cells.is_some(),
            ground_cells,
            sh_bands: v.sh_bands,
            ray_tracer: tracer.map(|t| t.to_string()),
            bounces: 0,
            refine: None,
        }
    }
}

/// Precomputes `scene` into a [`SceneCache`] (recording the options, whether the scene has
/// the ground plane, and the scene file's environment and camera), with what the
/// precomputation did.
///
/// ```
/// use haarshift_relight::precompute::{PrecomputeOptions, precompute};
/// use haarshift_relight::{Generator, Scene, VisibilityOptions};
/// use haarshift::faces::{ParamKind, Parameterization};
/// let scene = Scene::from_mesh(Generator::Sphere { cells: 2 }.mesh().unwrap(), true).unwrap();
/// let param = Parameterization::new(ParamKind::LatLong, 8).unwrap();
/// let (cache, report) = precompute(scene, &PrecomputeOptions::new(VisibilityOptions::new(param))).unwrap();
/// assert_eq!(cache.transport.vertex_count(), 54 + 1089);
/// assert!(cache.params.ground_plane && report.rays > 0);
/// let mut options = PrecomputeOptions::new(VisibilityOptions::new(param));
/// options.bounces = 1; // and light that bounces once off the ground and the sphere
/// let scene = Scene::from_mesh(Generator::Sphere { cells: 2 }.mesh().unwrap(), true).unwrap();
/// let (bounced, report) = precompute(scene, &options).unwrap();
/// assert_eq!((bounced.params.bounces, bounced.transport, bounced.bounced.unwrap().is_grey()),
///            (1, cache.transport, true));
/// assert!(report.bounce_seconds > 0.0 && report.seconds > report.bounce_seconds);
/// let huge = Parameterization::new(ParamKind::LatLong, 4096).unwrap();
/// let scene = Scene::from_mesh(Generator::Sphere { cells: 2 }.mesh().unwrap(), false).unwrap();
/// assert!(precompute(scene, &PrecomputeOptions::new(VisibilityOptions::new(huge))).is_err());
/// ```
pub fn precompute(
    scene: Scene,
    options: &PrecomputeOptions,
) -> Result<(SceneCache, PrecomputeReport)> {
    let (transport, bounced, report) = transport(&scene, options, None)?;
    let mut cache = SceneCache::new(
        options.record(scene.ground_cells, report.tracer),
        scene.mesh,
        scene.albedo,
        transport,
    )?;
    if let Some(bounced) = bounced {
        cache.set_bounced(bounced)?;
    }
    cache.environment = scene.environment;
    cache.camera = scene.camera;
    Ok((cache, report))
}

/// Gathers `options.bounces` bounces over every vertex of `cache` from its direct transport
/// ([`bounce`]) and stores them in it; `report` followed by the gather's. Nothing without
/// bounces.
pub(crate) fn add_bounces(
    cache: &mut SceneCache,
    options: &PrecomputeOptions,
    report: PrecomputeReport,
) -> Result<PrecomputeReport> {
    if options.bounces == 0 {
        return Ok(report);
    }
    let bvh = SceneBvh::with_tracer(&cache.mesh, options.ray_tracer);
    let all = 0..cache.mesh.vertex_count();
    let (bounced, b) = bounce::bounce_range(
        &cache.mesh,
        &bvh,
        &options.visibility,
        cache.albedo.view(),
        &cache.transport,
        None,
        options.bounces,
        all,
    )?;
    cache.set_bounced(bounced)?;
    Ok(report.followed_by(&b))
}

/// Precomputes shard `shard` of `scene` ([`shard`] module: the vertices
/// `Shard::vertices` names, traced against the whole scene) into a [`CacheShard`] that
/// [`merge_shards`](crate::merge_shards) joins with the others. The vertex order only:
/// the direction order renders every vertex into each shadow buffer at once, so it is refused.
///
/// ```
/// use haarshift_relight::precompute::{Order, PrecomputeOptions, precompute_shard};
/// use haarshift_relight::precompute::shard::Shard;
/// use haarshift_relight::{Generator, Scene, VisibilityOptions};
/// use haarshift::faces::{ParamKind, Parameterization};
/// let scene = || Scene::from_mesh(Generator::Sphere { cells: 2 }.mesh().unwrap(), true).unwrap();
/// let mut options = PrecomputeOptions::new(VisibilityOptions::new(Parameterization::new(ParamKind::LatLong, 8).unwrap()));
/// let (part, report) = precompute_shard(scene(), &options, Shard::new(0, 2).unwrap()).unwrap();
/// assert_eq!((part.record.first, part.record.end, part.transport.vertex_count()), (0, 571, 571));
/// assert!(report.rays > 0);
/// options.order = Order::Direction;
/// assert!(precompute_shard(scene(), &options, Shard::new(0, 2).unwrap()).is_err());
/// ```
pub fn precompute_shard(
    scene: Scene,
    options: &PrecomputeOptions,
    shard: Shard,
) -> Result<(CacheShard, PrecomputeReport)> {
    options.check_shard(false)?;
    let (transport, _, report) = transport(&scene, options, Some(shard))?;
    let mut part = CacheShard::new(
        shard,
        options.record(scene.ground_cells, report.tracer),
        scene.mesh,
        scene.albedo,
        transport,
    )?;
    part.environment = scene.environment;
    part.camera = scene.camera;
    Ok((part, report))
}

/// Shard `shard` of one more bounce: the direct transport of its vertices copied from
/// `merged` (the merged cache of `options.bounces - 1` bounces of `scene`, made with
/// `options`), and the bounced sum of `options.bounces` bounces of its vertices gathered from
/// `merged`'s transport and bounced sum of every vertex ([`bounce::bounce_range`]). The
/// shards of each bounce, merged ([`merge_shards`](crate::merge_shards)), make the
/// cache the next bounce starts from, and the last merge is the cache an unsharded
/// `--bounces` run writes, byte for byte: bounce `b + 1` of a vertex needs bounce `b` of
/// every vertex, so shards go bounce by bounce with a merge between.
///
/// ```
/// use haarshift_relight::precompute::{PrecomputeOptions, precompute, precompute_bounce_shard};
/// use haarshift_relight::precompute::shard::Shard;
/// use haarshift_relight::{Generator, Scene, VisibilityOptions};
/// use haarshift::faces::{ParamKind, Parameterization};
/// let scene = || Scene::from_mesh(Generator::OpenBox { cells: 1 }.mesh().unwrap(), false).unwrap();
/// let mut options = PrecomputeOptions::new(VisibilityOptions::new(Parameterization::new(ParamKind::LatLong, 4).unwrap()));
/// let (direct, _) = precompute(scene(), &options).unwrap();
/// options.bounces = 1;
/// let (part, _) = precompute_bounce_shard(scene(), &options, Shard::new(1, 2).unwrap(), &direct).unwrap();
/// let (whole, _) = precompute(scene(), &options).unwrap();
/// let (first, bounced) = (part.record.first, part.bounced.unwrap());
/// assert_eq!(bounced.channel(0).coefficients(0), whole.bounced.unwrap().channel(0).coefficients(first));
/// options.bounces = 2; // two bounces on from a cache of none
/// assert!(precompute_bounce_shard(scene(), &options, Shard::new(1, 2).unwrap(), &direct).is_err());
/// ```
pub fn precompute_bounce_shard(
    scene: Scene,
    options: &PrecomputeOptions,
    shard: Shard,
    merged: &SceneCache,
) -> Result<(CacheShard, PrecomputeReport)> {
    options.check()?;
    let from = merged.params.bounces;
    if options.bounces != from + 1 {
        return Err(Error::parameter(
            "bounces",
            format!(
                "{}: a shard adds one bounce to its merged cache's {from}, so give --bounces {}",
                options.bounces,
                from + 1
            ),
        ));
    }
    let tracer = (options.order == Order::Vertex).then_some(options.ray_tracer);
    let mut params = options.record(scene.ground_cells, tracer);
    params.bounces = from;
    let wanted = Provenance::of_scene(&params, &scene);
    if let Some(how) = Provenance::of_cache(merged).difference(&wanted) {
        return Err(Error::from(SceneError::ShardMismatch(format!(
            "the merged cache has {how} than asked for"
        ))));
    }
    let mesh = &scene.mesh;
    let range = shard.range(mesh.vertex_count());
    let bvh = SceneBvh::with_tracer(mesh, options.ray_tracer);
    let (bounced, report) = bounce::bounce_range(
        mesh,
        &bvh,
        &options.visibility,
        scene.albedo.view(),
        &merged.transport,
        merged.bounced.as_ref(),
        options.bounces,
        range.clone(),
    )?;
    params.bounces = 0; // set again with the bounced sum
    let transport = merged.transport.part(range)?;
    let mut part = CacheShard::new(shard, params, scene.mesh, scene.albedo, transport)?;
    part.set_bounced(bounced)?;
    part.environment = scene.environment;
    part.camera = scene.camera;
    Ok((part, report))
}

/// Whether `path` already holds shard `shard` of `scene` made with `options`, complete: a
/// rerun after a preemption skips it (files are written atomically, so one that reads is
/// whole). `false` when there is no file; an error when the file is damaged or holds another
/// shard, scene or options, since replacing it is the caller's decision (`--force`).
///
/// ```
/// use haarshift_relight::precompute::{PrecomputeOptions, precompute_shard, shard_is_done};
/// use haarshift_relight::precompute::shard::Shard;
/// use haarshift_relight::{Generator, Scene, VisibilityOptions};
/// use haarshift::faces::{ParamKind, Parameterization};
/// let scene = || Scene::from_mesh(Generator::Sphere { cells: 2 }.mesh().unwrap(), false).unwrap();
/// let options = PrecomputeOptions::new(VisibilityOptions::new(Parameterization::new(ParamKind::Cube, 4).unwrap()));
/// let dir = tempfile::tempdir().unwrap();
/// let path = dir.path().join("part-1.hsr");
/// let one = Shard::new(1, 2).unwrap();
/// assert!(!shard_is_done(&path, &scene(), &options, one).unwrap());
/// precompute_shard(scene(), &options, one).unwrap().0.write(&path, false).unwrap();
/// assert!(shard_is_done(&path, &scene(), &options, one).unwrap());
/// let err = shard_is_done(&path, &scene(), &options, Shard::new(0, 2).unwrap()).unwrap_err();
/// assert!(err.to_string().contains("holds shard 1/2"), "{err}");
/// ```
pub fn shard_is_done(
    path: &Path,
    scene: &Scene,
    options: &PrecomputeOptions,
    shard: Shard,
) -> Result<bool> {
    if !path.exists() {
        return Ok(false);
    }
    let found = CacheShard::read(path)?;
    // The tracer a rerun would cast with: the one asked for (it fell back only if Embree
    // failed to build the scene, and then the records differ and the shard is recast).
    let tracer = (options.order == Order::Vertex).then_some(options.ray_tracer);
    let mut params = options.record(scene.ground_cells, tracer);
    // A shard of one more bounce ([`precompute_bounce_shard`]) records its bounces.
    params.bounces = options.bounces;
    let wanted = Provenance::of_scene(&params, scene);
    let (index, count) = (found.record.index, found.record.count);
    let reason = match found.provenance().difference(&wanted) {
        Some(how) => format!("it holds {how} than asked for"),
        None if (index, count) != (shard.index(), shard.count()) => {
            format!("it holds shard {index}/{count}, not {shard}")
        }
        None => return Ok(true),
    };
    Err(Error::from(SceneError::ShardMismatch(format!(
        "{reason}; --force replaces it"
    )))
    .in_file(path))
}

/// The transport of `scene`'s vertices, all of them or `shard`'s, with the report; and of
/// all of them in the vertex order with `options.bounces`, the bounced sum too, each ray cast
/// once for both ([`bounce::direct_and_bounced`]).
fn transport(
    scene: &Scene,
    options: &PrecomputeOptions,
    shard: Option<Shard>,
) -> Result<(TransportSet, Option<BouncedTransport>, PrecomputeReport)> {
    options.check()?;
    if shard.is_some() {
        // Refuses the direction order, so that below a shard is in the vertex order.
        options.check_shard(true)?;
    }
    let mesh = &scene.mesh;
    (options.budget(shard)).check("the scene", mesh.vertex_count() as u128)?;
    let without_bounces = |(set, report)| (set, None, report);
    match (options.order, shard) {
        (Order::Vertex, None) if options.bounces > 0 => {
            let bvh = SceneBvh::with_tracer(mesh, options.ray_tracer);
            let (set, bounced, report) = bounce::direct_and_bounced(
                mesh,
                &bvh,
                &options.visibility,
                scene.albedo.view(),
                options.bounces,
            )?;
            Ok((set, Some(bounced), report))
        }
        (Order::Vertex, shard) => vertex_range(
            mesh,
            &SceneBvh::with_tracer(mesh, options.ray_tracer),
            &options.visibility,
            shard.unwrap_or(Shard::whole()).range(mesh.vertex_count()),
        )
        .map(without_bounces),
        (Order::Direction, _) => {
            direction_major(mesh, &options.visibility, options.map_size).map(without_bounces)
        }
    }
}
