//! The frame's image half at 640 x 480, as `relight render` and `relight animate` time it
//! ("rasterisation"): [`ViewSpec::draw`] of the bunny with its ground plane
//! (`testdata/meshes/bunny.ply`, 5,722 triangles, the framing camera, as
//! `relight precompute --ground-plane` builds it) and of Vollick and Lessig's cubes scene
//! (`testdata/scenes/cubes.json`, its own camera), the environment behind
//! (`rooitou_park_256x128.npy`, and the 1024 x 512 `rooitou_park_1k.hdr`), turned by a yaw of
//! whole columns (an animation's frame) or by a general rotation (yaw 30, pitch 20), as one
//! frame on its own (`relight render`) and as an animation's later frame (`next_frame`:
//! [`Frames`] keeping what its first frame prepared); and the triangles alone in front of a
//! colour. The radiance is a smooth function of position (the
//! rasteriser's cost does not depend on it).
//!
//! Run: `cargo bench -p haarshift-relight --bench raster -- --warm-up-time 1 --measurement-time 5`; the figures
//! against the previous rasteriser are in `results/render/raster_speed.md`.

use criterion::{Criterion, criterion_group, criterion_main};
use std::path::Path;

use haarshift::io::read_image;
use haarshift::sphere::{LatLongMap, SphereRotation};
use haarshift_relight::light::environment::Environment;
use haarshift_relight::render::view::{Backdrop, Frames, ViewSpec};
use haarshift_relight::{Mesh, Scene};
use ndarray::{Array2, Array3};

fn data(path: &str) -> std::path::PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join(path)
}

/// A scene's mesh and camera (`ground_plane`: added under a mesh file, as the CLI does).
fn scene(path: &str, ground_plane: bool) -> (Mesh, Option<haarshift_relight::CameraSpec>) {
    let mut scene = Scene::load(&data(path)).expect("the scene");
    if ground_plane {
        scene.add_ground_plane().expect("a ground plane");
    }
    (scene.mesh, scene.camera)
}

/// The 256 x 128 map of the speed scripts and the 1024 x 512 one, as lat-long maps.
fn environments() -> [(&'static str, Environment); 2] {
    let small: Array3<f32> =
        ndarray_npy::read_npy(data("../testdata/envmaps/rooitou_park_256x128.npy")).expect("map");
    let big = read_image::<f64>(data("../testdata/envmaps/rooitou_park_1k.hdr")).expect("map");
    let big = big.planes().view().permuted_axes([1, 2, 0]).to_owned();
    [
        (
            "env_256x128",
            Environment::new(LatLongMap::new(small.mapv(f64::from)).expect("2:1")),
        ),
        (
            "env_1024x512",
            Environment::new(LatLongMap::new(big).expect("2:1")),
        ),
    ]
}

fn bench(c: &mut Criterion) {
    let scenes = [
        ("bunny_5722", scene("../testdata/meshes/bunny.ply", true)),
        ("cubes", scene("../testdata/scenes/cubes.json", false)),
    ];
    let environments = environments();
    let yaw = SphereRotation::from_degrees(45.0, 0.0, 0.0).expect("rotation");
    let turned = SphereRotation::from_degrees(30.0, 20.0, 0.0).expect("rotation");
    let mut group = c.benchmark_group("raster_640x480");
    group.sample_size(10);
    for (name, (mesh, camera_spec)) in &scenes {
        let view = ViewSpec::default();
        let camera = view.camera(camera_spec.as_ref(), mesh).expect("camera");
        let b = mesh.bounds();
        let radiance = Array2::from_shape_fn((mesh.vertex_count(), 3), |(v, c)| {
            let t = (mesh.positions()[[v, c]] - b.min[c]) / (b.max[c] - b.min[c]).max(1e-9);
            (0.2 + 0.6 * t) as f32
        });
        let name = format!("{name}_{}_triangles", mesh.triangles().len());
        for (env_name, env) in &environments {
            for (turn_name, rotation) in [("yaw_45", &yaw), ("yaw_30_pitch_20", &turned)] {
                group.bench_function(format!("{name}/{env_name}/{turn_name}"), |bench| {
                    bench.iter(|| {
                        view.draw(&camera, mesh, radiance.view(), env, rotation)
                            .expect("draws")
                    })
                });
                // An animation's later frame: what the first prepared, kept.
                let mut frames = Frames::new(view);
                frames
                    .draw(&camera, mesh, radiance.view(), env, rotation)
                    .expect("draws");
                group.bench_function(
                    format!("{name}/{env_name}/{turn_name}/next_frame"),
                    |bench| {
                        bench.iter(|| {
                            frames
                                .draw(&camera, mesh, radiance.view(), env, rotation)
                                .expect("draws")
                        })
                    },
                );
            }
        }
        let colour = ViewSpec {
            backdrop: Backdrop::Colour([0.1, 0.2, 0.3]),
            ..view
        };
        let env = &environments[0].1;
        group.bench_function(format!("{name}/colour"), |bench| {
            bench.iter(|| {
                colour
                    .draw(&camera, mesh, radiance.view(), env, &yaw)
                    .expect("draws")
            })
        });
    }
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
