//! `haarshift relight scene` and `experiment dynamic` end to end on small dynamic scenes: the
//! Haar frame agrees with the ray-cast reference, animations write every frame and time it,
//! and bad scene and path files fail cleanly with one line naming the file.

use std::path::{Path, PathBuf};

use crate::common::{
    fails_cleanly, p, run_scheduled, succeeds_with_stdout, testdata, text, usage_error,
};

/// Two spheres on the ground plane, one named `ball`, under the 32 x 16 test map.
fn two_spheres(dir: &Path) -> PathBuf {
    let path = dir.join("two.json");
    let env = testdata("envmaps/rooitou_park_32x16.hdr");
    std::fs::write(
        &path,
        format!(
            r#"{{"objects": [
                {{"name": "big", "generator": {{"sphere": {{"cells": 3}}}},
                  "transform": {{"translate": [0, 1, 0]}}}},
                {{"name": "ball", "generator": {{"sphere": {{"cells": 3}}}},
                  "transform": {{"translate": [2.2, 0.5, 0.4], "scale": 0.5}}}}],
              "ground_plane": true, "environment": {{"path": "{}"}}}}"#,
            env.display()
        ),
    )
    .unwrap();
    path
}

/// The map resolution and image size of every run here.
const SMALL: [&str; 6] = ["--resolution", "8", "--width", "24", "--height", "16"];

/// Coarse fields, for the runs that do not measure the interpolation.
const COARSE: [&str; 8] = [
    "--circles",
    "12",
    "--circle-points",
    "24",
    "--shells",
    "6",
    "--shell-grid",
    "4",
];

fn run_scene(scene: &Path, out: &Path, fields: &[&str], extra: &[&str]) -> String {
    let mut args = vec!["relight", "scene", p(scene), "-o", p(out)];
    args.extend(SMALL);
    args.extend(fields);
    args.extend(extra);
    succeeds_with_stdout(&args)
}

fn read_npy(path: &Path) -> ndarray::ArrayD<f32> {
    ndarray_npy::read_npy(path).unwrap()
}

#[test]
fn a_frame_agrees_with_the_ray_cast_reference_and_reports_its_build() {
    let dir = tempfile::tempdir().unwrap();
    let scene = two_spheres(dir.path());
    let (haar, truth) = (dir.path().join("h.npy"), dir.path().join("t.npy"));
    // Sun 2006's field density (the default), and the coarse fields of the other tests.
    let stdout = run_scene(
        &scene,
        &dir.path().join("h.png"),
        &[],
        &["--vertices", p(&haar)],
    );
    assert!(stdout.contains("2 objects (1 shapes)"), "{stdout}");
    assert!(stdout.contains("29720 samples a shape"), "{stdout}");
    assert!(stdout.contains("n-function product integrals"), "{stdout}");
    let coarse = dir.path().join("c.npy");
    run_scene(
        &scene,
        &dir.path().join("c.png"),
        &COARSE,
        &["--vertices", p(&coarse)],
    );
    run_scene(
        &scene,
        &dir.path().join("t.png"),
        &COARSE,
        &["--vertices", p(&truth), "--method", "reference"],
    );
    let (h, c, t) = (read_npy(&haar), read_npy(&coarse), read_npy(&truth));
    assert_eq!(h.shape(), &[2 * 96 + 33 * 33, 3]);
    let rms = |a: &ndarray::ArrayD<f32>| {
        (a.iter().map(|x| f64::from(*x).powi(2)).sum::<f64>() / a.len() as f64).sqrt()
    };
    // The fields interpolate between samples: close, not equal, and closer when denser
    // (measured at 8 x 16 texels: 0.088 and 0.155).
    let (dense_error, coarse_error) = (rms(&(&h - &t)) / rms(&t), rms(&(&c - &t)) / rms(&t));
    assert!(dense_error > 0.0 && dense_error < 0.1, "{dense_error}");
    assert!(
        dense_error < 0.8 * coarse_error,
        "{dense_error} {coarse_error}"
    );
}

