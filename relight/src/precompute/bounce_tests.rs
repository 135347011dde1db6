use std::f64::consts::PI;

use ndarray::{Array2, array};

use super::*;
use crate::precompute::cast::{RaySet, f32x3};
use crate::precompute::origin::RayOrigins;
use crate::scene::shapes::{cube_sphere, grid, merge};
use crate::{Generator, vertex_major};
use haarshift::faces::{ParamKind, Parameterization};
use haarshift::metrics::relative_rms_error;

fn cube(n: usize) -> Parameterization {
    Parameterization::new(ParamKind::Cube, n).unwrap()
}

/// Vertex `v`'s stored coefficients of `set` as a dense f64 vector.
fn dense_coefficients(set: &TransportSet, v: usize) -> Vec<f64> {
    let mut out = vec![0.0; set.param().texels()];
    let (indices, values) = set.coefficients(v);
    for (&i, &x) in indices.iter().zip(values) {
        out[i as usize] = f64::from(x);
    }
    out
}

/// Vertex `v`'s spherical-harmonic transfer as f64.
fn sh(set: &TransportSet, v: usize) -> Vec<f64> {
    let t = set.sh().unwrap().coefficients();
    t.row(v).iter().map(|&x| f64::from(x)).collect()
}

/// The gather written out independently of the library's: ray by ray, in f64, dense vectors
/// `x[i][c]` (vertex, channel) in, `G(x)[v][c]` out, with the rays of `rays(v)`: (direction,
/// weight `cos x dOmega / S^2`).
fn oracle_gather(
    mesh: &Mesh,
    albedo: &Array2<f32>,
    rays: &dyn Fn(usize) -> Vec<([f32; 3], f64)>,
    x: &[Vec<Vec<f64>>],
) -> Vec<Vec<Vec<f64>>> {
    let bvh = SceneBvh::new(mesh);
    let origins = RayOrigins::new(mesh);
    let normals = mesh.normals();
    let len = x[0][0].len();
    (0..mesh.vertex_count())
        .map(|v| {
            let (o, _) = origins.origin_and_normal(v);
            let mut out = vec![vec![0.0; len]; 3];
            for (d, w) in rays(v) {
                let mut hit = [None];
                bvh.closest_hits_from(f32x3(o), &[d], f32::INFINITY, &mut hit);
                let Some(h) = hit[0] else { continue };
                let tri = mesh.triangles()[h.triangle].map(|i| i as usize);
                let (u, vv) = (f64::from(h.u), f64::from(h.v));
                let beta = [1.0 - u - vv, u, vv];
                // The one-sided rule: the interpolated shading normal faces back along the ray.
                let along: f64 = (0..3)
                    .map(|axis| {
                        let n: f64 = (0..3).map(|k| beta[k] * normals[[tri[k], axis]]).sum();
                        n * f64::from(d[axis])
                    })
                    .sum();
                if along >= 0.0 {
                    continue;
                }
                for ch in 0..3 {
                    let rho: f64 = (0..3)
                        .map(|k| beta[k] * f64::from(albedo[[tri[k], ch]]))
                        .sum();
                    for t in 0..len {
                        let interp: f64 = (0..3).map(|k| beta[k] * x[tri[k]][ch][t]).sum();
                        out[ch][t] += w * rho / PI * interp;
                    }
                }
            }
            out
        })
        .collect()
}

/// Ray `(direction, cos x dOmega / S^2)` of vertex `v` at texel centres (`S = 1`), from the
/// parameterisation directly.
fn centre_rays(mesh: &Mesh, param: Parameterization, v: usize) -> Vec<([f32; 3], f64)> {
    let s = param.face_size();
    let n = [0, 1, 2].map(|k| mesh.normals()[[v, k]]);
    let omega = param.solid_angles();
    (0..param.texels())
        .filter_map(|t| {
            let (f, r, c) = (t / (s * s), (t / s) % s, t % s);
            let d = param.texel_direction(f, r, c);
            let cos = n[0] * d[0] + n[1] * d[1] + n[2] * d[2];
            (cos > 0.0).then(|| (f32x3(d), cos * omega[[f, r, c]]))
        })
        .collect()
}

