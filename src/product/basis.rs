//! The 2D non-standard (pyramid) Haar basis on one square face, from its definition.
//!
//! A face of side `S = 2^n` is split into a quadtree: the node `(level, row, col)` at detail
//! level `l` (`l = 0` coarsest, `2^l x 2^l` nodes) covers the block of side `S >> l` at block
//! row `row`, block column `col`. On each node live four functions ([`Band`]): the scaling
//! function (a box) and three wavelets, `Horizontal` (left half minus right half, the
//! transform's `a`), `Vertical` (top half minus bottom half, `b`) and `Diagonal` (their product,
//! `c`). The non-standard transform uses only the *restricted* basis: the face's scaling
//! function (the root node's box) and the wavelets of every node; boxes of finer nodes ("child
//! scaling functions") only appear as products.
//!
//! # Normalisation
//!
//! Values here are in Sun 2006's *continuous* normalisation: the face is the unit square and a
//! function on a level-`l` node has amplitude `2^l` (so its `L2` norm over the unit square is
//! 1). The transform's *discrete orthonormal* basis of a `2^n x 2^n` face (pixel-sum inner
//! product, [`Normalization::Orthonormal`](crate::transform::Normalization)) is the same
//! function divided by `S = 2^n` and sampled at pixel centres: `+-1 / (S >> l)` on the block
//! ([`BasisFunction::discrete`]).
//!
//! # Products of two basis functions (Sun 2006 section 3.3.2, derived here, not copied)
//!
//! [`product`] multiplies two basis functions by looking only at their definitions:
//! the sign of a function on each quadrant of its node is read off the mother function at
//! the quadrant's centre ([`quadrant_sign`]); two functions on one node multiply quadrant by
//! quadrant, and the resulting sign pattern is matched back to a band (the four patterns form
//! the Klein four-group: `H x V = D`, `H x D = V`, `V x D = H`, each squared is the box); a
//! coarser function is constant on the quadrant that holds a finer node, so it multiplies the
//! finer function by its value there (`+-2^l`, the sign of that quadrant).

use ndarray::Array2;

use crate::transform::Band;

/// The four bands in the order the trees store them: scaling first, then `H`, `V`, `D`.
pub const BANDS: [Band; 4] = [
    Band::Scaling,
    Band::Horizontal,
    Band::Vertical,
    Band::Diagonal,
];

/// The three wavelet bands, in the order trees store their coefficients.
pub const WAVELETS: [Band; 3] = [Band::Horizontal, Band::Vertical, Band::Diagonal];

/// One basis function on a square face: a band on a quadtree node.
///
/// ```
/// use haarshift::product::basis::BasisFunction;
/// use haarshift::transform::Band;
/// let root = BasisFunction::SCALING;
/// let w = BasisFunction::new(Band::Diagonal, 1, 1, 0);
/// assert!(root.contains(&w));
/// assert_eq!(w.value(0.1, 0.6), 2.0); // level 1: amplitude 2; bottom-left quadrant: +
/// ```
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct BasisFunction {
    /// Scaling (a box) or one of the three wavelets.
    pub band: Band,
    /// Detail level of the node, 0 coarsest (Sun 2006's "scale j").
    pub level: usize,
    /// Block row of the node, `0..2^level`.
    pub row: usize,
    /// Block column of the node, `0..2^level`.
    pub col: usize,
}

/// Quadrant index `q = 2 * row_bit + col_bit`: 0 top-left, 1 top-right, 2 bottom-left,
/// 3 bottom-right. Children of a node are ordered by it.
pub fn quadrant(row: usize, col: usize) -> usize {
    2 * (row & 1) + (col & 1)
}

/// The mother function of `band` on the unit square, `x` to the right, `y` down.
fn mother(band: Band, x: f64, y: f64) -> f64 {
    let left = if x < 0.5 { 1.0 } else { -1.0 };
    let top = if y < 0.5 { 1.0 } else { -1.0 };
    match band {
        Band::Scaling => 1.0,
        Band::Horizontal => left,
        Band::Vertical => top,
        Band::Diagonal => left * top,
    }
}

/// The sign of `band` on quadrant `q` of its node, read off the mother function at the
/// quadrant's centre.
///
/// ```
/// use haarshift::product::basis::quadrant_sign;
/// use haarshift::transform::Band;
/// assert_eq!(quadrant_sign(Band::Horizontal, 1), -1.0); // top-right: right half
/// assert_eq!(quadrant_sign(Band::Diagonal, 3), 1.0);
/// ```
pub fn quadrant_sign(band: Band, q: usize) -> f64 {
    let (qr, qc) = ((q >> 1) & 1, q & 1);
    mother(band, (qc as f64 + 0.5) / 2.0, (qr as f64 + 0.5) / 2.0)
}

/// The signs of the three wavelets on the four quadrants, `[q][H, V, D]`.
pub(crate) fn wavelet_signs() -> [[f64; 3]; 4] {
    std::array::from_fn(|q| WAVELETS.map(|band| quadrant_sign(band, q)))
}

