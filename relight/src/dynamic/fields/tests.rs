use ndarray::{Array3, Axis};
use proptest::prelude::*;

use super::*;
use crate::test_support::latlong;
use crate::test_support::squashed_sphere;
use haarshift::faces::integrate::layout;
use haarshift::product::{FaceLayout, HaarTree};

fn small(param: Parameterization) -> FieldOptions {
    FieldOptions {
        circles: 5,
        circle_points: 12,
        shells: 4,
        shell_grid: 3,
        ..FieldOptions::new(param)
    }
}

/// The visibility of `mesh` from `x` at every texel centre, 1 or 0, `(faces, S, S)`.
fn ray_cast(mesh: &Mesh, x: [f64; 3], param: Parameterization) -> Array3<f32> {
    let bvh = SceneBvh::new(mesh);
    let s = param.face_size();
    Array3::from_shape_fn((param.faces(), s, s), |(f, i, j)| {
        let d = f32x3(param.texel_direction(f, i, j));
        if bvh.occluded(f32x3(x), d, f32::INFINITY) {
            0.0
        } else {
            1.0
        }
    })
}

/// The orthonormal Haar coefficients of `pixels`, dense `(faces, S, S)`.
fn coefficients(pixels: &Array3<f32>, param: Parameterization) -> Array3<f32> {
    let t = HaarTree::<f32, 1>::from_pixels(
        pixels.view().insert_axis(Axis(3)),
        layout(param),
        Selection::All,
    )
    .unwrap();
    t.to_coefficients().index_axis_move(Axis(3), 0)
}

fn dense_faces(indices: &[u32], values: &[f32], param: Parameterization) -> Array3<f32> {
    let s = param.face_size();
    let mut out = Array3::zeros((param.faces(), s, s));
    let flat = out.as_slice_mut().unwrap();
    for (&i, &v) in indices.iter().zip(values) {
        flat[i as usize] = v;
    }
    out
}

fn max_diff(a: &Array3<f32>, b: &Array3<f32>) -> f32 {
    a.iter()
        .zip(b)
        .map(|(x, y)| (x - y).abs())
        .fold(0.0, f32::max)
}

#[test]
fn a_field_looked_up_at_a_sample_point_is_the_ray_cast_visibility_from_it() {
    for param in [
        latlong(8),
        Parameterization::new(ParamKind::Cube, 4).unwrap(),
    ] {
        let mesh = squashed_sphere();
        let (field, report) = OcclusionField::build(&mesh, &small(param)).unwrap();
        assert_eq!(report.rays, (60 + 4 * 54) as u64 * param.texels() as u64);
        let points = field.sample_points();
        let lift = ray_offset(&mesh);
        let mut occluded_somewhere = 0;
        // Planar samples on the inner and outer circles, spherical ones on every shell.
        for i in [0, 7, 59, 60, 60 + 13, 60 + 54 + 20, 60 + 3 * 54 + 53] {
            let x = points[i];
            let blend = field.lookup(x).unwrap();
            let (top, w) = blend
                .samples()
                .iter()
                .copied()
                .max_by(|a, b| a.1.total_cmp(&b.1))
                .unwrap();
            // Edge points are on two faces: either copy is the same point.
            let at = points[top as usize];
            assert!(
                (0..3).all(|k| (at[k] - x[k]).abs() < 1e-12),
                "sample {i}: {top}"
            );
            assert!(w > 1.0 - 1e-6, "sample {i}: weight {w}");
            let from = if i < 60 { [x[0], x[1] + lift, x[2]] } else { x };
            let pixels = ray_cast(&mesh, from, param);
            occluded_somewhere += (pixels.sum() < param.texels() as f32) as usize;
            let want = coefficients(&pixels, param);
            let mut scratch = vec![0.0; param.texels()];
            let mut out = (Vec::new(), Vec::new());
            field
                .blended(x, Truncation::Before, &mut scratch, &mut out)
                .unwrap();
            let got: Vec<f32> = out.1.iter().map(|&v| v as f32).collect();
            assert!(
                max_diff(&dense_faces(&out.0, &got, param), &want) < 1e-5,
                "sample {i}"
            );
            assert!(scratch.iter().all(|&v| v == 0.0));
        }
        // The inner samples see the object; the test means something.
        assert!(occluded_somewhere >= 5, "{occluded_somewhere}");
    }
}

