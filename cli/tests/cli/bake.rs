//! `haarshift relight bake`: every file it writes holds the mesh and the radiance
//! `relight render --vertices` computes, bit for bit; the Khronos glTF Validator passes each
//! with no error and no warning; three.js alone shows it; bad requests are refused in one line
//! before any work.

use std::path::{Path, PathBuf};
use std::process::Command;

use haarshift_relight::SceneCache;
use haarshift_relight::render::baked::BakedGltf;
use ndarray::Array2;
use serde_json::Value;

use crate::common::strs;
use crate::common::{fails_cleanly, p, succeeds, succeeds_with_stdout, testdata, usage_error};

/// A sphere on the ground plane precomputed at lat-long 8 x 16 in `dir`.
fn coloured_sphere_cache(dir: &Path) -> PathBuf {
    let scene = dir.join("sphere.json");
    std::fs::write(
        &scene,
        r#"{"objects": [{"generator": {"sphere": {"cells": 3}},
            "transform": {"translate": [0, 1, 0]},
            "material": {"brdf": "lambert", "albedo": [0.9, 0.6, 0.3]}}],
            "ground_plane": true}"#,
    )
    .unwrap();
    let cache = dir.join("sphere.hsr");
    succeeds(&[
        "relight",
        "precompute",
        p(&scene),
        "--resolution",
        "8",
        "-o",
        p(&cache),
    ]);
    cache
}

fn env() -> PathBuf {
    testdata("envmaps/rooitou_park_32x16.hdr")
}

/// `relight render --vertices` at `yaw` (with `extra` flags): the radiance `(V, 3)`.
fn rendered(dir: &Path, cache: &Path, yaw: &str, extra: &[&str]) -> Array2<f32> {
    let png = dir.join(format!("render{yaw}.png"));
    let npy = dir.join(format!("render{yaw}.npy"));
    let env = env();
    let mut args = vec!["relight", "render", p(cache), "--env", p(&env)];
    args.extend(["--yaw", yaw, "--width", "8", "--height", "6", "--force"]);
    args.extend(["-o", p(&png), "--vertices", p(&npy)]);
    args.extend(extra);
    succeeds(&args);
    ndarray_npy::read_npy(&npy).unwrap()
}

/// `relight bake CACHE --env ENV ARGS`: its standard output.
fn bake(cache: &Path, args: &[&str]) -> String {
    let env = env();
    let mut all = vec!["relight", "bake", p(cache), "--env", p(&env)];
    all.extend(args);
    succeeds_with_stdout(&all)
}

#[test]
fn each_yaw_s_file_holds_the_mesh_and_relight_render_s_radiance_bit_for_bit() {
    let dir = tempfile::tempdir().unwrap();
    let cache = coloured_sphere_cache(dir.path());
    let out = dir.path().join("out.glb");
    let stdout = bake(
        &cache,
        &["--yaw", "0,-90.5", "--exposure", "1", "-o", p(&out)],
    );
    let mesh = SceneCache::read(&cache).unwrap().mesh;
    for (yaw, name) in [("0", "out_yaw0.glb"), ("-90.5", "out_yaw-90.5.glb")] {
        let path = dir.path().join(name);
        assert!(
            stdout.contains(&format!("{}: ", path.display())),
            "{stdout}"
        );
        let baked = BakedGltf::read(&path).unwrap();
        let radiance = rendered(dir.path(), &cache, yaw, &[]);
        assert_eq!(baked.radiance, radiance, "{name}");
        // Exposure 1: COLOR_0 is 2 L clamped to 0..1 (doubling is exact in f32).
        assert_eq!(baked.colours, radiance.mapv(|l| (2.0 * l).clamp(0.0, 1.0)));
        assert_eq!(baked.positions, mesh.positions().mapv(|x| x as f32));
        assert_eq!(baked.normals, mesh.normals().mapv(|x| x as f32));
        assert_eq!(baked.triangles, mesh.triangles());
        let stated = &baked.extras["haarshift"];
        assert_eq!(
            stated["rotation_degrees"]["yaw"],
            yaw.parse::<f64>().unwrap()
        );
        assert_eq!(stated["exposure_stops"], 1.0);
        assert_eq!(stated["environment"], "rooitou_park_32x16.hdr");
        assert_eq!(stated["cache"], "sphere.hsr");
    }
    assert!(!out.exists(), "several yaws write only the named files");
    // One yaw writes -o itself; .gltf embeds the buffer; the material flags are render's.
    let gltf = dir.path().join("one.gltf");
    let flags = ["--albedo", "0.2,0.4,0.6", "--keep-light", "20"];
    let mut args = vec!["--yaw", "45", "-o", p(&gltf)];
    args.extend(flags);
    bake(&cache, &args);
    let baked = BakedGltf::read(&gltf).unwrap();
    assert_eq!(baked.radiance, rendered(dir.path(), &cache, "45", &flags));
}

