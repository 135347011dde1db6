//! What can be wrong with a scene: its mesh, its scene file, its cache or an occlusion field
//! file.
//!
//! [`SceneError`] names the problem; [`crate::Error::Scene`] adds the file it was found in (when
//! there is one), so the CLI prints one line such as
//! `bunny.ply: triangle 12 refers to vertex 2000 but there are 1839 vertices`.

/// A problem with a scene's content: a mesh, a scene file, a scene cache or an occlusion field
/// file.
///
/// ```
/// use haarshift::relight::SceneError;
/// let e = SceneError::NoFaces;
/// assert_eq!(e.to_string(), "the mesh has no triangles");
/// ```
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum SceneError {
    /// The mesh has no triangles (a point cloud, or faces that all failed to parse).
    #[error("the mesh has no triangles")]
    NoFaces,
    /// A triangle names a vertex the mesh does not have.
    #[error("triangle {triangle} refers to vertex {index} but there are {vertices} vertices")]
    IndexOutOfRange {
        /// The triangle, 0-based.
        triangle: usize,
        /// The vertex index it names, 0-based.
        index: u64,
        /// Vertices in the mesh.
        vertices: usize,
    },
    /// A vertex position or normal is NaN or infinite.
    #[error("vertex {vertex} has a non-finite {what} ({value})")]
    NonFinite {
        /// The vertex, 0-based.
        vertex: usize,
        /// `position` or `normal`.
        what: &'static str,
        /// The offending component.
        value: f64,
    },
    /// A stored vertex normal (a scene cache's) is neither unit nor zero, which no mesh's is.
    #[error("vertex {vertex} has a normal of length {length}, neither 1 nor 0")]
    NotUnitNormal {
        /// The vertex, 0-based.
        vertex: usize,
        /// The normal's length.
        length: f64,
    },
    /// A coordinate is not finite or farther from the origin than
    /// [`MAX_COORDINATE`](super::validate::MAX_COORDINATE) (what the BVH's f32 boxes can hold).
    #[error(
        "{what} has a coordinate {value:e}: coordinates must be finite and within 1e15 of the origin"
    )]
    OutOfRange {
        /// The vertex, camera or point with the coordinate.
        what: String,
        /// The coordinate.
        value: f64,
    },
    /// A ground plane was asked for under a mesh too narrow for one.
    #[error(
        "a ground plane needs a mesh with a width or depth (here {extent:e}) of at least 1e-6 of its largest coordinate ({largest:e})"
    )]
    NoGroundExtent {
        /// The larger of the mesh's width (x) and depth (z).
        extent: f64,
        /// Its largest coordinate in magnitude.
        largest: f64,
    },
    /// The file cannot be parsed: truncated, corrupt, or a layout that is not a triangle mesh.
    #[error("not a readable mesh: {0}")]
    Corrupt(String),
    /// A part of a mesh asset (a glTF node, mesh, accessor, buffer or image; an OBJ's
    /// material library or texture) cannot be read, or names a file outside the asset's folder.
    ///
    /// ```
    /// use haarshift::relight::SceneError;
    /// let e = SceneError::Asset { part: "buffer 0".into(), reason: "no such file".into() };
    /// assert_eq!(e.to_string(), "buffer 0: no such file");
    /// ```
    #[error("{part}: {reason}")]
    Asset {
        /// The part, e.g. `mesh 2, primitive 0, POSITION (accessor 5)`.
        part: String,
        /// What is wrong with it.
        reason: String,
    },
    /// The scene file is not valid (bad JSON, unknown key, bad value).
    #[error("invalid scene file: {0}")]
    SceneFile(String),
    /// The cache file is damaged: its checksum does not match, or it is cut short.
    #[error("scene cache is damaged ({0}); compute it again")]
    CacheCorrupt(String),
    /// The cache file was written by another version of the format.
    #[error(
        "scene cache has format version {found}, this build reads version {expected}; compute it again"
    )]
    CacheVersion {
        /// The version in the file.
        found: u32,
        /// The version this build reads and writes.
        expected: u32,
    },
    /// The cache file was made for another scene or with other parameters.
    #[error("scene cache was made for another scene ({0}); compute it again")]
    CacheMismatch(String),
    /// A shard (`relight precompute --shard`) was given where a whole scene cache is needed.
    #[error(
        "is shard {}/{} of a scene cache (vertices {}..{}), not a whole cache: merge the shards with `haarshift relight merge`",
        .0.index, .0.count, .0.first, .0.end
    )]
    CacheIsShard(crate::relight::ShardRecord),
    /// A whole scene cache was given where a shard is needed.
    #[error("is a whole scene cache, not a shard")]
    NotAShard,
    /// A shard belongs to another scene or was made with other options than the others.
    #[error("not a shard of the same scene and options: {0}")]
    ShardMismatch(String),
    /// Shards leave vertices out or hold some twice.
    #[error("the shards do not cover every vertex exactly once: {0}")]
    ShardCoverage(String),
    /// The occlusion field file is damaged: its checksum does not match, it is cut short, or
    /// what it holds is not a field.
    #[error("occlusion field file is damaged ({0}); build it again")]
    FieldCorrupt(String),
    /// The occlusion field file was written by another version of the format.
    #[error(
        "occlusion field file has format version {found}, this build reads version {expected}; build it again"
    )]
    FieldVersion {
        /// The version in the file.
        found: u32,
        /// The version this build reads and writes.
        expected: u32,
    },
    /// The occlusion field file was built for another mesh or with other field options.
    #[error("occlusion field file was built {0}; build it again")]
    FieldMismatch(String),
}
