//! Oracles that tests in several crates integrate against.

/// A brute-force quadrature of the sphere, independent of any Gauss rule: `(direction,
/// weight)` on composite Boole's rule in `y = cos theta` (`intervals`, a multiple of 4, equal
/// steps; error `O(h^6)` for smooth integrands) times `phis` equally spaced azimuths (exact
/// for trigonometric polynomials of degree below `phis`).
///
/// ```
/// // The sphere's area, 4 pi, to rounding.
/// let area: f64 = haarshift_testkit::quadrature::sphere_grid(8, 6).iter().map(|(_, w)| w).sum();
/// assert!((area - 4.0 * std::f64::consts::PI).abs() < 1e-12);
/// ```
pub fn sphere_grid(intervals: usize, phis: usize) -> Vec<([f64; 3], f64)> {
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
