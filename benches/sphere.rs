//! Sphere rotation on a 1024 x 512 RGB map (the rooitou park test map, upsampled from
//! 256 x 128 by pixel repetition), each method at full depth and from two levels coarser.
//! Run briefly: `cargo bench --bench sphere -- --warm-up-time 1 --measurement-time 3`.

use criterion::{BenchmarkId, Criterion, criterion_group, criterion_main};
use haarshift::sphere::{
    LatLongMap, Method, SphereCoefficients, SphereOptions, SphereRotation, rotate_coefficients,
    rotate_map,
};
use ndarray::Array3;

fn map_1024() -> LatLongMap<f32> {
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/testdata/envmaps/rooitou_park_256x128.npy"
    );
    let small: Array3<f32> = ndarray_npy::read_npy(path).expect("test map");
    let big = Array3::from_shape_fn((512, 1024, 3), |(i, j, c)| small[[i / 4, j / 4, c]]);
    LatLongMap::new(big).expect("a 2:1 map")
}

/// "full" or the level number, for benchmark names.
fn level_name(level: Option<usize>) -> String {
    level.map_or("full".into(), |l| l.to_string())
}

fn bench(c: &mut Criterion) {
    let map = map_1024();
    let coeffs = SphereCoefficients::from_map(&map).expect("power of two");
    let rotation = SphereRotation::from_degrees(40.0, -25.0, 60.0).expect("angles");
    let mut group = c.benchmark_group("sphere_1024x512_rgb");
    group.sample_size(10);
    for method in [
        Method::Reference,
        Method::Bilinear,
        Method::Bicubic,
        Method::Haar,
    ] {
        for level in [None, Some(6)] {
            let options = SphereOptions {
                method,
                level,
                ..Default::default()
            };
            let name = format!("{method}/level-{}", level_name(level));
            group.bench_function(BenchmarkId::new("rotate_map", &name), |b| {
                b.iter(|| rotate_map(&map, &rotation, &options).expect("rotates"))
            });
        }
    }
    for level in [None, Some(6), Some(4)] {
        let options = SphereOptions {
            level,
            ..Default::default()
        };
        let name = format!("haar/level-{}", level_name(level));
        group.bench_function(BenchmarkId::new("rotate_coefficients", &name), |b| {
            b.iter(|| rotate_coefficients(&coeffs, &rotation, &options).expect("rotates"))
        });
    }
    let yaw = SphereRotation::from_degrees(90.0, 0.0, 0.0).expect("angles");
    let options = SphereOptions::default();
    group.bench_function("rotate_coefficients/haar/exact-yaw-256-columns", |b| {
        b.iter(|| rotate_coefficients(&coeffs, &yaw, &options).expect("rotates"))
    });
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