#[test]
fn radii_are_geometric_between_the_options_bounds_and_beyond_the_last_shell_nothing_occludes() {
    let param = latlong(4);
    let mesh = squashed_sphere();
    let (field, _) = OcclusionField::build(&mesh, &small(param)).unwrap();
    let f = *field.frame();
    let points = field.sample_points();
    let radius = |p: [f64; 3]| {
        let d: Vec<f64> = (0..3).map(|k| p[k] - f.centre[k]).collect();
        (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt()
    };
    let circle = |k: usize| {
        let p = points[k * 12];
        ((p[0] - f.centre[0]).powi(2) + (p[2] - f.centre[2]).powi(2)).sqrt()
    };
    assert!((circle(0) - 0.05 * f.footprint).abs() < 1e-12);
    assert!((circle(4) - 10.0 * f.footprint).abs() < 1e-9);
    let shell = |k: usize| radius(points[60 + k * 54 + 4]);
    assert!((shell(0) - 0.2 * f.radius).abs() < 1e-12);
    assert!((shell(3) - 6.0 * f.radius).abs() < 1e-9);
    for k in 0..2 {
        // Spacing in proportion to the radius: a constant ratio.
        let (a, b) = (circle(k + 1) / circle(k), circle(k + 2) / circle(k + 1));
        assert!((a - b).abs() < 1e-9 && a > 1.0);
        let (a, b) = (shell(k + 1) / shell(k), shell(k + 2) / shell(k + 1));
        assert!((a - b).abs() < 1e-9 && a > 1.0);
    }
    let out = 6.0 * f.radius * 1.001;
    assert!(
        field
            .lookup([f.centre[0] + out, f.centre[1], f.centre[2]])
            .is_none()
    );
    let inside = field.lookup([f.centre[0] + 5.9 * f.radius, f.centre[1], f.centre[2]]);
    assert!(inside.is_some());
    // Inside the innermost shell: the innermost, weights summing to 1.
    let blend = field
        .lookup([f.centre[0] + 0.01, f.centre[1] + 0.02, f.centre[2]])
        .unwrap();
    let total: f32 = blend.samples().iter().map(|s| s.1).sum();
    assert!((total - 1.0).abs() < 1e-6);
    assert!(blend.samples().iter().all(|s| (s.0 as usize) < 60 + 54));
}

#[test]
fn a_point_between_samples_blends_their_maps_linearly() {
    let param = latlong(8);
    let mesh = squashed_sphere();
    let (field, _) = OcclusionField::build(&mesh, &small(param)).unwrap();
    let f = *field.frame();
    let x = [f.centre[0] + 0.8, f.centre[1] + 0.9, f.centre[2] - 0.4];
    let blend = field.lookup(x).unwrap();
    let mut want = Array3::<f32>::zeros((2, 8, 8));
    for &(i, w) in blend.samples() {
        let (idx, val) = field.map(i as usize);
        want.scaled_add(w, &dense_faces(idx, val, param));
    }
    let mut scratch = vec![0.0; param.texels()];
    let mut out = (Vec::new(), Vec::new());
    field
        .blended(x, Truncation::Before, &mut scratch, &mut out)
        .unwrap();
    let got: Vec<f32> = out.1.iter().map(|&v| v as f32).collect();
    assert!(max_diff(&dense_faces(&out.0, &got, param), &want) < 1e-5);
    // Truncating after the blend keeps the largest details of the blend (and the scaling).
    field
        .blended(
            x,
            Truncation::After(Selection::Largest(5)),
            &mut scratch,
            &mut out,
        )
        .unwrap();
    let scaling = out.0.iter().filter(|&&i| i % 64 == 0).count();
    assert_eq!(out.0.len() - scaling, 5);
    let smallest_kept = out
        .0
        .iter()
        .zip(&out.1)
        .filter(|(i, _)| **i % 64 != 0)
        .map(|(_, v)| v.abs() as f32)
        .fold(f32::INFINITY, f32::min);
    let dropped = want
        .iter()
        .enumerate()
        .filter(|(i, _)| i % 64 != 0 && !out.0.contains(&(*i as u32)))
        .map(|(_, v)| v.abs())
        .fold(0.0, f32::max);
    assert!(
        dropped <= smallest_kept + 1e-6,
        "{dropped} > {smallest_kept}"
    );
}

#[test]
fn a_turned_field_is_the_field_of_the_turned_object() {
    let param = latlong(8);
    let mesh = squashed_sphere();
    let (field, _) = OcclusionField::build(&mesh, &small(param)).unwrap();
    let k = 5; // 5 of 16 columns: 112.5 degrees
    let turned = field.turned(k).unwrap();
    let yaw =
        haarshift::sphere::SphereRotation::from_degrees(k as f64 * 360.0 / 16.0, 0.0, 0.0).unwrap();
    let moved = mesh.mapped(|p| yaw.apply(p), |n| yaw.apply(n)).unwrap();
    let points = field.sample_points();
    let (mut differ, mut occluded) = (0, 0);
    for i in [61, 60 + 54 + 7, 60 + 2 * 54 + 30] {
        let pixels = ray_cast(&moved, yaw.apply(points[i]), param);
        occluded += pixels.iter().filter(|&&v| v == 0.0).count();
        let (idx, val) = turned.map(i);
        let got = HaarTree::<f32, 1>::from_coefficients(
            dense_faces(idx, val, param).insert_axis(Axis(3)).view(),
            FaceLayout::Stacked,
            Selection::All,
        )
        .unwrap()
        .to_pixels()
        .unwrap()
        .index_axis_move(Axis(3), 0);
        differ += got
            .iter()
            .zip(&pixels)
            .filter(|(a, b)| (*a - *b).abs() > 1e-4)
            .count();
    }
    assert!(occluded > 20, "{occluded}");
    // Texels whose centre ray grazes an edge may flip with the rounding of the turned mesh.
    assert!(differ <= 2, "{differ} texels differ");
    // Turning twice adds up; turning back is the identity.
    let twice = field.turned(3).unwrap().turned(k).unwrap();
    assert_eq!(twice.map(61), turned.map(61));
    assert_eq!(turned.turned(0).unwrap().map(61), field.map(61));
}

#[test]
fn bad_options_are_refused() {
    let param = latlong(4);
    let mesh = squashed_sphere();
    let mut o = small(param);
    o.shell_radii = (2.0, 1.0);
    assert_err!(
        OcclusionField::build(&mesh, &o),
        InvalidParameter {
            name: "shell radii",
            ..
        },
        "increasing"
    );
    o = small(param);
    o.circle_radii = (f64::NAN, 1.0);
    assert_err!(
        OcclusionField::build(&mesh, &o),
        InvalidParameter {
            name: "circle radii",
            ..
        },
        "increasing"
    );
    o = small(param);
    o.circles = 1;
    assert_err!(
        OcclusionField::build(&mesh, &o),
        InvalidParameter {
            name: "field samples",
            ..
        },
        "at least 2 circles"
    );
    o = small(param);
    o.circle_points = usize::MAX / 2;
    assert_err!(
        OcclusionField::build(&mesh, &o),
        InvalidParameter {
            name: "field samples",
            ..
        },
        "4000000 sample points"
    );
    o = small(param);
    o.keep = Selection::Largest(1000);
    assert_err!(
        OcclusionField::build(&mesh, &o),
        InvalidParameter { name: "keep", .. },
        "only 30 details"
    );
    // No width or depth: no footprint to place the planar field by.
    let flat = Mesh::new(
        ndarray::array![[0.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 0.0]],
        vec![[0, 1, 2]],
        None,
    )
    .unwrap();
    assert_err!(
        OcclusionField::build(&flat, &small(param)),
        InvalidParameter { name: "mesh", .. },
        "width and depth"
    );
    let cube = Parameterization::new(ParamKind::Cube, 4).unwrap();
    let (field, _) = OcclusionField::build(&mesh, &small(cube)).unwrap();
    assert_err!(
        field.turned(1),
        InvalidParameter { name: "turn", .. },
        "lat-long"
    );
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(32))]

    #[test]
    fn yaw_sparse_is_a_column_roll_of_the_pixels(
        seed in 0u64..1000,
        k in 0usize..32,
    ) {
        let param = latlong(16);
        let pixels = Array3::from_shape_fn((2, 16, 16), |(f, i, j)| {
            let x = (seed.wrapping_mul(2654435761) ^ ((f * 256 + i * 16 + j) as u64 * 40503)) % 97;
            x as f32 / 97.0
        });
        let c = coefficients(&pixels, param);
        let (idx, val): (Vec<u32>, Vec<f32>) = c
            .iter()
            .enumerate()
            .filter(|(_, v)| **v != 0.0)
            .map(|(i, v)| (i as u32, *v))
            .unzip();
        let (ti, tv) = yaw_sparse(param, &idx, &val, k, Selection::All).unwrap();
        // The oracle: the H x 2H map with its columns rolled by hand, transformed.
        let mut rolled = Array3::<f32>::zeros((2, 16, 16));
        for f in 0..2 {
            for i in 0..16 {
                for j in 0..16 {
                    let col = (f * 16 + j + 32 - k) % 32;
                    rolled[[f, i, j]] = pixels[[col / 16, i, col % 16]];
                }
            }
        }
        let want = coefficients(&rolled, param);
        prop_assert!(max_diff(&dense_faces(&ti, &tv, param), &want) < 1e-5);
    }
}
