//! `haarshift relight ...` end to end on small scenes: the Haar render at full coefficients
//! equals the independent reference, outputs are refused before any work without `--force`,
//! and every bad input of the relighting issue fails cleanly with one line naming its file (or
//! works, and the test says how).

use std::path::{Path, PathBuf};

use crate::common::read_vertices;
use crate::common::relative_rms;
use crate::common::{
    fails_cleanly, p, succeeds, succeeds_with_stdout, testdata, text, usage_error,
};

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
    let cases: [(&str, String, &[&str]); 5] = [
        (
            "nofaces.ply",
            ply(&TETRA, &[]),
            &["nofaces.ply", "no triangles"],
        ),
        (
            "nan.obj",
            "v 0 0 0\nv 1 0 0\nv 0 nan 0\nf 1 2 3\n".to_string(),
            &["nan.obj", "non-finite position"],
        ),
        (
            "nan.ply",
            ply(&TETRA, &TETRA_FACES).replace("\n1 0 0\n", "\n1 NaN 0\n"),
            &["nan.ply", "not a readable mesh", "NaN"],
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

/// A precomputed sphere on its plane in `dir` (lat-long 8 x 16): the cache's path.
fn small_cache(dir: &Path) -> PathBuf {
    let out = dir.join("sphere.hsr");
    precompute(&sphere_on_plane(dir), &out, &["--resolution", "8"]);
    out
}

fn env32() -> PathBuf {
    testdata("envmaps/rooitou_park_32x16.hdr")
}

/// `relight render CACHE --env ENV -o OUT` with `extra` flags, small images.
fn render_args<'a>(cache: &'a Path, out: &'a Path, extra: &[&'a str]) -> Vec<&'a str> {
    let mut args = vec!["relight", "render", p(cache), "-o", p(out)];
    if !extra.contains(&"--width") {
        args.extend(["--width", "40", "--height", "30"]);
    }
    args.extend(extra);
    args
}

#[test]
fn render_writes_the_image_and_vertices_and_times_each_stage() {
    let dir = tempfile::tempdir().unwrap();
    let cache = small_cache(dir.path());
    let env = env32();
    let (png, npy) = (dir.path().join("a.png"), dir.path().join("a.npy"));
    let stdout = text(
        &succeeds(&render_args(
            &cache,
            &png,
            &[
                "--env",
                p(&env),
                "--vertices",
                p(&npy),
                "--keep-light",
                "20",
            ],
        ))
        .stdout,
    );
    for needle in [
        "lighting encoding ",
        "shading ",
        "rasterisation ",
        "40 x 30",
        // The transport is not copied: the render reads it from the mapped file.
        "coefficients read in place from the cache file",
    ] {
        assert!(stdout.contains(needle), "{needle:?} in {stdout}");
    }
    let image = haarshift::io::read_image::<f32>(&png).unwrap();
    assert_eq!(
        (image.width(), image.height(), image.channels().count()),
        (40, 30, 3)
    );
    let radiance: ndarray::Array2<f32> = ndarray_npy::read_npy(&npy).unwrap();
    // 6 x 4^2 sphere vertices, then the 33 x 33 ground plane.
    assert_eq!(radiance.dim(), (6 * 16 + 1089, 3));
    // The sphere's albedo is (0.9, 0.6, 0.3) and the park is nearly grey: red leads blue.
    let top = radiance.row(0);
    assert!(top[0] > top[2] && top[2] > 0.0, "{top}");
    // EXR: linear f32, the same radiance behind the same pixels as the PNG's codes.
    let exr = dir.path().join("a.exr");
    succeeds(&render_args(
        &cache,
        &exr,
        &["--env", p(&env), "--keep-light", "20"],
    ));
    let linear = haarshift::io::read_image::<f32>(&exr).unwrap();
    let srgb = haarshift_relight::render::to_srgb8(&linear, 0.0).unwrap();
    assert_eq!(srgb.planes(), image.planes());
}

