use super::*;
use std::f64::consts::PI;

/// A lumpy positive map with a bright cap at the north pole (the first `cap` rows).
pub(crate) fn bright_pole(h: usize, cap: usize) -> LatLongMap<f64> {
    let data = Array3::from_shape_fn((h, 2 * h, 2), |(i, j, c)| {
        let base = 1.0 + 0.3 * ((i * 7 + j * 3 + c) % 5) as f64;
        if i < cap { 1000.0 * base } else { base }
    });
    LatLongMap::new(data).unwrap()
}

pub(crate) fn relative_energy_change(a: &LatLongMap<f64>, b: &LatLongMap<f64>) -> f64 {
    a.energy()
        .iter()
        .zip(b.energy())
        .map(|(x, y)| (x - y).abs() / x.abs())
        .fold(0.0, f64::max)
}

#[test]
fn the_weighted_downsample_keeps_the_energy_and_the_plain_mean_does_not() {
    for (h, n) in [(64, 8), (64, 32), (48, 20), (37, 5), (64, 1)] {
        let f = bright_pole(h, 3);
        let g = downsample_solid_angle(&f, n).unwrap();
        let change = relative_energy_change(&f, &g);
        assert!(change < 1e-12, "{h} -> {n}: {change:e}");
    }
    // The plain block mean weighs the pole's texels like the equator's.
    let f = bright_pole(64, 3);
    let plain = relative_energy_change(&f, &f.downsample(8).unwrap());
    assert!(plain > 0.1, "the plain mean moved only {plain:e}");
}

#[test]
fn a_constant_stays_constant() {
    for (h, n) in [(32, 8), (30, 7), (16, 16)] {
        let f =
            LatLongMap::<f32>::from_fn(h, 3, |_, o| o.copy_from_slice(&[0.25, 2.0, 7.5])).unwrap();
        let g = downsample_solid_angle(&f, n).unwrap();
        for px in g.as_array().as_slice().unwrap().chunks_exact(3) {
            for (v, want) in px.iter().zip([0.25, 2.0, 7.5]) {
                assert!((v - want).abs() < 1e-6 * want, "{h} -> {n}: {v}");
            }
        }
    }
}

/// The oracle: cut the sphere into the common refinement of both grids (cells of
/// `pi / (h n)` in theta and `pi / (h n)` in phi), each cell in one source texel and one
/// target texel, with its exact solid angle; sum value x solid angle per target texel.
#[test]
fn overlaps_match_the_common_refinement() {
    let (h, n) = (6, 4);
    let f =
        LatLongMap::<f64>::from_fn(h, 1, |d, o| o[0] = (d[0] + 2.0 * d[1] - d[2]).exp()).unwrap();
    let g = downsample_solid_angle(&f, n).unwrap();
    let cell = PI / (h * n) as f64;
    let mut sum = Array2::<f64>::zeros((n, 2 * n));
    let mut area = Array2::<f64>::zeros((n, 2 * n));
    for a in 0..h * n {
        let band = (a as f64 * cell).cos() - ((a + 1) as f64 * cell).cos();
        for b in 0..2 * h * n {
            let omega = band * cell;
            let (si, sj) = (a / n, b / n);
            let (ti, tj) = (a / h, b / h);
            sum[[ti, tj]] += omega * f.as_array()[[si, sj, 0]];
            area[[ti, tj]] += omega;
        }
    }
    for ((i, j), s) in sum.indexed_iter() {
        let want = s / area[[i, j]];
        let got = g.as_array()[[i, j, 0]];
        assert!(
            (got - want).abs() < 1e-13 * want,
            "({i}, {j}): {got} vs {want}"
        );
    }
}

#[test]
fn bad_resolutions_are_errors() {
    let f = bright_pole(8, 1);
    assert_err!(
        downsample_solid_angle(&f, 0),
        InvalidParameter {
            name: "resolution",
            ..
        },
        "0: the working height"
    );
    assert_err!(
        downsample_solid_angle(&f, 9),
        InvalidParameter {
            name: "resolution",
            ..
        },
        "9: the working height"
    );
}
