use std::f64::consts::{FRAC_PI_2, PI};

use ndarray::{Array3, array};

use super::*;
use crate::{Generator, SceneBvh, VisibilityOptions, add_ground_plane, vertex_major};
use haarshift::faces::{ParamKind, Parameterization};

fn constant(n: usize, value: f64) -> LatLongMap<f64> {
    LatLongMap::from_fn(n, 1, |_, o| o[0] = value).unwrap()
}

fn run(mesh: &Mesh, albedo: ArrayView2<'_, f32>, lighting: &LatLongMap<f64>) -> Array2<f64> {
    let options = ReferenceOptions::default();
    reference(mesh, &SceneBvh::new(mesh), albedo, lighting, &options)
        .unwrap()
        .0
}

/// The lat-long midpoint quadrature of `int max(0, n . w) dOmega / pi` (1 exactly) for the
/// normal of every vertex: what an unoccluded vertex reflects per unit albedo.
fn open_quadrature(mesh: &Mesh, n: usize) -> Vec<f64> {
    (0..mesh.vertex_count())
        .map(|v| {
            let normal = [0, 1, 2].map(|k| mesh.normals()[[v, k]]);
            let mut sum = 0.0;
            for i in 0..n {
                for j in 0..2 * n {
                    let (t, p) = pixel_centre(n, i, j);
                    sum += dot(normal, direction(t, p)).max(0.0) * pixel_solid_angle(n, i);
                }
            }
            sum / PI
        })
        .collect()
}

#[test]
fn a_sphere_under_constant_lighting_reflects_its_albedo() {
    let cells = 12;
    let mesh = Generator::Sphere { cells }.mesh().unwrap();
    let albedo = Array2::from_shape_fn((mesh.vertex_count(), 3), |(_, c)| [0.2f32, 0.5, 0.9][c]);
    // The facets meet at angles up to delta (a cube-sphere cell spans at most ~pi/2 / cells),
    // so a ray within delta of the tangent plane may hit the neighbouring facet: it loses at
    // most the cosine-weighted solid angle of that band, int_{cos < delta} cos = pi delta^2,
    // i.e. delta^2 of the whole. So per unit albedo, each vertex lies between its open
    // quadrature q minus delta^2 and q, and q within the quadrature error of 1.
    let delta = PI / 2.0 / cells as f64;
    let mut errors = Vec::new();
    for n in [32, 64] {
        let r = run(&mesh, albedo.view(), &constant(n, 1.0));
        let open = open_quadrature(&mesh, n);
        let mut worst = 0.0f64;
        for (v, q) in open.iter().enumerate() {
            for c in 0..3 {
                let got = r[[v, c]] / f64::from(albedo[[v, c]]);
                assert!(
                    got <= q * (1.0 + 1e-12) && got >= q - delta * delta,
                    "N = {n}, vertex {v}: {got} against {q}"
                );
                worst = worst.max((got - 1.0).abs());
            }
        }
        errors.push(worst);
    }
    // Measured: 1.2e-3 at N = 32, 3.0e-4 at 64 (no grazing ray is blocked here): the
    // quadrature's second order.
    assert!(
        errors[1] < 5e-4 && errors[1] < 0.3 * errors[0],
        "{errors:?}"
    );
}

/// A polar cap of radiance 1 around +Y, out to the polar angle `cap`, as the solid-angle mean
/// over each texel of an `n x 2n` map (what the weighted downsample of an ever finer map gives).
fn cap_map(n: usize, cap: f64) -> LatLongMap<f64> {
    let step = PI / n as f64;
    LatLongMap::new(Array3::from_shape_fn((n, 2 * n, 1), |(i, _, _)| {
        let (a, b) = (i as f64 * step, (i + 1) as f64 * step);
        if a >= cap {
            0.0
        } else {
            (a.cos() - b.min(cap).cos()) / (a.cos() - b.cos())
        }
    }))
    .unwrap()
}

