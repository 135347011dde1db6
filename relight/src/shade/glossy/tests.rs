use ndarray::{Array2, Array3, ArrayView2, Axis};

use super::*;
use crate::TransportSet;
use haarshift::faces::integrate::layout;
use haarshift::faces::param::{ParamKind, SphereMap};
use haarshift::product::triple::triple_integral;
use haarshift::product::{HaarTree, Selection, Transport, WeightedPixels};

/// A strip of `n` vertices along X, normals varied, facing up and a little sideways.
fn strip(n: usize) -> Mesh {
    let positions = Array2::from_shape_fn((n, 3), |(v, k)| match k {
        0 => v as f64 * 0.3,
        1 => 0.1 * (v % 3) as f64,
        _ => -0.2 * (v % 2) as f64,
    });
    let normals = Array2::from_shape_fn((n, 3), |(v, k)| match k {
        0 => 0.3 * ((v as f64) * 1.3).sin(),
        1 => 1.0,
        _ => 0.4 * ((v as f64) * 0.7).cos(),
    });
    let normals = &normals
        / &normals
            .map_axis(Axis(1), |r| r.dot(&r).sqrt())
            .insert_axis(Axis(1));
    let triangles = (0..n as u32 - 2).map(|v| [v, v + 1, v + 2]).collect();
    Mesh::new(positions, triangles, Some(normals)).unwrap()
}

/// A pseudo-random transport per vertex: a cosine lobe about the normal with ragged shadows.
fn transport(param: Parameterization, mesh: &Mesh) -> TransportSet {
    let mut set = TransportSet::new(param, Selection::All);
    for v in 0..mesh.vertex_count() {
        let n = mesh.normals().row(v).to_owned();
        let map = SphereMap::<f64>::from_fn(param, 1, |d, o| {
            let c = n[0] * d[0] + n[1] * d[1] + n[2] * d[2];
            let shadow = if ((d[0] * 7.0 + v as f64).sin() * (d[2] * 5.0).cos()) > 0.6 {
                0.0
            } else {
                1.0
            };
            o[0] = c.max(0.0) * shadow;
        })
        .unwrap();
        set.push(
            map.as_array()
                .index_axis(Axis(3), 0)
                .mapv(|x| x as f32)
                .view(),
        )
        .unwrap();
    }
    set
}

fn sunlit_lighting(param: Parameterization, keep: Selection) -> Lighting {
    let map = SphereMap::<f64>::from_fn(param, 3, |d, o| {
        let sun = (d[0] * 0.3 + d[1] * 0.8 + d[2] * 0.52).max(0.0).powi(40) * 30.0;
        o[0] = 1.0 + d[1] + sun;
        o[1] = 0.7 + 0.3 * d[0] + sun;
        o[2] = 0.5 + 0.2 * d[2] * d[2] + sun;
    })
    .unwrap();
    Lighting::from_map(&map, keep).unwrap()
}

/// Each face's pixels replaced by their means over blocks of side `S >> depth`: the function
/// with its detail levels from `depth` on removed.
fn block_means(pixels: &mut ndarray::Array4<f64>, depth: usize) {
    let (faces, s, _, channels) = pixels.dim();
    let b = s >> depth;
    for f in 0..faces {
        for c in 0..channels {
            for bi in (0..s).step_by(b) {
                for bj in (0..s).step_by(b) {
                    let mut block = pixels.slice_mut(ndarray::s![f, bi..bi + b, bj..bj + b, c]);
                    let mean = block.mean().unwrap();
                    block.fill(mean);
                }
            }
        }
    }
}

