use super::*;
use std::f64::consts::PI;

fn kinds() -> [ParamKind; 2] {
    [ParamKind::LatLong, ParamKind::Cube]
}

#[test]
fn the_constant_one_integrates_to_four_pi() {
    for kind in kinds() {
        for size in [1, 2, 16, 128] {
            let p = Parameterization::new(kind, size).unwrap();
            let one = SphereMap::<f64>::from_fn(p, 1, |_, o| o[0] = 1.0).unwrap();
            let e = one.energy()[0];
            assert!((e - 4.0 * PI).abs() < 1e-12, "{kind} {size}: {e}");
        }
    }
}

#[test]
fn cells_split_each_texel_exactly() {
    for kind in kinds() {
        let p = Parameterization::new(kind, 4).unwrap();
        for (f, r, c) in [(0, 0, 0), (1, 3, 2), (p.faces() - 1, 1, 3)] {
            for n in [1, 3, 8] {
                let mut total = 0.0;
                for k in 0..n {
                    for l in 0..n {
                        let rows = (
                            r as f64 + k as f64 / n as f64,
                            r as f64 + (k + 1) as f64 / n as f64,
                        );
                        let cols = (
                            c as f64 + l as f64 / n as f64,
                            c as f64 + (l + 1) as f64 / n as f64,
                        );
                        let centre = p.point(f, 0.5 * (rows.0 + rows.1), 0.5 * (cols.0 + cols.1));
                        assert_eq!(p.texel_of(centre), (f, r, c), "{kind} {n}");
                        total += p.cell_solid_angle(rows, cols);
                    }
                }
                let want = p.texel_solid_angle(f, r, c);
                assert!((total - want).abs() < 1e-15, "{kind} ({f}, {r}, {c}) {n}");
            }
        }
    }
}

#[test]
fn lat_long_faces_are_the_halves_of_the_map() {
    let m = LatLongMap::<f64>::from_fn(8, 3, |d, out| out.copy_from_slice(&d)).unwrap();
    let s = SphereMap::from_lat_long(&m).unwrap();
    let p = s.param();
    for f in 0..2 {
        for r in 0..8 {
            for c in 0..8 {
                let d = p.texel_direction(f, r, c);
                for (k, dk) in d.iter().enumerate() {
                    assert_eq!(s.as_array()[[f, r, c, k]], m.as_array()[[r, 8 * f + c, k]]);
                    assert!((s.as_array()[[f, r, c, k]] - dk).abs() < 1e-15);
                }
            }
        }
    }
    for (a, b) in s.energy().iter().zip(m.energy()) {
        assert!((a - b).abs() < 1e-14);
    }
    assert_eq!(s.to_lat_long().unwrap(), m);
}

#[test]
fn directions_round_trip_and_stay_on_the_unit_sphere() {
    for kind in kinds() {
        let p = Parameterization::new(kind, 8).unwrap();
        for f in 0..p.faces() {
            for r in 0..8 {
                for c in 0..8 {
                    let d = p.texel_direction(f, r, c);
                    let norm = d.iter().map(|v| v * v).sum::<f64>();
                    assert!((norm - 1.0).abs() < 1e-15);
                    assert_eq!(p.texel_of(d), (f, r, c), "{kind}");
                }
            }
        }
    }
}

#[test]
fn bad_shapes_and_values_are_errors() {
    let p = Parameterization::new(ParamKind::Cube, 2).unwrap();
    assert_err!(
        SphereMap::new(p, Array4::<f64>::zeros((6, 2, 4, 1))),
        InvalidShape { .. },
        "[6, 2, 4, 1]",
        "(6, 6, 6, 1 to 64 channels)"
    );
    assert_err!(
        SphereMap::new(p, Array4::<f64>::zeros((6, 2, 2, 0))),
        InvalidShape { .. },
        "[6, 2, 2, 0]",
        "(6, 6, 6, 1 to 64 channels)"
    );
    let mut nan = Array4::<f64>::zeros((6, 2, 2, 1));
    nan[[3, 1, 0, 0]] = f64::NAN;
    assert!(matches!(
        SphereMap::new(p, nan),
        Err(Error::NonFinite { .. })
    ));
    assert_err!(
        Parameterization::new(ParamKind::Cube, 0),
        InvalidParameter {
            name: "resolution",
            ..
        },
        "0: a face side must be a power of two"
    );
    assert_err!(
        Parameterization::new(ParamKind::Cube, 1 << 16),
        InvalidParameter {
            name: "resolution",
            ..
        },
        "65536: a face side"
    );
    let odd = LatLongMap::<f64>::from_fn(3, 1, |_, o| o[0] = 1.0).unwrap();
    assert_err!(
        SphereMap::from_lat_long(&odd),
        InvalidParameter {
            name: "resolution",
            ..
        },
        "3: a face side"
    );
    let cube = SphereMap::<f64>::from_fn(p, 1, |_, o| o[0] = 1.0).unwrap();
    assert_err!(
        cube.to_lat_long(),
        InvalidParameter { name: "param", .. },
        "not a lat-long map"
    );
}
