//! Shards of a scene cache: what `haarshift relight precompute --shard I/N` writes (the
//! whole mesh and albedo, and the transport of one vertex range, in the
//! [cache's file format](super::cache) with [`CacheHeader::shard`] set), and their merge into
//! the cache an unsharded precomputation writes, byte for byte ([`merge_shards`]).
//!
//! **Checks of a merge**, each refusing with one line that names the file at fault: every file
//! is a readable shard (a damaged or truncated one fails its checksum); every shard comes from
//! the same scene (mesh hash, albedo, the scene file's environment and camera) and options as
//! the first; the ranges cover every vertex exactly once (the first missing or doubly held
//! range is named with the shard beside it).

use std::path::{Path, PathBuf};

use ndarray::Array2;

use crate::precompute::bounce::BouncedTransport;
use crate::precompute::shard::Shard;
use crate::scene::cache::{
    CacheHeader, CacheParams, Parts, Sets, ShardRecord, bounced_params, check_bounced, check_parts,
    header, read_parts, scene_hash, write_parts,
};
use crate::scene::{CameraSpec, EnvironmentSpec};
use crate::{Error, Result};
use crate::{Mesh, Scene, SceneCache, SceneError, TransportSet};

/// One shard of a scene cache; see the [module docs](self).
///
/// ```
/// use haarshift_relight::precompute::{PrecomputeOptions, precompute, precompute_shard};
/// use haarshift_relight::precompute::shard::Shard;
/// use haarshift_relight::{CacheShard, Generator, Scene, VisibilityOptions};
/// use haarshift::faces::{ParamKind, Parameterization};
/// let scene = || Scene::from_mesh(Generator::Sphere { cells: 2 }.mesh().unwrap(), false).unwrap();
/// let options = PrecomputeOptions::new(VisibilityOptions::new(Parameterization::new(ParamKind::Cube, 4).unwrap()));
/// let (shard, _) = precompute_shard(scene(), &options, Shard::new(1, 3).unwrap()).unwrap();
/// assert_eq!((shard.record.first, shard.record.end), (18, 36)); // 54 vertices
/// let dir = tempfile::tempdir().unwrap();
/// let path = dir.path().join("part-1.hsr");
/// shard.write(&path, false).unwrap();
/// assert_eq!(CacheShard::read(&path).unwrap(), shard);
/// let (whole, _) = precompute(scene(), &options).unwrap();
/// assert_eq!(shard.transport.coefficients(0), whole.transport.coefficients(18));
/// ```
#[derive(Clone, Debug, PartialEq)]
pub struct CacheShard {
    /// Which shard, and its vertex range.
    pub record: ShardRecord,
    /// How the transport was made.
    pub params: CacheParams,
    /// The whole scene's mesh (every shard traces all of it).
    pub mesh: Mesh,
    /// The whole scene's albedo, `(V, 3)`.
    pub albedo: Array2<f32>,
    /// The transport of the vertices `record.first..record.end`, row 0 the first.
    pub transport: TransportSet,
    /// Their bounced sum, with bounces ([`set_bounced`](Self::set_bounced)).
    pub bounced: Option<BouncedTransport>,
    /// The scene file's lighting.
    pub environment: Option<EnvironmentSpec>,
    /// The scene file's camera.
    pub camera: Option<CameraSpec>,
}

impl CacheShard {
    /// Bundles shard `shard` of a scene of `mesh` and `albedo`, checking that `transport`
    /// holds exactly the shard's vertices and that `params` names it.
    pub fn new(
        shard: Shard,
        params: CacheParams,
        mesh: Mesh,
        albedo: Array2<f32>,
        transport: TransportSet,
    ) -> Result<Self> {
        let range = shard.range(mesh.vertex_count());
        check_parts(&params, &mesh, &albedo, &transport, range.len())?;
        check_bounced(&params, &albedo, &transport, None)?;
        Ok(CacheShard {
            record: ShardRecord {
                index: shard.index(),
                count: shard.count(),
                first: range.start,
                end: range.end,
            },
            params,
            mesh,
            albedo,
            transport,
            bounced: None,
            environment: None,
            camera: None,
        })
    }

    /// Stores the bounced sum of the shard's vertices and records its bounces, checked as
    /// [`SceneCache::set_bounced`] checks a whole cache's.
    pub fn set_bounced(&mut self, bounced: BouncedTransport) -> Result<()> {
        self.params = bounced_params(&self.params, &self.albedo, &self.transport, &bounced)?;
        self.bounced = Some(bounced);
        Ok(())
    }

