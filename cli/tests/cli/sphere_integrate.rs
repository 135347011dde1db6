//! `haarshift sphere integrate` end to end: the printed integral equals the pixel-domain
//! contract computed here independently, `--keep` equals the same sum over the pruned maps,
//! and every bad request fails in one line.

use std::path::{Path, PathBuf};

use crate::common::maps::{planes, pruned, write_map};
use crate::common::{fails_cleanly, p, succeeds_with_stdout};

use haarshift::SampleDepth;
use ndarray::Array3;

/// The solid angle of a pixel of row `i` of an `h x 2h` map: `(pi / h)(cos theta_i -
/// cos theta_i+1)`.
fn solid_angle(h: usize, i: usize) -> f64 {
    let step = std::f64::consts::PI / h as f64;
    step * ((i as f64 * step).cos() - ((i + 1) as f64 * step).cos())
}

/// `sum over pixels of prod_k f_k(p) x solid_angle(p)` for channel `c` (one-channel maps
/// broadcast).
fn pixel_sum(maps: &[Array3<f64>], c: usize) -> f64 {
    let (_, h, w) = maps[0].dim();
    let mut sum = 0.0;
    for i in 0..h {
        for j in 0..w {
            let prod: f64 = maps
                .iter()
                .map(|m| m[[c.min(m.dim().0 - 1), i, j]])
                .product();
            sum += prod * solid_angle(h, i);
        }
    }
    sum
}

/// The integrals printed for each channel.
fn integrals(stdout: &str) -> Vec<f64> {
    stdout
        .lines()
        .filter_map(|l| l.split("integral ").nth(1))
        .map(|v| v.trim().parse().unwrap())
        .collect()
}

fn close(got: f64, want: f64, tolerance: f64) -> bool {
    (got - want).abs() <= tolerance * want.abs()
}

#[test]
fn the_printed_integral_is_the_pixel_sum_with_solid_angles() {
    let dir = tempfile::tempdir().unwrap();
    let maps = [planes(16, 3, 1), planes(16, 1, 2), planes(16, 3, 3)];
    let paths: Vec<PathBuf> = maps
        .iter()
        .enumerate()
        .map(|(k, m)| write_map(dir.path(), &format!("m{k}.npy"), m, SampleDepth::F64))
        .collect();
    for method in ["tree", "triple", "pixel", "pairwise"] {
        let mut args = vec!["sphere", "integrate"];
        args.extend(paths.iter().map(|q| p(q)));
        args.extend(["--method", method]);
        let got = integrals(&succeeds_with_stdout(&args));
        assert_eq!(got.len(), 3, "{method}");
        for (c, &g) in got.iter().enumerate() {
            let want = pixel_sum(&maps, c);
            assert!(close(g, want, 1e-9), "{method} channel {c}: {g} vs {want}");
        }
    }
}

#[test]
fn keep_is_the_pixel_sum_of_the_pruned_maps() {
    let dir = tempfile::tempdir().unwrap();
    let (h, k) = (16, 40);
    let (f, g) = (planes(h, 1, 4), planes(h, 1, 5));
    let (fp, gp) = (
        write_map(dir.path(), "f.npy", &f, SampleDepth::F64),
        write_map(dir.path(), "g.npy", &g, SampleDepth::F64),
    );
    // The first map is weighted by the solid angle before its coefficients are selected.
    let mut weighted = f.index_axis(ndarray::Axis(0), 0).to_owned();
    for ((i, _), v) in weighted.indexed_iter_mut() {
        *v *= solid_angle(h, i);
    }
    let fk = pruned(&weighted, k);
    let gk = pruned(&g.index_axis(ndarray::Axis(0), 0).to_owned(), k);
    let want: f64 = (&fk * &gk).sum();
    let full = integrals(&succeeds_with_stdout(&[
        "sphere",
        "integrate",
        p(&fp),
        p(&gp),
    ]))[0];
    let got = integrals(&succeeds_with_stdout(&[
        "sphere",
        "integrate",
        p(&fp),
        p(&gp),
        "--keep",
        &k.to_string(),
    ]))[0];
    assert!(close(got, want, 1e-9), "{got} vs {want}");
    assert!(
        !close(got, full, 1e-6),
        "--keep {k} left the integral at {full}"
    );
    let json = dir.path().join("r.json");
    succeeds_with_stdout(&[
        "sphere",
        "integrate",
        p(&fp),
        p(&gp),
        "--keep",
        "40,7",
        "--json",
        p(&json),
    ]);
    let records: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    assert_eq!(records[0]["kept"], serde_json::json!([40, 7]));
    assert_eq!(records[0]["method"], "tree");
    assert!(records[0]["visited"].as_u64().unwrap() > 0);
}

#[test]
fn bad_requests_fail_in_one_line() {
    let dir = tempfile::tempdir().unwrap();
    let a = write_map(dir.path(), "a.npy", &planes(16, 1, 6), SampleDepth::F64);
    let b = write_map(dir.path(), "b.npy", &planes(8, 1, 7), SampleDepth::F64);
    let odd = write_map(dir.path(), "odd.npy", &planes(6, 1, 8), SampleDepth::F64);
    let mut nan_planes = planes(16, 1, 9);
    nan_planes[[0, 3, 4]] = f64::NAN;
    let nan = dir.path().join("nan.npy");
    ndarray_npy_write(&nan, &nan_planes);
    let (a, b, odd) = (p(&a), p(&b), p(&odd));
    fails_cleanly(&["sphere", "integrate", a, b], &["different sizes"]);
    fails_cleanly(&["sphere", "integrate", odd, odd], &["not a power of two"]);
    fails_cleanly(
        &["sphere", "integrate", a, a, "--keep", "512"],
        &["keep", "only 510"],
    );
    fails_cleanly(
        &["sphere", "integrate", a, a, "--depth", "4"],
        &["depth", "level 4"],
    );
    fails_cleanly(
        &["sphere", "integrate", a, p(&nan)],
        &["nan.npy", "non-finite"],
    );
    fails_cleanly(
        &["sphere", "integrate", a, a, "--method", "triple"],
        &["method", "exactly 3"],
    );
}

/// Writes `(channels, h, w)` planes as an `(h, w, channels)` f64 `.npy` without the library's
/// checks (so that it can hold a NaN).
fn ndarray_npy_write(path: &Path, planes: &Array3<f64>) {
    let hwc = planes.view().permuted_axes([1, 2, 0]);
    let (h, w, c) = hwc.dim();
    let mut bytes = Vec::new();
    let header = format!("{{'descr': '<f8', 'fortran_order': False, 'shape': ({h}, {w}, {c}), }}");
    let pad = 64 - (10 + header.len() + 1) % 64;
    let header = format!("{header}{}\n", " ".repeat(pad % 64));
    bytes.extend_from_slice(b"\x93NUMPY\x01\x00");
    bytes.extend_from_slice(&(header.len() as u16).to_le_bytes());
    bytes.extend_from_slice(header.as_bytes());
    for v in hwc.as_standard_layout().iter() {
        bytes.extend_from_slice(&v.to_le_bytes());
    }
    std::fs::write(path, bytes).unwrap();
}
