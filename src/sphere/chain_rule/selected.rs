//! Individual coefficients of the rotated map from the expanded filters (the tent times the
//! box of (4.19) and (4.20)), for a few coefficients without the whole transform.

use rayon::prelude::*;

use crate::sphere::{LatLongMap, SphereRotation};
use crate::transform::Band;
use crate::{Error, Result, Sample};

use super::chain::ChainRule;
use super::gradient::SourceGradient;

/// The address of one detail coefficient in a [`SphereCoefficients`](crate::sphere::SphereCoefficients) pyramid.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct CoefficientIndex {
    /// Horizontal, vertical or diagonal ([`Band::Scaling`] is not available one at a time).
    pub band: Band,
    /// Detail level (0 coarsest).
    pub level: usize,
    /// Row within the band.
    pub row: usize,
    /// Column within the band.
    pub column: usize,
}

/// Only the requested detail coefficients of `g = f(R p)`, each computed from the chain
/// rule over its own footprint with the expanded kernels of (4.18)-(4.20) (tent `h_t` across
/// the difference, box `h_s` along it): a level-`l` coefficient costs `O(4^(L - l))` chain
/// rule evaluations, nothing else is computed. Returns one value per channel per request,
/// equal (to rounding) to the same coefficient of [`rotate`](super::rotate).
///
/// ```
/// use haarshift::sphere::{LatLongMap, SphereRotation, chain_rule::*};
/// use haarshift::transform::Band;
/// let f = LatLongMap::<f64>::from_fn(16, 1, |d, out| out[0] = d[0] * d[1]).unwrap();
/// let r = SphereRotation::from_degrees(20.0, 50.0, 0.0).unwrap();
/// let want = rotate(&f, &r, Scheme::Linear).unwrap();
/// let at = CoefficientIndex { band: Band::Diagonal, level: 1, row: 1, column: 2 };
/// let got = rotate_selected(&f, &r, &[at]).unwrap();
/// assert!((got[0][0] - want.band(0, Band::Diagonal, 1).unwrap()[[1, 2]]).abs() < 1e-12);
/// ```
pub fn rotate_selected<T: Sample>(
    approx: &LatLongMap<T>,
    rotation: &SphereRotation,
    requests: &[CoefficientIndex],
) -> Result<Vec<Vec<T>>> {
    let (m, n, ch) = approx.as_array().dim();
    let levels = m.trailing_zeros() as usize;
    if m < 2 || !m.is_power_of_two() {
        return Err(Error::shape(
            &[m, n],
            "height must be a power of two from 2 on",
        ));
    }
    for r in requests {
        let fits = r.level < levels && r.row < (1 << r.level) && r.column < (2 << r.level);
        if r.band == Band::Scaling || !fits {
            return Err(Error::parameter(
                "coefficient",
                format!(
                    "{r:?} is not a detail coefficient of levels 0..{levels} (scaling \
                     coefficients need the whole map: use rotate)"
                ),
            ));
        }
    }
    let grad = SourceGradient::new(approx);
    let rule = ChainRule::new(&grad, rotation, 0);
    requests
        .par_iter()
        .map(|r| Ok(footprint_coefficient(&rule, r, m, ch)))
        .collect()
}

/// One coefficient from the chain rule over its `s x s` footprint (`s = m >> level`).
fn footprint_coefficient<T: Sample>(
    rule: &ChainRule<'_, T>,
    at: &CoefficientIndex,
    m: usize,
    ch: usize,
) -> Vec<T> {
    let s = m >> at.level;
    let half = (s / 2) as f64;
    let (r0, c0) = (at.row * s, at.column * s);
    let tent = |k: usize| (k + 1).min(s - 1 - k) as f64;
    // V on the (s - 1) x s interior edges, U on the s x (s - 1) ones, as needed.
    let field = |rows: usize, cols: usize, f: &dyn Fn(usize, usize, &mut [T])| {
        let mut out = vec![T::zero(); rows * cols * ch];
        for (idx, px) in out.chunks_exact_mut(ch).enumerate() {
            f(r0 + idx / cols, c0 + idx % cols, px);
        }
        out
    };
    let v = || field(s - 1, s, &|i, j, o| rule.vertical(i, j, o));
    let u = || field(s, s - 1, &|i, j, o| rule.horizontal(i, j, o));
    let mut acc = vec![0.0f64; ch];
    let mut add = |weight: f64, vals: &[T]| {
        for (a, x) in acc.iter_mut().zip(vals) {
            *a += weight * x.as_f64();
        }
    };
    let norm = match at.band {
        Band::Vertical => {
            let v = v();
            for i in 0..s - 1 {
                for j in 0..s {
                    add(tent(i), &v[(i * s + j) * ch..][..ch]);
                }
            }
            2.0 * half * s as f64
        }
        Band::Horizontal => {
            let u = u();
            for i in 0..s {
                for j in 0..s - 1 {
                    add(tent(j), &u[(i * (s - 1) + j) * ch..][..ch]);
                }
            }
            2.0 * half * s as f64
        }
        Band::Diagonal | Band::Scaling => {
            let (v, u) = (v(), u());
            for i in 0..s - 1 {
                for j in 0..s - 1 {
                    let w = tent(i) * tent(j);
                    for k in 0..ch {
                        let c = v[(i * s + j) * ch + k] - v[(i * s + j + 1) * ch + k]
                            + u[(i * (s - 1) + j) * ch + k]
                            - u[((i + 1) * (s - 1) + j) * ch + k];
                        acc[k] += w * 0.5 * c.as_f64();
                    }
                }
            }
            4.0 * half * half
        }
    };
    acc.iter().map(|a| T::from_f64(a / norm)).collect()
}
