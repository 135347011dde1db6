//! Assertions shared by the experiments' unit tests.

/// Asserts that `result` is an `Err` holding the error variant `variant { fields }` (`Scene`
/// and `Merl` are the relighting's own; any other names a core [`haarshift::Error`] variant; a
/// core `Result` is converted first) whose message contains every `needle`.
macro_rules! assert_err {
    ($result:expr, $variant:ident { $($fields:tt)* } $(, $needle:expr)* $(,)?) => {
        haarshift_testkit::assert_err_matches!(
            $result.map_err($crate::Error::from),
            $crate::Error::Core(haarshift::Error::$variant { $($fields)* })
            $(, $needle)*
        )
    };
}
