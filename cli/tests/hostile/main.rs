//! Hostile geometry through the CLI: every input that once panicked, aborted or hung
//! fails with exit 1 and one `haarshift:` line naming the file and the field, or, for
//! degenerate but valid meshes, succeeds; either way within 2 CPU-seconds and 200 MB of the
//! child's peak resident memory (`ru_maxrss`, read by `wait4`). A test binary of its own: a
//! forked child's `ru_maxrss` starts at the parent's resident size, so the parent here runs
//! nothing large beside these tests.

use std::io::Read;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

// The CLI tests' helpers; this binary uses a few of them.
#[allow(dead_code)]
#[path = "../cli/common/mod.rs"]
mod common;

use common::{p, testdata, text};

mod assets;

/// What a child cost: CPU seconds (user + system) and peak resident bytes.
struct Cost {
    cpu: f64,
    peak: u64,
}

/// Runs `haarshift ARGS` in `dir` and returns its exit code, stdout, stderr and cost; kills it
/// (and fails) after 60 s of wall time.
// The child is reaped by `wait4` (which also gives its resource use), not by `Child::wait`.
#[allow(clippy::zombie_processes)]
fn run_measured(dir: &Path, args: &[&str]) -> (Option<i32>, String, String, Cost) {
    let mut child = Command::new(env!("CARGO_BIN_EXE_haarshift"))
        .current_dir(dir)
        .args(args)
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("the binary runs");
    let drain = |mut pipe: Box<dyn Read + Send>| {
        std::thread::spawn(move || {
            let mut bytes = Vec::new();
            pipe.read_to_end(&mut bytes).unwrap();
            bytes
        })
    };
    let out = drain(Box::new(child.stdout.take().unwrap()));
    let err = drain(Box::new(child.stderr.take().unwrap()));
    let pid = child.id() as libc::pid_t;
    let start = Instant::now();
    let mut status = 0;
    // SAFETY: `rusage` is plain data that `wait4` fills; `pid` is this process's child.
    let mut usage: libc::rusage = unsafe { std::mem::zeroed() };
    loop {
        // SAFETY: as above; WNOHANG returns at once.
        let r = unsafe { libc::wait4(pid, &mut status, libc::WNOHANG, &mut usage) };
        assert!(r >= 0, "wait4 failed");
        if r == pid {
            break;
        }
        if start.elapsed() > Duration::from_secs(60) {
            child.kill().unwrap();
            panic!("{args:?} hangs: killed after 60 s");
        }
        std::thread::sleep(Duration::from_millis(5));
    }
    let seconds = |t: libc::timeval| t.tv_sec as f64 + t.tv_usec as f64 * 1e-6;
    let cost = Cost {
        cpu: seconds(usage.ru_utime) + seconds(usage.ru_stime),
        peak: usage.ru_maxrss as u64 * 1024,
    };
    let code = libc::WIFEXITED(status).then(|| libc::WEXITSTATUS(status));
    let (out, err) = (out.join().unwrap(), err.join().unwrap());
    (code, text(&out), text(&err), cost)
}

/// The limits every case here keeps.
fn within_limits(args: &[&str], cost: &Cost) {
    assert!(cost.cpu < 2.0, "{args:?}: {} CPU-seconds", cost.cpu);
    assert!(cost.peak < 200 << 20, "{args:?}: peak {} bytes", cost.peak);
}

/// Runs `haarshift ARGS` in `dir` and requires exit 1, one `haarshift:` line holding every
/// needle, nothing on stdout, no panic, within the limits. Returns the line.
fn refused(dir: &Path, args: &[&str], needles: &[&str]) -> String {
    let (code, out, err, cost) = run_measured(dir, args);
    assert_eq!(code, Some(1), "{args:?}: {err}");
    assert!(out.is_empty(), "{args:?} wrote {out:?}");
    assert_eq!(err.lines().count(), 1, "{args:?}: not one line: {err:?}");
    assert!(err.starts_with("haarshift: "), "{args:?}: {err:?}");
    assert!(!err.contains("panicked"), "{err}");
    for needle in needles {
        assert!(err.contains(needle), "{args:?}: {err:?} lacks {needle:?}");
    }
    within_limits(args, &cost);
    err
}

