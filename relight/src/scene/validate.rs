//! The checks a scene passes once, between parsing and everything else: what the BVH, the
//! ground plane and the camera need of their input, stated as ranges.
//!
//! * **Coordinates** (vertex positions after every transform, camera positions and points
//!   looked at) are finite and within [`MAX_COORDINATE`] of the origin. The BVH ([`obvhs`]
//!   0.4) converts positions to f32 and assumes finite boxes whose Morton codes and surface
//!   areas it can compute: a coordinate beyond `f32::MAX` becomes infinite there and its
//!   wide-BVH conversion indexes out of bounds. `1e15` leaves the squares and cross products
//!   of differences (`~1e30`) far inside f32 and f64.
//! * **A ground plane** needs a horizontal extent (the mesh's width or depth) that is positive
//!   and large enough against its distance from the origin for the plane's corners to differ
//!   in f32 ([`check_ground_extent`]), so that its normal exists.
//! * **Counts** that size allocations (generator cells, path frames) are summed and multiplied
//!   with checked arithmetic ([`grid_vertices`]), so that no count wraps around a limit.
//! * **Memory**: a scene file's generators make meshes of any size from a few bytes, so
//!   their vertex count is known before anything is built, and a [`MemoryBudget`] (by
//!   default the image readers' [`DEFAULT_MEMORY_LIMIT`], 4 GiB) refuses it when the mesh,
//!   its BVH and what the caller will store per vertex (a precomputation's transport) would
//!   not fit. Mesh files are not estimated: their reader's memory is bounded by the file.
//!
//! Failures are [`SceneError`]s naming the field; the caller adds the file.

use ndarray::{ArrayView1, ArrayView2};

use super::mesh::Bounds;
use crate::Result;
use crate::SceneError;

pub use haarshift::io::DEFAULT_MEMORY_LIMIT;

/// The largest distance from the origin of any coordinate in a scene; see the
/// [module docs](self).
///
/// ```
/// use haarshift_relight::scene::validate::{MAX_COORDINATE, check_point};
/// assert!(check_point("camera", [0.0, MAX_COORDINATE, 0.0]).is_ok());
/// let far = check_point("camera", [0.0, 1e308, 0.0]);
/// assert!(matches!(far, Err(haarshift_relight::Error::Scene { .. })));
/// ```
pub const MAX_COORDINATE: f64 = 1e15;

/// The smallest horizontal extent of a mesh under a ground plane, relative to its largest
/// coordinate: above f32's relative precision (`1.2e-7`), so the plane's corners are distinct
/// points once the BVH converts them.
pub const MIN_GROUND_EXTENT_RATIO: f64 = 1e-6;

/// Whether `v` is finite and within [`MAX_COORDINATE`] of zero (a NaN is not).
///
/// ```
/// use haarshift_relight::scene::validate::in_range;
/// assert!(in_range(-1e15) && !in_range(2e15) && !in_range(f64::NAN));
/// ```
pub fn in_range(v: f64) -> bool {
    v.abs() <= MAX_COORDINATE
}

/// Checks that `point` is finite and within [`MAX_COORDINATE`] of the origin in every
/// coordinate; `what` names it in the error.
pub fn check_point(what: &str, point: [f64; 3]) -> Result<()> {
    match point.iter().find(|v| !in_range(**v)) {
        Some(v) => Err(SceneError::OutOfRange {
            what: what.to_owned(),
            value: *v,
        }
        .into()),
        None => Ok(()),
    }
}

/// Checks every row of a `(V, 3)` array of vertex positions with [`check_point`]; the error
/// names the first vertex out of range.
pub fn check_positions(positions: ArrayView2<'_, f64>) -> Result<()> {
    let outside = |r: &ArrayView1<'_, f64>| r.iter().any(|&v| !in_range(v));
    match positions.outer_iter().position(|r| outside(&r)) {
        Some(k) => {
            let r = positions.row(k);
            check_point(&format!("vertex {k}"), [r[0], r[1], r[2]])
        }
        None => Ok(()),
    }
}

/// Checks that a ground plane can go under a mesh of bounding box `bounds`: a positive
/// horizontal extent (width or depth) of at least [`MIN_GROUND_EXTENT_RATIO`] times its
/// largest coordinate.
///
/// ```
/// use haarshift_relight::Bounds;
/// use haarshift_relight::scene::validate::check_ground_extent;
/// let unit = Bounds { min: [0.0; 3], max: [1.0; 3] };
/// assert!(check_ground_extent(&unit).is_ok());
/// let line = Bounds { min: [1.0, 0.0, 1.0], max: [1.0, 5.0, 1.0] }; // vertical
/// assert!(matches!(check_ground_extent(&line), Err(haarshift_relight::Error::Scene { .. })));
/// ```
pub fn check_ground_extent(bounds: &Bounds) -> Result<()> {
    let extent = (bounds.max[0] - bounds.min[0]).max(bounds.max[2] - bounds.min[2]);
    let largest = bounds
        .min
        .iter()
        .chain(&bounds.max)
        .fold(0.0f64, |m, v| m.max(v.abs()));
    if extent.is_finite() && extent > 0.0 && extent >= MIN_GROUND_EXTENT_RATIO * largest {
        return Ok(());
    }
    Err(SceneError::NoGroundExtent { extent, largest }.into())
}

