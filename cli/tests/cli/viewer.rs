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
        ViewProcess::start_in(None, args)
    }

    /// [`start`](Self::start) in `dir`, when given.
    pub fn start_in(dir: Option<&Path>, args: &[&str]) -> ViewProcess {
        let mut command = Command::new(env!("CARGO_BIN_EXE_haarshift"));
        if let Some(dir) = dir {
            command.current_dir(dir);
        }
        let mut child = command
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

/// The numbers of the JavaScript array `expression` evaluates to, as f32 (exactly: the page's
/// values are f32).
fn page_floats(browser: &mut Browser, expression: &str) -> Vec<f32> {
    browser
        .evaluate(expression)
        .unwrap()
        .as_array()
        .unwrap()
        .iter()
        .map(|v| v.as_f64().unwrap() as f32)
        .collect()
}

/// The page's last frame: its state and its radiance `(V, 3)`.
fn page_frame(browser: &mut Browser) -> (Value, Array2<f32>) {
    let state = browser
        .evaluate("haarshiftViewer.frame.header.state")
        .unwrap();
    let values = page_floats(browser, "Array.from(haarshiftViewer.frame.radiance)");
    let rows = values.len() / 3;
    (state, Array2::from_shape_vec((rows, 3), values).unwrap())
}

/// Opens `url` and waits until the page has loaded.
pub fn load_page(browser: &mut Browser, url: &str) {
    browser.navigate(url).unwrap();
    browser
        .wait_for(
            "document.readyState === 'complete'",
            Duration::from_secs(30),
        )
        .unwrap();
}

/// Waits until the page has drawn the frame of the last state it sent.
pub fn wait_for_latest(browser: &mut Browser) {
    let waited = browser.wait_for(
        "haarshiftViewer.frame !== null && haarshiftViewer.state !== null && \
             haarshiftViewer.frame.header.seq === haarshiftViewer.state.seq && \
             haarshiftViewer.drawnSeq === haarshiftViewer.state.seq",
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

/// Runs `haarshift ARGS -o dir/NAME.png --vertices dir/NAME.npy` (a `relight render` without
/// its outputs); returns the image's path and the per-vertex radiance.
fn render_to(dir: &Path, name: &str, args: &[&str]) -> (std::path::PathBuf, Array2<f32>) {
    let png = dir.join(format!("{name}.png"));
    let npy = dir.join(format!("{name}.npy"));
    succeeds(&[args, &["-o", p(&png), "--vertices", p(&npy)]].concat());
    (png, ndarray_npy::read_npy(&npy).unwrap())
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
    let words: Vec<&str> = command
        .strip_prefix("haarshift ")
        .and_then(|c| c.strip_suffix(" -o view.png --vertices view.npy"))
        .unwrap_or_else(|| panic!("unexpected command {command:?}"))
        .split_whitespace()
        .collect();
    let (png, radiance) = render_to(dir, name, &words);
    let image = image::open(&png).unwrap().to_rgb8();
    (luminance(&image), radiance)
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
    load_page(
        &mut browser,
        &format!(
            "{}#width={}&height={}&panel=0&yaw=30&pitch=10&keep_light=200",
            view.url, SIZE[0], SIZE[1]
        ),
    );
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

    // A state the server refuses is said on the page, and the next one is drawn.
    browser
        .evaluate("haarshiftViewer.setState({ keep_light: 1e12 })")
        .unwrap();
    browser
        .wait_for(
            "haarshiftViewer.notices.some((n) => n.includes('keep_light')) && \
             document.getElementById('message').style.display === 'block'",
            Duration::from_secs(30),
        )
        .unwrap();

    // The error view: the reference arrives in the background, equal to relight render's
    // reference, and the page shows each vertex's error.
    browser
        .evaluate("haarshiftViewer.setState({ keep_light: 200, format: 'f32', error: true })")
        .unwrap();
    wait_for_latest(&mut browser);
    browser
        .wait_for(
            "haarshiftViewer.reference !== null",
            Duration::from_secs(120),
        )
        .unwrap();
    let yaw = state_b["yaw"].to_string();
    let pitch = state_b["pitch"].to_string();
    let (_, truth) = render_to(
        dir.path(),
        "truth",
        &[
            "relight",
            "render",
            p(&cache),
            "--env",
            p(&env),
            "--yaw",
            &yaw,
            "--pitch",
            &pitch,
            "--basis",
            "reference",
            "--width",
            "16",
            "--height",
            "12",
        ],
    );
    let reference = page_floats(
        &mut browser,
        "Array.from(haarshiftViewer.reference.radiance)",
    );
    assert_eq!(reference, truth.iter().copied().collect::<Vec<_>>());
    browser
        .wait_for(
            "document.getElementById('stats').textContent.includes('error RMS')",
            Duration::from_secs(30),
        )
        .unwrap();

    let errors = browser.console_errors();
    assert!(errors.is_empty(), "console errors: {errors:?}");
}

/// A WebSocket client of the viewer, as a page would be.
pub struct Client(tungstenite::WebSocket<std::net::TcpStream>);

impl Client {
    /// Connects to `/ws`, with an `Origin` header when given.
    fn connect(url: &str, origin: Option<&str>) -> Result<Client, tungstenite::Error> {
        use tungstenite::client::IntoClientRequest;
        let address = url.trim_start_matches("http://").trim_end_matches('/');
        let stream = std::net::TcpStream::connect(address).unwrap();
        stream
            .set_read_timeout(Some(Duration::from_secs(60)))
            .unwrap();
        let mut request = format!("ws://{address}/ws").into_client_request()?;
        if let Some(origin) = origin {
            request
                .headers_mut()
                .insert("Origin", origin.parse().unwrap());
        }
        match tungstenite::client(request, stream) {
            Ok((socket, _)) => Ok(Client(socket)),
            Err(tungstenite::HandshakeError::Failure(e)) => Err(e),
            Err(e) => panic!("{e}"),
        }
    }

    /// Reads the scene and environment packets a session opens with.
    pub fn opened(url: &str) -> Client {
        let mut client = Client::connect(url, None).unwrap();
        assert_eq!(client.packet_kind(), 1);
        assert_eq!(client.packet_kind(), 2);
        client
    }

    /// [`opened`](Self::opened) once a session is free: the page that left may still be
    /// finishing its frame, and its session ends with it.
    fn reopened(url: &str) -> Client {
        for _ in 0..300 {
            let mut client = Client::connect(url, None).unwrap();
            match client.next() {
                tungstenite::Message::Binary(b) if b[0] == 1 => {
                    assert_eq!(client.packet_kind(), 2);
                    return client;
                }
                tungstenite::Message::Text(t) if t.contains("pages at once") => {
                    std::thread::sleep(Duration::from_millis(100));
                }
                other => panic!("a scene or a refusal expected, got {other:?}"),
            }
        }
        panic!("no session was freed within 30 s");
    }

    pub fn send(&mut self, text: &str) {
        self.0.send(tungstenite::Message::text(text)).unwrap();
    }

    pub fn next(&mut self) -> tungstenite::Message {
        loop {
            let message = self.0.read().unwrap();
            if message.is_text() || message.is_binary() {
                return message;
            }
        }
    }

    /// The next message's packet kind (a binary message required).
    fn packet_kind(&mut self) -> u32 {
        match self.next() {
            tungstenite::Message::Binary(b) => u32::from_le_bytes(b[0..4].try_into().unwrap()),
            other => panic!("a packet expected, got {other:?}"),
        }
    }

    /// The next message: an error notice whose message contains `needle`.
    pub fn refused(&mut self, needle: &str) {
        match self.next() {
            tungstenite::Message::Text(t) => {
                let notice: Value = serde_json::from_str(&t).unwrap();
                assert_eq!(notice["type"], "error", "{t}");
                let message = notice["message"].as_str().unwrap();
                assert!(message.contains(needle), "{message:?} lacks {needle:?}");
                assert!(!message.contains('\n'), "{message:?} is not one line");
            }
            other => panic!("an error expected, got {other:?}"),
        }
    }

    /// The next message, a packet: its kind, header and payload as f32.
    pub fn packet(&mut self) -> (u32, Value, Vec<f32>) {
        match self.next() {
            tungstenite::Message::Binary(b) => {
                let kind = u32::from_le_bytes(b[0..4].try_into().unwrap());
                let len = u32::from_le_bytes(b[4..8].try_into().unwrap()) as usize;
                let header: Value = serde_json::from_slice(&b[8..8 + len]).unwrap();
                let start = (8 + len).next_multiple_of(4);
                let values = b[start..]
                    .chunks_exact(4)
                    .map(|c| f32::from_le_bytes(c.try_into().unwrap()))
                    .collect();
                (kind, header, values)
            }
            other => panic!("a packet expected, got {other:?}"),
        }
    }

    /// The next message: a frame answering state `seq`.
    fn frame(&mut self, seq: u64) {
        match self.next() {
            tungstenite::Message::Binary(b) => {
                assert_eq!(u32::from_le_bytes(b[0..4].try_into().unwrap()), 3);
                let len = u32::from_le_bytes(b[4..8].try_into().unwrap()) as usize;
                let header: Value = serde_json::from_slice(&b[8..8 + len]).unwrap();
                assert_eq!(header["seq"], seq, "{header}");
            }
            other => panic!("a frame expected, got {other:?}"),
        }
    }
}

/// The answer to a raw HTTP request.
pub fn http(url: &str, request: &[u8]) -> String {
    use std::io::{Read, Write};
    let address = url.trim_start_matches("http://").trim_end_matches('/');
    let mut stream = std::net::TcpStream::connect(address).unwrap();
    stream
        .set_read_timeout(Some(Duration::from_secs(30)))
        .unwrap();
    let _ = stream.write_all(request);
    let mut answer = String::new();
    let _ = stream.read_to_string(&mut answer);
    answer
}

#[test]
fn bad_requests_are_refused_in_one_line_and_the_viewer_keeps_serving() {
    let dir = tempfile::tempdir().unwrap();
    let cache = bunny_cache(dir.path());
    let env = testdata("envmaps/rooitou_park_256x128.npy");
    let view = ViewProcess::start(&[p(&cache), "--env", p(&env), "--max-sessions", "2"]);
    let mut page = Client::opened(&view.url);
    for (request, needle) in [
        (
            r#"{"type": "state", "seq": 1, "yaw": 10, "colour": 1}"#,
            "unknown field `colour`",
        ),
        (
            r#"{"type": "state", "seq": 1, "yaw": NaN}"#,
            "invalid request",
        ),
        (
            r#"{"type": "state", "seq": 1, "yaw": 1e300}"#,
            "finite angle",
        ),
        (
            r#"{"type": "state", "seq": 1, "eye": [0, 1e999, 0]}"#,
            "invalid request",
        ),
        (
            r#"{"type": "state", "seq": 1, "keep_light": 1000000000000000}"#,
            "keep_light",
        ),
        (
            r#"{"type": "state", "seq": 1, "keep_visibility": 0}"#,
            "keep_visibility",
        ),
        (r#"{"type": "state", "seq": 1, "depth": 99}"#, "depth"),
        (
            r#"{"type": "state", "seq": 1, "brdf": "phong:50", "rotation_cache": 100000000}"#,
            "rotation cache",
        ),
        (
            r#"{"type": "state", "seq": 1, "brdf": "merl:/etc/passwd"}"#,
            "measured BRDFs",
        ),
        (
            r#"{"type": "state", "seq": 1, "basis": "reference"}"#,
            "error view",
        ),
        (r#"{"type": "state", "seq": 1, "basis": "sh"}"#, "sh"),
        (r#"{"type": "play"}"#, "unknown variant `play`"),
        ("not json", "invalid request"),
    ] {
        page.send(request);
        page.refused(needle);
    }
    page.0
        .send(tungstenite::Message::binary(vec![1u8, 2, 3]))
        .unwrap();
    page.refused("binary requests");
    page.send(r#"{"type": "picture", "look_at": [0, 0, 0], "fov": 40, "width": 32, "height": 24}"#);
    page.refused("no frame has been drawn yet");
    // After all that, a good state is drawn, and pictured as OpenEXR.
    page.send(r#"{"type": "state", "seq": 7, "yaw": 12.5, "keep_light": 50}"#);
    page.frame(7);
    page.send(r#"{"type": "picture", "look_at": [0, 0, 0], "fov": 40, "width": 32, "height": 0}"#);
    page.refused("height");
    page.send(
        r#"{"type": "picture", "look_at": [0, 0, 0], "fov": 400, "width": 32, "height": 24}"#,
    );
    page.refused("fov");
    page.send(r#"{"type": "picture", "look_at": [0, 0, 0], "fov": 40, "width": 32, "height": 24}"#);
    match page.next() {
        tungstenite::Message::Binary(b) => {
            assert_eq!(u32::from_le_bytes(b[0..4].try_into().unwrap()), 5);
            let len = u32::from_le_bytes(b[4..8].try_into().unwrap()) as usize;
            let exr = &b[(8 + len).next_multiple_of(4)..];
            assert_eq!(
                &exr[0..4],
                &[0x76, 0x2f, 0x31, 0x01],
                "OpenEXR's magic number"
            );
        }
        other => panic!("a picture expected, got {other:?}"),
    }

    // A second page gets a session of its own; a third, beyond --max-sessions 2, one line.
    let mut second = Client::opened(&view.url);
    second.send(r#"{"type": "state", "seq": 1, "yaw": 80}"#);
    second.frame(1);
    let mut third = Client::connect(&view.url, None).unwrap();
    third.refused("serves 2 pages at once");
    drop(third);

    // A page that leaves while its frame is computed ends its session only.
    second.send(r#"{"type": "state", "seq": 2, "yaw": 81, "brdf": "phong:20"}"#);
    drop(second);
    page.send(r#"{"type": "state", "seq": 8, "yaw": 13}"#);
    page.frame(8);
    let mut again = Client::reopened(&view.url);
    again.send(r#"{"type": "state", "seq": 1, "pitch": 5}"#);
    again.frame(1);

    // Another site's page may not drive the viewer; plain HTTP gets its status lines.
    assert!(Client::connect(&view.url, Some("http://example.com")).is_err());
    assert!(http(&view.url, b"GET /ws HTTP/1.1\r\nHost: x\r\n\r\n").starts_with("HTTP/1.1 400"));
    assert!(
        http(&view.url, b"GET /secret HTTP/1.1\r\nHost: x\r\n\r\n").starts_with("HTTP/1.1 404")
    );
    assert!(http(&view.url, b"POST / HTTP/1.1\r\nHost: x\r\n\r\n").starts_with("HTTP/1.1 405"));
    assert!(http(&view.url, b"\x00\x01garbage\r\n\r\n").starts_with("HTTP/1.1 400"));
    let mut huge = b"GET / HTTP/1.1\r\nX: ".to_vec();
    huge.extend(vec![b'a'; 64 * 1024]);
    assert_eq!(http(&view.url, &huge), "");
    let index = http(&view.url, b"GET / HTTP/1.1\r\nHost: x\r\n\r\n");
    assert!(
        index.starts_with("HTTP/1.1 200") && index.contains("viewer.js"),
        "{index}"
    );
    page.send(r#"{"type": "state", "seq": 9, "yaw": 14}"#);
    page.frame(9);
}

#[test]
fn a_burst_of_states_is_answered_by_the_newest_state_s_frame_only() {
    let dir = tempfile::tempdir().unwrap();
    let cache = bunny_cache(dir.path());
    let env = testdata("envmaps/rooitou_park_256x128.npy");
    let view = ViewProcess::start(&[p(&cache), "--env", p(&env)]);
    let mut page = Client::opened(&view.url);
    // Twenty states in one write, as a fast drag queues them.
    for seq in 1..=20 {
        let state = format!(r#"{{"type": "state", "seq": {seq}, "yaw": {}}}"#, 3 * seq);
        page.0.write(tungstenite::Message::text(state)).unwrap();
    }
    page.0.flush().unwrap();
    let mut answered = Vec::new();
    while answered.last() != Some(&20) {
        match page.next() {
            tungstenite::Message::Binary(b) => {
                let len = u32::from_le_bytes(b[4..8].try_into().unwrap()) as usize;
                let header: Value = serde_json::from_slice(&b[8..8 + len]).unwrap();
                answered.push(header["seq"].as_u64().unwrap());
            }
            other => panic!("a frame expected, got {other:?}"),
        }
    }
    assert!(answered.len() <= 2, "frames for states {answered:?}");
}

#[test]
fn the_results_page_shows_an_experiment_s_records_pictures_and_plot() {
    let dir = tempfile::tempdir().unwrap();
    let cache = bunny_cache(dir.path());
    let env = testdata("envmaps/rooitou_park_256x128.npy");
    let results = testdata("../results/relight/experiments");
    let view = ViewProcess::start(&[p(&cache), "--env", p(&env), "--results", p(&results)]);
    let records: Vec<Value> =
        serde_json::from_slice(&std::fs::read(results.join("relight.json")).unwrap()).unwrap();
    let pictures = std::fs::read_dir(&results)
        .unwrap()
        .filter(|e| e.as_ref().unwrap().path().extension() == Some("png".as_ref()))
        .count();
    assert!(
        http(
            &view.url,
            b"GET /results/files/../relight.csv HTTP/1.1\r\n\r\n"
        )
        .starts_with("HTTP/1.1 404")
    );
    let mut browser = Browser::launch(1000, 800).unwrap();
    browser.navigate(&format!("{}results", view.url)).unwrap();
    browser
        .wait_for(
            &format!(
                "window.haarshiftResults !== undefined && haarshiftResults.records.length === {} && \
                 [...document.images].filter((i) => i.complete && i.naturalWidth > 0).length === {pictures}",
                records.len()
            ),
            Duration::from_secs(30),
        )
        .unwrap();
    // A method's button marks its records in the table and the plot.
    let method = browser
        .evaluate("document.querySelector('#methods button').click(); haarshiftResults.selected")
        .unwrap();
    let marked = browser
        .evaluate("[document.querySelectorAll('#records tr.on').length, document.querySelectorAll('#plot circle[r=\"6\"]').length]")
        .unwrap();
    let of_method = records
        .iter()
        .filter(|r| {
            let key = format!(
                "{} {}",
                r["method"].as_str().unwrap(),
                r["parameters"].as_str().unwrap_or("")
            );
            method.as_str() == Some(key.trim())
        })
        .count();
    assert!(of_method > 0, "{method}");
    assert_eq!(marked[0].as_u64(), Some(of_method as u64), "{marked}");
    assert!(marked[1].as_u64().unwrap() > 0, "{marked}");
    let errors = browser.console_errors();
    assert!(errors.is_empty(), "console errors: {errors:?}");
}

#[test]
fn a_measured_brdf_given_with_merl_is_offered_by_name_and_shaded_as_relight_render_does() {
    use haarshift::relight::material::merl::MerlBrdf;
    let dir = tempfile::tempdir().unwrap();
    let cache = bunny_cache(dir.path());
    let env = testdata("envmaps/rooitou_park_256x128.npy");
    let table = dir.path().join("sheen.binary");
    MerlBrdf::from_fn(|theta_h, _, _| {
        let lobe = theta_h.cos().powi(20);
        [0.2 + 2.0 * lobe, 0.15 + lobe, 0.1]
    })
    .unwrap()
    .write(&table, false)
    .unwrap();
    let view = ViewProcess::start(&[p(&cache), "--env", p(&env), "--merl", p(&table)]);
    let mut page = Client::opened(&view.url);
    // A page names a table it was offered, never a file.
    for name in ["merl:/etc/passwd", "merl:other"] {
        page.send(&format!(
            r#"{{"type": "state", "seq": 1, "brdf": "{name}"}}"#
        ));
        page.refused("given with --merl (merl:sheen)");
    }
    page.send(
        r#"{"type": "state", "seq": 2, "yaw": 30, "brdf": "merl:sheen",
            "light_rotation": "source", "eye": [0, 3, 8]}"#,
    );
    let (kind, header, radiance) = page.packet();
    assert_eq!((kind, &header["seq"]), (3, &Value::from(2)), "{header}");
    let (_, rendered) = render_to(
        dir.path(),
        "m",
        &[
            "relight",
            "render",
            p(&cache),
            "--env",
            p(&env),
            "--yaw",
            "30",
            "--brdf",
            &format!("merl:{}", p(&table)),
            "--camera",
            "0,3,8",
            "--look-at",
            "0,1,0",
            "--width",
            "24",
            "--height",
            "16",
        ],
    );
    assert_eq!(radiance, rendered.as_slice().unwrap());
    // The table, not a Lambertian stand-in: the same view in Lambert is another frame.
    page.send(
        r#"{"type": "state", "seq": 3, "yaw": 30, "light_rotation": "source", "eye": [0, 3, 8]}"#,
    );
    let (_, _, lambert) = page.packet();
    let gap: f32 = lambert
        .iter()
        .zip(&radiance)
        .map(|(a, b)| (a - b).abs())
        .sum();
    assert!(gap > 0.01 * lambert.iter().sum::<f32>(), "{gap}");
}
