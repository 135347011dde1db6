use super::*;
use crate::kernels::{Nearest, shear_rows, shift_plane};
use crate::rotate::{RotateOptions, RotationChain, RotationWorkspace};
use ndarray::Array2;

/// A kernel whose every row shift fails, to see that the drivers pass a kernel's error on.
struct Refusing;
struct RefusingRows;

impl RowShifter<f64> for RefusingRows {
    fn shift_row(&mut self, _: &[f64], _: f64, _: &mut [f64]) -> Result<()> {
        Err(Error::parameter("shift", "refused on purpose"))
    }
}

impl ShearKernel<f64> for Refusing {
    fn name(&self) -> String {
        "refusing".into()
    }

    fn support_radius(&self) -> usize {
        1
    }

    fn row_shifter(&self, _: RowGeometry, _: Outside) -> Box<dyn RowShifter<f64> + '_> {
        Box::new(RefusingRows)
    }
}

/// Every driver (row shear, plane shift, one rotation, rotation into a buffer, a chain)
/// returns a kernel's error instead of an image: a failed Haar shift is never swallowed.
#[test]
fn drivers_return_a_kernel_error() {
    let plane = Array2::from_shape_fn((9, 12), |(i, j)| (i * 12 + j) as f64);
    let refused = |r: Result<()>, what: &str| match r {
        Err(Error::InvalidParameter {
            name: "shift",
            reason,
        }) => {
            assert_eq!(reason, "refused on purpose", "{what}")
        }
        other => panic!("{what}: {other:?}"),
    };
    let fill = Outside::Fill(0.0);
    refused(
        shear_rows(plane.view(), 12, &[0.5; 9], &Refusing, fill).map(drop),
        "shear_rows",
    );
    refused(
        shift_plane(plane.view(), 0.5, 0.25, &Refusing, fill).map(drop),
        "shift_plane",
    );
    let options = RotateOptions::default();
    let mut workspace = RotationWorkspace::new();
    refused(
        workspace
            .rotate_plane(plane.view(), 17.0, &Refusing, &options)
            .map(drop),
        "rotate_plane",
    );
    let size = crate::rotate::rotated_size(9, 12, 17.0, &options).unwrap();
    let mut out = Array2::zeros(size);
    refused(
        workspace.rotate_plane_into(plane.view(), 17.0, &Refusing, &options, out.view_mut()),
        "rotate_plane_into",
    );
    let mut chain = RotationChain::new(plane.view(), &Refusing, options).unwrap();
    refused(chain.rotate(17.0).map(drop), "RotationChain::rotate");
}

/// The statement in the module docs, end to end: a chain of rotations with the retained Haar
/// kernel equals nearest neighbour on the 2^h-finer grid, box-averaged at the end.
#[test]
fn retained_haar_rotation_equals_supersampled_nearest() {
    let plane = Array2::from_shape_fn((21, 26), |(i, j)| ((i * 37 + j * 101) % 23) as f64);
    for h in 1..=3u32 {
        let haar = HaarShift::new(h, true).unwrap();
        let mut chain = RotationChain::new(plane.view(), &haar, RotateOptions::default()).unwrap();
        let nn_options = RotateOptions {
            supersample: h,
            ..Default::default()
        };
        let mut reference = RotationChain::new(plane.view(), &Nearest, nn_options).unwrap();
        for deg in [17.3, -31.1, 8.9] {
            chain.rotate(deg).unwrap();
            reference.rotate(deg).unwrap();
        }
        let (a, b) = (chain.finish(), reference.finish());
        let err = a
            .iter()
            .zip(b.iter())
            .map(|(x, y)| (x - y).abs())
            .fold(0.0, f64::max);
        // Measured 0 for h = 1, 2, 3 (integer values, dyadic weights); 1e-12 allows a
        // reordered sum.
        assert!(err < 1e-12, "h={h}: {err}");
    }
}
