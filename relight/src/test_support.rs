//! Assertions and oracles shared by the relighting's unit tests.

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
