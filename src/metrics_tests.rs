use super::*;
use ndarray::array;

#[test]
fn masked_statistics_count_only_the_mask() {
    let a = array![[0.0, 10.0], [3.0, 0.0]];
    let b = array![[0.0, 0.0], [0.0, 4.0]];
    let m = array![[true, false], [true, true]];
    let s = ErrorStats::between(a.view(), b.view(), Some(m.view()), 255.0).unwrap();
    assert_eq!(s.count, 3);
    assert_eq!(s.max_error, 4.0);
    assert!((s.rms - (25.0f64 / 3.0).sqrt()).abs() < 1e-15);
}

#[test]
fn identical_arrays_have_infinite_psnr_serialised_as_null() {
    let a = array![[1.0f32, 2.0]];
    let s = ErrorStats::between(a.view(), a.view(), None, 255.0).unwrap();
    assert_eq!((s.rms, s.max_error), (0.0, 0.0));
    assert!(s.psnr.is_infinite());
    let json = serde_json::to_string(&s).unwrap();
    assert!(json.contains("\"psnr\":null"));
    assert_eq!(serde_json::from_str::<ErrorStats>(&json).unwrap(), s);
}

#[test]
fn rejects_mismatched_shapes_and_empty_masks() {
    let a = array![[1.0, 2.0]];
    assert_err!(
        ErrorStats::between(a.view(), array![[1.0]].view(), None, 1.0),
        InvalidShape { .. },
        "one shape"
    );
    let none = array![[false, false]];
    assert_err!(
        ErrorStats::between(a.view(), a.view(), Some(none.view()), 1.0),
        InvalidParameter { name: "mask", .. },
        "selects no samples"
    );
}

#[test]
fn disk_mask_matches_a_direct_count() {
    // Radius 3 around the centre of a 7x7 grid: lattice points with di^2 + dj^2 <= 9.
    let m = disk_mask(7, 7, 3.0);
    let direct = (-3i32..=3)
        .flat_map(|i| (-3i32..=3).map(move |j| i * i + j * j))
        .filter(|&r2| r2 <= 9)
        .count();
    assert_eq!(m.iter().filter(|&&v| v).count(), direct);
    // Even sizes: the centre lies between pixels, so the mask is symmetric under flips.
    let e = disk_mask(8, 6, 2.5);
    assert_eq!(e, e.slice(ndarray::s![..;-1, ..;-1]));
}
