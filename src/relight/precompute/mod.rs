//! The whole precomputation of a scene, as `haarshift relight precompute` runs it: the
//! visibility in the chosen loop order ([`vertex_major`] through a [`SceneBvh`], or
//! [`direction_major`] with shadow buffers), the transport of every vertex, and the
//! [`SceneCache`] that records how it was made.
//!
//! **Limits.** A precomputation holds one `(faces, S, S)` array of f32 per thread and, in the
//! direction order, one bit per (vertex, direction); a transport of more than [`MAX_TEXELS`]
//! texels (lat-long `2048 x 4096`, cube `6 x 1024^2` are inside) is refused before any work,
//! so an absurd `--resolution` is a clear error rather than an exhausted machine. A scene
//! whose vertices would not fit in [`PrecomputeOptions::budget`] is refused from its count,
//! before the BVH or any transport is built.

pub mod raycast;
pub mod shadowmap;
pub mod sparse;
pub mod transport;
pub mod visibility;

use crate::named::named_enum;
use crate::product::Selection;
use crate::relight::precompute::visibility::{
    PrecomputeReport, VisibilityOptions, direction_major, vertex_major,
};
use crate::relight::scene::validate::{DEFAULT_MEMORY_LIMIT, MemoryBudget};
use crate::relight::{CacheParams, Scene, SceneBvh, SceneCache};
use crate::{Error, Result};

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
/// use haarshift::relight::precompute::{Order, PrecomputeOptions};
/// use haarshift::relight::VisibilityOptions;
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
        }
    }

    /// The [`MemoryBudget`] of this precomputation: per vertex, beyond the mesh, the most
    /// coefficients its selection can keep (every texel's unless it keeps a count), 8 bytes
    /// each (`u32` index, `f32` value) held twice (the vertices' rows, then the gathered set
    /// and the file's bytes), its row's 80 bytes of bookkeeping, the spherical-harmonic
    /// transfer, and in the direction order one bit per texel. The direction order's shadow
    /// buffers (one per thread, `4 M^2` bytes) are not per vertex and not counted.
    ///
    /// ```
    /// use haarshift::relight::precompute::PrecomputeOptions;
    /// use haarshift::relight::VisibilityOptions;
    /// use haarshift::faces::{ParamKind, Parameterization};
    /// use haarshift::product::Selection;
    /// let mut o = PrecomputeOptions::new(VisibilityOptions::new(Parameterization::new(ParamKind::LatLong, 8).unwrap()));
    /// assert_eq!(o.budget().per_vertex, 2 * 8 * 128 + 80); // every one of 8 x 16 texels
    /// o.visibility.keep = Selection::Largest(30);
    /// assert_eq!(o.budget().per_vertex, 2 * 8 * 32 + 80); // 30 details and 2 face scalings
    /// ```
    pub fn budget(&self) -> MemoryBudget {
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
        MemoryBudget {
            limit: self.memory_limit,
            per_vertex: kept
                .saturating_mul(2 * 8)
                .saturating_add(80)
                .saturating_add(sh.saturating_mul(2))
                .saturating_add(bits),
        }
    }

    /// What the cache records of these options.
    fn record(&self, ground_plane: bool) -> CacheParams {
        let v = &self.visibility;
        CacheParams {
            param: v.param.kind().to_string(),
            resolution: v.param.face_size(),
            keep: v.keep.into(),
            samples: v.samples,
            seed: v.seed,
            order: self.order.to_string(),
            map_size: (self.order == Order::Direction).then_some(self.map_size),
            ground_plane,
            sh_bands: v.sh_bands,
        }
    }
}

/// Precomputes `scene` into a [`SceneCache`] (recording the options, whether the scene has
/// the ground plane, and the scene file's environment and camera), with what the
/// precomputation did.
///
/// ```
/// use haarshift::relight::precompute::{PrecomputeOptions, precompute};
/// use haarshift::relight::{Generator, Scene, VisibilityOptions};
/// use haarshift::faces::{ParamKind, Parameterization};
/// let scene = Scene::from_mesh(Generator::Sphere { cells: 2 }.mesh().unwrap(), true).unwrap();
/// let param = Parameterization::new(ParamKind::LatLong, 8).unwrap();
/// let (cache, report) = precompute(scene, &PrecomputeOptions::new(VisibilityOptions::new(param))).unwrap();
/// assert_eq!(cache.transport.vertex_count(), 54 + 1089);
/// assert!(cache.params.ground_plane && report.rays > 0);
/// let huge = Parameterization::new(ParamKind::LatLong, 4096).unwrap();
/// let scene = Scene::from_mesh(Generator::Sphere { cells: 2 }.mesh().unwrap(), false).unwrap();
/// assert!(precompute(scene, &PrecomputeOptions::new(VisibilityOptions::new(huge))).is_err());
/// ```
pub fn precompute(
    scene: Scene,
    options: &PrecomputeOptions,
) -> Result<(SceneCache, PrecomputeReport)> {
    let param = options.visibility.param;
    if param.texels() > MAX_TEXELS {
        return Err(Error::parameter(
            "resolution",
            format!(
                "{} {}: {} texels per vertex, more than the {MAX_TEXELS} a precomputation takes",
                param.kind(),
                param.face_size(),
                param.texels()
            ),
        ));
    }
    options
        .budget()
        .check("the scene", scene.mesh.vertex_count() as u128)?;
    let (transport, report) = match options.order {
        Order::Vertex => vertex_major(
            &scene.mesh,
            &SceneBvh::new(&scene.mesh),
            &options.visibility,
        )?,
        Order::Direction => direction_major(&scene.mesh, &options.visibility, options.map_size)?,
    };
    let mut cache = SceneCache::new(
        options.record(scene.ground_plane),
        scene.mesh,
        scene.albedo,
        transport,
    )?;
    cache.environment = scene.environment;
    cache.camera = scene.camera;
    Ok((cache, report))
}
