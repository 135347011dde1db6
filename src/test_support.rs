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

/// A brute-force quadrature of the sphere, independent of any Gauss rule: `(direction,
/// weight)` on composite Boole's rule in `y = cos theta` (`intervals`, a multiple of 4, equal
/// steps; error `O(h^6)` for smooth integrands) times `phis` equally spaced azimuths (exact
/// for trigonometric polynomials of degree below `phis`).
pub(crate) fn sphere_grid(intervals: usize, phis: usize) -> Vec<([f64; 3], f64)> {
    assert!(intervals.is_multiple_of(4));
    let h = 2.0 / intervals as f64;
    let dphi = 2.0 * std::f64::consts::PI / phis as f64;
    let mut out = Vec::with_capacity((intervals + 1) * phis);
    for a in 0..=intervals {
        let boole = match a % 4 {
            _ if a == 0 || a == intervals => 7.0,
            0 => 14.0,
            2 => 12.0,
            _ => 32.0,
        };
        let y = -1.0 + a as f64 * h;
        let s = (1.0 - y * y).max(0.0).sqrt();
        for p in 0..phis {
            let phi = (p as f64 + 0.5) * dphi;
            out.push((
                [s * phi.sin(), y, s * phi.cos()],
                2.0 * h / 45.0 * boole * dphi,
            ));
        }
    }
    out
}

/// How many position and how many normal components of two meshes differ in their bits (all
/// of them when the vertex counts differ): meshes compared exactly, as a hash compares them
/// (`==` on floats holds 0.0 and -0.0 equal), and a failure that says how far apart they are.
pub(crate) fn differing_bits(a: &crate::relight::Mesh, b: &crate::relight::Mesh) -> (usize, usize) {
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
