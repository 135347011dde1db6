//! The ground plane under a scene (see the [module docs](super)): a square grid at the
//! scene's lowest `y` that receives its shadows, of [`GROUND_CELLS`] cells per side unless
//! asked otherwise (`--ground-cells`, a scene file's `"ground_cells"`).

use crate::Mesh;
use crate::scene::shapes::grid;
use crate::scene::validate;
use crate::{Error, Result};

/// Cells per side of the ground plane's grid by default.
pub const GROUND_CELLS: usize = 32;

/// The most cells per side a ground plane may have: `(1024 + 1)^2` vertices, about a
/// million, beyond which a denser grid everywhere costs more than any shadow needs.
pub const MAX_GROUND_CELLS: usize = 1024;

/// Vertices the default ground plane adds: `(GROUND_CELLS + 1)^2`.
pub const GROUND_VERTICES: usize = ground_vertices(GROUND_CELLS);

/// Vertices a ground plane of `cells` cells per side adds: `(cells + 1)^2`.
///
/// ```
/// use haarshift_relight::scene::{GROUND_VERTICES, ground_vertices};
/// assert_eq!((ground_vertices(32), ground_vertices(64)), (GROUND_VERTICES, 65 * 65));
/// ```
pub const fn ground_vertices(cells: usize) -> usize {
    (cells + 1) * (cells + 1)
}

/// Refuses a ground plane of other than `1..=`[`MAX_GROUND_CELLS`] cells per side.
///
/// ```
/// use haarshift_relight::scene::check_ground_cells;
/// assert!(check_ground_cells(64).is_ok());
/// let err = check_ground_cells(0).unwrap_err().to_string();
/// assert!(err.contains("0 cells per side"), "{err}");
/// assert!(check_ground_cells(1025).is_err());
/// ```
pub fn check_ground_cells(cells: usize) -> Result<()> {
    if (1..=MAX_GROUND_CELLS).contains(&cells) {
        return Ok(());
    }
    Err(Error::parameter(
        "ground cells",
        format!("{cells} cells per side: a ground plane takes 1 to {MAX_GROUND_CELLS}"),
    ))
}

/// Of `vertices`, those of the objects: all but the ground plane's, which are the last
/// `ground_vertices` (0 without a ground plane).
///
/// ```
/// use haarshift_relight::scene::{GROUND_VERTICES, object_vertices};
/// assert_eq!(object_vertices(GROUND_VERTICES + 54, GROUND_VERTICES), 54);
/// assert_eq!(object_vertices(54, 0), 54);
/// ```
pub fn object_vertices(vertices: usize, ground_vertices: usize) -> usize {
    vertices.saturating_sub(ground_vertices)
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

/// Appends the default ground plane described in the [module docs](super) to `mesh`
/// ([`GROUND_CELLS`] cells per side).
///
/// ```
/// use haarshift_relight::{Generator, add_ground_plane};
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
    mesh.append(&ground_plane_under(&mesh.bounds(), GROUND_CELLS)?);
    Ok(())
}

/// The ground plane [`add_ground_plane`] puts under a scene of bounding box `b`, on its own,
/// of `cells` cells per side.
///
/// ```
/// use haarshift_relight::{Generator, scene::ground_plane_under};
/// let ball = Generator::Sphere { cells: 4 }.mesh().unwrap();
/// let ground = ground_plane_under(&ball.bounds(), 32).unwrap();
/// assert_eq!((ground.vertex_count(), ground.bounds().min[1]), (33 * 33, -1.0));
/// assert_eq!(ground_plane_under(&ball.bounds(), 64).unwrap().vertex_count(), 65 * 65);
/// assert!(ground_plane_under(&ball.bounds(), 0).is_err());
/// ```
///
/// Errors when `cells` is outside [`check_ground_cells`]'s range, when the box has no
/// horizontal extent to size the plane by
/// ([`check_ground_extent`](crate::scene::validate::check_ground_extent)), or when the plane would
/// reach beyond [`MAX_COORDINATE`](crate::scene::validate::MAX_COORDINATE).
pub fn ground_plane_under(b: &crate::Bounds, cells: usize) -> Result<Mesh> {
    check_ground_cells(cells)?;
    crate::scene::validate::check_ground_extent(b)?;
    let side = 4.0 * (b.max[0] - b.min[0]).max(b.max[2] - b.min[2]);
    let c = b.centre();
    let (x0, z0) = (c[0] - 0.5 * side, c[2] + 0.5 * side);
    for corner in [[x0, b.min[1], z0], [x0 + side, b.min[1], z0 - side]] {
        validate::check_point("the ground plane's corner", corner)?;
    }
    ground(x0, z0, b.min[1], side, cells)
}
