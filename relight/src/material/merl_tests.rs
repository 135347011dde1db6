use std::f64::consts::{FRAC_PI_2, PI};

use super::*;

/// The unit directions of Rusinkiewicz angles, by the definition: the difference vector
/// `d(theta_diff, phi_diff)` and the half vector `z` rotated together by `theta_half` about `y`
/// and `phi_half` about `z`; `w_o` is `w_i` mirrored about the half vector.
fn rusinkiewicz_directions(
    theta_h: f64,
    phi_h: f64,
    theta_d: f64,
    phi_d: f64,
) -> ([f64; 3], [f64; 3]) {
    let rotate = |v: [f64; 3]| {
        let (s, c) = theta_h.sin_cos();
        let v = [c * v[0] + s * v[2], v[1], -s * v[0] + c * v[2]];
        let (s, c) = phi_h.sin_cos();
        [c * v[0] - s * v[1], s * v[0] + c * v[1], v[2]]
    };
    let d = [
        theta_d.sin() * phi_d.cos(),
        theta_d.sin() * phi_d.sin(),
        theta_d.cos(),
    ];
    let (wi, h) = (rotate(d), rotate([0.0, 0.0, 1.0]));
    let k = 2.0 * (0..3).map(|i| wi[i] * h[i]).sum::<f64>();
    (wi, std::array::from_fn(|i| k * h[i] - wi[i]))
}

/// A deterministic sequence in `[0, 1)`.
fn uniform(seed: &mut u64) -> f64 {
    *seed = seed
        .wrapping_mul(6364136223846793005)
        .wrapping_add(1442695040888963407);
    (*seed >> 11) as f64 / (1u64 << 53) as f64
}

#[test]
fn half_diff_inverts_the_definition() {
    let mut seed = 7;
    for _ in 0..2000 {
        let th = uniform(&mut seed) * 1.2;
        let td = uniform(&mut seed) * 1.5;
        let pd = (uniform(&mut seed) * 2.0 - 1.0) * PI * 0.999;
        let ph = uniform(&mut seed) * 2.0 * PI;
        let (wi, wo) = rusinkiewicz_directions(th, ph, td, pd);
        let (a, b, c) = half_diff(wi, wo).unwrap();
        assert!(
            (a - th).abs() < 1e-9 && (b - td).abs() < 1e-9 && (c - pd).abs() < 1e-9,
            "({th}, {td}, {pd}) came back as ({a}, {b}, {c})"
        );
    }
    assert_eq!(half_diff([0.0, 0.0, 1.0], [0.0, 0.0, -1.0]), None);
}

/// A table whose every entry, in every channel, is its own index within the block (so a
/// lookup says which bin it used).
fn index_table() -> MerlBrdf {
    let entries = (0..3 * SAMPLES).map(|k| (k % SAMPLES) as f64).collect();
    MerlBrdf::from_entries(None, entries).unwrap()
}

#[test]
fn a_lookup_uses_the_bins_of_the_reference_formulas() {
    let table = index_table();
    let [nh, nd, np] = DIMENSIONS;
    let mut seed = 11;
    let mut checked = 0;
    for _ in 0..5000 {
        // A bin, and a point strictly inside it (away from the edges' rounding).
        let bins = [
            (uniform(&mut seed) * nh as f64) as usize,
            (uniform(&mut seed) * nd as f64) as usize,
            (uniform(&mut seed) * np as f64) as usize,
        ];
        let [u, v, w] = [
            0.1 + 0.8 * uniform(&mut seed),
            0.1 + 0.8 * uniform(&mut seed),
            0.1 + 0.8 * uniform(&mut seed),
        ];
        // theta_half on the square-root scale, the others linear; phi_diff either itself or
        // (reciprocity) itself minus pi.
        let th = ((bins[0] as f64 + u) / nh as f64).powi(2) * FRAC_PI_2;
        let td = (bins[1] as f64 + v) / nd as f64 * FRAC_PI_2;
        let mut pd = (bins[2] as f64 + w) / np as f64 * PI;
        if uniform(&mut seed) < 0.5 {
            pd -= PI;
        }
        let (wi, wo) = rusinkiewicz_directions(th, uniform(&mut seed) * 2.0 * PI, td, pd);
        if wi[2] <= 0.0 || wo[2] <= 0.0 {
            continue;
        }
        checked += 1;
        let got = table.evaluate(wi, wo);
        let want = MerlBrdf::index(bins) as f64;
        for c in 0..3 {
            assert!(
                (got[c] - want * CHANNEL_SCALES[c]).abs() <= 1e-9 * want,
                "bins {bins:?}, channel {c}: {} is entry {}",
                got[c],
                got[c] / CHANNEL_SCALES[c]
            );
        }
    }
    assert!(checked > 2000, "{checked}");
    // Past the last bin: clamped.
    assert_eq!(MerlBrdf::bins(2.0, 2.0, PI), [89, 89, 179]);
}

