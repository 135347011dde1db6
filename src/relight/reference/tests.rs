use std::f64::consts::PI;

use ndarray::{Array3, array};

use super::*;
use crate::relight::{Generator, SceneBvh, VisibilityOptions, add_ground_plane, vertex_major};
use crate::sphere::{ParamKind, Parameterization};

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
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/testdata/meshes/bunny.ply");
    let mut mesh = Mesh::load(path.as_ref()).unwrap();
    add_ground_plane(&mut mesh);
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
