//! Headless Chromium driven over the Chrome DevTools Protocol: how the page is tested and its
//! frame rate measured, in a real browser with software WebGL (SwiftShader).
//!
//! [`Browser::launch`] starts the system's Chromium (Debian's `chromium`; `$CHROMIUM` names
//! another) headless, with a fresh profile in a temporary directory and the DevTools port
//! chosen by the browser (read back from the profile's `DevToolsActivePort`), and attaches to
//! one page over a WebSocket (`tungstenite`'s client). The protocol is JSON: a call is
//! `{id, method, params, sessionId}`, its answer carries the same `id`, everything else is an
//! event, kept so that [`Browser::console_errors`] can list the page's errors.

use std::ffi::OsString;
use std::net::TcpStream;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

use serde_json::{Value, json};
use tungstenite::{Message, WebSocket};

/// What went wrong driving the browser: it was not found, did not start, or a call failed.
#[derive(Debug, thiserror::Error)]
#[error("invalid {what}: {reason}")]
pub struct BrowserError {
    /// `chromium` (finding it) or `browser` (driving it).
    pub what: &'static str,
    /// Why.
    pub reason: String,
}

/// `Result` with [`BrowserError`].
pub type Result<T> = std::result::Result<T, BrowserError>;

/// The flags every launch passes: headless, no sandbox (CI runs as root), SwiftShader's
/// WebGL, nothing fetched from the network.
pub const FLAGS: [&str; 8] = [
    "--headless",
    "--no-sandbox",
    "--use-angle=swiftshader",
    "--enable-unsafe-swiftshader",
    "--disable-background-networking",
    "--disable-component-update",
    "--no-first-run",
    "--hide-scrollbars",
];

/// How long the browser may take to start and answer a call.
const WAIT: Duration = Duration::from_secs(60);

impl BrowserError {
    fn new(what: &'static str, reason: impl Into<String>) -> Self {
        BrowserError {
            what,
            reason: reason.into(),
        }
    }
}

/// A headless Chromium with one page attached.
///
/// ```no_run
/// use haarshift_testkit::browser::Browser;
/// use std::time::Duration;
/// let mut browser = Browser::launch(640, 480).unwrap();
/// browser.navigate("http://127.0.0.1:8765/").unwrap();
/// browser.wait_for("window.haarshiftViewer?.framesDrawn > 0", Duration::from_secs(30)).unwrap();
/// browser.drag([300.0, 240.0], [360.0, 240.0], 10, 0).unwrap(); // the lighting turns 30 degrees
/// std::fs::write("view.png", browser.screenshot().unwrap()).unwrap();
/// assert!(browser.console_errors().is_empty());
/// ```
pub struct Browser {
    child: Child,
    // Dropped after the child is killed: the profile lives as long as the browser.
    _profile: tempfile::TempDir,
    socket: WebSocket<TcpStream>,
    session: String,
    next_id: u64,
    events: Vec<Value>,
}

/// The browser to launch: `$CHROMIUM` (when set and not empty), else `chromium` on the
/// `PATH`; either must be an executable file, or there is none (a test then skips).
///
/// ```
/// // Either a path or a one-line reason saying how to install one.
/// match haarshift_testkit::browser::chromium() {
///     Ok(path) => assert!(path.ends_with("chromium") || std::env::var_os("CHROMIUM").is_some()),
///     Err(e) => assert!(e.to_string().contains("(apt-get install chromium"), "{e}"),
/// }
/// ```
pub fn chromium() -> Result<PathBuf> {
    find_chromium(std::env::var_os("CHROMIUM"), std::env::var_os("PATH"))
}

/// [`chromium`] with `$CHROMIUM` and `$PATH` given.
fn find_chromium(named: Option<OsString>, path: Option<OsString>) -> Result<PathBuf> {
    if let Some(named) = named.filter(|n| !n.is_empty()).map(PathBuf::from) {
        // The one named or none: another found on the PATH is not the browser asked for.
        return if executable(&named) {
            Ok(named)
        } else {
            Err(BrowserError::new(
                "browser",
                format!(
                    "$CHROMIUM names {}, which is no executable file (apt-get install chromium, \
                     or name another)",
                    named.display()
                ),
            ))
        };
    }
    path.iter()
        .flat_map(std::env::split_paths)
        .map(|dir| dir.join("chromium"))
        .find(|p| executable(p))
        .ok_or_else(|| {
            BrowserError::new(
                "browser",
                "no chromium on the PATH (apt-get install chromium, or name one in $CHROMIUM)",
            )
        })
}

