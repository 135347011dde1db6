//! `relight precompute --bounces B` and the render of its cache end to end on a small open
//! box: with every coefficient the render equals `relight reference --bounces B`, the direct
//! light of a bounce cache is that of a cache without, and what the baked albedo forbids is
//! refused in one line.

use std::path::Path;

use crate::common::read_vertices;
use crate::common::relative_rms;
use crate::common::{fails_cleanly, p, succeeds, succeeds_with_stdout, testdata};
use crate::viewer::{Client, ViewProcess};

#[test]
fn a_bounce_cache_renders_the_gather_and_refuses_what_its_albedo_forbids() {
    let dir = tempfile::tempdir().unwrap();
    let out = |name: &str| dir.path().join(name);
    // An open box, 2 x 2 cells a face (45 vertices), its floor coloured.
    let scene = out("box.json");
    std::fs::write(
        &scene,
        r#"{"objects": [{"generator": {"box": {"cells": 2}},
            "material": {"brdf": "lambert", "albedo": [0.9, 0.6, 0.3]}}]}"#,
    )
    .unwrap();
    let env = testdata("envmaps/rooitou_park_32x16.hdr");
    let grid = ["--param", "latlong", "--resolution", "8"];
    let precompute = |extra: &[&str], cache: &Path| {
        let mut args = vec!["relight", "precompute", p(&scene), "-o", p(cache)];
        args.extend(grid);
        args.extend(extra);
        succeeds_with_stdout(&args)
    };
    let render = |cache: &Path, extra: &[&str], vertices: &Path| {
        let image = out("image.png");
        let mut args = vec!["relight", "render", p(cache), "--env", p(&env)];
        args.extend(["--vertices", p(vertices), "-o", p(&image), "--force"]);
        args.extend(["--width", "16", "--height", "16"]);
        args.extend(extra);
        succeeds(&args);
        read_vertices(vertices)
    };
    let plain = out("plain.hsr");
    precompute(&[], &plain);
    let direct = render(&plain, &[], &out("direct.npy"));
    for b in ["1", "2"] {
        let cache = out(&format!("b{b}.hsr"));
        let stdout = precompute(&["--bounces", b], &cache);
        assert!(
            stdout.contains(&format!("and {b} bounces: 3 sets")),
            "{stdout}"
        );
        let got = render(&cache, &[], &out("got.npy"));
        let truth = out("truth.npy");
        let mut args = vec!["relight", "reference", p(&scene), "--env", p(&env)];
        args.extend(["--resolution", "8", "--bounces", b, "--vertices", p(&truth)]);
        args.push("--force");
        succeeds(&args);
        let error = relative_rms(&got, &read_vertices(&truth));
        assert!(error < 1e-6, "{b} bounces: {error:e}");
        assert!(relative_rms(&direct, &read_vertices(&truth)) > 1e-2);
        // The direct light of a bounce cache is the plain cache's, bit for bit.
        assert_eq!(render(&cache, &["--direct-only"], &out("d.npy")), direct);
    }
    let b2 = out("b2.hsr");
    let (fresh, fresh_png) = (out("fresh.npy"), out("fresh.png"));
    let render_args = |extra: &'static [&'static str]| {
        let mut args = vec!["relight", "render", p(&b2), "--env", p(&env)];
        args.extend(["--vertices", p(&fresh), "-o", p(&fresh_png)]);
        args.extend(extra);
        args
    };
    for (extra, needles) in [
        (
            &["--albedo", "0.5,0.5,0.5"][..],
            &["b2.hsr", "--albedo", "2 bounces"][..],
        ),
        (
            &["--brdf", "phong:10"],
            &["b2.hsr", "--brdf phong", "--direct-only"],
        ),
        (&["--basis", "ambient"], &["b2.hsr", "--basis ambient"]),
    ] {
        fails_cleanly(&render_args(extra), needles);
        assert!(!fresh.exists());
    }
    let refused = out("refused.hsr");
    let glossy = out("glossy.json");
    std::fs::write(
        &glossy,
        r#"{"objects": [{"generator": {"box": {"cells": 2}},
            "material": {"brdf": "phong", "exponent": 10, "albedo": [0.5, 0.5, 0.5]}}]}"#,
    )
    .unwrap();
    for (input, extra, needles) in [
        (&scene, &["--bounces", "9"][..], &["bounces", "0 to 8"][..]),
        (
            &scene,
            &["--bounces", "1", "--order", "direction"],
            &["shadow buffers", "--order vertex"],
        ),
        (
            &scene,
            &["--bounces", "1", "--shard", "0/2"],
            &["every vertex", "merge"],
        ),
        (&glossy, &["--bounces", "1"], &["glossy", "dynamic"]),
    ] {
        let mut args = vec!["relight", "precompute", p(input), "-o", p(&refused)];
        args.extend(grid);
        args.extend(extra);
        fails_cleanly(&args, needles);
        assert!(!refused.exists());
    }
    // The viewer offers the bounce cache's own material only: the scene packet says so (the
    // page greys its menu) and a state asking for another is refused in one line.
    let view = ViewProcess::start(&[p(&b2), "--env", p(&env)]);
    let address = view.url.trim_end_matches('/');
    let mut page = Client::connect(&view.url, Some(address)).unwrap();
    let (kind, scene_header, _) = page.packet();
    assert_eq!((kind, &scene_header["bounces"]), (1, &2.into()));
    assert_eq!(page.packet().0, 2);
    page.send(r#"{"type": "state", "seq": 1, "brdf": "phong:10"}"#);
    page.refused("2 bounces of light");
    page.send(r#"{"type": "state", "seq": 2, "basis": "haar"}"#);
    let (kind, frame, _) = page.packet();
    assert_eq!((kind, &frame["seq"]), (3, &2.into()));
    drop(page);
    drop(view);
    let image = out("s.png");
    let args = [
        "relight",
        "scene",
        p(&scene),
        "-o",
        p(&image),
        "--bounces",
        "1",
    ];
    fails_cleanly(&args, &["bounces", "static scenes"]);
}
