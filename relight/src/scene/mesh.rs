//! Triangle meshes: positions, vertex normals and triangles, read from OBJ or PLY.
//!
//! **Files.** OBJ through a small reader here (`v`, `vn` and `f` statements; polygons
//! triangulated as fans; objects and groups merged; vertex `k` is the file's `k`-th `v`). The
//! `tobj` crate was the first choice but renumbers vertices in the order faces first use them and
//! drops unreferenced ones, which breaks the contract that per-vertex outputs follow the file's
//! vertex order. PLY
//! through [`ply_rs_bw`] (ASCII, binary little and big endian; `vertex` elements with `x y z`
//! of any numeric type and optional `nx ny nz`; `face` elements with a `vertex_indices` or
//! `vertex_index` list, polygons triangulated as fans). `ply-rs-bw` is the maintained fork of
//! `ply-rs` (whose last release is from 2018) and reads all three encodings, so no hand-written
//! reader is needed.
//!
//! **Normals.** From the file when it has them (normalised; a zero-length file normal is
//! replaced by the computed one), else the area-weighted mean of the incident triangles'
//! normals: the normalised sum of the unnormalised cross products `(b - a) x (c - a)`, which
//! weighs each triangle by twice its area. Triangles are wound counter-clockwise seen from
//! outside. A mesh read back from a scene cache keeps the normals it was written with, bit for
//! bit (checked unit or zero, not normalised again), so that it hashes as it did.
//!
//! **What is refused and what works.** A mesh with no triangles, a triangle naming a vertex that
//! does not exist, a NaN or infinite coordinate, or a file that is truncated or cannot be
//! parsed gives a [`SceneError`]. Degenerate triangles (zero area, repeated vertices) are kept:
//! they add nothing to any normal and a ray never hits them. A vertex that belongs to no
//! triangle of non-zero area (and has no normal in the file) gets the normal `(0, 0, 0)`, so
//! `max(0, n . w)` is 0 in every direction and it receives no light. Open and non-manifold
//! meshes work: nothing here needs a closed surface or consistent neighbours; a vertex on a
//! boundary simply averages the triangles it has, and an open mesh lets light in from behind.

use std::path::Path;

use ndarray::{Array2, ArrayView2, Axis};

use crate::SceneError;
use crate::scene::asset::MeshAsset;
use crate::scene::texture::srgb_to_linear;
use crate::{Error, Result};

/// An axis-aligned bounding box.
///
/// ```
/// use haarshift_relight::Bounds;
/// let b = Bounds { min: [0.0, 0.0, 0.0], max: [3.0, 4.0, 0.0] };
/// assert_eq!(b.diagonal(), 5.0);
/// assert_eq!(b.centre(), [1.5, 2.0, 0.0]);
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Bounds {
    /// The smallest coordinate on each axis.
    pub min: [f64; 3],
    /// The largest coordinate on each axis.
    pub max: [f64; 3],
}

impl Bounds {
    /// The length of the box's diagonal.
    pub fn diagonal(&self) -> f64 {
        (0..3)
            .map(|k| (self.max[k] - self.min[k]).powi(2))
            .sum::<f64>()
            .sqrt()
    }

    /// The centre of the box.
    pub fn centre(&self) -> [f64; 3] {
        std::array::from_fn(|k| 0.5 * (self.min[k] + self.max[k]))
    }
}

/// A triangle mesh: `V` vertices with positions and unit normals, and triangles of vertex
/// indices; see the [module docs](self).
///
/// ```
/// use haarshift_relight::Mesh;
/// use ndarray::array;
/// let positions = array![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, -1.0]];
/// let mesh = Mesh::new(positions, vec![[0, 1, 2]], None).unwrap();
/// assert_eq!(mesh.normals().row(0).to_vec(), vec![0.0, 1.0, 0.0]); // counter-clockwise from +Y
/// assert!(Mesh::new(array![[0.0, 0.0, 0.0]], vec![[0, 0, 1]], None).is_err());
/// ```
#[derive(Clone, Debug, PartialEq)]
pub struct Mesh {
    positions: Array2<f64>,
    normals: Array2<f64>,
    triangles: Vec<[u32; 3]>,
}

