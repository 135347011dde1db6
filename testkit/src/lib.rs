//! What the workspace's tests share: [`quadrature`], oracles that tests in several crates
//! integrate against; [`browser`], headless Chromium over the DevTools protocol (the viewer's
//! page tests and frame-rate script); [`fuzz`], the fuzz harnesses' scratch files and corpus replay; and how a test that needs an optional system component (Chromium, Embree, Slurm, node) behaves
//! where that component is missing.
//!
//! On a machine with only Rust, a C toolchain and Python the workspace's tests pass: a test
//! whose component is absent is **skipped**, and says so in one line on the process's standard
//! error, visible in `cargo test`'s default output. libtest captures the `eprintln!` of a
//! passing test, so the line is written through [`std::io::stderr`]'s handle, which it does not
//! capture. Where the environment variable [`REQUIRE`] names the component (a comma-separated
//! list, as `.ci/run` sets: `HAARSHIFT_REQUIRE=chromium,embree,slurm,node`), its absence
//! **fails** the test instead, so that a CI run can never go green by skipping.
//!
//! ```
//! // A component that is present hands its value on.
//! assert_eq!(haarshift_testkit::needs("chromium", Ok::<_, String>(7)), Some(7));
//! ```

pub mod browser;
pub mod fuzz;
pub mod quadrature;

use std::fmt::Display;
use std::io::Write;

/// The environment variable listing the components whose absence fails a test.
pub const REQUIRE: &str = "HAARSHIFT_REQUIRE";

/// Whether [`REQUIRE`] names `component` (its entries trimmed, compared exactly).
///
/// ```
/// assert!(!haarshift_testkit::required("a-component-no-list-names"));
/// ```
pub fn required(component: &str) -> bool {
    std::env::var(REQUIRE).is_ok_and(|list| list.split(',').any(|c| c.trim() == component))
}

/// `found`'s value, or, when the component is missing (`Err(why)`, `why` saying what is
/// missing and how to install it): `None` after one line `skipped: TEST: why` on standard
/// error, or a panic when [`required`]. A test returns at once on `None`.
///
/// ```
/// let missing: Result<(), &str> = Err("no frobnicator on the PATH (apt-get install frob)");
/// assert_eq!(haarshift_testkit::needs("a-component-no-list-names", missing), None);
/// ```
pub fn needs<T, E: Display>(component: &str, found: Result<T, E>) -> Option<T> {
    let why = match found {
        Ok(value) => return Some(value),
        Err(why) => why,
    };
    let thread = std::thread::current();
    let test = thread.name().unwrap_or("a test");
    assert!(
        !required(component),
        "{test}: {component} is required ({REQUIRE}) but missing: {why}"
    );
    // Not eprintln!: libtest would capture it and show nothing for a passing test.
    let _ = writeln!(std::io::stderr(), "skipped: {test}: {why}");
    None
}

#[cfg(test)]
mod tests;

/// Asserts that `result` is an `Err` whose error matches `pattern` and whose message contains
/// every `needle`: the body of each crate's `assert_err!`, which names its error type's
/// variants. A bare `is_err()` passes for any failure, including the wrong check firing first;
/// this names the one the test expects.
///
/// ```
/// let r: Result<(), std::io::Error> = Err(std::io::Error::other("disk full"));
/// haarshift_testkit::assert_err_matches!(r, e if e.kind() == std::io::ErrorKind::Other, "full");
/// ```
#[macro_export]
macro_rules! assert_err_matches {
    ($result:expr, $pattern:pat $(if $guard:expr)? $(, $needle:expr)* $(,)?) => {
        match $result {
            Ok(_) => panic!("expected Err({}), got Ok", stringify!($pattern)),
            Err(e) => {
                assert!(
                    matches!(&e, $pattern $(if $guard)?),
                    "expected {}, got {e:?}",
                    stringify!($pattern)
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