#[test]
fn render_refuses_existing_outputs_before_any_work() {
    let dir = tempfile::tempdir().unwrap();
    let cache = small_cache(dir.path());
    let env = env32();
    let png = file(dir.path(), "a.png", b"old image");
    let npy = dir.path().join("a.npy");
    fails_cleanly(
        &render_args(&cache, &png, &["--env", p(&env), "--vertices", p(&npy)]),
        &["a.png", "already exists"],
    );
    assert!(!npy.exists());
    let fresh = dir.path().join("b.png");
    let npy = file(dir.path(), "b.npy", b"old array");
    fails_cleanly(
        &render_args(&cache, &fresh, &["--env", p(&env), "--vertices", p(&npy)]),
        &["b.npy", "already exists"],
    );
    assert!(!fresh.exists());
    // The image's format is checked before any work too, and the cache is never an output.
    fails_cleanly(
        &render_args(&cache, &dir.path().join("c.jpg"), &["--env", p(&env)]),
        &["c.jpg", ".png", ".exr"],
    );
    fails_cleanly(
        &render_args(
            &cache,
            &fresh,
            &["--env", p(&env), "--vertices", p(&cache), "--force"],
        ),
        &["sphere.hsr"],
    );
    // With --force both are replaced.
    succeeds(&render_args(
        &cache,
        &png,
        &["--env", p(&env), "--vertices", p(&npy), "--force"],
    ));
    assert_ne!(std::fs::read(&png).unwrap(), b"old image");
    assert_ne!(std::fs::read(&npy).unwrap(), b"old array");
}

#[test]
fn bad_lighting_and_caches_fail_cleanly_naming_the_file() {
    let dir = tempfile::tempdir().unwrap();
    let cache = small_cache(dir.path());
    let env = env32();
    let out = dir.path().join("x.png");
    // An environment map that is not 2:1.
    let square = testdata("camera.png");
    fails_cleanly(
        &render_args(&cache, &out, &["--env", p(&square)]),
        &["camera.png", "twice as wide"],
    );
    // A cache with one byte flipped, cut short, or from another format version.
    let good = std::fs::read(&cache).unwrap();
    let mut flipped = good.clone();
    let middle = flipped.len() / 2;
    flipped[middle] ^= 0x10;
    let damaged = file(dir.path(), "damaged.hsr", &flipped);
    fails_cleanly(
        &render_args(&damaged, &out, &["--env", p(&env)]),
        &["damaged.hsr", "damaged", "checksum"],
    );
    let short = file(dir.path(), "short.hsr", &good[..good.len() - 100]);
    fails_cleanly(
        &render_args(&short, &out, &["--env", p(&env)]),
        &["short.hsr", "damaged"],
    );
    let mut old = good.clone();
    old[8..12].copy_from_slice(&1u32.to_le_bytes());
    let old = file(dir.path(), "old.hsr", &old);
    fails_cleanly(
        &render_args(&old, &out, &["--env", p(&env)]),
        &["old.hsr", "format version 1"],
    );
    let mesh = testdata("meshes/bunny.ply");
    fails_cleanly(
        &render_args(&mesh, &out, &["--env", p(&env)]),
        &["bunny.ply", "not a haarshift scene cache"],
    );
    assert!(!out.exists());
    // No lighting at all: the scene file named none.
    fails_cleanly(&render_args(&cache, &out, &[]), &["--env"]);
    // Truncations that keep nothing, or more than there is.
    usage_error(
        &render_args(&cache, &out, &["--env", p(&env), "--keep-light", "0"]),
        &["--keep-light", "at least 1"],
    );
    usage_error(
        &render_args(&cache, &out, &["--env", p(&env), "--keep-visibility", "0"]),
        &["--keep-visibility"],
    );
    // A material the library cannot parse is a usage error naming the flag and the reason.
    usage_error(
        &render_args(&cache, &out, &["--env", p(&env), "--brdf", "phong:x"]),
        &["--brdf", "phong:x", "not a number"],
    );
    usage_error(
        &render_args(&cache, &out, &["--env", p(&env), "--brdf", "ward:2"]),
        &["--brdf", "lambert, phong:EXP, blinn:EXP, merl:FILE"],
    );
    fails_cleanly(
        &render_args(&cache, &out, &["--env", p(&env), "--keep-light", "1000000"]),
        &["keep", "1000000"],
    );
    fails_cleanly(
        &render_args(&cache, &out, &["--env", p(&env), "--width", "0"]),
        &["32768"],
    );
    assert!(!out.exists());
}

