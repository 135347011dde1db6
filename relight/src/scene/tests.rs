use std::path::Path;

use super::*;
use crate::Error;
use crate::SceneError;
use crate::scene::mesh::sub;
use crate::scene::mesh::{cross, dot};
use crate::scene::shapes::{cuboid, cylinder};

/// Every triangle of a closed convex mesh faces away from `centre`.
fn assert_outward(mesh: &Mesh, centre: [f64; 3]) {
    let p = mesh.positions();
    let point = |i: u32| [0, 1, 2].map(|k| p[[i as usize, k]]);
    for (k, t) in mesh.triangles().iter().enumerate() {
        let (a, b, c) = (point(t[0]), point(t[1]), point(t[2]));
        let n = cross(sub(b, a), sub(c, a));
        let g: [f64; 3] = std::array::from_fn(|i| (a[i] + b[i] + c[i]) / 3.0 - centre[i]);
        assert!(dot(n, g) > 0.0, "triangle {k} faces inward");
    }
}

#[test]
fn generators_have_their_documented_sizes() {
    // The count from the settings alone is the built mesh's, for every generator.
    let count = |g: Generator| {
        let built = g.mesh().unwrap().vertex_count();
        assert_eq!(g.vertex_count(), Some(built), "{g:?}");
        built
    };
    assert_eq!(count(Generator::Table { cells: 3 }), 30 * 16);
    assert_eq!(count(Generator::Chair { cells: 2 }), 36 * 9);
    assert_eq!(count(Generator::CylinderAndBump { cells: 96 }), 10_707);
    assert_eq!(
        count(Generator::CylinderAndBump { cells: 32 }),
        33 * 33 + 10_707 - 97 * 97
    );
    assert_eq!(
        count(Generator::Cubes {
            count: 10,
            cells: 10,
            distance: 1.5
        }),
        85_860
    );
    assert_eq!(
        count(Generator::Cubes {
            count: 2,
            cells: 3,
            distance: 1.0
        }),
        6 * 4 * 16 + 13_260
    );
    assert_eq!(count(Generator::PlaneWithSphere {}), 5_959);
    assert_eq!(count(Generator::Sphere { cells: 16 }), 1_734);
    assert_eq!(count(Generator::PlaneUnderBox { height: 1.0 }), 159);
    assert_err!(
        Generator::Sphere { cells: 0 }.mesh(),
        InvalidParameter {
            name: "generator",
            ..
        },
        "0 cells"
    );
    assert_err!(
        Generator::Cubes {
            count: 0,
            cells: 10,
            distance: 1.5
        }
        .mesh(),
        InvalidParameter {
            name: "generator",
            ..
        },
        "0 cubes per row"
    );
    assert_err!(
        Generator::PlaneUnderBox { height: -1.0 }.mesh(),
        InvalidParameter { name: "height", .. },
        "-1: must be positive"
    );
}

#[test]
fn closed_shapes_face_outward_and_spheres_have_radial_normals() {
    let sphere = Generator::Sphere { cells: 6 }.mesh().unwrap();
    assert_outward(&sphere, [0.0; 3]);
    for v in 0..sphere.vertex_count() {
        let p = [0, 1, 2].map(|k| sphere.positions()[[v, k]]);
        let n = [0, 1, 2].map(|k| sphere.normals()[[v, k]]);
        assert!((dot(p, p) - 1.0).abs() < 1e-12 && (dot(p, n) - 1.0).abs() < 1e-12);
    }
    assert_outward(
        &cuboid([0.0, 1.0, 2.0], [1.0, 3.0, 2.5], 3).unwrap(),
        [0.5, 2.0, 2.25],
    );
    assert_outward(&cylinder([1.0, 0.0, 1.0], 0.5, 3.0, 12, 4), [1.0, 1.5, 1.0]);
    // The cubes face away from their own centres, the wall towards them (+Z).
    let cubes = Generator::Cubes {
        count: 1,
        cells: 2,
        distance: 1.5,
    }
    .mesh()
    .unwrap();
    let only_cube = Mesh::new(
        cubes.positions().to_owned(),
        cubes.triangles()[2 * 129 * 101..].to_vec(),
        None,
    )
    .unwrap();
    assert_outward(&only_cube, [0.0, 0.6, 1.5]);
    assert_eq!(cubes.normals().row(0).to_vec(), vec![0.0, 0.0, 1.0]);
}

