use std::path::Path;

use super::*;
use crate::dynamic::fields::Truncation;
use crate::dynamic::{DynamicOptions, DynamicScene};
use crate::test_support::latlong;
use crate::test_support::squashed_sphere;
use crate::{Lighting, SceneFile, refusal_in};
use haarshift::faces::param::SphereMap;
use haarshift::product::Selection;

fn field_options() -> FieldOptions {
    FieldOptions {
        keep: Selection::Largest(20),
        circles: 5,
        circle_points: 12,
        shells: 4,
        shell_grid: 3,
        ..FieldOptions::new(latlong(8))
    }
}

fn written_field(dir: &Path) -> (OcclusionField, PathBuf) {
    let mesh = squashed_sphere();
    let (field, _) = OcclusionField::build(&mesh, &field_options()).unwrap();
    let path = dir.join("object.hsf");
    field.write(&path, &mesh, "test object", false).unwrap();
    (field, path)
}

/// Points about the object: on its ground plane, between shells, inside the innermost one.
const POINTS: [[f64; 3]; 5] = [
    [2.0, -1.0, 0.7],
    [-1.3, 0.4, 2.2],
    [0.35, 0.05, -0.1],
    [4.0, 2.5, -3.0],
    [0.9, -0.99, -0.4],
];

#[test]
fn write_then_read_gives_bit_identical_maps_and_identical_lookups() {
    let dir = tempfile::tempdir().unwrap();
    let (field, path) = written_field(dir.path());
    let bytes = std::fs::metadata(&path).unwrap().len();
    // 16 framing bytes, the header, then (samples + 1) offsets and 8 bytes a coefficient.
    let samples = 5 * 12 + 4 * 6 * 9;
    assert_eq!(field.sample_count(), samples);
    let arrays = (samples as u64 + 1) * 8 + field.coefficient_count() as u64 * 8;
    let (read, header) = OcclusionField::read(&path).unwrap();
    let json = serde_json::to_vec(&header).unwrap().len() as u64;
    assert_eq!(bytes, 16 + 8 + json + arrays);
    assert_eq!(header.samples, samples);
    assert_eq!(header.coefficients, field.coefficient_count());
    assert_eq!(header.shape.source, "test object");
    assert_eq!(header.frame, *field.frame());
    assert_eq!(header.options, FieldRecord::of(&field_options()));
    let bits = |f: &OcclusionField| {
        (0..f.sample_count())
            .flat_map(|i| {
                let (idx, val) = f.map(i);
                idx.iter()
                    .zip(val)
                    .map(move |(&j, v)| (i, j, v.to_bits()))
                    .collect::<Vec<_>>()
            })
            .collect::<Vec<_>>()
    };
    assert_eq!(bits(&read), bits(&field));
    assert_eq!(read, field);
    let loaded = OcclusionField::read_for(&path, &squashed_sphere(), &field_options()).unwrap();
    assert_eq!(loaded, field);
    let texels = latlong(8).texels();
    let mut scratch = vec![0.0; texels];
    let (mut a, mut b) = ((Vec::new(), Vec::new()), (Vec::new(), Vec::new()));
    let mut inside = 0;
    for x in POINTS {
        assert_eq!(loaded.lookup(x), field.lookup(x));
        for truncation in [Truncation::Before, Truncation::After(Selection::Largest(5))] {
            let got = loaded.blended(x, truncation, &mut scratch, &mut a);
            let want = field.blended(x, truncation, &mut scratch, &mut b);
            assert_eq!(got, want);
            assert_eq!(a, b);
            inside += usize::from(got.is_some() && !a.0.is_empty());
        }
    }
    // Every point blends non-empty maps but the one inside the object: within the innermost
    // shell, itself inside the object, every ray from a sample hits it (the map is 0).
    assert_eq!(inside, 2 * (POINTS.len() - 1));
    assert!(field.lookup(POINTS[2]).is_some());
}

