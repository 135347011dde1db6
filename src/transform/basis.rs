//! The Haar basis functions themselves, built from their definition (box and step functions),
//! not from the transform. They define what every coefficient means and are the brute-force
//! oracle that the fast transforms are tested against.

use ndarray::Array2;

use super::{Band, Normalization};

/// Height of the step for a support of `width` samples along one axis: `1 / width` for the
/// mean (Average scaling, and Average detail = half the difference of two half-means), or
/// `1 / sqrt(width)` for unit norm.
fn step_height(norm: Normalization, width: usize) -> f64 {
    match norm {
        Normalization::Average => 1.0 / width as f64,
        Normalization::Orthonormal => 1.0 / (width as f64).sqrt(),
    }
}

/// The 1D basis function whose inner product with a length-`len` signal is coefficient `k` of
/// its `levels`-step transform (layout of [`haar1d`](super::haar1d)).
///
/// ```
/// use haarshift::transform::{Normalization, basis::haar_basis_1d};
/// // Length 4, full transform, coefficient 2 is the first finest detail: (x0 - x1) / 2.
/// assert_eq!(haar_basis_1d(4, 2, 2, Normalization::Average), [0.5, -0.5, 0.0, 0.0]);
/// ```
pub fn haar_basis_1d(len: usize, levels: usize, k: usize, norm: Normalization) -> Vec<f64> {
    let n0 = len >> levels;
    let mut basis = vec![0.0; len];
    if k < n0 {
        let width = 1 << levels;
        let h = step_height(norm, width);
        basis[k * width..(k + 1) * width].fill(h);
        return basis;
    }
    // Detail level l holds n0 << l coefficients, each supported on len / (n0 << l) samples.
    let level = (k / n0).ilog2() as usize;
    let index = k - (n0 << level);
    let width = len / (n0 << level);
    let h = step_height(norm, width);
    let start = index * width;
    basis[start..start + width / 2].fill(h);
    basis[start + width / 2..start + width].fill(-h);
    basis
}

/// The 2D pyramid basis function of coefficient `(band, level, i, j)` of a `levels`-step
/// transform of an `h x w` array, as an `h x w` array (see [`pyramid`](super::pyramid)).
///
/// ```
/// use haarshift::transform::{Band, Normalization, basis::pyramid_basis};
/// let b = pyramid_basis((2, 2), 1, Band::Diagonal, 0, 0, 0, Normalization::Average);
/// assert_eq!(b, ndarray::array![[0.25, -0.25], [-0.25, 0.25]]);
/// ```
pub fn pyramid_basis(
    (h, w): (usize, usize),
    levels: usize,
    band: Band,
    level: usize,
    i: usize,
    j: usize,
    norm: Normalization,
) -> Array2<f64> {
    // Support side: 2^levels for scaling, 2^(levels - level) for details of `level`.
    let side = match band {
        Band::Scaling => 1 << levels,
        _ => 1 << (levels - level),
    };
    // Average: scaling = mean over side^2; a detail = half the difference of two half-means.
    // Orthonormal: +-1/side everywhere on the support (unit norm).
    let height = match norm {
        Normalization::Average => 1.0 / (side * side) as f64,
        Normalization::Orthonormal => 1.0 / side as f64,
    };
    let half = side / 2;
    Array2::from_shape_fn((h, w), |(r, c)| {
        let (r0, c0) = (i * side, j * side);
        if r < r0 || r >= r0 + side || c < c0 || c >= c0 + side {
            return 0.0;
        }
        let left = if c - c0 < half { 1.0 } else { -1.0 };
        let top = if r - r0 < half { 1.0 } else { -1.0 };
        height
            * match band {
                Band::Scaling => 1.0,
                Band::Horizontal => left,
                Band::Vertical => top,
                Band::Diagonal => left * top,
            }
    })
}
