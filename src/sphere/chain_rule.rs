//! The seed's Haar-domain rotation (section 4.5): detail coefficients are finite-difference
//! derivatives, so the chain rule gives the rotated map's differences at one level, and exact
//! short recursive filters give every coarser level.
//!
//! # The method, step by step
//!
//! Pick the finest detail level `L` to compute. Everything happens on the grid of the
//! approximation at resolution `L + 1` (`m x n = 2^(L+1) x 2^(L+2)` cells of side
//! `delta = pi / m`), the seed's "level `j + 1`":
//!
//! 1. **Derivatives of `f`** ([`SourceGradient`]). `X_f`, `f`'s approximation at that
//!    resolution, is the inverse of `f`'s coefficients of levels `0..=L` (cost `O(N / 4^k)`
//!    for `k` levels below the finest). Its first differences are the finite-difference
//!    derivatives the seed reads off the Haar coefficients (the in-block ones *are* the
//!    level-`L` details: `b = (V[2I][2J] + V[2I][2J+1]) / 4`, below). We keep
//!    `f_theta` on the edges between rows (`theta = i delta`, `phi = (j + 1/2) delta`, with
//!    the edge across each pole from the two pixels facing each other over it) and
//!    `f_phi / sin theta` on the edges between columns (`theta = (i + 1/2) delta`).
//! 2. **Chain rule** ((4.15), (4.16)). With `p(theta, phi)` the target direction and
//!    `q = R p` its pre-image of angles `(Theta, Phi)` ((4.12), (4.13)),
//!    `g_theta = f_Theta dTheta/dtheta + f_Phi dPhi/dtheta` and likewise for `phi`. The
//!    Jacobian comes from tangent vectors: `dTheta/dtheta = e_Theta(q) . R dp/dtheta` and
//!    `sin Theta dPhi/dtheta = e_Phi(q) . R dp/dtheta`, so
//!    `g_theta = f_Theta (e_Theta . R p_theta) + (f_Phi / sin Theta) (e_Phi . R p_theta)`.
//!    *Pole choice:* `dPhi/dtheta` is singular where `Theta` is 0 or `pi`; we never form it.
//!    We carry `f_Phi / sin Theta` (the gradient's component along `e_Phi`), which stays
//!    bounded, so the product `f_Phi dPhi/dtheta` is evaluated without dividing by zero.
//! 3. **Evaluating `f`'s derivatives at pre-image points** (an open choice): bilinear
//!    interpolation of the two staggered derivative maps, periodic in `phi` (the seam), and
//!    continued over the poles as the map is ([`latlong`](super::latlong)), except that the
//!    tangent component `f_Phi / sin Theta` changes sign there (`e_Phi` flips across a pole).
//! 4. **Differences of `g`.** `V[i][j] = X_g[i][j] - X_g[i+1][j] = -delta g_theta` at the
//!    edge midpoint and `U[i][j] = X_g[i][j] - X_g[i][j+1] = -delta g_phi` (periodic in `j`).
//!    For a difference of two cell means these midpoint values are second-order accurate.
//!    *Diagonal choice:* the seed's (4.17) is not the second derivative of (4.14) (see
//!    typos below), and the pure second derivatives it would need are not in the Haar
//!    coefficients anyway. The mixed difference satisfies the exact discrete identities
//!    `C = V[i][j] - V[i][j+1] = U[i][j] - U[i+1][j]`; we take the mean of the two ("the
//!    diagonal coefficients are computed by taking the cross-derivative using the horizontal
//!    or the vertical coefficients", section 4.5.2).
//! 5. **Coefficients at level `L` and coarser** ((4.18)-(4.22)) by exact identities on the
//!    difference fields: `b = (V[2I][2J] + V[2I][2J+1]) / 4`, `a = (U[2I][2J] + U[2I+1][2J]) / 4`,
//!    `c = C[2I][2J] / 4`, and one level coarser
//!    `V' = h_t (3 taps `[1 2 1]`, along theta) x h_s (2 taps `[1 1]`, along phi) of V / 4`,
//!    `U'` the same with the roles swapped, `C'` with `h_t` along both axes. Applied
//!    recursively this is the seed's `O(N)` algorithm; expanded, the weight of a level-`l`
//!    coefficient is the tent `h_t` of (4.19) times the box `h_s` of (4.20)
//!    ([`rotate_selected`] uses that expanded form). At the 1 x 2 root the horizontal field
//!    gives the difference of the two scaling coefficients.
//! 6. **Scaling coefficients** (an open choice): differences fix `g` up to one constant per
//!    channel. We choose it so that the solid-angle integral of `g` equals that of `f` at the
//!    working resolution, because rotation preserves that integral exactly. The energy of
//!    the result is therefore exact by construction; its error shows up instead as a
//!    constant offset.
//!
//! A pure whole-column yaw never gets here: it is an exact coefficient shift
//! ([`yaw`](super::yaw)).
//!
//! # Accuracy
//!
//! For a smooth `f` sampled on the grid, the derivatives of step 2 converge to the analytic
//! ones at second order (the interpolation and the midpoint differences are both
//! `O(delta^2)`), including next to the poles; the tests check the rate. For a sharp feature
//! (the sun) the method is a derivative-domain resampling whose errors are of the size of the
//! feature's own differences.
//!
//! # Typos in the seed's section 4.5
//!
//! * (4.13) `phi' = tan^-1(R1 p / R3 p)` loses the quadrant: it is `atan2(R1 p, R3 p)`.
//! * (4.17) is not the chain rule for `d^2 g / dphi dtheta`: that is
//!   `f_TT T_t T_p + f_TP (T_t P_p + T_p P_t) + f_PP P_t P_p + f_T T_tp + f_P P_tp`
//!   (`T = Theta`, `P = Phi`, subscripts derivatives): it needs the pure second derivatives
//!   of `f` and the second derivatives of the mapping, and (4.17) mixes `Theta` and `theta`.
//! * (4.18) sums over `tau` and `rho` but the summand is written `g_theta(theta, phi)`; it
//!   is `g_theta(tau, rho)`.
//! * (4.19) lacks its normalisation; with (4.20)'s `1 / 2^(l+2)` the weights of a level
//!   coefficient sum correctly only when the tent is divided by its area, as here.
//! * (4.21) `h_{t,j-l} = h_{t,j} * h_{t,j}^l` holds for `l = 1` only; the recursion is
//!   `h_{t,j-l} = h_{t,j-l+1} * h_{t,j}^l` (`[1 2 1] * [1 0 2 0 1] = [1 2 3 4 3 2 1]`, but
//!   `[1 2 1] * [1 0 0 0 2 0 0 0 1]` is not a tent).
//! * Section 4.5.2 says the diagonal coefficients are convolved "in both directions by `h_s`";
//!   the mixed difference needs the tent `h_t` in both directions.