#[test]
fn bad_requests_are_refused_in_one_line_before_any_work() {
    let dir = tempfile::tempdir().unwrap();
    let cache = coloured_sphere_cache(dir.path());
    let env = env();
    let out = dir.path().join("b.glb");
    // `relight bake CACHE --env ENV EXTRA -o OUT`.
    let with = |extra: &[&str], out: &Path| -> Vec<String> {
        let mut args = vec!["relight", "bake", p(&cache), "--env", p(&env)];
        args.extend(extra);
        args.extend(["-o", p(out)]);
        args.iter().map(|s| s.to_string()).collect()
    };
    for empty in ["", ",", "10,,20", "nan"] {
        let args = with(&["--yaw", empty], &out);
        usage_error(
            &strs(&args),
            &["--yaw", "expected one or more finite angles"],
        );
    }
    usage_error(
        &strs(&with(&["--yaw", "5,5"], &out)),
        &["yaw 5 is listed twice"],
    );
    // An existing output, the second of a list: refused before the first is written.
    let second = dir.path().join("b_yaw20.glb");
    std::fs::write(&second, b"keep").unwrap();
    fails_cleanly(
        &strs(&with(&["--yaw", "10,20"], &out)),
        &["b_yaw20.glb", "already exists"],
    );
    assert!(!dir.path().join("b_yaw10.glb").exists());
    assert_eq!(std::fs::read(&second).unwrap(), b"keep");
    succeeds(&strs(&with(&["--yaw", "10,20", "--force"], &out)));
    assert!(BakedGltf::read(&second).is_ok());
    // A folder that is not there, or is a file.
    let missing = dir.path().join("no/such/folder/x.glb");
    fails_cleanly(&strs(&with(&[], &missing)), &["x.glb", "output directory"]);
    let under_file = second.join("x.glb");
    fails_cleanly(
        &strs(&with(&[], &under_file)),
        &["x.glb", "output directory"],
    );
    // Another container, an absurd exposure, an output that is the cache.
    let obj = dir.path().join("b.obj");
    fails_cleanly(&strs(&with(&[], &obj)), &["b.obj", ".glb or .gltf"]);
    let args = with(&["--exposure", "100", "--force"], &out);
    fails_cleanly(&strs(&args), &["exposure", "100"]);
    let args = with(&["--force"], &cache);
    fails_cleanly(&strs(&args), &["sphere.hsr"]);
    assert!(SceneCache::read(&cache).is_ok());
}

/// Where a tool's npm packages are installed (`npm ci` in its folder), or why it cannot run.
fn node_tool(folder: &str, package: &str) -> Result<(PathBuf, PathBuf), String> {
    let tool = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../tools")
        .join(folder);
    let node = std::env::var_os("PATH")
        .iter()
        .flat_map(std::env::split_paths)
        .map(|d| d.join("node"))
        .find(|p| p.is_file())
        .ok_or("no node on the PATH (apt-get install nodejs npm)")?;
    if !tool.join("node_modules").join(package).is_dir() {
        return Err(format!(
            "{package} is not installed (npm ci in {})",
            tool.display()
        ));
    }
    Ok((node, tool))
}

