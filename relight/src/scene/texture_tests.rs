use super::*;

#[test]
fn srgb_decoding_follows_the_formula_on_both_sides_of_the_knee() {
    for k in 0..=255 {
        let c = f64::from(k) / 255.0;
        let expected = if c <= 0.04045 {
            c / 12.92
        } else {
            ((c + 0.055) / 1.055).powf(2.4)
        };
        assert_eq!(srgb_to_linear(c), expected);
    }
    // The two branches meet at the knee to 1e-7 (IEC 61966-2-1's constants).
    let knee = 0.04045;
    assert!((knee / 12.92 - ((knee + 0.055) / 1.055f64).powf(2.4)).abs() < 1e-7);
    assert_eq!(srgb_to_linear(10.0 / 255.0), 10.0 / 255.0 / 12.92);
    assert!((srgb_to_linear(128.0 / 255.0) - 0.21586050).abs() < 1e-8);
}

/// 3 x 2 texels whose channels are `(i, j, i + 10 j)`.
fn ramp() -> Texture {
    let texels = (0..6)
        .map(|k| {
            let (i, j) = ((k % 3) as f32, (k / 3) as f32);
            [i, j, i + 10.0 * j]
        })
        .collect();
    Texture::from_linear(3, 2, texels).unwrap()
}

#[test]
fn bilinear_sampling_hits_texel_centres_and_interpolates_between_them() {
    let t = ramp();
    let clamp = [Wrap::ClampToEdge; 2];
    let at = |u: f64, v: f64| t.sample([u, v], clamp, Filter::Linear);
    // Centres: u = (i + 0.5) / 3, v = (j + 0.5) / 2.
    for j in 0..2 {
        for i in 0..3 {
            let (u, v) = ((i as f64 + 0.5) / 3.0, (j as f64 + 0.5) / 2.0);
            assert_eq!(at(u, v), [i as f32, j as f32, (i + 10 * j) as f32]);
        }
    }
    // A quarter of the way from texel (0, 0) to (1, 0) and 0.3 of the way down to row 1:
    // x = 0.25, y = 0.3 by hand: channel 2 = 0.25 + 10 * 0.3 = 3.25.
    let (u, v) = ((0.5 + 0.25) / 3.0, (0.5 + 0.3) / 2.0);
    let s = at(u, v);
    assert!(
        (s[0] - 0.25).abs() < 1e-6 && (s[1] - 0.3).abs() < 1e-6,
        "{s:?}"
    );
    assert!((s[2] - 3.25).abs() < 1e-6, "{s:?}");
    // Beyond the last centre a clamped texture stays at the edge texel.
    assert_eq!(at(0.99, 0.99), [2.0, 1.0, 12.0]);
    assert_eq!(at(-3.0, 0.25), [0.0, 0.0, 0.0]);
}

#[test]
fn wrap_modes_fold_indices_as_the_gltf_spec_says() {
    let n = 3;
    let folded = |w: Wrap| (-4..7).map(|i| w.index(i, n)).collect::<Vec<_>>();
    assert_eq!(folded(Wrap::Repeat), [2, 0, 1, 2, 0, 1, 2, 0, 1, 2, 0]);
    assert_eq!(folded(Wrap::ClampToEdge), [0, 0, 0, 0, 0, 1, 2, 2, 2, 2, 2]);
    assert_eq!(
        folded(Wrap::MirroredRepeat),
        [2, 2, 1, 0, 0, 1, 2, 2, 1, 0, 0]
    );
    // Repeat: half way between the last texel and the first across the seam.
    let t = ramp();
    let s = t.sample([1.0, 0.25], [Wrap::Repeat; 2], Filter::Linear);
    assert_eq!(s[0], 1.0); // (2 + 0) / 2
    assert_eq!(
        t.sample([f64::NAN, 0.25], [Wrap::Repeat; 2], Filter::Nearest)[0],
        0.0
    );
}

#[test]
fn decoding_divides_by_the_depth_and_takes_srgb_to_linear() {
    // A 2 x 1 8-bit RGB PNG: (0, 128, 255) and (10, 20, 30).
    let mut png = Vec::new();
    image::codecs::png::PngEncoder::new(&mut png)
        .write_image(
            &[0, 128, 255, 10, 20, 30],
            2,
            1,
            image::ExtendedColorType::Rgb8,
        )
        .unwrap();
    let t = Texture::decode(&png, "t.png".as_ref(), 1 << 20).unwrap();
    let lin = |k: u8| srgb_to_linear(f64::from(k) / 255.0) as f32;
    assert_eq!(
        t.texels,
        vec![[lin(0), lin(128), lin(255)], [lin(10), lin(20), lin(30)]]
    );
    assert_err!(
        Texture::from_linear(2, 2, vec![[0.0; 3]; 3]),
        InvalidShape { .. },
        "invalid shape [2, 2]: 3 texels for a 2 x 2 texture"
    );
}

use image::ImageEncoder;
