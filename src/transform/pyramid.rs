//! The 2D non-separable Haar transform ("standard pyramid", Alnasser 2008's chapter 3) on
//! power-of-two arrays, in the Mallat layout described in the [module docs](super).
//!
//! Each level reads the current approximation once and writes its three detail bands straight
//! into the output and its half-size approximation into a ping-pong buffer (the last level
//! writes the approximation into the output too), so the whole transform moves about 4/3 of
//! the array through memory once each way: it runs at the speed of a copy. Rows of 2x2 blocks
//! are independent and processed in parallel.

use std::ops::Range;

use ndarray::{Array2, ArrayView2, ArrayViewMut2};
use rayon::prelude::*;

use super::{Band, Normalization};
use crate::sample::all_finite;
use crate::{Error, Result, Sample, ensure_finite};

/// Below this many output values per task, rayon's overhead outweighs the work.
const MIN_VALUES_PER_TASK: usize = 1 << 14;

/// The deepest pyramid an `h x w` array (powers of two) allows: the shorter side's log2.
///
/// ```
/// assert_eq!(haarshift::transform::pyramid::max_levels(512, 1024), 9);
/// ```
pub fn max_levels(h: usize, w: usize) -> usize {
    (h.trailing_zeros()).min(w.trailing_zeros()) as usize
}

/// Validates a power-of-two shape and a level count; returns nothing on success.
pub(crate) fn check(shape: (usize, usize), levels: usize) -> Result<()> {
    let (h, w) = shape;
    if h == 0 || w == 0 || !h.is_power_of_two() || !w.is_power_of_two() {
        return Err(Error::shape(
            &[h, w],
            "both sides must be non-zero powers of two",
        ));
    }
    let max = max_levels(h, w);
    if levels > max {
        return Err(Error::parameter(
            "levels",
            format!("{levels} levels do not fit {h}x{w} (at most {max})"),
        ));
    }
    Ok(())
}

/// Rows and columns of band `band` at detail level `level` in an `h x w` pyramid of `levels`.
pub(crate) fn band_ranges(
    (h, w): (usize, usize),
    levels: usize,
    band: Band,
    level: usize,
) -> Result<(Range<usize>, Range<usize>)> {
    let (h0, w0) = (h >> levels, w >> levels);
    if band == Band::Scaling {
        return match level {
            0 => Ok((0..h0, 0..w0)),
            _ => Err(Error::parameter(
                "level",
                "scaling coefficients are stored at level 0 only",
            )),
        };
    }
    if level >= levels {
        return Err(Error::parameter(
            "level",
            format!("detail level {level} does not exist in a {levels}-level pyramid"),
        ));
    }
    let (bh, bw) = (h0 << level, w0 << level);
    Ok(match band {
        Band::Horizontal => (0..bh, bw..2 * bw),
        Band::Vertical => (bh..2 * bh, 0..bw),
        Band::Diagonal | Band::Scaling => (bh..2 * bh, bw..2 * bw),
    })
}

/// One analysis step on a row pair: 2x2 blocks to (A, a, b, c). `f2` is the per-level factor,
/// a power of two (1/4 or 1/2), applied to the four values first: the results are the same
/// bits as scaling the sums (a power of two commutes with rounding), but in the average
/// normalisation no intermediate can overflow, since each is at most the largest input.
#[inline]
pub(crate) fn analyse_rows<T: Sample>(
    r0: &[T],
    r1: &[T],
    approx: &mut [T],
    a: &mut [T],
    b: &mut [T],
    c: &mut [T],
    f2: T,
) {
    let n = approx.len();
    let (top, bottom) = (&r0.as_chunks::<2>().0[..n], &r1.as_chunks::<2>().0[..n]);
    let (a, b, c) = (&mut a[..n], &mut b[..n], &mut c[..n]);
    for j in 0..n {
        let ([p, q], [r, s]) = (top[j], bottom[j]);
        let (p, q, r, s) = (f2 * p, f2 * q, f2 * r, f2 * s);
        let (sum_top, sum_bottom) = (p + q, r + s);
        let (dif_top, dif_bottom) = (p - q, r - s);
        approx[j] = sum_top + sum_bottom;
        a[j] = dif_top + dif_bottom;
        b[j] = sum_top - sum_bottom;
        c[j] = dif_top - dif_bottom;
    }
}

