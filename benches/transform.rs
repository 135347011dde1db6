//! Forward and inverse 2D pyramid transforms (f32, full depth) against a plain copy of the
//! same array: the transform is memory-bound, so the copy is the floor it is measured against.
//! `benches/compare_pywavelets.py` runs this and PyWavelets in one go and prints the ratios.

use criterion::{BenchmarkId, Criterion, Throughput, criterion_group, criterion_main};
use haarshift::transform::{Normalization, pyramid};
use ndarray::Array2;

fn image(n: usize) -> Array2<f32> {
    Array2::from_shape_fn((n, n), |(i, j)| ((i * 31 + j * 17) % 255) as f32)
}

fn bench_pyramid(c: &mut Criterion) {
    let mut group = c.benchmark_group("pyramid");
    for n in [512usize, 2048] {
        let input = image(n);
        let levels = pyramid::max_levels(n, n);
        let mut out = Array2::<f32>::zeros((n, n));
        let mut work = Vec::new();
        group.throughput(Throughput::Bytes((n * n * 4) as u64));
        group.bench_function(BenchmarkId::new("copy", n), |b| {
            b.iter(|| out.assign(&input));
        });
        group.bench_function(BenchmarkId::new("forward", n), |b| {
            b.iter(|| {
                pyramid::forward_into(
                    input.view(),
                    levels,
                    Normalization::Average,
                    out.view_mut(),
                    &mut work,
                )
                .unwrap()
            });
        });
        let coeffs = pyramid::forward(input.view(), levels, Normalization::Average).unwrap();
        group.bench_function(BenchmarkId::new("inverse", n), |b| {
            b.iter(|| {
                pyramid::inverse_into(
                    coeffs.view(),
                    levels,
                    Normalization::Average,
                    out.view_mut(),
                    &mut work,
                )
                .unwrap()
            });
        });
    }
    group.finish();
}

criterion_group!(benches, bench_pyramid);
criterion_main!(benches);
