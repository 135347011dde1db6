use super::*;
use proptest::prelude::*;

fn dominated(p: (f64, f64), q: (f64, f64)) -> bool {
    q.0 <= p.0 && q.1 <= p.1 && (q.0 < p.0 || q.1 < p.1)
}

proptest! {
    /// Brute force: the frontier is exactly the set of points no other point dominates
    /// (ties in both coordinates keep the first).
    #[test]
    fn frontier_is_the_set_of_undominated_points(pts in proptest::collection::vec((0u8..20, 0u8..20), 0..30)) {
        let pts: Vec<(f64, f64)> = pts.into_iter().map(|(a, b)| (a as f64, b as f64)).collect();
        let got = frontier(&pts);
        for (i, &p) in pts.iter().enumerate() {
            let undominated = !pts.iter().any(|&q| dominated(p, q));
            let first_of_equals = pts[..i].iter().all(|&q| q != p);
            prop_assert_eq!(got.contains(&i), undominated && first_of_equals, "point {} {:?}", i, p);
        }
    }
}

#[test]
fn nan_points_are_skipped() {
    assert_eq!(frontier(&[(f64::NAN, 1.0), (1.0, 1.0)]), vec![1]);
}
