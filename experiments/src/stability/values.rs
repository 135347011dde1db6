//! Values: images scaled over sixty decades and into the subnormals, constant images, a
//! single impulse, a Nyquist checkerboard, and non-finite inputs.

use ndarray::{Array2, ArrayView2};

use super::size::pixel_shift;
use super::{
    Category, Library, StabilityRecord, Subject, expect_error, kernels, max_abs_diff, measure, peak,
};
use haarshift::kernels::{KernelOptions, Outside, ShiftMethod};
use haarshift::rotate::{RotateOptions, rotate_plane};
use haarshift::shift::RetainedImage;
use haarshift::transform::{Band, TransformSpec, pyramid};
use haarshift::{BoundaryMode, Sample};
use haarshift::{Error, Result};

/// The scales of the scale checks: 1e-30 to 1e30 in steps of 1e10.
pub const SCALES: [f64; 7] = [1e-30, 1e-20, 1e-10, 1.0, 1e10, 1e20, 1e30];

/// The value checks on `image` (8-bit values, square), of `subject`'s kernels and shift.
pub fn checks(image: ArrayView2<'_, f64>, subject: &impl Subject) -> Vec<StabilityRecord> {
    let mut out = Vec::new();
    for scale in SCALES {
        out.push(scaled::<f64>(subject, image, scale));
        out.push(scaled::<f32>(subject, image, scale));
    }
    out.push(subnormal::<f32>(subject, image, 1e-40));
    out.push(subnormal::<f64>(subject, image, 1e-310));
    out.extend(constants(subject));
    out.extend(impulses(subject));
    out.extend(checkerboard(subject));
    out.extend(non_finite(subject));
    out
}

/// The compact Haar shift of the scale checks, and its precision.
const SCALE_SHIFT: (f64, f64, u32) = (0.3, -0.7, 3);

/// The three operations whose relative error must not depend on the scale: transform round
/// trip, compact Haar shift by (0.3, -0.7) at h = 3, Keys rotation by 30 degrees, of
/// `subject`.
fn operations<T: Sample>(subject: &impl Subject, x: ArrayView2<'_, T>) -> Result<[Array2<T>; 3]> {
    let spec = TransformSpec::default();
    let c = spec.forward(x)?;
    let keys = subject.kernel::<T>(ShiftMethod::Keys, &KernelOptions::default())?;
    let (dx, dy, h) = SCALE_SHIFT;
    Ok([
        c.inverse()?,
        subject.shift_image(&c, dx, dy, h)?.inverse()?,
        rotate_plane(x, 30.0, keys.as_ref(), &RotateOptions::default())?,
    ])
}

/// The largest of the three operations' relative deviations at `scale` in `T`, each against
/// its right answer on the unscaled image in f64, times the scale: the image itself for the
/// round trip, the shift's definition in the pixel domain ([`pixel_shift`]) for the Haar
/// shift, and the library's Keys rotation for the rotation (which has no closed form, so at
/// scale 1 in f64 that part compares the library with itself; the other two never do). All
/// arithmetic of the comparison is in f64, relative to the scaled peak, so nothing squares
/// the values.
fn relative_errors<T: Sample>(
    subject: &impl Subject,
    image: ArrayView2<'_, f64>,
    scale: f64,
) -> Result<[f64; 3]> {
    let (dx, dy, h) = SCALE_SHIFT;
    let keys = Library.kernel::<f64>(ShiftMethod::Keys, &KernelOptions::default())?;
    let reference = [
        image.to_owned(),
        pixel_shift(image, (dx, dy), h)?,
        rotate_plane(image, 30.0, keys.as_ref(), &RotateOptions::default())?,
    ];
    let x = image.mapv(|v| T::from_f64(v * scale));
    let got = operations(subject, x.view())?;
    let mut errors = [0.0; 3];
    for ((e, g), r) in errors.iter_mut().zip(&got).zip(&reference) {
        let want = r.mapv(|v| v * scale);
        let g = g.mapv(|v| v.as_f64());
        *e = max_abs_diff(g.view(), want.view()) / (scale * peak(image));
    }
    Ok(errors)
}

/// Tolerance of the scale checks: 64 units of roundoff of `T`.
fn scale_tolerance<T: Sample>() -> f64 {
    64.0 * T::epsilon().as_f64()
}

fn scaled<T: Sample>(
    subject: &impl Subject,
    image: ArrayView2<'_, f64>,
    scale: f64,
) -> StabilityRecord {
    measure(
        Category::Values,
        format!("scale {scale:e} {}", T::NAME),
        scale_tolerance::<T>(),
        || {
            let [trip, shift, rotation] = relative_errors::<T>(subject, image, scale)?;
            Ok((
                trip.max(shift).max(rotation),
                format!(
                    "relative error: round trip {trip:.1e}, haar shift {shift:.1e}, \
                     keys rotation {rotation:.1e}"
                ),
            ))
        },
    )
    .with("scale", scale)
    .with("type", T::NAME)
}

