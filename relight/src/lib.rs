//! # haarshift-relight
//!
//! All-frequency relighting on [`haarshift`]'s Haar transforms: a mesh's light transport
//! precomputed once per vertex as sparse Haar coefficients, then shaded under any environment
//! map, turned as it likes, with shadows, glossy BRDFs rotated in the Haar domain, bounced
//! light and moving objects.
//!
//! ## Start here
//!
//! **Precompute a mesh's transport**: visibility x cosine at every texel of a lat-long map
//! around each vertex, Haar-transformed and kept sparse ([`precompute`]):
//!
//! ```
//! use haarshift::faces::{ParamKind, Parameterization};
//! use haarshift_relight::precompute::{PrecomputeOptions, precompute};
//! use haarshift_relight::{Generator, Scene, VisibilityOptions};
//! let sphere = Generator::Sphere { cells: 2 }.mesh()?; // or Mesh::load("bunny.ply")
//! let scene = Scene::from_mesh(sphere, true)?; // on a ground plane
//! let param = Parameterization::new(ParamKind::LatLong, 8)?; // 8 x 16 directions
//! let (cache, report) = precompute(scene, &PrecomputeOptions::new(VisibilityOptions::new(param)))?;
//! assert_eq!(cache.transport.vertex_count(), cache.mesh.vertex_count());
//! # Ok::<(), haarshift_relight::Error>(())
//! ```
//!
//! **Shade it under a new lighting**: a [`Shader`](shade::Shader) built once from the cache,
//! then one sparse dot product a vertex for each frame ([`shade`](mod@shade)):
//!
//! ```
//! # use haarshift::faces::{ParamKind, Parameterization};
//! # use haarshift_relight::precompute::{PrecomputeOptions, precompute};
//! # use haarshift_relight::{Generator, Scene, VisibilityOptions};
//! # let scene = Scene::from_mesh(Generator::Sphere { cells: 2 }.mesh()?, true)?;
//! # let param = Parameterization::new(ParamKind::LatLong, 8)?;
//! # let (cache, _) = precompute(scene, &PrecomputeOptions::new(VisibilityOptions::new(param)))?;
//! use haarshift::sphere::{LatLongMap, SphereRotation};
//! use haarshift_relight::light::environment::Environment;
//! use haarshift_relight::shade::{FrameSpec, ShaderSpec, ShadingInput};
//! // A sky bright above the horizon (or Environment::load("sky.hdr")), turned 90 degrees.
//! let sky = Environment::new(LatLongMap::from_fn(16, 3, |d, rgb| rgb.fill(d[1].max(0.0)))?);
//! let mut shader = ShaderSpec::default().build(&ShadingInput::cache(&cache))?;
//! let rotation = SphereRotation::from_degrees(90.0, 0.0, 0.0)?;
//! let shading = shader.shade(&FrameSpec { environment: &sky, rotation, eye: None })?;
//! let radiance = shading.radiance.to_f32(); // (vertices, RGB), linear
//! assert_eq!(radiance.dim(), (cache.mesh.vertex_count(), 3));
//! # Ok::<(), haarshift_relight::Error>(())
//! ```
//!
//! Images of the result are [`render`]'s (`relight/examples/relight_mesh.rs` renders three
//! views); the command line's `haarshift relight` does all of this from files.
//!
//! ## Modules, in the order the data flows
//!
//! | module | idea |
//! |---|---|
//! | [`scene`] | meshes (OBJ+MTL, PLY, glTF 2.0) and the JSON scene file ([`Scene`]), the ground plane, generators; [`scene::cache`] ([`SceneCache`]: the versioned, checksummed `.hsr` file) |
//! | [`precompute`] | the whole precomputation of a scene into its cache, in either loop order: [`precompute::raycast`] ([`Occlusion`], [`SceneBvh`]), [`precompute::shadowmap`] ([`ShadowMap`]), [`precompute::visibility`] ([`vertex_major`], [`direction_major`]), [`precompute::transport_set`] ([`TransportSet`]), bounces, refinement, shards |
//! | [`sh_transfer`] | [`ShTransfer`]: the PRT patent's spherical-harmonic transfer |
//! | [`light`] | [`light::environment`]: the lighting loaded, downsampled, rotated; [`light::lighting`] ([`Lighting`]): its kept Haar coefficients |
//! | [`material`] | [`material::brdf`] ([`Brdf`]), [`material::merl`] (measured BRDFs), [`material::orient`] (a BRDF into a vertex's frame) |
//! | [`shade`](mod@shade) | per-vertex outgoing radiance behind one [`Shader`](shade::Shader), built from a [`ShaderSpec`](shade::ShaderSpec): Lambertian Haar, glossy Haar, spherical harmonics ([`shade::sh`]), the reference ([`reference()`]), ambient occlusion, dynamic scenes |
//! | [`dynamic`] | [`DynamicScene`](dynamic::DynamicScene): moving objects shadowing each other (Sun 2006); occlusion fields, animations |
//! | [`render`] | the rasteriser, cameras, animations, baked glTF out |
//! | [`mapped`] | a cache's arrays read in place from the file |
//! | [`error`] | [`Error`] (wraps [`haarshift::Error`] as [`Error::Core`]) and [`SceneError`] |
//!
//! Conventions are the core's: world Y up, right-handed, directions as in
//! [`sphere::latlong`](haarshift::sphere::latlong), rotations `g(p) = f(R p)` with
//! `R = Rz(roll) Ry(yaw) Rx(pitch)`.
//! The transport is the one factor of a product integral that carries the texel solid angle
//! ([`haarshift::product::Transport`]).
#![warn(missing_docs)]

#[cfg(test)]
#[macro_use]
mod test_support;

pub mod dynamic;
pub mod error;
pub mod light;
pub mod mapped;
pub mod material;
pub mod precompute;
pub mod render;
pub mod scene;
pub mod sh_transfer;
pub mod shade;

pub use error::{Error, Result, SceneError};
pub use light::lighting::Lighting;
pub use material::brdf::Brdf;
pub use precompute::embree::EMBREE_LIBRARY_VAR;
pub use precompute::raycast::{Hit, Occlusion, RayTracer, SceneBvh};
pub use precompute::shadowmap::ShadowMap;
pub use precompute::transport_set::TransportSet;
pub use precompute::visibility::{
    PrecomputeReport, VisibilityOptions, direction_major, ray_offset, vertex_major, vertex_range,
};
pub use scene::cache::{
    CacheHeader, CacheParams, KeepRecord, RefineRecord, SceneCache, ShardRecord, scene_hash,
};
pub use scene::cache_shard::{CacheShard, merge_shards};
pub use scene::mesh::{Bounds, Mesh};
pub use scene::{
    CameraSpec, EnvironmentSpec, Generator, Material, Scene, SceneFile, SceneObject, Transform,
    add_ground_plane,
};
pub use sh_transfer::ShTransfer;
pub use shade::reference::{ReferenceOptions, ReferenceReport, ReferenceVisibility, reference};
pub use shade::sh::{PhongSh, non_zonal_material, shade_sh, shade_sh_glossy};
pub use shade::{PreparedTransport, ShadeOptions, shade_lambertian};

/// The [`SceneError`] of a refusal that names the file `path`; panics on anything else.
#[cfg(test)]
pub(crate) fn refusal_in<T: std::fmt::Debug>(
    result: crate::Result<T>,
    path: &std::path::Path,
) -> SceneError {
    match result {
        Err(crate::Error::Scene {
            path: Some(p),
            source,
        }) if p == path => source,
        other => panic!(
            "expected a scene error naming {}, got {other:?}",
            path.display()
        ),
    }
}
