use std::f64::consts::PI;

use super::*;
use crate::precompute::cast::f32x3;
use crate::test_support::bunny_on_ground;
use crate::test_support::corner_form_factor;
use crate::test_support::latlong;
use crate::{Generator, SceneBvh, add_ground_plane};
use haarshift::faces::ParamKind;

/// Vertex `v`'s transport as pixels `(faces, S, S)`.
fn pixels(set: &TransportSet, v: usize) -> Vec<f32> {
    set.transport(v)
        .unwrap()
        .tree()
        .to_pixels()
        .unwrap()
        .iter()
        .copied()
        .collect()
}

/// The RMS over vertices of the difference of two sets' transport integrals, and of the
/// first set's integrals (errors are relative to the scene's RMS, never per vertex).
fn rms_difference(a: &TransportSet, b: &TransportSet) -> (f64, f64) {
    let total = |s: &TransportSet, v| pixels(s, v).iter().map(|&x| f64::from(x)).sum::<f64>();
    let n = a.vertex_count();
    let mean = |f: &dyn Fn(usize) -> f64| ((0..n).map(f).sum::<f64>() / n as f64).sqrt();
    (
        mean(&|k| (total(a, k) - total(b, k)).powi(2)),
        mean(&|k| total(a, k).powi(2)),
    )
}

#[test]
fn a_convex_sphere_is_unoccluded_above_its_horizon() {
    let mesh = Generator::Sphere { cells: 16 }.mesh().unwrap();
    let param = latlong(16);
    let (set, report) =
        vertex_major(&mesh, &SceneBvh::new(&mesh), &VisibilityOptions::new(param)).unwrap();
    let directions = texel_directions(param);
    let weights = param.solid_angles();
    let mut near_horizon_blocked = 0usize;
    for v in 0..mesh.vertex_count() {
        let n = [0, 1, 2].map(|k| mesh.normals()[[v, k]]);
        let t = pixels(&set, v);
        let mut total = 0.0;
        for (k, (&got, w)) in t.iter().zip(&directions).enumerate() {
            let cos = dot(n, *w);
            let open = cos.max(0.0) * weights.as_slice().unwrap()[k];
            total += f64::from(got);
            if cos > 0.2 {
                // Well above the horizon nothing can block a convex surface.
                assert!(
                    (f64::from(got) - open).abs() <= 1e-4 * open + 1e-7,
                    "v {v} texel {k}"
                );
            } else if cos > 0.0 && got == 0.0 {
                near_horizon_blocked += 1;
            }
        }
        // The cosine-weighted hemisphere integrates to pi, to the lat-long quadrature's error.
        assert!(
            (total / PI - 1.0).abs() < 0.03,
            "vertex {v}: {}",
            total / PI
        );
    }
    // Rays grazing the tessellation may hit neighbouring facets, a few per vertex at most.
    assert!(
        near_horizon_blocked < 2 * mesh.vertex_count(),
        "{near_horizon_blocked}"
    );
    assert!(report.rays > 0);
}

#[test]
fn a_point_under_a_floating_box_sees_one_minus_the_form_factor() {
    let height = 1.0;
    let mesh = Generator::PlaneUnderBox { height }.mesh().unwrap();
    let origin = 4; // the centre of the ground, under the box's centre
    assert_eq!(mesh.positions().row(origin).to_vec(), vec![0.0, 0.0, 0.0]);
    // The bottom face [-1, 1]^2 is four unit squares with a corner above the point.
    let f = 4.0 * corner_form_factor(1.0, 1.0, height);
    assert!((f - 0.554_1).abs() < 1e-4, "{f}");
    let bvh = SceneBvh::new(&mesh);
    let mut errors = Vec::new();
    for n in [16, 32, 64, 128] {
        let (set, _) = vertex_major(&mesh, &bvh, &VisibilityOptions::new(latlong(n))).unwrap();
        let seen: f64 = pixels(&set, origin)
            .iter()
            .map(|&x| f64::from(x))
            .sum::<f64>()
            / PI;
        let error = (seen - (1.0 - f)).abs();
        // A bound that halves with every doubling of the resolution.
        assert!(
            error <= 1.0 / n as f64,
            "N = {n}: {seen} against {}",
            1.0 - f
        );
        errors.push(error);
    }
    assert!(errors[3] < errors[0], "{errors:?}");
}

#[test]
fn stratified_samples_are_seeded_and_converge_to_the_centre_rays() {
    let mut mesh = Generator::Sphere { cells: 4 }.mesh().unwrap();
    add_ground_plane(&mut mesh).unwrap();
    let bvh = SceneBvh::new(&mesh);
    let mut options = VisibilityOptions::new(latlong(8));
    let (centre, _) = vertex_major(&mesh, &bvh, &options).unwrap();
    options.samples = 4;
    let (a, report) = vertex_major(&mesh, &bvh, &options).unwrap();
    let (b, _) = vertex_major(&mesh, &bvh, &options).unwrap();
    assert_eq!(a, b);
    options.seed = 1;
    let (c, _) = vertex_major(&mesh, &bvh, &options).unwrap();
    assert_ne!(a, c);
    assert!(report.rays > 10 * mesh.vertex_count() as u64);
    // The ground vertex straight under the sphere (the lowest point touches it) is shadowed
    // alike by both, and over all vertices the integrals agree to a few per cent of the RMS.
    let (diff, rms) = rms_difference(&centre, &a);
    assert!(diff < 0.05 * rms, "{diff} of {rms}");
}