#[test]
fn an_upward_vertex_under_a_polar_cap_matches_the_closed_form() {
    // An open square: nothing above it, normals +Y.
    let mesh = Mesh::new(
        array![
            [-1.0, 0.0, -1.0],
            [1.0, 0.0, -1.0],
            [1.0, 0.0, 1.0],
            [-1.0, 0.0, 1.0]
        ],
        vec![[0, 2, 1], [0, 3, 2]],
        None,
    )
    .unwrap();
    assert_eq!(mesh.normals().row(0).to_vec(), vec![0.0, 1.0, 0.0]);
    let albedo = Array2::from_elem((4, 3), 0.8f32);
    let cap: f64 = 1.0; // radians: not on a row edge of any of the resolutions
    // int_cap cos dOmega = pi sin^2(cap), so R = albedo sin^2(cap).
    let exact = 0.8 * cap.sin().powi(2);
    let mut errors = Vec::new();
    for n in [8, 16, 32, 64, 128] {
        let r = run(&mesh, albedo.view(), &cap_map(n, cap));
        let error = (r[[0, 1]] - exact).abs();
        // The map holds each texel's exact mean, so the only error is the cosine taken at the
        // row's centre: |cos theta - cos theta_c| <= step / 2, times the cap's solid angle.
        let step = PI / n as f64;
        let bound = 0.8 / PI * step / 2.0 * 2.0 * PI * (1.0 - cap.cos());
        assert!(error <= bound, "N = {n}: {error:e} above {bound:e}");
        errors.push(error);
    }
    // The midpoint rule does better than its first-order bound (measured: 1.0e-2 at N = 8,
    // 2.2e-5 at 128; not monotone, it depends on where the cap's edge cuts its row).
    assert!(errors[4] < errors[0] / 100.0, "{errors:?}");
}

#[test]
fn the_haar_transport_at_full_coefficients_agrees() {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../testdata/meshes/bunny.ply");
    let mut mesh = Mesh::load(path.as_ref()).unwrap();
    add_ground_plane(&mut mesh).unwrap();
    let n = 16;
    let lighting = LatLongMap::<f64>::from_fn(n, 3, |d, o| {
        let sun = (8.0 * (d[0] * 0.6 + d[1] * 0.8 - 1.0)).exp();
        o.copy_from_slice(&[1.0 + 20.0 * sun, 0.5 + d[2].abs(), 0.2 + 10.0 * sun]);
    })
    .unwrap();
    let albedo = Array2::from_shape_fn((mesh.vertex_count(), 3), |(v, c)| {
        0.3 + 0.1 * ((v * 7 + c) % 5) as f32
    });
    let bvh = SceneBvh::new(&mesh);
    let (r, report) = reference(
        &mesh,
        &bvh,
        albedo.view(),
        &lighting,
        &ReferenceOptions::default(),
    )
    .unwrap();
    let param = Parameterization::new(ParamKind::LatLong, n).unwrap();
    let (set, precompute) = vertex_major(&mesh, &bvh, &VisibilityOptions::new(param)).unwrap();
    assert_eq!(report.rays, precompute.rays); // the lighting is positive everywhere
    // The Haar path in the pixel domain: the transport's pixels (face f, row i, column j is
    // lat-long texel (i, f n + j)) dotted with the lighting.
    let map = lighting.as_array();
    let mut haar = Array2::<f64>::zeros(r.dim());
    for v in 0..mesh.vertex_count() {
        let pixels = set.transport(v).unwrap().tree().to_pixels().unwrap();
        for ((f, i, j, _), &t) in pixels.indexed_iter() {
            for c in 0..3 {
                haar[[v, c]] += f64::from(t) * map[[i, f * n + j, c]];
            }
        }
        for c in 0..3 {
            haar[[v, c]] *= f64::from(albedo[[v, c]]) / PI;
        }
    }
    let rms = (r.iter().map(|x| x * x).sum::<f64>() / r.len() as f64).sqrt();
    let worst = (&haar - &r).iter().fold(0.0f64, |a, d| a.max(d.abs()));
    assert!(worst <= 1e-6 * rms, "{worst:e} of RMS {rms}");
    // Shadows matter here: the scene is not a constant.
    let darkest = r.column(0).iter().cloned().fold(f64::INFINITY, f64::min);
    assert!(darkest < 0.5 * rms, "{darkest} {rms}");
}

#[test]
fn unlit_texels_cast_no_rays_and_bad_input_is_refused() {
    let mesh = Generator::Sphere { cells: 2 }.mesh().unwrap();
    let bvh = SceneBvh::new(&mesh);
    let albedo = Array2::from_elem((mesh.vertex_count(), 3), 1.0f32);
    let options = ReferenceOptions::default();
    let dark = constant(8, 0.0);
    let (r, report) = reference(&mesh, &bvh, albedo.view(), &dark, &options).unwrap();
    assert_eq!((report.rays, r.sum()), (0, 0.0));
    let short = albedo.slice(ndarray::s![1.., ..]);
    assert_err!(
        reference(&mesh, &bvh, short, &constant(8, 1.0), &options),
        InvalidShape { .. },
        "the albedo must be (54, 3)"
    );
    let two = LatLongMap::<f64>::from_fn(8, 2, |_, o| o.fill(1.0)).unwrap();
    assert_err!(
        reference(&mesh, &bvh, albedo.view(), &two, &options),
        InvalidParameter {
            name: "lighting",
            ..
        },
        "2 channels"
    );
}

