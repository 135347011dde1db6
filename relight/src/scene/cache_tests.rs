use std::path::{Path, PathBuf};

use super::*;
use crate::{Generator, Scene, SceneBvh, VisibilityOptions, vertex_major};

fn made(cells: usize) -> SceneCache {
    made_with(cells, None)
}

fn made_with(cells: usize, sh_bands: Option<usize>) -> SceneCache {
    let scene = Scene::from_mesh(Generator::Sphere { cells }.mesh().unwrap(), true).unwrap();
    let param = Parameterization::new(ParamKind::Cube, 4).unwrap();
    let mut options = VisibilityOptions::new(param);
    options.keep = Selection::Largest(10);
    options.sh_bands = sh_bands;
    let (transport, _) = vertex_major(&scene.mesh, &SceneBvh::new(&scene.mesh), &options).unwrap();
    let params = CacheParams {
        param: "cube".into(),
        resolution: 4,
        keep: options.keep.into(),
        samples: 1,
        seed: 0,
        order: "vertex".into(),
        map_size: None,
        ground_plane: true,
        ground_cells: Some(32),
        sh_bands,
        ray_tracer: Some("packets".into()),
        bounces: 0,
        refine: None,
    };
    let mut cache = SceneCache::new(params, scene.mesh, scene.albedo, transport).unwrap();
    // The scene file's lighting and camera travel in the header.
    cache.environment = Some(crate::EnvironmentSpec {
        path: PathBuf::from("maps/sky.hdr"),
        yaw: 30.0,
        pitch: -5.0,
        roll: 0.0,
    });
    cache.camera = Some(crate::CameraSpec {
        position: [0.0, 2.0, 5.0],
        look_at: [0.0, 0.5, 0.0],
        fov: 35.0,
    });
    cache
}

fn written_cache(cache: &SceneCache) -> (tempfile::TempDir, PathBuf) {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("scene.hsr");
    cache.write(&path, false).unwrap();
    (dir, path)
}

fn cache_refusal(path: &Path) -> SceneError {
    crate::refusal_in(SceneCache::read(path), path)
}

#[test]
fn a_cache_reads_back_exactly() {
    let cache = made(3);
    let (_dir, path) = written_cache(&cache);
    let back = SceneCache::read(&path).unwrap();
    assert_eq!(back, cache);
    assert!(back.transport.stored_bytes() > 0);
    // The transport is read in place from the mapped file (on a little-endian machine).
    assert_eq!(back.transport.is_mapped(), cfg!(target_endian = "little"));
    assert!(!cache.transport.is_mapped());
    // The transport trees are usable as they were.
    assert_eq!(
        back.transport.transport(5).unwrap(),
        cache.transport.transport(5).unwrap()
    );
    // Never over an existing file without force; with it, replaced.
    assert!(matches!(
        cache.write(&path, false),
        Err(Error::Core(haarshift::Error::OutputExists { .. }))
    ));
    assert!(cache.write(&path, true).is_ok());
}

#[test]
fn a_flipped_byte_anywhere_is_refused() {
    let (_dir, path) = written_cache(&made(2));
    let good = std::fs::read(&path).unwrap();
    // Every byte of the checksum and header, then every 31st (in memory: the same parser).
    let bytes = (12..400).chain((400..good.len()).step_by(31));
    for k in bytes.chain([good.len() - 1]) {
        let mut bad = good.clone();
        bad[k] ^= 0x10;
        assert!(
            matches!(parse_bytes(&bad).and_then(SceneCache::from_file_parts), Err(Error::Scene { source: SceneError::CacheCorrupt(r), .. }) if r == "checksum mismatch"),
            "byte {k}"
        );
    }
    let mut bad = good.clone();
    bad[100] ^= 0x01;
    std::fs::write(&path, &bad).unwrap();
    assert_eq!(
        cache_refusal(&path),
        SceneError::CacheCorrupt("checksum mismatch".into())
    );
    let mut bad = good.clone();
    bad[3] ^= 1;
    std::fs::write(&path, &bad).unwrap();
    assert!(matches!(cache_refusal(&path), SceneError::CacheCorrupt(r) if r.contains("not a")));
}

