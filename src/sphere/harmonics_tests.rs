use super::*;
use crate::faces::param::ParamKind;
use crate::test_support::param;
use std::f64::consts::PI;

/// Deterministic unit vectors spread over the sphere, the poles included.
fn directions() -> Vec<[f64; 3]> {
    let mut out = vec![[0.0, 1.0, 0.0], [0.0, -1.0, 0.0], [1.0, 0.0, 0.0]];
    for k in 0..40 {
        let t = 0.05 + 3.0 * (k as f64 * 0.618_034).fract();
        let p = k as f64 * 2.399_963;
        out.push(crate::sphere::latlong::direction(t, p));
    }
    out
}

#[test]
fn low_degrees_match_their_closed_forms() {
    let sh = SphericalHarmonics::new(3).unwrap();
    let mut y = vec![0.0; 9];
    for d in directions() {
        sh.evaluate(d, &mut y);
        // The textbook (x, y, z) with z the polar axis is the world's (z, x, y).
        let (xs, ys, zs) = (d[2], d[0], d[1]);
        let c1 = (3.0 / (4.0 * PI)).sqrt();
        let c2 = (15.0 / (4.0 * PI)).sqrt();
        let want = [
            0.5 / PI.sqrt(),
            -c1 * ys,
            c1 * zs,
            -c1 * xs,
            c2 * xs * ys,
            -c2 * ys * zs,
            0.25 * (5.0 / PI).sqrt() * (3.0 * zs * zs - 1.0),
            -c2 * xs * zs,
            0.5 * c2 * (xs * xs - ys * ys),
        ];
        for (i, (g, w)) in y.iter().zip(want).enumerate() {
            assert!((g - w).abs() < 1e-14, "Y[{i}] at {d:?}: {g} vs {w}");
        }
    }
}

/// The largest entry of `G - I`, `G` the Gram matrix of the first `bands` bands by the
/// texel quadrature of `p`.
fn gram_error(bands: usize, p: Parameterization) -> f64 {
    let sh = SphericalHarmonics::new(bands).unwrap();
    let n = sh.len();
    let mut gram = Array2::<f64>::zeros((n, n));
    let mut y = vec![0.0; n];
    let s = p.face_size();
    for face in 0..p.faces() {
        for row in 0..s {
            for col in 0..s {
                sh.evaluate(p.texel_direction(face, row, col), &mut y);
                let omega = p.texel_solid_angle(face, row, col);
                for i in 0..n {
                    for j in 0..n {
                        gram[[i, j]] += y[i] * y[j] * omega;
                    }
                }
            }
        }
    }
    gram.indexed_iter()
        .map(|((i, j), &g)| (g - if i == j { 1.0 } else { 0.0 }).abs())
        .fold(0.0, f64::max)
}

#[test]
fn the_first_nine_bands_are_orthonormal() {
    // Every pair of the 81 functions; the texel quadrature is second order, so the error
    // must fall about 4x per doubling of the resolution (it is quadrature, not a bias).
    // Measured: 1.6e-3 at lat-long 64, 4.0e-4 at 128, 1.5e-4 on the 6 x 64^2 cube.
    let coarse = gram_error(9, param(ParamKind::LatLong, 64));
    let fine = gram_error(9, param(ParamKind::LatLong, 128));
    assert!(fine < 5e-4, "{fine:e}");
    let ratio = coarse / fine;
    assert!(
        (3.6..4.4).contains(&ratio),
        "{coarse:e} / {fine:e} = {ratio}"
    );
    let cube = gram_error(9, param(ParamKind::Cube, 64));
    assert!(cube < 2e-4, "{cube:e}");
}

#[test]
fn the_addition_theorem_holds() {
    let bands = 64;
    let sh = SphericalHarmonics::new(bands).unwrap();
    let (mut ya, mut yb) = (vec![0.0; bands * bands], vec![0.0; bands * bands]);
    let dirs = directions();
    for (a, b) in dirs.iter().zip(dirs.iter().rev()) {
        sh.evaluate(*a, &mut ya);
        sh.evaluate(*b, &mut yb);
        let x: f64 = (0..3).map(|k| a[k] * b[k]).sum();
        // Legendre polynomials by Bonnet's recurrence.
        let (mut p0, mut p1) = (1.0, x);
        for l in 0..bands {
            let pl = if l == 0 { p0 } else { p1 };
            let sum: f64 = (l * l..(l + 1) * (l + 1)).map(|i| ya[i] * yb[i]).sum();
            let want = (2 * l + 1) as f64 / (4.0 * PI) * pl;
            let tol = 1e-12 * (2 * l + 1) as f64;
            assert!((sum - want).abs() < tol, "l = {l}: {sum} vs {want}");
            if l >= 1 {
                let next = ((2 * l + 1) as f64 * x * p1 - l as f64 * p0) / (l + 1) as f64;
                (p0, p1) = (p1, next);
            }
        }
    }
}

