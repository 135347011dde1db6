//! The local server: the page and its script over HTTP, one WebSocket session per page.
//!
//! Every connection gets a thread. Its request head is read (at most [`MAX_HEAD`] bytes within
//! [`HEAD_WAIT`]) and parsed by `httparse`; `GET /` and `GET /viewer.js` are answered with the
//! files embedded in the binary, `GET /ws` with the WebSocket handshake (RFC 6455, the accept
//! key by `tungstenite`), after which the thread runs the page's `Session`. Every page gets
//! a session of its own (its own shader, frames and reference) up to
//! [`ViewerOptions::max_sessions`] at once; one more is told so in one line and closed.
//!
//! Before anything else, every request's `Host` must be a name of the address listened on or
//! one of [`ViewerOptions::allowed_hosts`], or it is refused (403): a page of another site
//! that rebinds its own name to this address would otherwise read the viewer's answers. A
//! WebSocket must also come from a page at such a name (`Origin`), and one without `Origin`
//! (no browser opens one so) is refused too: any page the user opens could otherwise drive a
//! server on the loopback.

use std::io::{Read, Write};
use std::net::{SocketAddr, TcpListener, TcpStream};
use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::time::Duration;

use tungstenite::protocol::{Role, WebSocket};
use tungstenite::{Message, handshake::derive_accept_key};

use haarshift_relight::{Error, Result};

use crate::host::AllowedHosts;
use crate::protocol::Notice;
use crate::scene::ViewedScene;
use crate::session::Session;

/// The longest request head read.
pub const MAX_HEAD: usize = 16 * 1024;
/// How long a connection may take to send its request head.
pub const HEAD_WAIT: Duration = Duration::from_secs(10);

const INDEX_HTML: &str = include_str!("../page/index.html");
const VIEWER_JS: &str = include_str!("../page/viewer.js");
const RESULTS_HTML: &str = include_str!("../page/results.html");

/// Where and how the viewer serves.
///
/// ```
/// use haarshift_viewer::ViewerOptions;
/// let o = ViewerOptions::default();
/// assert_eq!((o.address.ip().to_string(), o.address.port(), o.max_sessions), ("127.0.0.1".into(), 8765, 4));
/// assert!(o.allowed_hosts.is_empty()); // 127.0.0.1, localhost and [::1] at port 8765 only
/// ```
#[derive(Clone, Debug)]
pub struct ViewerOptions {
    /// The address to listen on; port 0 takes a free one.
    pub address: SocketAddr,
    /// Pages served at once, each with its own session.
    pub max_sessions: usize,
    /// An `experiment relight` output directory, served at `/results`: its records
    /// (`relight.json`) and pictures (`*.png`) side by side.
    pub results: Option<PathBuf>,
    /// Names the page may be reached by besides those of `address` (its IP address and, on
    /// the loopback or every interface, `127.0.0.1`, `localhost` and `[::1]`): `NAME`, at the
    /// port listened on, or `NAME:PORT` (the port a proxy in front serves). A request whose
    /// `Host` is none of them is refused; case does not matter.
    pub allowed_hosts: Vec<String>,
}

impl Default for ViewerOptions {
    fn default() -> Self {
        ViewerOptions {
            address: SocketAddr::from(([127, 0, 0, 1], 8765)),
            max_sessions: 4,
            results: None,
            allowed_hosts: Vec::new(),
        }
    }
}

/// A viewer bound to its address, ready to [`serve`](Self::serve).
///
/// ```no_run
/// use haarshift_relight::shade::LightSpec;
/// use haarshift_viewer::{Viewer, ViewerOptions, ViewedScene};
/// let light = LightSpec { env: Some("park.hdr".into()), ..LightSpec::default() };
/// let scene = ViewedScene::load("bunny.hsr".as_ref(), &light).unwrap();
/// let viewer = Viewer::bind(scene, ViewerOptions::default()).unwrap();
/// println!("open {}", viewer.url());
/// viewer.serve(); // until the process ends
/// ```
pub struct Viewer {
    listener: TcpListener,
    scene: Arc<ViewedScene>,
    options: ViewerOptions,
    hosts: Arc<AllowedHosts>,
}

impl Viewer {
    /// Listens on `options.address` for pages of `scene`; a name of
    /// [`allowed_hosts`](ViewerOptions::allowed_hosts) that is no host name is refused.
    pub fn bind(scene: ViewedScene, options: ViewerOptions) -> Result<Viewer> {
        if options.max_sessions == 0 {
            return Err(Error::parameter(
                "max sessions",
                "0: at least one page must be served",
            ));
        }
        let listener = TcpListener::bind(options.address).map_err(|e| {
            Error::parameter(
                "address",
                format!("cannot listen on {}: {e}", options.address),
            )
        })?;
        // The port taken, not 0 when 0 was asked for: it is the one in the page's `Host`.
        let hosts = AllowedHosts::new(listening(&listener)?, &options.allowed_hosts)?;
        Ok(Viewer {
            listener,
            scene: Arc::new(scene),
            options,
            hosts: Arc::new(hosts),
        })
    }