/// One synthesis step: (A, a, b, c) rows back to a row pair of 2x2 blocks.
#[inline]
pub(crate) fn synthesise_rows<T: Sample>(
    approx: &[T],
    a: &[T],
    b: &[T],
    c: &[T],
    r0: &mut [T],
    r1: &mut [T],
    g2: T,
) {
    // Fixed-size pairs (rather than chunks_exact_mut(2)) let the compiler vectorise the
    // interleaved stores.
    let (top, _) = r0.as_chunks_mut::<2>();
    let (bottom, _) = r1.as_chunks_mut::<2>();
    let n = approx.len();
    let (top, bottom, a, b, c) = (&mut top[..n], &mut bottom[..n], &a[..n], &b[..n], &c[..n]);
    for j in 0..n {
        let (s_top, s_bottom) = (approx[j] + b[j], approx[j] - b[j]);
        let (d_top, d_bottom) = (a[j] + c[j], a[j] - c[j]);
        top[j] = [g2 * (s_top + d_top), g2 * (s_top - d_top)];
        bottom[j] = [g2 * (s_bottom + d_bottom), g2 * (s_bottom - d_bottom)];
    }
}

/// Where an analysis step puts its half-size approximation.
enum ApproxTarget<'a, T> {
    /// A separate buffer with rows of `w / 2` values.
    Buffer(&'a mut [T]),
    /// The output's top-left corner, left of the `a` band (the last level).
    Output,
}

/// A row of the top half of a level's output and its partner in the bottom half.
type RowPair<'a, T> = (&'a mut [T], &'a mut [T]);

/// Analysis of the `h x w` approximation `cur` (row stride `cur_stride`) into `out` (row
/// stride `out_stride`): `a`, `b`, `c` into their bands, the approximation into `target`.
/// Returns whether the values written are finite, checked on each row pair while it is in
/// cache: the approximations always (a NaN or infinity in `cur` reaches the approximation of
/// its block), the details too with `check_details` (where they can overflow).
#[allow(clippy::too_many_arguments)] // one level's geometry, target and arithmetic
fn analysis_step<T: Sample>(
    cur: &[T],
    cur_stride: usize,
    (h, w): (usize, usize),
    out: &mut [T],
    out_stride: usize,
    target: ApproxTarget<'_, T>,
    f2: T,
    check_details: bool,
) -> bool {
    let (hh, hw) = (h / 2, w / 2);
    let (top, bottom) = out[..h * out_stride].split_at_mut(hh * out_stride);
    let pair = move |r: usize| {
        (
            &cur[2 * r * cur_stride..][..w],
            &cur[(2 * r + 1) * cur_stride..][..w],
        )
    };
    let analyse = |r: usize, approx: &mut [T], a: &mut [T], b: &mut [T], c: &mut [T]| {
        let (r0, r1) = pair(r);
        analyse_rows(r0, r1, approx, a, b, c, f2);
        all_finite(approx) & (!check_details || all_finite(a) & all_finite(b) & all_finite(c))
    };
    // A level that would be one task anyway runs here: rayon's bridge costs more than a
    // small level's work (per-vertex products transform thousands of 32 x 32 faces).
    let serial = h * w <= MIN_VALUES_PER_TASK;
    let min_len = (MIN_VALUES_PER_TASK / w).max(1);
    match target {
        ApproxTarget::Buffer(buf) => {
            let row = |(r, ((t, b), approx)): (usize, (RowPair<'_, T>, &mut [T]))| {
                let (b_row, c_row) = b[..w].split_at_mut(hw);
                analyse(r, approx, &mut t[hw..w], b_row, c_row)
            };
            let buf = &mut buf[..hh * hw];
            if serial {
                let rows = top
                    .chunks_mut(out_stride)
                    .zip(bottom.chunks_mut(out_stride));
                rows.zip(buf.chunks_mut(hw))
                    .enumerate()
                    .map(row)
                    .fold(true, |x, y| x & y)
            } else {
                let rows = top
                    .par_chunks_mut(out_stride)
                    .zip(bottom.par_chunks_mut(out_stride));
                rows.zip(buf.par_chunks_mut(hw))
                    .with_min_len(min_len)
                    .enumerate()
                    .map(row)
                    .reduce(|| true, |x, y| x & y)
            }
        }
        ApproxTarget::Output => {
            let row = |(r, (t, b)): (usize, RowPair<'_, T>)| {
                let (approx, a_row) = t[..w].split_at_mut(hw);
                let (b_row, c_row) = b[..w].split_at_mut(hw);
                analyse(r, approx, a_row, b_row, c_row)
            };
            if serial {
                let rows = top
                    .chunks_mut(out_stride)
                    .zip(bottom.chunks_mut(out_stride));
                rows.enumerate().map(row).fold(true, |x, y| x & y)
            } else {
                let rows = top
                    .par_chunks_mut(out_stride)
                    .zip(bottom.par_chunks_mut(out_stride));
                rows.with_min_len(min_len)
                    .enumerate()
                    .map(row)
                    .reduce(|| true, |x, y| x & y)
            }
        }
    }
}

/// Rows of a 2D block inside a larger row-major buffer.
#[derive(Clone, Copy)]
struct Strided<'a, T> {
    data: &'a [T],
    stride: usize,
}

