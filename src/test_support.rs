//! Assertions shared by the unit tests.

/// Asserts that `result` is an `Err` holding the [`crate::Error`] variant `variant { fields }`
/// (a pattern on the fields that say what went wrong, e.g.
/// `InvalidParameter { name: "levels", .. }`) whose message contains every `needle`.
///
/// A bare `is_err()` passes for any failure, including the wrong check firing first; this
/// names the one the test expects.
macro_rules! assert_err {
    ($result:expr, $variant:ident { $($fields:tt)* } $(, $needle:expr)* $(,)?) => {
        match $result {
            Ok(_) => panic!(
                "expected Err({} {{ {} }}), got Ok",
                stringify!($variant),
                stringify!($($fields)*)
            ),
            Err(e) => {
                assert!(
                    matches!(e, $crate::Error::$variant { $($fields)* }),
                    "expected {} {{ {} }}, got {e:?}",
                    stringify!($variant),
                    stringify!($($fields)*)
                );
                let message = e.to_string();
                $(
                    let needle: &str = $needle;
                    assert!(!needle.trim().is_empty(), "an empty needle checks nothing");
                    assert!(message.contains(needle), "{message:?} lacks {needle:?}");
                )*
            }
        }
    };
}

/// The form factor from a differential area to a parallel `a x b` rectangle at distance `h`,
/// one corner of the rectangle straight above the area (Howell's catalogue of configuration
/// factors, B-3): `F = 1/(2 pi) [X/sqrt(1+X^2) atan(Y/sqrt(1+X^2)) + Y/sqrt(1+Y^2)
/// atan(X/sqrt(1+Y^2))]`, `X = a/h`, `Y = b/h`.
pub(crate) fn corner_form_factor(a: f64, b: f64, h: f64) -> f64 {
    let (x, y) = (a / h, b / h);
    let (sx, sy) = ((1.0 + x * x).sqrt(), (1.0 + y * y).sqrt());
    (x / sx * (y / sx).atan() + y / sy * (x / sy).atan()) / (2.0 * std::f64::consts::PI)
}
