//! The scene cache (`.hsr`): a precomputed scene, so that rendering never repeats the
//! precomputation.
//!
//! **Layout** (little endian):
//!
//! | bytes | content |
//! |---|---|
//! | 8 | magic `HSRCACHE` |
//! | 4 | format version ([`CACHE_VERSION`]) |
//! | 4 | CRC-32 of everything after this field |
//! | 8 | length `H` of the header |
//! | `H` | header, JSON: [`CacheHeader`] (the parameters, the counts, the scene hash, the scene file's environment and camera) |
//! | | positions `V x 3` f64, normals `V x 3` f64, triangles `T x 3` u32, albedo `V x 3` f32 |
//! | | transport: offsets `V + 1` u64, indices `N` u32, values `N` f32 ([`TransportSet`]) |
//! | | with `sh_bands = B` in the parameters: the spherical-harmonic transfer `V x B^2` f32 ([`ShTransfer`]) |
//!
//! Version 2 added the spherical-harmonic transfer and `sh_bands`, and the scene file's
//! environment and camera in the header; a version-1 file is refused like any other version.
//!
//! **Checks on reading**, in this order, each a [`SceneError`]: the magic (else "not a scene
//! cache"), the version (another version is refused, never guessed at), the checksum (a
//! flipped byte or a truncated file), the header and the sizes it announces, and, with
//! [`SceneCache::read_for`], the scene: the mesh must hash to the same [`scene_hash`].
//! Files are written atomically ([`crate::io::write_file_atomically`]).

use std::path::Path;

use ndarray::Array2;
use serde::{Deserialize, Serialize};

use crate::faces::{ParamKind, Parameterization};
use crate::product::Selection;
use crate::relight::harmonics::ShTransfer;
use crate::relight::precompute::transport::TransportSet;
use crate::relight::scene::framed::{Format, put_all};
use crate::relight::scene::{CameraSpec, EnvironmentSpec};
use crate::relight::{Mesh, SceneError};
use crate::{Error, Result};

/// The format version this build reads and writes.
pub const CACHE_VERSION: u32 = 2;

const FORMAT: Format = Format {
    magic: b"HSRCACHE",
    version: CACHE_VERSION,
    name: "scene cache",
    corrupt: SceneError::CacheCorrupt,
    other_version: |found, expected| SceneError::CacheVersion { found, expected },
};

/// [`Selection`] as recorded in a cache header.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case", deny_unknown_fields)]
pub enum KeepRecord {
    /// [`Selection::All`].
    All,
    /// [`Selection::Largest`].
    Largest(usize),
    /// [`Selection::LargestPerFace`].
    LargestPerFace(usize),
    /// [`Selection::Threshold`].
    Threshold(f64),
}

impl From<Selection> for KeepRecord {
    fn from(s: Selection) -> Self {
        match s {
            Selection::All => KeepRecord::All,
            Selection::Largest(k) => KeepRecord::Largest(k),
            Selection::LargestPerFace(k) => KeepRecord::LargestPerFace(k),
            Selection::Threshold(t) => KeepRecord::Threshold(t),
        }
    }
}

impl From<KeepRecord> for Selection {
    fn from(k: KeepRecord) -> Self {
        match k {
            KeepRecord::All => Selection::All,
            KeepRecord::Largest(k) => Selection::Largest(k),
            KeepRecord::LargestPerFace(k) => Selection::LargestPerFace(k),
            KeepRecord::Threshold(t) => Selection::Threshold(t),
        }
    }
}

/// The parameters a cache was made with (recorded, and compared by callers that care).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CacheParams {
    /// `latlong` or `cube`.
    pub param: String,
    /// Face side `S` (lat-long: the map height).
    pub resolution: usize,
    /// The truncation of each vertex's transport.
    pub keep: KeepRecord,
    /// `S x S` rays per texel.
    pub samples: usize,
    /// Seed of the stratified jitter.
    pub seed: u64,
    /// `vertex` (rays) or `direction` (shadow maps).
    pub order: String,
    /// Shadow-map side, for the direction order.
    pub map_size: Option<usize>,
    /// Whether the ground plane was added.
    pub ground_plane: bool,
    /// Bands of the spherical-harmonic transfer stored beside the Haar transport, if any.
    pub sh_bands: Option<usize>,
}