/// Runs `haarshift ARGS` in `dir` and requires success within the limits.
fn accepted(dir: &Path, args: &[&str]) {
    let (code, _, err, cost) = run_measured(dir, args);
    assert_eq!(code, Some(0), "{args:?}: {err}");
    within_limits(args, &cost);
}

/// `dir/name` holding `bytes`.
fn input_file(dir: &Path, name: &str, bytes: impl AsRef<[u8]>) -> PathBuf {
    let path = dir.join(name);
    std::fs::write(&path, bytes).unwrap();
    path
}

/// `relight precompute INPUT -o x.hsr --resolution 8 --force EXTRA...`.
fn precompute_args<'a>(input: &'a str, extra: &[&'a str]) -> Vec<&'a str> {
    let mut args = vec![
        "relight",
        "precompute",
        input,
        "-o",
        "x.hsr",
        "--resolution",
        "8",
        "--force",
    ];
    args.extend_from_slice(extra);
    args
}

/// A binary little-endian PLY of one triangle whose third vertex is `(0, y, 0)` in float32.
fn binary_ply(y: f32) -> Vec<u8> {
    let mut bytes = b"ply\nformat binary_little_endian 1.0\nelement vertex 3\n\
        property float x\nproperty float y\nproperty float z\nelement face 1\n\
        property list uchar int vertex_indices\nend_header\n"
        .to_vec();
    for v in [[0.0f32, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, y, 0.0]] {
        for x in v {
            bytes.extend_from_slice(&x.to_le_bytes());
        }
    }
    bytes.push(3);
    for i in [0i32, 1, 2] {
        bytes.extend_from_slice(&i.to_le_bytes());
    }
    bytes
}

#[test]
fn coordinates_beyond_the_range_are_refused_by_vertex() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let obj = |y: &str| format!("v 0 0 0\nv 1 0 0\nv 0 {y} 0\nf 1 2 3\n");
    input_file(d, "t.obj", obj("1e308"));
    refused(
        d,
        &precompute_args("t.obj", &[]),
        &["t.obj", "vertex 2", "1e15"],
    );
    input_file(d, "g.obj", obj("3.4e38"));
    let args = precompute_args("g.obj", &["--ground-plane"]);
    refused(d, &args, &["g.obj", "vertex 2", "1e15"]);
    input_file(d, "x.obj", "v 1e25 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
    let args = precompute_args("x.obj", &["--ground-plane"]);
    refused(d, &args, &["x.obj", "vertex 0", "1e15"]);
    input_file(d, "t.ply", binary_ply(3.4e38));
    let args = precompute_args("t.ply", &["--param", "cube"]);
    refused(d, &args, &["t.ply", "vertex 2", "1e15"]);
    // The edge of the range is accepted.
    input_file(d, "edge.obj", obj("1e15"));
    accepted(d, &precompute_args("edge.obj", &[]));
}

#[test]
fn transforms_and_cameras_far_from_the_origin_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let env = testdata("envmaps/rooitou_park_32x16.hdr");
    let scene = |translate: &str, look_at: &str, ground: bool| {
        format!(
            r#"{{"objects": [{{"name": "ball", "generator": {{"sphere": {{"cells": 2}}}},
                "transform": {{"translate": {translate}}}}}],
              "ground_plane": {ground}, "environment": {{"path": "{}"}},
              "camera": {{"position": [0, 2, 5], "look_at": {look_at}, "fov": 40}}}}"#,
            env.display()
        )
    };
    let small = ["--resolution", "8", "--width", "8", "--height", "8"];
    let render = |name: &'static str| {
        let mut args = vec!["relight", "scene", name, "-o", "x.png", "--force"];
        args.extend(small);
        args.extend(["--circles", "12", "--circle-points", "24"]);
        args.extend(["--shells", "6", "--shell-grid", "4"]);
        args
    };
    input_file(d, "far.json", scene("[-1e30, 0, 0]", "[0, 1e30, 0]", false));
    refused(d, &render("far.json"), &["far.json", "1e15"]);
    input_file(d, "eye.json", scene("[0, 0, 0]", "[0, 1e308, 0]", false));
    refused(
        d,
        &render("eye.json"),
        &["eye.json", "camera's look_at", "1e15"],
    );
    let chair = r#"{"objects": [{"generator": {"chair": {"cells": 2}},
        "transform": {"translate": [-1e30, 0, 0]}}], "ground_plane": true}"#;
    input_file(d, "chair.json", chair);
    refused(
        d,
        &precompute_args("chair.json", &[]),
        &["chair.json", "1e15"],
    );
    let inf = r#"{"objects": [{"generator": {"sphere": {"cells": 2}},
        "transform": {"translate": [1e308, 0, 0]}}], "ground_plane": true}"#;
    input_file(d, "inf.json", inf);
    refused(d, &precompute_args("inf.json", &[]), &["inf.json", "1e15"]);
    // A cache of a valid scene, rendered looking at a point out of range.
    input_file(d, "ok.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
    accepted(d, &precompute_args("ok.obj", &[]));
    let env = p(&env);
    let mut args = vec!["relight", "render", "x.hsr", "--env", env, "-o", "r.png"];
    args.extend(["--camera", "0,2,5", "--look-at", "0,1e308,0"]);
    args.extend(["--width", "8", "--height", "8"]);
    refused(d, &args, &["camera", "1e15"]);
}