/// A sphere floating over a small ground, with a colour per vertex.
fn sphere_over_ground() -> (Mesh, Array2<f32>) {
    let mesh = merge([
        grid([-2.0, 0.0, 2.0], [4.0, 0.0, 0.0], [0.0, 0.0, -4.0], 3, 3).unwrap(),
        cube_sphere([0.0, 1.2, 0.0], 1.0, 2).unwrap(),
    ]);
    let v = mesh.vertex_count();
    let albedo = Array2::from_shape_fn((v, 3), |(i, c)| {
        0.3 + 0.2 * c as f32 + 0.01 * (i % 7) as f32
    });
    (mesh, albedo)
}

/// A sphere in a corner: a floor and two walls meeting it, so that many rays start in a
/// neighbouring surface's plane or graze it (where tracers answer edge rays their own way).
fn sphere_in_a_corner() -> (Mesh, Array2<f32>) {
    let mesh = merge([
        grid([-2.0, 0.0, 2.0], [4.0, 0.0, 0.0], [0.0, 0.0, -4.0], 4, 4).unwrap(),
        grid([-2.0, 0.0, -2.0], [4.0, 0.0, 0.0], [0.0, 3.0, 0.0], 4, 3).unwrap(),
        grid([-2.0, 0.0, 2.0], [0.0, 0.0, -4.0], [0.0, 3.0, 0.0], 4, 3).unwrap(),
        cube_sphere([0.0, 1.0, 0.0], 0.8, 2).unwrap(),
    ]);
    let v = mesh.vertex_count();
    let albedo = Array2::from_shape_fn((v, 3), |(i, c)| {
        0.3 + 0.2 * c as f32 + 0.01 * (i % 5) as f32
    });
    (mesh, albedo)
}

#[test]
fn one_cast_gives_the_bits_of_visibility_and_of_the_gather_with_every_tracer() {
    let (mesh, albedo) = sphere_in_a_corner();
    let mut options = VisibilityOptions::new(cube(8));
    (options.samples, options.keep, options.sh_bands) = (2, Selection::Largest(60), Some(3));
    let all = 0..mesh.vertex_count();
    for bvh in crate::precompute::raycast::tests::every_tracer(&mesh) {
        let (direct, bounced, report) =
            direct_and_bounced(&mesh, &bvh, &options, albedo.view(), 2).unwrap();
        let (want, visibility) = vertex_major(&mesh, &bvh, &options).unwrap();
        let (sum, _) = bounce_range(
            &mesh,
            &bvh,
            &options,
            albedo.view(),
            &want,
            None,
            2,
            all.clone(),
        )
        .unwrap();
        let tracer = bvh.tracer();
        assert!(
            sum.coefficient_count() > 0,
            "{tracer:?}: the corner bounces light"
        );
        assert!(direct == want, "{tracer:?}: the direct transport differs");
        assert!(bounced == sum, "{tracer:?}: the bounced sum differs");
        assert_eq!(report.rays, visibility.rays, "{tracer:?}: each ray once");
        assert!(report.bounce_seconds > 0.0 && report.seconds >= report.bounce_seconds);
    }
}

/// `x[i][c]` of a set that is the same for every channel.
fn lifted(set: &TransportSet, f: &dyn Fn(&TransportSet, usize) -> Vec<f64>) -> Vec<Vec<Vec<f64>>> {
    (0..set.vertex_count())
        .map(|v| vec![f(set, v); 3])
        .collect()
}

fn assert_close(got: &[f64], want: &[f64], what: &str) {
    let scale = want.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    let worst = got
        .iter()
        .zip(want)
        .fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
    assert!(
        worst <= 2e-6 * scale.max(1e-30),
        "{what}: {worst} of {scale}"
    );
}

