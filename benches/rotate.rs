//! Three-shear rotation of an f32 image by 30 degrees (same canvas, zero fill) with every
//! kernel, at 512^2 and 2048^2, through a reused `RotationWorkspace` into a reused output (as
//! the Python baselines write into a given `dst`/`output` array); `rotate_one_shot` is the
//! allocating `rotate_plane` for comparison. `benches/compare_rotation.py` runs this and the
//! Python baselines (OpenCV warpAffine, scipy.ndimage.rotate) and prints the ratios.

use criterion::{BenchmarkId, Criterion, Throughput, criterion_group, criterion_main};
use haarshift::kernels::ShiftMethod;
use haarshift::rotate::{RotateOptions, RotationWorkspace, rotate_plane};
use ndarray::Array2;

fn image(n: usize) -> Array2<f32> {
    Array2::from_shape_fn((n, n), |(r, c)| {
        let (x, y) = (c as f32 / n as f32, r as f32 / n as f32);
        (40.0 * x * y).sin() + 0.5 * (13.0 * x - 7.0 * y).cos()
    })
}

fn rotate(c: &mut Criterion) {
    let mut group = c.benchmark_group("rotate");
    let options = RotateOptions::default();
    for n in [512usize, 2048] {
        let img = image(n);
        group.throughput(Throughput::Elements((n * n) as u64));
        for &method in ShiftMethod::ALL {
            let kernel = method.kernel::<f32>();
            let mut workspace = RotationWorkspace::new();
            let mut out = Array2::zeros((n, n));
            group.bench_with_input(BenchmarkId::new(method.name(), n), &img, |b, img| {
                b.iter(|| {
                    workspace
                        .rotate_plane_into(
                            img.view(),
                            30.0,
                            kernel.as_ref(),
                            &options,
                            out.view_mut(),
                        )
                        .unwrap()
                })
            });
        }
    }
    group.finish();
    let mut group = c.benchmark_group("rotate_one_shot");
    let kernel = ShiftMethod::Keys.kernel::<f32>();
    for n in [512usize, 2048] {
        let img = image(n);
        group.throughput(Throughput::Elements((n * n) as u64));
        group.bench_with_input(BenchmarkId::new("keys", n), &img, |b, img| {
            b.iter(|| rotate_plane(img.view(), 30.0, kernel.as_ref(), &options).unwrap())
        });
    }
    group.finish();
}

criterion_group!(benches, rotate);
criterion_main!(benches);
