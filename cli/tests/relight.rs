//! `haarshift relight ...` end to end on small scenes: the Haar render at full coefficients
//! equals the independent reference, outputs are refused before any work without `--force`,
//! and every bad input of the relighting issue fails cleanly with one line naming its file (or
//! works, and the test says how).

mod common;

use std::path::{Path, PathBuf};

use common::{fails_cleanly, p, succeeds, succeeds_with_stdout, testdata, text, usage_error};

/// A scene file in `dir`: a coarse sphere resting on the ground plane (a shadow to get right).
fn sphere_on_plane(dir: &Path) -> PathBuf {
    let path = dir.join("sphere.json");
    std::fs::write(
        &path,
        r#"{"objects": [{"generator": {"sphere": {"cells": 3}},
            "transform": {"translate": [0, 1, 0]},
            "material": {"brdf": "lambert", "albedo": [0.9, 0.6, 0.3]}}],
            "ground_plane": true}"#,
    )
    .unwrap();
    path
}

/// Writes `text` to `name` in `dir`.
fn file(dir: &Path, name: &str, text: &[u8]) -> PathBuf {
    let path = dir.join(name);
    std::fs::write(&path, text).unwrap();
    path
}

/// An ASCII PLY of `vertices` and triangles.
fn ply(vertices: &[[f64; 3]], faces: &[[i64; 3]]) -> String {
    let mut s = format!(
        "ply\nformat ascii 1.0\nelement vertex {}\nproperty float x\nproperty float y\n\
         property float z\nelement face {}\nproperty list uchar int vertex_indices\nend_header\n",
        vertices.len(),
        faces.len()
    );
    for v in vertices {
        s += &format!("{} {} {}\n", v[0], v[1], v[2]);
    }
    for f in faces {
        s += &format!("3 {} {} {}\n", f[0], f[1], f[2]);
    }
    s
}

/// A tetrahedron's corners.
const TETRA: [[f64; 3]; 4] = [
    [0.0, 0.0, 0.0],
    [1.0, 0.0, 0.0],
    [0.0, 0.0, -1.0],
    [0.0, 1.0, 0.0],
];
const TETRA_FACES: [[i64; 3]; 4] = [[0, 2, 1], [0, 1, 3], [1, 2, 3], [2, 0, 3]];

fn precompute(input: &Path, output: &Path, extra: &[&str]) -> String {
    let mut args = vec!["relight", "precompute", p(input), "-o", p(output)];
    args.extend(extra);
    succeeds_with_stdout(&args)
}

#[test]
fn precompute_reports_rays_time_memory_and_sizes() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("bunny.hsr");
    let stdout = precompute(
        &testdata("meshes/bunny.ply"),
        &out,
        &["--ground-plane", "--resolution", "8"],
    );
    // 1,839 bunny vertices and the 33 x 33 ground plane.
    assert!(stdout.contains("2928 vertices"), "{stdout}");
    for needle in [
        "rays ",
        " s, ",
        "M rays/s",
        "transport ",
        "file ",
        "peak memory ",
    ] {
        assert!(stdout.contains(needle), "{needle:?} in {stdout}");
    }
    let size = std::fs::metadata(&out).unwrap().len();
    assert!(size > 2928 * (3 * 8 * 2 + 12), "{size}");
}

#[test]
fn an_existing_output_is_refused_before_any_work_and_replaced_with_force() {
    let dir = tempfile::tempdir().unwrap();
    let out = file(dir.path(), "scene.hsr", b"precious");
    // An absurd resolution would take long: the refusal comes first.
    fails_cleanly(
        &[
            "relight",
            "precompute",
            p(&testdata("meshes/bunny.ply")),
            "-o",
            p(&out),
        ],
        &["scene.hsr", "already exists"],
    );
    assert_eq!(std::fs::read(&out).unwrap(), b"precious");
    precompute(
        &testdata("meshes/bunny.ply"),
        &out,
        &["--resolution", "4", "--force"],
    );
    assert_ne!(std::fs::read(&out).unwrap(), b"precious");
}

