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
//! | | with `bounces > 0` in the parameters, for each of the [`CacheHeader::bounced_coefficients`] (one set when the albedo is grey, else R, G, B): the bounced sum's offsets, indices, values and transfer, as the transport's ([`BouncedTransport`]) |
//!
//! Each array starts at a file offset that is a multiple of 8, zero bytes filling the gap
//! before it, so that [`SceneCache::read`] can map the file and read the transport in place:
//! a render holds the mesh, albedo and transfer in memory and the transport only as the
//! file's pages, which the kernel reads when touched and may drop again. Resident anonymous
//! memory is then near the mesh's, whatever the transport's size (`results/scale/`).
//!
//! A **shard** (`CacheShard`, what `relight precompute --shard I/N` writes) is the same file
//! with [`CacheHeader::shard`] set: the whole mesh and albedo, and the transport (and transfer)
//! of its vertex range only, `V` above read as the range's length in the transport's rows.
//! [`SceneCache::read`] refuses a shard, and `CacheShard::read` a whole cache.
//!
//! Version 2 added the spherical-harmonic transfer and `sh_bands`, and the scene file's
//! environment and camera in the header; version 3 the shard record; version 4 the aligned
//! arrays; version 5 the ray tracer in the parameters; version 6 the ground plane's cells per
//! side in the parameters ([`CacheParams::ground_cells`]), its vertex count in the header
//! ([`CacheHeader::ground_vertices`], the trailing block the glossy shaders keep Lambertian),
//! and the bounced sum of interreflected light ([`CacheParams::bounces`],
//! [`CacheHeader::bounced_coefficients`] and their sections). Both bounce fields are left out
//! of the header when there are no bounces, so a cache of direct light alone is byte for byte
//! what it was before they existed, and such a file reads as having none.
//! A file of another version is refused, never guessed at.
//!
//! **Checks on reading**, in this order, each a [`SceneError`]: the magic (else "not a scene
//! cache"), the version (another version is refused, never guessed at), the checksum (a
//! flipped byte or a truncated file), the header and the sizes it announces, the mesh (as
//! [`Mesh::new`] checks it, its normals unit or zero and kept bit for bit, so that the mesh
//! read back hashes as the one written), and, with [`SceneCache::read_for`], the scene: the
//! mesh must hash to the same [`scene_hash`].
//! Files are written atomically ([`haarshift::io::write_file_atomically`]).

use std::path::Path;

use ndarray::Array2;
use serde::{Deserialize, Serialize};

use crate::mapped::Buffer;
use crate::mapped::MappedFile;
use crate::precompute::bounce::{BouncedTransport, is_grey};
use crate::precompute::transport_set::TransportSet;
use crate::scene::framed::{Format, Reader};
use crate::scene::{CameraSpec, EnvironmentSpec};
use crate::sh_transfer::ShTransfer;
use crate::{Error, Result};
use crate::{Mesh, SceneError};
use haarshift::faces::{ParamKind, Parameterization};
use haarshift::product::Selection;

/// The format version this build reads and writes.
pub const CACHE_VERSION: u32 = 6;

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
    /// The ground plane's cells per side, with one (`None` without).
    #[serde(default)]
    pub ground_cells: Option<usize>,
    /// Bands of the spherical-harmonic transfer stored beside the Haar transport, if any.
    pub sh_bands: Option<usize>,
    /// The [`RayTracer`](crate::RayTracer) that cast the visibility rays (`embree`
    /// or `packets`; `None` for the direction order's shadow buffers). Shards merge only when
    /// they agree on it: the two may answer a ray through an edge differently.
    pub ray_tracer: Option<String>,
    /// Bounces of interreflected light summed in [`SceneCache::bounced`] (`--bounces B`);
    /// 0, and then left out of the header, for direct light alone.
    #[serde(default, skip_serializing_if = "is_zero")]
    pub bounces: usize,
    /// How the mesh was refined (`relight precompute --refine`), if it was; absent from the
    /// header of a cache that was not.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub refine: Option<RefineRecord>,
}

fn is_zero(n: &usize) -> bool {
    *n == 0
}