#[test]
fn an_animation_writes_every_frame_and_times_each() {
    let dir = tempfile::tempdir().unwrap();
    let scene = two_spheres(dir.path());
    let path = dir.path().join("path.json");
    std::fs::write(
        &path,
        r#"{"segments": [{"frames": 2, "object": "ball", "to": {"translate": [0.5, 0.5, 1.8], "scale": 0.5}},
                         {"frames": 1, "light_yaw": 45}]}"#,
    )
    .unwrap();
    let gif = dir.path().join("a.gif");
    let stack = dir.path().join("a.npy");
    let stdout = run_scene(
        &scene,
        &gif,
        &COARSE,
        &["--animate", p(&path), "--vertices", p(&stack)],
    );
    assert_eq!(stdout.matches("re-formed in").count(), 2, "{stdout}");
    assert!(stdout.contains("frame 3: lighting yaw +45.00"), "{stdout}");
    assert_eq!(read_npy(&stack).shape(), &[4, 2 * 96 + 33 * 33, 3]);
    let decoder = image::codecs::gif::GifDecoder::new(std::io::BufReader::new(
        std::fs::File::open(&gif).unwrap(),
    ))
    .unwrap();
    use image::AnimationDecoder;
    assert_eq!(decoder.into_frames().count(), 4);
    // One frame, then the same command again: its output exists, so it is refused.
    let one = dir.path().join("one.npy");
    let mut args = vec!["relight", "scene", p(&scene), "-o"];
    let png = dir.path().join("one.png");
    args.push(p(&png));
    args.extend(SMALL);
    args.extend(COARSE);
    args.extend(["--vertices", p(&one)]);
    succeeds_with_stdout(&args);
    fails_cleanly(&args, &["one.png", "already exists"]);
}

