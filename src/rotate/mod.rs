//! Image rotation by three 1D shears (Alnasser 2008's equation 2.26; Unser, Thevenaz and
//! Yaroslavsky 1995):
//!
//! `R(theta) = [[1, -tan(theta/2)], [0, 1]] x [[1, 0], [sin(theta), 1]] x [[1, -tan(theta/2)], [0, 1]]`
//!
//! Each shear shifts every row (or column) by its own fractional amount with a
//! [`ShearKernel`]; the column shear is a row shear between two transposes that are fused into
//! the shear passes.
//!
//! # Geometry
//!
//! * A positive angle turns the image counter-clockwise as displayed (row 0 at the top), like
//!   `scipy.ndimage.rotate`, about the centre `((w-1)/2, (h-1)/2)`.
//! * Any angle is reduced to an exact multiple of 90 degrees, done by transposes and flips
//!   (bit-exact), plus a residual in `[-45, 45]` degrees done by the shears, so that
//!   `tan(theta/2)` stays at most `tan(22.5)`. See [`reduce_angle`].
//! * [`Canvas::Same`] keeps the input size; [`Canvas::Expand`] grows to
//!   `round(w|cos| + h|sin|) x round(w|sin| + h|cos|)` (scipy's `reshape=True`), which holds
//!   the whole rotated image. Turning a non-square image by a quarter turn into the same
//!   canvas with `w - h` odd moves the centre by half a pixel: the shears then interpolate
//!   that half pixel, so only this case of a multiple of 90 degrees is not a pure copy.
//! * Samples from outside the image come from [`RotateOptions::outside`]: a fill value
//!   (default 0) or a boundary mode, which continues the input in 2D before rotating.
//! * Intermediate images are sized to hold everything the output needs plus the kernel's
//!   [`support_radius`](ShearKernel::support_radius); all work is in `T`, with no rounding
//!   between the shears.
//!
//! # Supersampling and finer-grid kernels
//!
//! With `supersample = S` (and a kernel whose [`grid_exponent`](ShearKernel::grid_exponent)
//! is `h`), the image is replicated onto a grid `2^(S+h)` times finer per axis (each pixel
//! becomes a block of equal samples), rotated there about the same continuous centre, and
//! box-averaged back. [`RotationChain`] keeps that fine grid across successive rotations and
//! projects only at the end, for error-accumulation experiments.
//!
//! ```
//! use haarshift::kernels::ShiftMethod;
//! use haarshift::rotate::{RotateOptions, rotate_plane};
//! use ndarray::array;
//! let p = array![[1.0, 2.0], [3.0, 4.0]];
//! let k = ShiftMethod::BSpline3.kernel::<f64>();
//! // A quarter turn counter-clockwise: the right column becomes the top row.
//! let r = rotate_plane(p.view(), 90.0, k.as_ref(), &RotateOptions::default()).unwrap();
//! assert_eq!(r, array![[2.0, 4.0], [1.0, 3.0]]);
//! ```

use ndarray::{Array2, ArrayView2, Axis, CowArray};

use crate::kernels::shear::{check_finite, shear_pass_into};
use crate::kernels::{Outside, ShearKernel};
use crate::named::named_enum;
use crate::sample::round_to_code;
use crate::{BoundaryMode, Error, PlanarImage, Result, Sample};

mod angle;
mod chain;

use angle::is_pure_copy;
pub use angle::{ReducedAngle, expanded_size, quarter_turn, reduce_angle};
pub use chain::RotationChain;

named_enum! {
    /// The size of the rotated image.
    #[derive(Default)]
    pub enum Canvas ("canvas") {
        /// The input's size (corners are cut off, the outside fills in).
        #[default]
        Same = "same",
        /// Large enough for the whole rotated image.
        Expand = "expand",
    }
}

/// The largest `supersample` exponent accepted (a 256-times finer grid per axis).
pub const MAX_SUPERSAMPLE: u32 = 8;

