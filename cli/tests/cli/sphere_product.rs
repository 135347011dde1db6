//! `haarshift sphere product` end to end: the written map equals the pixelwise product
//! computed here (of the pruned maps with `--keep`, of the converted maps in the cube), the
//! coefficients are the product's orthonormal pyramids, and bad requests fail cleanly before
//! anything is computed or written.

use std::path::Path;

use crate::common::maps::{planes, pruned, write_map};
use crate::common::{fails_cleanly, p, succeeds, text};

use haarshift::SampleDepth;
use haarshift::faces::convert::{convert, default_samples};
use haarshift::faces::{ParamKind, Parameterization, SphereMap};
use haarshift::io::read_image;
use haarshift::sphere::LatLongMap;
use haarshift::transform::{Normalization, pyramid};
use ndarray::{Array3, Array4, Axis, s};

/// The pixelwise product of `(channels, h, w)` maps, one-channel maps broadcast.
fn pixelwise(maps: &[Array3<f64>]) -> Array3<f64> {
    let c = maps.iter().map(|m| m.dim().0).max().unwrap();
    let (_, h, w) = maps[0].dim();
    Array3::from_shape_fn((c, h, w), |(k, i, j)| {
        maps.iter()
            .map(|m| m[[k.min(m.dim().0 - 1), i, j]])
            .product()
    })
}

/// The largest relative difference.
fn max_relative(got: &Array3<f64>, want: &Array3<f64>) -> f64 {
    assert_eq!(got.dim(), want.dim());
    got.iter()
        .zip(want)
        .map(|(g, w)| ((g - w) / w).abs())
        .fold(0.0, f64::max)
}

fn read_planes(path: &Path) -> Array3<f64> {
    read_image::<f64>(path).unwrap().planes().to_owned()
}

#[test]
fn the_written_map_is_the_pixelwise_product_in_f64_and_f32() {
    let dir = tempfile::tempdir().unwrap();
    let maps = [planes(16, 3, 1), planes(16, 1, 2), planes(16, 3, 3)];
    let want = pixelwise(&maps);
    // f64 .npy in: computed and written in f64.
    let paths: Vec<_> = maps
        .iter()
        .enumerate()
        .map(|(k, m)| write_map(dir.path(), &format!("m{k}.npy"), m, SampleDepth::F64))
        .collect();
    let out = dir.path().join("fg.npy");
    let mut args = vec!["sphere", "product"];
    args.extend(paths.iter().map(|q| p(q)));
    args.extend(["-o", p(&out)]);
    let stdout = text(&succeeds(&args).stdout);
    assert!(
        stdout.contains("kept 510,510,510") && stdout.contains("f64"),
        "{stdout}"
    );
    let err = max_relative(&read_planes(&out), &want);
    assert!(err < 1e-13, "f64: {err:.1e}");
    // EXR (f32) in and out: f32 rounding through the transforms, the product and the output
    // (measured 8.4e-6 relative at worst; about 70 f32 epsilons).
    let exr: Vec<_> = maps
        .iter()
        .enumerate()
        .map(|(k, m)| write_map(dir.path(), &format!("m{k}.exr"), m, SampleDepth::F32))
        .collect();
    let out = dir.path().join("fg.exr");
    let mut args = vec!["sphere", "product"];
    args.extend(exr.iter().map(|q| p(q)));
    args.extend(["-o", p(&out)]);
    assert!(text(&succeeds(&args).stdout).contains("f32"));
    let err = max_relative(&read_planes(&out), &want);
    assert!(err < 2e-5 && err > 1e-12, "f32: {err:.1e}");
}

#[test]
fn with_keep_it_is_the_product_of_the_pruned_maps() {
    let dir = tempfile::tempdir().unwrap();
    let (h, k) = (16, 40);
    let (f, g) = (planes(h, 1, 4), planes(h, 1, 5));
    let (fp, gp) = (
        write_map(dir.path(), "f.npy", &f, SampleDepth::F64),
        write_map(dir.path(), "g.npy", &g, SampleDepth::F64),
    );
    let plane = |m: &Array3<f64>| m.index_axis(Axis(0), 0).to_owned();
    let want = (&pruned(&plane(&f), k) * &pruned(&plane(&g), k)).insert_axis(Axis(0));
    let out = dir.path().join("fg.npy");
    let args = ["sphere", "product", p(&fp), p(&gp), "-o", p(&out)];
    succeeds(&[&args[..], &["--keep", &k.to_string()]].concat());
    let got = read_planes(&out);
    let err = max_relative(&got, &want);
    assert!(err < 1e-12, "{err:.1e}");
    let full = pixelwise(&[f, g]);
    assert!(
        max_relative(&got, &full) > 1e-3,
        "--keep {k} changed nothing"
    );
}

