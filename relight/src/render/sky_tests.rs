//! Tests of the environment behind a render: the prepared lookup against the pixel's ray
//! looked up directly (the brute-force oracle), bit for bit.

use super::*;
use crate::render::{Background, LitMesh, render};
use ndarray::{Array2, Array3};

/// A map with detail at every scale: each channel a different function of the direction.
fn detailed(h: usize, channels: usize) -> LatLongMap<f64> {
    LatLongMap::<f64>::from_fn(h, channels, |d, o| {
        for (c, v) in o.iter_mut().enumerate() {
            *v = 1.0 + (7.0 * d[0] + 3.0 * c as f64).sin() * d[1] + (11.0 * d[2]).cos();
        }
    })
    .unwrap()
}

/// The image of no triangles with `background` behind.
fn backdrop(camera: &Camera, w: usize, h: usize, background: Background<'_>) -> Array3<f32> {
    let (positions, radiance) = (Array2::<f64>::zeros((0, 3)), Array2::<f32>::zeros((0, 3)));
    let mesh = LitMesh {
        positions: positions.view(),
        triangles: &[],
        radiance: radiance.view(),
    };
    render(camera, w, h, &mesh, background)
        .unwrap()
        .planes()
        .to_owned()
}

/// The oracle: every pixel's ray, turned, looked up in `map` on its own.
fn oracle(
    camera: &Camera,
    w: usize,
    h: usize,
    map: &LatLongMap<f64>,
    rotation: &SphereRotation,
) -> Array3<f32> {
    let mut out = Array3::zeros((3, h, w));
    let mut v = vec![0.0; map.channels()];
    for i in 0..h {
        for j in 0..w {
            let d = rotation.apply(camera.ray(j as f64 + 0.5, i as f64 + 0.5, w, h));
            let (theta, phi) = angles(d);
            map.bilinear(theta, phi, &mut v);
            for c in 0..3 {
                out[[c, i, j]] = v[if v.len() < 3 { 0 } else { c }] as f32;
            }
        }
    }
    out
}

#[test]
fn a_whole_column_yaw_is_the_rolled_map_and_any_turn_is_the_oracle_bit_for_bit() {
    // Looking up past both poles and across the seam.
    let cameras = [
        Camera::new([0.0, 0.0, 0.0], [0.3, 1.0, -0.2], 120.0).unwrap(),
        Camera::new([0.0, 0.0, 0.0], [-0.1, -1.0, 0.05], 150.0).unwrap(),
        Camera::new([1.0, 2.0, 3.0], [0.0, 2.0, 4.0], 60.0).unwrap(),
    ];
    let (w, h) = (29, 23);
    for channels in [1, 4] {
        let map = detailed(16, channels);
        for camera in &cameras {
            let lookup = SkyLookup::new(camera, w, h, &map).unwrap();
            for k in [0usize, 1, 5, 16, 31] {
                let turn = SphereRotation::from_degrees(k as f64 * 360.0 / 32.0, 0.0, 0.0).unwrap();
                let sky = Sky {
                    map: &map,
                    rotation: &turn,
                    lookup: Some(&lookup),
                };
                let got = backdrop(camera, w, h, Background::Sky(sky));
                let rolled = map.roll_columns(k);
                let want = backdrop(camera, w, h, Background::Environment(&rolled));
                assert_eq!(got, want, "{channels} channels, k = {k}");
                assert_eq!(
                    want,
                    oracle(camera, w, h, &rolled, &SphereRotation::identity())
                );
            }
            for (yaw, pitch, roll) in [(10.0, 0.0, 0.0), (30.0, 20.0, 0.0), (-75.0, 110.0, 33.0)] {
                let turn = SphereRotation::from_degrees(yaw, pitch, roll).unwrap();
                assert_eq!(turn.whole_column_yaw(32), None);
                let sky = Sky {
                    map: &map,
                    rotation: &turn,
                    lookup: Some(&lookup),
                };
                let got = backdrop(camera, w, h, Background::Sky(sky));
                assert_eq!(
                    got,
                    oracle(camera, w, h, &map, &turn),
                    "{yaw} {pitch} {roll}"
                );
            }
        }
    }
}

#[test]
fn a_lookup_serves_only_its_camera_size_and_map_height() {
    let map = detailed(16, 3);
    let camera = Camera::new([0.0, 0.0, 4.0], [0.0; 3], 40.0).unwrap();
    let lookup = SkyLookup::new(&camera, 12, 10, &map).unwrap();
    assert!(lookup.fits(&camera, 12, 10, &detailed(16, 1)));
    let moved = camera.orbited(1.0).unwrap();
    let taller = detailed(32, 3);
    let identity = SphereRotation::identity();
    for (camera, w, h, map) in [
        (&moved, 12, 10, &map),
        (&camera, 10, 12, &map),
        (&camera, 12, 10, &taller),
    ] {
        assert!(!lookup.fits(camera, w, h, map));
        let sky = Sky {
            map,
            rotation: &identity,
            lookup: Some(&lookup),
        };
        let (positions, radiance) = (Array2::<f64>::zeros((0, 3)), Array2::<f32>::zeros((0, 3)));
        let mesh = LitMesh {
            positions: positions.view(),
            triangles: &[],
            radiance: radiance.view(),
        };
        let err = render(camera, w, h, &mesh, Background::Sky(sky)).unwrap_err();
        assert!(
            err.to_string()
                .contains("a sky lookup made for a 12 x 10 image"),
            "{err}"
        );
    }
    assert_err!(
        SkyLookup::new(&camera, 0, 10, &map),
        InvalidShape { .. },
        "invalid shape [10, 0]: an image is 1 to 32768 pixels wide and high"
    );
}