/// Default [`RotateOptions::memory_budget`]: 4 GiB.
pub const DEFAULT_MEMORY_BUDGET: u64 = 4 << 30;

/// How to rotate, apart from the angle and the kernel.
///
/// ```
/// use haarshift::rotate::{Canvas, RotateOptions};
/// let o = RotateOptions { canvas: Canvas::Expand, supersample: 1, ..Default::default() };
/// assert_eq!(o.outside, haarshift::kernels::Outside::Fill(0.0));
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RotateOptions {
    /// Output size.
    pub canvas: Canvas,
    /// Where samples from outside the image come from. For images with alpha, a fill value
    /// is the colour of the (fully transparent) outside; see [`rotate_image`].
    pub outside: Outside,
    /// Rotate on a `2^supersample`-finer grid (at most [`MAX_SUPERSAMPLE`]).
    pub supersample: u32,
    /// Largest number of bytes the working arrays may take together.
    pub memory_budget: u64,
}

impl RotateOptions {
    /// Checks the options that do not depend on the image or the kernel: the supersampling
    /// (at most [`MAX_SUPERSAMPLE`]) and the outside (a finite fill value).
    ///
    /// ```
    /// use haarshift::rotate::RotateOptions;
    /// let too_fine = RotateOptions { supersample: 9, ..RotateOptions::default() };
    /// assert_eq!(too_fine.validate().unwrap_err().to_string(),
    ///            "invalid supersample: 9 is above the largest, 8 (at most 8 doublings of the grid)");
    /// assert!(RotateOptions::default().validate().is_ok());
    /// ```
    pub fn validate(&self) -> Result<()> {
        if self.supersample > MAX_SUPERSAMPLE {
            return Err(Error::parameter(
                "supersample",
                format!(
                    "{} is above the largest, {MAX_SUPERSAMPLE} (at most {MAX_SUPERSAMPLE} \
                     doublings of the grid)",
                    self.supersample
                ),
            ));
        }
        self.outside.validate().map(|_| ())
    }
}

impl Default for RotateOptions {
    fn default() -> Self {
        RotateOptions {
            canvas: Canvas::Same,
            outside: Outside::Fill(0.0),
            supersample: 0,
            memory_budget: DEFAULT_MEMORY_BUDGET,
        }
    }
}

/// Checks the plane (non-empty, finite) and the options that do not depend on the kernel.
fn validate_plane<T: Sample>(plane: ArrayView2<'_, T>, options: &RotateOptions) -> Result<()> {
    let (h, w) = plane.dim();
    if h == 0 || w == 0 {
        return Err(Error::shape(&[h, w], "image is empty"));
    }
    options.validate()?;
    check_finite(plane)
}

/// Returns an error when `elements` samples of `T` exceed `budget` bytes.
fn check_budget<T>(what: &str, elements: u128, budget: u64) -> Result<()> {
    let needed = elements.saturating_mul(std::mem::size_of::<T>() as u128);
    if needed > u128::from(budget) {
        return Err(Error::MemoryBudget {
            what: what.to_string(),
            needed,
            budget: u128::from(budget),
        });
    }
    Ok(())
}

/// `a` continued by `mode` by `py` rows and `px` columns on each side.
fn pad_with_mode<T: Sample>(
    a: ArrayView2<'_, T>,
    py: usize,
    px: usize,
    mode: BoundaryMode,
) -> Array2<T> {
    let (h, w) = a.dim();
    let rows: Vec<usize> = (0..h + 2 * py)
        .map(|r| mode.source_index(r as isize - py as isize, h).unwrap_or(0))
        .collect();
    let cols: Vec<usize> = (0..w + 2 * px)
        .map(|c| mode.source_index(c as isize - px as isize, w).unwrap_or(0))
        .collect();
    Array2::from_shape_fn((rows.len(), cols.len()), |(r, c)| a[[rows[r], cols[c]]])
}

