//! The occlusion field file (`.hsf`): one shape's [`OcclusionField`] on disk, so that a
//! dynamic scene loads its fields instead of casting their rays again.
//!
//! **Layout** (little endian; the framing is the scene cache's, [`crate::scene::cache`]):
//!
//! | bytes | content |
//! |---|---|
//! | 8 | magic `HSOCCFLD` |
//! | 4 | format version ([`FIELD_VERSION`]) |
//! | 4 | CRC-32 of everything after this field |
//! | 8 | length `H` of the header |
//! | `H` | header, JSON: [`FieldHeader`] |
//! | | every sample's map: offsets `samples + 1` u64, indices `N` u32, values `N` f32 |
//!
//! Each array starts at a file offset that is a multiple of 8 (version 2; version 1 files are
//! refused).
//!
//! **What decides the content**, all recorded in the header and all compared by
//! [`OcclusionField::read_for`]: the shape (its mesh's [`scene_hash`] and its vertex and
//! triangle counts: the mesh file or generator is recorded for the messages only, so that a
//! moved mesh file still matches), and every [`FieldOptions`] entry that places a sample or
//! truncates a map ([`FieldRecord`]: parameterisation, resolution, kept coefficients, circles,
//! points, radii, shells, grid), and the turn. The frame (centre, radii, plane) follows from
//! the mesh; it is recorded so that [`OcclusionField::read`] needs no mesh, and compared too.
//! Not recorded: the [`Truncation`](crate::dynamic::fields::Truncation) of a lookup and the rest of a dynamic
//! scene's options, which act on the maps as stored, at shading time.
//!
//! **Checks on reading**, each a [`SceneError`]: the magic, the version and the checksum (a
//! flipped byte, a truncated file), then what the header announces (valid options, as many
//! maps as they place samples, indices within the maps, finite values, a frame with extent),
//! and with [`read_for`](OcclusionField::read_for) the shape and the options
//! ([`SceneError::FieldMismatch`] names every entry that differs). A stale file is refused,
//! never used. Files are written atomically ([`haarshift::io::write_file_atomically`]).
//!
//! [`FieldStore`] keeps a directory of them, one a shape.

use std::path::{Path, PathBuf};
use std::time::Instant;

use serde::{Deserialize, Serialize};

use crate::dynamic::fields::{FieldFrame, FieldOptions, FieldReport, OcclusionField};
use crate::precompute::sparse::SparseRows;
use crate::scene::cache::KeepRecord;
use crate::scene::framed::Format;
use crate::{Error, Result};
use crate::{Generator, Mesh, SceneError, scene_hash};
use haarshift::faces::{ParamKind, Parameterization};

/// The format version this build reads and writes.
pub const FIELD_VERSION: u32 = 2;

const FORMAT: Format = Format {
    magic: b"HSOCCFLD",
    version: FIELD_VERSION,
    name: "occlusion field file",
    corrupt: SceneError::FieldCorrupt,
    other_version: |found, expected| SceneError::FieldVersion { found, expected },
};

/// The field options that decide a field's maps, as recorded in a field file.
///
/// ```
/// use haarshift_relight::dynamic::fields::{FieldOptions, file::FieldRecord};
/// use haarshift::faces::{ParamKind, Parameterization};
/// let options = FieldOptions::new(Parameterization::new(ParamKind::Cube, 64).unwrap());
/// let record = FieldRecord::of(&options);
/// assert_eq!((record.param.as_str(), record.resolution, record.circles), ("cube", 64, 100));
/// assert_eq!(record.options().unwrap(), options);
/// ```
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FieldRecord {
    /// `latlong` or `cube`.
    pub param: String,
    /// Face side `S` (lat-long: the map height).
    pub resolution: usize,
    /// What each sample's map keeps.
    pub keep: KeepRecord,
    /// Concentric circles of the planar field.
    pub circles: usize,
    /// Points per circle.
    pub circle_points: usize,
    /// Innermost and outermost circle radius, in footprint radii.
    pub circle_radii: (f64, f64),
    /// Concentric shells of the spherical field.
    pub shells: usize,
    /// Points per face edge of a shell's cube grid.
    pub shell_grid: usize,
    /// Innermost and outermost shell radius, in bounding radii.
    pub shell_radii: (f64, f64),
}