#[test]
fn two_rgb_bounces_equal_a_dense_per_ray_oracle_haar_and_harmonics() {
    let (mesh, albedo) = sphere_over_ground();
    let mut options = VisibilityOptions::new(cube(4));
    options.sh_bands = Some(3);
    let bvh = SceneBvh::new(&mesh);
    let (direct, _) = vertex_major(&mesh, &bvh, &options).unwrap();
    let all = 0..mesh.vertex_count();
    let (got, report) =
        bounce_range(&mesh, &bvh, &options, albedo.view(), &direct, None, 2, all).unwrap();
    assert!(!got.is_grey() && report.rays > 0);
    let rays = |v| centre_rays(&mesh, options.param, v);
    for (what, f) in [
        (
            "haar",
            &dense_coefficients as &dyn Fn(&TransportSet, usize) -> Vec<f64>,
        ),
        ("sh", &sh),
    ] {
        let t0 = lifted(&direct, f);
        let t1 = oracle_gather(&mesh, &albedo, &rays, &t0);
        let t2 = oracle_gather(&mesh, &albedo, &rays, &t1);
        let mut gained = 0.0;
        for v in 0..mesh.vertex_count() {
            for c in 0..3 {
                let want: Vec<f64> = (0..t1[v][c].len())
                    .map(|t| t1[v][c][t] + t2[v][c][t])
                    .collect();
                gained += want[0].abs();
                assert_close(&f(got.channel(c), v), &want, what);
            }
        }
        assert!(
            gained > 1.0,
            "{what}: the scene must bounce light ({gained})"
        );
    }
}

#[test]
fn jittered_sub_rays_weigh_one_over_s_squared() {
    let (mesh, albedo) = sphere_over_ground();
    let mut options = VisibilityOptions::new(cube(4));
    (options.samples, options.seed) = (2, 7);
    let bvh = SceneBvh::new(&mesh);
    let (direct, _) = vertex_major(&mesh, &bvh, &options).unwrap();
    let all = 0..mesh.vertex_count();
    let (got, _) =
        bounce_range(&mesh, &bvh, &options, albedo.view(), &direct, None, 1, all).unwrap();
    let set = RaySet::new(&options);
    let omega = options.param.solid_angles();
    let rays = |v: usize| {
        let n = [0, 1, 2].map(|k| mesh.normals()[[v, k]]);
        let mut out = Vec::new();
        set.for_each(v, n, |d, t| {
            let w = dot(n, set.directions[t]) * omega.as_slice().unwrap()[t] / 4.0;
            out.push((d, w));
        });
        out
    };
    let want = oracle_gather(&mesh, &albedo, &rays, &lifted(&direct, &dense_coefficients));
    for (v, want) in want.iter().enumerate() {
        for (c, want) in want.iter().enumerate() {
            assert_close(&dense_coefficients(got.channel(c), v), want, "S = 2");
        }
    }
}

#[test]
fn each_bounce_gathers_the_truncated_lower_sum() {
    let (mesh, _) = sphere_over_ground();
    let albedo = Array2::from_elem((mesh.vertex_count(), 3), 0.7f32);
    let mut options = VisibilityOptions::new(cube(4));
    options.keep = Selection::Largest(6);
    let bvh = SceneBvh::new(&mesh);
    let (direct, _) = vertex_major(&mesh, &bvh, &options).unwrap();
    let all = 0..mesh.vertex_count();
    let (got, _) =
        bounce_range(&mesh, &bvh, &options, albedo.view(), &direct, None, 2, all).unwrap();
    assert!(got.is_grey());
    let rays = |v| centre_rays(&mesh, options.param, v);
    let keep = |x: &[f64]| {
        let a =
            ndarray::Array3::from_shape_fn((6, 4, 4), |(f, r, c)| x[(f * 4 + r) * 4 + c] as f32);
        let (i, c) = kept_of_coefficients(a.view(), layout(options.param), options.keep).unwrap();
        let mut out = vec![0.0; 96];
        for (&i, &c) in i.iter().zip(&c) {
            out[i as usize] = f64::from(c);
        }
        out
    };
    let t0 = lifted(&direct, &dense_coefficients);
    let s1: Vec<Vec<Vec<f64>>> = oracle_gather(&mesh, &albedo, &rays, &t0)
        .iter()
        .map(|v| v.iter().map(|c| keep(c)).collect())
        .collect();
    let input: Vec<Vec<Vec<f64>>> = (0..t0.len())
        .map(|v| {
            (0..3)
                .map(|c| (0..96).map(|t| t0[v][c][t] + s1[v][c][t]).collect())
                .collect()
        })
        .collect();
    let s2 = oracle_gather(&mesh, &albedo, &rays, &input);
    let mut untruncated_differs = false;
    for (v, s2) in s2.iter().enumerate() {
        let want = keep(&s2[0]);
        assert_close(&dense_coefficients(got.channel(0), v), &want, "keep");
        assert!(got.channel(0).coefficients(v).0.len() <= 6 + 6);
        untruncated_differs |= want.iter().zip(&s2[0]).any(|(a, b)| (a - b).abs() > 1e-4);
    }
    assert!(untruncated_differs, "the truncation must matter here");
}