#[test]
fn the_ground_plane_follows_its_definition() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../testdata/meshes/bunny.ply");
    let bunny = Mesh::load(&path).unwrap();
    let b = bunny.bounds();
    let mut with = bunny.clone();
    add_ground_plane(&mut with).unwrap();
    let v = bunny.vertex_count();
    assert_eq!(with.vertex_count(), v + 33 * 33);
    assert_eq!(
        with.positions().slice(ndarray::s![..v, ..]),
        bunny.positions()
    );
    let side = 4.0 * (b.max[0] - b.min[0]).max(b.max[2] - b.min[2]);
    let c = b.centre();
    let ground = with.positions().slice(ndarray::s![v.., ..]).to_owned();
    for (k, p) in ground.outer_iter().enumerate() {
        assert_eq!(p[1], b.min[1]);
        assert_eq!(with.normals().row(v + k).to_vec(), vec![0.0, 1.0, 0.0]);
    }
    // First vertex at (-x, +z), x fastest, spacing side / 32.
    assert!((ground[[0, 0]] - (c[0] - side / 2.0)).abs() < 1e-12);
    assert!((ground[[0, 2]] - (c[2] + side / 2.0)).abs() < 1e-12);
    assert!((ground[[1, 0]] - ground[[0, 0]] - side / 32.0).abs() < 1e-12);
    assert!((ground[[33, 2]] - ground[[0, 2]] + side / 32.0).abs() < 1e-12);
    assert!((ground[[1088, 0]] - (c[0] + side / 2.0)).abs() < 1e-12);
}

#[test]
fn transforms_scale_rotate_then_translate() {
    let mesh = Generator::PlaneUnderBox { height: 1.0 }.mesh().unwrap();
    let t = Transform {
        translate: [1.0, 2.0, 3.0],
        scale: 2.0,
        yaw: 90.0,
        pitch: 0.0,
        roll: 0.0,
    };
    let moved = t.apply(&mesh).unwrap();
    // Vertex 0 is (-3, 0, 3): scaled (-6, 0, 6); yaw 90 takes +Z to +X and +X to -Z.
    let p = moved.positions().row(0).to_vec();
    let want = [6.0 + 1.0, 2.0, 6.0 + 3.0];
    for k in 0..3 {
        assert!((p[k] - want[k]).abs() < 1e-12, "{p:?}");
    }
    // The box's +X face normal turns to -Z.
    let n = moved.normals().row(9).to_vec();
    assert!((n[2] + 1.0).abs() < 1e-12, "{n:?}");
    assert_err!(
        Transform {
            scale: 0.0,
            ..Transform::default()
        }
        .apply(&mesh),
        InvalidParameter {
            name: "transform",
            ..
        },
        "scale must be positive"
    );
}

fn scene_file_refusal(json: &str) -> SceneError {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("scene.json");
    std::fs::write(&path, json).unwrap();
    crate::refusal_in(Scene::load(&path), &path)
}

