use super::*;
use crate::light::environment::Environment;
use crate::precompute::precompute;
use crate::scene::bisect::Bisection;
use crate::shade::lambert::{ShadeOptions, shade_lambertian};
use crate::{Generator, RayTracer, VisibilityOptions};
use haarshift::faces::{ParamKind, Parameterization};
use haarshift::product::Selection;
use haarshift::sphere::LatLongMap;
use ndarray::Array2;

/// A cube sphere of two cells a face (touching the ground at one vertex) on a ground plane of
/// 2 x 2 cells: 54 + 9 vertices.
fn ball_on_ground() -> Scene {
    let mut scene =
        Scene::from_mesh(Generator::Sphere { cells: 2 }.mesh().unwrap(), false).unwrap();
    scene.add_ground_plane_of(2).unwrap();
    scene
}

fn packet_options(order: Order) -> PrecomputeOptions {
    let param = Parameterization::new(ParamKind::LatLong, 8).unwrap();
    let mut o = PrecomputeOptions::new(VisibilityOptions::new(param));
    o.ray_tracer = RayTracer::Packets;
    o.order = order;
    o
}

fn refinement(tolerance: f64, max_vertices: usize) -> Refinement {
    Refinement {
        tolerance,
        max_vertices: Some(max_vertices),
        probe: None,
    }
}

/// A dim sky of 0.05 with a sun of 50 within 0.15 rad of `(0.8, 0.6, 0)`, 37 degrees up in
/// the +x sky: the ball's shadow falls on the ground from about `x = 0` to `x = -3`.
fn sun_environment() -> Environment {
    let sun = [0.8, 0.6, 0.0];
    let len = dot(sun, sun).sqrt();
    let map = LatLongMap::<f64>::from_fn(64, 3, |d, out| {
        let c = dot([d[0], d[1], d[2]], sun) / len;
        out.fill(if c > 0.15f64.cos() { 50.0 } else { 0.05 });
    })
    .unwrap();
    Environment::new(map)
}

/// Every edge's criterion in `cache`, largest first.
fn edge_differences(cache: &SceneCache) -> Vec<f64> {
    let mut scene = Scene::from_mesh(cache.mesh.clone(), false).unwrap();
    scene.albedo = cache.albedo.clone();
    let edges: Vec<Edge> = Bisection::new(&scene).edges().collect();
    let unoccluded = Unoccluded::new(cache.transport.param());
    let n = cache.mesh.normals();
    let scale = |v: u32| unoccluded.norm([0, 1, 2].map(|k| n[[v as usize, k]]));
    let mut dense = vec![0.0; cache.transport.param().texels()];
    let mut d: Vec<f64> = (edges.iter())
        .map(|&(a, b)| {
            let most = scale(a).max(scale(b));
            difference(&cache.transport, a as usize, b as usize, &mut dense) / most
        })
        .filter(|d| !d.is_nan())
        .collect();
    d.sort_by(|x, y| y.total_cmp(x));
    d
}

#[test]
fn the_difference_is_the_dense_vectors_and_the_scale_an_unoccluded_vertex() {
    let param = Parameterization::new(ParamKind::Cube, 2).unwrap();
    let mut set = TransportSet::new(param, Selection::Largest(5));
    for seed in 0..3 {
        let values = ndarray::Array3::from_shape_fn((6, 2, 2), |(f, i, j)| {
            ((f * 7 + i * 3 + j + seed * 5) % 4) as f32 * 0.25
        });
        set.push(values.view()).unwrap();
    }
    set.push(ndarray::Array3::zeros((6, 2, 2)).view()).unwrap();
    let full = |v: usize| {
        let mut x = vec![0.0f64; 24];
        let (i, c) = set.coefficients(v);
        i.iter()
            .zip(c)
            .for_each(|(&i, &c)| x[i as usize] = c.into());
        x
    };
    let mut scratch = vec![0.0; 24];
    for a in 0..4 {
        for b in 0..4 {
            let (x, y) = (full(a), full(b));
            let want = x
                .iter()
                .zip(&y)
                .map(|(p, q)| (p - q).powi(2))
                .sum::<f64>()
                .sqrt();
            let got = difference(&set, a, b, &mut scratch);
            assert!((got - want).abs() < 1e-12, "{a} {b}: {got} {want}");
            assert!(want > 0.0 || a == b);
            assert!(scratch.iter().all(|&s| s == 0.0));
        }
    }
    // The scale is the norm of the transport of a vertex that sees every texel.
    let param = Parameterization::new(ParamKind::LatLong, 8).unwrap();
    let unoccluded = Unoccluded::new(param);
    for n in [[0.0, 1.0, 0.0], [0.6, 0.0, -0.8], [0.0; 3]] {
        let mut open = TransportSet::new(param, Selection::All);
        let values = ndarray::Array3::from_shape_fn((2, 8, 8), |(f, r, c)| {
            dot(n, param.texel_direction(f, r, c)).max(0.0) as f32
        });
        open.push(values.view()).unwrap();
        let norm = (open.coefficients(0).1.iter())
            .map(|&x| f64::from(x).powi(2))
            .sum::<f64>();
        let want = unoccluded.norm(n);
        assert!(
            (norm.sqrt() - want).abs() <= 1e-6 * want.max(1e-30),
            "{n:?}: {want}"
        );
    }
}

