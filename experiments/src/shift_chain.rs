//! The shift-chain experiment (Alnasser 2008's Table 3.1): one shift by `(dx, dy)` against the same
//! shift made as `steps` equal steps, periodic boundary, RMS over the whole frame.
//!
//! Every method sees the same input: the centred square crop whose side is the largest power
//! of two that fits, so that "periodic" means the same period for the pixel kernels (rows
//! continued by wrapping) and for the Haar transforms (periodic over their power-of-two size).

use std::time::Instant;

use ndarray::{Array2, ArrayView2, s};
use serde::{Deserialize, Serialize};

use haarshift::BoundaryMode;
use haarshift::kernels::{KernelOptions, Outside, ShiftMethod, shift_plane};
use haarshift::metrics::ErrorStats;
use haarshift::shift::{RetainedImage, shift_image};
use haarshift::transform::TransformSpec;
use haarshift::{Error, Result};

/// One result row: one image, one method.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ChainRecord {
    /// Image file name (or pattern name).
    pub image: String,
    /// Kernel name.
    pub method: String,
    /// Haar precision `h`, for the Haar method.
    pub precision: Option<u32>,
    /// Haar mode: retained (true) or compact (false), for the Haar method.
    pub retain: Option<bool>,
    /// Side of the square crop shifted.
    pub size: usize,
    /// Total shift in columns.
    pub dx: f64,
    /// Total shift in rows.
    pub dy: f64,
    /// Steps of the chain.
    pub steps: usize,
    /// RMS difference between the chain and the single shift, whole frame.
    pub rms: f64,
    /// PSNR in dB (peak 255); null when exact.
    #[serde(with = "haarshift::metrics::infinite_as_null")]
    pub psnr: f64,
    /// Largest absolute difference.
    pub max_error: f64,
    /// Wall time of the single shift and the chain together.
    pub seconds: f64,
}

/// The centred square crop whose side is the largest power of two within `min(h, w)`.
///
/// ```
/// let p = ndarray::Array2::<f64>::zeros((300, 451));
/// assert_eq!(haarshift_experiments::shift_chain::power_of_two_crop(p.view()).unwrap().dim(), (256, 256));
/// ```
pub fn power_of_two_crop(plane: ArrayView2<'_, f64>) -> Result<ArrayView2<'_, f64>> {
    let (h, w) = plane.dim();
    let m = h.min(w);
    if m == 0 {
        return Err(Error::shape(&[h, w], "image is empty"));
    }
    let side = 1usize << m.ilog2();
    let (top, left) = ((h - side) / 2, (w - side) / 2);
    Ok(plane.slice_move(s![top..top + side, left..left + side]))
}

/// Shifts `plane` by `(dx, dy)` in `steps` equal steps with `method`, periodically: pixel
/// kernels through [`shift_plane`] with wrapped rows, compact Haar through [`shift_image`]
/// once per step (each step rounded to `1/2^h`), retained Haar through [`RetainedImage`].
/// `plane` must have power-of-two sides for the Haar paths to be periodic over it.
pub fn shift_in_steps(
    plane: ArrayView2<'_, f64>,
    method: ShiftMethod,
    options: &KernelOptions,
    (dx, dy): (f64, f64),
    steps: usize,
) -> Result<Array2<f64>> {
    if steps == 0 {
        return Err(Error::parameter("steps", "must be at least 1"));
    }
    let (sx, sy) = (dx / steps as f64, dy / steps as f64);
    if method != ShiftMethod::Haar {
        let kernel = method.kernel_with::<f64>(options)?;
        let wrap = Outside::Boundary(BoundaryMode::Wrap);
        let mut out = plane.to_owned();
        for _ in 0..steps {
            out = shift_plane(out.view(), sx, sy, kernel.as_ref(), wrap)?;
        }
        return Ok(out);
    }
    let spec = TransformSpec {
        padding: BoundaryMode::Wrap,
        ..Default::default()
    };
    let mut coeffs = spec.forward(plane)?;
    if options.retain {
        let mut retained = RetainedImage::new(&coeffs, options.precision)?;
        for _ in 0..steps {
            retained.shift(sx, sy)?;
        }
        return retained.project().inverse();
    }
    for _ in 0..steps {
        coeffs = shift_image(&coeffs, sx, sy, options.precision)?;
    }
    coeffs.inverse()
}

/// Runs the experiment on one image (the crop of [`power_of_two_crop`]) for one method.
pub fn run_chain(
    image_name: &str,
    plane: ArrayView2<'_, f64>,
    method: ShiftMethod,
    options: &KernelOptions,
    shift: (f64, f64),
    steps: usize,
) -> Result<ChainRecord> {
    let crop = power_of_two_crop(plane)?;
    let start = Instant::now();
    let single = shift_in_steps(crop, method, options, shift, 1)?;
    let chain = shift_in_steps(crop, method, options, shift, steps)?;
    let seconds = start.elapsed().as_secs_f64();
    let stats = ErrorStats::between(chain.view(), single.view(), None, 255.0)?;
    let haar = method == ShiftMethod::Haar;
    Ok(ChainRecord {
        image: image_name.to_owned(),
        method: method.name().to_owned(),
        precision: haar.then_some(options.precision),
        retain: haar.then_some(options.retain),
        size: crop.nrows(),
        dx: shift.0,
        dy: shift.1,
        steps,
        rms: stats.rms,
        psnr: stats.psnr,
        max_error: stats.max_error,
        seconds,
    })
}

#[cfg(test)]
#[path = "shift_chain_tests.rs"]
mod tests;
