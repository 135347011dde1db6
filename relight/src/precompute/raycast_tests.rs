use rand::rngs::StdRng;
use rand::{Rng, SeedableRng};

use obvhs::ray::Ray;

use super::*;
use crate::Scene;
use crate::test_support::{bunny_in_box, bunny_on_ground};

/// The triangles our packets trace (none for another tracer).
fn traced(bvh: &SceneBvh) -> &[obvhs::rt_triangle::RtTriangle] {
    match &bvh.tracer {
        Some(Tracer::Packets(b)) => &b.triangles,
        _ => &[],
    }
}

/// Our packets' BVH of `mesh`.
fn packets(mesh: &Mesh) -> SceneBvh {
    SceneBvh::with_tracer(mesh, RayTracer::Packets)
}

/// The BVH of `mesh` with every tracer: Embree only where it loads (skipped in one line
/// otherwise, a failure where `HAARSHIFT_REQUIRE` names it).
pub(crate) fn every_tracer(mesh: &Mesh) -> Vec<SceneBvh> {
    let tracers = RayTracer::ALL.iter().filter(|t| {
        haarshift_testkit::needs(t.name(), t.unavailable().map_or(Ok(()), Err)).is_some()
    });
    tracers
        .map(|&t| {
            let bvh = SceneBvh::with_tracer(mesh, t);
            assert_eq!(bvh.tracer(), t, "an available tracer builds");
            bvh
        })
        .collect()
}

/// How far the f64 answers must be from deciding otherwise to count as clear-cut.
const TOL: f64 = 1e-5;

/// The ray against every triangle of `mesh` in f64 (Moller-Trumbore): for each triangle whose
/// plane it crosses, `(triangle, t, u, v, margin)`, `margin` the least of its barycentric
/// coordinates, its distance relative to the ray's and the edge's lengths, and its room below
/// `t_max`: a hit when positive, a clear-cut answer when farther than [`TOL`] from 0.
fn f64_crossings(
    mesh: &Mesh,
    o: [f32; 3],
    d: [f32; 3],
    t_max: f32,
) -> impl Iterator<Item = (usize, f64, f64, f64, f64)> + '_ {
    let (o, d, t_max) = (o.map(f64::from), d.map(f64::from), f64::from(t_max));
    let p = mesh.positions();
    let corner = move |i: u32| [0, 1, 2].map(|k| f64::from(p[[i as usize, k]] as f32));
    let dot = |a: [f64; 3], b: [f64; 3]| a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
    mesh.triangles()
        .iter()
        .enumerate()
        .filter_map(move |(index, t)| {
            let [a, b, c] = t.map(corner);
            let (e1, e2) = (sub(b, a), sub(c, a));
            let q = cross(d, e2);
            let det = dot(e1, q);
            if det == 0.0 {
                return None;
            }
            let s = sub(o, a);
            let u = dot(s, q) / det;
            let r = cross(s, e1);
            let v = dot(d, r) / det;
            let dist = dot(e2, r) / det;
            let inside = u.min(v).min(1.0 - u - v);
            let length = dot(d, d).sqrt() * dot(e1, e1).sqrt().max(dot(e2, e2).sqrt());
            let far = if t_max.is_finite() {
                (t_max - dist) / t_max.max(1.0)
            } else {
                f64::INFINITY
            };
            Some((index, dist, u, v, inside.min(dist / length).min(far)))
        })
}

/// Tracer-independent oracle: the ray against every triangle of `mesh` in f64, `None` when
/// the answer is not clear-cut, that is when a triangle's barycentric coordinates or distance
/// come within [`TOL`] (relative) of deciding otherwise: a ray through an edge, whose f32
/// answer rounding decides.
fn exact(mesh: &Mesh, o: [f32; 3], d: [f32; 3], t_max: f32) -> Option<bool> {
    let mut unclear = false;
    for (.., margin) in f64_crossings(mesh, o, d, t_max) {
        if margin > TOL {
            return Some(true);
        }
        unclear |= margin > -TOL;
    }
    (!unclear).then_some(false)
}

