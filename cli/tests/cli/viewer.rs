//! `relight view` in a real headless Chromium (Debian's `chromium`, software WebGL): the page
//! draws frames, a drag brings new ones, and what it received is what `relight render`
//! computes for the same view.

use std::io::{BufRead, BufReader};
use std::path::Path;
use std::process::{Child, Command, Stdio};
use std::time::Duration;

use haarshift_viewer::browser::Browser;
use ndarray::Array2;
use serde_json::Value;

use crate::common::{p, succeeds, testdata};

/// The image size of the page's canvas and of the renders it is compared with.
const SIZE: [usize; 2] = [320, 240];

/// A `relight view` process, killed when dropped.
pub struct ViewProcess {
    child: Child,
    pub url: String,
}

impl ViewProcess {
    /// Starts `relight view ARGS --port 0` and reads the address it prints.
    pub fn start(args: &[&str]) -> ViewProcess {
        let mut child = Command::new(env!("CARGO_BIN_EXE_haarshift"))
            .args(["relight", "view"])
            .args(args)
            .args(["--port", "0"])
            .stdout(Stdio::piped())
            .stderr(Stdio::inherit())
            .spawn()
            .expect("the binary runs");
        let mut line = String::new();
        BufReader::new(child.stdout.take().expect("piped"))
            .read_line(&mut line)
            .expect("the viewer prints its address");
        let url = line
            .split_whitespace()
            .find(|w| w.starts_with("http://"))
            .unwrap_or_else(|| panic!("no address in {line:?}"))
            .to_owned();
        ViewProcess { child, url }
    }
}

