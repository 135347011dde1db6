//! The drivers: shift every row of an array by its own amount, in parallel, optionally writing
//! the result transposed (so a column shear is a row shear between two fused transposes).

use ndarray::{Array2, ArrayView2, Axis, CowArray};
use rayon::prelude::*;

use super::grid::{box_average, upsample_nearest};
use super::{Outside, ROW_GROUP, RowGeometry, RowShifter, ShearKernel};
use crate::{Error, Result, Sample, ensure_finite};

/// Rows per parallel task when writing transposed: 32 output values per row segment (128 bytes
/// of f32) keep the transposed writes in whole cache lines while the tile stays in L2.
const TILE: usize = 32;

/// Shifts beyond this are rejected: far past any image, and safe to convert to `isize`.
const MAX_SHIFT: f64 = 1e15;

/// Checks `shifts` (one per row, finite, not absurd) and the sizes.
fn validate(rows: usize, len_in: usize, len_out: usize, shifts: &[f64]) -> Result<()> {
    if rows == 0 || len_in == 0 || len_out == 0 {
        return Err(Error::shape(
            &[rows, len_in, len_out],
            "rows must not be empty",
        ));
    }
    if shifts.len() != rows {
        return Err(Error::shape(
            &[shifts.len()],
            format!("{} shifts for {rows} rows", shifts.len()),
        ));
    }
    shifts.iter().try_for_each(|&s| check_shift(s))
}

/// Refuses a NaN shift or one beyond [`MAX_SHIFT`] (infinities included).
pub(crate) fn check_shift(shift: f64) -> Result<()> {
    if shift.is_nan() || shift.abs() > MAX_SHIFT {
        return Err(Error::parameter(
            "shift",
            format!("{shift} is not a finite shift of at most {MAX_SHIFT:e}"),
        ));
    }
    Ok(())
}

/// Shifts row `r` of `input` by `shifts[r]` into a row of `len_out` samples:
/// `out[r][n] = input_r(n - shifts[r])`, samples outside the row from `outside`.
///
/// Integer shifts are exact copies; the others go to the kernel. Rows run in parallel, each
/// worker thread reusing one [`RowShifter`].
///
/// ```
/// use haarshift::kernels::{Outside, ShiftMethod, shear_rows};
/// use ndarray::array;
/// let k = ShiftMethod::Nearest.kernel::<f32>();
/// let out = shear_rows(array![[1.0f32, 2.0], [3.0, 4.0]].view(), 3, &[1.0, -1.0], k.as_ref(),
///                      Outside::Fill(9.0)).unwrap();
/// assert_eq!(out, array![[9.0, 1.0, 2.0], [4.0, 9.0, 9.0]]);
/// ```
pub fn shear_rows<T: Sample>(
    input: ArrayView2<'_, T>,
    len_out: usize,
    shifts: &[f64],
    kernel: &dyn ShearKernel<T>,
    outside: Outside,
) -> Result<Array2<T>> {
    let (rows, len_in) = input.dim();
    validate(rows, len_in, len_out, shifts)?;
    check_finite(input)?;
    shear_pass(input, len_out, shifts, kernel, outside.validate()?, false)
}

/// Shifts a whole plane by `(dx, dy)` pixels: `out[r][c] = plane(r - dy, c - dx)`, separably
/// (rows, then columns), samples outside from `outside`. A kernel with a
/// [`grid_exponent`](ShearKernel::grid_exponent) `h` works on the `2^h`-finer grid.
///
/// ```
/// use haarshift::kernels::{Outside, ShiftMethod, shift_plane};
/// use ndarray::array;
/// let k = ShiftMethod::Linear.kernel::<f64>();
/// let p = array![[0.0, 0.0], [0.0, 4.0]];
/// let out = shift_plane(p.view(), -0.5, -0.5, k.as_ref(), Outside::Fill(0.0)).unwrap();
/// assert_eq!(out[[0, 0]], 1.0);
/// ```
pub fn shift_plane<T: Sample>(
    plane: ArrayView2<'_, T>,
    dx: f64,
    dy: f64,
    kernel: &dyn ShearKernel<T>,
    outside: Outside,
) -> Result<Array2<T>> {
    let (h, w) = plane.dim();
    let e = kernel.grid_exponent();
    let scale = f64::from(1u32 << e.min(31));
    let fine = match e {
        0 => CowArray::from(plane),
        _ => CowArray::from(upsample_nearest(plane, e)?),
    };
    let (fh, fw) = fine.dim();
    validate(fh, fw, fw, &vec![dx * scale; fh])?;
    validate(fw, fh, fh, &vec![dy * scale; fw])?;
    check_finite(plane)?;
    let outside = outside.validate()?;
    let columns = shear_pass(
        fine.view(),
        fw,
        &vec![dx * scale; fh],
        kernel,
        outside,
        true,
    )?;
    let fine = shear_pass(
        columns.view(),
        fh,
        &vec![dy * scale; fw],
        kernel,
        outside,
        true,
    )?;
    let out = if e == 0 {
        fine
    } else {
        box_average(fine.view(), e)
    };
    debug_assert_eq!(out.dim(), (h, w));
    Ok(out)
}