use std::f64::consts::PI;

use ndarray::{Array3, ArrayView3, ArrayViewMut2, Axis, s};
use rayon::prelude::*;

use super::latlong::{angles, continue_index, fill_grid, pixel_solid_angle};
use super::{LatLongMap, SphereCoefficients, SphereRotation};
use crate::transform::{Band, pyramid};
use crate::{Error, Result, Sample};

/// The derivatives of a source map on its staggered edge grids (step 1 of the
/// [module docs](self)), ready to be evaluated anywhere on the sphere.
///
/// ```
/// use haarshift::sphere::{LatLongMap, chain_rule::SourceGradient};
/// // f = y = cos theta: f_theta = -sin theta, f_phi = 0.
/// let f = LatLongMap::<f64>::from_fn(64, 1, |d, out| out[0] = d[1]).unwrap();
/// let grad = SourceGradient::new(&f);
/// let (mut ft, mut gp) = ([0.0], [0.0]);
/// grad.eval(1.0, 2.0, &mut ft, &mut gp);
/// assert!((ft[0] + 1.0f64.sin()).abs() < 1e-3 && gp[0].abs() < 1e-12);
/// ```
#[derive(Clone, Debug)]
pub struct SourceGradient<T> {
    m: usize,
    n: usize,
    channels: usize,
    step: f64,
    /// `f_theta` at `(i delta, (j + 1/2) delta)`, `i` in `0..=m`: `(m + 1) x n x C`.
    d_theta: Vec<T>,
    /// `f_phi / sin theta` at `((i + 1/2) delta, (j + 1) delta)`: `m x n x C`.
    d_phi: Vec<T>,
}

