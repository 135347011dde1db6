//! The Pareto frontier of (cost, error) pairs: the methods no other method beats on both.

/// Indices of the points on the Pareto frontier when both coordinates are to be minimised:
/// point `i` is on it when no other point is at most as large in both coordinates and smaller
/// in one. Returned in increasing order of the first coordinate. Points with a NaN are never
/// on the frontier.
///
/// ```
/// use haarshift_experiments::pareto::frontier;
/// // (seconds, rms): the third is slower and worse than the second.
/// let pts = [(0.01, 16.0), (0.1, 2.4), (0.5, 3.1), (1.0, 0.2)];
/// assert_eq!(frontier(&pts), vec![0, 1, 3]);
/// ```
pub fn frontier(points: &[(f64, f64)]) -> Vec<usize> {
    let mut order: Vec<usize> = (0..points.len())
        .filter(|&i| !points[i].0.is_nan() && !points[i].1.is_nan())
        .collect();
    // Sort by cost, then error: a sweep keeps each point that lowers the best error so far.
    order.sort_by(|&a, &b| {
        points[a]
            .0
            .total_cmp(&points[b].0)
            .then(points[a].1.total_cmp(&points[b].1))
    });
    let mut best = f64::INFINITY;
    let mut kept = Vec::new();
    for i in order {
        if points[i].1 < best {
            best = points[i].1;
            kept.push(i);
        }
    }
    kept
}

#[cfg(test)]
#[path = "pareto_tests.rs"]
mod tests;
