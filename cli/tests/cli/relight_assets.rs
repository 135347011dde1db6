//! Mesh assets with colour through `relight precompute` and `relight render`: the textured
//! glTF bunny renders as the PLY of its own vertices with the albedo written by the asset
//! script (`scripts/make_scene_assets.py`), and a glossy material is reported in one line.

use crate::common::{fails_cleanly, p, succeeds, testdata};

#[test]
fn the_textured_gltf_bunny_renders_as_the_ply_of_its_vertices_with_their_colours() {
    let dir = tempfile::tempdir().unwrap();
    let env = testdata("envmaps/rooitou_park_1k.hdr");
    let mut radiance = Vec::new();
    for name in ["bunny_boxes.glb", "bunny_boxes_colours.ply"] {
        let cache = dir.path().join(format!("{name}.hsr"));
        let mesh = testdata(&format!("meshes/{name}"));
        succeeds(&[
            "relight",
            "precompute",
            p(&mesh),
            "-o",
            p(&cache),
            "--resolution",
            "4",
        ]);
        let npy = dir.path().join(format!("{name}.npy"));
        let png = dir.path().join(format!("{name}.png"));
        succeeds(&[
            "relight",
            "render",
            p(&cache),
            "--env",
            p(&env),
            "-o",
            p(&png),
            "--vertices",
            p(&npy),
            "--width",
            "16",
            "--height",
            "12",
        ]);
        radiance.push(ndarray_npy::read_npy::<_, ndarray::Array2<f32>>(&npy).unwrap());
    }
    let (gltf, ply) = (&radiance[0], &radiance[1]);
    assert_eq!(gltf.dim(), (1839 + 48, 3));
    let rms = (ply.iter().map(|&x| f64::from(x).powi(2)).sum::<f64>() / ply.len() as f64).sqrt();
    let worst = (gltf - ply).iter().fold(0.0f32, |m, d| m.max(d.abs()));
    assert!(f64::from(worst) <= 1e-6 * rms, "worst {worst}, rms {rms}");
    // The texture shows: the bunny's radiance is not one colour times its irradiance.
    let ratio = |v: usize| gltf[[v, 0]] / gltf[[v, 2]];
    let (lo, hi) = (0..1839).fold((f32::MAX, 0.0f32), |(lo, hi), v| {
        (lo.min(ratio(v)), hi.max(ratio(v)))
    });
    assert!(hi > 1.2 * lo, "{lo} {hi}");
}

#[test]
fn an_asset_path_out_of_its_folder_is_refused_in_one_line() {
    let dir = tempfile::tempdir().unwrap();
    let text = std::fs::read_to_string(testdata("meshes/bunny_boxes.gltf")).unwrap();
    for (uri, needle) in [
        ("../bunny_boxes.bin", "climbs out"),
        ("/etc/passwd", "absolute path"),
        ("file:///etc/passwd", "scheme"),
    ] {
        let path = dir.path().join("x.gltf");
        std::fs::write(
            &path,
            text.replace("\"bunny_boxes.bin\"", &format!("{uri:?}")),
        )
        .unwrap();
        let out = dir.path().join("x.hsr");
        fails_cleanly(
            &[
                "relight",
                "precompute",
                p(&path),
                "-o",
                p(&out),
                "--resolution",
                "2",
            ],
            &["x.gltf: buffer 0: ", needle],
        );
    }
}