/// The oracle: `a_v x sum over texels of T~_v L~ rho~_v`, each factor reconstructed on its own
/// (the transport from its stored coefficients, the lighting and the BRDF through their Haar
/// trees and the product module's selection), block-averaged to the depth.
fn pixel_domain(
    param: Parameterization,
    (indices, values): (&[u32], &[f64]),
    light: &Lighting,
    rho: &SphereMap<f64>,
    keep_brdf: Selection,
    (depth, brdf_depth): (usize, usize),
) -> [f64; 3] {
    let (faces, s) = (param.faces(), param.face_size());
    let mut dense = Array3::<f64>::zeros((faces, s, s));
    for (&i, &c) in indices.iter().zip(values) {
        let i = i as usize;
        dense[[i / (s * s), (i / s) % s, i % s]] = c;
    }
    let t = HaarTree::<f64, 1>::from_coefficients(
        dense.insert_axis(Axis(3)).view(),
        layout(param),
        Selection::All,
    )
    .unwrap();
    let mut t = t.to_pixels().unwrap();
    let mut l = light.tree().unwrap().to_pixels().unwrap();
    let mut r = HaarTree::<f64, 1>::from_pixels(rho.as_array(), layout(param), keep_brdf)
        .unwrap()
        .to_pixels()
        .unwrap();
    for m in [&mut t, &mut l] {
        block_means(m, depth);
    }
    block_means(&mut r, depth.min(brdf_depth));
    let mut sum = [0.0; 3];
    for ((f, i, j, c), &x) in l.indexed_iter() {
        sum[c] += x * t[[f, i, j, 0]] * r[[f, i, j, 0]];
    }
    if depth == s.trailing_zeros() as usize && brdf_depth >= depth {
        // Issue 7's triple product on the three trees gives the same.
        let rgb = |a: &ndarray::Array4<f64>| a.broadcast((faces, s, s, 3)).unwrap().to_owned();
        let ones = Array3::<f64>::ones((faces, s, s));
        let weighted = WeightedPixels::<f64, 3>::new(rgb(&t).view(), ones.view()).unwrap();
        let transport = Transport::new(&weighted, layout(param), Selection::All).unwrap();
        let rho = HaarTree::from_pixels(rgb(&r).view(), layout(param), Selection::All).unwrap();
        let triple = triple_integral(&transport, &light.tree().unwrap(), &rho).unwrap();
        for (t, s) in triple.value.iter().zip(sum) {
            assert!((t - s).abs() < 1e-12 * s.abs().max(1.0));
        }
    }
    sum
}

#[test]
fn the_shading_is_the_pixel_domain_triple_product_of_the_truncated_factors() {
    let param = Parameterization::new(ParamKind::LatLong, 16).unwrap();
    let mesh = strip(5);
    let set = transport(param, &mesh);
    let albedo = Array2::from_shape_fn((5, 3), |(v, c)| 0.3 + 0.1 * (v + c) as f32);
    let eye = [0.5, 2.0, 3.0];
    let brdf = Brdf::Phong { exponent: 12.0 };
    let orientation = Orientation::new(&brdf, param, BrdfRotation::Direct, None, 16).unwrap();
    for (keep_light, keep_visibility, keep_brdf, depth, brdf_levels) in [
        (Selection::All, None, None, None, None),
        (Selection::Largest(40), Some(60), Some(30), None, None),
        (Selection::Largest(25), None, Some(9), Some(2), None),
        (Selection::All, Some(100), None, Some(3), None),
        // The thesis's coarse-to-fine cutoff: 16 coefficients per face, the rest at full depth.
        (Selection::All, None, None, None, Some(2)),
        (Selection::Largest(30), None, Some(20), Some(3), Some(1)),
    ] {
        let light = sunlit_lighting(param, keep_light);
        let shade = ShadeOptions {
            keep_visibility: keep_visibility.map(Selection::Largest),
            depth,
        };
        let options = GlossyOptions {
            brdf: brdf.clone(),
            rotation: BrdfRotation::Direct,
            keep_brdf,
            brdf_levels,
            ..GlossyOptions::default()
        };
        let shader =
            GlossyShader::<f64>::new(&set, &mesh, albedo.view(), &shade, &options, 5).unwrap();
        let (b, report) = shader.shade(&light, eye).unwrap();
        assert_eq!((report.maps, report.rotated, report.cached), (5, 5, 0));
        // The oracle reads the transport as the shader truncated it (re-truncation and
        // depth are the diffuse shading's, tested there).
        for v in 0..5 {
            let p = mesh.positions().row(v).to_owned();
            let n = mesh.normals().row(v).to_owned();
            let frame =
                Frame::new([n[0], n[1], n[2]], std::array::from_fn(|k| eye[k] - p[k])).unwrap();
            let rho = orientation.lobe(&frame).unwrap();
            let keep = keep_brdf.map_or(Selection::All, Selection::Largest);
            let stored = shader.transport().coefficients(v);
            let depths = (depth.unwrap_or(4), brdf_levels.unwrap_or(4));
            let want = pixel_domain(param, stored, &light, &rho, keep, depths);
            assert_radiance(b.view(), albedo.view(), v, want);
        }
    }
}