/// What a cache records of `relight precompute --refine TOL --max-vertices N`
/// ([`precompute::refine`](crate::precompute::refine)): its mesh is the scene's
/// refined, and its ground plane's vertices ([`CacheHeader::ground_vertices`]) are the
/// grid's and the midpoints made on it.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RefineRecord {
    /// `TOL`: the largest relative L2 difference left between an edge's endpoints'
    /// transports (unless the budget stopped the refinement first).
    pub tolerance: f64,
    /// `N`: the most vertices the refined mesh could have.
    pub max_vertices: usize,
    /// The probe lighting the edges were judged under (`--refine-light ENV`: its file
    /// name), or `None` when they were judged by their transport.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub probe: Option<String>,
}

impl CacheParams {
    /// The ground plane's vertices in a cache made with these parameters:
    /// `(N + 1)^2` for [`ground_cells`](Self::ground_cells) `N`, 0 without a ground plane.
    ///
    /// ```
    /// use haarshift_relight::{CacheParams, KeepRecord};
    /// let mut p = CacheParams { param: "cube".into(), resolution: 4, keep: KeepRecord::All,
    ///     samples: 1, seed: 0, order: "vertex".into(), map_size: None, ground_plane: true,
    ///     ground_cells: Some(64), sh_bands: None, ray_tracer: None, bounces: 0, refine: None };
    /// assert_eq!(p.grid_ground_vertices(), 65 * 65);
    /// (p.ground_plane, p.ground_cells) = (false, None);
    /// assert_eq!(p.grid_ground_vertices(), 0);
    /// ```
    pub fn grid_ground_vertices(&self) -> usize {
        self.ground_cells.map_or(0, super::ground_vertices)
    }
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
    /// How many of the last vertices are the ground plane's (0 without one).
    #[serde(default)]
    pub ground_vertices: usize,
    /// Stored transport coefficients, all vertices.
    pub coefficients: usize,
    /// With bounces, the coefficients of each set of the bounced sum: one entry when every
    /// albedo is grey, else three (R, G, B); empty, and left out, without bounces.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub bounced_coefficients: Vec<usize>,
    /// [`scene_hash`] of the mesh.
    pub scene_hash: u32,
    /// The scene file's lighting (path resolved when the scene was read), if it had one.
    pub environment: Option<EnvironmentSpec>,
    /// The scene file's camera, if it had one.
    pub camera: Option<CameraSpec>,
    /// In a shard, which one and the vertices it holds; `None` in a whole cache.
    pub shard: Option<ShardRecord>,
}

/// What a shard's header records of its place in the whole: shard `index` of `count`, holding
/// the transport of the vertices `first..end`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ShardRecord {
    /// `I` of `--shard I/N`.
    pub index: usize,
    /// `N`.
    pub count: usize,
    /// The first vertex held.
    pub first: usize,
    /// One past the last vertex held.
    pub end: usize,
}

