//! The ground plane under a scene (see the [module docs](super)): a square grid at the
//! scene's lowest `y` that receives its shadows.

use crate::Result;
use crate::relight::Mesh;
use crate::relight::scene::shapes::grid;
use crate::relight::scene::validate;

/// Cells per side of the ground plane's grid.
pub const GROUND_CELLS: usize = 32;

/// Vertices the ground plane adds: `(GROUND_CELLS + 1)^2`.
pub const GROUND_VERTICES: usize = (GROUND_CELLS + 1) * (GROUND_CELLS + 1);

/// Of `vertices`, those of the objects: all but the ground plane's (the last
/// [`GROUND_VERTICES`]) when there is one.
///
/// ```
/// use haarshift::relight::scene::{GROUND_VERTICES, object_vertices};
/// assert_eq!(object_vertices(GROUND_VERTICES + 54, true), 54);
/// assert_eq!(object_vertices(54, false), 54);
/// ```
pub fn object_vertices(vertices: usize, ground_plane: bool) -> usize {
    let ground = if ground_plane { GROUND_VERTICES } else { 0 };
    vertices.saturating_sub(ground)
}

/// The ground plane's albedo in a scene file.
pub const GROUND_ALBEDO: [f32; 3] = [0.8, 0.8, 0.8];

/// A horizontal grid facing `+Y` over `[x0, x0 + side] x [z0 - side, z0]` at height `y`.
pub(crate) fn ground(x0: f64, z0: f64, y: f64, side: f64, cells: usize) -> Result<Mesh> {
    grid(
        [x0, y, z0],
        [side, 0.0, 0.0],
        [0.0, 0.0, -side],
        cells,
        cells,
    )
}

/// Appends the ground plane described in the [module docs](super) to `mesh`.
///
/// ```
/// use haarshift::relight::{Generator, add_ground_plane};
/// let mut m = Generator::Sphere { cells: 4 }.mesh().unwrap();
/// let before = m.vertex_count();
/// add_ground_plane(&mut m).unwrap();
/// assert_eq!(m.vertex_count(), before + 33 * 33);
/// let b = m.bounds();
/// assert_eq!((b.min[1], b.max[0]), (-1.0, 4.0)); // at the lowest y, side 4 x 2
/// ```
///
/// Errors as [`ground_plane_under`] does.
pub fn add_ground_plane(mesh: &mut Mesh) -> Result<()> {
    mesh.append(&ground_plane_under(&mesh.bounds())?);
    Ok(())
}

/// The ground plane [`add_ground_plane`] puts under a scene of bounding box `b`, on its own.
///
/// ```
/// use haarshift::relight::{Generator, scene::ground_plane_under};
/// let ball = Generator::Sphere { cells: 4 }.mesh().unwrap();
/// let ground = ground_plane_under(&ball.bounds()).unwrap();
/// assert_eq!((ground.vertex_count(), ground.bounds().min[1]), (33 * 33, -1.0));
/// ```
///
/// Errors when the box has no horizontal extent to size the plane by
/// ([`check_ground_extent`](crate::relight::scene::validate::check_ground_extent)), or when the plane would
/// reach beyond [`MAX_COORDINATE`](crate::relight::scene::validate::MAX_COORDINATE).
pub fn ground_plane_under(b: &crate::relight::Bounds) -> Result<Mesh> {
    crate::relight::scene::validate::check_ground_extent(b)?;
    let side = 4.0 * (b.max[0] - b.min[0]).max(b.max[2] - b.min[2]);
    let c = b.centre();
    let (x0, z0) = (c[0] - 0.5 * side, c[2] + 0.5 * side);
    for corner in [[x0, b.min[1], z0], [x0 + side, b.min[1], z0 - side]] {
        validate::check_point("the ground plane's corner", corner)?;
    }
    ground(x0, z0, b.min[1], side, GROUND_CELLS)
}
