//! Tree structure: parent sums, the selection rule, the layouts' indices, real data.

use ndarray::{Array2, Axis, s};
use proptest::prelude::{ProptestConfig, prop_assert_eq, proptest};

use super::*;
use crate::transform::{Normalization, pyramid};

#[test]
fn parent_sums_are_block_means() {
    let map = random_faces(600, 6, 16, 3, -1.0, 1.0);
    for selection in [Selection::All, Selection::Largest(200)] {
        let tree =
            HaarTree::<f64, 3>::from_pixels(map.view(), FaceLayout::Stacked, selection).unwrap();
        let pixels = tree.to_pixels().unwrap();
        for (node, pos) in tree.nodes().iter().zip(tree.positions()) {
            let b = 16 >> pos.level;
            let (r, c) = (pos.row as usize * b, pos.col as usize * b);
            let block = pixels.slice(s![pos.face as usize, r..r + b, c..c + b, ..]);
            for ch in 0..3 {
                let mean = block.index_axis(Axis(2), ch).sum() / (b * b) as f64;
                assert!((node.mean[ch] - mean).abs() < 1e-13, "{pos:?} channel {ch}");
            }
        }
    }
}

/// The rule spelled out: sort by |c| descending, ties by index ascending, keep the first K.
fn expected_kept(entries: &mut [(f64, u64)], k: usize) -> Vec<u64> {
    entries.sort_by(|a, b| b.0.abs().total_cmp(&a.0.abs()).then(a.1.cmp(&b.1)));
    let mut kept: Vec<u64> = entries[..k].iter().map(|e| e.1).collect();
    kept.sort();
    kept
}

#[test]
fn side_by_side_selection_follows_the_lat_long_mallat_array() {
    // A 8 x 16 lat-long map with many ties (values from a small set).
    let mut rng = StdRng::seed_from_u64(12);
    let latlong = Array2::from_shape_fn((8, 16), |_| f64::from(rng.random_range(0..3u8)));
    let mallat = pyramid::forward(latlong.view(), 3, Normalization::Orthonormal).unwrap();
    let faces = ndarray::stack(
        Axis(0),
        &[latlong.slice(s![.., ..8]), latlong.slice(s![.., 8..])],
    )
    .unwrap()
    .insert_axis(Axis(3));
    // Every Mallat position but the two scaling coefficients is a detail.
    let mut entries: Vec<(f64, u64)> = mallat
        .indexed_iter()
        .filter(|((i, j), _)| !(*i == 0 && *j < 2))
        .map(|((i, j), v)| (*v, (i * 16 + j) as u64))
        .collect();
    for k in [0, 1, 7, 30, 126] {
        let tree = HaarTree::<f64, 1>::from_pixels(
            faces.view(),
            FaceLayout::SideBySide,
            Selection::Largest(k),
        )
        .unwrap();
        let coeffs = tree.to_coefficients();
        // Back to the H x 2H array: face f's band of level l sits in columns offset by f 2^l.
        let mut got = Vec::new();
        for ((i, j), v) in mallat.indexed_iter() {
            if i == 0 && j < 2 {
                continue;
            }
            let level = (i.max(j / 2)).max(1).ilog2() as usize;
            let (side, wide) = (1usize << level, 2usize << level);
            let (r, band_col) = (i % side, if j >= wide { j - wide } else { j });
            let (face, c) = (band_col / side, band_col % side);
            let (mi, mj) = (
                if i >= side { side + r } else { r },
                if j >= wide || i < side { side + c } else { c },
            );
            let kept = coeffs[[face, mi, mj, 0]];
            if kept != 0.0 {
                assert_eq!(kept, *v, "({i}, {j})");
                got.push((i * 16 + j) as u64);
            }
        }
        let want: Vec<u64> = expected_kept(&mut entries, k)
            .into_iter()
            .filter(|&idx| {
                let (i, j) = ((idx / 16) as usize, (idx % 16) as usize);
                mallat[[i, j]] != 0.0
            })
            .collect();
        assert_eq!(got, want, "K = {k}");
        assert_eq!(tree.kept(), k);
    }
}