#[test]
fn refined_cache_is_a_precompute_of_the_refined_mesh() {
    let scene = ball_on_ground();
    let o = packet_options(Order::Vertex);
    // Lat-long 8's texels are large: one texel turning dark is a step of about a quarter of
    // an unoccluded vertex's transport, so 0.6 is a tolerance the refinement can meet.
    let tolerance = 0.6;
    let (refined, _, report) =
        precompute_refined(scene.clone(), &o, &refinement(tolerance, 2000)).unwrap();
    assert!(!report.stopped_by_budget(), "{report:?}");
    assert!(report.vertices > 63 && report.rounds >= 2, "{report:?}");
    let mut again = Scene::from_mesh(refined.mesh.clone(), false).unwrap();
    again.albedo = refined.albedo.clone();
    again.ground_plane = true;
    again.ground_cells = scene.ground_cells;
    again.ground_vertices = refined.ground_vertices;
    let (unrefined, _) = precompute(again, &o).unwrap();
    assert_eq!(unrefined.transport, refined.transport);
    assert_eq!(unrefined.mesh, refined.mesh);
    // Every edge is within the tolerance, and the refinement was needed.
    let left = edge_differences(&refined)
        .iter()
        .filter(|&&d| d > tolerance)
        .count();
    assert_eq!(left, report.short, "{report:?}");
    let (plain, _) = precompute(scene, &o).unwrap();
    assert!(edge_differences(&plain)[0] > tolerance);
    // The ground's vertices are the trailing block, the grid's 9 and the midpoints on it.
    let g = refined.ground_vertices;
    assert!(g > 9 && report.ground_vertices == g, "{report:?}");
    let positions = refined.mesh.positions();
    let y = |v: usize| positions[[v, 1]];
    assert!((report.vertices - g..report.vertices).all(|v| y(v) == -1.0));
    assert!((0..report.vertices - g).all(|v| refined.albedo[[v, 0]] == 0.8));
}

#[test]
fn refine_first_then_bounce_bounces_over_the_refined_mesh() {
    let mut o = packet_options(Order::Vertex);
    o.bounces = 1;
    let r = refinement(0.6, 2000);
    let (bounced, _, _) = precompute_refined(ball_on_ground(), &o, &r).unwrap();
    let (direct, _, _) =
        precompute_refined(ball_on_ground(), &packet_options(Order::Vertex), &r).unwrap();
    // The refinement judges direct transport alone: the same mesh with or without bounces.
    assert_eq!(
        (&bounced.mesh, &bounced.transport),
        (&direct.mesh, &direct.transport)
    );
    let mut again = Scene::from_mesh(bounced.mesh.clone(), false).unwrap();
    again.albedo = bounced.albedo.clone();
    again.ground_plane = true;
    again.ground_cells = Some(2);
    again.ground_vertices = bounced.ground_vertices;
    let (unrefined, _) = precompute(again, &o).unwrap();
    let gathered = bounced.bounced.as_ref().expect("a bounced sum");
    assert!(gathered.coefficient_count() > 0);
    assert_eq!(unrefined.bounced.as_ref(), Some(gathered));
    assert_eq!(bounced.params.bounces, 1);
}

#[test]
fn the_probe_s_radiance_is_the_shaded_one_and_an_open_vertex_s_its_unoccluded_sum() {
    let o = packet_options(Order::Vertex);
    let probe = Probe::new("sun", &sun_environment(), o.visibility.param).unwrap();
    let (cache, _) = precompute(ball_on_ground(), &o).unwrap();
    // Against the Lambertian shading of the same transport (albedo pi: radiance <T, L>).
    let albedo = Array2::<f32>::from_elem((cache.mesh.vertex_count(), 3), std::f32::consts::PI);
    let shaded = shade_lambertian::<f64>(
        &cache.transport,
        albedo.view(),
        &probe.lighting,
        &ShadeOptions::default(),
    )
    .unwrap();
    let mut judge = Judge::new(o.visibility.param, Some(&probe));
    let bisection = Bisection::new(&ball_on_ground());
    judge.extend(&bisection, &cache.transport, 0..cache.mesh.vertex_count());
    for v in 0..cache.mesh.vertex_count() {
        for c in 0..3 {
            let (got, want) = (judge.radiance[v][c], shaded[[v, c]]);
            assert!(
                (got - want).abs() <= 1e-6 * want.abs().max(1e-3),
                "{v}: {got} {want}"
            );
        }
    }
    // A ground corner far from the ball sees the whole sky: its radiance is its scale.
    let (corner, r) = (
        cache.mesh.vertex_count() - 1,
        judge.radiance.last().unwrap(),
    );
    let rel = (norm(*r) - judge.scale[corner]).abs() / judge.scale[corner];
    assert!(rel < 1e-5, "{rel}");
    // A lighting at another parameterisation is refused.
    let mut r = refinement(0.3, 100);
    r.probe = Some(
        Probe::new(
            "sun",
            &sun_environment(),
            Parameterization::new(ParamKind::Cube, 4).unwrap(),
        )
        .unwrap(),
    );
    let e = r.check_with(&o, None).unwrap_err().to_string();
    assert!(e.contains("another parameterisation"), "{e}");
}

