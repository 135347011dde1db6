//! The integral coefficient of `N` basis functions, `C = integral of b_1 ... b_N`, in closed
//! form (Sun 2006 section 3.3.4, the "generalized Haar integral coefficient theorem"; Sun and Mukherjee 2012
//! eqs. 20-22).
//!
//! **Theorem (as checked here).** Let `j0` be the finest level among the functions. `C` is
//! non-zero if and only if (1) every function's node contains the node of every function at
//! level `j0` (they all lie on one path of the quadtree, so the functions at `j0` share one
//! node) and (2) the numbers of `H`, `V` and `D` wavelets at level `j0` have the same parity
//! (their product is then the box of that node). Then, in the continuous normalisation of
//! [`basis`],
//!
//! `C = s x 2^(sum of levels - 2 j0)`,
//!
//! where `s` is the product, over the functions coarser than `j0`, of each one's sign on the
//! quadrant that holds the level-`j0` node (`+1` for boxes). For the discrete orthonormal basis
//! of a `2^n x 2^n` face (pixel-sum inner product) every function is the continuous one over
//! `2^n` and the integral is `2^(2n)` times the pixel sum, so
//! [`discrete_integral_coefficient`] `= 2^((2 - N) n) C`.
//!
//! [`integral_coefficient_by_products`] computes the same number a second way, multiplying the
//! functions two at a time with [`basis::product`] (Sun 2006's lemmas
//! 2-7); the tests check both against the brute-force pixel sum.

use super::basis::{self, BasisFunction, Scaled, quadrant_sign};
use crate::transform::Band;

/// The closed-form integral coefficient over the unit square (continuous normalisation).
///
/// The empty product is the constant 1, whose integral is 1.
///
/// ```
/// use haarshift::product::basis::BasisFunction;
/// use haarshift::product::coefficient::integral_coefficient;
/// use haarshift::transform::Band;
/// let h = BasisFunction::new(Band::Horizontal, 1, 0, 1);
/// let parent = BasisFunction::new(Band::Horizontal, 0, 0, 0);
/// // Two equal wavelets at level 1 under a parent H at level 0, in its right half: -2^(2-2).
/// assert_eq!(integral_coefficient(&[h, h, parent]), -1.0);
/// // Three different wavelets on one node (Ng's tripling case): 2^(3 - 2) = 2.
/// let (v, d) = (BasisFunction { band: Band::Vertical, ..h }, BasisFunction { band: Band::Diagonal, ..h });
/// assert_eq!(integral_coefficient(&[h, v, d]), 2.0);
/// ```
pub fn integral_coefficient(functions: &[BasisFunction]) -> f64 {
    let Some(finest) = functions.iter().max_by_key(|f| f.level) else {
        return 1.0;
    };
    let j0 = finest.level;
    let mut counts = [0usize; 4];
    let mut sign = 1.0;
    let mut level_sum = 0usize;
    for f in functions {
        if !f.contains(finest) {
            return 0.0;
        }
        level_sum += f.level;
        if f.level == j0 {
            counts[band_index(f.band)] += 1;
        } else {
            let shift = j0 - f.level - 1;
            let q = basis::quadrant(finest.row >> shift, finest.col >> shift);
            sign *= quadrant_sign(f.band, q);
        }
    }
    let [_, h, v, d] = counts.map(|c| c % 2);
    if h != v || v != d {
        return 0.0;
    }
    sign * 2f64.powi(level_sum as i32 - 2 * j0 as i32)
}

/// Position of a band in [`basis::BANDS`].
fn band_index(band: Band) -> usize {
    match band {
        Band::Scaling => 0,
        Band::Horizontal => 1,
        Band::Vertical => 2,
        Band::Diagonal => 3,
    }
}

/// The integral coefficient of the discrete orthonormal basis functions of a `2^n x 2^n` face
/// (pixel sum of their product): `2^((2 - N) n)` times [`integral_coefficient`].
///
/// ```
/// use haarshift::product::basis::BasisFunction;
/// use haarshift::product::coefficient::discrete_integral_coefficient;
/// // The face's scaling function is 1/S everywhere: three of them sum to S^2 / S^3 = 1/S.
/// let s = BasisFunction::SCALING;
/// assert_eq!(discrete_integral_coefficient(&[s, s, s], 3), 0.125);
/// ```
pub fn discrete_integral_coefficient(functions: &[BasisFunction], n: u32) -> f64 {
    let exponent = (2 - functions.len() as i64) * n as i64;
    integral_coefficient(functions) * 2f64.powi(exponent as i32)
}

/// The same coefficient as [`integral_coefficient`], computed by multiplying the functions two
/// at a time ([`basis::product`]) and integrating the resulting scaled basis function.
///
/// ```
/// use haarshift::product::basis::BasisFunction;
/// use haarshift::product::coefficient::{integral_coefficient, integral_coefficient_by_products};
/// use haarshift::transform::Band;
/// let f = [BasisFunction::new(Band::Vertical, 2, 3, 1), BasisFunction::new(Band::Vertical, 2, 3, 1),
///          BasisFunction::new(Band::Diagonal, 1, 1, 0)];
/// assert_eq!(integral_coefficient_by_products(&f), integral_coefficient(&f));
/// ```
pub fn integral_coefficient_by_products(functions: &[BasisFunction]) -> f64 {
    let mut acc = Scaled {
        magnitude: 1.0,
        function: BasisFunction::SCALING,
    };
    for f in functions {
        match basis::product(&acc.function, f) {
            Some(p) => {
                acc = Scaled {
                    magnitude: acc.magnitude * p.magnitude,
                    function: p.function,
                }
            }
            None => return 0.0,
        }
    }
    basis::integral(&acc)
}