#[test]
fn truncation_keeps_k_coefficients_per_vertex() {
    let mesh = Generator::PlaneUnderBox { height: 1.0 }.mesh().unwrap();
    let mut options = VisibilityOptions::new(latlong(16));
    options.keep = Selection::Largest(20);
    let (set, _) = vertex_major(&mesh, &SceneBvh::new(&mesh), &options).unwrap();
    for v in 0..mesh.vertex_count() {
        // At most K details plus the two faces' scaling coefficients.
        assert!(set.coefficients(v).0.len() <= 22);
    }
    assert!(set.coefficients(4).0.len() >= 20);
}

#[test]
fn bad_options_are_refused() {
    let mesh = Generator::Sphere { cells: 1 }.mesh().unwrap();
    let bvh = SceneBvh::new(&mesh);
    let mut options = VisibilityOptions::new(latlong(4));
    options.samples = 0;
    assert_err!(
        vertex_major(&mesh, &bvh, &options),
        InvalidParameter {
            name: "visibility samples",
            ..
        },
        "0: must be 1 to 64"
    );
    options.samples = 2;
    assert_err!(
        direction_major(&mesh, &options, 64),
        InvalidParameter {
            name: "visibility samples",
            ..
        },
        "texel centres only"
    );
    options.samples = 1;
    options.keep = Selection::Largest(31); // 2 x 16 texels have 30 details
    assert_err!(
        vertex_major(&mesh, &bvh, &options),
        InvalidParameter { name: "keep", .. },
        "only 30 details"
    );
    options.keep = Selection::All;
    assert_err!(
        direction_major(&mesh, &options, 0),
        InvalidParameter {
            name: "shadow map size",
            ..
        },
        "0: must be 1 to 16384"
    );
    for bands in [0, 17] {
        options.sh_bands = Some(bands);
        assert_err!(
            vertex_major(&mesh, &bvh, &options),
            InvalidParameter {
                name: "sh-bands",
                ..
            },
            "transfer takes 1 to 16 bands"
        );
        assert_err!(
            direction_major(&mesh, &options, 64),
            InvalidParameter {
                name: "sh-bands",
                ..
            },
            "transfer takes 1 to 16 bands"
        );
    }
}

#[test]
fn both_orders_make_the_same_spherical_harmonic_transfer() {
    // An open triangle: nothing occludes it, so both orders see the same cosine lobe.
    let mesh = Mesh::new(
        ndarray::array![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, -1.0]],
        vec![[0, 1, 2]],
        None,
    )
    .unwrap();
    let mut options = VisibilityOptions::new(Parameterization::new(ParamKind::Cube, 4).unwrap());
    options.sh_bands = Some(3);
    let (by_maps, _) = direction_major(&mesh, &options, 256).unwrap();
    let (by_rays, _) = vertex_major(&mesh, &SceneBvh::new(&mesh), &options).unwrap();
    assert!(by_maps == by_rays && by_rays.sh().is_some());
    options.param = latlong(32);
    let (by_rays, _) = vertex_major(&mesh, &SceneBvh::new(&mesh), &options).unwrap();
    // The clamped cosine about +Y: t_00 = pi / (2 sqrt pi) and t_10 = 2 pi / 3 sqrt(3 / 4 pi)
    // (Lambert's A_l / sqrt(4 pi / (2l + 1))), to the quadrature; odd orders m vanish.
    let t = by_rays.sh().unwrap().coefficients();
    let want = [
        PI / (2.0 * PI.sqrt()),
        2.0 * PI / 3.0 * (3.0 / (4.0 * PI)).sqrt(),
    ];
    for (got, want) in [t[[0, 0]], t[[0, 2]]].into_iter().zip(want) {
        assert!(
            (f64::from(got) - want).abs() < 2e-3 * want,
            "{got} vs {want}"
        );
    }
    assert!(t[[0, 1]].abs() < 1e-5 && t[[0, 3]].abs() < 1e-5);
    // Without the option there is no transfer.
    options.sh_bands = None;
    assert!(
        vertex_major(&mesh, &SceneBvh::new(&mesh), &options)
            .unwrap()
            .0
            .sh()
            .is_none()
    );
}

