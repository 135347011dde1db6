//! Fractional and retained shifts computed in f32, against the pixel-domain definition in
//! f64 (periodic bilinear interpolation at the shift rounded to `1 / 2^h`, written here from
//! the module docs, not with the code under test), within a bound derived from f32's unit
//! roundoff.

use ndarray::Array2;

use super::{RetainedImage, shift_image};
use crate::transform::{Layout, TransformSpec};

/// Irregular values of magnitude up to 74 (not dyadic, so f32 rounds), held exactly in f32.
fn f32_image(h: usize, w: usize) -> Array2<f32> {
    Array2::from_shape_fn((h, w), |(i, j)| {
        ((i as u64 * 7919 + j as u64 * 104_729) % 1009) as f32 / 7.0 - 70.0
    })
}

/// `s` rounded to the `1 / 2^h` grid, ties up: `floor(s 2^h + 1/2) / 2^h`.
fn rounded(s: f64, h: u32) -> f64 {
    let scale = f64::from(1u32 << h);
    (s * scale + 0.5).floor() / scale
}

/// Periodic bilinear interpolation of `x` at `(r - dy, c - dx)`, in f64.
fn bilinear(x: &Array2<f64>, dx: f64, dy: f64) -> Array2<f64> {
    let (h, w) = x.dim();
    let at = |r: f64, c: f64| {
        x[[
            (r as i64).rem_euclid(h as i64) as usize,
            (c as i64).rem_euclid(w as i64) as usize,
        ]]
    };
    Array2::from_shape_fn((h, w), |(r, c)| {
        let (y, z) = (r as f64 - dy, c as f64 - dx);
        let (y0, z0) = (y.floor(), z.floor());
        let (a, b) = (y - y0, z - z0);
        (1.0 - a) * ((1.0 - b) * at(y0, z0) + b * at(y0, z0 + 1.0))
            + a * ((1.0 - b) * at(y0 + 1.0, z0) + b * at(y0 + 1.0, z0 + 1.0))
    })
}

/// The largest difference between an f32 result and the f64 definition.
fn error(got: &Array2<f32>, want: &Array2<f64>) -> f64 {
    assert_eq!(got.dim(), want.dim());
    got.iter()
        .zip(want)
        .map(|(&g, &w)| (f64::from(g) - w).abs())
        .fold(0.0, f64::max)
}

/// The rounding budget of an f32 shift of an `L`-level transform of values below `m`:
/// four transforms (forward, the shift's inverse and forward, the final inverse) of `L`
/// levels, each level at most 3 roundings (a sum of four) of values below `2m`, so at most
/// `4 * 3 * L` roundings of `u 2m` (`u = 2^-24`); the blend adds 2. A later inverse adds up
/// to `L + 1` coefficients into a pixel, so an error already present grows by at most
/// `L + 1`: in all at most `(L + 1) (12 L + 2) u 2m`.
fn f32_bound(levels: usize, m: f64) -> f64 {
    let l = levels as f64;
    (l + 1.0) * (12.0 * l + 2.0) * 2.0 * m * f64::from(f32::EPSILON) / 2.0
}

/// Compact fractional shifts in f32, pyramid and separable, positive and negative, several
/// precisions: the f64 bilinear interpolation at the rounded shift, within the f32 budget
/// (3.3e-3 pyramid, 4.6e-3 separable; measured at most 1.7e-5, the worst case of the
/// derivation being about 200x the typical one; a shift rounded to the wrong grid or a blend
/// with the wrong weight is off by more than 0.5).
#[test]
fn compact_fractional_shifts_in_f32_are_bilinear_within_the_rounding_budget() {
    let x = f32_image(32, 64);
    let x64 = x.mapv(f64::from);
    let m = x64.iter().fold(0.0f64, |a, v| a.max(v.abs()));
    let mut worst: f64 = 0.0;
    for layout in [Layout::Pyramid, Layout::Separable] {
        let spec = TransformSpec {
            layout,
            ..Default::default()
        };
        let c = spec.forward(x.view()).unwrap();
        let levels = *c.info().levels.iter().max().unwrap();
        for (dx, dy, h) in [
            (0.3, -0.7, 2u32),
            (-2.45, 1.1, 3),
            (5.5, 0.0, 1),
            (-0.126, 3.9, 5),
        ] {
            let got = shift_image(&c, dx, dy, h).unwrap().inverse().unwrap();
            let want = bilinear(&x64, rounded(dx, h), rounded(dy, h));
            let err = error(&got, &want);
            let bound = f32_bound(levels, m);
            assert!(
                err <= bound,
                "{layout:?} ({dx}, {dy}) h={h}: {err:e} > {bound:e}"
            );
            worst = worst.max(err);
        }
    }
    // f32 really was used (the bound is not vacuous for an f64 computation).
    assert!(worst > 0.0);
}

/// A retained chain in f32 whose steps sum to a fractional total: its projection is the f64
/// bilinear interpolation at the total (measured 1.1e-5), and its fine image is the
/// input's pixels as `2^h x 2^h` blocks moved by whole fine samples (measured 3.2e-5), to
/// the same budget (2.4e-2 for four steps of 8 levels).
#[test]
fn retained_f32_chains_project_to_bilinear_and_keep_whole_blocks() {
    let x = f32_image(16, 32);
    let x64 = x.mapv(f64::from);
    let m = x64.iter().fold(0.0f64, |a, v| a.max(v.abs()));
    let c = TransformSpec::default().forward(x.view()).unwrap();
    let levels = c.info().levels[0];
    let h = 3u32;
    let steps = [
        (0.375, -0.625),
        (1.125, 0.25),
        (-0.5, 2.875),
        (0.25, -0.125),
    ];
    let mut chain = RetainedImage::new(&c, h).unwrap();
    for &(dx, dy) in &steps {
        chain.shift(dx, dy).unwrap();
    }
    let (tx, ty) = (1.25, 2.375);
    assert_eq!(chain.offset(), (tx, ty));
    // Each retained shift recomputes the `L + h` levels once: one inverse and one forward per
    // step, all steps' errors adding up.
    let bound = steps.len() as f64 * f32_bound(levels + h as usize, m);
    let got = chain.project().inverse().unwrap();
    let err = error(&got, &bilinear(&x64, tx, ty));
    assert!(err <= bound, "projected: {err:e} > {bound:e}");
    // The fine image: pixel (r, c) of the 8x-finer grid holds x at the fine sample moved back
    // by (10, 19) fine samples, i.e. x[(r - 19) / 8][(c - 10) / 8] periodically.
    let fine = crate::transform::pyramid::inverse(
        chain.fine(),
        levels + h as usize,
        c.info().normalization,
    )
    .unwrap();
    let n = 1usize << h;
    let (fh, fw) = fine.dim();
    assert_eq!((fh, fw), (16 * n, 32 * n));
    let want = Array2::from_shape_fn((fh, fw), |(r, col)| {
        let rr = (r as i64 - 19).rem_euclid(fh as i64) as usize / n;
        let cc = (col as i64 - 10).rem_euclid(fw as i64) as usize / n;
        x64[[rr, cc]]
    });
    let err = error(&fine, &want);
    assert!(err <= bound, "fine: {err:e} > {bound:e}");
}
