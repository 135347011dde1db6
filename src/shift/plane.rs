//! Shifting one image plane by a whole or fractional number of pixels, in the Haar domain or
//! with a pixel kernel: what `haarshift shift` does to every plane.

use ndarray::{Array2, ArrayView2, s};

use crate::kernels::{KernelOptions, Outside, ShiftMethod, shift_plane};
use crate::shift::{GridShift, RetainedImage, shift_image};
use crate::transform::{TransformSpec, pyramid};
use crate::{BoundaryMode, Error, Result, Sample};

/// How to shift a plane: the method, its options, and where a pixel kernel's samples from
/// outside come from.
///
/// With [`ShiftMethod::Haar`] the plane is transformed (pyramid, average normalisation, full
/// depth, periodic padding to powers of two), shifted on its coefficients ([`shift_image`])
/// and transformed back: periodic over the padded size, each shift rounded to
/// `1 / 2^precision`. A shift that rounds to whole pixels is the permutation it is: the
/// periodically padded plane rolled and cropped, with no arithmetic, so it is exact in every
/// precision (through the transform, 8-bit codes divided by 255 in f32 would come back a few
/// units in the last place off). With `retain` the result is the `2^precision`-finer image that the
/// retained levels describe ([`RetainedImage`]). Other methods shift rows, then columns, in the
/// pixel domain ([`shift_plane`]) with `boundary` outside.
///
/// ```
/// use haarshift::BoundaryMode;
/// use haarshift::kernels::{KernelOptions, ShiftMethod};
/// use haarshift::shift::PlaneShift;
/// use ndarray::array;
/// let x = array![[0.0, 2.0, 4.0, 6.0]];
/// let opts = KernelOptions { precision: 1, ..Default::default() };
/// let haar = PlaneShift::new(ShiftMethod::Haar, opts, BoundaryMode::Wrap).unwrap();
/// assert_eq!(haar.apply(x.view(), 0.5, 0.0).unwrap(), array![[3.0, 1.0, 3.0, 5.0]]);
/// let fine = PlaneShift::new(ShiftMethod::Haar, KernelOptions { retain: true, ..opts }, BoundaryMode::Wrap).unwrap();
/// assert_eq!(fine.shape(1, 4).unwrap(), (2, 8));
/// let whole = haar.apply(x.view(), -1.0, 0.0).unwrap();
/// assert_eq!(whole, array![[2.0, 4.0, 6.0, 0.0]]);
/// let reflect = PlaneShift::new(ShiftMethod::Haar, opts, BoundaryMode::Reflect);
/// assert!(matches!(reflect, Err(haarshift::Error::InvalidParameter { name: "boundary", .. })));
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PlaneShift {
    method: ShiftMethod,
    options: KernelOptions,
    boundary: BoundaryMode,
}

impl PlaneShift {
    /// Checks the options: the kernel's parameters, and that a Haar shift is periodic.
    pub fn new(
        method: ShiftMethod,
        options: KernelOptions,
        boundary: BoundaryMode,
    ) -> Result<Self> {
        method.kernel_with::<f64>(&options)?;
        if method == ShiftMethod::Haar && boundary != BoundaryMode::Wrap {
            return Err(Error::InvalidParameter {
                name: "boundary",
                reason: format!("the Haar shift is periodic (wrap), not {boundary}"),
            });
        }
        Ok(PlaneShift {
            method,
            options,
            boundary,
        })
    }

    /// The size of the shifted `rows x cols` plane: the same, or `2^precision` times larger
    /// on each side for a retained Haar shift.
    pub fn shape(&self, rows: usize, cols: usize) -> Result<(usize, usize)> {
        if self.method != ShiftMethod::Haar || !self.options.retain {
            return Ok((rows, cols));
        }
        let scale = 1usize << self.options.precision;
        match (rows.checked_mul(scale), cols.checked_mul(scale)) {
            (Some(r), Some(c)) => Ok((r, c)),
            _ => Err(Error::shape(
                &[rows, cols],
                format!("too large for a 2^{}-finer grid", self.options.precision),
            )),
        }
    }

    /// `plane` moved by `dx` columns (right for `dx > 0`) and `dy` rows (down for `dy > 0`):
    /// `out[r][c] = plane(r - dy, c - dx)`.
    pub fn apply<T: Sample>(
        &self,
        plane: ArrayView2<'_, T>,
        dx: f64,
        dy: f64,
    ) -> Result<Array2<T>> {
        if self.method != ShiftMethod::Haar {
            let kernel = self.method.kernel_with::<T>(&self.options)?;
            return shift_plane(
                plane,
                dx,
                dy,
                kernel.as_ref(),
                Outside::Boundary(self.boundary),
            );
        }
        let spec = TransformSpec {
            padding: BoundaryMode::Wrap,
            ..Default::default()
        };
        let h = self.options.precision;
        if !self.options.retain {
            let (sx, sy) = (GridShift::new(dx, h)?, GridShift::new(dy, h)?);
            if let (Some(sx), Some(sy)) = (sx.whole_multiple_of(0), sy.whole_multiple_of(0)) {
                let padded = spec.padded_shape(plane.nrows(), plane.ncols())?;
                return periodic_roll(plane, padded, sx, sy);
            }
            return shift_image(&spec.forward(plane)?, dx, dy, h)?.inverse();
        }
        let coeffs = spec.forward(plane)?;
        let mut retained = RetainedImage::new(&coeffs, h)?;
        retained.shift(dx, dy)?;
        let info = coeffs.info();
        let fine = pyramid::inverse(
            retained.fine(),
            info.levels[0] + h as usize,
            info.normalization,
        )?;
        let [rows, cols] = info.original_shape;
        Ok(fine.slice(s![..rows << h, ..cols << h]).to_owned())
    }
}

/// `plane` padded periodically to `padded` (as the transform pads it), rolled by whole
/// shifts `sx` (columns) and `sy` (rows) over that period and cropped back to its size:
/// `out[r][c] = plane[((r - sy) mod R) mod rows][((c - sx) mod C) mod cols]`, exactly what the
/// Haar shift computes for a whole shift, as the permutation it is.
fn periodic_roll<T: Sample>(
    plane: ArrayView2<'_, T>,
    (period_rows, period_cols): (usize, usize),
    sx: GridShift,
    sy: GridShift,
) -> Result<Array2<T>> {
    let (qx, _) = sx.split(period_cols)?;
    let (qy, _) = sy.split(period_rows)?;
    let (rows, cols) = plane.dim();
    let source_col: Vec<usize> = (0..cols)
        .map(|c| (c + period_cols - qx) % period_cols % cols)
        .collect();
    Ok(Array2::from_shape_fn((rows, cols), |(r, c)| {
        plane[[(r + period_rows - qy) % period_rows % rows, source_col[c]]]
    }))
}
