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
//!    `U'` the same with the roles swapped, `C'` with `h_t` along both axes, which is the
//!    mixed difference of `V'` and `U'` exactly (`[1 2 1] * [1 -1] = [1 1] * [1 0 -1]`), so
//!    `C` is never stored: the diagonal details read it off `V` and `U`. Applied
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
//! # Rotating one map many times
//!
//! A renderer brings one BRDF into every vertex's frame: the same source, a new rotation each
//! time. [`Rotator`] does step 1 and the source's share of step 6 once; a rotation then costs
//! steps 2-5 alone. Four things make those cheap:
//!
//! * **Zonal sources** (constant along every row, such as a Phong lobe about +Y; detected
//!   exactly, [`SourceGradient::is_zonal`]): `f_phi` is zero and every column of `f_theta` is
//!   the same, so the interpolation of step 3 is one-dimensional and the azimuth of the
//!   pre-image is never needed. This is the general method's arithmetic with terms that are
//!   exactly zero left out (the two agree to rounding, tested).
//!   A zonal source's geometry needs only `Theta = atan2(rho, q_y)` and
//!   `dTheta = -(R dp)_y / rho`, each of `q` and `(R dp)_y` linear in `(sin phi, cos phi)`
//!   along a row, with no frame at `q`.
//! * **Rows at once.** That geometry (the angle from the pole by a polynomial
//!   [`atan2`](super::latlong::atan2)) runs over a row of targets in a branch-free loop the
//!   compiler vectorises, in the map's precision (an `f32` map gets `f32` geometry: within
//!   2e-7 of the `f64` result's peak, tested), then the interpolation reads the profile. On
//!   x86-64 with AVX2 the row is compiled for AVX2 and chosen at run time, and a one-channel
//!   `f32` row gathers its profile taps eight at a time; it gives the portable build's bits
//!   (tested).
//! * **Nothing where the lobe is zero.** A clamped-cosine lobe (Phong, Blinn-Phong) is zero
//!   on a hemisphere or more, and so is its profile past some row. A target whose pre-image
//!   lies there (`cos Theta` beyond a bound with the taps' reach as margin) would read only
//!   zeros: whole rows (`q_y` swings within `a -+ sqrt(b^2 + c^2)` along a row) and chunks of
//!   32 targets are written as zeros without their angles (exactly the computed values,
//!   tested).
//! * **Two fields, not three.** `C` is read off `V` and `U` (step 5), so each level filters
//!   two fields and stores no diagonal one.
//!
//! A source turned by `k` whole columns is read `k` columns on ([`Rotator::rotate_turned`]):
//! the same taps and weights as the turned map's own fields, at no cost. Measured
//! (`cargo bench --bench sphere -- lobe_one_channel`, 64 x 128 `f32`, one channel, one run,
//! `results/sphere/lobe_one_channel.txt`):
//! a prepared rotation 95 us (`haar`) and 0.25 ms (`haar-cubic`), against 0.41 ms for writing
//! the analytic lobe; steps 4-6 alone (`pyramid_of_fields`) 15 us, channel by channel so that
//! the column pairs are `[T; 2]` chunks. The Phong lobe is zero on a hemisphere, whose targets
//! are skipped; a lobe with no zero region pays for every target. From the thesis's level 4
//! (16 x 32 working grid) a rotation costs 12 us.
//!
//! # Accuracy
//!
//! For a smooth `f` sampled on the grid, the derivatives of step 2 converge to the analytic
//! ones at second order (the interpolation and the midpoint differences are both
//! `O(delta^2)`), including next to the poles; the tests check the rate. For a sharp feature
//! (the sun) the method is a derivative-domain resampling whose errors are of the size of the
//! feature's own differences.
//!
//! # The higher-order scheme ([`Scheme::Cubic`], `haar-cubic`)
//!
//! The seed's scheme has three second-order errors, each replaced by a fourth-order one
//! (for a map of samples at the texel centres):
//!
//! * step 1: `f`'s derivative on an edge from four samples across it,
//!   `(27 (X[k] - X[k-1]) - (X[k+1] - X[k-2])) / (24 delta)`, continued over seam and poles
//!   (the in-block difference is the level-`L` detail; the outer two come from the blocks
//!   next to it);
//! * step 3: Catmull-Rom interpolation of the two derivative fields over 4 x 4 edges (16
//!   taps instead of 4), with the sign flip of a tangent component across a pole;
//! * step 4: a difference of samples is not `delta` times the midpoint derivative but
//!   `delta (g' + delta^2 g''' / 24)`; the third derivative along the difference comes from
//!   second differences of the midpoint derivatives, which needs `g_theta` on the two edges
//!   across the poles as well: `V = V_mid + (V_mid[i-1] - 2 V_mid[i] + V_mid[i+1]) / 24`,
//!   likewise `U` along `phi` (periodic).
//!
//! Step 6 changes too: the plain solid-angle sum of samples is off the integral by an
//! `O(delta^2)` term proportional to the values at the two poles, which a rotation changes
//! (a lobe moved off the pole loses 0.5 % of its sum at 64 x 128, exponent 50), so the
//! constant is chosen to keep the pole-corrected sum ([`sampled_integral`]), rotation
//! invariant to `O(delta^4)`. Cost: the same chain-rule evaluations (plus the two pole rows),
//! 16 taps each instead of 4. Individual coefficients ([`rotate_selected`]) use the seed's
//! scheme.
//!
//! Measured ([`lobes`](super::lobes), 64 x 128, Phong exponents 10 and 50 about the pole
//! and a horizon direction, pitch 30 to 90 and a compound rotation): against the analytic
//! rotated lobe at the texel centres `haar-cubic`'s weighted RMS error is 0.37 to 0.83 times
//! bicubic's (and 3 % to 8 % of the seed's scheme's); against the lobe's texel means, where
//! every method carries the point-versus-mean difference of its input, 0.96 to 1.02 times.
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

use std::any::Any;
use std::f64::consts::PI;

use ndarray::{
    Array2, Array3, ArrayBase, ArrayView3, ArrayViewMut2, Axis, CowArray, Data, Dimension, Ix2, s,
};
use rayon::prelude::*;

use super::latlong::{
    atan2_finite, azimuth, catmull_rom, continue_index, for_each_row, pixel_solid_angle,
    rows_from_fn,
};
use super::{LatLongMap, SphereCoefficients, SphereRotation};
use crate::transform::{Band, pyramid};
use crate::{Error, Result, Sample};

/// How the chain rule reads `f`'s derivatives and turns `g`'s into differences.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum Scheme {
    /// The seed's: two-point differences of `f`, bilinear interpolation at the pre-image,
    /// `g`'s differences as `delta` times its midpoint derivative ([`Method::Haar`]).
    ///
    /// [`Method::Haar`]: super::Method::Haar
    #[default]
    Linear,
    /// Higher order: four-point differences of `f`, Catmull-Rom interpolation at the
    /// pre-image, `g`'s differences corrected by the third derivative along the difference
    /// ([`Method::HaarCubic`]).
    ///
    /// [`Method::HaarCubic`]: super::Method::HaarCubic
    Cubic,
}

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
    scheme: Scheme,
    m: usize,
    n: usize,
    channels: usize,
    step: f64,
    /// `1 / step`.
    inverse_step: f64,
    /// `f_theta` at `(i delta, (j + 1/2) delta)`, `i` in `0..=m`: `(m + 1) x n x C`.
    d_theta: Vec<T>,
    /// `f_phi / sin theta` at `((i + 1/2) delta, (j + 1) delta)`: `m x n x C`.
    d_phi: Vec<T>,
    /// For a zonal `f` (constant along every row: a lobe about the pole), `f_theta` of one
    /// column; `d_phi` is then zero.
    zonal: Option<ZonalProfile<T>>,
    /// `(sin, cos)` of `k delta / 2`, `k` in `0..=2n + 2`: every angle the target grids use.
    trig: Vec<(f64, f64)>,
    /// The column angles of the two target grids as flat arrays, for loops over a row:
    /// `[sin, cos]` of `(j + 1/2) delta` (index 0) and of `(j + 1) delta` (index 1).
    columns: [[Vec<T>; 2]; 2],
}

impl<T: Sample> SourceGradient<T> {
    /// The derivative maps of `approx` (an approximation of `f` at the working resolution)
    /// by the two-point differences of [`Scheme::Linear`].
    pub fn new(approx: &LatLongMap<T>) -> Self {
        Self::with_scheme(approx, Scheme::Linear)
    }