impl<T: Sample> SourceGradient<T> {
    /// The derivative maps of `approx` (an approximation of `f` at the working resolution).
    pub fn new(approx: &LatLongMap<T>) -> Self {
        let (m, n, ch) = approx.as_array().dim();
        let x = approx.as_array();
        let x = x.as_slice().expect("maps are in standard layout");
        let step = PI / m as f64;
        let px = |r: isize, c: isize| {
            let (r, c, _) = continue_index(r, c, m, n);
            &x[(r * n + c) * ch..][..ch]
        };
        let mut d_theta = vec![T::zero(); (m + 1) * n * ch];
        d_theta
            .par_chunks_mut(n * ch)
            .enumerate()
            .for_each(|(i, row)| {
                let inv = T::from_f64(1.0 / step);
                for (j, out) in row.chunks_exact_mut(ch).enumerate() {
                    let (below, above) =
                        (px(i as isize, j as isize), px(i as isize - 1, j as isize));
                    for ((o, &b), &a) in out.iter_mut().zip(below).zip(above) {
                        *o = (b - a) * inv;
                    }
                }
            });
        let mut d_phi = vec![T::zero(); m * n * ch];
        d_phi
            .par_chunks_mut(n * ch)
            .enumerate()
            .for_each(|(i, row)| {
                let inv = T::from_f64(1.0 / (step * ((i as f64 + 0.5) * step).sin()));
                for (j, out) in row.chunks_exact_mut(ch).enumerate() {
                    let (right, left) =
                        (px(i as isize, j as isize + 1), px(i as isize, j as isize));
                    for ((o, &r), &l) in out.iter_mut().zip(right).zip(left) {
                        *o = (r - l) * inv;
                    }
                }
            });
        SourceGradient {
            m,
            n,
            channels: ch,
            step,
            d_theta,
            d_phi,
        }
    }

    /// `f_theta` and `f_phi / sin theta` at `(theta, phi)`, one value per channel each
    /// (step 3 of the [module docs](self)).
    pub fn eval(&self, theta: f64, phi: f64, f_theta: &mut [T], f_phi_over_sin: &mut [T]) {
        let (m, n, ch) = (self.m, self.n, self.channels);
        let (ni, mi) = (n as isize, m as isize);
        // f_theta: rows at theta = i delta, i = 0..=m; no continuation needed in theta.
        let y = theta / self.step;
        let r0 = (y.floor() as isize).clamp(0, mi - 1);
        let fy = y - r0 as f64;
        let x = phi / self.step - 0.5;
        let c0 = x.floor();
        let fx = x - c0;
        let c0 = c0 as isize;
        f_theta.fill(T::zero());
        for (dr, wy) in [(0, 1.0 - fy), (1, fy)] {
            for (dc, wx) in [(0, 1.0 - fx), (1, fx)] {
                let (r, c) = ((r0 + dr) as usize, (c0 + dc).rem_euclid(ni) as usize);
                let src = &self.d_theta[(r * n + c) * ch..][..ch];
                let w = T::from_f64(wy * wx);
                for (o, &v) in f_theta.iter_mut().zip(src) {
                    *o += w * v;
                }
            }
        }
        // f_phi / sin theta: rows at (i + 1/2) delta, columns at (j + 1) delta; over a pole
        // the tangent component flips sign.
        let y = theta / self.step - 0.5;
        let r0 = y.floor();
        let fy = y - r0;
        let x = phi / self.step - 1.0;
        let c0 = x.floor();
        let fx = x - c0;
        let (r0, c0) = (r0 as isize, c0 as isize);
        f_phi_over_sin.fill(T::zero());
        for (dr, wy) in [(0, 1.0 - fy), (1, fy)] {
            for (dc, wx) in [(0, 1.0 - fx), (1, fx)] {
                let (r, c, crossed) = continue_index(r0 + dr, c0 + dc, m, n);
                let src = &self.d_phi[(r * n + c) * ch..][..ch];
                let w = T::from_f64(if crossed { -wy * wx } else { wy * wx });
                for (o, &v) in f_phi_over_sin.iter_mut().zip(src) {
                    *o += w * v;
                }
            }
        }
    }
}

