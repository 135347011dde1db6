use std::path::{Path, PathBuf};

use super::*;
use crate::precompute::{PrecomputeOptions, precompute, precompute_shard};
use crate::{Generator, Scene, VisibilityOptions};
use haarshift::faces::{ParamKind, Parameterization};

/// A ground of 9 vertices (vertex 4 at the origin) under a box (vertices 9 to 158) whose
/// bottom is 0.5 above it: the box shadows the ground from outside its vertex range.
fn box_scene() -> Scene {
    let mesh = Generator::PlaneUnderBox { height: 0.5 }.mesh().unwrap();
    Scene::from_mesh(mesh, false).unwrap()
}

/// Cube 8, 2 x 2 jittered rays a texel (the jitter is what depends on the vertex index), the
/// 3-band spherical-harmonic transfer beside the Haar transport.
fn jittered_cube_options() -> PrecomputeOptions {
    let mut visibility = VisibilityOptions::new(Parameterization::new(ParamKind::Cube, 8).unwrap());
    visibility.samples = 2;
    visibility.seed = 7;
    visibility.sh_bands = Some(3);
    PrecomputeOptions::new(visibility)
}

fn shard(index: usize, count: usize) -> CacheShard {
    let shard = Shard::new(index, count).unwrap();
    precompute_shard(box_scene(), &jittered_cube_options(), shard)
        .unwrap()
        .0
}

/// Shards `0..count` written as `part-I.hsr` in `dir`.
fn written_shards(dir: &Path, count: usize) -> Vec<PathBuf> {
    (0..count)
        .map(|i| {
            let path = dir.join(format!("part-{i}.hsr"));
            shard(i, count).write(&path, false).unwrap();
            path
        })
        .collect()
}

/// The one-line refusal of merging `paths`, which must name `culprit`.
fn merge_refusal(paths: &[PathBuf], culprit: &Path) -> String {
    let e = merge_shards(paths).unwrap_err();
    let message = e.to_string();
    assert!(
        message.starts_with(&format!("{}: ", culprit.display())),
        "{message}"
    );
    assert!(!message.contains('\n'), "{message}");
    message
}

#[test]
fn a_shard_has_the_bits_of_the_whole_whatever_the_count() {
    let (whole, _) = precompute(box_scene(), &jittered_cube_options()).unwrap();
    let sh = |t: &TransportSet, v: usize| t.sh().unwrap().coefficients().row(v).to_vec();
    for count in [1, 2, 3, 7, 17] {
        let mut next = 0;
        for index in 0..count {
            let part = shard(index, count);
            assert_eq!(part.record.first, next, "{index}/{count}");
            for k in 0..part.transport.vertex_count() {
                let v = part.record.first + k;
                assert_eq!(
                    part.transport.coefficients(k),
                    whole.transport.coefficients(v),
                    "vertex {v} in shard {index}/{count}"
                );
                assert_eq!(sh(&part.transport, k), sh(&whole.transport, v));
            }
            next = part.record.end;
        }
        assert_eq!(next, 159);
    }
    // Shard 0/17 is the ground alone, 0..9; its vertex 4, under the box, sees the sky only
    // below about 27 degrees of elevation: its transport integrates to about 0.2 pi, not pi.
    let ground = shard(0, 17);
    assert_eq!((ground.record.first, ground.record.end), (0, 9));
    let seen: f32 = ground
        .transport
        .transport(4)
        .unwrap()
        .tree()
        .to_pixels()
        .unwrap()
        .sum();
    assert!(seen > 0.2 && seen < 1.0, "{seen}");
}

#[test]
fn merged_shards_are_the_whole_cache_byte_for_byte() {
    let dir = tempfile::tempdir().unwrap();
    let whole = dir.path().join("whole.hsr");
    let (cache, _) = precompute(box_scene(), &jittered_cube_options()).unwrap();
    cache.write(&whole, false).unwrap();
    for count in [1, 3, 7] {
        let sub = dir.path().join(count.to_string());
        std::fs::create_dir(&sub).unwrap();
        let mut parts = written_shards(&sub, count);
        parts.reverse(); // any order
        let merged = merge_shards(&parts).unwrap();
        assert_eq!(merged, cache);
        let out = sub.join("merged.hsr");
        merged.write(&out, false).unwrap();
        assert_eq!(std::fs::read(&out).unwrap(), std::fs::read(&whole).unwrap());
    }
}

