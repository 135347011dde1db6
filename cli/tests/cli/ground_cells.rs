//! `--ground-cells N` and a scene file's `"ground_cells"`: the ground plane's grid as a
//! parameter, recorded in the cache (version 6), the default's arrays those of version 5, and
//! the glossy shaders told the ground's vertex count by the cache, not by the grid's formula.

use std::path::{Path, PathBuf};

use haarshift_relight::SceneCache;
use ndarray::Array2;

use crate::common::{fails_cleanly, p, succeeds, succeeds_with_stdout, testdata, usage_error};
use crate::ray_tracer::version_and_header;

/// The fields version 6 added to a cache's header (`params.ground_cells`, `ground_vertices`),
/// removed: what is left is a version 5 header's.
pub fn drop_version_6_fields(header: &mut serde_json::Value) {
    let params = header["params"].as_object_mut().unwrap();
    params.remove("ground_cells");
    header.as_object_mut().unwrap().remove("ground_vertices");
}

/// A unit cube sphere of 1 x 1 cells a face (24 vertices) on the ground plane.
fn ball_on_ground(dir: &Path, ground: &str) -> PathBuf {
    let path = dir.join("ball.json");
    let json =
        format!(r#"{{"objects": [{{"generator": {{"sphere": {{"cells": 1}}}}}}], {ground}}}"#);
    std::fs::write(&path, json).unwrap();
    path
}

/// The bytes of a cache file from its first array on (after the header and its padding to a
/// multiple of 8): every array, whatever the header's length.
fn arrays(bytes: &[u8]) -> &[u8] {
    let header = u64::from_le_bytes(bytes[16..24].try_into().unwrap()) as usize;
    &bytes[(24 + header).next_multiple_of(8)..]
}

#[test]
fn the_default_ground_plane_writes_version_5s_arrays_bit_for_bit() {
    // testdata/caches/ball_ground32_cube2_v5.hsr was written by the build of commit be617a2e
    // (cache version 5, the ground fixed at 32 x 32 cells) from this scene file:
    //   haarshift relight precompute ball.json --param cube --resolution 2 --keep-visibility 1
    //     --ray-tracer packets -o ..
    let dir = tempfile::tempdir().unwrap();
    let scene = ball_on_ground(dir.path(), r#""ground_plane": true"#);
    let out = dir.path().join("now.hsr");
    let flags = [
        "--param",
        "cube",
        "--resolution",
        "2",
        "--keep-visibility",
        "1",
    ];
    let rest = ["--ray-tracer", "packets", "-o", p(&out)];
    succeeds_with_stdout(&[&["relight", "precompute", p(&scene)][..], &flags, &rest].concat());
    let old = std::fs::read(testdata("caches/ball_ground32_cube2_v5.hsr")).unwrap();
    let now = std::fs::read(&out).unwrap();
    let (old_version, old_header) = version_and_header(&old);
    let (version, mut header) = version_and_header(&now);
    assert_eq!((old_version, version), (5, 6));
    assert_eq!(header["params"]["ground_cells"], serde_json::json!(32));
    assert_eq!(header["ground_vertices"], serde_json::json!(33 * 33));
    drop_version_6_fields(&mut header);
    assert_eq!(header, old_header);
    assert_eq!(arrays(&now).len(), arrays(&old).len());
    assert!(arrays(&now) == arrays(&old), "the arrays differ");
}

#[test]
fn ground_cells_outside_1_to_1024_or_without_a_ground_plane_are_refused_in_one_line() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("x.hsr");
    let bunny = testdata("meshes/bunny.ply");
    let head = ["relight", "precompute", p(&bunny), "-o", p(&out)];
    for cells in ["0", "1025", "many"] {
        let args = [&head[..], &["--ground-plane", "--ground-cells", cells]].concat();
        usage_error(&args, &["--ground-cells", cells]);
    }
    usage_error(
        &[&head[..], &["--ground-cells", "8"]].concat(),
        &["--ground-plane"],
    );
    let without = ball_on_ground(dir.path(), r#""ground_cells": 8"#);
    let args = ["relight", "precompute", p(&without), "-o", p(&out)];
    fails_cleanly(
        &args,
        &[
            p(&without),
            "\"ground_cells\": 8 needs \"ground_plane\": true",
        ],
    );
    let huge = ball_on_ground(dir.path(), r#""ground_plane": true, "ground_cells": 2000"#);
    let args = ["relight", "precompute", p(&huge), "-o", p(&out)];
    fails_cleanly(&args, &[p(&huge), "2000 cells per side", "1 to 1024"]);
    // A scene file's plane of 16 cells is not silently another count.
    let sixteen = ball_on_ground(dir.path(), r#""ground_plane": true, "ground_cells": 16"#);
    let args = [
        "relight",
        "precompute",
        p(&sixteen),
        "--ground-plane",
        "--ground-cells",
        "8",
    ];
    fails_cleanly(
        &[&args[..], &["-o", p(&out)]].concat(),
        &[p(&sixteen), "16 cells per side, not 8"],
    );
    assert!(!out.exists());
}

/// `relight render CACHE --vertices` of `cache` with `brdf`, `(V, 3)`.
fn radiance(dir: &Path, cache: &Path, brdf: &str) -> Array2<f32> {
    let (image, npy) = (
        dir.join(format!("{brdf}.png")),
        dir.join(format!("{brdf}.npy")),
    );
    let env = testdata("envmaps/rooitou_park_32x16.hdr");
    succeeds(&[
        "relight",
        "render",
        p(cache),
        "--env",
        p(&env),
        "--brdf",
        brdf,
        "--vertices",
        p(&npy),
        "--width",
        "16",
        "--height",
        "12",
        "-o",
        p(&image),
    ]);
    ndarray_npy::read_npy(&npy).unwrap()
}

#[test]
fn a_cache_of_64_ground_cells_shades_its_ground_lambertian_under_a_glossy_brdf() {
    let dir = tempfile::tempdir().unwrap();
    let scene = ball_on_ground(dir.path(), r#""ground_plane": true, "ground_cells": 64"#);
    let cache = dir.path().join("ball.hsr");
    succeeds_with_stdout(&[
        "relight",
        "precompute",
        p(&scene),
        "--resolution",
        "4",
        "--ray-tracer",
        "packets",
        "-o",
        p(&cache),
    ]);
    let read = SceneCache::read(&cache).unwrap();
    assert_eq!(
        (read.params.ground_cells, read.ground_vertices),
        (Some(64), 65 * 65)
    );
    assert_eq!(read.object_vertices(), 24);
    let (glossy, lambert) = (
        radiance(dir.path(), &cache, "phong:30"),
        radiance(dir.path(), &cache, "lambert"),
    );
    // Every ground vertex, the last 65^2 (not the default's 33^2), is shaded as Lambert shades
    // it; no vertex of the ball is.
    for v in 0..glossy.nrows() {
        assert_eq!(glossy.row(v) == lambert.row(v), v >= 24, "vertex {v}");
    }
}