/// A precomputed scene: the mesh, its albedo and every vertex's sparse transport.
///
/// ```
/// use haarshift_relight::{CacheParams, KeepRecord, Scene, SceneBvh, SceneCache,
///                          VisibilityOptions, Generator, vertex_major};
/// use haarshift::faces::{ParamKind, Parameterization};
/// let scene = Scene::from_mesh(Generator::Sphere { cells: 2 }.mesh().unwrap(), false).unwrap();
/// let options = VisibilityOptions::new(Parameterization::new(ParamKind::LatLong, 4).unwrap());
/// let (transport, _) = vertex_major(&scene.mesh, &SceneBvh::new(&scene.mesh), &options).unwrap();
/// let params = CacheParams { param: "latlong".into(), resolution: 4, keep: KeepRecord::All,
///     samples: 1, seed: 0, order: "vertex".into(), map_size: None, ground_plane: false,
///     ground_cells: None, sh_bands: None, ray_tracer: Some("packets".into()), bounces: 0, refine: None };
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
    /// The bounced sum `T1 + ... + TB` of every vertex, when precomputed with bounces
    /// ([`set_bounced`](Self::set_bounced); [`SceneCache::new`] leaves it `None`).
    pub bounced: Option<BouncedTransport>,
    /// The scene file's lighting, used when a render names none ([`SceneCache::new`] leaves
    /// it `None`).
    pub environment: Option<EnvironmentSpec>,
    /// The scene file's camera, likewise.
    pub camera: Option<CameraSpec>,
    /// How many of the last vertices are the ground plane's:
    /// [`CacheParams::grid_ground_vertices`], set by [`SceneCache::new`]; in a refined cache
    /// ([`CacheParams::refine`]) the grid's and the midpoints on it.
    pub ground_vertices: usize,
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
        check_parts(&params, &mesh, &albedo, &transport, mesh.vertex_count())?;
        let ground_vertices = params.grid_ground_vertices();
        if ground_vertices > mesh.vertex_count() {
            return Err(Error::parameter(
                "ground cells",
                format!(
                    "a ground plane of {:?} cells per side has {ground_vertices} vertices, the mesh {}",
                    params.ground_cells,
                    mesh.vertex_count()
                ),
            ));
        }
        check_bounced(&params, &albedo, &transport, None)?;
        Ok(SceneCache {
            params,
            mesh,
            albedo,
            transport,
            bounced: None,
            environment: None,
            camera: None,
            ground_vertices,
        })
    }

    /// Stores the bounced sum of every vertex ([`bounce_range`](crate::precompute::bounce::bounce_range)
    /// over all of them, from this cache's transport) and records its bounces in the
    /// parameters, after checking that it has the transport's vertices, parameterisation,
    /// truncation and bands, and one set exactly when the albedo is grey.
    ///
    /// ```
    /// use haarshift_relight::precompute::{PrecomputeOptions, precompute};
    /// use haarshift_relight::precompute::bounce::bounce_range;
    /// use haarshift_relight::{Generator, Scene, SceneBvh, SceneCache, VisibilityOptions};
    /// use haarshift::faces::{ParamKind, Parameterization};
    /// let scene = Scene::from_mesh(Generator::OpenBox { cells: 1 }.mesh().unwrap(), false).unwrap();
    /// let options = VisibilityOptions::new(Parameterization::new(ParamKind::LatLong, 4).unwrap());
    /// let (mut cache, _) = precompute(scene, &PrecomputeOptions::new(options)).unwrap();
    /// let bvh = SceneBvh::new(&cache.mesh);
    /// let all = 0..cache.mesh.vertex_count();
    /// let (bounced, _) = bounce_range(&cache.mesh, &bvh, &options, cache.albedo.view(),
    ///                                 &cache.transport, None, 2, all).unwrap();
    /// cache.set_bounced(bounced).unwrap();
    /// assert_eq!(cache.params.bounces, 2);
    /// let dir = tempfile::tempdir().unwrap();
    /// cache.write(&dir.path().join("box.hsr"), false).unwrap();
    /// assert_eq!(SceneCache::read(&dir.path().join("box.hsr")).unwrap(), cache);
    /// ```
    pub fn set_bounced(&mut self, bounced: BouncedTransport) -> Result<()> {
        self.params = bounced_params(&self.params, &self.albedo, &self.transport, &bounced)?;
        self.bounced = Some(bounced);
        Ok(())
    }

    /// Writes the cache to `path` atomically (an existing file only with `force`); returns
    /// the file's size in bytes.
    pub fn write(&self, path: &Path, force: bool) -> Result<u64> {
        let sets = Sets {
            direct: &self.transport,
            bounced: self.bounced.as_ref(),
        };
        let header = header(
            &self.params,
            &self.mesh,
            sets,
            (&self.environment, &self.camera),
            (self.ground_vertices, None),
        );
        write_parts(path, force, &header, &self.mesh, &self.albedo, sets)
    }

    /// The vertices of the scene's objects: all but the ground plane's, which stays
    /// Lambertian ([`Scene::object_vertices`](super::Scene::object_vertices) of the scene
    /// it was precomputed from).
    pub fn object_vertices(&self) -> usize {
        super::object_vertices(self.mesh.vertex_count(), self.ground_vertices)
    }

    /// Reads a cache, refusing a damaged file, another version or a shard; see the
    /// [module docs](self). The file is memory-mapped and the transport read in place
    /// ([`TransportSet::is_mapped`]); everything else is copied.
    pub fn read(path: &Path) -> Result<Self> {
        read_parts(path)
            .and_then(Self::from_file_parts)
            .map_err(|e| e.in_file(path))
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

    fn from_file_parts((header, parts): (CacheHeader, Parts)) -> Result<Self> {
        if let Some(shard) = header.shard {
            return Err(SceneError::CacheIsShard(shard).into());
        }
        let mut params = header.params;
        params.bounces = 0; // set again with the bounced sum, checked against it
        let mut cache = SceneCache::new(params, parts.mesh, parts.albedo, parts.transport)?;
        // The reader holds a bounced sum exactly when the parameters give bounces.
        if let Some(bounced) = parts.bounced {
            cache.set_bounced(bounced)?;
        }
        // Refinement adds midpoints to the ground's grid, never takes its vertices away.
        let refined_ground = cache.ground_vertices..=cache.mesh.vertex_count();
        if cache.params.refine.is_some() && refined_ground.contains(&header.ground_vertices) {
            cache.ground_vertices = header.ground_vertices;
        }
        if header.ground_vertices != cache.ground_vertices {
            return Err(SceneError::CacheCorrupt(format!(
                "its header says {} ground vertices, its ground plane of {:?} cells per side has {}",
                header.ground_vertices, cache.params.ground_cells, cache.ground_vertices
            ))
            .into());
        }
        cache.environment = header.environment;
        cache.camera = header.camera;
        Ok(cache)
    }
}