/// The JSON header of a cache file.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CacheHeader {
    /// How the transport was made.
    pub params: CacheParams,
    /// Vertices.
    pub vertices: usize,
    /// Triangles.
    pub triangles: usize,
    /// Stored transport coefficients, all vertices.
    pub coefficients: usize,
    /// [`scene_hash`] of the mesh.
    pub scene_hash: u32,
    /// The scene file's lighting (path resolved when the scene was read), if it had one.
    pub environment: Option<EnvironmentSpec>,
    /// The scene file's camera, if it had one.
    pub camera: Option<CameraSpec>,
}

/// A precomputed scene: the mesh, its albedo and every vertex's sparse transport.
///
/// ```
/// use haarshift::relight::{CacheParams, KeepRecord, Scene, SceneBvh, SceneCache,
///                          VisibilityOptions, Generator, vertex_major};
/// use haarshift::faces::{ParamKind, Parameterization};
/// let scene = Scene::from_mesh(Generator::Sphere { cells: 2 }.mesh().unwrap(), false).unwrap();
/// let options = VisibilityOptions::new(Parameterization::new(ParamKind::LatLong, 4).unwrap());
/// let (transport, _) = vertex_major(&scene.mesh, &SceneBvh::new(&scene.mesh), &options).unwrap();
/// let params = CacheParams { param: "latlong".into(), resolution: 4, keep: KeepRecord::All,
///     samples: 1, seed: 0, order: "vertex".into(), map_size: None, ground_plane: false,
///     sh_bands: None };
/// let cache = SceneCache::new(params, scene.mesh, scene.albedo, transport).unwrap();
/// let dir = tempfile::tempdir().unwrap();
/// let path = dir.path().join("sphere.hsr");
/// let bytes = cache.write(&path, false).unwrap();
/// assert_eq!(std::fs::metadata(&path).unwrap().len(), bytes);
/// assert_eq!(SceneCache::read_for(&path, &cache.mesh).unwrap(), cache);
/// ```
#[derive(Clone, Debug, PartialEq)]
pub struct SceneCache {
    /// How the transport was made.
    pub params: CacheParams,
    /// The scene's mesh.
    pub mesh: Mesh,
    /// RGB albedo per vertex, `(V, 3)`.
    pub albedo: Array2<f32>,
    /// Every vertex's transport.
    pub transport: TransportSet,
    /// The scene file's lighting, used when a render names none ([`SceneCache::new`] leaves
    /// it `None`).
    pub environment: Option<EnvironmentSpec>,
    /// The scene file's camera, likewise.
    pub camera: Option<CameraSpec>,
}

/// A CRC-32 of the mesh's positions, normals and triangles: what "the same scene" means.
pub fn scene_hash(mesh: &Mesh) -> u32 {
    let mut h = crc32fast::Hasher::new();
    mesh.positions()
        .iter()
        .for_each(|x| h.update(&x.to_le_bytes()));
    mesh.normals()
        .iter()
        .for_each(|x| h.update(&x.to_le_bytes()));
    mesh.triangles()
        .iter()
        .flatten()
        .for_each(|x| h.update(&x.to_le_bytes()));
    h.finalize()
}

impl SceneCache {
    /// Bundles the parts, checking that they describe the same vertices and that `params`
    /// names the transport's parameterisation and spherical-harmonic bands.
    pub fn new(
        params: CacheParams,
        mesh: Mesh,
        albedo: Array2<f32>,
        transport: TransportSet,
    ) -> Result<Self> {
        let v = mesh.vertex_count();
        if albedo.dim() != (v, 3) || transport.vertex_count() != v {
            return Err(Error::shape(
                albedo.shape(),
                format!(
                    "albedo must be ({v}, 3) and the transport have {v} vertices (it has {})",
                    transport.vertex_count()
                ),
            ));
        }
        let p = transport.param();
        let bands = transport.sh().map(|t| t.bands());
        if params.param != p.kind().to_string()
            || params.resolution != p.face_size()
            || params.sh_bands != bands
        {
            return Err(Error::parameter(
                "cache parameters",
                format!(
                    "they say {} {} with {:?} sh bands but the transport is {} {} with {bands:?}",
                    params.param,
                    params.resolution,
                    params.sh_bands,
                    p.kind(),
                    p.face_size()
                ),
            ));
        }
        Ok(SceneCache {
            params,
            mesh,
            albedo,
            transport,
            environment: None,
            camera: None,
        })
    }

