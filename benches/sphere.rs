//! Sphere rotation on a 1024 x 512 RGB map (the rooitou park test map, upsampled from
//! 256 x 128 by pixel repetition), each method at full depth and from two levels coarser;
//! and one rotation of a small one-channel Phong lobe (`lobe_one_channel`), the unit of work
//! of a renderer that turns a BRDF into each vertex's frame.
//! Run briefly: `cargo bench --bench sphere -- --warm-up-time 1 --measurement-time 3`
//! (`-- lobe_one_channel` for the lobe only).

use criterion::{BenchmarkId, Criterion, criterion_group, criterion_main};
use haarshift::sphere::chain_rule::{Rotator, Scheme};
use haarshift::sphere::lobes::phong;
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

/// A Phong lobe of exponent 50 about +Y on an `h`-row map, one channel.
fn lobe<T: haarshift::Sample>(h: usize) -> LatLongMap<T> {
    LatLongMap::from_fn(h, 1, |d, out| {
        out[0] = T::from_f64(phong(50.0, [0.0, 1.0, 0.0], d))
    })
    .expect("a map")
}

/// One rotation of a one-channel lobe: what a renderer pays per vertex. 64 x 128 in f32 and
/// f64 for each method, against `direct` (writing the 8192 texels of the analytic lobe), by
/// a prepared [`Rotator`], and the share of its steps 4-6 (`pyramid_of_fields`: the pyramid
/// from a map's difference fields); levels 3 to 6 of a 128 x 256 map (the thesis's levels 4
/// to 7), prepared and not.
fn bench_lobe(c: &mut Criterion) {
    let rotation = SphereRotation::from_degrees(40.0, -25.0, 60.0).expect("angles");
    let axis = rotation.inverse().apply([0.0, 1.0, 0.0]);
    let mut group = c.benchmark_group("lobe_one_channel");
    group.bench_function("64x128/direct/f32", |b| {
        b.iter(|| lobe_about::<f32>(64, axis))
    });
    one_rotation::<f32>(&mut group, "f32", &rotation);
    one_rotation::<f64>(&mut group, "f64", &rotation);
    let map = lobe::<f32>(128);
    let coeffs = SphereCoefficients::from_map(&map).expect("power of two");
    for method in [Method::Haar, Method::HaarCubic] {
        for level in [3, 4, 5, 6] {
            // What the renderer pays: the level's approximation prepared once, then rotated.
            let scheme = method.scheme().expect("a Haar method");
            let source = map
                .downsample(128 >> (level + 1))
                .expect("a level of the map");
            let rotator = Rotator::new(&source, scheme).expect("a power of two");
            let name = format!("128x256/{method}/level-{level}/f32");
            group.bench_function(BenchmarkId::new("rotator", &name), |b| {
                b.iter(|| rotator.rotate(&rotation).expect("rotates"))
            });
            let options = SphereOptions {
                method,
                level: Some(level),
                ..Default::default()
            };
            group.bench_function(BenchmarkId::new("rotate_coefficients", name), |b| {
                b.iter(|| rotate_coefficients(&coeffs, &rotation, &options).expect("rotates"))
            });
        }
    }
    group.finish();
}

/// The lobe about `axis` written texel by texel (the `direct` baseline).
fn lobe_about<T: haarshift::Sample>(h: usize, axis: [f64; 3]) -> LatLongMap<T> {
    LatLongMap::from_fn(h, 1, |d, out| out[0] = T::from_f64(phong(50.0, axis, d))).expect("a map")
}

/// The 64 x 128 rotations in precision `T`.
fn one_rotation<T: haarshift::Sample>(
    group: &mut criterion::BenchmarkGroup<'_, criterion::measurement::WallTime>,
    precision: &str,
    rotation: &SphereRotation,
) {
    let map = lobe::<T>(64);
    let coeffs = SphereCoefficients::from_map(&map).expect("power of two");
    for method in [
        Method::Haar,
        Method::HaarCubic,
        Method::Bilinear,
        Method::Bicubic,
    ] {
        let options = SphereOptions {
            method,
            ..Default::default()
        };
        let name = format!("64x128/{method}/{precision}");
        group.bench_function(BenchmarkId::new("rotate_map", &name), |b| {
            b.iter(|| rotate_map(&map, rotation, &options).expect("rotates"))
        });
        group.bench_function(BenchmarkId::new("rotate_coefficients", &name), |b| {
            b.iter(|| rotate_coefficients(&coeffs, rotation, &options).expect("rotates"))
        });
    }
    // Steps 4-6 alone: the pyramid from a map's exact difference fields.
    let fields = haarshift::sphere::chain_rule::DifferenceFields::of_map(&map);
    group.bench_function(
        BenchmarkId::new("pyramid_of_fields", format!("64x128/{precision}")),
        |b| b.iter(|| fields.to_coefficients().expect("a pyramid")),
    );
    // The renderer's unit: the lobe prepared once, then one rotation into a vertex frame.
    for scheme in [Scheme::Linear, Scheme::Cubic] {
        let rotator = Rotator::new(&map, scheme).expect("a power of two");
        let name = format!("64x128/{scheme:?}/{precision}");
        group.bench_function(BenchmarkId::new("rotator", name), |b| {
            b.iter(|| rotator.rotate(rotation).expect("rotates"))
        });
    }
}

criterion_group!(benches, bench, bench_lobe);
criterion_main!(benches);
