//! Shifting signals and images directly in the Haar domain: whole and fractional shifts,
//! 1D, 2D non-separable (pyramid) and N-D separable, dense or one coefficient at a time.
//!
//! # What a shift is (the oracle)
//!
//! The coefficients of a shifted signal are, by definition, `forward(shift(inverse(c)))` with
//! a **periodic** boundary over the (power-of-two) array; [`oracle`] computes exactly that.
//! Every fast path here is tested against it. For [`Coefficients`] of an image that was padded
//! to a power of two, the period is the padded size.
//!
//! **Sign convention** (that of `scipy.ndimage.shift`): a shift by `+s` moves content towards
//! higher indices, `out[n] = in[n - s]`; in 2D `dx` moves columns (right for `dx > 0`) and
//! `dy` rows (down for `dy > 0`), `out[r][c] = in[r - dy][c - dx]`. Alnasser 2008 writes the
//! shifted signal as `x[n + s]`: its `s` is our `-s`.
//!
//! # Fractional shifts
//!
//! A shift with precision `h` (see [`GridShift`]) means: upsample by `2^h` per axis by adding
//! `h` levels of zero details under the transform, shift the fine signal by
//! `r = round(s 2^h)` fine samples (ties towards `+infinity`), and read the transform back at
//! the original levels (Alnasser 2008's section 2.4 / 3.6). Adding zero-detail levels repeats each
//! sample `2^h` times (in either normalisation: the coefficients keep their places), and
//! reading back the original levels box-averages `2^h` fine samples. Hence, exactly:
//!
//! > With `s_h = r / 2^h = q + a`, `q = floor(s_h)`, `0 <= a < 1`, the compact fractional
//! > shift of the transform of `x` is the transform (same levels, same normalisation) of
//! > `z[n] = (1 - a) x[(n - q) mod N] + a x[(n - q - 1) mod N]`: **periodic linear
//! > interpolation of `x` at `n - s_h`**, with the shift rounded to the `1 / 2^h` grid. In 2D
//! > the same holds per axis: periodic **bilinear** interpolation at `(r - dy_h, c - dx_h)`.
//!
//! So the compact shift is as smooth as linear interpolation, whatever `h`; `h` only sets how
//! finely the shift is resolved. A chain of compact shifts interpolates (and blurs) at every
//! step; [`RetainedImage`] / [`RetainedSignal`] keep the `h` extra levels instead, so that a
//! chain of shifts on the `1 / 2^h` grid equals the single shift by their sum, and project
//! (box-average) to the original levels only when asked.
//!
//! # Exactness
//!
//! * **Whole shifts move fine levels without arithmetic.** At the `s`-th finest level a
//!   coefficient describes a block of `2^s` samples per axis; when `2^s` divides the shift
//!   (both `dx` and `dy` in 2D) the shifted signal's block `i` is exactly the old block
//!   `i - shift / 2^s`, so the level's bands are rolled, not recomputed: bit-exact for any
//!   data. The dense path ([`dense`], hence [`shift_image`], [`separable`] and the retained
//!   forms) does exactly that, and recomputes only the coarse block above those levels, which
//!   is itself the transform of the level-`s` approximation shifted by `shift / 2^s`. A shift
//!   by a multiple of `2^L` (`L` levels) is therefore a pure permutation (the scaling block
//!   rolls by `shift / 2^L`; a full-depth square's single scaling coefficient stays), and
//!   **any chain of such shifts is bit-identical to one shift by their sum, for any data**.
//! * **Chains of arbitrary whole shifts are bit-exact when the arithmetic is.** The recomputed
//!   levels go inverse, roll, forward using only `+`, `-` and the factors of the
//!   normalisation. With [`Normalization::Average`](crate::transform::Normalization) (factors
//!   1, 1/2, 1/4) and with the 2D orthonormal pyramid (1/2 per level) that is `+`, `-` and
//!   powers of two, so on short dyadic values, such as 8- or 16-bit images in f64, every
//!   intermediate is exact (the depth-`j` coefficients of 8-bit data are `k / 4^j` or
//!   `k / 2^j` with `|k| < 2^(8 + 2j)`: exact in f64 below 22 levels, in f32 up to 8 levels),
//!   and a chain of any whole shifts equals the transform of the rolled image bit for bit.
//!   The 1D and separable orthonormal transforms multiply by a rounded `1/sqrt 2` and are not
//!   exact.
//! * **Otherwise a chain drifts by rounding.** For arbitrary floats, `forward(inverse(c))`
//!   differs from `c` by a few units in the last place (sums of four values round), so each
//!   recomputing shift adds rounding noise of relative size about `1e-16` (f64), a random
//!   walk over a chain. `haarshift experiment stability` measures it.
//! * Fractional shifts interpolate (see above) and are never permutations.
//!
//! # Two ways to compute
//!
//! **Dense** ([`dense`]): all coefficients in O(n), in parallel, the image rebuilt and
//! re-analysed strip by strip in cache so that the coefficients cross main memory once each
//! way (see the module docs there). [`shift_image`] is the one-call entry point.
//!
//! **Random access** ([`ShiftQuery1d`], [`ShiftQuery2d`]): one coefficient of the shifted
//! transform, from the original coefficients alone, without materialising the rest. Alnasser 2008
//! expresses a shifted coefficient through its *D tables*: `D^l_i = A^l_i - A^0_0`, the
//! approximations minus the DC value, computed recursively from the details (eq. 2.4-2.6 in
//! 1D, 3.1-3.4 in 2D), and sums `D` over the window the coefficient's support moves to
//! (eq. 2.13, 2.23, 3.10, 3.13, 3.16, 3.27-3.28). Those window sums cost O(support), O(log L)
//! on average per coefficient. Here the sums are prefix sums: the prefix sums (1D) or the
//! summed-area table (2D) of the finest D table, `x - mean`, are prepared once in O(n), after
//! which every coefficient, of any level, band, partial-transform scaling block, for **any**
//! integer or fractional shift, costs O(1) (at most nine interpolated table reads): a box sum
//! is four corners, and a fractional corner is the (bi)linear interpolation of the table,
//! because the integral of the piecewise-constant upsampled signal is piecewise (bi)linear.
//! The query is prepared once and answers every shift. For "coarse levels only" with shifts
//! by multiples of `2^t`, [`ShiftQuery2d::with_resolution`] prepares from the coarse
//! `1 / 4^t` of the coefficients alone (the per-level D tables of Alnasser 2008's partial
//! transforms, eq. 2.6).
//!
//! # Typos in Alnasser 2008's printed equations
//!
//! Found while re-deriving the closed forms from the definition. The corrected 1D closed
//! forms (2.13) and (2.23) (with the D tables (2.5)-(2.6)) and the `k = t + 1` cases of
//! (3.13), (3.16), (3.17) and (3.19) are implemented literally in this module's tests and
//! agree with the oracle for every size up to 64 (1D) / 16x16 (2D) and every shift.
//!
//! * Text after (2.9) and before (2.11): "substituting ... in (3.6)" / "modification of
//!   equation (3.6)" should refer to (2.9).
//! * (2.12), (2.13): "`d^{N-t-1}_{i_2 % 2^{N-1}} = 0`": the modulus is `2^{N-t-1}`.
//! * (2.18): "substituting (2.3)" should be (2.4); likewise (3.22) "substituting (3.2)" should
//!   be (3.3).
//! * (2.2), (2.14): `i = 0, ..., 2^l` should end at `2^l - 1`.
//! * (2.25): the index `floor((i % 2^{N'-t-1}) / 2^{N'-t-t})` should divide by `2^{h-t-1}`
//!   (from `D^{N+h_0}_i = D^N_{floor(i / 2^{h_0})}` with `h_0 = h - t - 1`); the same
//!   denominators in (3.32)-(3.34) are printed as `N'-t-1` and should be `2^{h-t-1}`.
//! * (3.2): `X^l_{i/2, j/2}` (and `Y`, `Z`, `W`) halves the index twice, since (3.1) already
//!   defines `X^l_{i,j}` with `[i/2], [j/2]`: it should read `X^l_{i,j}`.
//! * (3.6), (3.8), (3.21)-(3.23), (3.25): the row sums `m = 2^k i ... 2^k (i + 1)` should stop
//!   at `2^k (i + 1) - 1` (and `2^{k-t}` forms alike).
//! * (3.15): the first row sum should stop at `2^{k-t-1}(2i + 1) - 1` and the second start at
//!   `2^{k-t-1}(2i + 1)` (printed `2^{k-t-1}(i + 1)`: the upper and lower halves).
//! * (3.17): in the case `k <= t` of `b` under a vertical shift, the indices are swapped:
//!   `b^{N-k}_{(j + s_v/2^k) % 2^{N-k}, i}` should be `b^{N-k}_{(i + s_v/2^k) % 2^{N-k}, j}`.
//! * (3.25)-(3.28): written for `t = 0` but labelled general: `4^k`, `2^k j + s_h`, the sums
//!   from `2^{k-1} i`, and `j_1 = 2^{k-1} j + floor(s_h / 2)` should read `4^{k-t}`,
//!   `2^{k-t} j + s_h / 2^t`, `2^{k-t-1} i` and `2^{k-t-1} j + floor(s_h / 2^{t+1})`; the
//!   detail `a^{N-t-1}_{m, j_1 % 2^{N-1}}` has modulus `2^{N-t-1}`.
//! * Section 3.6: "Equations (3.10), (3.13) and (3.13)" should be (3.10), (3.13) and (3.16);
//!   (3.31) writes `c^{N-k}` for `c^{N'-k}`; "modify (3.32), (3.33) and (3.34)" should be
//!   (3.29), (3.30) and (3.31).
//! * Section 3.1: node `ij` at level `l` holds `a^l_{i,j}`, printed `a^N_{i,j}`.
//! * Section 2.6 refers to "Table (2.6)" for Table 2.1; the discussion of chapter 3 states a
//!   precision of `1/(2h)` for `1/2^h`.
//!
//! Apart from these, the printed (2.10), (2.13), (2.20), (2.23) and (3.7) and the `k = t + 1`
//! cases above are right, in Alnasser 2008's sign convention and the average normalisation (in the
//! orthonormal one every level carries an extra `sqrt 2` or `2` per step).