#[test]
fn a_projection_has_the_same_bits_on_any_number_of_threads() {
    let p = Parameterization::new(ParamKind::LatLong, 64).unwrap();
    let f = SphereMap::<f64>::from_fn(p, 3, |d, o| {
        o.copy_from_slice(&[1.0 + d[1], (9.0 * d[0]).sin(), (d[2] * 40.0).exp()]);
    })
    .unwrap();
    let sh = SphericalHarmonics::new(6).unwrap();
    let on = |threads| {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        pool.install(|| sh.project(&f))
    };
    let one = on(1);
    for threads in [2, 3, 7] {
        assert_eq!(on(threads), one, "{threads} threads");
    }
}

#[test]
fn projection_then_reconstruction_returns_a_band_limited_function() {
    let bands = 9;
    let sh = SphericalHarmonics::new(bands).unwrap();
    let n = sh.len();
    let coeffs = Array2::from_shape_fn((n, 2), |(i, c)| {
        ((i * 37 + c * 11) % 17) as f64 / 17.0 - 0.5
    });
    for p in [param(ParamKind::LatLong, 128), param(ParamKind::Cube, 64)] {
        let f = SphereMap::<f64>::from_fn(p, 2, |d, out| {
            let mut y = vec![0.0; n];
            sh.evaluate(d, &mut y);
            for (c, o) in out.iter_mut().enumerate() {
                *o = (0..n).map(|i| coeffs[[i, c]] * y[i]).sum();
            }
        })
        .unwrap();
        let got = sh.project(&f);
        let err = (&got - &coeffs).iter().fold(0.0f64, |a, v| a.max(v.abs()));
        // The Gram matrix's quadrature error times the coefficients' size (<= 0.5 x 81).
        assert!(err < 5e-3, "{:?}: {err:e}", p.kind());
        let back = sh.reconstruct(got.view(), p).unwrap();
        let diff = (&back.as_array() - &f.as_array())
            .iter()
            .fold(0.0f64, |a, v| a.max(v.abs()));
        assert!(diff < 5e-3, "{:?}: {diff:e}", p.kind());
    }
}

#[test]
fn lambert_factors_match_the_clamped_cosine_by_quadrature() {
    // A_l = sqrt(4 pi / (2l + 1)) t_l with t_l the clamped cosine's zonal coefficients,
    // here by quadrature (the equator is a row edge, so the kink costs no accuracy).
    let bands = 9;
    let sh = SphericalHarmonics::new(bands).unwrap();
    let p = param(ParamKind::LatLong, 256);
    let cosine = SphereMap::<f64>::from_fn(p, 1, |d, o| o[0] = d[1].max(0.0)).unwrap();
    let t = sh.project(&cosine);
    for l in 0..bands {
        let want = (4.0 * PI / (2 * l + 1) as f64).sqrt() * t[[l * (l + 1), 0]];
        let got = lambert_factor(l);
        assert!((got - want).abs() < 1e-4, "l = {l}: {got} vs {want}");
    }
}

/// `c_i = int f(r . w) Y_i(w) dOmega` of a zonal `f` about `axis`, by a quadrature in the
/// lobe's own frame: Gauss-Legendre in `x = r . w` on `[lo, 1]` (`nodes`, exact for the
/// polynomial `f(x) x^l` when `f` is one) times uniform azimuths about `axis`, the harmonics
/// evaluated at the world directions: independent of Funk-Hecke and of the recurrence.
fn project_zonal(
    sh: &SphericalHarmonics,
    f: impl Fn(f64) -> f64,
    axis: [f64; 3],
    lo: f64,
    nodes: usize,
) -> Vec<f64> {
    let n = sh.len();
    // An orthonormal frame (u, v, axis).
    let helper = if axis[0].abs() < 0.9 {
        [1.0, 0.0, 0.0]
    } else {
        [0.0, 1.0, 0.0]
    };
    let cross = |a: [f64; 3], b: [f64; 3]| {
        [
            a[1] * b[2] - a[2] * b[1],
            a[2] * b[0] - a[0] * b[2],
            a[0] * b[1] - a[1] * b[0],
        ]
    };
    let u = cross(axis, helper);
    let norm = u.iter().map(|c| c * c).sum::<f64>().sqrt();
    let u = u.map(|c| c / norm);
    let v = cross(axis, u);
    let phis = 2 * sh.bands() + 1;
    let mut out = vec![0.0; n];
    let mut y = vec![0.0; n];
    for (t, w) in crate::sphere::gaunt::gauss_legendre(nodes) {
        let x = lo + (1.0 - lo) * (t + 1.0) / 2.0;
        let weight = w * (1.0 - lo) / 2.0 * f(x) * 2.0 * PI / phis as f64;
        let s = (1.0 - x * x).max(0.0).sqrt();
        for p in 0..phis {
            let phi = 2.0 * PI * p as f64 / phis as f64;
            let (c, si) = (s * phi.cos(), s * phi.sin());
            let d = [0, 1, 2].map(|k| x * axis[k] + c * u[k] + si * v[k]);
            sh.evaluate(d, &mut y);
            out.iter_mut().zip(&y).for_each(|(o, yi)| *o += weight * yi);
        }
    }
    out
}

