//! Alnasser 2008's Haar-domain rotation (section 4.5): detail coefficients are finite-difference
//! derivatives, so the chain rule gives the rotated map's differences at one level, and exact
//! short recursive filters give every coarser level.
//!
//! # The method, step by step
//!
//! Pick the finest detail level `L` to compute. Everything happens on the grid of the
//! approximation at resolution `L + 1` (`m x n = 2^(L+1) x 2^(L+2)` cells of side
//! `delta = pi / m`), Alnasser 2008's "level `j + 1`":
//!
//! 1. **Derivatives of `f`** ([`SourceGradient`]). `X_f`, `f`'s approximation at that
//!    resolution, is the inverse of `f`'s coefficients of levels `0..=L` (cost `O(N / 4^k)`
//!    for `k` levels below the finest). Its first differences are the finite-difference
//!    derivatives Alnasser 2008 reads off the Haar coefficients (the in-block ones *are* the
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
//!    *Diagonal choice:* Alnasser 2008's (4.17) is not the second derivative of (4.14) (see
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
//!    recursively this is Alnasser 2008's `O(N)` algorithm; expanded, the weight of a level-`l`
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
//! Alnasser 2008's scheme has three second-order errors, each replaced by a fourth-order one
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
//! 16 taps each instead of 4. Individual coefficients ([`rotate_selected`]) use Alnasser 2008's
//! scheme.
//!
//! Measured ([`lobes`](super::lobes), 64 x 128, Phong exponents 10 and 50 about the pole
//! and a horizon direction, pitch 30 to 90 and a compound rotation): against the analytic
//! rotated lobe at the texel centres `haar-cubic`'s weighted RMS error is 0.37 to 0.83 times
//! bicubic's (and 3 % to 8 % of Alnasser 2008's scheme's); against the lobe's texel means, where
//! every method carries the point-versus-mean difference of its input, 0.96 to 1.02 times.
//!
//! # Typos in Alnasser 2008's section 4.5
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

// One file a step of the method above:
//
// | file | step |
// |---|---|
// | `gradient` | 1: `f`'s derivatives on the working grid's edges ([`SourceGradient`], [`Scheme`]) |
// | `chain` | 2-4: the chain rule at each edge's pre-image, `g`'s differences |
// | `zonal` | 2-3 for a lobe about one axis: a profile of one angle, AVX2 for f32 |
// | `fields` | 5: the difference fields and every level's details ([`DifferenceFields`]) |
// | `mean` | 6: the scaling coefficients from the integral ([`set_mean_from_energy`]) |
// | `rotator` | the whole rotation ([`rotate`], [`Rotator`]) |
// | `selected` | individual coefficients from the expanded filters ([`rotate_selected`]) |
mod chain;
mod fields;
mod gradient;
mod mean;
mod rotator;
mod selected;
mod zonal;

pub use fields::DifferenceFields;
pub use gradient::{Scheme, SourceGradient};
pub use mean::{sampled_integral, set_mean_from_energy, set_mean_from_sampled_integral};
pub use rotator::{Rotator, rotate};
pub use selected::{CoefficientIndex, rotate_selected};

#[cfg(test)]
mod tests;