#[test]
fn a_cached_vertex_is_the_weighted_triple_product_of_its_bins() {
    // Each vertex against the pixel-domain oracle of every bin it blends, weighted: the blend
    // of the bins' texels is the blend of their triple products.
    let param = Parameterization::new(ParamKind::LatLong, 16).unwrap();
    let (mesh, set, albedo) = strip_scene(param, 6);
    let light = sunlit_lighting(param, Selection::Largest(50));
    let eye = [0.5, 2.0, 3.0];
    for (brdf, bins) in [
        (Brdf::Phong { exponent: 12.0 }, 8),
        (Brdf::BlinnPhong { exponent: 8.0 }, 4),
    ] {
        // Phong blends four bins; a view-dependent BRDF takes one.
        let phong = brdf.is_mirror_symmetric();
        let options = GlossyOptions {
            brdf,
            cache_bins: Some(bins),
            ..GlossyOptions::default()
        };
        let shade = ShadeOptions::default();
        let shader =
            GlossyShader::<f64>::new(&set, &mesh, albedo.view(), &shade, &options, 6).unwrap();
        let (b, _) = shader.shade(&light, eye).unwrap();
        let mut blended = 0;
        for v in 0..6 {
            let blend = shader.bin_keys(&shader.vertex_frame(v, eye).unwrap(), bins);
            blended += usize::from(blend.len > 1);
            let mut want = [0.0; 3];
            for &(key, w) in &blend.bins[..blend.len] {
                let rho = shader.orientation.lobe(&shader.frame_of(key)).unwrap();
                let stored = shader.transport().coefficients(v);
                let sum = pixel_domain(param, stored, &light, &rho, Selection::All, (4, 4));
                for c in 0..3 {
                    want[c] += w * sum[c];
                }
            }
            assert_radiance(b.view(), albedo.view(), v, want);
        }
        assert_eq!(blended > 0, phong, "{blended} vertices blend bins");
    }
}

#[test]
fn the_f32_shading_stays_within_its_rounding_of_the_f64_one() {
    // f32 everywhere: the rotation, the texels, the sums in runs. Measured 5.4e-7 of the RMS
    // without a cache, 4.5e-7 with one.
    let param = Parameterization::new(ParamKind::LatLong, 32).unwrap();
    let (mesh, set, albedo) = strip_scene(param, 8);
    let light = sunlit_lighting(param, Selection::All);
    let shade = ShadeOptions::default();
    for bins in [None, Some(16)] {
        let options = GlossyOptions {
            brdf: Brdf::Phong { exponent: 30.0 },
            cache_bins: bins,
            ..GlossyOptions::default()
        };
        let wide =
            GlossyShader::<f64>::new(&set, &mesh, albedo.view(), &shade, &options, 8).unwrap();
        let narrow =
            GlossyShader::<f32>::new(&set, &mesh, albedo.view(), &shade, &options, 8).unwrap();
        let (want, _) = wide.shade(&light, [1.0, 3.0, 2.0]).unwrap();
        let (got, _) = narrow.shade(&light, [1.0, 3.0, 2.0]).unwrap();
        let rms = (want.iter().map(|x| x * x).sum::<f64>() / want.len() as f64).sqrt();
        let worst = (&got.mapv(f64::from) - &want)
            .iter()
            .fold(0.0f64, |a, d| a.max(d.abs()));
        assert!(worst < 2e-6 * rms, "{bins:?}: {worst:e} of RMS {rms}");
    }
}

