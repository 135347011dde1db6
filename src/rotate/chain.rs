//! Successive rotations on one persistent finer grid ([`RotationChain`]), projected to pixels
//! once at the end.

use ndarray::{Array2, ArrayView2};

use super::{GridRotation, RotateOptions, RotationWorkspace, buffer, check_budget, validate_plane};
use crate::kernels::{ShearKernel, grid};
use crate::{Error, Result, Sample};

/// Successive rotations of one plane on a persistent working grid, projected to pixels only
/// by [`finish`](Self::finish): the setting of error-accumulation experiments (rotate by
/// 22.5 degrees sixteen times and compare with the original).
///
/// ```
/// use haarshift::kernels::ShiftMethod;
/// use haarshift::rotate::{RotateOptions, RotationChain};
/// use ndarray::Array2;
/// let p = Array2::from_shape_fn((8, 8), |(r, c)| (r * 8 + c) as f64);
/// let k = ShiftMethod::Nearest.kernel::<f64>();
/// let opts = RotateOptions { supersample: 1, ..Default::default() };
/// let mut chain = RotationChain::new(p.view(), k.as_ref(), opts).unwrap();
/// assert_eq!(chain.working().dim(), (16, 16));
/// for _ in 0..4 {
///     chain.rotate(90.0).unwrap();
/// }
/// assert_eq!(chain.finish(), p);
/// ```
pub struct RotationChain<'k, T: Sample> {
    work: Array2<T>,
    /// The previous working grid's memory, reused for the next rotation's output.
    spare: Vec<T>,
    workspace: RotationWorkspace<T>,
    exponent: u32,
    kernel: &'k dyn ShearKernel<T>,
    options: RotateOptions,
}

impl<'k, T: Sample> RotationChain<'k, T> {
    /// Puts `plane` on the working grid (`2^(supersample + kernel.grid_exponent())` samples per
    /// pixel per axis, nearest replication).
    pub fn new(
        plane: ArrayView2<'_, T>,
        kernel: &'k dyn ShearKernel<T>,
        options: RotateOptions,
    ) -> Result<Self> {
        validate_plane(plane, &options)?;
        let (h, w) = plane.dim();
        let exponent = options.supersample + kernel.grid_exponent();
        if exponent > 30 {
            return Err(Error::parameter(
                "grid exponent",
                format!("2^{exponent} samples per pixel is too fine"),
            ));
        }
        let fine = ((h as u128) << exponent) * ((w as u128) << exponent);
        check_budget::<T>("the working grid", fine, options.memory_budget)?;
        Ok(RotationChain {
            work: grid::upsample_nearest(plane, exponent)?,
            spare: Vec::new(),
            workspace: RotationWorkspace::new(),
            exponent,
            kernel,
            options,
        })
    }

    /// Rotates the working grid by `deg` (counter-clockwise as displayed).
    pub fn rotate(&mut self, deg: f64) -> Result<&mut Self> {
        let granule = 1usize << self.exponent;
        let rotation = GridRotation::new::<T>(
            self.work.dim(),
            deg,
            granule,
            self.kernel.support_radius(),
            &self.options,
        )?;
        let (h, w) = rotation.out;
        let mut out = std::mem::take(&mut self.spare);
        buffer(&mut out, h * w);
        out.truncate(h * w);
        self.workspace.rotate_grid(
            self.work.view(),
            &rotation,
            self.kernel,
            self.options.outside,
            &mut out,
        )?;
        let out = Array2::from_shape_vec((h, w), out).expect("sized");
        self.spare = std::mem::replace(&mut self.work, out)
            .into_raw_vec_and_offset()
            .0;
        Ok(self)
    }

    /// The working grid as it stands.
    pub fn working(&self) -> ArrayView2<'_, T> {
        self.work.view()
    }

    /// Box-averages the working grid back to pixels.
    pub fn finish(self) -> Array2<T> {
        if self.exponent == 0 {
            return self.work;
        }
        grid::box_average(self.work.view(), self.exponent)
    }
}