#[test]
fn every_array_starts_at_a_multiple_of_8_with_zeros_before_it() {
    // Version 4's promise: the header is followed by zeros up to an aligned offset; a non-zero
    // gap (with a right checksum) is refused rather than read past.
    let (_dir, path) = written_cache(&made(2));
    let good = std::fs::read(&path).unwrap();
    let header_len = u64::from_le_bytes(good[16..24].try_into().unwrap()) as usize;
    let first_array = (24 + header_len).next_multiple_of(8);
    assert!(
        first_array > 24 + header_len,
        "the test needs a gap: pick another sphere"
    );
    assert!(good[24 + header_len..first_array].iter().all(|&b| b == 0));
    let mut bad = good.clone();
    bad[24 + header_len] = 1;
    let checksum = crc32fast::hash(&bad[16..]);
    bad[12..16].copy_from_slice(&checksum.to_le_bytes());
    std::fs::write(&path, &bad).unwrap();
    assert_eq!(
        cache_refusal(&path),
        SceneError::CacheCorrupt("padding that is not zero".into())
    );
}

#[test]
fn a_truncated_file_is_refused() {
    let (_dir, path) = written_cache(&made(2));
    let good = std::fs::read(&path).unwrap();
    for cut in [0, 5, 16, 23, 40, good.len() / 2, good.len() - 1] {
        std::fs::write(&path, &good[..cut]).unwrap();
        assert!(
            matches!(cache_refusal(&path), SceneError::CacheCorrupt(_)),
            "cut at {cut}"
        );
    }
}

#[test]
fn another_version_is_refused_with_both_versions_named() {
    let (_dir, path) = written_cache(&made(2));
    let mut bytes = std::fs::read(&path).unwrap();
    bytes[8..12].copy_from_slice(&(CACHE_VERSION + 1).to_le_bytes());
    std::fs::write(&path, &bytes).unwrap();
    let e = cache_refusal(&path);
    assert_eq!(
        e,
        SceneError::CacheVersion {
            found: CACHE_VERSION + 1,
            expected: CACHE_VERSION
        }
    );
    assert!(e.to_string().contains("compute it again"));
}

#[test]
fn a_cache_of_another_scene_is_refused() {
    let cache = made(2);
    let (_dir, path) = written_cache(&cache);
    assert!(SceneCache::read_for(&path, &cache.mesh).is_ok());
    let other = made(3).mesh;
    assert!(matches!(
        SceneCache::read_for(&path, &other),
        Err(Error::Scene {
            source: SceneError::CacheMismatch(_),
            ..
        })
    ));
    // A moved vertex is another scene too.
    let mut moved = cache.mesh.clone();
    moved.append(&made(2).mesh);
    assert_ne!(scene_hash(&moved), scene_hash(&cache.mesh));
}

#[test]
fn inconsistent_parts_are_refused() {
    let cache = made(2);
    let mut params = cache.params.clone();
    params.resolution = 8;
    assert_err!(
        SceneCache::new(
            params,
            cache.mesh.clone(),
            cache.albedo.clone(),
            cache.transport.clone()
        ),
        InvalidParameter {
            name: "cache parameters",
            ..
        },
        "cube 8"
    );
    let short = cache.albedo.slice(ndarray::s![1.., ..]).to_owned();
    assert_err!(
        SceneCache::new(cache.params.clone(), cache.mesh, short, cache.transport),
        InvalidShape { .. },
        "albedo must be (1143, 3)"
    );
}