/// A strip, its transport and albedo, for the tests below.
fn strip_scene(param: Parameterization, n: usize) -> (Mesh, TransportSet, Array2<f32>) {
    let mesh = strip(n);
    let set = transport(param, &mesh);
    let albedo = Array2::from_shape_fn((n, 3), |(v, c)| 0.2 + 0.15 * ((v + 2 * c) % 5) as f32);
    (mesh, set, albedo)
}

fn shader(
    param: Parameterization,
    n: usize,
    options: &GlossyOptions,
    object_vertices: usize,
) -> (GlossyShader<f64>, PreparedTransport<f64>) {
    let (mesh, set, albedo) = strip_scene(param, n);
    let shade = ShadeOptions::default();
    let glossy =
        GlossyShader::new(&set, &mesh, albedo.view(), &shade, options, object_vertices).unwrap();
    (
        glossy,
        PreparedTransport::new(&set, albedo.view(), &shade).unwrap(),
    )
}

#[test]
fn phong_zero_is_lambert_with_the_same_albedo() {
    // 0^0 = 1: Phong 0 is 1/pi everywhere, whatever the rotation or the cache.
    let param = Parameterization::new(ParamKind::LatLong, 16).unwrap();
    let light = sunlit_lighting(param, Selection::All);
    for (rotation, bins) in [
        (BrdfRotation::Direct, None),
        (BrdfRotation::Haar, None),
        (BrdfRotation::Spatial, Some(8)),
    ] {
        let options = GlossyOptions {
            brdf: Brdf::Phong { exponent: 0.0 },
            rotation,
            cache_bins: bins,
            ..GlossyOptions::default()
        };
        let (glossy, lambert) = shader(param, 6, &options, 6);
        let (b, _) = glossy.shade(&light, [1.0, 3.0, 2.0]).unwrap();
        let want = lambert.shade(&light).unwrap();
        let err = (&b - &want).iter().fold(0.0f64, |m, v| m.max(v.abs()));
        assert!(err < 1e-12, "{rotation}: {err}");
    }
}

#[test]
fn the_ground_plane_stays_lambertian() {
    let param = Parameterization::new(ParamKind::LatLong, 16).unwrap();
    let light = sunlit_lighting(param, Selection::All);
    let options = GlossyOptions {
        brdf: Brdf::Phong { exponent: 30.0 },
        ..GlossyOptions::default()
    };
    let (glossy, lambert) = shader(param, 7, &options, 4);
    let (b, report) = glossy.shade(&light, [1.0, 3.0, 2.0]).unwrap();
    let want = lambert.shade(&light).unwrap();
    assert_eq!(report.maps, 4);
    for v in 0..7 {
        let same = b.row(v) == want.row(v);
        assert_eq!(same, v >= 4, "vertex {v}");
    }
}

#[test]
fn the_rotation_cache_reuses_bins_and_stays_close_to_exact_frames() {
    let param = Parameterization::new(ParamKind::LatLong, 32).unwrap();
    let light = sunlit_lighting(param, Selection::All);
    let exact = GlossyOptions {
        brdf: Brdf::Phong { exponent: 10.0 },
        ..GlossyOptions::default()
    };
    let cached = GlossyOptions {
        cache_bins: Some(32),
        ..exact.clone()
    };
    let (exact, _) = shader(param, 12, &exact, 12);
    let (cached, _) = shader(param, 12, &cached, 12);
    let eye = [1.0, 3.0, 2.0];
    let (want, _) = exact.shade(&light, eye).unwrap();
    let (cold, first) = cached.shade(&light, eye).unwrap();
    assert!(first.maps > 0 && first.rotated == first.maps && first.cached == first.maps);
    let (warm, second) = cached.shade(&light, eye).unwrap();
    assert_eq!((second.rotated, second.cached), (0, first.maps));
    assert_eq!(warm, cold);
    // Bilinear over 5.6-degree bins of the mirror direction, a 26-degree lobe: measured 0.5 %.
    let rms = |a: &Array2<f64>| a.iter().map(|v| v * v).sum::<f64>().sqrt();
    let e = rms(&(&cold - &want)) / rms(&want);
    assert!(e < 0.02, "cache error {e}");
    // Another view reuses what it can.
    let (_, third) = cached.shade(&light, [-2.0, 2.5, 1.0]).unwrap();
    assert!(third.rotated < third.maps, "{third:?}");
}

