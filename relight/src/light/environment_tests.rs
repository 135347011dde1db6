use super::*;
use crate::light::downsample::tests::{bright_pole, relative_energy_change};
use haarshift::io::{WriteOptions, write_image};
use haarshift::{Channels, PlanarImage, SampleDepth};
use ndarray::{Array2, Array3, Axis};
use std::f64::consts::PI;

#[test]
fn bad_resolutions_and_shapes_are_errors() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("square.npy");
    let planes = Array3::<f32>::ones((3, 4, 4));
    let image = PlanarImage::new(planes, Channels::Rgb, SampleDepth::F32).unwrap();
    write_image(&image, &path, WriteOptions::default()).unwrap();
    let err = Environment::load(&path).unwrap_err().to_string();
    assert!(err.starts_with(&path.display().to_string()), "{err}");
    assert!(err.contains("4 x 4"), "{err}");
    assert_err!(
        Environment::load(&dir.path().join("missing.hdr")),
        Io { .. },
        "missing.hdr"
    );
}

#[test]
fn a_run_length_encoded_radiance_file_loads() {
    // Values whose RGBE form is exact: a shared exponent and 8-bit mantissas.
    let planes = Array3::from_shape_fn((3, 8, 16), |(c, i, j)| {
        [3.0f32, 1.0, 0.5][c] * 2f32.powi((i as i32 + j as i32 % 3) - 4)
    });
    let image = PlanarImage::new(planes.clone(), Channels::Rgb, SampleDepth::F32).unwrap();
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("sky.hdr");
    write_image(&image, &path, WriteOptions::default()).unwrap();
    let bytes = std::fs::read(&path).unwrap();
    // A new-style run-length scanline starts 2, 2, then the width (16) in two bytes.
    assert!(bytes.windows(4).any(|w| w == [2, 2, 0, 16]), "not RLE");
    let env = Environment::load(&path).unwrap();
    let map = env.map().as_array();
    assert_eq!(map.dim(), (8, 16, 3));
    for ((c, i, j), &v) in planes.indexed_iter() {
        assert_eq!(map[[i, j, c]], f64::from(v), "({c}, {i}, {j})");
    }
}

#[test]
fn rotations_keep_constants_and_whole_column_yaws_are_exact() {
    let f = bright_pole(32, 2);
    let env = Environment::new(f.clone());
    let yaw = SphereRotation::from_degrees(-45.0, 0.0, 0.0).unwrap(); // -2 columns of 16
    let turned = env.lat_long(8, &yaw).unwrap();
    let want = downsample_solid_angle(&f, 8).unwrap().roll_columns(14);
    assert_eq!(turned, want);
    let one = Environment::new(LatLongMap::from_fn(32, 1, |_, o| o[0] = 3.0).unwrap());
    let tilt = SphereRotation::from_degrees(20.0, 35.0, -10.0).unwrap();
    for param in [
        Parameterization::new(ParamKind::LatLong, 8).unwrap(),
        Parameterization::new(ParamKind::Cube, 4).unwrap(),
    ] {
        let m = one.sphere_map(param, &tilt).unwrap();
        assert!(m.as_array().iter().all(|&v| (v - 3.0).abs() < 1e-12));
    }
    // A general rotation of a linear map: within O(source texel^2) of the exact means.
    let (env, exact) = linear_map_and_means(&tilt, 16);
    let worst = max_difference(&env.lat_long(16, &tilt).unwrap(), &exact);
    // The source holds centre samples, not texel means, and the rotation integrates their
    // bilinear interpolant: both are O(source texel^2) = O(6e-4).
    assert!(worst < 2e-3, "{worst}");
}

/// A linear map `f(p) = a . p + 2` 128 high, and the exact mean of `f(R p) = (R^T a) . p + 2`
/// over each texel of the `n x 2n` grid, from the closed-form texel mean of `p`.
fn linear_map_and_means(rotation: &SphereRotation, n: usize) -> (Environment, Array2<f64>) {
    let a = [1.0, -0.5, 0.25];
    let env = Environment::new(
        LatLongMap::from_fn(128, 1, |d, o| {
            o[0] = 2.0 + (0..3).map(|k| a[k] * d[k]).sum::<f64>()
        })
        .unwrap(),
    );
    let m = rotation.matrix();
    let rta: Vec<f64> = (0..3)
        .map(|k| (0..3).map(|i| m[i][k] * a[i]).sum())
        .collect();
    let step = PI / n as f64;
    let sin2 = |t: f64| t / 2.0 - (2.0 * t).sin() / 4.0; // an antiderivative of sin^2
    let means = Array2::from_shape_fn((n, 2 * n), |(i, j)| {
        let (t0, t1) = (i as f64 * step, (i + 1) as f64 * step);
        let (p0, p1) = (j as f64 * step, (j + 1) as f64 * step);
        let omega = (t0.cos() - t1.cos()) * step;
        let mean = [
            (sin2(t1) - sin2(t0)) * (p0.cos() - p1.cos()) / omega,
            0.5 * (t1.sin().powi(2) - t0.sin().powi(2)) * step / omega,
            (sin2(t1) - sin2(t0)) * (p1.sin() - p0.sin()) / omega,
        ];
        2.0 + (0..3).map(|k| rta[k] * mean[k]).sum::<f64>()
    });
    (env, means)
}