    /// The derivative maps of `approx` by `scheme`'s differences: two-point
    /// `(X[k] - X[k-1]) / delta`, or four-point
    /// `(27 (X[k] - X[k-1]) - (X[k+1] - X[k-2])) / (24 delta)` (fourth order for samples).
    ///
    /// ```
    /// use haarshift::sphere::{LatLongMap, chain_rule::{Scheme, SourceGradient}};
    /// let f = LatLongMap::<f64>::from_fn(64, 1, |d, out| out[0] = d[1]).unwrap();
    /// let grad = SourceGradient::with_scheme(&f, Scheme::Cubic);
    /// let (mut ft, mut gp) = ([0.0], [0.0]);
    /// grad.eval(1.0, 2.0, &mut ft, &mut gp);
    /// assert!((ft[0] + 1.0f64.sin()).abs() < 1e-5 && gp[0].abs() < 1e-12);
    /// ```
    pub fn with_scheme(approx: &LatLongMap<T>, scheme: Scheme) -> Self {
        let (m, n, ch) = approx.as_array().dim();
        let x = approx.as_array();
        let x = x.as_slice().expect("maps are in standard layout");
        let step = PI / m as f64;
        let px = |r: isize, c: isize| {
            let (r, c, _) = continue_index(r, c, m, n);
            &x[(r * n + c) * ch..][..ch]
        };
        let mut d_theta = vec![T::zero(); (m + 1) * n * ch];
        for_each_row(&mut d_theta, n * ch, |i, row| {
            let inv = T::from_f64(1.0 / step);
            let i = i as isize;
            for (j, out) in row.chunks_exact_mut(ch).enumerate() {
                let j = j as isize;
                difference(scheme, out, inv, |k| px(i + k, j));
            }
        });
        let mut d_phi = vec![T::zero(); m * n * ch];
        for_each_row(&mut d_phi, n * ch, |i, row| {
            let inv = T::from_f64(1.0 / (step * ((i as f64 + 0.5) * step).sin()));
            let i = i as isize;
            for (j, out) in row.chunks_exact_mut(ch).enumerate() {
                let j = j as isize;
                difference(scheme, out, inv, |k| px(i, j + 1 + k));
            }
        });
        // Zonal exactly, not nearly: the zonal path then gives what the general one would.
        let zonal = (d_phi.iter().all(|v| *v == T::zero())
            && d_theta
                .chunks_exact(n * ch)
                .all(|row| row.chunks_exact(ch).all(|px| px == &row[..ch])))
        .then(|| {
            let values: Vec<T> = d_theta
                .chunks_exact(n * ch)
                .flat_map(|row| row[..ch].to_vec())
                .collect();
            ZonalProfile::new(values, ch, step, scheme)
        });
        let half = 0.5 * step;
        let trig: Vec<(f64, f64)> = (0..=2 * n + 2)
            .map(|k| (k as f64 * half).sin_cos())
            .collect();
        let columns = [1, 2].map(|first| {
            let at = |j: usize| trig[first + 2 * j];
            [
                (0..n).map(|j| T::from_f64(at(j).0)).collect(),
                (0..n).map(|j| T::from_f64(at(j).1)).collect(),
            ]
        });
        SourceGradient {
            scheme,
            m,
            n,
            channels: ch,
            step,
            inverse_step: 1.0 / step,
            d_theta,
            d_phi,
            zonal,
            trig,
            columns,
        }
    }

    /// Whether `f` is constant along every row (a function of `theta` alone, such as a lobe
    /// about the pole): its derivatives are then one column of `f_theta`, and a rotation
    /// needs only the angle of each pre-image from the pole.
    ///
    /// ```
    /// use haarshift::sphere::{LatLongMap, chain_rule::SourceGradient};
    /// let lobe = LatLongMap::<f64>::from_fn(16, 1, |d, out| out[0] = d[1].max(0.0).powi(8)).unwrap();
    /// let tilted = LatLongMap::<f64>::from_fn(16, 1, |d, out| out[0] = d[0].max(0.0)).unwrap();
    /// assert!(SourceGradient::new(&lobe).is_zonal() && !SourceGradient::new(&tilted).is_zonal());
    /// ```
    pub fn is_zonal(&self) -> bool {
        self.zonal.is_some()
    }

    /// `f_theta` and `f_phi / sin theta` at `(theta, phi)`, one value per channel each
    /// (step 3 of the [module docs](self)), interpolated as the scheme says.
    pub fn eval(&self, theta: f64, phi: f64, f_theta: &mut [T], f_phi_over_sin: &mut [T]) {
        self.write(theta, phi, 1.0, 0.0, 0, f_theta);
        self.write(theta, phi, 0.0, 1.0, 0, f_phi_over_sin);
    }

    /// Writes `alpha f_theta + beta f_phi / sin theta` at `(theta, phi)` (`theta` in
    /// `[0, pi]`, `phi` in `[0, 2 pi)`) into `out`: the chain rule's combination, fused with
    /// the interpolation so that no temporary is written. The fields are read `turn` columns
    /// further on, which is reading the fields of `f` turned by `turn` columns
    /// ([`yaw_pixels`](super::yaw::yaw_pixels)) with the same taps and weights.
    #[inline]
    fn write(&self, theta: f64, phi: f64, alpha: f64, beta: f64, turn: usize, out: &mut [T]) {
        if let Some(zonal) = &self.zonal {
            return self.interpolate_zonal(zonal, &[theta], &[alpha], out);
        }
        out.fill(T::zero());
        match self.scheme {
            Scheme::Linear => self.accumulate_linear((theta, phi), (alpha, beta), turn, out),
            Scheme::Cubic => self.accumulate_cubic((theta, phi), (alpha, beta), turn, out),
        }
    }

    /// [`write`](Self::write) of a zonal `f` for a run of targets: writes
    /// `alpha[j] f_theta(theta[j])` into pixel `j` of `out` (`C` values each). `f_phi` is zero
    /// and every column of `f_theta` is `profile`, so the bilinear (Catmull-Rom)
    /// interpolation of the general path reduces to a linear (cubic) one along `theta`, its
    /// weights across the columns summing to 1; across a pole the profile continues negated
    /// (a tangent component). The linear scheme computes in `T` (its two taps need no
    /// more), the cubic one in `f64`, rounded once per value.
    #[inline(always)]
    fn interpolate_zonal<A: Sample>(
        &self,
        profile: &ZonalProfile<T>,
        theta: &[A],
        alpha: &[A],
        out: &mut [T],
    ) {
        // The common channel counts as constants, so the channel loop disappears.
        match self.channels {
            1 => self.interpolate_zonal_channels::<1, A>(profile, theta, alpha, out),
            3 => self.interpolate_zonal_channels::<3, A>(profile, theta, alpha, out),
            _ => self.interpolate_zonal_channels::<0, A>(profile, theta, alpha, out),
        }
    }

    /// [`interpolate_zonal`](Self::interpolate_zonal) for `CH` channels (0: any number).
    #[inline(always)]
    fn interpolate_zonal_channels<const CH: usize, A: Sample>(
        &self,
        profile: &ZonalProfile<T>,
        theta: &[A],
        alpha: &[A],
        out: &mut [T],
    ) {
        let (m, ch) = (self.m, if CH == 0 { self.channels } else { CH });
        if self.scheme == Scheme::Linear {
            self.interpolate_zonal_linear::<CH, A>(&profile.spans, theta, alpha, out);
            return;
        }
        let profile = &profile.values;
        let targets = out.chunks_exact_mut(ch).zip(theta.iter().zip(alpha));
        for (px, (&theta, &alpha)) in targets {
            let (y, alpha) = (theta.as_f64() * self.inverse_step, alpha.as_f64());
            // (entry, weight) of the four taps along the profile, continued over the poles.
            let mut taps = [(0usize, 0.0); 4];
            let r0 = (y + 1.0) as isize - 1;
            for (dr, w) in catmull_rom(y - r0 as f64).into_iter().enumerate() {
                let row = r0 - 1 + dr as isize;
                let (r, w) = if row < 0 {
                    (-row, -w)
                } else if row > m as isize {
                    (2 * m as isize - row, -w)
                } else {
                    (row, w)
                };
                taps[dr] = (r as usize * ch, alpha * w);
            }
            for k in 0..ch {
                let value: f64 = taps
                    .iter()
                    .map(|&(at, w)| w * profile[at + k].as_f64())
                    .sum();
                px[k] = T::from_f64(value);
            }
        }
    }

    /// The linear interpolation of [`interpolate_zonal`](Self::interpolate_zonal): two taps,
    /// never across a pole (rows `0..=m` hold every `theta` in `[0, pi]`), in `T`. A chunk
    /// of targets at a time: first each target's row and weights, in a loop without lookups
    /// (it vectorises but for the saturating float-to-index conversion), then the lookups:
    /// each reads one span of two neighbouring rows ([`ZonalProfile::spans`]) and takes three
    /// operations a value. The AVX2 build does both for one channel of `f32` with vector
    /// conversions and gathers ([`interpolate_f32_avx2`]).
    #[inline(always)]
    fn interpolate_zonal_linear<const CH: usize, A: Sample>(
        &self,
        spans: &[T],
        theta: &[A],
        alpha: &[A],
        out: &mut [T],
    ) {
        const CHUNK: usize = 32;
        let (m, ch) = (self.m, if CH == 0 { self.channels } else { CH });
        let spans = &spans[..2 * m * ch];
        let (inverse_step, last) = (T::from_f64(self.inverse_step), T::from_f64((m - 1) as f64));
        let chunks = theta.chunks(CHUNK).zip(alpha.chunks(CHUNK));
        for ((theta, alpha), out) in chunks.zip(out.chunks_mut(CHUNK * ch)) {
            let (mut at, mut w0, mut w1) = ([0u32; CHUNK], [T::zero(); CHUNK], [T::zero(); CHUNK]);
            let taps = at.iter_mut().zip(w0.iter_mut().zip(w1.iter_mut()));
            for ((at, (w0, w1)), (&theta, &alpha)) in taps.zip(theta.iter().zip(alpha)) {
                let y = T::from_f64(theta.as_f64()) * inverse_step;
                // theta is finite (atan2), so is y: the row is in 0..m and exact.
                let r = y.floor().min(last).max(T::zero());
                let (fy, alpha) = (y - r, T::from_f64(alpha.as_f64()));
                *at = r.as_f64() as u32 * ch as u32;
                *w0 = alpha * (T::one() - fy);
                *w1 = alpha * fy;
            }
            let taps = at.iter().zip(w0.iter().zip(&w1));
            for (px, (&at, (&w0, &w1))) in out.chunks_exact_mut(ch).zip(taps) {
                let (here, next) = spans[2 * at as usize..][..2 * ch].split_at(ch);
                for k in 0..ch {
                    px[k] = w0 * here[k] + w1 * next[k];
                }
            }
        }
    }