/// The vertices of a `cells x cells` grid, `(cells + 1)^2`, or `None` when that does not fit
/// in a `usize` (checked: `cells + 1` itself may wrap).
///
/// ```
/// use haarshift_relight::scene::validate::grid_vertices;
/// assert_eq!(grid_vertices(2), Some(9));
/// assert_eq!(grid_vertices(usize::MAX), None);
/// assert_eq!(grid_vertices(1 << 32), None);
/// ```
pub fn grid_vertices(cells: usize) -> Option<usize> {
    let side = cells.checked_add(1)?;
    side.checked_mul(side)
}

/// The bytes one vertex of a scene holds while it is loaded, its BVH built and its cache
/// written, about two triangles a vertex: the mesh (positions and normals in f64, albedo in
/// f32, indices: 84 bytes), the BVH's f32 triangles and its build, and the file's copy of
/// the mesh. Measured: `haarshift relight precompute s.json --resolution 2 -o s.hsr` with
/// `s.json` = `{"objects":[{"generator":{"sphere":{"cells":300}}}]}` (543,606 vertices)
/// reports a peak of 342.9 MiB, 646 bytes a vertex, about 136 of them its 8-texel transport
/// and file copy of it; the remaining 510 leave 640 a quarter to spare.
pub const MESH_BYTES_PER_VERTEX: u64 = 640;

/// How much memory a scene and the work on it may take, checked from its vertex count
/// before anything is built: [`MESH_BYTES_PER_VERTEX`] times the vertices, plus `per_vertex`
/// (what the caller stores for each vertex, e.g. a precomputation's transport) times the
/// vertices of the largest of `shards` equal shares, against `limit`; more is an
/// [`Error::MemoryBudget`](haarshift::Error::MemoryBudget).
///
/// ```
/// use haarshift_relight::scene::validate::{DEFAULT_MEMORY_LIMIT, MemoryBudget};
/// let budget = MemoryBudget::default();
/// assert_eq!((budget.limit, budget.per_vertex, budget.shards), (DEFAULT_MEMORY_LIMIT, 0, 1));
/// assert!(budget.check("the scene", 1_000_000).is_ok());
/// let err = budget.check("the scene", 100_000_000).unwrap_err();
/// assert!(matches!(err, haarshift_relight::Error::Core(haarshift::Error::MemoryBudget { .. })));
/// assert!(err.to_string().starts_with("the scene (100000000 vertices) needs"));
/// ```
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct MemoryBudget {
    /// The most bytes the scene and its work may hold at once.
    pub limit: u64,
    /// Bytes each stored vertex needs beyond [`MESH_BYTES_PER_VERTEX`].
    pub per_vertex: u64,
    /// The work is split into this many shares of the vertices (shards), each storing
    /// `per_vertex` for its own; 0 counts as 1.
    pub shards: u64,
}

impl Default for MemoryBudget {
    fn default() -> Self {
        MemoryBudget {
            limit: DEFAULT_MEMORY_LIMIT,
            per_vertex: 0,
            shards: 1,
        }
    }
}

/// A memory limit as people write it (`--memory-limit`): a number of bytes with an optional
/// unit (`4GiB`, `512 MiB`, `2G`), more than 0.
///
/// ```
/// use haarshift_relight::scene::validate::parse_memory_limit;
/// assert_eq!(parse_memory_limit("4GiB").unwrap(), 4 << 30);
/// assert_eq!(parse_memory_limit("512 MiB").unwrap(), 512 << 20);
/// let err = parse_memory_limit("0").unwrap_err().to_string();
/// assert_eq!(err, "invalid memory limit: must be more than 0 bytes");
/// assert!(parse_memory_limit("lots").is_err());
/// ```
pub fn parse_memory_limit(s: &str) -> crate::Result<u64> {
    match s.parse::<bytesize::ByteSize>() {
        Ok(size) => check_memory_limit(size.as_u64()),
        Err(e) => Err(crate::Error::parameter(
            "memory limit",
            format!("{s:?}: {e}"),
        )),
    }
}

/// `limit` bytes, refused when 0 (nothing fits).
///
/// ```
/// use haarshift_relight::scene::validate::check_memory_limit;
/// assert_eq!(check_memory_limit(1 << 30).unwrap(), 1 << 30);
/// assert!(check_memory_limit(0).is_err());
/// ```
pub fn check_memory_limit(limit: u64) -> crate::Result<u64> {
    match limit {
        0 => Err(crate::Error::parameter(
            "memory limit",
            "must be more than 0 bytes",
        )),
        _ => Ok(limit),
    }
}

impl MemoryBudget {
    /// The bytes `vertices` vertices need under this budget (in `u128`: no count wraps).
    pub fn needed(&self, vertices: u128) -> u128 {
        let stored = vertices.div_ceil(u128::from(self.shards.max(1)));
        vertices
            .saturating_mul(u128::from(MESH_BYTES_PER_VERTEX))
            .saturating_add(stored.saturating_mul(u128::from(self.per_vertex)))
    }

    /// Refuses `vertices` vertices whose [`needed`](Self::needed) bytes exceed the limit;
    /// `what` names them in the error.
    pub fn check(&self, what: &str, vertices: u128) -> Result<()> {
        let needed = self.needed(vertices);
        if needed <= u128::from(self.limit) {
            return Ok(());
        }
        Err(crate::Error::from(haarshift::Error::MemoryBudget {
            what: format!("{what} ({vertices} vertices)"),
            needed,
            budget: u128::from(self.limit),
        }))
    }
}

#[cfg(test)]
#[path = "validate_tests.rs"]
mod tests;