/// Runs `node TOOL/SCRIPT ARGS`; its exit status and each line of standard output as JSON.
fn run_node(node: &Path, script: &Path, args: &[&str]) -> (bool, Vec<Value>) {
    let out = Command::new(node).arg(script).args(args).output().unwrap();
    let stdout = String::from_utf8_lossy(&out.stdout);
    let lines = stdout
        .lines()
        .map(|l| serde_json::from_str(l).unwrap_or_else(|e| panic!("{e}: {l}")))
        .collect();
    assert!(
        out.status.code().is_some_and(|c| c < 2),
        "{}: {}",
        script.display(),
        String::from_utf8_lossy(&out.stderr)
    );
    (out.status.success(), lines)
}

#[test]
fn the_khronos_validator_finds_nothing_to_say_about_any_file_baked() {
    let Some((node, tool)) =
        haarshift_testkit::needs("node", node_tool("gltf-validate", "gltf-validator"))
    else {
        return;
    };
    let dir = tempfile::tempdir().unwrap();
    let cache = coloured_sphere_cache(dir.path());
    let glb = dir.path().join("v.glb");
    let gltf = dir.path().join("v.gltf");
    bake(
        &cache,
        &["--yaw", "0,120", "--exposure", "-1", "-o", p(&glb)],
    );
    bake(&cache, &["-o", p(&gltf)]);
    let files: Vec<PathBuf> = ["v_yaw0.glb", "v_yaw120.glb", "v.gltf"]
        .map(|n| dir.path().join(n))
        .to_vec();
    let args: Vec<&str> = files.iter().map(|f| p(f)).collect();
    let (passed, reports) = run_node(&node, &tool.join("validate.mjs"), &args);
    assert_eq!(reports.len(), 3);
    for report in &reports {
        // Nothing at all: no error, warning, information or hint.
        let counts = ["errors", "warnings", "infos", "hints"].map(|k| report[k].as_u64());
        assert_eq!(counts, [Some(0); 4], "{report}");
    }
    assert!(passed);
    // The validator is no rubber stamp: a POSITION beyond its declared bounds is an error.
    let mut document: Value = serde_json::from_slice(&std::fs::read(&gltf).unwrap()).unwrap();
    document["accessors"][0]["max"] = serde_json::json!([0.0, 0.0, 0.0]);
    let broken = dir.path().join("broken.gltf");
    std::fs::write(&broken, serde_json::to_vec(&document).unwrap()).unwrap();
    let (passed, reports) = run_node(&node, &tool.join("validate.mjs"), &[p(&broken)]);
    assert!(
        !passed && reports[0]["errors"].as_u64() > Some(0),
        "{reports:?}"
    );
    assert!(
        reports[0]
            .to_string()
            .contains("ACCESSOR_ELEMENT_OUT_OF_MAX_BOUND"),
        "{reports:?}"
    );
}