#[test]
fn the_spherical_harmonic_transfer_reads_back_and_is_checksummed() {
    let cache = made_with(2, Some(3));
    let transfer = cache.transport.sh().unwrap();
    assert_eq!(
        transfer.coefficients().dim(),
        (cache.mesh.vertex_count(), 9)
    );
    let (_dir, path) = written_cache(&cache);
    assert_eq!(SceneCache::read(&path).unwrap(), cache);
    // The transfer is the file's last V x 9 f32: a flipped byte there fails the checksum.
    let good = std::fs::read(&path).unwrap();
    let block = cache.mesh.vertex_count() * 9 * 4;
    for k in [good.len() - block, good.len() - block / 2, good.len() - 1] {
        let mut bad = good.clone();
        bad[k] ^= 0x04;
        std::fs::write(&path, &bad).unwrap();
        assert_eq!(
            cache_refusal(&path),
            SceneError::CacheCorrupt("checksum mismatch".into()),
            "byte {k}"
        );
    }
    // Parameters that do not name the transfer's bands are refused.
    let mut params = cache.params.clone();
    params.sh_bands = Some(4);
    let parts = (cache.mesh.clone(), cache.albedo.clone());
    assert_err!(
        SceneCache::new(params, parts.0.clone(), parts.1.clone(), cache.transport),
        InvalidParameter {
            name: "cache parameters",
            ..
        },
        "Some(4) sh bands"
    );
    let plain = made(2);
    let mut params = plain.params.clone();
    params.sh_bands = Some(3);
    assert_err!(
        SceneCache::new(params, parts.0, parts.1, plain.transport),
        InvalidParameter {
            name: "cache parameters",
            ..
        },
        "Some(3) sh bands but the transport is cube 4 with None"
    );
}

#[test]
fn version_1_to_5_files_are_refused() {
    // Version 1 had no spherical-harmonic transfer, version 2 no shard record, version 3 no
    // aligned arrays, version 4 no ray tracer, version 5 no ground plane counts: their files
    // must be remade, not misread.
    let (_dir, path) = written_cache(&made(2));
    let good = std::fs::read(&path).unwrap();
    for old in [1u32, 2, 3, 4, 5] {
        let mut bytes = good.clone();
        bytes[8..12].copy_from_slice(&old.to_le_bytes());
        std::fs::write(&path, &bytes).unwrap();
        let e = cache_refusal(&path);
        assert_eq!(
            e,
            SceneError::CacheVersion {
                found: old,
                expected: 6
            }
        );
        assert_eq!(
            e.to_string(),
            format!(
                "scene cache has format version {old}, this build reads version 6; compute it again"
            )
        );
    }
}

#[test]
fn a_cache_of_any_scene_reads_back_its_mesh_bit_for_bit() {
    use crate::precompute::{PrecomputeOptions, precompute};
    use crate::test_support::differing_bits;
    let testdata = Path::new(env!("CARGO_MANIFEST_DIR")).join("../testdata");
    let mesh_file = |name: &str, ground_plane: bool| {
        let mesh = Mesh::load(&testdata.join("meshes").join(name)).unwrap();
        Scene::from_mesh(mesh, ground_plane).unwrap()
    };
    let scene_file = |name: &str| Scene::load(&testdata.join("scenes").join(name)).unwrap();
    // Mesh files (normals computed, then normalised), with and without the ground plane; a
    // scene file naming a mesh; generators moved by transforms (normals mapped, then
    // normalised). Every one had normals that a second normalisation moves.
    let scenes = [
        ("bunny.ply", mesh_file("bunny.ply", false)),
        (
            "bunny.ply with the ground plane",
            mesh_file("bunny.ply", true),
        ),
        ("bunny.obj", mesh_file("bunny.obj", false)),
        ("bunny.json", scene_file("bunny.json")),
        (
            "cylinder_and_bump.json",
            scene_file("cylinder_and_bump.json"),
        ),
        ("sphere_on_plane.json", scene_file("sphere_on_plane.json")),
    ];
    let param = Parameterization::new(ParamKind::LatLong, 4).unwrap();
    let options = PrecomputeOptions::new(VisibilityOptions::new(param));
    for (name, scene) in scenes {
        let (cache, _) = precompute(scene, &options).unwrap();
        let (_dir, path) = written_cache(&cache);
        let (header, parts) = read_parts(&path).unwrap();
        let differing = differing_bits(&parts.mesh, &cache.mesh);
        assert_eq!(
            differing,
            (0, 0),
            "{name}: position and normal components moved"
        );
        assert_eq!(parts.mesh.triangles(), cache.mesh.triangles(), "{name}");
        let hash = scene_hash(&cache.mesh);
        assert_eq!(
            (header.scene_hash, scene_hash(&parts.mesh)),
            (hash, hash),
            "{name}"
        );
        // So the cache is found to be its scene's.
        assert!(SceneCache::read_for(&path, &cache.mesh).is_ok(), "{name}");
    }
}