/// The open square of [`an_upward_vertex_under_a_polar_cap_matches_the_closed_form`]: normals
/// +Y, nothing above it; vertex 0 at `(-1, 0, -1)`.
fn open_square() -> Mesh {
    Mesh::new(
        array![
            [-1.0, 0.0, -1.0],
            [1.0, 0.0, -1.0],
            [1.0, 0.0, 1.0],
            [-1.0, 0.0, 1.0]
        ],
        vec![[0, 2, 1], [0, 3, 2]],
        None,
    )
    .unwrap()
}

fn glossy(brdf: &str, eye: [f64; 3]) -> ReferenceOptions {
    ReferenceOptions {
        brdf: brdf.parse().unwrap(),
        eye: Some(eye),
        ..Default::default()
    }
}

fn run_with(
    mesh: &Mesh,
    albedo: ArrayView2<'_, f32>,
    lighting: &LatLongMap<f64>,
    options: &ReferenceOptions,
) -> Array2<f64> {
    reference(mesh, &SceneBvh::new(mesh), albedo, lighting, options)
        .unwrap()
        .0
}

/// A sky with a sun near `(0.6, 0.8, 0)`, RGB, positive everywhere.
fn sunny_map(n: usize) -> LatLongMap<f64> {
    LatLongMap::<f64>::from_fn(n, 3, |d, o| {
        let sun = (8.0 * (d[0] * 0.6 + d[1] * 0.8 - 1.0)).exp();
        o.copy_from_slice(&[1.0 + 20.0 * sun, 0.5 + d[2].abs(), 0.2 + 10.0 * sun]);
    })
    .unwrap()
}

#[test]
fn phong_zero_is_lambert_with_albedo_one_and_the_ground_stays_lambertian() {
    let mesh = Generator::PlaneUnderBox { height: 1.0 }.mesh().unwrap();
    let ones = Array2::from_elem((mesh.vertex_count(), 3), 1.0f32);
    let lighting = sunny_map(16);
    let eye = [4.0, 3.0, 5.0];
    let lambert = run(&mesh, ones.view(), &lighting);
    let phong0 = run_with(&mesh, ones.view(), &lighting, &glossy("phong:0", eye));
    for (p, l) in phong0.iter().zip(&lambert) {
        assert!((p - l).abs() <= 1e-12 * l.abs(), "{p} vs {l}");
    }
    // Phong 20 on the first 9 vertices (plane_under_box's 3 x 3 ground grid): the box after
    // them stays Lambertian, bit for bit.
    let objects = 9;
    let options = ReferenceOptions {
        object_vertices: Some(objects),
        ..glossy("phong:20", eye)
    };
    let mixed = run_with(&mesh, ones.view(), &lighting, &options);
    assert_eq!(
        mixed.slice(ndarray::s![objects.., ..]),
        lambert.slice(ndarray::s![objects.., ..])
    );
    let changed = (0..objects)
        .filter(|&v| (mixed[[v, 0]] - lambert[[v, 0]]).abs() > 1e-3 * lambert[[v, 0]])
        .count();
    assert_eq!(changed, objects);
}

/// `(e + 2) / (2 pi) x` the integral of `max(0, r . w)^e max(0, n . w)` over the sphere for a
/// mirror direction `theta_r` from the normal, by the midpoint rule in coordinates about `r`
/// (`alpha` from `r`, `beta` about it): `n . w = cos alpha cos theta_r + sin alpha cos beta
/// sin theta_r`. Independent of the lat-long grid and of the BRDF code.
fn phong_about_the_mirror(e: f64, theta_r: f64, steps: usize) -> f64 {
    let (da, db) = (FRAC_PI_2 / steps as f64, 2.0 * PI / steps as f64);
    let mut sum = 0.0;
    for i in 0..steps {
        let a = (i as f64 + 0.5) * da;
        let lobe = a.cos().powf(e) * a.sin();
        for j in 0..steps {
            let b = (j as f64 + 0.5) * db;
            let cos = a.cos() * theta_r.cos() + a.sin() * b.cos() * theta_r.sin();
            sum += lobe * cos.max(0.0);
        }
    }
    (e + 2.0) / (2.0 * PI) * sum * da * db
}