#[inline]
fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// Which derivative of `g` the chain rule evaluates.
#[derive(Clone, Copy)]
enum Along {
    Theta,
    Phi,
}

/// The chain rule (4.15)/(4.16) for one rotation and one source.
struct ChainRule<'a, T> {
    grad: &'a SourceGradient<T>,
    rotation: &'a SphereRotation,
    /// `(sin, cos)` of `k delta / 2`: every angle the grids use.
    trig: Vec<(f64, f64)>,
}

impl<'a, T: Sample> ChainRule<'a, T> {
    fn new(grad: &'a SourceGradient<T>, rotation: &'a SphereRotation) -> Self {
        let half = 0.5 * grad.step;
        let trig = (0..=2 * grad.n + 2)
            .map(|k| (k as f64 * half).sin_cos())
            .collect();
        ChainRule {
            grad,
            rotation,
            trig,
        }
    }

    /// `scale * dg/d(along)` at the angles `(theta, phi) = (kt, kp) * delta / 2` into `out`.
    fn derivative(&self, kt: usize, kp: usize, along: Along, scale: f64, out: &mut [T]) {
        let (st, ct) = self.trig[kt];
        let (sp, cp) = self.trig[kp];
        let p = [st * sp, ct, st * cp];
        let tangent = match along {
            Along::Theta => [ct * sp, -st, ct * cp],
            Along::Phi => [st * cp, 0.0, -st * sp],
        };
        let q = self.rotation.apply(p);
        let tq = self.rotation.apply(tangent);
        let (big_t, big_p) = angles(q);
        // The frame at q straight from q (atan2's convention at the poles: Phi = 0).
        let rho = q[0].hypot(q[2]);
        let (s_p, c_p) = if rho > 0.0 {
            (q[0] / rho, q[2] / rho)
        } else {
            (0.0, 1.0)
        };
        let (s_t, c_t) = (rho, q[1].clamp(-1.0, 1.0));
        let alpha = T::from_f64(scale * dot([c_t * s_p, -s_t, c_t * c_p], tq));
        let beta = T::from_f64(scale * dot([c_p, 0.0, -s_p], tq));
        let mut ft = [T::zero(); 64];
        let mut gp = [T::zero(); 64];
        let ch = out.len();
        self.grad.eval(big_t, big_p, &mut ft[..ch], &mut gp[..ch]);
        for ((o, &a), &b) in out.iter_mut().zip(&ft[..ch]).zip(&gp[..ch]) {
            *o = alpha * a + beta * b;
        }
    }

    /// `V[i][j] = -delta g_theta((i + 1) delta, (j + 1/2) delta)`.
    fn vertical(&self, i: usize, j: usize, out: &mut [T]) {
        self.derivative(2 * i + 2, 2 * j + 1, Along::Theta, -self.grad.step, out);
    }

    /// `U[i][j] = -delta g_phi((i + 1/2) delta, (j + 1) delta)`.
    fn horizontal(&self, i: usize, j: usize, out: &mut [T]) {
        self.derivative(2 * i + 1, 2 * j + 2, Along::Phi, -self.grad.step, out);
    }
}

/// The differences of the rotated map at one resolution (steps 2-4 of the
/// [module docs](self)): `V` (between rows), `U` (between columns, periodic) and `C` (mixed).
///
/// ```
/// use haarshift::sphere::{LatLongMap, SphereRotation, chain_rule::DifferenceFields};
/// let f = LatLongMap::<f64>::from_fn(8, 1, |_, out| out[0] = 1.0).unwrap();
/// let r = SphereRotation::from_degrees(0.0, 40.0, 0.0).unwrap();
/// let d = DifferenceFields::rotated(&f, &r);
/// assert_eq!(d.vertical().dim(), (7, 16, 1));
/// assert!(d.horizontal().iter().all(|v| v.abs() < 1e-15)); // a constant has no differences
/// ```
#[derive(Clone, Debug)]
pub struct DifferenceFields<T> {
    v: Array3<T>,
    u: Array3<T>,
    c: Array3<T>,
}