fn corrupt_reason(e: SceneError) -> String {
    match e {
        SceneError::FieldCorrupt(r) => r,
        other => panic!("expected a damaged field file, got {other:?}"),
    }
}

#[test]
fn a_truncated_file_a_flipped_byte_and_a_wrong_magic_or_version_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    let (_, path) = written_field(dir.path());
    let good = std::fs::read(&path).unwrap();
    let bad = dir.path().join("bad.hsf");
    let refusal = |bytes: &[u8]| {
        std::fs::write(&bad, bytes).unwrap();
        refusal_in(OcclusionField::read(&bad), &bad)
    };
    // Cut anywhere: the framing's 24 bytes, the header, the arrays, the last byte.
    for len in [0, 7, 12, 23, 24, 40, good.len() / 2, good.len() - 1] {
        let reason = corrupt_reason(refusal(&good[..len]));
        let want = match len {
            0 | 7 => "not a haarshift occlusion field file",
            12 | 23 => "cut short",
            _ => "checksum mismatch",
        };
        assert_eq!(reason, want, "cut to {len} bytes");
    }
    // A flipped byte past the version: every byte of the checksum and header, then every 97th.
    for at in (12..200).chain((200..good.len()).step_by(97)) {
        let mut flipped = good.clone();
        flipped[at] ^= 0x10;
        assert_eq!(
            corrupt_reason(refusal(&flipped)),
            "checksum mismatch",
            "{at}"
        );
    }
    let mut magic = good.clone();
    magic[..8].copy_from_slice(b"HSRCACHE");
    assert_eq!(
        corrupt_reason(refusal(&magic)),
        "not a haarshift occlusion field file"
    );
    let mut version = good.clone();
    // Version 1 had unaligned arrays.
    version[8..12].copy_from_slice(&1u32.to_le_bytes());
    assert_eq!(
        refusal(&version),
        SceneError::FieldVersion {
            found: 1,
            expected: 2
        }
    );
    assert!(
        refusal(&version)
            .to_string()
            .contains("format version 1, this build reads version 2")
    );
}

/// `good` with its body replaced by `f(body)` and the checksum made right again: what a
/// damaged file the checksum cannot catch looks like.
fn rechecksummed(good: &[u8], f: impl FnOnce(&mut Vec<u8>)) -> Vec<u8> {
    let mut body = good[16..].to_vec();
    f(&mut body);
    let mut out = good[..12].to_vec();
    out.extend_from_slice(&crc32fast::hash(&body).to_le_bytes());
    out.extend_from_slice(&body);
    out
}

#[test]
fn a_file_that_passes_its_checksum_but_holds_no_field_is_refused_without_a_panic() {
    let dir = tempfile::tempdir().unwrap();
    let (field, path) = written_field(dir.path());
    let good = std::fs::read(&path).unwrap();
    let bad = dir.path().join("bad.hsf");
    let refusal = |bytes: Vec<u8>| {
        std::fs::write(&bad, bytes).unwrap();
        corrupt_reason(refusal_in(OcclusionField::read(&bad), &bad))
    };
    // The last coefficient's index (just before the values) pointing beyond the map.
    let n = field.coefficient_count();
    let beyond = rechecksummed(&good, |b| {
        let at = b.len() - 4 * n - 4;
        b[at..at + 4].copy_from_slice(&(latlong(8).texels() as u32).to_le_bytes());
    });
    assert!(refusal(beyond).contains("do not describe"));
    // A NaN value.
    let nan = rechecksummed(&good, |b| {
        let at = b.len() - 4;
        b[at..].copy_from_slice(&f32::NAN.to_le_bytes());
    });
    assert!(refusal(nan).contains("do not describe"));
    // Trailing bytes, and a header whose options place no field (one circle).
    let trailing = rechecksummed(&good, |b| b.extend_from_slice(&[0; 4]));
    assert_eq!(refusal(trailing), "bytes after the maps");
    let one_circle = rechecksummed(&good, |b| {
        let at = b.windows(11).position(|w| w == b"\"circles\":5").unwrap();
        b[at + 10] = b'1';
    });
    assert!(refusal(one_circle).contains("circles"));
}