#[test]
fn a_scene_files_lighting_and_camera_are_used_when_no_flag_names_them() {
    let dir = tempfile::tempdir().unwrap();
    let env = env32();
    std::fs::copy(&env, dir.path().join("sky.hdr")).unwrap();
    let scene = file(
        dir.path(),
        "lit.json",
        br#"{"objects": [{"generator": {"sphere": {"cells": 3}}}],
            "environment": {"path": "sky.hdr", "yaw": 45},
            "camera": {"position": [0, 0, 6], "look_at": [0, 0, 0], "fov": 30}}"#,
    );
    let cache = dir.path().join("lit.hsr");
    precompute(&scene, &cache, &["--resolution", "8"]);
    let from_file = dir.path().join("file.npy");
    succeeds(&render_args(
        &cache,
        &dir.path().join("a.png"),
        &["--vertices", p(&from_file)],
    ));
    let from_flags = dir.path().join("flags.npy");
    succeeds(&render_args(
        &cache,
        &dir.path().join("b.png"),
        &[
            "--env",
            p(&env),
            "--yaw",
            "45",
            "--camera",
            "0,0,6",
            "--look-at",
            "0,0,0",
            "--fov",
            "30",
            "--vertices",
            p(&from_flags),
        ],
    ));
    let a: ndarray::Array2<f32> = ndarray_npy::read_npy(&from_file).unwrap();
    let b: ndarray::Array2<f32> = ndarray_npy::read_npy(&from_flags).unwrap();
    assert_eq!(a, b);
    assert_eq!(
        std::fs::read(dir.path().join("a.png")).unwrap(),
        std::fs::read(dir.path().join("b.png")).unwrap()
    );
    // Another yaw gives another radiance.
    let turned = dir.path().join("turned.npy");
    succeeds(&render_args(
        &cache,
        &dir.path().join("c.png"),
        &["--yaw", "135", "--vertices", p(&turned)],
    ));
    let c: ndarray::Array2<f32> = ndarray_npy::read_npy(&turned).unwrap();
    assert_ne!(a, c);
}

#[test]
fn animate_writes_a_gif_or_numbered_frames_and_times_each() {
    let dir = tempfile::tempdir().unwrap();
    let cache = small_cache(dir.path());
    let env = env32();
    let gif = dir.path().join("turn.gif");
    let base = [
        "relight",
        "animate",
        p(&cache),
        "--env",
        p(&env),
        "--frames",
        "4",
        "--width",
        "24",
        "--height",
        "16",
    ];
    let mut args = base.to_vec();
    args.extend(["-o", p(&gif)]);
    let stdout = succeeds_with_stdout(&args);
    assert_eq!(stdout.matches("frame ").count(), 4, "{stdout}");
    assert!(stdout.contains("frame 3: yaw 270.00"), "{stdout}");
    let decoder = image::codecs::gif::GifDecoder::new(std::io::BufReader::new(
        std::fs::File::open(&gif).unwrap(),
    ))
    .unwrap();
    use image::AnimationDecoder;
    assert_eq!(decoder.into_frames().count(), 4);
    fails_cleanly(&args, &["turn.gif", "already exists"]);
    // Numbered PNGs: frame k is `relight render` at yaw 90 k.
    let pattern = dir.path().join("f_%02d.png");
    let mut args = base.to_vec();
    args.extend(["-o", p(&pattern), "--background", "0,0,0"]);
    succeeds(&args);
    let single = dir.path().join("single.png");
    succeeds(&render_args(
        &cache,
        &single,
        &[
            "--env",
            p(&env),
            "--yaw",
            "180",
            "--background",
            "0,0,0",
            "--width",
            "24",
            "--height",
            "16",
        ],
    ));
    assert_eq!(
        std::fs::read(dir.path().join("f_02.png")).unwrap(),
        std::fs::read(&single).unwrap()
    );
    assert!(dir.path().join("f_03.png").exists() && !dir.path().join("f_04.png").exists());
    let mut args = base.to_vec();
    let bad = dir.path().join("frame.png");
    args.extend(["-o", p(&bad)]);
    fails_cleanly(&args, &["frame.png", "%d"]);
}

