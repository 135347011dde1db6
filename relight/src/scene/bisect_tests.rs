use ndarray::array;

use super::*;
use crate::scene::ground_plane_under;
use crate::scene::mesh::cross;

/// A scene of `mesh` alone (no ground plane).
fn scene_of(mesh: Mesh) -> Scene {
    Scene::from_mesh(mesh, false).unwrap()
}

/// The closed octahedron, one vertex per corner: every edge has exactly two triangles.
fn octahedron() -> Mesh {
    let p = array![
        [1.0, 0.0, 0.0],
        [-1.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        [0.0, -1.0, 0.0],
        [0.0, 0.0, 1.0],
        [0.0, 0.0, -1.0]
    ];
    let t = vec![
        [0, 2, 4],
        [2, 1, 4],
        [1, 3, 4],
        [3, 0, 4],
        [2, 0, 5],
        [1, 2, 5],
        [3, 1, 5],
        [0, 3, 5],
    ];
    Mesh::new(p, t, None).unwrap()
}

fn position(b: &Bisection, v: u32) -> [f64; 3] {
    b.positions[v as usize]
}

/// Twice the area vector of triangle `t`.
fn area(b: &Bisection, t: [u32; 3]) -> [f64; 3] {
    let (p, q, r) = (position(b, t[0]), position(b, t[1]), position(b, t[2]));
    cross(sub(q, p), sub(r, p))
}

/// The conformity of a bisection of a mesh whose edges had at most `most` triangles: every
/// edge has at most `most` triangles, each edge with two is used once in each direction (the
/// windings agree), the edge map is exactly the triangles' edges, and no vertex lies inside
/// any triangle's edge (no T-junction: a midpoint is a vertex of every triangle beside it).
fn assert_conforming(b: &Bisection, most: usize) {
    let mut directed = BTreeMap::<(u32, u32), usize>::new();
    let mut undirected = BTreeMap::<Edge, Vec<u32>>::new();
    for (t, tri) in b.triangles().iter().enumerate() {
        for i in 0..3 {
            let (x, y) = (tri[i], tri[(i + 1) % 3]);
            *directed.entry((x, y)).or_default() += 1;
            undirected.entry(edge(x, y)).or_default().push(t as u32);
        }
    }
    for (&e, ts) in &undirected {
        assert!(ts.len() <= most, "edge {e:?} has {} triangles", ts.len());
        if ts.len() == 2 {
            assert_eq!(directed.get(&(e.0, e.1)), Some(&1), "edge {e:?}");
            assert_eq!(directed.get(&(e.1, e.0)), Some(&1), "edge {e:?}");
        }
        let mut mine = b.triangles_of(e).to_vec();
        mine.sort_unstable();
        assert_eq!(&mine, ts, "edge {e:?}");
    }
    assert_eq!(b.edges().count(), undirected.len());
    for &(x, y) in undirected.keys() {
        let (p, q) = (position(b, x), position(b, y));
        let d = sub(q, p);
        for v in 0..b.vertex_count() as u32 {
            if v == x || v == y {
                continue;
            }
            let w = sub(position(b, v), p);
            let off = cross(d, w);
            let along = dot(w, d) / dot(d, d);
            let inside = dot(off, off) <= 1e-20 * dot(d, d) && along > 1e-9 && along < 1.0 - 1e-9;
            assert!(
                !inside,
                "vertex {v} lies inside edge ({x}, {y}): a T-junction"
            );
        }
    }
}

fn square() -> Mesh {
    let corners = array![
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [1.0, 0.0, -1.0],
        [0.0, 0.0, -1.0]
    ];
    Mesh::new(corners, vec![[0, 1, 2], [0, 2, 3]], None).unwrap()
}

#[test]
fn splitting_the_shared_diagonal_of_a_square_splits_both_triangles_at_one_midpoint() {
    let mut b = Bisection::new(&scene_of(square()));
    assert!(b.split((0, 2), 100));
    assert_eq!(b.vertex_count(), 5);
    assert_eq!(position(&b, 4), [0.5, 0.0, -0.5]);
    // [0, 1, 2] has the edge as 2 -> 0, [0, 2, 3] as 0 -> 2: each halves keeping its winding.
    assert_eq!(b.triangles(), &[[2, 4, 1], [0, 4, 3], [4, 0, 1], [4, 2, 3]]);
    for &t in b.triangles() {
        assert_eq!(area(&b, t), [0.0, 0.5, 0.0], "{t:?}"); // a quarter of the square, +Y
    }
    assert_eq!(b.normals[4], [0.0, 1.0, 0.0]);
    assert_eq!(b.triangles_of((0, 2)), &[] as &[u32]);
    assert_conforming(&b, 2);
}

#[test]
fn a_short_edge_waits_for_the_longest_edge_of_its_triangle_and_its_neighbour() {
    // The square's side (0, 1) is not the longest edge of [0, 1, 2]: the diagonal (0, 2) is
    // split first (in both triangles); then the side is the longest edge of the half
    // [4, 0, 1] that has it, and is split.
    let mut b = Bisection::new(&scene_of(square()));
    assert!(b.split((0, 1), 100));
    assert_eq!(position(&b, 4), [0.5, 0.0, -0.5]); // the diagonal's midpoint first
    assert_eq!(position(&b, 5), [0.5, 0.0, 0.0]); // then the side's
    assert_eq!((b.vertex_count(), b.triangles().len()), (6, 5));
    assert!(b.edges().all(|e| e != (0, 1)));
    assert_conforming(&b, 2);
}

/// The sum of the triangles' areas (twice).
fn total_area(b: &Bisection) -> f64 {
    b.triangles()
        .iter()
        .map(|&t| dot(area(b, t), area(b, t)).sqrt())
        .sum()
}

/// The mean of triangle `t`'s corners.
fn centroid(b: &Bisection, t: [u32; 3]) -> [f64; 3] {
    std::array::from_fn(|k| t.iter().map(|&v| position(b, v)[k]).sum::<f64>() / 3.0)
}

#[test]
fn every_sequence_of_splits_of_small_meshes_conforms_and_keeps_their_area_and_winding() {
    let flat = ground_plane_under(&square().bounds(), 2).unwrap();
    // Whether a triangle of area vector `n` at `c` faces the way the mesh does.
    let up = |n: [f64; 3], _: [f64; 3]| n[1] > 0.0;
    let outward = |n: [f64; 3], c: [f64; 3]| dot(n, c) > 0.0;
    type Facing<'a> = &'a dyn Fn([f64; 3], [f64; 3]) -> bool;
    let cases: [(Mesh, Facing); 3] = [(square(), &up), (flat, &up), (octahedron(), &outward)];
    for (mesh, faces) in cases {
        let original = Bisection::new(&scene_of(mesh));
        // Each edge alone, then every edge the mesh then has, in turn, to two levels.
        for first in original.edges() {
            let mut b = original.clone();
            assert!(b.split(first, 10_000));
            assert_conforming(&b, 2);
            for level in 0..2 {
                let edges: Vec<Edge> = b.edges().collect();
                for e in edges {
                    assert!(b.split(e, 10_000), "level {level}");
                    assert_conforming(&b, 2);
                }
            }
            let (now, was) = (total_area(&b), total_area(&original));
            assert!((now - was).abs() < 1e-12 * was, "{now} {was}");
            for &t in b.triangles() {
                assert!(faces(area(&b, t), centroid(&b, t)), "{t:?}");
            }
        }
    }
}

#[test]
fn the_budget_stops_a_split_before_the_vertex_that_would_exceed_it_leaving_the_mesh_conforming() {
    let mut b = Bisection::new(&scene_of(octahedron()));
    assert!(!b.split((0, 2), 6));
    assert_eq!(b.vertex_count(), 6);
    // The octahedron's edges are all of one length and ties go to the larger indices, so
    // (0, 2)'s triangle [0, 2, 4] has (2, 4) as its longest, split first: 7 vertices allow
    // that one only.
    assert!(!b.split((0, 2), 7));
    assert_eq!(b.vertex_count(), 7);
    assert!(b.edges().any(|e| e == (0, 2)));
    assert_conforming(&b, 2);
    assert!(b.split((0, 2), 100));
    assert_conforming(&b, 2);
}

#[test]
fn new_vertices_interpolate_normals_and_albedo_and_the_ground_stays_the_trailing_block() {
    let mut scene = scene_of(octahedron());
    scene.albedo.row_mut(0).fill(0.2);
    scene.add_ground_plane_of(1).unwrap(); // vertices 6..10
    let mut b = Bisection::new(&scene);
    assert!(b.split((0, 2), 100)); // object midpoints first
    let objects = b.vertex_count();
    let length = |b: &Bisection, (x, y): Edge| {
        let d = sub(position(b, x), position(b, y));
        dot(d, d)
    };
    let diagonal = (b.edges().filter(|e| e.0 >= 6))
        .max_by(|&e, &f| length(&b, e).total_cmp(&length(&b, f)))
        .unwrap();
    assert!(b.split(diagonal, 100)); // the ground's diagonal
    assert_eq!(b.vertex_count(), objects + 1);
    let n = |v: usize| scene.mesh.normals().row(v).to_vec();
    let m = (0..b.vertex_count())
        .find(|&v| b.positions[v] == [0.5, 0.5, 0.0])
        .expect("the edge's midpoint");
    let sum: Vec<f64> = (0..3).map(|k| n(0)[k] + n(2)[k]).collect();
    let len = sum.iter().map(|x| x * x).sum::<f64>().sqrt();
    for (got, s) in b.normals[m].iter().zip(&sum) {
        assert!((got - s / len).abs() < 1e-15);
    }
    assert_eq!(b.albedo[m], [0.5 * (0.2f32 + 0.8); 3]);
    let refined = b.scene(&scene).unwrap();
    let (v, g) = (refined.mesh.vertex_count(), refined.ground_vertices);
    assert_eq!((v, g), (b.vertex_count(), 5));
    assert_eq!(refined.object_vertices(), objects - 4);
    // Originals keep their places: the objects' first, the ground's after the new objects'.
    let order = b.order();
    assert_eq!(&order[..6], &[0, 1, 2, 3, 4, 5]);
    assert_eq!(&order[v - 5..v - 1], &[6, 7, 8, 9]);
    assert_eq!(order[v - 1] as usize, objects);
    for (k, &from) in order.iter().enumerate() {
        assert_eq!(
            refined.mesh.positions().row(k).to_vec(),
            b.positions[from as usize].to_vec()
        );
    }
    assert!(
        refined
            .mesh
            .positions()
            .outer_iter()
            .skip(v - g)
            .all(|p| p[1] == -1.0)
    );
}