#[test]
fn a_ground_plane_under_a_mesh_without_width_or_depth_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    input_file(d, "point.obj", "v 1 1 1\nv 1 1 1\nv 1 1 1\nf 1 2 3\n");
    input_file(d, "line.obj", "v 1 0 1\nv 1 1 1\nv 1 2 1\nf 1 2 3\n");
    for name in ["point.obj", "line.obj"] {
        let args = precompute_args(name, &["--ground-plane"]);
        refused(d, &args, &[name, "ground plane", "width or depth"]);
    }
    // Without the plane the same meshes have no area to hit and precompute.
    accepted(d, &precompute_args("point.obj", &[]));
}

#[test]
fn counts_that_would_wrap_are_refused_before_allocating() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    for generator in ["sphere", "table", "chair", "cylinder_and_bump"] {
        for cells in ["18446744073709551615", "4294967296", "10000"] {
            let json =
                format!(r#"{{"objects":[{{"generator":{{"{generator}":{{"cells":{cells}}}}}}}]}}"#);
            input_file(d, "g.json", json);
            refused(
                d,
                &precompute_args("g.json", &[]),
                &["g.json", "cells", cells],
            );
        }
    }
    let cubes = r#"{"objects":[{"generator":{"cubes":{"count":4294967296,"cells":4294967296}}}]}"#;
    input_file(d, "cubes.json", cubes);
    refused(
        d,
        &precompute_args("cubes.json", &[]),
        &["cubes.json", "4294967296"],
    );
    let scene = r#"{"objects": [{"name": "ball", "generator": {"sphere": {"cells": 2}}}],
        "ground_plane": true}"#;
    input_file(d, "s.json", scene);
    let env = testdata("envmaps/rooitou_park_32x16.hdr");
    for frames in ["18446744073709551615", "2147483647", "4294967296"] {
        let path = format!(r#"{{"segments":[{{"frames":{frames},"light_yaw":90}}]}}"#);
        input_file(d, "p.json", path);
        let mut args = vec!["relight", "scene", "s.json", "-o", "a.gif", "--force"];
        args.extend(["--animate", "p.json", "--env", p(&env)]);
        args.extend(["--resolution", "8", "--width", "8", "--height", "8"]);
        args.extend(["--circles", "12", "--circle-points", "24"]);
        args.extend(["--shells", "6", "--shell-grid", "4"]);
        refused(
            d,
            &args,
            &["p.json", "path segment 0", "more than 3600 frames"],
        );
    }
}

