//! Relighting's image half: the rasteriser on a 512 x 512 image of a 100,352-triangle sphere
//! (all threads, and one thread for the ratio), the solid-angle-weighted downsample of a
//! 512 x 1024 map to 128 x 256 beside the plain block mean, and the projection of a
//! 128 x 256 RGB map onto 9 bands (81) of spherical harmonics.
//! Run: `cargo bench --bench relight -- --warm-up-time 1 --measurement-time 5`.

use criterion::{Criterion, criterion_group, criterion_main};
use haarshift::relight::environment::downsample_solid_angle;
use haarshift::relight::raster::{Background, Camera, DEFAULT_FOV, Mesh, render};
use haarshift::sphere::LatLongMap;
use haarshift::sphere::harmonics::SphericalHarmonics;
use haarshift::sphere::latlong::direction;
use haarshift::sphere::param::SphereMap;
use ndarray::{Array2, Array3};

/// A UV sphere of radius 1 with `n x 2n` quads (`4 n^2` triangles) and a smooth radiance.
fn sphere(n: usize) -> (Array2<f64>, Vec<[u32; 3]>, Array2<f32>) {
    let (rows, cols) = (n + 1, 2 * n + 1);
    let positions = Array2::from_shape_fn((rows * cols, 3), |(k, c)| {
        let (i, j) = (k / cols, k % cols);
        let d = direction(
            std::f64::consts::PI * i as f64 / n as f64,
            std::f64::consts::PI * j as f64 / n as f64,
        );
        d[c]
    });
    let mut tris = Vec::with_capacity(4 * n * n);
    for i in 0..n {
        for j in 0..2 * n {
            let k = (i * cols + j) as u32;
            let c = cols as u32;
            tris.push([k, k + 1, k + c + 1]);
            tris.push([k, k + c + 1, k + c]);
        }
    }
    let radiance = Array2::from_shape_fn((rows * cols, 3), |(k, c)| {
        (0.5 + 0.4 * positions[[k, c]]) as f32
    });
    (positions, tris, radiance)
}

fn map_512() -> LatLongMap<f64> {
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/testdata/envmaps/rooitou_park_256x128.npy"
    );
    let small: Array3<f32> = ndarray_npy::read_npy(path).expect("test map");
    let big = Array3::from_shape_fn((512, 1024, 3), |(i, j, c)| {
        f64::from(small[[i / 4, j / 4, c]])
    });
    LatLongMap::new(big).expect("a 2:1 map")
}

fn bench(c: &mut Criterion) {
    let (positions, triangles, radiance) = sphere(158);
    let mesh = Mesh {
        positions: positions.view(),
        triangles: &triangles,
        radiance: radiance.view(),
    };
    let camera = Camera::framing([-1.0; 3], [1.0; 3], DEFAULT_FOV).expect("camera");
    let env = map_512();
    let mut group = c.benchmark_group("relight");
    group.sample_size(10);
    let name = format!("raster_512x512_{}_triangles", triangles.len());
    group.bench_function(format!("{name}/all_threads"), |b| {
        b.iter(|| render(&camera, 512, 512, &mesh, Background::Environment(&env)).expect("renders"))
    });
    let one = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .expect("pool");
    group.bench_function(format!("{name}/one_thread"), |b| {
        b.iter(|| {
            one.install(|| {
                render(&camera, 512, 512, &mesh, Background::Environment(&env)).expect("renders")
            })
        })
    });
    group.bench_function("downsample_512x1024_to_128x256/solid_angle", |b| {
        b.iter(|| downsample_solid_angle(&env, 128).expect("downsamples"))
    });
    group.bench_function("downsample_512x1024_to_128x256/plain_mean", |b| {
        b.iter(|| env.downsample(4).expect("downsamples"))
    });
    let working =
        SphereMap::from_lat_long(&downsample_solid_angle(&env, 128).expect("map")).expect("faces");
    let sh = SphericalHarmonics::new(9).expect("bands");
    group.bench_function("sh_project_128x256_rgb_9_bands", |b| {
        b.iter(|| sh.project(&working))
    });
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