/// The arrays of a cache file, whole or shard.
pub(super) struct Parts {
    /// The whole scene's mesh.
    pub mesh: Mesh,
    /// Its albedo, `(V, 3)`.
    pub albedo: Array2<f32>,
    /// The transport of the vertices the file holds.
    pub transport: TransportSet,
    /// Their bounced sum, when the file holds one.
    pub bounced: Option<BouncedTransport>,
}

/// The transport sets a cache file holds: the direct transport and, with bounces, the
/// bounced sum, of the same vertices.
#[derive(Clone, Copy)]
pub(super) struct Sets<'a> {
    /// The direct transport.
    pub direct: &'a TransportSet,
    /// The bounced sum.
    pub bounced: Option<&'a BouncedTransport>,
}

impl Sets<'_> {
    /// The sets in the file's order: the direct transport, then each bounced channel.
    fn all(&self) -> impl Iterator<Item = &TransportSet> {
        let bounced = self.bounced.map_or(&[][..], BouncedTransport::channels);
        std::iter::once(self.direct).chain(bounced)
    }
}

/// `params` recording `bounced`'s bounces, once [`check_bounced`] accepts it beside
/// `transport` and `albedo`.
pub(super) fn bounced_params(
    params: &CacheParams,
    albedo: &Array2<f32>,
    transport: &TransportSet,
    bounced: &BouncedTransport,
) -> Result<CacheParams> {
    let mut params = params.clone();
    params.bounces = bounced.bounces();
    check_bounced(&params, albedo, transport, Some(bounced))?;
    Ok(params)
}

/// Checks that `bounced` (with `params.bounces` bounces, none when absent) has the vertices,
/// parameterisation, truncation and bands of `transport`, and one set exactly when `albedo`
/// is grey.
pub(super) fn check_bounced(
    params: &CacheParams,
    albedo: &Array2<f32>,
    transport: &TransportSet,
    bounced: Option<&BouncedTransport>,
) -> Result<()> {
    let found = bounced.map_or(0, BouncedTransport::bounces);
    let why = if params.bounces != found {
        Some(format!(
            "they say {} bounces but the bounced sum has {found}",
            params.bounces
        ))
    } else {
        bounced.and_then(|b| {
            let bands = |s: &TransportSet| s.sh().map(ShTransfer::bands);
            let c = b.channel(0);
            if (c.param(), c.keep(), bands(c), c.vertex_count())
                != (
                    transport.param(),
                    transport.keep(),
                    bands(transport),
                    transport.vertex_count(),
                )
            {
                Some("the bounced sum is of other vertices, directions, truncation or bands".into())
            } else if b.is_grey() != is_grey(albedo.view()) {
                Some(format!(
                    "the bounced sum has {} set(s) but the albedo is {}",
                    b.channels().len(),
                    if is_grey(albedo.view()) {
                        "grey"
                    } else {
                        "coloured"
                    }
                ))
            } else {
                None
            }
        })
    };
    match why {
        Some(why) => Err(Error::parameter("cache parameters", why)),
        None => Ok(()),
    }
}

