//! Agreement with PyWavelets: `wavedec2(x, 'haar', mode='periodization', level=K)`, arrays
//! generated once by `scripts/pywt_reference.py` and committed in `testdata/pywt/`.
//!
//! Band mapping (measured on PyWavelets 1.8, documented in the script): cA = A, cH = b,
//! cV = a, cD = c in the orthonormal normalisation, same signs. In the `average`
//! normalisation every band is the orthonormal one divided by 2 per level step: the scaling
//! block by 2^K, a detail band `j` steps above the pixels by 2^j.

use std::path::PathBuf;

use crate::BoundaryMode;
use crate::transform::{
    Band, Coefficients, Layout, Levels, Normalization, TransformInfo, TransformSpec,
};
use ndarray::Array2;
use ndarray_npy::read_npy;

/// (input, reference array, levels) for every case in testdata/pywt.
fn cases() -> Vec<(String, Array2<f64>, Array2<f64>, usize)> {
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("testdata/pywt");
    let mut cases = Vec::new();
    for entry in std::fs::read_dir(&dir).expect("testdata/pywt exists") {
        let path = entry.unwrap().path();
        let name = path.file_name().unwrap().to_string_lossy().into_owned();
        let Some(stem) = name.strip_suffix("_pywt.npy") else {
            continue;
        };
        let (case, levels) = stem
            .rsplit_once("_levels")
            .expect("file name carries the level count");
        let input: Array2<f64> = read_npy(dir.join(format!("{case}_input.npy"))).unwrap();
        let reference: Array2<f64> = read_npy(&path).unwrap();
        cases.push((case.to_owned(), input, reference, levels.parse().unwrap()));
    }
    assert_eq!(cases.len(), 4, "every generated case is present");
    cases
}

fn spec(normalization: Normalization, levels: usize) -> TransformSpec {
    TransformSpec {
        layout: Layout::Pyramid,
        normalization,
        levels: Levels::Count(levels),
        padding: BoundaryMode::Zero,
    }
}

#[test]
fn orthonormal_pyramid_equals_pywavelets() {
    for (case, input, reference, levels) in cases() {
        let ours = spec(Normalization::Orthonormal, levels)
            .forward(input.view())
            .unwrap();
        let scale = reference.iter().fold(1.0f64, |m, v| m.max(v.abs()));
        let err = ours
            .as_array()
            .iter()
            .zip(reference.iter())
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max);
        assert!(err <= 1e-12 * scale, "{case}: max difference {err}");
    }
}

#[test]
fn average_pyramid_equals_pywavelets_scaled_per_level() {
    for (case, input, reference, levels) in cases() {
        let ours = spec(Normalization::Average, levels)
            .forward(input.view())
            .unwrap();
        let info = TransformInfo {
            normalization: Normalization::Orthonormal,
            ..*ours.info()
        };
        let reference = Coefficients::from_parts(reference, info).unwrap();
        let compare = |band: Band, level: usize, steps_above_pixels: usize| {
            let factor = 0.5f64.powi(steps_above_pixels as i32);
            let (a, b) = (
                ours.band(band, level).unwrap(),
                reference.band(band, level).unwrap(),
            );
            let err = a
                .iter()
                .zip(b.iter())
                .map(|(x, y)| (x - factor * y).abs())
                .fold(0.0, f64::max);
            assert!(err < 1e-11, "{case} {band:?} level {level}: {err}");
        };
        compare(Band::Scaling, 0, levels);
        for level in 0..levels {
            for band in [Band::Horizontal, Band::Vertical, Band::Diagonal] {
                compare(band, level, levels - level);
            }
        }
    }
}
