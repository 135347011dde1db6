//! `haarshift relight error`: the relighting error measure of renders against a reference,
//! checked on arrays whose figures are worked out by hand.

use ndarray::{Array2, array};

use crate::common::{fails_cleanly, p, succeeds_with_stdout};

fn write_npy(dir: &std::path::Path, name: &str, a: &Array2<f32>) -> std::path::PathBuf {
    let path = dir.join(name);
    ndarray_npy::write_npy(&path, a).unwrap();
    path
}

#[test]
fn each_render_gets_its_rms_and_largest_difference_over_the_references_rms() {
    let dir = tempfile::tempdir().unwrap();
    // RMS of the reference sqrt(25 / 6); one sample off by 0.5: RMS difference sqrt(0.25 / 6),
    // so 0.1 relative, and the largest 0.5 / sqrt(25 / 6) = 0.2449.
    let reference = array![[3.0f32, 0.0, 0.0], [0.0, 4.0, 0.0]];
    let truth = write_npy(dir.path(), "truth.npy", &reference);
    let near = write_npy(
        dir.path(),
        "near.npy",
        &array![[3.0f32, 0.5, 0.0], [0.0, 4.0, 0.0]],
    );
    // Three times the reference: the difference is twice it, 2 relative; largest 8 / 2.0412.
    let far = write_npy(dir.path(), "far.npy", &(&reference * 3.0));
    let stdout = succeeds_with_stdout(&["relight", "error", p(&truth), p(&near), p(&far)]);
    assert_eq!(
        stdout,
        format!(
            "{}: relative RMS 1.00e-01, largest 2.45e-01\n\
             {}: relative RMS 2.00e+00, largest 3.92e+00\n",
            near.display(),
            far.display()
        )
    );
}

#[test]
fn a_render_of_another_shape_or_a_zero_reference_is_refused_naming_the_file() {
    let dir = tempfile::tempdir().unwrap();
    let truth = write_npy(dir.path(), "truth.npy", &Array2::ones((4, 3)));
    let short = write_npy(dir.path(), "short.npy", &Array2::ones((3, 3)));
    fails_cleanly(
        &["relight", "error", p(&truth), p(&short)],
        &["short.npy", "(3, 3)", "truth.npy", "(4, 3)"],
    );
    let black = write_npy(dir.path(), "black.npy", &Array2::zeros((4, 3)));
    fails_cleanly(
        &["relight", "error", p(&black), p(&truth)],
        &["black.npy", "0 everywhere"],
    );
}
