//! `relight view` in a real headless Chromium (Debian's `chromium`, software WebGL): the page
//! draws frames, a drag brings new ones, and what it received is what `relight render`
//! computes for the same view.

use std::io::{BufRead, BufReader};
use std::path::Path;
use std::process::{Child, Command, Stdio};
use std::time::Duration;

use haarshift_testkit::browser::{Browser, chromium};
use ndarray::Array2;
use serde_json::Value;

use crate::common::{fails_cleanly_within, p, succeeds, testdata};

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
    if haarshift_testkit::needs("chromium", chromium()).is_none() {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let cache = bunny_cache(dir.path());
    let env = testdata("envmaps/rooitou_park_256x128.npy");
    let view = ViewProcess::start(&[p(&cache), "--env", p(&env)]);
    let mut browser = Browser::launch(SIZE[0], SIZE[1]).unwrap();
    let first_view = format!(
        "#width={}&height={}&panel=0&yaw=30&pitch=10&keep_light=200",
        SIZE[0], SIZE[1]
    );
    load_page(&mut browser, &format!("{}{first_view}", view.url));
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

    // The page through the loopback's other name: the first view again, the same frame.
    let localhost = view.url.replace("//127.0.0.1:", "//localhost:");
    assert_ne!(localhost, view.url);
    load_page(&mut browser, &format!("{localhost}{first_view}"));
    wait_for_latest(&mut browser);
    assert_eq!(
        browser.evaluate("location.host").unwrap(),
        Value::from(&localhost["http://".len()..localhost.len() - 1])
    );
    let (state_l, radiance_l) = page_frame(&mut browser);
    assert_eq!(state_l["yaw"], state_a["yaw"], "{state_l}");
    assert_eq!(radiance_l, rendered_a);
    let errors = browser.console_errors();
    assert!(errors.is_empty(), "console errors: {errors:?}");
}

/// A WebSocket client of the viewer, as a page would be.
pub struct Client(tungstenite::WebSocket<std::net::TcpStream>);

impl Client {
    /// Connects to `/ws` (its `Host` the url's), with an `Origin` header when given.
    pub fn connect(url: &str, origin: Option<&str>) -> Result<Client, tungstenite::Error> {
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
        let mut client = Client::connect(url, Some(origin(url))).unwrap();
        assert_eq!(client.packet_kind(), 1);
        assert_eq!(client.packet_kind(), 2);
        client
    }