/// Everything about one rotation of an `h x w` working grid that does not need the samples:
/// the quarter turns, the output size, and the shears' geometry, with the memory budget
/// checked before anything is allocated. `granule` is the number of working samples per pixel
/// per axis (the expanded canvas is rounded in whole pixels).
struct GridRotation {
    quarter_turns: u8,
    out: (usize, usize),
    /// `None` when the quarter turns alone give the output.
    shears: Option<ShearGeometry>,
}

/// The three shears' amounts and the intermediate images' sizes.
struct ShearGeometry {
    /// The x-shear's factor `-tan(theta/2)` and the y-shear's `sin(theta)`.
    a_x: f64,
    s_y: f64,
    /// Rows and columns of boundary-mode padding around the (quarter-turned) input.
    pad: (usize, usize),
    /// Columns of the intermediate images and the integer margin of the first shear.
    w_b: usize,
    margin: f64,
}

impl GridRotation {
    fn new<T: Sample>(
        dim: (usize, usize),
        deg: f64,
        granule: usize,
        support_radius: usize,
        options: &RotateOptions,
    ) -> Result<Self> {
        let reduced = reduce_angle(deg)?;
        let (h1, w1) = if reduced.quarter_turns % 2 == 1 {
            (dim.1, dim.0)
        } else {
            dim
        };
        // Working grids are whole pixels of `granule x granule` samples, and so is the canvas.
        let (h, w) = rotated_size(dim.0 / granule, dim.1 / granule, deg, options)?;
        let too_large = || Error::shape(&[h, w], "rotated canvas too large");
        let (out_h, out_w) = (
            h.checked_mul(granule).ok_or_else(too_large)?,
            w.checked_mul(granule).ok_or_else(too_large)?,
        );
        let mut rotation = GridRotation {
            quarter_turns: reduced.quarter_turns,
            out: (out_h, out_w),
            shears: None,
        };
        if reduced.residual_deg == 0.0 && (out_h, out_w) == (h1, w1) {
            return Ok(rotation);
        }
        let theta = reduced.residual_deg.to_radians();
        let (a_x, s_y) = (-(theta / 2.0).tan(), theta.sin());
        let (cx_out, cy_out) = ((out_w as f64 - 1.0) / 2.0, (out_h as f64 - 1.0) / 2.0);
        let reach = support_radius.min(h1.max(w1)) as f64;

        // With a boundary mode, the input is continued in 2D far enough that every position
        // the output needs (its preimage plus the kernel's reach through three shears) lies
        // inside.
        let pad = match options.outside {
            Outside::Boundary(mode) if mode != BoundaryMode::Zero => {
                let (sin, cos) = (theta.sin().abs(), theta.cos().abs());
                let pad = |half_extent: f64, centre: f64| {
                    ((half_extent - centre).max(0.0) + 3.0 * reach + 2.0).ceil() as usize
                };
                let px = pad(cos * cx_out + sin * cy_out, (w1 as f64 - 1.0) / 2.0);
                let py = pad(sin * cx_out + cos * cy_out, (h1 as f64 - 1.0) / 2.0);
                check_budget::<T>(
                    "padding for the boundary mode",
                    ((h1 + 2 * py) * (w1 + 2 * px)) as u128,
                    options.memory_budget,
                )?;
                (py, px)
            }
            _ => (0, 0),
        };
        let (h_a, w_a) = (h1 + 2 * pad.0, w1 + 2 * pad.1);
        let (cx_a, cy_a) = ((w_a as f64 - 1.0) / 2.0, (h_a as f64 - 1.0) / 2.0);

        // Columns of the two intermediate images (x in centred coordinates): what the last
        // shear reads (x = X - a_x Y over the output) that the first shear can produce
        // (x + a_x y over the input), plus the kernel's reach. Both ranges are symmetric
        // about 0.
        let need = cx_out + a_x.abs() * cy_out;
        let content = cx_a + a_x.abs() * cy_a;
        let half = need.min(content) + reach;
        let margin = (half - cx_a).ceil(); // integer: keeps the first shift an exact integer at 0
        let w_b = (half + cx_a + margin).floor() as usize + 1;
        check_budget::<T>(
            "the intermediate images of the rotation",
            (h_a * w_a + w_b * h_a + out_h * w_b + out_h * out_w) as u128,
            options.memory_budget,
        )?;
        rotation.shears = Some(ShearGeometry {
            a_x,
            s_y,
            pad,
            w_b,
            margin,
        });
        Ok(rotation)
    }
}