    /// The address listened on (with the port taken when 0 was asked for).
    pub fn address(&self) -> Result<SocketAddr> {
        listening(&self.listener)
    }

    /// The page's address, `http://HOST:PORT/`.
    pub fn url(&self) -> String {
        match self.address() {
            Ok(a) => format!("http://{a}/"),
            Err(_) => format!("http://{}/", self.options.address),
        }
    }

    /// Serves pages until the process ends; each connection on its own thread.
    pub fn serve(self) {
        let sessions = Arc::new(AtomicUsize::new(0));
        for stream in self.listener.incoming().flatten() {
            let scene = Arc::clone(&self.scene);
            let sessions = Arc::clone(&sessions);
            let options = self.options.clone();
            let hosts = Arc::clone(&self.hosts);
            std::thread::spawn(move || connection(stream, scene, sessions, options, &hosts));
        }
    }
}

/// The address `listener` listens on.
fn listening(listener: &TcpListener) -> Result<SocketAddr> {
    listener
        .local_addr()
        .map_err(|e| Error::parameter("address", e.to_string()))
}

/// One connection: the page, the script, or a session.
fn connection(
    mut stream: TcpStream,
    scene: Arc<ViewedScene>,
    sessions: Arc<AtomicUsize>,
    options: ViewerOptions,
    hosts: &AllowedHosts,
) {
    let _ = stream.set_read_timeout(Some(HEAD_WAIT));
    let Some((head, rest)) = read_head(&mut stream) else {
        return;
    };
    let mut headers = [httparse::EMPTY_HEADER; 32];
    let mut request = httparse::Request::new(&mut headers);
    if !matches!(request.parse(&head), Ok(httparse::Status::Complete(_))) {
        let _ = respond(
            &mut stream,
            "400 Bad Request",
            "text/plain",
            b"bad request\n",
        );
        return;
    }
    let header = |name: &str| {
        request
            .headers
            .iter()
            .find(|h| h.name.eq_ignore_ascii_case(name))
            .and_then(|h| std::str::from_utf8(h.value).ok())
    };
    // Two `Host` headers are as good as none: which one a proxy or the browser meant is unknown.
    let mut host_headers = request
        .headers
        .iter()
        .filter(|h| h.name.eq_ignore_ascii_case("host"));
    let host = match (host_headers.next(), host_headers.next()) {
        (Some(h), None) => std::str::from_utf8(h.value).ok(),
        _ => None,
    };
    if !hosts.host(host) {
        let body = format!(
            "another host: this viewer answers {} only (relight view --allow-host NAME adds one)\n",
            hosts.names()
        );
        let _ = respond(&mut stream, "403 Forbidden", "text/plain", body.as_bytes());
        return;
    }
    let path = request.path.unwrap_or("/");
    let path = path.split(['?', '#']).next().unwrap_or("/");
    match (request.method, path) {
        (Some("GET"), path) if embedded(path).is_some() => {
            let (kind, body) = embedded(path).expect("matched");
            let _ = respond(&mut stream, "200 OK", kind, body.as_bytes());
        }
        (Some("GET"), "/ws") => {
            let origin_ok = hosts.origin(header("origin"));
            let key = header("sec-websocket-key").map(str::to_owned);
            let upgrade = header("upgrade").is_some_and(|u| u.eq_ignore_ascii_case("websocket"));
            match (origin_ok, upgrade, key) {
                (false, _, _) => {
                    let _ = respond(
                        &mut stream,
                        "403 Forbidden",
                        "text/plain",
                        b"a page of another origin, or none\n",
                    );
                }
                (true, true, Some(key)) => session(stream, rest, &key, scene, &sessions, options),
                _ => {
                    let _ = respond(
                        &mut stream,
                        "400 Bad Request",
                        "text/plain",
                        b"a WebSocket upgrade is expected\n",
                    );
                }
            }
        }
        (Some("GET"), "/results") if options.results.is_some() => {
            let _ = respond(
                &mut stream,
                "200 OK",
                "text/html; charset=utf-8",
                RESULTS_HTML.as_bytes(),
            );
        }
        (Some("GET"), path) if path.starts_with("/results/") => {
            match options
                .results
                .as_deref()
                .and_then(|dir| result_file(dir, &path[9..]))
            {
                Some((kind, bytes)) => {
                    let _ = respond(&mut stream, "200 OK", kind, &bytes);
                }
                None => {
                    let _ = respond(&mut stream, "404 Not Found", "text/plain", b"not found\n");
                }
            }
        }
        (Some("GET"), _) => {
            let _ = respond(&mut stream, "404 Not Found", "text/plain", b"not found\n");
        }
        _ => {
            let _ = respond(
                &mut stream,
                "405 Method Not Allowed",
                "text/plain",
                b"GET only\n",
            );
        }
    }
}

