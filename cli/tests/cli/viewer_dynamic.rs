//! `relight view SCENE.json`: a dynamic scene's objects moved and its motion path played from
//! the page's WebSocket, each frame what `relight scene` computes for the same placements.

use std::path::Path;
use std::time::Duration;

use haarshift_testkit::browser::{Browser, chromium};
use ndarray::Array3;
use serde_json::Value;

use crate::common::{p, succeeds, testdata};
use crate::viewer::{Client, ViewProcess, load_page, wait_for_latest};

/// Small occlusion fields: a build of seconds.
const BUILD: [&str; 10] = [
    "--resolution",
    "8",
    "--circles",
    "8",
    "--circle-points",
    "16",
    "--shells",
    "4",
    "--shell-grid",
    "3",
];

/// Every frame's radiance `(frames, V, 3)` of `relight scene SCENE --animate PATH`.
fn played(dir: &Path, scene: &Path, path: &Path) -> Array3<f32> {
    let (gif, frames) = (dir.join("path.gif"), dir.join("path.npy"));
    let mut cli = vec![
        "relight",
        "scene",
        p(scene),
        "--animate",
        p(path),
        "--force",
    ];
    cli.extend(BUILD);
    cli.extend([
        "--width",
        "24",
        "--height",
        "16",
        "-o",
        p(&gif),
        "--vertices",
        p(&frames),
    ]);
    succeeds(&cli);
    ndarray_npy::read_npy(&frames).unwrap()
}