/// Working memory of the three shears: the two intermediate images, kept between rotations.
///
/// Rotating many images (or one image many times) through one workspace allocates the
/// intermediates once: fresh memory costs a page fault per 4 KiB, which at 2048^2 is about a
/// third of a rotation's time. [`rotate_plane`] is the one-shot form.
///
/// ```
/// use haarshift::kernels::ShiftMethod;
/// use haarshift::rotate::{RotateOptions, RotationWorkspace, rotate_plane, rotated_size};
/// use ndarray::Array2;
/// let k = ShiftMethod::Keys.kernel::<f32>();
/// let opts = RotateOptions::default();
/// let mut workspace = RotationWorkspace::new();
/// let p = Array2::from_shape_fn((32, 48), |(r, c)| (r * c) as f32);
/// let mut out = Array2::zeros(rotated_size(32, 48, 30.0, &opts).unwrap());
/// for _ in 0..3 {
///     workspace.rotate_plane_into(p.view(), 30.0, k.as_ref(), &opts, out.view_mut()).unwrap();
/// }
/// assert_eq!(out, rotate_plane(p.view(), 30.0, k.as_ref(), &opts).unwrap());
/// ```
#[derive(Debug, Default)]
pub struct RotationWorkspace<T> {
    first: Vec<T>,
    second: Vec<T>,
}

/// The first `len` samples of `buffer`, replaced by a larger one when too small (its contents
/// are scratch: a fresh zeroed allocation is `calloc`'s untouched pages, not a `memset`).
fn buffer<T: Sample>(buffer: &mut Vec<T>, len: usize) -> &mut [T] {
    if buffer.len() < len {
        *buffer = vec![T::zero(); len];
    }
    &mut buffer[..len]
}

impl<T: Sample> RotationWorkspace<T> {
    /// An empty workspace; it grows to the largest rotation it serves.
    pub fn new() -> Self {
        RotationWorkspace {
            first: Vec::new(),
            second: Vec::new(),
        }
    }

    /// [`rotate_plane`] through this workspace.
    ///
    /// ```
    /// use haarshift::kernels::ShiftMethod;
    /// use haarshift::rotate::{RotateOptions, RotationWorkspace};
    /// let k = ShiftMethod::Linear.kernel::<f64>();
    /// let p = ndarray::array![[1.0, 2.0], [3.0, 4.0]];
    /// let r = RotationWorkspace::new()
    ///     .rotate_plane(p.view(), -90.0, k.as_ref(), &RotateOptions::default())
    ///     .unwrap();
    /// assert_eq!(r, ndarray::array![[3.0, 1.0], [4.0, 2.0]]);
    /// ```
    pub fn rotate_plane(
        &mut self,
        plane: ArrayView2<'_, T>,
        deg: f64,
        kernel: &dyn ShearKernel<T>,
        options: &RotateOptions,
    ) -> Result<Array2<T>> {
        if options.supersample > 0 || kernel.grid_exponent() > 0 {
            return rotate_on_finer_grid(plane, deg, kernel, options);
        }
        let rotation = plan_on_pixels(plane, deg, kernel, options)?;
        let mut out = Array2::zeros(rotation.out);
        let slice = out.as_slice_mut().expect("new array");
        self.rotate_grid(plane, &rotation, kernel, options.outside, slice)?;
        Ok(out)
    }