/// Whether `path` is a file its owner, group or others may execute.
fn executable(path: &Path) -> bool {
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt;
        path.metadata()
            .is_ok_and(|m| m.is_file() && m.permissions().mode() & 0o111 != 0)
    }
    #[cfg(not(unix))]
    {
        path.is_file()
    }
}

/// A failure to drive the browser.
fn failure(what: impl std::fmt::Display) -> BrowserError {
    BrowserError::new("browser", what.to_string())
}

impl Browser {
    /// Starts Chromium with a `width x height` window on a blank page.
    pub fn launch(width: usize, height: usize) -> Result<Browser> {
        let profile = tempfile::tempdir().map_err(failure)?;
        let child = Command::new(chromium()?)
            .args(FLAGS)
            .arg(format!("--user-data-dir={}", profile.path().display()))
            .arg("--remote-debugging-port=0")
            .arg(format!("--window-size={width},{height}"))
            .arg("about:blank")
            .stdin(Stdio::null())
            .stdout(Stdio::null())
            .stderr(Stdio::null())
            .spawn()
            .map_err(|e| failure(format!("cannot start chromium: {e}")))?;
        let active = profile.path().join("DevToolsActivePort");
        let start = Instant::now();
        let (port, path) = loop {
            if let Ok(text) = std::fs::read_to_string(&active) {
                let mut lines = text.lines();
                if let (Some(port), Some(path)) = (lines.next(), lines.next()) {
                    break (port.to_owned(), path.to_owned());
                }
            }
            if start.elapsed() > WAIT {
                return Err(failure(
                    "chromium did not open its DevTools port within 60 s",
                ));
            }
            std::thread::sleep(Duration::from_millis(50));
        };
        let stream = TcpStream::connect(format!("127.0.0.1:{port}")).map_err(failure)?;
        stream.set_read_timeout(Some(WAIT)).map_err(failure)?;
        let (socket, _) = tungstenite::client(format!("ws://127.0.0.1:{port}{path}"), stream)
            .map_err(|e| failure(format!("DevTools handshake: {e}")))?;
        let mut browser = Browser {
            child,
            _profile: profile,
            socket,
            session: String::new(),
            next_id: 0,
            events: Vec::new(),
        };
        let target = browser.call("Target.createTarget", json!({ "url": "about:blank" }))?;
        let attached = browser.call(
            "Target.attachToTarget",
            json!({ "targetId": target["targetId"], "flatten": true }),
        )?;
        browser.session = attached["sessionId"]
            .as_str()
            .ok_or_else(|| failure("no session attached"))?
            .to_owned();
        for domain in ["Runtime.enable", "Page.enable", "Log.enable"] {
            browser.call(domain, json!({}))?;
        }
        browser.call(
            "Emulation.setDeviceMetricsOverride",
            json!({ "width": width, "height": height, "deviceScaleFactor": 1, "mobile": false }),
        )?;
        Ok(browser)
    }

    /// Calls `method` on the page (the browser itself before a page is attached) and returns
    /// its result; events read meanwhile are kept.
    pub fn call(&mut self, method: &str, params: Value) -> Result<Value> {
        self.next_id += 1;
        let id = self.next_id;
        let mut message = json!({ "id": id, "method": method, "params": params });
        if !self.session.is_empty() {
            message["sessionId"] = json!(self.session);
        }
        self.socket
            .send(Message::text(message.to_string()))
            .map_err(failure)?;
        loop {
            let text = match self.socket.read().map_err(failure)? {
                Message::Text(text) => text,
                _ => continue,
            };
            let value: Value = serde_json::from_str(&text).map_err(failure)?;
            if value["id"] == json!(id) {
                if let Some(error) = value.get("error") {
                    return Err(failure(format!("{method}: {error}")));
                }
                return Ok(value["result"].clone());
            }
            self.events.push(value);
        }
    }

