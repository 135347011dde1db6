//! The viewer's frame rate in headless Chromium (software WebGL sharing the machine's cores
//! with the server): one markdown row per run.
//!
//! ```sh
//! cargo run --release -p haarshift-viewer --example frame_rate -- SCENE ENV [KEY=VALUE ...]
//! ```
//!
//! SCENE is a scene cache (`.hsr`) or a scene file (`.json`, built as `relight scene` builds
//! it at lat-long `resolution`, 32 by default, its occlusion maps kept to `keep_field`
//! detail coefficients, all by default). Keys: `brdf` (`lambert`), `keep_light`,
//! `keep_visibility`, `keep_brdf`, `rotation_cache` (the page's state), `drag` (`light`,
//! `orbit` or `object:K`, a dynamic scene's object K), `moves` (50: mouse moves of the drag,
//! one every 16 ms), `size` (`640x480`), `label`, `screenshot` (a PNG of the page after the
//! drag).
//!
//! The server's time per frame is the median over the frames computed during the drag of
//! their lighting encoding and shading (rotations included), from the frames' headers; frames
//! received and drawn per second are the page's own counters over the drag's wall time, read
//! over the DevTools protocol. `scripts/viewer_frame_rate.sh` runs the configurations of
//! `results/viewer/frame_rate.md`.

use std::collections::HashMap;
use std::time::{Duration, Instant};

