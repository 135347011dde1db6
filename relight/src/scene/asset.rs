//! A mesh file as a scene takes it: the geometry, the colour the file carries (if any) and
//! what the reader had to approximate.
//!
//! [`MeshAsset::load_within`] reads by the extension: `.ply` and `.obj` ([`super::mesh`],
//! with PLY vertex colours and OBJ + MTL materials), `.gltf` and `.glb` ([`super::gltf_file`]).
//! Its [`albedo`](MeshAsset::albedo) is `Some` only when the file carries colour (a PLY's
//! `red green blue`, an OBJ's materials, and always for glTF, whose material-less primitives
//! take the spec's default material); a scene gives a mesh without one its material's albedo
//! (0.8 by default), and multiplies a mesh's own by the material's.

use std::path::Path;

use ndarray::Array2;

use crate::Mesh;
use crate::Result;
use crate::scene::validate::MemoryBudget;

/// A mesh file read: its [`Mesh`], the linear RGB albedo per vertex when the file carries
/// colour, and the approximations made (one line each, e.g. a metallic glTF material shaded
/// as its base colour).
///
/// ```
/// use haarshift_relight::scene::MeshAsset;
/// let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../testdata/meshes/bunny.ply");
/// let bunny = MeshAsset::load(path.as_ref()).unwrap();
/// assert_eq!(bunny.mesh.vertex_count(), 1839);
/// assert!(bunny.albedo.is_none() && bunny.warnings.is_empty());
/// ```
#[derive(Clone, Debug, PartialEq)]
pub struct MeshAsset {
    /// The geometry.
    pub mesh: Mesh,
    /// Linear RGB albedo per vertex, `(V, 3)`, when the file gives colour.
    pub albedo: Option<Array2<f32>>,
    /// What was approximated, one line each.
    pub warnings: Vec<String>,
}

impl MeshAsset {
    /// A mesh that carries no colour.
    pub fn plain(mesh: Mesh) -> MeshAsset {
        MeshAsset {
            mesh,
            albedo: None,
            warnings: Vec::new(),
        }
    }

    /// [`load_within`](Self::load_within) the default [`MemoryBudget`].
    pub fn load(path: &Path) -> Result<MeshAsset> {
        Self::load_within(path, &MemoryBudget::default())
    }

    /// Reads an OBJ, PLY, glTF or GLB file, chosen by the extension; counts that size
    /// allocations (glTF accessors and instances, textures) are checked against `budget`
    /// first. Errors name the file.
    pub fn load_within(path: &Path, budget: &MemoryBudget) -> Result<MeshAsset> {
        let extension = path
            .extension()
            .and_then(|e| e.to_str())
            .map(str::to_ascii_lowercase);
        let asset = match extension.as_deref() {
            Some("obj") => super::obj::read_obj(path, budget),
            Some("ply") => super::mesh::read_ply(path),
            Some("gltf" | "glb") => super::gltf_file::read_gltf(path, budget),
            _ => Err(crate::Error::from(haarshift::Error::Format {
                path: path.to_path_buf(),
                reason: "a mesh must be an .obj, .ply, .gltf or .glb file".into(),
            })),
        };
        asset.map_err(|e| e.in_file(path))
    }
}
