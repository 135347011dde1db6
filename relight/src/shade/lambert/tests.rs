use std::f64::consts::PI;

use ndarray::{Array2, Array3, Array4, Axis};

use super::*;
use crate::light::downsample::downsample_solid_angle;
use crate::light::environment::Environment;
use crate::test_support::corner_form_factor;
use crate::test_support::latlong;
use crate::{Generator, Mesh, Occlusion, SceneBvh, VisibilityOptions, ray_offset, vertex_major};
use haarshift::faces::integrate::layout;
use haarshift::faces::param::{ParamKind, SphereMap};
use haarshift::metrics::relative_rms_error;
use haarshift::product::{HaarTree, IntegralOptions, product_integral, triple::triple_integral};
use haarshift::sphere::{LatLongMap, SphereRotation};

/// The mesh's transport at `param`, one ray per texel centre, every coefficient kept.
fn precompute(mesh: &Mesh, param: Parameterization) -> TransportSet {
    let options = VisibilityOptions::new(param);
    vertex_major(mesh, &SceneBvh::new(mesh), &options)
        .unwrap()
        .0
}

/// The shared test environment (Rooitou Park, 256 x 128).
fn park() -> Environment {
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../testdata/envmaps/rooitou_park_256x128.npy"
    );
    Environment::load(path.as_ref()).unwrap()
}

fn constant_lighting(param: Parameterization, radiance: f64) -> Lighting {
    let map = SphereMap::<f64>::from_fn(param, 1, |_, o| o[0] = radiance).unwrap();
    Lighting::from_map(&map, Selection::All).unwrap()
}

/// A per-vertex albedo that varies over vertices and channels.
fn varied_albedo(vertices: usize) -> Array2<f32> {
    Array2::from_shape_fn((vertices, 3), |(v, c)| {
        0.2 + 0.6 * ((v * 7 + c * 3) % 11) as f32 / 10.0
    })
}

fn grey(vertices: usize, a: f32) -> Array2<f32> {
    Array2::from_elem((vertices, 3), a)
}

/// `integral over a lat-long texel of w dOmega`, closed form (`w = (sin t sin p, cos t,
/// sin t cos p)`, `dOmega = sin t dt dp`).
fn texel_moment(n: usize, row: usize, col: usize) -> [f64; 3] {
    let step = PI / n as f64;
    let (t0, t1) = (row as f64 * step, (row + 1) as f64 * step);
    let (p0, p1) = (col as f64 * step, (col + 1) as f64 * step);
    let sin2 = |t: f64| t / 2.0 - (2.0 * t).sin() / 4.0; // an antiderivative of sin^2
    [
        (sin2(t1) - sin2(t0)) * (p0.cos() - p1.cos()),
        0.5 * (t1.sin().powi(2) - t0.sin().powi(2)) * (p1 - p0),
        (sin2(t1) - sin2(t0)) * (p1.sin() - p0.sin()),
    ]
}