    /// [`accumulate`](Self::accumulate) by bilinear interpolation.
    #[inline]
    fn accumulate_linear(
        &self,
        (theta, phi): (f64, f64),
        (alpha, beta): (f64, f64),
        turn: usize,
        out: &mut [T],
    ) {
        let (m, n) = (self.m, self.n);
        // Columns from -1 to below 3n (a half turn over a pole plus the turn) onto 0..n.
        let wrap = |c: isize| -> usize {
            let c = c + turn as isize;
            if c < 0 {
                (c + n as isize) as usize
            } else if c >= 2 * n as isize {
                c as usize - 2 * n
            } else if c >= n as isize {
                c as usize - n
            } else {
                c as usize
            }
        };
        // (entry, weight) of the four taps of each field.
        let mut ft = [(0usize, T::zero()); 4];
        let mut gp = [(0usize, T::zero()); 4];
        // f_theta: rows at theta = i delta, i = 0..=m; no continuation needed in theta.
        // (Positions are at least -1, so `(x + 1) as isize - 1` is their floor.)
        let y = theta / self.step;
        let r0 = (y as usize).min(m - 1);
        let fy = y - r0 as f64;
        let x = phi / self.step - 0.5;
        let c0 = (x + 1.0) as isize - 1;
        let fx = x - c0 as f64;
        let (ca, cb) = (wrap(c0), wrap(c0 + 1));
        for (t, (r, wy)) in [(r0, 1.0 - fy), (r0 + 1, fy)].into_iter().enumerate() {
            ft[2 * t] = (r * n + ca, T::from_f64(alpha * wy * (1.0 - fx)));
            ft[2 * t + 1] = (r * n + cb, T::from_f64(alpha * wy * fx));
        }
        // f_phi / sin theta: rows at (i + 1/2) delta, columns at (j + 1) delta; over a pole
        // (rows -1 and m) the row is continued half a turn away and the tangent component
        // flips sign.
        let y = theta / self.step - 0.5;
        let r0 = (y + 1.0) as isize - 1;
        let fy = y - r0 as f64;
        let x = phi / self.step - 1.0;
        let c0 = (x + 1.0) as isize - 1;
        let fx = x - c0 as f64;
        let half = n as isize / 2;
        for (t, (r, wy)) in [(r0, 1.0 - fy), (r0 + 1, fy)].into_iter().enumerate() {
            let (r, across, w) = if r < 0 {
                (0, half, -beta * wy)
            } else if r >= m as isize {
                (m - 1, half, -beta * wy)
            } else {
                (r as usize, 0, beta * wy)
            };
            gp[2 * t] = (r * n + wrap(c0 + across), T::from_f64(w * (1.0 - fx)));
            gp[2 * t + 1] = (r * n + wrap(c0 + 1 + across), T::from_f64(w * fx));
        }
        self.apply_taps(&ft, &gp, out);
    }

    /// `out[k] += sum w d_theta[e][k] + sum w d_phi[e][k]` over the `(entry, weight)` taps
    /// of each field, one channel at a time so that the sum stays in a register.
    #[inline]
    fn apply_taps(&self, ft: &[(usize, T)], gp: &[(usize, T)], out: &mut [T]) {
        let ch = self.channels;
        for (k, o) in out.iter_mut().enumerate() {
            let mut acc = *o;
            for &(e, w) in ft {
                acc += w * self.d_theta[e * ch + k];
            }
            for &(e, w) in gp {
                acc += w * self.d_phi[e * ch + k];
            }
            *o = acc;
        }
    }

    /// [`accumulate`](Self::accumulate) by Catmull-Rom interpolation over 4 x 4 edges of
    /// each field, continued over the seam and the poles (a tangent component changes sign
    /// across a pole: `f_theta` on the edge rows `-k` and `m + k` is minus the one on rows
    /// `k` and `m - k` half a turn away).
    #[inline]
    fn accumulate_cubic(
        &self,
        (theta, phi): (f64, f64),
        (alpha, beta): (f64, f64),
        turn: usize,
        out: &mut [T],
    ) {
        let (m, n) = (self.m as isize, self.n as isize);
        let turn = turn as isize;
        // f_theta: rows at i delta (i = 0..=m), columns at (j + 1/2) delta.
        let ft = cubic_taps((theta / self.step, phi / self.step - 0.5), alpha, |r, c| {
            let (r, flip) = if r < 0 {
                (-r, true)
            } else if r > m {
                (2 * m - r, true)
            } else {
                (r, false)
            };
            let c = if flip { c + n / 2 } else { c } + turn;
            (r as usize * self.n + c.rem_euclid(n) as usize, flip)
        });
        // f_phi / sin theta: rows at (i + 1/2) delta, columns at (j + 1) delta.
        let gp = cubic_taps(
            (theta / self.step - 0.5, phi / self.step - 1.0),
            beta,
            |r, c| {
                let (r, c, crossed) = continue_index(r, c + turn, self.m, self.n);
                (r * self.n + c, crossed)
            },
        );
        self.apply_taps(&ft, &gp, out);
    }
}

/// The derivative of `scheme` at the edge between samples `at(-1)` and `at(0)`, times
/// `inv` (`1 / delta`, or that over `sin theta`), into `out`.
#[inline]
fn difference<'a, T: Sample>(scheme: Scheme, out: &mut [T], inv: T, at: impl Fn(isize) -> &'a [T]) {
    match scheme {
        Scheme::Linear => {
            for ((o, &b), &a) in out.iter_mut().zip(at(0)).zip(at(-1)) {
                *o = (b - a) * inv;
            }
        }
        Scheme::Cubic => {
            let (near, far) = (T::from_f64(27.0 / 24.0), T::from_f64(1.0 / 24.0));
            let (a, b, c, d) = (at(-2), at(-1), at(0), at(1));
            for (k, o) in out.iter_mut().enumerate() {
                *o = (near * (c[k] - b[k]) - far * (d[k] - a[k])) * inv;
            }
        }
    }
}

