//! Shifting one image plane by a whole or fractional number of pixels, in the Haar domain or
//! with a pixel kernel: what `haarshift shift` does to every plane.

use ndarray::{Array2, ArrayView2, s};

use crate::kernels::{KernelOptions, Outside, ShiftMethod, shift_plane};
use crate::shift::{RetainedImage, shift_image};
use crate::transform::{TransformSpec, pyramid};
use crate::{BoundaryMode, Error, Result, Sample};

/// How to shift a plane: the method, its options, and where a pixel kernel's samples from
/// outside come from.
///
/// With [`ShiftMethod::Haar`] the plane is transformed (pyramid, average normalisation, full
/// depth, periodic padding to powers of two), shifted on its coefficients ([`shift_image`])
/// and transformed back: periodic over the padded size, each shift rounded to
/// `1 / 2^precision`. With `retain` the result is the `2^precision`-finer image that the
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
        let coeffs = spec.forward(plane)?;
        let h = self.options.precision;
        if !self.options.retain {
            return shift_image(&coeffs, dx, dy, h)?.inverse();
        }
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