#[test]
fn the_haar_render_at_full_coefficients_equals_the_reference() {
    // The contract for checking: lat-long N, nothing truncated, same rays, the same
    // downsampled lighting; only the order of the sums and f32 rounding differ.
    let dir = tempfile::tempdir().unwrap();
    let scene = sphere_on_plane(dir.path());
    let cache = dir.path().join("s.hsr");
    precompute(&scene, &cache, &["--resolution", "8", "--sh-bands", "3"]);
    let env = env32();
    let common = ["--env", p(&env), "--yaw", "-37", "--albedo", "0.7,0.5,0.2"];
    let haar = dir.path().join("haar.npy");
    let h_png = dir.path().join("h.png");
    let mut args = render_args(&cache, &h_png, &common);
    args.extend(["--vertices", p(&haar)]);
    succeeds(&args);
    let truth = dir.path().join("truth.npy");
    let mut args = vec![
        "relight",
        "reference",
        p(&scene),
        "--resolution",
        "8",
        "--vertices",
        p(&truth),
    ];
    args.extend(common);
    let stdout = succeeds_with_stdout(&args);
    assert!(stdout.contains("rays "), "{stdout}");
    let (haar, truth) = (read_vertices(&haar), read_vertices(&truth));
    assert_eq!(haar.dim(), (96 + 1089, 3));
    let full = relative_rms(&haar, &truth);
    assert!(full < 1e-6, "full coefficients: {full:.2e}");
    // Truncating the lighting moves away from it (so the comparison can fail) ...
    let kept = dir.path().join("kept.npy");
    let k_png = dir.path().join("k.png");
    let mut args = render_args(&cache, &k_png, &common);
    args.extend(["--vertices", p(&kept), "--keep-light", "8"]);
    succeeds(&args);
    let kept = relative_rms(&read_vertices(&kept), &truth);
    assert!(kept > 1e-3, "8 lighting coefficients: {kept:.2e}");
    // ... and so does the low-frequency basis.
    let sh = dir.path().join("sh.npy");
    let sh_png = dir.path().join("sh.png");
    let mut args = render_args(&cache, &sh_png, &common);
    args.extend(["--vertices", p(&sh), "--basis", "sh"]);
    let stdout = succeeds_with_stdout(&args);
    assert!(stdout.contains("3 bands (9 coefficients)"), "{stdout}");
    let sh = relative_rms(&read_vertices(&sh), &truth);
    assert!(sh > 1e-3 && sh < 0.5, "SH, 3 bands: {sh:.2e}");
    // SH needs its transfer in the cache, and takes no Haar truncation.
    let plain = small_cache(dir.path());
    let out = dir.path().join("x.png");
    fails_cleanly(
        &render_args(&plain, &out, &["--env", p(&env), "--basis", "sh"]),
        &["sphere.hsr", "--sh-bands"],
    );
    fails_cleanly(
        &render_args(
            &cache,
            &out,
            &["--env", p(&env), "--basis", "sh", "--keep-light", "5"],
        ),
        &["--keep-light", "basis"],
    );
}

#[test]
fn reference_refuses_bad_inputs_before_any_work() {
    let dir = tempfile::tempdir().unwrap();
    let scene = sphere_on_plane(dir.path());
    let env = env32();
    let out = file(dir.path(), "truth.npy", b"old");
    let base = [
        "relight",
        "reference",
        p(&scene),
        "--env",
        p(&env),
        "--vertices",
    ];
    let mut args = base.to_vec();
    args.push(p(&out));
    fails_cleanly(&args, &["truth.npy", "already exists"]);
    let fresh = dir.path().join("fresh.npy");
    for (flags, needles) in [
        (&["--resolution", "1000"][..], &["resolution", "1000"][..]),
        (&["--resolution", "0"], &["resolution"]),
        (&["-o", "x.gif"], &["x.gif", ".png"]),
    ] {
        let mut args = base.to_vec();
        args.push(p(&fresh));
        args.extend(flags);
        fails_cleanly(&args, needles);
        assert!(!fresh.exists());
    }
    let square = testdata("camera.png");
    fails_cleanly(
        &[
            "relight",
            "reference",
            p(&scene),
            "--env",
            p(&square),
            "--vertices",
            p(&fresh),
        ],
        &["camera.png", "twice as wide"],
    );
}