impl<T: Sample> DifferenceFields<T> {
    /// The fields of `g = f(R p)` from `approx` (`f` at the working resolution).
    pub fn rotated(approx: &LatLongMap<T>, rotation: &SphereRotation) -> Self {
        let (m, n, ch) = approx.as_array().dim();
        let grad = SourceGradient::new(approx);
        let rule = ChainRule::new(&grad, rotation);
        let v = fill_grid((m - 1, n, ch), |i, j, out| rule.vertical(i, j, out));
        let u = fill_grid((m, n, ch), |i, j, out| rule.horizontal(i, j, out));
        let c = mixed_from(v.view(), u.view());
        DifferenceFields { v, u, c }
    }

    /// The exact differences of a map `x` (the identity a rotation's fields approximate).
    ///
    /// ```
    /// use haarshift::sphere::{LatLongMap, chain_rule::DifferenceFields};
    /// let x = LatLongMap::<f64>::from_fn(4, 1, |d, out| out[0] = d[0]).unwrap();
    /// let d = DifferenceFields::of_map(&x);
    /// let a = x.as_array();
    /// assert_eq!(d.vertical()[[1, 3, 0]], a[[1, 3, 0]] - a[[2, 3, 0]]);
    /// assert_eq!(d.horizontal()[[2, 7, 0]], a[[2, 7, 0]] - a[[2, 0, 0]]); // periodic
    /// ```
    pub fn of_map(x: &LatLongMap<T>) -> Self {
        let a = x.as_array();
        let (m, n, ch) = a.dim();
        let v = grid_from_fn((m - 1, n, ch), |(i, j, k)| a[[i, j, k]] - a[[i + 1, j, k]]);
        let u = grid_from_fn((m, n, ch), |(i, j, k)| {
            a[[i, j, k]] - a[[i, (j + 1) % n, k]]
        });
        let c = mixed_from(v.view(), u.view());
        DifferenceFields { v, u, c }
    }

