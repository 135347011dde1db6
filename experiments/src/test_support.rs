//! Assertions shared by the experiments' unit tests.
//!
//! Where tests live (one rule for the workspace): never inline. The unit tests of `x.rs` are in
//! the sibling file `x_tests.rs`, declared at the end of `x.rs` as
//! `#[cfg(test)] #[path = "x_tests.rs"] mod tests;`; those of a folder module `x/mod.rs` (or of
//! the crate root) are in `x/tests.rs` (`#[cfg(test)] mod tests;`), a folder `x/tests/` when
//! they are many. A second set of tests of one module is a second such file, named for its
//! topic (`x_topic_tests.rs`, or `x/topic_tests.rs` in a folder module). A helper that more
//! than one test file needs is written once, in this file (the CLI's integration tests:
//! `cli/tests/cli/common/`), or is the library's own function; no two test helpers of a crate
//! share a name (`python3 scripts/test_helper_names.py` checks it).

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

/// 8-bit values, irregular, `side x side`: a stand-in for a photograph.
pub(crate) fn photo(side: usize) -> ndarray::Array2<f64> {
    ndarray::Array2::from_shape_fn((side, side), |(i, j)| {
        ((i * 37 + j * j * 11 + i * j) % 256) as f64
    })
}
