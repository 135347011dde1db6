use rand::rngs::StdRng;
use rand::{Rng, SeedableRng};

use obvhs::ray::Ray;

use super::*;
use crate::relight::{Scene, add_ground_plane};

fn bunny_on_ground() -> Mesh {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/testdata/meshes/bunny.ply");
    let mut mesh = Mesh::load(path.as_ref()).unwrap();
    add_ground_plane(&mut mesh).unwrap();
    mesh
}

fn traced(bvh: &SceneBvh) -> &[obvhs::rt_triangle::RtTriangle] {
    bvh.bvh.as_ref().map_or(&[], |b| &b.triangles)
}

/// The oracle: every triangle tested, the same intersection routine.
fn brute_force(bvh: &SceneBvh, origin: [f32; 3], direction: [f32; 3], t_max: f32) -> bool {
    let ray = Ray::new(
        Vec3A::from_array(origin),
        Vec3A::from_array(direction),
        0.0,
        t_max,
    );
    traced(bvh).iter().any(|t| t.intersect(&ray) < t_max)
}

#[test]
fn bvh_answers_as_testing_every_triangle() {
    let mesh = bunny_on_ground();
    let bvh = SceneBvh::new(&mesh);
    assert_eq!(traced(&bvh).len(), mesh.triangles().len()); // none degenerate here
    let b = mesh.bounds();
    let mut rng = StdRng::seed_from_u64(11);
    let mut hits = 0;
    for k in 0..20_000 {
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
        let d = d.map(|x| x / len);
        let t_max = if k % 3 == 0 { 2.0 } else { f32::INFINITY };
        let want = brute_force(&bvh, origin, d, t_max);
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
    let bvh = SceneBvh::new(&mesh);
    assert!(traced(&bvh).is_empty());
    assert!(!bvh.occluded([0.5, 0.0, 0.0], [0.0, 1.0, 0.0], f32::INFINITY));
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
    let bvh = SceneBvh::new(&mesh);
    assert_eq!(traced(&bvh).len(), 1);
    assert!(bvh.occluded([0.0, 0.0, 0.0], [0.0, 1.0, 0.0], f32::INFINITY));
    assert!(!bvh.occluded([0.0, 0.0, 0.0], [0.0, -1.0, 0.0], f32::INFINITY));
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
    let (near, tiny) = (
        SceneBvh::new(&scaled(unit)),
        SceneBvh::new(&scaled(2f64.powi(-76))),
    );
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

#[test]
fn packets_from_vertices_answer_as_testing_every_triangle() {
    // The visibility case: from just above vertices of the bunny on its ground, one ray to
    // every cube 8 x 8 texel centre, in the order and packets precomputation casts them.
    let mesh = bunny_on_ground();
    let bvh = SceneBvh::new(&mesh);
    let param = crate::faces::Parameterization::new(crate::faces::ParamKind::Cube, 8).unwrap();
    let directions: Vec<[f32; 3]> = (0..param.texels())
        .map(|t| {
            param
                .texel_direction(t / 64, (t / 8) % 8, t % 8)
                .map(|x| x as f32)
        })
        .collect();
    let eps = crate::relight::ray_offset(&mesh);
    let mut blocked = vec![false; directions.len()];
    let mut hits = 0;
    for v in (0..mesh.vertex_count()).step_by(97) {
        let origin: [f32; 3] = std::array::from_fn(|k| {
            (mesh.positions()[[v, k]] + eps * mesh.normals()[[v, k]]) as f32
        });
        bvh.occluded_from(origin, &directions, f32::INFINITY, &mut blocked);
        for (d, &b) in directions.iter().zip(&blocked) {
            assert_eq!(
                b,
                brute_force(&bvh, origin, *d, f32::INFINITY),
                "vertex {v} {d:?}"
            );
            hits += usize::from(b);
        }
    }
    let rays = directions.len() * mesh.vertex_count().div_ceil(97);
    assert!((rays / 5..rays * 4 / 5).contains(&hits), "{hits} of {rays}");
}