/// Below the smallest normal number precision degrades gradually (subnormals keep a fixed
/// absolute spacing). The check: the absolute error stays within 64 subnormal spacings, i.e.
/// nothing flushes to zero or blows up; the relative error is reported.
fn subnormal<T: Sample>(
    subject: &impl Subject,
    image: ArrayView2<'_, f64>,
    scale: f64,
) -> StabilityRecord {
    let spacing = T::min_positive_value().as_f64() * T::epsilon().as_f64();
    measure(
        Category::Values,
        format!("subnormal {scale:e} {}", T::NAME),
        64.0,
        || {
            let [trip, shift, rotation] = relative_errors::<T>(subject, image, scale)?;
            let worst = trip.max(shift).max(rotation);
            let absolute = worst * (scale * peak(image));
            Ok((
                absolute / spacing,
                format!(
                    "error in subnormal spacings ({spacing:.1e}); relative: round trip \
                     {trip:.1e}, haar shift {shift:.1e}, keys rotation {rotation:.1e}"
                ),
            ))
        },
    )
    .with("scale", scale)
    .with("type", T::NAME)
}

/// A constant image stays constant under a 30-degree rotation with the edge boundary, for
/// every kernel (and both Haar modes): the weights of every kernel sum to one.
fn constants(subject: &impl Subject) -> Vec<StabilityRecord> {
    let value = 0.1;
    let c = Array2::from_elem((33, 33), value);
    let opts = RotateOptions {
        outside: Outside::Boundary(BoundaryMode::Edge),
        ..Default::default()
    };
    let retained = KernelOptions {
        precision: 2,
        retain: true,
        ..Default::default()
    };
    let all = ShiftMethod::ALL
        .iter()
        .map(|&m| (m.name().to_owned(), m, KernelOptions::default()))
        .chain([("haar-retained".to_owned(), ShiftMethod::Haar, retained)]);
    all.map(|(name, method, options)| {
        measure(Category::Values, "constant stays constant", 1e-12, || {
            let kernel = subject.kernel::<f64>(method, &options)?;
            let r = rotate_plane(c.view(), 30.0, kernel.as_ref(), &opts)?;
            Ok((
                max_abs_diff(r.view(), c.view()) / value,
                "rotate 30 deg, edge boundary: relative deviation from 0.1".into(),
            ))
        })
        .with("kernel", name)
    })
    .collect()
}

/// A unit impulse off the centre of a 129x129 image (at 7 pixels right and 5 up), rotated by
/// 30 degrees. The mass stays 1 where the kernel's reach stays inside the image (compact
/// kernels, and the cubic B-spline whose prefilter decays as `0.268^d`); the FFT kernel
/// spreads the impulse as a sinc whose `1/x` tails leave the image, about `1 / (pi d)` per
/// shear at distance `d` from the edge, so its tolerance is `3 / (pi d)` and its centroid is
/// not checked. The centroid lands where the rotation takes the impulse: exactly for kernels
/// that reproduce linear functions; compact Haar rounds each of the three shears' shifts to
/// `1/2^h`, which may move it by up to `3 / 2^(h+1)` pixels.
fn impulses(subject: &impl Subject) -> Vec<StabilityRecord> {
    let n = 129;
    let centre = (n / 2) as f64;
    let (right, up) = (7.0, 5.0);
    let edge_distance = centre - right;
    let mut x = Array2::zeros((n, n));
    x[[(centre - up) as usize, (centre + right) as usize]] = 1.0;
    let (sin, cos) = 30f64.to_radians().sin_cos();
    let (want_x, want_y) = (cos * right - sin * up, sin * right + cos * up);
    let kernels = match kernels::<f64>(subject) {
        Ok(kernels) => kernels,
        Err(e) => return vec![measure(Category::Values, "kernels", 0.0, || Err(e))],
    };
    let mut out = Vec::new();
    for (name, kernel) in kernels {
        let rotated = rotate_plane(x.view(), 30.0, kernel.as_ref(), &RotateOptions::default());
        let moments = rotated.as_ref().map(|r| {
            let (mut mass, mut mx, mut my) = (0.0, 0.0, 0.0);
            for ((i, j), &v) in r.indexed_iter() {
                mass += v;
                mx += (j as f64 - centre) * v;
                my += (centre - i as f64) * v;
            }
            (mass, mx / mass, my / mass)
        });
        let moments = moments.map_err(|e| e.to_string());
        let failed = |e: &String| Error::parameter("rotation", e.clone());
        let band_limited = name == "fft";
        let mass_tolerance = if band_limited {
            3.0 / (std::f64::consts::PI * edge_distance)
        } else {
            1e-12
        };
        out.push(
            measure(
                Category::Values,
                "impulse keeps its mass",
                mass_tolerance,
                || {
                    let (mass, _, _) = moments.as_ref().map_err(failed)?;
                    Ok((
                        (mass - 1.0).abs(),
                        "|sum of the rotated impulse - 1|".into(),
                    ))
                },
            )
            .with("kernel", name.as_str()),
        );
        if band_limited {
            continue;
        }
        let tolerance = if name.starts_with("haar") {
            3.0 / 16.0
        } else {
            1e-9
        };
        out.push(
            measure(
                Category::Values,
                "impulse centroid rotates",
                tolerance,
                || {
                    let &(_, cx, cy) = moments.as_ref().map_err(failed)?;
                    Ok((
                        (cx - want_x).hypot(cy - want_y),
                        format!("centroid vs the rotated position ({want_x:.4}, {want_y:.4}), px"),
                    ))
                },
            )
            .with("kernel", name.as_str()),
        );
    }
    out
}