impl Mesh {
    /// A mesh from positions `(V, 3)`, triangles and, optionally, vertex normals `(V, 3)`
    /// (computed when `None`); checked as the [module docs](self) say.
    pub fn new(
        positions: Array2<f64>,
        triangles: Vec<[u32; 3]>,
        normals: Option<Array2<f64>>,
    ) -> Result<Self> {
        check_geometry(positions.view(), &triangles)?;
        let computed = area_weighted_normals(positions.view(), &triangles);
        let normals = match normals {
            None => computed,
            Some(given) => {
                check_normals(given.view(), positions.nrows())?;
                let mut given = given.as_standard_layout().into_owned();
                for (mut n, fallback) in given.outer_iter_mut().zip(computed.outer_iter()) {
                    match unit([n[0], n[1], n[2]]) {
                        Some(u) => n.assign(&ndarray::arr1(&u)),
                        None => n.assign(&fallback),
                    }
                }
                given
            }
        };
        Ok(Mesh {
            positions: positions.as_standard_layout().into_owned(),
            normals,
            triangles,
        })
    }

    /// A mesh as a scene cache stores it: the checks of [`Mesh::new`], and every normal unit
    /// (its squared length within [`UNIT_TOLERANCE`] of 1) or zero, as every mesh's are, and
    /// kept bit for bit. Not [`Mesh::new`]: normalising is not idempotent in floating point
    /// (`n / |n|` of a unit `n` may move its last bit), so normalising again would give the
    /// mesh read back another [`scene_hash`](crate::scene_hash) than the one written,
    /// and a merge of shards other bytes than the unsharded cache. Keeping the stored bits is
    /// exact by construction, where an idempotent normalisation would change every cache's
    /// normals and still need this check.
    pub(crate) fn stored(
        positions: Array2<f64>,
        triangles: Vec<[u32; 3]>,
        normals: Array2<f64>,
    ) -> Result<Self> {
        check_geometry(positions.view(), &triangles)?;
        check_normals(normals.view(), positions.nrows())?;
        for (vertex, n) in normals.outer_iter().enumerate() {
            let n = [n[0], n[1], n[2]];
            let squared = dot(n, n);
            if n != [0.0; 3] && (squared - 1.0).abs() > UNIT_TOLERANCE {
                return Err(SceneError::NotUnitNormal {
                    vertex,
                    length: squared.sqrt(),
                }
                .into());
            }
        }
        Ok(Mesh {
            positions: positions.as_standard_layout().into_owned(),
            normals: normals.as_standard_layout().into_owned(),
            triangles,
        })
    }

    /// Reads an OBJ (`.obj`), PLY (`.ply`), glTF (`.gltf`) or GLB (`.glb`) file, chosen by the
    /// extension: the geometry of [`MeshAsset::load`], without its colour.
    ///
    /// ```
    /// let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../testdata/meshes/bunny.ply");
    /// let bunny = haarshift_relight::Mesh::load(path.as_ref()).unwrap();
    /// assert_eq!((bunny.vertex_count(), bunny.triangles().len()), (1839, 3674));
    /// ```
    pub fn load(path: &Path) -> Result<Self> {
        MeshAsset::load(path).map(|asset| asset.mesh)
    }