#[test]
fn a_dynamic_scene_s_objects_move_and_its_path_plays_as_relight_scene_computes_them() {
    let dir = tempfile::tempdir().unwrap();
    let scene = testdata("scenes/bunny_and_ball.json");
    let path = testdata("scenes/ball_path.json");
    let mut args = vec![p(&scene), "--animate", p(&path)];
    args.extend(BUILD);
    let view = ViewProcess::start(&args);
    let mut page = Client::opened(&view.url);

    // The ball dragged to (2, 1.2, 3): its positions first, then the frame. `relight scene`
    // computes the same placement as frame 1 of a path moving the ball there (by just-in-time
    // radiance transfer: another order of the same products).
    page.send(
        r#"{"type": "state", "seq": 1, "yaw": 30, "light_rotation": "source",
            "objects": [[0, 0, 0], [2, 1.2, 3]]}"#,
    );
    let (kind, header, positions) = page.packet();
    assert_eq!(kind, 6, "{header}");
    let (kind, header, moved) = page.packet();
    assert_eq!((kind, &header["seq"]), (3, &Value::from(1)), "{header}");
    assert_eq!(
        header["translations"][1],
        serde_json::json!([2.0, 1.2, 3.0])
    );
    let to_two = dir.path().join("to_two.json");
    std::fs::write(
        &to_two,
        r#"{"segments": [{"frames": 1, "light_yaw": 30},
            {"frames": 1, "object": "ball", "to": {"translate": [2, 1.2, 3], "scale": 1.2}}]}"#,
    )
    .unwrap();
    let expected = played(dir.path(), &scene, &to_two);
    let expected = expected.index_axis(ndarray::Axis(0), 2).to_owned();
    let expected = expected.as_slice().unwrap();
    let moved_error = relative_rms_of_slices(&moved, expected);
    assert!(moved_error < 1e-6, "{moved_error}");
    assert_eq!(positions.len(), expected.len());

    // The ball where the file has it: other shadows (so the comparison above tells
    // placements apart), and positions sent again.
    page.send(r#"{"type": "state", "seq": 2, "yaw": 30, "light_rotation": "source"}"#);
    let (kind, _, back) = page.packet();
    assert_eq!(kind, 6);
    let (_, _, at_rest) = page.packet();
    assert_ne!(back, positions);
    let at_rest_error = relative_rms_of_slices(&at_rest, expected);
    assert!(
        at_rest_error > 100.0 * moved_error.max(1e-9),
        "{at_rest_error}"
    );

    // Path frame 8 of 25: the ball halfway along its first segment, from x = 6.5 to -6.5.
    page.send(r#"{"type": "state", "seq": 3, "path_frame": 8, "light_rotation": "source"}"#);
    let (kind, _, _) = page.packet();
    assert_eq!(kind, 6);
    let (_, header, frame) = page.packet();
    assert_eq!(
        header["translations"][1],
        serde_json::json!([0.0, 1.2, 3.0])
    );
    let all = played(dir.path(), &scene, &path);
    let frame8 = all.index_axis(ndarray::Axis(0), 8).to_owned();
    let path_error = relative_rms_of_slices(&frame, frame8.as_slice().unwrap());
    assert!(path_error < 1e-6, "{path_error}");

    // What a dynamic scene does not offer, and states no page sends, are refused in one
    // line; the session goes on.
    for (request, needle) in [
        (
            r#"{"type": "state", "seq": 4, "objects": [[0, 0, 0]]}"#,
            "the scene has 2 objects",
        ),
        (
            r#"{"type": "state", "seq": 5, "path_frame": 25}"#,
            "the motion path has 25 frames",
        ),
        (
            r#"{"type": "state", "seq": 6, "basis": "sh"}"#,
            "Haar product integrals",
        ),
        (
            r#"{"type": "state", "seq": 7, "objects": [[0, 0, 0], [1e300, 0, 0]]}"#,
            "within 1e15 of the origin",
        ),
    ] {
        page.send(request);
        page.refused(needle);
    }
    // The frame drawn last still answers path frame 8 (the refused states changed nothing);
    // the next path frame is computed.
    page.send(r#"{"type": "state", "seq": 8, "path_frame": 8, "light_rotation": "source"}"#);
    match page.next() {
        tungstenite::Message::Text(t) => assert!(t.contains(r#""unchanged","seq":8"#), "{t}"),
        other => panic!("unchanged expected, got {other:?}"),
    }
    page.send(r#"{"type": "state", "seq": 9, "path_frame": 9, "light_rotation": "source"}"#);
    assert_eq!(page.packet().0, 6);
    let (kind, header, frame9) = page.packet();
    assert_eq!((kind, &header["seq"]), (3, &Value::from(9)), "{header}");
    let expected9 = all.index_axis(ndarray::Axis(0), 9).to_owned();
    assert!(relative_rms_of_slices(&frame9, expected9.as_slice().unwrap()) < 1e-6);
}

#[test]
fn the_page_drags_a_dynamic_scene_s_object_and_plays_its_path_in_headless_chromium() {
    if haarshift_testkit::needs("chromium", chromium()).is_none() {
        return;
    }
    let scene = testdata("scenes/bunny_and_ball.json");
    let path = testdata("scenes/ball_path.json");
    let mut args = vec![p(&scene), "--animate", p(&path)];
    args.extend(BUILD);
    let view = ViewProcess::start(&args);
    let mut browser = Browser::launch(320, 240).unwrap();
    load_page(&mut browser, &format!("{}#width=320&height=240", view.url));
    wait_for_latest(&mut browser);
    let js = |browser: &mut Browser, expression: &str| browser.evaluate(expression).unwrap();
    // The controls a dynamic scene does not offer are hidden, its own are shown.
    assert_eq!(
        js(
            &mut browser,
            "[getComputedStyle(document.getElementById('basis').parentElement).display, getComputedStyle(document.getElementById('dynamic')).display]"
        ),
        serde_json::json!(["none", "block"])
    );

    // The ball chosen (the panel then hidden: it covers this small canvas) and dragged to the
    // right: it slides on the ground (its height stays), the page receives its new positions
    // and the frame for it.
    js(
        &mut browser,
        "const s = document.getElementById('drag_target'); s.value = '1'; \
         s.dispatchEvent(new Event('change')); \
         document.getElementById('panel').style.display = 'none'; true",
    );
    browser.drag([100.0, 120.0], [190.0, 120.0], 10, 0).unwrap();
    wait_for_latest(&mut browser);
    let moved = js(&mut browser, "haarshiftViewer.frame.header.translations[1]");
    let [x, y, z] = [0, 1, 2].map(|i| moved[i].as_f64().unwrap());
    assert!((y - 1.2).abs() < 1e-12 && (x, z) != (6.5, 3.0), "{moved}");
    assert!(js(&mut browser, "haarshiftViewer.positionsReceived").as_u64() >= Some(1));
    let command = js(&mut browser, "haarshiftViewer.command()");
    let command = command.as_str().unwrap();
    assert!(
        command.starts_with("haarshift relight scene")
            && command.contains("# with ball translated to"),
        "{command}"
    );

    // Play: the path's frames follow one another as they arrive.
    js(
        &mut browser,
        "document.getElementById('play').click(); true",
    );
    browser
        .wait_for(
            "haarshiftViewer.frame.header.state.path_frame >= 3",
            Duration::from_secs(60),
        )
        .unwrap();
    js(
        &mut browser,
        "document.getElementById('play').click(); true",
    );
    assert_eq!(browser.console_errors(), Vec::<String>::new());
}

/// The relative RMS difference of two radiance arrays of equal length (the library's
/// [`haarshift::metrics::relative_rms_error`] of them as rows).
fn relative_rms_of_slices(a: &[f32], b: &[f32]) -> f64 {
    let row = |x: &[f32]| ndarray::Array2::from_shape_vec((1, x.len()), x.to_vec()).unwrap();
    crate::common::relative_rms(&row(a), &row(b))
}
