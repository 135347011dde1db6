//! Lat-long test maps for the `sphere` commands: deterministic pseudo-random maps written as
//! files, and the pruned-map oracle of the selection rule.

use std::path::{Path, PathBuf};

use haarshift::io::{WriteOptions, write_image};
use haarshift::transform::{Normalization, pyramid};
use haarshift::{Channels, PlanarImage, SampleDepth};
use ndarray::{Array2, Array3};

/// A deterministic pseudo-random positive `(channels, h, 2h)` map, values in `[0.1, 1.1)`.
pub fn planes(h: usize, channels: usize, seed: u64) -> Array3<f64> {
    let mut x = seed;
    Array3::from_shape_fn((channels, h, 2 * h), |_| {
        x = x
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        0.1 + (x >> 11) as f64 / (1u64 << 53) as f64
    })
}

/// Writes `planes` (1 or 3 channels) as `name` in `dir` at `depth` (the extension picks the
/// format); returns the path.
pub fn write_map(dir: &Path, name: &str, planes: &Array3<f64>, depth: SampleDepth) -> PathBuf {
    let channels = if planes.dim().0 == 1 {
        Channels::Gray
    } else {
        Channels::Rgb
    };
    let image = PlanarImage::new(planes.clone(), channels, depth).unwrap();
    let path = dir.join(name);
    write_image(&image, &path, WriteOptions::default()).unwrap();
    path
}

/// A one-channel `h x 2h` plane reconstructed from its `k` largest orthonormal detail
/// coefficients and its two scaling coefficients: sort by `|c|` descending, ties by row-major
/// index in the `h x 2h` Mallat array ascending.
pub fn pruned(plane: &Array2<f64>, k: usize) -> Array2<f64> {
    let levels = plane.dim().0.trailing_zeros() as usize;
    let c = pyramid::forward(plane.view(), levels, Normalization::Orthonormal).unwrap();
    let w = c.dim().1;
    let mut order: Vec<usize> = (0..c.len()).filter(|&i| i != 0 && i != 1).collect();
    order.sort_by(|&a, &b| {
        let (va, vb) = (c[[a / w, a % w]].abs(), c[[b / w, b % w]].abs());
        vb.total_cmp(&va).then(a.cmp(&b))
    });
    let mut kept = Array2::zeros(c.dim());
    for &i in order.iter().take(k).chain([0, 1].iter()) {
        kept[[i / w, i % w]] = c[[i / w, i % w]];
    }
    pyramid::inverse(kept.view(), levels, Normalization::Orthonormal).unwrap()
}