/// The band whose quadrant sign pattern is `pattern`, if any.
fn band_with_pattern(pattern: [f64; 4]) -> Option<Band> {
    BANDS
        .into_iter()
        .find(|&band| (0..4).all(|q| quadrant_sign(band, q) == pattern[q]))
}

impl BasisFunction {
    /// The face's scaling function (the root node's box): constant 1 on the unit square.
    pub const SCALING: BasisFunction = BasisFunction {
        band: Band::Scaling,
        level: 0,
        row: 0,
        col: 0,
    };

    /// The function of `band` on node `(level, row, col)`.
    pub fn new(band: Band, level: usize, row: usize, col: usize) -> Self {
        BasisFunction {
            band,
            level,
            row,
            col,
        }
    }

    /// Whether this function's support (its node's block) contains `other`'s.
    pub fn contains(&self, other: &BasisFunction) -> bool {
        other.level >= self.level
            && other.row >> (other.level - self.level) == self.row
            && other.col >> (other.level - self.level) == self.col
    }

    /// The quadrant of this function's node that holds the (strictly finer) node of `finer`.
    fn quadrant_holding(&self, finer: &BasisFunction) -> usize {
        let shift = finer.level - self.level - 1;
        quadrant(finer.row >> shift, finer.col >> shift)
    }

    /// The value at `(x, y)` in the unit square (`x` right, `y` down), continuous normalisation
    /// (amplitude `2^level` on the node's block, 0 outside).
    pub fn value(&self, x: f64, y: f64) -> f64 {
        let side = (1u64 << self.level) as f64;
        let (u, v) = (x * side - self.col as f64, y * side - self.row as f64);
        if !(0.0..1.0).contains(&u) || !(0.0..1.0).contains(&v) {
            return 0.0;
        }
        side * mother(self.band, u, v)
    }

    /// The discrete orthonormal function on a `2^n x 2^n` face: the continuous function at
    /// each pixel centre divided by `2^n` (pixel-sum norm 1).
    ///
    /// ```
    /// use haarshift::product::basis::BasisFunction;
    /// use haarshift::transform::Band;
    /// let b = BasisFunction::new(Band::Vertical, 0, 0, 0).discrete(1);
    /// assert_eq!(b, ndarray::array![[0.5, 0.5], [-0.5, -0.5]]);
    /// ```
    pub fn discrete(&self, n: u32) -> Array2<f64> {
        let s = 1usize << n;
        Array2::from_shape_fn((s, s), |(i, j)| {
            self.value((j as f64 + 0.5) / s as f64, (i as f64 + 0.5) / s as f64) / s as f64
        })
    }
}

/// A basis function times a signed magnitude: what a product of basis functions is.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Scaled {
    /// The signed magnitude (Sun 2006's `|P|`), continuous normalisation.
    pub magnitude: f64,
    /// The basis function (possibly a child scaling function).
    pub function: BasisFunction,
}

/// The product of two basis functions (continuous normalisation), `None` when it is zero
/// (disjoint supports).
///
/// ```
/// use haarshift::product::basis::{BasisFunction, product};
/// use haarshift::transform::Band;
/// let h = BasisFunction::new(Band::Horizontal, 1, 0, 1);
/// let v = BasisFunction::new(Band::Vertical, 1, 0, 1);
/// let p = product(&h, &v).unwrap();
/// assert_eq!((p.magnitude, p.function.band), (2.0, Band::Diagonal));
/// // A finer function in the right half of a coarser H: the sign of that half.
/// let coarse = BasisFunction::new(Band::Horizontal, 0, 0, 0);
/// assert_eq!(product(&coarse, &h).unwrap().magnitude, -1.0);
/// assert!(product(&h, &BasisFunction::new(Band::Vertical, 1, 1, 1)).is_none());
/// ```
pub fn product(a: &BasisFunction, b: &BasisFunction) -> Option<Scaled> {
    let (coarse, fine) = if a.level <= b.level { (a, b) } else { (b, a) };
    if !coarse.contains(fine) {
        return None;
    }
    let amplitude = (1u64 << coarse.level) as f64;
    if coarse.level == fine.level {
        let pattern: [f64; 4] =
            std::array::from_fn(|q| quadrant_sign(a.band, q) * quadrant_sign(b.band, q));
        let band = band_with_pattern(pattern)?;
        return Some(Scaled {
            magnitude: amplitude,
            function: BasisFunction { band, ..*fine },
        });
    }
    Some(Scaled {
        magnitude: amplitude * quadrant_sign(coarse.band, coarse.quadrant_holding(fine)),
        function: *fine,
    })
}

/// The integral over the unit square of a scaled basis function: `magnitude x 2^-level` for a
/// box (Sun 2006 observation 7), 0 for a wavelet (observation 6).
pub fn integral(scaled: &Scaled) -> f64 {
    match scaled.function.band {
        Band::Scaling => scaled.magnitude / (1u64 << scaled.function.level) as f64,
        _ => 0.0,
    }
}