    /// Writes the shard to `path` atomically (an existing file only with `force`), by the
    /// writer of whole caches; returns the file's size in bytes.
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
            (self.params.grid_ground_vertices(), Some(self.record)),
        );
        write_parts(path, force, &header, &self.mesh, &self.albedo, sets)
    }

    /// Reads a shard, refusing a damaged file, another version or a whole cache.
    pub fn read(path: &Path) -> Result<Self> {
        read_parts(path)
            .and_then(Self::from_file_parts)
            .map_err(|e| e.in_file(path))
    }

    fn from_file_parts((header, parts): (CacheHeader, Parts)) -> Result<Self> {
        let record = header.shard.ok_or(SceneError::NotAShard)?;
        // The reader checked the range against the mesh; it must also be the range the index
        // and count name, so that a merge can trust either.
        let shard = Shard::new(record.index, record.count)?;
        let mut params = header.params;
        params.bounces = 0; // set again with the bounced sum, checked against it
        let mut made = CacheShard::new(shard, params, parts.mesh, parts.albedo, parts.transport)?;
        if let Some(bounced) = parts.bounced {
            made.set_bounced(bounced)?;
        }
        if made.record != record {
            return Err(SceneError::CacheCorrupt(format!(
                "shard {shard} records vertices {}..{}, not {}..{}",
                record.first, record.end, made.record.first, made.record.end
            ))
            .into());
        }
        made.environment = header.environment;
        made.camera = header.camera;
        Ok(made)
    }

    /// What the shard was made from, to compare with another shard or a scene.
    pub(crate) fn provenance(&self) -> Provenance<'_> {
        Provenance {
            params: &self.params,
            mesh: &self.mesh,
            albedo: &self.albedo,
            environment: self.environment.as_ref(),
            camera: self.camera.as_ref(),
        }
    }
}

/// What a shard is made from: the scene (mesh, albedo, the scene file's lighting and camera)
/// and the options; shards merge only when theirs are the same.
pub(crate) struct Provenance<'a> {
    /// The options, as the cache records them.
    pub params: &'a CacheParams,
    /// The whole scene's mesh.
    pub mesh: &'a Mesh,
    /// Its albedo.
    pub albedo: &'a Array2<f32>,
    /// The scene file's lighting.
    pub environment: Option<&'a EnvironmentSpec>,
    /// The scene file's camera.
    pub camera: Option<&'a CameraSpec>,
}

impl<'a> Provenance<'a> {
    /// What `scene` precomputed with `params` is made from.
    pub(crate) fn of_scene(params: &'a CacheParams, scene: &'a Scene) -> Self {
        Provenance {
            params,
            mesh: &scene.mesh,
            albedo: &scene.albedo,
            environment: scene.environment.as_ref(),
            camera: scene.camera.as_ref(),
        }
    }

    /// What a whole cache was made from.
    pub(crate) fn of_cache(cache: &'a SceneCache) -> Self {
        Provenance {
            params: &cache.params,
            mesh: &cache.mesh,
            albedo: &cache.albedo,
            environment: cache.environment.as_ref(),
            camera: cache.camera.as_ref(),
        }
    }

    /// How `self` differs from `other` (the first difference, as `self`'s value then
    /// `other`'s), or `None` when they are the same.
    pub(crate) fn difference(&self, other: &Provenance<'_>) -> Option<String> {
        let (mine, theirs) = (scene_hash(self.mesh), scene_hash(other.mesh));
        if mine != theirs || self.mesh.triangles() != other.mesh.triangles() {
            return Some(format!(
                "another mesh ({} vertices, hash {mine:08x}, not {} vertices, hash {theirs:08x})",
                self.mesh.vertex_count(),
                other.mesh.vertex_count()
            ));
        }
        if self.albedo != other.albedo {
            return Some("another albedo (the scene's materials differ)".into());
        }
        if self.environment != other.environment || self.camera != other.camera {
            return Some("another environment or camera in the scene file".into());
        }
        // The first option that differs, by its name in the header.
        let fields = |p: &CacheParams| match serde_json::to_value(p) {
            Ok(serde_json::Value::Object(map)) => map,
            _ => serde_json::Map::new(),
        };
        let (a, b) = (fields(self.params), fields(other.params));
        a.iter()
            .find(|(k, v)| b.get(*k) != Some(*v))
            .map(|(k, v)| {
                let theirs = b.get(k).map_or("unset".into(), |w| w.to_string());
                format!("other options ({k} {v}, not {theirs})")
            })
            .or_else(|| (self.params != other.params).then(|| "other options".into()))
    }
}