/// The 16 `(entry, weight)` taps of `scale` times the Catmull-Rom interpolation of a
/// staggered field at continuous grid position `(y, x)` (entries at whole numbers, `y` and
/// `x` at least -1). `index(r, c)` continues an entry position over seam and poles: its
/// entry and whether to negate it.
#[inline]
fn cubic_taps<T: Sample>(
    (y, x): (f64, f64),
    scale: f64,
    index: impl Fn(isize, isize) -> (usize, bool),
) -> [(usize, T); 16] {
    let (r0, c0) = ((y + 1.0) as isize - 1, (x + 1.0) as isize - 1);
    let (wy, wx) = (catmull_rom(y - r0 as f64), catmull_rom(x - c0 as f64));
    let (r0, c0) = (r0 - 1, c0 - 1);
    let mut taps = [(0usize, T::zero()); 16];
    for (dr, &wr) in wy.iter().enumerate() {
        let wr = scale * wr;
        for (dc, &wc) in wx.iter().enumerate() {
            let (at, flip) = index(r0 + dr as isize, c0 + dc as isize);
            taps[4 * dr + dc] = (at, T::from_f64(if flip { -wr * wc } else { wr * wc }));
        }
    }
    taps
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

/// Where a target direction comes from: its pre-image `q = R p`, the rotated tangent
/// `R dp/d(along)`, the angle `Theta` of `q` from the pole, the frame's azimuth `(sin, cos)`
/// and the tangent's component along `e_Theta(q)` (step 2 of the [module docs](self)).
struct PreImage {
    q: [f64; 3],
    tangent: [f64; 3],
    theta: f64,
    sin_phi: f64,
    cos_phi: f64,
    along_theta: f64,
}

/// The [`PreImage`] of the target at `(sin, cos)` of `theta` and of `phi`. Branch-free, so
/// that a loop over a row vectorises.
#[inline(always)]
fn pre_image(
    rotation: &SphereRotation,
    (st, ct): (f64, f64),
    (sp, cp): (f64, f64),
    along: Along,
) -> PreImage {
    let p = [st * sp, ct, st * cp];
    let tangent = match along {
        Along::Theta => [ct * sp, -st, ct * cp],
        Along::Phi => [st * cp, 0.0, -st * sp],
    };
    let q = rotation.apply(p);
    let tq = rotation.apply(tangent);
    // The frame at q straight from q (atan2's convention at the poles: Phi = 0).
    let rho = (q[0] * q[0] + q[2] * q[2]).sqrt();
    let inv = 1.0 / rho;
    let (s_p, c_p) = if rho > 0.0 {
        (q[0] * inv, q[2] * inv)
    } else {
        (0.0, 1.0)
    };
    let c_t = q[1].clamp(-1.0, 1.0);
    PreImage {
        q,
        tangent: tq,
        theta: atan2_finite(rho, q[1]),
        sin_phi: s_p,
        cos_phi: c_p,
        along_theta: dot([c_t * s_p, -rho, c_t * c_p], tq),
    }
}

/// A zonal source's `f_theta` along one column, and where it can be nonzero.
#[derive(Clone, Debug)]
struct ZonalProfile<T> {
    /// `f_theta` at `theta = i delta`, `i` in `0..=m`: `(m + 1) x C`.
    values: Vec<T>,
    /// Rows `r` and `r + 1` of `values` side by side for each `r` in `0..m`: `m x 2 x C`, so
    /// that a linear tap pair is one contiguous read.
    spans: Vec<T>,
    /// `(low, high)`: a target whose pre-image has `cos Theta = q_y` outside `[low, high]`
    /// reads only zero rows of `values`, so its value is exactly zero and is not computed.
    /// Every clamped-cosine lobe (Phong, Blinn-Phong about their axes) is zero on a
    /// hemisphere or more.
    cos_bounds: (f64, f64),
}

impl<T: Sample> ZonalProfile<T> {
    /// The profile `values` (`C` channels, rows `delta` apart) for `scheme`'s interpolation,
    /// and its bounds: past the first and last nonzero rows by the rows the taps reach (one
    /// for the linear scheme's pair, two for the cubic one's four,
    /// [`SourceGradient::interpolate_zonal`]) and a hundredth of a row more, so that the
    /// rounding of the computed angle never matters; no bound where that would reach a pole,
    /// across which the taps fold back.
    fn new(values: Vec<T>, ch: usize, step: f64, scheme: Scheme) -> Self {
        let m = values.len() / ch - 1;
        let reach = match scheme {
            Scheme::Linear => 1.01,
            Scheme::Cubic => 2.01,
        };
        let nonzero = |i: &usize| values[i * ch..][..ch].iter().any(|v| *v != T::zero());
        let cos_bounds = match (0..=m).find(nonzero) {
            // A constant source: every derivative is zero.
            None => (f64::INFINITY, f64::NEG_INFINITY),
            Some(first) => {
                let last = (first..=m).rev().find(nonzero).unwrap_or(first);
                let (near, far) = (first as f64 - reach, last as f64 + reach);
                let high = if near > 0.0 {
                    (near * step).cos()
                } else {
                    f64::INFINITY
                };
                let low = if far < m as f64 {
                    (far * step).cos()
                } else {
                    f64::NEG_INFINITY
                };
                (low, high)
            }
        };
        let spans = (0..m)
            .flat_map(|r| values[r * ch..(r + 2) * ch].iter().copied())
            .collect();
        ZonalProfile {
            values,
            spans,
            cos_bounds,
        }
    }
}

/// For a zonal source, the chain rule's geometry along one row of targets: with `q = R p` the
/// pre-image of the target `p`, `Theta = atan2(rho, q_y)` (`rho` the length of `(q_x, q_z)`)
/// and `scale * dTheta/d(along) = -scale (R dp)_y / rho`. That factor is the general path's
/// `e_Theta(q) . R dp` (the two are equal because `q . R dp = 0`) with the frame at `q` never
/// formed: 18 products fewer per target. Its size is at most `|dp| <= 1`; it is clamped
/// there, so that a pre-image on a pole (`rho = 0`, where a zonal profile is exactly zero)
/// gives a finite factor. Along the row each of `q` and `(R dp)_y` is
/// `a + b sin(phi) + c cos(phi)`: the row's coefficients are formed once, in `G`.
struct ZonalRow<G> {
    /// `[a, b, c]` of `q_x`, `q_y`, `q_z`.
    q: [[G; 3]; 3],
    /// `[a, b, c]` of `(R dp)_y`.
    t: [G; 3],
    scale: G,
}

impl<G: Sample> ZonalRow<G> {
    /// The row at `(sin, cos)` of `theta`, for the derivative `along`, times `scale`.
    #[inline(always)]
    fn new(rotation: &SphereRotation, (st, ct): (f64, f64), along: Along, scale: f64) -> Self {
        let r = rotation.matrix();
        let g = G::from_f64;
        let q = r.map(|row| [row[1] * ct, row[0] * st, row[2] * st].map(g));
        let t = match along {
            // dp/dtheta = (cos theta sin phi, -sin theta, cos theta cos phi)
            Along::Theta => [-r[1][1] * st, r[1][0] * ct, r[1][2] * ct],
            // dp/dphi = (sin theta cos phi, 0, -sin theta sin phi)
            Along::Phi => [0.0, -r[1][2] * st, r[1][0] * st],
        }
        .map(g);
        ZonalRow {
            q,
            t,
            scale: g(scale),
        }
    }

    #[inline(always)]
    fn line([a, b, c]: [G; 3], sp: G, cp: G) -> G {
        a + b * sp + c * cp
    }

    /// Whether some target of the row may have its pre-image's `q_y` in `[low, high]`: along
    /// the row `q_y = a + b sin(phi) + c cos(phi)` stays within `a -+ sqrt(b^2 + c^2)`.
    #[inline(always)]
    fn may_reach(&self, (low, high): (G, G)) -> bool {
        let [a, b, c] = self.q[1];
        let swing = (b * b + c * c).sqrt();
        a + swing >= low && a - swing <= high
    }

    /// Whether any target at the columns' `(sin, cos)` of `phi` has its pre-image's `q_y` in
    /// `[low, high]`. No early exit, so that the loop vectorises.
    #[inline(always)]
    fn reaches(&self, (sines, cosines): (&[G], &[G]), (low, high): (G, G)) -> bool {
        let targets = sines.iter().zip(cosines);
        targets.fold(false, |any, (&sp, &cp)| {
            let qy = Self::line(self.q[1], sp, cp);
            any | ((qy >= low) & (qy <= high))
        })
    }

    /// `Theta` and the factor of each target at the columns' `(sin, cos)` of `phi` into
    /// `theta` and `alpha`. Branch-free, so that the loop vectorises.
    #[inline(always)]
    fn angles(&self, (sines, cosines): (&[G], &[G]), (theta, alpha): (&mut [G], &mut [G])) {
        let (one, tiny, q, t) = (G::one(), G::min_positive_value(), self.q, self.t);
        let targets = theta.iter_mut().zip(alpha.iter_mut());
        for ((th, al), (&sp, &cp)) in targets.zip(sines.iter().zip(cosines)) {
            let qx = Self::line(q[0], sp, cp);
            let (qy, qz) = (Self::line(q[1], sp, cp), Self::line(q[2], sp, cp));
            let rho = (qx * qx + qz * qz).sqrt();
            *th = atan2_finite(rho, qy);
            let d = -Self::line(t, sp, cp) / rho.max(tiny);
            *al = self.scale * d.max(-one).min(one);
        }
    }
}

/// Targets of a zonal row computed together: four AVX2 vectors of `f32`.
const ZONAL_CHUNK: usize = 32;

/// [`SourceGradient::interpolate_zonal`] of one channel of `f32` by the linear scheme, for
/// one chunk: the rows, weights and two taps of eight targets at a time, the taps gathered
/// from `spans` ([`ZonalProfile::spans`]) by the rows found. The operations of the portable
/// loop in the same order and with no fused multiply-adds, so the same bits; the rows are
/// clamped to `0..m` exactly as there, which keeps every gathered index in `spans`.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
fn interpolate_f32_avx2(
    spans: &[f32],
    inverse_step: f32,
    (theta, alpha): (&[f32; ZONAL_CHUNK], &[f32; ZONAL_CHUNK]),
    out: &mut [f32; ZONAL_CHUNK],
) {
    use std::arch::x86_64::*;
    let m = spans.len() / 2;
    // Every row index is in 0..m, so every gathered index (2 row + 0 or 1) is in spans.
    assert!((1..1 << 24).contains(&m), "a profile of {m} rows");
    let (last, zero, one) = (
        _mm256_set1_ps((m - 1) as f32),
        _mm256_setzero_ps(),
        _mm256_set1_ps(1.0),
    );
    let step = _mm256_set1_ps(inverse_step);
    for k in (0..ZONAL_CHUNK).step_by(8) {
        let (theta, alpha, out) = (&theta[k..k + 8], &alpha[k..k + 8], &mut out[k..k + 8]);
        // SAFETY: the loads and the store touch the eight values of the slices above; every
        // gathered index (`at` and `at + 1`) is below 2m = spans.len() (the assertion above
        // and the clamp of the rows).
        unsafe {
            let y = _mm256_mul_ps(_mm256_loadu_ps(theta.as_ptr()), step);
            // floor, then min and max as the portable loop (a NaN takes the last row there too).
            let r = _mm256_max_ps(_mm256_min_ps(_mm256_floor_ps(y), last), zero);
            let fy = _mm256_sub_ps(y, r);
            let a = _mm256_loadu_ps(alpha.as_ptr());
            let (w0, w1) = (
                _mm256_mul_ps(a, _mm256_sub_ps(one, fy)),
                _mm256_mul_ps(a, fy),
            );
            let at = _mm256_slli_epi32::<1>(_mm256_cvttps_epi32(r));
            let here = _mm256_i32gather_ps::<4>(spans.as_ptr(), at);
            let next = _mm256_i32gather_ps::<4>(spans.as_ptr().add(1), at);
            let value = _mm256_add_ps(_mm256_mul_ps(w0, here), _mm256_mul_ps(w1, next));
            _mm256_storeu_ps(out.as_mut_ptr(), value);
        }
    }
}

/// The chain rule (4.15)/(4.16) for one rotation and one source.
struct ChainRule<'a, T> {
    grad: &'a SourceGradient<T>,
    rotation: &'a SphereRotation,
    /// Columns the source is turned by before the rotation (exact, [`SourceGradient`]).
    turn: usize,
}