/// The largest difference of a one-channel map from `want`.
fn max_difference(map: &LatLongMap<f64>, want: &Array2<f64>) -> f64 {
    map.as_array()
        .index_axis(Axis(2), 0)
        .iter()
        .zip(want)
        .fold(0.0f64, |m, (a, b)| m.max((a - b).abs()))
}

#[test]
fn the_prefiltered_rotation_is_the_source_path_for_whole_column_yaws_and_small_sources() {
    let f = bright_pole(64, 2);
    let env = Environment::new(f.clone());
    for degrees in [0.0, 22.5, -45.0, 180.0, 337.5] {
        // Whole columns of the 16-column working map.
        let yaw = SphereRotation::from_degrees(degrees, 0.0, 0.0).unwrap();
        let fast = env.rotated(8, &yaw, LightRotation::Prefiltered).unwrap();
        assert_eq!(fast, env.lat_long(8, &yaw).unwrap(), "{degrees}");
    }
    // 2n >= H: the prefiltered copy would be the source, so the paths coincide.
    let tilt = SphereRotation::from_degrees(20.0, 35.0, -10.0).unwrap();
    for n in [32, 48, 64] {
        let fast = env.rotated(n, &tilt, LightRotation::Prefiltered).unwrap();
        assert_eq!(fast, env.lat_long(n, &tilt).unwrap(), "{n}");
    }
    // Below that, a general rotation goes through the copy and differs.
    let fast = env.rotated(8, &tilt, LightRotation::Prefiltered).unwrap();
    assert_ne!(fast, env.lat_long(8, &tilt).unwrap());
    assert_err!(
        env.rotated(65, &tilt, LightRotation::Prefiltered),
        InvalidParameter {
            name: "resolution",
            ..
        },
        "65: the working height"
    );
}

#[test]
fn the_prefiltered_rotation_keeps_the_energy_under_the_identity() {
    let f = bright_pole(64, 3);
    let env = Environment::new(f.clone());
    let identity = SphereRotation::identity();
    for n in [4, 8, 16, 20] {
        let g = env
            .rotated(n, &identity, LightRotation::Prefiltered)
            .unwrap();
        let change = relative_energy_change(&f, &g);
        assert!(change < 1e-12, "{n}: {change:e}");
    }
}

#[test]
fn the_prefiltered_rotation_agrees_with_the_source_path_on_smooth_maps() {
    let tilt = SphereRotation::from_degrees(20.0, 35.0, -10.0).unwrap();
    // The linear map against its exact texel means: the copy 32 high holds texel means,
    // whose bilinear interpolant is within O(copy texel^2) = O(1e-2) of the linear map
    // (measured 6.3e-3; the source path, whose texel is 4 times smaller, 2e-3).
    let (env, exact) = linear_map_and_means(&tilt, 16);
    let fast = env.rotated(16, &tilt, LightRotation::Prefiltered).unwrap();
    let worst = max_difference(&fast, &exact);
    assert!(worst < 1e-2, "{worst}");
    // A smooth, strongly varying map (a broad lobe of peak 21 on 1), 256 high: the two
    // paths' working maps within 0.6% relative RMS over the sphere.
    let lobe = [0.48, 0.6, 0.64];
    let f = LatLongMap::from_fn(256, 3, |d, o| {
        let c: f64 = (0..3).map(|k| lobe[k] * d[k]).sum();
        for (ch, v) in o.iter_mut().enumerate() {
            *v = 1.0 + (20.0 - 5.0 * ch as f64) * (4.0 * (c - 1.0)).exp();
        }
    })
    .unwrap();
    let env = Environment::new(f);
    let param = Parameterization::new(ParamKind::LatLong, 16).unwrap();
    let source = SphereMapping::new(256, param).unwrap();
    let fast = source.clone().with_rotation(LightRotation::Prefiltered);
    let (a, b) = (
        fast.apply(&env, &tilt).unwrap(),
        source.apply(&env, &tilt).unwrap(),
    );
    let error = a.relative_rms_error(&b).unwrap();
    assert!(error > 1e-6 && error < 6e-3, "{error:e}"); // measured 4.2e-3
}