#[test]
fn three_js_alone_shows_the_baked_colours_in_headless_chromium() {
    let Some((node, tool)) = haarshift_testkit::needs("node", node_tool("bake-threejs", "three"))
    else {
        return;
    };
    if haarshift_testkit::needs("chromium", haarshift_testkit::browser::chromium()).is_none() {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let cache = coloured_sphere_cache(dir.path());
    let glb = dir.path().join("s.glb");
    bake(&cache, &["--exposure", "1", "-o", p(&glb)]);
    let png = dir.path().join("s.png");
    let (passed, reports) = run_node(
        &node,
        &tool.join("shoot.mjs"),
        &[p(&glb), p(&png), "160", "120"],
    );
    assert!(passed, "{reports:?}");
    let page = &reports[0];
    assert_eq!(page["materials"][0]["type"], "MeshBasicMaterial", "{page}");
    assert_eq!(page["materials"][0]["vertexColors"], true, "{page}");
    let vertices = SceneCache::read(&cache).unwrap().mesh.vertex_count();
    assert_eq!(page["materials"][0]["vertices"], vertices, "{page}");
    // The page frames the mesh with relight render's default camera (Camera::framing) over
    // #202020 (linear 0.0144, 0.0072 before the exposure of 1 stop): its picture is haarshift's own rasterisation of the same
    // radiance, but for the edges' antialiasing and the two rasterisers' rounding.
    let shot = image::open(&png).unwrap().to_rgb8();
    let ours = dir.path().join("ours.png");
    let env = env();
    succeeds(&[
        "relight",
        "render",
        p(&cache),
        "--env",
        p(&env),
        "--exposure",
        "1",
        "--width",
        "160",
        "--height",
        "120",
        "--background",
        "0.0072,0.0072,0.0072",
        "-o",
        p(&ours),
    ]);
    let ours = image::open(&ours).unwrap().to_rgb8();
    let background = shot.pixels().filter(|px| px.0 == [32, 32, 32]).count();
    let covered = 1.0 - background as f64 / (160.0 * 120.0);
    let differences: Vec<u8> = shot
        .pixels()
        .zip(ours.pixels())
        .map(|(a, b)| (0..3).map(|k| a.0[k].abs_diff(b.0[k])).max().unwrap())
        .collect();
    let mean = differences.iter().map(|&d| f64::from(d)).sum::<f64>() / differences.len() as f64;
    let far = differences.iter().filter(|&&d| d > 16).count() as f64 / differences.len() as f64;
    assert!(
        covered > 0.1 && mean < 2.0 && far < 0.02,
        "the mesh covers {covered} of the frame; three.js's picture is {mean} codes from \
         relight render's on average, {far} of the pixels more than 16"
    );
}

#[test]
fn the_viewer_s_save_glb_is_the_last_frame_baked_as_relight_bake_bakes_it() {
    use crate::viewer::{Client, ViewProcess};
    let dir = tempfile::tempdir().unwrap();
    let cache = coloured_sphere_cache(dir.path());
    let view = ViewProcess::start(&[p(&cache), "--env", p(&env())]);
    let mut page = Client::opened(&view.url);
    page.send(r#"{"type": "glb", "exposure": 0}"#);
    page.refused("no frame has been drawn yet");
    page.send(r#"{"type": "state", "seq": 4, "yaw": 30, "light_rotation": "source"}"#);
    let (kind, header, frame) = page.packet();
    assert_eq!((kind, header["seq"].as_u64()), (3, Some(4)), "{header}");
    page.send(r#"{"type": "glb", "exposure": 100}"#);
    page.refused("exposure");
    page.send(r#"{"type": "glb", "exposure": 1}"#);
    let glb = match page.next() {
        tungstenite::Message::Binary(b) => {
            assert_eq!(u32::from_le_bytes(b[0..4].try_into().unwrap()), 7);
            let len = u32::from_le_bytes(b[4..8].try_into().unwrap()) as usize;
            b[(8 + len).next_multiple_of(4)..].to_vec()
        }
        other => panic!("a glb expected, got {other:?}"),
    };
    let saved = BakedGltf::from_bytes(&glb).unwrap();
    assert_eq!(saved.radiance.iter().copied().collect::<Vec<_>>(), frame);
    let out = dir.path().join("bake.glb");
    bake(&cache, &["--yaw", "30", "--exposure", "1", "-o", p(&out)]);
    let baked = BakedGltf::read(&out).unwrap();
    assert_eq!(
        (&saved.positions, &saved.normals, &saved.triangles),
        (&baked.positions, &baked.normals, &baked.triangles)
    );
    assert_eq!(
        (&saved.colours, &saved.radiance),
        (&baked.colours, &baked.radiance)
    );
    assert_eq!(saved.extras["haarshift"]["rotation_degrees"]["yaw"], 30.0);
}
