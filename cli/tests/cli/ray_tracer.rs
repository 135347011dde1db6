//! The precomputation's two ray tracers from the command line: Embree 3 loaded at run time
//! where it is installed, our packets everywhere; which one cast is said, recorded and
//! checked by `relight merge`; a machine without Embree is told what to install.

use std::path::Path;
use std::process::{Command, Output};

use haarshift_relight::precompute::origin::RayOrigins;
use haarshift_relight::{EMBREE_LIBRARY_VAR, RayTracer, SceneCache};

use crate::common::{p, succeeds_with_stdout, testdata, text};

/// Runs `haarshift ARGS` with Embree's library named as `library` (a missing file: no
/// Embree).
fn with_embree_at(library: &str, args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_haarshift"))
        .env(EMBREE_LIBRARY_VAR, library)
        .args(args)
        .output()
        .expect("the binary runs")
}

/// `Some(())` where Embree loads; else the test is skipped in one line (or fails under
/// `HAARSHIFT_REQUIRE=embree`).
fn embree() -> Option<()> {
    haarshift_testkit::needs(
        "embree",
        RayTracer::Embree.unavailable().map_or(Ok(()), Err),
    )
}

#[test]
fn without_embree_the_packets_cast_and_asking_for_embree_names_the_package() {
    let dir = tempfile::tempdir().unwrap();
    let bunny = testdata("meshes/bunny.ply");
    let out = dir.path().join("bunny.hsr");
    let flags = ["relight", "precompute", p(&bunny), "--resolution", "4"];
    let missing = dir.path().join("no-libembree3.so.3");
    let asked = with_embree_at(
        p(&missing),
        &[&flags[..], &["--ray-tracer", "embree", "-o", p(&out)]].concat(),
    );
    let err = text(&asked.stderr);
    assert_eq!(asked.status.code(), Some(1), "{err}");
    assert_eq!(err.lines().count(), 1, "{err}");
    for needle in [
        "embree is not available",
        "no-libembree3.so.3",
        "libembree3-3",
    ] {
        assert!(err.contains(needle), "{needle:?} in {err}");
    }
    assert!(!out.exists());
    // The default casts with our packets, says so, and records it.
    let run = with_embree_at(p(&missing), &[&flags[..], &["-o", p(&out)]].concat());
    assert!(run.status.success(), "{}", text(&run.stderr));
    assert!(
        text(&run.stdout).contains(" (packets), "),
        "{}",
        text(&run.stdout)
    );
    let cache = SceneCache::read(&out).unwrap();
    assert_eq!(cache.params.ray_tracer.as_deref(), Some("packets"));
    // --help says which tracer this machine would use, and why.
    let help = text(&with_embree_at(p(&missing), &["relight", "precompute", "--help"]).stdout);
    // Its paragraph, as clap wraps it.
    let line = help
        .split("\n\n")
        .find(|l| l.starts_with("Ray tracer on this machine: "))
        .unwrap_or_else(|| panic!("no tracer line in {help}"))
        .replace('\n', " ");
    assert!(
        line.contains("packets (") && line.contains("libembree3-3"),
        "{line}"
    );
}

#[test]
fn help_names_embree_where_it_loads() {
    if embree().is_none() {
        return;
    }
    let help = succeeds_with_stdout(&["relight", "precompute", "--help"]);
    assert!(
        help.contains("Ray tracer on this machine: embree (Embree 3."),
        "{help}"
    );
}

#[test]
fn both_ray_tracers_precompute_the_bunny_alike_and_say_which_cast() {
    if embree().is_none() {
        return;
    }
    // Embree is the default where it loads; our packets on request. The bunny's rays pass no
    // triangle's edge closely enough for the two to differ: the arrays agree, the headers
    // differ in the tracer alone.
    let dir = tempfile::tempdir().unwrap();
    let bunny = testdata("meshes/bunny.ply");
    let flags = [
        "relight",
        "precompute",
        p(&bunny),
        "--resolution",
        "8",
        "-o",
    ];
    let (default, packets) = (dir.path().join("a.hsr"), dir.path().join("b.hsr"));
    let stdout = succeeds_with_stdout(&[&flags[..], &[p(&default)]].concat());
    assert!(stdout.contains(" (embree), "), "{stdout}");
    let extra = [p(&packets), "--ray-tracer", "packets"];
    let stdout = succeeds_with_stdout(&[&flags[..], &extra].concat());
    assert!(stdout.contains(" (packets), "), "{stdout}");
    let (mut a, b) = (
        SceneCache::read(&default).unwrap(),
        SceneCache::read(&packets).unwrap(),
    );
    assert_eq!(a.params.ray_tracer.as_deref(), Some("embree"));
    a.params.ray_tracer = b.params.ray_tracer.clone();
    assert_eq!(a, b);
}

/// A cache file's version and its JSON header.
pub fn version_and_header(bytes: &[u8]) -> (u32, serde_json::Value) {
    let version = u32::from_le_bytes(bytes[8..12].try_into().unwrap());
    let length = u64::from_le_bytes(bytes[16..24].try_into().unwrap()) as usize;
    (
        version,
        serde_json::from_slice(&bytes[24..24 + length]).unwrap(),
    )
}