#[test]
fn generators_too_large_for_the_memory_limit_are_refused_before_they_are_built() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    // Inside the 50 M-vertex cap, each of these ran for many seconds at 3.5-9 GB.
    for (generator, cells) in [
        ("sphere", 1000),
        ("sphere", 1614),
        ("table", 1000),
        ("chair", 3000),
    ] {
        let json =
            format!(r#"{{"objects":[{{"generator":{{"{generator}":{{"cells":{cells}}}}}}}]}}"#);
        input_file(d, "g.json", json);
        let cells = format!("\"cells\":{cells}");
        refused(
            d,
            &precompute_args("g.json", &[]),
            &[
                "g.json: object 0",
                &cells,
                "more than the memory budget of 4294967296 bytes",
            ],
        );
    }
    // The limit is the flag's: 10,086 vertices need 28.7 MB at lat-long 8 with every coefficient
    // (640 + 16 x 128 + 80 bytes each).
    input_file(
        d,
        "s.json",
        r#"{"objects":[{"generator":{"sphere":{"cells":40}}}]}"#,
    );
    refused(
        d,
        &precompute_args("s.json", &["--memory-limit", "8MiB"]),
        &[
            "s.json: object 0",
            "10086 vertices",
            "memory budget of 8388608 bytes",
        ],
    );
    accepted(d, &precompute_args("s.json", &["--memory-limit", "64MiB"]));
    // A mesh file is counted once read, before its BVH and transport.
    let bunny = testdata("meshes/bunny.ply");
    refused(
        d,
        &precompute_args(p(&bunny), &["--memory-limit", "1MiB"]),
        &["bunny.ply: the scene (1839 vertices)", "memory budget"],
    );
}

#[test]
fn degenerate_meshes_build_their_bvh_in_linear_time() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let copies = "f 1 2 3\n".repeat(90_000);
    input_file(
        d,
        "copies.obj",
        format!("v 0 0 0\nv 1 0 0\nv 0 1 0\n{copies}"),
    );
    accepted(d, &precompute_args("copies.obj", &[]));
    let fan = " 1 2 3".repeat(300_000);
    input_file(d, "fan.obj", format!("v 0 0 0\nv 1 0 0\nv 0 1 0\nf{fan}\n"));
    accepted(d, &precompute_args("fan.obj", &[]));
    // 90,000 distinct triangles on 100 vertices inside a 1e-9 box: at (1, 1, 1) they are
    // distinct in f64 and one point in f32; at the origin f32 tells them apart, so exact
    // de-duplication alone would not pass.
    for (name, base) in [("tiny.obj", 1.0), ("origin.obj", 0.0)] {
        input_file(d, name, tiny_triangles(base));
        accepted(d, &precompute_args(name, &[]));
    }
    // A whole scene of extent 1e-23 (found by the scene_structured fuzz target): its BVH's f32
    // surface areas underflow to zero, and it built for a minute until the scene was scaled.
    let tiny = r#"{"objects": [{"generator": {"cylinder_and_bump": {"cells": 63}},
        "transform": {"translate": [8.98e-320, 0, 0], "scale": 1.655976812239948e-24}}],
        "ground_plane": true}"#;
    input_file(d, "tiny.json", tiny);
    accepted(d, &precompute_args("tiny.json", &[]));
}

