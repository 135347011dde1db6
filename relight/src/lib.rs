//! All-frequency relighting, in the order the data flows: a scene is read and checked
//! ([`scene`]), its per-vertex transport precomputed ([`precompute`]), the lighting encoded
//! ([`light`]), a material brought into each vertex's frame ([`material`]), the outgoing
//! radiance computed behind one [`Shader`](shade::Shader) ([`shade`](mod@shade)), and
//! scenes whose objects move relit by just-in-time radiance transfer ([`dynamic`]). Images of
//! the result are [`crate::render`]'s.
//!
//! | module | idea |
//! |---|---|
//! | [`error`] | [`SceneError`]: what can be wrong with a mesh, a scene file or a cache |
//! | [`scene`] | the ground plane, procedural generators, the JSON scene file ([`Scene`]); [`scene::mesh`] ([`Mesh`]: OBJ and PLY in, vertex normals); [`scene::cache`] ([`SceneCache`]: the versioned, checksummed `.hsr` file) |
//! | [`precompute`] | the whole precomputation of a scene into its cache, in either loop order: [`precompute::raycast`] ([`Occlusion`], answered by [`SceneBvh`]), [`precompute::shadowmap`] ([`ShadowMap`], the PRT patent's depth buffer), [`precompute::visibility`] ([`vertex_major`], [`direction_major`]), [`precompute::transport_set`] ([`TransportSet`]), [`precompute::sparse`] (many sparse Haar functions in flat arrays) |
//! | [`light`] | [`light::environment`]: the lighting loaded, downsampled by solid-angle-weighted means, rotated; [`light::lighting`] ([`Lighting`]): its kept Haar coefficients, RGB, in Mallat order |
//! | [`material`] | [`material::brdf`] ([`Brdf`]: Lambert, Phong, Blinn-Phong, local copies), [`material::merl`] (measured BRDFs), [`material::orient`] (a BRDF into a vertex's frame: Haar, spatial, reference or direct) |
//! | [`shade`](mod@shade) | per-vertex outgoing radiance behind one [`Shader`](shade::Shader), built from a [`ShaderSpec`](shade::ShaderSpec): Lambertian Haar ([`PreparedTransport`]), glossy Haar with the rotation cache ([`shade::glossy`]), spherical harmonics ([`shade_sh`], [`PhongSh`]), the ground truth by direct quadrature ([`reference()`]), ambient occlusion, dynamic scenes |
//! | [`harmonics`] | [`ShTransfer`]: the PRT patent's spherical-harmonic transfer |
//! | [`dynamic`] | [`DynamicScene`](dynamic::DynamicScene): moving objects shadowing each other (Sun 2006); [`dynamic::fields`] (occlusion fields, the `.hsf` file), [`dynamic::motion`] (animations played with re-formed transfer) |
//! | [`gallery`] | the committed diffuse renders: Haar, SH and the reference under several maps |
//!
//! Conventions are the sphere module's: world Y up, right-handed, directions as in
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