#[test]
fn an_open_glossy_vertex_under_a_constant_sky_matches_the_closed_forms() {
    // Seen from straight above (w_o = r = n): Phong reflects
    // (e + 2) / (2 pi) x int cos^(e+1) dOmega = (e + 2) / (2 pi) x 2 pi / (e + 2) = 1 per unit
    // albedo (the lobe alone integrates to (e + 2) / (e + 1); the cosine takes it to 1).
    // Blinn-Phong: n . h = cos(theta / 2), and with c = cos(theta / 2),
    // int cos^e(theta/2) cos theta dOmega = 8 pi (e + 2^(-e/2)) / ((e + 2)(e + 4)), so it
    // reflects (e + 8)(e + 2^(-e/2)) / ((e + 2)(e + 4)) (1 at e = 0).
    let mesh = open_square();
    let albedo = Array2::from_elem((4, 3), 0.5f32);
    let above = [-1.0, 5.0, -1.0];
    let blinn = |e: f64| (e + 8.0) * (e + 2f64.powf(-e / 2.0)) / ((e + 2.0) * (e + 4.0));
    // An oblique view, 40 degrees from the normal: the independent quadrature about r.
    let theta: f64 = 40f64.to_radians();
    let oblique = [-1.0 + 5.0 * theta.sin(), 5.0 * theta.cos(), -1.0];
    let cases = [
        ("phong:1", above, 1.0),
        ("phong:20", above, 1.0),
        ("blinn:20", above, blinn(20.0)),
        ("blinn:0", above, 1.0),
        (
            "phong:20",
            oblique,
            phong_about_the_mirror(20.0, theta, 2000),
        ),
    ];
    for (brdf, eye, want) in cases {
        let mut errors = Vec::new();
        for n in [32, 64, 128] {
            let r = run_with(&mesh, albedo.view(), &constant(n, 1.0), &glossy(brdf, eye));
            errors.push((r[[0, 1]] / 0.5 - want).abs() / want);
        }
        eprintln!("{brdf} {eye:?}: want {want}, relative errors {errors:?}");
        // The midpoint rule's second order: each doubling divides the error by about 4.
        assert!(
            errors[2] < 1e-3 && errors[2] < 0.4 * errors[0].max(1e-12),
            "{brdf}: {errors:?}"
        );
    }
}

#[test]
fn a_glossy_brdf_without_an_eye_is_refused() {
    let mesh = open_square();
    let albedo = Array2::from_elem((4, 3), 0.5f32);
    let bvh = SceneBvh::new(&mesh);
    let options = ReferenceOptions {
        brdf: "phong:20".parse().unwrap(),
        ..Default::default()
    };
    assert_err!(
        reference(&mesh, &bvh, albedo.view(), &constant(8, 1.0), &options),
        InvalidParameter { name: "eye", .. },
        "phong:20",
        "camera position"
    );
    let options = ReferenceOptions {
        object_vertices: Some(5),
        ..glossy("phong:20", [0.0, 1.0, 0.0])
    };
    assert_err!(
        reference(&mesh, &bvh, albedo.view(), &constant(8, 1.0), &options),
        InvalidParameter {
            name: "object vertices",
            ..
        },
        "4 vertices"
    );
    let options = ReferenceOptions {
        eye: Some([f64::NAN, 0.0, 0.0]),
        ..options
    };
    assert_err!(
        reference(
            &mesh,
            &bvh,
            albedo.view(),
            &constant(8, 1.0),
            &ReferenceOptions {
                object_vertices: None,
                ..options
            }
        ),
        InvalidParameter { name: "eye", .. },
        "finite"
    );
}