impl<'a, T: Sample> ChainRule<'a, T> {
    fn new(grad: &'a SourceGradient<T>, rotation: &'a SphereRotation, turn: usize) -> Self {
        ChainRule {
            grad,
            rotation,
            turn,
        }
    }

    /// `scale * dg/d(along)` at the angles `(theta, phi) = (kt, kp) * delta / 2` into `out`.
    #[inline]
    fn derivative(&self, kt: usize, kp: usize, along: Along, scale: f64, out: &mut [T]) {
        let (st, ct) = self.grad.trig[kt];
        let (sp, cp) = self.grad.trig[kp];
        if let Some(zonal) = &self.grad.zonal {
            // No azimuth needed: f has no phi derivative.
            let (mut theta, mut alpha) = ([T::zero()], [T::zero()]);
            let columns = ([T::from_f64(sp)], [T::from_f64(cp)]);
            let row = ZonalRow::new(self.rotation, (st, ct), along, scale);
            row.angles((&columns.0, &columns.1), (&mut theta, &mut alpha));
            self.grad.interpolate_zonal(zonal, &theta, &alpha, out);
            return;
        }
        let at = pre_image(self.rotation, (st, ct), (sp, cp), along);
        let (q, tq) = (at.q, at.tangent);
        let beta = scale * dot([at.cos_phi, 0.0, -at.sin_phi], tq);
        let big_p = azimuth(q[0], q[2]);
        let alpha = scale * at.along_theta;
        self.grad
            .write(at.theta, big_p, alpha, beta, self.turn, out);
    }

    /// One row of [`derivative`](Self::derivative): `theta = kt delta / 2` and the columns
    /// `phi = (2j + first) delta / 2` (`first` 1 or 2), `n x C` values into `row`. A zonal
    /// source takes [`zonal_row`](Self::zonal_row); the values are those of `derivative`.
    fn derivative_row(&self, kt: usize, first: usize, along: Along, scale: f64, row: &mut [T]) {
        let ch = self.grad.channels;
        let Some(profile) = &self.grad.zonal else {
            for (j, px) in row.chunks_exact_mut(ch).enumerate() {
                self.derivative(kt, first + 2 * j, along, scale, px);
            }
            return;
        };
        #[cfg(target_arch = "x86_64")]
        if std::arch::is_x86_feature_detected!("avx2") {
            // SAFETY: the CPU has AVX2, the only feature `zonal_row_avx2` is compiled for.
            unsafe { self.zonal_row_avx2(profile, (kt, first), along, scale, row) };
            return;
        }
        self.zonal_row::<false>(profile, (kt, first), along, scale, row)
    }

    /// [`zonal_row`](Self::zonal_row) compiled for AVX2: four lanes of `f64`, eight of `f32`
    /// (whose one-channel linear lookups gather, [`interpolate_f32_avx2`]), and no fused
    /// multiply-adds, so that every CPU gets the same bits.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2")]
    fn zonal_row_avx2(
        &self,
        profile: &ZonalProfile<T>,
        at: (usize, usize),
        along: Along,
        scale: f64,
        row: &mut [T],
    ) {
        self.zonal_row::<true>(profile, at, along, scale, row)
    }

    /// A row of a zonal source's derivative in two passes over chunks of the row: the
    /// geometry ([`ZonalRow::angles`]), then the interpolation
    /// ([`interpolate_zonal`](SourceGradient::interpolate_zonal)); the first vectorises, the
    /// second is a table lookup per target. A chunk whose pre-images all lie where the
    /// profile is zero ([`ZonalProfile::cos_bounds`]) is zero without either.
    /// `AVX2` says the caller runs on an AVX2 CPU.
    #[inline(always)]
    fn zonal_row<const AVX2: bool>(
        &self,
        profile: &ZonalProfile<T>,
        (kt, first): (usize, usize),
        along: Along,
        scale: f64,
        row: &mut [T],
    ) {
        let ch = self.grad.channels;
        let geometry = ZonalRow::<T>::new(self.rotation, self.grad.trig[kt], along, scale);
        let (low, high) = profile.cos_bounds;
        let bounds = (T::from_f64(low), T::from_f64(high));
        if !geometry.may_reach(bounds) {
            row.fill(T::zero());
            return;
        }
        let [sines, cosines] = &self.grad.columns[first - 1];
        let (mut theta, mut alpha) = ([T::zero(); ZONAL_CHUNK], [T::zero(); ZONAL_CHUNK]);
        for (c, pixels) in row.chunks_mut(ZONAL_CHUNK * ch).enumerate() {
            let count = pixels.len() / ch;
            let at = c * ZONAL_CHUNK;
            let columns = (&sines[at..][..count], &cosines[at..][..count]);
            if !geometry.reaches(columns, bounds) {
                pixels.fill(T::zero());
                continue;
            }
            if count < ZONAL_CHUNK {
                let (theta, alpha) = (&mut theta[..count], &mut alpha[..count]);
                geometry.angles(columns, (&mut *theta, &mut *alpha));
                self.grad.interpolate_zonal(profile, theta, alpha, pixels);
                continue;
            }
            geometry.angles(columns, (&mut theta[..], &mut alpha[..]));
            #[cfg(target_arch = "x86_64")]
            if AVX2 && ch == 1 && self.grad.scheme == Scheme::Linear {
                // One channel of f32 (the types checked at run time; nothing is cast).
                let spans = (&profile.spans as &dyn Any).downcast_ref::<Vec<f32>>();
                let angles = (&theta as &dyn Any).downcast_ref::<[f32; ZONAL_CHUNK]>();
                let factors = (&alpha as &dyn Any).downcast_ref::<[f32; ZONAL_CHUNK]>();
                let out = <&mut [T; ZONAL_CHUNK]>::try_from(&mut *pixels).ok();
                let out =
                    out.and_then(|o| (o as &mut dyn Any).downcast_mut::<[f32; ZONAL_CHUNK]>());
                if let (Some(spans), Some(theta), Some(alpha), Some(out)) =
                    (spans, angles, factors, out)
                {
                    let step = self.grad.inverse_step as f32;
                    // SAFETY: `AVX2` is true only in `zonal_row_avx2`, which runs on AVX2 CPUs.
                    unsafe { interpolate_f32_avx2(spans, step, (theta, alpha), out) };
                    continue;
                }
            }
            self.grad.interpolate_zonal(profile, &theta, &alpha, pixels);
        }
    }

