use rand::rngs::StdRng;
use rand::{Rng, SeedableRng};

use super::*;
use crate::relight::{Scene, add_ground_plane};

fn bunny_on_ground() -> Mesh {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/testdata/meshes/bunny.ply");
    let mut mesh = Mesh::load(path.as_ref()).unwrap();
    add_ground_plane(&mut mesh).unwrap();
    mesh
}

/// The oracle: every triangle tested, the same intersection routine.
fn brute_force(bvh: &SceneBvh, origin: [f32; 3], direction: [f32; 3], t_max: f32) -> bool {
    let ray = Ray::new(
        Vec3A::from_array(origin),
        Vec3A::from_array(direction),
        0.0,
        t_max,
    );
    bvh.triangles.iter().any(|t| {
        let hit = t.intersect(&ray);
        hit.is_finite() && hit <= t_max
    })
}

#[test]
fn bvh_answers_as_testing_every_triangle() {
    let mesh = bunny_on_ground();
    let bvh = SceneBvh::new(&mesh);
    assert_eq!(bvh.triangles.len(), mesh.triangles().len()); // none degenerate here
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
    assert!(bvh.triangles.is_empty());
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
    assert_eq!(bvh.triangles.len(), 1);
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
        hits += usize::from(answer);
    }
    assert!((1_000..19_000).contains(&hits), "{hits}");
}
