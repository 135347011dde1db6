use super::*;
use haarshift::faces::ParamKind;

#[test]
fn the_projector_matches_the_sphere_modules_projection() {
    // The transfer of one vertex is the projection of its values, as for any sphere function.
    let bands = 4;
    for (kind, size) in [(ParamKind::LatLong, 8), (ParamKind::Cube, 4)] {
        let param = Parameterization::new(kind, size).unwrap();
        let values = haarshift::faces::param::SphereMap::<f64>::from_fn(param, 1, |d, o| {
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