/// One floor triangle at `y = 0`, normals up, and a second at `y = at` whose shading normals
/// face down (towards the floor) when `facing_floor`, else up; `wound` the same way when
/// `wound_alike`, the other way otherwise.
fn floor_and_sheet(at: f64, facing_floor: bool, wound_alike: bool) -> Mesh {
    let sheet = if facing_floor == wound_alike {
        [3, 5, 4]
    } else {
        [3, 4, 5]
    };
    let sheet_normal = if facing_floor { -1.0 } else { 1.0 };
    Mesh::new(
        array![
            [-0.1, 0.0, 0.1],
            [0.1, 0.0, 0.1],
            [0.0, 0.0, -0.1],
            [-5.0, at, 5.0],
            [5.0, at, 5.0],
            [0.0, at, -5.0]
        ],
        vec![[0, 1, 2], sheet],
        Some(Array2::from_shape_fn((6, 3), |(v, k)| match (v, k) {
            (0..3, 1) => 1.0,
            (_, 1) => sheet_normal,
            _ => 0.0,
        })),
    )
    .unwrap()
}

fn floor_gain(mesh: &Mesh, samples: usize) -> usize {
    let mut options = VisibilityOptions::new(cube(8));
    options.samples = samples;
    let bvh = SceneBvh::new(mesh);
    let (direct, _) = vertex_major(mesh, &bvh, &options).unwrap();
    let albedo = Array2::from_elem((6, 3), 1.0f32);
    let (got, _) =
        bounce_range(mesh, &bvh, &options, albedo.view(), &direct, None, 1, 0..6).unwrap();
    (0..3).map(|v| got.channel(0).coefficients(v).0.len()).sum()
}

#[test]
fn hits_behind_their_shading_normal_and_rays_below_the_horizon_gather_nothing() {
    // A sheet above the floor lit from above: its underside sends light down only when its
    // shading normals face down, whatever its winding (Mitsuba's and pbrt's one-sided rule).
    for wound_alike in [true, false] {
        assert!(floor_gain(&floor_and_sheet(1.0, true, wound_alike), 1) > 0);
        assert_eq!(floor_gain(&floor_and_sheet(1.0, false, wound_alike), 1), 0);
    }
    // A sheet below the floor facing up: only rays below the floor's horizon could reach it.
    assert_eq!(floor_gain(&floor_and_sheet(-0.5, false, true), 3), 0);
}

#[test]
fn a_lone_flat_grid_gains_nothing() {
    let mesh = grid([-1.0, 0.0, 1.0], [2.0, 0.0, 0.0], [0.0, 0.0, -2.0], 6, 6).unwrap();
    let mut options = VisibilityOptions::new(cube(8));
    (options.samples, options.sh_bands) = (2, Some(2));
    let bvh = SceneBvh::new(&mesh);
    let (direct, _) = vertex_major(&mesh, &bvh, &options).unwrap();
    let albedo = Array2::from_elem((49, 3), 1.0f32);
    let (got, _) = bounce_range(
        &mesh,
        &bvh,
        &options,
        albedo.view(),
        &direct,
        None,
        3,
        0..49,
    )
    .unwrap();
    assert_eq!(got.coefficient_count(), 0);
    let transfer = got.channel(0).sh().unwrap().coefficients();
    assert!(transfer.iter().all(|&x| x.to_bits() == 0));
}

/// The integral of each vertex's transport under a white sky, `sum_t T(t)`: each face's
/// scaling coefficient times `S` (orthonormal).
fn white_sky(set: &TransportSet, v: usize) -> f64 {
    let s = set.param().face_size();
    let (indices, values) = set.coefficients(v);
    let scaling = indices
        .iter()
        .zip(values)
        .filter(|(i, _)| (**i as usize).is_multiple_of(s * s));
    scaling.map(|(_, &x)| f64::from(x) * s as f64).sum()
}

