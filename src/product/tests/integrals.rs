//! Product integrals and products against the pixel-domain oracle.

use super::*;
use crate::product::multiply::{product, weighted_product};

const ALL: IntegralOptions = IntegralOptions { finest_level: None };

#[test]
fn full_trees_equal_the_pixel_sum_for_n_2_to_6() {
    for (faces, s, layout) in [(6, 8, FaceLayout::Stacked), (2, 16, FaceLayout::SideBySide)] {
        for n in 2..=6 {
            let maps: Vec<_> = (0..n)
                .map(|k| random_faces(100 * n as u64 + k as u64, faces, s, 1, -1.0, 2.0))
                .collect();
            let weights = random_weights(7, faces, s);
            assert_full_integral_is_the_pixel_sum::<1>(
                &weights,
                &maps,
                layout,
                &format!("N = {n}, {faces} x {s}^2"),
            );
        }
    }
}

#[test]
fn rgb_integral_is_three_one_channel_integrals() {
    let maps: Vec<_> = (0..3)
        .map(|k| random_faces(40 + k, 6, 8, 3, 0.0, 1.0))
        .collect();
    let weights = random_weights(3, 6, 8);
    let (t, f) = trees_of::<3>(&weights, &maps, FaceLayout::Stacked, Selection::Largest(50));
    let refs: Vec<_> = f.iter().collect();
    let rgb = product_integral(&t, &refs, ALL).unwrap();
    // The selection is shared (sum of squares), so the pruned RGB functions are the oracle.
    let pruned: Vec<_> = std::iter::once(t.tree().to_pixels().unwrap())
        .chain(f.iter().map(|x| x.to_pixels().unwrap()))
        .collect();
    let views: Vec<_> = pruned.iter().map(|m| m.view()).collect();
    let (want, scale) = pixel_oracle(&Array3::ones((6, 8, 8)), &views);
    assert_close(&rgb.value, &want, &scale, 1e-12, "rgb");
}

#[test]
fn pruned_trees_equal_the_pixel_sum_of_the_pruned_functions() {
    for selection in [
        Selection::Largest(40),
        Selection::LargestPerFace(5),
        Selection::Threshold(0.3),
    ] {
        let maps: Vec<_> = (0..4)
            .map(|k| random_faces(10 + k, 6, 16, 1, -1.0, 1.0))
            .collect();
        let weights = random_weights(11, 6, 16);
        let (t, f) = trees_of::<1>(&weights, &maps, FaceLayout::Stacked, selection);
        let refs: Vec<_> = f.iter().collect();
        let got = product_integral(&t, &refs, ALL).unwrap();
        let pruned: Vec<_> = std::iter::once(t.tree().to_pixels().unwrap())
            .chain(f.iter().map(|x| x.to_pixels().unwrap()))
            .collect();
        let views: Vec<_> = pruned.iter().map(|m| m.view()).collect();
        let (want, scale) = pixel_oracle(&Array3::ones((6, 16, 16)), &views);
        assert_close(&got.value, &want, &scale, 1e-12, &format!("{selection:?}"));
        // And pruning changed the answer (the test can tell the functions apart).
        let full_views: Vec<_> = maps.iter().map(|m| m.view()).collect();
        let (full, _) = pixel_oracle(&weights, &full_views);
        assert!((full[0] - want[0]).abs() > 1e-6 * scale[0], "{selection:?}");
    }
}

/// Block means of side `b` of every face, broadcast back to pixels.
fn averaged(map: &Array4<f64>, b: usize) -> Array4<f64> {
    let (faces, s, _, c) = map.dim();
    let mut out = map.clone();
    for f in 0..faces {
        for bi in 0..s / b {
            for bj in 0..s / b {
                for ch in 0..c {
                    let block = map.slice(ndarray::s![
                        f,
                        bi * b..(bi + 1) * b,
                        bj * b..(bj + 1) * b,
                        ch
                    ]);
                    let mean = block.sum() / (b * b) as f64;
                    out.slice_mut(ndarray::s![
                        f,
                        bi * b..(bi + 1) * b,
                        bj * b..(bj + 1) * b,
                        ch
                    ])
                    .fill(mean);
                }
            }
        }
    }
    out
}