/// Reads the shards `paths` and merges them into the scene cache an unsharded precomputation
/// makes (written by [`SceneCache::write`], the same bytes); see the [module docs](self) for
/// the checks. The order of `paths` does not matter.
///
/// ```
/// use haarshift_relight::precompute::{PrecomputeOptions, precompute, precompute_shard};
/// use haarshift_relight::precompute::shard::Shard;
/// use haarshift_relight::{Generator, Scene, VisibilityOptions, merge_shards};
/// use haarshift::faces::{ParamKind, Parameterization};
/// let scene = || Scene::from_mesh(Generator::Sphere { cells: 2 }.mesh().unwrap(), true).unwrap();
/// let options = PrecomputeOptions::new(VisibilityOptions::new(Parameterization::new(ParamKind::Cube, 4).unwrap()));
/// let dir = tempfile::tempdir().unwrap();
/// let parts: Vec<_> = (0..3).rev().map(|i| {
///     let path = dir.path().join(format!("part-{i}.hsr"));
///     let (shard, _) = precompute_shard(scene(), &options, Shard::new(i, 3).unwrap()).unwrap();
///     shard.write(&path, false).unwrap();
///     path
/// }).collect();
/// let merged = merge_shards(&parts).unwrap();
/// assert_eq!(merged, precompute(scene(), &options).unwrap().0);
/// let err = merge_shards(&parts[1..]).unwrap_err().to_string(); // shard 2/3 left out
/// assert!(err.ends_with("vertices 762..1143 are in no shard (after shard 1/3)"), "{err}");
/// ```
pub fn merge_shards(paths: &[PathBuf]) -> Result<SceneCache> {
    let Some((first_path, rest)) = paths.split_first() else {
        return Err(Error::parameter(
            "shards",
            "give at least one shard to merge",
        ));
    };
    let mut first = CacheShard::read(first_path)?;
    // Only the transports are kept: the mesh and albedo are the first shard's.
    let placeholder = TransportSet::new(first.transport.param(), first.transport.keep());
    let own = std::mem::replace(&mut first.transport, placeholder);
    let mut parts = vec![(first_path, first.record, own, first.bounced.take())];
    for path in rest {
        let shard = CacheShard::read(path)?;
        if let Some(how) = shard.provenance().difference(&first.provenance()) {
            return Err(Error::from(SceneError::ShardMismatch(format!(
                "shard {}/{} has {how} than {}",
                shard.record.index,
                shard.record.count,
                first_path.display()
            )))
            .in_file(path));
        }
        parts.push((path, shard.record, shard.transport, shard.bounced));
    }
    // Empty ranges (more shards than vertices) hold nothing and cover nothing.
    parts.retain(|(_, r, _, _)| r.first < r.end);
    parts.sort_by_key(|(_, r, _, _)| (r.first, r.end));
    let coverage = |path: &Path, reason: String| {
        Err(Error::from(SceneError::ShardCoverage(reason)).in_file(path))
    };
    let mut covered = 0;
    let mut previous: Option<(&PathBuf, ShardRecord)> = None;
    for (path, r, _, _) in &parts {
        if r.first > covered {
            return coverage(
                path,
                format!(
                    "vertices {covered}..{} are in no shard (before shard {}/{})",
                    r.first, r.index, r.count
                ),
            );
        }
        if let Some((other, _)) = previous.filter(|_| r.first < covered) {
            return coverage(
                path,
                format!(
                    "vertices {}..{} of shard {}/{} are also in {}",
                    r.first,
                    r.end.min(covered),
                    r.index,
                    r.count,
                    other.display()
                ),
            );
        }
        covered = r.end;
        previous = Some((path, *r));
    }
    let vertices = first.mesh.vertex_count();
    if covered < vertices {
        let (path, after) = match previous {
            Some((path, r)) => (
                path.as_path(),
                format!("after shard {}/{}", r.index, r.count),
            ),
            None => (first_path.as_path(), "every shard is empty".into()),
        };
        return coverage(
            path,
            format!("vertices {covered}..{vertices} are in no shard ({after})"),
        );
    }
    let mut transports = parts.into_iter().map(|(_, _, t, b)| (t, b));
    // Never the fallback: the shards cover at least one vertex here.
    let (mut transport, mut bounced) = transports.next().unwrap_or((first.transport, None));
    for (part, part_bounced) in transports {
        transport.append(&part)?;
        // The shards agree on their bounces (a parameter), so each has a sum when any has.
        if let (Some(sum), Some(more)) = (&mut bounced, &part_bounced) {
            sum.append(more)?;
        }
    }
    let mut params = first.params;
    params.bounces = 0; // set again with the merged bounced sum
    let mut cache = SceneCache::new(params, first.mesh, first.albedo, transport)?;
    if let Some(bounced) = bounced {
        cache.set_bounced(bounced)?;
    }
    cache.environment = first.environment;
    cache.camera = first.camera;
    Ok(cache)
}

#[cfg(test)]
#[path = "cache_shard_tests.rs"]
mod tests;