    /// `rows x n x C` values of `scale * dg/d(along)`, row `i` at `theta = kt(i) delta / 2`,
    /// column `j` at `phi = (2j + first) delta / 2`.
    fn field(
        &self,
        rows: usize,
        kt: impl Fn(usize) -> usize + Sync,
        first: usize,
        along: Along,
        scale: f64,
    ) -> Array3<T> {
        let (n, ch) = (self.grad.n, self.grad.channels);
        let mut data = Array3::zeros((rows, n, ch));
        let flat = data.as_slice_mut().expect("standard layout");
        for_each_row(flat, n * ch, |i, row| {
            self.derivative_row(kt(i), first, along, scale, row)
        });
        data
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
/// use haarshift::sphere::{LatLongMap, SphereRotation, chain_rule::{DifferenceFields, Scheme}};
/// let f = LatLongMap::<f64>::from_fn(8, 1, |_, out| out[0] = 1.0).unwrap();
/// let r = SphereRotation::from_degrees(0.0, 40.0, 0.0).unwrap();
/// let d = DifferenceFields::rotated(&f, &r, Scheme::Linear);
/// assert_eq!(d.vertical().dim(), (7, 16, 1));
/// assert!(d.horizontal().iter().all(|v| v.abs() < 1e-15)); // a constant has no differences
/// ```
#[derive(Clone, Debug)]
pub struct DifferenceFields<T> {
    v: Array3<T>,
    u: Array3<T>,
}

impl<T: Sample> DifferenceFields<T> {
    /// The fields of `g = f(R p)` from `approx` (`f` at the working resolution) by `scheme`.
    pub fn rotated(approx: &LatLongMap<T>, rotation: &SphereRotation, scheme: Scheme) -> Self {
        Self::from_gradient(&SourceGradient::with_scheme(approx, scheme), rotation, 0)
    }

    /// The fields of `g = f_k(R p)`, `f_k` the source of `grad` turned by `turn` columns.
    fn from_gradient(grad: &SourceGradient<T>, rotation: &SphereRotation, turn: usize) -> Self {
        let (m, n, ch, scheme) = (grad.m, grad.n, grad.channels, grad.scheme);
        let rule = ChainRule::new(grad, rotation, turn);
        let (v, u) = match scheme {
            // V[i][j] = -delta g_theta((i + 1) delta, (j + 1/2) delta),
            // U[i][j] = -delta g_phi((i + 1/2) delta, (j + 1) delta).
            Scheme::Linear => (
                rule.field(m - 1, |i| 2 * i + 2, 1, Along::Theta, -grad.step),
                rule.field(m, |i| 2 * i + 1, 2, Along::Phi, -grad.step),
            ),
            Scheme::Cubic => {
                // Midpoint derivatives on every row edge, the two across the poles included,
                // then the differences of samples to fourth order:
                // X[k] - X[k+1] = -delta (g_1 + delta^2 g_3 / 24) at the edge between them,
                // g_3 (the third derivative) from second differences of the midpoint values.
                let vm = rule.field(m + 1, |e| 2 * e, 1, Along::Theta, -grad.step);
                let um = rule.field(m, |i| 2 * i + 1, 2, Along::Phi, -grad.step);
                let w = T::from_f64(1.0 / 24.0);
                let two = T::from_f64(2.0);
                let (vm, um, len) = (flat(&vm), flat(&um), n * ch);
                let v = rows_from_fn((m - 1, n, ch), |i, out| {
                    let (above, here, below) =
                        (row(vm, len, i), row(vm, len, i + 1), row(vm, len, i + 2));
                    for (e, o) in out.iter_mut().enumerate() {
                        let c = here[e];
                        *o = c + w * (above[e] - two * c + below[e]);
                    }
                });
                let u = rows_from_fn((m, n, ch), |i, out| {
                    let here = row(um, len, i);
                    for (e, o) in out.iter_mut().enumerate() {
                        let c = here[e];
                        let (left, right) = (here[before(e, ch, len)], here[after(e, ch, len)]);
                        *o = c + w * (left - two * c + right);
                    }
                });
                (v, u)
            }
        };
        DifferenceFields { v, u }
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
        let (x, len) = (flat_view(&a), n * ch);
        let v = rows_from_fn((m - 1, n, ch), |i, out| {
            let (here, below) = (row(x, len, i), row(x, len, i + 1));
            for ((o, &a), &b) in out.iter_mut().zip(here).zip(below) {
                *o = a - b;
            }
        });
        let u = rows_from_fn((m, n, ch), |i, out| {
            let here = row(x, len, i);
            for (e, o) in out.iter_mut().enumerate() {
                *o = here[e] - here[after(e, ch, len)];
            }
        });
        DifferenceFields { v, u }
    }

    /// `V`: `(m - 1, n, C)`, `V[i][j] = X[i][j] - X[i+1][j]`.
    pub fn vertical(&self) -> ArrayView3<'_, T> {
        self.v.view()
    }

    /// `U`: `(m, n, C)`, `U[i][j] = X[i][j] - X[i][j+1]` (periodic).
    pub fn horizontal(&self) -> ArrayView3<'_, T> {
        self.u.view()
    }

    /// `C`: `(m - 1, n, C)`, `C[i][j] = X[i][j] - X[i][j+1] - X[i+1][j] + X[i+1][j+1]`, the
    /// mean of its two expressions in `V` and `U` (step 4). Not stored: the diagonal
    /// details read it where they need it (step 5).
    pub fn diagonal(&self) -> Array3<T> {
        mixed_from(&self.v, &self.u)
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
        let half = T::from_f64(0.5);
        for (k, mut plane) in out.axis_iter_mut(Axis(0)).enumerate() {
            // One channel at a time (a view when there is one channel), so that the column
            // pairs of a row are `[T; 2]` chunks.
            let mut fields = ChannelFields {
                v: channel(&self.v, k),
                u: channel(&self.u, k),
            };
            while fields.u.nrows() > 1 {
                let (v, u) = fields.next_level(&mut plane);
                fields = ChannelFields {
                    v: v.into(),
                    u: u.into(),
                };
            }
            // At the 1 x 2 root, U[0][0] = A0 - A1 and U[0][1] = A1 - A0.
            let d = half * (fields.u[[0, 0]] - fields.u[[0, 1]]);
            plane[[0, 0]] = half * d;
            plane[[0, 1]] = -half * d;
        }
        SphereCoefficients::from_array(out)
    }
}

/// One channel's `V` and `U` (step 5 runs channel by channel).
struct ChannelFields<'a, T> {
    v: CowArray<'a, T, Ix2>,
    u: CowArray<'a, T, Ix2>,
}

impl<T: Sample> ChannelFields<'_, T> {
    /// One level of step 5: writes the details of the level whose blocks are 2 x 2 cells of
    /// this grid into `plane`, `b = (V[2I][2J] + V[2I][2J+1]) / 4`,
    /// `a = (U[2I][2J] + U[2I+1][2J]) / 4` and `c = C[2I][2J] / 4` (`C` from `V` and `U`),
    /// and returns the fields `(V', U')` one level coarser (the recursive filters (4.21)-(4.22)):
    /// `V' = h_t (along theta) x h_s (along phi) of V / 4`, `U'` with the roles swapped.
    /// The seed's third recursion, `C' = h_t x h_t of C / 4`, is not needed: it is the mixed
    /// difference of `V'` and `U'` exactly (`h_t` applied to a difference along an axis is
    /// the difference of `h_s` applied along it: `[1 2 1] * [1 -1] = [1 1] * [1 0 -1]`), so
    /// `C` is read off `V` and `U` at every level.
    fn next_level(&self, plane: &mut ArrayViewMut2<'_, T>) -> (Array2<T>, Array2<T>) {
        let (m, n) = self.u.dim();
        let (mh, nh) = (m / 2, n / 2);
        let (q, two) = (T::from_f64(0.25), T::from_f64(2.0));
        let (v, u) = (flat(&self.v), flat(&self.u));
        let level = mh.trailing_zeros() as usize;
        let size = plane.dim();
        let levels = size.0.trailing_zeros() as usize;
        // Row i of band b is written by `f(i, row)`.
        let mut band = |b: Band, f: &dyn Fn(usize, &mut [T])| {
            let (rows, cols) = pyramid::band_ranges(size, levels, b, level).expect("level exists");
            let mut view = plane.slice_mut(s![rows, cols]);
            for (i, mut band_row) in view.rows_mut().into_iter().enumerate() {
                f(
                    i,
                    band_row.as_slice_mut().expect("plane rows are contiguous"),
                );
            }
        };
        band(Band::Vertical, &|i, out| {
            for (o, p) in out.iter_mut().zip(pairs(row(v, n, 2 * i))) {
                *o = q * (p[0] + p[1]);
            }
        });
        band(Band::Horizontal, &|i, out| {
            let (u0, u1) = (pairs(row(u, n, 2 * i)), pairs(row(u, n, 2 * i + 1)));
            for (o, (p0, p1)) in out.iter_mut().zip(u0.iter().zip(u1)) {
                *o = q * (p0[0] + p1[0]);
            }
        });
        band(Band::Diagonal, &|i, out| {
            let vr = pairs(row(v, n, 2 * i));
            let (u0, u1) = (pairs(row(u, n, 2 * i)), pairs(row(u, n, 2 * i + 1)));
            for (o, (pv, (p0, p1))) in out.iter_mut().zip(vr.iter().zip(u0.iter().zip(u1))) {
                *o = q * mixed(pv[0], pv[1], p0[0], p1[0]);
            }
        });
        let v = rows_of((mh.saturating_sub(1), nh), |i, out| {
            let (a, b, d) = (
                pairs(row(v, n, 2 * i)),
                pairs(row(v, n, 2 * i + 1)),
                pairs(row(v, n, 2 * i + 2)),
            );
            for (o, (a, (b, d))) in out.iter_mut().zip(a.iter().zip(b.iter().zip(d))) {
                let c0 = a[0] + two * b[0] + d[0];
                let c1 = a[1] + two * b[1] + d[1];
                *o = q * (c0 + c1);
            }
        });
        let u = rows_of((mh, nh), |i, out| {
            let (a, b) = (row(u, n, 2 * i), row(u, n, 2 * i + 1));
            // `[1 2 1]` along each row from column 2j: columns 2j, 2j + 1 and the next pair's
            // first (periodic).
            let cell = |a: [T; 3], b: [T; 3]| {
                let t0 = a[0] + two * a[1] + a[2];
                let t1 = b[0] + two * b[1] + b[2];
                q * (t0 + t1)
            };
            let (last, out) = out.split_last_mut().expect("a row has columns");
            let (here, next) = (
                pairs(a).iter().zip(pairs(b)),
                pairs(&a[2..]).iter().zip(pairs(&b[2..])),
            );
            for (o, ((a, b), (a2, b2))) in out.iter_mut().zip(here.zip(next)) {
                *o = cell([a[0], a[1], a2[0]], [b[0], b[1], b2[0]]);
            }
            *last = cell([a[n - 2], a[n - 1], a[0]], [b[n - 2], b[n - 1], b[0]]);
        });
        (v, u)
    }
}

/// Channel `k` of a grid in standard layout: a view when it is the only one.
fn channel<T: Sample>(a: &Array3<T>, k: usize) -> CowArray<'_, T, Ix2> {
    let view = a.index_axis(Axis(2), k);
    if view.is_standard_layout() {
        view.into()
    } else {
        view.as_standard_layout().into_owned().into()
    }
}

/// The column pairs `(2j, 2j + 1)` of a one-channel row (a trailing odd entry left out).
#[inline]
fn pairs<T>(row: &[T]) -> &[[T; 2]] {
    row.as_chunks::<2>().0
}