/// The oracle: every triangle tested, the same intersection routine.
fn bvh_hit_by_brute_force(
    bvh: &SceneBvh,
    origin: [f32; 3],
    direction: [f32; 3],
    t_max: f32,
) -> bool {
    let ray = Ray::new(
        Vec3A::from_array(origin),
        Vec3A::from_array(direction),
        0.0,
        t_max,
    );
    traced(bvh).iter().any(|t| t.intersect(&ray) < t_max)
}

/// Rays from near the bunny's vertices (the visibility case) and from anywhere in its box,
/// with `t_max` 2 or infinite.
fn bunny_rays(mesh: &Mesh) -> impl Iterator<Item = ([f32; 3], [f32; 3], f32)> + '_ {
    let b = mesh.bounds();
    let mut rng = StdRng::seed_from_u64(11);
    (0..20_000).map(move |k| {
        let origin: [f32; 3] = std::array::from_fn(|i| {
            // Half the rays start near vertices (the visibility case), half anywhere.
            if k % 2 == 0 {
                let v = (k / 2) % mesh.vertex_count();
                (mesh.positions()[[v, i]] + 1e-3 * mesh.normals()[[v, i]]) as f32
            } else {
                rng.random_range(b.min[i]..=b.max[i]) as f32
            }
        });
        let d: [f32; 3] = std::array::from_fn(|_| rng.random_range(-1.0f32..1.0));
        let len = d.iter().map(|x| x * x).sum::<f32>().sqrt();
        let t_max = if k % 3 == 0 { 2.0 } else { f32::INFINITY };
        (origin, d.map(|x| x / len), t_max)
    })
}

#[test]
fn every_tracer_answers_every_clear_cut_ray_as_f64() {
    let mesh = bunny_on_ground();
    for bvh in every_tracer(&mesh) {
        let (mut hits, mut unclear) = (0, 0);
        // A quarter of the rays: the f64 oracle tests every triangle for each.
        for (k, (o, d, t_max)) in bunny_rays(&mesh).enumerate().step_by(4) {
            let got = bvh.occluded(o, d, t_max);
            match exact(&mesh, o, d, t_max) {
                Some(want) => assert_eq!(got, want, "{}: ray {k}", bvh.tracer()),
                None => unclear += 1,
            }
            hits += usize::from(got);
        }
        // Both outcomes are well represented, and few rays are left unjudged.
        assert!((1_000..4_000).contains(&hits), "{hits}");
        assert!(unclear < 50, "{unclear}"); // 1%
    }
}

#[test]
fn bvh_answers_as_testing_every_triangle() {
    let mesh = bunny_on_ground();
    let bvh = packets(&mesh);
    assert_eq!(traced(&bvh).len(), mesh.triangles().len()); // none degenerate here
    let mut hits = 0;
    for (k, (origin, d, t_max)) in bunny_rays(&mesh).enumerate() {
        let want = bvh_hit_by_brute_force(&bvh, origin, d, t_max);
        assert_eq!(bvh.occluded(origin, d, t_max), want, "ray {k}");
        hits += usize::from(want);
    }
    // Both outcomes are well represented.
    assert!((4_000..16_000).contains(&hits), "{hits}");
}

#[test]
fn degenerate_triangles_never_occlude() {
    let positions = ndarray::array![[0.0, 1.0, 0.0], [1.0, 1.0, 0.0], [2.0, 1.0, 0.0]];
    let mesh = Mesh::new(positions, vec![[0, 1, 2], [0, 0, 1]], None).unwrap();
    assert!(traced(&packets(&mesh)).is_empty());
    for bvh in every_tracer(&mesh) {
        assert!(!bvh.occluded([0.5, 0.0, 0.0], [0.0, 1.0, 0.0], f32::INFINITY));
    }
    // A scene built the usual way is unaffected by such triangles.
    let scene = Scene::from_mesh(mesh, true).unwrap();
    assert!(SceneBvh::new(&scene.mesh).occluded([0.5, 2.0, 0.0], [0.0, -1.0, 0.0], 10.0));
}