/// The WebSocket handshake, then the page's session (or the refusal of one too many).
fn session(
    mut stream: TcpStream,
    rest: Vec<u8>,
    key: &str,
    scene: Arc<ViewedScene>,
    sessions: &AtomicUsize,
    options: ViewerOptions,
) {
    let accept = format!(
        "HTTP/1.1 101 Switching Protocols\r\nUpgrade: websocket\r\nConnection: Upgrade\r\n\
         Sec-WebSocket-Accept: {}\r\n\r\n",
        derive_accept_key(key.as_bytes())
    );
    if stream.write_all(accept.as_bytes()).is_err() {
        return;
    }
    let _ = stream.set_nodelay(true);
    let mut ws = WebSocket::from_partially_read(stream, rest, Role::Server, None);
    let open = sessions.fetch_add(1, Ordering::SeqCst);
    if open >= options.max_sessions {
        let message = Notice::Error {
            message: format!(
                "the viewer serves {} pages at once and all are open: close one and reload",
                options.max_sessions
            ),
        };
        let _ = ws.send(Message::text(
            serde_json::to_string(&message).expect("a notice serialises"),
        ));
        let _ = ws.close(None);
        let _ = ws.flush();
    } else {
        Session::new(scene).run(ws, options.max_sessions);
    }
    sessions.fetch_sub(1, Ordering::SeqCst);
}

/// The page's files embedded in the binary: the content type and the text at `path`.
fn embedded(path: &str) -> Option<(&'static str, &'static str)> {
    match path {
        "/" | "/index.html" => Some(("text/html; charset=utf-8", INDEX_HTML)),
        "/viewer.js" => Some(("text/javascript; charset=utf-8", VIEWER_JS)),
        _ => None,
    }
}

/// A file of the results directory, with its content type: `relight.json`, `files` (the names
/// of its pictures, JSON) or `files/NAME.png` of a [`plain_png`] name.
fn result_file(dir: &Path, name: &str) -> Option<(&'static str, Vec<u8>)> {
    let (kind, file) = match name {
        "relight.json" => ("application/json", name),
        "files" => {
            let mut names: Vec<String> = std::fs::read_dir(dir)
                .ok()?
                .flatten()
                .filter_map(|e| e.file_name().into_string().ok())
                .filter(|n| plain_png(n))
                .collect();
            names.sort();
            return serde_json::to_vec(&names)
                .ok()
                .map(|b| ("application/json", b));
        }
        _ => {
            let file = name.strip_prefix("files/").filter(|f| plain_png(f))?;
            ("image/png", file)
        }
    };
    std::fs::read(dir.join(file))
        .ok()
        .map(|bytes| (kind, bytes))
}

/// A `.png` file name of letters, digits, `.`, `-` and `_`, not starting with `.`: no path.
fn plain_png(name: &str) -> bool {
    !name.starts_with('.')
        && name.ends_with(".png")
        && name
            .chars()
            .all(|c| c.is_ascii_alphanumeric() || matches!(c, '.' | '-' | '_'))
}

/// The request head (through its blank line) and any bytes read after it, or `None` when the
/// client sent no complete head within the limits.
fn read_head(stream: &mut TcpStream) -> Option<(Vec<u8>, Vec<u8>)> {
    let mut buffer = Vec::with_capacity(1024);
    let mut chunk = [0u8; 1024];
    loop {
        if let Some(end) = buffer.windows(4).position(|w| w == b"\r\n\r\n") {
            let rest = buffer.split_off(end + 4);
            return Some((buffer, rest));
        }
        if buffer.len() >= MAX_HEAD {
            return None;
        }
        match stream.read(&mut chunk) {
            Ok(0) | Err(_) => return None,
            Ok(n) => buffer.extend_from_slice(&chunk[..n]),
        }
    }
}

/// A complete response with `body`; the connection closes after it.
fn respond(stream: &mut TcpStream, status: &str, kind: &str, body: &[u8]) -> std::io::Result<()> {
    let head = format!(
        "HTTP/1.1 {status}\r\nContent-Type: {kind}\r\nContent-Length: {}\r\n\
         Cache-Control: no-store\r\nConnection: close\r\n\r\n",
        body.len()
    );
    stream.write_all(head.as_bytes())?;
    stream.write_all(body)?;
    stream.flush()
}

#[cfg(test)]
#[path = "server_tests.rs"]
mod tests;