use haarshift::faces::{ParamKind, Parameterization};
use haarshift::product::Selection;
use haarshift_relight::dynamic::{DynamicOptions, DynamicScene};
use haarshift_relight::shade::LightSpec;
use haarshift_testkit::browser::Browser;
use haarshift_viewer::{ViewedScene, Viewer, ViewerOptions};
use serde_json::Value;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let [path, env, options @ ..] = args.as_slice() else {
        return Err("usage: frame_rate SCENE ENV [KEY=VALUE ...]".into());
    };
    let options: HashMap<&str, &str> = options
        .iter()
        .map(|o| o.split_once('=').ok_or(format!("{o}: expected KEY=VALUE")))
        .collect::<Result<_, _>>()?;
    let get = |key: &str, default: &'static str| options.get(key).copied().unwrap_or(default);
    let moves: usize = get("moves", "50").parse()?;
    let (width, height) = get("size", "640x480")
        .split_once('x')
        .ok_or("size: expected WxH")?;
    let (width, height): (usize, usize) = (width.parse()?, height.parse()?);
    let drag = get("drag", "light");
    let orbit = drag == "orbit";
    let object = drag
        .strip_prefix("object:")
        .map(str::parse::<usize>)
        .transpose()?;

    let light = LightSpec {
        env: Some(env.into()),
        ..LightSpec::default()
    };
    let scene = if path.ends_with(".json") {
        let resolution = get("resolution", "32").parse()?;
        let mut build = DynamicOptions::new(Parameterization::new(ParamKind::LatLong, resolution)?);
        if let Some(k) = options.get("keep_field") {
            build.field.keep = Selection::Largest(k.parse()?);
        }
        let built = DynamicScene::load_with(path.as_ref(), &build, None)?;
        ViewedScene::dynamic(built, path.as_ref(), None, &light)?
    } else {
        ViewedScene::load(path.as_ref(), &light)?
    };
    let vertices = scene.mesh().vertex_count();
    let param = scene.param();
    let viewer = Viewer::bind(
        scene,
        ViewerOptions {
            address: "127.0.0.1:0".parse()?,
            max_sessions: 2,
            ..ViewerOptions::default()
        },
    )?;
    let url = viewer.url();
    std::thread::spawn(move || viewer.serve());

    let mut hash = format!(
        "width={width}&height={height}&panel=0&brdf={}",
        get("brdf", "lambert")
    );
    for key in [
        "keep_light",
        "keep_visibility",
        "keep_brdf",
        "rotation_cache",
    ] {
        if let Some(v) = options.get(key) {
            hash.push_str(&format!("&{key}={v}"));
        }
    }
    let mut browser = Browser::launch(width, height)?;
    browser.navigate(&format!("{url}#{hash}"))?;
    // The newest state's frame drawn, or a refusal (which ends the run).
    let latest = "window.haarshiftViewer !== undefined && (haarshiftViewer.notices.length > 0 || \
                  haarshiftViewer.frame !== null && haarshiftViewer.state !== null && \
                  haarshiftViewer.drawnSeq === haarshiftViewer.state.seq)";
    let refused = |b: &mut Browser| -> Result<(), Box<dyn std::error::Error>> {
        match b.evaluate("haarshiftViewer.notices")?.as_array() {
            Some(notices) if !notices.is_empty() => {
                Err(format!("the server refused the page's state: {notices:?}").into())
            }
            _ => Ok(()),
        }
    };
    let first = Instant::now();
    browser.wait_for(latest, Duration::from_secs(1800))?;
    refused(&mut browser)?;
    let first_frame = first.elapsed().as_secs_f64();

    let count = |b: &mut Browser, what: &str| -> Result<f64, Box<dyn std::error::Error>> {
        Ok(b.evaluate(what)?.as_f64().ok_or(what.to_owned())?)
    };
    if let Some(k) = object {
        browser.evaluate(&format!(
            "const s = document.getElementById('drag_target'); s.value = '{k}'; \
             s.dispatchEvent(new Event('change')); true"
        ))?;
    }
    let received = count(&mut browser, "haarshiftViewer.framesReceived")?;
    let drawn = count(&mut browser, "haarshiftViewer.framesDrawn")?;
    let since = count(&mut browser, "performance.now()")?;
    let modifiers = if orbit { 8 } else { 0 };
    let (x0, y0) = (width as f64 / 2.0, height as f64 / 2.0);
    let start = Instant::now();
    browser.mouse("mousePressed", x0, y0, modifiers)?;
    for k in 1..=moves {
        // Back and forth, 4 pixels a move (2 degrees of yaw, 1.6 of orbit).
        let x = x0
            + 4.0
                * (if (k / 40) % 2 == 0 {
                    k % 40
                } else {
                    40 - k % 40
                }) as f64;
        browser.mouse("mouseMoved", x, y0, modifiers)?;
        let next = Duration::from_millis(16 * k as u64);
        if let Some(rest) = next.checked_sub(start.elapsed()) {
            std::thread::sleep(rest);
        }
    }
    browser.mouse("mouseReleased", x0, y0, modifiers)?;
    let seconds = start.elapsed().as_secs_f64();
    let received = (count(&mut browser, "haarshiftViewer.framesReceived")? - received) / seconds;
    let drawn = (count(&mut browser, "haarshiftViewer.framesDrawn")? - drawn) / seconds;
    browser.wait_for(latest, Duration::from_secs(600))?;
    refused(&mut browser)?;
    let timings = browser.evaluate(&format!(
        "haarshiftViewer.timings.filter((t) => t.at > {since}).map((t) => [t.encode, t.rotate, t.shade, t.prepare])"
    ))?;
    let mut server: Vec<[f64; 4]> = timings
        .as_array()
        .ok_or("no timings")?
        .iter()
        .map(|t| {
            let v: Vec<f64> = t
                .as_array()
                .into_iter()
                .flatten()
                .filter_map(Value::as_f64)
                .collect();
            [v[0], v[1], v[2], v[3]]
        })
        .collect();
    server.sort_by(|a, b| (a[0] + a[2]).total_cmp(&(b[0] + b[2])));
    let median = server
        .get(server.len() / 2)
        .copied()
        .unwrap_or([f64::NAN; 4]);
    if let Some(path) = options.get("screenshot") {
        // A new document (a hash change alone would not reload the page), controls shown.
        browser.navigate("about:blank")?;
        browser.navigate(&format!("{url}#{}", hash.replace("&panel=0", "")))?;
        browser.wait_for(latest, Duration::from_secs(1800))?;
        std::thread::sleep(Duration::from_millis(500));
        std::fs::write(path, browser.screenshot()?)?;
    }
    let errors = browser.console_errors();
    if !errors.is_empty() {
        return Err(format!("the page logged errors: {errors:?}").into());
    }
    println!(
        "| {} | {vertices} | {} {} | {} | {} | {width} x {height} | {} | {:.1} | {:.1} | {:.1} | {:.1} | {} | {received:.1} | {drawn:.1} | {first_frame:.1} |",
        get("label", "-"),
        param.kind(),
        param.face_size(),
        get("brdf", "lambert"),
        ["keep_light", "keep_visibility", "keep_field", "keep_brdf"]
            .iter()
            .filter_map(|k| options.get(k).map(|v| format!("{k} {v}")))
            .collect::<Vec<_>>()
            .join(", "),
        match object {
            Some(k) => format!("object {k}"),
            None if orbit => "camera".into(),
            None => "lighting".into(),
        },
        median[0],
        median[1],
        median[2],
        median[0] + median[2],
        server.len(),
    );
    Ok(())
}