pub mod dense;
mod grid;
pub mod oracle;
mod plane;
mod random_access;
mod retained;
pub mod separable;

pub use dense::ShiftWorkspace;
pub use grid::{GridShift, MAX_PRECISION};
pub use plane::PlaneShift;
pub use random_access::{PyramidIndex, ShiftQuery1d, ShiftQuery2d};
pub use retained::{DEFAULT_MEMORY_BUDGET, RetainedImage, RetainedSignal};

use crate::transform::{Coefficients, Layout};
use crate::{Result, Sample};

/// Shifts an image in the Haar domain: `dx` columns (right for `dx > 0`) and `dy` rows (down
/// for `dy > 0`), periodic over the padded size, each rounded to the `1 / 2^precision` grid
/// (`precision = 0` for whole pixels). Returns coefficients with the same [`TransformInfo`]
/// (layout, levels, normalisation, padding).
///
/// Pyramid coefficients take the non-separable 2D path; separable coefficients are shifted
/// along each axis ([`separable`]). A fractional shift is the compact one of the
/// [module docs](self): the result is the transform of the bilinear interpolation of the
/// image at the rounded shift. Errors on non-finite shifts or a precision above
/// [`MAX_PRECISION`].
///
/// [`TransformInfo`]: crate::transform::TransformInfo
///
/// ```
/// use haarshift::shift::shift_image;
/// use haarshift::transform::TransformSpec;
/// use ndarray::array;
/// let image = array![[1.0, 2.0, 3.0, 4.0], [5.0, 6.0, 7.0, 8.0]];
/// let c = TransformSpec::default().forward(image.view()).unwrap();
/// let moved = shift_image(&c, -1.0, 0.0, 0).unwrap().inverse().unwrap();
/// assert_eq!(moved, array![[2.0, 3.0, 4.0, 1.0], [6.0, 7.0, 8.0, 5.0]]);
/// let half = shift_image(&c, 0.5, 0.0, 1).unwrap().inverse().unwrap();
/// assert_eq!(half.row(0), ndarray::aview1(&[2.5, 1.5, 2.5, 3.5]));
/// let inf = shift_image(&c, f64::INFINITY, 0.0, 0);
/// assert!(matches!(inf, Err(haarshift::Error::InvalidParameter { name: "shift", .. })));
/// ```
pub fn shift_image<T: Sample>(
    coeffs: &Coefficients<T>,
    dx: f64,
    dy: f64,
    precision: u32,
) -> Result<Coefficients<T>> {
    let dx = GridShift::new(dx, precision)?;
    let dy = GridShift::new(dy, precision)?;
    let info = *coeffs.info();
    let data = match info.layout {
        Layout::Pyramid => dense::shift_pyramid(
            coeffs.as_array(),
            info.levels[0],
            info.normalization,
            dx,
            dy,
        )?,
        Layout::Separable => {
            let mut data = coeffs.as_array().to_owned();
            separable::shift_in_place(
                data.view_mut(),
                &info.levels,
                info.normalization,
                &[dy, dx],
            )?;
            data
        }
    };
    Ok(Coefficients::from_trusted_parts(data, info))
}

#[cfg(test)]
mod f32_tests;
#[cfg(test)]
mod tests;