#[test]
fn a_lone_sphere_gains_less_than_one_percent() {
    let mesh = Generator::Sphere { cells: 6 }.mesh().unwrap();
    let options = VisibilityOptions::new(cube(8));
    let bvh = SceneBvh::new(&mesh);
    let (direct, _) = vertex_major(&mesh, &bvh, &options).unwrap();
    let v = mesh.vertex_count();
    let albedo = Array2::from_elem((v, 3), 1.0f32);
    let (got, _) =
        bounce_range(&mesh, &bvh, &options, albedo.view(), &direct, None, 1, 0..v).unwrap();
    let (lit, gained): (f64, f64) = (0..v)
        .map(|k| (white_sky(&direct, k), white_sky(got.channel(0), k)))
        .fold((0.0, 0.0), |(a, b), (x, y)| (a + x, b + y));
    // Every triangle's corners lie on the sphere, so below each vertex's tangent plane: the
    // gain is in fact 0 here, the contract's bound holding with room.
    assert!(
        lit > 0.0 && (0.0..0.01 * lit).contains(&gained),
        "{gained} of {lit}"
    );
}

/// The inside of a closed surface: a box's triangles wound and its flat normals turned
/// inwards. Its edge vertices are contact vertices ([`RayOrigins`]): each lifted point lies in
/// the neighbouring face's plane, and only their move into their own faces keeps their rays
/// towards that face from passing through it. (A coarse sphere would not do: its facets meet
/// near a vertex's tangent plane, where the smooth shading normal of the facet hit faces away
/// from the ray, and the one-sided rule drops that light.)
fn inward_box() -> Mesh {
    let outward = crate::scene::shapes::cuboid([-1.0; 3], [1.0; 3], 3).unwrap();
    let triangles = outward
        .triangles()
        .iter()
        .map(|&[a, b, c]| [a, c, b])
        .collect();
    Mesh::new(
        outward.positions().to_owned(),
        triangles,
        Some(-&outward.normals()),
    )
    .unwrap()
}

/// The white-sky integral of the bounced sum of `1..=8` bounces in the closed box, every
/// vertex given the transport of seeing the whole sphere as `T0` (nothing reaches inside).
fn box_sums(rho: f32) -> Vec<f64> {
    let mesh = inward_box();
    // (Fine enough that the texel centres' quadrature of the cosine about a face's normal,
    // the same at every vertex of a box, is within a few percent of pi.)
    let options = VisibilityOptions::new(cube(8));
    let bvh = SceneBvh::new(&mesh);
    let v = mesh.vertex_count();
    let mut direct = TransportSet::new(options.param, Selection::All);
    for _ in 0..v {
        direct
            .push(ndarray::Array3::ones((6, 8, 8)).view())
            .unwrap();
    }
    let albedo = Array2::from_elem((v, 3), rho);
    let mut sums = Vec::new();
    let mut lower: Option<BouncedTransport> = None;
    for b in 1..=MAX_BOUNCES {
        let run = bounce_range(
            &mesh,
            &bvh,
            &options,
            albedo.view(),
            &direct,
            lower.as_ref(),
            b,
            0..v,
        );
        let sum = run.unwrap().0;
        sums.push((0..v).map(|k| white_sky(sum.channel(0), k)).sum::<f64>() / v as f64);
        lower = Some(sum);
    }
    sums
}

#[test]
fn in_a_closed_surface_white_stays_finite_and_grey_decays_by_its_albedo() {
    let lit = 4.0 * PI;
    let added = |s: &[f64]| {
        let mut last = 0.0;
        s.iter()
            .map(|&x| std::mem::replace(&mut last, x))
            .zip(s)
            .map(|(a, b)| b - a)
            .collect::<Vec<f64>>()
    };
    // Albedo 1: each bounce passes on about all it gathers (the cosine's quadrature is not
    // exactly pi), so bounce b adds about T0 again and 8 bounces stay near 8 T0.
    let white = box_sums(1.0);
    for d in added(&white) {
        assert!(d.is_finite() && (d / lit - 1.0).abs() < 0.1, "{d}");
    }
    let d = added(&box_sums(0.5));
    for w in d.windows(2) {
        let ratio = w[1] / w[0];
        assert!(w[1] < w[0] && (ratio - 0.5).abs() < 0.05, "{ratio}");
    }
}

