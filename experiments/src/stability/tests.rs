use super::*;
use crate::test_support::photo;

#[test]
fn panics_and_wrong_answers_fail_and_expected_errors_pass() {
    let r = measure(Category::Size, "panics", 1.0, || panic!("boom"));
    assert!(!r.pass && r.detail.contains("boom"), "{}", r.detail);
    let r = measure(Category::Size, "errs", 1.0, || {
        Err(Error::parameter("x", "bad"))
    });
    assert!(!r.pass && r.detail.contains("unexpected error"));
    assert!(!measure(Category::Size, "big", 1.0, || Ok((2.0, String::new()))).pass);
    assert!(!measure(Category::Size, "nan", 1.0, || Ok((f64::NAN, String::new()))).pass);
    let parameter = |e: &Error| matches!(e, Error::InvalidParameter { .. });
    let r = expect_error(Category::Values, "e", parameter, || {
        Err(Error::parameter("x", "bad"))
    });
    assert!(r.pass && r.figure.is_none());
    assert!(!expect_error(Category::Values, "e", parameter, || Ok("fine".into())).pass);
    let r = expect_error(Category::Values, "e", parameter, || {
        Err(Error::shape(&[1], "no"))
    });
    assert!(!r.pass && r.detail.starts_with("wrong error"));
}

#[test]
fn records_serialise_with_flat_parameters() {
    let r = StabilityRecord::measured(Category::Angle, "a", 0.5, 1.0, "d").with("kernel", "keys");
    let v = serde_json::to_value(&r).unwrap();
    assert_eq!(v["kernel"], "keys");
    assert_eq!(v["category"], "angle");
    assert_eq!(v["pass"], true);
    let report = StabilityReport {
        records: vec![r.clone(), StabilityRecord { pass: false, ..r }],
        drift: vec![],
    };
    assert_eq!(report.failures(), 1);
    assert_err!(
        run_stability(
            &StabilityConfig::new(Array2::zeros((64, 64))),
            &crate::rotation_cycle::NoMeter,
            |_| {}
        ),
        InvalidShape { .. },
        "at least 128x128"
    );
}

/// A kernel that shifts every row `ERROR` samples further than asked: a bug of a thousandth
/// of a pixel.
struct Overshooting<T: Sample>(Box<dyn ShearKernel<T>>);

/// The extra shift of [`Overshooting`], in samples.
const ERROR: f64 = 1e-3;

impl<T: Sample> ShearKernel<T> for Overshooting<T> {
    fn name(&self) -> String {
        self.0.name()
    }

    fn support_radius(&self) -> usize {
        self.0.support_radius() + 1
    }

    fn row_shifter(
        &self,
        geometry: haarshift::kernels::RowGeometry,
        outside: haarshift::kernels::Outside,
    ) -> Box<dyn haarshift::kernels::RowShifter<T> + '_> {
        let wider = haarshift::kernels::RowGeometry {
            max_shift: geometry.max_shift + 1.0,
            ..geometry
        };
        Box::new(OvershootingRows(self.0.row_shifter(wider, outside)))
    }
}

struct OvershootingRows<'a, T: Sample>(Box<dyn haarshift::kernels::RowShifter<T> + 'a>);

impl<T: Sample> haarshift::kernels::RowShifter<T> for OvershootingRows<'_, T> {
    fn shift_row(&mut self, row: &[T], shift: f64, out: &mut [T]) -> haarshift::Result<()> {
        self.0.shift_row(row, shift + ERROR, out)
    }
}

/// The code under test with at most one deliberate fault: kernels that overshoot, or a
/// Haar shift that moves content one sample too far right.
enum Faulty {
    None,
    Kernel,
    Shift,
}

impl Subject for Faulty {
    fn kernel<T: Sample>(
        &self,
        method: ShiftMethod,
        options: &KernelOptions,
    ) -> Result<Box<dyn ShearKernel<T>>> {
        let kernel = Library.kernel(method, options)?;
        Ok(match self {
            Faulty::Kernel => Box::new(Overshooting(kernel)),
            Faulty::None | Faulty::Shift => kernel,
        })
    }

    fn shift_image<T: Sample>(
        &self,
        coeffs: &Coefficients<T>,
        dx: f64,
        dy: f64,
        h: u32,
    ) -> Result<Coefficients<T>> {
        let extra = match self {
            Faulty::None | Faulty::Kernel => 0.0,
            Faulty::Shift => 1.0,
        };
        Library.shift_image(coeffs, dx + extra, dy, h)
    }
}

/// Requires `family` to pass every check on the library and to fail `must_fail` with
/// `fault`.
fn reports(fault: Faulty, must_fail: &str, family: impl Fn(&Faulty) -> Vec<StabilityRecord>) {
    let library = family(&Faulty::None);
    assert!(library.iter().all(|r| r.pass), "{library:?}");
    let failures: Vec<String> = family(&fault)
        .into_iter()
        .filter(|r| !r.pass)
        .map(|r| r.check)
        .collect();
    assert!(
        failures.iter().any(|c| c == must_fail),
        "{must_fail}: {failures:?}"
    );
}

#[test]
fn the_angle_family_reports_a_kernel_that_overshoots() {
    let x = photo(64);
    reports(Faulty::Kernel, "1e-9 deg ~ identity", |s| {
        angle::checks(x.view(), s)
    });
}

#[test]
fn the_size_family_reports_a_wrong_shift() {
    let (x, meter) = (photo(131), &crate::rotation_cycle::NoMeter);
    reports(Faulty::Shift, "haar shift (3, -2)", |s| {
        size::checks(x.view(), meter, s)
    });
}

#[test]
fn the_values_family_reports_a_wrong_kernel_and_a_wrong_shift() {
    let x = photo(64);
    for (fault, must_fail) in [
        (Faulty::Kernel, "impulse centroid rotates"),
        (Faulty::Kernel, "scale 1e0 f64"),
        (Faulty::Shift, "checkerboard: shift by 1 negates"),
        (Faulty::Shift, "scale 1e0 f64"),
    ] {
        reports(fault, must_fail, |s| values::checks(x.view(), s));
    }
}

#[test]
fn the_chain_family_reports_a_wrong_shift() {
    let x = photo(64);
    reports(Faulty::Shift, "whole shifts, 8-bit, average", |s| {
        chain::checks(x.view(), 20, 5, s).0
    });
}

#[test]
fn the_precision_family_reports_a_wrong_shift() {
    let (x, meter) = (photo(32), &crate::rotation_cycle::NoMeter);
    reports(Faulty::Shift, "compact h=3", |s| {
        precision::checks(x.view(), meter, s)
    });
}