    /// [`opened`](Self::opened) once a session is free: the page that left may still be
    /// finishing its frame, and its session ends with it.
    fn reopened(url: &str) -> Client {
        for _ in 0..300 {
            let mut client = Client::connect(url, Some(origin(url))).unwrap();
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

/// The origin of the page at `url` (`http://HOST:PORT/`): `http://HOST:PORT`.
fn origin(url: &str) -> &str {
    url.trim_end_matches('/')
}

/// The `HOST:PORT` of `url` (`http://HOST:PORT/`), as the page's requests name it.
pub fn authority(url: &str) -> &str {
    origin(url).trim_start_matches("http://")
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
    let mut third = Client::connect(&view.url, Some(origin(&view.url))).unwrap();
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

    // Another site's page may not drive the viewer, nor a socket that names no page; plain
    // HTTP gets its status lines.
    let forbidden = |origin| match Client::connect(&view.url, origin) {
        Err(tungstenite::Error::Http(response)) => {
            assert_eq!(response.status(), 403, "{origin:?}");
            // The reason, when it came with the status line's packet (an empty body when it
            // did not: the client stops reading at the end of the headers).
            if let Some(body) = response.body().as_ref().filter(|b| !b.is_empty()) {
                let body = String::from_utf8_lossy(body);
                assert_eq!(body, "a page of another origin, or none\n", "{origin:?}");
            }
        }
        other => panic!(
            "{origin:?}: expected a 403, got {:?}",
            other.map(|_| "a socket")
        ),
    };
    forbidden(Some("http://example.com"));
    forbidden(None);
    let host = authority(&view.url);
    let get = |path: &str| format!("GET {path} HTTP/1.1\r\nHost: {host}\r\n\r\n");
    let ws = format!("GET /ws HTTP/1.1\r\nHost: {host}\r\nOrigin: http://{host}\r\n\r\n");
    assert!(http(&view.url, ws.as_bytes()).starts_with("HTTP/1.1 400"));
    assert!(http(&view.url, get("/secret").as_bytes()).starts_with("HTTP/1.1 404"));
    let post = format!("POST / HTTP/1.1\r\nHost: {host}\r\n\r\n");
    assert!(http(&view.url, post.as_bytes()).starts_with("HTTP/1.1 405"));
    assert!(http(&view.url, b"\x00\x01garbage\r\n\r\n").starts_with("HTTP/1.1 400"));
    let mut huge = b"GET / HTTP/1.1\r\nX: ".to_vec();
    huge.extend(vec![b'a'; 64 * 1024]);
    assert_eq!(http(&view.url, &huge), "");
    let index = http(&view.url, get("/").as_bytes());
    assert!(
        index.starts_with("HTTP/1.1 200") && index.contains("viewer.js"),
        "{index}"
    );
    page.send(r#"{"type": "state", "seq": 9, "yaw": 14}"#);
    page.frame(9);
}

/// The first line of the answer to a raw HTTP request (a WebSocket's 101 is not read on).
fn status_line(url: &str, request: &str) -> String {
    use std::io::Write;
    let mut stream = std::net::TcpStream::connect(authority(url)).unwrap();
    stream
        .set_read_timeout(Some(Duration::from_secs(30)))
        .unwrap();
    let _ = stream.write_all(request.as_bytes());
    let mut line = String::new();
    let _ = BufReader::new(stream).read_line(&mut line);
    line.trim_end().to_owned()
}

/// A request for `path` with the `Host` and `Origin` headers given (a WebSocket's upgrade
/// headers for `/ws`).
fn request(method: &str, path: &str, host: Option<&str>, origin: Option<&str>) -> String {
    let mut request = format!("{method} {path} HTTP/1.1\r\n");
    if let Some(host) = host {
        request += &format!("Host: {host}\r\n");
    }
    if let Some(origin) = origin {
        request += &format!("Origin: {origin}\r\n");
    }
    if path == "/ws" {
        request += "Upgrade: websocket\r\nConnection: Upgrade\r\n\
                    Sec-WebSocket-Key: dGhlIHNhbXBsZSBub25jZQ==\r\nSec-WebSocket-Version: 13\r\n";
    }
    request + "\r\n"
}

#[test]
fn only_the_address_s_own_names_and_those_of_allow_host_are_answered() {
    let dir = tempfile::tempdir().unwrap();
    let cache = bunny_cache(dir.path());
    let env = testdata("envmaps/rooitou_park_256x128.npy");
    let results = testdata("../results/relight/experiments");
    let (cache, env, results) = (p(&cache), p(&env), p(&results));
    for bad in ["http://viewer.lan", "viewer.lan:port", "viewer.lan/ws"] {
        let args = ["relight", "view", cache, "--env", env, "--port", "0"];
        let args = [&args[..], &["--allow-host", bad]].concat();
        fails_cleanly_within(Duration::from_secs(60), &args, &["allowed host", bad]);
    }
    let view = ViewProcess::start(&[
        cache,
        "--env",
        env,
        "--results",
        results,
        "--allow-host",
        "Viewer.LAN",
        "--allow-host",
        "proxy.lan:8080",
    ]);
    let port = authority(&view.url).rsplit_once(':').unwrap().1;
    let at = |name: &str| format!("{name}:{port}");
    let status = |method, path, host: Option<&str>, origin: Option<&str>| {
        status_line(&view.url, &request(method, path, host, origin))
    };

    // A rebound page (another name, its own origin), no Host, and names at other ports: 403
    // on every path, before the path or the method is looked at.
    let evil = at("evil.example");
    let refused = [
        Some(evil.clone()),
        Some(at("localhost.evil.example")),
        None,
        Some("localhost".to_owned()),
        Some("127.0.0.1:1".to_owned()),
        Some("viewer.lan:8080".to_owned()),
        Some(at("proxy.lan")),
    ];
    let paths = [
        "/",
        "/index.html",
        "/viewer.js",
        "/ws",
        "/results",
        "/results/relight.json",
        "/results/files",
        "/results/files/../relight.csv",
        "/secret",
    ];
    let mut answered = Vec::new();
    for path in paths {
        for host in &refused {
            let origin = host.as_ref().map(|h| format!("http://{h}"));
            for method in ["GET", "POST"] {
                let answer = status(method, path, host.as_deref(), origin.as_deref());
                if answer != "HTTP/1.1 403 Forbidden" {
                    answered.push(format!("{method} {path} at {host:?}: {answer}"));
                }
            }
        }
    }
    assert!(answered.is_empty(), "answered: {answered:#?}");
    let two = format!(
        "GET / HTTP/1.1\r\nHost: {}\r\nHost: {evil}\r\n\r\n",
        at("localhost")
    );
    assert_eq!(status_line(&view.url, &two), "HTTP/1.1 403 Forbidden");

    // The loopback's names at the port, and those allowed, in any case.
    for host in [
        at("127.0.0.1"),
        at("localhost"),
        at("LocalHost"),
        at("[::1]"),
        at("viewer.lan"),
        at("VIEWER.lan"),
        "proxy.lan:8080".to_owned(),
    ] {
        let page = format!("http://{host}");
        let host = Some(host.as_str());
        for (path, expected) in [
            ("/", "200 OK"),
            ("/viewer.js", "200 OK"),
            ("/results", "200 OK"),
            ("/results/relight.json", "200 OK"),
            ("/results/files/../relight.csv", "404 Not Found"),
            ("/secret", "404 Not Found"),
        ] {
            let answer = status("GET", path, host, None);
            assert_eq!(answer, format!("HTTP/1.1 {expected}"), "{path} at {host:?}");
        }
        assert_eq!(
            status("POST", "/", host, None),
            "HTTP/1.1 405 Method Not Allowed"
        );
        // A WebSocket of a page at an accepted name only: never without Origin.
        let ws = |origin: Option<&str>| status("GET", "/ws", host, origin);
        assert_eq!(
            ws(Some(&page)),
            "HTTP/1.1 101 Switching Protocols",
            "{page}"
        );
        for origin in [
            None,
            Some(format!("http://{evil}")),
            Some(page.replace("http:", "https:")),
            Some("http://localhost:1".to_owned()),
        ] {
            assert_eq!(
                ws(origin.as_deref()),
                "HTTP/1.1 403 Forbidden",
                "{origin:?}"
            );
        }
    }
    let index = http(
        &view.url,
        request("GET", "/", Some(&at("localhost")), None).as_bytes(),
    );
    assert!(index.contains("viewer.js"), "{index}");

    // The refusal says which names are answered.
    let refusal = http(&view.url, request("GET", "/", Some(&evil), None).as_bytes());
    assert!(
        refusal.ends_with(&format!(
            "this viewer answers 127.0.0.1:{port}, localhost:{port}, [::1]:{port}, \
             viewer.lan:{port}, proxy.lan:8080 only (relight view --allow-host NAME adds one)\n"
        )),
        "{refusal}"
    );

    // A page at localhost gets its session (once the handshakes above have left theirs).
    let localhost = view.url.replace("//127.0.0.1:", "//localhost:");
    let mut page = Client::reopened(&localhost);
    page.send(r#"{"type": "state", "seq": 1, "yaw": 10}"#);
    page.frame(1);
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
    if haarshift_testkit::needs("chromium", chromium()).is_none() {
        return;
    }
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
    use haarshift_relight::material::merl::MerlBrdf;
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
