//! Haar-domain shifting at 2048^2 f32 against the round trip inverse -> pixel shift ->
//! forward (all three with preallocated buffers, the transforms and the shift parallel).
//!
//! `cargo bench --bench shift -- --warm-up-time 1 --measurement-time 3`

use std::hint::black_box;

use criterion::{Criterion, criterion_group, criterion_main};
use haarshift::shift::{GridShift, ShiftQuery2d, ShiftWorkspace, dense};
use haarshift::transform::{Band, Normalization, pyramid};
use ndarray::{Array2, ArrayView2, ArrayViewMut2};
use rayon::prelude::*;

const SIDE: usize = 2048;
const LEVELS: usize = 11;
const NORM: Normalization = Normalization::Average;
/// Odd along both axes: the worst case for a Haar-domain shift.
const DX: i64 = 37;
const DY: i64 = -91;

/// Periodic pixel shift `out[r][c] = src[r - dy][c - dx]`, rows in parallel.
fn roll(src: ArrayView2<'_, f32>, mut out: ArrayViewMut2<'_, f32>, dx: i64, dy: i64) {
    let (h, w) = src.dim();
    let (qy, qx) = (
        dy.rem_euclid(h as i64) as usize,
        dx.rem_euclid(w as i64) as usize,
    );
    let src = src.as_slice().expect("contiguous");
    let out = out.as_slice_mut().expect("contiguous");
    out.par_chunks_mut(w).enumerate().for_each(|(r, dst)| {
        let row = &src[((r + h - qy) % h) * w..][..w];
        dst[qx..].copy_from_slice(&row[..w - qx]);
        dst[..qx].copy_from_slice(&row[w - qx..]);
    });
}

fn bench(c: &mut Criterion) {
    let image = Array2::from_shape_fn((SIDE, SIDE), |(i, j)| ((i * 31 + j * 17) % 251) as f32);
    let coeffs = pyramid::forward(image.view(), LEVELS, NORM).unwrap();
    let (dx, dy) = (GridShift::whole(DX), GridShift::whole(DY));
    let mut group = c.benchmark_group("shift_2048_f32");

    let mut out = Array2::zeros((SIDE, SIDE));
    let mut work = ShiftWorkspace::default();
    group.bench_function("dense_haar_shift", |b| {
        b.iter(|| {
            dense::shift_pyramid_into(
                coeffs.view(),
                LEVELS,
                NORM,
                dx,
                dy,
                out.view_mut(),
                &mut work,
            )
            .unwrap();
            black_box(&out);
        })
    });

    let (fx, fy) = (
        GridShift::new(37.3, 3).unwrap(),
        GridShift::new(-91.6, 3).unwrap(),
    );
    group.bench_function("dense_haar_shift_fractional_h3", |b| {
        b.iter(|| {
            dense::shift_pyramid_into(
                coeffs.view(),
                LEVELS,
                NORM,
                fx,
                fy,
                out.view_mut(),
                &mut work,
            )
            .unwrap();
            black_box(&out);
        })
    });

    let mut pixels = Array2::zeros((SIDE, SIDE));
    let mut moved = Array2::zeros((SIDE, SIDE));
    let mut scratch = Vec::new();
    group.bench_function("round_trip", |b| {
        b.iter(|| {
            pyramid::inverse_into(coeffs.view(), LEVELS, NORM, pixels.view_mut(), &mut scratch)
                .unwrap();
            roll(pixels.view(), moved.view_mut(), DX, DY);
            pyramid::forward_into(moved.view(), LEVELS, NORM, out.view_mut(), &mut scratch)
                .unwrap();
            black_box(&out);
        })
    });

    group.bench_function("random_access_prepare", |b| {
        b.iter(|| black_box(ShiftQuery2d::new(coeffs.view(), LEVELS, NORM).unwrap()))
    });
    let query = ShiftQuery2d::new(coeffs.view(), LEVELS, NORM).unwrap();
    group.bench_function("random_access_one_coefficient", |b| {
        b.iter(|| {
            black_box(
                query
                    .coefficient(black_box(dx), black_box(dy), Band::Diagonal, 9, 300, 200)
                    .unwrap(),
            )
        })
    });
    group.bench_function("random_access_one_coefficient_fractional", |b| {
        b.iter(|| {
            black_box(
                query
                    .coefficient(black_box(fx), black_box(fy), Band::Diagonal, 9, 300, 200)
                    .unwrap(),
            )
        })
    });
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