impl<'a, T> Strided<'a, T> {
    /// `len` values of row `r` from column `col`.
    fn row(&self, r: usize, col: usize, len: usize) -> &'a [T] {
        &self.data[r * self.stride + col..][..len]
    }
}

/// Synthesis of a `2h x 2w` approximation into `dst` (row stride `dst_stride`) from the
/// `h x w` approximation `cur` and the level's bands in `coeffs`.
fn synthesis_step<T: Sample>(
    cur: Strided<'_, T>,
    coeffs: Strided<'_, T>,
    (h, w): (usize, usize),
    dst: &mut [T],
    dst_stride: usize,
    g2: T,
) {
    let row = |(r, rows): (usize, &mut [T])| {
        let (r0, r1) = rows.split_at_mut(dst_stride);
        let (b, c) = coeffs.row(h + r, 0, 2 * w).split_at(w);
        synthesise_rows(
            cur.row(r, 0, w),
            coeffs.row(r, w, w),
            b,
            c,
            &mut r0[..2 * w],
            &mut r1[..2 * w],
            g2,
        );
    };
    let dst = &mut dst[..2 * h * dst_stride];
    // As in analysis: a level that would be one task runs here.
    if 4 * h * w <= MIN_VALUES_PER_TASK {
        dst.chunks_mut(2 * dst_stride).enumerate().for_each(row);
    } else {
        let min_len = (MIN_VALUES_PER_TASK / (4 * w)).max(1);
        dst.par_chunks_mut(2 * dst_stride)
            .with_min_len(min_len)
            .enumerate()
            .for_each(row);
    }
}

/// Splits `work` into the two ping-pong approximation buffers for an `h x w` transform.
fn ping_pong<T: Sample>(work: &mut Vec<T>, h: usize, w: usize) -> (&mut [T], &mut [T]) {
    let first = (h / 2) * (w / 2);
    let second = (h / 4) * (w / 4);
    if work.len() < first + second {
        work.resize(first + second, T::zero());
    }
    let (x, rest) = work.split_at_mut(first);
    (x, &mut rest[..second])
}

/// Forward pyramid transform of `image` into `out` (same shape, standard layout), reusing
/// `work` as scratch so that repeated calls allocate nothing. Errors name a NaN or infinity
/// in `image`, or orthonormal coefficients that overflow `T`; the check rides on the
/// transform's own pass (each row pair's outputs while they are in cache), not a pass of its
/// own.
///
/// ```
/// use haarshift::transform::{Normalization, pyramid};
/// use ndarray::{Array2, array};
/// let image = array![[1.0, 3.0], [5.0, 7.0]];
/// let mut out = Array2::zeros((2, 2));
/// pyramid::forward_into(image.view(), 1, Normalization::Average, out.view_mut(), &mut Vec::new()).unwrap();
/// assert_eq!(out, array![[4.0, -1.0], [-2.0, 0.0]]);
/// ```
pub fn forward_into<T: Sample>(
    image: ArrayView2<'_, T>,
    levels: usize,
    norm: Normalization,
    mut out: ArrayViewMut2<'_, T>,
    work: &mut Vec<T>,
) -> Result<()> {
    let (h, w) = image.dim();
    check((h, w), levels)?;
    if out.dim() != (h, w) {
        return Err(Error::shape(
            &[out.nrows(), out.ncols()],
            format!("output must be {h}x{w}"),
        ));
    }
    let out = out
        .as_slice_mut()
        .ok_or_else(|| Error::shape(&[h, w], "output must be contiguous row-major"))?;
    let image = image.as_standard_layout();
    let image = image.as_slice().expect("standard layout is contiguous");
    if levels == 0 {
        out.copy_from_slice(image);
        return ensure_finite(&rows_view(out, w));
    }
    let f2 = norm.forward_factor_2d::<T>();
    // Average coefficients are means and half-differences of values in range: only the
    // orthonormal ones, which grow by 2 a level, can overflow.
    let check_details = norm == Normalization::Orthonormal;
    let (x, y) = ping_pong(work, h, w);
    // Step s writes its approximation to x when s is even, y when odd; the last to `out`.
    let (mut dst, mut spare) = (x, y);
    let mut finite = true;
    for step in 0..levels {
        let size = (h >> step, w >> step);
        let last = step + 1 == levels;
        let (cur, stride): (&[T], usize) = if step == 0 {
            (image, w)
        } else {
            (&*spare, size.1)
        };
        let target = if last {
            ApproxTarget::Output
        } else {
            ApproxTarget::Buffer(&mut *dst)
        };
        finite &= analysis_step(cur, stride, size, out, w, target, f2, check_details);
        std::mem::swap(&mut dst, &mut spare);
    }
    if finite {
        return Ok(());
    }
    // Name the input's first NaN or infinity; with none, the sums overflowed.
    ensure_finite(&rows_view(image, w))?;
    Err(Error::parameter(
        "image",
        format!("values too large: the transform overflows {}", T::NAME),
    ))
}

