//! The programs to start from (`examples/`, `relight/examples/`) run as a newcomer runs them,
//! built by `cargo test` beside the binaries, and do what their docs say. (The README's lines
//! that run two of them are run as written by `readme`.)

use std::path::{Path, PathBuf};

use haarshift::io::read_image;

use crate::common::{run_example as example, testdata};

#[test]
fn rotate_image_turns_the_coins_a_quarter_with_both_kernels() {
    let dir = tempfile::tempdir().unwrap();
    let coins = testdata("coins.png");
    let out = dir.path().join("out");
    example("rotate_image", &[&coins, Path::new("90"), &out]);
    let original = read_image::<f32>(&coins).unwrap();
    let (h, w) = (original.height(), original.width());
    for name in ["haar.png", "keys.png"] {
        let turned = read_image::<f32>(out.join(name)).unwrap();
        assert_eq!((turned.height(), turned.width()), (w, h), "{name}");
        // Counter-clockwise: the top row's last pixel comes to the top left corner.
        let (a, b) = (turned.plane(0)[[0, 0]], original.plane(0)[[0, w - 1]]);
        assert!((a - b).abs() <= 1.0, "{name}: {a} against {b}");
    }
}

#[test]
fn rotate_envmap_writes_the_turned_map_and_its_error_against_the_reference() {
    let dir = tempfile::tempdir().unwrap();
    let map = testdata("envmaps/rooitou_park_32x16.hdr");
    let out: PathBuf = dir.path().join("turned.exr");
    let angles = ["30", "20", "0"].map(Path::new);
    let printed = example(
        "rotate_envmap",
        &[&map, angles[0], angles[1], angles[2], &out],
    );
    let turned = read_image::<f64>(&out).unwrap();
    assert_eq!((turned.height(), turned.width()), (16, 32));
    let rms: f64 = printed.trim().rsplit(' ').next().unwrap().parse().unwrap();
    // The Haar rotation approximates the reference: an error, small against the map's RMS.
    let pixels = read_image::<f64>(&map).unwrap();
    let size =
        (pixels.planes().iter().map(|v| v * v).sum::<f64>() / pixels.planes().len() as f64).sqrt();
    assert!(
        rms > 0.0 && rms < 0.5 * size,
        "rms {rms} against a map of RMS {size}"
    );
}

#[test]
fn relight_mesh_renders_three_views_under_a_turning_sky() {
    let dir = tempfile::tempdir().unwrap();
    let (mesh, map) = (
        testdata("meshes/bunny.ply"),
        testdata("envmaps/rooitou_park_256x128.npy"),
    );
    let printed = example("relight_mesh", &[&mesh, &map, dir.path()]);
    assert!(printed.contains("precomputed"), "{printed}");
    let views = ["yaw0.png", "yaw120.png", "yaw240.png"]
        .map(|n| read_image::<f32>(dir.path().join(n)).unwrap());
    assert!(views.iter().all(|v| (v.height(), v.width()) == (240, 320)));
    // The sun moves: the views differ, the bunny (the middle of the frame) most.
    assert_ne!(views[0].planes(), views[1].planes());
    assert_ne!(views[1].planes(), views[2].planes());
}
