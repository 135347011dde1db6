//! All-frequency relighting: meshes and scenes, ray casting, per-vertex visibility and
//! transport precomputation, and the scene cache.
//!
//! | file | idea |
//! |---|---|
//! | [`error`] | [`SceneError`]: what can be wrong with a mesh, a scene file or a cache |
//! | [`mesh`] | [`Mesh`]: OBJ and PLY in, vertex normals |
//!
//! Conventions are the sphere module's: world Y up, right-handed, directions as in
//! [`sphere::latlong`](crate::sphere::latlong).
pub mod error;
pub mod mesh;

pub use error::SceneError;
pub use mesh::{Bounds, Mesh};
