use std::f64::consts::PI;

use ndarray::Array2;

use super::*;
use crate::ReferenceOptions;
use crate::scene::shapes::{grid, merge};
use crate::shade::reference::interreflection::interreflected;
use crate::shade::reference::reference;
use haarshift::metrics::rms;

/// Radiance varying over the sphere, different in each channel.
fn varied_sky(n: usize) -> LatLongMap<f64> {
    LatLongMap::from_fn(n, 3, |d, o| {
        o[0] = 1.0 + d[1];
        o[1] = 0.5 + d[0] * d[0];
        o[2] = 1.5 + d[2];
    })
    .unwrap()
}

/// A 2 x 2 floor facing +Y, `cells` a side, with (when `wall`) a 2 x 1 wall just behind its
/// back edge facing it.
fn floor_and_wall(cells: usize, wall: bool) -> Mesh {
    let floor = grid(
        [-1.0, 0.0, 1.0],
        [2.0, 0.0, 0.0],
        [0.0, 0.0, -2.0],
        cells,
        cells,
    )
    .unwrap();
    if !wall {
        return floor;
    }
    let wall = grid(
        [-1.0, 0.0, -1.1],
        [2.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        cells,
        cells,
    )
    .unwrap();
    merge([floor, wall])
}

fn albedo_by_channel(v: usize) -> Array2<f32> {
    Array2::from_shape_fn((v, 3), |(_, c)| [0.7f32, 0.5, 0.3][c])
}

fn trace(
    mesh: &Mesh,
    light: &LatLongMap<f64>,
    paths: usize,
    bounces: usize,
    seed: u64,
) -> PathTrace {
    let a = albedo_by_channel(mesh.vertex_count());
    let options = PathTraceOptions {
        paths,
        bounces,
        seed,
        progress: false,
    };
    path_trace(mesh, &SceneBvh::new(mesh), a.view(), light, &options).unwrap()
}

#[test]
fn runs_repeat_bit_for_bit_and_the_seed_changes_them() {
    let mesh = floor_and_wall(3, true);
    let light = varied_sky(8);
    let first = trace(&mesh, &light, 32, 2, 7);
    let again = trace(&mesh, &light, 32, 2, 7);
    assert_eq!(first.radiance, again.radiance);
    assert_eq!(first.standard_error, again.standard_error);
    let other = trace(&mesh, &light, 32, 2, 8);
    assert_ne!(first.radiance, other.radiance);
}

/// `a / pi x int L cos dOmega` over the upper hemisphere exactly, for the piecewise-constant
/// map `light` and the normal +Y: row `i`'s texels span `cos theta` from `cos(i step)` to
/// `cos((i + 1) step)`, and `int cos theta sin theta dtheta dphi` over one of them is
/// `(sin^2 theta_1 - sin^2 theta_0) / 2 x dphi`.
fn upward_exact(light: &LatLongMap<f64>, a: [f64; 3]) -> [f64; 3] {
    let (h, w) = (light.height(), light.width());
    let step = PI / h as f64;
    let map = light.as_array();
    let mut sum = [0.0; 3];
    for i in 0..h / 2 {
        let (t0, t1) = (i as f64 * step, (i + 1) as f64 * step);
        let band = (t1.sin().powi(2) - t0.sin().powi(2)) / 2.0 * (2.0 * PI / w as f64);
        for j in 0..w {
            (0..3).for_each(|c| sum[c] += map[[i, j, c]] * band);
        }
    }
    std::array::from_fn(|c| a[c] / PI * sum[c])
}

#[test]
fn four_times_the_paths_halve_the_error_against_the_closed_form() {
    let flat = floor_and_wall(12, false);
    let light = varied_sky(8);
    let exact = upward_exact(&light, [0.7, 0.5, 0.3]);
    let error = |t: &PathTrace| {
        let e = Array2::from_shape_fn(t.radiance.dim(), |(v, c)| t.radiance[[v, c]] - exact[c]);
        rms(e.view())
    };
    let (few, many) = (
        trace(&flat, &light, 64, 0, 1),
        trace(&flat, &light, 256, 0, 1),
    );
    let ratio = error(&many) / error(&few);
    // 169 vertices x 3 channels of independent errors: the ratio of two RMS is 1/2 within
    // about 5% (measured: see the message).
    assert!((0.42..0.6).contains(&ratio), "ratio {ratio}");
    // And the reported standard error is what the error is.
    for t in [&few, &many] {
        let r = error(t) / t.rms_standard_error();
        assert!((0.85..1.15).contains(&r), "error / standard error {r}");
    }
}

#[test]
fn direct_light_agrees_with_the_reference_within_its_standard_errors() {
    let mesh = floor_and_wall(4, true);
    let light = varied_sky(32);
    let a = albedo_by_channel(mesh.vertex_count());
    let bvh = SceneBvh::new(&mesh);
    let (truth, _) =
        reference(&mesh, &bvh, a.view(), &light, &ReferenceOptions::default()).unwrap();
    let t = trace(&mesh, &light, 512, 0, 3);
    let z = (&t.radiance - &truth) / &t.standard_error;
    let (rms_z, worst) = (rms(z.view()), z.iter().fold(0.0f64, |m, x| m.max(x.abs())));
    // Measured: see the message; a z-score's RMS is 1 where the reference's quadrature error
    // is far below the standard error.
    assert!(rms_z < 1.3 && worst < 4.5, "rms z {rms_z}, worst {worst}");
}

#[test]
fn one_bounce_agrees_with_the_gather_on_a_corner() {
    let mesh = floor_and_wall(8, true);
    let light = varied_sky(16);
    let a = albedo_by_channel(mesh.vertex_count());
    let bvh = SceneBvh::new(&mesh);
    let gather = interreflected(&mesh, &bvh, a.view(), &light, 1, false).unwrap();
    let t = trace(&mesh, &light, 1024, 1, 5);
    let bounce = rms(gather.bounces[0].view());
    let difference = rms((&t.radiance - &gather.radiance(1)).view());
    // The gather interpolates over 8 x 8 cells and takes 16 x 32 directions; the difference
    // stays a small part of the bounced light (measured: see the message), and without the
    // bounce the path tracer would be a whole bounce away.
    let direct = rms((&t.radiance - &gather.direct).view());
    assert!(
        difference < 0.25 * bounce && direct > 0.8 * bounce,
        "difference {difference:e}, bounce {bounce:e}, standard error {:e}, direct only {direct:e}",
        t.rms_standard_error()
    );
}

#[test]
fn few_paths_and_too_many_bounces_are_refused() {
    let mesh = floor_and_wall(1, false);
    let bvh = SceneBvh::new(&mesh);
    let a = albedo_by_channel(mesh.vertex_count());
    let light = varied_sky(4);
    let e = path_trace(&mesh, &bvh, a.view(), &light, &PathTraceOptions::new(1)).unwrap_err();
    assert!(e.to_string().contains("2 to"), "{e}");
    let deep = PathTraceOptions {
        bounces: 9,
        ..PathTraceOptions::new(4)
    };
    assert_err!(
        path_trace(&mesh, &bvh, a.view(), &light, &deep),
        InvalidParameter {
            name: "bounces",
            ..
        },
        "9: must be 0 to 8"
    );
}