#[test]
fn reference_takes_glossy_and_measured_brdfs() {
    use haarshift_relight::material::merl::MerlBrdf;
    let dir = tempfile::tempdir().unwrap();
    let scene = sphere_on_plane(dir.path());
    let env = env32();
    let run = |brdf: &str, out: &Path| {
        succeeds_with_stdout(&[
            "relight",
            "reference",
            p(&scene),
            "--env",
            p(&env),
            "--resolution",
            "8",
            "--brdf",
            brdf,
            "--vertices",
            p(out),
        ])
    };
    let (lambert, phong) = (dir.path().join("l.npy"), dir.path().join("p.npy"));
    run("lambert", &lambert);
    let stdout = run("phong:20", &phong);
    assert!(stdout.contains("(phong:20)"), "{stdout}");
    let (lambert, phong) = (read_vertices(&lambert), read_vertices(&phong));
    // The sphere's 96 vertices are glossy; the ground plane after them stays Lambertian.
    let ground = ndarray::s![96.., ..];
    assert_eq!(phong.slice(ground), lambert.slice(ground));
    let sphere = ndarray::s![..96, ..];
    let gap = relative_rms(
        &phong.slice(sphere).to_owned(),
        &lambert.slice(sphere).to_owned(),
    );
    assert!(gap > 0.05, "phong:20 against lambert: {gap:.2e}");
    // A measured BRDF: a constant table of 1 / pi is Lambert wherever the camera sees the
    // surface (a measured BRDF is 0 seen from below its horizon).
    let table = dir.path().join("flat.binary");
    MerlBrdf::from_fn(|_, _, _| [std::f64::consts::FRAC_1_PI; 3])
        .unwrap()
        .write(&table, false)
        .unwrap();
    let merl = dir.path().join("m.npy");
    let stdout = run(&format!("merl:{}", p(&table)), &merl);
    assert!(stdout.contains("flat.binary"), "{stdout}");
    let merl = read_vertices(&merl);
    assert_eq!(merl.slice(ground), lambert.slice(ground));
    let same = (0..96)
        .filter(|&v| (merl[[v, 0]] - lambert[[v, 0]]).abs() <= 1e-5 * lambert[[v, 0]])
        .count();
    let dark = (0..96).filter(|&v| merl[[v, 0]] == 0.0).count();
    assert!(
        same + dark == 96 && same > 30,
        "{same} as lambert, {dark} dark"
    );
    // Bad files: one line naming the file and the problem.
    let out = dir.path().join("x.npy");
    let missing = dir.path().join("missing.binary");
    let args = |brdf: &str| {
        vec![
            "relight".to_owned(),
            "reference".to_owned(),
            p(&scene).to_owned(),
            "--env".to_owned(),
            p(&env).to_owned(),
            "--brdf".to_owned(),
            brdf.to_owned(),
            "--vertices".to_owned(),
            p(&out).to_owned(),
        ]
    };
    let missing_args = args(&format!("merl:{}", p(&missing)));
    let missing_args: Vec<&str> = missing_args.iter().map(String::as_str).collect();
    fails_cleanly(&missing_args, &["missing.binary"]);
    let mut short: Vec<u8> = [90i32, 90, 180]
        .iter()
        .flat_map(|d| d.to_le_bytes())
        .collect();
    short.extend([0u8; 800]);
    let truncated = file(dir.path(), "short.binary", &short);
    let truncated_args = args(&format!("merl:{}", p(&truncated)));
    let truncated_args: Vec<&str> = truncated_args.iter().map(String::as_str).collect();
    fails_cleanly(&truncated_args, &["short.binary", "truncated"]);
    assert!(!out.exists());
}

#[test]
fn the_gallery_writes_its_images_table_and_turntable() {
    let dir = tempfile::tempdir().unwrap();
    let maps = dir.path().join("maps");
    std::fs::create_dir(&maps).unwrap();
    std::fs::copy(env32(), maps.join("park.hdr")).unwrap();
    std::fs::write(maps.join("SOURCES.md"), "not a map").unwrap();
    let out = dir.path().join("out");
    let bunny = testdata("meshes/bunny.ply");
    let args = [
        "relight",
        "gallery",
        p(&bunny),
        "--env-dir",
        p(&maps),
        "--out-dir",
        p(&out),
        "--resolution",
        "8",
        "--keep-light",
        "20",
        "--sh-bands",
        "3",
        "--frames",
        "2",
    ];
    let stdout = succeeds_with_stdout(&args);
    assert!(stdout.contains("1 maps"), "{stdout}");
    let table = std::fs::read_to_string(out.join("errors.md")).unwrap();
    assert!(
        table.contains("relight gallery") && table.contains("| park | [park.png](park.png) |"),
        "{table}"
    );
    let image = haarshift::io::read_image::<f32>(out.join("park.png")).unwrap();
    assert_eq!((image.width(), image.height()), (3 * 320, 240));
    assert!(out.join("turntable.gif").exists());
    // The Haar error at every coefficient is rounding; the other two are not.
    let row = table.lines().find(|l| l.starts_with("| park")).unwrap();
    let errors: Vec<f64> = row
        .split('|')
        .skip(3)
        .take(3)
        .map(|x| x.trim().parse().unwrap())
        .collect();
    assert!(
        errors[0] < 1e-6 && errors[1] > errors[0] && errors[2] > errors[0],
        "{row}"
    );
    fails_cleanly(&args, &["already exists"]);
}