    /// [`rotate_plane`] into `out`, which must have the size [`rotated_size`] gives.
    pub fn rotate_plane_into(
        &mut self,
        plane: ArrayView2<'_, T>,
        deg: f64,
        kernel: &dyn ShearKernel<T>,
        options: &RotateOptions,
        mut out: ndarray::ArrayViewMut2<'_, T>,
    ) -> Result<()> {
        let expected = rotated_size(plane.nrows(), plane.ncols(), deg, options)?;
        if out.dim() != expected {
            return Err(Error::shape(
                &[out.nrows(), out.ncols()],
                format!("the rotated image is {}x{}", expected.0, expected.1),
            ));
        }
        if options.supersample > 0 || kernel.grid_exponent() > 0 || !out.is_standard_layout() {
            out.assign(&self.rotate_plane(plane, deg, kernel, options)?);
            return Ok(());
        }
        let rotation = plan_on_pixels(plane, deg, kernel, options)?;
        let slice = out.as_slice_mut().expect("standard layout");
        self.rotate_grid(plane, &rotation, kernel, options.outside, slice)
    }

    /// Rotates the working-grid array `a` as `rotation` says into `out` (row-major, of the
    /// rotation's output size).
    fn rotate_grid(
        &mut self,
        a: ArrayView2<'_, T>,
        rotation: &GridRotation,
        kernel: &dyn ShearKernel<T>,
        outside: Outside,
        out: &mut [T],
    ) -> Result<()> {
        let a1 = match rotation.quarter_turns {
            0 => CowArray::from(a),
            q => CowArray::from(quarter_turn(a, q)),
        };
        let Some(shears) = &rotation.shears else {
            out.copy_from_slice(a1.as_standard_layout().as_slice().expect("standard layout"));
            return Ok(());
        };
        let (out_h, out_w) = rotation.out;
        let (a2, outside) = match outside {
            Outside::Boundary(mode) if mode != BoundaryMode::Zero => (
                CowArray::from(pad_with_mode(a1.view(), shears.pad.0, shears.pad.1, mode)),
                outside,
            ),
            Outside::Boundary(_) => (a1, Outside::Fill(0.0)),
            fill => (a1, fill),
        };
        let (h_a, w_a) = a2.dim();
        let (cx_a, cy_a) = ((w_a as f64 - 1.0) / 2.0, (h_a as f64 - 1.0) / 2.0);
        let (cx_out, cy_out) = ((out_w as f64 - 1.0) / 2.0, (out_h as f64 - 1.0) / 2.0);
        let ShearGeometry {
            a_x,
            s_y,
            w_b,
            margin,
            ..
        } = *shears;
        let ox = cx_a + margin;

        // x-shear: row r (y = cy_a - r) of A moves by a_x y; stored transposed (w_b x h_a).
        let shifts: Vec<f64> = (0..h_a).map(|r| margin + a_x * (cy_a - r as f64)).collect();
        let b1t = buffer(&mut self.first, w_b * h_a);
        shear_pass_into(a2.view(), w_b, &shifts, kernel, outside, true, b1t)?;
        let b1t = ArrayView2::from_shape((w_b, h_a), &*b1t).expect("sized");
        // y-shear: column c (x = c - ox) moves up by s_y x, i.e. by -s_y x in row index, onto
        // the output's rows; stored transposed back (out_h x w_b).
        let shifts: Vec<f64> = (0..w_b)
            .map(|c| (cy_out - cy_a) - s_y * (c as f64 - ox))
            .collect();
        let b2 = buffer(&mut self.second, out_h * w_b);
        shear_pass_into(b1t, out_h, &shifts, kernel, outside, true, b2)?;
        let b2 = ArrayView2::from_shape((out_h, w_b), &*b2).expect("sized");
        // x-shear again: row r (y = cy_out - r) onto the output's columns.
        let shifts: Vec<f64> = (0..out_h)
            .map(|r| (cx_out - ox) + a_x * (cy_out - r as f64))
            .collect();
        shear_pass_into(b2, out_w, &shifts, kernel, outside, false, out)
    }
}