#[test]
fn from_fn_samples_the_grid_points() {
    let m = MerlBrdf::from_fn(|th, td, pd| [th, td, pd]).unwrap();
    for bins in [[0, 0, 0], [1, 2, 3], [45, 17, 100], [89, 89, 179]] {
        let want = MerlBrdf::grid_point(bins);
        let got = m.at(bins);
        for (g, w) in got.iter().zip([want.0, want.1, want.2]) {
            assert!((g - w).abs() < 1e-15, "{bins:?}: {got:?} vs {want:?}");
        }
    }
    assert_eq!(
        MerlBrdf::grid_point([45, 0, 90]),
        (FRAC_PI_2 / 4.0, 0.0, FRAC_PI_2)
    );
}

/// A MERL file's bytes: `dims`, then the entries `f(k)` for `k` in `0..3 SAMPLES`.
fn file_bytes(dims: [i32; 3], f: impl Fn(usize) -> f64) -> Vec<u8> {
    let mut bytes: Vec<u8> = dims.iter().flat_map(|d| d.to_le_bytes()).collect();
    bytes.extend((0..3 * SAMPLES).flat_map(|k| f(k).to_le_bytes()));
    bytes
}

#[test]
fn a_file_round_trips_and_reads_unmeasured_entries_as_zero() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("m.binary");
    // Every 1000th entry "not measured".
    let value = |k: usize| {
        if k.is_multiple_of(1000) {
            -1.0
        } else {
            (k % 977) as f64 * 0.5
        }
    };
    std::fs::write(&path, file_bytes([90, 90, 180], value)).unwrap();
    let m = MerlBrdf::read(&path).unwrap();
    assert_eq!(m.unmeasured(), 3 * SAMPLES / 1000);
    for k in [0, 1, 999, 1000, 1001, SAMPLES + 5, 3 * SAMPLES - 1] {
        let (c, within) = (k / SAMPLES, k % SAMPLES);
        let [_, nd, np] = DIMENSIONS;
        let bins = [within / (nd * np), within / np % nd, within % np];
        assert_eq!(
            m.at(bins)[c],
            value(k).max(0.0) * CHANNEL_SCALES[c],
            "entry {k}"
        );
    }
    let copy = dir.path().join("copy.binary");
    m.write(&copy, false).unwrap();
    let back = MerlBrdf::read(&copy).unwrap();
    assert_eq!(back.entries, m.entries);
    assert_eq!(back.path(), Some(copy.as_path()));
    assert_err!(m.write(&copy, false), OutputExists { .. }, "already exists");
}

/// The [`MerlError`] of reading `bytes` from a file, which the error must name.
fn merl_refusal(bytes: &[u8]) -> MerlError {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("bad.binary");
    std::fs::write(&path, bytes).unwrap();
    match MerlBrdf::read(&path) {
        Err(Error::Merl { path: p, source }) if p == path => {
            let line = Error::Merl {
                path: p,
                source: source.clone(),
            }
            .to_string();
            assert!(line.starts_with(&path.display().to_string()) && !line.contains('\n'));
            source
        }
        other => panic!("expected a MERL error naming the file, got {other:?}"),
    }
}

