//! Assertions and oracles shared by the relighting's unit tests.
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
/// (`Scene` and `Merl` are the relighting's own; any other names a core
/// [`haarshift::Error`] variant, wrapped in [`crate::Error::Core`]; a core `Result` is converted
/// first) whose message contains every `needle`.
macro_rules! assert_err {
    ($result:expr, Scene { $($fields:tt)* } $(, $needle:expr)* $(,)?) => {
        haarshift_testkit::assert_err_matches!(
            $result.map_err($crate::Error::from),
            $crate::Error::Scene { $($fields)* }
            $(, $needle)*
        )
    };
    ($result:expr, Merl { $($fields:tt)* } $(, $needle:expr)* $(,)?) => {
        haarshift_testkit::assert_err_matches!(
            $result.map_err($crate::Error::from),
            $crate::Error::Merl { $($fields)* }
            $(, $needle)*
        )
    };
    ($result:expr, $variant:ident { $($fields:tt)* } $(, $needle:expr)* $(,)?) => {
        haarshift_testkit::assert_err_matches!(
            $result.map_err($crate::Error::from),
            $crate::Error::Core(haarshift::Error::$variant { $($fields)* })
            $(, $needle)*
        )
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

/// How many position and how many normal components of two meshes differ in their bits (all
/// of them when the vertex counts differ): meshes compared exactly, as a hash compares them
/// (`==` on floats holds 0.0 and -0.0 equal), and a failure that says how far apart they are.
pub(crate) fn differing_bits(a: &crate::Mesh, b: &crate::Mesh) -> (usize, usize) {
    let count = |x: ndarray::ArrayView2<'_, f64>, y: ndarray::ArrayView2<'_, f64>| {
        if x.dim() != y.dim() {
            return x.len().max(y.len());
        }
        x.iter()
            .zip(y)
            .filter(|(p, q)| p.to_bits() != q.to_bits())
            .count()
    };
    (
        count(a.positions(), b.positions()),
        count(a.normals(), b.normals()),
    )
}

/// The lat-long parameterisation of height `n` (`n x 2n` texels).
pub(crate) fn latlong(n: usize) -> haarshift::faces::Parameterization {
    haarshift::faces::Parameterization::new(haarshift::faces::ParamKind::LatLong, n).unwrap()
}

/// The Stanford bunny of `testdata/` on the ground plane.
pub(crate) fn bunny_on_ground() -> crate::Mesh {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../testdata/meshes/bunny.ply");
    let mut mesh = crate::Mesh::load(path.as_ref()).unwrap();
    crate::add_ground_plane(&mut mesh).unwrap();
    mesh
}

/// The box scene of `testdata/scenes`: the bunny in an open box of 16 cells a side, whose floor
/// and walls meet in creases.
pub(crate) fn bunny_in_box() -> crate::Mesh {
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../testdata/scenes/bunny_in_box.json"
    );
    crate::Scene::load(path.as_ref()).unwrap().mesh
}

/// An off-centre, squashed sphere, so that nothing about it is symmetric and its frame has no
/// round numbers.
pub(crate) fn squashed_sphere() -> crate::Mesh {
    crate::Generator::Sphere { cells: 3 }
        .mesh()
        .unwrap()
        .mapped(|p| [1.5 * p[0] + 0.3, p[1], 0.6 * p[2]], |n| n)
        .unwrap()
}
