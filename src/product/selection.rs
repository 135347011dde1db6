//! Nonlinear approximation: which detail coefficients a tree keeps.
//!
//! **Rule.** Every face's scaling coefficient is always kept. Of the detail coefficients
//! (orthonormal normalisation), [`Selection::Largest`]`(K)` keeps the `K` largest by magnitude
//! over all faces together, [`Selection::LargestPerFace`]`(K)` the `K` largest of each face,
//! [`Selection::Threshold`]`(t)` every one of magnitude greater than `t`, [`Selection::All`]
//! every one. Ties are broken by index ascending, where the index of a coefficient is its
//! row-major position in the Mallat array of the whole function ([`FaceLayout`]): for
//! [`FaceLayout::SideBySide`] (lat-long, `H x 2H`) the position in that `S x (F S)` array,
//! for [`FaceLayout::Stacked`] (a cube map) `face x S^2 +` the position in the face's own
//! `S x S` array. So for one channel the rule is exactly: sort by `|c|` descending, ties by
//! index ascending, keep the first `K`.
//!
//! **Several channels.** A coefficient's magnitude is the root of the sum of the squares of its
//! channels (so an RGB coefficient is kept or dropped as a whole, and a grey map broadcast to
//! three channels keeps the same coefficients as the grey map).

use crate::named::named_enum;
use crate::{Error, Result};

named_enum! {
    /// How the faces of a function are laid out in its Mallat array: it decides only the
    /// index that breaks ties in a [`Selection`].
    #[derive(Default)]
    pub enum FaceLayout ("face layout") {
        #[default]
        /// Face after face (`(faces, S, S)`, a cube map).
        Stacked = "stacked",
        /// Faces side by side in one `S x (faces S)` array (a lat-long map: `H x 2H`, two faces).
        SideBySide = "side-by-side",
    }
}

impl FaceLayout {
    /// Row-major index, in the whole function's Mallat array, of detail `band` (0 `H`, 1 `V`,
    /// 2 `D`) of node `(level, row, col)` of `face`, for `faces` faces of side `s`.
    ///
    /// ```
    /// use haarshift::product::FaceLayout;
    /// // A 4 x 8 lat-long array: the H detail of level 0 of the right face sits at (0, 3).
    /// assert_eq!(FaceLayout::SideBySide.index(2, 4, 1, 0, 0, 0, 0), 3);
    /// assert_eq!(FaceLayout::Stacked.index(2, 4, 1, 0, 0, 0, 0), 16 + 1);
    /// ```
    #[allow(clippy::too_many_arguments)]
    pub fn index(
        self,
        faces: usize,
        s: usize,
        face: usize,
        band: usize,
        level: usize,
        row: usize,
        col: usize,
    ) -> u64 {
        let side = 1usize << level;
        // Position of the coefficient inside its face's own S x S Mallat array.
        let (r, c) = match band {
            0 => (row, side + col),
            1 => (side + row, col),
            _ => (side + row, side + col),
        };
        match self {
            FaceLayout::Stacked => (face * s * s + r * s + c) as u64,
            FaceLayout::SideBySide => {
                // In the S x (F S) array a band of level l is 2^l x F 2^l, faces side by side.
                let c = match band {
                    1 => face * side + col,
                    _ => faces * side + face * side + col,
                };
                (r * faces * s + c) as u64
            }
        }
    }
}

/// Which detail coefficients a tree keeps; see the [module docs](self).
///
/// ```
/// use haarshift::product::Selection;
/// assert_eq!(Selection::Largest(200).limit(1000).unwrap(), Some(200));
/// let too_many = Selection::Largest(2000).limit(1000);
/// assert!(matches!(too_many, Err(haarshift::Error::InvalidParameter { name: "keep", .. })));
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Selection {
    /// Every coefficient (the complete tree).
    All,
    /// The `K` largest details over all faces together.
    Largest(usize),
    /// The `K` largest details of each face.
    LargestPerFace(usize),
    /// Every detail of magnitude greater than this (finite, non-negative).
    Threshold(f64),
}

impl Selection {
    /// The count this selection keeps out of `available` candidates (`None`: no count limit),
    /// or an error when it asks for more than there are or names a bad threshold.
    pub fn limit(self, available: usize) -> Result<Option<usize>> {
        match self {
            Selection::All => Ok(None),
            Selection::Largest(k) | Selection::LargestPerFace(k) if k > available => {
                Err(Error::parameter(
                    "keep",
                    format!("{k} coefficients asked for but there are only {available} details"),
                ))
            }
            Selection::Largest(k) | Selection::LargestPerFace(k) => Ok(Some(k)),
            Selection::Threshold(t) if !(t.is_finite() && t >= 0.0) => Err(Error::parameter(
                "threshold",
                format!("{t} is not a finite non-negative number"),
            )),
            Selection::Threshold(_) => Ok(None),
        }
    }

    /// The selections of the command line's `--keep K[,K...]` (one count for every map, or one
    /// per map), `--threshold T` and `--per-face`: empty (keep everything) when none is given.
    ///
    /// ```
    /// use haarshift::product::Selection;
    /// assert_eq!(Selection::from_counts(&[200, 70], None, false).unwrap(),
    ///            [Selection::Largest(200), Selection::Largest(70)]);
    /// assert_eq!(Selection::from_counts(&[], Some(0.5), false).unwrap(), [Selection::Threshold(0.5)]);
    /// assert!(Selection::from_counts(&[], None, false).unwrap().is_empty());
    /// assert!(Selection::from_counts(&[10], Some(0.5), false).is_err());
    /// assert!(Selection::from_counts(&[], None, true).is_err());
    /// ```
    pub fn from_counts(
        keep: &[usize],
        threshold: Option<f64>,
        per_face: bool,
    ) -> Result<Vec<Self>> {
        match (threshold, per_face) {
            (Some(_), _) if !keep.is_empty() => Err(Error::parameter(
                "threshold",
                "keep counts and a threshold are two different selections: give one",
            )),
            (Some(_), true) => Err(Error::parameter(
                "per_face",
                "per-face selection counts coefficients: it needs keep, not a threshold",
            )),
            (Some(t), false) => Ok(vec![Selection::Threshold(t)]),
            (None, true) if keep.is_empty() => Err(Error::parameter(
                "per_face",
                "per-face selection needs keep counts",
            )),
            (None, true) => Ok(keep.iter().map(|&k| Selection::LargestPerFace(k)).collect()),
            (None, false) => Ok(keep.iter().map(|&k| Selection::Largest(k)).collect()),
        }
    }
}

/// A detail coefficient competing for a place: its squared magnitude and tie-break index.
#[derive(Clone, Copy, Debug)]
#[doc(hidden)] // For haarshift-relight : public only for the sibling crates (crate docs).
pub struct Candidate {
    /// The coefficient's squared magnitude.
    pub magnitude2: f64,
    /// Its tie-break index.
    pub index: u64,
    /// Where the caller records the choice.
    pub slot: usize,
}

/// Keeps the `k` best candidates (largest magnitude, then smallest index) in `pool`,
/// reordering it; returns how many were kept (the first ones).
#[doc(hidden)] // For haarshift-relight : public only for the sibling crates (crate docs).
pub fn keep_largest(pool: &mut [Candidate], k: usize) -> usize {
    if k == 0 {
        return 0;
    }
    if k < pool.len() {
        pool.select_nth_unstable_by(k - 1, |a, b| {
            b.magnitude2
                .total_cmp(&a.magnitude2)
                .then(a.index.cmp(&b.index))
        });
    }
    k.min(pool.len())
}