#[test]
fn merge_refuses_gaps_overlaps_strangers_and_damage_naming_the_file() {
    let dir = tempfile::tempdir().unwrap();
    let parts = written_shards(dir.path(), 3); // 0..53, 53..106, 106..159
    let missing = merge_refusal(&[parts[0].clone(), parts[2].clone()], &parts[2]);
    assert!(
        missing.ends_with("vertices 53..106 are in no shard (before shard 2/3)"),
        "{missing}"
    );
    let last = merge_refusal(&parts[1..], &parts[1]);
    assert!(
        last.ends_with("vertices 0..53 are in no shard (before shard 1/3)"),
        "{last}"
    );
    let twice = [parts.clone(), vec![parts[1].clone()]].concat();
    let message = merge_refusal(&twice, &parts[1]);
    assert!(
        message.ends_with(&format!(
            "vertices 53..106 of shard 1/3 are also in {}",
            parts[1].display()
        )),
        "{message}"
    );
    // Overlapping shards of different counts: 2/7 is 45..68.
    let odd = dir.path().join("odd.hsr");
    shard(2, 7).write(&odd, false).unwrap();
    let message = merge_refusal(&[parts.clone(), vec![odd.clone()]].concat(), &odd);
    assert!(
        message.contains("vertices 45..53 of shard 2/7 are also in"),
        "{message}"
    );

    // Another scene: the box 0.25 higher.
    let other = dir.path().join("other-scene.hsr");
    let mesh = Generator::PlaneUnderBox { height: 0.75 }.mesh().unwrap();
    let scene = Scene::from_mesh(mesh, false).unwrap();
    let part = precompute_shard(scene, &jittered_cube_options(), Shard::new(1, 3).unwrap())
        .unwrap()
        .0;
    part.write(&other, false).unwrap();
    let message = merge_refusal(&[parts[0].clone(), other.clone(), parts[2].clone()], &other);
    assert!(
        message.contains("shard 1/3 has another mesh (159 vertices, hash"),
        "{message}"
    );

    // Other options: another seed of the jitter.
    let reseeded = dir.path().join("other-options.hsr");
    let mut seed = jittered_cube_options();
    seed.visibility.seed = 8;
    let part = precompute_shard(box_scene(), &seed, Shard::new(1, 3).unwrap())
        .unwrap()
        .0;
    part.write(&reseeded, false).unwrap();
    let message = merge_refusal(
        &[parts[0].clone(), reseeded.clone(), parts[2].clone()],
        &reseeded,
    );
    assert!(
        message.ends_with(&format!(
            "not a shard of the same scene and options: shard 1/3 has other options (seed 8, not 7) than {}",
            parts[0].display()
        )),
        "{message}"
    );

    // A truncated shard fails its checksum.
    let cut = dir.path().join("cut.hsr");
    let bytes = std::fs::read(&parts[1]).unwrap();
    std::fs::write(&cut, &bytes[..bytes.len() - 100]).unwrap();
    let message = merge_refusal(&[parts[0].clone(), cut.clone(), parts[2].clone()], &cut);
    assert!(message.ends_with("scene cache is damaged (checksum mismatch); compute it again"));

    // A whole cache is not a shard, and a shard is not a whole cache.
    let whole = dir.path().join("whole.hsr");
    precompute(box_scene(), &jittered_cube_options())
        .unwrap()
        .0
        .write(&whole, false)
        .unwrap();
    let message = merge_refusal(&[parts[0].clone(), whole.clone()], &whole);
    assert!(
        message.ends_with("is a whole scene cache, not a shard"),
        "{message}"
    );
    let e = SceneCache::read(&parts[1]).unwrap_err().to_string();
    assert_eq!(
        e,
        format!(
            "{}: is shard 1/3 of a scene cache (vertices 53..106), not a whole cache: merge \
             the shards with `haarshift relight merge`",
            parts[1].display()
        )
    );
    assert_err!(
        merge_shards(&[]),
        InvalidParameter { name: "shards", .. },
        "give at least one shard to merge"
    );
}

#[test]
fn sharded_bounces_merged_bounce_by_bounce_are_the_unsharded_cache_byte_for_byte() {
    use crate::precompute::{precompute_bounce_shard, shard_is_done};
    let dir = tempfile::tempdir().unwrap();
    // A coloured albedo: three channels of bounced light.
    let scene = || {
        let mut s = box_scene();
        s.albedo.column_mut(1).fill(0.4);
        s
    };
    let mut options = jittered_cube_options();
    let merged_of = |parts: &[PathBuf], name: &str| {
        let path = dir.path().join(name);
        merge_shards(parts).unwrap().write(&path, false).unwrap();
        path
    };
    let direct: Vec<PathBuf> = (0..3)
        .map(|i| {
            let path = dir.path().join(format!("d-{i}.hsr"));
            let (part, _) = precompute_shard(scene(), &options, Shard::new(i, 3).unwrap()).unwrap();
            part.write(&path, false).unwrap();
            path
        })
        .collect();
    let mut merged = merged_of(&direct, "b0.hsr");
    for b in 1..=2 {
        options.bounces = b;
        let from = SceneCache::read(&merged).unwrap();
        let parts: Vec<PathBuf> = (0..3)
            .map(|i| {
                let shard = Shard::new(i, 3).unwrap();
                let (part, _) = precompute_bounce_shard(scene(), &options, shard, &from).unwrap();
                let path = dir.path().join(format!("b{b}-{i}.hsr"));
                part.write(&path, false).unwrap();
                assert!(shard_is_done(&path, &scene(), &options, shard).unwrap());
                path
            })
            .collect();
        merged = merged_of(&parts, &format!("b{b}.hsr"));
    }
    let whole = dir.path().join("whole.hsr");
    let (cache, _) = precompute(scene(), &options).unwrap();
    assert_eq!(cache.bounced.as_ref().unwrap().channels().len(), 3);
    cache.write(&whole, false).unwrap();
    assert_eq!(
        std::fs::read(&merged).unwrap(),
        std::fs::read(&whole).unwrap()
    );
    // A merged cache of other options, or two bounces on at once, is refused.
    let from = SceneCache::read(&dir.path().join("b1.hsr")).unwrap();
    let mut other = options;
    other.visibility.seed = 8;
    let e = precompute_bounce_shard(scene(), &other, Shard::new(0, 3).unwrap(), &from);
    assert!(e.unwrap_err().to_string().contains("seed"));
    options.bounces = 3;
    let e = precompute_bounce_shard(scene(), &options, Shard::new(0, 3).unwrap(), &from);
    assert!(e.unwrap_err().to_string().contains("give --bounces 2"));
}