    /// The vertex positions, `(V, 3)`.
    pub fn positions(&self) -> ArrayView2<'_, f64> {
        self.positions.view()
    }

    /// The unit vertex normals, `(V, 3)` (`(0, 0, 0)` for a vertex of no triangle).
    pub fn normals(&self) -> ArrayView2<'_, f64> {
        self.normals.view()
    }

    /// The triangles, counter-clockwise seen from outside.
    pub fn triangles(&self) -> &[[u32; 3]] {
        &self.triangles
    }

    /// Vertices in the mesh.
    pub fn vertex_count(&self) -> usize {
        self.positions.nrows()
    }

    /// The bounding box of the vertex positions.
    pub fn bounds(&self) -> Bounds {
        let mut b = Bounds {
            min: [f64::INFINITY; 3],
            max: [f64::NEG_INFINITY; 3],
        };
        for p in self.positions.outer_iter() {
            for k in 0..3 {
                b.min[k] = b.min[k].min(p[k]);
                b.max[k] = b.max[k].max(p[k]);
            }
        }
        b
    }

    /// Appends `other`'s vertices after this mesh's and its triangles after this mesh's,
    /// renumbered; every vertex keeps its normal.
    ///
    /// ```
    /// use haarshift_relight::Mesh;
    /// use ndarray::array;
    /// let a = Mesh::new(array![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]],
    ///                   vec![[0, 1, 2]], None).unwrap();
    /// let mut b = a.clone();
    /// b.append(&a);
    /// assert_eq!(b.triangles()[1], [3, 4, 5]);
    /// ```
    pub fn append(&mut self, other: &Mesh) {
        let offset = self.vertex_count() as u32;
        self.positions
            .append(Axis(0), other.positions.view())
            .expect("both are (V, 3)");
        self.normals
            .append(Axis(0), other.normals.view())
            .expect("both are (V, 3)");
        self.triangles
            .extend(other.triangles.iter().map(|t| t.map(|i| i + offset)));
    }

    /// The mesh with every triangle's winding reversed (`[a, b, c]` to `[a, c, b]`), normals
    /// kept: what a mirroring transform needs to keep triangles counter-clockwise seen from
    /// outside.
    pub(crate) fn reversed(mut self) -> Mesh {
        for t in &mut self.triangles {
            t.swap(1, 2);
        }
        self
    }

    /// The mesh with every position mapped by `position` and every normal by `normal` (then
    /// normalised): the caller passes a transform and its inverse transpose. Errors when a
    /// mapped position leaves the range of [`check_positions`](super::validate::check_positions).
    pub(crate) fn mapped(
        &self,
        position: impl Fn([f64; 3]) -> [f64; 3],
        normal: impl Fn([f64; 3]) -> [f64; 3],
    ) -> Result<Mesh> {
        let map = |a: &Array2<f64>, f: &dyn Fn([f64; 3]) -> [f64; 3], normals: bool| {
            let mut out = a.clone();
            for mut row in out.outer_iter_mut() {
                let mut p = f([row[0], row[1], row[2]]);
                if normals {
                    p = unit(p).unwrap_or(p);
                }
                row.assign(&ndarray::arr1(&p));
            }
            out
        };
        let positions = map(&self.positions, &position, false);
        super::validate::check_positions(positions.view())?;
        Ok(Mesh {
            positions,
            normals: map(&self.normals, &normal, true),
            triangles: self.triangles.clone(),
        })
    }
}

/// The checks of every mesh's positions and triangles: positions `(V, 3)`, finite and in
/// range, at least one triangle, and every index below `V`.
fn check_geometry(positions: ArrayView2<'_, f64>, triangles: &[[u32; 3]]) -> Result<()> {
    if positions.ncols() != 3 {
        return Err(Error::shape(positions.shape(), "positions must be (V, 3)"));
    }
    if triangles.is_empty() {
        return Err(SceneError::NoFaces.into());
    }
    let vertices = positions.nrows();
    for (triangle, t) in triangles.iter().enumerate() {
        if let Some(&index) = t.iter().find(|&&i| i as usize >= vertices) {
            return Err(SceneError::IndexOutOfRange {
                triangle,
                index: index.into(),
                vertices,
            }
            .into());
        }
    }
    check_finite(positions, "position")?;
    super::validate::check_positions(positions)
}

/// Checks that normals given for `vertices` vertices are `(V, 3)` and finite.
fn check_normals(normals: ArrayView2<'_, f64>, vertices: usize) -> Result<()> {
    if normals.dim() != (vertices, 3) {
        return Err(Error::shape(
            normals.shape(),
            format!("normals must be ({vertices}, 3), one per vertex"),
        ));
    }
    check_finite(normals, "normal")
}

/// The first non-finite entry of a `(V, 3)` array as an error.
fn check_finite(a: ArrayView2<'_, f64>, what: &'static str) -> Result<()> {
    for (vertex, row) in a.outer_iter().enumerate() {
        if let Some(&value) = row.iter().find(|x| !x.is_finite()) {
            return Err(SceneError::NonFinite {
                vertex,
                what,
                value,
            }
            .into());
        }
    }
    Ok(())
}