/// A row-major `h x w` slice as an array view, for error messages naming an index.
fn rows_view<T>(values: &[T], w: usize) -> ArrayView2<'_, T> {
    ArrayView2::from_shape((values.len() / w, w), values).expect("whole rows")
}

/// Forward pyramid transform with `levels` steps, returning the coefficients.
///
/// ```
/// use haarshift::transform::{Normalization, pyramid};
/// use ndarray::Array2;
/// let image = Array2::from_elem((4, 4), 2.5f32);
/// let c = pyramid::forward(image.view(), 2, Normalization::Average).unwrap();
/// assert_eq!(c[[0, 0]], 2.5);
/// assert_eq!(c.iter().filter(|&&v| v != 0.0).count(), 1);
/// ```
pub fn forward<T: Sample>(
    image: ArrayView2<'_, T>,
    levels: usize,
    norm: Normalization,
) -> Result<Array2<T>> {
    check(image.dim(), levels)?;
    let mut out = Array2::zeros(image.dim());
    forward_into(image, levels, norm, out.view_mut(), &mut Vec::new())?;
    Ok(out)
}

/// Inverse pyramid transform of `coeffs` into `out` (same shape, standard layout).
pub fn inverse_into<T: Sample>(
    coeffs: ArrayView2<'_, T>,
    levels: usize,
    norm: Normalization,
    mut out: ArrayViewMut2<'_, T>,
    work: &mut Vec<T>,
) -> Result<()> {
    let (h, w) = coeffs.dim();
    check((h, w), levels)?;
    if out.dim() != (h, w) {
        return Err(Error::shape(
            &[out.nrows(), out.ncols()],
            format!("output must be {h}x{w}"),
        ));
    }
    let out = out
        .as_slice_mut()
        .ok_or_else(|| Error::shape(&[h, w], "output must be contiguous row-major"))?;
    let coeffs = coeffs.as_standard_layout();
    let coeffs = coeffs.as_slice().expect("standard layout is contiguous");
    if levels == 0 {
        out.copy_from_slice(coeffs);
        return Ok(());
    }
    let g2 = norm.inverse_factor_2d::<T>();
    let (h0, w0) = (h >> levels, w >> levels);
    let (x, y) = ping_pong(work, h, w);
    // Step s (from coarse) produces a (2 h0 << s) x (2 w0 << s) approximation; counted from
    // the last, even distances go to the larger buffer x.
    let (mut dst, mut spare) = if levels.is_multiple_of(2) {
        (x, y)
    } else {
        (y, x)
    };
    for step in 0..levels {
        let size = (h0 << step, w0 << step);
        let bands = Strided {
            data: coeffs,
            stride: w,
        };
        let cur = match step {
            0 => bands,
            _ => Strided {
                data: &*spare,
                stride: size.1,
            },
        };
        if step + 1 == levels {
            synthesis_step(cur, bands, size, out, w, g2);
        } else {
            synthesis_step(cur, bands, size, dst, 2 * size.1, g2);
        }
        std::mem::swap(&mut dst, &mut spare);
    }
    Ok(())
}

/// Inverse pyramid transform with `levels` steps, returning the array.
///
/// ```
/// use haarshift::transform::{Normalization, pyramid};
/// use ndarray::array;
/// let c = array![[4.0, -1.0], [-2.0, 0.0]];
/// let x = pyramid::inverse(c.view(), 1, Normalization::Average).unwrap();
/// assert_eq!(x, array![[1.0, 3.0], [5.0, 7.0]]);
/// ```
pub fn inverse<T: Sample>(
    coeffs: ArrayView2<'_, T>,
    levels: usize,
    norm: Normalization,
) -> Result<Array2<T>> {
    check(coeffs.dim(), levels)?;
    let mut out = Array2::zeros(coeffs.dim());
    inverse_into(coeffs, levels, norm, out.view_mut(), &mut Vec::new())?;
    Ok(out)
}