/// [`ensure_finite`] in one vectorised, parallel pass (`v * 0` is NaN exactly for NaN and
/// infinities; sixteen partial sums keep the additions independent so that they vectorise);
/// the slower indexed search runs only to name the culprit.
pub(crate) fn check_finite<T: Sample>(plane: ArrayView2<'_, T>) -> Result<()> {
    fn probe<T: Sample>(values: &[T]) -> bool {
        let mut acc = [T::zero(); 16];
        let mut chunks = values.chunks_exact(16);
        for chunk in chunks.by_ref() {
            for (a, v) in acc.iter_mut().zip(chunk) {
                *a += *v * T::zero();
            }
        }
        let tail = chunks
            .remainder()
            .iter()
            .fold(T::zero(), |a, v| a + *v * T::zero());
        (acc.iter().fold(tail, |a, v| a + *v)).is_nan()
    }
    let suspicious = match plane.as_slice() {
        Some(values) => values.par_chunks(1 << 16).any(probe),
        None => plane.rows().into_iter().any(|r| probe(&r.to_vec())),
    };
    if suspicious {
        ensure_finite(&plane)?;
    }
    Ok(())
}

/// [`shear_rows`] without validation, into a new array; see [`shear_pass_into`].
pub(crate) fn shear_pass<T: Sample>(
    input: ArrayView2<'_, T>,
    len_out: usize,
    shifts: &[f64],
    kernel: &dyn ShearKernel<T>,
    outside: Outside,
    transposed: bool,
) -> Result<Array2<T>> {
    let rows = input.nrows();
    let mut out = vec![T::zero(); rows * len_out];
    shear_pass_into(
        input, len_out, shifts, kernel, outside, transposed, &mut out,
    )?;
    let shape = if transposed {
        (len_out, rows)
    } else {
        (rows, len_out)
    };
    Ok(Array2::from_shape_vec(shape, out).expect("sized above"))
}