#[test]
fn a_cache_filled_ahead_serves_every_view_with_the_same_maps() {
    let param = Parameterization::new(ParamKind::LatLong, 16).unwrap();
    let light = sunlit_lighting(param, Selection::All);
    let options = GlossyOptions {
        brdf: Brdf::Phong { exponent: 10.0 },
        cache_bins: Some(8),
        ..GlossyOptions::default()
    };
    let (filled, _) = shader(param, 9, &options, 9);
    let (lazy, _) = shader(param, 9, &options, 9);
    assert_eq!(filled.fill_cache().unwrap(), 8 * 16);
    assert_eq!((filled.cached(), filled.fill_cache().unwrap()), (8 * 16, 0));
    for eye in [[1.0, 3.0, 2.0], [-2.0, 2.5, 1.0], [0.5, 0.2, -3.0]] {
        let (a, report) = filled.shade(&light, eye).unwrap();
        assert_eq!(report.rotated, 0, "{eye:?}");
        let (b, _) = lazy.shade(&light, eye).unwrap();
        assert_eq!(a, b, "{eye:?}");
    }
    // Nothing to fill without a cache, and a view-dependent BRDF's bins are not filled ahead.
    let none = GlossyOptions {
        cache_bins: None,
        ..options.clone()
    };
    assert_err!(
        shader(param, 3, &none, 3).0.fill_cache(),
        InvalidParameter {
            name: "rotation cache",
            ..
        },
        "no cache"
    );
    let blinn = GlossyOptions {
        brdf: Brdf::BlinnPhong { exponent: 10.0 },
        ..options
    };
    assert_err!(
        shader(param, 3, &blinn, 3).0.fill_cache(),
        InvalidParameter {
            name: "rotation cache",
            ..
        },
        "depends on the view"
    );
}

#[test]
fn bad_inputs_are_refused() {
    let param = Parameterization::new(ParamKind::LatLong, 8).unwrap();
    let (mesh, set, albedo) = strip_scene(param, 4);
    let shade = ShadeOptions::default();
    let make = |options: &GlossyOptions, glossy: usize| {
        GlossyShader::<f32>::new(&set, &mesh, albedo.view(), &shade, options, glossy)
    };
    let phong = GlossyOptions {
        brdf: Brdf::Phong { exponent: 5.0 },
        ..GlossyOptions::default()
    };
    assert_err!(
        make(
            &GlossyOptions {
                cache_bins: Some(0),
                ..phong.clone()
            },
            4
        ),
        InvalidParameter {
            name: "rotation cache",
            ..
        },
        "1 to 1024"
    );
    assert_err!(
        make(
            &GlossyOptions {
                keep_brdf: Some(1000),
                ..phong.clone()
            },
            4
        ),
        InvalidParameter { name: "keep", .. },
        "1000"
    );
    assert_err!(
        make(&phong, 5),
        InvalidParameter {
            name: "vertices",
            ..
        },
        "5 glossy"
    );
    let shader = make(&phong, 4).unwrap();
    let light = sunlit_lighting(param, Selection::All);
    assert_err!(
        shader.shade(&light, [f64::NAN, 0.0, 0.0]),
        InvalidParameter { name: "camera", .. },
        "finite"
    );
    let on_vertex = mesh.positions().row(2).to_owned();
    assert_err!(
        shader.shade(&light, [on_vertex[0], on_vertex[1], on_vertex[2]]),
        InvalidParameter { name: "camera", .. },
        "vertex 2"
    );
    let other = sunlit_lighting(
        Parameterization::new(ParamKind::LatLong, 16).unwrap(),
        Selection::All,
    );
    assert_err!(
        shader.shade(&other, [0.0, 3.0, 0.0]),
        InvalidParameter {
            name: "lighting",
            ..
        },
        "precomputed at latlong 8"
    );
}

