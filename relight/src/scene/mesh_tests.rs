use std::io::Write;
use std::path::{Path, PathBuf};

use ndarray::array;

use super::*;
use crate::test_support::differing_bits;

fn testdata(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../testdata/meshes")
        .join(name)
}

/// Writes `bytes` to `name` in a fresh directory and loads it.
fn load_bytes(name: &str, bytes: &[u8]) -> Result<Mesh> {
    load_in(name, bytes).0
}

/// [`load_bytes`] and the path it wrote.
fn load_in(name: &str, bytes: &[u8]) -> (Result<Mesh>, PathBuf) {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join(name);
    std::fs::File::create(&path)
        .unwrap()
        .write_all(bytes)
        .unwrap();
    (Mesh::load(&path), path)
}

/// The refusal of a mesh file, which must name the file.
fn mesh_refusal((result, path): (Result<Mesh>, PathBuf)) -> SceneError {
    crate::refusal_in(result, &path)
}

/// A square pyramid: apex 4 over the square 0..4, one quad base (two triangles when read).
const PYRAMID_ASCII: &str = "ply\nformat ascii 1.0\nelement vertex 5\nproperty float x\nproperty float y\nproperty float z\nelement face 5\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n1 0 -1\n0 0 -1\n0.5 1 -0.5\n4 0 3 2 1\n3 0 1 4\n3 1 2 4\n3 2 3 4\n3 3 0 4\n";

const PYRAMID_POSITIONS: [[f32; 3]; 5] = [
    [0.0, 0.0, 0.0],
    [1.0, 0.0, 0.0],
    [1.0, 0.0, -1.0],
    [0.0, 0.0, -1.0],
    [0.5, 1.0, -0.5],
];
const PYRAMID_FACES: [&[i32]; 5] = [
    &[0, 3, 2, 1],
    &[0, 1, 4],
    &[1, 2, 4],
    &[2, 3, 4],
    &[3, 0, 4],
];

/// The pyramid as binary PLY in the given byte order.
fn pyramid_binary(big_endian: bool) -> Vec<u8> {
    let format = if big_endian {
        "binary_big_endian"
    } else {
        "binary_little_endian"
    };
    let mut out = PYRAMID_ASCII
        .replace("format ascii", &format!("format {format}"))
        .split("end_header\n")
        .next()
        .unwrap()
        .to_string()
        .into_bytes();
    out.extend_from_slice(b"end_header\n");
    let f32b = |x: f32| {
        if big_endian {
            x.to_be_bytes()
        } else {
            x.to_le_bytes()
        }
    };
    let i32b = |x: i32| {
        if big_endian {
            x.to_be_bytes()
        } else {
            x.to_le_bytes()
        }
    };
    for p in PYRAMID_POSITIONS {
        p.iter().for_each(|&x| out.extend_from_slice(&f32b(x)));
    }
    for f in PYRAMID_FACES {
        out.push(f.len() as u8);
        f.iter().for_each(|&i| out.extend_from_slice(&i32b(i)));
    }
    out
}

#[test]
fn bunny_ply_and_obj_are_the_same_mesh() {
    let ply = Mesh::load(&testdata("bunny.ply")).unwrap();
    let obj = Mesh::load(&testdata("bunny.obj")).unwrap();
    assert_eq!((ply.vertex_count(), ply.triangles().len()), (1839, 3674));
    assert_eq!(ply.triangles(), obj.triangles());
    // PLY stores f32, OBJ decimal text: the same points to f32 rounding.
    let diff = (&ply.positions() - &obj.positions())
        .iter()
        .fold(0.0f64, |m, d| m.max(d.abs()));
    assert!(diff < 1e-6, "{diff}");
    // Y up, resting on y = 0 (the SOURCES table says so; the lowest point is at -0.003 of a
    // height of 9.65).
    let b = ply.bounds();
    assert!(b.min[1].abs() < 1e-3 * b.max[1] && b.max[1] > 9.0, "{b:?}");
}