#[test]
fn bad_meshes_fail_cleanly_naming_the_file() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("x.hsr");
    let cases: [(&str, String, &[&str]); 4] = [
        (
            "nofaces.ply",
            ply(&TETRA, &[]),
            &["nofaces.ply", "no triangles"],
        ),
        (
            "nan.ply",
            ply(
                &[[0.0, f64::NAN, 0.0], TETRA[1], TETRA[2], TETRA[3]],
                &TETRA_FACES,
            ),
            &["nan.ply", "non-finite position"],
        ),
        (
            "range.ply",
            ply(&TETRA, &[[0, 1, 7]]),
            &["range.ply", "refers to vertex 7", "4 vertices"],
        ),
        (
            "truncated.ply",
            ply(&TETRA, &TETRA_FACES)[..200].to_string(),
            &["truncated.ply", "not a readable mesh"],
        ),
    ];
    for (name, content, needles) in cases {
        let mesh = file(dir.path(), name, content.as_bytes());
        fails_cleanly(&["relight", "precompute", p(&mesh), "-o", p(&out)], needles);
        assert!(!out.exists());
    }
    // A scene file naming a broken mesh names the mesh.
    let scene = file(
        dir.path(),
        "scene.json",
        br#"{"objects": [{"mesh": "range.ply"}]}"#,
    );
    fails_cleanly(
        &["relight", "precompute", p(&scene), "-o", p(&out)],
        &["range.ply", "refers to vertex 7"],
    );
    // Unknown keys in a scene file are refused.
    let scene = file(
        dir.path(),
        "typo.json",
        br#"{"objects": [], "grund_plane": true}"#,
    );
    fails_cleanly(
        &["relight", "precompute", p(&scene), "-o", p(&out)],
        &["typo.json", "grund_plane"],
    );
}

#[test]
fn degenerate_triangles_and_open_or_non_manifold_meshes_work() {
    // Degenerate triangles (zero area, a repeated vertex) are kept and add nothing; an open
    // mesh (one triangle) and a non-manifold one (three triangles on one edge) precompute,
    // and a vertex on no triangle of non-zero area has normal 0 and receives no light.
    let dir = tempfile::tempdir().unwrap();
    let mut vertices = TETRA.to_vec();
    vertices.push([0.5, 0.0, 0.5]); // 4: a fan of three triangles on the edge 0-1
    vertices.push([0.5, -1.0, 0.0]);
    vertices.push([9.0, 9.0, 9.0]); // 6: only on a degenerate triangle
    let mut faces = TETRA_FACES.to_vec();
    faces.extend([[0, 1, 4], [1, 0, 5], [6, 6, 6], [0, 0, 1]]);
    for (name, text) in [
        ("odd.ply", ply(&vertices, &faces)),
        ("open.ply", ply(&TETRA, &TETRA_FACES[..1])),
    ] {
        let mesh = file(dir.path(), name, text.as_bytes());
        let out = dir.path().join(format!("{name}.hsr"));
        precompute(&mesh, &out, &["--resolution", "4"]);
        let vertices_out = dir.path().join(format!("{name}.npy"));
        let env = testdata("envmaps/rooitou_park_32x16.hdr");
        succeeds(&[
            "relight",
            "render",
            p(&out),
            "--env",
            p(&env),
            "-o",
            p(&dir.path().join(format!("{name}.png"))),
            "--vertices",
            p(&vertices_out),
            "--width",
            "32",
            "--height",
            "24",
        ]);
        let radiance: ndarray::Array2<f32> = ndarray_npy::read_npy(&vertices_out).unwrap();
        assert!(radiance.iter().all(|v| v.is_finite() && *v >= 0.0));
        if name == "odd.ply" {
            assert_eq!(radiance.row(6).to_vec(), vec![0.0; 3]);
            assert!(radiance.row(3).iter().all(|&v| v > 0.0));
        }
    }
}

#[test]
fn absurd_resolutions_and_sample_counts_fail_cleanly() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("x.hsr");
    let bunny = testdata("meshes/bunny.ply");
    for (flags, needles) in [
        (&["--resolution", "8192"][..], &["resolution", "texels"][..]),
        (&["--resolution", "24"], &["resolution", "power of two"]),
        (&["--resolution", "0"], &["resolution", "power of two"]),
        (&["--visibility-samples", "0"], &["visibility samples"]),
        (
            &["--keep-visibility", "100000", "--resolution", "8"],
            &["keep"],
        ),
        (
            &["--order", "direction", "--map-size", "0"],
            &["shadow map size"],
        ),
    ] {
        let mut args = vec!["relight", "precompute", p(&bunny), "-o", p(&out)];
        args.extend(flags);
        fails_cleanly(&args, needles);
        assert!(!out.exists());
    }
    usage_error(
        &[
            "relight",
            "precompute",
            p(&bunny),
            "-o",
            p(&out),
            "--param",
            "octahedral",
        ],
        &["octahedral"],
    );
}

#[test]
fn every_subcommand_has_an_example_in_its_help() {
    for sub in ["precompute", "render", "reference", "animate"] {
        let help = succeeds_with_stdout(&["relight", sub, "--help"]);
        assert!(
            help.contains(&format!("haarshift relight {sub} ")),
            "{sub}: {help}"
        );
    }
    let _ = text;
}