/// A `(rows, cols)` array whose row `i` is written by `f(i, row)`: [`rows_from_fn`] of one
/// channel.
fn rows_of<T: Sample>(shape: (usize, usize), f: impl Fn(usize, &mut [T]) + Sync) -> Array2<T> {
    rows_from_fn((shape.0, shape.1, 1), f)
        .into_shape_with_order(shape)
        .expect("one channel")
}

/// The values of a grid of this module (always built in standard layout).
fn flat<T, S: Data<Elem = T>, D: Dimension>(a: &ArrayBase<S, D>) -> &[T] {
    a.as_slice().expect("standard layout")
}

/// The values of a standard-layout view.
fn flat_view<'a, T>(a: &ArrayView3<'a, T>) -> &'a [T] {
    a.to_slice().expect("maps are in standard layout")
}

/// Row `i` of a grid with rows of `len` values.
#[inline]
fn row<T>(values: &[T], len: usize, i: usize) -> &[T] {
    &values[i * len..][..len]
}

/// The entry one column on from entry `e` of a periodic row of `len` values, `ch` a column.
#[inline]
fn after(e: usize, ch: usize, len: usize) -> usize {
    if e + ch < len { e + ch } else { e + ch - len }
}

/// The entry one column back from entry `e` of a periodic row.
#[inline]
fn before(e: usize, ch: usize, len: usize) -> usize {
    if e >= ch { e - ch } else { e + len - ch }
}

/// `C = (V[i][j] - V[i][j+1] + U[i][j] - U[i+1][j]) / 2`, the mixed difference from both
/// first-difference fields (step 4).
fn mixed_from<T: Sample>(v: &Array3<T>, u: &Array3<T>) -> Array3<T> {
    let (rows, n, ch) = v.dim();
    let (v, u, len) = (flat(v), flat(u), n * ch);
    rows_from_fn((rows, n, ch), |i, out| {
        let (vr, u0, u1) = (row(v, len, i), row(u, len, i), row(u, len, i + 1));
        for (e, o) in out.iter_mut().enumerate() {
            *o = mixed(vr[e], vr[after(e, ch, len)], u0[e], u1[e]);
        }
    })
}

/// `C[i][j]` from `V[i][j]`, `V[i][j+1]`, `U[i][j]` and `U[i+1][j]`: the mean of its two
/// expressions (step 4).
#[inline(always)]
fn mixed<T: Sample>(v0: T, v1: T, u0: T, u1: T) -> T {
    T::from_f64(0.5) * (v0 - v1 + u0 - u1)
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
    let solid = row_solid_angles(coeffs.height());
    set_mean(coeffs, energy, 0.0, &solid)
}

/// Sets each channel's constant so that [`sampled_integral`] of the map equals that of
/// `samples` (the [`Scheme::Cubic`] choice of step 6), keeping every difference.
///
/// ```
/// use haarshift::sphere::{LatLongMap, SphereCoefficients, chain_rule::*};
/// let f = LatLongMap::<f64>::from_fn(16, 1, |d, out| out[0] = (4.0 * d[1]).exp()).unwrap();
/// let mut c = SphereCoefficients::from_map(&f).unwrap();
/// set_mean_from_sampled_integral(&mut c, &f).unwrap();
/// let back = c.to_map().unwrap();
/// assert!((sampled_integral(&back)[0] - sampled_integral(&f)[0]).abs() < 1e-12);
/// ```
pub fn set_mean_from_sampled_integral<T: Sample>(
    coeffs: &mut SphereCoefficients<T>,
    samples: &LatLongMap<T>,
) -> Result<()> {
    let m = coeffs.height();
    let target = sampled_integral(samples);
    set_mean(coeffs, &target, pole_weight(m), &row_solid_angles(m))
}

/// The integral over the sphere of the function whose values at the texel centres the map
/// holds, to fourth order in the texel size `delta`: `sum_ij X_ij Omega_i` (the exact row
/// solid angles `Omega_i`) is off by `delta^2 / 24` times `(4 pi) mean(f)` (a factor common
/// to every rotation of `f`) minus `2 pi (f_N + f_S)`, the values at the two poles (the
/// Euler-Maclaurin end terms of the rows, `[f cos theta]` from 0 to `pi`). This returns the
/// sum with the pole terms removed, `sum_ij X_ij Omega_i - (delta^2 / 24) 2 pi (N + S)`, with
/// `N`, `S` the means of the first and last rows: a quantity a rotation preserves to
/// `O(delta^4)` (the plain sum changes by `O(delta^2)` when a peak moves onto a pole).
///
/// ```
/// use haarshift::sphere::{LatLongMap, SphereRotation, chain_rule::sampled_integral};
/// // exp(4 y) about the pole and turned to the horizon: the plain sums differ by 3.9e-4
/// // relative, these by less than 1e-5.
/// let r = SphereRotation::from_degrees(0.0, 90.0, 0.0).unwrap();
/// let f = LatLongMap::<f64>::from_fn(64, 1, |d, out| out[0] = (4.0 * d[1]).exp()).unwrap();
/// let g = LatLongMap::<f64>::from_fn(64, 1, |d, out| out[0] = (4.0 * r.apply(d)[1]).exp()).unwrap();
/// let rel = |a: f64, b: f64| (a - b).abs() / b;
/// assert!(rel(f.energy()[0], g.energy()[0]) > 3e-4);
/// assert!(rel(sampled_integral(&f)[0], sampled_integral(&g)[0]) < 1e-5);
/// ```
pub fn sampled_integral<T: Sample>(samples: &LatLongMap<T>) -> Vec<f64> {
    let a = samples.as_array();
    let (m, n, _) = a.dim();
    let w = pole_weight(m) * 2.0 * PI / n as f64;
    let row_mean = |i: usize, k: usize| -> f64 {
        a.index_axis(Axis(0), i)
            .index_axis(Axis(1), k)
            .iter()
            .map(|v| v.as_f64())
            .sum()
    };
    samples
        .energy()
        .iter()
        .enumerate()
        .map(|(k, e)| e - w * (row_mean(0, k) + row_mean(m - 1, k)))
        .collect()
}

/// `delta^2 / 24` for an `m`-row map: the weight of the pole terms of [`sampled_integral`].
fn pole_weight(m: usize) -> f64 {
    let delta = PI / m as f64;
    delta * delta / 24.0
}

/// The solid angle `Omega_i` of a pixel in each row of an `m`-row map.
fn row_solid_angles(m: usize) -> Vec<f64> {
    (0..m).map(|i| pixel_solid_angle(m, i)).collect()
}

/// Sets each channel's constant so that `sum_ij X_ij Omega_i - pole 2 pi (N + S)` (see
/// [`sampled_integral`]; `pole = 0`: the plain solid-angle integral) equals `target`, with
/// `solid` the map's [`row_solid_angles`].
fn set_mean<T: Sample>(
    coeffs: &mut SphereCoefficients<T>,
    target: &[f64],
    pole: f64,
    solid: &[f64],
) -> Result<()> {
    let (ch, m, n) = coeffs.as_array().dim();
    if target.len() != ch {
        return Err(Error::parameter(
            "energy",
            format!("{} values for {ch} channels", target.len()),
        ));
    }
    let levels = coeffs.levels();
    let w = pole * 2.0 * PI / n as f64;
    for (k, &target) in target.iter().enumerate() {
        let data = coeffs.as_array();
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
            .map(|(i, s)| solid[i] * s)
            .sum::<f64>()
            - w * (rows[0] + rows[m - 1]);
        // A constant c adds 4 pi c to the sum and 2 pi c to each pole mean.
        let shift = T::from_f64((target - current) / (4.0 * PI * (1.0 - pole)));
        coeffs.shift_mean(k, shift)?;
    }
    Ok(())
}

/// The Haar coefficients of `g = f(R p)` at the resolution of `approx` (the approximation of
/// `f` at resolution `L + 1`, an `m x 2m` map): a full `m x 2m` pyramid holding detail
/// levels `0..=L`. Embed it in a larger pyramid with
/// [`SphereCoefficients::zero_padded`].
///
/// ```
/// use haarshift::sphere::{LatLongMap, SphereRotation, chain_rule::{Scheme, rotate}};
/// let f = LatLongMap::<f64>::from_fn(16, 1, |d, out| out[0] = 1.0 + d[0]).unwrap();
/// let r = SphereRotation::from_degrees(0.0, 30.0, 0.0).unwrap();
/// let g = rotate(&f, &r, Scheme::Linear).unwrap().to_map().unwrap();
/// // g = 1 + x(R p) and a pitch about X keeps x: g is f, to the method's accuracy.
/// let err = (&g.as_array() - &f.as_array()).iter().fold(0.0f64, |a, v| a.max(v.abs()));
/// assert!(err < 0.02);
/// ```
pub fn rotate<T: Sample>(
    approx: &LatLongMap<T>,
    rotation: &SphereRotation,
    scheme: Scheme,
) -> Result<SphereCoefficients<T>> {
    Rotator::new(approx, scheme)?.rotate(rotation)
}