/// Checks that `albedo` and `mesh` describe the same vertices, `transport` has `rows` of
/// them, and `params` names its parameterisation and spherical-harmonic bands.
pub(super) fn check_parts(
    params: &CacheParams,
    mesh: &Mesh,
    albedo: &Array2<f32>,
    transport: &TransportSet,
    rows: usize,
) -> Result<()> {
    let v = mesh.vertex_count();
    if params.ground_plane != params.ground_cells.is_some() {
        return Err(Error::parameter(
            "cache parameters",
            format!(
                "ground_plane {} with ground_cells {:?}: cells are recorded with a ground plane only",
                params.ground_plane, params.ground_cells
            ),
        ));
    }
    if albedo.dim() != (v, 3) || transport.vertex_count() != rows {
        return Err(Error::shape(
            albedo.shape(),
            format!(
                "albedo must be ({v}, 3) and the transport have {rows} vertices (it has {})",
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
    Ok(())
}

/// The header of a file holding the transport `sets` for `mesh` (the scene file's environment and
/// camera in `scene_file`) whose last `ground_vertices` are the ground plane's, a shard's
/// when `shard` is given.
pub(super) fn header(
    params: &CacheParams,
    mesh: &Mesh,
    sets: Sets<'_>,
    scene_file: (&Option<EnvironmentSpec>, &Option<CameraSpec>),
    (ground_vertices, shard): (usize, Option<ShardRecord>),
) -> CacheHeader {
    CacheHeader {
        params: params.clone(),
        vertices: mesh.vertex_count(),
        triangles: mesh.triangles().len(),
        ground_vertices,
        coefficients: sets.direct.coefficient_count(),
        bounced_coefficients: (sets.bounced).map_or(vec![], |b| {
            b.channels()
                .iter()
                .map(TransportSet::coefficient_count)
                .collect()
        }),
        scene_hash: scene_hash(mesh),
        environment: scene_file.0.clone(),
        camera: scene_file.1.clone(),
        shard,
    }
}

/// Writes a cache file, whole or shard: the one writer of both.
pub(super) fn write_parts(
    path: &Path,
    force: bool,
    header: &CacheHeader,
    mesh: &Mesh,
    albedo: &Array2<f32>,
    sets: Sets<'_>,
) -> Result<u64> {
    let (positions, normals) = (mesh.positions(), mesh.normals());
    let (positions, normals) = (positions.as_standard_layout(), normals.as_standard_layout());
    let albedo = albedo.as_standard_layout();
    let flat = "a standard layout is contiguous";
    let (positions, normals) = (
        positions.as_slice().expect(flat),
        normals.as_slice().expect(flat),
    );
    let albedo = albedo.as_slice().expect(flat);
    FORMAT.write(path, force, header, |body| {
        body.array([positions, normals]);
        body.array([bytemuck::cast_slice::<_, u32>(mesh.triangles())]);
        body.array([albedo]);
        for set in sets.all() {
            let (offsets, indices, values) = set.parts();
            body.array([offsets]);
            body.array([indices]);
            body.array([values]);
            if let Some(sh) = set.sh() {
                body.array([sh.as_slice()]);
            }
        }
    })
}

/// One transport section as read: offsets, indices, values and transfer.
type Section = (Buffer<u64>, Buffer<u32>, Buffer<f32>, Option<ShTransfer>);

/// Reads a transport section of `rows` vertices, `n` coefficients and `sh_bands` bands.
fn read_section(
    r: &mut Reader<'_>,
    rows: usize,
    n: usize,
    sh_bands: Option<usize>,
) -> Result<Section> {
    let overflow = || FORMAT.corrupt("size overflows");
    let offsets = r.array(rows.checked_add(1).ok_or_else(overflow)?)?;
    let indices = r.array(n)?;
    let values = r.array(n)?;
    let sh = match sh_bands {
        Some(b) => {
            let per_vertex = b.checked_mul(b).ok_or_else(overflow)?;
            let flat = r.values(rows.checked_mul(per_vertex).ok_or_else(overflow)?)?;
            Some(ShTransfer::from_flat(b, flat)?)
        }
        None => None,
    };
    Ok((offsets, indices, values, sh))
}

/// Parses a cache file, whole or shard: the one reader of both. The file is mapped and its
/// transport read in place ([`crate::mapped`]); the mesh and albedo are copied. The
/// transport has the rows of the shard's range, or of every vertex.
pub(super) fn read_parts(path: &Path) -> Result<(CacheHeader, Parts)> {
    let file = MappedFile::open(path)?;
    let (header, r) = FORMAT.open_mapped::<CacheHeader>(&file)?;
    parse_parts(header, r)
}

/// [`read_parts`] of a file's bytes in memory, copied.
#[cfg(test)]
pub(super) fn parse_bytes(bytes: &[u8]) -> Result<(CacheHeader, Parts)> {
    let (header, r) = FORMAT.open::<CacheHeader>(bytes)?;
    parse_parts(header, r)
}

fn parse_parts(header: CacheHeader, mut r: Reader<'_>) -> Result<(CacheHeader, Parts)> {
    let (v, t, n) = (header.vertices, header.triangles, header.coefficients);
    let rows = match header.shard {
        None => v,
        Some(s) if s.index < s.count && s.first <= s.end && s.end <= v => s.end - s.first,
        Some(s) => {
            return Err(r.corrupt(format!(
                "shard {}/{} of vertices {}..{} among {v}",
                s.index, s.count, s.first, s.end
            )));
        }
    };
    let overflow = || FORMAT.corrupt("size overflows");
    let triple = v.checked_mul(3).ok_or_else(overflow)?;
    let positions =
        Array2::from_shape_vec((v, 3), r.values(triple)?).map_err(|e| r.corrupt(e.to_string()))?;
    let normals =
        Array2::from_shape_vec((v, 3), r.values(triple)?).map_err(|e| r.corrupt(e.to_string()))?;
    let flat = r.values::<u32>(t.checked_mul(3).ok_or_else(overflow)?)?;
    let triangles = flat.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect();
    let albedo =
        Array2::from_shape_vec((v, 3), r.values(triple)?).map_err(|e| r.corrupt(e.to_string()))?;
    let bands = header.params.sh_bands;
    let direct = read_section(&mut r, rows, n, bands)?;
    let (bounces, counts) = (header.params.bounces, &header.bounced_coefficients);
    // Checked before any section is read: a hostile count of sets or bounces is refused
    // here, not sized into an allocation.
    if (bounces == 0) != counts.is_empty() || !matches!(counts.len(), 0 | 1 | 3) {
        return Err(r.corrupt(format!(
            "{bounces} bounces with {} bounced sets (0 and none, or 1 to 8 and 1 or 3)",
            counts.len()
        )));
    }
    let bounced = counts
        .iter()
        .map(|&n| read_section(&mut r, rows, n, bands))
        .collect::<Result<Vec<_>>>()?;
    r.finish(if bounced.is_empty() {
        "transport"
    } else {
        "bounced sum"
    })?;
    // The normals as written, not normalised again: see `Mesh::stored`.
    let mesh = Mesh::stored(positions, triangles, normals)?;
    let kind: ParamKind = header.params.param.parse()?;
    let param = Parameterization::new(kind, header.params.resolution)?;
    let keep: Selection = header.params.keep.into();
    let set = |(offsets, indices, values, sh): Section| {
        TransportSet::from_parts(param, keep, offsets, indices, values, sh)
    };
    let transport = set(direct)?;
    let bounced = match bounced.is_empty() {
        true => None,
        false => {
            let sets = bounced.into_iter().map(set).collect::<Result<Vec<_>>>()?;
            Some(BouncedTransport::new(bounces, sets)?)
        }
    };
    Ok((
        header,
        Parts {
            mesh,
            albedo,
            transport,
            bounced,
        },
    ))
}

#[cfg(test)]
#[path = "cache_tests.rs"]
mod tests;