#[test]
fn repeated_and_f32_degenerate_triangles_are_kept_once_and_dropped() {
    // One roof triangle, the same triangle twice more (rotated corners, reversed winding), one
    // of zero area in f32 only (its corners differ by 1e-9 near 1) and one of zero area.
    let positions = ndarray::array![
        [-1.0, 1.0, 1.0],
        [1.0, 1.0, 1.0],
        [0.0, 1.0, -1.0],
        [1.0, 1.0, 1.0],
        [1.0 + 1e-9, 1.0, 1.0],
        [1.0, 1.0 + 1e-9, 1.0],
    ];
    let triangles = vec![[0, 1, 2], [1, 2, 0], [0, 2, 1], [3, 4, 5], [0, 0, 1]];
    let mesh = Mesh::new(positions, triangles.clone(), None).unwrap();
    assert_eq!(traced(&packets(&mesh)).len(), 1);
    for bvh in every_tracer(&mesh) {
        assert!(bvh.occluded([0.0, 0.0, 0.0], [0.0, 1.0, 0.0], f32::INFINITY));
        assert!(!bvh.occluded([0.0, 0.0, 0.0], [0.0, -1.0, 0.0], f32::INFINITY));
    }
    // The mesh keeps every triangle as read: cleaning feeds only the BVH.
    assert_eq!(mesh.triangles(), &triangles[..]);
}

#[test]
fn a_tiny_scene_answers_as_the_same_scene_at_an_extent_between_one_and_two() {
    // The bunny on its ground scaled by 2^-76 (extent about 1e-23, where PLOC's f32 surface
    // areas underflow and the traversal's 1e-4 epsilon skips every box) is traced at an
    // extent in [1, 2): exactly the bunny scaled there directly, powers of two being exact.
    let mesh = bunny_on_ground();
    let scaled = |s: f64| {
        let positions = mesh.positions().mapv(|x| x * s);
        Mesh::new(positions, mesh.triangles().to_vec(), None).unwrap()
    };
    let b = mesh.bounds();
    let extent = (0..3).map(|k| b.max[k] - b.min[k]).fold(0.0, f64::max);
    let unit = 2f64.powi(-(extent.log2().floor() as i32));
    let (near, tiny) = (scaled(unit), scaled(2f64.powi(-76)));
    for (near, tiny) in every_tracer(&near).into_iter().zip(every_tracer(&tiny)) {
        tiny_answers_as_near(&near, &tiny, unit);
    }
}

fn tiny_answers_as_near(near: &SceneBvh, tiny: &SceneBvh, unit: f64) {
    assert_eq!(near.scale, 1.0);
    assert_eq!(f64::from(tiny.scale), unit * 2f64.powi(76));
    let mut rng = StdRng::seed_from_u64(7);
    let mut hits = 0;
    for _ in 0..20_000 {
        let o: [f32; 3] = std::array::from_fn(|_| rng.random_range(-1.0..1.0));
        let d: [f32; 3] = std::array::from_fn(|_| rng.random_range(-1.0..1.0));
        let t_max = if rng.random_bool(0.5) {
            f32::INFINITY
        } else {
            0.3
        };
        let answer = near.occluded(o, d, t_max);
        let t = (2f64.powi(-76) / unit) as f32;
        assert_eq!(tiny.occluded(o.map(|x| x * t), d, t_max * t), answer);
        // And as a packet of rays around it.
        let around: Vec<[f32; 3]> = (0..16).map(|k| d.map(|x| x + 0.01 * k as f32)).collect();
        let (mut a, mut b) = ([false; 16], [false; 16]);
        near.occluded_from(o, &around, t_max, &mut a);
        tiny.occluded_from(o.map(|x| x * t), &around, t_max * t, &mut b);
        assert_eq!((a, a[0]), (b, answer));
        hits += usize::from(answer);
    }
    assert!((1_000..19_000).contains(&hits), "{hits}");
}

