use super::*;
use std::f64::consts::PI;

/// `int dA / (1 + a^2 + b^2)^(3/2)` over a rectangle by the composite midpoint rule with
/// `n x n` cells, Richardson-extrapolated from `n` and `2 n` (error `O(n^-4)`): an
/// integration that knows nothing of the closed form.
fn quadrature(a0: f64, a1: f64, b0: f64, b1: f64, n: usize) -> f64 {
    let midpoint = |n: usize| {
        let (da, db) = ((a1 - a0) / n as f64, (b1 - b0) / n as f64);
        let mut sum = 0.0;
        for i in 0..n {
            let b = b0 + (i as f64 + 0.5) * db;
            for j in 0..n {
                let a = a0 + (j as f64 + 0.5) * da;
                sum += (1.0 + a * a + b * b).powf(-1.5);
            }
        }
        sum * da * db
    };
    (4.0 * midpoint(2 * n) - midpoint(n)) / 3.0
}

#[test]
fn solid_angles_sum_to_four_pi() {
    for size in [1, 2, 3, 8, 64, 256] {
        let total: f64 = (0..6)
            .map(|_| {
                (0..size)
                    .flat_map(|r| (0..size).map(move |c| texel_solid_angle(size, r, c)))
                    .sum::<f64>()
            })
            .sum();
        assert!((total - 4.0 * PI).abs() < 1e-12, "{size}: {total}");
    }
}

#[test]
fn solid_angles_equal_brute_force_quadrature() {
    for size in [1, 2, 4, 8] {
        for r in 0..size {
            for c in 0..size {
                let (a0, a1) = (edge(size, c as f64), edge(size, c as f64 + 1.0));
                let (b0, b1) = (edge(size, r as f64), edge(size, r as f64 + 1.0));
                let want = quadrature(a0, a1, b0, b1, 64);
                let got = texel_solid_angle(size, r, c);
                assert!(
                    (got - want).abs() < 1e-10 * want,
                    "{size} ({r}, {c}): {got} vs {want}"
                );
            }
        }
    }
}

#[test]
fn solid_angles_equal_a_monte_carlo_count_of_directions() {
    // Independent of the face parametrisation: directions spread uniformly over the
    // sphere (a Fibonacci lattice), binned by texel_of, count in proportion to the
    // texels' solid angles.
    let (size, n) = (4, 400_000);
    let mut counts = vec![0usize; 6 * size * size];
    let golden = PI * (3.0 - 5f64.sqrt());
    for k in 0..n {
        let y = 1.0 - (k as f64 + 0.5) * 2.0 / n as f64;
        let r = (1.0 - y * y).sqrt();
        let phi = k as f64 * golden;
        let (f, row, col) = texel_of(size, [r * phi.sin(), y, r * phi.cos()]);
        counts[(f * size + row) * size + col] += 1;
    }
    for (i, &count) in counts.iter().enumerate() {
        let (row, col) = ((i / size) % size, i % size);
        let want = texel_solid_angle(size, row, col) / (4.0 * PI) * n as f64;
        assert!(
            (count as f64 - want).abs() < 0.01 * want,
            "{i}: {count} vs {want}"
        );
    }
}

#[test]
fn directions_round_trip_through_texels() {
    for size in [1, 2, 5, 16] {
        for face in 0..6 {
            for r in 0..size {
                for c in 0..size {
                    let d = texel_direction(size, face, r, c);
                    let norm = d.iter().map(|v| v * v).sum::<f64>().sqrt();
                    assert!((norm - 1.0).abs() < 1e-15);
                    assert_eq!(texel_of(size, d), (face, r, c));
                    let (f, a, b) = face_point(d);
                    assert_eq!(f, face);
                    assert!((a - edge(size, c as f64 + 0.5)).abs() < 1e-14);
                    assert!((b - edge(size, r as f64 + 0.5)).abs() < 1e-14);
                }
            }
        }
    }
}

#[test]
fn faces_meet_along_shared_edges_and_match_the_lat_long_azimuth() {
    use crate::sphere::latlong::{angles, direction};
    let close = |p: [f64; 3], q: [f64; 3]| p.iter().zip(q).all(|(x, y)| (x - y).abs() < 1e-15);
    // Side faces in phi order +Z, +X, -Z, -X: each face's right edge is the next one's
    // left edge, rows aligned.
    let ring = [4, 0, 5, 1];
    for k in 0..4 {
        let (f, g) = (ring[k], ring[(k + 1) % 4]);
        for b in [-1.0, -0.3, 0.0, 0.7, 1.0] {
            assert!(close(face_direction(f, 1.0, b), face_direction(g, -1.0, b)));
        }
    }
    for a in [-1.0, -0.2, 0.5, 1.0] {
        // +Y's last row is +Z's first row; -Y's first row is +Z's last row.
        assert!(close(face_direction(2, a, 1.0), face_direction(4, a, -1.0)));
        assert!(close(face_direction(3, a, -1.0), face_direction(4, a, 1.0)));
    }
    // Along a side face's centre row, phi increases with the column, as in lat-long.
    for &f in &ring {
        let phis: Vec<f64> = [-0.9, -0.3, 0.3, 0.9]
            .iter()
            .map(|&a| angles(face_direction(f, a, 0.0)).1)
            .map(|p| (p - angles(face_direction(f, 0.0, 0.0)).1 + PI).rem_euclid(2.0 * PI))
            .collect();
        assert!(phis.windows(2).all(|w| w[0] < w[1]), "{f}: {phis:?}");
        // and the row runs downwards
        assert!(face_direction(f, 0.0, 0.5)[1] < 0.0);
    }
    // The +Z face's centre is the lat-long direction theta = 90, phi = 0.
    assert!(close(face_direction(4, 0.0, 0.0), direction(PI / 2.0, 0.0)));
    // Right-handed world: +X cross +Y = +Z.
    let [x, y] = [CubeFace::PosX.axes()[0], CubeFace::PosY.axes()[0]];
    let cross = [
        x[1] * y[2] - x[2] * y[1],
        x[2] * y[0] - x[0] * y[2],
        x[0] * y[1] - x[1] * y[0],
    ];
    assert_eq!(cross, CubeFace::PosZ.axes()[0]);
}
