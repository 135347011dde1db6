use super::*;

#[test]
fn phong_lobe_integrates_to_one_about_its_axis() {
    // (e + 2) / (2 pi) x the integral of cos^e over the hemisphere, 2 pi / (e + 1): the
    // normalisation is the cosine-weighted one, so the plain integral is (e + 2) / (e + 1).
    for e in [1.0, 10.0, 50.0] {
        let got = Brdf::Phong { exponent: e }
            .local_map(256, 0.0)
            .unwrap()
            .energy()[0];
        let want = (e + 2.0) / (e + 1.0);
        assert!((got - want).abs() < 2e-3 * want, "e = {e}: {got} vs {want}");
    }
}

#[test]
fn phong_zero_is_lambert() {
    let n = [0.0, 0.6, 0.8];
    for wi in [[1.0, 0.0, 0.0], [0.0, -1.0, 0.0], [0.0, 0.6, 0.8]] {
        let p = Brdf::Phong { exponent: 0.0 }.evaluate(n, wi, [0.0, 1.0, 0.0]);
        let l = Brdf::Lambert.evaluate(n, wi, [0.0, 1.0, 0.0]);
        assert!((p[0] - l[0]).abs() < 1e-12 * l[0]);
    }
}

#[test]
fn blinn_peaks_where_the_half_vector_is_the_normal() {
    let n = [0.0, 1.0, 0.0];
    let wo = direction(0.7, 0.0);
    let b = Brdf::BlinnPhong { exponent: 30.0 };
    let peak = b.evaluate(n, mirror(n, wo), wo)[0];
    assert!((peak - 38.0 / (8.0 * std::f64::consts::PI)).abs() < 1e-12);
    assert!(b.evaluate(n, direction(0.6, std::f64::consts::PI), wo)[0] < peak);
}

#[test]
fn parse_refuses_what_it_cannot_shade() {
    assert_err!(
        "phong:nan".parse::<Brdf>(),
        InvalidParameter { name: "brdf", .. },
        "must be from 0"
    );
    assert_err!(
        "phong:x".parse::<Brdf>(),
        InvalidParameter { name: "brdf", .. },
        "not a number"
    );
    assert_err!(
        "lambert:2".parse::<Brdf>(),
        InvalidParameter { name: "brdf", .. },
        "expected one of"
    );
    assert_err!(
        "blinn:1e5".parse::<Brdf>(),
        InvalidParameter { name: "brdf", .. },
        "must be from 0"
    );
    for s in ["lambert", "phong:0", "phong:200", "blinn:12.5"] {
        assert_eq!(s.parse::<Brdf>().unwrap().to_string(), s);
    }
    assert_err!(
        "merl:".parse::<Brdf>(),
        InvalidParameter { name: "brdf", .. },
        "merl:FILE"
    );
    assert_err!(
        "merl:no/such.binary".parse::<Brdf>(),
        Io { .. },
        "no/such.binary"
    );
}

#[test]
fn a_measured_brdf_parses_and_depends_only_on_the_angles_between_n_wi_and_wo() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("phong.binary");
    let table = super::super::merl::tests::phong_table(20.0);
    table.write(&path, false).unwrap();
    let spec = format!("merl:{}", path.display());
    let brdf: Brdf = spec.parse().unwrap();
    assert_eq!(brdf.to_string(), spec);
    assert_eq!((brdf.channels(), brdf.is_mirror_symmetric()), (3, false));
    let Brdf::Measured(read) = &brdf else {
        panic!("{brdf:?}")
    };
    assert_eq!((read.path(), read.unmeasured()), (Some(path.as_path()), 0));
    // The same configuration about the normal z (the table's own frame) and about two
    // other normals, reached by rotations: the same value.
    let (wi, wo) = (direction(0.5, 0.3), direction(0.7, 2.0));
    let z = [0.0, 0.0, 1.0];
    // A quarter turn about x takes direction()'s pole +Y to z.
    let in_frame = |w: [f64; 3]| [w[0], -w[2], w[1]];
    let want = table.evaluate(in_frame(wi), in_frame(wo));
    assert!(want[0] > 0.0);
    assert_eq!(brdf.evaluate(z, in_frame(wi), in_frame(wo)), want);
    for (yaw, pitch) in [(0.3, 1.1), (2.0, -0.4)] {
        let rotate = |w: [f64; 3]| {
            let (s, c) = f64::sin_cos(pitch);
            let w = [w[0], c * w[1] - s * w[2], s * w[1] + c * w[2]];
            let (s, c) = f64::sin_cos(yaw);
            [c * w[0] + s * w[2], w[1], -s * w[0] + c * w[2]]
        };
        let n = rotate([0.0, 1.0, 0.0]);
        let got = brdf.evaluate(n, rotate(wi), rotate(wo));
        for c in 0..3 {
            assert!(
                (got[c] - want[c]).abs() < 1e-12 * want[c],
                "{got:?} {want:?}"
            );
        }
    }
    // Its local maps carry the three channels (the scales of the MERL channels).
    let map = brdf.local_map(8, 0.5).unwrap();
    let a = map.as_array();
    assert_eq!(a.dim(), (8, 16, 3));
    let (r, b) = (a[[1, 0, 0]], a[[1, 0, 2]]);
    assert!(r > 0.0 && (b / r - 1.0).abs() < 1e-9, "{r} {b}");
}