#[test]
fn depth_limit_equals_the_integral_of_block_averages() {
    let maps: Vec<_> = (0..3)
        .map(|k| random_faces(70 + k, 2, 16, 1, -1.0, 2.0))
        .collect();
    let ones = Array3::ones((2, 16, 16));
    let (t, f) = trees_of::<1>(&ones, &maps, FaceLayout::SideBySide, Selection::All);
    let refs: Vec<_> = f.iter().collect();
    for level in 0..4 {
        let got = product_integral(
            &t,
            &refs,
            IntegralOptions {
                finest_level: Some(level),
            },
        )
        .unwrap();
        let avg: Vec<_> = maps
            .iter()
            .map(|m| averaged(m, 16 >> (level + 1)))
            .collect();
        let views: Vec<_> = avg.iter().map(|m| m.view()).collect();
        let (want, scale) = pixel_oracle(&ones, &views);
        assert_close(&got.value, &want, &scale, 1e-12, &format!("level {level}"));
    }
    let err = product_integral(
        &t,
        &refs,
        IntegralOptions {
            finest_level: Some(4),
        },
    )
    .unwrap_err();
    assert!(err.to_string().contains("detail level 4"), "{err}");
}

#[test]
fn product_tree_inverts_to_the_pointwise_product() {
    for selection in [Selection::All, Selection::Largest(30)] {
        let maps: Vec<_> = (0..3)
            .map(|k| random_faces(90 + k, 6, 8, 3, -1.0, 1.0))
            .collect();
        let trees: Vec<HaarTree<f64, 3>> = maps
            .iter()
            .map(|m| HaarTree::from_pixels(m.view(), FaceLayout::Stacked, selection).unwrap())
            .collect();
        let refs: Vec<_> = trees.iter().collect();
        let got = product(&refs).unwrap().to_pixels().unwrap();
        let mut want = trees[0].to_pixels().unwrap();
        for t in &trees[1..] {
            want *= &t.to_pixels().unwrap();
        }
        let worst = got
            .iter()
            .zip(&want)
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max);
        assert!(worst < 1e-13, "{selection:?}: worst pixel error {worst:e}");
    }
}

#[test]
fn weighted_product_then_integral_equals_the_direct_integral() {
    let maps: Vec<_> = (0..4)
        .map(|k| random_faces(30 + k, 6, 8, 1, 0.0, 1.0))
        .collect();
    let weights = random_weights(5, 6, 8);
    let (t, f) = trees_of::<1>(&weights, &maps, FaceLayout::Stacked, Selection::Largest(60));
    let direct = product_integral(&t, &[&f[0], &f[1], &f[2]], ALL).unwrap();
    let jrt = weighted_product(&t, &[&f[0], &f[1]]).unwrap();
    let reused = product_integral(&jrt, &[&f[2]], ALL).unwrap();
    assert_close(&reused.value, &direct.value, &direct.value, 1e-12, "JRT");
}

#[test]
fn mismatched_trees_are_an_error() {
    let ones = Array3::ones((6, 8, 8));
    let (t, _) = trees_of::<1>(
        &ones,
        &[random_faces(1, 6, 8, 1, 0.0, 1.0)],
        FaceLayout::Stacked,
        Selection::All,
    );
    let other = HaarTree::<f64, 1>::from_pixels(
        random_faces(2, 6, 4, 1, 0.0, 1.0).view(),
        FaceLayout::Stacked,
        Selection::All,
    )
    .unwrap();
    assert_err!(
        product_integral(&t, &[&other], ALL),
        InvalidShape { .. },
        "different faces"
    );
    assert_err!(
        product(&[t.tree(), &other]),
        InvalidShape { .. },
        "different faces"
    );
}
