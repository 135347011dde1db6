use std::f64::consts::PI;

use super::*;
use crate::sphere::ParamKind;

#[test]
fn the_projector_matches_the_sphere_modules_projection() {
    // The transfer of one vertex is the projection of its values, as for any sphere function.
    let bands = 4;
    for (kind, size) in [(ParamKind::LatLong, 8), (ParamKind::Cube, 4)] {
        let param = Parameterization::new(kind, size).unwrap();
        let values = crate::sphere::param::SphereMap::<f64>::from_fn(param, 1, |d, o| {
            o[0] = (d[0] + 0.5 * d[1] * d[2]).max(0.0)
        })
        .unwrap();
        let want = SphericalHarmonics::new(bands).unwrap().project(&values);
        let flat: Vec<f32> = values.as_array().iter().map(|&v| v as f32).collect();
        let mut got = vec![0.0; bands * bands];
        ShProjector::new(param, bands)
            .unwrap()
            .project(&flat, &mut got);
        for (i, g) in got.iter().enumerate() {
            let w = want[[i, 0]];
            assert!((f64::from(*g) - w).abs() < 1e-6, "{kind:?} {i}: {g} vs {w}");
        }
    }
}

#[test]
fn shading_is_albedo_over_pi_times_the_dot_product() {
    let t = ShTransfer::new(2, Array2::from_shape_fn((3, 4), |(v, i)| (v + i) as f32)).unwrap();
    let albedo = Array2::from_shape_fn((3, 3), |(v, c)| 0.1 * (1 + v + c) as f32);
    let rgb = Array2::from_shape_fn((4, 3), |(i, c)| (i as f64 - 1.0) * (c + 1) as f64);
    let r = shade_sh(&t, albedo.view(), rgb.view()).unwrap();
    for v in 0..3 {
        for c in 0..3 {
            let dot: f64 = (0..4).map(|i| (v + i) as f64 * rgb[[i, c]]).sum();
            let want = f64::from(albedo[[v, c]]) / PI * dot;
            assert!((f64::from(r[[v, c]]) - want).abs() < 1e-6 * want.abs().max(1.0));
        }
    }
    // Gray lighting is the same in every channel.
    let gray = rgb.column(0).to_owned().insert_axis(ndarray::Axis(1));
    let g = shade_sh(&t, Array2::ones((3, 3)).view(), gray.view()).unwrap();
    assert!(
        g.rows()
            .into_iter()
            .all(|row| row[0] == row[1] && row[1] == row[2])
    );
    // Shapes that do not fit are errors.
    assert_err!(
        shade_sh(&t, albedo.slice(ndarray::s![1.., ..]), rgb.view()),
        InvalidShape { .. },
        "the albedo must be (3, 3)"
    );
    assert_err!(
        shade_sh(&t, albedo.view(), rgb.slice(ndarray::s![1.., ..])),
        InvalidShape { .. },
        "(4, 1) or (4, 3) for 2 bands"
    );
    assert_err!(
        shade_sh(&t, albedo.view(), Array2::zeros((4, 2)).view()),
        InvalidShape { .. },
        "(4, 1) or (4, 3) for 2 bands"
    );
    assert_err!(
        ShTransfer::new(0, Array2::zeros((1, 0))),
        InvalidParameter {
            name: "sh-bands",
            ..
        },
        "0: transfer takes 1 to 16 bands"
    );
    assert_err!(
        ShTransfer::new(17, Array2::zeros((1, 289))),
        InvalidParameter {
            name: "sh-bands",
            ..
        },
        "17: transfer takes 1 to 16 bands"
    );
    assert_err!(
        ShTransfer::new(1, Array2::from_elem((1, 1), f32::NAN)),
        InvalidParameter {
            name: "sh transfer",
            ..
        },
        "not finite"
    );
}

/// Never occluded: visibility 1 everywhere above the horizon.
struct Open;

impl crate::relight::Occlusion for Open {
    fn occluded(&self, _: [f32; 3], _: [f32; 3], _: f32) -> bool {
        false
    }
}

/// The RMS of `reference` and the largest difference of `sh` from it, over vertices and
/// channels.
fn error_of(sh: &Array2<f32>, reference: &Array2<f64>) -> (f64, f64) {
    let rms = (reference.iter().map(|x| x * x).sum::<f64>() / reference.len() as f64).sqrt();
    let worst = sh
        .iter()
        .zip(reference)
        .fold(0.0f64, |a, (s, r)| a.max((f64::from(*s) - r).abs()));
    (worst, rms)
}

/// A lumpy albedo, `(V, 3)`.
fn albedo(vertices: usize) -> Array2<f32> {
    Array2::from_shape_fn((vertices, 3), |(v, c)| {
        0.4 + 0.15 * ((v + 2 * c) % 4) as f32
    })
}