/// 100 vertices scattered inside `[base, base + 1e-9]^3` (a fixed Weyl sequence per axis) and
/// 90,000 distinct triangles over them, as an OBJ.
fn tiny_triangles(base: f64) -> String {
    let mut obj = String::new();
    let frac = |x: f64| x - x.floor();
    for k in 0..100 {
        let k = f64::from(k);
        let (x, y, z) = (
            frac(k * 0.618_034),
            frac(k * 0.754_878),
            frac(k * 0.569_840),
        );
        obj.push_str(&format!(
            "v {} {} {}\n",
            base + 1e-9 * x,
            base + 1e-9 * y,
            base + 1e-9 * z
        ));
    }
    let triples = (1..=100u32)
        .flat_map(|a| (a + 1..=100).flat_map(move |b| (b + 1..=100).map(move |c| (a, b, c))));
    for (a, b, c) in triples.take(90_000) {
        obj.push_str(&format!("f {a} {b} {c}\n"));
    }
    obj
}

#[test]
fn malformed_headers_and_sidecars_give_one_short_line() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    // A .npy header with a syntax error 60 KB long: one line, not the header echoed.
    let mut header = format!(
        "{{'descr': '<f4', 'fortran_order': False, 'shape': (4, 4), 'x': '{}' oops}}",
        "x".repeat(60_000)
    );
    while (10 + header.len() + 1) % 64 != 0 {
        header.push(' ');
    }
    header.push('\n');
    let mut npy = b"\x93NUMPY\x01\x00".to_vec();
    npy.extend((header.len() as u16).to_le_bytes());
    npy.extend(header.as_bytes());
    npy.extend([0u8; 64]);
    input_file(d, "long.npy", npy);
    let line = refused(
        d,
        &["info", "long.npy"],
        &["long.npy", "invalid .npy header"],
    );
    assert!(line.len() < 400, "{} bytes: {line}", line.len());
    // A 21-byte file whose header says it is 2.4 GB long (found by the exr fuzz target).
    input_file(
        d,
        "liar.npy",
        b"\x93NUMPY\x03\x00\x00\x10\x00\x8f#\xcdh**#c\x00$",
    );
    refused(
        d,
        &["info", "liar.npy"],
        &["liar.npy", "2399145984 bytes long"],
    );
    // A coefficient file whose sidecar is a link to an endless device.
    let image = testdata("camera.png");
    let (code, _, err, _) = run_measured(d, &["transform", p(&image), "-o", "c.npy"]);
    assert_eq!(code, Some(0), "{err}");
    std::fs::remove_file(d.join("c.npy.json")).unwrap();
    std::os::unix::fs::symlink("/dev/zero", d.join("c.npy.json")).unwrap();
    refused(
        d,
        &["info", "c.npy"],
        &["c.npy.json", "at most 1048576 bytes"],
    );
    // An OpenEXR file whose first chunk offset is u64::MAX.
    let env = testdata("envmaps/rooitou_park_32x16.hdr");
    let (code, _, err, _) = run_measured(d, &["rotate", p(&env), "--angle", "0", "-o", "a.exr"]);
    assert_eq!(code, Some(0), "{err}");
    let mut exr = std::fs::read(d.join("a.exr")).unwrap();
    let table = exr_offset_table(&exr);
    exr[table..table + 8].copy_from_slice(&u64::MAX.to_le_bytes());
    input_file(d, "far.exr", exr);
    refused(
        d,
        &["info", "far.exr"],
        &["far.exr", "chunk offset lies outside"],
    );
}

/// Where a single-part scanline OpenEXR file's offset table starts: after the magic number,
/// the version and the attributes (`name\0 type\0 size value`), ended by an empty name.
fn exr_offset_table(exr: &[u8]) -> usize {
    let mut at = 8;
    while exr[at] != 0 {
        for _ in 0..2 {
            at += exr[at..].iter().position(|&b| b == 0).unwrap() + 1;
        }
        let size = u32::from_le_bytes(exr[at..at + 4].try_into().unwrap()) as usize;
        at += 4 + size;
    }
    at + 1
}
