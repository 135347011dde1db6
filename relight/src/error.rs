//! The relighting's errors: [`Error`], which wraps the core crate's [`haarshift::Error`] beside
//! what only a scene can get wrong, and [`SceneError`], what can be wrong with a mesh, a scene
//! file, a cache or an occlusion field file.
//!
//! [`SceneError`] names the problem; [`Error::Scene`] adds the file it was found in (when there
//! is one), so the CLI prints one line such as
//! `bunny.ply: triangle 12 refers to vertex 2000 but there are 1839 vertices`.

use std::path::{Path, PathBuf};

/// Everything that can go wrong in the relighting: an error of the core crate (a bad parameter,
/// shape or file), a scene that is not usable, or a measured BRDF file that is not.
///
/// Every variant names what was wrong in words a command-line user can act on; the CLI prints
/// the `Display` form on one line.
///
/// ```
/// use haarshift_relight::{Error, SceneError};
/// let e = Error::parameter("levels", "must be at most 9");
/// assert_eq!(e.to_string(), "invalid levels: must be at most 9");
/// assert!(matches!(e, Error::Core(haarshift::Error::InvalidParameter { name: "levels", .. })));
/// let e = Error::from(SceneError::NoFaces).in_file("a.ply".as_ref());
/// assert_eq!(e.to_string(), "a.ply: the mesh has no triangles");
/// ```
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum Error {
    /// An error of the core crate, displayed as it is.
    #[error(transparent)]
    Core(#[from] haarshift::Error),
    /// A scene (mesh, scene file or scene cache) is not usable; `path` names its file when
    /// there is one.
    #[error("{}{source}", file_prefix(path.as_deref()))]
    Scene {
        /// The file the problem was found in, if any.
        path: Option<PathBuf>,
        /// What is wrong.
        #[source]
        source: SceneError,
    },
    /// A measured-BRDF (MERL) file is not usable.
    #[error("{}: {source}", path.display())]
    Merl {
        /// The file.
        path: PathBuf,
        /// What is wrong with it.
        #[source]
        source: crate::material::merl::MerlError,
    },
}

/// `"path: "` when there is a path, else nothing.
fn file_prefix(path: Option<&Path>) -> String {
    path.map(|p| format!("{}: ", p.display()))
        .unwrap_or_default()
}

impl From<SceneError> for Error {
    fn from(source: SceneError) -> Self {
        Error::Scene { path: None, source }
    }
}

/// `Result` with [`Error`].
pub type Result<T, E = Error> = std::result::Result<T, E>;

impl Error {
    /// This error as one about the file `path`: a scene error that names no file gets `path`,
    /// a core error becomes one about `path` as [`haarshift::Error::in_file`] says, and an
    /// error that names a file already is returned unchanged.
    pub fn in_file(self, path: &Path) -> Self {
        match self {
            Error::Scene { path: None, source } => Error::Scene {
                path: Some(path.to_path_buf()),
                source,
            },
            Error::Core(e) => Error::Core(e.in_file(path)),
            Error::Scene { .. } | Error::Merl { .. } => self,
        }
    }

    /// Shorthand for the core's [`haarshift::Error::InvalidParameter`].
    pub fn parameter(name: &'static str, reason: impl Into<String>) -> Self {
        haarshift::Error::parameter(name, reason).into()
    }

    /// Shorthand for the core's [`haarshift::Error::Io`]: `source` met reading or writing
    /// `path`.
    pub fn io(path: impl Into<PathBuf>, source: std::io::Error) -> Self {
        haarshift::Error::Io {
            path: path.into(),
            source,
        }
        .into()
    }

    /// Shorthand for the core's [`haarshift::Error::InvalidShape`].
    pub fn shape(shape: &[usize], reason: impl Into<String>) -> Self {
        haarshift::Error::shape(shape, reason).into()
    }

    /// The core error this is, if it is one.
    pub fn as_core(&self) -> Option<&haarshift::Error> {
        match self {
            Error::Core(e) => Some(e),
            _ => None,
        }
    }
}

/// A problem with a scene's content: a mesh, a scene file, a scene cache or an occlusion field
/// file.
///
/// ```
/// use haarshift_relight::SceneError;
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
    /// [`MAX_COORDINATE`](crate::scene::validate::MAX_COORDINATE) (what the BVH's f32 boxes can hold).
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
    /// use haarshift_relight::SceneError;
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
    CacheIsShard(crate::ShardRecord),
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