#[test]
fn every_subcommand_has_an_example_in_its_help() {
    for sub in [
        "precompute",
        "render",
        "bake",
        "reference",
        "animate",
        "gallery",
    ] {
        let help = succeeds_with_stdout(&["relight", sub, "--help"]);
        assert!(
            help.contains(&format!("haarshift relight {sub} ")),
            "{sub}: {help}"
        );
    }
    let _ = text;
}

#[test]
fn glossy_render_with_direct_evaluation_equals_the_glossy_reference() {
    let dir = tempfile::tempdir().unwrap();
    let scene = sphere_on_plane(dir.path());
    let cache = dir.path().join("s.hsr");
    precompute(&scene, &cache, &["--resolution", "16", "--sh-bands", "4"]);
    let env = env32();
    let common = [
        "--env",
        p(&env),
        "--brdf",
        "phong:20",
        "--albedo",
        "0.7,0.5,0.2",
    ];
    let render = |name: &str, extra: &[&str]| {
        let npy = dir.path().join(format!("{name}.npy"));
        let png = dir.path().join(format!("{name}.png"));
        let mut args = render_args(&cache, &png, &common);
        args.extend(extra);
        args.extend(["--vertices", p(&npy)]);
        let stdout = succeeds_with_stdout(&args);
        (read_vertices(&npy), stdout)
    };
    let truth = dir.path().join("truth.npy");
    let mut args = vec!["relight", "reference", p(&scene), "--resolution", "16"];
    args.extend(common);
    args.extend(["--vertices", p(&truth)]);
    succeeds(&args);
    let truth = read_vertices(&truth);
    let (direct, stdout) = render("direct", &["--brdf-rotation", "direct"]);
    assert!(stdout.contains("phong:20 rotated by direct"), "{stdout}");
    let e = relative_rms(&direct, &truth);
    assert!(e < 1e-6, "direct: {e:.2e}");
    // The rotations approximate it; the cache too; the material matters.
    let (haar, stdout) = render("haar", &["--rotation-cache", "8"]);
    assert!(stdout.contains("rotation cache 8 x 16"), "{stdout}");
    let e = relative_rms(&haar, &truth);
    assert!(e > 1e-4 && e < 0.2, "haar, cache 8: {e:.2e}");
    let (sh, _) = render("sh", &["--basis", "sh"]);
    let e = relative_rms(&sh, &truth);
    assert!(e > 1e-3 && e < 0.5, "SH, 4 bands: {e:.2e}");
    let lambert = dir.path().join("lambert.npy");
    let png = dir.path().join("lambert.png");
    let mut args = render_args(&cache, &png, &["--env", p(&env), "--albedo", "0.7,0.5,0.2"]);
    args.extend(["--vertices", p(&lambert)]);
    succeeds(&args);
    assert!(relative_rms(&read_vertices(&lambert), &truth) > 0.05);
    // Glossy flags with a Lambertian BRDF, a rotation on a cube map, a zonal-only basis.
    let out = dir.path().join("x.png");
    fails_cleanly(
        &render_args(&cache, &out, &["--env", p(&env), "--rotation-cache", "8"]),
        &["--rotation-cache", "lambert"],
    );
    fails_cleanly(
        &render_args(
            &cache,
            &out,
            &["--env", p(&env), "--brdf", "blinn:10", "--basis", "sh"],
        ),
        &["zonal", "blinn:10"],
    );
    let cube = dir.path().join("cube.hsr");
    precompute(&scene, &cube, &["--resolution", "4", "--param", "cube"]);
    fails_cleanly(
        &render_args(&cube, &out, &["--env", p(&env), "--brdf", "phong:5"]),
        &["haar", "--param latlong"],
    );
    assert!(!out.exists());
}

