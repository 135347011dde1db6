use std::f64::consts::PI;

use super::*;
use haarshift::faces::{ParamKind, Parameterization};

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

impl crate::Occlusion for Open {
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
fn lumpy_albedo(vertices: usize) -> Array2<f32> {
    Array2::from_shape_fn((vertices, 3), |(v, c)| {
        0.4 + 0.15 * ((v + 2 * c) % 4) as f32
    })
}

/// The SH render of `mesh` under `lighting` (lat-long `n`) from a transfer of `bands` bands
/// precomputed through `occlusion`.
fn sh_render(
    mesh: &crate::Mesh,
    occlusion: &impl crate::Occlusion,
    lighting: &haarshift::sphere::LatLongMap<f64>,
    bands: usize,
) -> Array2<f32> {
    use crate::{VisibilityOptions, vertex_major};
    let n = lighting.height();
    let mut options = VisibilityOptions::new(Parameterization::new(ParamKind::LatLong, n).unwrap());
    options.sh_bands = Some(bands);
    let (set, _) = vertex_major(mesh, occlusion, &options).unwrap();
    let transfer = set.sh().unwrap();
    assert_eq!(
        (transfer.bands(), transfer.vertex_count()),
        (bands, mesh.vertex_count())
    );
    let map = haarshift::faces::param::SphereMap::from_lat_long(lighting).unwrap();
    let l = SphericalHarmonics::new(bands).unwrap().project(&map);
    shade_sh(transfer, lumpy_albedo(mesh.vertex_count()).view(), l.view()).unwrap()
}

/// The reference render of the same.
fn reference_render(
    mesh: &crate::Mesh,
    occlusion: &impl crate::Occlusion,
    lighting: &haarshift::sphere::LatLongMap<f64>,
) -> Array2<f64> {
    let a = lumpy_albedo(mesh.vertex_count());
    let options = crate::ReferenceOptions::default();
    crate::reference(mesh, occlusion, a.view(), lighting, &options)
        .unwrap()
        .0
}

#[test]
fn unoccluded_band_limited_lighting_is_rendered_to_quadrature_accuracy() {
    // Degree <= 2 and positive: 1 + 0.4 y + 0.3 x + 0.2 (x z) + 0.1 (3 y^2 - 1).
    let mesh = crate::Generator::Sphere { cells: 6 }.mesh().unwrap();
    let lighting = |n| {
        haarshift::sphere::LatLongMap::<f64>::from_fn(n, 3, |d, o| {
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
    let mut mesh = crate::Generator::Sphere { cells: 4 }.mesh().unwrap();
    crate::add_ground_plane(&mut mesh).unwrap();
    let bvh = crate::SceneBvh::new(&mesh);
    // A smooth sky: a broad lobe towards the upper +X +Z and a dim floor.
    let lighting = haarshift::sphere::LatLongMap::<f64>::from_fn(64, 1, |d, o| {
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

/// `count` unit vectors spread over the sphere (a golden-angle spiral).
fn unit_vectors(count: usize) -> Array2<f64> {
    Array2::from_shape_fn((count, 3), |(v, k)| {
        let y = 1.0 - 2.0 * (v as f64 + 0.5) / count as f64;
        let s = (1.0 - y * y).sqrt();
        let phi = v as f64 * 2.399_963;
        [s * phi.sin(), y, s * phi.cos()][k]
    })
}

/// A deterministic transfer of `vertices` rows, `albedo` and RGB lighting of `bands` bands,
/// decaying with the degree as real ones do.
fn glossy_inputs(bands: usize, vertices: usize) -> (ShTransfer, Array2<f32>, Array2<f64>) {
    let n = bands * bands;
    let decay = |i: usize| 1.0 / (1.0 + i.isqrt() as f64);
    let t = Array2::from_shape_fn((vertices, n), |(v, i)| {
        (decay(i) * ((v * 7 + i * 13) as f64 * 0.37).sin()) as f32
    });
    let albedo = Array2::from_shape_fn((vertices, 3), |(v, c)| 0.3 + 0.2 * ((v + c) % 3) as f32);
    let l = Array2::from_shape_fn((n, 3), |(i, c)| {
        decay(i) * (1.0 + ((i * 5 + c * 3) as f64 * 0.61).cos())
    });
    (ShTransfer::new(bands, t).unwrap(), albedo, l)
}

#[test]
fn phong_exponent_zero_is_lambert_with_albedo_one() {
    // 0^0 = 1: the lobe is the constant 1 / pi, so every glossy vertex is shade_sh's.
    let (t, albedo, l) = glossy_inputs(6, 40);
    let mirror = unit_vectors(40);
    let glossy = shade_sh_glossy(&t, albedo.view(), l.view(), 0.0, mirror.view(), 40).unwrap();
    let lambert = shade_sh_glossy(&t, albedo.view(), l.view(), 0.0, mirror.view(), 0).unwrap();
    let single = shade_sh(&t, albedo.view(), l.view()).unwrap();
    let scale = lambert.iter().fold(0.0f64, |a, v| a.max(v.abs()));
    for ((g, w), s) in glossy.iter().zip(&lambert).zip(&single) {
        assert!((g - w).abs() < 1e-12 * scale, "{g} vs {w}");
        assert!((f64::from(*s) - w).abs() < 1e-6 * scale, "{s} vs {w}");
    }
    // A real lobe is not Lambert: exponent 10 changes every glossy vertex.
    let phong = shade_sh_glossy(&t, albedo.view(), l.view(), 10.0, mirror.view(), 20).unwrap();
    for (v, (p, w)) in phong.rows().into_iter().zip(lambert.rows()).enumerate() {
        let differs = (p[0] - w[0]).abs() > 1e-6 * scale;
        assert_eq!(differs, v < 20, "vertex {v}: {} vs {}", p[0], w[0]);
    }
}

#[test]
fn band_limited_triple_products_equal_the_pixel_domain_integral() {
    // Transfer, lighting and lobe of degrees below B reconstructed on a fine grid (composite
    // Boole, 2048 steps in cos theta, error ~1e-15 on these polynomials) and integrated there:
    // the triple product's definition, independent of the Gaunt table.
    let bands = 5;
    let n = bands * bands;
    let (t, albedo, l) = glossy_inputs(bands, 4);
    let mirror = unit_vectors(4);
    let exponent = 10.0;
    let got = shade_sh_glossy(&t, albedo.view(), l.view(), exponent, mirror.view(), 4).unwrap();
    let sh = SphericalHarmonics::new(bands).unwrap();
    let lambda = haarshift::sphere::harmonics::phong_factors(exponent, bands).unwrap();
    let grid = haarshift_testkit::quadrature::sphere_grid(2048, 4 * bands);
    let mut y = vec![0.0; n];
    let mut rho = vec![0.0; n];
    let lighting: Vec<Vec<f64>> = l.columns().into_iter().map(|c| c.to_vec()).collect();
    let mut worst = 0.0f64;
    for v in 0..4 {
        let r = mirror.row(v);
        sh.rotated_zonal(&lambda, [r[0], r[1], r[2]], &mut rho);
        let tv: Vec<f64> = t.coefficients().row(v).iter().map(|&x| x.into()).collect();
        let mut integral = [0.0; 3];
        for (d, w) in &grid {
            sh.evaluate(*d, &mut y);
            let at = |c: &[f64]| c.iter().zip(&y).map(|(a, b)| a * b).sum::<f64>();
            let lobe = at(&rho) * at(&tv);
            for (i, c) in integral.iter_mut().zip(&lighting) {
                *i += w * lobe * at(c);
            }
        }
        for c in 0..3 {
            let want = f64::from(albedo[[v, c]]) * integral[c];
            worst = worst.max((got[[v, c]] - want).abs() / want.abs().max(1e-3));
        }
    }
    eprintln!("band-limited: worst relative {worst:e}");
    assert!(worst < 1e-10, "{worst:e}");
}

#[test]
fn more_bands_converge_to_the_integral_of_the_unprojected_functions() {
    // An upward vertex's unoccluded transfer max(0, y), the lighting 0.3 + 2 max(0, s . w)^8 and
    // a Phong 10 lobe about r: all zonal, so their coefficients are exact at every B (Funk-Hecke)
    // and the only error is the cut to B bands. The reference integrates the functions
    // themselves on a fine grid (Boole in y, whose step boundary y = 0 is the transfer's kink;
    // the lobes' kinks are C^7 and smoother): 1024 and 2048 steps agree to 4e-15.
    let s = [0.6, 0.48, 0.64];
    let r = [-0.36, 0.48, 0.8];
    let dot = |a: [f64; 3], b: [f64; 3]| a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
    let light = |w: [f64; 3]| 0.3 + 2.0 * dot(s, w).max(0.0).powi(8);
    let lobe = |w: [f64; 3]| 12.0 / (2.0 * PI) * dot(r, w).max(0.0).powi(10);
    let reference = |steps| {
        haarshift_testkit::quadrature::sphere_grid(steps, steps)
            .iter()
            .map(|(d, w)| w * d[1].max(0.0) * light(*d) * lobe(*d))
            .sum::<f64>()
    };
    let want = reference(2048);
    assert!((reference(1024) - want).abs() < 1e-13 * want);
    let mut errors = Vec::new();
    for bands in (2..=16).step_by(2) {
        let sh = SphericalHarmonics::new(bands).unwrap();
        let n = bands * bands;
        let mut t = vec![0.0; n];
        let cosine: Vec<f64> = (0..bands)
            .map(haarshift::sphere::harmonics::lambert_factor)
            .collect();
        sh.rotated_zonal(&cosine, [0.0, 1.0, 0.0], &mut t);
        // max(0, x)^8 is the Phong 8 lobe times 2 pi / 10; the constant is 0.3 sqrt(4 pi) Y_00.
        let mut l = vec![0.0; n];
        let eight = haarshift::sphere::harmonics::phong_factors(8.0, bands).unwrap();
        sh.rotated_zonal(&eight, s, &mut l);
        l.iter_mut().for_each(|c| *c *= 2.0 * 2.0 * PI / 10.0);
        l[0] += 0.3 * (4.0 * PI).sqrt();
        let transfer = ShTransfer::new(
            bands,
            Array2::from_shape_vec((1, n), t.iter().map(|&x| x as f32).collect()).unwrap(),
        )
        .unwrap();
        let lighting = Array2::from_shape_fn((n, 1), |(i, _)| l[i]);
        let mirror = ndarray::arr2(&[r]);
        let got = shade_sh_glossy(
            &transfer,
            Array2::ones((1, 3)).view(),
            lighting.view(),
            10.0,
            mirror.view(),
            1,
        )
        .unwrap();
        let error = (got[[0, 0]] - want).abs() / want;
        eprintln!(
            "B = {bands}: {got} vs {want}: relative error {error:e}",
            got = got[[0, 0]]
        );
        errors.push(error);
    }
    // Measured: 0.40, 0.18, 3.3e-2, 4.2e-4, 2.0e-4, 1.2e-5, 2.7e-6, 3.1e-7 at B = 2, 4, ..., 16:
    // falling at every step, about B^-10 from 8 to 16 (the factors' smoothness: C^7 and C^9
    // lobes, the cosine's kink), down to the f32 transfer's rounding.
    assert!(errors.windows(2).all(|w| w[1] < w[0]), "{errors:?}");
    assert!(errors[3] < 1e-3 && errors[7] < 1e-6, "{errors:?}");
    assert!(errors[7] < errors[3] / 500.0, "{errors:?}");
}

#[test]
fn bad_glossy_inputs_are_errors() {
    let (t, albedo, l) = glossy_inputs(3, 5);
    let mirror = unit_vectors(5);
    let shade =
        |a: ArrayView2<'_, f32>, l: ArrayView2<'_, f64>, e: f64, m: ArrayView2<'_, f64>, g| {
            shade_sh_glossy(&t, a, l, e, m, g)
        };
    assert!(shade(albedo.view(), l.view(), 20.0, mirror.view(), 5).is_ok());
    assert_err!(
        shade(albedo.view(), l.view(), -1.0, mirror.view(), 5),
        InvalidParameter {
            name: "phong exponent",
            ..
        },
        "-1 (expected 0 to 10000)"
    );
    assert_err!(
        shade(albedo.view(), l.view(), f64::NAN, mirror.view(), 5),
        InvalidParameter {
            name: "phong exponent",
            ..
        },
        "NaN (expected 0 to 10000)"
    );
    assert_err!(
        shade(
            albedo.view(),
            l.view(),
            20.0,
            mirror.slice(ndarray::s![1.., ..]),
            5
        ),
        InvalidShape { .. },
        "the mirror directions must be (5, 3)"
    );
    let mut long = mirror.clone();
    long[[3, 1]] *= 1.01;
    assert_err!(
        shade(albedo.view(), l.view(), 20.0, long.view(), 5),
        InvalidParameter {
            name: "mirror direction",
            ..
        },
        "vertex 3 has length",
        "(must be a unit vector)"
    );
    let mut nan = mirror.clone();
    nan[[2, 0]] = f64::NAN;
    assert_err!(
        shade(albedo.view(), l.view(), 20.0, nan.view(), 5),
        NonFinite { .. },
        "at index [2, 0]"
    );
    let mut bad_light = l.clone();
    bad_light[[4, 2]] = f64::INFINITY;
    assert_err!(
        shade(albedo.view(), bad_light.view(), 20.0, mirror.view(), 5),
        NonFinite { .. },
        "at index [4, 2]"
    );
    let mut bad_albedo = albedo.clone();
    bad_albedo[[1, 1]] = f32::NAN;
    assert_err!(
        shade(bad_albedo.view(), l.view(), 20.0, mirror.view(), 5),
        NonFinite { .. },
        "at index [1, 1]"
    );
    assert_err!(
        shade(
            albedo.view(),
            l.slice(ndarray::s![..4, ..]),
            20.0,
            mirror.view(),
            5
        ),
        InvalidShape { .. },
        "(9, 1) or (9, 3) for 3 bands"
    );
    assert_err!(
        shade(albedo.view(), l.view(), 20.0, mirror.view(), 6),
        InvalidParameter {
            name: "glossy vertices",
            ..
        },
        "6 of 5 vertices"
    );
    assert_err!(
        PhongSh::new(4, 20.0)
            .unwrap()
            .shade(&t, albedo.view(), l.view(), mirror.view(), 5),
        InvalidShape { .. },
        "the transfer has 3 bands, the Phong baseline 4"
    );
    assert_err!(
        PhongSh::new(17, 20.0),
        InvalidParameter {
            name: "sh-bands",
            ..
        },
        "17: transfer takes 1 to 16 bands"
    );
    let refusal = non_zonal_material("blinn:50");
    assert_eq!(
        refusal.to_string(),
        "invalid basis: sh shades zonal lobes only (lambert, phong:EXP), not blinn:50; use --basis haar"
    );
}