fn mismatch(result: Result<OcclusionField>, path: &Path) -> String {
    match refusal_in(result, path) {
        SceneError::FieldMismatch(r) => r,
        other => panic!("expected a mismatch, got {other:?}"),
    }
}

#[test]
fn a_file_built_with_other_options_or_for_another_mesh_is_refused_naming_the_difference() {
    let dir = tempfile::tempdir().unwrap();
    let (_, path) = written_field(dir.path());
    let mesh = squashed_sphere();
    let base = field_options();
    let cases: [(FieldOptions, &str); 9] = [
        (FieldOptions { circles: 6, ..base }, "circles 5 (asked: 6)"),
        (
            FieldOptions {
                circle_points: 13,
                ..base
            },
            "circle_points 12 (asked: 13)",
        ),
        (
            FieldOptions {
                circle_radii: (0.05, 9.0),
                ..base
            },
            "circle_radii [0.05,10.0] (asked: [0.05,9.0])",
        ),
        (FieldOptions { shells: 3, ..base }, "shells 4 (asked: 3)"),
        (
            FieldOptions {
                shell_grid: 4,
                ..base
            },
            "shell_grid 3 (asked: 4)",
        ),
        (
            FieldOptions {
                shell_radii: (0.2, 6.000000000000001),
                ..base
            },
            "shell_radii [0.2,6.0] (asked: [0.2,6.000000000000001])",
        ),
        (
            FieldOptions {
                keep: Selection::Largest(19),
                ..base
            },
            r#"keep {"largest":20} (asked: {"largest":19})"#,
        ),
        (
            FieldOptions {
                param: latlong(16),
                ..base
            },
            "resolution 8 (asked: 16)",
        ),
        (
            FieldOptions {
                param: Parameterization::new(ParamKind::Cube, 8).unwrap(),
                ..base
            },
            r#"param "latlong" (asked: "cube")"#,
        ),
    ];
    for (asked, want) in cases {
        let reason = mismatch(OcclusionField::read_for(&path, &mesh, &asked), &path);
        assert_eq!(reason, format!("with other options: {want}"));
    }
    // Another mesh: the same sphere moved by a hair, and another sphere.
    let moved = mesh.mapped(|p| [p[0] + 1e-9, p[1], p[2]], |n| n).unwrap();
    let other = Generator::Sphere { cells: 2 }.mesh().unwrap();
    for m in [&moved, &other] {
        let reason = mismatch(OcclusionField::read_for(&path, m, &base), &path);
        assert!(
            reason.starts_with("for another mesh (test object: 96 vertices"),
            "{reason}"
        );
    }
    let e = OcclusionField::read_for(&path, &other, &base).unwrap_err();
    assert!(e.to_string().contains("built for another mesh"), "{e}");
    // The progress bar decides nothing.
    let quiet = FieldOptions {
        progress: true,
        ..base
    };
    assert!(OcclusionField::read_for(&path, &mesh, &quiet).is_ok());
    // A field is written only with the mesh it was built from.
    let (field, _) = OcclusionField::read(&path).unwrap();
    assert_err!(
        field.write(&dir.path().join("x.hsf"), &other, "x", false),
        InvalidParameter { name: "mesh", .. },
        "the field was not built from this mesh"
    );
}