#[test]
fn bad_scene_and_path_files_fail_cleanly_naming_the_file() {
    let dir = tempfile::tempdir().unwrap();
    let scene = two_spheres(dir.path());
    let out = dir.path().join("o.png");
    let write = |name: &str, text: &str| {
        let path = dir.path().join(name);
        std::fs::write(&path, text).unwrap();
        path
    };
    let cases = [
        (
            write("m.json", r#"{"objects": [{"mesh": "nowhere.ply"}]}"#),
            "nowhere.ply",
        ),
        (
            write(
                "k.json",
                r#"{"objects": [{"generator": {"sphere": {"cells": 2}}, "spin": 1}]}"#,
            ),
            "unknown field",
        ),
        (
            write(
                "s.json",
                r#"{"objects": [{"generator": {"sphere": {"cells": 2}}, "transform": {"scale": -2}}]}"#,
            ),
            "scale",
        ),
        (
            write(
                "n.json",
                r#"{"objects": [{"generator": {"sphere": {"cells": 2}}, "transform": {"translate": [NaN, 0, 0]}}]}"#,
            ),
            "n.json",
        ),
    ];
    for (path, needle) in &cases {
        let mut args = vec!["relight", "scene", p(path), "-o", p(&out), "--env"];
        let env = testdata("envmaps/rooitou_park_32x16.hdr");
        args.push(p(&env));
        args.extend(SMALL);
        args.extend(COARSE);
        fails_cleanly(&args, &[needle]);
    }
    let bad_path = write(
        "p.json",
        r#"{"segments": [{"frames": 2, "object": "nobody", "to": {}}]}"#,
    );
    let mut args = vec!["relight", "scene", p(&scene), "-o"];
    let gif = dir.path().join("x.gif");
    args.push(p(&gif));
    args.extend(["--animate", p(&bad_path)]);
    args.extend(SMALL);
    args.extend(COARSE);
    fails_cleanly(&args, &["nobody"]);
    // A GIF without a path, and a turn under a cube map, are refused before any work.
    let mut args = vec!["relight", "scene", p(&scene), "-o", p(&gif)];
    args.extend(SMALL);
    args.extend(COARSE);
    fails_cleanly(&args, &["--animate"]);
    let turned = write(
        "t.json",
        r#"{"objects": [{"generator": {"sphere": {"cells": 2}}, "transform": {"yaw": 30}}]}"#,
    );
    let env = testdata("envmaps/rooitou_park_32x16.hdr");
    let args = [
        "relight",
        "scene",
        p(&turned),
        "-o",
        p(&out),
        "--env",
        p(&env),
        "--param",
        "cube",
        "--resolution",
        "4",
    ];
    fails_cleanly(&args, &["latlong"]);
}

/// `relight scene` with `--fields-dir DIR` and the coarse fields, writing the radiance to
/// `vertices`; returns what it printed.
fn run_with_fields(scene: &Path, dir: &Path, vertices: &Path, extra: &[&str]) -> String {
    let out = vertices.with_extension("png");
    let mut args = vec!["--fields-dir", p(dir), "--vertices", p(vertices)];
    args.extend(extra);
    run_scene(scene, &out, &COARSE, &args)
}

#[test]
fn a_fields_directory_is_written_once_then_loaded_and_renders_the_same() {
    let dir = tempfile::tempdir().unwrap();
    let scene = two_spheres(dir.path());
    let fields = dir.path().join("fields");
    let (first, second, fresh) = (
        dir.path().join("first.npy"),
        dir.path().join("second.npy"),
        dir.path().join("fresh.npy"),
    );
    let stdout = run_with_fields(&scene, &fields, &first, &[]);
    // Both spheres are one shape: one file, named after the generator.
    let file = fields.join("sphere-cells-3.hsf");
    let size = std::fs::metadata(&file).unwrap().len();
    assert!(
        stdout.contains(": 0 loaded in 0.00 s, 1 written, "),
        "{stdout}"
    );
    assert!(!stdout.contains(" 0 rays"), "{stdout}");
    let stdout = run_with_fields(&scene, &fields, &second, &[]);
    assert!(stdout.contains(", 0 rays, 0.0 s,"), "{stdout}");
    assert!(stdout.contains(": 1 loaded in "), "{stdout}");
    assert!(stdout.contains(", 0 written, "), "{stdout}");
    // The size printed is the file's (12 x 24 + 6 x 6 x 16 maps at 8 x 16 texels).
    let kib = format!("{:.1} KiB on disk", size as f64 / 1024.0);
    assert!(stdout.contains(&kib), "{kib} in {stdout}");
    assert_eq!(std::fs::metadata(&file).unwrap().len(), size);
    run_scene(
        &scene,
        &dir.path().join("fresh.png"),
        &COARSE,
        &["--vertices", p(&fresh)],
    );
    let (a, b, c) = (read_npy(&first), read_npy(&second), read_npy(&fresh));
    assert_eq!(a.shape(), &[2 * 96 + 33 * 33, 3]);
    assert!(a.iter().any(|&x| x > 0.0));
    assert_eq!(a, b);
    assert_eq!(a, c);
}

#[test]
fn a_stale_or_damaged_field_file_fails_cleanly_naming_it_until_force_replaces_it() {
    let dir = tempfile::tempdir().unwrap();
    let scene = two_spheres(dir.path());
    let fields = dir.path().join("fields");
    let npy = dir.path().join("v.npy");
    run_with_fields(&scene, &fields, &npy, &[]);
    let file = fields.join("sphere-cells-3.hsf");
    let good = std::fs::read(&file).unwrap();
    let args = |extra: &[&'static str]| {
        let mut a: Vec<String> = [
            "relight",
            "scene",
            p(&scene),
            "-o",
            p(&dir.path().join("x.png")),
            "--fields-dir",
            p(&fields),
        ]
        .iter()
        .map(|s| s.to_string())
        .collect();
        a.extend(
            SMALL
                .iter()
                .chain(&COARSE)
                .chain(extra)
                .map(|s| s.to_string()),
        );
        a
    };
    let fails = |extra: &[&'static str], needles: &[&str]| {
        let a = args(extra);
        let a: Vec<&str> = a.iter().map(String::as_str).collect();
        fails_cleanly(&a, needles);
        assert!(!dir.path().join("x.png").exists());
    };
    // Other field flags than the file's.
    fails(
        &["--keep-field", "10"],
        &["sphere-cells-3.hsf", "built with other options", "keep"],
    );
    fails(
        &["--param", "cube"],
        &["sphere-cells-3.hsf", r#"param "latlong" (asked: "cube")"#],
    );
    // A flipped byte, a cut, another magic, another version.
    let mut flipped = good.clone();
    flipped[good.len() / 2] ^= 1;
    let mut version = good.clone();
    version[8] = 9;
    let damaged: [(Vec<u8>, &[&str]); 4] = [
        (
            flipped,
            &["sphere-cells-3.hsf", "damaged", "checksum mismatch"],
        ),
        (
            good[..good.len() - 100].to_vec(),
            &["sphere-cells-3.hsf", "damaged"],
        ),
        (
            b"HSRCACHE and more".to_vec(),
            &["not a haarshift occlusion field file"],
        ),
        (version, &["sphere-cells-3.hsf", "format version 9"]),
    ];
    for (bytes, needles) in &damaged {
        std::fs::write(&file, bytes).unwrap();
        fails(&[], needles);
        assert_eq!(
            &std::fs::read(&file).unwrap(),
            bytes,
            "refused, left as it was"
        );
    }
    // --force builds it again and replaces it; the next run loads it.
    let a = args(&["--force"]);
    let a: Vec<&str> = a.iter().map(String::as_str).collect();
    let stdout = succeeds_with_stdout(&a);
    assert!(stdout.contains("0 loaded in 0.00 s, 1 written"), "{stdout}");
    assert_eq!(std::fs::read(&file).unwrap(), good);
    // A mesh file changed after its fields were built.
    let obj = dir.path().join("tetra.obj");
    let tetra = |top: f64| {
        format!("v 0 0 0\nv 1 0 0\nv 0 {top} 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n")
    };
    std::fs::write(&obj, tetra(1.0)).unwrap();
    let scene = dir.path().join("tetra.json");
    std::fs::write(
        &scene,
        r#"{"objects": [{"mesh": "tetra.obj"}], "environment": {"path": "env.hdr"}}"#,
    )
    .unwrap();
    std::fs::copy(
        testdata("envmaps/rooitou_park_32x16.hdr"),
        dir.path().join("env.hdr"),
    )
    .unwrap();
    run_with_fields(&scene, &fields, &dir.path().join("t.npy"), &[]);
    assert!(fields.join("tetra.hsf").exists());
    std::fs::write(&obj, tetra(2.0)).unwrap();
    let mut a = vec!["relight", "scene", p(&scene), "-o"];
    let out = dir.path().join("t2.png");
    a.extend([p(&out), "--fields-dir", p(&fields)]);
    a.extend(SMALL);
    a.extend(COARSE);
    fails_cleanly(
        &a,
        &[
            "tetra.hsf",
            "built for another mesh",
            "mesh tetra.obj: 4 vertices",
        ],
    );
    // A fields directory that is a file.
    a[6] = p(&obj);
    fails_cleanly(&a, &["tetra.obj"]);
}

/// A box over a plane, alone (no field between objects), with `material` and a camera.
fn glossy_box(dir: &Path, name: &str, material: &str) -> PathBuf {
    let path = dir.join(name);
    let env = testdata("envmaps/rooitou_park_32x16.hdr");
    std::fs::write(
        &path,
        format!(
            r#"{{"objects": [{{"generator": {{"plane_under_box": {{"height": 0.4}}}},
                  "material": {material}}}],
              "environment": {{"path": "{}"}},
              "camera": {{"position": [2, 3, 5], "look_at": [0, 0, 0]}}}}"#,
            env.display()
        ),
    )
    .unwrap();
    path
}