#[test]
fn an_orbiting_glossy_animation_shows_new_views_from_a_filled_cache() {
    let dir = tempfile::tempdir().unwrap();
    let cache = small_cache(dir.path());
    let env = env32();
    let glossy = [
        "--brdf",
        "phong:20",
        "--rotation-cache",
        "4",
        "--fill-cache",
    ];
    let view = ["--width", "24", "--height", "16", "--background", "0,0,0"];
    let camera = ["--camera", "0,2,5", "--look-at", "0,0.5,0"];
    let pattern = dir.path().join("o_%d.png");
    let mut args = vec!["relight", "animate", p(&cache), "--env", p(&env), "--orbit"];
    args.extend(["--frames", "4", "-o", p(&pattern)]);
    args.extend(glossy.iter().chain(&view).chain(&camera));
    let stdout = succeeds_with_stdout(&args);
    // 4 x 8 mirror bins, rotated once ahead; every view then finds its maps.
    assert!(
        stdout.contains("cache filled ahead: 32 maps rotated"),
        "{stdout}"
    );
    assert_eq!(stdout.matches("(0 rotated in").count(), 4, "{stdout}");
    assert!(stdout.contains("frame 2: camera orbit 180.00"), "{stdout}");
    // Frame 2 is the render from the camera taken half-way round the point looked at.
    let single = dir.path().join("half.png");
    let mut extra = vec![
        "--env",
        p(&env),
        "--camera",
        "0,2,-5",
        "--look-at",
        "0,0.5,0",
    ];
    extra.extend(glossy.iter().chain(&view));
    let stdout = succeeds_with_stdout(&render_args(&cache, &single, &extra));
    assert!(
        stdout.contains("cache filled ahead: 32 maps rotated"),
        "{stdout}"
    );
    let pixels = |path: PathBuf| image::open(path).unwrap().to_rgb8().into_raw();
    let (frame, render) = (pixels(dir.path().join("o_2.png")), pixels(single));
    let worst = frame
        .iter()
        .zip(&render)
        .map(|(a, b)| a.abs_diff(*b))
        .max()
        .unwrap();
    assert!(worst <= 1, "frame 2 against the render: {worst} levels");
    // The views differ: the highlight moves with the camera.
    assert_ne!(pixels(dir.path().join("o_0.png")), frame);
    // Filling needs a cache, and a view-dependent BRDF's bins are not filled ahead.
    let out = dir.path().join("x.png");
    let mut args = render_args(&cache, &out, &["--env", p(&env), "--brdf", "phong:5"]);
    args.push("--fill-cache");
    fails_cleanly(&args, &["--fill-cache", "--rotation-cache"]);
    let mut args = render_args(&cache, &out, &["--env", p(&env), "--brdf", "blinn:5"]);
    args.extend(["--rotation-cache", "4", "--fill-cache"]);
    fails_cleanly(&args, &["blinn:5", "depends on the view"]);
    assert!(!out.exists());
}

