use super::*;

/// Brute force: build the extended signal by the table in the docs and compare.
#[test]
fn source_index_matches_the_documented_extensions() {
    for n in 1..6usize {
        let sig: Vec<isize> = (0..n as isize).collect();
        // Reflect: the period-2n signal a b c d d c b a.
        let mut refl = sig.clone();
        refl.extend(sig.iter().rev());
        for i in -3 * n as isize..4 * n as isize {
            let wrap = sig[i.rem_euclid(n as isize) as usize] as usize;
            assert_eq!(BoundaryMode::Wrap.source_index(i, n), Some(wrap));
            let r = refl[i.rem_euclid(2 * n as isize) as usize] as usize;
            assert_eq!(BoundaryMode::Reflect.source_index(i, n), Some(r));
            let e = i.clamp(0, n as isize - 1) as usize;
            assert_eq!(BoundaryMode::Edge.source_index(i, n), Some(e));
            let inside = (0..n as isize).contains(&i);
            assert_eq!(BoundaryMode::Zero.source_index(i, n).is_some(), inside);
        }
    }
    assert_eq!(BoundaryMode::Edge.source_index(0, 0), None);
}

#[test]
fn names_round_trip() {
    for &m in BoundaryMode::ALL {
        assert_eq!(m.name().parse::<BoundaryMode>().unwrap(), m);
    }
    assert_err!(
        "mirror".parse::<BoundaryMode>(),
        InvalidParameter {
            name: "boundary mode",
            ..
        },
        "unknown value \"mirror\""
    );
}