#[test]
fn glossy_materials_come_from_the_scene_file_or_brdf_and_agree_with_the_reference() {
    let dir = tempfile::tempdir().unwrap();
    let phong = r#"{"brdf": "phong", "exponent": 20, "albedo": [0.9, 0.9, 0.9]}"#;
    let lambert = r#"{"brdf": "lambert", "albedo": [0.9, 0.9, 0.9]}"#;
    let (glossy, matte) = (
        glossy_box(dir.path(), "g.json", phong),
        glossy_box(dir.path(), "l.json", lambert),
    );
    let npy = |name: &str| dir.path().join(name);
    let run = |scene: &Path, name: &str, extra: &[&str]| {
        let out = npy(&format!("{name}.npy"));
        let mut args = vec!["--vertices", p(&out)];
        args.extend(extra);
        run_scene(scene, &npy(&format!("{name}.png")), &COARSE, &args);
        read_npy(&out)
    };
    let direct = ["--brdf-rotation", "direct"];
    let haar = run(&glossy, "h", &direct);
    let truth = run(&glossy, "t", &["--method", "reference"]);
    let rms = |a: &ndarray::ArrayD<f32>| {
        (a.iter().map(|x| f64::from(*x).powi(2)).sum::<f64>() / a.len() as f64).sqrt()
    };
    let worst = |a: &ndarray::ArrayD<f32>, b: &ndarray::ArrayD<f32>| {
        a.iter()
            .zip(b)
            .map(|(x, y)| f64::from((x - y).abs()))
            .fold(0.0, f64::max)
            / rms(b)
    };
    // f32 output: agreement to its precision (measured 5.1e-7).
    assert!(worst(&haar, &truth) < 1e-5, "{}", worst(&haar, &truth));
    // --brdf gives every object its BRDF: the Lambertian file made glossy is the glossy file.
    let made = run(
        &matte,
        "m",
        &["--brdf", "phong:20", "--brdf-rotation", "direct"],
    );
    assert_eq!(made, haar);
    let flat = run(&glossy, "f", &["--brdf", "lambert"]);
    assert!(worst(&flat, &truth) > 0.05, "{}", worst(&flat, &truth));
    // Bad materials and flags: one line each.
    let bad = [
        (
            r#"{"brdf": "chrome", "albedo": [1, 1, 1]}"#,
            "unknown variant",
        ),
        (
            r#"{"brdf": "phong", "exponent": -1, "albedo": [1, 1, 1]}"#,
            "from 0",
        ),
    ];
    for (k, (material, needle)) in bad.iter().enumerate() {
        let scene = glossy_box(dir.path(), &format!("bad{k}.json"), material);
        let out = npy(&format!("bad{k}.png"));
        let mut args = vec!["relight", "scene", p(&scene), "-o", p(&out)];
        args.extend(SMALL);
        args.extend(COARSE);
        fails_cleanly(&args, &[needle]);
    }
    let out = npy("cache.png");
    let mut args = vec!["relight", "scene", p(&glossy), "-o", p(&out)];
    args.extend(SMALL);
    args.extend(COARSE);
    args.extend(["--rotation-cache", "4"]);
    fails_cleanly(&args, &["rotation cache", "exact frame"]);
}