/// Checks `plane` and `options` and plans its rotation on the pixel grid.
fn plan_on_pixels<T: Sample>(
    plane: ArrayView2<'_, T>,
    deg: f64,
    kernel: &dyn ShearKernel<T>,
    options: &RotateOptions,
) -> Result<GridRotation> {
    validate_plane(plane, options)?;
    GridRotation::new::<T>(plane.dim(), deg, 1, kernel.support_radius(), options)
}

/// One rotation on the `2^(supersample + grid exponent)`-finer grid, box-averaged back.
fn rotate_on_finer_grid<T: Sample>(
    plane: ArrayView2<'_, T>,
    deg: f64,
    kernel: &dyn ShearKernel<T>,
    options: &RotateOptions,
) -> Result<Array2<T>> {
    let mut chain = RotationChain::new(plane, kernel, *options)?;
    chain.rotate(deg)?;
    Ok(chain.finish())
}

/// The size `(rows, cols)` of `h x w` image rotated by `deg` with `options`: the input's for
/// [`Canvas::Same`], [`expanded_size`] for [`Canvas::Expand`].
///
/// ```
/// use haarshift::rotate::{Canvas, RotateOptions, rotated_size};
/// let expand = RotateOptions { canvas: Canvas::Expand, ..Default::default() };
/// assert_eq!(rotated_size(30, 50, 90.0, &expand).unwrap(), (50, 30));
/// assert_eq!(rotated_size(30, 50, 90.0, &RotateOptions::default()).unwrap(), (30, 50));
/// ```
pub fn rotated_size(
    h: usize,
    w: usize,
    deg: f64,
    options: &RotateOptions,
) -> Result<(usize, usize)> {
    Ok(match options.canvas {
        Canvas::Same => {
            reduce_angle(deg)?;
            (h, w)
        }
        Canvas::Expand => expanded_size(h, w, deg)?,
    })
}

/// Rotates one plane by `deg` degrees (counter-clockwise as displayed) with `kernel`.
///
/// ```
/// use haarshift::kernels::ShiftMethod;
/// use haarshift::rotate::{Canvas, RotateOptions, rotate_plane};
/// use ndarray::Array2;
/// let p = Array2::<f32>::ones((20, 30));
/// let k = ShiftMethod::Keys.kernel::<f32>();
/// let opts = RotateOptions { canvas: Canvas::Expand, ..Default::default() };
/// let r = rotate_plane(p.view(), 30.0, k.as_ref(), &opts).unwrap();
/// assert_eq!(r.dim(), (32, 36));
/// assert!((r[[16, 18]] - 1.0).abs() < 1e-6);
/// ```
pub fn rotate_plane<T: Sample>(
    plane: ArrayView2<'_, T>,
    deg: f64,
    kernel: &dyn ShearKernel<T>,
    options: &RotateOptions,
) -> Result<Array2<T>> {
    RotationWorkspace::new().rotate_plane(plane, deg, kernel, options)
}

/// Below this alpha (as a fraction of opaque) a rotated pixel counts as fully transparent and
/// takes the fill colour instead of an unstable `colour / alpha`.
const TRANSPARENT: f64 = 1e-6;

