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
    assert!(shade_sh(&t, albedo.slice(ndarray::s![1.., ..]), rgb.view()).is_err());
    assert!(shade_sh(&t, albedo.view(), rgb.slice(ndarray::s![1.., ..])).is_err());
    assert!(shade_sh(&t, albedo.view(), Array2::zeros((4, 2)).view()).is_err());
    assert!(ShTransfer::new(0, Array2::zeros((1, 0))).is_err());
    assert!(ShTransfer::new(17, Array2::zeros((1, 289))).is_err());
    assert!(ShTransfer::new(1, Array2::from_elem((1, 1), f32::NAN)).is_err());
}