impl FieldRecord {
    /// The record of `options`.
    pub fn of(options: &FieldOptions) -> Self {
        FieldRecord {
            param: options.param.kind().to_string(),
            resolution: options.param.face_size(),
            keep: options.keep.into(),
            circles: options.circles,
            circle_points: options.circle_points,
            circle_radii: options.circle_radii,
            shells: options.shells,
            shell_grid: options.shell_grid,
            shell_radii: options.shell_radii,
        }
    }

    /// The options it records (not whether progress is reported), checked as a build checks them.
    pub fn options(&self) -> Result<FieldOptions> {
        let kind: ParamKind = self.param.parse()?;
        let options = FieldOptions {
            keep: self.keep.into(),
            circles: self.circles,
            circle_points: self.circle_points,
            circle_radii: self.circle_radii,
            shells: self.shells,
            shell_grid: self.shell_grid,
            shell_radii: self.shell_radii,
            ..FieldOptions::new(Parameterization::new(kind, self.resolution)?)
        };
        options.check()?;
        Ok(options)
    }
}

/// The shape a field file was built for.
///
/// ```
/// use haarshift_relight::{Generator, scene_hash};
/// use haarshift_relight::dynamic::fields::file::ShapeRecord;
/// let ball = Generator::Sphere { cells: 2 }.mesh().unwrap();
/// let shape = ShapeRecord::of(&ball, "sphere");
/// assert_eq!((shape.vertices, shape.mesh_hash), (ball.vertex_count(), scene_hash(&ball)));
/// ```
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ShapeRecord {
    /// The mesh file or generator it came from (for messages; not compared).
    pub source: String,
    /// [`scene_hash`] of the mesh in its own frame.
    pub mesh_hash: u32,
    /// Vertices of the mesh.
    pub vertices: usize,
    /// Triangles of the mesh.
    pub triangles: usize,
}

impl ShapeRecord {
    /// The record of `mesh`, which came from `source`.
    pub fn of(mesh: &Mesh, source: impl Into<String>) -> Self {
        ShapeRecord {
            source: source.into(),
            mesh_hash: scene_hash(mesh),
            vertices: mesh.vertex_count(),
            triangles: mesh.triangles().len(),
        }
    }

    fn same_mesh(&self, other: &ShapeRecord) -> bool {
        (self.mesh_hash, self.vertices, self.triangles)
            == (other.mesh_hash, other.vertices, other.triangles)
    }
}

/// The JSON header of a field file.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FieldHeader {
    /// The shape it was built for.
    pub shape: ShapeRecord,
    /// How it was sampled.
    pub options: FieldRecord,
    /// Where its samples are (from the mesh).
    pub frame: FieldFrame,
    /// Columns its maps are turned by.
    pub turn: usize,
    /// Sample points (maps).
    pub samples: usize,
    /// Stored coefficients, all maps.
    pub coefficients: usize,
}

impl OcclusionField {
    /// Writes the field, built from `mesh` (which came from `source`), to `path` atomically (an
    /// existing file only with `force`); returns the file's size in bytes. A field whose
    /// frame is not `mesh`'s is refused.
    ///
    /// ```
    /// use haarshift_relight::{Generator, dynamic::fields::{FieldOptions, OcclusionField}};
    /// use haarshift::faces::{ParamKind, Parameterization};
    /// let ball = Generator::Sphere { cells: 2 }.mesh().unwrap();
    /// let mut options = FieldOptions::new(Parameterization::new(ParamKind::LatLong, 4).unwrap());
    /// (options.circles, options.circle_points, options.shells, options.shell_grid) = (3, 6, 2, 2);
    /// let (field, _) = OcclusionField::build(&ball, &options).unwrap();
    /// let dir = tempfile::tempdir().unwrap();
    /// let path = dir.path().join("ball.hsf");
    /// let bytes = field.write(&path, &ball, "sphere", false).unwrap();
    /// assert_eq!(std::fs::metadata(&path).unwrap().len(), bytes);
    /// assert_eq!(OcclusionField::read_for(&path, &ball, &options).unwrap(), field);
    /// assert!(field.write(&path, &ball, "sphere", false).is_err()); // exists: needs force
    /// ```
    pub fn write(&self, path: &Path, mesh: &Mesh, source: &str, force: bool) -> Result<u64> {
        if FieldFrame::of(mesh)? != self.frame {
            return Err(Error::parameter(
                "mesh",
                "the field was not built from this mesh",
            ));
        }
        let (offsets, indices, values) = self.maps.parts();
        let header = FieldHeader {
            shape: ShapeRecord::of(mesh, source),
            options: FieldRecord::of(&self.options),
            frame: self.frame,
            turn: self.turn,
            samples: self.maps.len(),
            coefficients: indices.len(),
        };
        FORMAT.write(path, force, &header, |body| {
            body.array([offsets]);
            body.array([indices]);
            body.array([values]);
        })
    }

