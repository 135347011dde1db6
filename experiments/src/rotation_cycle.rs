//! The rotation-cycle experiment (Alnasser 2008's Table 2.2): rotate an image `steps` times by
//! `360 / steps` degrees, back to where it started, and measure what the round trip lost.
//!
//! The protocol is fixed so that figures from different runs and machines compare:
//!
//! 1. Convert to luma `0.2125 R + 0.7154 G + 0.0721 B` on the stored values (a gray image is
//!    used as is; alpha is ignored). 8-bit images are in 0..255 units.
//! 2. Take the centred square crop of side `m = min(width, height)`.
//! 3. Zero-pad it by `floor(m / 2)` on every side, so that no rotation moves image content off
//!    the canvas.
//! 4. Rotate `steps` times by `360 / steps` degrees about the canvas centre, canvas `same`,
//!    fill 0.
//! 5. Measure RMS, PSNR (peak 255) and maximum error over the pixels whose centres lie within
//!    `m / 2 - 2` of the centre (the crop's inscribed disk, less a 2-pixel rim).
//!
//! Wall time covers step 4 only; peak memory is what the method allocated during step 4 above
//! what was allocated before it, when a [`MemoryMeter`] can tell.

use std::time::Instant;

use ndarray::{Array2, ArrayView2, Axis, s};
use serde::{Deserialize, Serialize};

use haarshift::metrics::{ErrorStats, disk_mask};
use haarshift::{Channels, PlanarImage, Sample};
use haarshift::{Error, Result};

/// Rec. 709 luma weights on the stored values, as the protocol fixes them.
pub const LUMA_WEIGHTS: [f64; 3] = [0.2125, 0.7154, 0.0721];

/// The text of the protocol, printed with every result.
pub const PROTOCOL: &str = "luma 0.2125R+0.7154G+0.0721B on stored values; centred square crop of side m = min(w, h); \
zero-pad by floor(m/2) on every side; rotate `steps` times by 360/steps degrees about the canvas centre (canvas same, fill 0); \
RMS, PSNR (peak 255) and max error over pixel centres within m/2 - 2 of the centre";

/// Reports peak heap use, when the program has a way to know it (the CLI installs a counting
/// global allocator; a library user may have none).
pub trait MemoryMeter: Sync {
    /// Starts a new measurement from the current heap use.
    fn reset_peak(&self);
    /// Peak heap bytes since the last reset above the use at that reset, if known.
    fn peak_bytes(&self) -> Option<u64>;
}

/// A meter that knows nothing: `peak_bytes` is always `None`.
#[derive(Clone, Copy, Debug, Default)]
pub struct NoMeter;

impl MemoryMeter for NoMeter {
    fn reset_peak(&self) {}
    fn peak_bytes(&self) -> Option<u64> {
        None
    }
}

/// How a method is described in results: its command-line name and its parameters.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct MethodSpec {
    /// As given to `--method`.
    pub method: String,
    /// Haar precision `h` (extra levels), when the method has one.
    pub precision: Option<u32>,
    /// Whether the Haar method keeps its `N + h` levels across the whole cycle.
    pub retain: Option<bool>,
    /// Rotation on a `2^supersample` finer grid.
    pub supersample: u32,
}

impl MethodSpec {
    /// A short label for tables and plots, e.g. `haar h=3 retained` or `fft s=1`.
    ///
    /// ```
    /// use haarshift_experiments::rotation_cycle::MethodSpec;
    /// let m = MethodSpec { method: "haar".into(), precision: Some(3), retain: Some(true), supersample: 0 };
    /// assert_eq!(m.label(), "haar h=3 retained");
    /// ```
    pub fn label(&self) -> String {
        let mut label = self.method.clone();
        if let Some(h) = self.precision {
            label.push_str(&format!(" h={h}"));
        }
        match self.retain {
            Some(true) => label.push_str(" retained"),
            Some(false) => label.push_str(" compact"),
            None => {}
        }
        if self.supersample > 0 {
            label.push_str(&format!(" s={}", self.supersample));
        }
        label
    }
}

/// A way of rotating a plane repeatedly: what the experiment compares.
pub trait CycleMethod: Sync {
    /// Name and parameters, for the results.
    fn spec(&self) -> MethodSpec;
    /// Rotates `plane` `steps` times by `angle_deg` (counter-clockwise as displayed) about
    /// its centre, canvas `same`, fill 0, and returns the result.
    fn rotate_repeatedly(
        &self,
        plane: ArrayView2<'_, f64>,
        angle_deg: f64,
        steps: usize,
    ) -> Result<Array2<f64>>;
}

/// One result row: one image, one method.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct CycleRecord {
    /// Image file name (or pattern name).
    pub image: String,
    /// The method and its parameters.
    #[serde(flatten)]
    pub method: MethodSpec,
    /// Rotations in the cycle.
    pub steps: usize,
    /// Side of the square crop.
    pub crop: usize,
    /// Root mean square error inside the measurement disk.
    pub rms: f64,
    /// PSNR in dB (peak 255); null when exact.
    #[serde(with = "haarshift::metrics::infinite_as_null")]
    pub psnr: f64,
    /// Largest absolute error inside the disk.
    pub max_error: f64,
    /// Wall time of the rotations.
    pub seconds: f64,
    /// Peak heap bytes the rotations allocated, when measured.
    pub peak_bytes: Option<u64>,
}