/// The SH render of `mesh` under `lighting` (lat-long `n`) from a transfer of `bands` bands
/// precomputed through `occlusion`.
fn sh_render(
    mesh: &crate::relight::Mesh,
    occlusion: &impl crate::relight::Occlusion,
    lighting: &crate::sphere::LatLongMap<f64>,
    bands: usize,
) -> Array2<f32> {
    use crate::relight::{VisibilityOptions, vertex_major};
    let n = lighting.height();
    let mut options = VisibilityOptions::new(Parameterization::new(ParamKind::LatLong, n).unwrap());
    options.sh_bands = Some(bands);
    let (set, _) = vertex_major(mesh, occlusion, &options).unwrap();
    let transfer = set.sh().unwrap();
    assert_eq!(
        (transfer.bands(), transfer.vertex_count()),
        (bands, mesh.vertex_count())
    );
    let map = crate::sphere::param::SphereMap::from_lat_long(lighting).unwrap();
    let l = SphericalHarmonics::new(bands).unwrap().project(&map);
    shade_sh(transfer, albedo(mesh.vertex_count()).view(), l.view()).unwrap()
}

/// The reference render of the same.
fn reference_render(
    mesh: &crate::relight::Mesh,
    occlusion: &impl crate::relight::Occlusion,
    lighting: &crate::sphere::LatLongMap<f64>,
) -> Array2<f64> {
    let a = albedo(mesh.vertex_count());
    let options = crate::relight::ReferenceOptions::default();
    crate::relight::reference(mesh, occlusion, a.view(), lighting, &options)
        .unwrap()
        .0
}

#[test]
fn unoccluded_band_limited_lighting_is_rendered_to_quadrature_accuracy() {
    // Degree <= 2 and positive: 1 + 0.4 y + 0.3 x + 0.2 (x z) + 0.1 (3 y^2 - 1).
    let mesh = crate::relight::Generator::Sphere { cells: 6 }
        .mesh()
        .unwrap();
    let lighting = |n| {
        crate::sphere::LatLongMap::<f64>::from_fn(n, 3, |d, o| {
            let (x, y, z) = (d[0], d[1], d[2]);
            let base = 1.0 + 0.4 * y + 0.3 * x + 0.2 * x * z + 0.1 * (3.0 * y * y - 1.0);
            o.copy_from_slice(&[base, base + 0.2 * z, 0.8 * base]);
        })
        .unwrap()
    };
    let mut errors = Vec::new();
    let references = [16, 32].map(|n| reference_render(&mesh, &Open, &lighting(n)));
    for (n, bands, r) in [(16, 3, 0), (32, 3, 1), (32, 5, 1)] {
        let sh = sh_render(&mesh, &Open, &lighting(n), bands);
        let (worst, rms) = error_of(&sh, &references[r]);
        eprintln!("N = {n}, B = {bands}: {:e} of the RMS", worst / rms);
        errors.push(worst / rms);
    }
    // The only error is the texel quadrature's, second order: about 4x less per doubling
    // (measured: 4.5e-3 of the RMS at N = 16, 1.1e-3 at 32, 9.8e-4 at 32 with 5 bands).
    assert!(errors[1] < 2e-3, "{errors:?}");
    assert!(errors[1] < 0.35 * errors[0], "{errors:?}");
    // More bands than the lighting has add nothing but quadrature noise.
    assert!(errors[2] < 2.0 * errors[1], "{errors:?}");
    // With too few bands the lighting's degree 2 is lost: far worse.
    let sh = sh_render(&mesh, &Open, &lighting(32), 2);
    let (worst, rms) = error_of(&sh, &references[1]);
    assert!(worst / rms > 20.0 * errors[1], "{}", worst / rms);
}

#[test]
fn on_an_occluded_scene_more_bands_come_closer_to_the_reference() {
    let mut mesh = crate::relight::Generator::Sphere { cells: 4 }
        .mesh()
        .unwrap();
    crate::relight::add_ground_plane(&mut mesh);
    let bvh = crate::relight::SceneBvh::new(&mesh);
    // A smooth sky: a broad lobe towards the upper +X +Z and a dim floor.
    let lighting = crate::sphere::LatLongMap::<f64>::from_fn(64, 1, |d, o| {
        let s = [0.5, 0.7, 0.5];
        let c = (d[0] * s[0] + d[1] * s[1] + d[2] * s[2]) / 0.99f64.sqrt();
        o[0] = 0.2 + 3.0 * (5.0 * (c - 1.0)).exp();
    })
    .unwrap();
    let r = reference_render(&mesh, &bvh, &lighting);
    let mut errors = Vec::new();
    for bands in [2, 4, 6, 8] {
        let sh = sh_render(&mesh, &bvh, &lighting, bands);
        let (worst, rms) = error_of(&sh, &r);
        eprintln!("B = {bands}: {:e} of the RMS", worst / rms);
        errors.push(worst / rms);
    }
    for w in errors.windows(2) {
        assert!(w[1] < w[0], "{errors:?}");
    }
    // Measured: 0.30, 4.3e-2, 3.9e-3, 3.4e-4 of the RMS.
    assert!(
        errors[3] < 1e-3 && errors[3] < 2e-3 * errors[0],
        "{errors:?}"
    );
}
