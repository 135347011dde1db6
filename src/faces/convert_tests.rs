use super::super::param::ParamKind;
use super::*;
use crate::sphere::LatLongMap;
use crate::test_support::param;
use ndarray::Array3;
use std::f64::consts::PI;

/// A smooth test function: low-order spherical harmonics plus a constant.
fn smooth_function(d: [f64; 3]) -> f64 {
    let [x, y, z] = d;
    1.0 + 0.5 * x - 0.4 * z + 0.3 * y * z + 0.2 * (3.0 * y * y - 1.0) + 0.25 * x * y
}

/// The rooitou park test map (128 x 256 x 3, see testdata/envmaps/SOURCES.md).
fn rooitou_sphere_map() -> SphereMap<f64> {
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/testdata/envmaps/rooitou_park_256x128.npy"
    );
    let data: Array3<f32> = ndarray_npy::read_npy(path).unwrap();
    SphereMap::from_lat_long(&LatLongMap::new(data.mapv(f64::from)).unwrap()).unwrap()
}

/// The largest relative change of a channel's integral.
fn energy_change(a: &SphereMap<f64>, b: &SphereMap<f64>) -> f64 {
    a.energy()
        .iter()
        .zip(b.energy())
        .map(|(x, y)| ((x - y) / x).abs())
        .fold(0.0, f64::max)
}

/// The solid-angle weighted RMS difference of two maps in one parameterisation, relative
/// to the first one's weighted RMS.
fn relative_rms(a: &SphereMap<f64>, b: &SphereMap<f64>) -> f64 {
    b.relative_rms_error(a).unwrap()
}

#[test]
fn constants_map_to_the_same_constant_and_one_integrates_to_four_pi() {
    let pairs = [
        (param(ParamKind::LatLong, 32), param(ParamKind::Cube, 16)),
        (param(ParamKind::Cube, 16), param(ParamKind::LatLong, 32)),
        (param(ParamKind::LatLong, 32), param(ParamKind::LatLong, 8)),
        (param(ParamKind::Cube, 4), param(ParamKind::Cube, 32)),
    ];
    for (from, to) in pairs {
        let f = SphereMap::<f64>::from_fn(from, 2, |_, o| o.copy_from_slice(&[1.0, 3.5])).unwrap();
        for n in [1, 5] {
            let g = convert(&f, to, n).unwrap();
            for px in g.as_array().as_slice().unwrap().chunks_exact(2) {
                assert!((px[0] - 1.0).abs() < 1e-14 && (px[1] - 3.5).abs() < 1e-14);
            }
            let e = g.energy();
            assert!((e[0] - 4.0 * PI).abs() < 1e-12, "{from:?} -> {to:?}: {e:?}");
        }
    }
}

#[test]
fn a_map_already_on_the_target_grid_is_unchanged() {
    // Every cell centre lies inside its own texel: converting to the same
    // parameterisation, or to a finer one and back, is exact.
    let f = rooitou_sphere_map();
    let same = convert(&f, f.param(), 3).unwrap();
    assert!(relative_rms(&f, &same) < 1e-15);
    let fine = convert(&f, param(ParamKind::LatLong, 256), 1).unwrap();
    let back = convert(&fine, f.param(), 2).unwrap();
    assert!(relative_rms(&f, &back) < 1e-15);
}

/// lat-long 128 -> cube 64 -> lat-long 128 with the default cell counts: the energy
/// change of each step and the relative weighted RMS of the round trip.
fn round_trip(f: &SphereMap<f64>) -> (f64, f64, f64) {
    let (ll, cube) = (f.param(), param(ParamKind::Cube, 64));
    let g = convert(f, cube, default_samples(ll, cube)).unwrap();
    let back = convert(&g, ll, default_samples(cube, ll)).unwrap();
    (
        energy_change(f, &g),
        energy_change(&g, &back),
        relative_rms(f, &back),
    )
}

#[test]
fn converting_keeps_the_energy_and_round_trips_stay_close() {
    // Measured (lat-long 128 -> cube 64 -> lat-long 128, default cells 6 and 4):
    //   smooth map: energy 1.1e-6 and 1.4e-7, round trip 1.8e-3 relative weighted RMS;
    //   rooitou park (RGB, max over channels): energy 1.7e-2 and 1.6e-2 (its sun holds
    //   most of the energy in about one texel, whose edges the cells straddle), round
    //   trip 0.63 (the sun spread over its neighbours).
    // Bounds: 2x the measured figures.
    let smooth = SphereMap::from_fn(param(ParamKind::LatLong, 128), 1, |d, o| {
        o[0] = smooth_function(d)
    })
    .unwrap();
    let (e1, e2, rms) = round_trip(&smooth);
    eprintln!("smooth: energy {e1:.2e} {e2:.2e}, round trip {rms:.2e}");
    assert!(e1 < 2.2e-6 && e2 < 3e-7 && rms < 3.6e-3, "{e1} {e2} {rms}");
    let (e1, e2, rms) = round_trip(&rooitou_sphere_map());
    eprintln!("rooitou: energy {e1:.2e} {e2:.2e}, round trip {rms:.2e}");
    assert!(e1 < 3.4e-2 && e2 < 3.2e-2 && rms < 1.3, "{e1} {e2} {rms}");
}

#[test]
fn cube_texels_are_solid_angle_means_of_the_lat_long_texels() {
    // Oracle by brute force: a 1-texel-per-face cube from a 2 x 4 lat-long map whose
    // texels are the indicator functions; face f's value must be the fraction of face f
    // covered by the lat-long texel, which a fine Fibonacci lattice estimates.
    let ll = param(ParamKind::LatLong, 2);
    let cube = param(ParamKind::Cube, 1);
    let n = 200_000;
    let golden = PI * (3.0 - 5f64.sqrt());
    let mut hits = [[0usize; 8]; 6];
    for k in 0..n {
        let y = 1.0 - (k as f64 + 0.5) * 2.0 / n as f64;
        let r = (1.0 - y * y).sqrt();
        let phi = k as f64 * golden;
        let d = [r * phi.sin(), y, r * phi.cos()];
        let (f, _, _) = cube.texel_of(d);
        let (lf, lr, lc) = ll.texel_of(d);
        hits[f][lr * 4 + lf * 2 + lc] += 1;
    }
    for t in 0..8 {
        let indicator = SphereMap::<f64>::from_texels(ll, 1, |(f, r, c), o| {
            o[0] = if r * 4 + f * 2 + c == t { 1.0 } else { 0.0 }
        })
        .unwrap();
        let g = convert(&indicator, cube, 64).unwrap();
        for (f, face_hits) in hits.iter().enumerate() {
            let want = face_hits[t] as f64 / face_hits.iter().sum::<usize>() as f64;
            let got = g.as_array()[[f, 0, 0, 0]];
            assert!(
                (got - want).abs() < 0.01,
                "texel {t}, face {f}: {got} vs {want}"
            );
        }
    }
}

#[test]
fn bad_sample_counts_are_errors() {
    let f = rooitou_sphere_map();
    assert_err!(
        convert(&f, param(ParamKind::Cube, 4), 0),
        InvalidParameter {
            name: "samples",
            ..
        },
        "0 cells per axis"
    );
    assert_err!(
        convert(&f, param(ParamKind::Cube, 4), 65),
        InvalidParameter {
            name: "samples",
            ..
        },
        "65 cells per axis"
    );
}