    /// Reads a field file and its header, refusing a damaged file or another version; see the
    /// [module docs](self).
    ///
    /// ```
    /// # use haarshift_relight::{Generator, dynamic::fields::{FieldOptions, OcclusionField}};
    /// # use haarshift::faces::{ParamKind, Parameterization};
    /// # let ball = Generator::Sphere { cells: 2 }.mesh().unwrap();
    /// # let mut options = FieldOptions::new(Parameterization::new(ParamKind::LatLong, 4).unwrap());
    /// # (options.circles, options.circle_points, options.shells, options.shell_grid) = (3, 6, 2, 2);
    /// # let (field, _) = OcclusionField::build(&ball, &options).unwrap();
    /// # let dir = tempfile::tempdir().unwrap();
    /// # let path = dir.path().join("ball.hsf");
    /// field.write(&path, &ball, "a sphere of 2 cells", false).unwrap();
    /// let (read, header) = OcclusionField::read(&path).unwrap();
    /// assert_eq!((read, header.shape.source.as_str()), (field, "a sphere of 2 cells"));
    /// std::fs::write(&path, b"HSOCCFLD").unwrap();
    /// assert!(OcclusionField::read(&path).unwrap_err().to_string().contains("damaged"));
    /// ```
    pub fn read(path: &Path) -> Result<(Self, FieldHeader)> {
        let bytes =
            std::fs::read(path).map_err(|source| crate::Error::io(path.to_path_buf(), source))?;
        Self::parse(&bytes).map_err(|e| e.in_file(path))
    }

    /// Reads a field file and refuses it unless it was built for `mesh` with `options`
    /// ([`SceneError::FieldMismatch`] names what differs).
    ///
    /// ```
    /// # use haarshift_relight::{Generator, dynamic::fields::{FieldOptions, OcclusionField}};
    /// # use haarshift::faces::{ParamKind, Parameterization};
    /// # let ball = Generator::Sphere { cells: 2 }.mesh().unwrap();
    /// # let mut options = FieldOptions::new(Parameterization::new(ParamKind::LatLong, 4).unwrap());
    /// # (options.circles, options.circle_points, options.shells, options.shell_grid) = (3, 6, 2, 2);
    /// # let (field, _) = OcclusionField::build(&ball, &options).unwrap();
    /// # let dir = tempfile::tempdir().unwrap();
    /// # let path = dir.path().join("ball.hsf");
    /// field.write(&path, &ball, "sphere", false).unwrap();
    /// options.circles = 4;
    /// let e = OcclusionField::read_for(&path, &ball, &options).unwrap_err().to_string();
    /// assert!(e.contains("circles 3 (asked: 4)"), "{e}");
    /// ```
    pub fn read_for(path: &Path, mesh: &Mesh, options: &FieldOptions) -> Result<Self> {
        let (field, header) = Self::read(path)?;
        let mismatch = |what: String| Error::from(SceneError::FieldMismatch(what)).in_file(path);
        let shape = ShapeRecord::of(mesh, "");
        if !header.shape.same_mesh(&shape) || FieldFrame::of(mesh)? != field.frame {
            return Err(mismatch(format!(
                "for another mesh ({}: {} vertices, {} triangles, hash {:08x}; this one has {}, \
                 {}, {:08x})",
                header.shape.source,
                header.shape.vertices,
                header.shape.triangles,
                header.shape.mesh_hash,
                shape.vertices,
                shape.triangles,
                shape.mesh_hash
            )));
        }
        let differences = differences(&header.options, &FieldRecord::of(options));
        if !differences.is_empty() || field.turn != 0 {
            return Err(mismatch(format!(
                "with other options: {}",
                if differences.is_empty() {
                    format!("turned by {} columns (asked: 0)", field.turn)
                } else {
                    differences.join(", ")
                }
            )));
        }
        // The recorded options equal the asked ones but for progress reporting.
        Ok(OcclusionField {
            options: *options,
            ..field
        })
    }

