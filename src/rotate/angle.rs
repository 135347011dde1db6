//! The angle of a rotation: exact quarter turns and a residual in `[-45, 45]` degrees for the
//! shears, and the size of the canvas that holds the turned image.

use ndarray::{Array2, ArrayView2, s};

use super::Canvas;
use crate::kernels::transpose;
use crate::{Error, Result};

/// An angle split into exact quarter turns and a residual.
///
/// ```
/// let r = haarshift::rotate::reduce_angle(1e6).unwrap();
/// assert_eq!((r.quarter_turns, r.residual_deg), (3, 10.0));
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ReducedAngle {
    /// Counter-clockwise quarter turns, `0..4`.
    pub quarter_turns: u8,
    /// The rest, in `[-45, 45]` degrees.
    pub residual_deg: f64,
}

/// Splits `deg` into `quarter_turns * 90 + residual_deg` modulo 360, exactly: `deg % 360` is
/// exact in floating point, and so is subtracting the nearest multiple of 90 (the two are
/// within a factor of two). Halfway cases (45, 135, ...) go to an even number of quarter turns.
///
/// ```
/// use haarshift::rotate::reduce_angle;
/// let r = reduce_angle(-180.0).unwrap();
/// assert_eq!((r.quarter_turns, r.residual_deg), (2, 0.0));
/// let nan = reduce_angle(f64::NAN);
/// assert!(matches!(nan, Err(haarshift::Error::InvalidParameter { name: "angle", .. })));
/// ```
pub fn reduce_angle(deg: f64) -> Result<ReducedAngle> {
    if !deg.is_finite() {
        return Err(Error::parameter(
            "angle",
            format!("{deg} is not a finite number of degrees"),
        ));
    }
    let r = deg % 360.0;
    let q = (r / 90.0).round_ties_even();
    let residual = r - 90.0 * q;
    Ok(ReducedAngle {
        quarter_turns: (q as i64).rem_euclid(4) as u8,
        // -0.0 and 0.0 are the same rotation; report the plain zero.
        residual_deg: residual + 0.0,
    })
}

/// `plane` turned counter-clockwise (as displayed) by `turns` quarter turns: a copy, no
/// arithmetic (`np.rot90`).
///
/// ```
/// use ndarray::array;
/// let t = haarshift::rotate::quarter_turn(array![[1, 2, 3], [4, 5, 6]].view(), 1);
/// assert_eq!(t, array![[3, 6], [2, 5], [1, 4]]);
/// ```
pub fn quarter_turn<A: Copy + Default + Send + Sync>(
    plane: ArrayView2<'_, A>,
    turns: u8,
) -> Array2<A> {
    match turns % 4 {
        0 => plane.to_owned(),
        1 => transpose(plane).slice(s![..;-1, ..]).to_owned(),
        2 => plane.slice(s![..;-1, ..;-1]).to_owned(),
        _ => transpose(plane.slice(s![..;-1, ..])),
    }
}

/// The [`Canvas::Expand`] size `(rows, cols)` of an `h x w` image turned by `deg`:
/// `round(w|cos| + h|sin|)` columns and `round(w|sin| + h|cos|)` rows, with the quarter turns
/// exact.
///
/// ```
/// use haarshift::rotate::expanded_size;
/// assert_eq!(expanded_size(100, 100, 45.0).unwrap(), (141, 141));
/// assert_eq!(expanded_size(30, 50, 90.0).unwrap(), (50, 30));
/// ```
pub fn expanded_size(h: usize, w: usize, deg: f64) -> Result<(usize, usize)> {
    let r = reduce_angle(deg)?;
    let (h1, w1) = if r.quarter_turns % 2 == 1 {
        (w, h)
    } else {
        (h, w)
    };
    let t = r.residual_deg.to_radians();
    let (sin, cos) = (t.sin().abs(), t.cos().abs());
    let (h1, w1) = (h1 as f64, w1 as f64);
    let rows = (w1 * sin + h1 * cos + 0.5).floor();
    let cols = (w1 * cos + h1 * sin + 0.5).floor();
    Ok((rows.max(1.0) as usize, cols.max(1.0) as usize))
}

/// Whether rotating an `h x w` image by `deg` onto `canvas` only moves pixels: a multiple of 90
/// degrees whose centre stays on the pixel grid.
pub(super) fn is_pure_copy(h: usize, w: usize, deg: f64, canvas: Canvas) -> Result<bool> {
    let r = reduce_angle(deg)?;
    Ok(r.residual_deg == 0.0
        && (canvas == Canvas::Expand
            || r.quarter_turns.is_multiple_of(2)
            || h.abs_diff(w).is_multiple_of(2)))
}
