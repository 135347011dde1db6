//! All-frequency relighting: meshes and scenes, ray casting, per-vertex visibility and
//! transport precomputation, the scene cache, the lighting, and images of the result.
//!
//! | file | idea |
//! |---|---|
//! | [`error`] | [`SceneError`]: what can be wrong with a mesh, a scene file or a cache |
//! | [`mesh`] | [`Mesh`]: OBJ and PLY in, vertex normals |
//! | [`scene`] | the ground plane, procedural generators, the JSON scene file ([`Scene`]) |
//! | [`raycast`] | [`Occlusion`], the any-hit query, answered by [`SceneBvh`] |
//! | [`shadowmap`] | [`ShadowMap`], seed 003's orthographic depth buffer along one direction |
//! | [`visibility`] | the precomputation in two loop orders: [`vertex_major`], [`direction_major`] |
//! | [`sparse`] | [`SparseRows`](sparse::SparseRows): many sparse Haar functions in flat arrays |
//! | [`transport`] | [`TransportSet`]: every vertex's sparse Haar transport |
//! | [`harmonics`] | [`ShTransfer`]: seed 003's spherical-harmonic transfer |
//! | [`fields`] | [`OcclusionField`](fields::OcclusionField): an object's occlusion seen from sample points around it (seed 001); on disk, the `.hsf` file ([`fields::file`]) |
//! | [`dynamic`] | [`DynamicScene`](dynamic::DynamicScene): moving objects shadowing each other; [`Jrt`](dynamic::Jrt), just-in-time radiance transfer |
//! | [`motion`] | [`MotionPath`](motion::MotionPath): animations of dynamic scenes, played with re-formed transfer |
//! | [`cache`] | [`SceneCache`]: the versioned, checksummed `.hsr` file (its framing, `framed`, is shared with the `.hsf` field file) |
//! | [`environment`] | the lighting: loaded, downsampled by solid-angle-weighted means, rotated |
//! | [`lighting`] | [`Lighting`]: the environment's kept Haar coefficients, RGB, in Mallat order |
//! | [`brdf`] | [`Brdf`]: Lambert, Phong, Blinn-Phong; local copies of a BRDF |
//! | [`shade`](mod@shade) | per-vertex outgoing radiance behind one [`Shader`](shade::Shader), built from a [`ShaderSpec`](shade::ShaderSpec): Lambertian Haar ([`PreparedTransport`]), glossy Haar with the rotation cache, spherical harmonics ([`shade_sh`], [`PhongSh`]), the ground truth by direct quadrature ([`reference()`]), ambient occlusion, dynamic scenes |
//! | [`orient`] | bringing a BRDF into a vertex's frame: Haar, spatial, reference or direct |
//! | [`raster`] | the software rasteriser: camera, z-buffer, perspective-correct interpolation, sRGB |
//! | [`view`] | [`ViewSpec`](view::ViewSpec): the camera resolved (asked for, the scene file's, the framing) and the frame drawn |
//! | [`animation`] | frames into an animated GIF |
//! | [`precompute`] | the whole precomputation of a scene into its cache, in either loop order |
//! | [`memory`] | the process's peak resident memory, for reports |
//! | [`gallery`] | the committed diffuse renders: Haar, SH and the reference under several maps |
//!
//! Conventions are the sphere module's: world Y up, right-handed, directions as in
//! [`sphere::latlong`](crate::sphere::latlong), rotations `g(p) = f(R p)` with
//! `R = Rz(roll) Ry(yaw) Rx(pitch)`.
//! The transport is the one factor of a product integral that carries the texel solid angle
//! ([`crate::product::Transport`]).
pub mod animation;
pub mod brdf;
pub mod cache;
pub mod dynamic;
pub mod environment;
pub mod error;
pub mod fields;
mod framed;
pub mod gallery;
/// Moved to [`shade::glossy`].
#[deprecated(note = "moved to haarshift::relight::shade::glossy")]
pub mod glossy {
    pub use super::shade::glossy::*;
}
pub mod harmonics;
pub mod lighting;
pub mod memory;
pub mod mesh;
pub mod motion;
pub mod orient;
pub mod precompute;
pub mod raster;
pub mod raycast;
/// Moved to [`shade::reference`]; this path stays for one release (not marked deprecated:
/// importing the function [`reference()`] by its name imports this module too).
pub mod reference {
    pub use super::shade::reference::*;
}
pub mod scene;
pub mod shade;
pub mod shadowmap;
pub mod sparse;
pub mod transport;
pub mod view;
pub mod visibility;

pub use brdf::Brdf;
pub use cache::{CacheHeader, CacheParams, KeepRecord, SceneCache, scene_hash};
pub use error::SceneError;
pub use harmonics::ShTransfer;
pub use lighting::Lighting;
pub use mesh::{Bounds, Mesh};
pub use raycast::{Occlusion, SceneBvh};
pub use scene::{
    CameraSpec, EnvironmentSpec, Generator, Material, Scene, SceneFile, SceneObject, Transform,
    add_ground_plane,
};
pub use shade::harmonics::{PhongSh, non_zonal_material, shade_sh, shade_sh_glossy};
pub use shade::reference::{ReferenceOptions, ReferenceReport, ReferenceVisibility, reference};
pub use shade::{PreparedTransport, ShadeOptions, shade};
pub use shadowmap::ShadowMap;
pub use transport::TransportSet;
pub use visibility::{
    PrecomputeReport, VisibilityOptions, direction_major, ray_offset, vertex_major,
};

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
