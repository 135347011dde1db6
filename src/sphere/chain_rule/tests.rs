use super::chain::*;
use super::fields::*;
use super::gradient::*;
use crate::Sample;
use crate::sphere::{LatLongMap, SphereRotation};

/// The zonal rows compiled for AVX2 give the portable build's bits (no fused
/// multiply-adds, the same operations in wider registers), for both precisions, both
/// schemes and both fields. On a CPU without AVX2 there is only one build to run.
#[test]
fn the_avx2_build_of_a_zonal_row_gives_the_portable_bits() {
    #[cfg(target_arch = "x86_64")]
    if std::arch::is_x86_feature_detected!("avx2") {
        same_bits::<f32>();
        same_bits::<f64>();
    } else {
        eprintln!("no AVX2 on this CPU: only the portable build runs");
    }
}

/// Two channels, and one (whose `f32` linear lookups gather in the AVX2 build), on rows
/// whose chunks are partly skipped.
#[cfg(target_arch = "x86_64")]
fn same_bits<T: Sample>() {
    let two = LatLongMap::<T>::from_fn(32, 2, |d, out| {
        out[0] = T::from_f64(d[1].max(0.0).powi(20));
        out[1] = T::from_f64((2.0 * d[1]).exp());
    })
    .unwrap();
    let one = LatLongMap::<T>::from_fn(32, 1, |d, out| {
        out[0] = T::from_f64(d[1].max(0.0).powi(20));
    })
    .unwrap();
    let rotation = SphereRotation::from_degrees(25.0, -70.0, 40.0).unwrap();
    for (lobe, scheme) in [
        (&two, Scheme::Linear),
        (&two, Scheme::Cubic),
        (&one, Scheme::Linear),
    ] {
        let ch = lobe.channels();
        let grad = SourceGradient::with_scheme(lobe, scheme);
        let profile = grad.zonal.as_ref().expect("a zonal source");
        let rule = ChainRule::new(&grad, &rotation, 0);
        let mut largest = T::zero();
        for (kt, first, along) in [
            (3, 1, Along::Theta),
            (6, 2, Along::Phi),
            (40, 1, Along::Theta),
        ] {
            let mut portable = vec![T::zero(); 64 * ch];
            let mut wide = portable.clone();
            rule.zonal_row::<false>(profile, (kt, first), along, -0.1, &mut portable);
            // SAFETY: the caller checked that the CPU has AVX2.
            unsafe { rule.zonal_row_avx2(profile, (kt, first), along, -0.1, &mut wide) };
            let bits = |v: &[T]| v.iter().map(|x| x.as_f64().to_bits()).collect::<Vec<_>>();
            assert_eq!(bits(&portable), bits(&wide), "{scheme:?} {ch} {kt}");
            largest = portable.iter().fold(largest, |a, v| a.max(v.abs()));
        }
        assert!(largest > T::from_f64(1e-3));
    }
}

/// Rows and chunks whose pre-images all lie where the profile is zero are written as
/// zeros without being computed; computing them gives exactly those zeros. A Phong lobe
/// (zero below its horizon: a lower bound on `cos Theta`) and a ring (zero near both
/// poles: both bounds), both schemes, both precisions, rotations that tilt the zero
/// region across the grid.
#[test]
fn skipping_where_the_profile_is_zero_changes_no_value() {
    skips_exactly::<f32>();
    skips_exactly::<f64>();
}

fn skips_exactly<T: Sample>() {
    let phong = LatLongMap::<T>::from_fn(32, 1, |d, out| {
        out[0] = T::from_f64(d[1].max(0.0).powi(20));
    })
    .unwrap();
    let ring = LatLongMap::<T>::from_fn(32, 1, |d, out| {
        out[0] = T::from_f64((0.4 - d[1].abs()).max(0.0));
    })
    .unwrap();
    for (lobe, both) in [(&phong, false), (&ring, true)] {
        for scheme in [Scheme::Linear, Scheme::Cubic] {
            let grad = SourceGradient::with_scheme(lobe, scheme);
            let (low, high) = grad.zonal.as_ref().expect("zonal").cos_bounds;
            assert!(low > -1.0 && low < 0.0, "{low}");
            assert_eq!(high.is_finite(), both, "{high}");
            let mut everything = grad.clone();
            everything.zonal.as_mut().expect("zonal").cos_bounds =
                (f64::NEG_INFINITY, f64::INFINITY);
            for (yaw, pitch, roll) in [(0.0, 0.0, 0.0), (25.0, -70.0, 40.0), (10.0, 120.0, -15.0)] {
                let r = SphereRotation::from_degrees(yaw, pitch, roll).unwrap();
                let skipped = DifferenceFields::from_gradient(&grad, &r, 3);
                let computed = DifferenceFields::from_gradient(&everything, &r, 3);
                assert_eq!(skipped.v, computed.v, "{scheme:?} {pitch}");
                assert_eq!(skipped.u, computed.u, "{scheme:?} {pitch}");
                // Not every value is zero: the comparison is of something.
                let mut values = computed.v.iter().chain(computed.u.iter());
                assert!(values.any(|v| v.abs() > T::from_f64(1e-4)));
            }
        }
    }
}
