use ndarray::{Array2, Array3};
use rand::rngs::StdRng;
use rand::{Rng, SeedableRng};

use super::*;
use crate::precompute::transport_set::Encoded;
use crate::{ShadeOptions, TransportSet};
use haarshift::faces::param::{ParamKind, SphereMap};
use haarshift::product::Selection;

/// Random sparse transport: each texel seen with probability `seen`, values over six decades.
fn random_set(param: Parameterization, vertices: usize, seen: f64, seed: u64) -> TransportSet {
    let mut rng = StdRng::seed_from_u64(seed);
    let s = param.face_size();
    let mut set = TransportSet::new(param, Selection::All);
    for _ in 0..vertices {
        let values = Array3::from_shape_fn((param.faces(), s, s), |_| {
            if rng.random_bool(seen) {
                10f32.powf(rng.random_range(-6.0..0.0))
            } else {
                0.0
            }
        });
        set.push(values.view()).unwrap();
    }
    set
}

fn sky_lighting(param: Parameterization) -> Lighting {
    let map = SphereMap::<f64>::from_fn(param, 3, |d, out| {
        out[0] = 1.0 + d[0];
        out[1] = 2.0 + d[1] * d[2];
        out[2] = (4.0 * d[2]).exp();
    })
    .unwrap();
    Lighting::from_map(&map, Selection::All).unwrap()
}

fn prepared(set: &TransportSet) -> PreparedTransport<f32> {
    let albedo = Array2::from_shape_fn((set.vertex_count(), 3), |(v, c)| {
        0.2 + 0.1 * ((v + 2 * c) % 7) as f32
    });
    PreparedTransport::new(set, albedo.view(), &ShadeOptions::default()).unwrap()
}

/// Each stored coefficient is within half a step of the exact one, at the same index, and an
/// index the exact transport does not hold has value 0.
fn assert_within_half_a_step(exact: &PreparedTransport<f32>, packed: &QuantisedTransport) {
    for v in 0..exact.vertex_count() {
        let (indices, values) = exact.coefficients(v);
        let step = values.iter().fold(0.0f32, |m, c| m.max(c.abs())) / 32767.0;
        let (stored, decoded) = packed.coefficients(v);
        let mut found = 0;
        for (&i, &q) in stored.iter().zip(&decoded) {
            match indices.binary_search(&i) {
                Ok(k) => {
                    found += 1;
                    let (q, c) = (f64::from(q), f64::from(values[k]));
                    // Half a step, and the rounding of q / s_v and of q x s_v in f32.
                    let error = (q - c).abs();
                    assert!(
                        error <= 0.5 * f64::from(step) + 2.0 * f64::from(f32::EPSILON) * c.abs(),
                        "vertex {v} index {i}: {q} for {} (step {step})",
                        values[k]
                    );
                }
                Err(_) => assert_eq!(q, 0.0, "vertex {v}: index {i} is not stored"),
            }
        }
        assert_eq!(
            found,
            indices.len(),
            "vertex {v}: every coefficient is stored"
        );
    }
}

#[test]
fn every_coefficient_is_within_half_a_step_and_the_radiance_within_the_rounding_bound() {
    for (param, seen) in [
        (Parameterization::new(ParamKind::LatLong, 16).unwrap(), 0.7),
        (Parameterization::new(ParamKind::Cube, 8).unwrap(), 0.3),
    ] {
        let set = random_set(param, 40, seen, 7);
        let exact = prepared(&set);
        let packed = QuantisedTransport::new(&exact);
        assert_eq!(packed.entry_count(), exact.coefficient_count());
        assert_within_half_a_step(&exact, &packed);
        // The radiance: f64 sums of the exact coefficients, against the bound of the module
        // docs, albedo / pi x s_v / 2 x sum_k |L(i_k)|, and f32's rounding beside it.
        let light = sky_lighting(param);
        let rows = light.coefficients_f64();
        let got = packed.shade(&light).unwrap();
        let mut worst = 0.0f64;
        for v in 0..exact.vertex_count() {
            let (indices, values) = exact.coefficients(v);
            let step = f64::from(values.iter().fold(0.0f32, |m, c| m.max(c.abs()))) / 32767.0;
            let a = exact.albedo(v);
            for c in 0..3 {
                let (mut truth, mut light_sum, mut size) = (0.0, 0.0, 0.0);
                for (&i, &t) in indices.iter().zip(values) {
                    let l = rows[[i as usize, c]];
                    truth += f64::from(t) * l;
                    light_sum += l.abs();
                    size += (f64::from(t) * l).abs();
                }
                let scale = a[c] / std::f64::consts::PI;
                let bound = scale * (0.5 * step * light_sum + 1e-6 * size);
                let error = (f64::from(got[[v, c]]) - scale * truth).abs();
                assert!(
                    error <= bound,
                    "vertex {v} channel {c}: off by {error:e}, bound {bound:e}"
                );
                worst = worst.max(error / bound);
            }
        }
        // The bound is not loose by orders of magnitude: rounding errors of random sign.
        assert!(worst > 1e-3, "{param:?}: worst error {worst} of the bound");
    }
}

#[test]
fn gaps_over_65535_are_bridged_by_zero_entries() {
    // Cube 128: 98,304 texels. A vertex with the scaling coefficients of faces 0 and 5 only,
    // at 0 and 5 x 128^2 = 81,920.
    let param = Parameterization::new(ParamKind::Cube, 128).unwrap();
    let mut set = TransportSet::new(param, Selection::All);
    set.extend(&Encoded {
        indices: vec![0, 81_920],
        coefficients: vec![0.25, 1.0],
        sh: Vec::new(),
    });
    let exact = prepared(&set);
    assert_eq!(exact.coefficients(0).0, [0, 81_920]);
    let packed = QuantisedTransport::new(&exact);
    assert_eq!(packed.entry_count(), 3, "one zero entry bridges the gap");
    assert_eq!(packed.coefficients(0).0, [0, 65_535, 81_920]);
    assert_within_half_a_step(&exact, &packed);
    let light = sky_lighting(param);
    let (a, b) = (exact.shade(&light).unwrap(), packed.shade(&light).unwrap());
    for c in 0..3 {
        assert!(
            (a[[0, c]] - b[[0, c]]).abs() <= 1e-4 * a[[0, c]].abs(),
            "{a} {b}"
        );
    }
}

#[test]
fn a_lighting_of_another_map_or_a_wrong_output_is_refused() {
    let param = Parameterization::new(ParamKind::LatLong, 8).unwrap();
    let packed = QuantisedTransport::new(&prepared(&random_set(param, 3, 0.5, 1)));
    let other = sky_lighting(Parameterization::new(ParamKind::Cube, 8).unwrap());
    assert!(
        packed
            .shade(&other)
            .unwrap_err()
            .to_string()
            .contains("precomputed at")
    );
    let mut out = Array2::<f64>::zeros((2, 3));
    assert_err!(
        packed.shade_into(&sky_lighting(param), &mut out),
        InvalidShape { .. },
        "invalid shape [2, 3]: the output must be (3, 3)"
    );
}