#[test]
fn bad_files_are_refused_naming_the_problem() {
    let mut good = file_bytes([90, 90, 180], |k| (k % 7) as f64);
    let size = good.len() as u64;
    assert_eq!(size, FILE_BYTES);
    assert_eq!(merl_refusal(&good[..5]), MerlError::Truncated { bytes: 5 });
    assert_eq!(
        merl_refusal(&good[..good.len() - 1]),
        MerlError::Truncated { bytes: size - 1 }
    );
    let mut wrong = good[..100].to_vec();
    wrong[8..12].copy_from_slice(&360i32.to_le_bytes());
    assert_eq!(
        merl_refusal(&wrong),
        MerlError::Dimensions {
            found: [90, 90, 360]
        }
    );
    good.extend_from_slice(&[0; 8]);
    assert_eq!(merl_refusal(&good), MerlError::TooLarge { bytes: size + 8 });
    good.truncate(size as usize);
    // The green block's entry at bins (2, 3, 4) is NaN.
    let at = 12 + 8 * (SAMPLES + MerlBrdf::index([2, 3, 4]));
    good[at..at + 8].copy_from_slice(&f64::NAN.to_le_bytes());
    match merl_refusal(&good) {
        MerlError::NonFinite {
            channel: "green",
            bin: [2, 3, 4],
            value,
        } if value.is_nan() => {}
        other => panic!("{other:?}"),
    }
    assert_err!(
        MerlBrdf::read("no/such/file.binary".as_ref()),
        Io { .. },
        "no/such/file.binary"
    );
}

/// Phong of `exponent` as a MERL table: each grid point's directions (the definition above,
/// `phi_half = 0`) evaluated by [`crate::Brdf::Phong`] about the normal `z`.
pub(crate) fn phong_table(exponent: f64) -> MerlBrdf {
    let phong = crate::Brdf::Phong { exponent };
    MerlBrdf::from_fn(|th, td, pd| {
        let (wi, wo) = rusinkiewicz_directions(th, 0.0, td, pd);
        phong.evaluate([0.0, 0.0, 1.0], wi, wo)
    })
    .unwrap()
}

/// Phong of `exponent` as a table sampled at its bins' centres (`theta_half` at the centre of
/// its square-root scale), not at their lower corners as [`MerlBrdf::from_fn`] does.
pub(crate) fn phong_table_at_centres(exponent: f64) -> MerlBrdf {
    let phong = crate::Brdf::Phong { exponent };
    let [nh, nd, np] = DIMENSIONS;
    let mut entries = vec![0.0; 3 * SAMPLES];
    for i in 0..nh {
        for j in 0..nd {
            for k in 0..np {
                let th = ((i as f64 + 0.5) / nh as f64).powi(2) * FRAC_PI_2;
                let td = (j as f64 + 0.5) / nd as f64 * FRAC_PI_2;
                let pd = (k as f64 + 0.5) / np as f64 * PI;
                let (wi, wo) = rusinkiewicz_directions(th, 0.0, td, pd);
                let v = phong.evaluate([0.0, 0.0, 1.0], wi, wo);
                for c in 0..3 {
                    entries[c * SAMPLES + MerlBrdf::index([i, j, k])] = v[c] / CHANNEL_SCALES[c];
                }
            }
        }
    }
    MerlBrdf::from_entries(None, entries).unwrap()
}

#[test]
fn a_phong_table_returns_phong_at_its_grid_points() {
    let table = phong_table(20.0);
    let phong = crate::Brdf::Phong { exponent: 20.0 };
    // At a grid point nudged into its bin, the lookup is the grid point's exact value.
    for bins in [[0, 0, 0], [3, 10, 20], [20, 30, 170], [40, 5, 90]] {
        let (th, td, pd) = MerlBrdf::grid_point(bins);
        let (wi, wo) = rusinkiewicz_directions(th + 1e-9, 0.4, td + 1e-9, pd + 1e-9);
        let want = phong.evaluate([0.0, 0.0, 1.0], wi, wo)[0];
        let got = table.evaluate(wi, wo);
        assert!(
            got.iter().all(|g| (g - want).abs() < 1e-6 * want.max(1e-3)),
            "{bins:?}: {got:?} vs {want}"
        );
    }
}