    fn parse(bytes: &[u8]) -> Result<(Self, FieldHeader)> {
        let (header, mut r) = FORMAT.open::<FieldHeader>(bytes)?;
        let options = header
            .options
            .options()
            .map_err(|e| r.corrupt(e.to_string()))?;
        let param = options.param;
        let f = &header.frame;
        let frame_ok = f.centre.iter().chain([&f.plane]).all(|x| x.is_finite())
            && f.radius.is_finite()
            && f.footprint.is_finite()
            && f.radius > 0.0
            && f.footprint > 0.0;
        let turn_ok = header.turn < 2 * param.face_size()
            && (param.kind() == ParamKind::LatLong || header.turn == 0);
        if !frame_ok || !turn_ok || header.samples != options.samples() {
            return Err(r.corrupt(format!(
                "the header's frame, turn or {} samples do not fit its options",
                header.samples
            )));
        }
        let offsets = r.array(header.samples + 1)?;
        let indices = r.array(header.coefficients)?;
        let values = r.array::<f32>(header.coefficients)?;
        r.finish("maps")?;
        let texels = param.texels() as u32;
        let maps = SparseRows::from_parts(offsets, indices, values)
            .filter(|rows| {
                let (_, indices, values) = rows.parts();
                indices.iter().all(|&i| i < texels) && values.iter().all(|v| v.is_finite())
            })
            .ok_or_else(|| {
                FORMAT
                    .corrupt("the arrays do not describe one sparse map of these options a sample")
            })?;
        let field = OcclusionField {
            options,
            frame: header.frame,
            maps,
            turn: header.turn,
        };
        Ok((field, header))
    }
}

/// `entry recorded (asked: wanted)` for every entry of the records that differs.
fn differences(recorded: &FieldRecord, wanted: &FieldRecord) -> Vec<String> {
    let wanted = serde_json::to_value(wanted).expect("a record serialises");
    let recorded = serde_json::to_value(recorded).expect("a record serialises");
    let asked = |k: &str| wanted.get(k).cloned().unwrap_or_default();
    recorded
        .as_object()
        .into_iter()
        .flatten()
        .filter(|(k, v)| wanted.get(k) != Some(v))
        .map(|(k, v)| format!("{k} {v} (asked: {})", asked(k)))
        .collect()
}

/// Where a shape's field came from.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum FieldOrigin {
    /// Read from a matching file: its size and the seconds reading and checking it took.
    Loaded {
        /// Bytes of the file.
        bytes: u64,
        /// Seconds to read, check and parse it.
        seconds: f64,
    },
    /// Built by ray casting (no file held it) and written.
    Built {
        /// What the build did.
        report: FieldReport,
        /// Bytes of the file written.
        bytes: u64,
    },
}

/// A directory of field files, one a shape, named after the shape's mesh file or generator
/// (`bunny.hsf`, `sphere-cells-3.hsf`): a file that matches is read, an absent one is built
/// and written, one that does not match (damaged, another version, mesh or options) is an
/// error unless the store may replace it, when it is built again and replaced.
///
/// ```
/// use haarshift_relight::{Generator, dynamic::fields::{FieldOptions, file::{FieldOrigin, FieldStore}}};
/// use haarshift::faces::{ParamKind, Parameterization};
/// let generator = Generator::Sphere { cells: 2 };
/// let ball = generator.mesh().unwrap();
/// let mut options = FieldOptions::new(Parameterization::new(ParamKind::LatLong, 4).unwrap());
/// (options.circles, options.circle_points, options.shells, options.shell_grid) = (3, 6, 2, 2);
/// let dir = tempfile::tempdir().unwrap();
/// let mut store = FieldStore::new(dir.path(), false);
/// let (built, how) = store.field(&ball, None, Some(&generator), &options).unwrap();
/// assert!(matches!(how, FieldOrigin::Built { .. }));
/// assert!(dir.path().join("sphere-cells-2.hsf").exists());
/// let (loaded, how) = store.field(&ball, None, Some(&generator), &options).unwrap();
/// assert!(matches!(how, FieldOrigin::Loaded { .. }) && loaded == built);
/// ```
#[derive(Clone, Debug)]
pub struct FieldStore {
    dir: PathBuf,
    replace: bool,
    /// The file name each source has taken, so that two shapes never share a file.
    claimed: Vec<(String, String)>,
}

impl FieldStore {
    /// A store in `dir` (which must exist); `replace`: build again and replace a file that
    /// does not match instead of refusing it.
    pub fn new(dir: impl Into<PathBuf>, replace: bool) -> Self {
        FieldStore {
            dir: dir.into(),
            replace,
            claimed: Vec::new(),
        }
    }