/// [`made_with`] and its bounced sum of two bounces (the albedo made coloured first when
/// `rgb`).
fn bounced_with(sh_bands: Option<usize>, rgb: bool) -> SceneCache {
    use crate::precompute::bounce::bounce_range;
    let mut cache = made_with(2, sh_bands);
    if rgb {
        cache.albedo.column_mut(2).fill(0.3);
    }
    let param = cache.transport.param();
    let mut options = VisibilityOptions::new(param);
    (options.keep, options.sh_bands) = (Selection::Largest(10), sh_bands);
    let bvh = SceneBvh::new(&cache.mesh);
    let all = 0..cache.mesh.vertex_count();
    let (bounced, _) = bounce_range(
        &cache.mesh,
        &bvh,
        &options,
        cache.albedo.view(),
        &cache.transport,
        None,
        2,
        all,
    )
    .unwrap();
    cache.set_bounced(bounced).unwrap();
    cache
}

/// The header of a cache file's bytes, and where its first array starts.
fn header_of(bytes: &[u8]) -> (serde_json::Value, usize) {
    let len = u64::from_le_bytes(bytes[16..24].try_into().unwrap()) as usize;
    let header = serde_json::from_slice(&bytes[24..24 + len]).unwrap();
    (header, (24 + len).next_multiple_of(8))
}

/// `bytes` with its header replaced by `header` (padded, the checksum made right again).
fn with_header(bytes: &[u8], header: &serde_json::Value) -> Vec<u8> {
    let (_, first) = header_of(bytes);
    let json = serde_json::to_vec(header).unwrap();
    let mut out = bytes[..16].to_vec();
    out.extend((json.len() as u64).to_le_bytes());
    out.extend(&json);
    out.resize(out.len().next_multiple_of(8), 0);
    out.extend(&bytes[first..]);
    let checksum = crc32fast::hash(&out[16..]);
    out[12..16].copy_from_slice(&checksum.to_le_bytes());
    out
}

#[test]
fn bounced_caches_read_back_exactly_grey_and_rgb() {
    for (rgb, sets) in [(false, 1), (true, 3)] {
        let cache = bounced_with(Some(2), rgb);
        let b = cache.bounced.as_ref().unwrap();
        assert_eq!((cache.params.bounces, b.channels().len()), (2, sets));
        assert!(b.channel(0).sh().is_some() && b.coefficient_count() > 0);
        let (_dir, path) = written_cache(&cache);
        let back = SceneCache::read(&path).unwrap();
        assert_eq!(back, cache);
        let channel = back.bounced.as_ref().unwrap().channel(sets - 1);
        assert_eq!(channel.is_mapped(), cfg!(target_endian = "little"));
        let (header, _) = header_of(&std::fs::read(&path).unwrap());
        assert_eq!(header["params"]["bounces"], 2);
        let counts = header["bounced_coefficients"].as_array().unwrap();
        assert_eq!(counts.len(), sets);
    }
    // A cache without bounces writes neither field: its bytes are those of a cache made
    // before bounces existed.
    let (_dir, path) = written_cache(&made(2));
    let (header, _) = header_of(&std::fs::read(&path).unwrap());
    assert!(!header.to_string().contains("bounce"), "{header}");
}