#[test]
fn scene_files_refuse_unknown_keys_and_bad_objects() {
    let sphere = r#"{"generator": {"sphere": {"cells": 2}}}"#;
    let cases = [
        format!(r#"{{"objects": [{sphere}], "lights": 1}}"#),
        r#"{"objects": [{"generator": {"sphere": {"cells": 2}}, "colour": 1}]}"#.into(),
        r#"{"objects": [{"generator": {"sphere": {"cells": 2, "r": 1}}}]}"#.into(),
        r#"{"objects": [{"generator": {"teapot": {}}}]}"#.into(),
        format!(r#"{{"objects": [{sphere}], "camera": {{"position": [0,0,0], "look_at": [0,0,1], "zoom": 2}}}}"#),
        r#"{"objects": [{"generator": {"sphere": {"cells": 2}}, "transform": {"rotate": 1}}]}"#.into(),
        r#"{"objects": [{"generator": {"sphere": {"cells": 2}}, "material": {"brdf": "lambert", "albedo": [1,1,1], "gloss": 1}}]}"#.into(),
        r#"{"objects": [{"generator": {"sphere": {"cells": 2}}, "material": {"brdf": "phong", "albedo": [1,1,1]}}]}"#.into(),
        r#"{"objects": [{"generator": {"sphere": {"cells": 2}}, "material": {"brdf": "lambert", "albedo": [2,1,1]}}]}"#.into(),
        r#"{"objects": [{"mesh": "a.ply", "generator": {"sphere": {"cells": 2}}}]}"#.into(),
        r#"{"objects": [{}]}"#.into(),
        r#"{"objects": []}"#.into(),
        r#"{"objects": [ "#.into(),
    ];
    for json in &cases {
        assert!(
            matches!(scene_file_refusal(json), SceneError::SceneFile(_)),
            "{json}"
        );
    }
    // A mesh path that does not exist names that file.
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("scene.json");
    std::fs::write(&path, r#"{"objects": [{"mesh": "missing.ply"}]}"#).unwrap();
    let e = Scene::load(&path).unwrap_err();
    assert!(
        matches!(e, Error::Core(haarshift::Error::Io { .. }))
            && e.to_string().contains("missing.ply")
    );
}

#[test]
fn scene_files_resolve_paths_against_their_directory() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::create_dir(dir.path().join("meshes")).unwrap();
    let bunny = Path::new(env!("CARGO_MANIFEST_DIR")).join("../testdata/meshes/bunny.ply");
    std::fs::copy(&bunny, dir.path().join("meshes/bunny.ply")).unwrap();
    let json = r#"{
        "objects": [
            {"mesh": "meshes/bunny.ply", "transform": {"translate": [0, 1, 0]},
             "material": {"brdf": "lambert", "albedo": [0.1, 0.2, 0.3]}},
            {"generator": {"sphere": {"cells": 2}}}
        ],
        "ground_plane": true,
        "environment": {"path": "env/sky.hdr", "yaw": 30},
        "camera": {"position": [0, 5, 20], "look_at": [0, 4, 0]}
    }"#;
    let path = dir.path().join("scene.json");
    std::fs::write(&path, json).unwrap();
    let scene = Scene::load(&path).unwrap();
    assert_eq!(scene.mesh.vertex_count(), 1839 + 54 + 1089);
    assert_eq!(scene.albedo.dim(), (1839 + 54 + 1089, 3));
    assert_eq!(scene.albedo.row(0).to_vec(), vec![0.1, 0.2, 0.3]);
    assert_eq!(scene.albedo.row(1839).to_vec(), vec![0.8, 0.8, 0.8]);
    let original = Mesh::load(&bunny).unwrap();
    assert_eq!(
        scene.mesh.positions()[[7, 1]],
        original.positions()[[7, 1]] + 1.0
    );
    let env = scene.environment.unwrap();
    assert_eq!((env.path, env.yaw), (dir.path().join("env/sky.hdr"), 30.0));
    assert_eq!(scene.camera.unwrap().fov, 45.0);
    // A mesh file is a scene of one object.
    let single = Scene::load(&bunny).unwrap();
    assert_eq!(single.mesh, original);
}

#[test]
fn the_open_box_has_five_inward_faces_and_the_stated_extent() {
    let cells = 3;
    let m = Generator::OpenBox { cells }.mesh().unwrap();
    let face = (cells + 1) * (cells + 1);
    assert_eq!(m.vertex_count(), 5 * face);
    assert_eq!(m.triangles().len(), 5 * 2 * cells * cells);
    let b = m.bounds();
    assert_eq!((b.min, b.max), ([-1.0, 0.0, -1.0], [1.0, 2.0, 1.0]));
    // Floor +Y, walls x = -1 (+X), x = 1 (-X), z = -1 (+Z), z = 1 (-Z): each face's normal
    // points from its plane toward the box's centre line, and every winding agrees with it.
    let normals = [
        [0.0, 1.0, 0.0],
        [1.0, 0.0, 0.0],
        [-1.0, 0.0, 0.0],
        [0.0, 0.0, 1.0],
        [0.0, 0.0, -1.0],
    ];
    for v in 0..m.vertex_count() {
        let n = [0, 1, 2].map(|k| m.normals()[[v, k]]);
        assert_eq!(n, normals[v / face], "vertex {v}");
        let p = [0, 1, 2].map(|k| m.positions()[[v, k]]);
        assert!(dot(n, [-p[0], 1.0 - p[1], -p[2]]) > 0.0);
    }
    for t in m.triangles() {
        let [a, b, c] = t.map(|i| [0, 1, 2].map(|k| m.positions()[[i as usize, k]]));
        let n = [0, 1, 2].map(|k| m.normals()[[t[0] as usize, k]]);
        assert!(dot(n, cross(sub(b, a), sub(c, a))) > 0.0);
    }
    assert_eq!(Generator::OpenBox { cells }.vertex_count(), Some(5 * face));
    assert_err!(
        Generator::OpenBox { cells: 0 }.mesh(),
        InvalidParameter {
            name: "generator",
            ..
        },
        "0 cells: must be at least 1"
    );
}
