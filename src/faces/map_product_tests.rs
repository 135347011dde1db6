use super::*;
use crate::faces::convert::{convert, default_samples};
use crate::faces::param::Parameterization;
use crate::product::{FaceLayout, HaarTree};
use crate::transform::{Normalization, pyramid};
use ndarray::{Array3, Axis};

fn map<T: Sample>(h: usize, channels: usize, seed: u64) -> LatLongMap<T> {
    let mut x = seed;
    LatLongMap::new(Array3::from_shape_fn((h, 2 * h, channels), |_| {
        x = x
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        T::from_f64(0.1 + (x >> 11) as f64 / (1u64 << 53) as f64)
    }))
    .unwrap()
}

fn max_relative(got: &[f64], want: &[f64]) -> f64 {
    assert_eq!(got.len(), want.len());
    got.iter()
        .zip(want)
        .map(|(g, w)| ((g - w) / w).abs())
        .fold(0.0, f64::max)
}

#[test]
fn the_product_map_is_the_pointwise_product_in_f64_and_f32() {
    let maps = [map::<f64>(16, 3, 1), map(16, 1, 2), map(16, 3, 3)];
    let want: Vec<f64> = Array3::from_shape_fn((16, 32, 3), |(i, j, c)| {
        maps.iter()
            .map(|m| m.as_array()[[i, j, c.min(m.channels() - 1)]])
            .product()
    })
    .into_iter()
    .collect();
    /// The product's lat-long pixels, in f64.
    fn pixels<T: Sample>(maps: &[LatLongMap<T>]) -> Vec<f64> {
        let got = map_product(maps, &ProductOptions::default()).unwrap();
        assert_eq!(got.kept, vec![16 * 32 - 2; 3]);
        let map = got.map.to_lat_long().unwrap();
        map.as_array().iter().map(|v| v.as_f64()).collect()
    }
    assert!(max_relative(&pixels(&maps), &want) < 1e-13);
    let single: Vec<LatLongMap<f32>> = maps
        .iter()
        .map(|m| LatLongMap::new(m.as_array().mapv(|v| v as f32)).unwrap())
        .collect();
    let err = max_relative(&pixels(&single), &want);
    assert!(err < 2e-5 && err > 0.0, "{err}");
}

#[test]
fn coefficients_are_the_orthonormal_pyramids_of_the_product_faces() {
    let maps = [map::<f64>(8, 1, 4), map(8, 1, 5)];
    let got = map_product(&maps, &ProductOptions::default()).unwrap();
    let faces = got.map.as_array();
    for f in 0..2 {
        let plane = faces
            .index_axis(Axis(0), f)
            .index_axis(Axis(2), 0)
            .to_owned();
        let want = pyramid::forward(plane.view(), 3, Normalization::Orthonormal).unwrap();
        let have = got
            .coefficients
            .index_axis(Axis(0), f)
            .index_axis(Axis(2), 0)
            .to_owned();
        assert!(
            have.iter()
                .zip(want.iter())
                .all(|(a, b)| (a - b).abs() < 1e-12)
        );
    }
}

#[test]
fn with_k_kept_it_is_the_product_of_the_pruned_maps() {
    // The selection rule itself is tested in `product::tests`; here the pruned maps are
    // the pixels of each map's own pruned tree, multiplied pixel by pixel.
    let maps = [map::<f64>(16, 1, 6), map::<f64>(16, 1, 7)];
    let k = 37;
    let pruned: Vec<Array4<f64>> = maps
        .iter()
        .map(|m| {
            let faces = SphereMap::from_lat_long(m).unwrap().into_array();
            HaarTree::<f64, 1>::from_pixels(
                faces.view(),
                FaceLayout::SideBySide,
                Selection::Largest(k),
            )
            .unwrap()
            .to_pixels()
            .unwrap()
        })
        .collect();
    let want = &pruned[0] * &pruned[1];
    let o = ProductOptions {
        selections: vec![Selection::Largest(k)],
        ..Default::default()
    };
    let got = map_product(&maps, &o).unwrap();
    assert_eq!(got.kept, vec![k, k]);
    let err = got
        .map
        .as_array()
        .iter()
        .zip(want.iter())
        .map(|(a, b)| (a - b).abs())
        .fold(0.0, f64::max);
    assert!(err < 1e-12, "{err}");
    let full = map_product(&maps, &ProductOptions::default()).unwrap();
    assert!(
        max_relative(
            &got.map.as_array().iter().copied().collect::<Vec<_>>(),
            &full.map.as_array().iter().copied().collect::<Vec<_>>()
        ) > 1e-3
    );
}

#[test]
fn in_the_cube_it_is_the_product_of_the_converted_maps() {
    let maps = [map::<f64>(16, 3, 8), map(16, 1, 9)];
    let o = ProductOptions {
        param: ParamKind::Cube,
        ..Default::default()
    };
    let got = map_product(&maps, &o).unwrap();
    let (ll, cube) = (
        Parameterization::new(ParamKind::LatLong, 16).unwrap(),
        Parameterization::new(ParamKind::Cube, 8).unwrap(),
    );
    assert_eq!(got.map.param(), cube);
    let converted: Vec<_> = maps
        .iter()
        .map(|m| {
            let s = SphereMap::from_lat_long(m).unwrap();
            convert(&s, cube, default_samples(ll, cube))
                .unwrap()
                .into_array()
        })
        .collect();
    let want = &converted[0] * &converted[1];
    let err = got
        .map
        .as_array()
        .iter()
        .zip(want.iter())
        .map(|(a, b)| (a - b).abs() / b)
        .fold(0.0, f64::max);
    assert!(err < 1e-13, "{err}");
}

#[test]
fn bad_requests_are_errors() {
    let (a, b) = (map::<f64>(16, 1, 10), map::<f64>(8, 1, 11));
    let d = ProductOptions::default();
    assert_err!(
        map_product(&[a.clone(), b], &d),
        InvalidShape { .. },
        "maps of different sizes"
    );
    assert_err!(
        map_product::<f64>(&[], &d),
        InvalidParameter { name: "maps", .. },
        "no map given"
    );
    let many = ProductOptions {
        selections: vec![Selection::Largest(16 * 32)],
        ..Default::default()
    };
    assert_err!(
        map_product(&[a.clone(), a.clone()], &many),
        InvalidParameter { name: "keep", .. },
        "only 510 details"
    );
    let odd = LatLongMap::<f64>::from_fn(6, 1, |_, o| o[0] = 1.0).unwrap();
    assert_err!(
        map_product(&[odd.clone(), odd], &d),
        InvalidShape { .. },
        "not a power of two"
    );
}