/// The cube 8 x 8 texel centres in texel order, as visibility casts them.
fn cube8_directions() -> Vec<[f32; 3]> {
    let param =
        haarshift::faces::Parameterization::new(haarshift::faces::ParamKind::Cube, 8).unwrap();
    (0..param.texels())
        .map(|t| {
            param
                .texel_direction(t / 64, (t / 8) % 8, t % 8)
                .map(|x| x as f32)
        })
        .collect()
}

/// The visibility case: from just above every 97th vertex of `mesh`, one ray to every cube
/// 8 x 8 texel centre, in the order precomputation casts them.
fn vertex_rays(mesh: &Mesh) -> (Vec<[f32; 3]>, Vec<[f32; 3]>) {
    let directions = cube8_directions();
    let eps = crate::ray_offset(mesh);
    let origins = (0..mesh.vertex_count())
        .step_by(97)
        .map(|v| {
            std::array::from_fn(|k| {
                (mesh.positions()[[v, k]] + eps * mesh.normals()[[v, k]]) as f32
            })
        })
        .collect();
    (origins, directions)
}

#[test]
fn packets_from_vertices_answer_as_testing_every_triangle() {
    let mesh = bunny_on_ground();
    let bvh = packets(&mesh);
    let (origins, directions) = vertex_rays(&mesh);
    let mut blocked = vec![false; directions.len()];
    let mut hits = 0;
    for origin in &origins {
        bvh.occluded_from(*origin, &directions, f32::INFINITY, &mut blocked);
        for (d, &b) in directions.iter().zip(&blocked) {
            let want = bvh_hit_by_brute_force(&bvh, *origin, *d, f32::INFINITY);
            assert_eq!(b, want, "{origin:?} {d:?}");
            hits += usize::from(b);
        }
    }
    let rays = directions.len() * origins.len();
    assert!((rays / 5..rays * 4 / 5).contains(&hits), "{hits} of {rays}");
}

#[test]
fn every_tracer_answers_the_rays_of_vertices_as_f64() {
    let mesh = bunny_on_ground();
    let (origins, directions) = vertex_rays(&mesh);
    for bvh in every_tracer(&mesh) {
        let mut blocked = vec![false; directions.len()];
        let (mut hits, mut unclear) = (0, 0);
        // Every other vertex: the f64 oracle tests every triangle for each ray.
        for origin in origins.iter().step_by(2) {
            bvh.occluded_from(*origin, &directions, f32::INFINITY, &mut blocked);
            for (d, &b) in directions.iter().zip(&blocked) {
                match exact(&mesh, *origin, *d, f32::INFINITY) {
                    Some(want) => assert_eq!(b, want, "{}: {origin:?} {d:?}", bvh.tracer()),
                    None => unclear += 1,
                }
                hits += usize::from(b);
            }
        }
        let rays = directions.len() * origins.len().div_ceil(2);
        assert!((rays / 5..rays * 4 / 5).contains(&hits), "{hits} of {rays}");
        assert!(unclear < rays / 100, "{unclear} of {rays}");
    }
}

#[test]
fn embree_is_the_best_tracer_where_it_loads() {
    let why = RayTracer::Embree.unavailable().map_or(Ok(()), Err);
    if haarshift_testkit::needs("embree", why).is_none() {
        // Where it does not load, the reason names the package to install.
        let why = RayTracer::Embree.unavailable().unwrap();
        assert!(why.contains("apt-get install libembree3-3"), "{why}");
        assert_eq!(RayTracer::best(), RayTracer::Packets);
        assert!(RayTracer::choice().starts_with("packets ("));
        return;
    }
    assert_eq!(RayTracer::best(), RayTracer::Embree);
    assert!(
        RayTracer::choice().starts_with("embree (Embree 3."),
        "{}",
        RayTracer::choice()
    );
    assert_eq!(
        SceneBvh::new(&bunny_on_ground()).tracer(),
        RayTracer::Embree
    );
}