/// Area-weighted vertex normals; see the [module docs](self).
fn area_weighted_normals(positions: ArrayView2<'_, f64>, triangles: &[[u32; 3]]) -> Array2<f64> {
    let mut sum = Array2::<f64>::zeros(positions.raw_dim());
    let p = |i: u32| {
        let r = positions.row(i as usize);
        [r[0], r[1], r[2]]
    };
    for t in triangles {
        let (a, b, c) = (p(t[0]), p(t[1]), p(t[2]));
        let n = cross(sub(b, a), sub(c, a));
        for &i in t {
            let mut row = sum.row_mut(i as usize);
            for k in 0..3 {
                row[k] += n[k];
            }
        }
    }
    for mut row in sum.outer_iter_mut() {
        if let Some(u) = unit([row[0], row[1], row[2]]) {
            row.assign(&ndarray::arr1(&u));
        }
    }
    sum
}

/// How far from 1 the squared length of a stored normal may be ([`Mesh::stored`]): [`unit`]
/// leaves a few units in the last place (`~1e-16`); a normal that was never normalised, or
/// damaged, is off by far more.
const UNIT_TOLERANCE: f64 = 1e-12;

/// `n / |n|`, or `None` for the zero vector: the one normalisation of every mesh's normals.
/// A vector whose squared length leaves f64's normal range (components below about 1e-154
/// or above 1e154) is first divided by its largest component, so that the result is unit to
/// a few ulps whatever the magnitude (what [`Mesh::stored`] checks); any other vector gets
/// plainly `n / |n|`.
pub(crate) fn unit(n: [f64; 3]) -> Option<[f64; 3]> {
    let squared = dot(n, n);
    let n = if squared.is_normal() && squared.is_finite() {
        n
    } else {
        let largest = n.iter().fold(0.0_f64, |m, x| m.max(x.abs()));
        if largest == 0.0 {
            return None;
        }
        n.map(|x| x / largest)
    };
    let len = dot(n, n).sqrt();
    Some(n.map(|x| x / len))
}

pub(crate) fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

pub(crate) fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

pub(crate) fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// Triangles of a polygon as a fan from its first vertex.
fn fan(polygon: &[u32], triangles: &mut Vec<[u32; 3]>) {
    for k in 1..polygon.len().saturating_sub(1) {
        triangles.push([polygon[0], polygon[k], polygon[k + 1]]);
    }
}

/// A parse failure as one line: the PLY reader's messages span several lines (the line, the
/// string, the nested error), and an error is printed on one.
pub(crate) fn corrupt(reason: impl std::fmt::Display) -> Error {
    let reason = reason.to_string();
    SceneError::Corrupt(reason.split_whitespace().collect::<Vec<_>>().join(" ")).into()
}