#[test]
fn in_the_cube_it_is_the_product_of_the_converted_maps_face_after_face() {
    let dir = tempfile::tempdir().unwrap();
    let maps = [planes(16, 3, 6), planes(16, 1, 7)];
    let paths: Vec<_> = maps
        .iter()
        .enumerate()
        .map(|(k, m)| write_map(dir.path(), &format!("m{k}.npy"), m, SampleDepth::F64))
        .collect();
    let out = dir.path().join("cube.npy");
    let mut args = vec!["sphere", "product", p(&paths[0]), p(&paths[1])];
    args.extend(["--param", "cube", "--resolution", "4", "-o", p(&out)]);
    succeeds(&args);
    let ll = Parameterization::new(ParamKind::LatLong, 16).unwrap();
    let cube = Parameterization::new(ParamKind::Cube, 4).unwrap();
    let converted: Vec<Array4<f64>> = maps
        .iter()
        .map(|m| {
            let map = LatLongMap::new(m.view().permuted_axes([1, 2, 0]).to_owned()).unwrap();
            let map = SphereMap::from_lat_long(&map).unwrap();
            convert(&map, cube, default_samples(ll, cube))
                .unwrap()
                .into_array()
        })
        .collect();
    let product = &converted[0] * &converted[1];
    // The strip: face f is rows 4 f .. 4 f + 4.
    let got = read_planes(&out);
    assert_eq!(got.dim(), (3, 24, 4));
    let want = Array3::from_shape_fn((3, 24, 4), |(c, i, j)| product[[i / 4, i % 4, j, c]]);
    let err = max_relative(&got, &want);
    assert!(err < 1e-13, "{err:.1e}");
}

#[test]
fn coefficients_are_the_orthonormal_pyramids_of_the_product_faces() {
    let dir = tempfile::tempdir().unwrap();
    let maps = [planes(8, 3, 8), planes(8, 3, 9)];
    let paths: Vec<_> = maps
        .iter()
        .enumerate()
        .map(|(k, m)| write_map(dir.path(), &format!("m{k}.npy"), m, SampleDepth::F64))
        .collect();
    let out = dir.path().join("c.npy");
    succeeds(&[
        "sphere",
        "product",
        p(&paths[0]),
        p(&paths[1]),
        "--coefficients",
        "-o",
        p(&out),
    ]);
    let got: Array4<f64> = ndarray_npy::read_npy(&out).unwrap();
    assert_eq!(got.dim(), (2, 8, 8, 3));
    let want = pixelwise(&maps);
    for f in 0..2 {
        for c in 0..3 {
            let face = want.slice(s![c, .., 8 * f..8 * f + 8]);
            let pyramid = pyramid::forward(face, 3, Normalization::Orthonormal).unwrap();
            let have = got.slice(s![f, .., .., c]);
            let err = have
                .iter()
                .zip(&pyramid)
                .map(|(a, b)| (a - b).abs())
                .fold(0.0, f64::max);
            assert!(err < 1e-12, "face {f} channel {c}: {err:.1e}");
        }
    }
}

#[test]
fn bad_requests_fail_cleanly_before_anything_is_written() {
    let dir = tempfile::tempdir().unwrap();
    let a = write_map(dir.path(), "a.npy", &planes(16, 1, 10), SampleDepth::F64);
    let b = write_map(dir.path(), "b.npy", &planes(8, 1, 11), SampleDepth::F64);
    let odd = write_map(dir.path(), "odd.npy", &planes(6, 1, 12), SampleDepth::F64);
    let existing = dir.path().join("existing.npy");
    std::fs::write(&existing, b"keep me").unwrap();
    let out = dir.path().join("out.npy");
    let (a, b, odd, o) = (p(&a), p(&b), p(&odd), p(&out));
    let cases: [(&[&str], &[&str]); 8] = [
        (&[a, b, "-o", o], &["b.npy", "different sizes"]),
        (&[odd, odd, "-o", o], &["odd.npy", "not a power of two"]),
        (&[a, a, "--keep", "511", "-o", o], &["keep", "only 510"]),
        (&[a, a, "-o", p(&existing)], &["existing.npy", "exists"]),
        (&[a, a, "-o", a], &["a.npy", "input"]),
        (&[a, a, "-o", "x.png"], &["x.png", ".exr, .hdr or .npy"]),
        (&[a, a, "--coefficients", "-o", "x.exr"], &["x.exr", ".npy"]),
        (
            &[a, a, "--param", "cube", "--resolution", "6", "-o", o],
            &["resolution", "6"],
        ),
    ];
    for (args, needles) in cases {
        fails_cleanly(&[&["sphere", "product"], args].concat(), needles);
        assert!(!out.exists(), "{args:?} wrote {o}");
    }
    assert_eq!(std::fs::read(&existing).unwrap(), b"keep me");
}