#[test]
fn stacked_selection_and_threshold_follow_the_rule() {
    let mut rng = StdRng::seed_from_u64(13);
    let map = Array4::from_shape_fn((6, 4, 4, 1), |_| f64::from(rng.random_range(0..4u8)));
    let full =
        HaarTree::<f64, 1>::from_pixels(map.view(), FaceLayout::Stacked, Selection::All).unwrap();
    let coeffs = full.to_coefficients();
    let mut entries: Vec<(f64, u64)> = coeffs
        .indexed_iter()
        .filter(|((_, i, j, _), _)| (*i, *j) != (0, 0))
        .map(|((f, i, j, _), v)| (*v, (f * 16 + i * 4 + j) as u64))
        .collect();
    let kept_indices = |t: &HaarTree<f64, 1>| -> Vec<u64> {
        let c = t.to_coefficients();
        let mut v: Vec<u64> = c
            .indexed_iter()
            .filter(|((_, i, j, _), v)| (*i, *j) != (0, 0) && **v != 0.0)
            .map(|((f, i, j, _), _)| (f * 16 + i * 4 + j) as u64)
            .collect();
        v.sort();
        v
    };
    for k in [1, 5, 40, 90] {
        let t = full.select(Selection::Largest(k)).unwrap();
        let want: Vec<u64> = expected_kept(&mut entries, k)
            .into_iter()
            .filter(|&idx| coeffs.as_slice().unwrap()[idx as usize] != 0.0)
            .collect();
        assert_eq!(kept_indices(&t), want, "K = {k}");
    }
    let t = full.select(Selection::Threshold(0.75)).unwrap();
    let want: Vec<u64> = entries
        .iter()
        .filter(|e| e.0.abs() > 0.75)
        .map(|e| e.1)
        .collect::<std::collections::BTreeSet<_>>()
        .into_iter()
        .collect();
    assert_eq!(kept_indices(&t), want);
    // Per face: each face keeps its own K.
    let t = full.select(Selection::LargestPerFace(2)).unwrap();
    assert_eq!(t.kept(), 12);
    assert_err!(
        full.select(Selection::Largest(91)),
        InvalidParameter { name: "keep", .. },
        "only 90 details"
    );
    assert_err!(
        full.select(Selection::LargestPerFace(16)),
        InvalidParameter { name: "keep", .. },
        "a face has 15"
    );
    assert_err!(
        full.select(Selection::Threshold(f64::NAN)),
        InvalidParameter {
            name: "threshold",
            ..
        },
        "NaN"
    );
}

#[test]
fn rgb_selection_ranks_by_the_sum_of_squares() {
    // H = (2, 0, 0) is the largest in channel 0 and by the largest channel; V = (1.5, 1.5, 1.5)
    // is the largest by the sum of squares (6.75 > 4), which is the documented rule.
    let mut c = Array4::<f64>::zeros((1, 2, 2, 3));
    c[[0, 0, 1, 0]] = 2.0;
    for ch in 0..3 {
        c[[0, 1, 0, ch]] = 1.5;
    }
    let t =
        HaarTree::<f64, 3>::from_coefficients(c.view(), FaceLayout::Stacked, Selection::Largest(1))
            .unwrap();
    let kept = t.to_coefficients();
    assert_eq!(kept[[0, 1, 0, 2]], 1.5);
    assert_eq!(kept[[0, 0, 1, 0]], 0.0);
}

#[test]
fn bad_inputs_are_errors_not_panics() {
    let ok = Array4::<f64>::zeros((2, 4, 4, 1));
    assert_err!(
        HaarTree::<f64, 1>::from_pixels(
            Array4::zeros((2, 4, 8, 1)).view(),
            FaceLayout::Stacked,
            Selection::All
        ),
        InvalidShape { .. },
        "[2, 4, 8, 1]",
        "S a power of two"
    );
    assert_err!(
        HaarTree::<f64, 1>::from_pixels(
            Array4::zeros((2, 3, 3, 1)).view(),
            FaceLayout::Stacked,
            Selection::All
        ),
        InvalidShape { .. },
        "[2, 3, 3, 1]",
        "S a power of two"
    );
    assert_err!(
        HaarTree::<f64, 3>::from_pixels(ok.view(), FaceLayout::Stacked, Selection::All),
        InvalidShape { .. },
        "(faces >= 1, S, S, 3)"
    );
    assert_err!(
        HaarTree::<f64, 1>::from_pixels(
            Array4::zeros((0, 4, 4, 1)).view(),
            FaceLayout::Stacked,
            Selection::All
        ),
        InvalidShape { .. },
        "[0, 4, 4, 1]",
        "faces >= 1"
    );
    let mut nan = ok.clone();
    nan[[1, 2, 3, 0]] = f64::NAN;
    assert_err!(
        HaarTree::<f64, 1>::from_pixels(nan.view(), FaceLayout::Stacked, Selection::All),
        NonFinite { .. },
        "index [1, 2, 3, 0]"
    );
    assert_err!(
        WeightedPixels::<f64, 1>::new(ok.view(), Array3::zeros((2, 4, 2)).view()),
        InvalidShape { .. },
        "weights must be (2, 4, 4)"
    );
    // A 1x1 face has no details: fine.
    let tiny = HaarTree::<f64, 1>::from_pixels(
        Array4::from_elem((6, 1, 1, 1), 2.0).view(),
        FaceLayout::Stacked,
        Selection::All,
    )
    .unwrap();
    assert_eq!(tiny.kept(), 0);
}