#[test]
fn phong_lobes_rotated_to_a_direction_match_their_projection() {
    let bands = 12;
    let sh = SphericalHarmonics::new(bands).unwrap();
    let axes = [[0.0, 1.0, 0.0], [0.48, -0.6, 0.64], [0.0, 0.0, -1.0]];
    let mut got = vec![0.0; bands * bands];
    for e in [0.0, 1.0, 10.0, 50.0, 10_000.0] {
        let lambda = phong_factors(e, bands).unwrap();
        let f = |x: f64| (e + 2.0) / (2.0 * PI) * if e == 0.0 { 1.0 } else { x.powf(e) };
        // The lobe lives on [0, 1] in x, except exponent 0 (0^0 = 1: the whole sphere).
        let lo = if e == 0.0 { -1.0 } else { 0.0 };
        let nodes = (e as usize + bands) / 2 + 2;
        let mut worst = 0.0f64;
        for axis in axes {
            sh.rotated_zonal(&lambda, axis, &mut got);
            let want = project_zonal(&sh, f, axis, lo, nodes);
            for (g, w) in got.iter().zip(&want) {
                worst = worst.max((g - w).abs());
            }
        }
        eprintln!("phong {e}: worst {worst:e}");
        assert!(worst < 1e-10, "phong {e}: {worst:e}");
    }
    // Exponent 0 is the constant 1 / pi exactly: 4 Y_00 Y_00 = 1 / pi.
    sh.rotated_zonal(&phong_factors(0.0, bands).unwrap(), axes[1], &mut got);
    assert!((got[0] * 0.5 / PI.sqrt() - 1.0 / PI).abs() < 1e-16);
    assert!(got[1..].iter().all(|c| *c == 0.0));
}

#[test]
fn phong_factors_refuse_exponents_out_of_range() {
    for bad in [-0.5, 10_000.5, f64::NAN, f64::INFINITY] {
        assert_err!(
            phong_factors(bad, 4),
            InvalidParameter {
                name: "phong exponent",
                ..
            },
            "(expected 0 to 10000)"
        );
    }
    assert_err!(
        phong_factors(2.0, 0),
        InvalidParameter {
            name: "sh-bands",
            ..
        },
        "0 (expected 1 to 64 bands)"
    );
}

#[test]
fn a_constant_environment_gives_irradiance_pi_times_its_radiance() {
    let sh = SphericalHarmonics::new(9).unwrap();
    let p = param(ParamKind::Cube, 32);
    let env = SphereMap::<f32>::from_fn(p, 3, |_, o| o.copy_from_slice(&[1.0, 0.5, 2.0])).unwrap();
    let e = sh.lambert_irradiance(sh.project(&env).view()).unwrap();
    let irradiance = sh.reconstruct(e.view(), p).unwrap();
    for px in irradiance.as_array().as_slice().unwrap().chunks_exact(3) {
        for (v, l) in px.iter().zip([1.0, 0.5, 2.0]) {
            assert!((v - PI * l).abs() < 1e-3 * l, "{v} vs {}", PI * l);
        }
    }
}

#[test]
fn bad_band_counts_and_shapes_are_errors() {
    assert_err!(
        SphericalHarmonics::new(0),
        InvalidParameter {
            name: "sh-bands",
            ..
        },
        "0 (expected 1 to 64 bands)"
    );
    assert_err!(
        SphericalHarmonics::new(65),
        InvalidParameter {
            name: "sh-bands",
            ..
        },
        "65 (expected"
    );
    let sh = SphericalHarmonics::new(2).unwrap();
    let wrong = Array2::<f64>::zeros((3, 1));
    assert_err!(
        sh.reconstruct(wrong.view(), param(ParamKind::Cube, 2)),
        InvalidShape { .. },
        "need 4 coefficients"
    );
    assert_err!(
        sh.lambert_irradiance(wrong.view()),
        InvalidShape { .. },
        "need 4 coefficients"
    );
}
