//! The command line reading a real run-length-encoded Radiance `.hdr`: `sphere rotate` on
//! `testdata/envmaps/rooitou_park_32x16.hdr` gives the library's rotation of the values the
//! file's generator recorded (`rooitou_park_32x16_values.npy`, computed from the RGBE bytes,
//! not decoded from the file).

use crate::common::{p, succeeds, testdata};

use haarshift::SampleDepth;
use haarshift::io::read_image;
use haarshift::sphere::{LatLongMap, Method, SphereOptions, SphereRotation, rotate_map};

#[test]
fn sphere_rotate_reads_a_run_length_encoded_hdr() {
    let dir = tempfile::tempdir().unwrap();
    let input = testdata("envmaps/rooitou_park_32x16.hdr");
    let values = read_image::<f32>(testdata("envmaps/rooitou_park_32x16_values.npy")).unwrap();
    let map = LatLongMap::from_image(&values).unwrap();
    let rotation = SphereRotation::from_degrees(25.0, 30.0, -10.0).unwrap();
    for method in ["bilinear", "haar"] {
        let out = dir.path().join(format!("{method}.npy"));
        succeeds(&[
            "sphere",
            "rotate",
            p(&input),
            "-o",
            p(&out),
            "--yaw",
            "25",
            "--pitch",
            "30",
            "--roll",
            "-10",
            "--method",
            method,
        ]);
        let got = read_image::<f32>(&out).unwrap();
        let options = SphereOptions {
            method: method.parse::<Method>().unwrap(),
            ..Default::default()
        };
        let want = rotate_map(&map, &rotation, &options)
            .unwrap()
            .map
            .to_image(SampleDepth::F32)
            .unwrap();
        assert_eq!(got.planes().dim(), want.planes().dim());
        let peak = want.planes().iter().fold(0.0f32, |m, &v| m.max(v.abs()));
        let err = got
            .planes()
            .iter()
            .zip(want.planes())
            .map(|(a, b)| (a - b).abs())
            .fold(0.0f32, f32::max);
        // Same computation on the same values in f32: equal to rounding.
        assert!(err <= 1e-6 * peak, "{method}: {err} (peak {peak})");
        assert!(peak > 1.0, "{method}: {peak}");
    }
}