/// The test envmap as two square faces (see testdata/envmaps/SOURCES.md), and per-pixel
/// lat-long solid angles as weights.
fn envmap_faces() -> (Array4<f64>, Array3<f64>) {
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/testdata/envmaps/rooitou_park_256x128.npy"
    );
    let data: ndarray::Array3<f32> = ndarray_npy::read_npy(path).unwrap();
    let h = data.dim().0;
    let faces = Array4::from_shape_fn((2, h, h, 3), |(f, i, j, ch)| {
        f64::from(data[[i, f * h + j, ch]])
    });
    let weights = Array3::from_shape_fn((2, h, h), |(_, i, _)| {
        crate::sphere::latlong::pixel_solid_angle(h, i)
    });
    (faces, weights)
}

#[test]
fn real_envmap_products_equal_the_pixel_sum() {
    let (env, weights) = envmap_faces();
    // Real functions: the map and copies turned by whole columns (same data, other positions).
    let turned = |k: usize| {
        let mut m = env.clone();
        for f in 0..2 {
            for j in 0..128 {
                let src = (f * 128 + j + k) % 256;
                m.slice_mut(s![f, .., j, ..])
                    .assign(&env.slice(s![src / 128, .., src % 128, ..]));
            }
        }
        m / 100.0
    };
    let maps: Vec<_> = [0, 17, 64, 100, 200, 255]
        .iter()
        .map(|&k| turned(k))
        .collect();
    for n in 2..=6 {
        assert_full_integral_is_the_pixel_sum::<3>(
            &weights,
            &maps[..n],
            FaceLayout::SideBySide,
            &format!("envmap, N = {n}"),
        );
    }
    // The constant 1 integrates to 4 pi with these weights.
    let ones = Array4::ones((2, 128, 128, 1));
    let (t, f) = trees_of::<1>(
        &weights,
        &[ones.clone(), ones],
        FaceLayout::SideBySide,
        Selection::All,
    );
    let i = product_integral(&t, &[&f[0]], IntegralOptions::default()).unwrap();
    assert!((i.value[0] - 4.0 * std::f64::consts::PI).abs() < 1e-12);
}