#[test]
fn ascii_and_both_binary_byte_orders_read_alike() {
    let ascii = load_bytes("p.ply", PYRAMID_ASCII.as_bytes()).unwrap();
    for big in [false, true] {
        let binary = load_bytes("p.ply", &pyramid_binary(big)).unwrap();
        assert_eq!(binary, ascii, "big endian: {big}");
    }
    // The quad base is a fan of two triangles, then the four sides.
    assert_eq!(ascii.triangles().len(), 6);
    assert_eq!(&ascii.triangles()[..2], &[[0, 3, 2], [0, 2, 1]]);
}

#[test]
fn normals_are_the_area_weighted_mean_of_the_incident_faces() {
    // Two triangles meeting along the edge 0-1: a big one in the plane y = 0 (area 2, normal
    // +Y) and a small one in the plane x = 0 (area 0.5, normal +X).
    let positions = array![
        [0.0, 0.0, 0.0],
        [0.0, 0.0, -1.0],
        [-4.0, 0.0, 0.0],
        [0.0, -1.0, 0.0],
    ];
    let mesh = Mesh::new(positions, vec![[0, 1, 2], [0, 3, 1]], None).unwrap();
    // Oracle by hand: 2 (0, 1, 0) + 0.5 (1, 0, 0), normalised.
    let len = (2.0f64 * 2.0 + 0.5 * 0.5).sqrt();
    let want = [0.5 / len, 2.0 / len, 0.0];
    for v in [0, 1] {
        let n = mesh.normals().row(v).to_vec();
        for k in 0..3 {
            assert!((n[k] - want[k]).abs() < 1e-15, "{n:?}");
        }
    }
    assert_eq!(mesh.normals().row(2).to_vec(), vec![0.0, 1.0, 0.0]);
    assert_eq!(mesh.normals().row(3).to_vec(), vec![1.0, 0.0, 0.0]);
}

#[test]
fn degenerate_triangles_and_unused_vertices_work() {
    let positions = array![
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [0.0, 0.0, -1.0],
        [5.0, 5.0, 5.0],
    ];
    // A repeated vertex and three collinear points: both zero area.
    let triangles = vec![[0, 1, 2], [0, 0, 1], [0, 1, 1]];
    let mesh = Mesh::new(positions, triangles, None).unwrap();
    assert_eq!(mesh.normals().row(0).to_vec(), vec![0.0, 1.0, 0.0]);
    // Vertex 3 is in no triangle: normal zero (it receives no light).
    assert_eq!(mesh.normals().row(3).to_vec(), vec![0.0, 0.0, 0.0]);
}

#[test]
fn file_normals_are_used_and_normalised() {
    let obj = "v 0 0 0\nv 1 0 0\nv 0 0 -1\nvn 0 2 0\nvn 3 0 0\nvn 0 0 0\nf 1//1 2//2 3//3\n";
    let mesh = load_bytes("t.obj", obj.as_bytes()).unwrap();
    assert_eq!(mesh.normals().row(0).to_vec(), vec![0.0, 1.0, 0.0]);
    assert_eq!(mesh.normals().row(1).to_vec(), vec![1.0, 0.0, 0.0]);
    // A zero file normal falls back to the computed one.
    assert_eq!(mesh.normals().row(2).to_vec(), vec![0.0, 1.0, 0.0]);
    // Normals indexed unlike the positions cannot be per-vertex: computed instead.
    let shuffled = obj.replace("f 1//1 2//2 3//3", "f 1//2 2//1 3//3");
    let mesh = load_bytes("t.obj", shuffled.as_bytes()).unwrap();
    assert_eq!(mesh.normals().row(1).to_vec(), vec![0.0, 1.0, 0.0]);
}

#[test]
fn obj_keeps_the_file_vertex_order_and_relative_indices() {
    let obj = "o a\nv 9 9 9\nv 0 0 0\nv 1 0 0\nv 0 0 -1\ng b\nf -3 -2 -1\nf 2 3 4 1\n";
    let mesh = load_bytes("t.obj", obj.as_bytes()).unwrap();
    assert_eq!(mesh.positions().row(0).to_vec(), vec![9.0, 9.0, 9.0]);
    assert_eq!(mesh.triangles(), &[[1, 2, 3], [1, 2, 3], [1, 3, 0]]);
}