#[test]
fn a_merl_table_of_phong_agrees_with_phong_to_its_quantisation() {
    // A MERL lookup returns its bin's lower corner (the reference BRDFRead.cpp rounds every
    // angle down): bins of theta_diff and phi_diff are 1 degree, of theta_half up to 2 degrees
    // (0.95 degree where this Phong 20 lobe falls off). The lobe cos^20 falls by
    // 20 tan(alpha) per radian in relative terms, about 9 % per degree at its half maximum
    // (alpha = 15 degrees): the table is exact at its grid points (the MERL module's tests)
    // and its integrals are a few percent off, more for sharper lobes.
    use crate::material::merl::tests::{phong_table, phong_table_at_centres};
    use std::sync::Arc;
    let mesh = Generator::PlaneUnderBox { height: 1.0 }.mesh().unwrap();
    let albedo = Array2::from_elem((mesh.vertex_count(), 3), 0.7f32);
    let lighting = sunny_map(32);
    let eye = [2.5, 4.0, 3.0];
    let shade = |options: &ReferenceOptions| run_with(&mesh, albedo.view(), &lighting, options);
    // Only vertices that face the eye: seen from below its horizon a measured BRDF is 0 (the
    // table has no such directions) where Phong's formula is not.
    let seen: Vec<usize> = (0..mesh.vertex_count())
        .filter(|&v| {
            (0..3)
                .map(|k| mesh.normals()[[v, k]] * (eye[k] - mesh.positions()[[v, k]]))
                .sum::<f64>()
                > 0.0
        })
        .collect();
    assert!(seen.len() > mesh.vertex_count() / 2, "{}", seen.len());
    let rms = |a: &Array2<f64>| {
        let sum: f64 = seen
            .iter()
            .map(|&v| a.row(v).iter().map(|x| x * x).sum::<f64>())
            .sum();
        (sum / (3 * seen.len()) as f64).sqrt()
    };
    let gap = |a: &Array2<f64>, b: &Array2<f64>| rms(&(a - b)) / rms(b);
    let mut gaps = Vec::new();
    for e in [5.0, 20.0] {
        let phong = shade(&glossy(&format!("phong:{e}"), eye));
        let merl = shade(&ReferenceOptions {
            brdf: Brdf::Measured(Arc::new(phong_table(e))),
            ..glossy("lambert", eye)
        });
        gaps.push(gap(&merl, &phong));
    }
    let phong10 = shade(&glossy("phong:10", eye));
    let phong20 = shade(&glossy("phong:20", eye));
    let other = gap(&phong10, &phong20);
    // The same lookup in a table sampled at its bins' centres: the rounding down's bias gone,
    // what is left is the bins' width.
    let centred = shade(&ReferenceOptions {
        brdf: Brdf::Measured(Arc::new(phong_table_at_centres(20.0))),
        ..glossy("lambert", eye)
    });
    let centred = gap(&centred, &phong20);
    // Measured (relative RMS over the vertices facing the eye): 4.0e-2 for Phong 5, 6.2e-2
    // for Phong 20, against 1.0e-1 between Phong 10 and 20 (and 1.1e-2 between 20 and 22: at
    // this quantisation a table does not tell 20 from 22, it does tell 20 from 10); the
    // table sampled at bin centres, 5.3e-3: the rounding down is most of the gap, the
    // frames and the lookup are right.
    eprintln!(
        "MERL against Phong 5 and 20: {gaps:?}; sampled at bin centres {centred:e}; \
         Phong 10 against 20: {other:e}"
    );
    assert!(
        gaps[1] < 0.08 && gaps[0] < gaps[1] && gaps[1] < 0.75 * other,
        "{gaps:?} {other}"
    );
    assert!(
        centred < 0.01 && centred < 0.15 * gaps[1],
        "{centred} {gaps:?}"
    );
}

/// Cast once, the bits give the reference's quadrature exactly, for every lighting, BRDF and
/// view; a map of another height or another mesh is refused.
#[test]
fn cached_visibility_gives_the_reference_bit_for_bit() {
    let mesh = Generator::PlaneUnderBox { height: 0.5 }.mesh().unwrap();
    let bvh = SceneBvh::new(&mesh);
    let albedo = Array2::from_shape_fn((mesh.vertex_count(), 3), |(v, c)| {
        0.2 + 0.1 * ((v + c) % 4) as f32
    });
    let bits = ReferenceVisibility::new(&mesh, &bvh, 12, false).unwrap();
    assert!(bits.report().rays > 0);
    let shadows = LatLongMap::<f64>::from_fn(12, 3, |d, o| o.fill(0.1 + d[1].max(0.0)));
    for (lighting, options) in [
        (sunny_map(12), ReferenceOptions::default()),
        (sunny_map(12), glossy("phong:30", [2.0, 3.0, 1.0])),
        (shadows.unwrap(), glossy("blinn:8", [-1.0, 2.0, 0.5])),
    ] {
        let options = ReferenceOptions {
            object_vertices: Some(mesh.vertex_count() / 2),
            ..options
        };
        let (want, cast) = reference(&mesh, &bvh, albedo.view(), &lighting, &options).unwrap();
        let (got, report) = bits
            .reference(&mesh, albedo.view(), &lighting, &options)
            .unwrap();
        assert_eq!(got, want);
        assert_eq!((report.rays, cast.rays), (0, bits.report().rays));
    }
    // The box shadows the plane: fewer rays escape than were cast.
    let escaped: u64 = bits.bits.iter().map(|w| u64::from(w.count_ones())).sum();
    assert!(
        escaped > 0 && escaped < bits.report().rays,
        "{escaped} of {}",
        bits.report().rays
    );
    assert_err!(
        bits.reference(
            &mesh,
            albedo.view(),
            &sunny_map(8),
            &ReferenceOptions::default()
        ),
        InvalidParameter {
            name: "reference visibility",
            ..
        },
        "12 x 24 texels"
    );
}
