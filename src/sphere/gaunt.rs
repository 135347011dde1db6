//! Real Gaunt coefficients: the integrals `G_ijk = int Y_i Y_j Y_k dOmega` of products of three
//! real spherical harmonics ([`harmonics`](super::harmonics), same indexing `l (l + 1) + m`),
//! the coupling that turns a triple product integral of three band-limited functions into a
//! sum over coefficients: `int f g h = sum_ijk G_ijk f_i g_j h_k`.
//!
//! # Computation (exact)
//!
//! A product of three harmonics of degrees below `B` is, in `x = cos theta`, a polynomial of
//! degree at most `3 (B - 1)` whenever its azimuthal integral does not vanish (the powers of
//! `sin theta` then add up to an even number), and a trigonometric polynomial of degree at
//! most `3 (B - 1)` in `phi`. Gauss-Legendre in `x` with `ceil((3 (B - 1) + 1) / 2)` nodes times
//! `3 B` equally spaced azimuths integrates it exactly, so every coefficient is exact to
//! rounding (about `1e-16`). The nodes are Newton-polished roots of the Legendre polynomial.
//!
//! # Sparsity: the selection rules
//!
//! With `(l_a, m_a)` the degree and order of index `a`, `G_ijk` vanishes unless
//! ([`selection_rules`]):
//!
//! * the degrees form a triangle, `|l_i - l_j| <= l_k <= l_i + l_j`, with an even sum (parity
//!   under `w -> -w`);
//! * an even number of the orders are negative (the `sin(|m| phi)` functions are odd in `phi`);
//! * one of `|m_i|, |m_j|, |m_k|` is the sum of the other two (the azimuthal integral of
//!   `cos(a phi) cos(b phi) cos(c phi)` vanishes unless `+-a +- b +- c = 0`).
//!
//! Only triples that pass are integrated; those whose integral still vanishes (accidental
//! zeros of the Wigner `3j` symbols, below `1e-14` in magnitude) are dropped too. At `B = 8`
//! 12,868 of the `B^6 = 262,144` triples are stored (4.9 %).
//!
//! ```
//! use haarshift::sphere::gaunt::Gaunt;
//! let g = Gaunt::new(3).unwrap();
//! let y00 = 0.5 / std::f64::consts::PI.sqrt();
//! // Y_00 is a constant, so G_{i j 0} = Y_00 delta_ij.
//! assert!((g.get(4, 4, 0) - y00).abs() < 1e-15);
//! assert_eq!(g.get(4, 5, 0), 0.0);
//! ```

use super::harmonics::SphericalHarmonics;
use crate::{Error, Result};

/// The most bands accepted (degrees 0 to 15): the transfer's limit
/// (`haarshift_relight::sh_transfer::MAX_SH_BANDS`).
pub const MAX_GAUNT_BANDS: usize = 16;

/// One non-zero coefficient `G_ijk`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GauntEntry {
    /// First index, `l (l + 1) + m`.
    pub i: u16,
    /// Second index.
    pub j: u16,
    /// Third index.
    pub k: u16,
    /// `int Y_i Y_j Y_k dOmega`.
    pub value: f64,
}

/// The non-zero real Gaunt coefficients of `B` bands, every ordering of the three indices
/// stored, sorted by `(i, j, k)`; see the [module docs](self).
///
/// ```
/// use haarshift::sphere::gaunt::Gaunt;
/// let g = Gaunt::new(4).unwrap();
/// assert_eq!(g.bands(), 4);
/// // The table is symmetric in its three indices.
/// assert_eq!(g.get(1, 5, 9), g.get(9, 1, 5));
/// assert!(g.entries().iter().all(|e| e.value != 0.0));
/// ```
#[derive(Clone, Debug, PartialEq)]
pub struct Gaunt {
    bands: usize,
    entries: Vec<GauntEntry>,
}

/// `(l, m)` of index `l (l + 1) + m`.
fn degree_order(index: usize) -> (usize, isize) {
    let l = index.isqrt();
    (l, index as isize - (l * (l + 1)) as isize)
}

/// Whether the selection rules (see the [module docs](self)) allow `G_ijk` to be non-zero;
/// `false` means it is zero.
///
/// ```
/// use haarshift::sphere::gaunt::selection_rules;
/// assert!(selection_rules(1, 1, 0)); // Y_1,-1 Y_1,-1 Y_00
/// assert!(!selection_rules(1, 2, 0)); // orthogonal
/// assert!(!selection_rules(2, 2, 2)); // 1 + 1 + 1 is odd
/// ```
pub fn selection_rules(i: usize, j: usize, k: usize) -> bool {
    let ((li, mi), (lj, mj), (lk, mk)) = (degree_order(i), degree_order(j), degree_order(k));
    let triangle = li.abs_diff(lj) <= lk && lk <= li + lj && (li + lj + lk) % 2 == 0;
    let negatives = [mi, mj, mk].iter().filter(|m| **m < 0).count();
    let (a, b, c) = (mi.unsigned_abs(), mj.unsigned_abs(), mk.unsigned_abs());
    let orders = a == b + c || b == a + c || c == a + b;
    triangle && negatives % 2 == 0 && orders
}