#[test]
fn bad_meshes_give_typed_errors_naming_the_file() {
    let no_faces = PYRAMID_ASCII
        .replace("element face 5", "element face 0")
        .split("4 0 3 2 1")
        .next()
        .unwrap()
        .to_string();
    assert_eq!(
        mesh_refusal(load_in("a.ply", no_faces.as_bytes())),
        SceneError::NoFaces
    );
    assert_eq!(
        mesh_refusal(load_in("a.obj", b"v 0 0 0\nv 1 0 0\n")),
        SceneError::NoFaces
    );
    let out_of_range = PYRAMID_ASCII.replace("3 3 0 4", "3 3 0 7");
    assert_eq!(
        mesh_refusal(load_in("a.ply", out_of_range.as_bytes())),
        SceneError::IndexOutOfRange {
            triangle: 5,
            index: 7,
            vertices: 5
        }
    );
    assert!(matches!(
        mesh_refusal(load_in("a.obj", b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 4\n")),
        SceneError::IndexOutOfRange { index: 3, .. }
    ));
    for bad in ["nan", "inf", "-inf"] {
        let obj = format!("v 0 0 0\nv 1 {bad} 0\nv 0 1 0\nf 1 2 3\n");
        assert!(matches!(
            mesh_refusal(load_in("a.obj", obj.as_bytes())),
            SceneError::NonFinite { vertex: 1, .. }
        ));
    }
    let nan_ply = PYRAMID_ASCII.replace("0.5 1 -0.5", "0.5 nan -0.5");
    assert!(matches!(
        mesh_refusal(load_in("a.ply", nan_ply.as_bytes())),
        SceneError::NonFinite { vertex: 4, .. } | SceneError::Corrupt(_)
    ));
    // Truncated binary and ASCII files, a damaged header, garbage.
    let bunny = std::fs::read(testdata("bunny.ply")).unwrap();
    for cut in [bunny.len() - 1, bunny.len() / 2, 200, 20] {
        assert!(
            matches!(
                mesh_refusal(load_in("a.ply", &bunny[..cut])),
                SceneError::Corrupt(_)
            ),
            "cut at {cut}"
        );
    }
    let ascii_cut = &PYRAMID_ASCII[..PYRAMID_ASCII.len() - 10];
    assert!(matches!(
        mesh_refusal(load_in("a.ply", ascii_cut.as_bytes())),
        SceneError::Corrupt(_)
    ));
    assert!(matches!(
        mesh_refusal(load_in("a.obj", b"v 0 zero 0\n")),
        SceneError::Corrupt(_)
    ));
    assert!(matches!(
        Mesh::load(Path::new("mesh.stl")),
        Err(Error::Core(haarshift::Error::Format { .. }))
    ));
    assert!(matches!(
        Mesh::load(Path::new("/nonexistent/mesh.ply")),
        Err(Error::Core(haarshift::Error::Io { .. }))
    ));
}

#[test]
fn errors_print_as_one_line_with_the_file() {
    let e = load_bytes("broken.obj", b"v 0 0 0\n").unwrap_err();
    let line = e.to_string();
    assert!(line.contains("broken.obj: ") && line.ends_with("the mesh has no triangles"));
    assert!(!line.contains('\n'));
}

#[test]
fn a_byte_order_mark_keeps_the_first_vertex_and_index_0_is_named() {
    let mesh = load_bytes(
        "bom.obj",
        "\u{feff}v 9 9 9\nv 0 0 0\nv 1 0 0\nf 1 2 3\n".as_bytes(),
    );
    let mesh = mesh.unwrap();
    assert_eq!(mesh.vertex_count(), 3);
    assert_eq!(mesh.positions().row(0).to_vec(), vec![9.0, 9.0, 9.0]);
    let zero = mesh_refusal(load_in("z.obj", b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 0 1 2\n"));
    assert_eq!(
        zero,
        SceneError::Corrupt("line 4: face index 0 (OBJ counts vertices from 1)".into())
    );
}

#[test]
fn positions_beyond_the_range_are_refused_by_vertex() {
    let far = mesh_refusal(load_in(
        "far.obj",
        b"v 0 0 0\nv 1 0 0\nv 0 1e308 0\nf 1 2 3\n",
    ));
    assert_eq!(
        far,
        SceneError::OutOfRange {
            what: "vertex 2".into(),
            value: 1e308
        }
    );
    let edge = load_bytes("edge.obj", b"v 0 0 0\nv 1 0 0\nv 0 -1e15 0\nf 1 2 3\n");
    assert_eq!(edge.unwrap().bounds().min[1], -1e15);
}

/// The scene error of a mesh refused with no file.
fn refused(result: Result<Mesh>) -> SceneError {
    match result {
        Err(Error::Scene { path: None, source }) => source,
        other => panic!("expected a scene error, got {other:?}"),
    }
}

#[test]
fn stored_normals_are_kept_bit_for_bit_where_normalising_them_again_is_not() {
    let bunny = Mesh::load(&testdata("bunny.ply")).unwrap();
    let parts = || {
        (
            bunny.positions().to_owned(),
            bunny.triangles().to_vec(),
            bunny.normals().to_owned(),
        )
    };
    // Normalising unit normals again moves the last bit of many: what a cache read back
    // through `Mesh::new` did to its mesh (measured: 1797 of the 5517 components).
    let (p, t, n) = parts();
    let again = Mesh::new(p, t, Some(n)).unwrap();
    let (_, moved) = differing_bits(&again, &bunny);
    assert!(moved > 1000, "{moved} components moved");
    let (p, t, n) = parts();
    let stored = Mesh::stored(p, t, n).unwrap();
    assert_eq!(differing_bits(&stored, &bunny), (0, 0));
    assert_eq!(stored.triangles(), bunny.triangles());

    // Checked: a zero normal (a vertex of no triangle) passes; one that is not unit, to
    // more than a normalisation's rounding, is refused by vertex, as a non-finite one is.
    let (p, t, mut n) = parts();
    n.row_mut(7).fill(0.0);
    assert!(Mesh::stored(p, t, n).is_ok());
    let with_normal = |vertex: usize, normal: [f64; 3]| {
        let (p, t, mut n) = parts();
        n.row_mut(vertex).assign(&ndarray::arr1(&normal));
        refused(Mesh::stored(p, t, n))
    };
    assert_eq!(
        with_normal(5, [0.0, 2.0, 0.0]),
        SceneError::NotUnitNormal {
            vertex: 5,
            length: 2.0
        }
    );
    assert!(matches!(
        with_normal(9, [0.0, 1.0 + 1e-9, 0.0]),
        SceneError::NotUnitNormal { vertex: 9, .. }
    ));
    assert!(matches!(
        with_normal(11, [1e-170, 0.0, 0.0]),
        SceneError::NotUnitNormal { vertex: 11, .. }
    ));
    assert!(matches!(
        with_normal(3, [0.0, f64::NAN, 0.0]),
        SceneError::NonFinite {
            vertex: 3,
            what: "normal",
            ..
        }
    ));
    let (p, t, _) = parts();
    assert!(matches!(
        Mesh::stored(p, t, Array2::zeros((4, 3))),
        Err(Error::Core(haarshift::Error::InvalidShape { .. }))
    ));
}

#[test]
fn file_normals_of_any_magnitude_become_unit_and_store() {
    // Squared lengths below f64's normal range (1e-320 is subnormal: normalised plainly, the
    // first came out of length 1.0000056) and above it (1e400 overflows, and n / inf was zero).
    let given = array![
        [1e-160, 0.0, 0.0],
        [3e-170, 4e-170, 0.0],
        [3e200, -4e200, 0.0],
    ];
    let want = [[1.0, 0.0, 0.0], [0.6, 0.8, 0.0], [0.6, -0.8, 0.0]];
    let positions = array![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, -1.0]];
    let mesh = Mesh::new(positions.clone(), vec![[0, 1, 2]], Some(given)).unwrap();
    for (v, w) in want.iter().enumerate() {
        let n = mesh.normals().row(v).to_vec();
        assert!((0..3).all(|k| (n[k] - w[k]).abs() < 1e-15), "{v}: {n:?}");
    }
    let normals = mesh.normals().to_owned();
    let stored = Mesh::stored(positions, vec![[0, 1, 2]], normals).unwrap();
    assert_eq!(differing_bits(&stored, &mesh), (0, 0));
}
