use super::*;
use ndarray::array;

#[test]
fn upsample_then_average_is_identity_and_blocks_are_replicated() {
    let p = array![[1.0, 2.0, 3.0], [4.0, 5.0, 6.0]];
    let fine = upsample_nearest(p.view(), 2).unwrap();
    assert_eq!(fine.dim(), (8, 12));
    assert_eq!(fine[[5, 7]], p[[1, 1]]);
    assert_eq!(box_average(fine.view(), 2), p);
    let avg = box_average(array![[1.0, 3.0], [5.0, 7.0]].view(), 1);
    assert_eq!(avg, array![[4.0]]);
    assert_err!(
        upsample_nearest(p.view(), 40),
        InvalidShape { .. },
        "too large for a 2^40-finer grid"
    );
}
