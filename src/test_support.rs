//! Assertions shared by the unit tests.

/// Asserts that `result` is an `Err` holding the [`crate::Error`] variant `variant { fields }`
/// (a pattern on the fields that say what went wrong, e.g.
/// `InvalidParameter { name: "levels", .. }`) whose message contains every `needle`.
macro_rules! assert_err {
    ($result:expr, $variant:ident { $($fields:tt)* } $(, $needle:expr)* $(,)?) => {
        haarshift_testkit::assert_err_matches!(
            $result,
            $crate::Error::$variant { $($fields)* }
            $(, $needle)*
        )
    };
}