    /// `V`: `(m - 1, n, C)`, `V[i][j] = X[i][j] - X[i+1][j]`.
    pub fn vertical(&self) -> ArrayView3<'_, T> {
        self.v.view()
    }

    /// `U`: `(m, n, C)`, `U[i][j] = X[i][j] - X[i][j+1]` (periodic).
    pub fn horizontal(&self) -> ArrayView3<'_, T> {
        self.u.view()
    }

    /// `C`: `(m - 1, n, C)`, `C[i][j] = X[i][j] - X[i][j+1] - X[i+1][j] + X[i+1][j+1]`.
    pub fn diagonal(&self) -> ArrayView3<'_, T> {
        self.c.view()
    }

    /// Rows of the grid the fields live on.
    fn rows(&self) -> usize {
        self.u.dim().0
    }

    /// Writes the details of the level whose blocks are 2 x 2 cells of this grid into the
    /// per-channel planes of `out` (step 5).
    fn write_details(&self, out: &mut Array3<T>) {
        let (m, _, ch) = self.u.dim();
        let level = (m / 2).trailing_zeros() as usize;
        let quarter = T::from_f64(0.25);
        let size = (out.dim().1, out.dim().2);
        let levels = size.0.trailing_zeros() as usize;
        for k in 0..ch {
            let mut plane = out.index_axis_mut(Axis(0), k);
            let mut band = |b: Band, f: &dyn Fn(usize, usize) -> T| {
                let (rows, cols) =
                    pyramid::band_ranges(size, levels, b, level).expect("level exists");
                let mut view: ArrayViewMut2<'_, T> = plane.slice_mut(s![rows, cols]);
                for ((i, j), o) in view.indexed_iter_mut() {
                    *o = f(i, j) * quarter;
                }
            };
            band(Band::Vertical, &|i, j| {
                self.v[[2 * i, 2 * j, k]] + self.v[[2 * i, 2 * j + 1, k]]
            });
            band(Band::Horizontal, &|i, j| {
                self.u[[2 * i, 2 * j, k]] + self.u[[2 * i + 1, 2 * j, k]]
            });
            band(Band::Diagonal, &|i, j| self.c[[2 * i, 2 * j, k]]);
        }
    }

    /// The fields one level coarser (the recursive filters (4.21)-(4.22), step 5).
    fn coarser(&self) -> Self {
        let (m, n, ch) = self.u.dim();
        let (mh, nh) = (m / 2, n / 2);
        let q = T::from_f64(0.25);
        let two = T::from_f64(2.0);
        let v = grid_from_fn((mh.saturating_sub(1), nh, ch), |(i, j, k)| {
            let col = |c: usize| {
                self.v[[2 * i, c, k]] + two * self.v[[2 * i + 1, c, k]] + self.v[[2 * i + 2, c, k]]
            };
            q * (col(2 * j) + col(2 * j + 1))
        });
        let u = grid_from_fn((mh, nh, ch), |(i, j, k)| {
            let row = |r: usize| {
                self.u[[r, 2 * j, k]]
                    + two * self.u[[r, 2 * j + 1, k]]
                    + self.u[[r, (2 * j + 2) % n, k]]
            };
            q * (row(2 * i) + row(2 * i + 1))
        });
        let c = grid_from_fn((mh.saturating_sub(1), nh, ch), |(i, j, k)| {
            let row = |r: usize| {
                self.c[[r, 2 * j, k]]
                    + two * self.c[[r, 2 * j + 1, k]]
                    + self.c[[r, (2 * j + 2) % n, k]]
            };
            q * (row(2 * i) + two * row(2 * i + 1) + row(2 * i + 2))
        });
        DifferenceFields { v, u, c }
    }

    /// All detail levels of the `m x 2m` pyramid these fields describe, the root's two
    /// scaling coefficients set to `(+d/2, -d/2)` with `d` their difference from the root
    /// field (the constant is fixed later by [`set_mean_from_energy`]).
    pub fn to_coefficients(&self) -> Result<SphereCoefficients<T>> {
        let (m, n, ch) = self.u.dim();
        if m < 2 || !m.is_power_of_two() || n != 2 * m {
            return Err(Error::shape(
                &[m, n, ch],
                "fields of an m x 2m grid, m >= 2",
            ));
        }
        let mut out = Array3::zeros((ch, m, n));
        self.write_details(&mut out);
        let mut fields = self.coarser();
        while fields.rows() > 1 {
            fields.write_details(&mut out);
            fields = fields.coarser();
        }
        let half = T::from_f64(0.5);
        for k in 0..ch {
            // At the 1 x 2 root, U[0][0] = A0 - A1 and U[0][1] = A1 - A0.
            let d = half * (fields.u[[0, 0, k]] - fields.u[[0, 1, k]]);
            out[[k, 0, 0]] = half * d;
            out[[k, 0, 1]] = -half * d;
        }
        SphereCoefficients::from_array(out)
    }
}

/// `Array3::from_shape_fn` with the rows computed in parallel.
fn grid_from_fn<T: Sample>(
    shape: (usize, usize, usize),
    f: impl Fn((usize, usize, usize)) -> T + Sync,
) -> Array3<T> {
    fill_grid(shape, |i, j, out| {
        for (k, o) in out.iter_mut().enumerate() {
            *o = f((i, j, k));
        }
    })
}

/// `C = (V[i][j] - V[i][j+1] + U[i][j] - U[i+1][j]) / 2`, the mixed difference from both
/// first-difference fields (step 4).
fn mixed_from<T: Sample>(v: ArrayView3<'_, T>, u: ArrayView3<'_, T>) -> Array3<T> {
    let (rows, n, ch) = v.dim();
    let half = T::from_f64(0.5);
    grid_from_fn((rows, n, ch), |(i, j, k)| {
        half * (v[[i, j, k]] - v[[i, (j + 1) % n, k]] + u[[i, j, k]] - u[[i + 1, j, k]])
    })
}