#[test]
fn envmap_error_shrinks_to_zero_as_k_grows() {
    let (env, weights) = envmap_faces();
    let grey = env
        .map_axis(Axis(3), |px| px.sum() / 3.0)
        .insert_axis(Axis(3));
    let maps = [
        grey.clone(),
        grey.mapv(f64::sqrt),
        grey.mapv(|v| 1.0 / (1.0 + v)),
    ];
    let (t, f) = trees_of::<1>(&weights, &maps, FaceLayout::SideBySide, Selection::All);
    let full = product_integral(&t, &[&f[0], &f[1]], IntegralOptions::default())
        .unwrap()
        .value[0];
    let total = 2 * (128 * 128 - 1);
    let mut errors = Vec::new();
    for k in [10, 100, 1000, 10000, total] {
        let sel = Selection::Largest(k);
        let (ts, fs) = (
            t.select(sel).unwrap(),
            [f[0].select(sel).unwrap(), f[1].select(sel).unwrap()],
        );
        let v = product_integral(&ts, &[&fs[0], &fs[1]], IntegralOptions::default())
            .unwrap()
            .value[0];
        errors.push(((v - full) / full).abs());
    }
    assert_eq!(*errors.last().unwrap(), 0.0, "{errors:?}");
    assert!(errors[0] > errors[2] && errors[2] > errors[3], "{errors:?}");
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    /// A tree from sparse coefficients is the tree of the dense array holding them.
    #[test]
    fn a_tree_from_sparse_coefficients_is_the_tree_of_their_dense_array(
        entries in proptest::collection::vec((0u32..3 * 64, -4.0f64..4.0, -4.0f64..4.0), 0..40),
    ) {
        let mut dense = Array4::<f64>::zeros((3, 8, 8, 2));
        let mut seen = std::collections::BTreeMap::new();
        for (i, a, b) in entries {
            seen.insert(i, [a, b]);
        }
        let (indices, values): (Vec<u32>, Vec<[f64; 2]>) = seen.into_iter().unzip();
        for (&i, v) in indices.iter().zip(&values) {
            let i = i as usize;
            for ch in 0..2 {
                dense[[i / 64, (i / 8) % 8, i % 8, ch]] = v[ch];
            }
        }
        let want = HaarTree::<f64, 2>::from_coefficients(
            dense.view(), FaceLayout::Stacked, Selection::Threshold(0.0)).unwrap();
        let got = HaarTree::<f64, 2>::from_sparse(3, 8, FaceLayout::Stacked, &indices, &values)
            .unwrap();
        prop_assert_eq!(got.to_coefficients(), dense);
        prop_assert_eq!(got.nodes(), want.nodes());
        prop_assert_eq!(got.positions(), want.positions());
        prop_assert_eq!(got.kept(), want.kept());
        let (back_i, back_v) = got.sparse_coefficients();
        let nonzero: Vec<(u32, [f64; 2])> = indices.iter().copied().zip(values.iter().copied())
            .filter(|(_, v)| v.iter().any(|x| *x != 0.0)).collect();
        prop_assert_eq!(back_i.into_iter().zip(back_v).collect::<Vec<_>>(), nonzero);
    }
}

#[test]
fn sparse_coefficients_out_of_range_or_not_finite_are_refused() {
    let ok = HaarTree::<f64, 1>::from_sparse(2, 4, FaceLayout::Stacked, &[3], &[[1.0]]);
    assert!(ok.is_ok());
    for (i, v) in [(32u32, 1.0), (3, f64::NAN)] {
        assert_err!(
            HaarTree::<f64, 1>::from_sparse(2, 4, FaceLayout::Stacked, &[i], &[[v]]),
            InvalidParameter {
                name: "coefficients",
                ..
            },
            "one finite value per index below 32"
        );
    }
    assert_err!(
        HaarTree::<f64, 1>::from_sparse(2, 4, FaceLayout::Stacked, &[1, 2], &[[1.0]]),
        InvalidParameter {
            name: "coefficients",
            ..
        },
        "2 indices and 1 values"
    );
    assert_err!(
        HaarTree::<f64, 1>::from_sparse(2, 6, FaceLayout::Stacked, &[], &[]),
        InvalidShape { .. },
        "S a power of two"
    );
}

#[test]
fn kept_coefficients_are_the_trees_non_zero_coefficients() {
    // Every selection on f32 faces with exact zeros among them (as visibility has): the flat
    // list equals the tree's coefficients array scanned for non-zeros, to the bit.
    let map = random_faces(61, 6, 16, 1, -1.0, 1.0)
        .mapv(|x| if x.abs() < 0.3 { 0.0 } else { x as f32 })
        .index_axis_move(Axis(3), 0);
    for layout in [FaceLayout::Stacked, FaceLayout::SideBySide] {
        let faces = if layout == FaceLayout::Stacked { 6 } else { 2 };
        let map = map.slice(s![..faces, .., ..]);
        for selection in [
            Selection::All,
            Selection::Largest(100),
            Selection::LargestPerFace(7),
            Selection::Threshold(0.5),
        ] {
            let (indices, values) =
                crate::product::kept::kept_coefficients(map, layout, selection).unwrap();
            let tree = HaarTree::<f32, 1>::from_pixels(map.insert_axis(Axis(3)), layout, selection)
                .unwrap();
            let flat = tree.to_coefficients();
            let (want_i, want_v): (Vec<u32>, Vec<f32>) = (flat.iter().enumerate())
                .filter(|(_, c)| **c != 0.0)
                .map(|(i, &c)| (i as u32, c))
                .unzip();
            assert_eq!(indices, want_i, "{layout:?} {selection:?}");
            assert_eq!(
                values.iter().map(|v| v.to_bits()).collect::<Vec<_>>(),
                want_v.iter().map(|v| v.to_bits()).collect::<Vec<_>>()
            );
            assert!(
                indices.len() > faces * 4,
                "{selection:?}: {}",
                indices.len()
            );
        }
    }
}
