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