/// Sets each channel's constant so that the solid-angle integral of the map equals
/// `energy` (step 6), keeping every difference.
///
/// The integral is computed from the coefficients by the row-sum recursion: the two rows of
/// children of a block with average `A` and vertical detail `b` sum to `2 (A + b)` and
/// `2 (A - b)`.
pub fn set_mean_from_energy<T: Sample>(
    coeffs: &mut SphereCoefficients<T>,
    energy: &[f64],
) -> Result<()> {
    let (ch, m, n) = coeffs.as_array().dim();
    if energy.len() != ch {
        return Err(Error::parameter(
            "energy",
            format!("{} values for {ch} channels", energy.len()),
        ));
    }
    let levels = coeffs.levels();
    let mut data = coeffs.as_array().to_owned();
    for (k, &target) in energy.iter().enumerate() {
        let plane = data.index_axis(Axis(0), k);
        let mut rows = vec![plane[[0, 0]].as_f64() + plane[[0, 1]].as_f64()];
        for level in 0..levels {
            let (r, c) = pyramid::band_ranges((m, n), levels, Band::Vertical, level)?;
            let b = plane.slice(s![r, c]);
            rows = rows
                .iter()
                .zip(b.axis_iter(Axis(0)))
                .flat_map(|(&sum, brow)| {
                    let sb: f64 = brow.iter().map(|v| v.as_f64()).sum();
                    [2.0 * (sum + sb), 2.0 * (sum - sb)]
                })
                .collect();
        }
        let current: f64 = rows
            .iter()
            .enumerate()
            .map(|(i, s)| pixel_solid_angle(m, i) * s)
            .sum();
        let shift = T::from_f64((target - current) / (4.0 * PI));
        data[[k, 0, 0]] += shift;
        data[[k, 0, 1]] += shift;
    }
    *coeffs = SphereCoefficients::from_array(data)?;
    Ok(())
}

/// The Haar coefficients of `g = f(R p)` at the resolution of `approx` (the approximation of
/// `f` at resolution `L + 1`, an `m x 2m` map): a full `m x 2m` pyramid holding detail
/// levels `0..=L`. Embed it in a larger pyramid with
/// [`SphereCoefficients::zero_padded`].
///
/// ```
/// use haarshift::sphere::{LatLongMap, SphereRotation, chain_rule::rotate};
/// let f = LatLongMap::<f64>::from_fn(16, 1, |d, out| out[0] = 1.0 + d[0]).unwrap();
/// let r = SphereRotation::from_degrees(0.0, 30.0, 0.0).unwrap();
/// let g = rotate(&f, &r).unwrap().to_map().unwrap();
/// // g = 1 + x(R p) and a pitch about X keeps x: g is f, to the method's accuracy.
/// let err = (&g.as_array() - &f.as_array()).iter().fold(0.0f64, |a, v| a.max(v.abs()));
/// assert!(err < 0.02);
/// ```
pub fn rotate<T: Sample>(
    approx: &LatLongMap<T>,
    rotation: &SphereRotation,
) -> Result<SphereCoefficients<T>> {
    let m = approx.height();
    if m < 2 || !m.is_power_of_two() {
        return Err(Error::shape(
            &[m, 2 * m],
            "the Haar method needs a height that is a power of two from 2 on",
        ));
    }
    let fields = DifferenceFields::rotated(approx, rotation);
    let mut coeffs = fields.to_coefficients()?;
    set_mean_from_energy(&mut coeffs, &approx.energy())?;
    Ok(coeffs)
}

/// The address of one detail coefficient in a [`SphereCoefficients`] pyramid.
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
/// equal (to rounding) to the same coefficient of [`rotate`].
///
/// ```
/// use haarshift::sphere::{LatLongMap, SphereRotation, chain_rule::*};
/// use haarshift::transform::Band;
/// let f = LatLongMap::<f64>::from_fn(16, 1, |d, out| out[0] = d[0] * d[1]).unwrap();
/// let r = SphereRotation::from_degrees(20.0, 50.0, 0.0).unwrap();
/// let want = rotate(&f, &r).unwrap();
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
    let rule = ChainRule::new(&grad, rotation);
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