#[test]
fn refuses_what_it_cannot_gather() {
    let mesh = Generator::Sphere { cells: 2 }.mesh().unwrap();
    let options = VisibilityOptions::new(cube(4));
    let bvh = SceneBvh::new(&mesh);
    let (direct, _) = vertex_major(&mesh, &bvh, &options).unwrap();
    let albedo = Array2::from_elem((54, 3), 0.5f32);
    let run = |albedo: ArrayView2<'_, f32>, b, range: Range<usize>| {
        bounce_range(&mesh, &bvh, &options, albedo, &direct, None, b, range).map(|_| ())
    };
    let bounces = |albedo, b, range, needle| {
        assert_err!(
            run(albedo, b, range),
            InvalidParameter {
                name: "bounces",
                ..
            },
            needle
        );
    };
    bounces(albedo.view(), 9, 0..54, "9: must be 0 to 8");
    bounces(albedo.view(), 0, 0..54, "0: must be 0 to 8");
    bounces(albedo.view(), 1, 50..60, "vertices 50..60 of 54");
    bounces(
        albedo.slice(ndarray::s![..10, ..]),
        1,
        0..54,
        "the albedo and the direct transport must have the mesh's 54 vertices",
    );
    let mut bad = albedo.clone();
    bad[[3, 1]] = f32::NAN;
    assert_err!(
        run(bad.view(), 1, 0..54),
        InvalidParameter { name: "albedo", .. },
        "NaN at vertex 3: must be finite and non-negative"
    );
    let (one, _) = bounce_range(
        &mesh,
        &bvh,
        &options,
        albedo.view(),
        &direct,
        None,
        1,
        0..54,
    )
    .unwrap();
    let again = bounce_range(
        &mesh,
        &bvh,
        &options,
        albedo.view(),
        &direct,
        Some(&one),
        1,
        0..54,
    );
    assert_err!(
        again,
        InvalidParameter {
            name: "bounces",
            ..
        },
        "1 bounces asked for from a sum of 1"
    );
}

#[test]
fn rendered_bounces_equal_the_pixel_domain_gather_to_1e_6_of_the_rms() {
    use crate::Scene;
    use crate::light::environment::Environment;
    use crate::precompute::{PrecomputeOptions, precompute};
    use crate::shade::reference::interreflection::interreflected;
    use crate::shade::{FrameSpec, Precision, ShaderSpec, ShadingInput};
    use haarshift::sphere::{LatLongMap, SphereRotation};
    // An open box (concave) under a sky brighter above and redder to one side, with a
    // coloured albedo so that the three channels of the bounced sum differ.
    let mut scene =
        Scene::from_mesh(Generator::OpenBox { cells: 2 }.mesh().unwrap(), false).unwrap();
    let v = scene.mesh.vertex_count();
    scene.albedo = Array2::from_shape_fn((v, 3), |(i, c)| {
        0.4 + 0.15 * c as f32 + 0.02 * (i % 7) as f32
    });
    let sky = LatLongMap::<f64>::from_fn(8, 3, |d, o| {
        o.copy_from_slice(&[
            1.0 + d[1] + 0.5 * d[0].max(0.0),
            1.0 + d[1],
            0.7 + 0.3 * d[2],
        ]);
    })
    .unwrap();
    let env = Environment::new(sky);
    let frame = FrameSpec {
        environment: &env,
        rotation: SphereRotation::identity(),
        eye: None,
    };
    let lighting = env.lat_long(8, &SphereRotation::identity()).unwrap();
    let mut options = PrecomputeOptions::new(VisibilityOptions::new(
        Parameterization::new(ParamKind::LatLong, 8).unwrap(),
    ));
    for bounces in [1, 2] {
        options.bounces = bounces;
        let (cache, _) = precompute(scene.clone(), &options).unwrap();
        assert_eq!(cache.bounced.as_ref().unwrap().channels().len(), 3);
        let bvh = SceneBvh::with_tracer(&cache.mesh, options.ray_tracer);
        let truth = interreflected(
            &cache.mesh,
            &bvh,
            cache.albedo.view(),
            &lighting,
            bounces,
            false,
        )
        .unwrap();
        let want = truth.radiance(bounces);
        for precision in [Precision::F32, Precision::F64] {
            let spec = ShaderSpec {
                precision,
                ..ShaderSpec::default()
            };
            let shade = |input: &ShadingInput<'_>| {
                let shader = spec.build(input).unwrap().shade(&frame).unwrap();
                shader.radiance.to_f64()
            };
            let mut input = ShadingInput::cache(&cache);
            let got = shade(&input);
            let error = relative_rms_error(got.view(), want.view()).unwrap();
            assert!(error < 1e-6, "{bounces} bounces, {precision}: {error:e}");
            // Direct light alone is the reference's direct light, far from the bounced.
            input.bounced = None;
            let direct = shade(&input);
            assert!(relative_rms_error(direct.view(), truth.direct.view()).unwrap() < 1e-6);
            assert!(
                relative_rms_error(direct.view(), want.view()).unwrap() > 1e-2,
                "{bounces}"
            );
        }
    }
}