/// Rotates every plane of `image`.
///
/// With alpha, colour is premultiplied by alpha before rotating and divided by the rotated
/// alpha after, so colour from transparent pixels does not bleed into opaque ones; outside the
/// image alpha is 0 (with a fill value) and pixels whose rotated alpha is below `1e-6` of
/// opaque get the fill value as colour (0 with a boundary mode). Integer depths (8, 16 bit)
/// are rounded to the nearest code value and clamped to their range; float depths are
/// returned as computed.
///
/// ```
/// use haarshift::{PlanarImage, SampleDepth};
/// use haarshift::kernels::ShiftMethod;
/// use haarshift::rotate::{Canvas, RotateOptions, rotate_image};
/// use ndarray::Array2;
/// let img = PlanarImage::from_gray(Array2::from_elem((9, 9), 200.0f32), SampleDepth::U8).unwrap();
/// let k = ShiftMethod::Lanczos3.kernel::<f32>();
/// let opts = RotateOptions { canvas: Canvas::Expand, ..Default::default() };
/// let r = rotate_image(&img, 30.0, k.as_ref(), &opts).unwrap();
/// assert_eq!(r.plane(0)[[6, 6]], 200.0);
/// assert_eq!(r.plane(0)[[0, 0]], 0.0);
/// ```
pub fn rotate_image<T: Sample>(
    image: &PlanarImage<T>,
    deg: f64,
    kernel: &dyn ShearKernel<T>,
    options: &RotateOptions,
) -> Result<PlanarImage<T>> {
    let depth = image.depth();
    let opaque = depth.integer_max().unwrap_or(1.0);
    let count = image.channels().count();
    let alpha_plane = count - 1;
    let (h, w) = rotated_size(image.height(), image.width(), deg, options)?;
    check_budget::<T>(
        "the rotated image",
        (count * h * w) as u128,
        options.memory_budget,
    )?;
    // Every plane is rotated straight into its place in the output; the intermediates are
    // shared by all planes.
    let mut out = ndarray::Array3::<T>::zeros((count, h, w));
    let mut workspace = RotationWorkspace::new();
    match image.alpha() {
        None => {
            for (p, o) in image.planes().outer_iter().zip(out.outer_iter_mut()) {
                workspace.rotate_plane_into(p, deg, kernel, options, o)?;
            }
        }
        Some(_) if is_pure_copy(image.height(), image.width(), deg, options.canvas)? => {
            // Nothing is interpolated: copy colour as it is (even under alpha 0), with a
            // transparent outside.
            let transparent = RotateOptions {
                outside: Outside::Fill(0.0),
                ..*options
            };
            for (c, (p, o)) in image
                .planes()
                .outer_iter()
                .zip(out.outer_iter_mut())
                .enumerate()
            {
                let opts = if c == alpha_plane {
                    &transparent
                } else {
                    options
                };
                workspace.rotate_plane_into(p, deg, kernel, opts, o)?;
            }
        }
        Some(alpha) => {
            let fill = match options.outside.validate()? {
                Outside::Fill(v) => v,
                Outside::Boundary(_) => 0.0,
            };
            let premultiplied_outside = match options.outside {
                Outside::Fill(_) => Outside::Fill(0.0),
                mode => mode,
            };
            let scale = T::from_f64(1.0 / opaque);
            let opts = RotateOptions {
                outside: premultiplied_outside,
                ..*options
            };
            let (mut colours, mut new_alpha) = out.view_mut().split_at(Axis(0), alpha_plane);
            let mut new_alpha = new_alpha.index_axis_mut(Axis(0), 0);
            workspace.rotate_plane_into(alpha, deg, kernel, &opts, new_alpha.view_mut())?;
            let mut premultiplied = Array2::<T>::zeros(alpha.dim());
            let threshold = T::from_f64(TRANSPARENT * opaque);
            let (fill, opaque_t) = (T::from_f64(fill), T::from_f64(opaque));
            for (p, mut o) in image
                .color_planes()
                .outer_iter()
                .zip(colours.outer_iter_mut())
            {
                ndarray::Zip::from(&mut premultiplied)
                    .and(p)
                    .and(alpha)
                    .par_for_each(|m, &v, &a| *m = v * a * scale);
                workspace.rotate_plane_into(
                    premultiplied.view(),
                    deg,
                    kernel,
                    &opts,
                    o.view_mut(),
                )?;
                ndarray::Zip::from(o).and(&new_alpha).par_for_each(|v, &a| {
                    *v = if a > threshold {
                        *v * opaque_t / a
                    } else {
                        fill
                    };
                });
            }
        }
    }
    if let Some(max) = depth.integer_max() {
        out.par_mapv_inplace(|v| round_to_code(v, max));
    }
    PlanarImage::new(out, image.channels(), depth)
}

#[cfg(test)]
mod tests;