fn dot3(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// A bound on `|sum_t max(0, n . w_t) dOmega_t - pi|`, the cosine lobe's midpoint quadrature
/// at lat-long `n x 2n`: a texel wholly above the horizon (`n . w_t > d_t`, `d_t` the largest
/// distance from its centre to its corners, which bounds `|w - w_t|` on it) errs by exactly
/// `n . (M_t - w_t dOmega_t)` (`M_t` its closed-form moment); one wholly below errs by 0; one
/// that may straddle the horizon errs by at most `d_t dOmega_t` (`max(0, .)` is 1-Lipschitz).
fn cosine_quadrature_bound(n: usize, normal: [f64; 3]) -> f64 {
    let param = latlong(n);
    let step = PI / n as f64;
    let (mut above, mut straddling) = (0.0, 0.0);
    for row in 0..n {
        for col in 0..2 * n {
            let w = param.texel_direction(col / n, row, col % n);
            let omega = param.texel_solid_angle(0, row, 0);
            let d = [(0, 0), (0, 1), (1, 0), (1, 1)]
                .iter()
                .map(|&(a, b)| {
                    let corner = haarshift::sphere::latlong::direction(
                        (row + a) as f64 * step,
                        (col + b) as f64 * step,
                    );
                    let e = [corner[0] - w[0], corner[1] - w[1], corner[2] - w[2]];
                    dot3(e, e).sqrt()
                })
                .fold(0.0, f64::max);
            let c = dot3(normal, w);
            if c > d {
                let m = texel_moment(n, row, col);
                above += dot3(normal, m) - c * omega;
            } else if c >= -d {
                straddling += d * omega;
            }
        }
    }
    above.abs() + straddling
}

#[test]
fn an_unoccluded_sphere_returns_its_albedo() {
    let mesh = Generator::Sphere { cells: 8 }.mesh().unwrap();
    let a = 0.6f32;
    for n in [16, 32] {
        let param = latlong(n);
        let set = precompute(&mesh, param);
        let b = shade_lambertian::<f64>(
            &set,
            grey(mesh.vertex_count(), a).view(),
            &constant_lighting(param, 1.0),
            &ShadeOptions::default(),
        )
        .unwrap();
        let (mut worst, mut worst_ratio) = (0.0f64, 0.0f64);
        for v in 0..mesh.vertex_count() {
            let normal = std::array::from_fn(|k| mesh.normals()[[v, k]]);
            // The transport is f32: 1e-6 a covers its rounding.
            let bound = f64::from(a) / PI * cosine_quadrature_bound(n, normal) + 1e-6;
            for c in 0..3 {
                let err = (b[[v, c]] - f64::from(a)).abs();
                assert!(
                    err <= bound,
                    "N = {n}, vertex {v}: {} vs {a}, bound {bound:e}",
                    b[[v, c]]
                );
                worst = worst.max(err);
                worst_ratio = worst_ratio.max(err / bound);
            }
        }
        eprintln!("sphere N = {n}: worst error {worst:.3e}, at most {worst_ratio:.3} of its bound");
    }
}

#[test]
fn a_point_under_a_floating_box_sees_one_minus_the_form_factor() {
    let height = 1.0;
    let mesh = Generator::PlaneUnderBox { height }.mesh().unwrap();
    let v = 4;
    assert_eq!(mesh.positions().row(v).to_vec(), vec![0.0; 3]);
    assert_eq!(mesh.normals().row(v).to_vec(), vec![0.0, 1.0, 0.0]);
    // The ray origin is offset 1e-4 x the diagonal up the normal: the box is that much nearer.
    let c = height - ray_offset(&mesh);
    // The 2 x 2 bottom face, centred over the point: four 1 x 1 rectangles with a corner there.
    let f = 4.0 * corner_form_factor(1.0, 1.0, c);
    let a = 0.7;
    let want = a * (1.0 - f);
    let mut errors = Vec::new();
    for n in [16, 32, 64, 128] {
        let param = latlong(n);
        let set = precompute(&mesh, param);
        let b = shade_lambertian::<f64>(
            &set,
            grey(mesh.vertex_count(), a as f32).view(),
            &constant_lighting(param, 1.0),
            &ShadeOptions::default(),
        )
        .unwrap();
        let err = (b[[v, 0]] - want).abs();
        eprintln!(
            "box N = {n}: {} vs {want} (F = {f}), error {err:.3e}",
            b[[v, 0]]
        );
        errors.push(err);
    }
    // Centre sampling decides each texel on the box's silhouette wholly in or out: O(1/N)
    // texels of solid angle O(1/N^2), an error O(1/N). Measured (lat-long 16 to 128):
    // 6.2e-3, 3.8e-3, 2.1e-3, 4.0e-4, i.e. error x N at most 0.131; the bound 0.15 / N is
    // 1.15 x that and halves per doubling. Successive ratios measured 1.64, 1.85, 5.09.
    for (n, err) in [16, 32, 64, 128].iter().zip(&errors) {
        assert!(*err <= 0.15 / *n as f64, "N = {n}: error {err:e}");
    }
    for (n, pair) in [16, 32, 64].iter().zip(errors.windows(2)) {
        let ratio = pair[0] / pair[1];
        eprintln!("box error ratio {n} -> {}: {ratio:.2}", 2 * n);
        assert!(
            ratio > 1.5,
            "{n} -> {}: the error shrank by only {ratio}",
            2 * n
        );
    }
}

/// Channel `c` of the lighting as a one-channel f32 tree, for the general product integrals.
fn channel_tree(light: &Lighting, c: usize) -> HaarTree<f32, 1> {
    let p = light.param();
    let s = p.face_size();
    let column = light.coefficients().column(c).to_owned();
    let faces = column.into_shape_with_order((p.faces(), s, s, 1)).unwrap();
    HaarTree::from_coefficients(faces.view(), layout(p), Selection::Threshold(0.0)).unwrap()
}

#[test]
fn full_coefficients_equal_the_pixel_quadrature() {
    let mesh = Generator::PlaneWithSphere {}.mesh().unwrap();
    let vertices = mesh.vertex_count();
    let albedo = varied_albedo(vertices);
    let bvh = SceneBvh::new(&mesh);
    let eps = ray_offset(&mesh);
    let env = park();
    for param in [
        latlong(16),
        Parameterization::new(ParamKind::Cube, 8).unwrap(),
    ] {
        let map = env.sphere_map(param, &SphereRotation::identity()).unwrap();
        let l = map.as_array();
        let s = param.face_size();
        // albedo / pi x sum_t L(t) V(v, t) max(0, n . w_t) dOmega_t, one ray per texel centre
        // from the offset origin, in f64.
        let mut want = Array2::<f64>::zeros((vertices, 3));
        for v in 0..vertices {
            let n: [f64; 3] = std::array::from_fn(|k| mesh.normals()[[v, k]]);
            let origin = std::array::from_fn(|k| (mesh.positions()[[v, k]] + eps * n[k]) as f32);
            for t in 0..param.texels() {
                let (f, r, c) = (t / (s * s), (t / s) % s, t % s);
                let w = param.texel_direction(f, r, c);
                let cos = dot3(n, w);
                if cos <= 0.0 || bvh.occluded(origin, w.map(|x| x as f32), f32::INFINITY) {
                    continue;
                }
                let weight = cos * param.texel_solid_angle(f, r, c);
                for ch in 0..3 {
                    want[[v, ch]] += l[[f, r, c, ch]] * weight;
                }
            }
            for ch in 0..3 {
                want[[v, ch]] *= f64::from(albedo[[v, ch]]) / PI;
            }
        }
        let set = precompute(&mesh, param);
        let light = Lighting::from_map(&map, Selection::All).unwrap();
        let options = ShadeOptions::default();
        let in_f64 = shade_lambertian::<f64>(&set, albedo.view(), &light, &options).unwrap();
        let in_f32 = shade_lambertian::<f32>(&set, albedo.view(), &light, &options).unwrap();
        let e64 = relative_rms_error(in_f64.view(), want.view()).unwrap();
        let e32 = relative_rms_error(in_f32.mapv(f64::from).view(), want.view()).unwrap();
        eprintln!(
            "{} {s}: relative RMS error f64 {e64:.2e}, f32 {e32:.2e}",
            param.kind()
        );
        // Measured 1e-7 to 2e-7 (the transport is stored in f32): the bound is 5 to 10 x that.
        assert!(
            e64 < 1e-6 && e32 < 1e-6,
            "{} {s}: {e64:e}, {e32:e}",
            param.kind()
        );
    }
}

#[test]
fn a_whole_column_yaw_equals_the_shifted_map_and_a_fractional_one_does_not() {
    let mesh = Generator::PlaneWithSphere {}.mesh().unwrap();
    let albedo = varied_albedo(mesh.vertex_count());
    let n = 16;
    let param = latlong(n);
    let set = precompute(&mesh, param);
    let prepared =
        PreparedTransport::<f64>::new(&set, albedo.view(), &ShadeOptions::default()).unwrap();
    let env = park();
    let base = downsample_solid_angle(env.map(), n).unwrap();
    let column = 360.0 / (2 * n) as f64;
    for (k, keep) in [
        (1, Selection::All),
        (5, Selection::Largest(50)),
        (21, Selection::All),
    ] {
        // Turning by k columns: texel (i, j) of the result is texel (i, j + k) of the source.
        let shifted = Array3::from_shape_fn((n, 2 * n, 3), |(i, j, c)| {
            base.as_array()[[i, (j + k) % (2 * n), c]]
        });
        let shifted = SphereMap::from_lat_long(&LatLongMap::new(shifted).unwrap()).unwrap();
        let want = prepared
            .shade(&Lighting::from_map(&shifted, keep).unwrap())
            .unwrap();
        let scale = want.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        let render = |columns: f64| {
            let yaw = SphereRotation::from_degrees(columns * column, 0.0, 0.0).unwrap();
            prepared
                .shade(&Lighting::new(&env, param, &yaw, keep).unwrap())
                .unwrap()
        };
        let whole = render(k as f64);
        let worst = (&whole - &want).iter().fold(0.0f64, |m, v| m.max(v.abs()));
        assert!(
            worst <= 1e-12 * scale,
            "{k} columns: {worst:e} of {scale:e}"
        );
        // Half a column more is another lighting: measured 0.15 relative RMS (worst above: 0).
        let half = relative_rms_error(render(k as f64 + 0.5).view(), want.view()).unwrap();
        eprintln!("yaw {k} columns: worst {worst:.1e}; {k}.5 columns: {half:.2e}");
        assert!(half > 1e-3, "{k}.5 columns: {half:e}");
    }
}

fn sci(values: &[f64]) -> String {
    let v: Vec<String> = values.iter().map(|e| format!("{e:.2e}")).collect();
    v.join(", ")
}

/// Errors against the full-coefficient render, for each `K`.
fn truncation_errors(ks: &[usize], render: impl Fn(Selection) -> Array2<f64>) -> Vec<f64> {
    let full = render(Selection::All);
    ks.iter()
        .map(|&k| relative_rms_error(render(Selection::Largest(k)).view(), full.view()).unwrap())
        .collect()
}

#[test]
fn the_error_shrinks_as_more_coefficients_are_kept_and_vanishes_at_all() {
    let mesh = Generator::PlaneWithSphere {}.mesh().unwrap();
    let albedo = varied_albedo(mesh.vertex_count());
    let param = latlong(16);
    let set = precompute(&mesh, param);
    let env = park();
    let identity = SphereRotation::identity();
    let details = param.texels() - param.faces();
    let ks = [4, 16, 64, 256, details];
    let full_light = Lighting::new(&env, param, &identity, Selection::All).unwrap();
    let by_light = truncation_errors(&ks, |keep| {
        let light = Lighting::new(&env, param, &identity, keep).unwrap();
        shade_lambertian::<f64>(&set, albedo.view(), &light, &ShadeOptions::default()).unwrap()
    });
    let by_visibility = truncation_errors(&ks, |keep| {
        let options = ShadeOptions {
            keep_visibility: Some(keep),
            ..ShadeOptions::default()
        };
        shade_lambertian::<f64>(&set, albedo.view(), &full_light, &options).unwrap()
    });
    for (what, errors) in [("light", &by_light), ("visibility", &by_visibility)] {
        eprintln!("keep {what} {ks:?}: {}", sci(errors));
        assert!(
            errors.windows(2).all(|w| w[1] < w[0]),
            "{what}: {errors:?} does not shrink"
        );
        assert_eq!(errors[ks.len() - 1], 0.0, "{what}: every detail kept");
        assert!(
            errors[0] > 1e-2,
            "{what}: 4 coefficients cannot be that close"
        );
    }
}

#[test]
fn depth_limits_match_the_product_integral_and_the_face_means() {
    let mesh = Generator::PlaneWithSphere {}.mesh().unwrap();
    let vertices = mesh.vertex_count();
    let albedo = varied_albedo(vertices);
    let param = latlong(16);
    let levels = 4;
    let set = precompute(&mesh, param);
    let map = park()
        .sphere_map(param, &SphereRotation::identity())
        .unwrap();
    let light = Lighting::from_map(&map, Selection::Largest(100)).unwrap();
    let render = |depth| {
        let options = ShadeOptions {
            depth,
            ..ShadeOptions::default()
        };
        shade_lambertian::<f64>(&set, albedo.view(), &light, &options).unwrap()
    };
    assert_eq!(render(Some(levels)), render(None));
    // Depth 0: albedo / pi x sum over faces of S^2 x mean(T_v) x mean(L), from the pixels.
    let s2 = (param.face_size() * param.face_size()) as f64;
    let l = map.as_array();
    let light_sums: Vec<[f64; 3]> = (0..param.faces())
        .map(|f| std::array::from_fn(|c| l.index_axis(Axis(0), f).index_axis(Axis(2), c).sum()))
        .collect();
    let coarse = render(Some(0));
    let mut want = Array2::<f64>::zeros((vertices, 3));
    for v in 0..vertices {
        let t: Array4<f32> = set.transport(v).unwrap().tree().to_pixels().unwrap();
        for (f, sums) in light_sums.iter().enumerate() {
            let t_sum: f64 = t.index_axis(Axis(0), f).iter().map(|&x| f64::from(x)).sum();
            for c in 0..3 {
                want[[v, c]] += f64::from(albedo[[v, c]]) / PI * t_sum * sums[c] / s2;
            }
        }
    }
    let e0 = relative_rms_error(coarse.view(), want.view()).unwrap();
    assert!(e0 < 1e-6, "depth 0: {e0:e}");
    // Every depth against the general traversal with finest_level = depth - 1, on every
    // 40th vertex.
    let trees: Vec<HaarTree<f32, 1>> = (0..3).map(|c| channel_tree(&light, c)).collect();
    for depth in 1..=levels {
        let got = render(Some(depth));
        let options = IntegralOptions {
            finest_level: Some(depth - 1),
        };
        let (mut worst, mut scale) = (0.0f64, 0.0f64);
        for v in (0..vertices).step_by(40) {
            let t = set.transport(v).unwrap();
            for (c, tree) in trees.iter().enumerate() {
                let i = product_integral(&t, &[tree], options).unwrap().value[0];
                let want = f64::from(albedo[[v, c]]) / PI * i;
                worst = worst.max((got[[v, c]] - want).abs());
                scale = scale.max(want.abs());
            }
        }
        eprintln!("depth {depth}: worst {:.2e} of the largest", worst / scale);
        assert!(
            worst < 1e-6 * scale,
            "depth {depth}: {worst:e} of {scale:e}"
        );
    }
    // A depth limit is not a no-op here: measured 0.62, 0.69, 0.60, 0.22 relative RMS from
    // the full integral at depths 0 to 3 (not monotone: averaging both factors can cancel).
    let full = render(None);
    for d in 0..levels {
        let e = relative_rms_error(render(Some(d)).view(), full.view()).unwrap();
        assert!(e > 0.1, "depth {d}: {e:e}");
    }
}

#[test]
fn retruncation_keeps_what_transport_select_keeps() {
    let mesh = Generator::PlaneUnderBox { height: 1.0 }.mesh().unwrap();
    let albedo = grey(mesh.vertex_count(), 0.5);
    for param in [
        latlong(8),
        Parameterization::new(ParamKind::Cube, 4).unwrap(),
    ] {
        let set = precompute(&mesh, param);
        for keep in [
            Selection::Largest(5),
            Selection::Largest(40),
            Selection::LargestPerFace(2),
            Selection::Threshold(2e-3),
        ] {
            let options = ShadeOptions {
                keep_visibility: Some(keep),
                ..ShadeOptions::default()
            };
            let prepared = PreparedTransport::<f32>::new(&set, albedo.view(), &options).unwrap();
            for v in 0..mesh.vertex_count() {
                let want = set.transport(v).unwrap().select(keep).unwrap();
                let want: Vec<(u32, f32)> = want
                    .tree()
                    .to_coefficients()
                    .iter()
                    .enumerate()
                    .filter(|(_, c)| **c != 0.0)
                    .map(|(i, &c)| (i as u32, c))
                    .collect();
                let (i, c) = prepared.coefficients(v);
                let got: Vec<(u32, f32)> = i.iter().copied().zip(c.iter().copied()).collect();
                assert_eq!(got, want, "{} {keep:?}, vertex {v}", param.kind());
            }
        }
    }
}

#[test]
fn lambert_is_the_triple_product_with_a_constant_brdf() {
    let mesh = Generator::PlaneUnderBox { height: 1.0 }.mesh().unwrap();
    let albedo = varied_albedo(mesh.vertex_count());
    let param = latlong(8);
    let set = precompute(&mesh, param);
    let light = Lighting::new(&park(), param, &SphereRotation::identity(), Selection::All).unwrap();
    let got =
        shade_lambertian::<f64>(&set, albedo.view(), &light, &ShadeOptions::default()).unwrap();
    let trees: Vec<HaarTree<f32, 1>> = (0..3).map(|c| channel_tree(&light, c)).collect();
    let s = param.face_size();
    let (mut worst, mut scale) = (0.0f64, 0.0f64);
    for v in 0..mesh.vertex_count() {
        let t = set.transport(v).unwrap();
        for (c, tree) in trees.iter().enumerate() {
            let rho = Array4::from_elem((2, s, s, 1), albedo[[v, c]] / std::f32::consts::PI);
            let rho = HaarTree::from_pixels(rho.view(), layout(param), Selection::Threshold(0.0))
                .unwrap();
            assert_eq!(rho.kept(), 0);
            let want = triple_integral(&t, tree, &rho).unwrap().value[0];
            worst = worst.max((got[[v, c]] - want).abs());
            scale = scale.max(want.abs());
        }
    }
    assert!(worst < 1e-6 * scale, "{worst:e} of {scale:e}");
}

#[test]
fn mismatches_are_one_line_errors() {
    let param = latlong(4);
    let mut set = TransportSet::new(param, Selection::All);
    set.push(Array3::ones((2, 4, 4)).view()).unwrap();
    let light = constant_lighting(param, 1.0);
    let one = grey(1, 0.5);
    let options = ShadeOptions::default();
    let message = |e: crate::Error| {
        let m = e.to_string();
        assert!(!m.contains('\n'), "{m}");
        m
    };
    let e = shade_lambertian::<f32>(&set, grey(2, 0.5).view(), &light, &options).unwrap_err();
    assert!(matches!(
        e,
        Error::Core(haarshift::Error::InvalidShape { .. })
    ));
    assert!(message(e).contains("must be (1, 3)"));
    let cube = constant_lighting(Parameterization::new(ParamKind::Cube, 4).unwrap(), 1.0);
    let e = shade_lambertian::<f32>(&set, one.view(), &cube, &options).unwrap_err();
    assert!(matches!(
        e,
        Error::Core(haarshift::Error::InvalidParameter {
            name: "lighting",
            ..
        })
    ));
    assert!(message(e).contains("cube 4 map but the transport was precomputed at latlong 4"));
    let bad = [
        (
            "depth",
            ShadeOptions {
                depth: Some(3),
                ..options
            },
        ),
        (
            "keep",
            ShadeOptions {
                keep_visibility: Some(Selection::Largest(31)),
                ..options
            },
        ),
        (
            "keep",
            ShadeOptions {
                keep_visibility: Some(Selection::LargestPerFace(16)),
                ..options
            },
        ),
        (
            "threshold",
            ShadeOptions {
                keep_visibility: Some(Selection::Threshold(-1.0)),
                ..options
            },
        ),
    ];
    for (name, o) in bad {
        let e = shade_lambertian::<f32>(&set, one.view(), &light, &o).unwrap_err();
        assert!(
            matches!(&e, Error::Core(haarshift::Error::InvalidParameter { name: n, .. }) if *n == name),
            "{e}"
        );
        message(e);
    }
    let e = shade_lambertian::<f32>(&set, grey(1, -0.5).view(), &light, &options).unwrap_err();
    assert!(message(e).contains("-0.5 at vertex 0"));
    let two = SphereMap::<f64>::from_fn(param, 2, |_, o| o.fill(1.0)).unwrap();
    let e = Lighting::from_map(&two, Selection::All).unwrap_err();
    assert!(message(e).contains("2 channels"));
    // Every detail of the 2 x 16 texels may be kept, no more.
    assert_err!(
        Lighting::from_map(
            &SphereMap::from_fn(param, 1, |_, o| o[0] = 1.0).unwrap(),
            Selection::Largest(31)
        ),
        InvalidParameter { name: "keep", .. },
        "only 30 details"
    );
}

#[test]
fn a_mapped_cache_shades_in_place_and_equal_to_the_transport_in_memory() {
    use crate::{CacheParams, KeepRecord, SceneCache};
    let mesh = Generator::Sphere { cells: 3 }.mesh().unwrap();
    let param = latlong(8);
    let set = precompute(&mesh, param);
    let albedo = varied_albedo(mesh.vertex_count());
    let params = CacheParams {
        param: "latlong".into(),
        resolution: 8,
        keep: KeepRecord::All,
        samples: 1,
        seed: 0,
        order: "vertex".into(),
        map_size: None,
        ground_plane: false,
        ground_cells: None,
        sh_bands: None,
        ray_tracer: Some("packets".into()),
        bounces: 0,
        refine: None,
    };
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("ball.hsr");
    SceneCache::new(params, mesh, albedo.clone(), set.clone())
        .unwrap()
        .write(&path, false)
        .unwrap();
    let read = SceneCache::read(&path).unwrap();
    let sky = park()
        .sphere_map(param, &SphereRotation::identity())
        .unwrap();
    let light = Lighting::from_map(&sky, Selection::All).unwrap();
    let little = cfg!(target_endian = "little");
    let in_place =
        PreparedTransport::<f32>::new(&read.transport, albedo.view(), &ShadeOptions::default())
            .unwrap();
    assert_eq!(in_place.is_mapped(), little, "f32 as stored: no copy");
    let in_memory =
        PreparedTransport::<f32>::new(&set, albedo.view(), &ShadeOptions::default()).unwrap();
    assert!(!in_memory.is_mapped());
    assert_eq!(
        in_place.shade(&light).unwrap(),
        in_memory.shade(&light).unwrap()
    );
    // Anything that changes the coefficients makes its own copy.
    let depth = ShadeOptions {
        depth: Some(2),
        ..ShadeOptions::default()
    };
    assert!(
        !PreparedTransport::<f32>::new(&read.transport, albedo.view(), &depth)
            .unwrap()
            .is_mapped()
    );
    assert!(
        !PreparedTransport::<f64>::new(&read.transport, albedo.view(), &ShadeOptions::default())
            .unwrap()
            .is_mapped()
    );
}

proptest::proptest! {
    /// A truncated lighting's rows gathered through the byte table, or only its lit terms
    /// visited, give the dense rows' sums, bit for bit; a lighting of 255 non-zero rows or more
    /// stays dense.
    #[test]
    fn compact_light_rows_give_the_dense_rows_sums_bit_for_bit(
        keep in 1usize..400,
        terms in proptest::collection::vec((0u32..4096, -1e3f32..1e3f32), 0..300),
    ) {
        let param = Parameterization::new(ParamKind::Cube, 16).unwrap();
        let map = SphereMap::<f64>::from_fn(param, 3, |d, out| {
            out.copy_from_slice(&[1.0 + d[0] * d[1], (3.0 * d[2]).sin() + 1.5, d[1].exp()]);
        })
        .unwrap();
        let lighting = Lighting::from_map(&map, Selection::Largest(keep)).unwrap();
        let rows = LightRows::<f32>::new(&lighting);
        let compact = matches!(rows, LightRows::Compact { .. });
        proptest::prop_assert_eq!(compact, lighting.kept() + param.faces() < 256);
        let dense = LightRows::<f32>::Dense(lighting.quads::<f32>());
        let (indices, values): (Vec<u32>, Vec<f32>) = terms.into_iter().unzip();
        let sum = |r: &LightRows<f32>| {
            r.gather(&indices, &values, |i| i as usize, |t| t).map(f64::to_bits)
        };
        proptest::prop_assert_eq!(sum(&rows), sum(&dense));
        // Visiting only the lit terms changes no bit either, in f32 and in f64 (the buffer
        // kept dirty from a longer vertex, as the frame keeps it).
        let mut buffers = DotBuffers::default();
        rows.dot(&[7; 400], &[1.5; 400], &mut buffers);
        let dot = rows.dot(&indices, &values, &mut buffers).map(f64::to_bits);
        proptest::prop_assert_eq!(dot, sum(&dense));
        let values64: Vec<f64> = values.iter().map(|&x| f64::from(x) * 1.1).collect();
        let rows64 = LightRows::<f64>::new(&lighting);
        let dense64 = LightRows::<f64>::Dense(lighting.quads::<f64>());
        proptest::prop_assert_eq!(
            rows64.dot(&indices, &values64, &mut DotBuffers::default()).map(f64::to_bits),
            dense64.gather(&indices, &values64, |i| i as usize, |t| t).map(f64::to_bits)
        );
    }
}