#[test]
fn a_store_reads_what_matches_builds_what_is_absent_and_refuses_what_is_stale() {
    let dir = tempfile::tempdir().unwrap();
    let mesh = squashed_sphere();
    let generator = Generator::Sphere { cells: 3 };
    let mut store = FieldStore::new(dir.path(), false);
    let path = dir.path().join("sphere-cells-3.hsf");
    let (built, origin) = store
        .field(&mesh, None, Some(&generator), &field_options())
        .unwrap();
    let FieldOrigin::Built { report, bytes } = origin else {
        panic!("{origin:?}")
    };
    assert_eq!(report.rays, built.sample_count() as u64 * 128);
    assert_eq!(bytes, std::fs::metadata(&path).unwrap().len());
    let (loaded, origin) = store
        .field(&mesh, None, Some(&generator), &field_options())
        .unwrap();
    assert!(matches!(origin, FieldOrigin::Loaded { bytes: b, .. } if b == bytes));
    assert_eq!(loaded, built);
    // Other options: refused, the file untouched; a store that may replace builds again.
    let other = FieldOptions {
        shells: 5,
        ..field_options()
    };
    let reason = mismatch(
        store
            .field(&mesh, None, Some(&generator), &other)
            .map(|f| f.0),
        &path,
    );
    assert!(reason.contains("shells 4 (asked: 5)"), "{reason}");
    assert_eq!(std::fs::metadata(&path).unwrap().len(), bytes);
    let mut replacing = FieldStore::new(dir.path(), true);
    let (rebuilt, origin) = replacing
        .field(&mesh, None, Some(&generator), &other)
        .unwrap();
    assert!(matches!(origin, FieldOrigin::Built { .. }));
    assert_eq!(rebuilt.sample_count(), 5 * 12 + 5 * 6 * 9);
    assert_eq!(
        OcclusionField::read_for(&path, &mesh, &other).unwrap(),
        rebuilt
    );
    // Two sources that would share one file name.
    let (a, b) = (Path::new("a/ball.ply"), Path::new("b/ball.ply"));
    store.field(&mesh, Some(a), None, &field_options()).unwrap();
    let e = store
        .field(&mesh, Some(b), None, &field_options())
        .unwrap_err()
        .to_string();
    assert!(e.contains("would share the field file"), "{e}");
}

#[test]
fn a_scene_shaded_from_loaded_fields_equals_one_from_fields_built_afresh() {
    let file: SceneFile = serde_json::from_str(
        r#"{"objects": [
            {"name": "big", "generator": {"sphere": {"cells": 3}}, "transform": {"translate": [0, 1, 0]}},
            {"name": "ball", "generator": {"sphere": {"cells": 2}},
             "transform": {"translate": [1.8, 0.4, 0.3], "scale": 0.4, "yaw": 45}}],
          "ground_plane": true}"#,
    )
    .unwrap();
    let mut dynamic = DynamicOptions::new(latlong(8));
    dynamic.field = FieldOptions {
        keep: Selection::Largest(30),
        ..field_options()
    };
    let sky = SphereMap::<f64>::from_fn(latlong(8), 3, |d, out| {
        let sun = (d[0] + 0.5 * d[1]).max(0.0).powi(8);
        out.iter_mut()
            .enumerate()
            .for_each(|(c, o)| *o = 0.3 + (4.0 - c as f64) * sun);
    })
    .unwrap();
    let lighting = Lighting::from_map(&sky, Selection::All).unwrap();
    let dir = tempfile::tempdir().unwrap();
    let here = Path::new(".");
    let fresh = DynamicScene::build(&file, here, &dynamic).unwrap();
    let mut store = FieldStore::new(dir.path(), false);
    let first = DynamicScene::build_with(&file, here, &dynamic, Some(&mut store)).unwrap();
    let second = DynamicScene::build_with(&file, here, &dynamic, Some(&mut store)).unwrap();
    let (r1, r2) = (first.report(), second.report());
    assert_eq!((r1.fields_written, r1.fields_loaded), (2, 0));
    assert_eq!(
        (r2.fields_written, r2.fields_loaded, r2.field_rays),
        (0, 2, 0)
    );
    assert_eq!(r1.field_file_bytes, r2.field_file_bytes);
    assert!(r2.field_load_seconds > 0.0);
    for k in 0..2 {
        assert_eq!(second.field(k), fresh.field(k));
    }
    let want = fresh.shade::<f64>(&lighting).unwrap();
    let got = second.shade::<f64>(&lighting).unwrap();
    assert!(want.iter().any(|&x| x > 0.0));
    assert_eq!(got, want);
}