#[test]
fn an_eye_segment_renders_as_the_camera_placed_where_it_orbits_to() {
    let dir = tempfile::tempdir().unwrap();
    let phong = r#"{"brdf": "phong", "exponent": 20, "albedo": [0.9, 0.9, 0.9]}"#;
    let scene = glossy_box(dir.path(), "g.json", phong);
    let path = dir.path().join("orbit.json");
    std::fs::write(&path, r#"{"segments": [{"frames": 2, "eye_yaw": 90}]}"#).unwrap();
    let (stack, one) = (dir.path().join("a.npy"), dir.path().join("one.npy"));
    let stdout = run_scene(
        &scene,
        &dir.path().join("a.gif"),
        &COARSE,
        &["--animate", p(&path), "--vertices", p(&stack)],
    );
    // The camera at (2, 3, 5) about (0, 0, 0), +Z toward +X: a quarter turn ends at (5, 3, -2).
    assert!(
        stdout.contains("frame 2: eye at [5.000, 3.000, -2.000]"),
        "{stdout}"
    );
    assert_eq!(stdout.matches("re-formed in").count(), 1, "{stdout}");
    run_scene(
        &scene,
        &dir.path().join("one.png"),
        &COARSE,
        &[
            "--camera",
            "5,3,-2",
            "--look-at",
            "0,0,0",
            "--vertices",
            p(&one),
        ],
    );
    let (frames, still) = (read_npy(&stack), read_npy(&one));
    let last = frames.index_axis(ndarray::Axis(0), 2);
    let first = frames.index_axis(ndarray::Axis(0), 0);
    let scale = still.iter().fold(0.0f32, |m, x| m.max(x.abs()));
    let differ = |a: &ndarray::ArrayViewD<f32>, b: &ndarray::ArrayViewD<f32>| {
        a.iter()
            .zip(b)
            .map(|(x, y)| (x - y).abs())
            .fold(0.0f32, f32::max)
            / scale
    };
    // Just-in-time transfer against the full product integrals, in f32.
    assert!(
        differ(&last, &still.view()) < 1e-5,
        "{}",
        differ(&last, &still.view())
    );
    // The glossy radiance moved with the eye.
    assert!(
        differ(&first, &still.view()) > 1e-2,
        "{}",
        differ(&first, &still.view())
    );
}

#[test]
fn fields_built_by_shard_load_into_the_render_of_an_unsharded_run() {
    let dir = tempfile::tempdir().unwrap();
    let scene = dir.path().join("shapes.json");
    let env = testdata("envmaps/rooitou_park_32x16.hdr");
    std::fs::write(
        &scene,
        format!(
            r#"{{"objects": [
                {{"generator": {{"sphere": {{"cells": 3}}}}, "transform": {{"translate": [0, 1, 0]}}}},
                {{"generator": {{"sphere": {{"cells": 2}}}},
                  "transform": {{"translate": [2.2, 0.5, 0.4], "scale": 0.5}}}}],
              "ground_plane": true, "environment": {{"path": "{}"}}}}"#,
            env.display()
        ),
    )
    .unwrap();
    let fields = dir.path().join("fields");
    let shard = |vars: &[(&str, &str)], spec: &str| {
        let mut args = vec!["relight", "scene", p(&scene), "--fields-dir", p(&fields)];
        args.extend(["--shard", spec]);
        args.extend(SMALL);
        args.extend(COARSE);
        let out = run_scheduled(vars, &args);
        assert!(out.status.success(), "{}", text(&out.stderr));
        text(&out.stdout)
    };
    // Shard 0 of 2 holds the first shape only.
    let stdout = shard(&[], "0/2");
    assert!(
        stdout.contains("shard 0/2: fields of 1 shapes in "),
        "{stdout}"
    );
    assert!(stdout.contains(": 1 built ("), "{stdout}");
    assert!(fields.join("sphere-cells-3.hsf").exists());
    assert!(!fields.join("sphere-cells-2.hsf").exists());
    // Shard 1 of 2 from a Slurm array's variables; run again, it finds its file.
    let slurm = [
        ("SLURM_ARRAY_TASK_ID", "1"),
        ("SLURM_ARRAY_TASK_MIN", "0"),
        ("SLURM_ARRAY_TASK_MAX", "1"),
        ("SLURM_ARRAY_TASK_COUNT", "2"),
    ];
    let stdout = shard(&slurm, "auto");
    assert!(
        stdout.contains("shard 1/2: fields of 1 shapes in "),
        "{stdout}"
    );
    assert!(fields.join("sphere-cells-2.hsf").exists());
    let stdout = shard(&slurm, "auto");
    assert!(
        stdout.contains(": 0 built (0 rays, 0.0 s), 1 loaded"),
        "{stdout}"
    );
    // A render with the directory loads both and builds nothing; its radiance is that of a
    // run that built its fields itself.
    let (sharded, fresh) = (dir.path().join("s.npy"), dir.path().join("f.npy"));
    let stdout = run_with_fields(&scene, &fields, &sharded, &[]);
    assert!(stdout.contains(": 2 loaded in "), "{stdout}");
    assert!(stdout.contains(", 0 written, "), "{stdout}");
    run_with_fields(&scene, &dir.path().join("other"), &fresh, &[]);
    let (a, b) = (read_npy(&sharded), read_npy(&fresh));
    assert!(a.iter().any(|&x| x > 0.0));
    assert_eq!(a, b);
    // --shard needs --fields-dir, and renders nothing.
    let args = ["relight", "scene", p(&scene), "--shard", "0/2"];
    fails_cleanly(&args, &["--fields-dir DIR"]);
    let out = dir.path().join("x.png");
    let args = [
        "relight",
        "scene",
        p(&scene),
        "--shard",
        "0/2",
        "-o",
        p(&out),
    ];
    usage_error(&args, &["--shard"]);
    usage_error(&["relight", "scene", p(&scene)], &["--output"]);
}
