//! Assertions shared by the unit tests.
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

/// The parameterisation of `kind` at `size`.
pub(crate) fn param(kind: crate::faces::ParamKind, size: usize) -> crate::faces::Parameterization {
    crate::faces::Parameterization::new(kind, size).unwrap()
}

/// The spherical rotation's options with `method` at `level` (the finest when `None`).
pub(crate) fn sphere_options(
    method: crate::sphere::Method,
    level: Option<usize>,
) -> crate::sphere::SphereOptions {
    crate::sphere::SphereOptions {
        method,
        level,
        ..Default::default()
    }
}