#[test]
fn bounced_harmonic_transfer_shades_as_its_haar_sum_with_every_band() {
    use crate::Scene;
    use crate::light::environment::Environment;
    use crate::precompute::{PrecomputeOptions, precompute};
    use crate::shade::{FrameSpec, Method, ShaderSpec, ShadingInput};
    use haarshift::sphere::{LatLongMap, SphereRotation};
    // A sky of degree 1 is exact in two bands, so the spherical harmonics' radiance with its
    // bounced transfer approaches the Haar one's; without the bounced transfer it does not.
    let scene = Scene::from_mesh(Generator::OpenBox { cells: 2 }.mesh().unwrap(), false).unwrap();
    let sky = LatLongMap::<f64>::from_fn(16, 3, |d, o| o.fill(1.0 + 0.5 * d[1])).unwrap();
    let env = Environment::new(sky);
    let frame = FrameSpec {
        environment: &env,
        rotation: SphereRotation::identity(),
        eye: None,
    };
    let mut visibility =
        VisibilityOptions::new(Parameterization::new(ParamKind::LatLong, 16).unwrap());
    visibility.sh_bands = Some(2);
    let mut options = PrecomputeOptions::new(visibility);
    options.bounces = 1;
    let (cache, _) = precompute(scene, &options).unwrap();
    let shade = |method, bounced: bool| {
        let mut input = ShadingInput::cache(&cache);
        if !bounced {
            input.bounced = None;
        }
        let spec = ShaderSpec {
            method,
            ..ShaderSpec::default()
        };
        spec.build(&input)
            .unwrap()
            .shade(&frame)
            .unwrap()
            .radiance
            .to_f64()
    };
    let (haar, sh) = (shade(Method::Haar, true), shade(Method::Sh, true));
    let (haar0, sh0) = (shade(Method::Haar, false), shade(Method::Sh, false));
    let with = relative_rms_error(sh.view(), haar.view()).unwrap();
    assert!(with < 1e-3, "{with:e}");
    assert!(relative_rms_error(sh0.view(), haar0.view()).unwrap() < 1e-3);
    assert!(relative_rms_error(sh0.view(), haar.view()).unwrap() > 10.0 * with);
    // Other methods refuse a bounced input; with the sum dropped they shade.
    for method in [Method::Reference, Method::Ambient] {
        let spec = ShaderSpec {
            method,
            ..ShaderSpec::default()
        };
        let e = spec
            .build(&ShadingInput::cache(&cache))
            .err()
            .unwrap()
            .to_string();
        assert!(e.contains("1 bounces of light baked"), "{e}");
    }
    let mut glossy = ShaderSpec::default();
    glossy.material.brdf = "phong:10".parse().unwrap();
    assert_err!(
        glossy.build(&ShadingInput::cache(&cache)),
        InvalidParameter { name: "scene", .. },
        "1 bounces of light baked",
        "--brdf phong:10 cannot show"
    );
}