/// `bytes` of an older cache relabelled as this build's version (the CRC-32 of what follows
/// it made anew): the layout of the arrays is the same, the header only lacks the tracer and
/// version 6's ground and refinement fields (read as absent: no ground plane, not refined).
fn as_current_version(mut bytes: Vec<u8>) -> Vec<u8> {
    bytes[8..12].copy_from_slice(&haarshift_relight::scene::cache::CACHE_VERSION.to_le_bytes());
    let crc = crc32fast::hash(&bytes[16..]);
    bytes[12..16].copy_from_slice(&crc.to_le_bytes());
    bytes
}

#[test]
fn embree_loaded_at_run_time_casts_the_cache_the_linked_build_cast() {
    if embree().is_none() {
        return;
    }
    // testdata/caches/table_cube4_embree3_linked.hsr was written by the build that linked
    // Embree 3.13.5 through the embree3 crate (commit 3c3193ae, cache version 4):
    //   haarshift relight precompute testdata/scenes/table.json --param cube --resolution 4 -o ..
    // A table's legs meet its top along shared edges, so Embree and our packets answer some
    // rays differently: the comparison tells the tracers apart.
    let dir = tempfile::tempdir().unwrap();
    let scene = testdata("scenes/table.json");
    let flags = [
        "relight",
        "precompute",
        p(&scene),
        "--param",
        "cube",
        "--resolution",
        "4",
    ];
    let (ours, packets) = (
        dir.path().join("embree.hsr"),
        dir.path().join("packets.hsr"),
    );
    succeeds_with_stdout(&[&flags[..], &["-o", p(&ours)]].concat());
    let extra = ["--ray-tracer", "packets", "-o", p(&packets)];
    succeeds_with_stdout(&[&flags[..], &extra].concat());
    let linked = std::fs::read(testdata("caches/table_cube4_embree3_linked.hsr")).unwrap();
    let now = std::fs::read(&ours).unwrap();
    // The headers: the version and the tracer differ, nothing else.
    let (old_version, old_header) = version_and_header(&linked);
    let (version, mut header) = version_and_header(&now);
    assert_eq!(
        (old_version, version),
        (4, haarshift_relight::scene::cache::CACHE_VERSION)
    );
    let tracer = header["params"]
        .as_object_mut()
        .unwrap()
        .remove("ray_tracer");
    assert_eq!(tracer, Some(serde_json::json!("embree")));
    crate::ground_cells::drop_version_6_fields(&mut header);
    // (The count of coefficients follows the rows that the crease contract changed, below.)
    let mut old_header = old_header;
    for h in [&mut header, &mut old_header] {
        h.as_object_mut().unwrap().remove("coefficients");
    }
    assert_eq!(header, old_header);
    // Every array: the linked build's cache, read as this version, equals ours.
    let relabelled = dir.path().join("linked.hsr");
    std::fs::write(&relabelled, as_current_version(linked)).unwrap();
    let (mut linked, ours) = (
        SceneCache::read(&relabelled).unwrap(),
        SceneCache::read(&ours).unwrap(),
    );
    assert_eq!(linked.params.ray_tracer, None);
    linked.params.ray_tracer = ours.params.ray_tracer.clone();
    assert_eq!((&linked.mesh, &linked.params), (&ours.mesh, &ours.params));
    // Where the legs meet the top, vertices stand in contact with another face: since the
    // crease contract (`relight::precompute::origin`) their rays start off it, so their rows
    // are cast anew. Every other row is the linked build's, bit for bit.
    let contact = RayOrigins::new(&ours.mesh).contact_vertices();
    let vertices = ours.mesh.vertex_count();
    assert!(
        !contact.is_empty() && contact.len() < vertices / 2,
        "{contact:?}"
    );
    let mut moved = 0;
    for v in 0..vertices {
        let same = linked.transport.coefficients(v) == ours.transport.coefficients(v);
        if contact.binary_search(&v).is_ok() {
            moved += usize::from(!same);
        } else {
            assert!(same, "vertex {v}");
        }
    }
    assert!(moved > 0, "no contact vertex's row changed");
    // And our packets do not: the test would see Embree silently replaced.
    let mut packets = SceneCache::read(&packets).unwrap();
    packets.params.ray_tracer = ours.params.ray_tracer.clone();
    assert_ne!(packets.transport, ours.transport);
}

#[test]
fn shards_cast_by_different_tracers_are_not_merged() {
    if embree().is_none() {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let bunny = testdata("meshes/bunny.ply");
    let part = |i: usize, tracer: &str| -> std::path::PathBuf {
        let out = dir.path().join(format!("part-{i}.hsr"));
        let shard = format!("{i}/2");
        let args = [
            "relight",
            "precompute",
            p(&bunny),
            "--resolution",
            "4",
            "--shard",
        ];
        let extra = [shard.as_str(), "--ray-tracer", tracer, "-o", p(&out)];
        succeeds_with_stdout(&[&args[..], &extra].concat());
        out
    };
    let (a, b) = (part(0, "embree"), part(1, "packets"));
    let merged = dir.path().join("merged.hsr");
    let line = crate::common::fails_cleanly(
        &["relight", "merge", p(&a), p(&b), "-o", p(&merged)],
        &["ray_tracer", "embree", "packets"],
    );
    assert!(!merged.exists(), "{line}");
    assert!(Path::new(&b).exists());
}