    /// The directory.
    pub fn dir(&self) -> &Path {
        &self.dir
    }

    /// Makes sure files can be written in the directory, creating it when absent: what a
    /// caller checks before the work whose fields the store will keep.
    ///
    /// ```
    /// use haarshift_relight::dynamic::fields::file::FieldStore;
    /// let dir = tempfile::tempdir().unwrap();
    /// FieldStore::new(dir.path().join("fields"), false).prepare().unwrap();
    /// assert!(dir.path().join("fields").is_dir());
    /// let file = dir.path().join("a file");
    /// std::fs::write(&file, b"").unwrap();
    /// assert!(FieldStore::new(&file, false).prepare().is_err());
    /// ```
    pub fn prepare(&self) -> Result<()> {
        let io = |source| crate::Error::io(self.dir.clone(), source);
        std::fs::create_dir_all(&self.dir).map_err(io)?;
        tempfile::tempfile_in(&self.dir).map_err(io)?;
        Ok(())
    }

    /// The file of the shape from the mesh file `mesh` or `generator`, and how the source is
    /// recorded.
    ///
    /// ```
    /// use haarshift_relight::{Generator, dynamic::fields::file::FieldStore};
    /// let store = FieldStore::new("fields", false);
    /// let (path, _) = store.path(Some("../meshes/bunny.ply".as_ref()), None);
    /// assert_eq!(path, std::path::Path::new("fields/bunny.hsf"));
    /// let (path, source) = store.path(None, Some(&Generator::Table { cells: 4 }));
    /// assert_eq!(path, std::path::Path::new("fields/table-cells-4.hsf"));
    /// assert_eq!(source, r#"generator {"table":{"cells":4}}"#);
    /// ```
    pub fn path(&self, mesh: Option<&Path>, generator: Option<&Generator>) -> (PathBuf, String) {
        let (name, source) = match (mesh, generator) {
            (Some(m), _) => (
                m.file_stem()
                    .map_or(String::new(), |s| s.to_string_lossy().into_owned()),
                format!("mesh {}", m.display()),
            ),
            (None, g) => {
                let json = serde_json::to_string(&g).expect("a generator serialises");
                (json.clone(), format!("generator {json}"))
            }
        };
        let mut label = String::new();
        for c in name.chars() {
            if c.is_ascii_alphanumeric() || c == '_' {
                label.push(c.to_ascii_lowercase());
            } else if !label.is_empty() && !label.ends_with('-') {
                label.push('-');
            }
        }
        let label = match label.trim_end_matches('-') {
            "" => "shape",
            l => l,
        };
        (self.dir.join(format!("{label}.hsf")), source)
    }

    /// The field of `mesh` (from the mesh file `mesh_path` or `generator`) sampled with
    /// `options`: read from its file when that matches, else built and written; see the
    /// [type docs](Self).
    pub fn field(
        &mut self,
        mesh: &Mesh,
        mesh_path: Option<&Path>,
        generator: Option<&Generator>,
        options: &FieldOptions,
    ) -> Result<(OcclusionField, FieldOrigin)> {
        let (path, source) = self.path(mesh_path, generator);
        let name = path.to_string_lossy().into_owned();
        match self.claimed.iter().find(|(n, _)| *n == name) {
            Some((_, other)) if *other != source => {
                return Err(Error::parameter(
                    "fields directory",
                    format!(
                        "{source} and {other} would share the field file {name}: give one mesh \
                         file another name"
                    ),
                ));
            }
            Some(_) => {}
            None => self.claimed.push((name, source.clone())),
        }
        if path.exists() {
            let start = Instant::now();
            match OcclusionField::read_for(&path, mesh, options) {
                Ok(field) => {
                    let bytes = std::fs::metadata(&path).map_or(0, |m| m.len());
                    let seconds = start.elapsed().as_secs_f64();
                    return Ok((field, FieldOrigin::Loaded { bytes, seconds }));
                }
                Err(e @ Error::Scene { .. }) if !self.replace => return Err(e),
                Err(Error::Scene { .. }) => {}
                Err(e) => return Err(e),
            }
        }
        let (field, report) = OcclusionField::build(mesh, options)?;
        let bytes = field.write(&path, mesh, &source, self.replace)?;
        Ok((field, FieldOrigin::Built { report, bytes }))
    }
}

#[cfg(test)]
#[path = "file_tests.rs"]
mod tests;