#[test]
fn render_selects_the_reference_and_ambient_occlusion_by_name() {
    // Methods are one list in the library: `--basis reference` is the quadrature of `relight
    // reference` at the cache's resolution, `--basis ambient` the transport's integral.
    let dir = tempfile::tempdir().unwrap();
    let scene = sphere_on_plane(dir.path());
    let cache = small_cache(dir.path());
    let env = env32();
    let render = |basis: &str, extra: &[&str]| {
        let npy = dir.path().join(format!("{basis}.npy"));
        let png = dir.path().join(format!("{basis}.png"));
        let mut args = render_args(&cache, &png, &["--env", p(&env), "--basis", basis]);
        args.extend(["--vertices", p(&npy)]);
        args.extend(extra);
        let stdout = succeeds_with_stdout(&args);
        (read_vertices(&npy), stdout)
    };
    let (quadrature, stdout) = render("reference", &[]);
    assert!(
        stdout.contains("by quadrature over 8 x 16 texels"),
        "{stdout}"
    );
    let truth = dir.path().join("truth.npy");
    succeeds(&[
        "relight",
        "reference",
        p(&scene),
        "--resolution",
        "8",
        "--env",
        p(&env),
        "--vertices",
        p(&truth),
    ]);
    assert_eq!(quadrature, read_vertices(&truth));
    // Ambient occlusion under a white sky of radiance 1 is the Lambertian render under it.
    let white = dir.path().join("white.npy");
    haarshift::io::write_npy(
        ndarray::Array3::<f64>::ones((16, 32, 3)).view(),
        haarshift::SampleDepth::F32,
        &white,
        false,
    )
    .unwrap();
    let (ambient, stdout) = render("ambient", &[]);
    assert!(stdout.contains("ambient occlusion"), "{stdout}");
    let lit = dir.path().join("lit.npy");
    let lit_png = dir.path().join("lit.png");
    let mut args = render_args(&cache, &lit_png, &["--env", p(&white)]);
    args.extend(["--vertices", p(&lit)]);
    succeeds(&args);
    let lit = read_vertices(&lit);
    let worst = ambient
        .iter()
        .zip(&lit)
        .fold(0.0f32, |a, (x, y)| a.max((x - y).abs()));
    assert!(worst < 1e-5, "{worst}");
    // The ground plane next to the sphere is occluded: darker than an open plane (0.8).
    assert!(ambient.column(0).iter().any(|&r| r < 0.6));
    fails_cleanly(
        &render_args(
            &cache,
            &dir.path().join("g.png"),
            &["--env", p(&env), "--basis", "ambient", "--brdf", "phong:10"],
        ),
        &["ambient occlusion is Lambertian"],
    );
}

#[test]
fn render_with_the_prefiltered_light_rotation_is_the_librarys_prefiltered_path() {
    use haarshift::product::Selection;
    use haarshift::sphere::SphereRotation;
    use haarshift_relight::SceneCache;
    use haarshift_relight::light::environment::{Environment, LightRotation};
    use haarshift_relight::shade::{FrameSpec, ShaderSpec, ShadingInput};
    // A map 128 high and a working map 8 high: the prefiltered copy (16 high) is not the
    // source, so the two rotations differ.
    let dir = tempfile::tempdir().unwrap();
    let cache = small_cache(dir.path());
    let env = testdata("envmaps/rooitou_park_256x128.npy");
    let render = |how: &str| {
        let npy = dir.path().join(format!("{how}.npy"));
        let png = dir.path().join(format!("{how}.png"));
        let common = [
            "--env",
            p(&env),
            "--yaw",
            "33",
            "--pitch",
            "20",
            "--keep-light",
            "20",
        ];
        let mut args = render_args(&cache, &png, &common);
        args.extend(["--light-rotation", how, "--vertices", p(&npy)]);
        succeeds(&args);
        read_vertices(&npy)
    };
    let (fast, source) = (render("prefiltered"), render("source"));
    // The library's prefiltered path, bit for bit.
    let scene = SceneCache::read(&cache).unwrap();
    let spec = ShaderSpec {
        keep_light: Selection::Largest(20),
        light_rotation: LightRotation::Prefiltered,
        ..ShaderSpec::default()
    };
    let mut shader = spec.build(&ShadingInput::cache(&scene)).unwrap();
    let environment = Environment::load(&env).unwrap();
    let frame = FrameSpec {
        environment: &environment,
        rotation: SphereRotation::from_degrees(33.0, 20.0, 0.0).unwrap(),
        eye: None,
    };
    assert_eq!(fast, shader.shade(&frame).unwrap().radiance.to_f32());
    // The default is the source's resolution, which the flag changes, slightly.
    let off = relative_rms(&fast, &source);
    assert!(off > 1e-6 && off < 0.05, "{off:e}");
    // The ground truth and ambient occlusion refuse it; a bad name is a usage error.
    let out = dir.path().join("x.png");
    for basis in ["reference", "ambient"] {
        let args = [
            "--env",
            p(&env),
            "--basis",
            basis,
            "--light-rotation",
            "prefiltered",
        ];
        fails_cleanly(
            &render_args(&cache, &out, &args),
            &["--light-rotation", basis],
        );
    }
    let args = ["--env", p(&env), "--light-rotation", "fast"];
    usage_error(
        &render_args(&cache, &out, &args),
        &["--light-rotation", "prefiltered"],
    );
}
