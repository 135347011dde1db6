//! The triple fast paths and the baselines against the general traversal and the pixel sum.

use super::*;
use crate::product::baseline::{pairwise_integral, pixel_integral, pixel_integral_of_trees};
use crate::product::triple::{DenseFaces, DenseTransport, dense_triple_integral, triple_integral};

#[test]
fn triple_paths_equal_the_general_traversal() {
    for selection in [
        Selection::All,
        Selection::Largest(70),
        Selection::LargestPerFace(9),
    ] {
        let maps: Vec<_> = (0..3)
            .map(|k| random_faces(200 + k, 6, 16, 3, -1.0, 1.0))
            .collect();
        let weights = random_weights(4, 6, 16);
        let (t, f) = trees_of::<3>(&weights, &maps, FaceLayout::Stacked, selection);
        let general = product_integral(&t, &[&f[0], &f[1]], IntegralOptions::default()).unwrap();
        let sparse = triple_integral(&t, &f[0], &f[1]).unwrap();
        let dense = dense_triple_integral(
            &DenseTransport::from_transport(&t),
            &DenseFaces::from_tree(&f[0]),
            &DenseFaces::from_tree(&f[1]),
        )
        .unwrap();
        let scale = general.value.map(f64::abs);
        assert_close(
            &sparse.value,
            &general.value,
            &scale,
            1e-12,
            &format!("sparse {selection:?}"),
        );
        assert_close(
            &dense,
            &general.value,
            &scale,
            1e-12,
            &format!("dense {selection:?}"),
        );
        assert_eq!(sparse.visited, general.visited, "{selection:?}");
    }
}

#[test]
fn dense_triple_of_one_channel_uses_the_vector_path() {
    let maps: Vec<_> = (0..3)
        .map(|k| random_faces(300 + k, 6, 32, 1, -1.0, 1.0))
        .collect();
    let weights = random_weights(8, 6, 32);
    let (t, f) = trees_of::<1>(&weights, &maps, FaceLayout::Stacked, Selection::All);
    let dense = dense_triple_integral(
        &DenseTransport::from_transport(&t),
        &DenseFaces::from_tree(&f[0]),
        &DenseFaces::from_tree(&f[1]),
    )
    .unwrap();
    let views: Vec<_> = maps.iter().map(|m| m.view()).collect();
    let (want, scale) = pixel_oracle(&weights, &views);
    assert_close(&dense, &want, &scale, 1e-12, "dense f64");
}

/// The dense path in f32 on full 6 x 64^2 maps (its benchmark size; with a partial last
/// chunk of 16 nodes and several accumulation blocks), one channel and RGB.
fn dense_f32_within_single_precision<const C: usize>() {
    let maps: Vec<_> = (0..3)
        .map(|k| random_faces(500 + k, 6, 64, C, -1.0, 1.0))
        .collect();
    let weights = random_weights(10, 6, 64);
    let single = |a: &Array4<f64>| a.mapv(|v| v as f32);
    let w =
        WeightedPixels::<f32, C>::new(single(&maps[0]).view(), weights.mapv(|v| v as f32).view())
            .unwrap();
    let t = Transport::new(&w, FaceLayout::Stacked, Selection::All).unwrap();
    let tree = |m: &Array4<f64>| {
        HaarTree::<f32, C>::from_pixels(single(m).view(), FaceLayout::Stacked, Selection::All)
            .unwrap()
    };
    let dense = dense_triple_integral(
        &DenseTransport::from_transport(&t),
        &DenseFaces::from_tree(&tree(&maps[1])),
        &DenseFaces::from_tree(&tree(&maps[2])),
    )
    .unwrap();
    let views: Vec<_> = maps.iter().map(|m| m.view()).collect();
    let (want, scale) = pixel_oracle(&weights, &views);
    // f32 rounding of the maps, the transforms and the sums of 1,024 nodes (f64 beyond).
    assert_close(&dense, &want, &scale, 1e-5, "dense f32");
}

#[test]
fn dense_triple_in_f32_equals_the_pixel_sum_to_single_precision() {
    dense_f32_within_single_precision::<1>();
    dense_f32_within_single_precision::<3>();
}

#[test]
fn baselines_equal_the_tree_integral() {
    for n in 2..=5 {
        let maps: Vec<_> = (0..n)
            .map(|k| random_faces(400 + k as u64, 2, 16, 1, -0.5, 1.5))
            .collect();
        let weights = random_weights(9, 2, 16);
        let (t, f) = trees_of::<1>(
            &weights,
            &maps,
            FaceLayout::SideBySide,
            Selection::Largest(100),
        );
        let refs: Vec<_> = f.iter().collect();
        let tree = product_integral(&t, &refs, IntegralOptions::default()).unwrap();
        let pixel = pixel_integral_of_trees(&t, &refs).unwrap();
        let pairwise = pairwise_integral(&t, &refs).unwrap();
        let scale = [pixel.value[0].abs().max(1e-3)];
        assert_close(
            &pixel.value,
            &tree.value,
            &scale,
            1e-12,
            &format!("pixel, N = {n}"),
        );
        assert_close(
            &pairwise.value,
            &tree.value,
            &scale,
            1e-12,
            &format!("pairwise, N = {n}"),
        );
        assert_eq!(pixel.visited, 2 * 16 * 16);
        // From stored pixel maps: the unpruned functions.
        let w = WeightedPixels::<f64, 1>::new(maps[0].view(), weights.view()).unwrap();
        let views: Vec<_> = maps[1..].iter().map(|m| m.view()).collect();
        let stored = pixel_integral(&w, &views).unwrap();
        let all: Vec<_> = maps.iter().map(|m| m.view()).collect();
        let (want, abs) = pixel_oracle(&weights, &all);
        assert_close(
            &stored.value,
            &want,
            &abs,
            1e-12,
            &format!("stored pixels, N = {n}"),
        );
    }
}

#[test]
fn f32_integrals_agree_with_f64_to_single_precision() {
    let maps: Vec<_> = (0..3)
        .map(|k| random_faces(500 + k, 6, 16, 1, 0.0, 1.0))
        .collect();
    let weights = random_weights(10, 6, 16);
    let (t64, f64s) = trees_of::<1>(&weights, &maps, FaceLayout::Stacked, Selection::Largest(80));
    let m32: Vec<_> = maps.iter().map(|m| m.mapv(|v| v as f32)).collect();
    let w32 =
        WeightedPixels::<f32, 1>::new(m32[0].view(), weights.mapv(|v| v as f32).view()).unwrap();
    let t32 = Transport::new(&w32, FaceLayout::Stacked, Selection::Largest(80)).unwrap();
    let f32s: Vec<_> = m32[1..]
        .iter()
        .map(|m| {
            HaarTree::from_pixels(m.view(), FaceLayout::Stacked, Selection::Largest(80)).unwrap()
        })
        .collect();
    let a = product_integral(&t64, &[&f64s[0], &f64s[1]], IntegralOptions::default()).unwrap();
    let b = product_integral(&t32, &[&f32s[0], &f32s[1]], IntegralOptions::default()).unwrap();
    let c = triple_integral(&t32, &f32s[0], &f32s[1]).unwrap();
    assert_close(&b.value, &a.value, &a.value, 1e-5, "f32 general");
    assert_close(&c.value, &a.value, &a.value, 1e-5, "f32 triple");
}