#[test]
fn full_coefficients_and_direct_evaluation_equal_the_reference() {
    use crate::precompute::visibility::{VisibilityOptions, vertex_major};
    use crate::{ReferenceOptions, reference};
    use crate::{SceneBvh, add_ground_plane};
    use haarshift::sphere::LatLongMap;
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../testdata/meshes/bunny.ply");
    let mut mesh = Mesh::load(path.as_ref()).unwrap();
    let objects = mesh.vertex_count();
    add_ground_plane(&mut mesh).unwrap();
    let n = 16;
    let sky = LatLongMap::<f64>::from_fn(n, 3, |d, o| {
        let sun = (8.0 * (d[0] * 0.6 + d[1] * 0.8 - 1.0)).exp();
        o.copy_from_slice(&[1.0 + 20.0 * sun, 0.5 + d[2].abs(), 0.2 + 10.0 * sun]);
    })
    .unwrap();
    let albedo = Array2::from_shape_fn((mesh.vertex_count(), 3), |(v, c)| {
        0.3 + 0.1 * ((v * 7 + c) % 5) as f32
    });
    let eye = [0.3, 0.4, 0.9];
    let bvh = SceneBvh::new(&mesh);
    let param = Parameterization::new(ParamKind::LatLong, n).unwrap();
    let (set, _) = vertex_major(&mesh, &bvh, &VisibilityOptions::new(param)).unwrap();
    let light =
        Lighting::from_map(&SphereMap::from_lat_long(&sky).unwrap(), Selection::All).unwrap();
    for brdf in [
        Brdf::Phong { exponent: 30.0 },
        Brdf::BlinnPhong { exponent: 20.0 },
    ] {
        let options = ReferenceOptions {
            brdf: brdf.clone(),
            eye: Some(eye),
            object_vertices: Some(objects),
            ..ReferenceOptions::default()
        };
        let (want, _) = reference(&mesh, &bvh, albedo.view(), &sky, &options).unwrap();
        let glossy = GlossyOptions {
            brdf: brdf.clone(),
            rotation: BrdfRotation::Direct,
            ..GlossyOptions::default()
        };
        let shader = GlossyShader::<f64>::new(
            &set,
            &mesh,
            albedo.view(),
            &ShadeOptions::default(),
            &glossy,
            objects,
        )
        .unwrap();
        let (got, _) = shader.shade(&light, eye).unwrap();
        let rms = (want.iter().map(|x| x * x).sum::<f64>() / want.len() as f64).sqrt();
        let worst = (&got - &want).iter().fold(0.0f64, |a, d| a.max(d.abs()));
        assert!(worst <= 1e-6 * rms, "{brdf}: {worst:e} of RMS {rms}");
        // The material matters: the glossy radiance is not the Lambertian one.
        let lambert = shader.transport().shade(&light).unwrap();
        let apart = (&lambert - &want)
            .iter()
            .fold(0.0f64, |a, d| a.max(d.abs()));
        assert!(apart > 0.1 * rms, "{brdf}: {apart} of {rms}");
    }
}

/// Vertex `v`'s radiance in `b` is its albedo times `want`, to 1e-12 (relative, or absolute
/// below 1).
fn assert_radiance(b: ArrayView2<'_, f64>, albedo: ArrayView2<'_, f32>, v: usize, want: [f64; 3]) {
    for c in 0..3 {
        let w = f64::from(albedo[[v, c]]) * want[c];
        assert!(
            (b[[v, c]] - w).abs() < 1e-12 * w.abs().max(1.0),
            "vertex {v} channel {c}: {} vs {w}",
            b[[v, c]]
        );
    }
}