/// Tracer-independent oracle of the closest hit: the ray against every triangle of `mesh` in
/// f64, `Some(None)` for no hit, `Some(Some((triangle, t, u, v)))` for the nearest, and `None`
/// when the answer is not clear-cut: a crossing within [`TOL`] of an edge, of the origin or of
/// `t_max`, or two hits within [`TOL`] (relative) of the same distance.
fn exact_closest(
    mesh: &Mesh,
    o: [f32; 3],
    d: [f32; 3],
    t_max: f32,
) -> Option<Option<(usize, f64, f64, f64)>> {
    let mut hits = Vec::new();
    for (index, dist, u, v, margin) in f64_crossings(mesh, o, d, t_max) {
        if margin.abs() <= TOL {
            return None;
        }
        if margin > 0.0 {
            hits.push((index, dist, u, v));
        }
    }
    hits.sort_by(|a, b| a.1.total_cmp(&b.1));
    match hits.as_slice() {
        [first, second, ..] if (second.1 - first.1) <= TOL * first.1.max(1e-3) => None,
        [first, ..] => Some(Some(*first)),
        [] => Some(None),
    }
}

#[test]
fn every_tracer_finds_the_closest_hit_as_f64() {
    let mesh = bunny_on_ground();
    let rays: Vec<_> = bunny_rays(&mesh).step_by(8).collect();
    for bvh in every_tracer(&mesh) {
        let (mut hits, mut unclear) = (0, 0);
        for (k, chunk) in rays.chunks(7).enumerate() {
            // Rays of one origin, as a vertex casts them: the chunk's directions from its first.
            let (o, _, t_max) = chunk[0];
            let directions: Vec<[f32; 3]> = chunk.iter().map(|r| r.1).collect();
            let mut got = vec![None; directions.len()];
            bvh.closest_hits_from(o, &directions, t_max, &mut got);
            for (d, got) in directions.iter().zip(&got) {
                let Some(want) = exact_closest(&mesh, o, *d, t_max) else {
                    unclear += 1;
                    continue;
                };
                let tracer = bvh.tracer();
                match (got, want) {
                    (None, None) => {}
                    (Some(h), Some((triangle, t, u, v))) => {
                        assert_eq!(h.triangle, triangle, "{tracer}: ray {k} {d:?}");
                        let close =
                            |a: f32, b: f64| (f64::from(a) - b).abs() <= 1e-4 * b.abs().max(1.0);
                        assert!(
                            close(h.t, t) && close(h.u, u) && close(h.v, v),
                            "{tracer}: {h:?} against {t} {u} {v}"
                        );
                        hits += 1;
                    }
                    _ => panic!("{tracer}: ray {k} {d:?}: {got:?} against {want:?}"),
                }
                // The occlusion query agrees.
                assert_eq!(
                    bvh.occluded(o, *d, t_max),
                    got.is_some(),
                    "{tracer}: ray {k}"
                );
            }
        }
        assert!((300..2_000).contains(&hits), "{hits} of {}", rays.len());
        assert!(unclear < rays.len() / 50, "{unclear} of {}", rays.len());
    }
}