/// Nodes and weights of the `n`-point Gauss-Legendre rule on `[-1, 1]` (exact for polynomials
/// of degree below `2 n`).
pub(crate) fn gauss_legendre(n: usize) -> Vec<(f64, f64)> {
    (0..n)
        .map(|i| {
            let mut x = (std::f64::consts::PI * (i as f64 + 0.75) / (n as f64 + 0.5)).cos();
            let mut derivative = 1.0;
            for _ in 0..100 {
                // P_n(x) by Bonnet's recurrence, and P_n'(x) from P_n and P_n-1.
                let (mut p0, mut p1) = (1.0, x);
                for k in 2..=n {
                    let kf = k as f64;
                    (p0, p1) = (p1, ((2.0 * kf - 1.0) * x * p1 - (kf - 1.0) * p0) / kf);
                }
                let (pn, pn1) = if n == 1 { (x, 1.0) } else { (p1, p0) };
                derivative = n as f64 * (x * pn - pn1) / (x * x - 1.0);
                let step = pn / derivative;
                x -= step;
                if step.abs() < 1e-16 {
                    break;
                }
            }
            (x, 2.0 / ((1.0 - x * x) * derivative * derivative))
        })
        .collect()
}

impl Gaunt {
    /// The coefficients of `bands` bands (1 to [`MAX_GAUNT_BANDS`]).
    pub fn new(bands: usize) -> Result<Self> {
        if !(1..=MAX_GAUNT_BANDS).contains(&bands) {
            return Err(Error::parameter(
                "sh-bands",
                format!("{bands}: Gaunt coefficients take 1 to {MAX_GAUNT_BANDS} bands"),
            ));
        }
        let sh = SphericalHarmonics::new(bands)?;
        let n = sh.len();
        let degree = 3 * (bands - 1);
        let phis = 3 * bands;
        // The harmonics at every node, weighted by the node's weight once (w Y_i Y_j Y_k).
        let mut nodes = Vec::new();
        let mut weights = Vec::new();
        for (x, w) in gauss_legendre(degree / 2 + 1) {
            let s = (1.0 - x * x).sqrt();
            for p in 0..phis {
                let phi = 2.0 * std::f64::consts::PI * p as f64 / phis as f64;
                let mut y = vec![0.0; n];
                sh.evaluate([s * phi.sin(), x, s * phi.cos()], &mut y);
                nodes.extend(y);
                weights.push(w * 2.0 * std::f64::consts::PI / phis as f64);
            }
        }
        let mut entries = Vec::new();
        for i in 0..n {
            for j in i..n {
                for k in j..n {
                    if !selection_rules(i, j, k) {
                        continue;
                    }
                    let value: f64 = nodes
                        .chunks_exact(n)
                        .zip(&weights)
                        .map(|(y, w)| w * y[i] * y[j] * y[k])
                        .sum();
                    if value.abs() < 1e-14 {
                        continue;
                    }
                    let mut orderings = [
                        [i, j, k],
                        [i, k, j],
                        [j, i, k],
                        [j, k, i],
                        [k, i, j],
                        [k, j, i],
                    ];
                    orderings.sort_unstable();
                    let mut last = None;
                    for [a, b, c] in orderings {
                        if last != Some([a, b, c]) {
                            entries.push(GauntEntry {
                                i: a as u16,
                                j: b as u16,
                                k: c as u16,
                                value,
                            });
                            last = Some([a, b, c]);
                        }
                    }
                }
            }
        }
        entries.sort_unstable_by_key(|e| (e.i, e.j, e.k));
        Ok(Gaunt { bands, entries })
    }

    /// The number of bands `B`.
    pub fn bands(&self) -> usize {
        self.bands
    }

    /// The stored (non-zero) coefficients, sorted by `(i, j, k)`.
    pub fn entries(&self) -> &[GauntEntry] {
        &self.entries
    }

    /// `G_ijk`: 0 for triples the table does not hold (including indices of `B` bands or
    /// more).
    pub fn get(&self, i: usize, j: usize, k: usize) -> f64 {
        self.entries
            .binary_search_by_key(&(i, j, k), |e| {
                (usize::from(e.i), usize::from(e.j), usize::from(e.k))
            })
            .map_or(0.0, |at| self.entries[at].value)
    }

    /// The matrix `M_ik = sum_j G_ijk c_j` of a function's coefficients `c` (`B^2` values),
    /// into `out` (`B^2 x B^2`, row-major, overwritten): then `t . M r` is the triple integral
    /// of the three band-limited functions with coefficients `t`, `c` and `r`.
    ///
    /// ```
    /// use haarshift::sphere::gaunt::Gaunt;
    /// let g = Gaunt::new(2).unwrap();
    /// // c = the constant 1 (= sqrt(4 pi) Y_00): M is the identity, the integral a dot product.
    /// let mut c = [0.0; 4];
    /// c[0] = (4.0 * std::f64::consts::PI).sqrt();
    /// let mut m = [0.0; 16];
    /// g.contract(&c, &mut m);
    /// assert!((0..16).all(|a| (m[a] - if a % 5 == 0 { 1.0 } else { 0.0 }).abs() < 1e-15));
    /// ```
    pub fn contract(&self, coefficients: &[f64], out: &mut [f64]) {
        let n = self.bands * self.bands;
        debug_assert_eq!((coefficients.len(), out.len()), (n, n * n));
        out.fill(0.0);
        for e in &self.entries {
            out[usize::from(e.i) * n + usize::from(e.k)] +=
                e.value * coefficients[usize::from(e.j)];
        }
    }
}

#[cfg(test)]
#[path = "gaunt_tests.rs"]
mod tests;