#[test]
fn a_bounced_sum_that_does_not_match_is_refused() {
    let cache = bounced_with(None, false);
    let mut coloured = cache.clone();
    coloured.albedo.column_mut(0).fill(0.1);
    let grey = cache.bounced.clone().unwrap();
    // One set for a coloured albedo, and a sum of fewer vertices.
    let e = coloured.clone().set_bounced(grey).unwrap_err().to_string();
    assert!(e.contains("1 set(s) but the albedo is coloured"), "{e}");
    let short = crate::precompute::bounce::BouncedTransport::new(
        1,
        vec![TransportSet::new(
            cache.transport.param(),
            Selection::Largest(10),
        )],
    )
    .unwrap();
    let e = coloured.set_bounced(short).unwrap_err().to_string();
    assert!(e.contains("other vertices"), "{e}");
    // A cache whose parameters claim bounces it does not hold.
    let mut params = cache.params.clone();
    params.bounces = 3;
    let (m, a, t) = (
        cache.mesh.clone(),
        cache.albedo.clone(),
        cache.transport.clone(),
    );
    assert_err!(
        SceneCache::new(params, m, a, t),
        InvalidParameter {
            name: "cache parameters",
            ..
        },
        "they say 3 bounces but the bounced sum has 0"
    );
}

#[test]
fn hostile_bounce_headers_are_refused_without_a_panic() {
    let (_dir, path) = written_cache(&bounced_with(Some(2), true));
    let good = std::fs::read(&path).unwrap();
    let (header, _) = header_of(&good);
    // Each edit and the refusal it meets: a count of bounces out of range is refused as a
    // parameter, a bounced sum that does not fit the header as a damaged cache.
    let sets = |b: usize, n: usize| {
        format!("{b} bounces with {n} bounced sets (0 and none, or 1 to 8 and 1 or 3)")
    };
    let edits: [(&str, serde_json::Value, String); 8] = [
        ("bounces", 0.into(), sets(0, 3)),
        ("bounces", 9.into(), "9: must be 0 to 8".into()),
        (
            "bounces",
            usize::MAX.into(),
            format!("{}: must be 0 to 8", usize::MAX),
        ),
        ("bounced_coefficients", serde_json::json!([]), sets(2, 0)),
        (
            "bounced_coefficients",
            serde_json::json!([1, 2]),
            sets(2, 2),
        ),
        (
            "bounced_coefficients",
            serde_json::json!([0, 0, 0]),
            "bytes after the bounced sum".into(),
        ),
        (
            "bounced_coefficients",
            serde_json::json!([u64::MAX, 0, 0]),
            "size overflows".into(),
        ),
        (
            "bounced_coefficients",
            serde_json::json!([1, 2, 3, 4]),
            sets(2, 4),
        ),
    ];
    for (field, value, needle) in edits {
        let mut h = header.clone();
        match field {
            "bounces" => h["params"][field] = value.clone(),
            _ => h[field] = value.clone(),
        }
        let bad = with_header(&good, &h);
        let got = parse_bytes(&bad).and_then(SceneCache::from_file_parts);
        if needle.contains("must be 0 to 8") {
            assert_err!(
                got,
                InvalidParameter {
                    name: "bounces",
                    ..
                },
                &needle
            );
        } else {
            assert_err!(
                got,
                Scene {
                    source: SceneError::CacheCorrupt(_),
                    ..
                },
                &format!("scene cache is damaged ({needle}); compute it again")
            );
        }
    }
    // The untouched header passes through the same rewriting.
    let same = with_header(&good, &header);
    assert!(
        parse_bytes(&same)
            .and_then(SceneCache::from_file_parts)
            .is_ok()
    );
}