pub(crate) fn read_ply(path: &Path) -> Result<MeshAsset> {
    use ply_rs_bw::parser::Parser;
    use ply_rs_bw::ply::{DefaultElement, Property};
    let file =
        std::fs::File::open(path).map_err(|source| crate::Error::io(path.to_path_buf(), source))?;
    let ply = Parser::<DefaultElement>::new()
        .read_ply(&mut std::io::BufReader::new(file))
        .map_err(corrupt)?;
    let scalar = |p: &Property| -> Option<f64> {
        Some(match *p {
            Property::Char(x) => x.into(),
            Property::UChar(x) => x.into(),
            Property::Short(x) => x.into(),
            Property::UShort(x) => x.into(),
            Property::Int(x) => x.into(),
            Property::UInt(x) => x.into(),
            Property::Float(x) => x.into(),
            Property::Double(x) => x,
            _ => return None,
        })
    };
    let list = |p: &Property| -> Option<Vec<i64>> {
        Some(match p {
            Property::ListChar(v) => v.iter().map(|&x| x.into()).collect(),
            Property::ListUChar(v) => v.iter().map(|&x| x.into()).collect(),
            Property::ListShort(v) => v.iter().map(|&x| x.into()).collect(),
            Property::ListUShort(v) => v.iter().map(|&x| x.into()).collect(),
            Property::ListInt(v) => v.iter().map(|&x| x.into()).collect(),
            Property::ListUInt(v) => v.iter().map(|&x| x.into()).collect(),
            _ => return None,
        })
    };
    let empty = Vec::new();
    let vertices = ply.payload.get("vertex").unwrap_or(&empty);
    let faces = ply.payload.get("face").unwrap_or(&empty);
    let read3 = |e: &DefaultElement, names: [&str; 3]| -> Option<[f64; 3]> {
        let mut out = [0.0; 3];
        for (o, name) in out.iter_mut().zip(names) {
            *o = scalar(e.get(name)?)?;
        }
        Some(out)
    };
    let mut positions = Array2::zeros((vertices.len(), 3));
    let mut normals = Array2::zeros((vertices.len(), 3));
    let mut has_normals = !vertices.is_empty();
    let has_colour = vertices.first().is_some_and(|e| e.contains_key("red"));
    let mut albedo = Array2::<f32>::zeros((if has_colour { vertices.len() } else { 0 }, 3));
    for (k, e) in vertices.iter().enumerate() {
        let p = read3(e, ["x", "y", "z"])
            .ok_or_else(|| corrupt(format!("vertex {k} has no numeric x, y and z")))?;
        positions.row_mut(k).assign(&ndarray::arr1(&p));
        match read3(e, ["nx", "ny", "nz"]) {
            Some(n) => normals.row_mut(k).assign(&ndarray::arr1(&n)),
            None => has_normals = false,
        }
        if has_colour {
            let rgb = ply_colour(e).map_err(|why| corrupt(format!("vertex {k}: {why}")))?;
            albedo.row_mut(k).assign(&ndarray::arr1(&rgb));
        }
    }
    let mut triangles = Vec::with_capacity(faces.len());
    let v = vertices.len();
    for (k, e) in faces.iter().enumerate() {
        let indices = e
            .get("vertex_indices")
            .or_else(|| e.get("vertex_index"))
            .and_then(list)
            .ok_or_else(|| corrupt(format!("face {k} has no vertex_indices list")))?;
        let mut polygon = Vec::with_capacity(indices.len());
        for &i in &indices {
            match u32::try_from(i) {
                Ok(i) if (i as usize) < v => polygon.push(i),
                _ => {
                    return Err(SceneError::IndexOutOfRange {
                        triangle: triangles.len(),
                        index: i as u64,
                        vertices: v,
                    }
                    .into());
                }
            }
        }
        fan(&polygon, &mut triangles);
    }
    Ok(MeshAsset {
        mesh: Mesh::new(positions, triangles, has_normals.then_some(normals))?,
        albedo: has_colour.then_some(albedo),
        warnings: Vec::new(),
    })
}

/// A PLY vertex's `red green blue` as linear RGB: `uchar` (or `ushort`) as sRGB-encoded
/// (divided by 255 or 65535, then [`srgb_to_linear`]), what scanners and exporters write;
/// `float` or `double` as linear and in `[0, 1]`, as written by programs that store
/// radiometric colour. Any other type, a missing channel, or a float outside `[0, 1]` is
/// refused.
fn ply_colour(e: &ply_rs_bw::ply::DefaultElement) -> std::result::Result<[f32; 3], String> {
    use ply_rs_bw::ply::Property;
    let mut out = [0.0f32; 3];
    for (o, name) in out.iter_mut().zip(["red", "green", "blue"]) {
        *o = match e.get(name) {
            Some(Property::UChar(x)) => srgb_to_linear(f64::from(*x) / 255.0) as f32,
            Some(Property::UShort(x)) => srgb_to_linear(f64::from(*x) / 65535.0) as f32,
            Some(Property::Float(x)) if (0.0..=1.0).contains(x) => *x,
            Some(Property::Double(x)) if (0.0..=1.0).contains(x) => *x as f32,
            Some(Property::Float(_) | Property::Double(_)) => {
                return Err(format!("a float {name} outside [0, 1]"));
            }
            Some(_) => return Err(format!("{name} is neither uchar, ushort, float nor double")),
            None => return Err(format!("no {name} beside the first vertex's colour")),
        };
    }
    Ok(out)
}

#[cfg(test)]
#[path = "mesh_tests.rs"]
mod tests;