    /// Writes the cache to `path` atomically (an existing file only with `force`); returns
    /// the file's size in bytes.
    pub fn write(&self, path: &Path, force: bool) -> Result<u64> {
        let (offsets, indices, values) = self.transport.parts();
        let header = CacheHeader {
            params: self.params.clone(),
            vertices: self.mesh.vertex_count(),
            triangles: self.mesh.triangles().len(),
            coefficients: indices.len(),
            scene_hash: scene_hash(&self.mesh),
            environment: self.environment.clone(),
            camera: self.camera.clone(),
        };
        let sh = self.transport.sh().map_or(&[][..], |t| t.as_slice());
        let sizes = [
            self.mesh.positions().len() * 16,
            self.transport.stored_bytes(),
        ];
        FORMAT.write(path, force, &header, sizes.iter().sum(), |body| {
            put_all(
                body,
                self.mesh.positions().iter().chain(self.mesh.normals()),
            );
            put_all(body, self.mesh.triangles().iter().flatten());
            put_all(body, &self.albedo);
            put_all(body, offsets);
            put_all(body, indices);
            put_all(body, values.iter().chain(sh));
        })
    }

    /// The vertices of the scene's objects: all but the ground plane's, which stays
    /// Lambertian ([`Scene::object_vertices`](super::Scene::object_vertices) of the scene
    /// it was precomputed from).
    pub fn object_vertices(&self) -> usize {
        super::object_vertices(self.mesh.vertex_count(), self.params.ground_plane)
    }

    /// Reads a cache, refusing a damaged file or another version; see the [module docs](self).
    pub fn read(path: &Path) -> Result<Self> {
        let bytes = std::fs::read(path).map_err(|source| Error::Io {
            path: path.to_path_buf(),
            source,
        })?;
        Self::parse(&bytes).map_err(|e| e.in_file(path))
    }

    /// Reads a cache and refuses it unless it was made for `mesh` (same [`scene_hash`]).
    pub fn read_for(path: &Path, mesh: &Mesh) -> Result<Self> {
        let cache = Self::read(path)?;
        let (want, found) = (scene_hash(mesh), scene_hash(&cache.mesh));
        if want != found {
            return Err(Error::from(SceneError::CacheMismatch(format!(
                "its mesh has {} vertices and hash {found:08x}, this one {} vertices and hash {want:08x}",
                cache.mesh.vertex_count(),
                mesh.vertex_count()
            )))
            .in_file(path));
        }
        Ok(cache)
    }

    fn parse(bytes: &[u8]) -> Result<Self> {
        let (header, mut r) = FORMAT.open::<CacheHeader>(bytes)?;
        let (v, t, n) = (header.vertices, header.triangles, header.coefficients);
        let positions =
            Array2::from_shape_vec((v, 3), r.f64s(3 * v)?).map_err(|e| r.corrupt(e.to_string()))?;
        let normals =
            Array2::from_shape_vec((v, 3), r.f64s(3 * v)?).map_err(|e| r.corrupt(e.to_string()))?;
        let flat = r.u32s(3 * t)?;
        let triangles = flat.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect();
        let albedo =
            Array2::from_shape_vec((v, 3), r.f32s(3 * v)?).map_err(|e| r.corrupt(e.to_string()))?;
        let offsets = r.u64s(v + 1)?;
        let indices = r.u32s(n)?;
        let values = r.f32s(n)?;
        let sh = match header.params.sh_bands {
            Some(b) => {
                let per_vertex = b
                    .checked_mul(b)
                    .ok_or_else(|| r.corrupt("size overflows"))?;
                let flat = r.f32s(
                    v.checked_mul(per_vertex)
                        .ok_or_else(|| r.corrupt("size overflows"))?,
                )?;
                Some(ShTransfer::from_flat(b, flat)?)
            }
            None => None,
        };
        r.finish("transport")?;
        let mesh = Mesh::new(positions, triangles, Some(normals))?;
        let kind: ParamKind = header.params.param.parse()?;
        let param = Parameterization::new(kind, header.params.resolution)?;
        let transport = TransportSet::from_parts(
            param,
            header.params.keep.into(),
            offsets,
            indices,
            values,
            sh,
        )?;
        let mut cache = SceneCache::new(header.params, mesh, albedo, transport)?;
        cache.environment = header.environment;
        cache.camera = header.camera;
        Ok(cache)
    }
}

#[cfg(test)]
#[path = "cache_tests.rs"]
mod tests;