/// The luma plane of `image` by [`LUMA_WEIGHTS`] (gray images as they are; alpha ignored).
///
/// ```
/// use haarshift_experiments::rotation_cycle::luma;
/// use haarshift::{Channels, PlanarImage, SampleDepth};
/// use ndarray::Array3;
/// let rgb = PlanarImage::new(Array3::from_elem((3, 1, 1), 100.0), Channels::Rgb, SampleDepth::U8).unwrap();
/// assert!((luma(&rgb)[[0, 0]] - 100.0).abs() < 1e-12); // the weights sum to 1
/// ```
pub fn luma<T: Sample>(image: &PlanarImage<T>) -> Array2<f64> {
    let colour = image.color_planes();
    match image.channels() {
        Channels::Gray | Channels::GrayAlpha => colour.index_axis(Axis(0), 0).mapv(Sample::as_f64),
        Channels::Rgb | Channels::Rgba => {
            let mut out = Array2::zeros((image.height(), image.width()));
            for (plane, w) in colour.outer_iter().zip(LUMA_WEIGHTS) {
                out.zip_mut_with(&plane, |o, &v| *o += w * v.as_f64());
            }
            out
        }
    }
}

/// The protocol's input: the centred square crop of side `min(h, w)` of `plane`, zero-padded
/// by `floor(m / 2)` on every side. Returns the canvas and `m`.
///
/// ```
/// use haarshift_experiments::rotation_cycle::prepare_canvas;
/// let (canvas, m) = prepare_canvas(ndarray::Array2::ones((3, 5)).view()).unwrap();
/// assert_eq!((canvas.dim(), m), ((5, 5), 3));
/// assert_eq!(canvas.sum(), 9.0);
/// ```
pub fn prepare_canvas(plane: ArrayView2<'_, f64>) -> Result<(Array2<f64>, usize)> {
    let (h, w) = plane.dim();
    let m = h.min(w);
    if m == 0 {
        return Err(Error::shape(&[h, w], "image is empty"));
    }
    let (top, left) = ((h - m) / 2, (w - m) / 2);
    let pad = m / 2;
    let mut canvas = Array2::zeros((m + 2 * pad, m + 2 * pad));
    canvas
        .slice_mut(s![pad..pad + m, pad..pad + m])
        .assign(&plane.slice(s![top..top + m, left..left + m]));
    Ok((canvas, m))
}

/// The measurement disk for a crop of side `m` on its canvas (radius `m/2 - 2`).
pub fn measurement_mask(canvas: usize, m: usize) -> Result<Array2<bool>> {
    let radius = m as f64 / 2.0 - 2.0;
    if radius < 0.0 {
        return Err(Error::parameter(
            "image size",
            format!("a crop of side {m} leaves no pixels to measure (needs m >= 4)"),
        ));
    }
    Ok(disk_mask(canvas, canvas, radius))
}

/// One run of the protocol: the record, and the canvas before and after the cycle (for
/// figures such as [`crate::plot::labelled_tiles`]).
#[derive(Clone, Debug, PartialEq)]
pub struct CycleRun {
    /// The measured figures.
    pub record: CycleRecord,
    /// The padded canvas the cycle started from (step 3).
    pub canvas: Array2<f64>,
    /// The canvas after the cycle.
    pub result: Array2<f64>,
}

/// Runs the protocol for one plane (already in luma) and one method.
pub fn run_cycle(
    image_name: &str,
    plane: ArrayView2<'_, f64>,
    method: &dyn CycleMethod,
    steps: usize,
    meter: &dyn MemoryMeter,
) -> Result<CycleRun> {
    if steps == 0 {
        return Err(Error::parameter("steps", "must be at least 1"));
    }
    let (canvas, m) = prepare_canvas(plane)?;
    let mask = measurement_mask(canvas.nrows(), m)?;
    meter.reset_peak();
    let start = Instant::now();
    let result = method.rotate_repeatedly(canvas.view(), 360.0 / steps as f64, steps)?;
    let seconds = start.elapsed().as_secs_f64();
    let peak_bytes = meter.peak_bytes();
    let stats = ErrorStats::between(result.view(), canvas.view(), Some(mask.view()), 255.0)?;
    let record = CycleRecord {
        image: image_name.to_owned(),
        method: method.spec(),
        steps,
        crop: m,
        rms: stats.rms,
        psnr: stats.psnr,
        max_error: stats.max_error,
        seconds,
        peak_bytes,
    };
    Ok(CycleRun {
        record,
        canvas,
        result,
    })
}

#[cfg(test)]
#[path = "rotation_cycle_tests.rs"]
mod tests;