/// One source map prepared for any number of rotations: its derivative fields (step 1 of
/// the [module docs](self)) and the integral every rotation keeps (step 6) are computed once,
/// so a rotation costs the chain rule and the filters alone. This is what a renderer needs
/// to bring one BRDF into every vertex's frame. A zonal source (constant along every row,
/// such as a lobe about the pole, [`SourceGradient::is_zonal`]) takes a shorter path with
/// the same result: one angle per pre-image and a one-dimensional interpolation.
///
/// ```
/// use haarshift::sphere::{LatLongMap, SphereRotation, chain_rule::{Rotator, Scheme, rotate}};
/// let lobe = LatLongMap::<f64>::from_fn(32, 1, |d, out| out[0] = d[1].max(0.0).powi(20)).unwrap();
/// let rotator = Rotator::new(&lobe, Scheme::Linear).unwrap();
/// assert!(rotator.is_zonal());
/// for pitch in [10.0, 50.0, 120.0] {
///     let r = SphereRotation::from_degrees(30.0, pitch, 0.0).unwrap();
///     let diff = &rotator.rotate(&r).unwrap().as_array() - &rotate(&lobe, &r, Scheme::Linear).unwrap().as_array();
///     assert!(diff.iter().all(|v| v.abs() < 1e-12));
/// }
/// ```
#[derive(Clone, Debug)]
pub struct Rotator<T> {
    grad: SourceGradient<T>,
    /// Per channel, what step 6 keeps: the solid-angle integral, or (cubic) the sampled one.
    integral: Vec<f64>,
    /// [`row_solid_angles`] of the source's rows, which every rotation's step 6 weighs by.
    solid: Vec<f64>,
}

impl<T: Sample> Rotator<T> {
    /// `approx` (an `m x 2m` map, `m` a power of two from 2 on) prepared for rotation by
    /// `scheme`.
    pub fn new(approx: &LatLongMap<T>, scheme: Scheme) -> Result<Self> {
        let m = approx.height();
        if m < 2 || !m.is_power_of_two() {
            return Err(Error::shape(
                &[m, 2 * m],
                "the Haar method needs a height that is a power of two from 2 on",
            ));
        }
        Ok(Rotator {
            grad: SourceGradient::with_scheme(approx, scheme),
            integral: match scheme {
                Scheme::Linear => approx.energy(),
                Scheme::Cubic => sampled_integral(approx),
            },
            solid: row_solid_angles(m),
        })
    }

    /// Whether the source is zonal ([`SourceGradient::is_zonal`]).
    pub fn is_zonal(&self) -> bool {
        self.grad.is_zonal()
    }

    /// The coefficients of `g = f(R p)`, as [`rotate`].
    pub fn rotate(&self, rotation: &SphereRotation) -> Result<SphereCoefficients<T>> {
        self.rotate_turned(rotation, 0)
    }

    /// The coefficients of `g = f_k(R p)`, with `f_k` the source turned by `turn` columns
    /// ([`yaw_pixels`](super::yaw::yaw_pixels)`(f, turn)`): the turn is exact (the fields
    /// are read `turn` columns on, with the taps and weights the turned source would give)
    /// and costs nothing.
    ///
    /// ```
    /// use haarshift::sphere::{LatLongMap, SphereRotation, chain_rule::{Rotator, Scheme}, yaw::yaw_pixels};
    /// let f = LatLongMap::<f64>::from_fn(16, 1, |d, out| out[0] = (d[0] + 2.0 * d[1]).exp()).unwrap();
    /// let r = SphereRotation::from_degrees(10.0, 40.0, -20.0).unwrap();
    /// let turned = Rotator::new(&f, Scheme::Cubic).unwrap().rotate_turned(&r, 5).unwrap();
    /// let want = Rotator::new(&yaw_pixels(&f, 5), Scheme::Cubic).unwrap().rotate(&r).unwrap();
    /// let diff = &turned.as_array() - &want.as_array();
    /// assert!(diff.iter().all(|v| v.abs() < 1e-13));
    /// ```
    pub fn rotate_turned(
        &self,
        rotation: &SphereRotation,
        turn: usize,
    ) -> Result<SphereCoefficients<T>> {
        let fields = DifferenceFields::from_gradient(&self.grad, rotation, turn % self.grad.n);
        let mut coeffs = fields.to_coefficients()?;
        let pole = match self.grad.scheme {
            Scheme::Linear => 0.0,
            Scheme::Cubic => pole_weight(self.grad.m),
        };
        set_mean(&mut coeffs, &self.integral, pole, &self.solid)?;
        Ok(coeffs)
    }
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

#[cfg(test)]
mod tests {
    use super::*;

    /// The zonal rows compiled for AVX2 give the portable build's bits (no fused
    /// multiply-adds, the same operations in wider registers), for both precisions, both
    /// schemes and both fields. On a CPU without AVX2 there is only one build to run.
    #[test]
    fn the_avx2_build_of_a_zonal_row_gives_the_portable_bits() {
        #[cfg(target_arch = "x86_64")]
        if std::arch::is_x86_feature_detected!("avx2") {
            same_bits::<f32>();
            same_bits::<f64>();
        } else {
            eprintln!("no AVX2 on this CPU: only the portable build runs");
        }
    }

    /// Two channels, and one (whose `f32` linear lookups gather in the AVX2 build), on rows
    /// whose chunks are partly skipped.
    #[cfg(target_arch = "x86_64")]
    fn same_bits<T: Sample>() {
        let two = LatLongMap::<T>::from_fn(32, 2, |d, out| {
            out[0] = T::from_f64(d[1].max(0.0).powi(20));
            out[1] = T::from_f64((2.0 * d[1]).exp());
        })
        .unwrap();
        let one = LatLongMap::<T>::from_fn(32, 1, |d, out| {
            out[0] = T::from_f64(d[1].max(0.0).powi(20));
        })
        .unwrap();
        let rotation = SphereRotation::from_degrees(25.0, -70.0, 40.0).unwrap();
        for (lobe, scheme) in [
            (&two, Scheme::Linear),
            (&two, Scheme::Cubic),
            (&one, Scheme::Linear),
        ] {
            let ch = lobe.channels();
            let grad = SourceGradient::with_scheme(lobe, scheme);
            let profile = grad.zonal.as_ref().expect("a zonal source");
            let rule = ChainRule::new(&grad, &rotation, 0);
            let mut largest = T::zero();
            for (kt, first, along) in [
                (3, 1, Along::Theta),
                (6, 2, Along::Phi),
                (40, 1, Along::Theta),
            ] {
                let mut portable = vec![T::zero(); 64 * ch];
                let mut wide = portable.clone();
                rule.zonal_row::<false>(profile, (kt, first), along, -0.1, &mut portable);
                // SAFETY: the caller checked that the CPU has AVX2.
                unsafe { rule.zonal_row_avx2(profile, (kt, first), along, -0.1, &mut wide) };
                let bits = |v: &[T]| v.iter().map(|x| x.as_f64().to_bits()).collect::<Vec<_>>();
                assert_eq!(bits(&portable), bits(&wide), "{scheme:?} {ch} {kt}");
                largest = portable.iter().fold(largest, |a, v| a.max(v.abs()));
            }
            assert!(largest > T::from_f64(1e-3));
        }
    }

    /// Rows and chunks whose pre-images all lie where the profile is zero are written as
    /// zeros without being computed; computing them gives exactly those zeros. A Phong lobe
    /// (zero below its horizon: a lower bound on `cos Theta`) and a ring (zero near both
    /// poles: both bounds), both schemes, both precisions, rotations that tilt the zero
    /// region across the grid.
    #[test]
    fn skipping_where_the_profile_is_zero_changes_no_value() {
        skips_exactly::<f32>();
        skips_exactly::<f64>();
    }

    fn skips_exactly<T: Sample>() {
        let phong = LatLongMap::<T>::from_fn(32, 1, |d, out| {
            out[0] = T::from_f64(d[1].max(0.0).powi(20));
        })
        .unwrap();
        let ring = LatLongMap::<T>::from_fn(32, 1, |d, out| {
            out[0] = T::from_f64((0.4 - d[1].abs()).max(0.0));
        })
        .unwrap();
        for (lobe, both) in [(&phong, false), (&ring, true)] {
            for scheme in [Scheme::Linear, Scheme::Cubic] {
                let grad = SourceGradient::with_scheme(lobe, scheme);
                let (low, high) = grad.zonal.as_ref().expect("zonal").cos_bounds;
                assert!(low > -1.0 && low < 0.0, "{low}");
                assert_eq!(high.is_finite(), both, "{high}");
                let mut everything = grad.clone();
                everything.zonal.as_mut().expect("zonal").cos_bounds =
                    (f64::NEG_INFINITY, f64::INFINITY);
                for (yaw, pitch, roll) in
                    [(0.0, 0.0, 0.0), (25.0, -70.0, 40.0), (10.0, 120.0, -15.0)]
                {
                    let r = SphereRotation::from_degrees(yaw, pitch, roll).unwrap();
                    let skipped = DifferenceFields::from_gradient(&grad, &r, 3);
                    let computed = DifferenceFields::from_gradient(&everything, &r, 3);
                    assert_eq!(skipped.v, computed.v, "{scheme:?} {pitch}");
                    assert_eq!(skipped.u, computed.u, "{scheme:?} {pitch}");
                    // Not every value is zero: the comparison is of something.
                    let mut values = computed.v.iter().chain(computed.u.iter());
                    assert!(values.any(|v| v.abs() > T::from_f64(1e-4)));
                }
            }
        }
    }
}