#[test]
#[allow(clippy::needless_range_loop)] // `v` indexes the mesh and the per-vertex sums alike
fn both_orders_agree_on_the_bunny_with_its_ground_plane() {
    let mesh = bunny_on_ground();
    let bvh = SceneBvh::new(&mesh);
    let param = latlong(8);
    let origins = RayOrigins::new(&mesh);
    let size = 2048;
    let (mut pairs, mut differ, mut contact, mut unexplained) = (0usize, 0usize, 0usize, 0usize);
    let weights = param.solid_angles();
    // Per vertex, the transport integral the maps add over the rays (from the pairs alone).
    let mut delta = vec![0.0f64; mesh.vertex_count()];
    for (t, w) in texel_directions(param).into_iter().enumerate() {
        let map = ShadowMap::render(&mesh, w, size);
        for v in 0..mesh.vertex_count() {
            let (o, n) = origins.origin_and_normal(v);
            let cos = dot(n, w);
            if cos <= 0.0 {
                continue;
            }
            pairs += 1;
            let by_ray = !bvh.occluded(f32x3(o), f32x3(w), f32::INFINITY);
            if by_ray != map.lit(o, cos) {
                differ += 1;
                let sign = if by_ray { -1.0 } else { 1.0 };
                delta[v] += sign * f64::from(cos as f32) * weights.as_slice().unwrap()[t];
                if !map.near_silhouette(o, cos, 2) {
                    // Not at a silhouette: then the ray's occluder must be closer than the bias.
                    if !by_ray && bvh.occluded(f32x3(o), f32x3(w), map.bias(cos) as f32) {
                        contact += 1;
                    } else {
                        unexplained += 1;
                        eprintln!(
                            "far: v {v} ray lit {by_ray} cos {cos:.3} clearance {:.2}",
                            map.clearance(o)
                        );
                    }
                }
            }
        }
    }
    assert!(pairs > 100_000, "{pairs}");
    eprintln!("{pairs} pairs, {differ} differ, {contact} of them contact shadows");
    assert!(differ as f64 <= 0.01 * pairs as f64, "{differ} of {pairs}");
    assert!(
        contact as f64 <= 0.003 * pairs as f64,
        "{contact} of {pairs}"
    );
    assert_eq!(unexplained, 0, "{differ} differ");
    // The library's direction-major order builds on the same maps.
    let options = VisibilityOptions::new(param);
    let (by_maps, report) = direction_major(&mesh, &options, size).unwrap();
    let (by_rays, _) = vertex_major(&mesh, &bvh, &options).unwrap();
    assert!(report.working_bytes >= 128 * mesh.vertex_count().div_ceil(64) * 8);
    let (diff, rms) = rms_difference(&by_rays, &by_maps);
    let total = |s: &TransportSet, v| pixels(s, v).iter().map(|&x| f64::from(x)).sum::<f64>();
    eprintln!("transport integrals differ by {diff} RMS, the scene's RMS is {rms}");
    // The two transports differ exactly by the differing pairs' cos x solid angle.
    for (k, want) in delta.iter().enumerate() {
        let d = total(&by_maps, k) - total(&by_rays, k);
        assert!((d - want).abs() < 1e-4, "vertex {k}: {d} against {want}");
    }
}

/// The precomputation reports its progress through the core's reporter.
#[cfg(test)]
mod progress_tests {
    use haarshift::progress::{Progress, ProgressTask, set_reporter};
    use std::sync::Mutex;

    /// Every task begun in this test binary: (name, length, units advanced), kept after
    /// the task ends.
    static SEEN: Mutex<Vec<(String, u64, u64)>> = Mutex::new(Vec::new());

    struct Record;
    struct RecordTask(usize);

    impl Progress for Record {
        fn begin(&self, what: &str, len: u64) -> Box<dyn ProgressTask> {
            let mut seen = SEEN.lock().unwrap();
            seen.push((what.to_string(), len, 0));
            Box::new(RecordTask(seen.len() - 1))
        }
    }

    impl ProgressTask for RecordTask {
        fn advance(&self, units: u64) {
            SEEN.lock().unwrap()[self.0].2 += units;
        }
    }

    /// The tasks named `what` that were begun since `from`.
    fn tasks_since(from: usize, what: &str) -> Vec<(u64, u64)> {
        SEEN.lock().unwrap()[from..]
            .iter()
            .filter(|t| t.0 == what)
            .map(|t| (t.1, t.2))
            .collect()
    }

    #[test]
    fn visibility_reports_one_unit_per_vertex_only_when_asked() {
        use crate::{Mesh, SceneBvh, VisibilityOptions, vertex_major};
        use haarshift::faces::{ParamKind, Parameterization};
        use ndarray::array;

        // Installed once for the whole binary; other tests report into it harmlessly.
        let _ = set_reporter(Box::new(Record));
        let mesh = Mesh::new(
            array![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, -1.0]],
            vec![[0, 1, 2]],
            None,
        )
        .unwrap();
        let param = Parameterization::new(ParamKind::LatLong, 8).unwrap();
        let name = "visibility (rays)";
        for report in [false, true] {
            let from = SEEN.lock().unwrap().len();
            let options = VisibilityOptions {
                progress: report,
                ..VisibilityOptions::new(param)
            };
            vertex_major(&mesh, &SceneBvh::new(&mesh), &options).unwrap();
            let n = mesh.vertex_count() as u64;
            let expected = if report { vec![(n, n)] } else { vec![] };
            assert_eq!(tasks_since(from, name), expected, "report = {report}");
        }
    }
}