    /// Loads `url` in the page.
    pub fn navigate(&mut self, url: &str) -> Result<()> {
        self.call("Page.navigate", json!({ "url": url })).map(drop)
    }

    /// The value of the JavaScript `expression` in the page (a promise awaited), as JSON.
    pub fn evaluate(&mut self, expression: &str) -> Result<Value> {
        let result = self.call(
            "Runtime.evaluate",
            json!({ "expression": expression, "returnByValue": true, "awaitPromise": true }),
        )?;
        if let Some(e) = result.get("exceptionDetails") {
            return Err(failure(format!("{expression}: {e}")));
        }
        Ok(result["result"]["value"].clone())
    }

    /// Evaluates `expression` until it is true (every 20 ms), for at most `timeout`.
    pub fn wait_for(&mut self, expression: &str, timeout: Duration) -> Result<()> {
        let start = Instant::now();
        loop {
            if self.evaluate(expression)? == json!(true) {
                return Ok(());
            }
            if start.elapsed() > timeout {
                return Err(failure(format!(
                    "still not true after {timeout:?}: {expression}"
                )));
            }
            std::thread::sleep(Duration::from_millis(20));
        }
    }

    /// A mouse event at `(x, y)` CSS pixels: `mousePressed`, `mouseMoved`, `mouseReleased`.
    pub fn mouse(&mut self, kind: &str, x: f64, y: f64, modifiers: u32) -> Result<()> {
        let buttons = if kind == "mouseMoved" { 1 } else { 0 };
        self.call(
            "Input.dispatchMouseEvent",
            json!({ "type": kind, "x": x, "y": y, "button": "left", "buttons": buttons,
                    "clickCount": 1, "modifiers": modifiers }),
        )
        .map(drop)
    }

    /// A left-button drag from `from` to `to` in `steps` moves (`modifiers` 8 holds shift).
    pub fn drag(
        &mut self,
        from: [f64; 2],
        to: [f64; 2],
        steps: usize,
        modifiers: u32,
    ) -> Result<()> {
        self.mouse("mousePressed", from[0], from[1], modifiers)?;
        for k in 1..=steps.max(1) {
            let t = k as f64 / steps.max(1) as f64;
            let x = from[0] + t * (to[0] - from[0]);
            let y = from[1] + t * (to[1] - from[1]);
            self.mouse("mouseMoved", x, y, modifiers)?;
        }
        self.mouse("mouseReleased", to[0], to[1], modifiers)
    }

    /// A PNG of the page's viewport.
    pub fn screenshot(&mut self) -> Result<Vec<u8>> {
        let shot = self.call("Page.captureScreenshot", json!({ "format": "png" }))?;
        let data = shot["data"]
            .as_str()
            .ok_or_else(|| failure("a screenshot without data"))?;
        data_encoding::BASE64
            .decode(data.as_bytes())
            .map_err(failure)
    }

    /// The page's errors so far: console errors, uncaught exceptions and errors logged by the
    /// browser (a failed load, a WebGL error).
    pub fn console_errors(&mut self) -> Vec<String> {
        // Let queued events in: a cheap call reads whatever arrived before its answer.
        let _ = self.evaluate("0");
        self.events
            .iter()
            .filter_map(|e| match e["method"].as_str() {
                Some("Runtime.exceptionThrown") => {
                    Some(e["params"]["exceptionDetails"].to_string())
                }
                Some("Runtime.consoleAPICalled") if e["params"]["type"] == "error" => {
                    Some(e["params"]["args"].to_string())
                }
                Some("Log.entryAdded") if e["params"]["entry"]["level"] == "error" => {
                    Some(e["params"]["entry"]["text"].to_string())
                }
                _ => None,
            })
            .collect()
    }
}

impl Drop for Browser {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

// The modes set are Unix's.
#[cfg(all(test, unix))]
#[path = "browser_tests.rs"]
mod tests;