impl Drop for ViewProcess {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

/// A bunny scene cache at lat-long 32 in `dir`.
pub fn bunny_cache(dir: &Path) -> std::path::PathBuf {
    let cache = dir.join("bunny.hsr");
    succeeds(&[
        "relight",
        "precompute",
        p(&testdata("meshes/bunny.ply")),
        "--ground-plane",
        "--resolution",
        "32",
        "-o",
        p(&cache),
    ]);
    cache
}

/// The page's last frame: its state and its radiance `(V, 3)`.
fn page_frame(browser: &mut Browser) -> (Value, Array2<f32>) {
    let state = browser
        .evaluate("haarshiftViewer.frame.header.state")
        .unwrap();
    let values = browser
        .evaluate("Array.from(haarshiftViewer.frame.radiance)")
        .unwrap();
    let values: Vec<f32> = values
        .as_array()
        .unwrap()
        .iter()
        .map(|v| v.as_f64().unwrap() as f32)
        .collect();
    let rows = values.len() / 3;
    (state, Array2::from_shape_vec((rows, 3), values).unwrap())
}

/// Waits until the page has drawn the frame of the last state it sent.
fn wait_for_latest(browser: &mut Browser) {
    let waited = browser.wait_for(
        "haarshiftViewer.frame !== null && haarshiftViewer.state !== null && \
             haarshiftViewer.frame.header.seq === haarshiftViewer.state.seq && \
             haarshiftViewer.framesDrawn >= haarshiftViewer.framesReceived",
        Duration::from_secs(120),
    );
    if let Err(e) = waited {
        let page = browser.evaluate(
            "JSON.stringify({ ready: haarshiftViewer.ready, received: haarshiftViewer.framesReceived, \
             drawn: haarshiftViewer.framesDrawn, notices: haarshiftViewer.notices, \
             message: document.getElementById('message').textContent, state: haarshiftViewer.state, \
             seq: haarshiftViewer.frame && haarshiftViewer.frame.header.seq })",
        );
        panic!(
            "{e}: the page says {page:?}, errors {:?}",
            browser.console_errors()
        );
    }
}

/// Runs the page's own `relight render` command line with outputs in `dir/NAME.png` and
/// `.npy`; returns the image's luminance and the per-vertex radiance.
fn render_as_the_page_says(
    browser: &mut Browser,
    dir: &Path,
    name: &str,
) -> (Vec<f64>, Array2<f32>) {
    let command = browser.evaluate("haarshiftViewer.command()").unwrap();
    let command = command.as_str().unwrap();
    let png = dir.join(format!("{name}.png"));
    let npy = dir.join(format!("{name}.npy"));
    let words: Vec<&str> = command
        .strip_prefix("haarshift ")
        .and_then(|c| c.strip_suffix(" -o view.png --vertices view.npy"))
        .unwrap_or_else(|| panic!("unexpected command {command:?}"))
        .split_whitespace()
        .collect();
    let mut args = words.clone();
    args.extend(["-o", p(&png), "--vertices", p(&npy)]);
    succeeds(&args);
    let image = image::open(&png).unwrap().to_rgb8();
    (luminance(&image), ndarray_npy::read_npy(&npy).unwrap())
}

/// Rec. 709 luminance of 8-bit pixels, row-major.
fn luminance(image: &image::RgbImage) -> Vec<f64> {
    image
        .pixels()
        .map(|p| 0.2126 * p[0] as f64 + 0.7152 * p[1] as f64 + 0.0722 * p[2] as f64)
        .collect()
}

/// Pearson correlation.
fn correlation(a: &[f64], b: &[f64]) -> f64 {
    let n = a.len() as f64;
    let (ma, mb) = (a.iter().sum::<f64>() / n, b.iter().sum::<f64>() / n);
    let cov: f64 = a.iter().zip(b).map(|(x, y)| (x - ma) * (y - mb)).sum();
    let va: f64 = a.iter().map(|x| (x - ma).powi(2)).sum();
    let vb: f64 = b.iter().map(|y| (y - mb).powi(2)).sum();
    cov / (va * vb).sqrt()
}

fn screenshot(browser: &mut Browser) -> Vec<f64> {
    let png = browser.screenshot().unwrap();
    let image = image::load_from_memory(&png).unwrap().to_rgb8();
    assert_eq!([image.width() as usize, image.height() as usize], SIZE);
    luminance(&image)
}

#[test]
fn the_page_draws_in_headless_chromium_what_relight_render_computes() {
    let dir = tempfile::tempdir().unwrap();
    let cache = bunny_cache(dir.path());
    let env = testdata("envmaps/rooitou_park_256x128.npy");
    let view = ViewProcess::start(&[p(&cache), "--env", p(&env)]);
    let mut browser = Browser::launch(SIZE[0], SIZE[1]).unwrap();
    browser
        .navigate(&format!(
            "{}#width={}&height={}&panel=0&yaw=30&pitch=10&keep_light=200",
            view.url, SIZE[0], SIZE[1]
        ))
        .unwrap();
    browser
        .wait_for(
            "document.readyState === 'complete'",
            Duration::from_secs(30),
        )
        .unwrap();
    assert_eq!(
        browser.evaluate("haarshiftViewer.webgl2").unwrap(),
        Value::Bool(true),
        "getContext('webgl2') is null"
    );
    wait_for_latest(&mut browser);

    // The first lighting: the page's radiance is relight render's, bit for bit.
    let (state_a, radiance_a) = page_frame(&mut browser);
    assert_eq!(
        (state_a["yaw"].as_f64(), state_a["keep_light"].as_u64()),
        (Some(30.0), Some(200))
    );
    let shot_a = screenshot(&mut browser);
    let (image_a, rendered_a) = render_as_the_page_says(&mut browser, dir.path(), "a");
    assert_eq!(radiance_a, rendered_a);

    // A drag of the lighting brings a new frame, again relight render's.
    let received = browser.evaluate("haarshiftViewer.framesReceived").unwrap();
    browser.drag([100.0, 120.0], [190.0, 150.0], 15, 0).unwrap();
    wait_for_latest(&mut browser);
    let now = browser.evaluate("haarshiftViewer.framesReceived").unwrap();
    assert!(
        now.as_u64() > received.as_u64(),
        "{now} frames after {received}"
    );
    let (state_b, radiance_b) = page_frame(&mut browser);
    assert_eq!(
        state_b["yaw"].as_f64(),
        Some(30.0 + 0.5 * 90.0),
        "{state_b}"
    );
    assert_eq!(
        state_b["pitch"].as_f64(),
        Some(10.0 + 0.5 * 30.0),
        "{state_b}"
    );
    let shot_b = screenshot(&mut browser);
    let (image_b, rendered_b) = render_as_the_page_says(&mut browser, dir.path(), "b");
    assert_eq!(radiance_b, rendered_b);
    assert_ne!(radiance_a, radiance_b);

    // What the page shows changes as the renders do.
    let page: Vec<f64> = shot_b.iter().zip(&shot_a).map(|(b, a)| b - a).collect();
    let cli: Vec<f64> = image_b.iter().zip(&image_a).map(|(b, a)| b - a).collect();
    let r = correlation(&page, &cli);
    assert!(
        r >= 0.9,
        "the change on the page correlates {r:.3} with relight render's"
    );

    // Frames in f16: relight render's radiance to f16 rounding.
    browser
        .evaluate("haarshiftViewer.setState({ format: 'f16' })")
        .unwrap();
    wait_for_latest(&mut browser);
    assert_eq!(
        browser
            .evaluate("haarshiftViewer.frame.header.format")
            .unwrap(),
        Value::from("f16")
    );
    let (_, radiance_h) = page_frame(&mut browser);
    for (h, v) in radiance_h.iter().zip(&rendered_b) {
        assert_eq!(*h, half::f16::from_f32(*v).to_f32(), "{v} sent as {h}");
    }
    let errors = browser.console_errors();
    assert!(errors.is_empty(), "console errors: {errors:?}");
}