/// The Nyquist checkerboard `(-1)^(i+j)`: its transform is the finest diagonal band alone, a
/// whole Haar shift by one pixel negates it, and a half-pixel compact shift averages it to 0.
fn checkerboard(subject: &impl Subject) -> Vec<StabilityRecord> {
    let n = 64;
    let x = Array2::from_shape_fn((n, n), |(i, j)| if (i + j) % 2 == 0 { 1.0 } else { -1.0 });
    let spec = TransformSpec::default();
    let levels = pyramid::max_levels(n, n);
    vec![
        measure(
            Category::Values,
            "checkerboard: finest diagonal only",
            0.0,
            || {
                let c = spec.forward(x.view())?;
                let mut rest = c.as_array().to_owned();
                rest.slice_mut(ndarray::s![n / 2.., n / 2..]).fill(0.0);
                let diagonal = c.band(Band::Diagonal, levels - 1)?;
                let off = diagonal
                    .iter()
                    .fold(0.0f64, |m, &v: &f64| m.max((v - 1.0).abs()));
                Ok((
                    peak(rest.view()).max(off),
                    "every coefficient but the finest diagonal (all 1) is 0".into(),
                ))
            },
        ),
        measure(
            Category::Values,
            "checkerboard: shift by 1 negates",
            0.0,
            || {
                let c = spec.forward(x.view())?;
                let y = subject.shift_image(&c, 1.0, 0.0, 0)?.inverse()?;
                Ok((
                    max_abs_diff(y.view(), x.mapv(|v| -v).view()),
                    "max |shifted + x|".into(),
                ))
            },
        ),
        measure(
            Category::Values,
            "checkerboard: half-pixel shift is 0",
            0.0,
            || {
                let c = spec.forward(x.view())?;
                let y = subject.shift_image(&c, 0.5, 0.0, 1)?.inverse()?;
                Ok((
                    peak(y.view()),
                    "max |shifted|: linear interpolation halfway".into(),
                ))
            },
        ),
    ]
}

/// Non-finite inputs and parameters: typed errors, never a result.
fn non_finite(subject: &impl Subject) -> Vec<StabilityRecord> {
    let mut x = Array2::from_elem((8, 8), 1.0);
    let spec = TransformSpec::default();
    let c = spec.forward(x.view()).expect("finite input");
    let keys = subject.kernel::<f64>(ShiftMethod::Keys, &KernelOptions::default());
    let keys = || {
        keys.as_ref()
            .map_err(|e| Error::parameter("kernel", e.to_string()))
    };
    let opts = RotateOptions::default();
    let non_finite = |e: &Error| matches!(e, Error::NonFinite { .. });
    let parameter = |e: &Error| matches!(e, Error::InvalidParameter { .. });
    let describe = |a: Array2<f64>| format!("returned a {}x{} array", a.nrows(), a.ncols());
    let mut out = Vec::new();
    for bad in [f64::NAN, f64::INFINITY] {
        x[[3, 4]] = bad;
        let xv = x.view();
        out.push(expect_error(
            Category::Values,
            format!("{bad} pixel: transform"),
            non_finite,
            || spec.forward(xv).map(|c| describe(c.as_array().to_owned())),
        ));
        out.push(expect_error(
            Category::Values,
            format!("{bad} pixel: rotate"),
            non_finite,
            || rotate_plane(xv, 30.0, keys()?.as_ref(), &opts).map(describe),
        ));
        out.push(expect_error(
            Category::Values,
            format!("{bad} shift"),
            parameter,
            || {
                subject
                    .shift_image(&c, bad, 0.0, 3)
                    .map(|c| describe(c.as_array().to_owned()))
            },
        ));
        out.push(expect_error(
            Category::Values,
            format!("{bad} shift: retained"),
            parameter,
            || {
                let mut r = RetainedImage::new(&c, 1)?;
                r.shift(0.0, bad).map(|_| "shifted".into())
            },
        ));
        out.push(expect_error(
            Category::Values,
            format!("{bad} angle"),
            parameter,
            || rotate_plane(c.as_array(), bad, keys()?.as_ref(), &opts).map(describe),
        ));
    }
    out
}

#[cfg(test)]
#[path = "values_tests.rs"]
mod tests;