#[test]
fn under_a_sunny_probe_the_refinement_follows_the_shadow_to_its_far_end() {
    let o = packet_options(Order::Vertex);
    let mut r = refinement(0.3, 400);
    let (by_transport, _, _) = precompute_refined(ball_on_ground(), &o, &r).unwrap();
    r.probe = Some(Probe::new("sun", &sun_environment(), o.visibility.param).unwrap());
    let (by_probe, _, report) = precompute_refined(ball_on_ground(), &o, &r).unwrap();
    // The ground's 2 x 2 cells span [-4, 4]. The transport splits the ground's edges around
    // the contact alike on every side; the probe follows the shadow, which the sun at +x
    // casts towards -x: more new vertices beyond |x| = 2 near z = 0 on that side than on the
    // lit one.
    let beyond = |c: &SceneCache, side: f64| {
        let p = c.mesh.positions();
        (c.mesh.vertex_count() - c.ground_vertices..c.mesh.vertex_count())
            .filter(|&v| (2.01..3.99).contains(&(side * p[[v, 0]])) && p[[v, 2]].abs() < 0.9)
            .count()
    };
    let sides = |c: &SceneCache| [beyond(c, -1.0), beyond(c, 1.0)];
    let [shadow, lit] = sides(&by_probe);
    assert_eq!(sides(&by_transport)[0], sides(&by_transport)[1]);
    assert!(shadow > lit + 10, "{shadow} {lit}: {report:?}"); // measured 31 and 0
    let record = by_probe.params.refine.as_ref().unwrap();
    assert_eq!(record.probe.as_deref(), Some("sun"));
    // Still a plain precompute of the refined mesh.
    let mut again = Scene::from_mesh(by_probe.mesh.clone(), false).unwrap();
    again.albedo = by_probe.albedo.clone();
    again.ground_plane = true;
    again.ground_cells = Some(2);
    again.ground_vertices = by_probe.ground_vertices;
    assert_eq!(
        precompute(again, &o).unwrap().0.transport,
        by_probe.transport
    );
}

#[test]
fn the_budget_is_never_exceeded_and_what_it_left_is_reported() {
    let o = packet_options(Order::Vertex);
    for max in [63, 64, 70, 90] {
        let (cache, _, report) =
            precompute_refined(ball_on_ground(), &o, &refinement(0.05, max)).unwrap();
        assert_eq!(cache.mesh.vertex_count(), max, "{report:?}");
        assert_eq!((report.vertices, report.max_vertices), (max, max));
        let above = edge_differences(&cache)
            .iter()
            .filter(|&&d| d > 0.05)
            .count();
        assert_eq!(report.above + report.short, above);
        assert!(report.stopped_by_budget());
    }
}

#[test]
fn a_refined_cache_reads_back_with_its_ground_vertices() {
    let o = packet_options(Order::Vertex);
    let (cache, _, report) =
        precompute_refined(ball_on_ground(), &o, &refinement(0.5, 90)).unwrap();
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("refined.hsr");
    cache.write(&path, false).unwrap();
    let read = SceneCache::read(&path).unwrap();
    assert_eq!(read, cache);
    assert_eq!(
        read.object_vertices(),
        report.vertices - report.ground_vertices
    );
}

#[test]
fn what_refinement_cannot_be_combined_with_is_refused_before_any_work() {
    let refuse = |o: &PrecomputeOptions, r: Refinement, why: &str| {
        let err = precompute_refined(ball_on_ground(), o, &r)
            .unwrap_err()
            .to_string();
        assert!(err.contains(why), "{err}");
    };
    let o = packet_options(Order::Vertex);
    refuse(
        &packet_options(Order::Direction),
        refinement(0.1, 100),
        "--order direction",
    );
    let mut jittered = o;
    jittered.visibility.samples = 2;
    refuse(&jittered, refinement(0.1, 100), "--visibility-samples");
    for bad in [0.0, -1.0, 2.01, f64::NAN] {
        refuse(&o, refinement(bad, 100), "in (0, 2]");
    }
    refuse(
        &o,
        refinement(0.1, 62),
        "62 vertices: the scene has 63 already",
    );
    let mut small = o;
    small.memory_limit = 1 << 16;
    refuse(&small, refinement(0.1, 1_000_000), "the refined scene");
}