/// [`shear_rows`] without validation, writing every sample of `out` (`rows x len_out`, or
/// `len_out x rows` with `transposed`, row-major). With `transposed` the rows go through a tile
/// per task, which is the blocked transpose fused in. A kernel's error stops the pass and is
/// returned (`out` is then partly written).
pub(crate) fn shear_pass_into<T: Sample>(
    input: ArrayView2<'_, T>,
    len_out: usize,
    shifts: &[f64],
    kernel: &dyn ShearKernel<T>,
    outside: Outside,
    transposed: bool,
    out: &mut [T],
) -> Result<()> {
    let input = input.as_standard_layout();
    let (rows, len_in) = input.dim();
    assert_eq!(out.len(), rows * len_out, "output sized for the pass");
    let src = input.as_slice().expect("standard layout");
    let geometry = RowGeometry {
        len_in,
        len_out,
        min_shift: shifts.iter().copied().fold(f64::INFINITY, f64::min),
        max_shift: shifts.iter().copied().fold(f64::NEG_INFINITY, f64::max),
    };
    // Rows `r0..` into `block` (whole rows of `len_out`): integer shifts are exact copies,
    // the others go to the kernel together.
    let shift_group = |shifter: &mut Box<dyn RowShifter<T> + '_>, r0: usize, block: &mut [T]| {
        let mut rows: [&[T]; ROW_GROUP] = [&[]; ROW_GROUP];
        let mut amounts = [0.0; ROW_GROUP];
        let mut outs: [&mut [T]; ROW_GROUP] = Default::default();
        let mut m = 0;
        for (i, o) in block.chunks_exact_mut(len_out).enumerate() {
            let r = r0 + i;
            let row = &src[r * len_in..(r + 1) * len_in];
            let s = shifts[r];
            if s.fract() == 0.0 {
                outside.extend_into(row, -(s as isize), o);
            } else {
                (rows[m], amounts[m], outs[m]) = (row, s, o);
                m += 1;
            }
        }
        if m > 0 {
            shifter.shift_rows(&rows[..m], &amounts[..m], &mut outs[..m])?;
        }
        Ok(())
    };
    // Few, large tasks: each one builds a worker (and a tile), which costs far more than a row.
    let tasks = 4 * rayon::current_num_threads();
    if !transposed {
        return out
            .par_chunks_mut(len_out * ROW_GROUP)
            .enumerate()
            .with_min_len(rows.div_ceil(ROW_GROUP * tasks))
            .try_for_each_init(
                || kernel.row_shifter(geometry, outside),
                |shifter, (g, block)| shift_group(shifter, g * ROW_GROUP, block),
            );
    }
    let mut out = ndarray::ArrayViewMut2::from_shape((len_out, rows), out).expect("sized");
    out.axis_chunks_iter_mut(Axis(1), TILE)
        .into_par_iter()
        .enumerate()
        .with_min_len(rows.div_ceil(TILE).div_ceil(tasks))
        .try_for_each_init(
            || {
                let tile = vec![T::zero(); TILE * len_out];
                (kernel.row_shifter(geometry, outside), tile)
            },
            |(shifter, tile), (chunk, mut block)| {
                let r0 = chunk * TILE;
                let t = block.ncols();
                for (g, group) in tile[..t * len_out]
                    .chunks_mut(len_out * ROW_GROUP)
                    .enumerate()
                {
                    shift_group(shifter, r0 + g * ROW_GROUP, group)?;
                }
                write_transposed(&tile[..t * len_out], len_out, &mut block);
                Ok(())
            },
        )
}

/// Writes the `t x len` rows of `tile` into the `len x t` block, through a small square that
/// stays in L1: whole cache lines are read from the tile and written to the block.
fn write_transposed<T: Sample>(tile: &[T], len: usize, block: &mut ndarray::ArrayViewMut2<'_, T>) {
    const SQUARE: usize = 16;
    let t = block.ncols();
    let mut square = [[T::zero(); TILE]; SQUARE];
    for j0 in (0..len).step_by(SQUARE) {
        let width = SQUARE.min(len - j0);
        for (i, row) in tile.chunks_exact(len).enumerate() {
            for (dj, v) in row[j0..j0 + width].iter().enumerate() {
                square[dj][i] = *v;
            }
        }
        for (dj, values) in square.iter().enumerate().take(width) {
            let mut out = block.row_mut(j0 + dj);
            let out = out.as_slice_mut().expect("rows of a standard array");
            out.copy_from_slice(&values[..t]);
        }
    }
}

/// The transpose of `a` as a new standard-layout array, copied in cache-sized blocks in
/// parallel.
///
/// ```
/// use ndarray::array;
/// let t = haarshift::kernels::transpose(array![[1, 2, 3], [4, 5, 6]].view());
/// assert_eq!(t, array![[1, 4], [2, 5], [3, 6]]);
/// ```
pub fn transpose<A: Copy + Default + Send + Sync>(a: ArrayView2<'_, A>) -> Array2<A> {
    let a = a.as_standard_layout();
    let (h, w) = a.dim();
    let src = a.as_slice().expect("standard layout");
    let mut out = Array2::from_elem((w, h), A::default());
    if h == 0 || w == 0 {
        return out;
    }
    out.as_slice_mut()
        .expect("new array")
        .par_chunks_mut(TILE * h)
        .enumerate()
        .for_each(|(chunk, block)| {
            let j0 = chunk * TILE;
            for i0 in (0..h).step_by(TILE) {
                let i1 = (i0 + TILE).min(h);
                for (dj, orow) in block.chunks_exact_mut(h).enumerate() {
                    for (i, v) in orow[i0..i1].iter_mut().enumerate() {
                        *v = src[(i0 + i) * w + j0 + dj];
                    }
                }
            }
        });
    out
}