#[test]
fn a_closest_hit_names_the_first_of_repeated_triangles_and_never_a_flat_one() {
    // A flat triangle first (corners on the line y = 1, z = 1), then one facing down, its
    // mirror image (the same corners, the other winding) and its copy, all in the plane
    // y = 1, then one at y = 2.
    let positions = ndarray::array![
        [-1.0, 1.0, 1.0],
        [1.0, 1.0, 1.0],
        [0.0, 1.0, -1.0],
        [3.0, 1.0, 1.0],
        [-1.0, 2.0, 1.0],
        [1.0, 2.0, 1.0],
        [0.0, 2.0, -1.0]
    ];
    let triangles = vec![[0, 1, 3], [0, 1, 2], [0, 2, 1], [1, 2, 0], [4, 5, 6]];
    let mesh = Mesh::new(positions, triangles, None).unwrap();
    for bvh in every_tracer(&mesh) {
        let up = [[0.0, 1.0, 0.0], [0.1, 1.0, 0.1], [0.0, -1.0, 0.0]];
        let mut hits = [None; 3];
        bvh.closest_hits_from([0.0, 0.0, 0.0], &up, f32::INFINITY, &mut hits);
        for h in &hits[..2] {
            let h = h.unwrap();
            assert_eq!(h.triangle, 1, "{}", bvh.tracer());
            assert!((h.t - 1.0).abs() < 1e-6, "{h:?}");
        }
        assert_eq!(hits[2], None);
        // From between the two planes, up: the roof at y = 2, triangle 4, at its centroid's
        // weights.
        bvh.closest_hits_from(
            [0.0, 1.5, 1.0 / 3.0],
            &up[..1],
            f32::INFINITY,
            &mut hits[..1],
        );
        let h = hits[0].unwrap();
        assert_eq!(h.triangle, 4, "{}", bvh.tracer());
        assert!((h.t - 0.5).abs() < 1e-6, "{h:?}");
        assert!(
            (h.u - 1.0 / 3.0).abs() < 1e-6 && (h.v - 1.0 / 3.0).abs() < 1e-6,
            "{h:?}"
        );
        // t_max short of it: nothing.
        bvh.closest_hits_from([0.0, 1.5, 0.0], &up[..1], 0.25, &mut hits[..1]);
        assert_eq!(hits[0], None);
    }
}

/// Every ray visibility casts in the box scene (every vertex from its [`RayOrigins`] origin,
/// every cube 8 x 8 texel centre above its horizon): where Embree and our packets answer a ray
/// differently, it is a ray that rounding decides (the f64 oracle finds it within [`TOL`] of
/// an edge or of the origin), never a clear-cut one. Before the crease contract, the rays of the
/// box's 260 crease vertices started in a wall's plane and the tracers differed on 15% of the
/// radiance's RMS.
#[test]
fn embree_and_our_packets_differ_on_the_box_scene_only_where_rounding_decides() {
    let mesh = bunny_in_box();
    let tracers = every_tracer(&mesh);
    let [embree, ours] = tracers.as_slice() else {
        return; // Embree is missing: every_tracer said so in one line
    };
    let directions = cube8_directions();
    let origins = crate::precompute::origin::RayOrigins::new(&mesh);
    let (mut a, mut b) = (vec![false; directions.len()], vec![false; directions.len()]);
    let (mut rays, mut differ) = (0usize, 0usize);
    for v in 0..mesh.vertex_count() {
        let (o, n) = origins.origin_and_normal(v);
        let o = o.map(|x| x as f32);
        embree.occluded_from(o, &directions, f32::INFINITY, &mut a);
        ours.occluded_from(o, &directions, f32::INFINITY, &mut b);
        for (k, d) in directions.iter().enumerate() {
            let above = (0..3).map(|i| n[i] * f64::from(d[i])).sum::<f64>() > 0.0;
            if !above {
                continue;
            }
            rays += 1;
            if a[k] != b[k] {
                differ += 1;
                assert_eq!(
                    exact(&mesh, o, *d, f32::INFINITY),
                    None,
                    "vertex {v} ray {d:?}"
                );
            }
        }
    }
    // Measured: 1,081 of 630,528 rays (0.17%), all through an edge to within rounding.
    // (Without the contract: 4,463.)
    assert!(differ * 400 < rays, "{differ} of {rays}");
    eprintln!("{differ} of {rays} rays answered differently, none clear-cut");
}
